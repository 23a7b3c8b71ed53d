"""P4 (docs/problems.md P4, docs/p4-bars.md): two elastic rods, or a rod and a rigid wall,
in impact: elementary one-dimensional wave theory for the force plateau, the contact
duration, the final velocities and the displacement of the contact ends."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class RodImpact:
    c: float              #: bar wave speed sqrt(E/rho)
    impedance: float      #: Z = rho c A
    force: float          #: contact force plateau
    duration: float       #: contact duration
    vA: float             #: final rigid-body (mean) velocity of rod A
    vB: float             #: final rigid-body (mean) velocity of rod B (0 for the wall)
    restitution: float    #: rigid-body restitution (vB - vA)/v0


def rod_impact(E, rho, A, LA, LB, v0, wall=False) -> RodImpact:
    """P4 (docs/problems.md). Rod A moves at v0 and strikes rod B at rest, or a rigid wall.
    Elementary 1-D wave theory.

    Rods: force Z v0/2 for 2 min(LA, LB)/c. LA <= LB: vA = 0, vB = v0 LA/LB, e = LA/LB.
    LA > LB: vA = v0 (1 - LB/LA), vB = v0, e = LB/LA.
    Wall: force Z v0 for 2 LA/c, vA = -v0, e = 1. LB is ignored.
    """
    c = math.sqrt(E / rho)
    Z = rho * c * A
    if wall:
        return RodImpact(c, Z, Z * v0, 2.0 * LA / c, -v0, 0.0, 1.0)
    if LA <= LB:
        vA, vB = 0.0, v0 * LA / LB
    else:
        vA, vB = v0 * (1.0 - LB / LA), v0
    return RodImpact(c, Z, 0.5 * Z * v0, 2.0 * min(LA, LB) / c, vA, vB, (vB - vA) / v0)


def impedance_plateau_force(ZA, ZB, v0):
    """P4: the force plateau for different impedances, Z_A Z_B v0/(Z_A + Z_B), valid until
    the first reflection returns."""
    return ZA * ZB * v0 / (ZA + ZB)


def _pulse_integral(t, T, tau):
    """Integral over [0, t] of D, the velocity of a free-free rod's struck end in units of v0.
    The rod has round-trip time T and is struck by a pulse of duration tau <= T whose
    particle velocity is v0/2. D = 1/2 on [0, tau), then 1 on [kT, kT + tau) for k >= 1,
    else 0. (d'Alembert: a free end doubles the returning wave, and a wave in a free-free
    rod recurs with period T.)"""
    t = np.asarray(t, dtype=float)
    out = 0.5 * np.minimum(t, tau)
    n = np.floor(t / T)
    later = n >= 1
    out = out + np.where(later, (n - 1) * tau + np.minimum(t - n * T, tau), 0.0)
    return out


def rod_impact_interface_displacement(t, E, rho, LA, LB, v0, wall=False):
    """P4: exact displacements of the two contact ends for t >= 0, piecewise linear in t.
    Contact starts at t = 0, and displacements are positive in A's direction of travel.

    Equal rods: both ends move at v0/2 during contact (0 <= t <= 2L/c). Afterwards A is at
    rest (its end stays at v0 L/c) and B moves rigidly at v0.
    Wall: the end is held at 0 for 0 <= t <= 2L/c, then the rod leaves rigidly at -v0.
    Unequal rods (a d'Alembert solution for each free-free rod, with tau = 2 min(LA, LB)/c):
    the end velocities are v0 D(t; 2LB/c) for B and v0 - v0 D(t; 2LA/c) for A
    (:func:`_pulse_integral`). The longer rod's end then moves in bursts of duration tau
    once per round trip. The shorter rod is left free of stress and moves rigidly.
    Returns (uA_end, uB_end) as arrays (uB_end is zeros for the wall case).
    """
    t = np.asarray(t, dtype=float)
    if np.any(t < 0):
        raise ValueError("t must be >= 0 (contact starts at t = 0)")
    c = math.sqrt(E / rho)
    TA = 2.0 * LA / c
    if wall:
        uA = np.where(t <= TA, 0.0, -v0 * (t - TA))
        return uA, np.zeros_like(t)
    TB = 2.0 * LB / c
    tau = min(TA, TB)
    uB = v0 * _pulse_integral(t, TB, tau)
    uA = v0 * t - v0 * _pulse_integral(t, TA, tau)
    return uA, uB
