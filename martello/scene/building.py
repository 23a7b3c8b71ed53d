"""[[building]] tables: buildings in 3D (docs/problems.md P11, docs/buildings.md), expanded into
the nodes that carry the floor masses (ux, uy, rz of each rigid floor; ux, uy of each massive
joint of a flexible floor and of each split point) and one stiffness block between them (the
3D frame statically condensed, martello.building3d), with the mass couplings of a floor whose
reference point is not its mass centre and the ground motion's influence on each node. The
loader keeps what the results need (recovery operators, modes) in scene.extras["buildings"]."""

import math

import numpy as np

from ..building3d import (Beam, Building, Floor, Line, Section, Slab, Split, column_section,
                          beam_section, modal_damping, modal_table, rayleigh_coefficients)
from ..errors import SceneError
from .fields import ANY, MAX_GENERATED, POSITIVE, check_fields, choice, kind_ok, per_item

BUILDING_KEYS = {"prefix": ("str", True, None, None),
                 "storeys": ("int", True, POSITIVE, None),
                 "storey_height": ("any", True, None, None),
                 "model": ("str", False, None, "shear"),
                 "grid_x": ("list", True, None, None),
                 "grid_y": ("list", True, None, None),
                 "column": ("any", False, None, None),
                 "column_angle": ("float", False, ANY, 0.0),
                 "omit": ("list", False, None, []),
                 "beam": ("any", False, None, None),
                 "beam_y": ("any", False, None, None),
                 "mass": ("any", True, None, None),
                 "mass_centre": ("list", False, None, None),
                 "inertia": ("any", False, None, None),
                 "reference": ("list", False, None, None),
                 "diaphragm": ("any", False, None, True),
                 "slab": ("table", False, None, None),
                 "base": ("str", False, None, "fixed"),
                 "zeta": ("float", False, (lambda x: 0 <= x < 1, "a number in [0, 1)"), 0.0),
                 "damping": ("str", False, None, "rayleigh"),
                 "rayleigh_modes": ("list", False, None, [1, 2]),
                 "ground_angle": ("float", False, ANY, 0.0),
                 "histories": ("bool", False, None, False),
                 "member": ("list", False, None, []),
                 "beams": ("list", False, None, []),
                 "split": ("list", False, None, []),
                 "point": ("list", False, None, [])}
SECTION_COMMON = {"E": ("float", True, POSITIVE, None), "G": ("float", False, POSITIVE, None),
                  "As2": ("float", False, POSITIVE, None), "As3": ("float", False, POSITIVE, None)}
SECTION_PROPS = {"A": ("float", True, POSITIVE, None), "I2": ("float", True, POSITIVE, None),
                 "I3": ("float", True, POSITIVE, None), "J": ("float", True, POSITIVE, None)}
CRACKED = {"cracked": ("float", False, (lambda x: 0 < x <= 1, "a number in (0, 1]"), 1.0)}
COLUMN_RECT = {"b2": ("float", True, POSITIVE, None), "b3": ("float", True, POSITIVE, None)}
BEAM_RECT = {"b": ("float", True, POSITIVE, None), "h": ("float", True, POSITIVE, None)}
MEMBER_KEYS = {"name": ("str", True, None, None), "x": ("float", True, ANY, None),
               "y": ("float", True, ANY, None), "angle": ("float", False, ANY, 0.0),
               "section": ("any", True, None, None), "storeys": ("list", False, None, None)}
BEAM_KEYS = {"name": ("str", True, None, None), "floors": ("any", False, None, None),
             "a": ("list", True, None, None), "b": ("list", True, None, None),
             "section": ("table", True, None, None)}
SPLIT_KEYS = {"name": ("str", True, None, None), "line": ("str", True, None, None),
              "storey": ("int", True, POSITIVE, None), "height": ("float", True, POSITIVE, None),
              "mass": ("float", True, POSITIVE, None)}
SLAB_KEYS = {"E": ("float", True, POSITIVE, None), "thickness": ("float", True, POSITIVE, None),
             "nu": ("float", False, (lambda x: 0 <= x < 0.5, "a number in [0, 0.5)"), 0.2)}
