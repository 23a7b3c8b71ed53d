"""[[bar]] tables: axial rods meshed into bar elements (docs/problems.md P4, docs/p4-bars.md).

A `[[bar]]` table stands for one straight elastic rod along the scene's axis. The loader
(martello.scene.loader) calls :func:`expand_bars` before it validates nodes and links; the rod
stands for ordinary `[[node]]`, `[[link]]` (type "bar") and, for a consistent mass matrix,
`[[mass_coupling]]` entries, so every integrator sees plain scene items. They are kept as the
rod's mesh (segments of the scene's item tables, martello.scene.items), not one dict each.

Keys (SI units):

========================  ==========================================================================
``name``                  required; prefix of the generated names. Nodes ``<name>.left``,
                          ``<name>.1`` … ``<name>.<n-2>``, ``<name>.right`` (left to right, n nodes);
                          elements ``<name>.e1`` … The two end nodes are the ones contacts name.
``L``                     required, > 0: length of the rod [m]
``elements``              required, int >= 1 (>= 2 for ``ends = "half-cell"``): N
``EA`` or ``E`` and ``A`` axial stiffness [N] (exactly one way)
``rhoA`` or ``rho``+``A`` mass per length [kg/m] (exactly one way; ``A`` may serve both)
``mass``                  ``"lumped"`` (default; row sums, ρA·L_e/2 at the ends of every element)
                          or ``"consistent"`` (ρA·L_e/6·[[2, 1], [1, 2]] per element: diagonal
                          terms on the nodes, off-diagonal ones as mass_coupling)
``ends``                  ``"node"`` (default): N elements, N+1 nodes, the rod's ends are nodes.
                          ``"half-cell"``: N cells of length L_e, one node of mass ρA·L_e at the
                          centre of each, N−1 elements between the centres; each end face lies
                          L_e/2 beyond its end node, so the end half cell belongs to whatever
                          touches that end (a contact of stiffness 2EA/L_e per half cell, see
                          docs/p4-bars.md: with this contact element and lumped mass, central
                          difference at Courant number 1 is exact). Lumped mass only.
``x0``                    position of the left end [m], default 0: reporting only (node positions
                          in ``info``); displacements stay relative to the reference positions
``v0``                    uniform initial velocity [m/s], default 0
``fixed``                 ``"none"`` (default), ``"left"``, ``"right"`` or ``"both"``: ends held
                          at u = 0. ``ends = "node"``: the end node is fixed. ``"half-cell"``: the
                          end node is tied to ground by the half cell (a bar of length L_e/2).
``output``                ``"all"`` (default), ``"ends"`` or ``"none"``: the rod's nodes appended to
                          ``analysis.output.nodes`` (the rod-impact measures need ``"all"``).
========================  ==========================================================================

``info`` (stored by the loader as ``scene.extras["bars"]``) is a list with one dict per rod:
its parameters (``EA``, ``rhoA``, ``c``, ``impedance``, ``element_length``,
``element_stiffness``, ``half_cell_stiffness``, ``mass_total`` …), the node names left to
right, their reference positions ``x`` and the rod's lumped diagonal ``node_mass`` and
``couplings`` (pairs of node names with values), enough to form the rod's momentum from a
velocity history without the native model.
"""

import math

import numpy as np

from ..errors import SceneError
from .fields import MAX_GENERATED, TINY, check_fields
from .items import Listed, Numbered

BAR_KEYS = {
    "name": ("str", True, None, None),
    "L": ("float", True, (lambda x: x > 0, "a number > 0"), None),
    "elements": ("int", True, (lambda x: x >= 1, "an integer >= 1"), None),
    "EA": ("float", False, (lambda x: x > 0, "a number > 0"), None),
    "E": ("float", False, (lambda x: x > 0, "a number > 0"), None),
    "A": ("float", False, (lambda x: x > 0, "a number > 0"), None),
    "rhoA": ("float", False, (lambda x: x > 0, "a number > 0"), None),
    "rho": ("float", False, (lambda x: x > 0, "a number > 0"), None),
    "mass": ("str", False, None, "lumped"),
    "ends": ("str", False, None, "node"),
    "x0": ("float", False, (lambda x: True, "a number"), 0.0),
    "v0": ("float", False, (lambda x: True, "a number"), 0.0),
    "fixed": ("str", False, None, "none"),
    "output": ("str", False, None, "all"),
}
MASS_KINDS = ("lumped", "consistent")
END_KINDS = ("node", "half-cell")
FIXED_KINDS = ("none", "left", "right", "both")
OUTPUT_KINDS = ("all", "ends", "none")


