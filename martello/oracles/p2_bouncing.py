"""P2 (docs/problems.md P2): the bouncing oscillator, a mass on a spring against a rigid
plane. The restitution law has exact impact sequences (and the Zeno time, summed to
convergence); the penalty (Kelvin) plane has a *semi-analytic* reference: exact piecewise
closed forms whose phase ends are roots of closed-form scalar functions."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from scipy import integrate, optimize

from .linear_sdof import damped_state

_EPS = np.finfo(float).eps


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
    docs/problems.md's (2/w) atan(e v/(w (u_s - h))). With no gravity (dist = -h) it is
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
    """P2, restitution law (docs/problems.md "P2 - Mass on a rigid plane, dynamic").

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
        t1 = math.acos(1.0 - h / us) / w        # docs/problems.md formula, verbatim
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
    tau_n = (2/w)(pi - atan(e v_n/(w h))) (docs/problems.md; derived in :func:`_flight_tau`).
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
    x, v, _ = damped_state(tl, x0, v0, par["a"], par["w02"])
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
    """P2 penalty, semi-analytic reference (docs/problems.md P2 "Penalty"). During contact a
    Kelvin spring eps plus a dashpot c acts; the flights are undamped.

    Flight, m u'' + k u = m g: u = u_s + (u0-u_s) cos wt + (v0/w) sin wt. With k = 0 the
    flight is the parabola u0 + v0 t + g t^2/2.
    Contact (u > h), m u'' + c u' + (k+eps) u = m g + eps h: a damped linear oscillator about
    u_c = (m g + eps h)/(k + eps), solved in closed form for any damping (underdamped,
    critical, overdamped; see :func:`damped_state`).
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
                        xb, _, _ = damped_state(t_b, x0, v, 0.0, w * w)
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
                xn, vn, _ = damped_state(dt, x0, v, 0.0, w * w)
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
                return damped_state(tt, x0, v0_, a, w02)

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
