#!/usr/bin/env bash
# Sets up the machine, builds OnTime, and reproduces the navigation row of the paper's Table II
# on the project's own navigation domain (docs/domains.md): collects 1,000 refinements of every
# action of the skeleton tree with OMPL RRT-Connect (deterministic collision-check effort,
# seed 1), writes data/logs/navigation.jsonl, fits data/instances/navigation.json (D = 22),
# draws the map and the histograms into docs/images/, trains the ppo policy and prints the table
# with every allocator, exact values and the exact optimum. About 7 minutes on 2 cores (the
# table 5 minutes); the exact parts need up to 3.3 GB of memory.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
./scripts/build.sh
build/ontime collect --domain navigation --trials 1000 --seed 1
build/ontime plot data/instances/navigation.json -o docs/images/navigation-histograms.png
build/ontime map --domain navigation --seed 1 -o docs/images/navigation-map.png
build/ontime train data/instances/navigation.json --solver ppo --episodes 10000 --seed 1 \
  --out build/policies/navigation.json
build/ontime table data/instances/navigation.json --solvers mcts,dp,dp-rerun,ppo,round-robin,greedy \
  --policy build/policies/navigation.json --exact --max-states 58000000
