"""Exogenous chains from Python: fit_chain gives the chain file `ontime fit-chain` writes, byte for byte,
from a log or from sequences of observed states; the chain's matrix and distributions are numpy arrays;
bad input is refused as the command line refuses it."""

import json
import math

import numpy as np
import pytest

import ontime


def write_log(path, sequences):
    with open(path, "w") as out:
        for name, states in sequences.items():
            for step, state in enumerate(states):
                out.write(json.dumps({"sequence": name, "step": step, "state": state}) + "\n")


def test_a_queue_fits_as_the_command_line_fits_it(tmp_path, cli):
    log = tmp_path / "queue.jsonl"
    write_log(log, {"mon": [0, 1, 1, 2, 1, 0, 0, 1], "tue": [1, 1, 2]})
    chain_file = tmp_path / "queue.chain.json"
    out = cli("fit-chain", log, "--kind", "birth-death", "--capacity", 3, "--name", "queue", "-o", chain_file, "--json")
    fit = ontime.fit_chain(log, kind="birth-death", capacity=3, name="queue")
    assert fit.chain.to_json() == chain_file.read_text()
    assert fit.transitions_counted == out["transitions_counted"] == 9
    assert fit.arrival == out["arrival"]
    # Sequences in memory are the same observations: the same chain.
    from_sequences = ontime.fit_chain([[0, 1, 1, 2, 1, 0, 0, 1], ["1", "1", "2"]], kind="birth-death", capacity=3,
                                      name="queue")
    assert from_sequences.chain.to_json() == fit.chain.to_json()
    loaded = ontime.load_chain(chain_file)
    assert loaded.states == ["0", "1", "2", "3"]
    assert loaded.start == "0"


def test_the_matrix_and_the_distributions_are_numpy_arrays(tmp_path):
    fit = ontime.fit_chain([["open", "open", "closed", "open", "open"]], name="door")
    chain = fit.chain
    assert chain.states == ["closed", "open"]
    assert chain.start == "open"
    # open -> open twice, open -> closed once; closed -> open once.
    np.testing.assert_array_equal(chain.transitions, np.array([[0.0, 1.0], [1 / 3, 2 / 3]]))
    assert fit.log_likelihood == pytest.approx(2 * math.log(2 / 3) + math.log(1 / 3), abs=1e-12)
    np.testing.assert_array_equal(chain.distribution(0), [0.0, 1.0])
    two = chain.distribution(2, from_state="closed")
    np.testing.assert_allclose(two, [1 / 3, 2 / 3], rtol=0, atol=1e-15)
    chain.save(tmp_path / "door.json")
    assert ontime.load_chain(tmp_path / "door.json").to_json() == chain.to_json()


def test_bad_input_is_refused(tmp_path):
    with pytest.raises(ontime.UsageError, match="unknown chain kind 'poisson'"):
        ontime.fit_chain([[0, 1]], kind="poisson")
    with pytest.raises(ontime.UsageError, match="whole number >= 0"):
        ontime.fit_chain([[0, -1]])
    with pytest.raises(ValueError, match="prior"):
        ontime.fit_chain([[0, 1, 0]], prior=-1)
    with pytest.raises(ontime.InputError, match=r"sequences\[1\]: sequence '1', step 2: the queue goes from 1 to 3"):
        ontime.fit_chain([[0, 1], [0, 1, 3]], kind="birth-death")
    log = tmp_path / "backwards.jsonl"
    log.write_text('{"step": 2, "state": 0}\n{"step": 1, "state": 1}\n')
    with pytest.raises(ontime.InputError, match="line 2: step"):
        ontime.fit_chain(log)
    broken = tmp_path / "broken.json"
    broken.write_text('{"format": "ontime-chain", "version": 1, "name": "d", "states": ["a"], "start": "a", '
                      '"transitions": [[0.5]]}')
    with pytest.raises(ontime.InputError, match=r"transitions\[0\]: the probabilities of leaving state 'a' sum to 1"):
        ontime.load_chain(broken)
    chain = ontime.fit_chain([["a", "b", "a"]]).chain
    with pytest.raises(ontime.UsageError, match="no state 'c'"):
        chain.distribution(1, from_state="c")


QUEUE = {"deadline": 4,
         "chains": {"queue": {"states": ["short", "long"], "start": "short", "transitions": [[0.7, 0.3], [0.4, 0.6]]}},
         "actions": {"wait": {"planning": {"pmf": {"1": 1.0}},
                              "execution": {"chain": "queue", "by_state": {"short": {"pmf": {"1": 1.0}},
                                                                           "long": {"pmf": {"5": 1.0}}}}}},
         "skeletons": [["wait"]]}


