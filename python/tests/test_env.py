"""The Gymnasium-style environment: the API contract as Gymnasium's environment checker checks it."""

import math

import numpy as np
import pytest

import ontime
from ontime.env import EffortAllocationEnv
from conftest import PAPER_INSTANCES, SOURCE_DIR

CHAINS = SOURCE_DIR / "data" / "instances" / "chains"


@pytest.fixture
def env():
    return EffortAllocationEnv(ontime.load_problem(PAPER_INSTANCES[2]), seed=3)


def rollout(env, seed, policy_seed):
    rng = np.random.default_rng(policy_seed)
    observations = []
    observation, info = env.reset(seed=seed)
    total = 0.0
    while True:
        observations.append(observation)
        action = int(rng.choice(np.flatnonzero(info["action_mask"])))
        observation, reward, terminated, truncated, info = env.step(action)
        total += reward
        if terminated or truncated:
            observations.append(observation)
            return observations, total


def test_reset_and_step_return_the_types_and_shapes_of_the_api(env):
    observation, info = env.reset(seed=1)
    assert isinstance(observation, np.ndarray) and observation.dtype == np.float32
    assert observation.shape == env.observation_space.shape == (1 + 3 * 4,)
    assert env.observation_space.contains(observation)
    assert isinstance(info, dict) and info["action_mask"].shape == (env.action_space.n,)
    result = env.step(int(np.flatnonzero(info["action_mask"])[0]))
    assert len(result) == 5
    observation, reward, terminated, truncated, info = result
    assert env.observation_space.contains(observation)
    assert isinstance(reward, float) and isinstance(terminated, bool) and isinstance(truncated, bool)
    assert env.action_space.contains(0) and not env.action_space.contains(env.action_space.n)


def test_the_same_seed_gives_the_same_episode(env):
    first, reward_one = rollout(env, seed=9, policy_seed=4)
    second, reward_two = rollout(env, seed=9, policy_seed=4)
    assert reward_one == reward_two
    assert len(first) == len(second)
    for a, b in zip(first, second):
        np.testing.assert_array_equal(a, b)
    # A different seed is a different hidden world (somewhere in 20 episodes).
    differs = any(rollout(env, seed=s, policy_seed=4)[0][-1].tolist() != first[-1].tolist() for s in range(20))
    assert differs


def test_episodes_terminate_with_reward_one_exactly_on_success(env):
    successes = 0
    for seed in range(200):
        observations, total = rollout(env, seed=seed, policy_seed=seed)
        assert total in (0.0, 1.0)
        assert len(observations) <= env.problem.deadline + 2
        successes += total == 1.0
        assert env.state.time == round(observations[-1][0] * env.problem.deadline)
    assert 0 < successes < 200


def test_masks_mark_the_useful_choices(env):
    observation, info = env.reset(seed=2)
    mdp = ontime.Mdp(env.problem)
    assert np.flatnonzero(info["action_mask"]).tolist() == mdp.useful_choices(env.state)
    assert env.action_masks().dtype == bool
    assert env.action_masks().tolist() == info["action_mask"].astype(bool).tolist()


def test_stepping_a_finished_episode_or_a_bad_action_is_refused(env):
    _, info = env.reset(seed=0)
    with pytest.raises(ontime.UsageError):
        env.step(env.action_space.n)
    terminated = False
    while not terminated:
        mask = info["action_mask"]
        _, _, terminated, _, info = env.step(int(np.flatnonzero(mask)[0]) if mask.any() else 0)
    assert not info["action_mask"].any()
    with pytest.raises(ontime.UsageError, match="reset"):
        env.step(0)


def test_the_observation_is_the_normalised_state(env):
    env.reset(seed=5)
    observation, *_ = env.step(1)
    state = env.state
    deadline = env.problem.deadline
    expected = [state.time / deadline]
    for k, skeleton in enumerate(env.problem.skeletons):
        expected += [state.refined[k] / len(skeleton), state.spent[k] / deadline, state.execution[k] / deadline]
    np.testing.assert_allclose(observation, np.array(expected, dtype=np.float32))


@pytest.mark.parametrize("path", [PAPER_INSTANCES[0], CHAINS / "meeting-through-the-queue.json"])
def test_the_success_rate_of_an_episode_matches_evaluate_for_the_same_worlds(path):
    # Episode e after reset(seed=s) is episode e of evaluate(seed=s): the same hidden world and, with
    # chains (SPEC §9), the same simulated chains. A greedy policy played through the environment
    # succeeds as often and earns the same rewards.
    problem = ontime.load_problem(path)
    env = EffortAllocationEnv(problem)
    greedy = ontime.make_allocator(problem, "greedy")
    successes = 0
    units = 0  # the runner sums rewards in units of 2^-32 (util/statistics.hpp)
    env.reset(seed=21)
    for episode in range(1000):
        if episode:
            env.reset()
        while True:
            observation, reward, terminated, _, _ = env.step(greedy.choose(env.state))
            if terminated:
                successes += int(reward > 0)
                units += math.floor(reward * 2**32 + 0.5)
                break
    evaluated = ontime.evaluate(problem, "greedy", episodes=1000, seed=21, threads=1)
    assert successes == evaluated["successes"]
    assert units * 2**-32 / 1000 == evaluated.get("mean_reward", evaluated["success_rate"])
