"""Table I of the paper, exact: every stationary allocator's success probability and the optimum on
the paper's five instances, computed without sampling.

    PYTHONPATH=build/python /usr/bin/python3 python/examples/table1_exact.py [INSTANCE_DIR]
"""

import pathlib
import sys

import ontime

SOLVERS = ["dp", "dp-rerun", "greedy", "round-robin"]


def main():
    root = pathlib.Path(sys.argv[1]) if len(sys.argv) > 1 else \
        pathlib.Path(__file__).resolve().parents[2] / "data" / "instances" / "paper"
    print("instance  " + "  ".join(f"{name:>11}" for name in SOLVERS + ["optimum"]))
    for index in range(1, 6):
        problem = ontime.load_problem(root / f"instance{index}.json")
        values = [ontime.evaluate(problem, solver, episodes=1, exact=True)["exact_success_probability"]
                  for solver in SOLVERS]
        values.append(ontime.solve(problem)["optimal_success_probability"])
        print(f"{index:>8}  " + "  ".join(f"{value:>11.4f}" for value in values))


if __name__ == "__main__":
    main()
