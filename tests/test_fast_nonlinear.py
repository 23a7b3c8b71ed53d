"""Fast nonlinear analysis (integrator fast-nonlinear, docs/integrators.md "Fast nonlinear
analysis"): its linear part against closed forms, and the whole method against direct
integration (Newmark at fine steps, IDA at tight tolerance) on a frame scene of the seed's
model class (docs/problems.md P10): two linear frames, gap contacts and a fluid damper."""

import math

import numpy as np
import pytest

from martello.errors import SceneError
from martello.run import run_full
from martello.scene.loader import from_dict

E = 2.5e10


def sdof(analysis, zeta=0.0, u0=0.01, force=None):
    """A one-storey portal (one lateral DOF) released from u0, or loaded by force."""
    d = {"frame": [{"prefix": "F", "storeys": 1, "bays": 1, "storey_height": 3.0, "bay_width": 5.0,
                    "column": {"E": E, "A": 0.16, "I": 2.1e-3}, "beam": {"E": E, "A": 0.12, "I": 1.6e-3},
                    "mass": 5e4, "zeta": zeta}],
         "analysis": analysis}
    if force is not None:
        d["loads"] = {"force": [{"node": "F1", "function": force}]}
    sc = from_dict(d)
    sc.nodes[0]["u0"] = u0
    return sc


def test_linear_part_is_exact_for_a_piecewise_linear_load():
    """A damped SDOF under a ramp force f = F t/τ (t ≤ τ), then constant: the load is linear
    in every step, so FNA's modal step is exact (Nigam–Jennings) at any step — here h = 10 ms,
    a quarter of the period. The closed form (Chopra, Dynamics of Structures, §4.5) is written
    here; the match is to round-off of a 4 × 4 matrix exponential (rtol 1e-9 of the static
    displacement)."""
    zeta, F, tau = 0.05, 1e5, 0.1
    an = {"type": "dynamic", "integrator": "fast-nonlinear", "dt": 0.01, "t_end": 1.0}
    sc = sdof(an, zeta=zeta, u0=0.0,
              force={"type": "table", "t": [0.0, tau, 10.0], "values": [0.0, F, F]})
    s, (cols, hist) = run_full(sc)
    k, m = sc.blocks[0]["k"][0, 0], sc.nodes[0]["mass"]
    wn = math.sqrt(k / m)
    wd = wn * math.sqrt(1 - zeta**2)

    def ramp(t):   # response to f = F t/τ from rest: u = (F/kτ)(t − 2ζ/ω + e^{−ζωt}(...))
        e = np.exp(-zeta * wn * t)
        return F / (k * tau) * (t - 2 * zeta / wn + e * (2 * zeta / wn * np.cos(wd * t)
                                - (1 - 2 * zeta**2) / wd * np.sin(wd * t)))
    t = hist[:, cols.index("t")]
    exact = np.where(t <= tau, ramp(t), ramp(t) - ramp(np.maximum(t - tau, 0.0)))
    assert np.max(np.abs(hist[:, cols.index("u:F1")] - exact)) < 1e-9 * F / k
    assert s["cost"]["modes"] == 1


def frame_pair(integrator, dt, **an):
    """A 2-storey and a 5-storey frame (joint masses), 5 mm joint, gap contacts at the two
    shared floors, a fluid damper (α = 0.15) at floor 2, a sine ground motion."""
    frame = {"bays": 2, "storey_height": 3.0, "bay_width": 5.0, "zeta": 0.05, "mass_model": "joints",
             "beam": {"E": E, "A": 0.12, "I": 1.6e-3}, "mass": 5e4}
    d = {"frame": [dict(frame, prefix="A", storeys=2, column={"E": E, "A": 0.16, "I": 2.1e-3}),
                   dict(frame, prefix="B", storeys=5, column={"E": E, "A": 0.12, "I": 1.0e-3})],
         "contact": [{"name": f"g{f}", "a": f"A{f}.2", "b": f"B{f}.0", "gap": 0.005, "scheme": "penalty",
                      "stiffness": 6e8} for f in (1, 2)],
         "link": [{"name": "fvd", "type": "fluid_damper", "a": "A2.2", "b": "B2.0", "c": 3.5e5,
                   "alpha": 0.15, "v_reg": 1e-3}],
         "loads": {"ground_acceleration": {"type": "sine", "amplitude": 3.0, "omega": 8.0, "t_end": 1.2}},
         "analysis": dict({"type": "dynamic", "integrator": integrator, "dt": dt, "t_end": 1.2}, **an)}
    return from_dict(d)


