"""The build backend's CMake step (pyproject.toml): `pip install .` configures
this tree with the project's CMake for the interpreter that runs pip, builds
the target ascorr_python (the same core and host library as the command line)
and puts the compiled module and the version CMake writes (_version.py) next
to python/ascorr/'s files in the wheel.

ASCORR_BUILD_DIR=DIR: the build directory, kept and reused (CMake in DIR/cmake,
setuptools' staging and metadata in DIR/setuptools), e.g. build/pip as the
CMake presets' build/<preset>. Without it, a temporary directory removed at the
end. Nothing else is written into the source tree.
CMAKE_BUILD_PARALLEL_LEVEL, CMAKE_GENERATOR and CMAKE_ARGS (extra -D options,
space separated) are passed on to CMake.
"""

import atexit
import os
import pathlib
import re
import shlex
import shutil
import subprocess
import sys
import tempfile

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = pathlib.Path(__file__).resolve().parent


def build_dir():
    given = os.environ.get("ASCORR_BUILD_DIR")
    if given:
        path = pathlib.Path(given).resolve()
    else:
        path = pathlib.Path(tempfile.mkdtemp(prefix="ascorr-build-"))
        atexit.register(shutil.rmtree, path, ignore_errors=True)
    if path == ROOT:
        sys.exit(f"ASCORR_BUILD_DIR={given}: the source tree itself; give a directory of its own")
    (path / "setuptools").mkdir(parents=True, exist_ok=True)
    return path


BUILD = build_dir()


def project_version():
    text = (ROOT / "CMakeLists.txt").read_text()
    return re.search(r"project\(ascorr\s+VERSION\s+([0-9.]+)", text).group(1)


class CMakeBuild(build_ext):
    """Builds ascorr._ascorr with the project's CMake (the target ascorr_python)."""

    def build_extension(self, ext):
        cmake_build = BUILD / "cmake"
        args = [
            "-S", str(ROOT), "-B", str(cmake_build),
            "-DCMAKE_BUILD_TYPE=Release",
            "-DASCORR_PYTHON=ON",
            "-DASCORR_INSTALL=OFF",
            f"-DPython3_EXECUTABLE={sys.executable}",
        ]
        try:  # pybind11 from PyPI (build isolation) carries its CMake package
            import pybind11

            args.append(f"-Dpybind11_DIR={pybind11.get_cmake_dir()}")
        except (ImportError, AttributeError):
            pass  # Debian's python3-pybind11: found by CMake in /usr
        if not (cmake_build / "CMakeCache.txt").exists() and "CMAKE_GENERATOR" not in os.environ \
                and shutil.which("ninja"):
            args += ["-G", "Ninja"]
        args += shlex.split(os.environ.get("CMAKE_ARGS", ""))
        subprocess.run(["cmake", *args], check=True)
        build = ["cmake", "--build", str(cmake_build), "--target", "ascorr_python"]
        if "CMAKE_BUILD_PARALLEL_LEVEL" not in os.environ:
            build += ["-j", str(os.cpu_count() or 1)]
        subprocess.run(build, check=True)
        built = sorted((cmake_build / "python" / "ascorr").glob("_ascorr.*"))
        if len(built) != 1:
            sys.exit(f"expected one compiled module in {cmake_build / 'python' / 'ascorr'}, found {built}")
        target = pathlib.Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(built[0], target)
        # ascorr/_version.py: written by CMake from project(VERSION), beside the module.
        shutil.copy2(cmake_build / "python" / "ascorr" / "_version.py", target.parent / "_version.py")


staging = BUILD / "setuptools"
setup(
    version=project_version(),
    packages=["ascorr"],
    package_dir={"ascorr": "python/ascorr"},
    package_data={"ascorr": ["__init__.pyi", "py.typed"]},
    ext_modules=[Extension("ascorr._ascorr", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    options={
        "build": {"build_base": str(staging / "build")},
        "egg_info": {"egg_base": str(staging)},
    },
    zip_safe=False,
)
