"""The online update in Python: an OnlineBelief learns from what a session saw (Session.attempts,
LiveSession.attempts) and a live session plans with what it believes (revise_distributions), with
the numbers of the C++ posterior (PlanningPosterior)."""

import pytest

import ontime
from conftest import SOURCE_DIR

BACKTRACKING_EXAMPLES = [SOURCE_DIR / "data" / "instances" / name for name in (
    "backtracking/grasp-and-place.json", "kitchen-grasps.json", "chains/cup-through-the-door.json")]

LIBRARY = {
    "name": "library",
    "deadline": 4,
    "actions": {
        "a": {"planning": {"pmf": {"1": 0.5, "2": 0.25}}, "execution": {"pmf": {"0": 1.0}}},
        "b": {"planning": {"pmf": {"1": 1.0}}, "execution": {"pmf": {"0": 1.0}}},
    },
    "skeletons": [["a"], ["b"]],
}
EPISODE = {
    "name": "episode",
    "deadline": 4,
    "actions": {
        "a": {"planning": {"pmf": {"1": 1.0}}, "execution": {"pmf": {"0": 1.0}}},
        "b": {"planning": {"pmf": {"1": 1.0}}, "execution": {"pmf": {"0": 1.0}}},
        "a#2": {"planning": {"pmf": {"1": 1.0}}, "execution": {"pmf": {"0": 1.0}}},
    },
    "skeletons": [["a"], ["b", "a#2"]],
}


def pmf(distribution, horizon):
    """The masses of steps 1..horizon."""
    masses = list(distribution.pmf) + [0.0] * (horizon + 1)
    return [float(mass) for mass in masses[1:horizon + 1]]


def test_a_node_and_its_base_learn_one_posterior_as_planning_posterior_computes_it():
    library = ontime.Problem.from_dict(LIBRARY)
    belief = ontime.OnlineBelief(library, strength=2.0)
    assert pmf(belief.planning("a"), 2) == [0.5, 0.25] and belief.observations == 0
    belief.observe("a#2", effort=2, found=True)
    belief.observe("a", effort=1, found=False)
    posterior = ontime.PlanningPosterior(library.actions[0].planning, 4, 2.0)
    posterior.observe_found(2)
    posterior.observe_cut_off(1)
    assert pmf(belief.planning("a"), 2) == pmf(posterior.mean(), 2) == [0.25, 9 / 16]
    assert pmf(belief.planning("b"), 2) == [1.0, 0.0]
    applied = belief.believed_for(ontime.Problem.from_dict(EPISODE))
    assert pmf(applied.actions[2].planning, 2) == [0.25, 9 / 16]
    assert belief.observations == 2 and belief.strength == 2.0
    with pytest.raises(ontime.UsageError, match="no action 'c'"):
        belief.observe("c", effort=1, found=True)
    with pytest.raises(ontime.UsageError, match="strength"):
        ontime.OnlineBelief(library, strength=0)


def test_a_session_records_each_actions_attempt_and_the_belief_learns_from_it():
    episode = ontime.Problem.from_dict(EPISODE)
    session = ontime.Session(ontime.make_allocator(episode, "greedy"), seed=1)
    while session.status == ontime.Status.running:
        session.choose()
        session.report_refined(0)
    attempts = session.attempts
    assert len(attempts) == 3 and session.problem.name == "episode"
    assert sum(a.effort for a in attempts) == session.steps_used
    assert all(a.found for a in attempts if a.effort > 0)
    belief = ontime.OnlineBelief(ontime.Problem.from_dict(LIBRARY), strength=2.0)
    belief.observe(session.problem, attempts)
    assert belief.observations == sum(1 for a in attempts if a.effort > 0)


def test_a_live_session_counts_slices_and_plans_with_revised_distributions():
    clock = ontime.ManualClock()
    episode = ontime.Problem.from_dict(EPISODE)
    session = ontime.LiveSession(episode, "dp-rerun", clock=clock)
    decision = session.choose()
    clock.advance(1.5)  # one slice and a half: one step of effort
    session.report_not_yet()
    attempt = session.attempts[decision.action]
    assert (attempt.effort, attempt.found) == (1, False)
    belief = ontime.OnlineBelief(ontime.Problem.from_dict(LIBRARY), strength=2.0)
    belief.observe(session.problem, session.attempts)
    session.revise_distributions(belief.believed())
    for action in session.problem.actions:
        expected = belief.planning(action.id)
        assert pmf(action.planning, 2) == pmf(expected, 2)
    assert session.status == ontime.Status.running
    with pytest.raises(ontime.UsageError, match="no distributions for the action"):
        session.revise_distributions(ontime.Problem.from_dict({**LIBRARY, "actions": {"b": LIBRARY["actions"]["b"]},
                                                               "skeletons": [["b"]]}))


