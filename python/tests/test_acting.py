"""Acting while planning (SPEC §10) from Python: the instance's mode, the exact optimum of the model
with `act=`, the same figures as the command line, and what does not take the mode yet."""

import json

import pytest

import ontime
from conftest import PAPER


def test_the_mode_is_the_instances_and_travels_with_its_copies():
    problem = ontime.load_problem(PAPER / "instance1.json")
    assert problem.acting == "plan-first"
    concurrent = problem.with_acting("concurrent")
    assert concurrent.acting == "concurrent"
    assert json.loads(concurrent.to_json())["acting"] == "concurrent"
    assert "acting" not in json.loads(problem.to_json())
    assert ontime.Problem.from_json(concurrent.to_json()).acting == "concurrent"


def test_the_optimum_of_acting_while_planning():
    problem = ontime.load_problem(PAPER / "instance1.json")
    plan_first = ontime.solve(problem, method="memoised")
    concurrent = ontime.solve(problem, act="concurrent")
    assert plan_first["optimal_success_probability"] == pytest.approx(0.942, abs=1e-12)
    assert concurrent["acting"] == "concurrent"
    assert concurrent["method"] == "memoised"
    assert concurrent["optimal_success_probability"] == pytest.approx(1.0, abs=1e-12)
    # The instance's own mode, and act= over it.
    marked = problem.with_acting("concurrent")
    assert ontime.solve(marked)["optimal_success_probability"] == concurrent["optimal_success_probability"]
    assert ontime.solve(marked, act="plan-first", method="memoised")["optimal_success_probability"] == \
        plan_first["optimal_success_probability"]
    # Fig. 1 and instance 4 gain nothing from acting while planning.
    for name in ("figure1", "instance4"):
        instance = PAPER / f"{name}.json"
        assert ontime.solve(instance, act="concurrent")["optimal_success_probability"] == pytest.approx(
            ontime.solve(instance, method="memoised")["optimal_success_probability"], abs=1e-12)


def test_the_same_figures_as_the_command_line(cli):
    instance = PAPER / "instance2.json"
    from_cli = cli("solve", str(instance), "--act", "concurrent", "--json", "--no-timing")
    from_python = ontime.solve(str(instance), act="concurrent")
    assert from_python["optimal_success_probability"] == from_cli["optimal_success_probability"]
    assert from_python["states"] == from_cli["states"]
    assert from_python["first_choice"] == from_cli["first_choice"]


@pytest.mark.parametrize("arguments, message", [
    ({"act": "interleaved"}, "act must be 'plan-first' or 'concurrent'"),
    ({"act": 1}, "act must be 'plan-first' or 'concurrent'"),
    ({"act": "concurrent", "method": "layered"}, "method='memoised' only"),
    ({"act": "concurrent", "tolerance": 0.1}, "do not solve acting while planning"),
])
def test_bad_requests_raise_usage_errors(arguments, message):
    with pytest.raises(ontime.UsageError, match=message):
        ontime.solve(PAPER / "instance1.json", **arguments)


def test_evaluate_acts_while_planning_by_the_allocators_commit_rule(cli):
    instance = PAPER / "instance2.json"
    result = ontime.evaluate(instance, "round-robin", act="concurrent", episodes=4000, seed=5, exact=True)
    assert result["acting"] == "concurrent"
    assert result["commit_rule"].startswith("eager")
    assert result["exact_success_probability"] == pytest.approx(0.58, abs=1e-12)
    # The same counts as the command line, and from the problem's own mode.
    from_cli = cli("evaluate", str(instance), "--act", "concurrent", "--solver", "round-robin", "--episodes", "4000",
                   "--seed", "5", "--exact", "--json", "--no-timing")
    assert result["successes"] == from_cli["successes"]
    marked = ontime.load_problem(instance).with_acting("concurrent")
    assert ontime.evaluate(marked, "round-robin", episodes=4000, seed=5)["successes"] == result["successes"]
    # The optimum is certain on instance 1 (0.942 plan-first).
    first = ontime.evaluate(PAPER / "instance1.json", "optimal", act="concurrent", episodes=500, exact=True)
    assert first["successes"] == 500
    assert first["exact_success_probability"] == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize("arguments, message", [
    ({"solver": "mcts"}, "'mcts' does not act while planning"),
    ({"solver": "dp-rerun", "regret": True}, "regret: acting while planning"),
    ({"solver": "dp-rerun", "belief": PAPER / "instance1.json"}, "belief: acting while planning"),
    ({"solver": "thompson", "exact": True}, "exact evaluation needs an allocator whose move"),
    ({"solver": "dp-rerun", "act": "sometimes"}, "act must be 'plan-first' or 'concurrent'"),
])
def test_evaluate_refuses_what_acting_while_planning_does_not_take_yet(arguments, message):
    arguments = {"act": "concurrent", **arguments}
    solver = arguments.pop("solver")
    with pytest.raises(ontime.UsageError, match=message):
        ontime.evaluate(PAPER / "instance1.json", solver, episodes=10, **arguments)


def test_what_does_not_take_the_mode_yet_refuses_it():
    concurrent = ontime.load_problem(PAPER / "instance1.json").with_acting("concurrent")
    with pytest.raises(ontime.UsageError, match="acts while planning"):
        ontime.make_allocator(concurrent, "dp-rerun")
    with pytest.raises(ontime.UsageError, match="acting must be"):
        concurrent.with_acting(None)
