"""The published vendor verification problems of contact and impact (docs/vendor-problems.md):
ANSYS VM65 (Thomson 1979, Ex. 4.6-1), Abaqus Benchmarks 1.3.15 and code_aster SDND101. For
each, the exact solution derived here from the physics (SI units) and, where the vendor's
manual prints a number, that number converted to SI with the digits it prints, so that a
scene's [check] can compare a run with both: the printed digits (a published value, trusted
to half a unit of its last printed digit) and the exact value.

Unit conversions are exact by definition: 1 in = 0.0254 m, 1 lbf = 4.4482216152605 N."""

import math
from dataclasses import dataclass

INCH = 0.0254
LBF = 4.4482216152605


@dataclass(frozen=True)
class BallOnSpringSurface:
    t_impact: float
    v_impact: float
    ke_impact: float
    max_compression: float
    t_max: float
    u_max: float


def ball_on_spring_surface(m, k, h, g) -> BallOnSpringSurface:
    """A ball of mass m released at rest a height h above a massless spring surface of
    stiffness k, under gravity g (ANSYS VM65; Thomson 1979, Ex. 4.6-1). Free fall to the
    surface: t = √(2h/g), v = √(2gh), KE = m g h. On the surface m δ̈ = m g − k δ from
    (δ, δ̇) = (0, v): δ = W/k + A sin(ωt − φ), ω = √(k/m), A = √((W/k)² + (v/ω)²),
    sin φ = (W/k)/A; the largest compression W/k + A at t_impact + (π/2 + φ)/ω.
    u counts the ball's descent from the release point."""
    t = math.sqrt(2.0 * h / g)
    v = math.sqrt(2.0 * g * h)
    w = math.sqrt(k / m)
    s = m * g / k
    amp = math.hypot(s, v / w)
    phi = math.asin(s / amp)
    return BallOnSpringSurface(t, v, m * g * h, s + amp, t + (0.5 * math.pi + phi) / w, h + s + amp)


def vm65_printed():
    """The numbers ANSYS VM65 prints (Thomson's units: in, lbf, s), in SI, each with the
    half-unit of its last printed digit: impact at 0.071982 s, velocity −27.785 in/s (down;
    martello's approach speed is its magnitude), kinetic energy 193.00 lbf·in."""
    return {"t_impact": (0.071982, 0.5e-6),
            "v_impact": (27.785 * INCH, 0.0005 * INCH),
            "ke_impact": (193.00 * LBF * INCH, 0.005 * LBF * INCH)}


def vm65_reference(m, k, h, g):
    """VM65 for [check]: the exact fields of ball_on_spring_surface, and the printed ones
    (`printed_*`, SI) with `printed_v_from_ke` = √(2 KE_printed/m), the impact speed the
    printed kinetic energy stands for (the summary reports speeds, not energies)."""
    ex = ball_on_spring_surface(m, k, h, g)
    p = vm65_printed()
    out = dict(vars(ex))
    out.update({f"printed_{key}": val for key, (val, _) in p.items()})
    out["printed_v_from_ke"] = math.sqrt(2.0 * p["ke_impact"][0] / m)
    return out


@dataclass(frozen=True)
class TrussOnWall:
    t_impact: float
    c: float
    duration: float
    force: float
    momentum_change: float
    v_after: float


def truss_on_rigid_wall(E, rho, A, L, v0, clearance) -> TrussOnWall:
    """A free elastic truss (1-D rod) at v0 meets a rigid wall after a clearance (Abaqus
    Benchmarks 1.3.15). Linear 1-D wave theory: c = √(E/ρ); the contact force is the
    impedance times v0, F = A√(Eρ) v0, for T = 2L/c; the rod leaves at −v0; the momentum
    change is F T = 2ρALv0."""
    c = math.sqrt(E / rho)
    F = A * math.sqrt(E * rho) * v0
    T = 2.0 * L / c
    return TrussOnWall(clearance / v0, c, T, F, F * T, -v0)


def abaqus_1_3_15_printed():
    """Abaqus Benchmarks 1.3.15 prints: impact at 6.67e-4 s, c = 5064 m/s, T = 7.9e-4 s,
    F = 11.8e6 N, momentum change "9.36 kg m/s" (for 9.36e3: 2ρLAv0 = 9360 kg m/s), each
    with half a unit of its last digit. It states T = 2L/(c + v0) and F = ρv0(c + v0)A:
    with c + v0 those give 7.8965e-4 s and 1.1853e7 N (which rounds to 11.9e6, not the
    printed 11.8e6); linear wave theory gives 2L/c = 7.8993e-4 s and ρcv0A = 1.1849e7 N."""
    return {"t_impact": (6.67e-4, 0.005e-4), "c": (5064.0, 0.5), "duration": (7.9e-4, 0.05e-4),
            "force": (11.8e6, 0.05e6), "momentum_change": (9.36e3, 0.005e3)}


def abaqus_1_3_15_reference(E, rho, A, L, v0, clearance):
    """Abaqus 1.3.15 for [check]: the exact fields and `printed_*` (the momentum change as
    printed, corrected to kg m/s, and `printed_v_after` = v0 − Δp_printed/(ρAL), the rebound
    velocity the printed momentum change stands for)."""
    ex = truss_on_rigid_wall(E, rho, A, L, v0, clearance)
    p = abaqus_1_3_15_printed()
    out = dict(vars(ex))
    out.update({f"printed_{key}": val for key, (val, _) in p.items()})
    out["printed_v_after"] = v0 - p["momentum_change"][0] / (rho * A * L)
    return out


@dataclass(frozen=True)
class OscillatorOnStop:
    contact_time: float
    max_penetration: float
    max_force: float
    v_out: float
    period: float
    t_second_impact: float


def oscillator_on_stop(m, k, K, v0) -> OscillatorOnStop:
    """A mass m on a spring k, at rest position against a stop of stiffness K (zero gap),
    launched into the stop at v0 (code_aster SDND101). In contact m ü + (k + K) u = 0:
    u = (v0/Ω) sin Ωt, Ω = √((k + K)/m), for π/Ω; peak penetration v0/Ω, peak stop force
    K v0/Ω; it leaves at −v0, swings freely for π/ω (ω = √(k/m)) and strikes again at v0:
    the motion is periodic with period π/Ω + π/ω.
    code_aster's printed reference values (V5.01.101 §2) were not available to this module:
    only the exact solution is here (docs/vendor-problems.md)."""
    W = math.sqrt((k + K) / m)
    w = math.sqrt(k / m)
    return OscillatorOnStop(math.pi / W, v0 / W, K * v0 / W, -v0, math.pi / W + math.pi / w,
                            math.pi / W + math.pi / w)
