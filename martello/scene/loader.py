"""Scene files: read, validate, and describe a 1D mechanical network.

A scene is TOML with tables `[[node]]`, `[[link]]`, `[[contact]]`, `[loads]`, `[analysis]`
and an optional `[check]` (the closed form it is verified against). The format is documented
in docs/scene-input.md. Every error names the file, the field and what would be valid."""

import hashlib
import json
import tomllib

import numpy as np
from dataclasses import dataclass, field
from pathlib import Path

from ..errors import SceneError
from .bars import expand_bars
from .chain import ChainContacts, ChainLinks, ChainNodes, expand_chains
from .items import ItemTable, NameIndex, Names
from .rows import is_point, plan_direction, row_terms, side_terms
from .compatibility import COMPATIBLE
from ..paths import MiB, UnreadableFile, check_regular, read_input
from .fields import (ANY, MAX_DEPTH, NONNEG, POSITIVE, check_fields, choice, finite_everywhere,
                     kind_ok)
from .spec import (ALL_SPECIFIC, ANALYSIS_TYPES, CONTACT_COMMON, CONTACT_SCHEMES,
                   ARRAY_ITEMS, FIXED_EXPONENT, FUNCTION_TYPES, GROUND, INTEGRATOR_KEYS,
                   INTEGRATORS, LARGE_SCENE_TRACKS, LAWS, LINK_COMMON, LINK_TYPES, METHODS,
                   NEWMARK_PRESETS, NODE_KEYS, OUTPUT_KEYS, SCHEMES, TOP_KEYS, TRACKABLE)


@dataclass
class Scene:
    source: str
    title: str
    problem: str
    description: str
    # item tables (martello.scene.items.ItemTable: sequences of dicts, a generator's stored
    # as arrays; .names their names, .segments what the run layer reads)
    nodes: list          # dicts: name, mass, u0, v0, fixed
    links: list          # dicts: name, type, a, b (indices, -1 ground) + parameters
    contacts: list       # dicts: name, a, b, gap, scheme + parameters
    gravity: float
    forces: list         # dicts: node (index), function (dict)
    ground: dict | None  # function dict, or None
    analysis: dict
    check: dict | None
    digest: str          # sha256 of the file (or of the canonical JSON of a dict scene)
    index: dict = field(default_factory=dict)   # node name -> index (a NameIndex)
    couplings: list = field(default_factory=list)  # dicts: a, b (indices), value
    extras: dict = field(default_factory=dict)     # what generators ([[bar]]) know of the scene
    blocks: list = field(default_factory=list)     # dicts: name, nodes (indices), k, c ([[frame]], [[building]])
    # the ground motion's (and gravity's) influence on each node, M·ι loaded (None: ι = 1
    # everywhere, the scene's axis; a [[building]]'s uy and rz nodes differ)
    influence: np.ndarray | None = None

    def node_index(self, name):
        return -1 if name == GROUND else self.index[name]

    @classmethod
    def from_dict(cls, data, base_dir=".", source="<scene>"):
        """A validated scene from a dict shaped like the scene file's tables
        (docs/scene-input.md), e.g. the parsed TOML; record files named in it are relative
        to base_dir. The dict is not modified."""
        if not isinstance(data, dict):
            raise SceneError(source, "(scene)", f"is a {type(data).__name__}",
                             "give a dict of the scene file's tables: node, link, contact, "
                             "loads, analysis (docs/scene-input.md)")
        return from_dict(data, source=source, base_dir=Path(base_dir))

    @classmethod
    def load(cls, path):
        """A validated scene from its TOML file (the same as martello.load)."""
        return load(path)


# --- helpers ---------------------------------------------------------------------------------

