"""Shared fixtures of the Python tests: where the sources and the command line are.

CTest sets ONTIME_SOURCE_DIR, ONTIME_BUILD_DIR and ONTIME_CLI (the `ontime` binary, when built) and
puts the build tree's package first on PYTHONPATH.
"""

import json
import os
import pathlib
import subprocess

import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("ONTIME_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))
PAPER = SOURCE_DIR / "data" / "instances" / "paper"
PAPER_INSTANCES = [PAPER / f"instance{i}.json" for i in range(1, 6)]


@pytest.fixture(scope="session")
def source_dir() -> pathlib.Path:
    return SOURCE_DIR


@pytest.fixture(scope="session")
def cli():
    """Runs the command line and returns its parsed --json output (skips when it is not built)."""
    path = os.environ.get("ONTIME_CLI")
    if not path or not os.path.exists(path):
        pytest.skip("the ontime command line is not built")

    def run(*args, expect_json=True):
        done = subprocess.run([path, *map(str, args)], capture_output=True, text=True, check=False)
        if not expect_json:
            return done
        assert done.returncode == 0, done.stderr
        return json.loads(done.stdout)

    return run
