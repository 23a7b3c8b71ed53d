"""The seed's Newmark–Lagrange scheme (Papadrakakis et al. 1991, seed eq. 48;
docs/problems.md "Integrators", Lagrange + Newmark; docs/integrators.md): Newmark with the
contact held at the displacement level by a multiplier and (β, γ) re-chosen in each impact
step so that the relative velocity leaves at −e times the approach speed. On P2 and P5,
against closed forms, and its cost against Moreau–Jean on the same scene (run with -s to see
the table)."""

import math
import time

import numpy as np
import pytest

from martello.oracles.p2_bouncing import bouncing_oscillator_restitution
from martello.oracles.p5_contact_laws import newton_impact
from dynamics_helpers import execute, slope

EPS = np.finfo(float).eps
M, K, GAP, G = 1.0, 100.0, 0.05, 9.81
W = math.sqrt(K / M)
US = M * G / K


def p2(dt, t_end, e=0.8, u0=0.0, v0=0.0, integrator="newmark-lagrange", every=1):
    an = {"type": "dynamic", "integrator": integrator, "dt": dt, "t_end": t_end,
          "output": {"every": every}}
    return execute({
        "node": [{"name": "mass", "mass": M, "u0": u0, "v0": v0}],
        "link": [{"type": "spring", "a": "mass", "b": "ground", "k": K}],
        "contact": [{"name": "plane", "a": "mass", "b": "ground", "gap": GAP,
                     "scheme": "restitution", "restitution": e}],
        "loads": {"gravity": G}, "analysis": an})


@pytest.fixture(scope="module")
def p2_run():
    """e = 0.8, h = 1e-4, through the Zeno point (t∞ = 1.29967 s) to rest."""
    return p2(1e-4, 2.0)


def test_p2_restitution_and_first_impact(p2_run):
    s, h = p2_run
    dt = 1e-4
    c = s["contacts"]["plane"]
    ref = bouncing_oscillator_restitution(M, K, GAP, G, 0.8, 8)
    # Every impact leaves at exactly −e v_in: that is what (β, γ) are solved for; the only
    # error is the rounding of the step (measured 9e-16).
    assert len(c["restitution"]) >= 8
    np.testing.assert_allclose(c["restitution"], 0.8, rtol=0, atol=64 * EPS)
    # The first impact is located by the quadratic root inside the step, so its time error is
    # that of the trapezoidal flight before it: the phase lag ω²h²t/12 (docs/problems.md: the
    # trapezoidal ω̄ = (2/h)atan(ωh/2)). Measured 8.82e-9 against 8.82e-9 predicted.
    lag = W ** 2 * dt ** 2 * ref.t[0] / 12
    assert c["impact_times"][0] - ref.t[0] == pytest.approx(lag, rel=0.05)


def test_p2_orders():
    """Later impact times are first order: the constraint puts the mass back on the plane at
    the end of the impact step, where it should already be e·v·(1 − α)h away, so each rebound
    starts (1 − α)h late. The approach speeds are second order (the flight is trapezoidal and
    the tuned step gives the rebound speed exactly). Errors averaged over 8 phases of the
    start, as in test_moreau_jean. Measured slopes 1.03 (times) and 1.97 (speeds)."""
    n_imp, n_phase = 6, 8
    hs = [1e-3 / 2 ** j for j in range(5)]
    et, ev = [], []
    for dt in hs:
        errs_t, errs_v = [], []
        for i in range(n_phase):
            s0 = i / n_phase * dt
            u0, v0 = US * (1 - math.cos(W * s0)), US * W * math.sin(W * s0)
            ref = bouncing_oscillator_restitution(M, K, GAP, G, 0.8, n_imp, u0=u0, v0=v0)
            s, _ = p2(dt, 0.9, u0=u0, v0=v0, every=10 ** 6)
            c = s["contacts"]["plane"]
            errs_t.append(np.abs(np.array(c["impact_times"][:n_imp]) - ref.t))
            errs_v.append(np.abs(np.array(c["approach_speeds"][:n_imp]) - ref.v))
        et.append(np.mean(errs_t))
        ev.append(np.mean(errs_v))
    assert slope(np.array(hs), np.array(et)) == pytest.approx(1.0, abs=0.15)
    assert slope(np.array(hs), np.array(ev)) == pytest.approx(2.0, abs=0.2)


