#!/usr/bin/env bash
# Calibration of a domain's collection settings (docs/domains.md): for each STEP:CHECKS_PER_SECOND
# pair, collects TRIALS trials per action into a scratch directory, fits the instance (the world
# file's deadline) and prints a Markdown row with the exact success of dp, dp-rerun and greedy and
# the sampled success of round-robin (whose exact evaluation can need tens of millions of states).
# Run from a built tree (./scripts/build.sh). Usage: calibrate-domain.sh DOMAIN TRIALS STEP:RATE...
set -euo pipefail
cd "$(dirname "$0")/.."
domain=$1
trials=$2
shift 2
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
value() { /usr/bin/python3 -c "import json,sys; print('%.3f' % json.load(sys.stdin)['$1'])"; }
echo "| step (s) | checks/s | dp | dp-rerun | greedy | round-robin (sampled) |"
echo "|----------|----------|----|----------|--------|-----------------------|"
for setting in "$@"; do
  step=${setting%%:*}
  rate=${setting##*:}
  instance="$scratch/$domain-$step-$rate.json"
  build/ontime collect --domain "$domain" --trials "$trials" --seed 1 --step "$step" --checks-per-second "$rate" \
    --log "$scratch/log.jsonl" -o "$instance" > /dev/null
  row="| $step | $rate"
  for solver in dp dp-rerun greedy; do
    row="$row | $(build/ontime evaluate "$instance" --solver "$solver" --episodes 1000 --exact --json | value exact_success_probability)"
  done
  row="$row | $(build/ontime evaluate "$instance" --solver round-robin --episodes 10000 --json | value success_rate) |"
  echo "$row"
done
