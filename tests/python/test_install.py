"""The package as Python users install it (python/README.md): pip, offline,
with Debian's pip, setuptools and wheel and no build isolation, into a fresh
venv that sees the system's numpy, and a wheel installed into a system-style
prefix. The extension is the one this build made (TEXEL_PYTHON_EXTENSION),
so the test packages and installs; it neither compiles nor runs CMake."""
import os
import pathlib
import subprocess
import sys
import zipfile

import pytest

import texel
from conftest import SOURCE_DIR

BUILD_DIR = pathlib.Path(texel.__file__).resolve().parents[2]  # <build>/python/texel/__init__.py

CHECK = r"""
import importlib.metadata, inspect, os, sys, texel
assert os.path.realpath(texel.__file__).startswith(os.path.realpath(sys.argv[1])), texel.__file__
assert texel.__version__ == importlib.metadata.version("texel"), (texel.__version__, importlib.metadata.version("texel"))
assert str(inspect.signature(texel.render)).startswith("(*, central_pitch_db: float = 10.0")
m = texel.render(seed=7)
assert m.dtype.name == "uint16" and m.shape == (19200,)
import texel.experiment
print("ok", texel.__version__)
"""


def clean_env(tmp_path):
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PIP_INDEX_URL", "PIP_FIND_LINKS")}
    (extension,) = pathlib.Path(texel._texel.__file__).parent.glob("_texel*.so")
    env["TEXEL_PYTHON_EXTENSION"] = str(extension)
    env["TEXEL_SETUP_BUILD_DIR"] = str(tmp_path / "setup")
    env["PIP_NO_INPUT"] = "1"
    env["PIP_DISABLE_PIP_VERSION_CHECK"] = "1"
    return env


def run(args, env, cwd):
    r = subprocess.run([str(a) for a in args], env=env, cwd=cwd, capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, f"{' '.join(map(str, args))}:\n{r.stdout[-3000:]}\n{r.stderr[-3000:]}"
    return r.stdout


@pytest.fixture(scope="module")
def build_dir():
    if not (BUILD_DIR / "CMakeCache.txt").exists():
        pytest.skip(f"texel is not imported from a CMake build ({texel.__file__})")
    return BUILD_DIR


def test_pip_install_into_a_venv(build_dir, tmp_path):
    env = clean_env(tmp_path)
    venv = tmp_path / "venv"
    # Without its own pip (ensurepip is most of a venv's creation time): Debian's
    # pip installs into it through --python, as the venv's own pip would.
    run([sys.executable, "-m", "venv", "--system-site-packages", "--without-pip", venv], env, tmp_path)
    python = venv / "bin" / "python"
    run([sys.executable, "-m", "pip", "--python", python, "install", "--no-build-isolation", "--no-index",
         SOURCE_DIR / "python"], env, tmp_path)
    assert run([python, "-c", CHECK, venv], env, tmp_path).startswith("ok")
    # The source tree stays clean: setuptools built under TEXEL_SETUP_BUILD_DIR.
    assert not list((SOURCE_DIR / "python").glob("*.egg-info"))


def test_wheel_into_a_system_prefix(build_dir, tmp_path):
    env = clean_env(tmp_path)
    out = tmp_path / "wheel"
    run([sys.executable, "-m", "pip", "wheel", "--no-build-isolation", "--no-index", "--no-deps", "-w", out,
         SOURCE_DIR / "python"], env, tmp_path)
    (wheel,) = out.glob("texel-*.whl")
    names = set(zipfile.ZipFile(wheel).namelist())
    for f in ("__init__.py", "_front.py", "experiment.py", "__init__.pyi", "experiment.pyi", "py.typed"):
        assert f"texel/{f}" in names
    assert any(n.startswith("texel/_texel") and n.endswith(".so") for n in names)
    # What `pip install` of the wheel does system-wide (Debian: /usr/local/lib/python3.X/dist-packages),
    # staged under a root folder.
    root = tmp_path / "root"
    run([sys.executable, "-m", "pip", "install", "--no-index", "--no-deps", "--break-system-packages", "--root", root,
         wheel], env, tmp_path)
    (site,) = {p.parent.parent for p in root.rglob("texel/__init__.py")}
    assert "dist-packages" in str(site) or "site-packages" in str(site), site
    env["PYTHONPATH"] = str(site)
    assert run([sys.executable, "-c", CHECK, site], env, tmp_path).startswith("ok")
