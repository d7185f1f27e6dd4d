"""The domain commands and their Python counterparts are one library function each: for the same
arguments, ontime.domains.tamp, map_data, generate_world, run and collect_and_fit give what `ontime
tamp`, `map`, `generate-world`, `run` and `collect` print or write, number for number (all but the
run's own duration)."""

import json

import pytest

import ontime
from conftest import SOURCE_DIR

pytestmark = pytest.mark.skipif(not ontime.domains.available, reason="built without the domains")

NAVIGATION = str(SOURCE_DIR / "data" / "domains" / "navigation.json")
NAVIGATION_MODEL = str(SOURCE_DIR / "data" / "instances" / "navigation.json")
BUILDING = str(SOURCE_DIR / "data" / "domains" / "building-6x5.json")
BUILDING_MOVES = str(SOURCE_DIR / "data" / "instances" / "building-6x5-moves.json")
KITCHEN_GRASPS = str(SOURCE_DIR / "data" / "domains" / "kitchen-grasps.json")
KITCHEN_GRASPS_MODEL = str(SOURCE_DIR / "data" / "instances" / "kitchen-grasps.json")


def without(result, *keys):
    return {key: value for key, value in result.items() if key not in keys}


def test_tamp_on_the_modelled_clock_matches_the_cli(cli, tmp_path):
    # A few episodes of the TAMP loop on the 30-room building: with the modelled clock every charge
    # is the same, whichever process runs them.
    picture = tmp_path / "episode.png"
    expected = cli("tamp", "--world", BUILDING, "--library", BUILDING_MOVES, "--deadline", 150, "--solver", "dp-rerun",
                   "--episodes", 3, "--threads", 2, "--max-skeletons", 3, "--seed", 5, "--clock", "model",
                   "--picture", picture, "--picture-episode", 1, "--no-plot", "--json")
    building = ontime.domains.load("navigation", BUILDING)
    got = ontime.domains.tamp(building, BUILDING_MOVES, "dp-rerun", 150, episodes=3, threads=1, max_skeletons=3,
                              seed=5, clock="model", picture_episode=1)
    assert without(got, "seconds", "picture") == without(expected, "seconds")
    assert got["clock"] == "model" and got["deadline_steps"] == 50 and len(got["episode_results"]) == 3
    assert got["successes"] >= 1 and got["refinements_started"] > 0
    assert got["picture"]["episode"] == 1
    assert got["picture"]["drawing"] == json.loads((tmp_path / "episode.json").read_text())
    assert got["picture"]["timeline_csv"] == (tmp_path / "episode-timeline.csv").read_text()
    drawing = got["picture"]["drawing"]
    assert drawing["skeletons"] and all(len(skeleton["points"]) >= 3 for skeleton in drawing["skeletons"])
    assert drawing["motions"] and (got["episode_results"][1]["status"] == "success") == any(
        skeleton["executed"] for skeleton in drawing["skeletons"])


def test_tamp_that_learns_across_episodes_matches_the_cli(cli):
    # Two sequences of three episodes, each planning with the library updated by the sequence's
    # attempts so far: the same successes by episode from both.
    expected = cli("tamp", "--world", BUILDING, "--library", BUILDING_MOVES, "--deadline", 150, "--solver", "dp-rerun",
                   "--episodes", 3, "--sequences", 2, "--adapt-strength", 5, "--threads", 2, "--max-skeletons", 3,
                   "--seed", 5, "--clock", "model", "--json")
    building = ontime.domains.load("navigation", BUILDING)
    got = ontime.domains.tamp(building, BUILDING_MOVES, "dp-rerun", 150, episodes=3, sequences=2, adapt_strength=5,
                              threads=1, max_skeletons=3, seed=5, clock="model")
    assert without(got, "seconds") == without(expected, "seconds")
    adaptation = got["adaptation"]
    assert adaptation["sequences"] == 2 and adaptation["episodes_per_sequence"] == 3 and adaptation["strength"] == 5
    assert len(adaptation["by_episode"]) == 3 and got["episodes"] == 6
    assert sum(e["successes"] for e in adaptation["by_episode"]) == got["successes"]
    # The first episode of each sequence plans with the library itself: episodes 0 and 3 of a run
    # without learning.
    plain = ontime.domains.tamp(building, BUILDING_MOVES, "dp-rerun", 150, episodes=6, threads=1, max_skeletons=3,
                                seed=5, clock="model")
    for first in (0, 3):
        assert got["episode_results"][first] == plain["episode_results"][first]


