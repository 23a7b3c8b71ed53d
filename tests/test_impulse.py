"""The shared impulse problem (fortran/impulse.f90 through its C door, docs/impulse.md):
Newton's law and the contact-force LCP against closed forms and independent constructions
(two bodies, Newton's cradles and chains of equal masses whose impulses are known, random
symmetric positive definite W with a complementary solution built by construction, sizes 0
and 1, an infeasible redundant pair), the accumulation policy against the closed-form
accumulation point of a bouncing ball, and the same multi-contact impact resolved by the GSL
event-driven integrator, IDA and Moreau–Jean. Oracles: closed forms written out here and
martello.closed_forms."""

import ctypes
import math

import numpy as np
import pytest

from martello.oracles.p5_contact_laws import newton_impact
from martello.binding.native import library_path
from tests.dynamics_helpers import execute

EPS = float(np.finfo(float).eps)
OK, ERR_SINGULAR = 0, -3
_D = np.ctypeslib.ndpointer(dtype=np.float64, flags="F_CONTIGUOUS")
_I = np.ctypeslib.ndpointer(dtype=np.int32, flags="C_CONTIGUOUS")


@pytest.fixture(scope="module")
def door():
    """The impulse door of c/martello_internal.h (not part of the public API)."""
    L = ctypes.CDLL(str(library_path()))
    ci, cd = ctypes.c_int, ctypes.c_double
    topology = [ci, ci, _I, ctypes.POINTER(Rows), _I, _D]   # n, m, list, rows, col, cols
    L.martello_impulse_newton.argtypes = topology + [_D, _D, _D, ctypes.POINTER(ci)]
    L.martello_impulse_contact_forces.argtypes = topology + [_D, _D, _I, ctypes.POINTER(ci)]
    L.martello_impulse_delassus.argtypes = topology + [_D]
    L.martello_impulse_accumulation.argtypes = [cd, cd, cd, cd, cd, cd, cd, cd, ci,
                                                ctypes.POINTER(cd)]
    for f in ("newton", "contact_forces", "delassus", "accumulation"):
        getattr(L, "martello_impulse_" + f).restype = ci
    return L


class Rows(ctypes.Structure):
    """martello_rows of c/martello_internal.h: contact j's penetration row G_j (terms
    first[j] .. first[j+1]-1 of node and coef)."""
    _fields_ = [("first", ctypes.POINTER(ctypes.c_int)), ("node", ctypes.POINTER(ctypes.c_int)),
                ("coef", ctypes.POINTER(ctypes.c_double))]


def _lists(a, b):
    """The door's topology of node-pair contacts (a[j], b[j]) (−1: the ground), column j:
    list, rows (G_j = e_a − e_b), col."""
    a, b = np.asarray(a, dtype=np.int32), np.asarray(b, dtype=np.int32)
    idx = np.arange(len(a), dtype=np.int32)
    first, node, coef = [0], [], []
    for i, j in zip(a, b):
        for n_, c in ((i, 1.0), (j, -1.0)):
            if n_ >= 0:
                node.append(n_); coef.append(c)
        first.append(len(node))
    arrays = (np.array(first, np.int32), np.array(node or [0], np.int32), np.array(coef or [0.0]))
    rows = Rows(*(x.ctypes.data_as(ctypes.POINTER(t)) for x, t in
                  zip(arrays, (ctypes.c_int, ctypes.c_int, ctypes.c_double))))
    rows._keep = arrays                   # the arrays live as long as the struct
    return idx, ctypes.byref(rows), idx, rows


def lumped_columns(mass, a, b):
    """C_k = M⁻¹ B_kᵀ, B_k = e_b − e_a (−1: the ground), for a lumped mass."""
    c = np.zeros((len(mass), len(a)), order="F")
    for k, (i, j) in enumerate(zip(a, b)):
        if i >= 0:
            c[i, k] -= 1.0 / mass[i]
        if j >= 0:
            c[j, k] += 1.0 / mass[j]
    return c


