"""Moreau–Jean time stepping (docs/problems.md P2, P5 and "Integrators"; docs/moreau-jean.md).

Oracles: martello.oracles (bouncing_oscillator_restitution, newton_impact) and the
reference rows of Siconos' bouncing-ball example (reference/siconos_bouncing_ball/). Every
tolerance says where it comes from; "measured" values are from this implementation."""

import math
from pathlib import Path

import numpy as np
import pytest

from martello.oracles.p2_bouncing import bouncing_oscillator_restitution
from martello.oracles.p5_contact_laws import newton_impact
from dynamics_helpers import execute, slope

EPS = np.finfo(float).eps
REF = Path(__file__).resolve().parent.parent / "reference" / "siconos_bouncing_ball" / "BouncingBallTS_ref_rows.csv"

# P2 of docs/problems.md: m = 1, k = 100, plane at h = 0.05, g = 9.81 (u_s = 0.0981 > h: Zeno)
M, K, GAP, G = 1.0, 100.0, 0.05, 9.81
G_EFF = (M * G - K * GAP) / M      # acceleration pressing the mass onto the plane there


def p2(dt, t_end, e=0.8, theta=0.5, u0=0.0, v0=0.0, every=1):
    return execute({
        "node": [{"name": "mass", "mass": M, "u0": u0, "v0": v0}],
        "link": [{"type": "spring", "a": "mass", "b": "ground", "k": K}],
        "contact": [{"name": "plane", "a": "mass", "b": "ground", "gap": GAP,
                     "scheme": "restitution", "restitution": e}],
        "loads": {"gravity": G},
        "analysis": {"type": "dynamic", "integrator": "moreau-jean", "theta": theta, "dt": dt,
                     "t_end": t_end, "output": {"every": every}}})


# ---------------------------------------------------------------------------------------------
# Siconos' BouncingBallTS.py, reproduced to round-off
# ---------------------------------------------------------------------------------------------
def siconos_ball():
    """The 1-DOF equivalent of BouncingBallTS.py. There the ball has q = (height, x, angle),
    M = diag(1, 1, 2/5 r²), f_ext = (−m g, 0, 0) and the relation y = H q with H = [1 0 0] and
    no offset: the radius only sets the rotational inertia, and the two other DOFs carry no
    force, so they stay at rest. Here u = q₀ (so gravity is −9.81 along +u) and the contact
    puts the ground on side a: δ = 0 − u − 0 = −y, penetration when y < 0."""
    return {"node": [{"name": "ball", "mass": 1.0, "u0": 1.0}],
            "contact": [{"name": "floor", "a": "ground", "b": "ball", "gap": 0.0,
                         "scheme": "restitution", "restitution": 0.9}],
            "loads": {"gravity": -9.81},
            "analysis": {"type": "dynamic", "integrator": "moreau-jean", "theta": 0.5,
                         "dt": 0.005, "t_end": 10.0}}


def test_siconos_bouncing_ball_rows():
    ref = np.loadtxt(REF, delimiter=",", comments="#", skiprows=3)
    step = ref[:, 0].astype(int)
    s, h = execute(siconos_ball())
    assert s["status"] == "MARTELLO_OK" and len(h["t"]) == 2001
    t, q, v = h["t"][step], h["u:ball"][step], h["v:ball"][step]
    p = h["force:floor"][step] * 0.005          # the history holds p/h; Siconos records p
    # The two codes do the same floating-point operations in a different order, so the state
    # drifts apart by a rounding a step: a random walk of N = 2000 steps stays within
    # 4·√N·ε of the scale (q: 1 m, v: the first impact speed, p: the first impulse).
    # Measured: |Δq| 2.2e-15, |Δv| 1.8e-14, |Δp| 2.7e-14 (≈ 0.4–1·√N·ε·scale).
    walk = 4.0 * math.sqrt(2000) * EPS
    np.testing.assert_allclose(t, ref[:, 1], rtol=0, atol=1e-12)
    np.testing.assert_allclose(q, ref[:, 2], rtol=0, atol=walk * 1.0)
    np.testing.assert_allclose(v, ref[:, 3], rtol=0, atol=walk * 4.4145)
    np.testing.assert_allclose(p, ref[:, 4], rtol=0, atol=walk * 8.4366)
    # Same impacts in the same steps: the stored rows include every row of the .ref file with
    # p ≠ 0 before the resting phase (step 1697 on), so the sets must be equal.
    p_all = h["force:floor"]
    ours = set(np.nonzero(p_all[:1697] > 0)[0])
    theirs = set(step[(ref[:, 4] > 0) & (step < 1697)])
    assert ours == theirs and len(ours) == 41
    assert np.all(p_all[1697:] > 0)
    # 41 separate impacts, then one phase that lasts to the end (still open at T)
    c = s["contacts"]["floor"]
    assert c["impacts"] == 42 and c["separation_times"][-1] is None
    # restitution holds exactly at every completed impact: Newton's law is the LCP's equality
    np.testing.assert_allclose(c["restitution"], 0.9, rtol=4 * EPS)


