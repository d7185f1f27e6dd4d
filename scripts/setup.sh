#!/usr/bin/env bash
# Installs the Debian packages OnTime needs to build, test and plot.
# Idempotent: packages already present are left alone, and `apt-get update`
# runs at most once, only when something is missing.
set -euo pipefail

packages=(
  build-essential cmake ninja-build pkg-config git
  libeigen3-dev nlohmann-json3-dev libcli11-dev libfmt-dev libabsl-dev
  # SLEEF's deterministic elementary functions (src/util/portable_math.hpp); NLopt (L-BFGS for the
  # conditional time models); XGBoost's C API (the boosted conditional time model).
  libsleef-dev libnlopt-dev libxgboost-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  libompl-dev libfcl-dev liborocos-kdl-dev libigraph-dev
  libboost-serialization-dev libboost-filesystem-dev libboost-system-dev
  python3 python3-matplotlib python3-numpy
  python3-dev pybind11-dev python3-pybind11 python3-pytest
  # pip install of the Python package (pyproject.toml, setup.py) and its check in a venv.
  python3-pip python3-setuptools python3-wheel python3-venv
  clang libclang-rt-14-dev clang-format clang-tidy
  # The Debian package (CPack's DEB generator: dpkg-shlibdeps, file).
  dpkg-dev file
  # MPI for the split commands; a single-node SLURM cluster for their check (scripts/cluster/).
  # (libpmix-dev must be there before slurmd first starts, or `srun --mpi=pmix` hangs: slurmd
  # is only ever started by scripts/cluster/slurm-up.sh, after this.)
  openmpi-bin libopenmpi-dev libpmix-dev bc
  munge slurmctld slurmd slurm-client
  # The documentation site (scripts/docs.sh): Doxygen's XML of the headers, Sphinx with MyST,
  # Breathe, Furo and copy buttons; the tutorial notebook executed (nbsphinx, nbconvert, ipykernel;
  # pandoc converts its Markdown cells); headless Chromium driven over DevTools (python3-websocket)
  # and linkchecker for the site's checks.
  doxygen python3-sphinx python3-myst-parser python3-breathe furo python3-sphinx-copybutton
  python3-nbsphinx python3-nbconvert python3-ipykernel pandoc chromium python3-websocket linkchecker
)

missing=()
for package in "${packages[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$package" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$package")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#packages[@]} packages present"
  exit 0
fi

sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then
  sudo_cmd=(sudo)
fi

echo "setup: installing ${missing[*]}"
# Without systemd the maintainer scripts of munge, slurmctld and slurmd start those daemons
# through their init.d scripts, SLURM's with a system-wide /etc/slurm/slurm.conf that does not
# exist, and the installation fails. A policy-rc.d that answers 101 ("action forbidden") stops
# that (OnTime starts the daemons itself, scripts/cluster/slurm-up.sh); it is written only for
# the installation, and only when the machine has none of its own.
policy=/usr/sbin/policy-rc.d
if [ ! -e "$policy" ]; then
  printf '#!/bin/sh\nexit 101\n' | "${sudo_cmd[@]}" tee "$policy" > /dev/null
  "${sudo_cmd[@]}" chmod 755 "$policy"
  trap '"${sudo_cmd[@]}" rm -f "$policy"' EXIT
fi
"${sudo_cmd[@]}" apt-get update -q
DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -q --no-install-recommends "${missing[@]}"
