"""The module gives the command line's numbers: exact values to 1e-12, identical Monte Carlo counts
for the same seed, the same fields, the same registry."""

import pytest

import ontime
from conftest import PAPER_INSTANCES

EXACT_SOLVERS = ["dp", "dp-rerun", "greedy", "round-robin"]


@pytest.mark.parametrize("path", PAPER_INSTANCES, ids=lambda p: p.stem)
def test_solve_matches_the_cli(path, cli):
    expected = cli("solve", path, "--json")
    got = ontime.solve(str(path))
    assert set(got) == set(expected)
    assert got["optimal_success_probability"] == pytest.approx(expected["optimal_success_probability"], abs=1e-12)
    for key in ("instance", "name", "states", "first_choice", "first_action"):
        assert got[key] == expected[key]


@pytest.mark.parametrize("path", PAPER_INSTANCES, ids=lambda p: p.stem)
def test_the_search_matches_the_cli_and_the_layered_bits(path, cli):
    expected = cli("solve", path, "--json", "--method", "search", "--no-timing")
    got = ontime.solve(str(path), method="search")
    assert set(got) == set(expected) | {"seconds"}
    for key in ("optimal_success_probability", "states", "upper_tests", "first_choice", "first_action"):
        assert got[key] == expected[key]
    assert got["optimal_success_probability"] == ontime.solve(str(path))["optimal_success_probability"]
    capped = ontime.solve(str(path), method="search", max_states=1)
    assert capped["lower_bound"] <= got["optimal_success_probability"] <= capped["upper_bound"]
    narrow = ontime.solve(str(path), method="search", gap=0.001)
    expected_narrow = cli("solve", path, "--json", "--method", "search", "--gap", 0.001, "--no-timing")
    if not narrow["exact"]:
        assert narrow["stopped_by"] == "the gap"
        assert narrow["upper_bound"] - narrow["lower_bound"] <= 0.001
    for key in ("lower_bound", "upper_bound", "first_choice", "refined_states"):
        assert narrow[key] == expected_narrow[key]
    with pytest.raises(ontime.UsageError, match="gap is for method='search'"):
        ontime.solve(str(path), gap=0.001)


@pytest.mark.parametrize("path", PAPER_INSTANCES, ids=lambda p: p.stem)
@pytest.mark.parametrize("solver", EXACT_SOLVERS)
def test_exact_evaluation_matches_the_cli(path, solver, cli):
    expected = cli("evaluate", path, "--solver", solver, "--episodes", 2000, "--seed", 7, "--exact", "--json")
    got = ontime.evaluate(str(path), solver, episodes=2000, seed=7, exact=True)
    assert got["exact_success_probability"] == pytest.approx(expected["exact_success_probability"], abs=1e-12)
    assert got["exact_states"] == expected["exact_states"]
    assert got["successes"] == expected["successes"]


@pytest.mark.parametrize("solver,params,flags", [
    ("mcts", {"iterations": 300}, ["--iterations", 300]),
    ("thompson", {}, []),
    ("dp-rerun", {"aggregation": "max"}, ["--aggregation", "max"]),
])
def test_monte_carlo_counts_match_the_cli_for_the_same_seed(solver, params, flags, cli):
    path = PAPER_INSTANCES[1]
    expected = cli("evaluate", path, "--solver", solver, "--episodes", 3000, "--seed", 11, "--threads", 2, *flags,
                   "--json")
    got = ontime.evaluate(str(path), solver, episodes=3000, seed=11, threads=1, **params)
    # Every field of the CLI's JSON is there; the counts are identical (other thread count too).
    assert set(expected) <= set(got)
    for key in ("solver", "parameters", "instance", "episodes", "seed", "successes", "success_rate", "ci95"):
        assert got[key] == expected[key], key
    assert set(got["decision_time_us"]) == set(expected["decision_time_us"])
    assert got["decision_time_us"]["decisions"] == expected["decision_time_us"]["decisions"]


def test_the_regret_estimate_matches_the_cli(cli):
    # dp-rerun on instance 1 (V* - V about 0.002): the estimate's bits are the CLI's
    # (fixed point: whatever the thread counts).
    path = PAPER_INSTANCES[0]
    expected = cli("evaluate", path, "--solver", "dp-rerun", "--episodes", 2000, "--seed", 5, "--threads", 2,
                   "--regret", "--json")
    got = ontime.evaluate(str(path), "dp-rerun", episodes=2000, seed=5, threads=1, regret=True)
    assert got["regret"] == expected["regret"]
    assert got["regret"]["optimum"] == ontime.solve(str(path))["optimal_success_probability"]
    exact = ontime.evaluate(str(path), "dp-rerun", episodes=1, exact=True)["exact_success_probability"]
    truth = got["regret"]["optimum"] - exact
    assert abs(got["regret"]["mean"] - truth) <= 2 * got["regret"]["ci95"]
    assert got["regret"]["ci95"] < got["ci95"]
    assert "regret" not in ontime.evaluate(str(path), "dp-rerun", episodes=10)


def test_the_registry_is_listed_as_the_cli_lists_it(cli):
    assert ontime.allocators() == cli("allocators", "--json")


def test_table_one_optimum_values():
    # The paper's Table I instances: the exact optimum OnTime reports (docs/experiments.md).
    values = [ontime.solve(str(p))["optimal_success_probability"] for p in PAPER_INSTANCES]
    assert [round(v, 4) for v in values] == [0.9420, 0.7200, 0.6763, 0.9000, 0.6992]


