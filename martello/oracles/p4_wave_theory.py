"""Elementary one-dimensional wave theory for the impact of elastic rods (docs/problems.md
P4), coded from d'Alembert's solution alone: nothing here calls or imitates a solver. It adds
to martello.oracles.p4_rod_impact (rod_impact, rod_impact_interface_displacement) the
displacement of any point of either rod, the rectangular force pulse, and the post-impact
energy split.

Setting. Rod A (length L_A) meets rod B (length L_B), or a rigid wall, with relative
approach speed v0 at t = 0; both rods are free at their far ends and have the same wave
speed c and impedance Z. The contact face carries the compressive force P0 = Z v0/2 (Z v0
on a wall) during 0 <= t < tau, tau = 2 min(L_A, L_B)/c (2 L_A/c on a wall), and is free
afterwards: the first wave to come back to the face is the one that ends the contact (it
returns from the shorter rod's far end at tau), so every later return meets a free face.

Particle velocity in a rod at depth s from the contact face (method of images, a free end
reflecting the particle velocity with its sign): the pulse of speed v_p = P0/Z and duration
tau passes the point at times t_k = (2kL + s)/c (going away from the face) and
t'_k = (2(k+1)L - s)/c (coming back), k = 0, 1, ...; the rod's velocity change there is the
sum of these windows. Displacement: the integral, a sum of ramps clip(t - t_k, 0, tau).
"""

import math

import numpy as np

__all__ = ["pulse_ramps", "rod_point_displacement", "contact_force_pulse",
           "vibration_energy_fraction", "penalty_rod_impact", "X_STAR"]


def pulse_ramps(s, t, c, L, tau):
    """Sum over the images of clip(t − t_k, 0, tau) at depth s in [0, L] of a rod of length
    L: the time integral of the windows during which the pulse of duration tau passes the
    point (arrays broadcast). Zero for t <= s/c."""
    s = np.asarray(s, dtype=float)
    t = np.asarray(t, dtype=float)
    s, t = np.broadcast_arrays(s, t)
    out = np.zeros(s.shape)
    if np.any(s < -1e-12 * L) or np.any(s > L * (1 + 1e-12)):
        raise ValueError("depth s must lie in [0, L]")
    T = 2.0 * L / c
    kmax = int(math.floor(float(np.max(t, initial=0.0)) / T)) + 1 if t.size else 0
    for k in range(kmax + 1):
        out += np.clip(t - (k * T + s / c), 0.0, tau)
        out += np.clip(t - ((k + 1) * T - s / c), 0.0, tau)
    return out


def rod_point_displacement(s, t, c, L_self, L_other, v0, side, wall=False):
    """Displacement of the point at depth s from the contact face of one rod, relative to
    the motion the rod would have without the impact (so: subtract nothing for t <= 0).

    side = "a": the rod moving toward the face (its velocity change is −v_p), "b": the rod
    being struck (+v_p), both along the direction of approach. v0 is the approach speed.
    L_other is the length of the other rod (ignored with wall = True). Time t is measured
    from the first touch; t < 0 gives 0.

    Valid for rods of equal impedance and wave speed with free far ends."""
    if side not in ("a", "b"):
        raise ValueError("side must be 'a' or 'b'")
    if wall:
        tau, vp = 2.0 * L_self / c, v0
    else:
        tau, vp = 2.0 * min(L_self, L_other) / c, 0.5 * v0
    ramps = pulse_ramps(s, np.maximum(np.asarray(t, dtype=float), 0.0), c, L_self, tau)
    return (-vp if side == "a" else vp) * ramps


def contact_force_pulse(t, force, duration):
    """The exact contact force: `force` on [0, duration), 0 elsewhere (t from first touch)."""
    t = np.asarray(t, dtype=float)
    return np.where((t >= 0.0) & (t < duration), force, 0.0)


