"""Builds the compiled module with the repository's CMake (the same liboobleck as the CLI) and
copies it, the library (with its glibc-hwcaps variants) and the presets into the package.

The build folder is $OOBLECK_BUILD_DIR, else the release preset's build/release of this checkout;
when it does not hold the module yet, `cmake --preset release` and `cmake --build --preset release
--target _oobleck oobleck` run first (the Debian packages of scripts/bootstrap are needed).
"""
import glob
import os
import shutil
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build = Path(os.environ.get("OOBLECK_BUILD_DIR") or ROOT / "build" / "release")
        if not (ROOT / "CMakeLists.txt").exists():
            raise RuntimeError(f"oobleck: {ROOT} is not the oobleck repository (pip install ./python from its root)")
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL", "2")
        if not (build / "CMakeCache.txt").exists():
            subprocess.check_call(["cmake", "--preset", "release", f"-DOOBLECK_PYTHON_EXECUTABLE={sys.executable}"],
                                  cwd=ROOT)
        subprocess.check_call(["cmake", "--build", str(build), "-j", jobs, "--target", "_oobleck"], cwd=ROOT)
        modules = glob.glob(str(build / "python" / "oobleck" / "_oobleck*.so"))
        if not modules:
            raise RuntimeError(f"oobleck: no _oobleck module in {build}/python/oobleck after the build")
        target = Path(self.get_ext_fullpath(ext.name))
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(modules[0], target)
        for lib in glob.glob(str(build / "liboobleck.so*")):
            shutil.copy2(lib, target.parent, follow_symlinks=True)
        for lib in glob.glob(str(build / "glibc-hwcaps" / "*" / "liboobleck.so*")):
            dest = target.parent / Path(lib).relative_to(build)
            dest.parent.mkdir(parents=True, exist_ok=True)
            shutil.copy2(lib, dest, follow_symlinks=True)
        presets = target.parent / "presets"
        if presets.exists():
            shutil.rmtree(presets)
        shutil.copytree(ROOT / "presets", presets)


setup(ext_modules=[Extension("oobleck._oobleck", sources=[])], cmdclass={"build_ext": CMakeBuild})
