"""Acting while planning (SPEC §10) from Python: the instance's mode, the exact optimum of the model
with `act=`, the same figures as the command line, and what does not take the mode yet."""

import json

import pytest

import ontime
from conftest import PAPER


def test_the_mode_is_the_instances_and_travels_with_its_copies():
    problem = ontime.load_problem(PAPER / "instance1.json")
    assert problem.acting == "plan-first"
    concurrent = problem.with_acting("concurrent")
    assert concurrent.acting == "concurrent"
    assert json.loads(concurrent.to_json())["acting"] == "concurrent"
    assert "acting" not in json.loads(problem.to_json())
    assert ontime.Problem.from_json(concurrent.to_json()).acting == "concurrent"


def test_the_optimum_of_acting_while_planning():
    problem = ontime.load_problem(PAPER / "instance1.json")
    plan_first = ontime.solve(problem, method="memoised")
    concurrent = ontime.solve(problem, act="concurrent")
    assert plan_first["optimal_success_probability"] == pytest.approx(0.942, abs=1e-12)
    assert concurrent["acting"] == "concurrent"
    assert concurrent["method"] == "memoised"
    assert concurrent["optimal_success_probability"] == pytest.approx(1.0, abs=1e-12)
    # The instance's own mode, and act= over it.
    marked = problem.with_acting("concurrent")
    assert ontime.solve(marked)["optimal_success_probability"] == concurrent["optimal_success_probability"]
    assert ontime.solve(marked, act="plan-first", method="memoised")["optimal_success_probability"] == \
        plan_first["optimal_success_probability"]
    # Fig. 1 and instance 4 gain nothing from acting while planning.
    for name in ("figure1", "instance4"):
        instance = PAPER / f"{name}.json"
        assert ontime.solve(instance, act="concurrent")["optimal_success_probability"] == pytest.approx(
            ontime.solve(instance, method="memoised")["optimal_success_probability"], abs=1e-12)


def test_the_search_gives_the_memoised_optimum_to_the_bit():
    instance = PAPER / "instance4.json"
    memoised = ontime.solve(instance, act="concurrent")
    search = ontime.solve(instance, act="concurrent", method="search")
    assert search["method"] == "search" and search["exact"]
    assert search["optimal_success_probability"] == memoised["optimal_success_probability"]
    assert search["first_choice"] == memoised["first_choice"]
    assert search["states"] < memoised["states"]
    cut = ontime.solve(instance, act="concurrent", method="search", gap=0.5)
    assert cut["lower_bound"] <= memoised["optimal_success_probability"] <= cut["upper_bound"]


def test_the_layered_solver_gives_the_memoised_optimum_to_the_bit(cli):
    instance = PAPER / "instance1.json"
    memoised = ontime.solve(instance, act="concurrent")
    layered = ontime.solve(instance, act="concurrent", method="layered", threads=2)
    assert layered["method"] == "layered" and layered["exact"]
    assert layered["optimal_success_probability"] == memoised["optimal_success_probability"]
    assert layered["first_choice"] == memoised["first_choice"]
    from_cli = cli("solve", str(instance), "--act", "concurrent", "--method", "layered", "--json", "--no-timing")
    assert {key: layered[key] for key in from_cli if key != "instance"} == \
        {key: value for key, value in from_cli.items() if key != "instance"}
    cut = ontime.solve(instance, act="concurrent", method="layered", max_states=1000)
    assert not cut["exact"] and cut["stopped_by"] == "the state cap"
    assert cut["lower_bound"] <= memoised["optimal_success_probability"] <= cut["upper_bound"]
    for refused in ({"tolerance": 0.1}, {"policy": "policy.jsonl"}, {"method": "split"},
                    {"method": "search", "max_memory_mib": 10}, {"method": "memoised", "max_disk_mib": 10}):
        arguments = {"method": "layered", **refused}
        with pytest.raises(ontime.UsageError, match="SPEC §10"):
            ontime.solve(instance, act="concurrent", **arguments)


def test_the_same_figures_as_the_command_line(cli):
    instance = PAPER / "instance2.json"
    from_cli = cli("solve", str(instance), "--act", "concurrent", "--json", "--no-timing")
    from_python = ontime.solve(str(instance), act="concurrent")
    assert from_python["optimal_success_probability"] == from_cli["optimal_success_probability"]
    assert from_python["states"] == from_cli["states"]
    assert from_python["first_choice"] == from_cli["first_choice"]


