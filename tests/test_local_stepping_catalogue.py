"""A sample of benchmarks/local_stepping/cross_check.py (the whole catalogue's cvode scenes run
with and without analysis.local_stepping; docs/sundials-ode.md, "Local stepping"): one scene
per kind, in seconds.

Two kinds of evidence: the CROSS-CHECK of every summary number and history column against the
global run within both runs' own errors (the same kernels: not verification), and the
VERIFICATION rows `martello check` makes of the scene (closed form or independent engine),
none of which may be lost with local stepping."""

import importlib.util
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]


def _script():
    path = ROOT / "benchmarks" / "local_stepping" / "cross_check.py"
    spec = importlib.util.spec_from_file_location("cross_check_under_test", path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod
    spec.loader.exec_module(mod)
    return mod


CC = _script()


@pytest.mark.parametrize("scene", ["p7/laws/p7_two_linear_cvode.toml",     # two clusters that meet
                                   "sdof/sdof_sine_cvode.toml"])          # one cluster, ground motion
def test_local_stepping_agrees_with_the_global_run_and_keeps_every_verified_row(scene):
    r = CC.one(ROOT / "benchmarks" / scene)
    assert "refused" not in r, r
    assert r["n_summary_mismatches"] == 0 and not r["missing"], r["summary_mismatches"]
    assert r["n_history_mismatches"] == 0, r["history_mismatches"]
    assert r["numbers"] > 10 and r["columns"] > 1          # it compared something
    g, loc = r["check"]["global"], r["check"]["local"]
    assert loc["verification"] > 0 and not loc["failed"], loc
    assert loc["verification_passed"] >= g["verification_passed"], r["check"]


def test_a_scene_with_rigid_contacts_is_refused_by_its_reason():
    r = CC.one(ROOT / "benchmarks" / "p2" / "p2_cvode_restitution.toml", with_check=False)
    assert "rigid" in r["refused"] and "local_stepping" in r["refused"]
