"""Every switching surface is an event on the adaptive paths (docs/event-driven.md, switching
surfaces; docs/ida.md): bilinear yield and unloading, penalty onset and separation, the Kelvin
cut-off, the kinks of the loads. Verification against independent oracles: the scipy
event-located reference of benchmarks/events/reference.py (no martello code: DOP853 with every
switch a terminal event, rtol 2.3e-14 (its floor), trusted to ~1e-11 relative on extrema and ~1e-10 on the
final displacements, measured by repeating it at rtol 1e-13), and the closed form of an
undamped oscillator under a rectangular pulse."""
import copy
import math
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

from dynamics_helpers import dynamic, execute, sdof

EVENTS = Path(__file__).resolve().parent.parent / "benchmarks" / "events"
sys.path.insert(0, str(EVENTS))
import reference  # noqa: E402  (the independent engine)


def _scene(name, **analysis):
    d = tomllib.loads((EVENTS / name).read_text())
    d = copy.deepcopy(d)
    d["analysis"].update(analysis)
    return d


@pytest.fixture(scope="module")
def references():
    out = {}
    for name in ("pounding_bilinear.toml", "pounding_kelvin.toml"):
        sc, ext = reference.solve(EVENTS / name, rtol=2.3e-14, atol=1e-18)
        q = reference.quantities(sc, ext)
        q["contacts.gap.max_penetration"] = ext["pen"][0]
        out[name] = q
    return out


def worst_error(summary, refq):
    worst = 0.0
    for key, ref in refq.items():
        kind, name, field = key.split(".")
        worst = max(worst, abs(summary[kind][name][field] - ref) / abs(ref))
    return worst


@pytest.mark.parametrize("name", ["pounding_bilinear.toml", "pounding_kelvin.toml"])
def test_rk8pd_error_follows_rtol_on_hysteretic_pounding(name, references):
    # Yield, unloading, onset, separation (and the Kelvin cut-off) located as events: the
    # state is smooth inside every step, so rk8pd's error shrinks with rtol. Measured worst
    # relative error (u max/min, final u, peak penetration): 2.0e-7 / 1.6e-7 at rtol 1e-8,
    # 3.1e-10 / 7.3e-11 at rtol 1e-11 (before: ~1e-3 at any rtol, the return map inside RK
    # stages). Bounds: a factor 100 over three decades of rtol (slope >= 2/3) and the
    # rtol 1e-11 run within 1e-8 (the reference trusts ~1e-10).
    e8 = worst_error(execute(_scene(name, rtol=1e-8, atol=1e-11))[0], references[name])
    e11 = worst_error(execute(_scene(name, rtol=1e-11, atol=1e-14))[0], references[name])
    assert e11 < 1e-8
    assert e11 < e8 / 100.0


@pytest.mark.parametrize("integrator,rtol,bound", [
    ("rkf45", 1e-10, 1e-7),    # measured 2.9e-9 / 1.2e-8 (bilinear / Kelvin)
    ("ida", 1e-11, 1e-6),      # measured 3.4e-8 (BDF, restarts at every switch)
])
def test_other_adaptive_integrators_agree_with_the_reference(integrator, rtol, bound, references):
    for name, refq in references.items():
        s, _ = execute(_scene(name, integrator=integrator, rtol=rtol, atol=1e-3 * rtol))
        assert worst_error(s, refq) < bound, (name, integrator)


def test_ida_from_rest_at_tight_tolerance_with_one_far_output(references):
    # From rest with the first output at t_end: IDA's own first-step guess (from the output
    # time) made its error test fail at t = 0 (IDA_ERR_FAIL); the first step is now set from
    # the state (docs/ida.md, initial step). The run ends exactly at t_end.
    s, h = execute(_scene("pounding_bilinear.toml", integrator="ida", rtol=1e-12, atol=1e-15,
                          dt=8.0))
    assert s["status"] == "MARTELLO_OK"
    assert h["t"][-1] == 8.0 and s["t_reached"] == 8.0
    assert worst_error(s, references["pounding_bilinear.toml"]) < 1e-6   # measured 4.4e-9


