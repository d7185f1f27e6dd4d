"""Each command's capability from Python gives the command line's numbers: the same library
function and the same report behind both (knapsack reduction, log sampling, training, studies)."""

import csv
import io
import json

import pytest

import ontime
from conftest import PAPER_INSTANCES, SOURCE_DIR

KNAPSACK = SOURCE_DIR / "data" / "knapsack" / "example.json"


def test_reduce_knapsack_writes_the_cli_instance(cli):
    expected = cli("reduce-knapsack", KNAPSACK)
    problem = ontime.reduce_knapsack(KNAPSACK)
    assert json.loads(problem.to_json()) == expected
    assert problem.name == KNAPSACK.stem
    # The same knapsack as a dict gives the same instance under the name asked for.
    with open(KNAPSACK) as file:
        data = json.load(file)
    named = ontime.reduce_knapsack(data, name=KNAPSACK.stem)
    assert json.loads(named.to_json()) == expected
    assert named.skeleton_count == len(data["items"])
    with pytest.raises(ontime.InputError, match="capacity"):
        ontime.reduce_knapsack({"items": []})


def test_sample_log_writes_the_cli_log_byte_for_byte(cli, tmp_path):
    instance = PAPER_INSTANCES[0]
    done = cli("sample-log", instance, "--attempts", 300, "--seed", 5, "--cutoff", 12, "-o", tmp_path / "cli.jsonl",
               expect_json=False)
    assert done.returncode == 0, done.stderr
    records = ontime.sample_log(str(instance), tmp_path / "py.jsonl", attempts=300, seed=5, cutoff=12)
    cli_bytes = (tmp_path / "cli.jsonl").read_bytes()
    assert (tmp_path / "py.jsonl").read_bytes() == cli_bytes
    assert records == cli_bytes.count(b"\n") == 300 * len(ontime.load_problem(instance).actions)
    assert f"Wrote {records} records" in done.stdout
    with pytest.raises(ontime.UsageError, match="attempts"):
        ontime.sample_log(str(instance), tmp_path / "none.jsonl", attempts=0)


def test_train_ppo_writes_the_cli_policy_and_curve(cli, tmp_path):
    instance = PAPER_INSTANCES[3]
    out = cli("train", instance, "--solver", "ppo", "--episodes", 400, "--seed", 2, "--out", tmp_path / "cli.json",
              "--no-plot", "--json")
    curve = ontime.train_ppo(str(instance), tmp_path / "py.json", episodes=400, seed=2)
    assert (tmp_path / "py.json").read_bytes() == (tmp_path / "cli.json").read_bytes()
    assert out["epochs"] == len(curve)
    rows = {}
    for name in ("cli", "py"):
        with open(tmp_path / f"{name}.curve.csv") as file:
            rows[name] = [{k: v for k, v in row.items() if k != "seconds"} for row in csv.DictReader(file)]
    assert rows["py"] == rows["cli"] and len(rows["py"]) == len(curve)
    assert [int(row["episodes"]) for row in rows["py"]] == [point["episodes"] for point in curve]
    # The exact value the command line reports is the trained policy's.
    exact = ontime.evaluate(str(instance), "ppo", policy=str(tmp_path / "py.json"), episodes=10, exact=True)
    assert exact["exact_success_probability"] == out["exact_success_probability"]


def test_studies_give_the_cli_counts(cli, tmp_path):
    instance = PAPER_INSTANCES[0]
    done = cli("study", "compute-time", instance, "--episodes", 60, "--seed", 4, "--iterations", 30, "--out",
               tmp_path, "--no-plot", expect_json=False)
    assert done.returncode == 0, done.stderr
    text = ontime.study("compute-time", [str(instance)], episodes=60, seed=4, iterations=30)
    with open(tmp_path / "compute_time.csv") as file:
        expected = list(csv.DictReader(file))
    got = list(csv.DictReader(io.StringIO(text)))
    assert [row["solver"] for row in got] == [row["solver"] for row in expected] == ["mcts", "dp-rerun"]
    for mine, theirs in zip(got, expected):
        for key in ("instance", "episodes", "success_rate", "ci95", "iterations_per_search"):
            assert mine[key] == theirs[key], key
    # mcts with 30 iterations per decision: 30 iterations per search, exactly.
    assert float(got[0]["iterations_per_search"]) == 30
    with pytest.raises(ontime.UsageError, match="unknown study 'nope'"):
        ontime.study("nope", [str(instance)])
    with pytest.raises(ontime.UsageError, match="searcher of a study must be an anytime allocator"):
        ontime.study("equal-time", [str(instance)], searcher="dp")


def test_studies_acting_while_planning_give_the_cli_counts(cli, tmp_path):
    instance = PAPER_INSTANCES[3]
    done = cli("study", "compute-time", instance, "--act", "concurrent", "--episodes", 60, "--seed", 4,
               "--iterations", 30, "--out", tmp_path, "--no-plot", expect_json=False)
    assert done.returncode == 0, done.stderr
    problem = ontime.load_problem(instance).with_acting("concurrent")
    text = ontime.study("compute-time", [problem], episodes=60, seed=4, iterations=30)
    with open(tmp_path / "compute_time.csv") as file:
        expected = list(csv.DictReader(file))
    got = list(csv.DictReader(io.StringIO(text)))
    for mine, theirs in zip(got, expected):
        for key in ("episodes", "success_rate", "ci95", "iterations_per_search"):
            assert mine[key] == theirs[key], key
    assert float(got[0]["iterations_per_search"]) == 30
    with pytest.raises(ontime.UsageError, match="ppo needs a trained policy"):
        ontime.study("compute-time", [problem], reference="ppo", episodes=2)


def test_histogram_csv_is_the_data_of_the_cli_plot(cli, tmp_path):
    instance = PAPER_INSTANCES[1]
    done = cli("plot", instance, "-o", tmp_path / "h.png", expect_json=False)
    assert done.returncode == 0, done.stderr
    text = ontime.histogram_csv(str(instance))
    assert (tmp_path / "h.csv").read_text() == text
    problem = ontime.load_problem(instance)
    rows = list(csv.DictReader(io.StringIO(text)))
    never = [row for row in rows if row["step"] == "never"]
    assert len(never) == 2 * len(problem.actions)
    # Each distribution's masses and "never" add up to one.
    for action in problem.actions:
        for kind in ("planning", "execution"):
            total = sum(float(row["probability"]) for row in rows
                        if row["action"] == action.id and row["distribution"] == kind)
            assert total == pytest.approx(1.0, abs=1e-12)


def test_solve_writes_the_cli_policy(cli, tmp_path):
    instance = PAPER_INSTANCES[0]
    cli("solve", instance, "--policy", tmp_path / "cli.jsonl", "--policy-layers", 3, "--json")
    got = ontime.solve(str(instance), policy=tmp_path / "py.jsonl", policy_layers=3)
    assert (tmp_path / "py.jsonl").read_bytes() == (tmp_path / "cli.jsonl").read_bytes()
    lines = [json.loads(line) for line in (tmp_path / "py.jsonl").read_text().splitlines()]
    assert {line["time"] for line in lines} == {0, 1, 2}
    start = next(line for line in lines if line["time"] == 0)
    assert start["choice"] == got["first_choice"]
    assert start["lower_bound"] == start["upper_bound"] == got["optimal_success_probability"]
