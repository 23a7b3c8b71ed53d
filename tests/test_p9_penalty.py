"""P9's forced oscillator on a penalty barrier (benchmarks/p9/p9_davis_penalty_kelvin.toml,
docs/problems.md P9). Its catalogue rows verify it against its own converged reference (the
independent engine); the rigid period-1 orbit of Davis (1992) is another model, and how far
the penalty orbit lies from it is a model difference, measured here, not verification."""

import math
from pathlib import Path

import numpy as np

from martello.checks.independent_rows import find_independent
from martello.oracles.p9_davis import davis_period1_damped
from martello.run import run
from martello.scene.loader import load

SCENE = Path(__file__).resolve().parent.parent / "benchmarks/p9/p9_davis_penalty_kelvin.toml"


def test_the_penalty_orbit_approaches_the_rigid_one_as_one_over_root_eps():
    # Model difference: the contact lasts π/√(ε/m) and the spring and the forcing act during
    # it, so the penalty orbit's impact speed differs from the rigid orbit's V by O(1/√ε).
    # Measured (rk8pd, rtol 1e-11, 60th period): 1.64e-2, 5.0e-3, 1.57e-3, 4.96e-4 of V at
    # ε/k = 1e4 … 1e7, slope −0.50 per decade of ε.
    V = davis_period1_damped(1.0, 1.5, 0.8, zeta=0.05).V
    eps = np.array([1e4, 1e5, 1e6, 1e7])
    diff = []
    for e in eps:
        s = load(SCENE)
        s.contacts[0]["stiffness"] = float(e)
        diff.append(abs(run(s)["contacts"]["barrier"]["approach_speeds"][-1] - V) / V)
    slope = np.polyfit(np.log10(eps), np.log10(diff), 1)[0]
    assert abs(slope + 0.5) <= 0.05, (slope, diff)
    assert 1e-3 < diff[2] < 3e-3


def test_the_penalty_scene_is_verified_against_its_own_reference():
    # the catalogue finds the independent engine's reference of this very physics
    ref = find_independent(load(SCENE))
    assert ref is not None and ref["name"] == "p9_davis_penalty_kelvin"
    assert len(ref["contacts"]["barrier"]["phases"]) == 60 and not ref["ambiguous"]
    assert ref["trusted_digits"] >= 8
    assert math.isclose(ref["t_end"], 251.32741228718345)