# ---------------------------------------------------------------------------------------------
# P2: order of the impact times, non-penetration, Zeno, energy
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("theta", [0.5, 1.0])
def test_p2_impact_times_first_order(theta):
    """The first 6 impact times converge like h. Their error depends on where each impact
    falls inside its step (the index set is a grid decision: the error is (1 − θ)h − s for an
    impact s after t_k, uniform over the phase), so at one h the error is erratic between 0
    and ~h; averaged over 8 equally spaced phases of the start (the exact state at s·h/8 is
    the initial state) the mean error is C·h + o(h). Measured slopes 1.007 (θ = ½) and
    0.992 (θ = 1) over 5 halvings; the bar is 1 ± 0.15."""
    w, us, n_imp, n_phase = math.sqrt(K / M), M * G / K, 6, 8
    hs = [1e-3 / 2 ** j for j in range(6)]
    mean_err = []
    for dt in hs:
        errs = []
        for i in range(n_phase):
            s0 = i / n_phase * dt
            u0, v0 = us * (1 - math.cos(w * s0)), us * w * math.sin(w * s0)
            ref = bouncing_oscillator_restitution(M, K, GAP, G, 0.8, n_imp, u0=u0, v0=v0)
            s, _ = p2(dt, 0.9, theta=theta, u0=u0, v0=v0, every=10 ** 6)
            errs.append(np.abs(np.array(s["contacts"]["plane"]["impact_times"][:n_imp]) - ref.t))
        mean_err.append(np.mean(errs))
    # the error is O(h), never better: no accidental second order hides behind the fit
    assert all(1.0 < err / dt < 6.0 for err, dt in zip(mean_err, hs))
    assert slope(np.array(hs), np.array(mean_err)) == pytest.approx(1.0, abs=0.15)


@pytest.fixture(scope="module")
def p2_zeno():
    """e = 0.8 through the Zeno point t∞ = 1.29967 s to rest, h = 1e-4, every step recorded."""
    return p2(1e-4, 2.0)


def test_p2_no_penetration_at_velocity_level(p2_zeno):
    """On every step whose contact was predicted active (δ_k + ½h δ̇_k ≥ 0) the post-step
    velocity satisfies δ̇_{k+1} ≤ −e δ̇_k (ġ_{k+1} + e ġ_k ≥ 0), with equality when p > 0:
    the LCP solution is exact up to the few roundings of v_free + W⁻¹p (tolerance 8ε·max|v|;
    measured ≤ 1 ulp). This is the sense in which Moreau–Jean does not penetrate."""
    s, h = p2_zeno
    dt, e = 1e-4, 0.8
    v, pen, f = h["v:mass"], h["penetration:plane"], h["force:plane"]
    vmax = np.abs(v).max()
    law = v[1:] + e * v[:-1]                     # = −(ġ_{k+1} + e ġ_k)
    pushed = f[1:] > 0
    active = pen[:-1] + 0.5 * dt * v[:-1] >= 0
    assert pushed.sum() > 1000                   # impacts and the resting phase
    assert np.abs(law[pushed]).max() <= 8 * EPS * vmax
    assert law[active].max() <= 8 * EPS * vmax
    # Position level: the impact step reverses the velocity at mid-step, so for θ = ½ the
    # penetration is bounded by δ ≤ (2 − e)/2·h·max δ̇ (docs/moreau-jean.md): O(h·v), not 0.
    # Measured max δ = 4.1e-5 = 0.80 of that bound.
    assert 0 < s["contacts"]["plane"]["max_penetration"] <= (2 - e) / 2 * dt * vmax


