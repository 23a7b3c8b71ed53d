"""P5 (docs/problems.md P5): two bodies colliding. Newton's impact law and the restitution,
contact time and peak penetration that each penalty contact law (linear, Kelvin, Hertz, the
Hunt-Crossley family, Jankowski) realises. ``jankowski_realised_e`` is *semi-analytic*: a
tight-tolerance quadrature of the scaled energy equation in phase-plane variables, not a
time integration of the equation of motion."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import integrate, optimize, special

from .linear_sdof import damped_state

_EPS = np.finfo(float).eps


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
    positive root is theta* = atan2(2 xi nu, 2 xi^2 - 1), which equals docs/problems.md's
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


@dataclass(frozen=True)
class KelvinPeaks:
    delta_max: float    #: the largest penetration
    t_delta_max: float  #: its time from the onset
    force_max: float    #: the largest force k delta + c delta'
    t_force_max: float  #: its time from the onset


def kelvin_impact_peaks(mstar, k, xi, v0) -> KelvinPeaks:
    """P5, the unclipped Kelvin contact (k, c = 2 xi sqrt(k m*), xi < 1) entered at speed v0:
    delta is the damped free response from (0, v0) (linear_sdof.damped_state), the force
    F = k delta + c delta' = -m* delta''. The penetration peaks where delta' = 0, the force
    where F' = m* (w^2 delta' + 2 xi w delta'') = 0 (F' = -m* delta''' and the equation of
    motion): both are roots of closed-form functions in the first half period pi/w_d
    (brentq). The force peaks inside the phase when its rate at the onset, v0 (k - c^2/m*),
    is positive (xi < 1/2); else it is c v0 at the onset."""
    w = math.sqrt(k / mstar)
    a = xi * w
    wd = w * math.sqrt(1.0 - xi * xi)

    def state(t):
        x, v, acc = damped_state(np.array([t]), 0.0, v0, a, w * w)
        return float(x[0]), float(v[0]), float(acc[0])

    t_d = optimize.brentq(lambda t: state(t)[1], 1e-3 / wd, math.pi / wd, xtol=1e-16,
                          rtol=4 * _EPS)
    c = 2.0 * xi * math.sqrt(k * mstar)
    if k - c * c / mstar <= 0.0:
        return KelvinPeaks(state(t_d)[0], t_d, c * v0, 0.0)
    t_f = optimize.brentq(lambda t: w * w * state(t)[1] + 2.0 * a * state(t)[2], 0.0, t_d,
                          xtol=1e-16, rtol=4 * _EPS)
    return KelvinPeaks(state(t_d)[0], t_d, -mstar * state(t_f)[2], t_f)


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