def test_tamp_that_learns_in_a_kitchen_that_backtracks_matches_the_cli(cli):
    # The kitchen whose refinements give up and blame the grasp (docs/spec.md section 7), its fitted
    # library (planning and backtracking of move+place(B1,S) take all its mass) a prior of strength
    # 10: the believed libraries used to be refused ("planning and backtrack probabilities sum above
    # 1"); now the sequences run and give the command line's numbers.
    expected = cli("tamp", "--domain", "manipulation", "--world", KITCHEN_GRASPS, "--library", KITCHEN_GRASPS_MODEL,
                   "--deadline", 280, "--solver", "dp-rerun", "--episodes", 3, "--sequences", 2, "--adapt-strength", 10,
                   "--threads", 2, "--clock", "model", "--json")
    kitchen = ontime.domains.load("manipulation", KITCHEN_GRASPS)
    got = ontime.domains.tamp(kitchen, KITCHEN_GRASPS_MODEL, "dp-rerun", 280, episodes=3, sequences=2,
                              adapt_strength=10, threads=1, clock="model")
    assert without(got, "seconds") == without(expected, "seconds")
    assert got["backtracks"] > 0 and got["episodes"] == 6
    assert sum(e["successes"] for e in got["adaptation"]["by_episode"]) == got["successes"]
    plain = ontime.domains.tamp(kitchen, KITCHEN_GRASPS_MODEL, "dp-rerun", 280, episodes=6, threads=1, clock="model")
    for first in (0, 3):
        assert got["episode_results"][first] == plain["episode_results"][first]


def test_tamp_refuses_what_the_cli_refuses():
    building = ontime.domains.load("navigation", BUILDING)
    with pytest.raises(ontime.UsageError, match="^deadline 2: 0 steps of 3 s"):
        ontime.domains.tamp(building, BUILDING_MOVES, "dp-rerun", 2)
    with pytest.raises(ontime.UsageError, match="clock model needs effort checks"):
        ontime.domains.tamp(building, BUILDING_MOVES, "dp-rerun", 45, clock="model", effort="wall")
    with pytest.raises(ontime.UsageError, match="need clock='model'"):
        ontime.domains.tamp(building, BUILDING_MOVES, "dp-rerun", 45, decision_seconds=0.001)
    with pytest.raises(ontime.UsageError, match="picture_episode 3: the run has episodes 0 to 2"):
        ontime.domains.tamp(building, BUILDING_MOVES, "dp-rerun", 45, episodes=3, picture_episode=3)
    with pytest.raises(ontime.UsageError, match="sequences needs adapt_strength"):
        ontime.domains.tamp(building, BUILDING_MOVES, "dp-rerun", 45, sequences=2)
    with pytest.raises(ontime.UsageError, match="picture_episode is not taken with adapt_strength"):
        ontime.domains.tamp(building, BUILDING_MOVES, "dp-rerun", 45, adapt_strength=5, picture_episode=0)
    paper = str(SOURCE_DIR / "data" / "instances" / "paper" / "instance1.json")
    with pytest.raises(ontime.InputError, match=r"instance1.json: actions: no action 'move\(R1,"):
        ontime.domains.tamp(building, paper, "dp-rerun", 45)


def test_run_refuses_an_instance_whose_actions_are_not_the_worlds():
    """Before any episode, as the command line does (exit 2 there), in either acting mode."""
    navigation = ontime.domains.load("navigation", NAVIGATION)
    paper = str(SOURCE_DIR / "data" / "instances" / "paper" / "instance1.json")
    for act in ("plan-first", "concurrent"):
        with pytest.raises(ontime.InputError, match=r"instance1.json: actions\.\S+: not an action of the world"):
            ontime.domains.run(navigation, paper, "greedy", episodes=2, act=act)


def test_map_data_is_the_drawing_the_cli_writes(cli, tmp_path):
    png = tmp_path / "map.png"
    done = cli("map", "--domain", "navigation", "--world", NAVIGATION, "--seed", 2, "-o", png, expect_json=False)
    assert done.returncode == 0, done.stderr
    got = ontime.domains.map_data(ontime.domains.load("navigation", NAVIGATION), seed=2)
    assert got == json.loads((tmp_path / "map.json").read_text())
    assert len(got["paths"]) == 4 and got["title"].endswith("(seed 2)")