def test_p2_zeno_comes_to_rest(p2_zeno):
    """Past t∞ the mass rests on the plane; the contact force (p/h) is the static value for
    the resting position u = h + δ_res, m g − k u, to round-off; δ_res, the penetration the last
    impacts leave, is O(h·v_last) with v_last = O(g_eff h): measured δ_res/(g_eff h²) between
    0.14 and 0.28 for h = 1e-3 … 7.8e-6, asserted ≤ 1. So the force is k h − m g (the P1
    Lagrange value, seed sign; compression positive here) to k·g_eff·h² relative."""
    s, h = p2_zeno
    dt = 1e-4
    assert s["status"] == "MARTELLO_OK"
    rest = h["t"] > 1.6
    u, f, v = h["u:mass"][rest], h["force:plane"][rest], h["v:mass"][rest]
    delta_res = h["penetration:plane"][-1]
    assert 0 <= delta_res <= G_EFF * dt ** 2
    np.testing.assert_allclose(f, M * G - K * u, rtol=64 * EPS)
    ref = bouncing_oscillator_restitution(M, K, GAP, G, 0.8, 1)
    assert f == pytest.approx(-ref.resting_force, rel=K * G_EFF * dt ** 2 / (M * G - K * GAP))
    assert np.abs(v).max() <= 1e-15
    # the energy that the impacts took out is the whole mechanical energy lost: m g h − ½ k h²
    # (released from rest at u = 0, resting at u = h): exact up to the final δ_res terms
    assert s["energy"]["impact"] == pytest.approx(M * G * GAP - 0.5 * K * GAP ** 2, rel=1e-6)


def test_p2_energy_identity_theta_half(p2_zeno):
    """θ = ½, linear forces: E_{k+1} − E_k = Δqᵀf_ext,θ + ġ_θᵀp exactly, so the balance is
    round-off (measured 1e-14 of the input work). On an impulse step ġ_{k+1} = −e ġ_k, so the
    impulse work is ġ_θ p = (1 − θ(1+e)) ġ_k p: with θ(1 + e) = 0.9 ≤ 1 it is ≤ 0 whenever the
    contact approaches (ġ_k ≤ 0). In the resting phase δ̇ alternates in sign from step to step
    (Siconos' rows show the same) and the steps that start separating (ġ_k > 0) with p > 0 put
    energy back: measured 7.6e-9 J in all, against 0.3655 J taken out."""
    s, h = p2_zeno
    dt, e, theta = 1e-4, 0.8, 0.5
    scale = s["energy"]["input"]
    assert s["energy"]["balance_max"] <= 1e-12 * scale
    loss = np.diff(h["energy:impact"])           # −ġ_θ p of each step
    v, p = h["v:mass"], h["force:plane"] * dt
    # the identity step by step: −ġ_θ p = (1 − θ(1+e)) δ̇_k p (δ̇ = −ġ), to the rounding of p
    np.testing.assert_allclose(loss, (1 - theta * (1 + e)) * v[:-1] * p[1:], rtol=0,
                               atol=16 * EPS * np.abs(v).max() * p.max())
    approaching = v[:-1] >= 0
    assert loss[approaching].min() >= 0
    assert -loss[loss < 0].sum() <= 1e-7 * loss[loss > 0].sum()


def test_p2_impulse_work_sign_needs_theta_one_plus_e_at_most_one():
    """θ = 1, e = 0.8: θ(1 + e) = 1.8 > 1, so ġ_θ p = (1 − θ(1+e)) ġ_k p > 0 at an impact:
    the impulses alone put energy in, and only the θ-dissipation (θ−½)(‖Δv‖²_M + ‖Δq‖²_K)
    keeps the scheme dissipative. energy.impact holds both (docs/moreau-jean.md "Energy"):
    it ends positive, and the balance, which held the θ-dissipation before, is round-off for
    these linear forces (8 ε of the input per step, accumulated)."""
    s, h = p2(1e-3, 2.0, theta=1.0)
    assert h["energy:impact"][-1] > 1e-3
    bal = h["energy:balance"]
    assert np.abs(bal).max() <= 2000 * 8 * EPS * s["energy"]["input"]


def test_p2_elastic_impacts_conserve_energy():
    """e = 1, θ = ½: ġ_θ = 0 on every impulse step, so the impulses do no work and the
    mechanical energy (kinetic + spring − gravity work) is conserved to round-off (measured
    4.5e-16 J over 2000 steps and 9 impacts)."""
    s, h = p2(1e-3, 2.0, e=1.0)
    assert s["contacts"]["plane"]["impacts"] == 9
    assert abs(s["energy"]["impact"]) <= 1e-13
    assert s["energy"]["balance_max"] <= 1e-13


