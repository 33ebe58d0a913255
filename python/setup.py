"""Builds the texel package: the pure-Python files of python/texel/ plus the
extension texel._texel, which CMake builds from this repository (the same
target, texel_python, as `make python`).

    pip install --no-build-isolation ./python          # offline, Debian's pip/setuptools/wheel

Environment:
  TEXEL_CMAKE_BUILD_DIR  an existing CMake build directory of this repository
                         (e.g. build/ after `make python`): its texel_python
                         target is brought up to date there and its extension
                         packaged, instead of configuring a fresh build
                         (which compiles the whole library: minutes).
  TEXEL_PYTHON_EXTENSION the extension file itself (build/python/texel/_texel*.so),
                         packaged as it is: no CMake run at all (the tests).
  TEXEL_CMAKE_ARGS       extra arguments for a fresh configure.
  TEXEL_SETUP_BUILD_DIR  where setuptools builds (default: build-pip/ in the
                         repository, beside the CMake build folders).
  CMAKE_BUILD_PARALLEL_LEVEL  build jobs (default: the machine's cores).
The extension is built for the interpreter running this file; an extension
built for another one (its file name says which) is refused.
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

HERE = pathlib.Path(__file__).resolve().parent
ROOT = HERE.parent  # the repository: this file lives in its python/ folder
# setuptools' own build files (and a fresh CMake build, reused by the next
# install) go beside the CMake build folders, not into the source tree.
SETUP_BUILD = pathlib.Path(os.environ.get("TEXEL_SETUP_BUILD_DIR", ROOT / "build-pip")).resolve()
SETUP_BUILD.mkdir(parents=True, exist_ok=True)


def project_version() -> str:
    """The project's version, from the top-level CMakeLists.txt (as texel.__version__)."""
    text = (ROOT / "CMakeLists.txt").read_text(encoding="utf-8")
    m = re.search(r"project\(\s*texel\s+VERSION\s+([0-9][0-9.]*)", text)
    if not m:
        raise SystemExit(f"setup.py: no 'project(texel VERSION x.y.z)' in {ROOT / 'CMakeLists.txt'}")
    return m.group(1)


class CMakeBuild(build_ext):
    """build_ext that lets CMake build texel._texel and copies the result."""

    def build_extension(self, ext):
        dest = pathlib.Path(self.get_ext_fullpath(ext.name)).resolve()
        dest.parent.mkdir(parents=True, exist_ok=True)
        suffix = sysconfig.get_config_var("EXT_SUFFIX")
        prebuilt = os.environ.get("TEXEL_PYTHON_EXTENSION")
        if prebuilt:
            if not prebuilt.endswith(suffix):
                raise SystemExit(f"setup.py: TEXEL_PYTHON_EXTENSION={prebuilt} is not built for {sys.executable} "
                                 f"(its extensions end in {suffix})")
            shutil.copyfile(prebuilt, dest)
            return
        given = os.environ.get("TEXEL_CMAKE_BUILD_DIR")
        build_dir = pathlib.Path(given).resolve() if given else pathlib.Path(self.build_temp).resolve() / "cmake"
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL", str(os.cpu_count() or 2))
        if not given or not (build_dir / "CMakeCache.txt").exists():
            configure = ["cmake", "-S", str(ROOT), "-B", str(build_dir), "-DCMAKE_BUILD_TYPE=Release",
                         f"-DTEXEL_PYTHON_EXECUTABLE={sys.executable}", "-DTEXEL_WITH_PYTHON=ON",
                         "-DTEXEL_BUILD_APPS=OFF", "-DTEXEL_BUILD_TESTS=OFF", "-DTEXEL_BUILD_BENCH=OFF",
                         "-DTEXEL_BUILD_EXAMPLES=OFF", "-DTEXEL_INSTALL=OFF"]
            configure += shlex.split(os.environ.get("TEXEL_CMAKE_ARGS", ""))
            subprocess.run(configure, check=True)
        subprocess.run(["cmake", "--build", str(build_dir), "--target", "texel_python", "-j", jobs], check=True)
        built = build_dir / "python" / "texel" / f"_texel{suffix}"
        if not built.exists():
            found = sorted(p.name for p in (build_dir / "python" / "texel").glob("_texel*"))
            raise SystemExit(f"setup.py: {built} does not exist; {build_dir} holds {found or 'no extension'}: "
                             f"it was configured for another Python than {sys.executable} ({suffix})")
        shutil.copyfile(built, dest)


setup(
    version=project_version(),
    packages=["texel"],
    package_dir={"texel": "texel"},
    package_data={"texel": ["*.pyi", "py.typed"]},
    ext_modules=[Extension("texel._texel", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    zip_safe=False,
    options={"build": {"build_base": str(SETUP_BUILD)}, "egg_info": {"egg_base": str(SETUP_BUILD)}},
)