def peaks(s):
    fr = s["frames"]["B"]["members"]
    return np.array([fr["C3.0"]["M_i"]["max"], fr["C2.1"]["M_j"]["min"], fr["B2.1"]["M_i"]["max"],
                     s["contacts"]["g2"]["max_penetration"], s["links"]["fvd"]["max_abs_force"]])


@pytest.fixture(scope="module")
def reference_runs():
    """Each method at h and h/2, and IDA at rtol 1e-11 on a 0.1 ms output grid. FNA's
    iteration stops at 1e-12 of the modal force scale (its round-off floor is ~1e-13)."""
    out = {}
    for h in (1e-4, 5e-5):
        out["fna", h] = peaks(run_full(frame_pair("fast-nonlinear", h, tol_residual=1e-12,
                                                  max_newton=200))[0])
        out["newmark", h] = peaks(run_full(frame_pair("newmark", h, tol_residual=1e-13))[0])
    out["ida"] = peaks(run_full(frame_pair("ida", 1e-4, rtol=1e-11, atol=1e-14))[0])
    return out


def test_fna_agrees_with_newmark_and_ida_to_six_digits(reference_runs):
    """Peaks of member end moments, the gap penetration and the damper force. FNA and
    Newmark are both second order but with different error constants; each is extrapolated
    from h and h/2 (Richardson, p = 2), which removes the O(h²) terms of the states; what is
    left is the sampling of a peak between grid points (O(h²) too, by the curvature at the
    peak) and, for IDA, its tolerance. Measured differences of the extrapolated values are
    below 1e-6 of each peak: the bar is 1e-6 (six digits)."""
    r = reference_runs
    fna = r["fna", 5e-5] + (r["fna", 5e-5] - r["fna", 1e-4]) / 3
    nm = r["newmark", 5e-5] + (r["newmark", 5e-5] - r["newmark", 1e-4]) / 3
    assert np.all(np.abs(fna - nm) <= 1e-6 * np.abs(nm)), (fna, nm)
    assert np.all(np.abs(fna - r["ida"]) <= 1e-6 * np.abs(r["ida"])), (fna, r["ida"])
    # the gaps closed and the damper worked: the peaks are of the nonlinear response
    assert fna[3] > 1e-4 and fna[4] > 1e5


def test_fna_refuses_rigid_contacts_naming_the_integrators_that_can():
    d = {"node": [{"name": "m", "mass": 1.0}], "link": [{"type": "spring", "a": "m", "b": "ground", "k": 1.0}],
         "contact": [{"name": "c", "a": "m", "b": "ground", "scheme": "restitution", "restitution": 0.5}],
         "analysis": {"type": "dynamic", "integrator": "fast-nonlinear", "dt": 1e-3, "t_end": 1.0}}
    with pytest.raises(SceneError, match="cannot run on integrator fast-nonlinear"):
        from_dict(d)


