"""Closed-form oracles for the martello verification suite.

Every function here is coded from the mathematics in ``/work/shared/PROBLEMS.md`` (the problem
catalogue; section names P1-P9, "Integrators", "Metrics") and the papers it cites. None of
them time-steps the equations the solvers integrate. The tools used are: explicit formulas,
scalar root finding (``scipy.optimize.brentq``) on closed-form functions, quadrature and
special functions. Two helpers are *semi-analytic*, and their docstrings say so:

* :func:`bouncing_oscillator_kelvin`: exact piecewise closed forms, with phase ends found as
  roots of closed-form scalar functions.
* :func:`jankowski_realised_e`: a tight-tolerance ODE quadrature of the scaled energy equation
  in phase-plane variables. It does not integrate the equation of motion in time.

Units are SI. Sign conventions follow PROBLEMS.md. Displacements are positive toward the
obstacle. In P1 the multiplier ``lam = k h - m g`` is negative in contact (the seed's sign),
and ``force = -lam >= 0`` is the compressive force magnitude.

Results come back as small frozen dataclasses with named fields. Call
``dataclasses.asdict(result)`` to get a plain dict.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import integrate, optimize, special

__all__ = [
    # P1
    "MassOnPlaneStatic", "mass_on_plane_static",
    # P2
    "BounceSequence", "bouncing_oscillator_restitution",
    "bouncing_oscillator_restitution_no_gravity", "free_fall_ball",
    "KelvinBounce", "bouncing_oscillator_kelvin",
    # P3
    "TwoBarsStatic", "two_bars_static",
    # P4
    "RodImpact", "rod_impact", "rod_impact_interface_displacement",
    "impedance_plateau_force",
    # P5
    "NewtonImpact", "newton_impact", "kelvin_xi_from_e", "kelvin_e_from_xi",
    "kelvin_damping", "kelvin_clipped_restitution", "linear_contact_time",
    "HertzImpact", "hertz_impact", "HERTZ_TC_CONSTANT",
    "hunt_crossley_realised_e", "hunt_crossley_exact_factor",
    "hc_factor_hunt_crossley", "hc_factor_lankarani_nikravesh", "hc_factor_flores",
    "hc_factor_gonthier", "HC_FACTORS", "hc_max_penetration",
    "jankowski_xi", "jankowski_realised_e",
    # P6
    "ElastoplasticImpulse", "elastoplastic_impulse", "epp_step_load_ductility",
    "bilinear_cycle_energy",
    # linear SDOF
    "SDOFResponse", "sdof_free_response", "sdof_sine_ground_response",
    # P9
    "DavisPeriod1", "davis_period1_impact_velocity", "davis_period1_damped",
    # integrators
    "newmark_params", "hht_params", "generalized_alpha_params",
    "trapezoidal_period_elongation", "central_difference_critical_step",
    "newmark_lagrange_restitution",
    # metrics
    "max_abs_error", "max_rel_error", "scd", "mescd", "EventMatch", "match_events",
]

_EPS = np.finfo(float).eps


# ================================================================================================
# Shared closed form: free response of a linear damped oscillator
# ================================================================================================
def _cs(t, a, wd2):
    """C(t), S(t) of the damped free response, valid in every damping regime.

    x'' + 2 a x' + w0^2 x = 0 has x(t) = e^{-a t} [x0 C + (v0 + a x0) S] and
    v(t) = e^{-a t} [v0 C - (w0^2 x0 + a v0) S]. Here wd2 = w0^2 - a^2, and
    C = cos(wd t), S = sin(wd t)/wd (underdamped), C = cosh(mu t), S = sinh(mu t)/mu
    (overdamped, mu^2 = -wd2), C = 1, S = t (critical). S stays well conditioned as wd -> 0.
    """
    t = np.asarray(t, dtype=float)
    if wd2 > 0.0:
        wd = math.sqrt(wd2)
        return np.cos(wd * t), np.sin(wd * t) / wd
    if wd2 < 0.0:
        mu = math.sqrt(-wd2)
        return np.cosh(mu * t), np.sinh(mu * t) / mu
    return np.ones_like(t), t.copy()


def _damped_state(t, x0, v0, a, w02):
    """Exact (x, v, acc) at times t for x'' + 2 a x' + w02 x = 0 from (x0, v0) at t = 0."""
    t = np.asarray(t, dtype=float)
    wd2 = w02 - a * a
    if wd2 < 0.0 and a > 0.0:
        # overdamped: write the product of exponentials as one exponential so it cannot overflow
        mu = math.sqrt(-wd2)
        ep, em = np.exp((mu - a) * t), np.exp((-mu - a) * t)
        eC = 0.5 * (ep + em)
        eS = 0.5 * (ep - em) / mu
    else:
        C, S = _cs(t, a, wd2)
        ex = np.exp(-a * t)
        eC, eS = ex * C, ex * S
    x = x0 * eC + (v0 + a * x0) * eS
    v = v0 * eC - (w02 * x0 + a * v0) * eS
    acc = -w02 * x - 2.0 * a * v
    return x, v, acc


# ================================================================================================
# P1 - mass on a rigid plane, static
# ================================================================================================
@dataclass(frozen=True)
class MassOnPlaneStatic:
    u: float            #: displacement of the mass (m), positive toward the plane
    lam: float          #: multiplier / contact reaction, seed sign: k h - m g < 0 in contact
    force: float        #: compressive contact force magnitude, -lam >= 0 (N)
    penetration: float  #: max(u - h, 0) (m); 0 for Lagrange
    in_contact: bool


def mass_on_plane_static(m, k, h, g, scheme="lagrange", eps=None) -> MassOnPlaneStatic:
    """P1 (PROBLEMS.md; seed section 3.1, eqs 11-22). A spring k holds a mass m under gravity,
    with a rigid plane at distance h.

    Free (m g <= k h): u = m g/k, lam = 0.
    Lagrange: u = h, lam = k h - m g (< 0).
    Penalty eps: u = (m g + eps h)/(k + eps), lam = eps (h - u) = eps (k h - m g)/(k + eps).
    The grazing case m g = k h counts as not in contact (lam = 0 either way).
    """
    scheme = scheme.lower()
    if scheme not in ("lagrange", "penalty"):
        raise ValueError("scheme must be 'lagrange' or 'penalty'")
    if k <= 0 or m <= 0:
        raise ValueError("m and k must be positive")
    f_r = k * h - m * g                       # seed's f_R; negative iff the plane is reached
    if f_r >= 0.0:
        return MassOnPlaneStatic(m * g / k, 0.0, 0.0, 0.0, False)
    if scheme == "lagrange":
        return MassOnPlaneStatic(float(h), float(f_r), float(-f_r), 0.0, True)
    if eps is None or eps <= 0:
        raise ValueError("penalty scheme needs eps > 0")
    pen = (m * g - k * h) / (k + eps)          # penetration, computed without cancellation
    lam = eps * f_r / (k + eps)
    return MassOnPlaneStatic(float(h + pen), float(lam), float(-lam), float(pen), True)


# ================================================================================================
# P2 - bouncing oscillator with a restitution law
# ================================================================================================
@dataclass(frozen=True)
class BounceSequence:
    t: np.ndarray        #: impact times t_1..t_N (s)
    v: np.ndarray        #: impact (approach) speeds v_1..v_N (m/s), v_{n+1} = e v_n
    tau: np.ndarray      #: flight times between consecutive impacts, tau_n = t_{n+1} - t_n
    zeno_time: float     #: accumulation time t_inf (inf when there is no Zeno point)
    resting_force: float  #: multiplier once resting on the plane, k h - m g (< 0); 0 if none


def _flight_tau(w, dist, e_v):
    """Flight time between impacts for an undamped oscillator whose equilibrium lies at
    signed distance dist = u_eq - h beyond the plane (dist > 0: pressed against the plane),
    leaving the plane with speed e_v.

    The phase-plane circle about the equilibrium runs clockwise from (-dist, -e_v/w) to
    (-dist, +e_v/w), which gives tau = (2/w) atan2(e_v/w, dist). For dist > 0 that is
    PROBLEMS.md's (2/w) atan(e v/(w (u_s - h))). With no gravity (dist = -h) it is
    (2/w)(pi - atan(e v/(w h))).
    """
    return (2.0 / w) * np.arctan2(np.asarray(e_v, float) / w, dist)


def _first_impact_harmonic(w, u_eq, u0, v0, h):
    """First time t > 0 at which u(t) = u_eq + (u0-u_eq) cos wt + (v0/w) sin wt reaches h
    while moving toward it. Returns (t1, v1), or (inf, nan) if the plane is never reached."""
    x0, w0, X = u0 - u_eq, v0 / w, h - u_eq
    r2mx2 = (x0 - X) * (x0 + X) + w0 * w0       # R^2 - X^2 without cancellation
    if r2mx2 <= 0.0:
        return math.inf, math.nan
    s = math.sqrt(r2mx2)
    # x = R cos(phi), phi = w t - psi. The approach crossing has sin(phi) < 0: phi_c = -atan2(s, X)
    psi = math.atan2(w0, x0)
    ang = (-math.atan2(s, X) + psi) % (2.0 * math.pi)
    if ang == 0.0 and not (abs(x0 - X) == 0.0 and w0 > 0):
        ang = 2.0 * math.pi
    return ang / w, w * s