POINT_KEYS = {"name": ("str", True, None, None), "floor": ("int", True, POSITIVE, None),
              "x": ("float", True, ANY, None), "y": ("float", True, ANY, None)}
MODELS = ["shear", "frame"]
BASES = ["fixed", "pinned"]
DAMPING = ["rayleigh", "modal"]
# The cap of a building's kept DOFs: its block is dense, n² doubles per evaluation.
MAX_KEPT = 2000


def section(src, where, tab, kind):
    """A Section from a section table: E (G, As2, As3 optional) with A, I2, I3, J, or the
    rectangle b2 x b3 (a column; b2 along local axis 2) or b x h (a beam), `cracked` scaling
    its flexural I."""
    if not isinstance(tab, dict):
        raise SceneError(src, where, "must be a section table",
                         "e.g. { E = 3e10, b2 = 0.3, b3 = 0.5 } or { E = ..., A = ..., I2 = ..., I3 = ..., J = ... }")
    rect = BEAM_RECT if kind == "beam" else COLUMN_RECT
    if any(k in tab for k in rect):
        s = check_fields(src, tab, where, SECTION_COMMON | rect | CRACKED)
        try:
            sec = (beam_section(s["E"], s["b"], s["h"], s["G"], s["cracked"]) if kind == "beam"
                   else column_section(s["E"], s["b2"], s["b3"], s["G"], s["cracked"]))
        except (OverflowError, ZeroDivisionError):     # b h³ of a side of 1e300 m
            sec = None
        if sec is None or not all(math.isfinite(x) and x > 0 for x in (sec.A, sec.I2, sec.I3, sec.J)):
            raise SceneError(src, where, "the rectangle's area, second moments or torsion "
                             "constant leave the doubles", "give the sides in m of a real section")
        return Section(sec.E, sec.G, sec.A, sec.I2, sec.I3, sec.J, s["As2"], s["As3"])
    s = check_fields(src, tab, where, SECTION_COMMON | SECTION_PROPS)
    G = s["G"] if s["G"] is not None else s["E"] / 2.4
    return Section(s["E"], G, s["A"], s["I2"], s["I3"], s["J"], s["As2"], s["As3"])


def per_storey_sections(src, where, value, n, kind):
    """One section table for every storey, or a list of n (a table, or false: none there)."""
    if isinstance(value, dict):
        sec = section(src, where, value, kind)
        return [sec] * n
    if not isinstance(value, list) or len(value) != n:
        raise SceneError(src, where, "must be a section table or a list of one per storey",
                         f"a list of {n} (false where the member is absent)")
    return [None if v is False else section(src, f"{where}[{i}]", v, kind) for i, v in enumerate(value)]


def _point(src, where, v):
    if not (isinstance(v, list) and len(v) == 2 and all(kind_ok("float", x) for x in v)):
        raise SceneError(src, where, f"invalid value {v!r}", "a plan point [x, y] in m")
    return (float(v[0]), float(v[1]))


def _grid(src, where, v):
    if not v or not all(kind_ok("float", x) for x in v):
        raise SceneError(src, where, "must be a list of numbers", "e.g. [0.0, 5.0, 10.0]")
    g = [float(x) for x in v]
    if any(b <= a for a, b in zip(g, g[1:])):
        raise SceneError(src, where, "must increase strictly", "grid lines in m, left to right")
    if not math.isfinite(g[-1] - g[0]):
        raise SceneError(src, where, f"spans {g[-1]!r} - ({g[0]!r}) m, past the doubles",
                         "grid lines in m of a real building")
    return g


def _tributary(g):
    """Half the bays on either side of each grid line (1 for a single line)."""
    if len(g) == 1:
        return np.ones(1)
    w = np.diff(g)
    return (np.concatenate([[0.0], w]) + np.concatenate([w, [0.0]])) / 2


