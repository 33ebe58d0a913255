"""The Python examples (examples/python/*.py) run."""
import os
import subprocess
import sys

import pytest

from conftest import SOURCE_DIR

EXAMPLES = sorted((SOURCE_DIR / "examples" / "python").glob("*.py"))


def test_there_are_examples():
    assert len(EXAMPLES) >= 2


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.name)
def test_example_runs(path, tmp_path):
    r = subprocess.run([sys.executable, str(path)], capture_output=True, text=True, cwd=tmp_path, env=dict(os.environ),
                       timeout=300)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip()