def _zeno_series(x1, e):
    """Sum_{n>=0} atan(x1 e^n) for 0 < e < 1. Direct summation (math.fsum), closed by the
    exact alternating tail series Sum_k (-1)^k x^{2k+1}/((2k+1)(1-e^{2k+1})) once x < 0.05.
    For 1 - e < 1e-3 it switches to Euler-Maclaurin, using the closed-form integral
    Ti2(x1)/(-ln e) and derivative corrections up to f^(5)."""
    if x1 == 0.0:
        return 0.0
    if 1.0 - e >= 1e-3:
        terms = []
        x = x1
        while x >= 0.05:
            terms.append(math.atan(x))
            x *= e
        for j in range(0, 40):
            p = 2 * j + 1
            term = (-1) ** j * x ** p / (p * (1.0 - e ** p))
            terms.append(term)
            if abs(term) <= 1e-18 * x1:
                break
        return math.fsum(terms)
    return _zeno_euler_maclaurin(x1, e)


def _zeno_euler_maclaurin(x1, e):
    L = math.log(e)                                         # < 0
    ti2, _ = integrate.quad(lambda y: math.atan(y) / y if y > 0 else 1.0, 0.0, x1,
                            epsabs=0.0, epsrel=2e-14, limit=200)
    F1, F3, F5 = (_atan_exp_deriv(x1, j) for j in (1, 3, 5))
    return (ti2 / (-L) + 0.5 * math.atan(x1) - F1 * L / 12.0 + F3 * L ** 3 / 720.0
            - F5 * L ** 5 / 30240.0)


def _atan_exp_deriv(y, n):
    """n-th derivative of s -> atan(y0 e^s) at y = y0 e^s, by exact polynomial recursion:
    d/ds = y d/dy. It is written as P(y)/(1+y^2)^n."""
    # f1 = y/(1+y^2); represent f_k = P_k(y)/(1+y^2)^k with numpy polynomials (ascending)
    P = np.polynomial.Polynomial([0.0, 1.0])
    Q = np.polynomial.Polynomial([1.0, 0.0, 1.0])
    for k in range(1, n):
        # d/ds [P/Q^k] = y (P' Q - k P Q') / Q^{k+1}
        P = np.polynomial.Polynomial([0.0, 1.0]) * (P.deriv() * Q - k * P * Q.deriv())
    return float(P(y) / Q(y) ** n)


def _neumaier_cumsum(x):
    """[0, x0, x0+x1, ...]: compensated (Neumaier) running sums, O(n), error ~1 ulp."""
    out = np.empty(len(x) + 1)
    out[0] = 0.0
    s = comp = 0.0
    for i, xi in enumerate(np.asarray(x, float).tolist()):
        tt = s + xi
        comp += (s - tt) + xi if abs(s) >= abs(xi) else (xi - tt) + s
        s = tt
        out[i + 1] = s + comp
    return out


def bouncing_oscillator_restitution(m, k, h, g, e, n_impacts, u0=0.0, v0=0.0) -> BounceSequence:
    """P2, restitution law (PROBLEMS.md "P2 - Mass on a rigid plane, dynamic").

    An undamped oscillator (mass m, spring k, gravity g toward the plane) is released from
    (u0, v0); the default is rest at u = 0. The rigid plane sits at u = h. At each impact the
    speed becomes e v_n away from the plane. The flight back is a half-orbit of the same
    harmonic motion, so it returns with the same speed and v_{n+1} = e v_n. With
    u_s = m g/k:

      t_1 = arccos(1 - h/u_s)/w, v_1 = u_s w sin(w t_1)       (release from rest, u_s > h)
      tau_n = (2/w) atan2(e v_n / w, u_s - h)
            = (2/w) atan(e v_n/(w (u_s - h)))                  if u_s > h  (Zeno for e < 1)
            = (2/w) (pi - atan(e v_n/(w (h - u_s))))           if u_s < h  (no Zeno)

    zeno_time is t_1 + sum tau_n, summed to convergence. It is t_1 for e = 0 and inf for
    e = 1 or when u_s <= h. For e = 0 with u_s > h, only the first (sticking) impact is
    returned. resting_force is k h - m g after the Zeno point (the P1 Lagrange
    value), and 0 when there is no resting phase. If the plane is never reached, the arrays
    are empty and zeno_time is inf.
    """
    if not (0.0 <= e <= 1.0):
        raise ValueError("e must lie in [0, 1]")
    w = math.sqrt(k / m)
    us = m * g / k
    if u0 == 0.0 and v0 == 0.0 and us > 0.0 and h <= 2.0 * us:
        t1 = math.acos(1.0 - h / us) / w        # PROBLEMS.md formula, verbatim
        v1 = us * w * math.sin(w * t1)
    else:
        t1, v1 = _first_impact_harmonic(w, us, u0, v0, h)
    empty = np.zeros(0)
    if not math.isfinite(t1):
        return BounceSequence(empty, empty, empty, math.inf, 0.0)
    dist = us - h
    n = int(n_impacts)
    v = v1 * e ** np.arange(n, dtype=float)
    if e == 0.0 and dist > 0.0:
        n = min(n, 1)                 # plastic impact against a pressing load: it sticks at t_1
        v = v[:n]
    tau = _flight_tau(w, dist, e * v[:-1]) if n > 1 else empty
    t = t1 + _neumaier_cumsum(tau) if n >= 1 else empty
    zeno = math.inf
    resting = 0.0
    if dist > 0.0 and e < 1.0:
        resting = k * h - m * g
        zeno = t1 if e == 0.0 else t1 + (2.0 / w) * _zeno_series(e * v1 / (w * dist), e)
    return BounceSequence(np.asarray(t, float)[:n], v[:n], np.asarray(tau, float),
                          float(zeno), float(resting))


def bouncing_oscillator_restitution_no_gravity(m, k, h, v0, e, n_impacts) -> BounceSequence:
    """P2 without gravity (u_s = 0). The mass starts at u = 0 with speed v0 > w h toward a
    plane at h > 0.

    t_1 = arcsin(w h / v0)/w, v_1 = sqrt(v0^2 - w^2 h^2), v_{n+1} = e v_n,
    tau_n = (2/w)(pi - atan(e v_n/(w h))) (PROBLEMS.md; derived in :func:`_flight_tau`).
    There is no Zeno point: tau_n -> 2 pi/w, and the motion tends to a grazing oscillation
    of amplitude h.
    """
    return bouncing_oscillator_restitution(m, k, h, 0.0, e, n_impacts, u0=0.0, v0=v0)


def free_fall_ball(h0, g, e, n_impacts) -> dict:
    """P2, free-fall ball (no spring) dropped from height h0 onto a rigid floor.

    t_1 = sqrt(2 h0/g), v_k = e^{k-1} v_1,
    t_k = t_1 + (2 e v_1/g)(1 - e^{k-1})/(1 - e) (t_1 + 2 v_1 (k-1)/g for e = 1),
    rebound height after impact k: e^{2k} h0, Zeno time t_1 (1+e)/(1-e) (inf for e = 1).

    Returns a dict with keys t, v (impact speeds), rebound_height, zeno_time, t1, v1.
    """
    t1 = math.sqrt(2.0 * h0 / g)
    v1 = g * t1
    k = np.arange(1, int(n_impacts) + 1, dtype=float)
    v = v1 * e ** (k - 1)
    if e == 1.0:
        t = t1 + 2.0 * v1 * (k - 1) / g
        zeno = math.inf
    else:
        t = t1 + (2.0 * e * v1 / g) * (1.0 - e ** (k - 1)) / (1.0 - e)
        zeno = t1 * (1.0 + e) / (1.0 - e)
    return {"t": t, "v": v, "rebound_height": h0 * e ** (2 * k), "zeno_time": zeno,
            "t1": t1, "v1": v1}


# ================================================================================================
# P2 - penalty (Kelvin) bouncing oscillator: semi-analytic reference
# ================================================================================================
@dataclass(frozen=True)
class KelvinBounce:
    t_impact: np.ndarray       #: contact onset times (s)
    t_separation: np.ndarray   #: contact end times (s); inf for a final persistent contact
    v_in: np.ndarray           #: velocity at onset (m/s, > 0 toward the plane)
    v_out: np.ndarray          #: velocity at separation (m/s, < 0 away); nan if persistent
    max_penetration: np.ndarray  #: max(u - h) during each contact phase (m)
    t_max_penetration: np.ndarray  #: time of that maximum (s)
    persistent_contact: bool   #: the last contact phase never ends (mass settles on the plane)
    end_reason: str            #: "persistent_contact" | "n_impacts" | "no_impact" | "escaped" | "max_phases"
    phases: tuple = field(repr=False, default=())  #: (t0, kind, x0, v0, params) per phase
    u_rest: float = math.nan   #: static equilibrium in contact, (m g + eps h)/(k + eps)

    def evaluate(self, t):
        """Exact u(t), u'(t) of the reference, for t inside the computed phases (numpy arrays).
        Beyond the last phase's end the result is nan, unless that phase is persistent."""
        t = np.atleast_1d(np.asarray(t, dtype=float))
        u = np.full_like(t, np.nan)
        v = np.full_like(t, np.nan)
        starts = np.array([p[0] for p in self.phases])
        idx = np.searchsorted(starts, t, side="right") - 1
        for i, ph in enumerate(self.phases):
            sel = idx == i
            if not np.any(sel):
                continue
            t0, kind, x0, vv0, par = ph
            tend = self.phases[i + 1][0] if i + 1 < len(self.phases) else par.get("t_end", math.inf)
            sel &= t <= tend
            uu, vv = _phase_eval(par, x0, vv0, t[sel] - t0)
            u[sel], v[sel] = uu, vv
        return u, v


