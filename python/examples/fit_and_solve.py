"""A planner log written from Python, fitted into an instance, and solved exactly.

A made-up planner whose planning times are log-normal (some attempts cut off at 8 s) refines the
moves of three routes; its records go to a log file, ontime.fit learns each move's distributions in
steps of one second, and the instance is solved and evaluated.

    PYTHONPATH=build/python /usr/bin/python3 python/examples/fit_and_solve.py [OUTPUT_DIR]
"""

import pathlib
import sys
import tempfile

import numpy as np

import ontime

SKELETONS = [["move(A,B)", "move(B,D)"], ["move(A,B)", "move(B,C)", "move(C,D)"], ["move(A,D)"]]
MEDIAN_SECONDS = {"move(A,B)": 1.5, "move(B,D)": 4.0, "move(B,C)": 1.0, "move(C,D)": 1.2, "move(A,D)": 6.0}
CUT_OFF = 8.0


def records(seed, attempts=300):
    rng = np.random.default_rng(seed)
    out = []
    for action, median in MEDIAN_SECONDS.items():
        for trial in range(attempts):
            seconds = float(median * rng.lognormal(0.0, 0.6))
            if seconds > CUT_OFF:
                out.append({"action": action, "planning_seconds": CUT_OFF, "found": False, "trial": trial})
            else:
                execution = float(rng.uniform(0.8, 1.6))
                out.append({"action": action, "planning_seconds": round(seconds, 3), "found": True,
                            "execution_seconds": round(execution, 3), "trial": trial})
    return out


def main():
    folder = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else pathlib.Path(tempfile.mkdtemp())
    log = folder / "planner-log.jsonl"
    ontime.write_planner_log(records(seed=7), log)
    problem = ontime.fit(log, step=1.0, deadline=12, skeletons=SKELETONS, name="three-routes")
    problem.save(folder / "three-routes.json")
    print(f"fitted {problem.name}: {len(problem.actions)} actions, {problem.skeleton_count} skeletons, "
          f"deadline {problem.deadline}")
    for action in problem.actions:
        print(f"  {action.id:10} planning: mean {action.planning.mean_finite():.2f} steps, "
              f"never {action.planning.never:.3f}")
    solved = ontime.solve(problem)
    print(f"optimum {solved['optimal_success_probability']:.4f}, first refine {solved['first_action']}")
    for solver in ("dp-rerun", "greedy", "round-robin"):
        value = ontime.evaluate(problem, solver, episodes=1, exact=True)["exact_success_probability"]
        print(f"  {solver:11} {value:.4f}")


if __name__ == "__main__":
    main()