def newton(door, mass, a, b, e, v):
    """Newton's law on all contacts at once: (status, impulses, v⁺)."""
    lst, rows, col, _keep = _lists(a, b)
    cols = lumped_columns(mass, a, b)
    v = np.array(v, dtype=float, order="F")
    p = np.zeros(len(a), order="F")
    its = ctypes.c_int()
    st = door.martello_impulse_newton(len(mass), len(a), lst, rows, col, cols,
                                      np.asfortranarray(e, dtype=float), v, p, ctypes.byref(its))
    return st, p, v


def contact_forces_of(door, W, q, held=False):
    """The LCP W z + q ≥ 0 ⊥ z ≥ 0 for any W, through the door: contact k joins node k and
    the ground, so B = −I and the columns −W give W_kl = B_k C_l; the accelerations −q give
    B acc = q. With held: also the persistent-contact rule's flags."""
    m = len(q)
    lst, rows, col, _keep = _lists(np.arange(m), -np.ones(m))
    z = np.zeros(m, order="F")
    keep = np.zeros(m, dtype=np.int32)
    its = ctypes.c_int()
    st = door.martello_impulse_contact_forces(m, m, lst, rows, col, np.asfortranarray(-W),
                                              np.asfortranarray(-q), z, keep, ctypes.byref(its))
    return (st, z, keep) if held else (st, z)


def residual(W, q, z):
    """LAPACK-style scale-free residual ‖min(z, W z + q)‖∞ / (‖W‖∞ ‖z‖∞ ε)."""
    r = np.minimum(z, W @ z + q)
    return np.abs(r).max() / (np.abs(W).sum(axis=1).max() * max(np.abs(z).max(), 1e-300) * EPS)


# --- Newton's law against closed forms --------------------------------------------------------

@pytest.mark.parametrize("m2", [1e-6, 0.3, 1.0, 7.0, 1e6])
@pytest.mark.parametrize("e", [0.0, 0.5, 1.0])
def test_one_contact_is_the_stereomechanical_impact(door, m2, e):
    # m = 1: the LCP is one division, P = (1 + e) m* (v1 − v2). Each velocity is a few
    # roundings away (W, ġ, q, the division, the update): 8ε of the speeds.
    st, p, v = newton(door, [1.0, m2], [0], [1], [e], [1.0, -0.5])
    ref = newton_impact(1.0, m2, 1.0, -0.5, e)
    assert st == OK
    assert p[0] == pytest.approx((1 + e) * 1.5 * m2 / (1 + m2), rel=8 * EPS)
    assert v == pytest.approx([ref.v1, ref.v2], rel=8 * EPS, abs=8 * EPS * 1.5)


def test_no_contact_and_separating_contacts(door):
    # m = 0: nothing to solve; a separating contact, or one at rest, takes no impulse
    # (Newton's law acts on the approach only), so v is returned bit for bit.
    st, p, v = newton(door, [1.0, 2.0], [], [], [], [0.3, 0.1])
    assert st == OK and v.tolist() == [0.3, 0.1]
    for vb in (0.3, 0.5):
        st, p, v = newton(door, [1.0, 2.0], [0], [1], [0.5], [0.3, vb])
        assert st == OK and p.tolist() == [0.0] and v.tolist() == [0.3, vb]


@pytest.mark.parametrize("e", [0.0, 0.5, 1.0])
def test_three_ball_cradle(door, e):
    # ball 1 at v0 hits ball 2, which touches ball 3 (equal masses): W = [[2, −1], [−1, 2]]/m,
    # q = [−(1 + e) v0, 0], so P = (1 + e) v0 m/3 · [2, 1] and v = (1 − 2(1+e)/3, (1+e)/3,
    # (1+e)/3) v0 (Newton's law on both contacts at once, not the sequential (0, 0, v0)).
    # cond(W) = 3: a few tens of roundings, 32ε of v0.
    v0 = 2.0
    st, p, v = newton(door, [1.0] * 3, [0, 1], [1, 2], [e, e], [v0, 0.0, 0.0])
    assert st == OK
    np.testing.assert_allclose(p, (1 + e) * v0 / 3 * np.array([2.0, 1.0]), rtol=32 * EPS)
    np.testing.assert_allclose(v, v0 * np.array([1 - 2 * (1 + e) / 3, (1 + e) / 3, (1 + e) / 3]),
                               rtol=0, atol=32 * EPS * v0)