def _phase_eval(par, x0, v0, tl):
    """u, u' in phase-local time tl, for a phase described by par."""
    if par["type"] == "ballistic":                 # k = 0 flight: u = u0 + v0 t + g t^2/2
        return par["u0"] + v0 * tl + 0.5 * par["g"] * tl * tl, v0 + par["g"] * tl
    x, v, _ = _damped_state(tl, x0, v0, par["a"], par["w02"])
    return par["u_eq"] + x, v


def _first_crossing(f, fp, horizon, scale_t, initial_sign, n_uniform=400):
    """First t in (0, horizon] at which the closed-form scalar f changes sign away from
    initial_sign. fp is its derivative.

    The bracket comes from a grid: geometric from 1e-13*scale_t up to scale_t/n_uniform,
    then uniform. A grazing dip that crosses and comes back between two grid points would
    escape a sign test. So every extremum between grid points (a sign change of fp, found
    with brentq) is also checked. Brentq then polishes the root to ~1e-15 relative.
    Returns inf if there is no crossing up to the horizon."""
    t_geo = np.geomspace(1e-13 * scale_t, scale_t / n_uniform, 60)
    n = max(int(math.ceil(horizon / (scale_t / n_uniform))), 2)
    if n > 4_000_000:
        raise RuntimeError("crossing search horizon too long for the sampling grid")
    t_uni = np.linspace(scale_t / n_uniform, horizon, n)
    grid = np.unique(np.concatenate((t_geo, t_uni)))
    grid = grid[grid <= horizon]
    fv = f(grid)
    dv = fp(grid)
    s0 = initial_sign
    # points with the wrong sign, or extrema (between samples) with the wrong sign
    for i in range(len(grid)):
        if i > 0 and dv[i - 1] * dv[i] < 0.0:
            # an extremum inside (grid[i-1], grid[i]): does it cross?
            te = optimize.brentq(fp, grid[i - 1], grid[i], xtol=1e-300, rtol=4 * _EPS,
                                 maxiter=400)
            fe = float(f(np.array([te]))[0])
            if fe * s0 < 0.0:
                return optimize.brentq(lambda s: float(f(np.array([s]))[0]), grid[i - 1], te,
                                       xtol=1e-300, rtol=4 * _EPS, maxiter=400)
        if fv[i] * s0 < 0.0:
            lo = grid[i - 1] if i > 0 else 0.0
            if i == 0:
                # a sign change before the first grid point: shrink until the sign is right
                lo = grid[0]
                while f(np.array([lo]))[0] * s0 <= 0.0 and lo > 1e-300:
                    lo *= 1e-3
            return optimize.brentq(lambda s: float(f(np.array([s]))[0]), lo, grid[i],
                                   xtol=1e-300, rtol=4 * _EPS, maxiter=400)
        if fv[i] == 0.0 and i > 0:
            return float(grid[i])
    return math.inf


def _harmonic_up_crossing(A, B, G, w):
    """Smallest t in (0, 2 pi/w] where A cos wt + B sin wt + G crosses zero upward, else inf."""
    R2 = A * A + B * B
    # R^2 - G^2 computed as (A - G')(A + G') + B^2 with G' = -G, which cancels nothing
    # when the phase starts on the level (A = -G)
    r2mg2 = (A + G) * (A - G) + B * B
    if R2 == 0.0 or r2mg2 <= 0.0:
        return math.inf
    s = math.sqrt(r2mg2)
    psi = math.atan2(B, A)
    # R cos(phi) = -G with sin(phi) < 0 (increasing), phi = w t - psi
    ang = (-math.atan2(s, -G) + psi) % (2.0 * math.pi)
    if ang <= 1e-14:
        ang += 2.0 * math.pi   # the starting point itself is not an up-crossing
    return ang / w


def _quadratic_up_crossing(p2, p1, p0):
    """Smallest t > 0 where p2 t^2 + p1 t + p0 crosses zero upward, else inf."""
    roots = []
    if p2 == 0.0:
        if p1 != 0.0:
            roots = [-p0 / p1]
    else:
        disc = p1 * p1 - 4.0 * p2 * p0
        if disc >= 0.0:
            sq = math.sqrt(disc)
            q = -0.5 * (p1 + math.copysign(sq, p1))
            roots = [q / p2] + ([p0 / q] if q != 0.0 else [])
    best = math.inf
    for r in roots:
        if r > 0.0 and 2.0 * p2 * r + p1 > 0.0 and r < best:
            best = r
    return best


def bouncing_oscillator_kelvin(m, k, h, g, eps, c, n_impacts, clipped=False, u0=0.0, v0=0.0,
                               max_phases=None) -> KelvinBounce:
    """P2 penalty, semi-analytic reference (PROBLEMS.md P2 "Penalty"). During contact a
    Kelvin spring eps plus a dashpot c acts; the flights are undamped.

    Flight, m u'' + k u = m g: u = u_s + (u0-u_s) cos wt + (v0/w) sin wt. With k = 0 the
    flight is the parabola u0 + v0 t + g t^2/2.
    Contact (u > h), m u'' + c u' + (k+eps) u = m g + eps h: a damped linear oscillator about
    u_c = (m g + eps h)/(k + eps), solved in closed form for any damping (underdamped,
    critical, overdamped; see :func:`_damped_state`).
    Phase ends:
      * flight -> contact: the first upward crossing of u = h, solved analytically (arctan
        form, no cancellation when the flight starts on the plane). With ``clipped=True``
        this is the first time at which u > h and eps (u-h) + c u' > 0 both hold, so a
        re-engagement while still penetrated is caught too.
      * contact -> flight: the first root of u - h (unclipped law; the force turns tensile
        just before the root), or of eps (u-h) + c u' (clipped law F = max(0, .)). The root
        is found on the closed form: fine sampling plus extremum checks give the bracket,
        then brentq with rtol 4 eps_mach (``_first_crossing``).
    The search horizon is one damped period plus 5 %: successive extrema of a damped
    oscillation decrease, so a crossing missed within one period never comes later. In the
    overdamped case the horizon is 60 slow time constants. If no root exists, the contact is
    persistent and the sequence ends.

    Returns a :class:`KelvinBounce` with onset/separation times, velocities in/out and the
    maximum penetration per contact. ``result.evaluate(t)`` gives the exact history.
    A start inside contact (u0 > h) is recorded as an onset at t = 0. With the clipped law an
    onset can also be a re-engagement at u > h (the force becomes positive again before the
    mass has left the plane's penetration zone); there v_in may be <= 0.

    Not handled: damping or other forces during flight; a structural damper; contact
    stiffness laws other than linear Kelvin; an exactly tangent (double) root, which is
    treated as "no crossing", and a crossing shallower than the sampling grid plus extremum
    check can resolve (a few ulps); Zeno-like cascades (they cannot occur for eps < inf,
    because the contact either separates with finite flight time or persists). Accuracy:
    each phase end is exact to ~1e-15 relative to the phase length. Absolute times
    accumulate one rounding per phase.
    """
    if m <= 0 or eps <= 0 or c < 0 or k < 0:
        raise ValueError("need m > 0, eps > 0, c >= 0, k >= 0")
    K = k + eps
    a_c = c / (2.0 * m)
    w02_c = K / m
    G_c = (m * g - k * h) / K                 # u_c - h, exact without cancellation
    u_c = h + G_c
    wd2_c = w02_c - a_c * a_c
    if wd2_c > 0.0:
        T_c = 2.0 * math.pi / math.sqrt(wd2_c)
        horizon_c = 1.05 * T_c
        scale_c = T_c
    else:
        mu = math.sqrt(-wd2_c) if wd2_c < 0.0 else 0.0
        slow = w02_c / (a_c + mu)       # = a_c - mu, the slow decay rate, without cancellation
        horizon_c = 60.0 / slow
        scale_c = horizon_c / 60.0
    contact_par = {"type": "damped", "a": a_c, "w02": w02_c, "u_eq": u_c}
    if k > 0.0:
        w = math.sqrt(k / m)
        u_s = m * g / k
        flight_par = {"type": "damped", "a": 0.0, "w02": k / m, "u_eq": u_s}
    else:
        w = 0.0
        u_s = math.nan
        flight_par = {"type": "ballistic", "g": g, "u0": None}

    t = 0.0
    u, v = float(u0), float(v0)
    phases = []
    ti, ts, vin, vout, dmax, tdmax = [], [], [], [], [], []
    persistent = False
    reason = "n_impacts"
    limit = max_phases if max_phases is not None else 4 * int(n_impacts) + 4
    in_contact = False
    if u > h or (u == h and v > 0.0):
        in_contact = True
        if clipped and eps * (u - h) + c * v <= 0.0:
            in_contact = False
    if in_contact:          # starting in contact counts as an onset at t = 0
        ti.append(0.0)
        vin.append(v)
    for _ in range(limit):
        if not in_contact:
            # ---------------- flight phase ----------------
            if flight_par["type"] == "ballistic":
                par = dict(flight_par, u0=u)
                phases.append((t, "flight", u, v, par))
                t_a = _quadratic_up_crossing(0.5 * g, v, u - h)
                t_b = math.inf
                if clipped and c > 0.0:
                    # eps (u-h) + c u' = eps(u0-h + v t + g t^2/2) + c (v + g t)
                    t_b = _quadratic_up_crossing(0.5 * eps * g, eps * v + c * g,
                                                 eps * (u - h) + c * v)
                    if math.isfinite(t_b) and (u - h) + v * t_b + 0.5 * g * t_b ** 2 <= 0.0:
                        t_b = math.inf
            else:
                x0, w0 = u - u_s, v / w
                par = dict(flight_par)
                phases.append((t, "flight", x0, v, par))
                t_a = _harmonic_up_crossing(x0, w0, u_s - h, w)
                t_b = math.inf
                if clipped and c > 0.0:
                    # eps x + c x' + eps (u_s - h), x = x0 cos + w0 sin, x' = w(w0 cos - x0 sin)
                    A = eps * x0 + c * w * w0
                    B = eps * w0 - c * w * x0
                    t_b = _harmonic_up_crossing(A, B, eps * (u_s - h), w)
                    if math.isfinite(t_b):
                        xb, _, _ = _damped_state(t_b, x0, v, 0.0, w * w)
                        if u_s + float(xb) - h <= 0.0:
                            t_b = math.inf
            dt = min(t_a, t_b)
            if not math.isfinite(dt):
                reason = "escaped" if ti else "no_impact"
                phases[-1][4]["t_end"] = math.inf
                break
            if len(ti) >= int(n_impacts):
                phases[-1][4]["t_end"] = t + dt
                break
            if flight_par["type"] == "ballistic":
                vn = v + g * dt
                un = h if dt == t_a else u + v * dt + 0.5 * g * dt * dt
            else:
                xn, vn, _ = _damped_state(dt, x0, v, 0.0, w * w)
                vn = float(vn)
                un = h if dt == t_a else u_s + float(xn)
            t += dt
            u, v = float(un), float(vn)
            in_contact = True
            ti.append(t)
            vin.append(v)
        else:
            # ---------------- contact phase ----------------
            x0 = u - u_c
            phases.append((t, "contact", x0, v, dict(contact_par)))
            a, w02 = a_c, w02_c

            def xs(tt, x0=x0, v0_=v):
                return _damped_state(tt, x0, v0_, a, w02)

            if clipped:
                def f(tt):
                    x, xd, _ = xs(tt)
                    return eps * (x + G_c) + c * xd

                def fp(tt):
                    _, xd, xdd = xs(tt)
                    return eps * xd + c * xdd
            else:
                def f(tt):
                    return xs(tt)[0] + G_c

                def fp(tt):
                    return xs(tt)[1]
            # a contact phase starts on an upward crossing of its end function, so f > 0 after 0
            dt = _first_crossing(f, fp, horizon_c, scale_c, 1.0)
            # maximum penetration: first zero of u' (u' > 0 at onset)
            if v > 0.0:
                tend = dt if math.isfinite(dt) else horizon_c
                tm = _first_crossing(lambda tt: xs(tt)[1], lambda tt: xs(tt)[2], tend,
                                     scale_c, 1.0)
                if not math.isfinite(tm):
                    tm = tend if math.isfinite(dt) else math.inf
            else:
                # re-engagement while moving away (clipped law only): largest u over the phase
                tend = dt if math.isfinite(dt) else horizon_c
                grid = np.linspace(0.0, tend, 2001)
                xg = xs(grid)[0]
                i = int(np.argmax(xg))
                tm = float(grid[i])
                if 0 < i < len(grid) - 1:
                    res = optimize.minimize_scalar(lambda s_: -float(xs(s_)[0]),
                                                   bounds=(grid[i - 1], grid[i + 1]),
                                                   method="bounded", options={"xatol": 1e-14})
                    tm = float(res.x)
            if math.isfinite(tm):
                dmax.append(float(xs(np.array([tm]))[0][0] + G_c))
                tdmax.append(t + tm)
            else:  # overdamped creeping toward u_c: the sup is the limit
                dmax.append(float(G_c))
                tdmax.append(math.inf)
            if not math.isfinite(dt):
                persistent = True
                reason = "persistent_contact"
                phases[-1][4]["t_end"] = math.inf
                ts.append(math.inf)
                vout.append(math.nan)
                break
            x1, v1, _ = xs(np.array([dt]))
            t += dt
            v = float(v1[0])
            u = h if not clipped else u_c + float(x1[0])
            ts.append(t)
            vout.append(v)
            in_contact = False
    else:
        reason = "max_phases"
        if phases:
            phases[-1][4].setdefault("t_end", t)
    return KelvinBounce(np.array(ti), np.array(ts), np.array(vin), np.array(vout),
                        np.array(dmax), np.array(tdmax), persistent, reason, tuple(phases),
                        float(u_c))