def vibration_energy_fraction(m_a, m_b, v_a0, v_b0, v_a, v_b):
    """Share of the initial kinetic energy left as vibration after the impact, from the
    rigid-body (mean) velocities before (v_a0, v_b0) and after (v_a, v_b); m_b = inf or
    None for a wall (then v_b0 = v_b = 0). Energy is conserved in the elastic rods, so the
    vibration is what the rigid-body motion no longer holds."""
    if m_b is None or not math.isfinite(m_b):
        e0, e1 = 0.5 * m_a * v_a0 ** 2, 0.5 * m_a * v_a ** 2
    else:
        e0 = 0.5 * m_a * v_a0 ** 2 + 0.5 * m_b * v_b0 ** 2
        e1 = 0.5 * m_a * v_a ** 2 + 0.5 * m_b * v_b ** 2
    return (e0 - e1) / e0 if e0 > 0 else 0.0


def _x_star():
    """Root x* > 0 of (1 + x) e^{−x} = 1/2 (Newton from x = 1.7)."""
    x = 1.7
    for _ in range(50):
        f = (1.0 + x) * math.exp(-x) - 0.5
        x_new = x - f / (-x * math.exp(-x))
        if abs(x_new - x) < 1e-16 * x_new:
            return x_new
        x = x_new
    return x


X_STAR = _x_star()   #: 1.678346990016661…


def penalty_rod_impact(Z, v0, eps, duration, duration_B=None, wall=False):
    """Continuum rods (or a rod and a wall) joined by a linear penalty spring ε.

    A free–free rod's face moves as v_face = v_free ∓ [P(t) + 2 Σ_k P(t − k T)]/Z (its
    end-velocity response to an end force, T = 2L/c its round trip), so the penetration δ
    obeys δ' + δ/τ_c = v0 − (echo terms), τ_c = Z/(2ε) between rods, Z/ε on a wall, with
    T = `duration` = 2 L_A/c (the shorter rod A) and `duration_B` = 2 L_B/c (None: equal rods):

    * 0 <= t <= T: δ = v0 τ_c (1 − e^{−t/τ_c}); the force rises to P0 = Z v0/2 (Z v0 on a
      wall), so the largest penetration is P0/ε (1 + O(e^{−T/τ_c})): 1/ε exactly;
    * equal rods or a wall (both echoes, or the single one, return at T): with
      x = (t − T)/τ_c, δ = v0 τ_c (2(1 + x) e^{−x} − 1), zero at x* = 1.6783…: the contact
      lasts T + x* τ_c and the impulse falls short of P0 T by (x* + 2e^{−x*} − 2) P0 τ_c
      = 0.0517… P0 τ_c;
    * L_A < L_B (only A's echo at T; B's returns at T_B): δ = v0 τ_c (1 + x) e^{−x} stays
      positive, the force decays as P0 (1 + x) e^{−x} until T_B and the impulse exceeds
      P0 T by P0 τ_c (the spring gives back the compression it stored): A rebounds at
      −v0 τ_c/T instead of stopping.

    Valid when e^{−T/τ_c} and e^{−(T_B − T)/τ_c} are negligible (τ_c ≪ T). Returns a dict:
    tau_c, force, max_penetration, impulse, impulse_relative_error (against P0 T) and, for
    equal rods and the wall, duration and duration_relative_error (None for L_A < L_B: the
    contact then lasts until about 2 L_B/c)."""
    tau = Z / ((1.0 if wall else 2.0) * eps)
    P0 = (1.0 if wall else 0.5) * Z * v0
    unequal = (not wall) and duration_B is not None and duration_B > duration
    if unequal:
        extra = P0 * tau            # −P0 τ_c while rising, +2 P0 τ_c in the tail
        dur, dur_err = None, None
    else:
        extra = -(X_STAR + 2.0 * math.exp(-X_STAR) - 2.0) * P0 * tau
        dur, dur_err = duration + X_STAR * tau, X_STAR * tau / duration
    gap_B = (duration_B - duration) if unequal else duration
    return {"tau_c": tau, "force": P0, "duration": dur, "duration_relative_error": dur_err,
            "max_penetration": P0 / eps, "impulse": P0 * duration + extra,
            "impulse_relative_error": extra / (P0 * duration),
            "validity": max(math.exp(-duration / tau), math.exp(-gap_B / tau))}