def test_a_session_takes_the_chains_states_with_each_report(tmp_path):
    path = tmp_path / "queue.json"
    path.write_text(json.dumps(QUEUE))
    problem = ontime.load_problem(path)
    # The wait is refined in step 1 and starts at once: done at 2 if the queue is short then (0.7).
    assert ontime.solve(problem)["optimal_success_probability"] == pytest.approx(0.7, abs=1e-15)
    for state, reward in (("short", 1.0), ("long", 0.0)):
        session = ontime.Session(ontime.make_allocator(problem, "optimal"))
        assert session.chains == {"queue": "short"}
        assert session.choose().action_id == "wait"
        with pytest.raises(ontime.UsageError, match="report their states"):
            session.report_refined(0)
        with pytest.raises(ontime.UsageError, match="no state 'empty'"):
            session.report_refined(0, chains={"queue": "empty"})
        assert session.report_refined(0, chains={"queue": state}) == ontime.Status.success
        assert session.chains == {"queue": state}
        # The plan's expected reward from the reported state: certain either way here.
        assert session.reward == reward


def test_every_allocator_takes_chains_and_ppo_learns_the_queue(tmp_path):
    assert all("chains" in kind["capabilities"] for kind in ontime.allocators())
    path = tmp_path / "queue.json"
    path.write_text(json.dumps(QUEUE))
    problem = ontime.load_problem(path)
    with pytest.raises(ontime.UsageError, match="'sum' has no form with chains"):
        ontime.make_allocator(problem, "dp-rerun", aggregation="sum")
    evaluated = ontime.evaluate(problem, "round-robin", episodes=4000, exact=True, seed=3)
    assert evaluated["exact_success_probability"] == pytest.approx(0.7, abs=1e-15)
    assert abs(evaluated["success_rate"] - 0.7) <= 4 * evaluated["ci95"]
    # One skeleton and one useful choice: any policy refines it; its file records the chain inputs
    # (the queue's two states and the timed slot of the wait).
    policy = tmp_path / "queue.policy.json"
    ontime.train_ppo(problem, policy, episodes=50, seed=2)
    assert json.loads(policy.read_text())["chain_inputs"] == 3
    evaluated = ontime.evaluate(problem, "ppo", policy=str(policy), episodes=2000, exact=True, seed=3)
    assert evaluated["exact_success_probability"] == pytest.approx(0.7, abs=1e-15)


def test_the_environment_draws_each_episodes_chains(tmp_path):
    from ontime.env import EffortAllocationEnv
    path = tmp_path / "queue.json"
    path.write_text(json.dumps(QUEUE))
    env = EffortAllocationEnv(ontime.load_problem(path), seed=4)
    rewards = []
    for _ in range(400):
        env.reset()
        observation, reward, terminated, truncated, info = env.step(0)  # the wait, found in one step
        assert terminated
        rewards.append(reward)
    # Only the queue is random here: short at step 1 (0.7) earns 1, long earns 0.
    assert set(rewards) == {0.0, 1.0}
    assert abs(np.mean(rewards) - 0.7) < 4 * math.sqrt(0.7 * 0.3 / 400)


def test_the_averaging_baseline_cannot_wait_for_a_door(tmp_path):
    # A door open at even steps only. Averaged, it is open 4 steps in 7 whenever the robot comes, so
    # the baseline enters as soon as the motion is found (step 1, locked); the optimum waits a step.
    door = {"deadline": 6,
            "chains": {"door": {"states": ["open", "locked"], "start": "open", "transitions": [[0, 1], [1, 0]]}},
            "actions": {"enter": {"planning": {"pmf": {"1": 1.0}}, "execution": {"pmf": {"1": 1.0}},
                                  "expires": {"chain": "door", "states": ["locked"]}},
                        "other": {"planning": {"pmf": {}}, "execution": {"pmf": {"1": 1.0}}}},
            "skeletons": [["enter"], ["other"]]}
    path = tmp_path / "door.json"
    path.write_text(json.dumps(door))
    problem = ontime.load_problem(path)
    optimal = ontime.evaluate(problem, "optimal", episodes=200, exact=True, seed=1)
    averaged = ontime.evaluate(problem, "averaged", episodes=200, exact=True, seed=1)
    assert optimal["exact_success_probability"] == 1.0
    assert averaged["exact_success_probability"] == 0.0
    assert averaged["success_rate"] == 0.0


