"""`[[building]]` tables for the independent engine: shear-type storeys on rigid floors
(docs/scene-input.md "[[building]]", docs/buildings.md "The model") written again from the
textbook storey model, not from martello.building3d.

A member of a shear-type storey has its ends held against rotation about the horizontal axes
and against vertical motion, so it is a plan spring 12 E I/(h³ (1 + φ)) along each principal
axis (φ = 12 E I/(G A_s h²) where a shear area is given; Przemieniecki, Theory of Matrix
Structural Analysis, §5.6) and a torsional spring G J/h at its plan position. A rigid floor s
moves a plan point P by (u_x − (y − y_c) r_z, u_y + (x − x_c) r_z) about its mass centre C
(Chopra, Dynamics of Structures, §9.5; Wilson, Three-Dimensional Static and Dynamic Analysis
of Structures, ch. 12), so a member between floors s − 1 and s along the plan direction e
stretches by d = r_s(e)·q_s − r_{s−1}(e)·q_{s−1} with r(e) = (e_x, e_y, −e_x (y − y_c) +
e_y (x − x_c)); the storey matrix is Σ k d dᵀ term by term. The floors' coordinates are their
mass centres' (ux, uy) and rz, so the mass matrix is diagonal (m, m, J_C): the only form the
engine takes. Rayleigh or modal damping as for [[frame]]; a ground motion along the plan
angle α loads a floor by −m (cos α, sin α, 0) ü_g.

Refused (Unsupported): the frame model, flexible floors, a reference point off the mass
centres, pinned bases, splits, beams and slabs."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .errors import Unsupported
from .frame import _damping

KEYS = {"prefix", "storeys", "storey_height", "model", "grid_x", "grid_y", "column", "column_angle",
        "omit", "mass", "mass_centre", "inertia", "diaphragm", "base", "zeta", "damping",
        "rayleigh_modes", "ground_angle", "histories", "member", "point"}
NU_CONCRETE = 0.2        # G = E/(2(1 + ν)) where a section gives no G (docs/scene-input.md)


@dataclass
class BuildingBlock:
    """A building as the engine integrates it: its floors' nodes (ux, uy, rz of each floor),
    their masses (m, m, J), K, C, the ground motion's influence on each, and the mass centres
    its plan points refer to."""
    name: str
    nodes: list
    mass: np.ndarray
    K: np.ndarray
    C: np.ndarray
    influence: np.ndarray
    centres: list


def _each(value, n, key):
    if isinstance(value, list):
        if len(value) != n:
            raise Unsupported(f"building.{key}: {len(value)} values for {n}")
        return [float(v) for v in value]
    return [float(value)] * n


def roark_J(a, b):
    """St Venant's torsion constant of an a × b rectangle (Roark's Formulas for Stress and
    Strain, table 10.7 case 4)."""
    a, b = max(a, b), min(a, b)
    return a * b ** 3 * (1.0 / 3.0 - 0.21 * (b / a) * (1.0 - (b / a) ** 4 / 12.0))


def _section(t):
    """(E, G, I3, I2, J, As2, As3) of a section table: I3 resists displacement along the
    member's axis 2, I2 along axis 3."""
    if not isinstance(t, dict):
        raise Unsupported("building section: not a table")
    E = float(t["E"])
    G = float(t["G"]) if "G" in t else E / (2.0 * (1.0 + NU_CONCRETE))
    if "b2" in t:
        b2, b3, cr = float(t["b2"]), float(t["b3"]), float(t.get("cracked", 1.0))
        I3, I2, J = cr * b3 * b2 ** 3 / 12.0, cr * b2 * b3 ** 3 / 12.0, roark_J(b2, b3)
    else:
        I2, I3, J = float(t["I2"]), float(t["I3"]), float(t["J"])
    return E, G, I3, I2, J, t.get("As2"), t.get("As3")


def _per_storey(value, n):
    if isinstance(value, dict):
        return [_section(value)] * n
    if not isinstance(value, list) or len(value) != n:
        raise Unsupported(f"building section: not a table nor {n} of them")
    return [None if v is False else _section(v) for v in value]


def _members(tab, ns):
    """[(x, y, angle°, sections per storey)] of the grid columns and the listed members."""
    out = []
    gx, gy = [float(v) for v in tab["grid_x"]], [float(v) for v in tab["grid_y"]]
    if tab.get("column") is not None:
        secs = _per_storey(tab["column"], ns)
        omit = set(tab.get("omit", []))
        angle = float(tab.get("column_angle", 0.0))
        out += [(x, y, angle, secs) for i, x in enumerate(gx) for j, y in enumerate(gy)
                if f"{i}.{j}" not in omit]
    for mt in tab.get("member", []):
        secs = _per_storey(mt["section"], ns)
        if "storeys" in mt:
            first, last = mt["storeys"]
            secs = [s if first <= k + 1 <= last else None for k, s in enumerate(secs)]
        out.append((float(mt["x"]), float(mt["y"]), float(mt.get("angle", 0.0)), secs))
    return out


