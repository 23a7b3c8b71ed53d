"""P9 (docs/problems.md P9): a harmonically forced oscillator against a rigid barrier
(Davis 1992). The period-1 impacting orbit, undamped and damped, with its admissibility
checked on the closed form."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import optimize

from .linear_sdof import damped_state


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
    x10, v10, _ = damped_state(T, 1.0, 0.0, a, 1.0)
    x01, v01, _ = damped_state(T, 0.0, 1.0, a, 1.0)
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
        xh, _, _ = damped_state(tau, -xp0, -r * V - vp0, a, 1.0)
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


@dataclass(frozen=True)
class DavisEvents:
    t: np.ndarray         #: impact times (s), in order, up to the first accumulation or t_end
    v: np.ndarray         #: approach speeds x'- > 0 at those impacts
    accumulation: float  #: the first accumulation time t_inf (inf if none before t_end)
    release: float       #: when the mass held from t_inf leaves the barrier (inf if not before t_end)


def davis_impact_sequence(F, eta, r, zeta=0.0, phi=0.0, x0=0.0, v0=0.0, t_end=100.0,
                          tau_end=1e-13) -> DavisEvents:
    """P9's transient, piecewise closed form: x'' + 2 zeta x' + x = F cos(eta t + phi), barrier
    at x = 0, x <= 0, x'+ = -r x'-, from (x0, v0) at t = 0 (x0 < 0, or x0 = 0 with v0 <= 0).

    Each flight is the exact damped forced solution (T: the shorter of the forcing and the natural period) (homogeneous part by damped_state,
    particular part F Re[H e^{i(eta t + phi)}], H = 1/(1 - eta^2 + 2 i zeta eta)); its end is
    the first root of x on the flight, bracketed on a grid of T/400 and refined by brentq.
    A flight shorter than T/400 (chatter, the load pressing the mass on the barrier) is
    solved on x(t0 + s)/s = v + a s/2 + ... + x^(6) s^5/720 by Newton: the derivatives at the
    barrier follow exactly from the equation of motion, the truncation is s^6 x^(7)/5040 (s <
    T/400: below 1e-15 relative), and the form has no root at s = 0 to lose in rounding.
    When a flight is shorter than tau_end the sequence accumulates: the rest is summed as
    the geometric tail tau r/(1 - r) of flights under a constant pressing acceleration (its
    error ~tau^2, below 1e-20 s), and the mass is held until the load pulls it off the barrier
    (F cos(eta t + phi) turns negative: its root, closed form). Independent of martello's
    solvers: numpy/scipy on the closed form alone."""
    H = 1.0 / complex(1.0 - eta * eta, 2.0 * zeta * eta)
    T = 2.0 * math.pi / max(eta, 1.0)     # the shorter of the forcing and natural periods

    def xp(t):
        th = eta * t + phi
        return (F * (H.real * math.cos(th) - H.imag * math.sin(th)),
                -F * eta * (H.real * math.sin(th) + H.imag * math.cos(th)))

    def flight(t0, x0_, v0_):
        p0, q0 = xp(t0)
        def x_at(s):
            xh, vh, _ = damped_state(s, x0_ - p0, v0_ - q0, zeta, 1.0)
            p, q = xp(t0 + s)
            return float(xh) + p, float(vh) + q
        return x_at

    def derivatives(t0, v):
        # x = 0, x' = v at t0: x^(n+2) = -2 zeta x^(n+1) - x^(n) + F eta^n cos(theta + n pi/2)
        th = eta * t0 + phi
        d = [0.0, v]
        for n in range(0, 6):
            d.append(-2.0 * zeta * d[-1] - d[-2] + F * eta ** n * math.cos(th + n * math.pi / 2))
        return d                           # x, x', ..., x^(7)

    def short_root(t0, v):
        """The end of a flight leaving the barrier at t0 with speed v < 0, if shorter than
        T/400 (else None)."""
        d = derivatives(t0, v)
        if d[2] <= 0.0:
            return None
        f = lambda s: sum(d[n] * s ** (n - 1) / math.factorial(n) for n in range(1, 7))  # noqa: E731
        df = lambda s: sum(d[n] * (n - 1) * s ** (n - 2) / math.factorial(n) for n in range(2, 7))  # noqa: E731
        s = -2.0 * v / d[2]
        if s > T / 400:
            return None
        for _ in range(50):
            ds = f(s) / df(s)
            s -= ds
            if abs(ds) <= 1e-16 * s:
                break
        return s if 0.0 < s <= T / 400 else None

    def release_after(t):
        # the next time F cos(eta t + phi) turns negative: eta t + phi = pi/2 (mod 2 pi)
        k = math.ceil((eta * t + phi - math.pi / 2) / (2 * math.pi))
        return (math.pi / 2 + 2 * math.pi * k - phi) / eta

    ts, vs = [], []
    t, x, v = 0.0, float(x0), float(v0)
    held = x == 0.0 and v == 0.0 and F * math.cos(phi) > 0.0
    if held:
        t = release_after(0.0)
    while t < t_end:
        s = short_root(t, v) if x == 0.0 and v < 0.0 else None
        if s is None:
            x_at = flight(t, x, v)
            ds = T / 400
            s0, f0 = 0.0, x
            s_root = None
            while t + s0 < t_end:
                s1 = s0 + ds
                f1 = x_at(s1)[0]
                if f1 >= 0.0 and not (s0 == 0.0 and f0 == 0.0 and f1 == 0.0):
                    s_root = optimize.brentq(lambda s: x_at(s)[0], s0 if s0 > 0 else 1e-300, s1,
                                             xtol=1e-15, rtol=4 * np.finfo(float).eps)
                    break
                s0, f0 = s1, f1
            if s_root is None:
                return DavisEvents(np.array(ts), np.array(vs), math.inf, math.inf)
            s = s_root
            v_in = x_at(s)[1]
        else:
            d = derivatives(t, v)
            v_in = sum(d[n] * s ** (n - 1) / math.factorial(n - 1) for n in range(1, 8))
        t += s
        if t >= t_end:
            break
        ts.append(t); vs.append(v_in)
        x, v = 0.0, -r * v_in
        if s < tau_end and v_in > 0:
            # accumulation: the rest of the flights, r s + r^2 s + ...
            t_inf = t + s * r / (1.0 - r)
            return DavisEvents(np.array(ts), np.array(vs), t_inf, release_after(t_inf))
    return DavisEvents(np.array(ts), np.array(vs), math.inf, math.inf)