@pytest.mark.parametrize("n", [10, 100])
@pytest.mark.parametrize("e", [0.0, 0.6])
def test_struck_chain_of_equal_masses(door, n, e):
    # ball 0 at v0 hits a touching chain of n − 1 equal balls: all N = n − 1 contacts take an
    # impulse, the chain moves as one body of mass n − 1 (newton_impact(1, n − 1, …)) and the
    # impulses fall linearly, P_k = P_1 (n − k)/(n − 1), P_1 = (1 + e) v0 (n − 1)/n. n = 10 is
    # Lemke's, n = 100 projected Gauss–Seidel's (beyond LEMKE_MAX = 64) with its direct band
    # finish. W is the tridiagonal [−1, 2, −1]/m, cond(W) ≤ ½N²; times the Nε backward error of
    # the band solve: ½N³ε relative.
    v0 = 1.0
    N = n - 1
    st, p, v = newton(door, [1.0] * n, list(range(N)), list(range(1, n)), [e] * N,
                      [v0] + [0.0] * N)
    ref = newton_impact(1.0, n - 1.0, v0, 0.0, e)
    p1 = (1 + e) * v0 * N / n
    tol = 0.5 * N ** 3 * EPS
    assert st == OK
    np.testing.assert_allclose(p, p1 * (n - np.arange(1, n)) / N, rtol=tol)
    np.testing.assert_allclose(v, [ref.v1] + [ref.v2] * N, rtol=0, atol=tol * v0)


def test_redundant_contacts_without_a_solution_are_refused(door):
    # a node that reaches two walls at once moving towards one of them: Newton's law asks the
    # impulses of both contacts to separate from both walls, which no P ≥ 0 does (W is the
    # singular [[1, −1], [−1, 1]]/m): MARTELLO_ERR_SINGULAR, v untouched
    st, p, v = newton(door, [1.0], [0, -1], [-1, 0], [0.5, 0.5], [1.0])
    assert st == ERR_SINGULAR and v.tolist() == [1.0]


# --- the LCP against solutions built by construction -------------------------------------------

@pytest.mark.parametrize("m,seed", [(1, 0), (2, 1), (6, 2), (30, 3), (64, 4), (65, 5), (90, 6)])
def test_random_spd_lcp_with_a_known_solution(door, m, seed):
    # W = A Aᵀ/m + I/2 (SPD, cond ≤ 2(1 + ‖A‖²/m) ≈ 10), a support J drawn at random, z* > 0 on
    # J and 0 off it, w* = 0 on J and > 0 off it, q = w* − W z*: (z*, w*) is the unique
    # solution (W is a P-matrix). m ≤ 64: Lemke; m > 64: PGS with its direct finish. The
    # backward error of either is a few mε ‖W‖ ‖z‖: residual ≤ 4m in units of ‖W‖‖z‖ε, and
    # the forward error ≤ cond(W) times that.
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((m, m))
    W = A @ A.T / m + 0.5 * np.eye(m)
    J = rng.random(m) < 0.5
    z_star = np.where(J, rng.uniform(0.1, 2.0, m), 0.0)
    w_star = np.where(J, 0.0, rng.uniform(0.1, 2.0, m))
    q = w_star - W @ z_star
    st, z = contact_forces_of(door, W, q)
    assert st == OK
    assert residual(W, q, z) <= 4 * m
    cond = np.linalg.cond(W)
    np.testing.assert_allclose(z, z_star, rtol=0, atol=4 * m * cond * EPS * np.abs(z_star).max())


