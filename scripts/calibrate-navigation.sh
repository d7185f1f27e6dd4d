#!/usr/bin/env bash
# The calibration of the navigation domain (docs/domains.md): for a few settings of the step
# length and the nominal collision-checker speed, collects 200 trials per action and prints the
# exact success of dp, dp-rerun and greedy and the sampled success of round-robin (D = 22).
# Run from a built tree (./scripts/build.sh).
# Arguments: pairs STEP:CHECKS_PER_SECOND (default: the ones in docs/domains.md).
set -euo pipefail
cd "$(dirname "$0")/.."
settings=("$@")
if [ ${#settings[@]} -eq 0 ]; then settings=(3:1000 3:1200 3:1500 2.5:1200 3.5:1200); fi
exec ./scripts/calibrate-domain.sh navigation 200 "${settings[@]}"