def test_generate_world_writes_the_clis_file(cli, tmp_path):
    expected = cli("generate-world", "--rows", 3, "--cols", 4, "--door-density", 1, "--seed", 2, "-o",
                   tmp_path / "cli.json", "--json")
    got = ontime.domains.generate_world(tmp_path / "python.json", rows=3, cols=4, door_density=1, seed=2)
    assert (tmp_path / "python.json").read_bytes() == (tmp_path / "cli.json").read_bytes()
    assert without(got, "output") == without(expected, "output")
    assert (got["name"], got["rooms"], got["doors"]) == ("building-3x4", 12, 17)
    # Without --json, the summary line the report writes as text.
    text = cli("generate-world", "-o", tmp_path / "default.json", expect_json=False).stdout
    default = ontime.domains.generate_world(tmp_path / "default-python.json")
    assert text == (f"Wrote {tmp_path / 'default.json'}: {default['rooms']} rooms, {default['doors']} doors, "
                    f"{default['furniture']} pieces of furniture; start in {default['start_room']}, goal "
                    f"{default['goal_room']}.\n")
    with pytest.raises(ontime.UsageError, match="at least two rooms"):
        ontime.domains.generate_world(tmp_path / "never.json", rows=1, cols=1)
    with pytest.raises(ontime.UsageError, match="parameter 'rows'"):
        ontime.domains.generate_world(tmp_path / "never.json", rows=0)
    assert not (tmp_path / "never.json").exists()


def test_generate_world_writes_the_clis_kitchen(cli, tmp_path):
    expected = cli("generate-world", "--domain", "manipulation", "--tables", 3, "--targets", 1, "--min-objects", 3,
                   "--max-objects", 4, "--classes", "cup,bottle", "--seed", 4, "-o", tmp_path / "cli.json", "--json")
    got = ontime.domains.generate_world(tmp_path / "python.json", domain="manipulation", tables=3, targets=1,
                                        min_objects=3, max_objects=4, classes=["cup", "bottle"], seed=4)
    assert (tmp_path / "python.json").read_bytes() == (tmp_path / "cli.json").read_bytes()
    assert without(got, "output") == without(expected, "output")
    assert (got["name"], got["tables"], len(got["goal"])) == ("kitchen", 3, 1)
    kitchen = ontime.domains.load("manipulation", tmp_path / "python.json")
    assert len(kitchen.skeletons) == got["skeletons"]
    with pytest.raises(ontime.UsageError, match=r"^min_objects \(5\) must not exceed max_objects \(4\)$"):
        ontime.domains.generate_world(tmp_path / "never.json", domain="manipulation", min_objects=5, max_objects=4)
    with pytest.raises(ontime.UsageError, match="parameter 'tables'"):
        ontime.domains.generate_world(tmp_path / "never.json", domain="manipulation", tables=0)
    with pytest.raises(ontime.UsageError, match="rows is not an option of the manipulation generator"):
        ontime.domains.generate_world(tmp_path / "never.json", domain="manipulation", rows=3)
    with pytest.raises(ontime.UsageError, match="domain must be 'navigation' or 'manipulation'"):
        ontime.domains.generate_world(tmp_path / "never.json", domain="garden")
    assert not (tmp_path / "never.json").exists()


def test_run_matches_the_cli(cli):
    expected = cli("run", "--domain", "navigation", "--world", NAVIGATION, "--instance", NAVIGATION_MODEL, "--solver",
                   "dp-rerun", "--episodes", 4, "--threads", 2, "--seed", 3, "--exact", "--json")
    nav = ontime.domains.load("navigation", NAVIGATION)
    got = ontime.domains.run(nav, NAVIGATION_MODEL, "dp-rerun", episodes=4, threads=1, seed=3, exact=True)
    assert without(got, "seconds") == without(expected, "seconds")
    assert got["live"] is False and "model_exact_success_probability" in got
    # Live episodes: the same fields, every episode with its timeline.
    live_expected = cli("run", "--domain", "navigation", "--world", NAVIGATION, "--instance", NAVIGATION_MODEL,
                        "--solver", "dp-rerun", "--episodes", 2, "--threads", 1, "--live", "--json")
    live = ontime.domains.run(nav, NAVIGATION_MODEL, "dp-rerun", episodes=2, threads=1, live=True)
    assert list(live) == list(live_expected)
    assert len(live["episode_results"]) == 2 and all(episode["timeline"] for episode in live["episode_results"])