def test_contact_forces_release_the_tensile_contact(door):
    # the persistent-contact rule: two contacts held, the free accelerations press the first
    # (g̈_free = −1) and pull the second off (g̈_free = +1). With W = [[2, −1], [−1, 2]],
    # holding both (W λ = −g̈_free) gives λ = (1/3, −1/3): tensile. The LCP releases the
    # second: λ = (½, 0), and the released contact opens, g̈_2 = −½ + 1 = ½ (exact: one pivot).
    W = np.array([[2.0, -1.0], [-1.0, 2.0]])
    q = np.array([-1.0, 1.0])
    assert np.linalg.solve(W, -q)[1] < 0
    st, lam, held = contact_forces_of(door, W, q, held=True)
    assert st == OK and lam.tolist() == [0.5, 0.0] and held.tolist() == [1, 0]
    assert (W @ lam + q).tolist() == [0.0, 0.5]
    # a multiplier that only reaches 0 (nothing presses or pulls the second contact: g̈ = 0)
    # is not tensile: the contact stays held
    st, lam, held = contact_forces_of(door, W, np.array([-1.0, 0.5]), held=True)
    assert st == OK and lam.tolist() == [0.5, 0.0] and held.tolist() == [1, 1]


def test_delassus_matrix_of_a_chain(door):
    # three masses, contacts (0, 1), (1, 2), (2, ground): W = B M⁻¹ Bᵀ written out
    mass = np.array([1.0, 2.0, 4.0])
    a, b = [0, 1, 2], [1, 2, -1]
    lst, rows, col, _keep = _lists(a, b)
    W = np.zeros((3, 3), order="F")
    assert door.martello_impulse_delassus(3, 3, lst, rows, col, lumped_columns(mass, a, b), W) == OK
    # a sub-problem: contacts 2 and 0 of the topology, in that order
    sub = np.zeros((2, 2), order="F")
    lst2 = np.array([2, 0], dtype=np.int32)
    assert door.martello_impulse_delassus(3, 2, lst2, rows, col, lumped_columns(mass, a, b), sub) == OK
    np.testing.assert_array_equal(sub, W[np.ix_([2, 0], [2, 0])])
    ref = np.array([[1 + 1 / 2, -1 / 2, 0.0], [-1 / 2, 1 / 2 + 1 / 4, -1 / 4], [0.0, -1 / 4, 1 / 4]])
    np.testing.assert_array_equal(W, ref)


# --- the accumulation policy --------------------------------------------------------------------

def accumulation(door, e, s, a, da=0.0, t=1.0, t_res=0.0, d_res=0.0, v_res=0.0, restarts=0):
    t_inf = ctypes.c_double()
    acc = door.martello_impulse_accumulation(e, s, a, da, t, t_res, d_res, v_res, restarts,
                                             ctypes.byref(t_inf))
    return acc, t_inf.value


RHO = 0.01      # a resolved flight's end is located to 1 % of its length (docs/impulse.md §4)


