#!/usr/bin/env bash
# The calibration of the navigation domain (docs/domains.md): for a few settings of the step
# length and the nominal collision-checker speed, collects 200 trials per action into a scratch
# directory, fits the instance (D = 22) and prints the exact success of dp, dp-rerun and greedy
# and the sampled success of round-robin. Run from a built tree (./scripts/build.sh).
# Arguments: pairs STEP:CHECKS_PER_SECOND (default: the ones in docs/domains.md).
set -euo pipefail
cd "$(dirname "$0")/.."
settings=("$@")
if [ ${#settings[@]} -eq 0 ]; then settings=(3:1000 3:1200 3:1500 2.5:1200 3.5:1200); fi
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
value() { /usr/bin/python3 -c "import json,sys; print('%.3f' % json.load(sys.stdin)['$1'])"; }
echo "| step (s) | checks/s | dp | dp-rerun | greedy | round-robin (sampled) |"
echo "|----------|----------|----|----------|--------|-----------------------|"
for setting in "${settings[@]}"; do
  step=${setting%%:*}
  rate=${setting##*:}
  instance="$scratch/navigation-$step-$rate.json"
  build/ontime collect --domain navigation --trials 200 --seed 1 --step "$step" --checks-per-second "$rate" \
    --log "$scratch/log.jsonl" -o "$instance" > /dev/null
  row="| $step | $rate"
  for solver in dp dp-rerun greedy; do
    row="$row | $(build/ontime evaluate "$instance" --solver "$solver" --episodes 1000 --exact --json | value exact_success_probability)"
  done
  row="$row | $(build/ontime evaluate "$instance" --solver round-robin --episodes 10000 --json | value success_rate) |"
  echo "$row"
done