# ---------------------------------------------------------------------------------------------
# P5: two bodies, one impulse step
# ---------------------------------------------------------------------------------------------
@pytest.mark.parametrize("e", [0.0, 0.3, 1.0])
@pytest.mark.parametrize("m2", [1e-6, 1.0, 1e6])
def test_p5_newton_velocities_in_one_step(e, m2):
    """Two free bodies: the impulse step solves the 1×1 LCP z = −q/W with W = 1/m1 + 1/m2,
    q = (1 + e)(v2 − v1), then v1 −= z/m1, v2 += z/m2: Newton's velocities (seed eqs 1–3)
    after a handful of roundings. Tolerance 8ε·v0 (measured: exact or 1 ulp) for mass ratios
    1e-6…1e6; momentum is conserved to the same."""
    m1, v0 = 1.0, 1.0
    s, h = execute({
        "node": [{"name": "m1", "mass": m1, "v0": v0}, {"name": "m2", "mass": m2}],
        "contact": [{"name": "impact", "a": "m1", "b": "m2", "gap": 1e-3, "scheme": "restitution",
                     "restitution": e}],
        "analysis": {"type": "dynamic", "integrator": "moreau-jean", "dt": 3e-4, "t_end": 0.003}})
    ref = newton_impact(m1, m2, v0, 0.0, e)
    assert h["v:m1"][-1] == pytest.approx(ref.v1, abs=8 * EPS * v0)
    assert h["v:m2"][-1] == pytest.approx(ref.v2, abs=8 * EPS * v0)
    assert m1 * h["v:m1"][-1] + m2 * h["v:m2"][-1] == pytest.approx(m1 * v0, abs=8 * EPS * m1 * v0)
    c = s["contacts"]["impact"]
    assert c["impacts"] == 1 and c["approach_speeds"] == [v0]
    # the impact lies in the step [0.9, 1.2] ms whose predicted mid-step gap closed; t_on is
    # the switching instant t_k + (1 − θ)h of that step: 1.05 ms for the true 1 ms
    assert c["impact_times"][0] == pytest.approx(1.05e-3, rel=1e-12)
    assert s["energy"]["impact"] == pytest.approx(ref.energy_lost, rel=1e-12, abs=1e-15 * m1)


@pytest.mark.parametrize("n", [10, 100])
@pytest.mark.parametrize("e", [0.0, 0.5, 1.0])
def test_chain_of_touching_bodies_simultaneous_impact(n, e):
    """Newton's cradle with no gaps: every contact is in the index set of the first step, and
    the LCP resolves the impacts simultaneously: the struck chain moves as one rigid body of
    mass n − 1 (newton_impact(1, n − 1, …)); that is Moreau–Jean's impact rule, not the
    sequential one of the physical cradle (docs/moreau-jean.md). n = 10 runs Lemke on a dense
    W, n = 100 projected Gauss–Seidel on the tridiagonal W with its direct finish: both exact
    to round-off (tolerance 64ε: n roundings in the band solve; measured ≤ 4ε)."""
    nodes = [{"name": f"b{i}", "mass": 1.0, "v0": 1.0 if i == 0 else 0.0} for i in range(n)]
    contacts = [{"name": f"c{i}", "a": f"b{i}", "b": f"b{i + 1}", "gap": 0.0,
                 "scheme": "restitution", "restitution": e} for i in range(n - 1)]
    s, h = execute({"node": nodes, "contact": contacts,
                    "analysis": {"type": "dynamic", "integrator": "moreau-jean", "dt": 1e-3,
                                 "t_end": 0.003,
                                 "output": {"every": 1, "nodes": [x["name"] for x in nodes]}}})
    v = np.array([h[f"v:b{i}"][-1] for i in range(n)])
    ref = newton_impact(1.0, n - 1.0, 1.0, 0.0, e)
    assert v[0] == pytest.approx(ref.v1, abs=64 * EPS)
    np.testing.assert_allclose(v[1:], ref.v2, rtol=0, atol=64 * EPS)
    assert v.sum() == pytest.approx(1.0, abs=64 * EPS)


@pytest.mark.parametrize("e", [0.0, 1.0])
def test_linked_chain_of_touching_bodies_band_lcp(e):
    """The cradle above with springs between neighbours (Ŵ tridiagonal, so W = BŴ⁻¹Bᵀ is
    dense) and 99 contacts, beyond Lemke's 64: the LCP is solved on the band of its
    saddle-point form (docs/impulse.md §2). One step: the springs are internal (1ᵀK = 0), so
    momentum is kept, and every contact holds, so Newton's law gives the struck chain one
    velocity: newton_impact(1, n − 1, …) exactly as without springs (their impulse within the
    step only shares the load between the contacts). Tolerance 64ε: n roundings in the band
    solve (measured ≤ 4ε)."""
    n = 100
    nodes = [{"name": f"b{i}", "mass": 1.0, "v0": 1.0 if i == 0 else 0.0} for i in range(n)]
    links = [{"type": "spring", "a": f"b{i}", "b": f"b{i + 1}", "k": 10.0} for i in range(n - 1)]
    contacts = [{"name": f"c{i}", "a": f"b{i}", "b": f"b{i + 1}", "gap": 0.0,
                 "scheme": "restitution", "restitution": e} for i in range(n - 1)]
    s, h = execute({"node": nodes, "link": links, "contact": contacts,
                    "analysis": {"type": "dynamic", "integrator": "moreau-jean", "dt": 1e-3,
                                 "t_end": 1e-3,
                                 "output": {"every": 1, "nodes": [x["name"] for x in nodes]}}})
    v = np.array([h[f"v:b{i}"][-1] for i in range(n)])
    ref = newton_impact(1.0, n - 1.0, 1.0, 0.0, e)
    assert v[0] == pytest.approx(ref.v1, abs=64 * EPS)
    np.testing.assert_allclose(v[1:], ref.v2, rtol=0, atol=64 * EPS)
    assert all(c["impacts"] == 1 for c in s["contacts"].values())


