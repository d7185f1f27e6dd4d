#!/usr/bin/env bash
# Builds the Debian package `ontime` with CPack from a build tree (default build/, built by
# scripts/build.sh), installs it with apt-get, runs the installed tool and `import ontime` with
# Debian's python3 from a folder outside the source tree (no PYTHONPATH, no ONTIME_* variables),
# then removes the package and checks that nothing of it is left. Needs root (or sudo) for
# apt-get; refuses to run when a package `ontime` is installed already.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
sudo_cmd=()
if [ "$(id -u)" -ne 0 ]; then sudo_cmd=(sudo); fi
fail() { echo "check-package: $*" >&2; exit 1; }
installed() { dpkg-query -W -f='${Status}' ontime 2>/dev/null | grep -q "install ok installed"; }
# apt-get, its output shown only when it fails.
apt_get() {
  local log
  log=$(mktemp)
  if ! DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get -y -q "$@" > "$log" 2>&1; then
    cat "$log" >&2
    rm -f "$log"
    return 1
  fi
  rm -f "$log"
}

if installed; then fail "a package ontime is installed already (apt-get remove ontime first)"; fi
[ -f "$build/CMakeCache.txt" ] || fail "$build is not a configured build tree (run scripts/build.sh)"
cmake --build "$build" --parallel "$(nproc)"
rm -f "$build"/ontime_*.deb
(cd "$build" && cpack -G DEB > cpack.log 2>&1) || { cat "$build/cpack.log" >&2; fail "cpack failed"; }
debs=("$build"/ontime_*.deb)
[ ${#debs[@]} -eq 1 ] && [ -f "${debs[0]}" ] || fail "cpack made no single ontime_*.deb in $build"
deb=$(realpath "${debs[0]}")
echo "check-package: $(basename "$deb"), $(du -h "$deb" | cut -f1)"
contents=$(dpkg-deb --contents "$deb")
for path in ./usr/bin/ontime ./usr/share/ontime/data/instances/paper/instance1.json \
  ./usr/share/ontime/data/domains/navigation.json ./usr/include/ontime/ \
  ./usr/lib/python3/dist-packages/ontime/__init__.py; do
  grep -qF " $path" <<<"$contents" || fail "the package lacks $path"
done
for pattern in '/usr/lib/python3/dist-packages/ontime/_ontime\..*\.so$' '/cmake/ontime/ontimeConfig\.cmake$' \
  '/usr/lib/.*libontime\.a$'; do
  grep -qE "$pattern" <<<"$contents" || fail "the package lacks a file matching $pattern"
done
depends=$(dpkg-deb --field "$deb" Depends)
echo "check-package: Depends: $depends"
for dependency in libc6 python3-numpy 'python3 (>='; do
  grep -qF "$dependency" <<<"$depends" || fail "Depends lacks $dependency: $depends"
done

trap 'if installed; then apt_get remove ontime; fi' EXIT
apt_get install --no-install-recommends "$deb"
installed || fail "apt-get did not install the package"

# From a scratch folder, with none of the variables that point into the source or build tree.
scratch=$(mktemp -d)
trap 'rm -rf "$scratch"; if installed; then apt_get remove ontime; fi' EXIT
clean_env=(env -u PYTHONPATH -u ONTIME_DATA_DIR -u ONTIME_PYTHON_DIR -u ONTIME_PYTHON -u ONTIME_CLI)
cd "$scratch"
"${clean_env[@]}" /usr/bin/ontime --help > help.txt || fail "ontime --help failed"
grep -q "solve" help.txt || fail "ontime --help lists no solve command"
"${clean_env[@]}" /usr/bin/ontime solve /usr/share/ontime/data/instances/paper/instance1.json > solve.txt
grep -q "optimal success probability  0.942000" solve.txt || fail "ontime solve answered: $(cat solve.txt)"
# The domains' data, found beside the installed tool: the world file and the fitted instance.
"${clean_env[@]}" /usr/bin/ontime run --domain navigation --solver dp --episodes 1 --threads 1 --json > run.json
grep -qF '"instance": "/usr/share/ontime/data/instances/navigation.json"' run.json ||
  fail "ontime run did not use the installed data: $(head -c 400 run.json)"
"${clean_env[@]}" /usr/bin/python3 -I -c '
import ontime
assert ontime.__file__ == "/usr/lib/python3/dist-packages/ontime/__init__.py", ontime.__file__
problem = ontime.load_problem("/usr/share/ontime/data/instances/paper/instance1.json")
value = ontime.solve(problem)["optimal_success_probability"]
assert abs(value - 0.942) < 1e-9, value
print(f"check-package: import ontime from {ontime.__file__}: optimum {value:.4f}")
' || fail "import ontime failed"
cd - > /dev/null

apt_get remove ontime
if installed; then fail "apt-get remove left the package installed"; fi
for path in /usr/bin/ontime /usr/share/ontime /usr/include/ontime /usr/lib/cmake/ontime \
  /usr/lib/python3/dist-packages/ontime; do
  [ ! -e "$path" ] || fail "$path is left after removing the package"
done
if "${clean_env[@]}" /usr/bin/python3 -I -c 'import ontime' 2>/dev/null; then fail "ontime still imports after removal"; fi
echo "check-package: $(basename "$deb") installs, runs and removes cleanly"