def _choice(src, path, value, choices):
    if value not in choices:
        raise SceneError(src, path, f"unknown value {value!r}", "valid: " + ", ".join(choices))
    return value


def _section(src, where, b):
    """EA and ρA from the keys given; exactly one way for each."""
    if b["EA"] is not None and b["E"] is not None:
        raise SceneError(src, f"{where}.E", "given together with EA", "give EA, or E and A")
    if b["rhoA"] is not None and b["rho"] is not None:
        raise SceneError(src, f"{where}.rho", "given together with rhoA", "give rhoA, or rho and A")
    if b["EA"] is None:
        if b["E"] is None:
            raise SceneError(src, f"{where}.EA", "missing", "give EA [N], or E [Pa] and A [m²]")
        if b["A"] is None:
            raise SceneError(src, f"{where}.A", "missing", "E needs the cross-section A [m²] (or give EA)")
        EA = b["E"] * b["A"]
    else:
        EA = b["EA"]
    if b["rhoA"] is None:
        if b["rho"] is None:
            raise SceneError(src, f"{where}.rhoA", "missing",
                             "give rhoA [kg/m], or rho [kg/m³] and A [m²]")
        if b["A"] is None:
            raise SceneError(src, f"{where}.A", "missing", "rho needs the cross-section A [m²] (or give rhoA)")
        rhoA = b["rho"] * b["A"]
    else:
        rhoA = b["rhoA"]
    if b["A"] is not None and b["EA"] is not None and b["rhoA"] is not None:
        raise SceneError(src, f"{where}.A", "is not used with both EA and rhoA", "remove it")
    return EA, rhoA


def _derived_ok(src, where, b, EA, rhoA, Le):
    """The rod's derived numbers must be normal doubles: E·A and ρ·A can underflow to zero
    or a subnormal (ρ = 1e-310), overflow to inf (E = 1e300, A = 1e10), and then c = √(EA/ρA),
    Z = √(EA ρA) and the element masses ρA·L_e are no numbers to integrate with."""
    tiny = TINY
    for key, value in (("EA", EA), ("rhoA", rhoA), ("element mass rhoA·L/elements", rhoA * Le),
                       ("element stiffness EA·elements/L", EA / Le)):
        if not (math.isfinite(value) and value >= tiny):
            field = key if key in ("EA", "rhoA") and b[key] is not None else (
                "elements" if key.startswith("element") else ("E" if key == "EA" else "rho"))
            raise SceneError(src, f"{where}.{field}", f"gives {key} = {value!r}",
                             "the rod's derived values must be finite numbers >= 2.2e-308: "
                             "check the units")
    c2, z2 = EA / rhoA, EA * rhoA
    if not (math.isfinite(c2) and c2 >= tiny and math.isfinite(z2) and z2 >= tiny):
        raise SceneError(src, f"{where}.{'rhoA' if b['rhoA'] is not None else 'rho'}",
                         f"gives a wave speed sqrt(EA/rhoA) = {math.sqrt(c2)!r} and impedance "
                         f"sqrt(EA rhoA) = {math.sqrt(z2)!r}", "both must be finite and > 0: check the units")


def mesh_rod(name, L, N, rhoA, mass="lumped", ends="node", x0=0.0):
    """Nodes, elements and mass of one rod, as plain data (no scene validation).

    Returns a dict: ``names`` (left to right), ``x`` (reference positions), ``node_mass``
    (diagonal of the mass matrix), ``couplings`` [(i, j, value)] (consistent off-diagonals),
    ``elements`` [(i, j)] with length ``element_length``."""
    Le = L / N
    me = rhoA * Le
    if ends == "node":
        n = N + 1
        x = [x0 + i * Le for i in range(n)]
        if mass == "lumped":
            node_mass = [me if 0 < i < n - 1 else 0.5 * me for i in range(n)]
            couplings = []
        else:   # consistent: ρA L_e/6 [[2, 1], [1, 2]] per element
            node_mass = [2.0 * me / 3.0 if 0 < i < n - 1 else me / 3.0 for i in range(n)]
            couplings = [(i, i + 1, me / 6.0) for i in range(N)]
        elements = [(i, i + 1) for i in range(N)]
    else:       # half-cell: one node at the centre of each cell
        n = N
        x = [x0 + (i + 0.5) * Le for i in range(n)]
        node_mass = [me] * n
        couplings = []
        elements = [(i, i + 1) for i in range(N - 1)]
    names = [f"{name}.{i}" for i in range(n)]
    names[0], names[-1] = f"{name}.left", f"{name}.right"
    return {"names": names, "x": x, "node_mass": node_mass, "couplings": couplings,
            "elements": elements, "element_length": Le}