def test_backtracking_acting_while_planning_as_the_command_line(cli):
    """SPEC §7 with §10: the kitchen whose placements may blame their grasps gains by acting while
    planning; the search gives its optimum to the bit; dp-rerun takes it (Eq. (1) with its give-up
    term), at most the optimum."""
    kitchen = PAPER.parent / "kitchen-grasps.json"
    from_cli = cli("solve", str(kitchen), "--act", "concurrent", "--json", "--no-timing")
    concurrent = ontime.solve(kitchen, act="concurrent")
    assert concurrent["optimal_success_probability"] == from_cli["optimal_success_probability"]
    assert concurrent["optimal_success_probability"] > \
        ontime.solve(kitchen, method="memoised")["optimal_success_probability"] + 0.01
    search = ontime.solve(kitchen, act="concurrent", method="search")
    assert search["exact"] and search["optimal_success_probability"] == concurrent["optimal_success_probability"]
    assert search["first_choice"] == concurrent["first_choice"]
    exact = ontime.evaluate(kitchen, "optimal", act="concurrent", episodes=200, exact=True)
    assert exact["exact_success_probability"] == concurrent["optimal_success_probability"]
    dp_rerun = ontime.evaluate(kitchen, "dp-rerun", act="concurrent", episodes=10, exact=True)
    assert 0 < dp_rerun["exact_success_probability"] <= concurrent["optimal_success_probability"]


def test_chains_acting_while_planning_as_the_command_line(cli):
    """SPEC §9 with §10: the robot may wait at a door that locks at random; exact from Python as from
    the command line; its episodes (the session simulates the door) earn the optimum within 4
    standard errors; the search gives the memoised optimum to the bit on it (it has give-ups) and on
    the meeting instance (chains, no give-up)."""
    cup = PAPER.parent / "chains" / "cup-through-the-door.json"
    from_cli = cli("solve", str(cup), "--act", "concurrent", "--json", "--no-timing")
    concurrent = ontime.solve(cup, act="concurrent")
    assert concurrent["optimal_expected_reward"] == from_cli["optimal_expected_reward"]
    assert concurrent["optimal_expected_reward"] > \
        ontime.solve(cup, method="memoised")["optimal_expected_reward"] + 0.1
    episodes = 20000
    evaluated = ontime.evaluate(cup, "optimal", act="concurrent", episodes=episodes, seed=7, exact=True)
    optimum = concurrent["optimal_expected_reward"]
    assert evaluated["exact_expected_reward"] == pytest.approx(optimum, abs=1e-12)
    assert abs(evaluated["mean_reward"] - optimum) <= 4 * (optimum * (1 - optimum) / episodes) ** 0.5
    meeting = PAPER.parent / "chains" / "meeting-through-the-queue.json"
    for instance in (cup, meeting):
        memoised = ontime.solve(instance, act="concurrent")
        search = ontime.solve(instance, act="concurrent", method="search")
        assert search["exact"] and search["optimal_expected_reward"] == memoised["optimal_expected_reward"]


def test_dp_and_dp_rerun_with_chains_acting_while_planning_as_the_command_line(cli):
    """SPEC §10 with §9: dp and dp-rerun value a skeleton by its devoted optimum (waiting for the door
    when that pays); from Python the same exact values as from the command line, the optimum on the
    cup; a session
    of dp-rerun plays the cup in its simulated door and refuses the report of an execution it did not
    start; an aggregation other than self is refused naming the rule."""
    cup = PAPER.parent / "chains" / "cup-through-the-door.json"
    optimum = ontime.solve(cup, act="concurrent")["optimal_expected_reward"]
    for solver in ("dp", "dp-rerun"):
        got = ontime.evaluate(cup, solver, act="concurrent", episodes=100, seed=2, exact=True)
        expected = cli("evaluate", str(cup), "--act", "concurrent", "--solver", solver, "--episodes", "100", "--seed",
                       "2", "--exact", "--json", "--no-timing")
        assert got["exact_expected_reward"] == expected["exact_expected_reward"]
        assert got["exact_expected_reward"] == pytest.approx(optimum, abs=1e-12)
    session = ontime.ConcurrentSession(cup, "dp-rerun", seed=5)
    with pytest.raises(ontime.UsageError, match="was never started"):
        session.report_execution_finished("place(cup)@door")
    while session.status == ontime.Status.running:
        move = session.choose()
        if move["start"] is None:
            session.report_refined(1) if move["action"] is not None else session.report_not_yet()
    assert session.started[0] == "grasp(cup)"
    with pytest.raises(ontime.UsageError, match="has no form with chains or expiry"):
        ontime.evaluate(cup, "dp-rerun", act="concurrent", episodes=10, aggregation="sum")


