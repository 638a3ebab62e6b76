"""Builds voxfield's extension module (voxfield._voxfield) with CMake for pip.

`pip install --no-build-isolation .` (offline: Debian's setuptools, CMake, Ninja and compilers,
and the libraries scripts/install-deps.sh installs) configures a release build of the layers and
the module in pip's build directory, builds only the module's target, and puts the extension
beside the package's Python files. VOXFIELD_CMAKE_BUILD_DIR names an already configured build
tree to build in instead (the tests reuse the release build: only the module is relinked).
"""

import os
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build = os.environ.get("VOXFIELD_CMAKE_BUILD_DIR")
        if build:
            build = Path(build).resolve()
        else:
            build = Path(self.build_temp).resolve() / "cmake"
            subprocess.run(["cmake", "-S", str(ROOT), "-B", str(build), "-G", "Ninja",
                            "-DCMAKE_BUILD_TYPE=Release", "-DVOXFIELD_BUILD_TESTS=OFF",
                            "-DVOXFIELD_VULKAN=OFF", "-DVOXFIELD_BUILD_MPI=OFF",
                            "-DVOXFIELD_BUILD_PYTHON=ON",  # a clear error if pybind11 is missing
                            f"-DPython_EXECUTABLE={sys.executable}"], check=True)
        jobs = str(os.cpu_count() or 1)
        subprocess.run(["cmake", "--build", str(build), "--target", "voxfield_python", "-j", jobs],
                       check=True)
        # The module for this interpreter's ABI (a reused tree may hold others).
        built = build / "python" / "voxfield" / ("_voxfield" + sysconfig.get_config_var("EXT_SUFFIX"))
        if not built.exists():
            raise RuntimeError(f"voxfield: the build in {build} made no {built.name} for this Python")
        target = Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(built, target)


setup(ext_modules=[Extension("voxfield._voxfield", sources=[])], cmdclass={"build_ext": CMakeBuild})
