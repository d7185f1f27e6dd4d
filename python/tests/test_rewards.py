"""Rewards beyond success (SPEC §8) from Python: the instance's rewards, the solvers' expected reward, the
environment's and the sessions' rewards."""

import json

import numpy as np
import pytest

import ontime
from ontime.env import EffortAllocationEnv
from conftest import SOURCE_DIR

COFFEE = SOURCE_DIR / "data" / "instances" / "rewards" / "meeting-with-coffee.json"


def test_the_instance_declares_its_rewards():
    problem = ontime.load_problem(COFFEE)
    assert problem.has_rewards
    assert problem.rewards == [{"value": 1.0, "per_step": 0.01}, {"value": 0.7, "per_step": 0.0}]
    plain = ontime.load_problem(SOURCE_DIR / "data" / "instances" / "paper" / "instance1.json")
    assert not plain.has_rewards
    assert all(reward == {"value": 1.0, "per_step": 0.0} for reward in plain.rewards)


def test_every_exact_solver_gives_the_same_expected_reward_and_evaluation_both_figures():
    problem = ontime.load_problem(COFFEE)
    values = {method: ontime.solve(problem, method=method)["optimal_expected_reward"]
              for method in ("memoised", "layered", "search")}
    assert len(set(values.values())) == 1
    optimum = values["memoised"]
    evaluated = ontime.evaluate(problem, "optimal", episodes=500, exact=True)
    assert evaluated["exact_expected_reward"] == optimum
    # Every reward is below 1: the expected reward is below the success probability of the same policy.
    assert evaluated["exact_expected_reward"] < evaluated["exact_success_probability"]
    assert 0.0 < evaluated["mean_reward"] < evaluated["success_rate"]


def test_the_environment_pays_the_reward_of_the_plan_and_its_arrival():
    problem = ontime.load_problem(COFFEE)
    env = EffortAllocationEnv(problem, seed=2)
    paid = set()
    for seed in range(60):
        observation, info = env.reset(seed=seed)
        reward, terminated = 0.0, False
        while not terminated:
            action = int(np.flatnonzero(info["action_mask"])[0])  # the coffee skeleton while it can succeed
            observation, reward, terminated, truncated, info = env.step(action)
        paid.add(round(reward, 12))
    # The coffee plan arriving at step f earns 1 - 0.01 f (f <= 20), the other 0.7, a failure 0.
    for reward in paid:
        assert reward in (0.0, 0.7) or any(abs(reward - (1.0 - 0.01 * f)) < 1e-12 for f in range(21))
    assert any(0.8 <= reward < 1.0 for reward in paid)


def test_a_session_reports_what_the_episode_earned():
    problem = ontime.load_problem(COFFEE)
    session = ontime.Session(ontime.make_allocator(problem, "greedy"))
    assert session.choose().action_id == "move(R1,meeting)"
    assert session.reward == 0.0
    session.report_refined(4)
    assert session.status == ontime.Status.success and session.solution == 1
    assert session.reward == 0.7


def test_bad_rewards_are_refused_with_their_place():
    document = json.loads(COFFEE.read_text())
    document["rewards"][1] = float("nan")
    with pytest.raises(ontime.InputError, match="invalid JSON"):
        ontime.Problem.from_json(json.dumps(document), "coffee.json")
    document["rewards"][1] = {"value": 0.7, "per_step": 0.5}
    with pytest.raises(ontime.InputError, match=r"rewards\[1\]: .*falls below 0 before the deadline"):
        ontime.Problem.from_json(json.dumps(document), "coffee.json")


def test_a_live_session_pays_by_the_robots_clock_and_takes_the_reward_of_an_arriving_skeleton():
    one_step = {"pmf": {"1": 1.0}}
    problem = ontime.Problem.from_dict({
        "deadline": 10, "step_seconds": 1.0,
        "actions": {"a": {"planning": one_step, "execution": {"pmf": {"2": 1.0}}},
                    "b": {"planning": one_step, "execution": one_step}},
        "skeletons": [["a"]], "rewards": [{"value": 1.0, "per_step": 0.1}],
    })
    clock = ontime.ManualClock()
    session = ontime.LiveSession(problem, "greedy", clock=clock)
    assert session.add_skeleton(["b"], reward=0.5, reward_per_step=0.02) == 1
    assert session.problem.rewards[1] == {"value": 0.5, "per_step": 0.02}
    session.retire_skeleton(1)
    assert session.problem.rewards == [{"value": 1.0, "per_step": 0.1}]
    session.choose()
    clock.advance(1.0)
    assert session.report_refined_seconds(2.5) == ontime.Status.success
    # The plan ends 1.0 + 2.5 seconds in: 3.5 steps of 1 s.
    assert session.reward == pytest.approx(1.0 - 0.1 * 3.5, abs=1e-12)