@pytest.mark.parametrize("arguments, message", [
    ({"act": "interleaved"}, "act must be 'plan-first' or 'concurrent'"),
    ({"act": 1}, "act must be 'plan-first' or 'concurrent'"),
    ({"act": "concurrent", "method": "split"}, "method='memoised', 'search' or 'layered'"),
    ({"act": "concurrent", "gap": 0.1}, "gap is for method='search'"),
    ({"act": "concurrent", "tolerance": 0.1}, "for the plan-first layered solver"),
])
def test_bad_requests_raise_usage_errors(arguments, message):
    with pytest.raises(ontime.UsageError, match=message):
        ontime.solve(PAPER / "instance1.json", **arguments)


def test_evaluate_acts_while_planning_by_the_allocators_commit_rule(cli):
    instance = PAPER / "instance2.json"
    result = ontime.evaluate(instance, "round-robin", act="concurrent", episodes=4000, seed=5, exact=True)
    assert result["acting"] == "concurrent"
    assert result["commit_rule"].startswith("eager")
    assert result["exact_success_probability"] == pytest.approx(0.58, abs=1e-12)
    # The same counts as the command line, and from the problem's own mode.
    from_cli = cli("evaluate", str(instance), "--act", "concurrent", "--solver", "round-robin", "--episodes", "4000",
                   "--seed", "5", "--exact", "--json", "--no-timing")
    assert result["successes"] == from_cli["successes"]
    marked = ontime.load_problem(instance).with_acting("concurrent")
    assert ontime.evaluate(marked, "round-robin", episodes=4000, seed=5)["successes"] == result["successes"]
    # The optimum is certain on instance 1 (0.942 plan-first).
    first = ontime.evaluate(PAPER / "instance1.json", "optimal", act="concurrent", episodes=500, exact=True)
    assert first["successes"] == 500
    assert first["exact_success_probability"] == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize("arguments, message", [
    ({"solver": "ppo"}, "ppo needs a trained policy"),
    ({"solver": "thompson", "exact": True}, "exact evaluation needs an allocator whose move"),
    ({"solver": "dp-rerun", "act": "sometimes"}, "act must be 'plan-first' or 'concurrent'"),
])
def test_evaluate_refuses_what_acting_while_planning_does_not_take_yet(arguments, message):
    arguments = {"act": "concurrent", **arguments}
    solver = arguments.pop("solver")
    with pytest.raises(ontime.UsageError, match=message):
        ontime.evaluate(PAPER / "instance1.json", solver, episodes=10, **arguments)


def test_evaluate_with_a_belief_acting_while_planning_as_the_command_line(cli, tmp_path):
    # A belief in which instance 2's a1_1 is never found: it counts skeleton 1 hopeless.
    instance = PAPER / "instance2.json"
    data = json.loads(instance.read_text())
    data["actions"]["a1_1"]["planning"] = {"pmf": {}}
    belief = tmp_path / "belief.json"
    belief.write_text(json.dumps(data))
    result = ontime.evaluate(instance, "dp-rerun", act="concurrent", belief=belief, episodes=2000, seed=4, exact=True)
    from_cli = cli("evaluate", str(instance), "--act", "concurrent", "--solver", "dp-rerun", "--belief", str(belief),
                   "--episodes", "2000", "--seed", "4", "--exact", "--json", "--no-timing")
    assert result["belief"] == from_cli["belief"] == str(belief)
    assert result["successes"] == from_cli["successes"]
    assert result["exact_success_probability"] == from_cli["exact_success_probability"]
    plain = ontime.evaluate(instance, "dp-rerun", act="concurrent", episodes=2000, seed=4, exact=True)
    assert result["exact_success_probability"] < plain["exact_success_probability"] - 0.01
    # The instance itself as the belief: the same numbers as without one.
    same = ontime.evaluate(instance, "dp-rerun", act="concurrent", belief=instance, episodes=2000, seed=4, exact=True)
    assert same["successes"] == plain["successes"]
    assert same["exact_success_probability"] == plain["exact_success_probability"]