def _function(src, tab, where, base_dir, allow_record):
    if not isinstance(tab, dict):
        raise SceneError(src, where, "must be a table", "e.g. { type = \"sine\", ... }")
    if "type" not in tab:
        raise SceneError(src, f"{where}.type", "missing",
                         "valid: " + ", ".join(FUNCTION_TYPES))
    kinds = list(FUNCTION_TYPES) if allow_record else [k for k in FUNCTION_TYPES if k != "record"]
    kind = choice(src, f"{where}.type", tab["type"], kinds)
    f = check_fields(src, tab, where, FUNCTION_TYPES[kind], extra_ok=("type",))
    f["type"] = kind
    if kind in ("rectangular", "half_sine", "sine") and f["t_end"] <= f["t_start"]:
        raise SceneError(src, f"{where}.t_end", "must be later than t_start")
    if kind == "table":
        t, y = f["t"], f["values"]
        for name, arr in (("t", t), ("values", y)):
            if not all(kind_ok("float", x) for x in arr):
                raise SceneError(src, f"{where}.{name}", "must be a list of numbers")
        if len(t) < 2 or len(t) != len(y):
            raise SceneError(src, where, f"t has {len(t)} and values {len(y)} entries",
                             "a table needs >= 2 pairs of equal length")
        for i in range(1, len(t)):
            if not t[i] > t[i - 1]:
                raise SceneError(src, f"{where}.t[{i}]", f"{t[i]} does not follow {t[i - 1]}",
                                 "times must increase strictly")
    if kind == "record":
        # read from the path resolved against the scene's folder; named in messages as the
        # scene gives it (relative to the scene). A FIFO or a device is refused from its
        # stat mode, without being opened.
        given = f["file"]
        p = Path(given)
        f["file"] = str(p if p.is_absolute() else (base_dir / p))
        f["given"], f["where"] = given, f"{where}.file"
        try:
            check_regular(f["file"])
        except UnreadableFile as exc:
            raise SceneError(src, f"{where}.file", f"{given} {exc.problem}",
                             "paths are relative to the scene file's folder") from None
    return f


# --- the loader ----------------------------------------------------------------------------

# A scene file is text of at most this size (the largest catalogue scene is 20 kB).
SCENE_LIMIT = 64 * MiB


