#!/usr/bin/env bash
# `pip install --no-build-isolation .` with Debian's python3, pip and setuptools and no package
# index, into a scratch virtual environment that sees Debian's packages (numpy); then imports the
# installed package from a folder outside the source tree and solves an instance with it.
#   scripts/check-pip-install.sh [BUILD_DIR]   reuse a configured build tree (default build/):
#                                              only the module's target is brought up to date
#   scripts/check-pip-install.sh --fresh       let setup.py configure and build in build-python/
set -euo pipefail
cd "$(dirname "$0")/.."
source_dir=$PWD
reuse=()
if [ "${1:-}" != "--fresh" ]; then reuse=(ONTIME_CMAKE_BUILD_DIR="$source_dir/${1:-build}"); fi
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"' EXIT
/usr/bin/python3 -m venv --system-site-packages "$scratch/venv"
start=$(date +%s)
env -u PYTHONPATH "${reuse[@]}" PIP_NO_INDEX=1 PIP_DISABLE_PIP_VERSION_CHECK=1 \
  "$scratch/venv/bin/python" -m pip install --no-build-isolation --quiet "$source_dir"
echo "check-pip-install: installed in $(($(date +%s) - start)) s"
cd "$scratch"
env -u PYTHONPATH "$scratch/venv/bin/python" -c '
import pathlib, sys
import ontime
site = pathlib.Path(sys.prefix)
assert pathlib.Path(ontime.__file__).is_relative_to(site), ontime.__file__
assert pathlib.Path(ontime._ontime.__file__).parent == pathlib.Path(ontime.__file__).parent
problem = ontime.load_problem(sys.argv[1])
value = ontime.solve(problem)["optimal_success_probability"]
assert abs(value - 0.942) < 1e-9, value
print(f"check-pip-install: import ontime from {ontime.__file__}: optimum {value:.4f}")
' "$source_dir/data/instances/paper/instance1.json"
"$scratch/venv/bin/python" -m pip show --files ontime | grep -q "ontime/py.typed" ||
  { echo "check-pip-install: the installed package lacks py.typed" >&2; exit 1; }