def test_accumulation_rule_clauses(door):
    # no rebound: accumulated at once (t∞ = t), pressed or not (the held-set LCP decides)
    assert accumulation(door, 0.0, 1.0, 9.81) == (1, 1.0)
    assert accumulation(door, 0.5, 0.0, -1.0) == (1, 1.0)
    # not pressed, or no dissipation: never, however short the flight
    assert accumulation(door, 0.5, 1e-30, 0.0, t_res=1.0)[0] == 0
    assert accumulation(door, 1.0, 1e-30, 9.81, t_res=1.0)[0] == 0
    # t∞ = t + 2s/(a(1 − e)), the geometric series of the flights; a method that resolves
    # every flight (no resolution given) never holds the sequence
    acc, t_inf = accumulation(door, 0.5, 0.3, 2.0)
    assert acc == 0 and t_inf == 1.0 + 2 * 0.3 / (2.0 * 0.5)
    tau = 2 * 0.3 / 2.0                                   # the next flight, 0.3 s
    # the time resolution: a flight no longer than t_res is not resolved
    assert accumulation(door, 0.5, 0.3, 2.0, t_res=tau)[0] == 1
    assert accumulation(door, 0.5, 0.3, 2.0, t_res=tau * (1 - 4 * EPS))[0] == 0
    # a one-step method locates the end of a flight τ leaving at aτ/2 to d/(aτ/2) from its
    # position error d: resolved while that is more than 1 % of τ, i.e. τ² > 2d/(ρa)
    d_edge = RHO * 2.0 * tau ** 2 / 2
    assert accumulation(door, 0.5, 0.3, 2.0, d_res=d_edge * (1 + 4 * EPS))[0] == 1
    assert accumulation(door, 0.5, 0.3, 2.0, d_res=d_edge * (1 - 4 * EPS))[0] == 0
    # a method that restarts at order 1 (BDF) errs by one backward-Euler step h₁ = √(2d/a)
    # on the end of a flight: resolved while h₁ < ρτ, a 1e4 times tighter bound on d here
    d_bdf = 2.0 * (RHO * tau) ** 2 / 2
    assert accumulation(door, 0.5, 0.3, 2.0, d_res=d_bdf * (1 + 4 * EPS), restarts=1)[0] == 1
    assert accumulation(door, 0.5, 0.3, 2.0, d_res=d_bdf * (1 - 4 * EPS), restarts=1)[0] == 0
    assert accumulation(door, 0.5, 0.3, 2.0, d_res=d_edge * 0.5, restarts=1)[0] == 1
    # a launch speed off by v makes the flight off by 2v/a: resolved while below ρτ
    v_edge = RHO * tau * 2.0 / 2
    assert accumulation(door, 0.5, 0.3, 2.0, v_res=v_edge * (1 + 4 * EPS))[0] == 1
    assert accumulation(door, 0.5, 0.3, 2.0, v_res=v_edge * (1 - 4 * EPS))[0] == 0
    # an unresolved flight is held only while a changes over it by at most ρ(1 − e)² a: the
    # constant-acceleration series then predicts t∞ as well as a resolved flight's end
    da_edge = RHO * (1 - 0.5) ** 2 * 2.0
    for sign in (1, -1):
        assert accumulation(door, 0.5, 0.3, 2.0, da=sign * da_edge, t_res=1.0)[0] == 1
        assert accumulation(door, 0.5, 0.3, 2.0, da=sign * da_edge * (1 + 4 * EPS),
                            t_res=1.0)[0] == 0
    # the rule reads the sequence and the method's resolution: no output time, no t_end


def test_constant_acceleration_series_error_on_the_bouncing_oscillator():
    # docs/impulse.md §4: the rest of a sequence is predicted by the constant-acceleration
    # series; on P2's spring the flights are exactly (2/ω) atan(e v/(ω (u_s − h))) (the closed
    # form), so the prediction from an impact whose next flight is τ errs by ≈ ω²τ³/(12(1 − e³))
    # (atan x = x − x³/3 + …), third order in τ. The rule's bound |da/τ| T²/a with da the
    # change of a over a flight (ω² s τ, the spring's) is ω²τ³/(2(1 − e)²): above it.
    from martello.oracles.p2_bouncing import bouncing_oscillator_restitution
    m, k, h, g, e = 1.0, 100.0, 0.05, 9.81, 0.8
    w, a = math.sqrt(k / m), g - k * h / m
    ref = bouncing_oscillator_restitution(m, k, h, g, e, 80)
    for n in (10, 20, 40):
        s = e * ref.v[n]                             # leaving impact n
        tau = 2 * s / a
        predicted = ref.t[n] + tau / (1 - e)
        err = abs(predicted - ref.zeno_time)
        assert err == pytest.approx(w ** 2 * tau ** 3 / (12 * (1 - e ** 3)), rel=0.05)
        assert err <= w ** 2 * tau ** 3 / (2 * (1 - e) ** 2)


# A ball dropped from H0 onto a rigid floor under gravity alone: the pressing acceleration is g
# at every flight, so the flights 2 e^n v1/g are exactly geometric and the accumulation point is
# t∞ = t1 + 2 e v1/(g (1 − e)), t1 = √(2 H0/g), v1 = g t1.
G, H0 = 9.81, 0.2


def ball(e, analysis):
    return {"node": [{"name": "ball", "mass": 1.0}],
            "contact": [{"name": "floor", "a": "ball", "b": "ground", "gap": H0,
                         "scheme": "restitution", "restitution": e}],
            "loads": {"gravity": G}, "analysis": analysis}


