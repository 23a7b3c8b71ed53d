"""Shared fixtures. The package is installed in .venv (editable) by scripts/setup; the path
line below also lets `python -m pytest` work from a checkout without that install."""

import atexit
import copy
import os
import shutil
import sys
import tempfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))
# References computed on demand (docs/reference.md) go to a cache of the test session, never
# to the user's (subprocesses inherit it)
os.environ["MARTELLO_CACHE_DIR"] = tempfile.mkdtemp(prefix="martello-test-cache-")
atexit.register(shutil.rmtree, os.environ["MARTELLO_CACHE_DIR"], True)


def p1_dict(scheme="lagrange", **contact):
    """P1 as a scene dict (m = 1, k = 100, h = 0.05, g = 9.81), for tests to vary."""
    c = {"name": "plane", "a": "mass", "b": "ground", "gap": 0.05, "scheme": scheme}
    c.update(contact)
    return {
        "title": "P1 test",
        "node": [{"name": "mass", "mass": 1.0}],
        "link": [{"name": "spring", "type": "spring", "a": "mass", "b": "ground", "k": 100.0}],
        "contact": [c],
        "loads": {"gravity": 9.81},
        "analysis": {"type": "static"},
    }


@pytest.fixture
def p1():
    return copy.deepcopy(p1_dict())
