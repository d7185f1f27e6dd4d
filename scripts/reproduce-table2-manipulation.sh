#!/usr/bin/env bash
# Sets up the machine, builds OnTime, and reproduces the manipulation row of the paper's Table II
# on the project's own kitchen domain (docs/domains.md): collects 1,000 refinements of every
# action of the skeleton tree with OMPL RRT-Connect, KDL and FCL (deterministic collision-check
# effort, seed 1; an interrupted run is resumed from its checkpoint), writes
# data/logs/manipulation.jsonl, fits data/instances/manipulation.json (D = 40), draws the kitchen
# and the histograms into docs/images/, trains the ppo policy and prints the table with every
# allocator, exact values where they fit within --max-states, and the optimum's certified
# interval (the layered solver up to 110 million states a part: the whole tree stops at layer 14
# of 40, then the split enumerates the skeletons through move+pick(B3) and bounds the others).
# About 20 minutes on 2 cores (collection 8 min, ppo 1.5 min, table 8.5 min); peak 9.7 GB.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
./scripts/build.sh
build/ontime collect --domain manipulation --trials 1000 --seed 1 --resume
build/ontime plot data/instances/manipulation.json -o docs/images/manipulation-histograms.png
build/ontime map --domain manipulation --seed 1 -o docs/images/manipulation-map.png
build/ontime train data/instances/manipulation.json --solver ppo --episodes 10000 --seed 1 \
  --out build/policies/manipulation.json
build/ontime table data/instances/manipulation.json --solvers mcts,dp,dp-rerun,ppo,round-robin,greedy \
  --policy build/policies/manipulation.json --exact --episodes 2000 --max-states 110000000
