#!/usr/bin/env bash
# Sets up the machine, builds OnTime with warnings as errors and runs every test.
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
./scripts/build.sh -DONTIME_WARNINGS_AS_ERRORS=ON
ctest --test-dir build --parallel "$(nproc)" --output-on-failure