def test_planning_and_backtracking_learn_together_as_the_algebra_says():
    # Planning p = (1/4, 1/4), backtrack q = (1/4, 1/8), strength 4 (tests/learn/online_update_test.cpp):
    # without data the prior; a backtrack at 2 gives p = (1/5, 1/5), q = (1/5, 3/10); found at 1 then
    # p = (1/3, 1/6), q = (1/6, 1/4); cut off after 1 then p = (2/7, 4/21), q = (1/7, 2/7).
    planning = ontime.Distribution.from_pmf([0.0, 0.25, 0.25])
    backtrack = ontime.Distribution.from_pmf([0.0, 0.25, 0.125])
    posterior = ontime.PlanningPosterior(planning, 2, 4.0, backtrack=backtrack)
    assert pmf(posterior.mean(), 2) == pytest.approx([0.25, 0.25], abs=1e-12)
    assert pmf(posterior.backtrack_mean(), 2) == pytest.approx([0.25, 0.125], abs=1e-12)
    posterior.observe_backtrack(2)
    assert pmf(posterior.mean(), 2) == pytest.approx([1 / 5, 1 / 5], abs=1e-15)
    assert pmf(posterior.backtrack_mean(), 2) == pytest.approx([1 / 5, 3 / 10], abs=1e-15)
    posterior.observe_found(1)
    assert pmf(posterior.mean(), 2) == pytest.approx([1 / 3, 1 / 6], abs=1e-15)
    assert pmf(posterior.backtrack_mean(), 2) == pytest.approx([1 / 6, 1 / 4], abs=1e-15)
    posterior.observe_cut_off(1)
    assert pmf(posterior.mean(), 2) == pytest.approx([2 / 7, 4 / 21], abs=1e-15)
    assert pmf(posterior.backtrack_mean(), 2) == pytest.approx([1 / 7, 2 / 7], abs=1e-15)
    assert posterior.predictive_backtrack(2) == pytest.approx(2 / 7, abs=1e-15)
    assert posterior.observations == 3


def test_a_session_records_the_attempts_a_backtrack_ended_and_the_belief_learns_them():
    # grasp-and-place with round-robin (tests/test_backtracking.py): pick(A) found after 1 step,
    # place(A,R2) and pick(B) one step each, then place(A,R1) gives up at its first step blaming
    # pick(A): pick(A)'s attempt (found), place(A,R1)'s (backtracked) and place(A,R2)'s (cut off, below
    # pick(A)) end; pick(B)'s goes on.
    problem = ontime.load_problem(BACKTRACKING_EXAMPLES[0])
    session = ontime.Session(ontime.make_allocator(problem, "round-robin"))
    for report in ("refined", "not_yet", "not_yet", "backtrack"):
        session.choose()
        if report == "refined":
            session.report_refined(1)
        elif report == "not_yet":
            session.report_not_yet()
        else:
            session.report_backtrack("pick(A)")
    attempts = session.attempts
    assert attempts[0] == ontime.ActionAttempt(0, False, [ontime.EndedAttempt(1, found=True)])
    assert attempts[1] == ontime.ActionAttempt(0, False, [ontime.EndedAttempt(1, backtracked=True)])
    assert attempts[2] == ontime.ActionAttempt(0, False, [ontime.EndedAttempt(1)])
    assert attempts[3] == ontime.ActionAttempt(1, False) and attempts[3].ended == []
    belief = ontime.OnlineBelief(problem, strength=3.0)
    belief.observe(session.problem, attempts)
    assert belief.observations == 4
    place = problem.actions[1]
    expected = ontime.PlanningPosterior(place.planning, problem.deadline, 3.0, backtrack=place.backtrack)
    expected.observe_backtrack(1)
    assert pmf(belief.planning("place(A,R1)"), 12) == pmf(expected.mean(), 12)
    assert pmf(belief.backtrack("place(A,R1)"), 12) == pmf(expected.backtrack_mean(), 12)
    # By hand: p(1) = 0.3, p(2) = 0.2, q(2) = 0.4 with strength 3; a backtrack at 1 makes b_1 = 1 of a
    # total of 4 at step 1 (hazards 0.9 / 4 and 1 / 4), and leaves step 2 as it was (a = 0.6, b = 1.2,
    # c = 0.3): p = (0.225, 0.525 x 0.6 / 2.1 = 0.15), q = (0.25, 0.525 x 1.2 / 2.1 = 0.3).
    assert pmf(belief.planning("place(A,R1)"), 2) == pytest.approx([0.225, 0.15], abs=1e-12)
    assert pmf(belief.backtrack("place(A,R1)"), 2) == pytest.approx([0.25, 0.3], abs=1e-12)
    believed = belief.believed()  # a valid instance: planning and backtracking sum to at most 1
    assert pmf(believed.actions[1].backtrack, 2) == pmf(belief.backtrack("place(A,R1)"), 2)
    # One attempt by hand: backtracked after 1 step.
    by_hand = ontime.OnlineBelief(problem, strength=3.0)
    by_hand.observe("place(A,R1)", 1, False, backtracked=True)
    assert pmf(by_hand.backtrack("place(A,R1)"), 12) == pmf(expected.backtrack_mean(), 12)
    with pytest.raises(ontime.UsageError, match="not both"):
        by_hand.observe("place(A,R1)", 1, True, backtracked=True)


@pytest.mark.parametrize("path", BACKTRACKING_EXAMPLES, ids=lambda path: path.name)
def test_adapt_takes_every_shipped_example_with_backtracking(cli, path):
    # The example its own prior: the believed instances used to be refused ("planning and backtrack
    # probabilities sum above 1"). The command line's numbers, and the first episode plans with the
    # prior itself: dp-rerun's exact value.
    got = ontime.adapt(path, path, "dp-rerun", episodes=3, sequences=20, exact=True)
    expected = cli("adapt", path, "--belief", path, "--solver", "dp-rerun", "--episodes", 3, "--sequences", 20,
                   "--json")
    assert got["successes"] == expected["successes"]
    assert got["exact_success_probability"] == expected["exact_success_probability"]
    own = ontime.evaluate(path, "dp-rerun", episodes=1, exact=True)["exact_success_probability"]
    assert got["exact_success_probability"][0] == pytest.approx(own, abs=1e-12)
