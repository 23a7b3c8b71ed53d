"""The linear oscillator, exact: the damped free response in every damping regime (the
building block of the piecewise closed forms of P2, P9 and the SDOF scenes) and the linear
SDOF's free and sine-ground responses (docs/problems.md "Integrators": the orders of the
integrators are measured on them)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


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


def damped_state(t, x0, v0, a, w02):
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
    x, v, acc = damped_state(np.asarray(t, float), u0, v0, a, w02)
    return SDOFResponse(x, v, acc)


def sdof_free_velocity_peak(m, k, zeta, u0):
    """(the largest |v|, its time) of the damped SDOF (zeta < 1) released from u0 at rest: the
    first root of its acceleration in (0, pi/w_d) (brentq on the closed form)."""
    from scipy.optimize import brentq
    w02 = k / m
    a = zeta * math.sqrt(w02)
    wd = math.sqrt(w02 - a * a)

    def acc(t):
        return float(damped_state(np.array([t]), u0, 0.0, a, w02)[2][0])

    t = brentq(acc, 1e-3 / wd, math.pi / wd, xtol=1e-16, rtol=1e-15)
    return abs(float(damped_state(np.array([t]), u0, 0.0, a, w02)[1][0])), t


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
    xh, vh, ah = damped_state(t, u0 - up0, v0 - vp0, a, w02)
    return SDOFResponse(xh + up, vh + vp, ah + ap)
