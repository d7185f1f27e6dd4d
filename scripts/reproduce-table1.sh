#!/usr/bin/env bash
# Sets up the machine, builds OnTime and reproduces the paper's Table I on its five instances:
# every allocator's sampled success (10,000 episodes, mean ± 95%) and exact success where its
# choices depend on the state alone, the exact optimum of each instance, and the mean decision
# time. The ppo column needs trained policies: they are trained first (10,000 episodes each,
# seed 1), which the paper's setup also did.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
./scripts/build.sh
instances=()
policies=()
mkdir -p build/policies
for i in 1 2 3 4 5; do
  instances+=("data/instances/paper/instance$i.json")
  policies+=(--policy "build/policies/instance$i.json")
  build/ontime train "data/instances/paper/instance$i.json" --solver ppo --episodes 10000 --seed 1 \
    --out "build/policies/instance$i.json" --no-plot
done
build/ontime table "${instances[@]}" --solvers mcts,dp,dp-rerun,ppo,round-robin,greedy,thompson "${policies[@]}" --exact
