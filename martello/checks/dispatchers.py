"""Catalogue dispatchers: one call per scene kind, returning a dict of named oracle values, so
that a scene's [check] table can name them (martello.checks.verify). They only combine the
closed forms of martello.oracles."""

from __future__ import annotations

import math

import numpy as np

from ..oracles.linear_sdof import sdof_sine_ground_response
from ..oracles.p2_bouncing import bouncing_oscillator_kelvin, bouncing_oscillator_restitution
from ..oracles.p5_contact_laws import (HC_FACTORS, hc_max_penetration, hertz_impact,
                                       hunt_crossley_realised_e, jankowski_realised_e,
                                       jankowski_xi, kelvin_clipped_restitution, kelvin_damping,
                                       kelvin_xi_from_e, linear_contact_time)
from ..oracles.p4_wave_theory import penalty_rod_impact
from ..oracles.p6_hysteresis import elastoplastic_impulse
from ..oracles.p10_frames import frame_sine_ground_response


def two_body_impact(law, m1, m2, v0, stiffness, restitution=None, exponent=None, clipped=False):
    """P5: a free two-body impact (approach speed v0 > 0) under one penalty law.

    Returns restitution (realised e), contact_time where a closed form exists, and
    max_penetration where one exists. For kelvin the damping is the Anagnostopoulos one
    derived from the target e; the HC family uses its own published factor a(e)."""
    mstar = m1 * m2 / (m1 + m2)
    out = {}
    if law == "linear":
        out.update(restitution=1.0, contact_time=linear_contact_time(mstar, stiffness),
                   max_penetration=v0 * math.sqrt(mstar / stiffness))
    elif law == "hertz":
        h = hertz_impact(mstar, stiffness, v0)
        out.update(restitution=1.0, contact_time=h.t_c, max_penetration=h.delta_max)
    elif law == "kelvin":
        xi = kelvin_xi_from_e(restitution)
        out["restitution"] = kelvin_clipped_restitution(xi) if clipped else restitution
        if not clipped:
            # the unclipped phase is exactly half a damped period
            out["contact_time"] = math.pi / (math.sqrt(stiffness / mstar) * math.sqrt(1 - xi * xi))
    elif law in ("hunt-crossley", "lankarani-nikravesh", "flores", "gonthier", "hertzdamp"):
        key = "lankarani_nikravesh" if law == "hertzdamp" else law.replace("-", "_")
        a = HC_FACTORS[key](restitution)
        n = 1.5 if (law == "hertzdamp" or exponent is None) else exponent
        out.update(restitution=hunt_crossley_realised_e(a),
                   max_penetration=hc_max_penetration(n, stiffness, mstar, a / v0, v0))
    elif law == "jankowski":
        out["restitution"] = jankowski_realised_e(jankowski_xi(restitution))
    else:
        raise ValueError(f"no closed form for law {law!r}")
    return out


def penalty_rods(E, rho, A, LA, v0, eps, LB=None, wall=False):
    """P4's penalty continuum for a scene's rods (docs/p4-bars.md): free rods of one bar
    (c = √(E/ρ), Z = ρcA), A of length LA at v0 toward B of length LB ≥ LA at rest, or
    toward a wall, joined by a linear spring eps (wave_theory.penalty_rod_impact). Adds to
    its values the rods' mean velocities after the contact from its impulse I:
    vA = v0 − I/(ρ A LA), vB = I/(ρ A LB); and the element-free scales T = 2 LA/c."""
    c = math.sqrt(E / rho)
    Z = rho * c * A
    T = 2.0 * LA / c
    T_B = None if (wall or LB is None) else 2.0 * LB / c
    out = dict(penalty_rod_impact(Z, v0, eps, T, duration_B=T_B, wall=wall))
    out["vA"] = v0 - out["impulse"] / (rho * A * LA)
    if not wall:
        out["vB"] = out["impulse"] / (rho * A * (LB if LB is not None else LA))
    out["T"] = T
    return {k: v for k, v in out.items() if v is not None}


def elastoplastic_peak(m, k, uy, rho, v0):
    """P6 as a dict (u_max, t_max) for scene checks."""
    r = elastoplastic_impulse(m, k, uy, rho, v0)
    return {"u_max": r.u_max, "t_max": r.t_max}


def sdof_sine_ground_final(m, k, zeta, ag_amp, omega_g, t_end):
    """Exact relative displacement and velocity of a damped SDOF under A sin(Ωt) ground
    acceleration at t_end, from rest."""
    r = sdof_sine_ground_response(m, k, zeta, ag_amp, omega_g, np.array([t_end]))
    return {"u": float(r.u[0]), "v": float(r.v[0])}


def frame_sine_ground_final(frame, ag_amp, omega_g, t_end):
    """P10: a linear frame's lateral displacements and velocities at t_end under
    ag_amp sin(omega_g t) from rest, by modal superposition (oracles.p10_frames), as named
    values u_<node>, v_<node>."""
    r = frame_sine_ground_response(frame, ag_amp, omega_g, [t_end])
    out = {}
    for nm, (u, v) in r.items():
        out[f"u_{nm}"], out[f"v_{nm}"] = float(u[0]), float(v[0])
    return out


def bouncing_kelvin_events(m, k, h, g, eps, n_impacts, restitution=None, damping=0.0,
                           clipped=False):
    """P2 with a Kelvin (or, damping = 0, linear) penalty plane, as named values for scene
    checks: t_impact_i, t_separation_i, max_penetration_i (i from 0). The dashpot c comes from
    the target e by Anagnostopoulos' formula with m* = m, as the scene's law does."""
    c = damping
    if restitution is not None:
        c = kelvin_damping(eps, m, kelvin_xi_from_e(restitution))
    r = bouncing_oscillator_kelvin(m, k, h, g, eps, c, n_impacts, clipped=clipped)
    out = {}
    for i in range(min(n_impacts, len(r.t_impact))):
        out[f"t_impact_{i}"] = r.t_impact[i]
        if i < len(r.t_separation) and r.t_separation[i] is not None:
            out[f"t_separation_{i}"] = r.t_separation[i]
        out[f"max_penetration_{i}"] = r.max_penetration[i]
    return out


def bouncing_restitution_events(m, k, h, g, e, n_impacts):
    """P2 with Newton restitution, as named values: t_impact_i, v_impact_i, zeno_time,
    resting_force."""
    r = bouncing_oscillator_restitution(m, k, h, g, e, n_impacts)
    out = {f"t_impact_{i}": float(t) for i, t in enumerate(r.t)}
    out.update({f"v_impact_{i}": float(v) for i, v in enumerate(r.v)})
    out.update(zeno_time=r.zeno_time, resting_force=r.resting_force)
    return out
