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


def test_what_does_not_take_the_mode_yet_refuses_it():
    concurrent = ontime.load_problem(PAPER / "instance1.json").with_acting("concurrent")
    with pytest.raises(ontime.UsageError, match="acts while planning"):
        ontime.evaluate(concurrent, "dp-rerun", episodes=10)
    with pytest.raises(ontime.UsageError, match="acts while planning"):
        ontime.make_allocator(concurrent, "dp-rerun")
    with pytest.raises(ontime.UsageError, match="acting must be"):
        concurrent.with_acting(None)
