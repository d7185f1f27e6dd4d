"""Scoring distributions on planner logs (ontime.score) and evaluating an allocator that plans with
other distributions than the world's (ontime.evaluate(belief=...)): the command line's numbers."""

import json
import math

import pytest

import ontime

INSTANCE = {
    "name": "one",
    "deadline": 3,
    "actions": {"a": {"planning": {"pmf": {"1": 0.6, "2": 0.2}}, "execution": {"pmf": {"0": 0.5, "1": 0.5}}}},
    "skeletons": [["a"]],
}
LOG = [
    {"action": "a", "planning_seconds": 1, "found": True, "execution_seconds": 1},
    {"action": "a", "planning_seconds": 2, "found": True, "execution_seconds": 0},
    {"action": "a", "planning_seconds": 1.5, "found": False},
    {"action": "a", "planning_seconds": 5, "found": True, "execution_seconds": 0.5},
]


@pytest.fixture()
def files(tmp_path):
    instance = tmp_path / "one.json"
    instance.write_text(json.dumps(INSTANCE))
    log = tmp_path / "log.jsonl"
    log.write_text("".join(json.dumps(record) + "\n" for record in LOG))
    return instance, log


def misleading_belief(source_dir, folder):
    """Instance 4 and a belief that swaps the planning times of its two skeletons' first actions."""
    truth = source_dir / "data/instances/paper/instance4.json"
    data = json.loads(truth.read_text())
    data["actions"]["a1_1"]["planning"], data["actions"]["a2_1"]["planning"] = (
        data["actions"]["a2_1"]["planning"], data["actions"]["a1_1"]["planning"])
    belief = folder / "belief.json"
    belief.write_text(json.dumps(data))
    return truth, belief


def test_score_gives_the_hand_computed_values_and_the_clis_fields(files, cli):
    instance, log = files
    scores = ontime.score(instance, [log])
    assert scores["attempts"] == 4 and scores["found"] == 2 and scores["censored"] == 2
    assert scores["planning_nll"] == pytest.approx(
        -(math.log(0.6) + math.log(0.2) + math.log(0.4) + math.log(0.2)) / 4, abs=1e-15)
    assert scores["integrated_brier"] == pytest.approx(0.28, abs=1e-15)
    assert scores == cli("score", instance, log, "--json")
    with pytest.raises(ontime.UsageError):
        ontime.score(instance, [log], horizon=4)


def test_evaluate_with_a_belief_matches_the_command_line(source_dir, tmp_path, cli):
    truth, belief = misleading_belief(source_dir, tmp_path)
    believing = ontime.evaluate(str(truth), "dp-rerun", episodes=300, exact=True, belief=str(belief))
    plain = ontime.evaluate(str(truth), "dp-rerun", episodes=300, exact=True)
    assert believing["exact_success_probability"] < plain["exact_success_probability"]
    assert believing["belief"] == str(belief)
    out = cli("evaluate", truth, "--belief", belief, "--solver", "dp-rerun", "--episodes", 300, "--exact", "--json")
    assert out["exact_success_probability"] == believing["exact_success_probability"]
    assert out["successes"] == believing["successes"]


def test_adapt_and_fit_strength_match_the_command_line(source_dir, tmp_path, cli):
    truth, prior = misleading_belief(source_dir, tmp_path)
    adapted = ontime.adapt(str(truth), str(prior), "dp-rerun", strength=2, episodes=4, sequences=30)
    out = cli("adapt", truth, "--belief", prior, "--solver", "dp-rerun", "--strength", 2, "--episodes", 4,
              "--sequences", 30, "--json")
    assert adapted == out
    assert adapted["exact_success_probability"][-1] > adapted["exact_success_probability"][0]

    def record(planning, found, world):
        line = {"action": "a", "planning_seconds": planning, "found": found, "world": world, "features": [0]}
        if found:
            line["execution_seconds"] = 1
        return json.dumps(line) + "\n"

    train = tmp_path / "train.jsonl"
    train.write_text(record(1, True, "t") + record(2, True, "t") + record(2, False, "t") + record(1, True, "t"))
    unseen = tmp_path / "unseen.jsonl"
    unseen.write_text(record(1, True, "v") + record(1, False, "v"))
    model = ontime.fit_conditional([train], step=1.0, kind="pooled")
    scores = ontime.fit_strength(model, [unseen], strengths=[1.0, 3.0])
    assert scores["best"] == 3.0
    for score in scores["scores"]:
        s = score["strength"]
        assert score["nll"] == pytest.approx(-(math.log(0.5) + math.log(s / 2 / (s + 1))) / 2, abs=1e-14)
    with pytest.raises(ontime.UsageError):
        ontime.fit_strength(model, [unseen], strengths=[0.0])
