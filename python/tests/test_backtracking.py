"""Backtracking (docs/spec.md §7) from Python: an instance whose actions may give up and blame an
earlier one reads with its backtrack distributions and culprits, solves to the command line's
optimum, and a session or a World of the caller's reports backtracks."""

import pytest

import ontime
from conftest import SOURCE_DIR

EXAMPLE = SOURCE_DIR / "data" / "instances" / "backtracking" / "grasp-and-place.json"


def test_an_instance_with_backtracking_reads_and_solves_as_the_cli_does(cli):
    problem = ontime.load_problem(EXAMPLE)
    place = problem.actions[1]
    assert place.id == "place(A,R1)" and place.culprits == {"pick(A)": 1.0}
    assert abs(place.backtrack.pmf[2] - 0.4) < 1e-15
    solved = ontime.solve(problem)
    assert solved["optimal_success_probability"] == cli("solve", EXAMPLE, "--json")[
        "optimal_success_probability"]
    # The layered solver (the default) and the memoised one agree to the bit.
    assert solved["optimal_success_probability"] == ontime.solve(problem, method="memoised")[
        "optimal_success_probability"]
    with pytest.raises(ontime.UsageError, match="a split does not apply to an instance with backtracking"):
        ontime.solve(problem, method="split")


def test_a_session_takes_a_backtrack_and_refines_the_culprit_again():
    problem = ontime.load_problem(EXAMPLE)
    # Round-robin: skeleton CT mod 3 every step.
    session = ontime.Session(ontime.make_allocator(problem, "round-robin"))
    assert session.choose().action_id == "pick(A)"
    session.report_refined(1)
    assert session.choose().action_id == "place(A,R2)"
    session.report_not_yet()
    assert session.choose().action_id == "pick(B)"
    session.report_not_yet()
    assert session.choose().action_id == "place(A,R1)"
    session.report_backtrack("pick(A)")
    state = session.state
    assert (state.refined[0], state.refined[1], state.spent[1]) == (0, 0, 0)  # both lost the grasp
    assert session.choose().action_id == "pick(A)"
    with pytest.raises(ontime.UsageError, match="no action 'pick\\(C\\)'"):
        session.report_backtrack("pick(C)")


class GraspWorld(ontime.World):
    """place(A,R1) fails with the first grasp and works with the second; nothing else is found."""

    def __init__(self):
        self.grasps = []

    def begin_episode(self, seed):
        self.grasps.append(0)

    def step(self, action, spent):
        if action == 0:
            self.grasps[-1] += 1
            return 1
        if action == 1:
            return 2 if self.grasps[-1] >= 2 else ("backtrack", 0)
        return None


def test_a_world_of_the_callers_own_can_backtrack():
    # Round-robin: pick(A), place(A,R2), pick(B), place(A,R1) backtracks, pick(A) again, pick(B),
    # place(A,R1) found at step 7 with 3 steps of execution: within the deadline of 12.
    problem = ontime.load_problem(EXAMPLE)
    world = GraspWorld()
    result = ontime.run_episodes(problem, world, "round-robin", episodes=3, threads=1)
    assert result["successes"] == 3 and world.grasps == [2, 2, 2]
