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