def test_regret_acting_while_planning_is_the_command_lines_and_holds_the_exact_regret(cli):
    # The same library call as `ontime evaluate --act concurrent --regret`: the same estimate; the
    # exact regret of round-robin (stationary) within twice its 95% half-width (3.92 standard errors).
    instance = PAPER / "instance2.json"
    result = ontime.evaluate(instance, "round-robin", act="concurrent", episodes=2000, seed=3, exact=True,
                             regret=True)
    from_cli = cli("evaluate", str(instance), "--act", "concurrent", "--solver", "round-robin", "--episodes", "2000",
                   "--seed", "3", "--exact", "--regret", "--json", "--no-timing")
    assert result["regret"] == from_cli["regret"]
    truth = result["regret"]["optimum"] - result["exact_success_probability"]  # (no rewards)
    assert truth > 0
    assert abs(result["regret"]["mean"] - truth) <= 2 * result["regret"]["ci95"] + 1e-9
    optimal = ontime.evaluate(instance, "optimal", act="concurrent", episodes=300, regret=True)
    assert optimal["regret"]["mean"] == pytest.approx(0.0, abs=1e-12)


def test_a_table_sets_both_modes_side_by_side_as_the_command_line(cli):
    instance = PAPER / "instance1.json"
    problem = ontime.load_problem(instance)
    got = ontime.table([problem, problem.with_acting("concurrent")], solvers=["dp-rerun", "greedy"], episodes=300,
                       exact=True)
    expected = cli("table", str(instance), "--act", "plan-first,concurrent", "--solvers", "dp-rerun,greedy",
                   "--episodes", "300", "--exact", "--json")
    assert [row.get("acting") for row in got["rows"]] == [None, "concurrent"]
    assert [row["optimal_success_probability"] for row in got["rows"]] == \
        [row["optimal_success_probability"] for row in expected["rows"]]
    assert got["rows"][1]["optimal_success_probability"] == pytest.approx(1.0, abs=1e-12)
    for name in ("dp-rerun", "greedy"):
        assert [row["solvers"][name]["successes"] if "successes" in row["solvers"][name] else
                row["solvers"][name]["success_rate"] for row in got["rows"]] == \
            [row["solvers"][name]["successes"] if "successes" in row["solvers"][name] else
             row["solvers"][name]["success_rate"] for row in expected["rows"]]
    markdown = ontime.table([problem.with_acting("concurrent")], solvers=["dp-rerun"], episodes=50, format="markdown")
    assert "paper-instance-1 (concurrent)" in markdown
    with pytest.raises(ontime.UsageError, match="ppo needs a trained policy"):
        ontime.table([problem.with_acting("concurrent")], solvers=["ppo"], episodes=10)


def test_what_does_not_take_the_mode_yet_refuses_it():
    concurrent = ontime.load_problem(PAPER / "instance1.json").with_acting("concurrent")
    with pytest.raises(ontime.UsageError, match="acts while planning"):
        ontime.make_allocator(concurrent, "dp-rerun")
    with pytest.raises(ontime.UsageError, match="acting must be"):
        concurrent.with_acting(None)


TWO_MOVES = {
    "deadline": 5,
    "actions": {"a": {"planning": {"pmf": {"1": 1}}, "execution": {"pmf": {"2": 1}}},
                "b": {"planning": {"pmf": {"2": 1}}, "execution": {"pmf": {"1": 1}}}},
    "skeletons": [["a", "b"]],
}


def two_moves():
    """a is found at 1 and runs 2; b is found 2 steps later and runs 1; deadline 5: plan-first fails
    (refined at 3, executed by 6), acting while planning finishes at 4."""
    return ontime.Problem.from_json(json.dumps(TWO_MOVES))


