"""Numbers out of range and input nested too deep are OnTime's errors, naming the parameter or the
limit, never pybind11's "incompatible function arguments" or a RecursionError."""

import numpy as np
import pytest

import ontime
from conftest import PAPER_INSTANCES

SEED_RULE = r"must be a whole number from 0 to 18446744073709551615"


@pytest.fixture(scope="module")
def problem():
    return ontime.load_problem(PAPER_INSTANCES[0])


def refused(call, parameter, rule, got):
    with pytest.raises(ontime.UsageError) as error:
        call()
    assert str(error.value) == f"parameter '{parameter}': {rule} (got {got})"


def test_counts_seeds_and_threads_out_of_range_name_the_parameter(problem):
    refused(lambda: ontime.solve(problem, max_states=-1), "max_states", "must be a whole number >= 1", "-1")
    refused(lambda: ontime.solve(problem, max_states=0), "max_states", "must be a whole number >= 1", "0")
    refused(lambda: ontime.evaluate(problem, "dp-rerun", episodes=-1), "episodes", "must be a whole number >= 1", "-1")
    refused(lambda: ontime.evaluate(problem, "dp-rerun", episodes=10, seed=2**64), "seed", SEED_RULE,
            str(2**64))
    refused(lambda: ontime.evaluate(problem, "dp-rerun", episodes=10, seed=-1), "seed", SEED_RULE, "-1")
    refused(lambda: ontime.evaluate(problem, "dp-rerun", episodes=10, threads=1025), "threads",
            "must be a whole number from 0 to 1024", "1025")
    refused(lambda: ontime.evaluate(problem, "dp-rerun", episodes=10, threads=True), "threads",
            "must be a whole number from 0 to 1024", "a bool")
    refused(lambda: ontime.evaluate(problem, "dp-rerun", episodes="ten"), "episodes",
            "must be a whole number >= 1", "a str")
    refused(lambda: ontime.evaluate(problem, "dp-rerun", episodes=10.0), "episodes",
            "must be a whole number >= 1", "10.0")
    refused(lambda: ontime.train_ppo(problem, "never-written.json", episodes=0), "episodes",
            "must be a whole number >= 1", "0")
    from ontime.env import EffortAllocationEnv
    refused(lambda: EffortAllocationEnv(problem, seed=-5), "seed", SEED_RULE, "-5")


def test_reals_out_of_range_name_the_parameter(problem):
    refused(lambda: ontime.solve(problem, tolerance=float("nan")), "tolerance",
            "must be a finite number from 0.0 to 1.0", "nan")
    refused(lambda: ontime.solve(problem, tolerance=1.5), "tolerance", "must be a finite number from 0.0 to 1.0",
            "1.5")
    allocator = ontime.make_allocator(problem, "mcts", iterations=50)
    refused(lambda: ontime.Session(allocator, iterations=0), "iterations", "must be a whole number >= 1", "0")
    refused(lambda: ontime.Session(allocator, seconds=-0.5), "seconds", "must be a finite number >= 0.0", "-0.5")
    refused(lambda: ontime.Session(allocator, seconds=float("inf")), "seconds", "must be a finite number >= 0.0",
            "inf")
    clock = ontime.ManualClock()
    refused(lambda: clock.advance(-1), "seconds", "must be a finite number >= 0.0", "-1")
    law = problem.actions[0].planning
    refused(lambda: law.quantile(2), "u", "must be a finite number from 0.0 to 1.0", "2")


def test_numpy_numbers_and_plain_ones_give_the_same_result(problem):
    plain = ontime.evaluate(problem, "dp-rerun", episodes=200, seed=3)
    numpy = ontime.evaluate(problem, "dp-rerun", episodes=np.int64(200), seed=np.uint64(3))
    assert plain["successes"] == numpy["successes"]
    assert ontime.solve(problem, max_states=np.int32(1000))["optimal_success_probability"] == pytest.approx(0.942)


def test_input_nested_too_deep_is_an_input_error_naming_the_limit():
    data = {}
    inner = data
    for _ in range(100_000):
        inner["a"] = {}
        inner = inner["a"]
    with pytest.raises(ontime.InputError, match=r"^<dict>: a\.a\.a.*: nested more than 256 levels deep"):
        ontime.Problem.from_dict(data)
    records = [{"action": "a", "planning_seconds": 1.0, "found": True, "execution_seconds": 1.0, "extra": data}]
    with pytest.raises(ontime.InputError, match=r"^<records>: record 1: .*nested more than 256 levels deep"):
        ontime.fit(records, step=1.0, deadline=10, skeletons=[["a"]])
