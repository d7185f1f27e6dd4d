"""Every example runs and prints what docs/python.md says it prints."""

import re
import subprocess
import sys

import pytest

from conftest import SOURCE_DIR

EXAMPLES = SOURCE_DIR / "python" / "examples"


def run(name, *args):
    done = subprocess.run([sys.executable, str(EXAMPLES / name), *map(str, args)], capture_output=True, text=True,
                          timeout=300, check=False)
    assert done.returncode == 0, done.stderr
    return done.stdout.splitlines()


def test_table1_exact_prints_the_exact_values_of_table_one():
    lines = run("table1_exact.py")
    assert lines[0].split() == ["instance", "dp", "dp-rerun", "greedy", "round-robin", "optimum"]
    assert lines[1:] == [
        "       1       0.9340       0.9400       0.9200       0.3651       0.9420",
        "       2       0.6500       0.6900       0.6500       0.5100       0.7200",
        "       3       0.3500       0.6763       0.3500       0.6763       0.6763",
        "       4       0.9000       0.9000       0.5500       0.4500       0.9000",
        "       5       0.3300       0.6992       0.3300       0.6992       0.6992",
    ]


def test_env_rollout_prints_the_random_masked_policy_below_the_optimum():
    lines = run("env_rollout.py", "--episodes", 2000, "--seed", 1)
    assert lines[0] == "observation space Box(0.0, 1.1111111640930176, (7,), float32), action space Discrete(2)"
    assert lines[1] == "random masked policy: 0.6070 +- 0.0214 over 2000 episodes (4.67 steps per episode)"
    assert lines[2] == "exact: dp-rerun 0.6900, optimum 0.7200"


def test_fit_and_solve_prints_the_fitted_instance_and_its_values(tmp_path):
    lines = run("fit_and_solve.py", tmp_path)
    assert lines[0] == "fitted three-routes: 5 actions, 3 skeletons, deadline 12"
    assert lines[6] == "optimum 0.8768, first refine move(A,B)"
    assert lines[7:] == ["  dp-rerun    0.8699", "  greedy      0.6767", "  round-robin 0.2704"]
    assert (tmp_path / "planner-log.jsonl").exists() and (tmp_path / "three-routes.json").exists()


def test_online_rrt_drives_a_session_to_an_outcome():
    lines = run("online_rrt.py", "--seed", 1)
    assert re.fullmatch(r"model: 2 skeletons, deadline 40 steps of 0\.01 s; dp-rerun expects success 0\.\d{3}",
                        lines[0])
    for line in lines[1:-1]:
        assert re.fullmatch(r"step +\d+: move\([SQPG],[SQPG]\) refined, executes in \d+ steps", line), line
    assert re.fullmatch(r"(success: move\(S,[PQ]\) -> move\([PQ],G\) refined after \d+ steps \([\d.]+ s of "
                        r"planning\)|failure: no route refined in time \(\d+ steps, [\d.]+ s\))", lines[-1])
