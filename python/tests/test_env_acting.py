"""The environment acting while planning (act='concurrent', SPEC §10): its episodes are the episode
runner's (a registry allocator's moves played through it succeed and earn exactly as
`ontime.evaluate(act='concurrent')` in the same episodes), its masks are the exact solver's useful
moves (checked against an independent reading of their rule), and it refuses what the rule refuses."""

import math

import numpy as np
import pytest

import ontime
from ontime.env import EffortAllocationEnv
from conftest import PAPER, SOURCE_DIR

INSTANCE1 = PAPER / "instance1.json"
# Two chains (a queue and a door, SPEC §9) and rewards (SPEC §8): 12 steps, 2 skeletons.
MEETING = SOURCE_DIR / "data" / "instances" / "chains" / "meeting-through-the-queue.json"
# Chains, 3 skeletons, 43 steps: random play saturates r / D at (D + 1) / D.
COFFEE = SOURCE_DIR / "data" / "instances" / "chains" / "coffee-building.json"
# A door chain whose locked state blocks an action, rewards, and give-ups blaming an earlier action
# (SPEC §7): 16 steps, 2 skeletons of 3 actions.
CUP = SOURCE_DIR / "data" / "instances" / "chains" / "cup-through-the-door.json"


def play_allocator(env, solver, seed, episodes):
    """Episodes 0..episodes-1 after reset(seed=seed), each move the one a ConcurrentSession of `solver`
    chooses: the session is seeded as the runner seeds episode e's (env.session_seed) and told what
    each step revealed (info). Returns the rewards, asserting that the session and the environment
    agree on every end and reward."""
    rewards = []
    for episode in range(episodes):
        env.reset(seed=seed) if episode == 0 else env.reset()
        session = ontime.ConcurrentSession(env.problem, solver, seed=env.session_seed)
        terminated = False
        while not terminated:
            move = session.choose()
            _, reward, terminated, truncated, info = env.step(env.action_of(move))
            assert not truncated
            if move["start"] is None:
                assert (info["found"] is None) == (move["action"] is None)  # None: the planner idled
                if info["found"]:
                    session.report_refined(info["execution_steps"])
                elif info["culprit"] is not None:
                    session.report_backtrack(info["culprit"])
                else:
                    session.report_not_yet()
            else:
                assert info["found"] is None and info["execution_steps"] is None and info["culprit"] is None
            assert (session.status != ontime.Status.running) == terminated
        assert reward == session.reward
        rewards.append(reward)
    return rewards


@pytest.mark.parametrize("instance, solver, episodes", [
    (INSTANCE1, "optimal", 300),
    (INSTANCE1, "round-robin", 300),
    (INSTANCE1, "thompson", 200),  # randomised: seeded by the session's seed, as the runner seeds it
    (MEETING, "optimal", 300),
    (CUP, "optimal", 300),
    (MEETING, "dp-rerun", 300),
    (CUP, "dp-rerun", 300),
])
def test_an_allocators_moves_played_through_the_env_are_evaluates_episodes(instance, solver, episodes):
    env = EffortAllocationEnv(instance, seed=5, act="concurrent")
    rewards = play_allocator(env, solver, seed=17, episodes=episodes)
    evaluated = ontime.evaluate(instance, solver, act="concurrent", episodes=episodes, seed=17, threads=1)
    assert sum(reward > 0 for reward in rewards) == evaluated["successes"]
    # The runner sums rewards in units of 2^-32, each rounded (util/statistics.hpp): the same sum here.
    units = sum(math.floor(reward * 2**32 + 0.5) for reward in rewards)
    assert units * 2**-32 / episodes == evaluated.get("mean_reward", evaluated["success_rate"])


def test_instance1_acting_while_planning_never_fails_with_the_optimum_and_plan_first_does():
    # The concurrent optimum of instance 1 is 1.0 (plan-first 0.942): every episode succeeds.
    env = EffortAllocationEnv(INSTANCE1, act="concurrent")
    assert play_allocator(env, "optimal", seed=3, episodes=100) == [1.0] * 100
    assert EffortAllocationEnv(INSTANCE1).act == "plan-first"
    assert EffortAllocationEnv(ontime.load_problem(INSTANCE1).with_acting("concurrent")).act == "concurrent"


