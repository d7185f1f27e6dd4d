#!/usr/bin/env bash
# Configures and builds OnTime (Release) in build/: the `release` preset of CMakePresets.json.
# Extra arguments go to the configure step.
set -euo pipefail
cd "$(dirname "$0")/.."
# Ninja when it is installed (CMake reads CMAKE_GENERATOR only for a new build folder; an existing
# one keeps its generator).
if [ -z "${CMAKE_GENERATOR:-}" ] && command -v ninja >/dev/null 2>&1; then export CMAKE_GENERATOR=Ninja; fi
cmake --preset release "$@"
cmake --build --preset release --parallel "$(nproc)"