# ================================================================================================
# P3 - two bars, static contact
# ================================================================================================
@dataclass(frozen=True)
class TwoBarsStatic:
    u1: float
    u2: float
    u3: float
    P: float          #: contact force, >= 0
    lam: float        #: multiplier, seed sign: -P
    in_contact: bool
    penetration: float  #: u2 - u3 - d (> 0 only for penalty)


def two_bars_static(F, r, d, scheme="lagrange", eps=None) -> TwoBarsStatic:
    """P3 (PROBLEMS.md; seed section 3.2, eqs 23-34). r = EA/l.

    No contact (F <= r d): u1 = u2 = F/r, u3 = 0.
    Lagrange: P = (F - r d)/3, u1 = (2F/r + d)/3, u2 = (F/r + 2d)/3, u3 = (F/r - d)/3,
    lam = (r d - F)/3.
    Penalty: P = eps (F/r - d)/(1 + 3 eps/r). The equilibrium r(2u1-u2) = F,
    r(u2-u1) + P = 0, r u3 = P gives u1 = (F - P)/r, u2 = (F - 2P)/r, u3 = P/r,
    penetration P/eps.
    """
    scheme = scheme.lower()
    if F <= r * d:
        return TwoBarsStatic(F / r, F / r, 0.0, 0.0, 0.0, False, 0.0)
    if scheme == "lagrange":
        P = (F - r * d) / 3.0
        return TwoBarsStatic((2 * F / r + d) / 3.0, (F / r + 2 * d) / 3.0, (F / r - d) / 3.0,
                             P, (r * d - F) / 3.0, True, 0.0)
    if scheme == "penalty":
        if eps is None or eps <= 0:
            raise ValueError("penalty scheme needs eps > 0")
        P = eps * (F / r - d) / (1.0 + 3.0 * eps / r)
        return TwoBarsStatic((F - P) / r, (F - 2 * P) / r, P / r, P, -P, True, P / eps)
    raise ValueError("scheme must be 'lagrange' or 'penalty'")


# ================================================================================================
# P4 - two rods, dynamic impact (1-D wave theory)
# ================================================================================================
@dataclass(frozen=True)
class RodImpact:
    c: float              #: bar wave speed sqrt(E/rho)
    impedance: float      #: Z = rho c A
    force: float          #: contact force plateau
    duration: float       #: contact duration
    vA: float             #: final rigid-body (mean) velocity of rod A
    vB: float             #: final rigid-body (mean) velocity of rod B (0 for the wall)
    restitution: float    #: rigid-body restitution (vB - vA)/v0


def rod_impact(E, rho, A, LA, LB, v0, wall=False) -> RodImpact:
    """P4 (PROBLEMS.md). Rod A moves at v0 and strikes rod B at rest, or a rigid wall.
    Elementary 1-D wave theory.

    Rods: force Z v0/2 for 2 min(LA, LB)/c. LA <= LB: vA = 0, vB = v0 LA/LB, e = LA/LB.
    LA > LB: vA = v0 (1 - LB/LA), vB = v0, e = LB/LA.
    Wall: force Z v0 for 2 LA/c, vA = -v0, e = 1. LB is ignored.
    """
    c = math.sqrt(E / rho)
    Z = rho * c * A
    if wall:
        return RodImpact(c, Z, Z * v0, 2.0 * LA / c, -v0, 0.0, 1.0)
    if LA <= LB:
        vA, vB = 0.0, v0 * LA / LB
    else:
        vA, vB = v0 * (1.0 - LB / LA), v0
    return RodImpact(c, Z, 0.5 * Z * v0, 2.0 * min(LA, LB) / c, vA, vB, (vB - vA) / v0)


def impedance_plateau_force(ZA, ZB, v0):
    """P4: the force plateau for different impedances, Z_A Z_B v0/(Z_A + Z_B), valid until
    the first reflection returns."""
    return ZA * ZB * v0 / (ZA + ZB)


def _pulse_integral(t, T, tau):
    """Integral over [0, t] of D, the velocity of a free-free rod's struck end in units of v0.
    The rod has round-trip time T and is struck by a pulse of duration tau <= T whose
    particle velocity is v0/2. D = 1/2 on [0, tau), then 1 on [kT, kT + tau) for k >= 1,
    else 0. (d'Alembert: a free end doubles the returning wave, and a wave in a free-free
    rod recurs with period T.)"""
    t = np.asarray(t, dtype=float)
    out = 0.5 * np.minimum(t, tau)
    n = np.floor(t / T)
    later = n >= 1
    out = out + np.where(later, (n - 1) * tau + np.minimum(t - n * T, tau), 0.0)
    return out


def rod_impact_interface_displacement(t, E, rho, LA, LB, v0, wall=False):
    """P4: exact displacements of the two contact ends for t >= 0, piecewise linear in t.
    Contact starts at t = 0, and displacements are positive in A's direction of travel.

    Equal rods: both ends move at v0/2 during contact (0 <= t <= 2L/c). Afterwards A is at
    rest (its end stays at v0 L/c) and B moves rigidly at v0.
    Wall: the end is held at 0 for 0 <= t <= 2L/c, then the rod leaves rigidly at -v0.
    Unequal rods (a d'Alembert solution for each free-free rod, with tau = 2 min(LA, LB)/c):
    the end velocities are v0 D(t; 2LB/c) for B and v0 - v0 D(t; 2LA/c) for A
    (:func:`_pulse_integral`). The longer rod's end then moves in bursts of duration tau
    once per round trip. The shorter rod is left free of stress and moves rigidly.
    Returns (uA_end, uB_end) as arrays (uB_end is zeros for the wall case).
    """
    t = np.asarray(t, dtype=float)
    if np.any(t < 0):
        raise ValueError("t must be >= 0 (contact starts at t = 0)")
    c = math.sqrt(E / rho)
    TA = 2.0 * LA / c
    if wall:
        uA = np.where(t <= TA, 0.0, -v0 * (t - TA))
        return uA, np.zeros_like(t)
    TB = 2.0 * LB / c
    tau = min(TA, TB)
    uB = v0 * _pulse_integral(t, TB, tau)
    uA = v0 * t - v0 * _pulse_integral(t, TA, tau)
    return uA, uB


