#!/usr/bin/env bash
# Builds the documentation site into build/docs/html: the C++ API from the headers (Doxygen XML,
# docs/api/Doxyfile, rendered by Breathe), the Python API from the package's docstrings, the
# guides and references of docs/ (Markdown, MyST) and the tutorial notebook, executed.
# Any warning fails the build: a Doxygen error in a header's comment, a public function or class
# without its comment (docs/api/check_documented.py), a Sphinx warning (a broken reference, a
# missing image or page, a header Breathe cannot render, a tutorial cell that raises).
#
#   scripts/docs.sh [--check] [BUILD_DIR]
#
# BUILD_DIR (default build/) holds the Python extension, build/python under it; when it is
# missing, the extension alone is configured and built there (the release preset for build/).
# --check then opens the built site in headless Chromium (scripts/docs-browser-test.py: pages,
# images, search; screenshots in build/docs/screenshots) and runs linkchecker over it, offline.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
check=0
if [ "${1:-}" = "--check" ]; then check=1; shift; fi
build=${1:-build}
out=$root/build/docs
step() {
  local start=$SECONDS
  "$@"
  echo "[docs.sh] $((SECONDS - start)) s: $*" >&2
}

step ./scripts/setup.sh

if ! ls "$build"/python/ontime/_ontime*.so >/dev/null 2>&1; then
  if [ -z "${CMAKE_GENERATOR:-}" ] && command -v ninja >/dev/null 2>&1; then export CMAKE_GENERATOR=Ninja; fi
  if [ "$build" = build ]; then
    step cmake --preset release
  else
    step cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release
  fi
  step cmake --build "$build" --parallel "$(nproc)" --target ontime_python ontime_python_files
fi
# Absolute: the notebook's kernel runs in docs/.
PYTHONPATH=$(cd "$build/python" && pwd)${PYTHONPATH:+:$PYTHONPATH}
export PYTHONPATH
# The kernel's debugger is not used; this keeps its start-up note off the build's output.
export PYDEVD_DISABLE_FILE_VALIDATION=1
# Matplotlib's cache in a folder of the build (the home folder may be read-only in CI). No
# MPLBACKEND: the notebook's plots need the kernel's inline backend.
export MPLCONFIGDIR=$out/matplotlib

rm -rf "$out/doxygen" "$out/html" "$out/doctrees"
mkdir -p "$out/doxygen" "$MPLCONFIGDIR"

# Doxygen: every warning but "not documented" is an error (those are judged by check_documented.py,
# which asks a comment of every public function and class, not of every data member).
run_doxygen() {
  (cat docs/api/Doxyfile; echo "OUTPUT_DIRECTORY = $out/doxygen"; echo "WARN_LOGFILE = $out/doxygen/warnings.log") |
    doxygen - >/dev/null
  local errors
  errors=$(grep -v ' is not documented\.$' "$out/doxygen/warnings.log" | grep -c 'warning\|error' || true)
  if [ "$errors" -ne 0 ]; then
    grep -v ' is not documented\.$' "$out/doxygen/warnings.log" >&2
    echo "docs.sh: $errors Doxygen warnings in the headers' comments" >&2
    return 1
  fi
}
step run_doxygen
step /usr/bin/python3 docs/api/check_documented.py "$out/doxygen/xml"

# -W: warnings are errors; --keep-going: report them all before failing; -n: nitpicky references
# are not asked (the C++ signatures name std:: types that no page documents).
step /usr/bin/python3 -m sphinx -b html -W --keep-going -j "$(nproc)" -d "$out/doctrees" docs "$out/html"
echo "docs.sh: the site is in $out/html/index.html" >&2

check_links() {
  local port server status=0
  port=$(/usr/bin/python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])')
  # linkchecker sends at most 10 requests a second to a server unless it answers with a
  # "LinkChecker" header: this one does, so that the check takes seconds rather than half a minute.
  /usr/bin/python3 -c '
import functools, http.server, sys
class Handler(http.server.SimpleHTTPRequestHandler):
    def end_headers(self):
        self.send_header("LinkChecker", "local")
        super().end_headers()
    def log_message(self, *args):
        pass
http.server.ThreadingHTTPServer(("127.0.0.1", int(sys.argv[1])),
                                functools.partial(Handler, directory=sys.argv[2])).serve_forever()
' "$port" "$1" &
  server=$!
  for _ in $(seq 50); do
    if /usr/bin/python3 -c "import urllib.request; urllib.request.urlopen('http://127.0.0.1:$port/index.html')" 2>/dev/null; then break; fi
    sleep 0.1
  done
  printf '[checking]\nmaxrequestspersecond=100\n' > "$out/linkcheckerrc"
  linkchecker -f "$out/linkcheckerrc" --no-status --no-warnings "http://127.0.0.1:$port/index.html" || status=$?
  kill "$server"
  return "$status"
}

if [ "$check" -eq 1 ]; then
  step /usr/bin/python3 scripts/docs-browser-test.py "$out/html" "$out/screenshots"
  # Offline: the site's own links only (linkchecker leaves other hosts alone without
  # --check-extern): every page, anchor-less link and image, the copied repository files included.
  # Served over HTTP because linkchecker run as root drops to the user nobody, who may not be
  # allowed to read a checkout under /root.
  step check_links "$out/html"
fi
