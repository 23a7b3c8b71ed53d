"""The stability atlas (martello.study.atlas): classification of runs, and the central-difference
boundary, which must fall at Δt_crit = 2/ω_max (docs/problems.md "Integrators": h_crit = 2/ω for
an undamped oscillator). Tiny sweeps; the committed atlas is run by `martello study`."""

import csv
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from martello.batch import execute
from martello.study import atlas

ROOT = Path(__file__).resolve().parent.parent
CD = {"label": "central difference", "integrator": "central-difference",
      "params": {"check_stability": False}, "rtol": []}
NEWMARK = {"label": "Newmark", "integrator": "newmark",
           "params": {"preset": "average-acceleration"}, "rtol": []}


def point(method, experiment, ratio, **y):
    (ya, yv), = y.items()
    mp = {"name": "t", "experiment": experiment, "x": {"dt_ratio": [ratio]}, "y": {ya: [yv]},
          "fixed": {}}
    spec, exp, par = atlas.point_spec(mp, method, ratio, yv, 0)
    res = execute(spec)
    return atlas.classify(res, exp), res, exp


@pytest.mark.parametrize("stiffness_ratio", [1.0, 1e6, 1e12])
def test_central_difference_boundary_is_two_over_omega_max(stiffness_ratio):
    # zero gap: the mass stays in contact and the system is linear with
    # ω_max = √((k + ε)/m); central difference (velocity Verlet) is stable iff ω Δt ≤ 2.
    # On either side by 2 %, the classes must differ: bounded (if inaccurate: the discrete
    # amplitude is h v0 / sin(ω̃h), 5x the exact one at ωh = 1.96) against growing errors.
    for ratio in (0.9, 0.98):
        (cls, det), res, exp = point(CD, "zero_gap", ratio, stiffness_ratio=stiffness_ratio)
        assert cls in ("accurate", "inaccurate"), (ratio, cls, det)
        assert det["error_growth"] < 10
        # the library's own Δt_crit agrees with 2/ω_max from the scene's parameters
        reported = res["summary"]["stability"]["dt_critical"]
        assert reported == pytest.approx(2.0 / exp.omega_max, rel=1e-10)
    for ratio in (1.02, 1.1):
        (cls, det), res, exp = point(CD, "zero_gap", ratio, stiffness_ratio=stiffness_ratio)
        assert cls == "unstable", (ratio, cls, det, res.get("message"))


def test_newmark_average_acceleration_never_unstable_in_persistent_contact():
    (cls, det), res, exp = point(NEWMARK, "zero_gap", 10.0, stiffness_ratio=1e8)
    assert cls == "inaccurate" and det["error_growth"] < 10


def test_small_steps_are_accurate_on_every_experiment():
    for experiment, y in (("impact", {"stiffness_ratio": 1e4}), ("two_body", {"mass_ratio": 1e3}),
                          ("zero_gap", {"stiffness_ratio": 1e4}), ("zeno", {"restitution": 0.5})):
        ratio = 0.01 if experiment == "zero_gap" else 0.02
        for method in (CD, NEWMARK):
            (cls, det), _, _ = point(method, experiment, ratio, **y)
            assert cls == "accurate", (experiment, method["label"], det)


def test_classification_of_failures():
    (cls, _), _, exp = point(CD, "impact", 0.5, stiffness_ratio=1e4)
    assert atlas.classify({"status": "MARTELLO_ERR_UNSUPPORTED"}, exp)[0] == "unavailable"
    assert atlas.classify({"status": "MARTELLO_ERR_DIVERGED", "message": "diverged at t = 1 s: "
                           "non-finite state (NaN/inf)"}, exp)[0] == "failed"
    assert atlas.classify({"status": "MARTELLO_ERR_DIVERGED", "message": "mechanical energy"}, exp)[0] == "unstable"
    assert atlas.classify({"status": "MARTELLO_ERR_NOT_CONVERGED"}, exp)[0] == "failed"
    assert atlas.classify({"status": "MARTELLO_ERR_STEP_UNDERFLOW"}, exp)[0] == "failed"


def test_an_impact_that_creates_energy_is_unstable():
    # one impact at Δt = 2 Δt_crit: the trapezoidal rule with a penalty wall rebounds
    # faster than it arrived (realised e ≈ 2.1 for a target 0.8): energy created at the
    # contact, which the run layer reports as a divergence (docs/behaviour.md)
    (cls, det), res, _ = point(NEWMARK, "impact", 2.0, stiffness_ratio=1e4)
    assert cls == "unstable"
    assert res["status"] == "MARTELLO_ERR_DIVERGED" and "created energy" in res["message"]


ATLAS = """
kind = "atlas"
title = "tiny atlas"
[[method]]
label = "central difference"
integrator = "central-difference"
params = { check_stability = false }
[[method]]
label = "rkf45"
integrator = "rkf45"
rtol = [1e-6]
[[map]]
name = "zero gap"
experiment = "zero_gap"
x = { dt_ratio = [0.5, 2.0] }
y = { stiffness_ratio = [1e4] }
"""


def test_atlas_cli_writes_csv_map_and_summary(tmp_path):
    f = tmp_path / "atlas.toml"
    f.write_text(ATLAS)
    r = subprocess.run([sys.executable, "-m", "martello", "study", f, "-o", tmp_path / "out"],
                       cwd=ROOT, capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    rows = list(csv.DictReader(open(tmp_path / "out" / "atlas.csv")))
    assert len(rows) == 3
    cd = {float(x["x"]): x["class"] for x in rows if x["integrator"] == "central-difference"}
    assert cd[0.5] in ("accurate", "inaccurate") and cd[2.0] == "unstable"
    rk = [x for x in rows if x["integrator"] == "rkf45"][0]
    assert rk["class"] in atlas.CLASSES and rk["x_axis"] == "rtol"
    assert (tmp_path / "out" / "atlas__zero_gap.png").stat().st_size > 5000
    assert "largest stable" in (tmp_path / "out" / "atlas.md").read_text()


def test_atlas_file_errors(tmp_path):
    f = tmp_path / "atlas.toml"
    f.write_text(ATLAS.replace('experiment = "zero_gap"', 'experiment = "nope"'))
    from martello.errors import MartelloError
    with pytest.raises(MartelloError, match="unknown experiment 'nope'"):
        atlas.load_atlas(f)
    f.write_text(ATLAS.replace("x = { dt_ratio = [0.5, 2.0] }", "x = { speed = [1] }"))
    with pytest.raises(MartelloError, match="must name one axis"):
        atlas.load_atlas(f)