def ball_closed_form(e, n):
    t1 = math.sqrt(2 * H0 / G)
    v = G * t1 * e ** np.arange(n)
    t = t1 + np.concatenate([[0.0], np.cumsum(2 * v[:-1] * e / G)])
    return t, v, t1 + 2 * e * G * t1 / (G * (1 - e))


def flights_resolved(e, flight_res):
    """How many impacts of the ball come before the one whose next flight 2 e v/g is not
    resolved (no longer than flight_res), that one included."""
    t1 = math.sqrt(2 * H0 / G)
    n = 1
    while 2 * e ** n * G * t1 / G > flight_res:
        n += 1
    return n


def held_ball(s):
    c = s["contacts"]["floor"]
    t_on, t_off = np.array(c["impact_times"]), c["separation_times"]
    instant = np.array([x is not None and x == y for x, y in zip(t_off, t_on)])
    return t_on, instant, c


@pytest.mark.parametrize("stepper", ["rkf45", "rk8pd", "msbdf"])
@pytest.mark.parametrize("e", [0.3, 0.6, 0.85])
def test_event_driven_holds_the_ball_from_the_accumulation_point(stepper, e):
    # The persistent phase starts at the predicted t∞ of the last resolved impact: exact for
    # constant g (da = 0), so its error is the error of that impact's time and speed (2/(g(1 −
    # e)) times the speed error). rkf45 and rk8pd at rtol 1e-12 keep every impact within 1e-9 s
    # (measured ≤ 3e-11); msbdf locates events on rk4imp runs whose errors add up from impact
    # to impact: 1e-6, its P2 bar. The contact is held at the first impact whose next flight
    # the method does not resolve (docs/impulse.md §4): its end not located to 1 % from the
    # position error a step d = atol + rtol |u| + 16 ε (|u| + gap) (u = H0 on the floor),
    # τ² ≤ 2d/(0.01 g), or for msbdf, which restarts at order 1, √(2d/g) ≥ 0.01 τ.
    rtol, atol = 1e-12, 1e-14
    an = {"type": "dynamic", "integrator": stepper, "dt": 0.01, "t_end": 3.0, "rtol": rtol,
          "atol": atol}
    s, hist = execute(ball(e, an))
    t_on, instant, c = held_ball(s)
    t_ref, v_ref, t_inf = ball_closed_form(e, int(instant.sum()))
    bar = 1e-6 if stepper == "msbdf" else 1e-9
    assert np.abs(t_on[instant] - t_ref).max() <= bar
    assert np.abs(np.array(c["approach_speeds"])[instant] - v_ref).max() <= bar
    assert (~instant).sum() == 1 and c["separation_times"][-1] is None
    assert abs(t_on[~instant][0] - t_inf) <= (1e-6 if stepper == "msbdf" else 1e-8)
    d = atol + rtol * H0 + 16 * EPS * 2 * H0
    res = math.sqrt(2 * d / G) / RHO if stepper == "msbdf" else math.sqrt(2 * d / (RHO * G))
    assert instant.sum() == flights_resolved(e, res)
    assert hist["u:ball"][hist["t"] > t_inf + 0.01] == pytest.approx(H0, rel=1e-14)


@pytest.mark.parametrize("e", [0.3, 0.6, 0.85])
def test_ida_holds_the_ball_from_the_accumulation_point(e):
    # IDA closes the contact at the first impact whose next flight it does not resolve (the
    # rule of every integrator, docs/impulse.md §4): IDA restarts at order 1 (BDF) and its
    # position error is 10 (rtol max(|u|, gap) + atol), u = H0 on the floor. The impact that
    # closes it is an impact; the persistent phase starts at the predicted t∞ (exact for
    # constant g). IDA's impact times carry its global error, which grows with the restarts
    # (measured 1.2e-11 s on the first five, 1.1e-6 s at the 30th): 1e-5.
    rtol, atol = 1e-12, 1e-16
    an = {"type": "dynamic", "integrator": "ida", "dt": 1e-3, "t_end": 3.0, "rtol": rtol,
          "atol": atol}
    s, _ = execute(ball(e, an))
    t_on, instant, c = held_ball(s)
    t_ref, v_ref, t_inf = ball_closed_form(e, int(instant.sum()))
    assert np.abs(t_on[instant] - t_ref).max() <= 1e-5
    assert (~instant).sum() == 1 and c["separation_times"][-1] is None
    assert abs(t_on[~instant][0] - t_inf) <= 1e-5
    assert c["persistent_from"] == t_on[~instant][0]
    d = 10 * (rtol * H0 + atol)
    assert instant.sum() == flights_resolved(e, math.sqrt(2 * d / G) / RHO)