# ================================================================================================
# P5 - two bodies colliding: contact laws and restitution
# ================================================================================================
@dataclass(frozen=True)
class NewtonImpact:
    v1: float
    v2: float
    energy_lost: float


def newton_impact(m1, m2, v1, v2, e) -> NewtonImpact:
    """P5, Newton's stereomechanical impact (seed eqs 1-3):
    v1' = v1 - (1+e) m2 (v1-v2)/(m1+m2), v2' = v2 + (1+e) m1 (v1-v2)/(m1+m2),
    energy lost (1/2)(1 - e^2) m* (v1 - v2)^2."""
    M = m1 + m2
    dv = v1 - v2
    ms = m1 * m2 / M
    return NewtonImpact(v1 - (1 + e) * m2 * dv / M, v2 + (1 + e) * m1 * dv / M,
                        0.5 * (1 - e * e) * ms * dv * dv)


def kelvin_xi_from_e(e):
    """P5 Kelvin (Anagnostopoulos 1988): xi = -ln e / sqrt(pi^2 + ln^2 e); e = 0 gives xi = 1."""
    if e <= 0.0:
        return 1.0
    L = math.log(e)
    return -L / math.sqrt(math.pi ** 2 + L * L)


def kelvin_e_from_xi(xi):
    """P5 Kelvin, unclipped law: e = exp(-xi pi / sqrt(1 - xi^2)) (0 for xi >= 1)."""
    if xi >= 1.0:
        return 0.0
    return math.exp(-xi * math.pi / math.sqrt(1.0 - xi * xi))


def kelvin_damping(k, mstar, xi):
    """c = 2 xi sqrt(k m*)."""
    return 2.0 * xi * math.sqrt(k * mstar)


def kelvin_clipped_restitution(xi):
    """P5: restitution of the clipped Kelvin law F = max(0, k delta + c delta'), which
    separates when F = 0.

    delta = (v0/wd) e^{-xi w t} sin(wd t) and F = -m* delta'', so F = 0 where
    tan(theta) = 2 xi nu/(2 xi^2 - 1), theta = wd t, nu = sqrt(1 - xi^2). The first
    positive root is theta* = atan2(2 xi nu, 2 xi^2 - 1), which equals PROBLEMS.md's
    pi - atan(2 xi nu/(1 - 2 xi^2)) for xi < 1/sqrt(2) and holds for all xi < 1. Then
    e_F0 = -delta'(theta*)/v0 = exp(-xi theta*/nu) [(xi/nu) sin theta* - cos theta*].
    Overdamped contact (xi > 1) is the analytic continuation nu = i nu~, theta = i theta~:
    tanh(theta~) = 2 xi nu~/(2 xi^2 - 1), where the ratio is < 1 because
    (2 xi^2 - 1)^2 - 4 xi^2 (xi^2 - 1) = 1, and
    e_F0 = exp(-xi theta~/nu~) [(xi/nu~) sinh theta~ - cosh theta~].
    Critical damping (xi = 1) is the common limit, e^{-2}. (The unclipped law never
    separates for xi >= 1.)
    """
    if xi < 0.0:
        raise ValueError("xi must be >= 0")
    if xi == 1.0:
        return math.exp(-2.0)
    if xi < 1.0:
        nu = math.sqrt(1.0 - xi * xi)
        th = math.atan2(2.0 * xi * nu, 2.0 * xi * xi - 1.0)
        return math.exp(-xi * th / nu) * ((xi / nu) * math.sin(th) - math.cos(th))
    nu = math.sqrt((xi - 1.0) * (xi + 1.0))
    th = math.atanh(2.0 * xi * nu / (2.0 * xi * xi - 1.0))
    # exp(-xi th/nu) * cosh th overflows for huge xi; fold the exponentials together
    return 0.5 * (math.exp(th - xi * th / nu) * (xi / nu - 1.0)
                  - math.exp(-th - xi * th / nu) * (xi / nu + 1.0))


def linear_contact_time(mstar, k):
    """P5 linear spring: contact time pi sqrt(m*/k) (and e = 1)."""
    return math.pi * math.sqrt(mstar / k)


HERTZ_TC_CONSTANT = 2.0 * 0.4 * special.beta(0.4, 0.5)
"""t_c v0 / delta_max for Hertz contact, 2 (2/5) B(2/5, 1/2) = 2.9432751843..."""


@dataclass(frozen=True)
class HertzImpact:
    delta_max: float
    t_c: float
    force_max: float


def hertz_impact(mstar, kh, v0) -> HertzImpact:
    """P5, Hertz F = k_h delta^{3/2}: delta_max = (5 m* v0^2/(4 k_h))^{2/5}.
    From energy, t_c = 2 int_0^dm d delta/(v0 sqrt(1 - (delta/dm)^{5/2})) = 2 (2/5)
    B(2/5, 1/2) dm/v0; the substitution y = x^{5/2} gives the Beta integral."""
    dm = (5.0 * mstar * v0 * v0 / (4.0 * kh)) ** 0.4
    return HertzImpact(dm, HERTZ_TC_CONSTANT * dm / v0, kh * dm ** 1.5)


def _hc_q(a, e, z):
    """q = [ln(1+a) - ln(1 - e a) - (1+e) a]/a^2 with z = ln(1 - e a) supplied exactly.

    Solving in z keeps the digits of 1 - e a, which is ~e^{-a} when a >> 1. For small a
    the series sum_{j>=2} a^{j-2} ((-1)^{j+1} + e^j)/j is used, which removes the O(a)
    cancellation."""
    if a * max(1.0, e) < 0.1:
        s = 0.0
        for j in range(40, 1, -1):
            s = s * a + ((-1.0) ** (j + 1) + e ** j) / j
        return s
    return (math.log1p(a) - z - (1.0 + e) * a) / (a * a)


def hunt_crossley_realised_e(a):
    """P5 Hunt-Crossley family F = K delta^n (1 + chi delta'), a = chi v0. Returns the
    exact realised e, the root of (1+e) a = ln[(1+a)/(1 - e a)] with 0 < e < min(1, 1/a).
    It depends on a only (not on n, K, m*).
    Derivation: m* v dv = -K delta^n (1 + chi v) d delta integrates to
    (m*/chi^2)[chi v - ln(1 + chi v)] + K delta^{n+1}/(n+1) = const.
    The unknown is z = ln(1 - e a) in (z_lo, 0), so e = -expm1(z)/a. Brentq on z works
    for any a: for a >> 1, e = (1 - O(e^{-a}))/a, and the distance to 1/a is kept in z."""
    if a < 0:
        raise ValueError("a = chi v0 must be >= 0")
    if a == 0.0:
        return 1.0
    ez = lambda z: -math.expm1(z) / a
    f = lambda z: _hc_q(a, ez(z), z)           # < 0 at z = 0 (e = 0); > 0 at e = min(1, 1/a)
    z_lo = math.log1p(-a) if a < 1.0 else -(2.0 * a + 50.0)
    z = optimize.brentq(f, z_lo, 0.0, xtol=1e-300, rtol=4 * _EPS, maxiter=500)
    return ez(z)


def hunt_crossley_exact_factor(e):
    """Inverse of :func:`hunt_crossley_realised_e`: the a = chi v0 that realises e exactly.
    Returns inf for e = 0 and 0 for e = 1. Solved in z = ln(1 - e a) with
    a = -expm1(z)/e. q < 0 as z -> 0- (q -> (e^2-1)/2), and q > 0 as z -> -inf (a -> 1/e),
    so z = 0 (the trivial root a = 0) is never returned."""
    if not (0.0 <= e <= 1.0):
        raise ValueError("e must lie in [0, 1]")
    if e == 1.0:
        return 0.0
    if e == 0.0:
        return math.inf
    az = lambda z: -math.expm1(z) / e
    f = lambda z: _hc_q(az(z), e, z)
    z = optimize.brentq(f, -(2.0 / e + 50.0), 0.0, xtol=1e-300, rtol=4 * _EPS, maxiter=500)
    return az(z)


def hc_factor_hunt_crossley(e):
    """Hunt & Crossley (1975): chi v0 = 3(1-e)/2."""
    return 1.5 * (1.0 - e)


def hc_factor_lankarani_nikravesh(e):
    """Lankarani & Nikravesh (1990); the Hertzdamp of Muthukumar & DesRoches (2006):
    chi v0 = 3(1-e^2)/4."""
    return 0.75 * (1.0 - e * e)


def hc_factor_flores(e):
    """Flores et al. (2011) / Ye et al. (2009): chi v0 = 8(1-e)/(5e)."""
    return 8.0 * (1.0 - e) / (5.0 * e) if e > 0 else math.inf


def hc_factor_gonthier(e):
    """Gonthier et al. (2004): chi v0 = (1-e^2)/e."""
    return (1.0 - e * e) / e if e > 0 else math.inf