@pytest.mark.parametrize("integrator", ["rk8pd", "ida"])
def test_output_interval_means_dt_times_every_on_both_paths(integrator, references):
    # One meaning of the output interval (docs/run-layer.md): rows at t = k·every·dt and at
    # t_end, exactly, for GSL and IDA alike; the last row is the state at t_end (IDA used to
    # stop up to 1e-9·dt·every short of it and label it t_end).
    d = _scene("pounding_bilinear.toml", integrator=integrator, rtol=1e-11, atol=1e-14, dt=0.3)
    d["analysis"]["output"] = {"every": 7}
    s, h = execute(d)
    expected = np.concatenate([[0.0], (np.arange(1, 4) * 7) * 0.3, [8.0]])   # t = k dt
    assert np.array_equal(h["t"], expected)
    ref = references["pounding_bilinear.toml"]
    for node in ("left", "right"):
        key = f"nodes.{node}.u_final"
        assert abs(h[f"u:{node}"][-1] - ref[key]) < 1e-6 * abs(ref[key])


@pytest.mark.parametrize("integrator", ["rk8pd", "rkf45", "ida"])
def test_a_rectangular_pulse_is_a_stop(integrator):
    # The window's start and end are kinks of the load (docs/event-driven.md, time events):
    # the integrators stop there and restart, so the closed form of an undamped oscillator,
    # u = F/k (1 - cos wt) during the pulse and F/k (cos w(t - t1) - cos wt) after it, is met
    # to the tolerance. The pulse ends at t1 = 0.3337 s, inside a step of the unstopped run.
    m, k, F, t1 = 1.0, 100.0, 2.0, 0.3337
    w = math.sqrt(k / m)
    d = sdof(m, k, analysis=dynamic(integrator, dt=0.1, t_end=1.0, rtol=1e-11, atol=1e-14))
    d["loads"] = {"force": [{"node": "m", "function": {"type": "rectangular", "amplitude": F,
                                                       "t_start": 0.0, "t_end": t1}}]}
    s, h = execute(d)
    t = h["t"]
    exact = np.where(t < t1, F / k * (1 - np.cos(w * t)),
                     F / k * (np.cos(w * (t - t1)) - np.cos(w * t)))
    bound = 1e-7 if integrator == "ida" else 1e-9    # measured 1.6e-10 rk8pd, 3e-9 ida
    assert np.max(np.abs(h["u:m"] - exact)) < bound * F / k


@pytest.fixture(scope="module")
def elastic_pounding():
    """The two-oscillator scene with springs that never yield (F_y = 1e6 N): no switch of a
    link falls on a node's extremum, so extrema are found only where they are located."""
    d = tomllib.loads((EVENTS / "pounding_bilinear.toml").read_text())
    for ln in d["link"]:
        ln["fy"] = 1e6
    sc, ext = reference.solve(d, rtol=2.3e-14, atol=1e-18)
    return d, reference.quantities(sc, ext)


@pytest.mark.parametrize("integrator", ["rkf45", "rk8pd", "msbdf", "ida"])
def test_node_extrema_are_located_inside_the_steps(integrator, elastic_pounding):
    # u max, u min and u_peak against the extrema the independent reference locates on its
    # dense output, at rtol 1e-11. Located (the root of v on a re-integrated state with a
    # parabolic correction, docs/run-layer.md) they carry the stepper's error: measured
    # 3.2e-12 rk8pd, 1.1e-10 rkf45, 1.9e-8 msbdf (its own error at this tolerance), for 7% more
    # RHS evaluations (rk8pd); IDA, bisection on its interpolant: 4.5e-9. Sampled at the
    # steps, with u_peak interpolated, they were off by 2.5e-3, 4.2e-6, 1.7e-5 and 1.7e-5.
    d, refq = elastic_pounding
    d = copy.deepcopy(d)
    d["analysis"].update(integrator=integrator, rtol=1e-11, atol=1e-14)
    s, _ = execute(d)
    bound = 1e-6 if integrator in ("msbdf", "ida") else 1e-8
    for node in ("left", "right"):
        n = s["nodes"][node]
        for field in ("u_max", "u_min"):
            ref = refq[f"nodes.{node}.{field}"]
            assert abs(n[field] - ref) < bound * abs(ref), (node, field)
        assert abs(n["u_peak"] - refq[f"nodes.{node}.u_max"]) < bound * abs(n["u_max"])


