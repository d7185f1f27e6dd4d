#!/usr/bin/env bash
# Sets up the machine, builds OnTime and reproduces the paper's Table I on its five instances:
# sampled success (10,000 episodes, mean ± 95%) and exact success of each allocator, and the
# exact optimum of each instance.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
./scripts/build.sh
build/ontime table data/instances/paper/instance{1,2,3,4,5}.json --exact