HC_FACTORS = {
    "hunt_crossley": hc_factor_hunt_crossley,
    "lankarani_nikravesh": hc_factor_lankarani_nikravesh,
    "flores": hc_factor_flores,
    "gonthier": hc_factor_gonthier,
    "exact": hunt_crossley_exact_factor,
}


def hc_max_penetration(n, K, mstar, chi, v0):
    """P5 Hunt-Crossley family: delta_max^{n+1} = (n+1) m* (a - ln(1+a))/(K chi^2), with
    a = chi v0. It tends to the undamped (n+1) m* v0^2/(2K) as chi -> 0; a series is used
    for small a."""
    a = chi * v0
    if a < 1e-4:
        g = a * a * (0.5 - a / 3.0 + a * a / 4.0 - a ** 3 / 5.0)   # a - ln(1+a)
    else:
        g = a - math.log1p(a)
    if chi == 0.0:
        val = (n + 1) * mstar * v0 * v0 / (2.0 * K)
    else:
        val = (n + 1) * mstar * g / (K * chi * chi)
    return val ** (1.0 / (n + 1))


def jankowski_xi(e):
    """Jankowski (EESD 2005): xi = (9 sqrt5/2)(1-e^2)/(e (e (9 pi - 16) + 16))."""
    return 4.5 * math.sqrt(5.0) * (1.0 - e * e) / (e * (e * (9.0 * math.pi - 16.0) + 16.0))


def jankowski_realised_e(xi, rtol=1e-13):
    """P5: the restitution actually realised by Jankowski's law F = beta delta^{3/2} + c delta'
    (c applied only while delta' > 0) with c = 2 xi sqrt(beta sqrt(delta) m*).
    Semi-analytic: a tight-tolerance quadrature of a smooth first-order ODE. It does NOT
    time-step the equation of motion.

    Scaling delta = L x, t = (L/v0) s, L = (m* v0^2/beta)^{2/5}, gives
    x'' = -x^{3/2} - 2 xi x^{1/4} x' (approach), x'' = -x^{3/2} (restitution), x(0)=0, x'(0)=1,
    so e depends on xi alone. Restitution is conservative:
    e^2/2 = (2/5) x_m^{5/2}, so e = sqrt(4/5) x_m^{5/4}. Only the approach is integrated,
    in the phase plane. With s = x^{1/4} and p = x', the equation is
    p dp/ds = -4 s^9 - 8 xi s^4 p, polynomial and therefore smooth, integrated from s = 0
    (p = 1) to p = 1/2. Then s is used as a function of p, ds/dp = p/(-4 s^9 - 8 xi s^4 p),
    which is smooth for s > 0 down to p = 0, where s = s_m = x_m^{1/4}. Both legs use
    DOP853 with rtol 1e-13 and atol 1e-16. The result agrees with a direct time integration
    to ~1e-12 (see the tests)."""
    if xi == 0.0:
        return 1.0
    if xi < 0:
        raise ValueError("xi must be >= 0")

    def leg1(s, y):
        p = y[0]
        return [(-4.0 * s ** 9 - 8.0 * xi * s ** 4 * p) / p]

    def ev_half(s, y):
        return y[0] - 0.5
    ev_half.terminal = True
    ev_half.direction = -1
    # undamped x_m = (5/4)^{2/5} < 1.1, so s_m < 1.03; s = 2 bounds the search safely
    sol1 = integrate.solve_ivp(leg1, (0.0, 2.0), [1.0], method="DOP853", rtol=rtol,
                               atol=1e-16, events=ev_half, dense_output=False)
    if sol1.status != 1:
        raise RuntimeError("jankowski_realised_e: p = 1/2 was not reached")
    s_half = float(sol1.t_events[0][0])

    def leg2(p, y):
        s = y[0]
        return [p / (-4.0 * s ** 9 - 8.0 * xi * s ** 4 * p)]
    sol2 = integrate.solve_ivp(leg2, (0.5, 0.0), [s_half], method="DOP853", rtol=rtol,
                               atol=1e-16)
    s_m = float(sol2.y[0, -1])
    x_m = s_m ** 4
    return math.sqrt(0.8) * x_m ** 1.25


# ================================================================================================
# P6 - elasto-plastic SDOF
# ================================================================================================
@dataclass(frozen=True)
class ElastoplasticImpulse:
    t1: float       #: time of first yield
    v1: float       #: speed at first yield
    u_max: float    #: peak displacement
    t_max: float    #: time of the peak
    ductility: float  #: u_max / u_y


def elastoplastic_impulse(m, k, uy, rho, v0) -> ElastoplasticImpulse:
    """P6 (PROBLEMS.md). An undamped bilinear SDOF (kinematic hardening rho) starts from rest
    at u = 0 with speed v0 > w u_y.

    t1 = arcsin(w u_y/v0)/w, v1 = sqrt(v0^2 - w^2 u_y^2).
    Then m x'' = -F_y - rho k x for x = u - u_y.
    rho = 0: u_max = u_y + m v1^2/(2 F_y), reached at t1 + m v1/F_y.
    rho > 0: x = (F_y/(rho k))(cos w_p t - 1) + (v1/w_p) sin w_p t with w_p = w sqrt(rho), so
    x_max = -a + sqrt(a^2 + (v1/w_p)^2) with a = u_y/rho, reached at
    t1 + atan2(v1, a w_p)/w_p.
    For v0 <= w u_y the motion is elastic: u_max = v0/w at pi/(2w)."""
    w = math.sqrt(k / m)
    Fy = k * uy
    if v0 <= w * uy:
        return ElastoplasticImpulse(math.inf, math.nan, v0 / w, 0.5 * math.pi / w, v0 / w / uy)
    t1 = math.asin(w * uy / v0) / w
    v1 = math.sqrt((v0 - w * uy) * (v0 + w * uy))
    if rho == 0.0:
        umax = uy + m * v1 * v1 / (2.0 * Fy)
        tmax = t1 + m * v1 / Fy
    else:
        wp = w * math.sqrt(rho)
        a = uy / rho
        b = v1 / wp
        # -a + sqrt(a^2 + b^2) = b^2/(a + sqrt(a^2+b^2)), which avoids cancellation
        umax = uy + b * b / (a + math.hypot(a, b))
        tmax = t1 + math.atan2(v1, a * wp) / wp
    return ElastoplasticImpulse(t1, v1, umax, tmax, umax / uy)


def epp_step_load_ductility(F0_over_Rm):
    """P6: ductility of an undamped elastic-perfectly-plastic SDOF under a suddenly applied
    constant load F0 (Biggs 1964).
    r = F0/R_m <= 1/2: elastic, mu = 2r. 1/2 <= r < 1: mu = 1/(2(1 - r)), from
    (R_m - F0)(u_m - u_y) = F0 u_y - R_m u_y/2. r >= 1: unbounded (inf)."""
    r = float(F0_over_Rm)
    if r < 0:
        raise ValueError("F0/R_m must be >= 0")
    if r <= 0.5:
        return 2.0 * r
    if r >= 1.0:
        return math.inf
    return 1.0 / (2.0 * (1.0 - r))


def bilinear_cycle_energy(Fy, rho, um, uy):
    """P6: energy dissipated per symmetric cycle to +/-u_m by the bilinear kinematic-hardening
    spring, 4(1 - rho) F_y (u_m - u_y) (0 if u_m <= u_y). The loop is a parallelogram with
    the bounding lines F = rho k u +/- (1 - rho) F_y as two sides and elastic sides of
    horizontal extent 2 u_y."""
    return 4.0 * (1.0 - rho) * Fy * max(um - uy, 0.0)


# ================================================================================================
# Linear SDOF, exact response
# ================================================================================================
@dataclass(frozen=True)
class SDOFResponse:
    u: np.ndarray   #: relative displacement
    v: np.ndarray   #: relative velocity
    a: np.ndarray   #: relative acceleration


def sdof_free_response(m, k, zeta, t, u0=0.0, v0=0.0) -> SDOFResponse:
    """Exact free response of m u'' + 2 zeta w m u' + k u = 0 for any zeta >= 0, vectorised
    over t."""
    w02 = k / m
    a = zeta * math.sqrt(w02)
    x, v, acc = _damped_state(np.asarray(t, float), u0, v0, a, w02)
    return SDOFResponse(x, v, acc)


def sdof_sine_ground_response(m, k, zeta, ag_amp, omega_g, t, u0=0.0, v0=0.0) -> SDOFResponse:
    """Exact relative response of m u'' + c u' + k u = -m u_g'' with u_g'' = A sin(Omega t),
    c = 2 zeta w m. This is the particular solution plus the homogeneous one that matches
    (u0, v0) at t = 0.

    Particular: u_p = -A[(w^2 - W^2) sin Wt - 2 zeta w W cos Wt]/((w^2 - W^2)^2 + (2 zeta w W)^2).
    Undamped resonance (zeta = 0, W = w): u_p = (A/(2w)) t cos wt.
    m cancels from the relative equation; it is kept for a uniform signature."""
    t = np.asarray(t, dtype=float)
    w02 = k / m
    w = math.sqrt(w02)
    a = zeta * w
    W = float(omega_g)
    A = float(ag_amp)
    if zeta == 0.0 and W == w:
        up = (A / (2 * w)) * t * np.cos(w * t)
        vp = (A / (2 * w)) * (np.cos(w * t) - w * t * np.sin(w * t))
        ap = -A * np.sin(w * t) - w02 * up
        up0, vp0 = 0.0, A / (2 * w)
    else:
        D = (w02 - W * W) ** 2 + (2 * a * W) ** 2
        P = -A * (w02 - W * W) / D      # coefficient of sin
        Q = A * 2 * a * W / D           # coefficient of cos
        up = P * np.sin(W * t) + Q * np.cos(W * t)
        vp = W * (P * np.cos(W * t) - Q * np.sin(W * t))
        ap = -W * W * up
        up0, vp0 = Q, W * P
    xh, vh, ah = _damped_state(t, u0 - up0, v0 - vp0, a, w02)
    return SDOFResponse(xh + up, vh + vp, ah + ap)