def parse_building(src, w, tab):
    """The Building a [[building]] table describes, and its options."""
    f = check_fields(src, tab, w, BUILDING_KEYS)
    ns = f["storeys"]
    choice(src, f"{w}.model", f["model"], MODELS)
    choice(src, f"{w}.base", f["base"], BASES)
    choice(src, f"{w}.damping", f["damping"], DAMPING)
    gx, gy = _grid(src, f"{w}.grid_x", f["grid_x"]), _grid(src, f"{w}.grid_y", f["grid_y"])
    heights = per_item(src, f"{w}.storey_height", f["storey_height"], ns, POSITIVE)
    if not math.isfinite(sum(heights)):
        raise SceneError(src, f"{w}.storey_height", "the building's height leaves the doubles",
                         "storey heights in m of a real building")
    masses = per_item(src, f"{w}.mass", f["mass"], ns, POSITIVE)
    rigid = f["diaphragm"] if isinstance(f["diaphragm"], list) else [f["diaphragm"]] * ns
    if len(rigid) != ns or not all(isinstance(x, bool) for x in rigid):
        raise SceneError(src, f"{w}.diaphragm", f"invalid value {f['diaphragm']!r}",
                         f"true (rigid floors), false, or a list of {ns} booleans")
    lx, ly = gx[-1] - gx[0], gy[-1] - gy[0]
    centre = ((gx[0] + gx[-1]) / 2, (gy[0] + gy[-1]) / 2)
    if f["mass_centre"] is None:
        centres = [centre] * ns
    elif f["mass_centre"] and isinstance(f["mass_centre"][0], list):
        if len(f["mass_centre"]) != ns:
            raise SceneError(src, f"{w}.mass_centre", f"has {len(f['mass_centre'])} points",
                             f"give one point [x, y] or a list of {ns}")
        centres = [_point(src, f"{w}.mass_centre[{i}]", p) for i, p in enumerate(f["mass_centre"])]
    else:
        centres = [_point(src, f"{w}.mass_centre", f["mass_centre"])] * ns
    if f["inertia"] is None:
        inertia = [m * (lx * lx + ly * ly) / 12 for m in masses]     # a uniform rectangular slab
        if not all(math.isfinite(j) for j in inertia):
            raise SceneError(src, f"{w}.inertia", "the floors' polar inertia m (lx² + ly²)/12 of "
                             "the grid's slab leaves the doubles (masses or plan dimensions too "
                             "large)", "give masses in kg and the grid in m, or inertia")
    else:
        inertia = per_item(src, f"{w}.inertia", f["inertia"], ns, POSITIVE)
    floors = [Floor(m, c, j, r) for m, c, j, r in zip(masses, centres, inertia, rigid)]

    lines = []
    omit = set()
    for i, name in enumerate(f["omit"]):
        if not isinstance(name, str):
            raise SceneError(src, f"{w}.omit[{i}]", f"invalid value {name!r}", "a grid point \"i.j\"")
        omit.add(name)
    if f["column"] is not None:
        cols = per_storey_sections(src, f"{w}.column", f["column"], ns, "column")
        grid_names = {f"{i}.{j}" for i in range(len(gx)) for j in range(len(gy))}
        for k, name in enumerate(f["omit"]):
            if name not in grid_names:
                raise SceneError(src, f"{w}.omit[{k}]", f"names no grid point {name!r}",
                                 f"grid points are i.j with i < {len(gx)}, j < {len(gy)}")
        for i, x in enumerate(gx):
            for j, y in enumerate(gy):
                if f"{i}.{j}" not in omit:
                    lines.append(Line(f"{i}.{j}", x, y, list(cols), f["column_angle"], "column"))
    elif f["omit"]:
        raise SceneError(src, f"{w}.omit", "applies to the grid's columns", "give column, or remove omit")
    names = {ln.name for ln in lines}
    for k, mt in enumerate(f["member"]):
        where = f"{w}.member[{k}]"
        m = check_fields(src, mt, where, MEMBER_KEYS)
        if m["name"] in names:
            raise SceneError(src, f"{where}.name", f"duplicate name {m['name']!r}", "names must be unique")
        names.add(m["name"])
        secs = per_storey_sections(src, f"{where}.section", m["section"], ns, "column")
        if m["storeys"] is not None:
            rng = m["storeys"]
            if not (len(rng) == 2 and all(isinstance(x, int) for x in rng) and 1 <= rng[0] <= rng[1] <= ns):
                raise SceneError(src, f"{where}.storeys", f"invalid value {rng!r}",
                                 f"[first, last] storey, 1 <= first <= last <= {ns}")
            secs = [s if rng[0] <= i + 1 <= rng[1] else None for i, s in enumerate(secs)]
        lines.append(Line(m["name"], m["x"], m["y"], secs, m["angle"], "member"))
    if not lines:
        raise SceneError(src, w, "has no vertical members", "give column (a grid of columns) or [[building.member]]")
    for s in range(ns):
        if not any(ln.sections[s] is not None for ln in lines):
            raise SceneError(src, w, f"storey {s + 1} has no member", "every storey needs members")

    beams = []
    if f["model"] == "frame" and f["beam"] is not None:
        secs = per_storey_sections(src, f"{w}.beam", f["beam"], ns, "beam")
        secs_y = secs
        if f["beam_y"] is False:
            secs_y = [None] * ns
        elif f["beam_y"] is not None:
            secs_y = per_storey_sections(src, f"{w}.beam_y", f["beam_y"], ns, "beam")
        present = {(ln.name, s) for ln in lines if ln.kind == "column"
                   for s in range(1, ns + 1) if ln.sections[s - 1] is not None}

        def has_node(i, j, s):
            return (f"{i}.{j}", s) in present or (f"{i}.{j}", s + 1) in present
        for s in range(1, ns + 1):
            for j in range(len(gy)):
                for i in range(len(gx) - 1):
                    if secs[s - 1] is not None and has_node(i, j, s) and has_node(i + 1, j, s):
                        beams.append(Beam(f"Bx{s}.{i}.{j}", s, (gx[i], gy[j]), (gx[i + 1], gy[j]), secs[s - 1]))
            for i in range(len(gx)):
                for j in range(len(gy) - 1):
                    if secs_y[s - 1] is not None and has_node(i, j, s) and has_node(i, j + 1, s):
                        beams.append(Beam(f"By{s}.{i}.{j}", s, (gx[i], gy[j]), (gx[i], gy[j + 1]), secs_y[s - 1]))
    elif f["beam"] is not None or f["beam_y"] is not None:
        key = "beam" if f["beam"] is not None else "beam_y"
        raise SceneError(src, f"{w}.{key}", "applies to a frame building's grid beams",
                         "set model = \"frame\" and give beam, or remove it")
    for k, bt in enumerate(f["beams"]):
        where = f"{w}.beams[{k}]"
        if f["model"] != "frame":
            raise SceneError(src, where, "a shear-type building has no beams", "set model = \"frame\"")
        b = check_fields(src, bt, where, BEAM_KEYS)
        fl = b["floors"] if b["floors"] is not None else list(range(1, ns + 1))
        fl = fl if isinstance(fl, list) else [fl]
        if not all(isinstance(x, int) and not isinstance(x, bool) and 1 <= x <= ns for x in fl):
            raise SceneError(src, f"{where}.floors", f"invalid value {b['floors']!r}", f"floor numbers in [1, {ns}]")
        sec = section(src, f"{where}.section", b["section"], "beam")
        for s in fl:
            beams.append(Beam(f"{b['name']}.{s}", s, _point(src, f"{where}.a", b["a"]),
                              _point(src, f"{where}.b", b["b"]), sec))
    splits = []
    for k, st in enumerate(f["split"]):
        where = f"{w}.split[{k}]"
        sp = check_fields(src, st, where, SPLIT_KEYS)
        if sp["line"] not in names:
            raise SceneError(src, f"{where}.line", f"names no member line {sp['line']!r}",
                             "a grid column \"i.j\" or a [[building.member]] name")
        if sp["storey"] > ns:
            raise SceneError(src, f"{where}.storey", f"invalid value {sp['storey']}", f"a storey in [1, {ns}]")
        splits.append(Split(sp["name"], sp["line"], sp["storey"], sp["height"], sp["mass"]))
    reference = None if f["reference"] is None else _point(src, f"{w}.reference", f["reference"])
    grid_masses = None
    if not all(rigid):
        grid_masses = {}
        tx, ty = _tributary(gx), _tributary(gy)
        for s in range(1, ns + 1):
            if rigid[s - 1]:
                continue
            wts = {}
            for ln in lines:
                if ln.kind != "column":
                    continue
                i, j = (int(x) for x in ln.name.split("."))
                at_floor = ln.sections[s - 1] is not None or (s < ns and ln.sections[s] is not None)
                if at_floor:
                    wts[ln.name] = tx[i] * ty[j]
            total = sum(wts.values())
            if not total > 0:
                raise SceneError(src, f"{w}.diaphragm[{s - 1}]", "a flexible floor with no grid column",
                                 "its mass is lumped at the grid columns' joints")
            grid_masses[s] = {k: masses[s - 1] * v / total for k, v in wts.items()}
    slabs = []
    if f["slab"] is not None:
        if all(rigid):
            raise SceneError(src, f"{w}.slab", "applies to flexible floors (a rigid floor's slab is "
                             "the diaphragm)", "set diaphragm = false (or a list), or remove slab")
        sl = check_fields(src, f["slab"], f"{w}.slab", SLAB_KEYS)
        joints = {(ln.name, s) for ln in lines if ln.kind == "column" for s in range(1, ns + 1)
                  if ln.sections[s - 1] is not None or (s < ns and ln.sections[s] is not None)}
        for s in range(1, ns + 1):
            if rigid[s - 1]:
                continue
            for i in range(len(gx) - 1):
                for j in range(len(gy) - 1):
                    if all((f"{a}.{b}", s) in joints for a, b in ((i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1))):
                        slabs.append(Slab(s, (gx[i], gx[i + 1]), (gy[j], gy[j + 1]), sl["thickness"], sl["E"], sl["nu"]))
    try:
        b = Building(heights=heights, floors=floors, lines=lines, beams=beams, splits=splits,
                     model=f["model"], base=f["base"], reference=reference, grid_masses=grid_masses,
                     slabs=slabs)
    except ValueError as exc:
        raise SceneError(src, w, str(exc), "check the members, beams and splits") from None
    points = []
    for k, pt in enumerate(f["point"]):
        p = check_fields(src, pt, f"{w}.point[{k}]", POINT_KEYS)
        if p["floor"] > ns or not rigid[p["floor"] - 1]:
            raise SceneError(src, f"{w}.point[{k}].floor", f"invalid value {p['floor']}",
                             f"a rigid floor in [1, {ns}]")
        points.append(p)
    return b, f, points