def load(path):
    """Read and validate a scene file."""
    path = Path(path)
    try:
        raw = read_input(path, SCENE_LIMIT)
    except UnreadableFile as exc:
        raise SceneError(path, "(file)", exc.problem, exc.fix) from None
    try:
        data = tomllib.loads(raw.decode("utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise SceneError(path, "(syntax)", f"not valid TOML: {exc}") from None
    except RecursionError:
        raise SceneError(path, "(syntax)", "tables or arrays nested too deeply to parse",
                         f"a scene needs at most 4 levels, and may have {MAX_DEPTH}") from None
    except ValueError as exc:        # e.g. an integer of more digits than int() takes
        raise SceneError(path, "(syntax)", f"not valid TOML: {exc}") from None
    return from_dict(data, source=str(path), base_dir=path.parent,
                     digest=hashlib.sha256(raw).hexdigest())


def from_dict(data, source="<scene>", base_dir=Path("."), digest=None):
    """Validate a scene given as a dict (the parsed TOML)."""
    src = source
    if digest is None:
        digest = hashlib.sha256(json.dumps(data, sort_keys=True, default=str).encode()).hexdigest()
    finite_everywhere(src, data, "")
    for key in data:
        if key not in TOP_KEYS:
            raise SceneError(src, key, "unknown key", "valid top-level keys: " + ", ".join(sorted(TOP_KEYS)))
    extras = {}
    # the entries written in the file come first; the generators' follow, in the order
    # chains, rods, frames (docs/scene-input.md, "Generators")
    written = {key: data.get(key) if isinstance(data.get(key), list) else [] for key in ("node", "link")}
    chains = []
    if "chain" in data:
        data, chains = expand_chains(src, data)
    chain_nodes = Names([b.node_names() for b in chains])
    rods = {"node": [], "link": [], "mass_coupling": []}
    if "bar" in data:
        # [[bar]]: rods meshed into elements (P4)
        data, extras["bars"], rods = expand_bars(src, data, generated=chain_nodes)
    if "frame" in data:
        from .frame import expand_frames        # numpy.linalg and the frame model: only here
        data, extras["frames"] = expand_frames(src, data)   # [[frame]]: condensed frames (P10)
    building_couplings = []
    buildings = []            # [[building]]: what plan points of contacts and links refer to
    if "building" in data:
        from .building import expand_buildings   # the 3D model: only here
        # [[building]]: 3D buildings condensed to their floors' DOFs (P11)
        data, extras["buildings"], building_couplings = expand_buildings(src, data)
        buildings = extras["buildings"]

    # nodes
    generated = [ChainNodes(b) for b in chains] + rods["node"]
    raw_nodes = data.get("node", [] if generated else None)
    if not isinstance(raw_nodes, list) or not (raw_nodes or generated):
        raise SceneError(src, "node", "missing", "a scene needs at least one [[node]]")
    w = len(written["node"])
    node_segments = _segments(raw_nodes[:w], generated, raw_nodes[w:])
    node_names = Names()

    def node(i, tab):
        where = f"node[{i}]"
        n = check_fields(src, tab, where, NODE_KEYS)
        if n["name"] == GROUND:
            raise SceneError(src, f"{where}.name", "'ground' is reserved", "choose another name")
        if node_names.add(n["name"]) >= 0:
            raise SceneError(src, f"{where}.name", f"duplicate name {n['name']!r}", "names must be unique")
        if n["fixed"]:
            if n["mass"] < 0:
                raise SceneError(src, f"{where}.mass", f"invalid value {n['mass']!r}", "must be >= 0 for a fixed node")
        elif not n["mass"] > 0:
            raise SceneError(src, f"{where}.mass", f"invalid value {n['mass']!r}", "must be > 0 (or set fixed = true)")
        return n

    _check_segments(src, "node", node_segments, node_names, node)
    nodes = ItemTable(node_segments, node_names)
    index = NameIndex(node_names)

    def node_ref(path, name, ground_ok=True):
        if name == GROUND and ground_ok:
            return -1
        i = node_names.position(name) if isinstance(name, str) else -1
        if i < 0:
            known = ", ".join(node_names[:8]) + (", ..." if len(node_names) > 8 else "")
            raise SceneError(src, path, f"names no node {name!r}",
                             f"use one of: {known}" + (", ground" if ground_ok else ""))
        return i

    for key in ("link", "contact", "mass_coupling"):
        if key in data and not isinstance(data[key], list):
            raise SceneError(src, key, "must be an array of tables", f"write [[{key}]]")
    if "loads" in data and not isinstance(data["loads"], dict):
        raise SceneError(src, "loads", "must be a table", "write [loads]")
    if "force" in data.get("loads", {}) and not isinstance(data["loads"]["force"], list):
        raise SceneError(src, "loads.force", "must be an array of tables", "write [[loads.force]]")
    # links
    raw_links = data.get("link", [])
    w = len(written["link"])
    link_segments = _segments(raw_links[:w], [ChainLinks(b) for b in chains] + rods["link"],
                              raw_links[w:])
    link_names = Names()

    def link(i, tab):
        where = f"link[{i}]"
        if not isinstance(tab, dict) or "type" not in tab:
            raise SceneError(src, f"{where}.type", "missing", "valid: " + ", ".join(LINK_TYPES))
        kind = choice(src, f"{where}.type", tab["type"], list(LINK_TYPES))
        spec = dict(LINK_COMMON, **LINK_TYPES[kind])
        lk = check_fields(src, tab, where, spec)
        _sides(src, where, lk, node_ref, buildings, "direction", "connects")
        if lk.get("terms") is not None and kind == "dashpot" and lk["zeta"] is not None:
            raise SceneError(src, f"{where}.zeta", "applies to a dashpot from a node to ground",
                             "give c for a dashpot between plan points")
        lk["name"] = lk["name"] or f"link{i}"
        if link_names.add(lk["name"]) >= 0:
            raise SceneError(src, f"{where}.name", f"duplicate name {lk['name']!r}", "names must be unique")
        if kind == "dashpot" and (lk["c"] is None) == (lk["zeta"] is None):
            raise SceneError(src, where, "needs exactly one of c or zeta",
                             "c = damping [N s/m], or zeta = damping ratio of a node-to-ground oscillator")
        return lk

    _check_segments(src, "link", link_segments, link_names, link)
    links = ItemTable(link_segments, link_names)

    # contacts: those written, then each chain's (one contact table each, validated once as
    # its first contact, where the per-item expansion would have found its errors)
    contact_segments = _segments(data.get("contact", []), [ChainContacts(b) for b in chains if b.n_contacts])
    contact_names, pos = Names(), 0
    for seg in contact_segments:
        if not isinstance(seg, list):
            b = seg.block
            b.contact0 = pos
            first = {"name": f"{b.prefix}1-{b.prefix}2", "a": f"{b.prefix}1", "b": f"{b.prefix}2",
                     "gap": float(b.gap[0])}
            first.update(b.contact)
            clash = []
            b.template = _contact(src, first, pos, node_ref, lambda nm: clash.append(
                contact_names.extend(b.contact_names())) or clash[0] == 0)
            _unique(src, "contact", pos, contact_names, clash[0])
            pos += len(seg)
            continue
        for i, tab in enumerate(seg, start=pos):
            seg[i - pos] = _contact(src, tab, i, node_ref, lambda nm: contact_names.add(nm) >= 0,
                                    buildings)
        pos += len(seg)
    contacts = ItemTable(contact_segments, contact_names)

    # loads
    loads = data.get("loads", {})
    lt = check_fields(src, loads, "loads", {"gravity": ("float", False, ANY, 0.0),
                                            "force": ("list", False, None, []),
                                            "ground_acceleration": ("table", False, None, None)})
    forces = []
    for i, tab in enumerate(lt["force"]):
        where = f"loads.force[{i}]"
        if not isinstance(tab, dict):
            raise SceneError(src, where, "must be a table", "write [[loads.force]]")
        f = check_fields(src, tab, where, {"node": ("str", True, None, None),
                                            "value": ("float", False, ANY, None),
                                            "function": ("table", False, None, None)})
        if (f["value"] is None) == (f["function"] is None):
            raise SceneError(src, where, "needs exactly one of value or function",
                             "value = 10.0 for a constant force, or function = { type = ... }")
        fn = ({"type": "constant", "value": f["value"]} if f["function"] is None
              else _function(src, f["function"], f"{where}.function", base_dir, False))
        forces.append({"node": node_ref(f"{where}.node", f["node"], ground_ok=False), "function": fn})
    ground = None
    if lt["ground_acceleration"] is not None:
        ground = _function(src, lt["ground_acceleration"], "loads.ground_acceleration", base_dir, True)

    # analysis
    an = data.get("analysis")
    if not isinstance(an, dict) or "type" not in an:
        raise SceneError(src, "analysis.type", "missing", "valid: " + ", ".join(ANALYSIS_TYPES))
    atype = choice(src, "analysis.type", an["type"], list(ANALYSIS_TYPES))
    analysis = check_fields(src, an, "analysis", ANALYSIS_TYPES[atype], extra_ok=("type",))
    analysis["type"] = atype
    if atype == "dynamic":
        _dynamic_analysis(src, an, analysis, index, contacts, links)
        # a frame's member forces are recovered from its lateral displacements: recorded
        for fr in extras.get("frames", []) + extras.get("buildings", []):
            out = analysis["output"]["nodes"]
            analysis["output"]["nodes"] = out + [n for n in fr["nodes"] if n not in out]
    blocks, influence = [], None
    if "frames" in extras:
        from .frame import frame_blocks
        blocks = frame_blocks(extras["frames"], index)
    if "buildings" in extras:
        from .building import building_blocks, influence_vector
        blocks += building_blocks(extras["buildings"], index)
        influence = influence_vector(extras["buildings"], index, len(index))
    listed = [(i, lk) for seg, at in zip(links.segments, links.offsets) if isinstance(seg, list)
              for i, lk in enumerate(seg, start=at)]
    ground_k = _ground_stiffness(lk for _, lk in listed)
    for i, lk in listed:
        if lk["type"] == "dashpot" and lk["zeta"] is not None:
            lk["c"] = _dashpot_from_zeta(src, i, lk, ground_k, nodes, chains)
    for ci, b in enumerate(chains):
        b.c = _chain_dampers(src, f"chain[{ci}]", b, ground_k)

    check = data.get("check")
    if check is not None:
        check = _check_table(src, check)

    # off-diagonal (consistent) mass terms: M(a,b) = M(b,a) += value
    couplings = []
    for i, tab in enumerate(data.get("mass_coupling", [])):
        where = f"mass_coupling[{i}]"
        mc = check_fields(src, tab, where, {"a": ("str", True, None, None),
                                            "b": ("str", True, None, None),
                                            "value": ("float", True, POSITIVE, None)})
        mc["a"] = node_ref(f"{where}.a", mc["a"], ground_ok=False)
        mc["b"] = node_ref(f"{where}.b", mc["b"], ground_ok=False)
        if mc["a"] == mc["b"]:
            raise SceneError(src, f"{where}.b", "couples a node with itself", "name two different nodes")
        couplings.append(mc)
    # a building's floor masses about a reference point other than their centres
    couplings += [{"a": index[mc["a"]], "b": index[mc["b"]], "value": mc["value"]}
                  for mc in building_couplings]
    couplings = ItemTable([couplings] + rods["mass_coupling"], None)

    meta = {k: data.get(k, "") for k in ("title", "problem", "description")}
    for k, v in meta.items():
        if not isinstance(v, str):
            raise SceneError(src, k, "must be a string")
    return Scene(source=src, title=meta["title"] or Path(src).stem, problem=meta["problem"],
                 description=meta["description"], nodes=nodes, links=links, contacts=contacts,
                 gravity=lt["gravity"], forces=forces, ground=ground, analysis=analysis,
                 check=check, digest=digest, index=index, couplings=couplings, extras=extras,
                 blocks=blocks, influence=influence)



def _segments(listed, generated, after=()):
    """The segments of an item table: the listed dicts (copied: validation replaces them),
    the generated segments, then the listed dicts that follow them."""
    return [list(listed)] + list(generated) + [list(after)]


def _check_segments(src, kind, segments, names, check):
    """Every segment of an item table in order: a listed one's entries replaced by
    check(position, table) (which adds their names), a generated one placed (_place)."""
    pos = 0
    for seg in segments:
        if isinstance(seg, list):
            for i, tab in enumerate(seg, start=pos):
                seg[i - pos] = check(i, tab)
        else:
            _place(src, kind, seg, pos, names)
        pos += len(seg)


def _place(src, kind, seg, pos, names):
    """A generated segment placed at pos: its names appended (the first one taken already
    is the loader's duplicate error)."""
    seg.place(pos)
    for rule in seg.names():
        _unique(src, kind, pos, names, names.extend(rule))
        pos += len(rule)


def _unique(src, kind, pos, names, j):
    """The duplicate name a generated segment starting at pos made at its index j (j < 0:
    none)."""
    if j >= 0:
        raise SceneError(src, f"{kind}[{pos + j}].name", f"duplicate name {names[pos + j]!r}",
                         "names must be unique")


def _sides(src, where, item, node_ref, buildings, direction_key, verb):
    """An element's sides a, b: two node names (indices; −1 the ground), or, where either is a
    plan point (martello.scene.rows), the element's row item["terms"] along its plan
    direction item[direction_key] (a and b then None)."""
    a, b = item["a"], item["b"]
    if item["terms"] is not None:
        if a is not None or b is not None or item[direction_key] is not None:
            key = "a" if a is not None else ("b" if b is not None else direction_key)
            raise SceneError(src, f"{where}.{key}", "given together with terms",
                             "give the row's terms alone, or the sides a and b")
        item["terms"] = row_terms(src, f"{where}.terms", item["terms"], node_ref)
        return
    for key, side in (("a", a), ("b", b)):
        if side is None:
            raise SceneError(src, f"{where}.{key}", "missing",
                             "a node name, a plan point { floor = …, x = …, y = … }, or give terms")
    if not (is_point(a) or is_point(b)):
        if item[direction_key] is not None:
            raise SceneError(src, f"{where}.{direction_key}", "applies to plan points",
                             "remove it: a node pair acts along the scene's axis")
        item["a"], item["b"] = node_ref(f"{where}.a", a), node_ref(f"{where}.b", b)
        if item["a"] == item["b"]:
            raise SceneError(src, f"{where}.b", f"{verb} a node with itself", "name two different nodes or ground")
        del item["terms"], item[direction_key]      # a node pair: the items a generator makes
        return
    n = plan_direction(src, f"{where}.{direction_key}", item[direction_key])
    terms = {}
    for key, side, sign in (("a", a, 1.0), ("b", b, -1.0)):
        for node, coef in side_terms(src, f"{where}.{key}", side, node_ref, buildings, n, sign):
            terms[node] = terms.get(node, 0.0) + coef
    terms = [(node, coef) for node, coef in terms.items() if coef != 0.0]
    if not terms:
        raise SceneError(src, f"{where}.b", f"{verb} nothing that moves along {list(n)}",
                         "two points of different floors, or a point and ground")
    item["a"] = item["b"] = None
    item["direction" if direction_key == "direction" else "normal"] = list(n)
    item["terms"] = terms


def _contact(src, tab, i, node_ref, duplicate, buildings=()):
    """One contact table validated as contact[i]; duplicate(name) says whether its name is
    taken (and takes it)."""
    where = f"contact[{i}]"
    if not isinstance(tab, dict) or "scheme" not in tab:
        raise SceneError(src, f"{where}.scheme", "missing", "valid: " + ", ".join(SCHEMES))
    scheme = choice(src, f"{where}.scheme", tab["scheme"], SCHEMES)
    c = check_fields(src, tab, where, dict(CONTACT_COMMON, **CONTACT_SCHEMES[scheme]))
    if duplicate(c["name"]):
        raise SceneError(src, f"{where}.name", f"duplicate name {c['name']!r}", "names must be unique")
    _sides(src, where, c, node_ref, buildings, "normal", "pairs")
    if scheme == "penalty":
        choice(src, f"{where}.law", c["law"], LAWS)
        if c["clipped"] and c["law"] != "kelvin":
            raise SceneError(src, f"{where}.clipped", "applies to law kelvin only", "remove it")
        if c["exponent"] is not None and c["law"] in FIXED_EXPONENT:
            raise SceneError(src, f"{where}.exponent", f"does not apply to law {c['law']}",
                             f"its exponent is fixed at {FIXED_EXPONENT[c['law']]:g}; remove it")
        if c["law"] in ("linear", "hertz") and (c["damping"] is not None or c["restitution"] is not None):
            key = "damping" if c["damping"] is not None else "restitution"
            raise SceneError(src, f"{where}.{key}", f"law {c['law']} is elastic (e = 1)",
                             "remove it, or choose a damped law (kelvin, hunt-crossley, ...)")
        if c["law"] in ("flores", "gonthier", "jankowski") and c["restitution"] == 0:
            raise SceneError(src, f"{where}.restitution", f"law {c['law']} divides by e",
                             "give e > 0 (e = 0 is a plastic impact: use scheme restitution)")
        if c["damping"] is not None and c["restitution"] is not None:
            raise SceneError(src, f"{where}.damping", "given together with restitution",
                             "give one: damping directly, or restitution to derive it")
    return c


def _dynamic_analysis(src, raw, an, index, contacts, links):
    integ = choice(src, "analysis.integrator", an["integrator"], INTEGRATORS)
    allowed = INTEGRATOR_KEYS[integ]
    for key in ALL_SPECIFIC:
        if key in raw and key not in allowed:
            raise SceneError(src, f"analysis.{key}", f"does not apply to integrator {integ}",
                             "valid here: " + ", ".join(sorted(allowed)))
    if integ == "newmark":
        if an["preset"] is not None:
            choice(src, "analysis.preset", an["preset"], list(NEWMARK_PRESETS))
            if an["beta"] is not None or an["gamma"] is not None:
                raise SceneError(src, "analysis.preset", "given together with beta/gamma",
                                 "give a preset or beta and gamma")
            an["beta"], an["gamma"] = NEWMARK_PRESETS[an["preset"]]
        else:
            if an["beta"] is None and an["gamma"] is None:
                an["preset"] = "average-acceleration"
                an["beta"], an["gamma"] = NEWMARK_PRESETS["average-acceleration"]
            elif an["beta"] is None or an["gamma"] is None:
                raise SceneError(src, "analysis.beta" if an["beta"] is None else "analysis.gamma",
                                 "missing", "Newmark needs both beta and gamma (or a preset)")
    if an.get("method") is not None:
        choice(src, "analysis.method", an["method"], METHODS[integ])
    if integ == "hht" and an["alpha"] is None:
        raise SceneError(src, "analysis.alpha", "missing", "HHT needs alpha in [-1/3, 0]")
    if integ == "generalized-alpha" and an["rho_inf"] is None:
        raise SceneError(src, "analysis.rho_inf", "missing", "generalized-alpha needs rho_inf in [0, 1]")
    # one contact of each generated segment stands for all of it (they share their table)
    kinds = [(i, c) for seg, at in zip(contacts.segments, contacts.offsets)
             for i, c in (enumerate(seg, start=at) if isinstance(seg, list)
                          else [(at, seg.block.template)])]
    for i, c in kinds:
        if integ not in COMPATIBLE[c["scheme"]]:
            works = ", ".join(COMPATIBLE[c["scheme"]]) or "none (a static scheme: use analysis type static)"
            raise SceneError(src, f"contact[{i}].scheme",
                             f"scheme {c['scheme']} cannot run on integrator {integ}",
                             f"integrators that can: {works}")
        if integ == "moreau-jean" and c["scheme"] == "penalty" and c.get("law") == "jankowski":
            # the library refuses the pair (fortran/run_checks.f90): one linearisation per
            # step misses Jankowski's unbounded stiffness at first touch (docs/moreau-jean.md)
            raise SceneError(src, f"contact[{i}].law", "law jankowski cannot run on integrator moreau-jean",
                             "use newmark, hht, generalized-alpha, central-difference, rkf45, rk8pd, "
                             "msbdf or ida")
    if an["dt"] > an["t_end"]:
        raise SceneError(src, "analysis.dt", f"{an['dt']} is longer than t_end = {an['t_end']}",
                         "choose dt <= t_end")
    out = check_fields(src, an["output"] or {}, "analysis.output", OUTPUT_KEYS)
    # default: every node and contact of a small scene; none of a large one (peaks are always there)
    out["nodes"] = out["nodes"] if out["nodes"] is not None else (list(index) if len(index) <= 50 else [])
    contact_names = contacts.names
    out["contacts"] = (out["contacts"] if out["contacts"] is not None
                       else (list(contact_names) if len(contact_names) <= 50 else []))
    for key in ("nodes", "contacts", "links"):
        for i, nm in enumerate(out[key]):
            if not isinstance(nm, str):
                raise SceneError(src, f"analysis.output.{key}[{i}]",
                                 f"has the wrong type ({type(nm).__name__})", "expected a name (str)")
    for i, nm in enumerate(out["nodes"]):
        if nm not in index:
            raise SceneError(src, f"analysis.output.nodes[{i}]", f"names no node {nm!r}",
                             "use node names of this scene")
    for i, nm in enumerate(out["contacts"]):
        if nm not in contact_names:
            raise SceneError(src, f"analysis.output.contacts[{i}]", f"names no contact {nm!r}",
                             "use contact names of this scene")
    link_names = links.names
    for i, nm in enumerate(out["links"]):
        if nm not in link_names:
            raise SceneError(src, f"analysis.output.links[{i}]", f"names no link {nm!r}",
                             "use link names of this scene (links without a name are link<i>)")
    out["track"] = _tracked(src, out["track"], len(index) + len(links) + len(contacts) > ARRAY_ITEMS)
    an["output"] = out


def _tracked(src, given, large):
    """What the run tracks (spec.TRACKABLE, in that order): output.track's names ("all": every
    one), or by default everything, a large scene's LARGE_SCENE_TRACKS."""
    if given is None:
        return list(LARGE_SCENE_TRACKS if large else TRACKABLE)
    for i, nm in enumerate(given):
        if nm not in TRACKABLE and nm != "all":
            raise SceneError(src, f"analysis.output.track[{i}]", f"unknown value {nm!r}",
                             "valid: " + ", ".join(TRACKABLE + ("all",)))
    return [nm for nm in TRACKABLE if nm in given or "all" in given]


def _ground_stiffness(links):
    """Sum of the stiffnesses of springs, bilinear springs and bars from each node to ground."""
    k = {}
    for l in links:
        if l["type"] in ("spring", "bilinear", "bar") and -1 in (l["a"], l["b"]):
            node = l["a"] if l["b"] == -1 else l["b"]
            k[node] = k.get(node, 0.0) + (l["EA"] / l["L"] if l["type"] == "bar" else l["k"])
    return k


def _chain_k(chains, node):
    """The stiffness of the chain spring from a node to ground (0 if it is no chain's)."""
    for b in chains:
        if b.node0 <= node < b.node0 + b.n:
            return float(b.k[node - b.node0])
    return 0.0


def _chain_dampers(src, where, b, ground_k):
    """c = 2ζ√(k m) of a chain's dampers: k its spring plus the written springs from the node
    to ground (which come before it in the scene's links; ground_k). SceneError naming the
    chain's zeta if one is not a finite number (k m past the doubles)."""
    d = b.dampers
    if not len(d):
        return np.zeros(0)
    k = np.array(b.k[d], np.float64)
    for node, kw in ground_k.items():
        i = node - b.node0
        if 0 <= i < b.n and b.zeta[i] > 0:
            k[np.searchsorted(d, i)] = kw + b.k[i]
    # float_power is libm's pow, as `** 0.5` of the listed dashpots (np.sqrt and np.power
    # round differently in the last bit now and then)
    with np.errstate(over="ignore", invalid="ignore"):
        c = 2.0 * b.zeta[d] * np.float_power(k * b.mass[d], 0.5)
    _finite_damping(src, f"{where}.zeta", c, k, b.mass[d], [f"{b.prefix}{i + 1}" for i in d])
    return c


def _finite_damping(src, where, c, k, mass, names):
    """SceneError unless every c = 2ζ√(k m) is a finite number."""
    bad = np.flatnonzero(~np.isfinite(np.atleast_1d(c)))
    if len(bad):
        i = int(bad[0])
        raise SceneError(src, where, f"the damping c = 2 zeta sqrt(k m) of node {names[i]} is not a "
                         f"finite number (k = {float(np.atleast_1d(k)[i]):.6g} N/m, m = "
                         f"{float(np.atleast_1d(mass)[i]):.6g} kg)",
                         "give k and the mass in N/m and kg, or c directly")


def _dashpot_from_zeta(src, i, lk, ground_k, nodes, chains=()):
    """c = 2ζ√(k m) for a dashpot from a node to ground, k the node's springs to ground
    (written ones, then a chain's)."""
    where = f"link[{i}].zeta"
    if lk["b"] != -1 and lk["a"] != -1:
        raise SceneError(src, where, "applies to a dashpot between a node and ground",
                         "give c for a dashpot between two nodes")
    node = lk["a"] if lk["b"] == -1 else lk["b"]
    if nodes[node]["fixed"]:
        raise SceneError(src, where, "the node is fixed", "a damping ratio needs a free node")
    k = ground_k.get(node, 0.0)
    if chains and _chain_k(chains, node) > 0:
        k = k + _chain_k(chains, node)
    if k <= 0:
        raise SceneError(src, where, "the node has no spring to ground to define a frequency",
                         "give c directly")
    c = 2.0 * lk["zeta"] * (k * nodes[node]["mass"]) ** 0.5
    _finite_damping(src, where, c, k, nodes[node]["mass"], [nodes[node]["name"]])
    return c


def _check_table(src, check):
    c = check_fields(src, check, "check", {"closed_form": ("str", True, None, None),
                                           "params": ("table", True, None, None),
                                           "compare": ("list", True, None, None)})
    for i, item in enumerate(c["compare"]):
        check_fields(src, item, f"check.compare[{i}]", {
            "result": ("str", True, None, None), "oracle": ("str", True, None, None),
            "rtol": ("float", False, NONNEG, None), "atol": ("float", False, NONNEG, None),
            # the size of the quantity when its reference is 0: what an atol is relative to
            # (martello.checks.kinds)
            "scale": ("float", False, POSITIVE, None),
            "why": ("str", True, None, None)})
        if "rtol" not in item and "atol" not in item:
            raise SceneError(src, f"check.compare[{i}]", "needs rtol or atol",
                             "state the tolerance and why (rtol = 0 and atol = 0 ask for exact equality)")
    return c
