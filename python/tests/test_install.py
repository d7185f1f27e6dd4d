"""`cmake --install` puts a package Debian's python3 imports."""

import os
import pathlib
import subprocess

import pytest


def test_the_installed_package_imports_with_the_prefix_on_the_path(tmp_path):
    build = os.environ.get("ONTIME_BUILD_DIR")
    if not build:
        pytest.skip("ONTIME_BUILD_DIR is not set (run through ctest)")
    prefix = tmp_path / "prefix"
    subprocess.run(["cmake", "--install", build, "--prefix", str(prefix)], check=True, capture_output=True)
    packages = [p.parent for p in prefix.rglob("ontime/__init__.py")]
    assert len(packages) == 1
    site = packages[0].parent
    assert site.name == "dist-packages"
    env = {"PATH": os.environ.get("PATH", "/usr/bin:/bin"), "PYTHONPATH": str(site)}
    done = subprocess.run(["/usr/bin/python3", "-c",
                           "import ontime; p = ontime.__file__; "
                           "print(p); print(ontime.solve(ontime.Problem.from_dict({'name': 'n', 'deadline': 3, "
                           "'actions': {'a': {'planning': {'pmf': {'1': 1.0}}, 'execution': {'pmf': {'1': 1.0}}}}, "
                           "'skeletons': [['a']]}))['optimal_success_probability'])"],
                          capture_output=True, text=True, env=env, cwd=tmp_path, check=False)
    assert done.returncode == 0, done.stderr
    location, value = done.stdout.split()
    assert pathlib.Path(location).is_relative_to(prefix)
    assert float(value) == 1.0