def test_the_allocators_that_model_chains_know_the_queue(tmp_path):
    # One skeleton: every allocator that takes chains refines it at once; the wait starts at step 1,
    # short then with probability 0.7 (done at 2), long with 0.3 (done at 6, past the deadline).
    path = tmp_path / "queue.json"
    path.write_text(json.dumps(QUEUE))
    problem = ontime.load_problem(path)
    for name in ("dp", "dp-rerun", "greedy", "found-order-round-robin"):
        evaluated = ontime.evaluate(problem, name, episodes=2000, exact=True, seed=5)
        assert evaluated["exact_success_probability"] == pytest.approx(0.7, abs=1e-15), name
        assert abs(evaluated["success_rate"] - 0.7) <= 4 * evaluated["ci95"], name
    for name in ("thompson", "mcts", "branch-and-bound"):
        search = {"iterations": 200} if name == "mcts" else {}
        evaluated = ontime.evaluate(problem, name, episodes=2000, seed=5, **search)
        assert abs(evaluated["success_rate"] - 0.7) <= 4 * evaluated["ci95"], name


def test_every_exact_method_solves_the_queue_to_the_same_bits(tmp_path):
    path = tmp_path / "queue.json"
    path.write_text(json.dumps(QUEUE))
    problem = ontime.load_problem(path)
    solved = {method: ontime.solve(problem, method=method) for method in ("layered", "memoised", "search")}
    assert solved["layered"]["method"] == "layered"  # the default with chains as without
    assert ontime.solve(problem)["method"] == "layered"
    for method, out in solved.items():
        assert out["optimal_success_probability"] == pytest.approx(0.7, abs=1e-15), method
        assert out["optimal_success_probability"] == solved["memoised"]["optimal_success_probability"], method
        assert out["first_choice"] == 0, method


def test_a_live_session_takes_the_queue_with_each_report():
    # move (2 s), then the coffee: a 1-step wait with the queue short when it starts, 6 when long.
    problem = ontime.Problem.from_dict({
        "deadline": 6, "step_seconds": 1.0,
        "chains": {"queue": {"states": ["short", "long"], "start": "short", "transitions": [[0.8, 0.2], [0.4, 0.6]]}},
        "actions": {"move": {"planning": {"pmf": {"1": 1.0}}, "execution": {"pmf": {"2": 1.0}}},
                    "coffee": {"planning": {"pmf": {"1": 1.0}},
                               "execution": {"chain": "queue", "by_state": {"short": {"pmf": {"1": 1.0}},
                                                                            "long": {"pmf": {"6": 1.0}}}}}},
        "skeletons": [["move", "coffee"]],
    })
    for queue, short_when_it_starts in (("short", 0.8 * 0.8 + 0.2 * 0.4), ("long", 0.4 * 0.8 + 0.6 * 0.4)):
        clock = ontime.ManualClock()
        session = ontime.LiveSession(problem, "dp-rerun", clock=clock)
        assert session.chains == {"queue": "short"}
        assert session.choose().action_id == "move"
        clock.advance(1.0)
        with pytest.raises(ontime.UsageError, match="report their states"):
            session.report_refined_seconds(2.0)
        assert session.report_refined_seconds(2.0, chains={"queue": "long"}) == ontime.Status.running
        assert session.chains == {"queue": "long"}
        assert session.choose().action_id == "coffee"
        clock.advance(1.0)
        # The coffee's reported 30 s are not its wait: the static part (2 s from 2 s in) fits.
        assert session.report_refined_seconds(30.0, chains={"queue": queue}) == ontime.Status.success
        # The move runs in steps 2-3; the coffee starts at 4, two steps of the queue after the report.
        assert session.reward == pytest.approx(short_when_it_starts, abs=1e-15)


def test_backtracking_with_chains_solves_and_evaluates(source_dir):
    # The cup carried through a door that locks, placing it sometimes blaming the grasp (SPEC §7, §9).
    problem = ontime.load_problem(source_dir / "data" / "instances" / "chains" / "cup-through-the-door.json")
    solved = {method: ontime.solve(problem, method=method) for method in ("layered", "memoised", "search")}
    for method, out in solved.items():
        assert out["optimal_expected_reward"] == solved["memoised"]["optimal_expected_reward"], method
    assert solved["layered"]["optimal_expected_reward"] == pytest.approx(0.620783, abs=5e-7)
    evaluated = ontime.evaluate(problem, "dp-rerun", episodes=4000, exact=True, seed=3)
    assert evaluated["exact_expected_reward"] < solved["layered"]["optimal_expected_reward"]
    assert abs(evaluated["mean_reward"] - evaluated["exact_expected_reward"]) <= 4 * evaluated["reward_ci95"] / 1.96