def test_run_acting_while_planning_matches_the_cli(cli):
    expected = cli("run", "--domain", "navigation", "--world", NAVIGATION, "--instance", NAVIGATION_MODEL, "--solver",
                   "dp-rerun", "--episodes", 6, "--threads", 2, "--seed", 3, "--exact", "--act", "concurrent",
                   "--json")
    nav = ontime.domains.load("navigation", NAVIGATION)
    got = ontime.domains.run(nav, NAVIGATION_MODEL, "dp-rerun", episodes=6, threads=1, seed=3, exact=True,
                             act="concurrent")
    assert without(got, "seconds") == without(expected, "seconds")
    assert got["acting"] == "concurrent"
    # The model's value of acting while planning is above planning first.
    plan_first = ontime.domains.run(nav, NAVIGATION_MODEL, "dp-rerun", episodes=1, exact=True)
    assert got["model_exact_success_probability"] > plan_first["model_exact_success_probability"] + 0.2
    # Live, on the robot's clock: the fields of the CLI's, every episode with its timeline and the
    # robot's executions, one per start of the timeline, one at a time.
    live_expected = cli("run", "--domain", "navigation", "--world", NAVIGATION, "--instance", NAVIGATION_MODEL,
                        "--solver", "dp-rerun", "--episodes", 2, "--threads", 1, "--live", "--act", "concurrent",
                        "--json")
    live = ontime.domains.run(nav, NAVIGATION_MODEL, "dp-rerun", episodes=2, threads=1, live=True, act="concurrent")
    assert list(live) == list(live_expected)
    assert "step_clock_successes" not in live
    for episode in live["episode_results"]:
        started = [step["started"] for step in episode["timeline"] if "started" in step]
        assert started == [execution["action"] for execution in episode["executions"]]
        ends = [0.0] + [execution["end"] for execution in episode["executions"]]
        assert all(execution["start"] >= end for execution, end in zip(episode["executions"], ends))


def test_run_with_a_belief_in_a_world_that_backtracks_matches_the_cli(cli, tmp_path):
    # The same log read without its backtracks: the allocator's belief; the world's places give up.
    with open(KITCHEN_GRASPS_MODEL, encoding="utf-8") as text:
        model = json.load(text)
    for action in model["actions"].values():
        action.pop("backtrack", None)
        action.pop("culprits", None)
    belief = tmp_path / "ignorant.json"
    belief.write_text(json.dumps(model), encoding="utf-8")
    expected = cli("run", "--domain", "manipulation", "--world", KITCHEN_GRASPS, "--instance", KITCHEN_GRASPS_MODEL,
                   "--belief", belief, "--solver", "dp-rerun", "--episodes", 3, "--threads", 1, "--seed", 2, "--json")
    kitchen = ontime.domains.load("manipulation", KITCHEN_GRASPS)
    got = ontime.domains.run(kitchen, KITCHEN_GRASPS_MODEL, "dp-rerun", episodes=3, threads=1, seed=2,
                             belief=str(belief))
    assert without(got, "seconds") == without(expected, "seconds")
    assert got["belief"] == str(belief)
    with pytest.raises(ontime.UsageError, match="belief: the deadlines differ"):
        ontime.domains.run(kitchen, KITCHEN_GRASPS_MODEL, "dp-rerun", episodes=1, belief=NAVIGATION_MODEL)


def test_collect_and_fit_writes_the_clis_files(cli, tmp_path):
    arguments = dict(trials=2, seed=4, threads=2)
    expected = cli("collect", "--domain", "navigation", "--world", NAVIGATION, "--trials", 2, "--seed", 4,
                   "--threads", 2, "--log", tmp_path / "cli.jsonl", "-o", tmp_path / "cli.json", "--json")
    nav = ontime.domains.load("navigation", NAVIGATION)
    got = ontime.domains.collect_and_fit(nav, tmp_path / "python.jsonl", tmp_path / "python.json", **arguments)
    assert without(got, "seconds", "log", "instance") == without(expected, "seconds", "log", "instance")
    assert (tmp_path / "python.jsonl").read_bytes() == (tmp_path / "cli.jsonl").read_bytes()
    assert (tmp_path / "python.json").read_bytes() == (tmp_path / "cli.json").read_bytes()
    assert not (tmp_path / "python.jsonl.checkpoint").exists()
    # The records collect() returns are the same log.
    records = ontime.domains.collect(nav, **arguments)
    assert len(records) == got["attempts"] == expected["attempts"]
    ontime.write_planner_log(records, tmp_path / "records.jsonl")
    assert (tmp_path / "records.jsonl").read_bytes() == (tmp_path / "cli.jsonl").read_bytes()