def test_banded_step_matrix_energy_identity():
    """Two masses joined by a spring (Ŵ tridiagonal, so W comes from Ŵ⁻¹Bᵀ columns) bounce
    elastically between two walls: with θ = ½ and e = 1 the discrete energy identity makes
    the energy exact to round-off whatever h (measured 5e-15 J of 0.5 J); the walls are a
    ground contact and a Lagrange contact on a fixed node."""
    s, h = execute({
        "node": [{"name": "a", "mass": 1.0, "v0": 1.0}, {"name": "b", "mass": 2.0},
                 {"name": "wall", "mass": 0.0, "fixed": True, "u0": 0.3}],
        "link": [{"type": "spring", "a": "a", "b": "b", "k": 50.0}],
        "contact": [{"name": "left", "a": "ground", "b": "a", "gap": 0.2,
                     "scheme": "restitution", "restitution": 1.0},
                    {"name": "right", "a": "b", "b": "wall", "gap": 0.1,
                     "scheme": "lagrange", "restitution": 1.0}],
        "analysis": {"type": "dynamic", "integrator": "moreau-jean", "dt": 2e-3, "t_end": 5.0}})
    assert s["contacts"]["left"]["impacts"] >= 2 and s["contacts"]["right"]["impacts"] >= 2
    e0 = s["energy"]["initial"]
    assert s["energy"]["balance_max"] <= 1e-13 * e0
    assert abs(s["energy"]["impact"]) <= 1e-13 * e0
    ke_spring = h["energy:kinetic"] + h["energy:recoverable"]
    np.testing.assert_allclose(ke_spring, e0, rtol=1e-13)


def test_lagrange_contact_defaults_to_plastic():
    """A Lagrange contact without restitution is Newton's law with e = 0: P5 ends with the
    common velocity (newton_impact with e = 0) and the bodies stay together."""
    s, h = execute({
        "node": [{"name": "m1", "mass": 1.0, "v0": 1.0}, {"name": "m2", "mass": 3.0}],
        "contact": [{"name": "c", "a": "m1", "b": "m2", "gap": 1e-3, "scheme": "lagrange"}],
        "analysis": {"type": "dynamic", "integrator": "moreau-jean", "dt": 3e-4, "t_end": 0.01}})
    ref = newton_impact(1.0, 3.0, 1.0, 0.0, 0.0)
    assert h["v:m1"][-1] == pytest.approx(ref.v1, abs=8 * EPS)
    assert h["v:m2"][-1] == pytest.approx(ref.v2, abs=8 * EPS)


@pytest.mark.parametrize("theta", [0.75, 1.0])
def test_theta_above_half_balances_with_its_numerical_dissipation(theta):
    """θ > ½ dissipates (θ − ½)(ΔvᵀMΔv + ΔqᵀKΔq) a step (docs/moreau-jean.md "Energy"): that
    term goes with the impulses' work into energy.impact, so P2 (e = 0.8, linear spring)
    balances to round-off at any θ (an identity of the method; it was a false 'step too
    large' warning at θ = 1) and the impacts and the scheme together take energy out."""
    import tomllib
    import martello
    from martello.run import run_full
    path = Path(__file__).resolve().parent.parent / "benchmarks/p2/p2_moreau_jean_e08.toml"
    d = tomllib.loads(path.read_text())
    d.pop("check", None)
    d["analysis"]["theta"] = theta
    s, _ = run_full(martello.Scene.from_dict(d, base_dir=path.parent))
    assert s["status"] == "MARTELLO_OK" and s["warnings"] == []
    assert s["energy"]["balance_relative"] < 1e-12
    assert s["energy"]["impact"] > 0