def expand_buildings(src, data, made=0):
    """Replace [[building]] tables by their kept nodes; return (data, buildings, couplings)
    with buildings what each stands for (Building, node names, K, C, M, influence, recovery
    operators, modes) and couplings the off-diagonal masses [{a, b, value}] by node name."""
    data = dict(data)
    tabs = data.pop("building")
    if not isinstance(tabs, list):
        raise SceneError(src, "building", "must be an array of tables", "write [[building]]")
    nodes, out, couplings = list(data.get("node", [])), [], []
    for bi, tab in enumerate(tabs):
        w = f"building[{bi}]"
        b, f, points = parse_building(src, w, tab)
        n = b.nkept
        made += n
        if n > MAX_KEPT or made > MAX_GENERATED:
            raise SceneError(src, f"{w}.storeys", f"{n} kept DOFs",
                             f"a building has at most {MAX_KEPT} (its condensed block is dense)")
        modes = f["rayleigh_modes"]
        if (len(modes) != 2 or not all(isinstance(x, int) and not isinstance(x, bool) and 1 <= x <= max(n, 1)
                                       for x in modes)):
            raise SceneError(src, f"{w}.rayleigh_modes", f"invalid value {modes!r}",
                             f"two mode numbers in [1, {n}], e.g. [1, 2]")
        try:
            with np.errstate(all="ignore"):
                K, G = b.condensed()
        except np.linalg.LinAlgError:
            raise SceneError(src, w, "the condensation is singular (a mechanism: a node or floor "
                             "that no member holds)", "check the members, beams and base") from None
        except (OverflowError, ZeroDivisionError):
            # lengths whose powers leave the doubles (a storey of 1e300 m or 1e-300 m):
            # refused by _check just below, naming the building
            K = G = np.array([[np.nan]])
        with np.errstate(all="ignore"):
            M = b.mass_matrix()
        _check(src, w, K, G, M)
        table = _modes_or_refuse(src, w, b, K, M)
        C = np.zeros_like(K)
        a0 = a1 = 0.0
        with np.errstate(all="ignore"):
            if f["zeta"] > 0 and f["damping"] == "modal":
                C = modal_damping(K, M, f["zeta"])
            elif f["zeta"] > 0:
                a0, a1 = rayleigh_coefficients(K, M, f["zeta"], tuple(modes))
                C = a0 * M + a1 * K
        if not np.all(np.isfinite(C)):
            raise SceneError(src, f"{w}.zeta", "the damping matrix is not finite (masses and "
                             "stiffness too disparate for double precision)",
                             "give floor masses in kg and sections in SI units of a real building")
        names = b.kept_names(f["prefix"])
        nodes += [{"name": nm, "mass": float(M[i, i])} for i, nm in enumerate(names)]
        for i in range(n):
            for j in range(i + 1, n):
                if M[i, j] != 0.0:
                    couplings.append({"a": names[i], "b": names[j], "value": float(M[i, j])})
        R = b.recovery(G)
        out.append({"prefix": f["prefix"], "building": b, "nodes": names, "K": K, "C": C, "M": M,
                    "influence": b.influence(f["ground_angle"]), "ground_angle": f["ground_angle"],
                    "rayleigh": (a0, a1), "zeta": f["zeta"], "damping": f["damping"],
                    "recovery": R, "storey": b.storey_operator(R), "points": points,
                    "modes": table, "histories": f["histories"]})
    data["node"] = nodes
    return data, out, couplings


