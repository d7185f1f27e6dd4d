#!/usr/bin/env bash
# Sets up the machine, checks the C++ formatting (clang-format, .clang-format), builds OnTime
# with warnings as errors and runs every test (the C++ suites, then the Python package's pytest suite, then the
# MPI and SLURM check of scripts/cluster/check.sh, then the documentation site and its browser
# test, scripts/docs.sh --check); then clang-tidy over OnTime's sources
# (.clang-tidy), the Python package installed by pip and the Debian package built, installed and
# removed (both from build/); then the core alone without OMPL, FCL and KDL (build-core/: build,
# the tool's refusals, install, consumer; compiled by clang, file by file, its warnings errors
# too: the other builds compile sources in batches, this one shows a missing include); then builds
# the suite again with AddressSanitizer and UndefinedBehaviorSanitizer (build-sanitize/, clang:
# two thirds of GCC's compile time) and runs it there too (warnings are checked by the first two
# builds).
# Each build folder is a preset of CMakePresets.json (release, core, sanitize).
set -euo pipefail
cd "$(dirname "$0")/.."
# Each step's wall time goes to stderr, so that a slow run shows where its time went.
step() {
  local start=$SECONDS
  "$@"
  echo "[test.sh] $((SECONDS - start)) s (at $SECONDS s): $*" >&2
}
step ./scripts/setup.sh
step ./scripts/check-format.sh
# Ninja when it is installed (CMake reads CMAKE_GENERATOR only for a new build folder).
if [ -z "${CMAKE_GENERATOR:-}" ] && command -v ninja >/dev/null 2>&1; then export CMAKE_GENERATOR=Ninja; fi
step ./scripts/build.sh -DONTIME_WARNINGS_AS_ERRORS=ON
step ctest --preset release --parallel "$(nproc)" --label-exclude python
# The Python package's pytest suite, verbose so that its closing line shows.
step ctest --preset release --label-regex python --verbose
# Split over MPI ranks (mpirun, and srun on a single-node SLURM cluster brought up for it): the
# same files as one process, byte for byte, and no work lost when a rank dies.
step ./scripts/cluster/check.sh build/ontime
# The documentation site, built with warnings as errors (every public header and Python name, the
# tutorial executed against build/python), opened in headless Chromium (pages, images, search;
# screenshots kept in build/docs/screenshots) and checked by linkchecker, offline.
step ./scripts/docs.sh --check build
# Static analysis: no finding of .clang-tidy's checks in src/, include/, apps/, domains/ (python/src/: see the script).
step ./scripts/clang-tidy.sh
# Installing: pip install --no-build-isolation . (reusing build/), then the .deb of cpack.
step ./scripts/check-pip-install.sh build
step ./scripts/check-package.sh build

# The core without the domains: configured with OMPL, FCL and KDL hidden from find_package, the
# library and the tool build, the tool refuses the domain commands, the install works and an
# outside project builds against it (install_and_consume, core component only, with Eigen hidden
# from the consumer). Its unit tests are those of build/ (and of build-sanitize/ below), the same
# sources with the same flags: they are not built a third time.
step cmake --preset core -DONTIME_WARNINGS_AS_ERRORS=ON
step cmake --build --preset core --parallel "$(nproc)" --target ontime ontime_cli
step ctest --preset core --parallel "$(nproc)" \
  --tests-regex '^(install_and_consume|cli_refuses_domain_commands_without_the_domains|layers_.*)$'

# (No Python package: an instrumented extension cannot be loaded by the uninstrumented
# interpreter. The install test, which builds an uninstrumented consumer against the library, is
# left out by the preset; it sets ASAN_OPTIONS and UBSAN_OPTIONS.)
step cmake --preset sanitize
step cmake --build --preset sanitize --parallel "$(nproc)"
step ctest --preset sanitize --parallel "$(nproc)"