# ================================================================================================
# P9 - harmonically forced oscillator against a rigid barrier (Davis 1992)
# ================================================================================================
@dataclass(frozen=True)
class DavisPeriod1:
    V: float             #: impact velocity (x' just before impact, > 0)
    phi: float           #: forcing phase at the impact (x'' + 2 zeta x' + x = F cos(eta tau + phi))
    admissible: bool     #: V > 0 and x < 0 on the open interval between impacts
    x_max_between: float  #: max of x over the sample grid of the open interval
    x_max_interior: float  #: largest interior local maximum of x (-inf if none); must be < 0


def davis_period1_impact_velocity(F, eta, r):
    """P9 (Davis 1992): impact velocity of the undamped period-1 orbit,
    v = (2/(1+r)) |P| / sqrt(cot^2(pi/eta) + ((1-r)/((1+r) eta))^2), P = F/(1 - eta^2).
    For r = 1 this is |P tan(pi/eta)|. Admissibility is not checked here; use
    :func:`davis_period1_damped` (zeta = 0 works too)."""
    P = F / (1.0 - eta * eta)
    cot = 1.0 / math.tan(math.pi / eta)
    return (2.0 / (1.0 + r)) * abs(P) / math.sqrt(cot * cot + ((1 - r) / ((1 + r) * eta)) ** 2)


def davis_period1_damped(F, eta, r, zeta=0.0, n_check=20000) -> DavisPeriod1:
    """P9 with damping: x'' + 2 zeta x' + x = F cos(eta tau + phi), barrier at x = 0, x <= 0,
    impacts at tau = 0 and tau = T = 2 pi/eta, with x'+ = -r x'-.

    Write x = homogeneous + particular, with the particular part
    x_p = F Re[e^{i(eta tau + phi)} H], H = 1/(1 - eta^2 + 2 i zeta eta). The initial data
    x(0) = 0, x'(0+) = -r V and the periodicity conditions x(T) = 0, x'(T-) = V are linear in
    (V, cos phi, sin phi). The 2x3 matrix is
      row1 = [-r Phi12, (1 - Phi11) p - Phi12 q]
      row2 = [-r Phi22 - 1, -Phi21 p + (1 - Phi22) q]
    where Phi is the exact homogeneous transition matrix over T, and x_p(0) = p.(c, s),
    x_p'(0) = q.(c, s). Its null vector (from the SVD) is normalised so that
    cos^2 + sin^2 = 1 and V > 0. Admissibility: x(tau) < 0 on (0, T). This is checked on
    n_check samples, and every interior local maximum is refined on the closed form
    (scipy's bounded minimize_scalar).
    Raises ValueError if the null space is degenerate, e.g. in internal resonance."""
    T = 2.0 * math.pi / eta
    a = zeta
    H = 1.0 / complex(1.0 - eta * eta, 2.0 * zeta * eta)
    p = np.array([F * H.real, -F * H.imag])            # x_p(0) = p . (c, s)
    q = np.array([-F * eta * H.imag, -F * eta * H.real])  # x_p'(0) = q . (c, s)
    x10, v10, _ = _damped_state(T, 1.0, 0.0, a, 1.0)
    x01, v01, _ = _damped_state(T, 0.0, 1.0, a, 1.0)
    Phi = np.array([[float(x10), float(x01)], [float(v10), float(v01)]])
    M = np.zeros((2, 3))
    M[0, 0] = -r * Phi[0, 1]
    M[0, 1:] = (1 - Phi[0, 0]) * p - Phi[0, 1] * q
    M[1, 0] = -r * Phi[1, 1] - 1.0
    M[1, 1:] = -Phi[1, 0] * p + (1 - Phi[1, 1]) * q
    _, sv, Vt = np.linalg.svd(M)
    if sv[1] < 1e-12 * max(sv[0], 1.0):
        raise ValueError("degenerate periodicity system (rank < 2)")
    n = Vt[-1]
    nrm = math.hypot(n[1], n[2])
    if nrm == 0.0:
        raise ValueError("null vector has no phase component")
    n = n / nrm
    if n[0] < 0:
        n = -n
    V, cph, sph = float(n[0]), float(n[1]), float(n[2])
    phi = math.atan2(sph, cph)

    def x_of(tau):
        tau = np.asarray(tau, float)
        xp0 = p @ [cph, sph]
        vp0 = q @ [cph, sph]
        xh, _, _ = _damped_state(tau, -xp0, -r * V - vp0, a, 1.0)
        xp = F * (H.real * np.cos(eta * tau + phi) - H.imag * np.sin(eta * tau + phi))
        return xh + xp

    taus = np.linspace(0.0, T, n_check + 1)[1:-1]
    xs = x_of(taus)
    # interior local maxima of the sampled curve, each refined on the closed form
    imax = [i for i in range(1, len(xs) - 1) if xs[i] >= xs[i - 1] and xs[i] >= xs[i + 1]]
    peaks = []
    for i in imax:
        res = optimize.minimize_scalar(lambda s: -float(x_of(s)), bounds=(taus[i - 1], taus[i + 1]),
                                       method="bounded", options={"xatol": 1e-12})
        peaks.append(max(float(xs[i]), -float(res.fun)))
    xmax_int = max(peaks) if peaks else -math.inf
    ok = bool(V > 0 and np.all(xs < 0.0) and xmax_int < 0.0)
    return DavisPeriod1(V, phi, ok, float(np.max(xs)), float(xmax_int))


# ================================================================================================
# Integrators
# ================================================================================================
_NEWMARK_NAMES = {
    "average_acceleration": (0.25, 0.5), "trapezoidal": (0.25, 0.5),
    "constant_average_acceleration": (0.25, 0.5),
    "linear_acceleration": (1.0 / 6.0, 0.5),
    "central_difference": (0.0, 0.5),
    "fox_goodwin": (1.0 / 12.0, 0.5),
}


def newmark_params(name=None, beta=None, gamma=None) -> dict:
    """Newmark (seed eqs 46a, b): named schemes average_acceleration/trapezoidal (1/4, 1/2),
    linear_acceleration (1/6, 1/2), central_difference (0, 1/2), fox_goodwin (1/12, 1/2),
    or explicit beta, gamma. The scheme is unconditionally stable for 2 beta >= gamma >= 1/2.
    For gamma >= 1/2 and 2 beta < gamma, the undamped stability limit is
    w h <= 1/sqrt(gamma/2 - beta). Returns a dict with beta, gamma,
    unconditionally_stable and omega_h_crit."""
    if name is not None:
        key = name.lower().replace("-", "_").replace(" ", "_")
        if key not in _NEWMARK_NAMES:
            raise ValueError(f"unknown Newmark scheme {name!r}; known: {sorted(_NEWMARK_NAMES)}")
        beta, gamma = _NEWMARK_NAMES[key]
    if beta is None or gamma is None:
        raise ValueError("give a name or both beta and gamma")
    uncond = (2 * beta >= gamma) and gamma >= 0.5
    if uncond:
        crit = math.inf
    elif gamma >= 0.5:
        crit = 1.0 / math.sqrt(gamma / 2.0 - beta)
    else:
        crit = 0.0   # gamma < 1/2: unstable (negative numerical damping)
    return {"beta": float(beta), "gamma": float(gamma), "unconditionally_stable": bool(uncond),
            "omega_h_crit": crit}


def hht_params(alpha) -> dict:
    """HHT-alpha (Hilber-Hughes-Taylor 1977), with alpha in [-1/3, 0]:
    gamma = 1/2 - alpha, beta = (1 - alpha)^2/4, rho_inf = (1 + alpha)/(1 - alpha).
    Also gives the equivalent generalized-alpha parameters alpha_m = 0 and alpha_f = -alpha,
    for the convention M a_{n+1-alpha_m} + K d_{n+1-alpha_f} = F."""
    if not (-1.0 / 3.0 - 1e-15 <= alpha <= 0.0):
        raise ValueError("HHT alpha must lie in [-1/3, 0]")
    return {"alpha": float(alpha), "gamma": 0.5 - alpha, "beta": 0.25 * (1 - alpha) ** 2,
            "rho_inf": (1 + alpha) / (1 - alpha), "alpha_m": 0.0, "alpha_f": -float(alpha)}


def generalized_alpha_params(rho_inf):
    """Generalized-alpha (Chung & Hulbert 1993), rho_inf in [0, 1]:
    alpha_m = (2 rho - 1)/(rho + 1), alpha_f = rho/(rho + 1), gamma = 1/2 - alpha_m + alpha_f,
    beta = (1 - alpha_m + alpha_f)^2/4. Returns (alpha_m, alpha_f, beta, gamma)."""
    r = float(rho_inf)
    if not (0.0 <= r <= 1.0):
        raise ValueError("rho_inf must lie in [0, 1]")
    am = (2 * r - 1) / (r + 1)
    af = r / (r + 1)
    gamma = 0.5 - am + af
    beta = 0.25 * (1 - am + af) ** 2
    return am, af, beta, gamma


def trapezoidal_period_elongation(omega, h):
    """The trapezoidal rule (average acceleration) rotates by w_bar h = 2 atan(w h/2) per
    step: w_bar = (2/h) atan(w h/2). Also returns the period ratio T_bar/T = w/w_bar, as
    (w_bar, ratio)."""
    wb = (2.0 / h) * math.atan(omega * h / 2.0)
    return wb, omega / wb


