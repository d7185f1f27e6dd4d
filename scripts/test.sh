#!/usr/bin/env bash
# Sets up the machine, checks the C++ formatting (clang-format, .clang-format), builds OnTime
# with warnings as errors and runs every test (the C++ suites, then the Python package's pytest suite, then the
# MPI and SLURM check of scripts/cluster/check.sh); then the core
# alone without OMPL, FCL and KDL (build-core/: build, tests, install, consumer); then builds
# the suite again with AddressSanitizer and UndefinedBehaviorSanitizer (build-sanitize/) and
# runs it there too (warnings are checked by the first build; GCC warns falsely inside the
# standard library when it is instrumented).
set -euo pipefail
cd "$(dirname "$0")/.."
./scripts/setup.sh
./scripts/check-format.sh
./scripts/build.sh -DONTIME_WARNINGS_AS_ERRORS=ON
ctest --test-dir build --parallel "$(nproc)" --output-on-failure --label-exclude python
# The Python package's pytest suite, verbose so that its closing line shows.
ctest --test-dir build --label-regex python --output-on-failure --verbose
# Split over MPI ranks (mpirun, and srun on a single-node SLURM cluster brought up for it): the
# same files as one process, byte for byte, and no work lost when a rank dies.
./scripts/cluster/check.sh build/ontime

# The core without the domains: configured with OMPL, FCL and KDL hidden from find_package, it
# builds, passes its tests, installs, and an outside project builds against the install (the
# install_and_consume test, core component only, with Eigen hidden from the consumer).
generator=()
if command -v ninja >/dev/null 2>&1 && [ ! -f build-core/CMakeCache.txt ]; then generator=(-G Ninja); fi
# (--no-warn-unused-cli: that nothing reads the CMAKE_DISABLE_FIND_PACKAGE_ variables is the point.)
cmake -S . -B build-core "${generator[@]}" --no-warn-unused-cli -DCMAKE_BUILD_TYPE=Release -DONTIME_WARNINGS_AS_ERRORS=ON \
  -DONTIME_BUILD_DOMAINS=OFF -DONTIME_BUILD_BENCHMARKS=OFF -DONTIME_PYTHON=OFF \
  -DCMAKE_DISABLE_FIND_PACKAGE_ompl=ON -DCMAKE_DISABLE_FIND_PACKAGE_fcl=ON -DCMAKE_DISABLE_FIND_PACKAGE_orocos_kdl=ON
cmake --build build-core --parallel "$(nproc)"
ctest --test-dir build-core --parallel "$(nproc)" --output-on-failure

generator=()
if command -v ninja >/dev/null 2>&1 && [ ! -f build-sanitize/CMakeCache.txt ]; then generator=(-G Ninja); fi
# (No Python package: an instrumented extension cannot be loaded by the uninstrumented interpreter.)
cmake -S . -B build-sanitize "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DONTIME_SANITIZE=ON \
  -DONTIME_BUILD_BENCHMARKS=OFF -DONTIME_PYTHON=OFF
cmake --build build-sanitize --parallel "$(nproc)"
# The install test builds an uninstrumented consumer against the library: not meaningful here.
ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
  ctest --test-dir build-sanitize --parallel "$(nproc)" --output-on-failure --label-exclude integration
