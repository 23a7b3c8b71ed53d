"""P7's special cases (docs/problems.md P7) on the library's Newmark, each against a closed
form, and Anagnostopoulos' (1988) published result on a row of three (a published
qualitative result, checked on the library and on the independent engine)."""

import copy
import math
from pathlib import Path

import numpy as np
import pytest

from martello import independent
from martello.oracles.linear_sdof import sdof_sine_ground_response
from martello.oracles.p5_contact_laws import kelvin_xi_from_e
from martello.run import run_full
from martello.scene.loader import from_dict, load

ROOT = Path(__file__).resolve().parent.parent
ROW = ROOT / "benchmarks/p7/p7_row_3.toml"


def chain(k, gap, n=None, t_end=2.0, dt=1e-4):
    k = list(k)
    return {"chain": [{"prefix": "s", "n": n or len(k), "mass": 1.0, "k": k, "zeta": 0.05, "gap": gap,
                       "contact": {"scheme": "penalty", "law": "kelvin", "stiffness": 1e5, "restitution": 0.65}}],
            "loads": {"ground_acceleration": {"type": "sine", "amplitude": 3.0, "omega": 8.0}},
            "analysis": {"type": "dynamic", "integrator": "newmark", "dt": dt, "t_end": t_end,
                         "output": {"every": 100}}}


def test_identical_neighbours_never_touch():
    # identical oscillators in the same initial state move as one: exactly no contact
    summary, _ = run_full(from_dict(chain([100.0] * 3, 0.001)))
    assert all(c["impacts"] == 0 for c in summary["contacts"].values())
    u = [summary["nodes"][f"s{i}"]["u_max"] for i in (1, 2, 3)]
    assert u[0] == u[1] == u[2]


def test_huge_gaps_give_independent_sdofs():
    # no contact ever closes: each oscillator is the damped SDOF of the closed form
    doc = chain([100.0, 400.0], 1e3)
    doc["analysis"]["output"]["nodes"] = ["s1", "s2"]
    summary, _ = run_full(from_dict(doc))
    for name, k in (("s1", 100.0), ("s2", 400.0)):
        ex = sdof_sine_ground_response(1.0, k, 0.05, 3.0, 8.0, np.array([2.0]))
        # second order: phase error ~ (ωΔt)²/12 · ω t ≈ 1e-7 rad at ω = 20, Δt = 1e-4, t = 2 s
        assert summary["nodes"][name]["u_final"] == pytest.approx(float(ex.u[0]), abs=1e-6 * 0.03)
    assert summary["contacts"]["s1-s2"]["impacts"] == 0


def test_two_free_masses_give_p5():
    # no springs, no ground motion: the chain's contact is P5's two-body Kelvin impact
    scene = {"node": [{"name": "s1", "mass": 1.0, "v0": 1.0}, {"name": "s2", "mass": 1.0}],
             "contact": [{"name": "s1-s2", "a": "s1", "b": "s2", "gap": 0.001, "scheme": "penalty",
                          "law": "kelvin", "stiffness": 1e5, "restitution": 0.65}],
             "analysis": {"type": "dynamic", "integrator": "newmark", "dt": 1e-7, "t_end": 0.02,
                          "output": {"every": 1000}}}
    c = run_full(from_dict(scene))[0]["contacts"]["s1-s2"]
    xi = kelvin_xi_from_e(0.65)
    # realised e exact for the unclipped law; the force jump cδ̇ costs O(ξωΔt) ≈ 5e-6
    assert c["restitution"][0] == pytest.approx(0.65, abs=5e-5)
    assert c["contact_time"] == pytest.approx(math.pi / (math.sqrt(1e5 / 0.5) * math.sqrt(1 - xi * xi)), rel=1e-6)


def alone(k):
    return {"node": [{"name": "m", "mass": 1.0}],
            "link": [{"type": "spring", "a": "m", "b": "ground", "k": k},
                     {"type": "dashpot", "a": "m", "b": "ground", "zeta": 0.05}],
            "loads": {"ground_acceleration": {"type": "sine", "amplitude": 3.0, "omega": 8.0}},
            "analysis": {"type": "dynamic", "integrator": "newmark", "dt": 1e-4, "t_end": 4.0,
                         "output": {"every": 100}}}


KS = (250.0, 100.0, 160.0)     # benchmarks/p7/p7_row_3.toml


def test_end_buildings_of_a_row_respond_more_the_interior_one_less():
    # Anagnostopoulos (1988): in a row the end structures respond more because of pounding,
    # the interior ones often less (a published qualitative result; ratios far from 1 here)
    row = run_full(load(ROW))[0]["nodes"]
    solo = [max(abs(n["u_max"]), abs(n["u_min"])) for n in (run_full(from_dict(alone(k)))[0]["nodes"]["m"]
                                                           for k in KS)]
    ratio = [max(abs(row[f"r{i + 1}"]["u_max"]), abs(row[f"r{i + 1}"]["u_min"])) / solo[i] for i in range(3)]
    assert ratio[0] > 1.5 and ratio[2] > 1.05 and ratio[1] < 0.6


def test_the_independent_engine_shows_the_same_row_result():
    ref = independent.run_once(ROW, rtol=1e-9)
    solo = []
    for k in KS:
        s = alone(k)
        s["analysis"].pop("integrator")
        solo.append(independent.run_once(s, rtol=1e-9)["nodes"]["m"]["u_absmax"])
    ratio = [ref["nodes"][f"r{i + 1}"]["u_absmax"] / solo[i] for i in range(3)]
    assert ratio[0] > 1.5 and ratio[2] > 1.05 and ratio[1] < 0.6
