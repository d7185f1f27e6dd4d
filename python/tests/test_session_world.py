"""Sessions driven from Python, and worlds written in Python run by the library's episode runner."""

import math

import numpy as np
import pytest

import ontime
from conftest import PAPER_INSTANCES


@pytest.fixture(scope="module")
def problem():
    return ontime.load_problem(PAPER_INSTANCES[0])


def drive(session, problem, world):
    """Runs a session to its end against `world` (a function (action id, spent) -> None or steps);
    returns the number of actions refined."""
    spent = {}
    refined = 0
    while session.status == ontime.Status.running:
        decision = session.choose()
        if decision.action < 0:
            session.report_not_yet()
            continue
        spent[decision.action] = spent.get(decision.action, 0) + 1
        outcome = world(decision.action_id, spent[decision.action])
        if outcome is None:
            session.report_not_yet()
        else:
            refined += 1
            session.report_refined(outcome)
    return refined


def test_a_session_follows_the_allocator_and_reports_success(problem):
    # Every action refined after 2 steps, executed in 1: skeleton 1 (the optimal first choice)
    # needs 3 x 2 = 6 steps and 3 of execution, within the deadline of 14.
    allocator = ontime.make_allocator(problem, "optimal")
    first = ontime.Session(allocator).choose()
    assert (first.skeleton, first.action_id) == (1, "a2_1")
    session = ontime.Session(allocator)
    refined = drive(session, problem, lambda action, spent: 1 if spent == 2 else None)
    assert session.status == ontime.Status.success
    assert session.solution is not None
    assert session.steps_used == 2 * refined
    assert session.state.refined[session.solution] == len(problem.skeletons[session.solution])


def test_a_session_that_cannot_succeed_stops_early(problem):
    session = ontime.Session(ontime.make_allocator(problem, "dp-rerun"))
    assert drive(session, problem, lambda a, s: None) == 0
    assert session.status == ontime.Status.failure
    assert session.solution is None
    assert session.steps_used < problem.deadline  # stopped once nothing could still meet the deadline


def test_out_of_turn_calls_are_usage_errors(problem):
    session = ontime.Session(ontime.make_allocator(problem, "dp"))
    with pytest.raises(ontime.UsageError):
        session.report_not_yet()
    session.choose()
    with pytest.raises(ontime.UsageError):
        session.choose()
    with pytest.raises(ontime.UsageError):
        session.report_refined(-1)


def test_a_budget_per_decision_reaches_an_anytime_allocator(problem):
    allocator = ontime.make_allocator(problem, "mcts", iterations=5000)
    session = ontime.Session(allocator, seed=2, iterations=40)
    session.choose()
    assert allocator.statistics()["iterations"] == 40
    session.report_not_yet()
    session.choose(iterations=7)
    assert allocator.statistics()["iterations"] == 47


class SampledWorld(ontime.World):
    """Draws each action's planning and execution time from the problem's distributions with numpy."""

    def __init__(self, problem):
        self.problem = problem
        self.started = 0

    def begin_episode(self, seed):
        rng = np.random.default_rng(seed)
        self.planning = [self.draw(rng, a.planning) for a in self.problem.actions]
        self.execution = [self.draw(rng, a.execution) for a in self.problem.actions]

    @staticmethod
    def draw(rng, law):
        step = law.quantile(rng.random())
        return ontime.NEVER if step is None else step

    def step(self, action, spent):
        if spent == 0:
            self.started += 1
        return self.execution[action] if spent + 1 == self.planning[action] else None

    def statistics(self):
        return {"refinements_started": self.started}


def test_a_python_world_gives_the_same_results_on_any_thread_count(problem):
    one = ontime.run_episodes(problem, lambda: SampledWorld(problem), "dp-rerun", episodes=600, seed=5, threads=1)
    two = ontime.run_episodes(problem, lambda: SampledWorld(problem), "dp-rerun", episodes=600, seed=5, threads=2)
    assert one["successes"] == two["successes"]
    assert one["world_statistics"] == two["world_statistics"]
    assert one["world_statistics"]["refinements_started"] >= 600
    # Sampled from the model, the success rate agrees with the exact value within its interval.
    exact = ontime.evaluate(problem, "dp-rerun", episodes=1, exact=True)["exact_success_probability"]
    assert abs(one["success_rate"] - exact) <= one["ci95"] * 1.5 + 0.01


def test_a_world_instance_runs_on_one_thread_and_counts_its_work(problem):
    world = SampledWorld(problem)
    result = ontime.run_episodes(problem, world, ontime.make_allocator(problem, "greedy"), episodes=50, seed=1)
    assert result["episodes"] == 50
    assert world.started == result["world_statistics"]["refinements_started"]
    with pytest.raises(ontime.UsageError, match="one thread"):
        ontime.run_episodes(problem, world, "greedy", episodes=5, threads=2)


def test_an_error_in_a_python_world_reaches_the_caller(problem):
    class Broken(SampledWorld):
        def step(self, action, spent):
            raise ZeroDivisionError("planner crashed")

    with pytest.raises(ZeroDivisionError, match="planner crashed"):
        ontime.run_episodes(problem, lambda: Broken(problem), "dp", episodes=10, threads=2)

    class Negative(SampledWorld):
        def step(self, action, spent):
            return -3

    with pytest.raises(ontime.UsageError, match="negative execution time"):
        ontime.run_episodes(problem, lambda: Negative(problem), "dp", episodes=10)


def test_infinite_execution_means_never(problem):
    class Unexecutable(SampledWorld):
        def step(self, action, spent):
            return math.inf

    result = ontime.run_episodes(problem, lambda: Unexecutable(problem), "dp", episodes=20)
    assert result["successes"] == 0
