"""P10 closed forms (docs/problems.md P10): a linear planar frame under a harmonic ground
acceleration, by modal superposition.

The frame's lateral stiffness, masses and damping are the independent engine's
(martello.independent.frame: its own direct stiffness and condensation, written apart from
the front end's martello.frame2d). With M ü + C u̇ + K u = −M ι A sin Ωt (ι = 1: every lateral
DOF moves with the ground) and a classical damping (Rayleigh C = a0 M + a1 K, or modal), the
mass-normalised modes φ_n of K φ = ω² M φ decouple it: u = Σ φ_n q_n with
q̈_n + 2ζ_n ω_n q̇_n + ω_n² q_n = −Γ_n A sin Ωt, Γ_n = φ_nᵀ M ι, ζ_n = a0/(2ω_n) + a1 ω_n/2
(Rayleigh; Chopra, Dynamics of Structures, §12.4 and §11.4), each mode an SDOF of
linear_sdof.sdof_sine_ground_response."""

from __future__ import annotations

import numpy as np
from scipy.linalg import eigh

from ..independent.frame import frame_block
from .linear_sdof import sdof_sine_ground_response


def frame_modes(frame: dict):
    """(names, ω (rad/s, ascending), Φ mass-normalised, ζ per mode, masses) of a [[frame]] table."""
    fb = frame_block(frame)
    w2, phi = eigh(fb.K, np.diag(fb.mass))
    w = np.sqrt(np.maximum(w2, 0.0))
    # the damping ratio of each mode: φᵀ C φ = 2 ζ ω for a classical damping
    zeta = np.array([float(phi[:, n] @ fb.C @ phi[:, n]) / (2.0 * w[n]) for n in range(len(w))])
    return fb.nodes, w, phi, zeta, fb.mass


def frame_sine_ground_response(frame: dict, ag_amp: float, omega_g: float, t):
    """{node: (u, v)} of the frame's lateral nodes at times t, from rest, relative to the
    ground, under the ground acceleration ag_amp sin(omega_g t)."""
    names, w, phi, zeta, mass = frame_modes(frame)
    t = np.atleast_1d(np.asarray(t, float))
    u = np.zeros((len(names), len(t)))
    v = np.zeros_like(u)
    for n in range(len(w)):
        gamma = float(phi[:, n] @ mass)
        r = sdof_sine_ground_response(1.0, w[n] ** 2, zeta[n], ag_amp, omega_g, t)
        u += np.outer(phi[:, n], gamma * r.u)
        v += np.outer(phi[:, n], gamma * r.v)
    return {nm: (u[i], v[i]) for i, nm in enumerate(names)}


def frame_periods(frame: dict):
    """The natural periods 2π/ω_n of the frame (s, longest first)."""
    _, w, _, _, _ = frame_modes(frame)
    return 2.0 * np.pi / w