def test_p2_zeno_rest_on_the_plane(p2_run):
    """Once the rebound flight would be shorter than a step the impact is made plastic and the
    contact held: the mass then sits exactly on the plane (δ = 0 is the constraint) and the
    multiplier is the P1 Lagrange force |k h − m g|. Its noise is the rounding of the KKT
    system, whose inertia block is M/(βh²): ε·m·u/(βh²) = 4.4e-9 N here (measured 3e-11)."""
    s, h = p2_run
    dt = 1e-4
    c = s["contacts"]["plane"]
    assert s["status"] == "MARTELLO_OK"
    assert c["separation_times"][-1] is None                 # the last phase never ends
    ref = bouncing_oscillator_restitution(M, K, GAP, G, 0.8, 1)
    # held from within 2 ms of the exact Zeno time (measured 1.2e-3 s late at h = 1e-4:
    # the impacts shorter than a step are lumped into one plastic impact)
    assert 0 <= c["impact_times"][-1] - ref.zeno_time <= 2e-3
    rest = h["t"] > 1.6
    assert np.all(h["penetration:plane"] <= 16 * EPS * GAP)
    np.testing.assert_allclose(h["penetration:plane"][rest], 0.0, atol=16 * EPS * GAP)
    np.testing.assert_allclose(h["force:plane"][rest], -ref.resting_force,
                               rtol=0, atol=EPS * M * GAP / (0.25 * dt ** 2))
    np.testing.assert_allclose(h["v:mass"][rest], 0.0, atol=1e-12)


def test_p2_energy(p2_run):
    """E_IMPACT books ½m*(v_in² − v_out²) at each impact (Newton's loss) and the plastic last
    one: in all m g h − ½k h² (from rest at u = 0 to rest at u = h), to O(h²). The balance,
    which then holds the error of the tuned impact steps and of the Zeno lumping, is measured
    3.4e-7 J at h = 1e-4 (5.9e-5 at 1e-3, 2e-9 at 1e-5)."""
    s, _ = p2_run
    assert s["energy"]["impact"] == pytest.approx(M * G * GAP - 0.5 * K * GAP ** 2, rel=1e-5)
    assert s["energy"]["balance_max"] <= 1e-5 * s["energy"]["input"]


@pytest.mark.parametrize("e", [0.0, 0.3, 1.0])
@pytest.mark.parametrize("m2", [1e-6, 1.0, 1e6])
def test_p5_newton_velocities(e, m2):
    """P5: after the impact step the velocities are Newton's (seed eqs 1–3). u, v, a and the
    constraint's δ move by the KKT increments (docs/moreau-jean.md, "Rounding"): the tuned
    ratio γ/β and the step's δ̇_{n+1} = δ̇_n + hδ̈_n − γD₀/(βh) share one D₀, so only the
    arithmetic of the step and of the KKT solve rounds, a few ε·v0 each: tolerance 64ε·v0
    (measured ≤ 34ε: e = 0, m2/m1 = 1e6, over h = 3e-4 … 1e-7 s and bodies 0 … 100 m from the
    origin; ≤ 3ε for e > 0). Taking a from u it was 4·√N·ε·max|u|/h (measured ≤ 93ε here)."""
    dt, t_end, m1, v0 = 3e-4, 0.005, 1.0, 1.0
    s, h = execute({
        "node": [{"name": "m1", "mass": m1, "v0": v0}, {"name": "m2", "mass": m2}],
        "contact": [{"name": "impact", "a": "m1", "b": "m2", "gap": 1e-3, "scheme": "restitution",
                     "restitution": e}],
        "analysis": {"type": "dynamic", "integrator": "newmark-lagrange", "dt": dt, "t_end": t_end}})
    ref = newton_impact(m1, m2, v0, 0.0, e)
    tol = 64 * EPS * v0
    assert h["v:m1"][-1] == pytest.approx(ref.v1, abs=tol)
    assert h["v:m2"][-1] == pytest.approx(ref.v2, abs=tol)
    c = s["contacts"]["impact"]
    # the gap closes at t = 1 ms, inside a step, and the root finder finds it to round-off
    # (no other force: the relative motion is uniform)
    assert c["impact_times"] == [pytest.approx(1e-3, rel=1e-12)]
    # ½m*(v_in² − v_out²) with v_out good to the tolerance above: abs 2·m*·v0·tol
    mstar = m1 * m2 / (m1 + m2)
    assert s["energy"]["impact"] == pytest.approx(ref.energy_lost, rel=0, abs=2 * mstar * v0 * tol)


