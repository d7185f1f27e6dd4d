"""Builds the Python package `ontime` with CMake (pyproject.toml has the metadata).

The extension `ontime._ontime` is CMake's target ontime_python (python/CMakeLists.txt), built for
the interpreter that runs this file; the pure-Python files come from python/ontime. Environment:
  ONTIME_CMAKE_BUILD_DIR  an existing build tree configured with ONTIME_PYTHON=ON for this
                          interpreter (e.g. build/): only the module's target is brought up to
                          date there, nothing is configured
  CMAKE_ARGS              extra options for the configure step of the build in build-python/cmake
  CMAKE_BUILD_PARALLEL_LEVEL  parallel jobs (default: the number of processors)
"""

import os
import pathlib
import re
import shlex
import shutil
import subprocess
import sys
import sysconfig

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

SOURCE_DIR = pathlib.Path(__file__).resolve().parent
# Not build/: that is the CMake build tree of scripts/build.sh.
BUILD_BASE = "build-python"


def project_version() -> str:
    text = (SOURCE_DIR / "CMakeLists.txt").read_text(encoding="utf-8")
    match = re.search(r"project\(ontime\s+VERSION\s+([0-9.]+)", text)
    if not match:
        raise RuntimeError("CMakeLists.txt: no project(ontime VERSION ...)")
    return match.group(1)


def cache_value(build_dir: pathlib.Path, name: str):
    cache = build_dir / "CMakeCache.txt"
    if not cache.is_file():
        return None
    for line in cache.read_text(encoding="utf-8", errors="replace").splitlines():
        if line.startswith(name + ":"):
            return line.split("=", 1)[1]
    return None


class CMakeBuild(build_ext):
    def build_extension(self, ext: Extension) -> None:
        reused = os.environ.get("ONTIME_CMAKE_BUILD_DIR")
        if reused:
            build_dir = pathlib.Path(reused).resolve()
            if cache_value(build_dir, "ONTIME_PYTHON") not in ("ON", "TRUE", "1"):
                raise SystemExit(f"ONTIME_CMAKE_BUILD_DIR={reused}: not a CMake build tree of OnTime "
                                 "configured with ONTIME_PYTHON=ON")
        else:
            build_dir = (SOURCE_DIR / BUILD_BASE / "cmake").resolve()
            configure = ["cmake", "-S", str(SOURCE_DIR), "-B", str(build_dir),
                         "-DCMAKE_BUILD_TYPE=Release", "-DONTIME_PYTHON=ON",
                         f"-DPython3_EXECUTABLE={sys.executable}",
                         "-DBUILD_TESTING=OFF", "-DONTIME_BUILD_APPS=OFF", "-DONTIME_BUILD_BENCHMARKS=OFF"]
            if not (build_dir / "CMakeCache.txt").is_file() and not os.environ.get("CMAKE_GENERATOR") \
                    and shutil.which("ninja"):
                configure += ["-G", "Ninja"]
            configure += shlex.split(os.environ.get("CMAKE_ARGS", ""))
            subprocess.run(configure, check=True)
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL") or str(os.cpu_count() or 1)
        subprocess.run(["cmake", "--build", str(build_dir), "--target", "ontime_python", "--parallel", jobs],
                       check=True)
        name = "_ontime" + sysconfig.get_config_var("EXT_SUFFIX")
        built = build_dir / "python" / "ontime" / name
        if not built.is_file():
            raise SystemExit(f"{built} was not built: the build tree is configured for another Python "
                             f"(configure it with -DPython3_EXECUTABLE={sys.executable})")
        target = pathlib.Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(built, target)


# setuptools' metadata folder (egg_base) must exist.
(SOURCE_DIR / BUILD_BASE).mkdir(exist_ok=True)
setup(
    version=project_version(),
    packages=["ontime"],
    package_dir={"": "python"},
    package_data={"ontime": ["py.typed"]},
    ext_modules=[Extension("ontime._ontime", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    options={"build": {"build_base": BUILD_BASE}, "egg_info": {"egg_base": BUILD_BASE}},
    zip_safe=False,
)