def expected_outputs(problem, state):
    """The outputs of ConcurrentMdp::useful_moves read off the rule (concurrent_mdp.hpp): the forced
    start alone (robot idle, every live skeleton's next action to execute the same refined one; none
    with chains or backtracking), else before the deadline one step per group of live skeletons
    sharing their next action to refine (its lowest index), the idle planner when there is none or
    with backtracking, then the starts (the robot may start them; K + the lowest live skeleton
    executing each next)."""
    skeletons = problem.skeletons
    count = len(skeletons)
    live = [k for k in range(count) if state["live"][k]]
    if not live:
        return []
    depth = len(state["started"])
    described = problem.to_dict()
    timed = bool(described.get("chains"))
    backtracking = any("backtrack" in action for action in described["actions"].values())
    if not timed and not backtracking and state["robot_left"] == 0 and all(state["refined"][k] > depth for k in live):
        nexts = {skeletons[k][depth] for k in live}
        if len(nexts) == 1:
            return [count + live[0]]
    outputs = []
    if state["time"] < problem.deadline:
        met = set()
        for k in live:
            if state["refined"][k] < len(skeletons[k]) and skeletons[k][state["refined"][k]] not in met:
                met.add(skeletons[k][state["refined"][k]])
                outputs.append(k)
        if not outputs or backtracking:
            outputs.append(2 * count)
    if not timed:  # else whether a chain lets the action start now is the environment's startable
        startable = sorted({skeletons[k][depth] for k in live
                            if state["robot_left"] == 0 and state["refined"][k] > depth})
        assert startable == sorted(state["startable"])
    for action in state["startable"]:
        outputs.append(count + min(k for k in live if skeletons[k][depth] == action))
    return sorted(outputs)


@pytest.mark.parametrize("instance", [INSTANCE1, MEETING, CUP, COFFEE])
def test_masks_are_the_useful_moves_of_every_state_reached_by_random_masked_play(instance):
    env = EffortAllocationEnv(instance, act="concurrent")
    problem = env.problem
    count = len(problem.skeletons)
    assert env.action_space.n == 2 * count + 1
    rng = np.random.default_rng(11)
    states = starts = idles = 0
    for episode in range(200):
        _, info = env.reset(seed=8) if episode == 0 else env.reset()
        terminated = False
        while not terminated:
            expected = expected_outputs(problem, env.state)
            assert np.flatnonzero(info["action_mask"]).tolist() == expected
            assert env.action_masks().tolist() == info["action_mask"].astype(bool).tolist()
            states += 1
            action = int(rng.choice(expected))
            starts += count <= action < 2 * count
            idles += action == 2 * count
            _, _, terminated, _, info = env.step(action)
        assert not info["action_mask"].any()
    assert states > 1000 and starts > 200


def rollout(env, seed, policy_seed):
    rng = np.random.default_rng(policy_seed)
    observation, info = env.reset(seed=seed)
    trajectory = [observation.tolist()]
    while True:
        action = int(rng.choice(np.flatnonzero(info["action_mask"])))
        observation, reward, terminated, truncated, info = env.step(action)
        trajectory += [action, observation.tolist(), reward, info["found"], info["execution_steps"], info["culprit"]]
        if terminated or truncated:
            return trajectory


@pytest.mark.parametrize("instance", [INSTANCE1, MEETING, CUP])
def test_the_same_seed_gives_the_same_trajectory(instance):
    first = EffortAllocationEnv(instance, act="concurrent")
    second = EffortAllocationEnv(instance, seed=99, act="concurrent")
    for seed in range(20):
        # reset(seed=s) starts the episodes of s afresh, in the same environment or another.
        one = rollout(first, seed, 4)
        assert rollout(first, seed, 4) == one
        assert rollout(second, seed, 4) == one
    # Another seed is another hidden world (the random policy is the same).
    assert any(rollout(first, seed, 4) != rollout(first, 0, 4) for seed in range(1, 20))