def building_block(tab: dict) -> BuildingBlock:
    prefix, ns = tab["prefix"], int(tab["storeys"])
    if tab.get("model", "shear") != "shear" or tab.get("base", "fixed") != "fixed":
        raise Unsupported(f"building {prefix}: model {tab.get('model')!r}, base {tab.get('base', 'fixed')!r} "
                          "(the engine has shear-type storeys on fixed feet)")
    unknown = set(tab) - KEYS
    if unknown:
        raise Unsupported(f"building keys {sorted(unknown)} (the engine models shear-type storeys "
                          "on rigid floors about their mass centres)")
    rigid = tab.get("diaphragm", True)
    if rigid is not True and not (isinstance(rigid, list) and all(r is True for r in rigid)):
        raise Unsupported(f"building {prefix}: flexible floors")
    heights = _each(tab["storey_height"], ns, "storey_height")
    masses = _each(tab["mass"], ns, "mass")
    gx, gy = [float(v) for v in tab["grid_x"]], [float(v) for v in tab["grid_y"]]
    mc = tab.get("mass_centre")
    if mc is None:
        centres = [((gx[0] + gx[-1]) / 2, (gy[0] + gy[-1]) / 2)] * ns
    elif isinstance(mc[0], list):
        centres = [(float(p[0]), float(p[1])) for p in mc]
    else:
        centres = [(float(mc[0]), float(mc[1]))] * ns
    lx, ly = gx[-1] - gx[0], gy[-1] - gy[0]
    inertia = (_each(tab["inertia"], ns, "inertia") if tab.get("inertia") is not None
               else [m * (lx ** 2 + ly ** 2) / 12.0 for m in masses])

    def r(s, x, y, e):
        """The row of floor s (1-based) for the motion of plan point (x, y) along e."""
        xc, yc = centres[s - 1]
        return np.array([e[0], e[1], -e[0] * (y - yc) + e[1] * (x - xc)])
    K = np.zeros((3 * ns, 3 * ns))
    for x, y, angle, secs in _members(tab, ns):
        a = math.radians(angle)
        e2, e3 = (math.cos(a), math.sin(a)), (-math.sin(a), math.cos(a))
        for s in range(1, ns + 1):
            if secs[s - 1] is None:
                continue
            E, G, I3, I2, J, As2, As3 = secs[s - 1]
            h = heights[s - 1]
            for e, I, As in ((e2, I3, As2), (e3, I2, As3)):
                phi = 12.0 * E * I / (G * float(As) * h * h) if As else 0.0
                k = 12.0 * E * I / (h ** 3 * (1.0 + phi))
                d = np.zeros(3 * ns)
                d[3 * (s - 1):3 * s] = r(s, x, y, e)
                if s > 1:
                    d[3 * (s - 2):3 * (s - 1)] = -r(s - 1, x, y, e)
                K += k * np.outer(d, d)
            d = np.zeros(3 * ns)
            d[3 * (s - 1) + 2] = 1.0
            if s > 1:
                d[3 * (s - 2) + 2] = -1.0
            K += G * J / h * np.outer(d, d)
    mass = np.array([v for m, J in zip(masses, inertia) for v in (m, m, J)])
    C = _damping(K, mass, float(tab.get("zeta", 0.0)), tab.get("damping", "rayleigh"),
                 tab.get("rayleigh_modes", [1, 2]))
    alpha = math.radians(float(tab.get("ground_angle", 0.0)))
    influence = np.array([math.cos(alpha), math.sin(alpha), 0.0] * ns)
    nodes = [f"{prefix}{s}.{q}" for s in range(1, ns + 1) for q in ("ux", "uy", "rz")]
    return BuildingBlock(prefix, nodes, mass, K, C, influence, centres)


def point_terms(side: dict, buildings: list, idx: dict, n: tuple, sign: float) -> list:
    """The terms [(node index, coefficient)] of a plan point { floor = "B2", x, y } moving
    along the plan direction n, times sign."""
    if "point" in side:
        raise Unsupported("a split point or a flexible floor's joint (the engine has rigid floors only)")
    floor = side["floor"]
    for b in buildings:
        tail = floor[len(b.name):] if floor.startswith(b.name) else ""
        if tail.isdigit() and 1 <= int(tail) <= len(b.centres):
            s = int(tail)
            xc, yc = b.centres[s - 1]
            x, y = float(side["x"]), float(side["y"])
            coef = (n[0], n[1], -n[0] * (y - yc) + n[1] * (x - xc))
            return [(idx[f"{b.name}{s}.{q}"], sign * c) for q, c in zip(("ux", "uy", "rz"), coef) if c != 0.0]
    raise Unsupported(f"plan point on floor {floor!r}: no such floor")


__all__ = ["BuildingBlock", "building_block", "point_terms", "roark_J"]