def test_parameters_as_keywords_reach_the_allocator():
    problem = ontime.load_problem(PAPER_INSTANCES[0])
    mcts = ontime.make_allocator(problem, "mcts", iterations=123, exploration=0.25)
    assert mcts.parameters["iterations"] == "123"
    assert mcts.parameters["exploration"] == "0.25"
    mcts.begin_episode(3)
    mcts.choose(ontime.Mdp(problem).start())
    assert mcts.statistics()["iterations"] == 123
    with pytest.raises(ontime.UsageError, match="unknown allocator 'nope'"):
        ontime.make_allocator(problem, "nope")
    with pytest.raises(ontime.UsageError, match="exploration"):
        ontime.make_allocator(problem, "mcts", exploration=-1.0)
    with pytest.raises(ontime.UsageError, match="allocator parameter 'colour'"):
        ontime.make_allocator(problem, "mcts", colour="red")


def test_a_non_stationary_allocator_has_no_exact_value():
    with pytest.raises(ontime.UsageError, match="does not"):
        ontime.evaluate(str(PAPER_INSTANCES[0]), "mcts", episodes=10, exact=True, iterations=10)


def test_a_state_cap_gives_the_clis_certified_interval(cli):
    path = PAPER_INSTANCES[0]  # instance 1: 872 states
    got = ontime.solve(str(path), max_states=100)
    expected = cli("solve", path, "--max-states", 100, "--json")
    assert got["exact"] is False and got["optimal_success_probability"] is None
    assert "cap of 100 states" in got["stopped_by"]
    assert got["lower_bound"] == expected["lower_bound"] and got["upper_bound"] == expected["upper_bound"]
    assert got["lower_bound"] <= ontime.solve(str(path))["optimal_success_probability"] <= got["upper_bound"]


@pytest.mark.parametrize("path", [PAPER_INSTANCES[0], PAPER_INSTANCES[2]], ids=lambda p: p.stem)
def test_a_split_and_a_tolerance_give_the_clis_interval(path, cli):
    optimum = ontime.solve(str(path))["optimal_success_probability"]
    got = ontime.solve(str(path), method="split", tolerance=0.01)
    expected = cli("solve", path, "--method", "split", "--tolerance", 0.01, "--json")
    assert set(got) == set(expected)
    assert got["lower_bound"] == expected["lower_bound"] and got["upper_bound"] == expected["upper_bound"]
    assert got["split"]["enumerated_skeletons"] == expected["split"]["enumerated_skeletons"]
    assert got["dropped"] == expected["dropped"]
    assert got["lower_bound"] <= optimum + 1e-12 and optimum - 1e-12 <= got["upper_bound"]


def test_table_matches_the_cli(cli):
    # The same computation (run/table.hpp) and the same report: every number but the timings.
    paths = [str(p) for p in PAPER_INSTANCES[:2]]
    expected = cli("table", *paths, "--solvers", "dp,greedy,mcts", "--iterations", 40, "--episodes", 400, "--seed", 3,
                   "--exact", "--json")
    got = ontime.table(paths, solvers=["dp", "greedy", "mcts"], iterations=40, episodes=400, seed=3, exact=True)
    assert got["solvers"] == expected["solvers"] == ["dp", "greedy", "mcts"]
    assert (got["episodes"], got["seed"]) == (400, 3)
    assert len(got["rows"]) == len(expected["rows"]) == 2
    for mine, theirs in zip(got["rows"], expected["rows"]):
        assert mine["instance"] == theirs["instance"] and mine["name"] == theirs["name"]
        assert mine["optimal_success_probability"] == theirs["optimal_success_probability"]
        assert mine["optimal_states"] == theirs["optimal_states"]
        for solver in ("dp", "greedy", "mcts"):
            for key in ("success_rate", "ci95"):
                assert mine["solvers"][solver][key] == theirs["solvers"][solver][key], (solver, key)
        for solver in ("dp", "greedy"):
            assert mine["solvers"][solver]["exact_success_probability"] == \
                theirs["solvers"][solver]["exact_success_probability"]
        assert "exact" not in mine["solvers"]["mcts"]
    # instance1's exact values (docs/experiments.md): dp 0.9340, greedy 0.9200, optimum 0.9420.
    first = got["rows"][0]
    assert round(first["solvers"]["dp"]["exact_success_probability"], 4) == 0.9340
    assert round(first["solvers"]["greedy"]["exact_success_probability"], 4) == 0.9200
    assert round(first["optimal_success_probability"], 4) == 0.9420


def test_table_takes_problems_one_parameter_per_instance_and_prints_markdown():
    problems = [ontime.load_problem(p) for p in PAPER_INSTANCES[:2]]
    text = ontime.table(problems, solvers=["mcts", "dp"], iterations=[20, 30], episodes=50, seed=1, format="markdown")
    lines = text.splitlines()
    assert lines[0].startswith("Success probability: mean ± 95% over 50 episodes (seed 1)")
    assert lines[2].split("|")[1].strip() == "instance" and "mcts" in lines[2] and "dp" in lines[2]
    # Rows labelled by the problems' own names.
    assert problems[0].name in lines[4] and problems[1].name in lines[5]
    with pytest.raises(ontime.UsageError, match="parameter 'iterations': 3 values for 2 instances"):
        ontime.table(problems, solvers=["mcts"], iterations=[1, 2, 3], episodes=5)
    with pytest.raises(ontime.UsageError, match="solvers: 'dp' is given twice"):
        ontime.table(problems, solvers=["dp", "dp"], episodes=5)
    with pytest.raises(ontime.UsageError, match="unknown solver 'nope'"):
        ontime.table(problems, solvers=["nope"], episodes=5)
