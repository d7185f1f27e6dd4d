"""Speed of the Python bindings (Release build), against the targets of docs/performance.md:

  - a dp-rerun decision through Session.choose() + report_*() on instance 1 (median per decision);
  - EffortAllocationEnv.step (median per step);
  - ontime.evaluate(..., episodes=100000) against `ontime evaluate` for the same work.

    PYTHONPATH=build/python /usr/bin/python3 bench/python_bench.py [--cli build/ontime]
"""

import argparse
import json
import pathlib
import statistics
import subprocess
import time

import ontime
from ontime.env import EffortAllocationEnv

ROOT = pathlib.Path(__file__).resolve().parents[1]
INSTANCE = ROOT / "data" / "instances" / "paper" / "instance1.json"


def session_decisions(problem, episodes=20_000):
    allocator = ontime.make_allocator(problem, "dp-rerun")
    clock = time.perf_counter_ns
    running = ontime.Status.running
    times = []
    for episode in range(episodes):
        session = ontime.Session(allocator, seed=episode)
        while session.status == running:
            started = clock()
            decision = session.choose()
            if (episode + decision.skeleton) % 3:
                session.report_not_yet()
            else:
                session.report_refined(1)
            times.append(clock() - started)
    return statistics.median(times), len(times)


def environment_steps(problem, episodes=20_000):
    env = EffortAllocationEnv(problem, seed=1)
    clock = time.perf_counter_ns
    times = []
    env.reset(seed=1)
    for episode in range(episodes):
        if episode:
            env.reset()
        action = 0
        while True:
            started = clock()
            _, _, terminated, _, info = env.step(action)
            times.append(clock() - started)
            if terminated:
                break
            action = 1 - action if info["action_mask"][1 - action] else action
    return statistics.median(times), len(times)


def evaluate_against_cli(cli, episodes=100_000, repeats=5):
    python_seconds, cli_seconds = [], []
    for _ in range(repeats):
        started = time.perf_counter()
        ontime.evaluate(str(INSTANCE), "dp-rerun", episodes=episodes, seed=1, threads=1)
        python_seconds.append(time.perf_counter() - started)
        started = time.perf_counter()
        out = subprocess.run([cli, "evaluate", str(INSTANCE), "--solver", "dp-rerun", "--episodes", str(episodes),
                              "--seed", "1", "--threads", "1", "--json"], capture_output=True, text=True, check=True)
        cli_seconds.append(time.perf_counter() - started)
        json.loads(out.stdout)
    return min(python_seconds), min(cli_seconds)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cli", default=str(ROOT / "build" / "ontime"))
    args = parser.parse_args()
    problem = ontime.load_problem(INSTANCE)
    median, count = session_decisions(problem)
    print(f"session decision (choose + report, dp-rerun, instance 1): median {median / 1000:.3f} us over {count}")
    median, count = environment_steps(problem)
    print(f"EffortAllocationEnv.step (instance 1): median {median / 1000:.3f} us over {count}")
    python_seconds, cli_seconds = evaluate_against_cli(args.cli)
    print(f"evaluate 100000 episodes, 1 thread: python {python_seconds:.3f} s, cli {cli_seconds:.3f} s "
          f"(process start included), ratio {python_seconds / cli_seconds:.3f}")


if __name__ == "__main__":
    main()
