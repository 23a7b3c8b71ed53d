"""P11 closed forms (docs/problems.md P11, docs/buildings.md): buildings in 3D, written from
the mathematics alone.

* Eccentric impact of two rigid floors (Newton's law on a contact whose row is
  g = (1, −r1; −1, r2) over (ux, rz) of each floor): w = 1/m1 + r1²/J1 + 1/m2 + r2²/J2, the
  approach speed v_n = (v1 − r1 ω1) − (v2 − r2 ω2), the impulse P = (1 + e) v_n / w and the
  velocities after it (Goldsmith, Impact, 1960, §2.3; Brach, Mechanical Impact Dynamics, 1991).
* One-storey eccentric system (Kan & Chopra 1977; Chopra, Dynamics of Structures, §15): the
  coupled lateral–torsional frequencies of a rigid floor on members with lateral stiffnesses
  at their plan positions."""

import math


def eccentric_impact(m1, J1, r1, m2, J2, r2, v1, e, w1=0.0, v2=0.0, w2=0.0):
    """Floors 1 and 2 (masses m, rotational inertias J about their mass centres) struck at
    points whose lever arms about the centres, normal to the contact's direction, are r1 and
    r2 (the row ux1 − r1 rz1 − ux2 + r2 rz2); translational speeds v and rotation rates w
    before. Returns w (the inverse effective mass), the approach speed, P and the speeds and
    rotation rates after."""
    w = 1.0 / m1 + r1**2 / J1 + 1.0 / m2 + r2**2 / J2
    vn = (v1 - r1 * w1) - (v2 - r2 * w2)
    P = (1.0 + e) * vn / w if vn > 0 else 0.0
    return {"w": w, "mstar": 1.0 / w, "approach": vn, "impulse": P,
            "v1_after": v1 - P / m1, "w1_after": w1 + r1 * P / J1,
            "v2_after": v2 + P / m2, "w2_after": w2 - r2 * P / J2,
            "abs_v2_after": abs(v2 + P / m2), "abs_w1_after": abs(w1 + r1 * P / J1),
            "abs_w2_after": abs(w2 - r2 * P / J2)}


def one_storey_periods(mass, J, members, kt=0.0, centre=(0.0, 0.0)):
    """The three periods (ascending order of frequency: longest first) of a rigid floor of
    mass m and rotational inertia J about its mass centre on members [x, y, kx, ky] (lateral
    stiffnesses along x and y at plan positions, principal axes along x and y) plus a
    torsional stiffness kt. Written as the 3 × 3 eigenproblem about the mass centre solved in
    closed form: with K_x = Σkx, K_y = Σky, centre of rigidity (x_R, y_R) = (Σky x/K_y,
    Σkx y/K_x), e = R − C, K_θR = Σ(kx (y − y_R)² + ky (x − x_R)²) + kt and r² = J/m, for
    e_y = 0 (x uncoupled): ω_x² = K_x/m and ω² = ½[ω_y²(1 + e_x²/r²) + ω_θ²] ∓
    ½√([ω_y²(1 + e_x²/r²) + ω_θ²]² − 4ω_y²ω_θ²); symmetric in x ↔ y otherwise."""
    Kx = sum(kx for _, _, kx, _ in members)
    Ky = sum(ky for _, _, _, ky in members)
    xR = sum(ky * x for x, _, _, ky in members) / Ky
    yR = sum(kx * y for _, y, kx, _ in members) / Kx
    KthR = sum(kx * (y - yR) ** 2 + ky * (x - xR) ** 2 for x, y, kx, ky in members) + kt
    ex, ey = xR - centre[0], yR - centre[1]
    if ex != 0.0 and ey != 0.0:
        raise ValueError("the closed form takes one eccentricity (e_x or e_y zero)")
    r2 = J / mass
    wth2 = KthR / J
    if ey == 0.0:          # x uncoupled; y and θ coupled through e_x
        wu2, wc2, e = Kx / mass, Ky / mass, ex
    else:
        wu2, wc2, e = Ky / mass, Kx / mass, ey
    a = wc2 * (1.0 + e * e / r2) + wth2
    d = math.sqrt(a * a - 4.0 * wc2 * wth2)
    T = sorted((2.0 * math.pi / math.sqrt(x) for x in (wu2, (a - d) / 2.0, (a + d) / 2.0)), reverse=True)
    return {"T1": T[0], "T2": T[1], "T3": T[2], "x_R": xR, "y_R": yR, "K_thetaR": KthR}