@pytest.mark.parametrize("integrator", ["newmark", "generalized-alpha", "central-difference",
                                        "rk8pd", "ida"])
@pytest.mark.parametrize("v0", [1.0, -1.0])
def test_u_absmax_is_the_located_peak_of_abs_u(integrator, v0):
    # Closed form: the undamped SDOF (k/m = 100, ω = 10 rad/s) from u = 0 at v0 reaches
    # |u| = |v0|/ω = 0.1 m first at t = π/(2ω) (a maximum for v0 > 0, a minimum for v0 < 0).
    # The fixed-step solutions are known in closed form too (Hughes 2000, §9.3): Newmark
    # (average acceleration) keeps the amplitude on its steps at the discrete frequency
    # ω_h = (2/h)·atan(ωh/2); central difference runs at ω_h = (2/h)·asin(ωh/2) with the
    # amplitude 1/√(1 − (ωh/2)²) larger. At ωh = 0.05 the turn falls 0.42 of a step from the
    # nearest step, whose |u| is (0.42ωh)²/2 ≈ 2.2e-4 relative low; the cubic Hermite on
    # (u, v) of the step around the turn is O((ωh)⁴) ≈ 6e-6 in u (measured 4.7e-8) and
    # O((ωh)³)/ω ≈ 1.3e-5 s in t (measured 8e-8 s, 3e-7 s): asserted at 1e-6 and 1e-6 s.
    # generalized-α (ρ∞ = 0.9) dissipates O((ωh)³) per radian: |u| within (ωh)³/10, its
    # period within 1.5× Newmark's. Adaptive (rtol 1e-10): located to their own error, 1e-8.
    h, w = 5e-3, 10.0
    extra = {"rtol": 1e-10, "atol": 1e-13} if integrator in ("rk8pd", "ida") else \
        {"rho_inf": 0.9} if integrator == "generalized-alpha" else {}
    d = sdof(v0=v0)
    d["analysis"] = dynamic(integrator=integrator, dt=h, t_end=0.2, **extra)
    s, _ = execute(d)
    n = s["nodes"]["m"]
    amplitude, w_h, bound_u, bound_t = 0.1, w, 1e-8, 1e-6
    if integrator == "newmark":
        w_h, bound_u = 2 / h * math.atan(w * h / 2), 1e-6
    elif integrator == "central-difference":
        w_h, bound_u = 2 / h * math.asin(w * h / 2), 1e-6
        amplitude = 0.1 / math.sqrt(1 - (w * h / 2) ** 2)
    elif integrator == "generalized-alpha":
        bound_u, bound_t = (w * h) ** 3 / 10, 1.5 * (w * h) ** 2 / 12 * math.pi / 20
    assert abs(n["u_absmax"] - amplitude) < bound_u * amplitude
    assert abs(n["t_absmax"] - math.pi / (2 * w_h)) < bound_t
    if v0 < 0:
        assert n["u_min"] < 0 and n["u_absmax"] >= -n["u_min"]


def test_v_absmax_is_located_inside_the_fixed_steps():
    # Closed form: the undamped SDOF (ω = 10 rad/s) from u0 = 0.1 m at rest has |v| = ωu0 =
    # 1 m/s first at t = π/(2ω). Newmark (average acceleration) keeps ½v² + ½ω²u² on its
    # steps, so its velocity amplitude is exact; at ωh = 0.05 the peak of |v| falls 0.42 of a
    # step from the nearest step, whose |v| is ≈ 2.2e-4 low. The cubic Hermite on (v, a) of
    # the step where a changes sign is O((ωh)⁴) ≈ 6e-6: asserted at 1e-6 relative (measured
    # 4.6e-8, as for u in the test above).
    d = sdof(u0=0.1)
    d["analysis"] = dynamic(dt=5e-3, t_end=0.2)
    s, h = execute(d)
    assert abs(s["nodes"]["m"]["v_absmax"] - 1.0) < 1e-6
    assert 1.0 - np.max(np.abs(h["v:m"])) > 1e-4      # the steps alone are this far below
