"""The online update in Python: an OnlineBelief learns from what a session saw (Session.attempts,
LiveSession.attempts) and a live session plans with what it believes (revise_distributions), with
the numbers of the C++ posterior (PlanningPosterior)."""

import pytest

import ontime

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
