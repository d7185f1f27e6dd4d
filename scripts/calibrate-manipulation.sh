#!/usr/bin/env bash
# The calibration of the manipulation domain (docs/domains.md): for a few settings of the step
# length and the nominal collision-checker speed, collects 100 trials per action and prints the
# exact success of dp, dp-rerun and greedy and the sampled success of round-robin (D = 40).
# Run from a built tree (./scripts/build.sh); a few minutes per setting on 2 cores.
# Arguments: pairs STEP:CHECKS_PER_SECOND (default: the ones in docs/domains.md).
set -euo pipefail
cd "$(dirname "$0")/.."
settings=("$@")
if [ ${#settings[@]} -eq 0 ]; then settings=(6:250 6:300 7:225 7:250 7:275 8:250); fi
exec ./scripts/calibrate-domain.sh manipulation 100 "${settings[@]}"
