"""P6 (docs/problems.md P6): the elasto-plastic SDOF. Peak response to an initial velocity
with a bilinear (kinematic hardening) spring, the ductility under a step load, and the
energy dissipated per cycle."""

from __future__ import annotations

import math
from dataclasses import dataclass


@dataclass(frozen=True)
class ElastoplasticImpulse:
    t1: float       #: time of first yield
    v1: float       #: speed at first yield
    u_max: float    #: peak displacement
    t_max: float    #: time of the peak
    ductility: float  #: u_max / u_y


def elastoplastic_impulse(m, k, uy, rho, v0) -> ElastoplasticImpulse:
    """P6 (docs/problems.md). An undamped bilinear SDOF (kinematic hardening rho) starts from rest
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
