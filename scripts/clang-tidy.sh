#!/usr/bin/env bash
# Runs clang-tidy (Debian's clang-tidy 14) with the checks of .clang-tidy over OnTime's own code:
# the sources of src/, apps/ and domains/, and the headers they include from there and from
# include/ (not the tests, not other projects' headers). Any finding fails (the checks are
# WarningsAsErrors). python/src/ is left out: clang 14 cannot compile the floating-point template
# arguments of its parameters' bounds (C++20; GCC can).
#
# It reads the sources in the batches of a unity build (build-tidy/, configured here, never
# built: only its compilation database is read). clang-tidy runs every check over the whole of a
# translation unit's headers (the standard library, CLI11, OMPL, Eigen); a batch of eight sources
# shares them, so the run costs a seventh of reading each source on its own. Findings are
# reported at the line of the source that has them. (build-tidy/ lies in the source tree, so that
# clang-tidy finds .clang-tidy above each batch.)
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
build=$root/build-tidy
mkdir -p "$build"
start=$(date +%s)
generator=()
if command -v ninja >/dev/null 2>&1 && [ ! -f "$build/CMakeCache.txt" ]; then generator=(-G Ninja); fi
# The library, the domains and the tool; no tests, benchmarks or Python package (not analysed).
cmake -S . -B "$build" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release -DCMAKE_UNITY_BUILD=ON \
  -DCMAKE_EXPORT_COMPILE_COMMANDS=ON -DBUILD_TESTING=OFF -DONTIME_BUILD_BENCHMARKS=OFF -DONTIME_PYTHON=OFF \
  > "$build/configure.log" 2>&1 || { cat "$build/configure.log" >&2; exit 1; }
# run-clang-tidy runs under Debian's python3 (the python3 first on PATH may be another).
/usr/bin/python3 "$(command -v run-clang-tidy-14)" -p "$build" -j "$(nproc)" -quiet \
  -header-filter="^$root/(include|src|apps|domains)/" \
  "^$build/(src|apps|domains)/CMakeFiles/[^/]*/Unity/unity_[0-9]+_cxx\.cxx$" > "$build/clang-tidy.log" 2>&1 || {
  # (run-clang-tidy colours clang-tidy's output; the colour codes are left out here.)
  sed 's/\x1b\[[0-9;]*m//g' "$build/clang-tidy.log" |
    grep -v "^clang-tidy-14 \|^[0-9]* warnings\? generated\.$\|^Suppressed [0-9]* warnings\|^Use -header-filter\|^$" >&2 || true
  echo "clang-tidy: findings above (all of them in $build/clang-tidy.log)" >&2
  exit 1
}
batches=$(grep -c "^clang-tidy-14 " "$build/clang-tidy.log" || true)
sources=$(cat "$build"/{src,apps,domains}/CMakeFiles/*/Unity/unity_*_cxx.cxx | grep -c '^#include "')
echo "clang-tidy: no findings in $sources files ($batches batches, $(($(date +%s) - start)) s)"