def expand_bars(src, data, generated=()):
    """Validate the scene's [[bar]] tables and mesh each rod.

    Returns (data, info, segments): the scene dict without its [[bar]] tables (the input is
    not modified; analysis.output.nodes gets the rods' recorded nodes), one dict per rod
    describing it (module docstring), and the rods' items as segments of the scene's item
    tables (martello.scene.items): {"node": [...], "link": [...], "mass_coupling": [...]} —
    each rod's nodes, elements and couplings generated from its mesh (``RodNodes``,
    ``RodElements``, ``RodCouplings``), its supports as listed dicts. `generated` holds the
    names of the nodes the chains made before (martello.scene.items.Names): they count and
    are taken too."""
    data = dict(data)
    bars = data.pop("bar")
    if not isinstance(bars, list) or not bars:
        raise SceneError(src, "bar", "must be a non-empty array of tables", "write [[bar]]")
    nodes = list(data.get("node", []))
    taken = {n.get("name") for n in nodes if isinstance(n, dict)}
    explicit_nodes = [n.get("name") for n in nodes if isinstance(n, dict)] + list(generated)
    out_nodes, info, bar_names, made = [], [], set(), len(nodes) + len(generated)
    segments = {"node": [], "link": [], "mass_coupling": []}
    for bi, tab in enumerate(bars):
        where = f"bar[{bi}]"
        b = check_fields(src, tab, where, BAR_KEYS)
        name = b["name"]
        if not name or name == "ground" or "." in name:
            raise SceneError(src, f"{where}.name", f"invalid name {name!r}",
                             "a non-empty name without '.', not 'ground'")
        if name in bar_names:
            raise SceneError(src, f"{where}.name", f"duplicate name {name!r}", "rod names must be unique")
        bar_names.add(name)
        mass = _choice(src, f"{where}.mass", b["mass"], MASS_KINDS)
        ends = _choice(src, f"{where}.ends", b["ends"], END_KINDS)
        fixed = _choice(src, f"{where}.fixed", b["fixed"], FIXED_KINDS)
        output = _choice(src, f"{where}.output", b["output"], OUTPUT_KINDS)
        N = b["elements"]
        if made + N + 1 > MAX_GENERATED:
            raise SceneError(src, f"{where}.elements", f"invalid value {N!r}",
                             f"the generators of a scene make at most {MAX_GENERATED} nodes in all")
        if ends == "half-cell":
            if mass != "lumped":
                raise SceneError(src, f"{where}.mass", "a half-cell rod has lumped mass only",
                                 "use mass = \"lumped\", or ends = \"node\" for a consistent mass")
            if N < 2:
                raise SceneError(src, f"{where}.elements", f"invalid value {N!r}",
                                 "a half-cell rod needs >= 2 cells (its two end nodes are distinct)")
        EA, rhoA = _section(src, where, b)
        L = b["L"]
        _derived_ok(src, where, b, EA, rhoA, L / N)
        mesh = mesh_rod(name, L, N, rhoA, mass, ends, b["x0"])
        names, Le = mesh["names"], mesh["element_length"]
        for nm in names:
            if nm in taken or nm in generated:
                raise SceneError(src, f"{where}.name", f"generates the node {nm!r}, which already exists",
                                 "choose another rod name")
            taken.add(nm)
        made += len(names)
        fix_left, fix_right = fixed in ("left", "both"), fixed in ("right", "both")
        rod = Rod(name, mesh, EA, b["v0"], ends == "node" and fix_left, ends == "node" and fix_right)
        segments["node"].append(RodNodes(rod))
        segments["link"].append(RodElements(rod))
        if ends == "half-cell":
            # a held end: the half cell between the end node and the support is a bar of L_e/2
            supports = []
            if fix_left:
                supports.append({"name": f"{name}.support.left", "type": "bar", "a": "ground",
                                 "b": names[0], "EA": EA, "L": 0.5 * Le})
            if fix_right:
                supports.append({"name": f"{name}.support.right", "type": "bar", "a": names[-1],
                                 "b": "ground", "EA": EA, "L": 0.5 * Le})
            segments["link"].append(supports)
        segments["mass_coupling"].append(RodCouplings(rod))
        if output == "all":
            out_nodes += names
        elif output == "ends":
            out_nodes += [names[0], names[-1]]
        c = math.sqrt(EA / rhoA)
        info.append({
            "name": name, "L": L, "elements": N, "EA": EA, "rhoA": rhoA,
            "E": b["E"], "A": b["A"], "rho": b["rho"],
            "c": c, "impedance": math.sqrt(EA * rhoA), "mass_total": rhoA * L,
            "mass": mass, "ends": ends, "x0": b["x0"], "v0": b["v0"], "fixed": fixed,
            "output": output, "element_length": Le, "element_stiffness": EA / Le,
            "half_cell_stiffness": 2.0 * EA / Le, "transit_time": Le / c,
            "nodes": names, "left": names[0], "right": names[-1], "x": mesh["x"],
            "node_mass": mesh["node_mass"],
            "couplings": [(names[i], names[j], v) for i, j, v in mesh["couplings"]],
        })
    data["analysis"] = _with_output_nodes(data.get("analysis"), explicit_nodes, out_nodes)
    return data, info, segments