def _check(src, where, K, G, M):
    """Finite, positive definite stiffness and mass (a mechanism or overflowing sections are
    refused here, not as a NaN run later)."""
    if not (np.all(np.isfinite(K)) and np.all(np.isfinite(G)) and np.all(np.isfinite(M))):
        raise SceneError(src, where, "the condensed stiffness is not finite (the products of "
                         "the sections and dimensions overflow)", "give SI units of a real building")
    for what, X in (("stiffness", K), ("mass", M)):
        try:
            np.linalg.cholesky(X)
        except np.linalg.LinAlgError:
            raise SceneError(src, where, f"the condensed {what} is not positive definite (a "
                             "mechanism, or sections too disparate for double precision)",
                             "every floor needs members that hold it in x, y and torsion") from None


def _modes_or_refuse(src, where, b, K, M):
    """The building's modal table; refused when a frequency is not a finite positive number:
    K and M passed their Cholesky factorization, so every ω² of K φ = ω² M φ is positive in
    exact arithmetic, and one computed as <= 0, inf or NaN says the masses and stiffness are
    too disparate for double precision (a floor of 1e-12 kg under a storey of 1e9 N/m) — the
    frequencies, the Rayleigh damping and the periods reported would be wrong, not clipped."""
    try:
        with np.errstate(all="ignore"):
            table = modal_table(b, K, M)
    except np.linalg.LinAlgError:
        table = None
    if table is None or not all(0 < m["omega"] < math.inf and all(math.isfinite(m[k]) for k in
                                ("mass_ratio_x", "mass_ratio_y", "torsional_share")) for m in table):
        raise SceneError(src, f"{where}.mass", "the frequencies of the building could not be "
                         "computed (masses and stiffness too disparate for double precision)",
                         "give floor masses in kg and sections in SI units of a real building")
    return table


def building_blocks(buildings, index):
    """The stiffness blocks of the buildings: dicts name, nodes (indices), k, c."""
    return [{"name": b["prefix"], "nodes": [index[n] for n in b["nodes"]], "k": b["K"], "c": b["C"]}
            for b in buildings]


def influence_vector(buildings, index, n):
    """ι of every node of the scene: 1 (the scene's axis), a building's nodes their own."""
    iota = np.ones(n)
    for b in buildings:
        iota[[index[nm] for nm in b["nodes"]]] = b["influence"]
    return iota