# --- one multi-contact impact, three integrators ----------------------------------------------

M3 = (1.0, 2.0, 3.0)
V0, E3 = 1.0, 0.25


def three_bodies(analysis):
    # body 1 at V0 reaches body 2 (gap 1 mm), which touches body 3
    return {"node": [{"name": "b1", "mass": M3[0], "v0": V0}, {"name": "b2", "mass": M3[1]},
                     {"name": "b3", "mass": M3[2]}],
            "contact": [{"name": "c12", "a": "b1", "b": "b2", "gap": 1e-3,
                         "scheme": "restitution", "restitution": E3},
                        {"name": "c23", "a": "b2", "b": "b3", "gap": 0.0,
                         "scheme": "restitution", "restitution": E3}],
            "analysis": analysis}


def three_bodies_closed_form():
    """Newton's law on both contacts at once: W = [[1/m1 + 1/m2, −1/m2], [−1/m2, 1/m2 + 1/m3]],
    q = (−(1 + e) V0, 0); both impulses come out positive, so P = −W⁻¹ q (Cramer)."""
    m1, m2, m3 = M3
    w11, w12, w22 = 1 / m1 + 1 / m2, -1 / m2, 1 / m2 + 1 / m3
    det = w11 * w22 - w12 * w12
    r = (1 + E3) * V0
    p = np.array([w22 * r / det, -w12 * r / det])
    v = np.array([V0 - p[0] / m1, (p[0] - p[1]) / m2, p[1] / m3])
    return p, v


@pytest.mark.parametrize("integrator", ["rk8pd", "ida", "moreau-jean"])
def test_same_multi_contact_impact_in_three_integrators(integrator):
    # All three resolve it by the shared Newton's law on both contacts at once, so the final
    # velocities, and the impulses m1 (V0 − v1) and m3 v3 they imply, are the closed form's
    # to the rounding of a 2 x 2 LCP (cond(W) < 6: 64ε of V0). Moreau–Jean meets the contact
    # inside a step: its free velocity is v (no forces), so it solves the same LCP.
    if integrator == "moreau-jean":
        an = {"type": "dynamic", "integrator": integrator, "dt": 1e-4, "t_end": 2e-3}
    elif integrator == "ida":
        an = {"type": "dynamic", "integrator": integrator, "dt": 1e-3, "t_end": 2e-3,
              "rtol": 1e-10, "atol": 1e-14}
    else:
        an = {"type": "dynamic", "integrator": integrator, "dt": 1e-3, "t_end": 2e-3,
              "rtol": 1e-12, "atol": 1e-14}
    s, _ = execute(three_bodies(an))
    p_ref, v_ref = three_bodies_closed_form()
    v = np.array([s["nodes"][b]["v_final"] for b in ("b1", "b2", "b3")])
    np.testing.assert_allclose(v, v_ref, rtol=0, atol=64 * EPS * V0)
    p = np.array([M3[0] * (V0 - v[0]), M3[2] * v[2]])
    np.testing.assert_allclose(p, p_ref, rtol=0, atol=64 * EPS * V0 * max(M3))
    if integrator == "rk8pd":      # the event list holds the impulses themselves
        for name, pk in zip(("c12", "c23"), p_ref):
            assert s["contacts"][name]["phase_max_force"][0] == pytest.approx(pk, rel=64 * EPS)