def test_a_session_of_the_callers_moves_walks_the_model():
    session = ontime.ConcurrentSession(two_moves())
    assert session.decide(refine=0) == {"start": None, "skeleton": 0, "action": "a"}
    session.report_refined(2)
    assert session.startable == ["a"]
    assert session.decide(start="a")["start"] == "a"
    assert (session.steps_used, session.robot_left) == (1, 2)
    session.decide(refine=0)
    session.report_not_yet()
    session.decide(refine=0)
    assert session.report_refined(1) == ontime.Status.running
    session.decide(start="b")
    assert session.status == ontime.Status.success
    assert (session.solution, session.finish, session.reward) == (0, 4, 1.0)
    assert session.started == ["a", "b"]


def test_a_robot_that_finishes_early_says_so_and_one_never_started_is_refused():
    session = ontime.ConcurrentSession(two_moves())
    session.decide(refine=0)
    session.report_refined(2)
    with pytest.raises(ontime.UsageError, match="was never started"):
        session.report_execution_finished("a")
    session.decide(start="a")
    session.decide(refine=0)
    session.report_not_yet()
    assert session.robot_left == 1
    session.report_execution_finished("a")
    assert session.robot_left == 0
    with pytest.raises(ontime.UsageError, match="was never started"):
        session.report_execution_finished("b")
    with pytest.raises(ontime.UsageError, match="no action 'c'"):
        session.report_execution_finished("c")


def test_an_allocators_session_earns_what_its_episodes_do():
    problem = ontime.load_problem(PAPER / "instance1.json")
    session = ontime.ConcurrentSession(problem, "dp-rerun", seed=3)
    moves = 0
    while session.status == ontime.Status.running:
        move = session.choose()
        moves += 1
        if move["start"] is None:
            session.report_refined(1) if move["action"] is not None else session.report_not_yet()
    assert session.status == ontime.Status.success
    assert moves > 1
    assert len(session.started) >= 1


@pytest.mark.parametrize("call, message", [
    (lambda s: s.decide(start="a", refine=0), "not both"),
    (lambda s: s.decide(start="a"), "cannot be started now"),
    (lambda s: s.decide(refine=3), "no skeleton 3"),
    (lambda s: s.decide(refine="0"), "a skeleton's index"),
    (lambda s: s.report_not_yet(), "no step awaits its report"),
    (lambda s: s.report_refined(-1), "execution_steps"),
    (lambda s: s.choose(), "no allocator"),
])
def test_moves_and_reports_out_of_rule_raise_usage_errors(call, message):
    with pytest.raises(ontime.UsageError, match=message):
        call(ontime.ConcurrentSession(two_moves()))


def test_a_session_refuses_allocators_without_a_commit_rule():
    with pytest.raises(ontime.UsageError, match="ppo needs a trained policy"):
        ontime.ConcurrentSession(two_moves(), "ppo")
    with pytest.raises(ontime.UsageError, match="need a solver"):
        ontime.ConcurrentSession(two_moves(), budget=4)


def test_ppo_trained_acting_while_planning_drives_concurrent_episodes(cli, tmp_path):
    # train_ppo(act='concurrent') writes the command line's policy, byte for byte; evaluate takes it
    # acting while planning with the exact value the command line prints, and refuses it plan-first.
    instance = PAPER / "instance2.json"
    policy = tmp_path / "py.json"
    curve = ontime.train_ppo(instance, policy, episodes=200, seed=2, act="concurrent")
    assert curve[-1]["episodes"] == 200
    trained = cli("train", instance, "--act", "concurrent", "--episodes", 200, "--seed", 2, "--out",
                  tmp_path / "cli.json", "--no-plot", "--json")
    assert policy.read_bytes() == (tmp_path / "cli.json").read_bytes()
    assert json.loads(policy.read_text())["acting"] == "concurrent"
    result = ontime.evaluate(instance, "ppo", act="concurrent", policy=str(policy), episodes=400, seed=3, exact=True)
    assert result["exact_success_probability"] == trained["exact_success_probability"]
    assert result["exact_success_probability"] <= ontime.solve(instance, act="concurrent")[
        "optimal_success_probability"] + 1e-12
    with pytest.raises(ontime.UsageError, match=r"trained acting while planning .*not plan-first \(SPEC §10\)"):
        ontime.evaluate(instance, "ppo", policy=str(policy), episodes=10)
