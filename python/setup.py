"""Builds libpfsph.so for the package (docs/python.md, "Install").

Where the library comes from, first match:
  1. $PFSPH_LIBRARY: an existing libpfsph.so (built with -DPFSPH_SHARED=ON), copied as is;
  2. the pfsph source tree this directory sits in (../CMakeLists.txt): CMake configures
     ../build-python (or $PFSPH_BUILD_DIR) with -DPFSPH_SHARED=ON and builds the target
     pfsph_shared only (incremental: a second install rebuilds nothing). $PFSPH_CMAKE_ARGS adds
     arguments, e.g. "-DPFSPH_DOUBLE=ON".
The library goes into the package as pfsph/_lib/libpfsph.so, which pfsph/_ffi.py opens (cffi
ABI mode: no compiler at import). The wheel is platform-specific for that reason."""
import os
import shlex
import shutil
import subprocess

from setuptools import setup
from setuptools.command.build_py import build_py
from setuptools.dist import Distribution

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)


def _build_library():
    lib = os.environ.get("PFSPH_LIBRARY")
    if lib:
        if not os.path.isfile(lib):
            raise SystemExit("pfsph: PFSPH_LIBRARY=%s: no such file" % lib)
        return lib
    if not os.path.isfile(os.path.join(ROOT, "CMakeLists.txt")) or not os.path.isfile(
            os.path.join(ROOT, "include", "pfsph.h")):
        raise SystemExit("pfsph: this package builds the C library from the pfsph source tree it sits in "
                         "(python/ of the repository), or takes PFSPH_LIBRARY=/path/to/libpfsph.so")
    cmake = shutil.which("cmake")
    if not cmake:
        raise SystemExit("pfsph: cmake not found (Debian: apt-get install cmake build-essential libcjson-dev "
                         "libpng-dev zlib1g-dev libode-dev)")
    build = os.environ.get("PFSPH_BUILD_DIR") or os.path.join(ROOT, "build-python")
    args = [cmake, "-S", ROOT, "-B", build, "-DCMAKE_BUILD_TYPE=Release", "-DPFSPH_SHARED=ON", "-DPFSPH_TESTS=OFF",
            "-DPFSPH_VIEWER=OFF"] + shlex.split(os.environ.get("PFSPH_CMAKE_ARGS", ""))
    print("pfsph: " + " ".join(shlex.quote(a) for a in args), flush=True)
    subprocess.check_call(args)
    jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL") or str(os.cpu_count() or 2)
    subprocess.check_call([cmake, "--build", build, "--target", "pfsph_shared", "-j", jobs])
    return os.path.join(build, "libpfsph.so")


class BuildPy(build_py):
    """The Python files, then the shared library beside them."""

    def run(self):
        super().run()
        lib = _build_library()
        dest = os.path.join(self.build_lib, "pfsph", "_lib")
        os.makedirs(dest, exist_ok=True)
        shutil.copy2(lib, os.path.join(dest, "libpfsph.so"))


class BinaryDistribution(Distribution):
    """A platform wheel: it carries a compiled library."""

    def has_ext_modules(self):
        return True


setup(cmdclass={"build_py": BuildPy}, distclass=BinaryDistribution)
