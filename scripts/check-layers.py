#!/usr/bin/python3
"""Fails when a file includes a layer above its own.

OnTime's layers, lowest first; each knows only those before it:

    util -> model -> mdp -> solve -> allocators -> run -> learn -> report -> domains -> apps, python

A file's layer is the folder it lives in: include/ontime/LAYER/ and src/LAYER/ for the core;
domains/, apps/, python/src/ and bench/ above them. The umbrella header include/ontime/ontime.hpp
stands above the core's layers, below the domains. Tests are kept by the layer they test
(tests/LAYER/), and a test of the core may check its layer against any layer of the core (an
allocator's exact value against the exact evaluation, say) but never uses the domains or the
CLI: tests/support/ and every tests/CORE-LAYER/ count as the umbrella; tests/domains/ as the
domains, tests/apps/ as the CLI. An include names a layer by its first folder: "ontime/solve/..."
(an installed header), "solve/expectimax.hpp" (a private header of src/), "ontime/domains/...".

Usage: scripts/check-layers.py [ROOT]   (exit 1 and one line per upward include; 0 otherwise)
"""
import pathlib
import re
import sys

CORE = ["util", "model", "mdp", "solve", "allocators", "run", "learn", "report"]
RANK = {name: rank for rank, name in enumerate(CORE)}
RANK["umbrella"] = len(CORE)  # ontime.hpp, tests/support: every core layer
RANK["domains"] = len(CORE) + 1
RANK["apps"] = len(CORE) + 2
RANK["python"] = len(CORE) + 2
RANK["bench"] = len(CORE) + 3
INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.MULTILINE)


def layer_of_file(relative: pathlib.PurePosixPath):
    parts = relative.parts
    if parts[:2] == ("include", "ontime"):
        return parts[2] if len(parts) > 3 and parts[2] in RANK else ("umbrella" if parts[2] == "ontime.hpp" else None)
    if parts[0] == "src" and len(parts) > 2 and parts[1] in RANK:
        return parts[1]
    if parts[0] == "tests" and len(parts) > 2:
        if parts[1] in CORE or parts[1] == "support":
            return "umbrella"
        return parts[1] if parts[1] in ("domains", "apps") else None
    if parts[0] == "domains":
        return "domains"
    if parts[0] in ("apps", "bench"):
        return parts[0]
    if parts[:2] == ("python", "src"):
        return "python"
    if parts[0] == "fuzz":
        return "umbrella"
    return None


def layer_of_include(path: str, own_layer: str):
    parts = path.split("/")
    if parts[0] == "ontime" and len(parts) > 1:
        if parts[1] == "ontime.hpp":
            return "umbrella"
        return parts[1] if parts[1] in RANK and len(parts) > 2 else None
    if parts[0] in CORE and len(parts) > 1:  # a private header of src/
        return parts[0]
    if parts[0] == "support":
        return "umbrella"
    return None


def main() -> int:
    root = pathlib.Path(sys.argv[1] if len(sys.argv) > 1 else pathlib.Path(__file__).resolve().parent.parent)
    broken = 0
    checked = 0
    for folder in ("include", "src", "tests", "domains", "apps", "python/src", "bench", "fuzz"):
        for path in sorted((root / folder).rglob("*")):
            if path.suffix not in (".hpp", ".cpp", ".inc", ".h") or not path.is_file():
                continue
            relative = pathlib.PurePosixPath(path.relative_to(root).as_posix())
            own = layer_of_file(relative)
            if own is None:
                continue
            checked += 1
            text = path.read_text(encoding="utf-8")
            for match in INCLUDE.finditer(text):
                target = layer_of_include(match.group(1), own)
                if target is not None and RANK[target] > RANK[own]:
                    line = text.count("\n", 0, match.start()) + 1
                    print(f"{relative}:{line}: layer '{own}' includes \"{match.group(1)}\" of layer '{target}', "
                          f"which is above it")
                    broken += 1
    if checked == 0:
        print(f"check-layers: no source files under {root}")
        return 2
    if broken:
        print(f"check-layers: {broken} upward include(s) in {checked} files")
        return 1
    print(f"check-layers: {checked} files, every include points to its own layer or below")
    return 0


if __name__ == "__main__":
    sys.exit(main())