class Rod:
    """One rod's mesh as the loader places it: its first node's position in the scene
    (node0, set by the loader), the mesh of mesh_rod, EA, v0 and which end nodes are held."""

    def __init__(self, name, mesh, EA, v0, held_left, held_right):
        self.name, self.mesh, self.EA, self.v0 = name, mesh, EA, v0
        self.held = (held_left, held_right)
        self.node0 = 0

    def is_held(self, i):
        return (i == 0 and self.held[0]) or (i == len(self.mesh["names"]) - 1 and self.held[1])


class RodNodes:
    """A rod's nodes as a segment of the scene's node table (martello.scene.items)."""

    def __init__(self, rod):
        self.rod = rod

    def __len__(self):
        return len(self.rod.mesh["names"])

    def place(self, pos):
        self.rod.node0 = pos

    def names(self):
        names = self.rod.mesh["names"]
        middle = Numbered(f"{self.rod.name}.", "", 1, len(names) - 2)
        return [Listed(names[:1]), middle, Listed(names[-1:])] if len(names) > 1 else [Listed(names)]

    def item(self, i):
        r = self.rod
        held = r.is_held(i)
        return {"name": r.mesh["names"][i], "mass": float(r.mesh["node_mass"][i]), "u0": 0.0,
                "v0": 0.0 if held or r.v0 == 0.0 else float(r.v0), "fixed": held}

    def arrays(self):
        """(mass, u0, v0, fixed) of its nodes, for the run layer."""
        n = len(self)
        fixed = np.zeros(n, np.int32)
        fixed[0], fixed[-1] = self.rod.held
        v0 = 0.0 if self.rod.v0 == 0.0 else float(self.rod.v0)     # a −0.0 given is 0.0
        return (np.array(self.rod.mesh["node_mass"], np.float64), np.zeros(n),
                np.where(fixed != 0, 0.0, v0), fixed)


class RodElements:
    """A rod's bar elements as a segment of the scene's link table."""

    def __init__(self, rod):
        self.rod = rod

    def __len__(self):
        return len(self.rod.mesh["elements"])

    def place(self, pos):
        pass

    def names(self):
        return [Numbered(f"{self.rod.name}.e", "", 1, len(self))]

    def item(self, k):
        r = self.rod
        i, j = r.mesh["elements"][k]
        return {"name": f"{r.name}.e{k + 1}", "type": "bar", "a": r.node0 + i, "b": r.node0 + j,
                "EA": r.EA, "L": r.mesh["element_length"]}

    def chunks(self, size):
        """(kind, a, b, par) arrays of its bars for the library's bulk door, size at a time:
        element k joins nodes k and k + 1."""
        from ..binding import native        # the run layer's (this module loads without it)
        r = self.rod
        for k0 in range(0, len(self), size):
            m = min(size, len(self) - k0)
            a = (r.node0 + np.arange(k0, k0 + m)).astype(np.int32)
            par = np.zeros((m, native.constant("NPAR_LINK")))
            par[:, native.constant("L_STIFF")] = r.EA / r.mesh["element_length"]
            yield np.full(m, native.value("links", "bar"), np.int32), a, a + 1, par

    def codes(self, key, at):
        """Its bars' codes in a category column."""
        return np.full(len(self), at["bar"] if key == "type" else -1, np.int8)


