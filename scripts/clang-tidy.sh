#!/usr/bin/env bash
# Runs clang-tidy (Debian's clang-tidy 14) with the checks of .clang-tidy over OnTime's own code:
# the sources of src/, apps/ and domains/, and the headers they include from there and from
# include/ (not the tests, not other projects' headers). Any finding fails (the checks are
# WarningsAsErrors). python/src/ is left out: clang 14 cannot compile the floating-point template
# arguments of its parameters' bounds (C++20; GCC can). Uses the compilation database of a
# configured build tree (default build/; CMAKE_EXPORT_COMPILE_COMMANDS is on), on all processors.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
root=$PWD
[ -f "$build/compile_commands.json" ] || { echo "clang-tidy: no $build/compile_commands.json (run scripts/build.sh)" >&2; exit 1; }
start=$(date +%s)
# run-clang-tidy runs under Debian's python3 (the python3 first on PATH may be another).
/usr/bin/python3 "$(command -v run-clang-tidy-14)" -p "$build" -j "$(nproc)" -quiet \
  -header-filter="^$root/(include|src|apps|domains)/" \
  "^$root/(src|apps|domains)/.*\.cpp$" > "$build/clang-tidy.log" 2>&1 || {
  # (run-clang-tidy colours clang-tidy's output; the colour codes are left out here.)
  sed 's/\x1b\[[0-9;]*m//g' "$build/clang-tidy.log" |
    grep -v "^clang-tidy-14 \|^[0-9]* warnings\? generated\.$\|^Suppressed [0-9]* warnings\|^Use -header-filter\|^$" >&2 || true
  echo "clang-tidy: findings above (all of them in $build/clang-tidy.log)" >&2
  exit 1
}
files=$(grep -c "^clang-tidy-14 " "$build/clang-tidy.log" || true)
echo "clang-tidy: no findings in $files files ($(($(date +%s) - start)) s)"
