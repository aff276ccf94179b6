"""How pip builds pdp (pyproject.toml): CMake configures the repository
once, builds the compiled core pdp._pdp and the pdp command, and setuptools
puts the core beside the package python/pdp and the command among the
environment's scripts (<venv>/bin/pdp). The command finds the package's
report.py where it is installed (PDP_PYTHON_INSTALL_DIR, the environment's
site-packages relative to its prefix), so `pdp report` works from the
install as from the build tree.

Settings (environment): PDP_BUILD_JOBS, the parallel build jobs (default:
the machine's cores); PDP_CMAKE_ARGS, more CMake arguments."""

import os
import re
import shlex
import subprocess
import sys
import sysconfig
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

try:
    from setuptools.command.build_scripts import build_scripts
except ImportError:  # setuptools before 66 (a venv's own): distutils' step, which setuptools provides
    from distutils.command.build_scripts import build_scripts

ROOT = Path(__file__).resolve().parent


def version():
    """The one version: CMakeLists.txt's project(pdp VERSION ...)."""
    found = re.search(r"project\(pdp\s+VERSION\s+([0-9][0-9.]*)", (ROOT / "CMakeLists.txt").read_text())
    if not found:
        raise RuntimeError("CMakeLists.txt: no project(pdp VERSION x.y.z)")
    return found.group(1)


def cmake_tree(command):
    """The CMake build folder of this build (under setuptools' build_temp)."""
    return Path(command.get_finalized_command("build_ext").build_temp).resolve() / "cmake"


class CMakeExtension(Extension):
    def __init__(self, name):
        super().__init__(name, sources=[])


class CMakeBuild(build_ext):
    """Configures and builds the core and the command once."""

    def build_extension(self, ext):
        tree = cmake_tree(self)
        # Where the package lands relative to the environment's prefix, as this
        # interpreter names it (a venv: lib/python3.X/site-packages).
        site = sysconfig.get_path("platlib", vars={"base": "/PREFIX", "platbase": "/PREFIX"})
        site = os.path.relpath(site, "/PREFIX")
        configure = ["cmake", "-S", str(ROOT), "-B", str(tree), "-DCMAKE_BUILD_TYPE=Release",
                     "-DPDP_BUILD_TESTS=OFF", "-DPDP_BUILD_BENCHMARKS=OFF", "-DPDP_BUILD_PYTHON=ON",
                     f"-DPython3_EXECUTABLE={sys.executable}", f"-DPDP_PYTHON_INSTALL_DIR={site}"]
        configure += shlex.split(os.environ.get("PDP_CMAKE_ARGS", ""))
        subprocess.run(configure, check=True)
        jobs = os.environ.get("PDP_BUILD_JOBS", str(os.cpu_count() or 2))
        subprocess.run(["cmake", "--build", str(tree), "--target", "pdp_python_core", "pdp", "-j", jobs], check=True)
        cores = sorted((tree / "python" / "pdp").glob("_pdp*.so"))
        if len(cores) != 1:
            raise RuntimeError(f"{tree / 'python' / 'pdp'}: expected one compiled core _pdp*.so, found {cores}")
        target = Path(self.get_ext_fullpath(ext.name)).resolve()
        self.mkpath(str(target.parent))
        self.copy_file(str(cores[0]), str(target))


class CommandScript(build_scripts):
    """The pdp command is the C++ executable: copied as it is (setuptools'
    own step would read it as a text script)."""

    def run(self):
        self.mkpath(self.build_dir)
        self.copy_file(str(cmake_tree(self) / "tools" / "pdp"), os.path.join(self.build_dir, "pdp"))


# Setuptools' folders under build-pip/ (ignored by git), apart from the CMake
# trees of scripts/build (build/) that its default would write into.
(ROOT / "build-pip").mkdir(exist_ok=True)

setup(
    version=version(),
    options={"build": {"build_base": "build-pip"}, "egg_info": {"egg_base": "build-pip"}},
    packages=["pdp"],
    package_dir={"pdp": "python/pdp"},
    package_data={"pdp": ["*.j2"]},
    ext_modules=[CMakeExtension("pdp._pdp")],
    # Replaced by CommandScript: one entry so that the install step copies the scripts.
    scripts=["tools/pdp/main.cpp"],
    cmdclass={"build_ext": CMakeBuild, "build_scripts": CommandScript},
    zip_safe=False,
)
