"""Shared fixtures: the CLI to compare against (TEXEL_BIN, set by ctest) and
the source tree (examples, protocols)."""
import json
import os
import pathlib
import subprocess

import pytest

SOURCE_DIR = pathlib.Path(os.environ.get("TEXEL_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))


def _texel_bin():
    env = os.environ.get("TEXEL_BIN")
    if env:
        return pathlib.Path(env)
    for build in ("build", "build-py"):
        p = SOURCE_DIR / build / "bin" / "texel"
        if p.exists():
            return p
    return None


@pytest.fixture(scope="session")
def source_dir():
    return SOURCE_DIR


@pytest.fixture(scope="session")
def cli():
    """Runs the texel CLI; returns stdout (raises on a non-zero exit)."""
    exe = _texel_bin()
    if exe is None or not exe.exists():
        pytest.fail("the texel CLI was not found: set TEXEL_BIN (ctest does)")

    def run(*args, check=True):
        r = subprocess.run([str(exe), *map(str, args)], capture_output=True, text=True)
        if check and r.returncode != 0:
            raise AssertionError(f"texel {' '.join(map(str, args))} exited {r.returncode}: {r.stderr}")
        return r

    return run


@pytest.fixture(scope="session")
def cli_json(cli):
    def run(*args):
        return json.loads(cli(*args).stdout)

    return run
