"""`[[frame]]` tables for the independent engine: a planar frame of Euler–Bernoulli
beam-columns (docs/scene-input.md "[[frame]]", docs/problems.md P10) written again from the
textbook, not from martello.frame2d: the members' global stiffness from their direction
cosines (McGuire, Gallagher & Ziemian, Matrix Structural Analysis, eq. 5.11, written out
term by term), joints numbered joint by joint, the massless vertical and rotational
coordinates eliminated by a Cholesky solve (Guyan's reduction without inertia, exact here),
and the damping from scipy's generalised symmetric eigensolver (Rayleigh at two modes, or
modal). The result is a dense stiffness and damping block on the frame's lateral nodes."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy.linalg import cho_factor, cho_solve, eigh

from .errors import Unsupported

KEYS = {"prefix", "storeys", "bays", "storey_height", "bay_width", "column", "beam", "mass",
        "mass_model", "base", "zeta", "damping", "rayleigh_modes", "histories"}


@dataclass
class FrameBlock:
    """A frame as the engine integrates it: its lateral nodes, their masses, K and C."""
    name: str
    nodes: list
    mass: np.ndarray
    K: np.ndarray
    C: np.ndarray


def _each(value, n, key):
    if isinstance(value, list):
        if len(value) != n:
            raise Unsupported(f"frame.{key}: {len(value)} values for {n} items")
        return [float(v) for v in value]
    return [float(value)] * n


def _sections(value, rows, per_row, key):
    """rows × per_row (E, A, I): one table for all, one per row, or one per member."""
    def one(t):
        return float(t["E"]), float(t["A"]), float(t["I"])
    if isinstance(value, dict):
        return [[one(value)] * per_row for _ in range(rows)]
    if not isinstance(value, list) or len(value) != rows:
        raise Unsupported(f"frame.{key}: not a section, nor {rows} of them")
    out = []
    for item in value:
        out.append([one(item)] * per_row if isinstance(item, dict) else [one(t) for t in item])
        if len(out[-1]) != per_row:
            raise Unsupported(f"frame.{key}: a row of {len(out[-1])} sections for {per_row} members")
    return out


def member_stiffness(E, A, I, L, c, s):
    """The 6 × 6 global stiffness of a member from (x1, y1, θ1) to (x2, y2, θ2) with direction
    cosines c, s (McGuire et al. eq. 5.11)."""
    a, b = E * A / L, 12.0 * E * I / L ** 3
    d, f = 6.0 * E * I / L ** 2, 4.0 * E * I / L
    k11 = np.array([[a * c * c + b * s * s, (a - b) * c * s, -d * s],
                    [(a - b) * c * s, a * s * s + b * c * c, d * c],
                    [-d * s, d * c, f]])
    k12 = np.array([[-(a * c * c + b * s * s), -(a - b) * c * s, -d * s],
                    [-(a - b) * c * s, -(a * s * s + b * c * c), d * c],
                    [d * s, -d * c, f / 2.0]])
    k22 = np.array([[a * c * c + b * s * s, (a - b) * c * s, d * s],
                    [(a - b) * c * s, a * s * s + b * c * c, -d * c],
                    [d * s, -d * c, f]])
    return np.block([[k11, k12], [k12.T, k22]])


def frame_block(tab: dict) -> FrameBlock:
    """The lateral nodes, masses, stiffness and damping of one [[frame]] table."""
    unknown = set(tab) - KEYS
    if unknown:
        raise Unsupported(f"frame keys {sorted(unknown)}")
    prefix, ns, nb = tab["prefix"], int(tab["storeys"]), int(tab["bays"])
    heights = _each(tab["storey_height"], ns, "storey_height")
    widths = _each(tab["bay_width"], nb, "bay_width")
    cols = _sections(tab["column"], ns, nb + 1, "column")
    beams = _sections(tab["beam"], ns, nb, "beam")
    joint_mass = isinstance(tab["mass"], list) and any(isinstance(v, list) for v in tab["mass"])
    floor_mass = ([_each(row, nb + 1, "mass") for row in tab["mass"]] if joint_mass
                  else _each(tab["mass"], ns, "mass"))
    model = tab.get("mass_model", "diaphragm")
    base = tab.get("base", "fixed")
    if model not in ("diaphragm", "joints") or base not in ("fixed", "pinned"):
        raise Unsupported(f"frame {prefix}: mass_model {model!r}, base {base!r}")
    x = np.concatenate([[0.0], np.cumsum(widths)])
    y = np.concatenate([[0.0], np.cumsum(heights)])
    # every joint's three displacements, joint by joint (line fastest), base included
    njoint = (nb + 1) * (ns + 1)

    def dofs(line, level):
        j = level * (nb + 1) + line
        return [3 * j, 3 * j + 1, 3 * j + 2]
    K = np.zeros((3 * njoint, 3 * njoint))
    members = [((i, s), (i, s + 1), cols[s][i]) for s in range(ns) for i in range(nb + 1)] + \
              [((b, s + 1), (b + 1, s + 1), beams[s][b]) for s in range(ns) for b in range(nb)]
    for (i1, j1), (i2, j2), (E, A, I) in members:
        dx, dy = x[i2] - x[i1], y[j2] - y[j1]
        L = math.hypot(dx, dy)
        idx = dofs(i1, j1) + dofs(i2, j2)
        K[np.ix_(idx, idx)] += member_stiffness(E, A, I, L, dx / L, dy / L)
    # the restraints of the base
    fixed = [q for i in range(nb + 1) for q in (dofs(i, 0) if base == "fixed" else dofs(i, 0)[:2])]
    free = [q for q in range(3 * njoint) if q not in set(fixed)]
    # the generalised coordinates: the lateral ones (a floor's, or every joint's), then the rest
    if model == "diaphragm":
        names = [f"{prefix}{s + 1}" for s in range(ns)]
        mass = np.array(floor_mass)
        lateral = [[dofs(i, s + 1)[0] for i in range(nb + 1)] for s in range(ns)]
    else:
        names = [f"{prefix}{s + 1}.{i}" for s in range(ns) for i in range(nb + 1)]
        share = np.array([(widths[i - 1] if i > 0 else 0.0) + (widths[i] if i < nb else 0.0)
                          for i in range(nb + 1)]) / (2.0 * sum(widths))
        # each joint's own mass where the scene gives them (docs/scene-input.md "[[frame]]")
        mass = np.concatenate([np.array(m) if joint_mass else m * share for m in floor_mass])
        lateral = [[dofs(i, s + 1)[0]] for s in range(ns) for i in range(nb + 1)]
    in_lateral = {q for group in lateral for q in group}
    rest = [q for q in free if q not in in_lateral]
    # T maps (lateral, rest) to the free joint displacements: a floor's joints move together
    col = {q: k for k, q in enumerate(free)}
    T = np.zeros((len(free), len(lateral) + len(rest)))
    for k, group in enumerate(lateral):
        for q in group:
            T[col[q], k] = 1.0
    for k, q in enumerate(rest):
        T[col[q], len(lateral) + k] = 1.0
    Kg = T.T @ K[np.ix_(free, free)] @ T
    nr = len(lateral)
    Krr, Krc, Kcc = Kg[:nr, :nr], Kg[:nr, nr:], Kg[nr:, nr:]
    if Kcc.size:
        Ks = Krr - Krc @ cho_solve(cho_factor(Kcc), Krc.T)
    else:
        Ks = Krr
    Ks = 0.5 * (Ks + Ks.T)
    C = _damping(Ks, mass, float(tab.get("zeta", 0.0)), tab.get("damping", "rayleigh"),
                 tab.get("rayleigh_modes", [1, 2]))
    return FrameBlock(prefix, names, mass, Ks, C)


def _damping(K, mass, zeta, kind, modes):
    if zeta == 0.0:
        return np.zeros_like(K)
    w2, phi = eigh(K, np.diag(mass))            # φᵀ M φ = I
    w = np.sqrt(np.maximum(w2, 0.0))
    if kind == "modal":
        mp = mass[:, None] * phi
        C = mp @ np.diag(2.0 * zeta * w) @ mp.T
        return 0.5 * (C + C.T)
    if kind != "rayleigh":
        raise Unsupported(f"frame damping {kind!r}")
    i, j = (min(int(modes[0]), len(w)) - 1, min(int(modes[1]), len(w)) - 1)
    if i == j:
        a0, a1 = zeta * w[i], zeta / w[i]
    else:
        a0, a1 = 2.0 * zeta * w[i] * w[j] / (w[i] + w[j]), 2.0 * zeta / (w[i] + w[j])
    return a0 * np.diag(mass) + a1 * K


__all__ = ["FrameBlock", "frame_block", "member_stiffness"]
