"""Live sessions from Python: the robot's clock charged, skeletons that arrive and leave."""

import math

import pytest

import ontime
from conftest import PAPER

UNIFORM_1_TO_15 = {"pmf": {str(t): 1.0 / 15 for t in range(1, 16)}}
ONE_STEP = {"pmf": {"1": 1.0}}


def two_actions(deadline=20, step=1.0):
    return ontime.Problem.from_dict({
        "name": "two", "deadline": deadline, "step_seconds": step,
        "actions": {"a": {"planning": UNIFORM_1_TO_15, "execution": ONE_STEP},
                    "b": {"planning": UNIFORM_1_TO_15, "execution": ONE_STEP}},
        "skeletons": [["a", "b"]],
    })


def test_an_overrun_of_two_and_a_half_slices_costs_three_steps():
    clock = ontime.ManualClock()
    session = ontime.LiveSession(two_actions(), "dp-rerun", clock=clock)
    decision = session.choose()
    assert decision.action_id == "a"
    clock.advance(3.5)
    assert session.report_not_yet() == ontime.Status.running
    assert session.steps_used == 4
    assert session.state.spent == [3]
    step = session.timeline[0]
    assert step["overrun_seconds"] == pytest.approx(2.5)
    assert step["planning_seconds"] == pytest.approx(3.5)
    assert step["steps_charged"] == 4
    assert session.totals["planning"] == pytest.approx(3.5)
    assert session.elapsed_seconds == pytest.approx(3.5)


@pytest.mark.parametrize("planning, execution, status", [
    (1.0, 9.0, ontime.Status.success),
    (1.0, 9.2, ontime.Status.failure),
    (0.5, 9.4, ontime.Status.success),
    (1.0, math.inf, ontime.Status.failure),
])
def test_success_needs_the_execution_seconds_to_fit(planning, execution, status):
    problem = ontime.Problem.from_dict({
        "deadline": 10, "step_seconds": 1.0,
        "actions": {"a": {"planning": ONE_STEP, "execution": {"pmf": {"2": 1.0}}}},
        "skeletons": [["a"]],
    })
    clock = ontime.ManualClock()
    session = ontime.LiveSession(problem, "greedy", clock=clock)
    session.choose()
    clock.advance(planning)
    assert session.report_refined_seconds(execution) == status
    assert session.solution == (0 if status == ontime.Status.success else None)


def test_time_away_and_charged_time_count_against_the_deadline():
    clock = ontime.ManualClock(100.0)
    session = ontime.LiveSession(two_actions(deadline=10), "dp-rerun", clock=clock)
    session.choose()
    clock.advance(1.0)
    session.report_not_yet()
    clock.advance(2.5)
    session.charge_outside(1.0)
    assert session.elapsed_seconds == pytest.approx(4.5)
    session.choose()
    assert session.state.time == 5
    assert session.totals["outside"] == pytest.approx(3.5)
    clock.advance(20.0)
    session.report_not_yet()
    assert session.status == ontime.Status.failure
    with pytest.raises(ontime.UsageError):
        session.choose()


def test_skeletons_arrive_and_leave():
    full = ontime.load_problem(PAPER / "instance1.json")
    data = full.to_dict()
    data["skeletons"] = full.skeletons[:2]
    clock = ontime.ManualClock()
    session = ontime.LiveSession(ontime.Problem.from_dict(data), "dp-rerun", clock=clock, seed=1)
    decision = session.choose()
    clock.advance(full.step_seconds)
    session.report_refined_seconds(full.step_seconds)
    first = decision.action_id
    assert session.add_skeleton(full.skeletons[2]) == 2
    assert session.problem.skeleton_count == 3
    # A new action behind a refined one: the new skeleton starts with that one refined.
    detour = ontime.Problem.from_dict({
        "deadline": full.deadline, "step_seconds": full.step_seconds,
        "actions": {"detour": {"planning": UNIFORM_1_TO_15, "execution": ONE_STEP}},
        "skeletons": [["detour"]],
    }).actions
    index = session.add_skeleton([first, "detour"], detour)
    assert index == 3
    assert session.state.refined[3] == 1
    session.retire_skeleton(0)
    assert session.problem.skeleton_count == 3
    assert session.problem.skeletons[2] == [first, "detour"]
    with pytest.raises(ontime.UsageError):
        session.add_skeleton(["no-such-action"])
    assert session.problem.skeleton_count == 3


def test_the_steady_clock_is_the_default_and_bad_clocks_are_refused():
    session = ontime.LiveSession(two_actions(), "dp-rerun")
    session.choose()
    session.report_not_yet()
    assert 0.0 < session.elapsed_seconds < 5.0
    assert session.deadline_seconds == pytest.approx(20.0)
    with pytest.raises(ontime.UsageError):
        ontime.LiveSession(two_actions(), "dp-rerun", clock=object())
    with pytest.raises(ontime.UsageError):
        ontime.LiveSession(two_actions(), "dp-rerun", decision_share=0.0)


def test_many_skeletons_are_sampled_and_refused_by_the_exact_solver():
    data = {"deadline": 40, "step_seconds": 1.0, "actions": {}, "skeletons": []}
    for k in range(40):
        data["actions"][f"x{k}"] = {"planning": UNIFORM_1_TO_15, "execution": ONE_STEP}
        data["skeletons"].append([f"x{k}"])
    problem = ontime.Problem.from_dict(data)
    result = ontime.evaluate(problem, "dp-rerun", episodes=500, seed=1)
    assert result["episodes"] == 500
    assert result["successes"] > 0
    with pytest.raises(ontime.UsageError, match="at most 16"):
        ontime.solve(problem)