@pytest.mark.parametrize("e", [0.3, 1.0])
def test_p5_far_from_the_origin_free_flight_and_rebound(e):
    """P5's bodies 1 m from the origin, the gap closing on a step end (t = 1 ms, h = 10 µs).
    Identity of the method: in free flight there is no force, and a, which moves by Newton
    increments only (the predictor's a_n = 0, no increment without a residual), is exactly 0
    before and after the impact (taking a from u, the rounding of u showed as |a| up to
    4.4e-6 m/s² = 0.5 ε|u|/(βh²)). Verification against Newton's law (closed form): the rebound
    speeds to 8ε·v0, the rounding of a few operations on speeds of order v0 — the constraint's
    δ_{n+1} moves by the increments from the D₀ the tuned (β, γ) were solved with; re-read from
    u, whose rounding ε|u| is 0.3 % of D₀ on a step that ends ~1e-8 h after the impact, the
    rebound was off by 2.6e-3 (e = 0.3) and 4.1e-3 m/s (e = 1); measured ≤ 3ε."""
    dt, m1, m2, v0 = 1e-5, 1.0, 2.0, 1.0
    s, h = execute({
        "node": [{"name": "m1", "mass": m1, "v0": v0, "u0": 1.0}, {"name": "m2", "mass": m2, "u0": 1.0}],
        "contact": [{"name": "impact", "a": "m1", "b": "m2", "gap": 1e-3, "scheme": "restitution",
                     "restitution": e}],
        "analysis": {"type": "dynamic", "integrator": "newmark-lagrange", "dt": dt, "t_end": 3e-3,
                     "output": {"every": 1}}})
    assert np.abs(h["a:m1"]).max() == 0.0 and np.abs(h["a:m2"]).max() == 0.0
    ref = newton_impact(m1, m2, v0, 0.0, e)
    assert h["v:m1"][-1] == pytest.approx(ref.v1, rel=0, abs=8 * EPS * v0)
    assert h["v:m2"][-1] == pytest.approx(ref.v2, rel=0, abs=8 * EPS * v0)


def test_cost_against_moreau_jean(capsys):
    """The same P2 scene (e = 0.8, first 6 impacts) with both schemes at the same steps:
    steps, factorizations, wall time and the errors. What the counters show exactly:
    Newmark–Lagrange does one dense KKT solve per step, plus one more per impact (the trial
    is redone with the tuned β, γ) and one equilibrium solve after it; Moreau–Jean one banded
    factorisation per step and an LCP (one Lemke pivot pair) on impact steps. At equal h
    Newmark–Lagrange is more accurate (speeds O(h²) against O(h); times both O(h), constants
    ~1 against ~2.7 over these impacts), at 2–3× the work per step (docs/moreau-jean.md has
    the measured table)."""
    ref = bouncing_oscillator_restitution(M, K, GAP, G, 0.8, 6)
    rows = []
    for dt in (1e-3, 1e-4, 1e-5):
        for integ in ("moreau-jean", "newmark-lagrange"):
            t0 = time.perf_counter()
            s, _ = p2(dt, 0.9, integrator=integ, every=10 ** 6)
            wall = time.perf_counter() - t0
            c, cost = s["contacts"]["plane"], s["cost"]
            err_t = np.abs(np.array(c["impact_times"][:6]) - ref.t).max()
            err_v = np.abs(np.array(c["approach_speeds"][:6]) - ref.v).max()
            rows.append((integ, dt, cost["steps"], cost["factorizations"], cost["newton_iterations"],
                         cost["wall_time_s"], wall, err_t, err_v))
            n_imp = c["impacts"]
            if integ == "newmark-lagrange":
                assert cost["newton_iterations"] == cost["steps"] + n_imp        # linear: 1 each
                assert cost["factorizations"] == cost["steps"] + 2 * n_imp + 1
                assert cost["rejected_steps"] == n_imp
            else:
                assert cost["factorizations"] == cost["steps"]
    with capsys.disabled():
        print("\nP2 e = 0.8, first 6 impacts: scheme, h, steps, factorizations, LCP pivots or"
              " Newton iterations, native s, total s, max |Δt_i|, max |Δv_i|")
        for r in rows:
            print("  %-17s %.0e %7d %7d %7d %8.4f %8.4f %9.2e %9.2e" % r)
    by = {(r[0], r[1]): r for r in rows}
    for dt in (1e-3, 1e-4, 1e-5):
        assert by[("newmark-lagrange", dt)][8] < by[("moreau-jean", dt)][8]
        assert by[("moreau-jean", dt)][7] < 8 * dt and by[("newmark-lagrange", dt)][7] < 4 * dt


def test_penalty_contacts_are_refused():
    """The compatibility table: Newmark–Lagrange is built for rigid impacts."""
    from martello.errors import SceneError
    from martello.scene.loader import from_dict
    with pytest.raises(SceneError, match="cannot run on integrator newmark-lagrange"):
        from_dict({
            "node": [{"name": "m", "mass": 1.0}],
            "contact": [{"name": "c", "a": "m", "b": "ground", "gap": 0.1, "scheme": "penalty",
                   "law": "linear", "stiffness": 1e6}],
            "analysis": {"type": "dynamic", "integrator": "newmark-lagrange", "dt": 1e-3,
                   "t_end": 0.01}})