class RodCouplings:
    """A rod's consistent-mass couplings as a segment of the scene's coupling table."""

    def __init__(self, rod):
        self.rod = rod

    def __len__(self):
        return len(self.rod.mesh["couplings"])

    def item(self, k):
        i, j, value = self.rod.mesh["couplings"][k]
        return {"a": self.rod.node0 + i, "b": self.rod.node0 + j, "value": value}


def _with_output_nodes(analysis, explicit_nodes, rod_nodes):
    """analysis.output.nodes + the rods' recorded nodes. Without an explicit list, the list
    starts from the scene's own [[node]] entries (all of them), so a rod's `output` decides
    alone whether its nodes are recorded."""
    if not isinstance(analysis, dict) or analysis.get("type") != "dynamic":
        return analysis
    analysis = dict(analysis)
    out = analysis.get("output")
    out = dict(out) if isinstance(out, dict) else ({} if out is None else out)
    if not isinstance(out, dict):
        return analysis            # the loader reports the malformed table
    listed = out.get("nodes")
    if listed is None:
        listed = [n for n in explicit_nodes if isinstance(n, str)]
    elif not isinstance(listed, list) or not all(isinstance(n, str) for n in listed):
        return analysis            # the loader reports the malformed list
    seen = set(listed)
    out["nodes"] = list(listed) + [n for n in rod_nodes if n not in seen]
    analysis["output"] = out
    return analysis


def rod_impact_scene(N=10, L_A=1.0, L_B=1.0, wall=False, E=2.0e11, rho=7850.0, A=1.0e-4, v0=1.0,
                     mass="lumped", ends="node", integrator="central-difference", courant=0.5,
                     eps_factor=1.0, gap_phase=0.5, t_end_factor=1.5, every=1, output="all",
                     scheme="penalty", restitution=None, **analysis):
    """A P4 scene as a dict (for tests and studies): rod A (N elements of L_e = L_A/N) at v0
    toward rod B (same bar, same L_e, round(N L_B/L_A) elements) at rest, or a rigid wall.

    The contact joins A.right to B.left (or ground). A penalty contact is linear with
    stiffness eps_factor × the matched stiffness: EA/L_e between rods (two half cells of
    2EA/L_e in series), 2EA/L_e on a wall (one half cell); with ends = "half-cell",
    eps_factor = 1 and lumped mass, central difference at courant = 1 is exact
    (docs/p4-bars.md). dt = courant·L_e/c; the gap is gap_phase·v0·dt, so the faces meet at
    gap_phase·dt; t_end = that + t_end_factor·2 min(L_A, L_B)/c, rounded up to whole steps.
    scheme = "lagrange" or "restitution" (with `restitution`) gives a rigid contact instead. Extra keyword arguments go
    to [analysis] (e.g. rho_inf, alpha, preset, check_stability)."""
    c = math.sqrt(E / rho)
    Le = L_A / N
    dt = courant * Le / c
    gap = gap_phase * v0 * dt
    bar = {"L": L_A, "elements": N, "E": E, "A": A, "rho": rho, "mass": mass, "ends": ends,
           "output": output}
    bars = [dict(bar, name="A", v0=v0)]
    if not wall:
        NB = max(1, round(N * L_B / L_A))
        bars.append(dict(bar, name="B", L=L_B, elements=NB))
    contact = {"name": "impact", "a": "A.right", "b": "ground" if wall else "B.left", "gap": gap,
               "scheme": scheme}
    if scheme == "penalty":
        contact.update(law="linear", stiffness=eps_factor * (2.0 if wall else 1.0) * E * A / Le)
    if restitution is not None:      # scheme restitution (required) or lagrange (optional)
        contact["restitution"] = restitution
    tau = 2.0 * (L_A if wall else min(L_A, L_B)) / c
    # a whole number of steps: the structural integrators take full steps and label the
    # last state t_end (fortran/fixed_step.f90), so t_end must be on the grid
    steps = math.ceil((gap / v0 + t_end_factor * tau) / dt - 1e-9)
    an = {"type": "dynamic", "integrator": integrator, "dt": dt, "t_end": steps * dt,
          "output": {"every": every}}
    an.update(analysis)
    return {"title": f"P4 {'rod on a wall' if wall else 'two rods'} ({integrator}, {mass}, {ends})",
            "problem": "P4", "bar": bars, "contact": [contact], "analysis": an}