def central_difference_critical_step(omega, xi=0.0, lagged=False):
    """Central difference: h_crit = 2/w with the central damping velocity (damping does
    not change the limit), or (2/w)(sqrt(1 + xi^2) - xi) with the lagged (half-step)
    velocity. The second is the root of W^2 + 4 xi W - 4 = 0, the z = -1 boundary of
    z^2 + (W^2 + 2 xi W - 2) z + (1 - 2 xi W) = 0."""
    if lagged:
        return (2.0 / omega) * (math.sqrt(1.0 + xi * xi) - xi)
    return 2.0 / omega


def newmark_lagrange_restitution(alpha, beta=0.25, gamma=0.5):
    """Integrators section: numerical restitution when a u-level contact constraint is
    enforced with a multiplier inside one Newmark step, and the gap closes a fraction alpha
    into the step: gamma (1 - alpha)/beta - 1 (trapezoidal: 1 - 2 alpha).
    Enforcing u_{n+1} = contact with a_n = 0 gives a_{n+1} = -(1-alpha) v/(beta h), so
    v_{n+1} = v (1 - gamma (1-alpha)/beta)."""
    return gamma * (1.0 - alpha) / beta - 1.0


# ================================================================================================
# Metrics
# ================================================================================================
def max_abs_error(y, yref):
    """max |y - y_ref| over all entries."""
    y, yref = np.asarray(y, float), np.asarray(yref, float)
    return float(np.max(np.abs(y - yref)))


def max_rel_error(y, yref, floor=0.0):
    """max |y - y_ref| / max(|y_ref|, floor). It is inf if y_ref has zeros, y differs there,
    and floor = 0."""
    y, yref = np.asarray(y, float), np.asarray(yref, float)
    den = np.maximum(np.abs(yref), floor)
    err = np.abs(y - yref)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.where(err == 0.0, 0.0, err / den)
    return float(np.max(r))


def scd(y, yref):
    """Significant correct digits, -log10(max relative error) (IVP Test Set, Mazzia &
    Magherini). inf for an exact match."""
    e = max_rel_error(y, yref)
    return math.inf if e == 0.0 else -math.log10(e)


def mescd(y, yref, atol, rtol):
    """Mixed significant correct digits, -log10(max |y - y_ref|/(atol/rtol + |y_ref|))."""
    y, yref = np.asarray(y, float), np.asarray(yref, float)
    e = float(np.max(np.abs(y - yref) / (atol / rtol + np.abs(yref))))
    return math.inf if e == 0.0 else -math.log10(e)


@dataclass(frozen=True)
class EventMatch:
    pairs: np.ndarray     #: (n_matched, 2) int array: index into t, index into t_ref
    dt: np.ndarray        #: t[i] - t_ref[j] for each pair
    n_matched: int
    n_missing: int        #: reference events with no computed partner
    n_extra: int          #: computed events with no reference partner
    missing: np.ndarray   #: indices into t_ref
    extra: np.ndarray     #: indices into t
    max_abs_dt: float     #: max |dt| over pairs (0 if none)


def match_events(t, t_ref, window) -> EventMatch:
    """Pair computed event times t with reference times t_ref one to one. A pair is allowed
    only if |t_i - t_ref_j| <= window. The pairing maximises the number of pairs, then
    minimises the sum of |dt|. This is an exact assignment (scipy linear_sum_assignment),
    solved independently in each cluster of events whose windows chain together. A shifted
    impact therefore shows up as a small dt, not as one missing and one extra event."""
    t = np.asarray(t, float).ravel()
    tr = np.asarray(t_ref, float).ravel()
    allt = np.concatenate((t, tr))
    src = np.concatenate((np.zeros(len(t), int), np.ones(len(tr), int)))
    idx = np.concatenate((np.arange(len(t)), np.arange(len(tr))))
    order = np.argsort(allt, kind="stable")
    allt, src, idx = allt[order], src[order], idx[order]
    pairs = []
    start = 0
    nall = len(allt)
    for end in range(1, nall + 1):
        if end == nall or allt[end] - allt[end - 1] > window:
            ci = idx[start:end][src[start:end] == 0]
            cj = idx[start:end][src[start:end] == 1]
            if len(ci) and len(cj):
                D = np.abs(t[ci][:, None] - tr[cj][None, :])
                big = (window + 1.0) * (len(ci) + len(cj) + 1) + 1.0
                cost = np.where(D <= window, D, big)
                r_, c_ = optimize.linear_sum_assignment(cost)
                for a_, b_ in zip(r_, c_):
                    if D[a_, b_] <= window:
                        pairs.append((ci[a_], cj[b_]))
            start = end
    pairs = np.array(sorted(pairs, key=lambda p: p[1]), dtype=int).reshape(-1, 2)
    dt = t[pairs[:, 0]] - tr[pairs[:, 1]] if len(pairs) else np.zeros(0)
    missing = np.setdiff1d(np.arange(len(tr)), pairs[:, 1])
    extra = np.setdiff1d(np.arange(len(t)), pairs[:, 0])
    return EventMatch(pairs, dt, len(pairs), len(missing), len(extra), missing, extra,
                      float(np.max(np.abs(dt))) if len(dt) else 0.0)


# ---------------------------------------------------------------------------------------------
# Catalogue dispatchers: one call per scene kind, returning a dict of named oracle values, so
# that a scene's [check] table can name them (martello/check.py). They only combine the
# closed forms above.

def two_body_impact(law, m1, m2, v0, stiffness, restitution=None, exponent=None, clipped=False):
    """P5: a free two-body impact (approach speed v0 > 0) under one penalty law.

    Returns restitution (realised e), contact_time where a closed form exists, and
    max_penetration where one exists. For kelvin the damping is the Anagnostopoulos one
    derived from the target e; the HC family uses its own published factor a(e)."""
    mstar = m1 * m2 / (m1 + m2)
    out = {}
    if law == "linear":
        out.update(restitution=1.0, contact_time=linear_contact_time(mstar, stiffness),
                   max_penetration=v0 * math.sqrt(mstar / stiffness))
    elif law == "hertz":
        h = hertz_impact(mstar, stiffness, v0)
        out.update(restitution=1.0, contact_time=h.t_c, max_penetration=h.delta_max)
    elif law == "kelvin":
        xi = kelvin_xi_from_e(restitution)
        out["restitution"] = kelvin_clipped_restitution(xi) if clipped else restitution
        if not clipped:
            # the unclipped phase is exactly half a damped period
            out["contact_time"] = math.pi / (math.sqrt(stiffness / mstar) * math.sqrt(1 - xi * xi))
    elif law in ("hunt-crossley", "lankarani-nikravesh", "flores", "gonthier", "hertzdamp"):
        key = "lankarani_nikravesh" if law == "hertzdamp" else law.replace("-", "_")
        a = HC_FACTORS[key](restitution)
        n = 1.5 if (law == "hertzdamp" or exponent is None) else exponent
        out.update(restitution=hunt_crossley_realised_e(a),
                   max_penetration=hc_max_penetration(n, stiffness, mstar, a / v0, v0))
    elif law == "jankowski":
        out["restitution"] = jankowski_realised_e(jankowski_xi(restitution))
    else:
        raise ValueError(f"no closed form for law {law!r}")
    return out


def elastoplastic_peak(m, k, uy, rho, v0):
    """P6 as a dict (u_max, t_max) for scene checks."""
    r = elastoplastic_impulse(m, k, uy, rho, v0)
    return {"u_max": r.u_max, "t_max": r.t_max}


def sdof_sine_ground_final(m, k, zeta, ag_amp, omega_g, t_end):
    """Exact relative displacement and velocity of a damped SDOF under A sin(Ωt) ground
    acceleration at t_end, from rest."""
    r = sdof_sine_ground_response(m, k, zeta, ag_amp, omega_g, np.array([t_end]))
    return {"u": float(r.u[0]), "v": float(r.v[0])}


def bouncing_kelvin_events(m, k, h, g, eps, n_impacts, restitution=None, damping=0.0,
                           clipped=False):
    """P2 with a Kelvin (or, damping = 0, linear) penalty plane, as named values for scene
    checks: t_impact_i, t_separation_i, max_penetration_i (i from 0). The dashpot c comes from
    the target e by Anagnostopoulos' formula with m* = m, as the scene's law does."""
    c = damping
    if restitution is not None:
        c = kelvin_damping(eps, m, kelvin_xi_from_e(restitution))
    r = bouncing_oscillator_kelvin(m, k, h, g, eps, c, n_impacts, clipped=clipped)
    out = {}
    for i in range(min(n_impacts, len(r.t_impact))):
        out[f"t_impact_{i}"] = r.t_impact[i]
        if i < len(r.t_separation) and r.t_separation[i] is not None:
            out[f"t_separation_{i}"] = r.t_separation[i]
        out[f"max_penetration_{i}"] = r.max_penetration[i]
    return out


def bouncing_restitution_events(m, k, h, g, e, n_impacts):
    """P2 with Newton restitution, as named values: t_impact_i, v_impact_i, zeno_time,
    resting_force."""
    r = bouncing_oscillator_restitution(m, k, h, g, e, n_impacts)
    out = {f"t_impact_{i}": float(t) for i, t in enumerate(r.t)}
    out.update({f"v_impact_{i}": float(v) for i, v in enumerate(r.v)})
    out.update(zeno_time=r.zeno_time, resting_force=r.resting_force)
    return out
