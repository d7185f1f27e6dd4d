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
