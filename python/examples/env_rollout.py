"""Rollouts of a random policy that only takes useful choices (the action mask) in the
Gymnasium-style environment, against the allocators' exact values.

    PYTHONPATH=build/python /usr/bin/python3 python/examples/env_rollout.py [--episodes N] [--seed S]
"""

import argparse
import pathlib

import numpy as np

import ontime
from ontime.env import EffortAllocationEnv


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--episodes", type=int, default=2000)
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    path = pathlib.Path(__file__).resolve().parents[2] / "data" / "instances" / "paper" / "instance2.json"
    problem = ontime.load_problem(path)
    env = EffortAllocationEnv(problem, seed=args.seed)
    rng = np.random.default_rng(args.seed)
    successes = 0
    steps = 0
    observation, info = env.reset(seed=args.seed)
    for episode in range(args.episodes):
        if episode:
            observation, info = env.reset()
        while True:
            action = int(rng.choice(np.flatnonzero(info["action_mask"])))
            observation, reward, terminated, truncated, info = env.step(action)
            steps += 1
            if terminated or truncated:
                successes += int(reward)
                break
    rate = successes / args.episodes
    half_width = 1.96 * np.sqrt(rate * (1 - rate) / args.episodes)
    print(f"observation space {env.observation_space}, action space {env.action_space}")
    print(f"random masked policy: {rate:.4f} +- {half_width:.4f} over {args.episodes} episodes "
          f"({steps / args.episodes:.2f} steps per episode)")
    optimum = ontime.solve(problem)["optimal_success_probability"]
    dp_rerun = ontime.evaluate(problem, "dp-rerun", episodes=1, exact=True)["exact_success_probability"]
    print(f"exact: dp-rerun {dp_rerun:.4f}, optimum {optimum:.4f}")


if __name__ == "__main__":
    main()