def test_a_masked_out_or_out_of_range_action_is_refused():
    env = EffortAllocationEnv(INSTANCE1, act="concurrent")
    _, info = env.reset(seed=1)
    count = len(env.problem.skeletons)
    # At the start nothing is refined: no start, no idle planner (every skeleton has work).
    assert np.flatnonzero(info["action_mask"]).tolist() == [k for k in range(count)
                                                            if env.problem.skeletons[k][0] not in
                                                            {env.problem.skeletons[j][0] for j in range(k)}]
    for masked in [count, 2 * count - 1, 2 * count]:
        with pytest.raises(ontime.UsageError, match=r"^parameter 'action': move \d+ is masked out: only the state's "
                                                    r"useful moves"):
            env.step(masked)
    for outside in [-1, 2 * count + 1, 10**30]:
        with pytest.raises(ontime.UsageError, match=r"parameter 'action'"):
            env.step(outside)
    with pytest.raises(ontime.UsageError, match=r"parameter 'action'"):
        env.step(1.0)
    assert env.state["time"] == 0  # nothing refused moved the episode
    # A move of a ConcurrentSession has its action; a start no live skeleton makes next has none.
    # Skeletons 1, 2 and 3 begin with a2_1: a step on any of them is the group's step, named 1.
    assert [env.action_of({"start": None, "skeleton": k, "action": None}) for k in range(count)] == [0, 1, 1, 1]
    assert env.action_of({"start": None, "skeleton": None, "action": None}) == 2 * count
    last = env.problem.skeletons[0][-1]
    with pytest.raises(ontime.UsageError, match="no live skeleton executes action"):
        env.action_of({"start": last, "skeleton": None})
    with pytest.raises(ontime.UsageError, match="parameter 'move'"):
        env.action_of({"start": None, "skeleton": count})
    with pytest.raises(ontime.UsageError, match="act='concurrent'"):
        EffortAllocationEnv(INSTANCE1).action_of({"start": None, "skeleton": 0})
    for act in ["sideways", 3]:
        with pytest.raises(ontime.UsageError, match="act"):
            EffortAllocationEnv(INSTANCE1, act=act)


@pytest.mark.parametrize("instance", [INSTANCE1, MEETING, CUP, COFFEE])
def test_every_observation_lies_in_the_observation_space(instance):
    env = EffortAllocationEnv(instance, act="concurrent")
    count = len(env.problem.skeletons)
    chain_states = sum(len(chain["states"]) for chain in env.problem.to_dict().get("chains", {}).values())
    assert env.observation_space.shape == (2 + 6 * count + chain_states,)
    # CT and PT at most D, r and the robot's backlog at most D + 1 (saturated), shares and flags in [0, 1].
    assert env.observation_space.low.tolist() == [0.0] * env.observation_space.shape[0]
    assert env.observation_space.high.tolist() == [np.float32(1 + 1 / env.problem.deadline)] * \
        env.observation_space.shape[0]
    rng = np.random.default_rng(2)
    highest = 0.0
    for episode in range(300):
        observation, info = env.reset(seed=6) if episode == 0 else env.reset()
        while True:
            assert observation.dtype == np.float32 and env.observation_space.contains(observation)
            highest = max(highest, float(observation.max()))
            state = env.state
            assert observation[0] == np.float32(state["time"] / env.problem.deadline)
            assert observation[1] == np.float32(state["robot_left"] / env.problem.deadline)
            assert observation[2:2 + 6 * count:6].tolist() == [float(live) for live in state["live"]]
            if not info["action_mask"].any():
                break
            action = int(rng.choice(np.flatnonzero(info["action_mask"])))
            observation, _, terminated, _, info = env.step(action)
    # The bound is tight: r reaches D + 1 on coffee-building (an execution its chain draws too slow at the start).
    assert highest == (env.observation_space.high[0] if instance == COFFEE else 1.0)


def test_a_concurrent_session_told_a_give_up_discards_what_its_culprit_led_to():
    # grasp-and-place (SPEC §7): place(A,R1)'s attempt may give up blaming pick(A).
    grasps = ontime.load_problem(SOURCE_DIR / "data" / "instances" / "backtracking" / "grasp-and-place.json")
    session = ontime.ConcurrentSession(grasps)
    session.decide(refine=0)
    session.report_refined(1)  # pick(A) refined: skeletons 0 and 1 may start it
    assert session.startable == ["pick(A)"]
    session.decide(refine=0)
    assert session.report_backtrack("pick(A)") == ontime.Status.running
    assert session.startable == [] and session.steps_used == 2  # pick(A)'s motion discarded
    with pytest.raises(ontime.UsageError, match="no action 'nowhere'"):
        session.decide(refine=0)
        session.report_backtrack("nowhere")
