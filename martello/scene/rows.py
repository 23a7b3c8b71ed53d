"""An element's row of the constraint operator (docs/buildings.md, "Contacts between plan
points"): a contact's penetration, or a link's elongation, is d = Σ_k c_k u(node_k) (minus the
gap). A pair of nodes a, b is the row (a, +1), (b, −1); a side may instead be a plan point of
a building — `{ floor = "B2", x = …, y = … }` on a rigid floor (ux, uy, rz of the floor), or
`{ point = "B.S" }`, a split point or a flexible floor's joint (its ux, uy) — and the row is
n·(u(P_a) − u(P_b)) along the element's plan direction n; or the row is written out as
`terms = [{ node = …, coef = … }, …]`. Only here do elements' sides
become rows: the loader validates through side_terms, the run layer and the reference
engines read element_terms."""

import math

from ..errors import SceneError

GROUND = "ground"
POINT_KEYS = ("floor", "x", "y", "point")


def is_point(side):
    return isinstance(side, dict)


def plan_direction(src, where, value, default=(1.0, 0.0)):
    """A plan direction [nx, ny], normalised to unit length."""
    if value is None:
        return default
    if not (isinstance(value, list) and len(value) == 2
            and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)):
        raise SceneError(src, where, f"invalid value {value!r}", "a plan direction [nx, ny]")
    n = math.hypot(*value)
    if not n > 0:
        raise SceneError(src, where, "is the zero vector", "a plan direction, e.g. [1.0, 0.0]")
    return (value[0] / n, value[1] / n)


def side_terms(src, where, side, node_ref, buildings, direction, sign):
    """The terms [(node index, coefficient)] of one side of an element: a node name (its
    displacement, times sign) or a plan point (n·u(P), times sign), ground none."""
    if isinstance(side, str):
        i = node_ref(where, side)
        return [] if i < 0 else [(i, float(sign))]
    if not is_point(side):
        raise SceneError(src, where, f"has the wrong type ({type(side).__name__})",
                         "a node name, or a plan point { floor = \"B2\", x = …, y = … } or { point = \"B.S\" }")
    for key in side:
        if key not in POINT_KEYS:
            raise SceneError(src, f"{where}.{key}", "unknown key", "valid keys here: " + ", ".join(POINT_KEYS))
    nx, ny = direction
    if "point" in side:
        if set(side) != {"point"} or not isinstance(side["point"], str):
            raise SceneError(src, where, "a point is { point = \"<name>\" } alone",
                             "name a split point or a flexible floor's joint, e.g. \"B.S\"")
        p = side["point"]
        terms = [(node_ref(f"{where}.point", f"{p}.ux", False), sign * nx),
                 (node_ref(f"{where}.point", f"{p}.uy", False), sign * ny)]
        return [(i, c) for i, c in terms if c != 0.0]
    missing = [k for k in ("floor", "x", "y") if k not in side]
    if missing:
        raise SceneError(src, f"{where}.{missing[0]}", "missing", "a plan point { floor = \"B2\", x = …, y = … }")
    x, y = side["x"], side["y"]
    for key, v in (("x", x), ("y", y)):
        if not (isinstance(v, (int, float)) and not isinstance(v, bool)):
            raise SceneError(src, f"{where}.{key}", f"has the wrong type ({type(v).__name__})", "expected float")
    floor = side["floor"]
    for b in buildings:
        bd, prefix = b["building"], b["prefix"]
        if not (isinstance(floor, str) and floor.startswith(prefix) and floor[len(prefix):].isdigit()):
            continue
        s = int(floor[len(prefix):])
        if not (1 <= s <= bd.storeys and bd.floors[s - 1].rigid):
            break
        P = bd.point_operator(s, float(x), float(y))          # 2 x kept: (ux, uy) of the point
        row = nx * P[0] + ny * P[1]
        names = b["nodes"]
        return [(node_ref(f"{where}.floor", names[k], False), sign * float(row[k]))
                for k in range(len(names)) if row[k] != 0.0]
    known = ", ".join(f"{b['prefix']}{s}" for b in buildings for s in range(1, b["building"].storeys + 1)
                      if b["building"].floors[s - 1].rigid)
    raise SceneError(src, f"{where}.floor", f"names no rigid floor {floor!r}",
                     f"use one of: {known}" if known else "a plan point needs a [[building]] with rigid floors")


def row_terms(src, where, terms, node_ref):
    """An element's row written out: terms = [{ node = "…", coef = … }, …] (the ground left
    out, a node given twice summed), at least one term on a node."""
    out = {}
    for i, t in enumerate(terms):
        at = f"{where}[{i}]"
        if not isinstance(t, dict) or set(t) != {"node", "coef"}:
            raise SceneError(src, at, f"invalid value {t!r}", "a term { node = \"<name>\", coef = <number> }")
        c = t["coef"]
        if not (isinstance(c, (int, float)) and not isinstance(c, bool)):
            raise SceneError(src, f"{at}.coef", f"has the wrong type ({type(c).__name__})", "expected float")
        i_node = node_ref(f"{at}.node", t["node"])
        if i_node >= 0:
            out[i_node] = out.get(i_node, 0.0) + float(c)
    rows = [(i, c) for i, c in out.items() if c != 0.0]
    if not rows:
        raise SceneError(src, where, "has no term on a node", "a row needs a node with a coefficient /= 0")
    return rows


def element_terms(item):
    """The row of a validated contact or link: its terms, or (a, +1), (b, −1) of a pair
    (ground sides, index −1, left out)."""
    if item.get("terms") is not None:
        return item["terms"]
    return [(i, c) for i, c in ((item["a"], 1.0), (item["b"], -1.0)) if i >= 0]
