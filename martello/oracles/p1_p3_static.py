"""P1 and P3 (docs/problems.md P1, P3): the static contact problems, a mass on a rigid plane
and two bars in contact, for the Lagrange and penalty schemes."""

from __future__ import annotations

from dataclasses import dataclass


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
    """P1 (docs/problems.md; seed section 3.1, eqs 11-22). A spring k holds a mass m under gravity,
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
    """P3 (docs/problems.md; seed section 3.2, eqs 23-34). r = EA/l.

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
