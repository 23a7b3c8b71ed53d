"""Properties of the time integrators (docs/problems.md "Integrators"): the parameters of the
Newmark, HHT and generalized-alpha families, their stability limits, the period elongation
of the trapezoidal rule and the numerical restitution of a multiplier enforced in a Newmark
step."""

from __future__ import annotations

import math


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