def test_fna_runs_bilinear_links_with_their_initial_stiffness_in_the_modes():
    """An elasto-plastic SDOF (P6 type) under a half-sine pulse: FNA (the bilinear spring's
    k in the modes, its departure from k a pseudo-force) and Newmark at the same fine step
    agree on the peak and the residual displacement to the O(h²) difference of two second-
    order methods at h = 1e-4 s (ωh = 1e-3): rtol 1e-5."""
    def run(integ):
        d = {"node": [{"name": "m", "mass": 1000.0}],
             "link": [{"type": "bilinear", "a": "m", "b": "ground", "k": 1e6, "fy": 5e3, "hardening": 0.05}],
             "loads": {"force": [{"node": "m", "function": {"type": "half_sine", "amplitude": 2e4,
                                                             "t_start": 0.0, "t_end": 0.1}}]},
             "analysis": {"type": "dynamic", "integrator": integ, "dt": 1e-4, "t_end": 1.0,
                          "tol_residual": 1e-12}}
        s, (cols, hist) = run_full(from_dict(d))
        return s["nodes"]["m"]["u_max"], hist[-1, cols.index("u:m")]
    fna, nm = run("fast-nonlinear"), run("newmark")
    assert fna == pytest.approx(nm, rel=1e-5)


# ---- Wilson's load-dependent Ritz vectors (analysis.modal_vectors = m) -----------------------

def p10_frame_scene(m):
    """P10's five-storey frame alone, linear, 2 sin(8 t) m/s² from rest for 2 s (the catalogue's
    benchmarks/p10/integrators/p10_linear_fast_nonlinear.toml), on m Ritz vectors."""
    import tomllib
    from pathlib import Path
    path = Path(__file__).resolve().parents[1] / "benchmarks/p10/integrators/p10_linear_fast_nonlinear.toml"
    raw = tomllib.load(open(path, "rb"))
    raw["analysis"]["modal_vectors"] = m
    return raw


def test_ritz_vectors_meet_the_modal_closed_form_on_a_frame():
    """Verification against the closed form (modal superposition of all the frame's modes,
    martello.checks.dispatchers.frame_sine_ground_final): 10 load-dependent Ritz vectors of the
    15 DOFs give the roof displacement at t_end within the scene's tolerance for all modes,
    rtol 5.6e-4 (the O(h²) phase and amplitude error at h = 1 ms; the truncation to 10
    vectors is measured 5e-15 of the all-modes answer: the ground motion's Krylov space has
    closed by then). 5 vectors: 6.7e-8, still inside."""
    from martello.checks.dispatchers import frame_sine_ground_final
    for m in (5, 10):
        raw = p10_frame_scene(m)
        s, _ = run_full(from_dict(raw))
        assert s["cost"]["modes"] == m
        ref = frame_sine_ground_final(**{k: v for k, v in raw["check"]["params"].items()})
        assert s["nodes"]["B5.0"]["u_final"] == pytest.approx(ref["u_B5.0"], rel=5.6e-4)


def test_ritz_vectors_spanning_every_node_are_the_modes():
    """Identity of the method: with as many Ritz vectors as free nodes the basis spans the
    space and Rayleigh–Ritz returns the modes, so the frame pair with pounding and a fluid
    damper runs as on all modes (Newton on the pseudo-forces in the m-space there, Woodbury on
    S here): peaks equal to 1e-10 (round-off of two eigensolves; measured ≤ 2e-13)."""
    ref, _ = run_full(frame_pair("fast-nonlinear", 5e-4, tol_residual=1e-12, max_newton=200))
    nf = ref["cost"]["modes"]
    s, _ = run_full(frame_pair("fast-nonlinear", 5e-4, tol_residual=1e-12, max_newton=200,
                               modal_vectors=nf))
    assert s["cost"]["modes"] == nf
    np.testing.assert_allclose(peaks(s), peaks(ref), rtol=1e-10)
    assert peaks(ref)[3] > 1e-4      # the gaps closed: the nonlinear path was taken


def test_ritz_vectors_are_refused_beyond_the_free_nodes_or_below_zero():
    s, _ = run_full(from_dict(p10_frame_scene(16)), raise_on_failure=False)
    assert s["status"] == "MARTELLO_ERR_ARGUMENT"
    assert "modal_vectors = 16 exceeds the 15 free nodes" in s["message"]
    with pytest.raises(SceneError, match="modal_vectors"):
        from_dict(p10_frame_scene(-1))
