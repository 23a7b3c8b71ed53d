"""Scene files: read, validate, and describe a 1D mechanical network (DESIGN.md).

A scene is TOML with tables `[[node]]`, `[[link]]`, `[[contact]]`, `[loads]`, `[analysis]`
and an optional `[check]` (the closed form it is verified against). The format is documented
in docs/scene-format.md. Every error names the file, the field and what would be valid."""

import hashlib
import json
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

from . import native
from .errors import SceneError

GROUND = "ground"

# --- field specifications -------------------------------------------------------------------
# Each table lists its keys: (kind, required, check, default). kind is "float", "int", "str",
# "bool", "list", "table" or "function". check is (predicate, "what is valid").

POSITIVE = (lambda x: x > 0, "a number > 0")
NONNEG = (lambda x: x >= 0, "a number >= 0")
ANY = (lambda x: True, "a number")


def _unit_interval(lo_open=False, hi_open=False):
    def ok(x):
        return (x > 0 if lo_open else x >= 0) and (x < 1 if hi_open else x <= 1)
    lo, hi = ("(" if lo_open else "["), (")" if hi_open else "]")
    return (ok, f"a number in {lo}0, 1{hi}")


NODE_KEYS = {
    "name": ("str", True, None, None),
    "mass": ("float", True, None, None),        # > 0 unless fixed: checked below
    "u0": ("float", False, ANY, 0.0),
    "v0": ("float", False, ANY, 0.0),
    "fixed": ("bool", False, None, False),
}

LINK_COMMON = {"name": ("str", False, None, None), "type": ("str", True, None, None),
               "a": ("str", True, None, None), "b": ("str", True, None, None)}
LINK_TYPES = {
    "spring": {"k": ("float", True, POSITIVE, None)},
    "dashpot": {"c": ("float", False, POSITIVE, None),
                "zeta": ("float", False, (lambda x: 0 < x < 10, "a number in (0, 10)"), None)},
    "bilinear": {"k": ("float", True, POSITIVE, None), "fy": ("float", True, POSITIVE, None),
                 "hardening": ("float", False, _unit_interval(hi_open=True), 0.0)},
    "fluid_damper": {"c": ("float", True, POSITIVE, None),
                     "alpha": ("float", False, (lambda x: 0 < x <= 2, "a number in (0, 2]"), 1.0),
                     "v_reg": ("float", False, NONNEG, 1e-6)},
    "bar": {"EA": ("float", True, POSITIVE, None), "L": ("float", True, POSITIVE, None)},
}

SCHEMES = native.names("schemes")
LAWS = native.names("laws")
FIXED_EXPONENT = {r.name: r.values["exponent"] for r in native.registry("laws")
                  if r.values["exponent_fixed"]}
CONTACT_COMMON = {"name": ("str", True, None, None), "a": ("str", True, None, None),
                  "b": ("str", True, None, None), "gap": ("float", False, ANY, 0.0),
                  "scheme": ("str", True, None, None)}
CONTACT_SCHEMES = {
    "penalty": {"law": ("str", False, None, "linear"),
                "stiffness": ("float", True, POSITIVE, None),
                "exponent": ("float", False, POSITIVE, None),
                "damping": ("float", False, NONNEG, None),
                "restitution": ("float", False, _unit_interval(), None),
                "clipped": ("bool", False, None, False)},
    "lagrange": {"restitution": ("float", False, _unit_interval(), None)},
    "augmented-lagrange": {"stiffness": ("float", True, POSITIVE, None)},
    "restitution": {"restitution": ("float", True, _unit_interval(), None)},
}

FUNCTION_TYPES = {
    "constant": {"value": ("float", True, ANY, None)},
    "sine": {"amplitude": ("float", True, ANY, None), "omega": ("float", True, POSITIVE, None),
             "phase": ("float", False, ANY, 0.0), "t_start": ("float", False, NONNEG, 0.0),
             "t_end": ("float", False, POSITIVE, 1e300)},
    "rectangular": {"amplitude": ("float", True, ANY, None),
                    "t_start": ("float", False, NONNEG, 0.0), "t_end": ("float", True, POSITIVE, None)},
    "half_sine": {"amplitude": ("float", True, ANY, None),
                  "t_start": ("float", False, NONNEG, 0.0), "t_end": ("float", True, POSITIVE, None)},
    "table": {"t": ("list", True, None, None), "values": ("list", True, None, None),
              "scale": ("float", False, ANY, 1.0)},
    "record": {"file": ("str", True, None, None), "format": ("str", False, None, None),
               "units": ("str", False, None, None), "scale": ("float", False, ANY, 1.0)},
}

# The integrators, and which contact schemes each runs, are the library's (its registry;
# tests/test_registry.py): penalty contacts are smooth forces; lagrange and restitution
# contacts need event location or impulse-level time stepping; augmented-lagrange is static.
INTEGRATORS = native.integrators()
ADAPTIVE = native.adaptive_integrators()
COMPATIBLE = native.compatibility()


def _setting(kind, name, required=False, default=True):
    """A key that is a native setting: the library's valid range and, unless required or
    default=False, its default (the registry's table settings)."""
    rng = native.settings_ranges()[name]
    return (kind, required, (lambda x: native.in_range(rng, x), rng.text),
            native.settings_defaults()[name] if default and not required else None)


NEWMARK_PRESETS = {"average-acceleration": (0.25, 0.5), "linear-acceleration": (1.0 / 6.0, 0.5)}
ANALYSIS_TYPES = {
    "static": {"tol": ("float", False, POSITIVE, 1e-14),
               "max_iter": ("int", False, POSITIVE, 500)},
    "dynamic": {"integrator": ("str", True, None, None),
                "dt": _setting("float", "dt", required=True),
                "t_end": _setting("float", "t_end", required=True),
                "preset": ("str", False, None, None),
                "beta": _setting("float", "beta", default=False),
                "gamma": _setting("float", "gamma", default=False),
                "alpha": _setting("float", "alpha", default=False),
                "rho_inf": _setting("float", "rho_inf", default=False),
                "tol_residual": _setting("float", "tol_residual"),
                "tol_increment": _setting("float", "tol_increment"),
                "max_newton": _setting("int", "max_newton"),
                "check_stability": _setting("bool", "check_stability"),
                "divergence_factor": _setting("float", "divergence_factor"),
                "rtol": _setting("float", "rtol"),
                "atol": _setting("float", "atol"),
                "theta": _setting("float", "theta"),
                "event_tol": _setting("float", "event_tol"),
                "h_max": _setting("float", "h_max"),
                "output": ("table", False, None, None)},
}
OUTPUT_KEYS = {"every": _setting("int", "every"), "nodes": ("list", False, None, None),
               "contacts": ("list", False, None, None), "links": ("list", False, None, [])}
# The analysis keys of one integrator or a group: the settings it reads beyond those every
# integrator reads (the library's table "reads"); Newmark also takes a preset.
_READ_BY_ALL = set.intersection(*(native.settings_read(i) for i in INTEGRATORS))
INTEGRATOR_KEYS = {i: native.settings_read(i) - _READ_BY_ALL | ({"preset"} if i == "newmark" else set())
                   for i in INTEGRATORS}
ALL_SPECIFIC = set().union(*INTEGRATOR_KEYS.values())

TOP_KEYS = {"title", "problem", "description", "node", "link", "contact", "loads", "analysis",
            "check", "chain", "bar", "mass_coupling"}

# [[chain]]: n oscillators in a row (PROBLEMS.md P7), each a mass on a spring to ground
# (bilinear if fy is given) with an optional dashpot (zeta), and contacts between
# neighbours: δ_i = u_i − u_{i+1} − gap_i. Scalars apply to every oscillator, lists give one
# value each (n for oscillators, n − 1 for gaps).
CHAIN_KEYS = {"prefix": ("str", True, None, None), "n": ("int", True, POSITIVE, None),
              "mass": ("any", True, None, None), "k": ("any", True, None, None),
              "fy": ("any", False, None, None), "hardening": ("any", False, None, None),
              "zeta": ("any", False, None, None), "gap": ("any", False, None, 0.0),
              "u0": ("any", False, None, None), "v0": ("any", False, None, None),
              "contact": ("table", False, None, None)}


@dataclass
class Scene:
    source: str
    title: str
    problem: str
    description: str
    nodes: list          # dicts: name, mass, u0, v0, fixed
    links: list          # dicts: name, type, a, b (indices, -1 ground) + parameters
    contacts: list       # dicts: name, a, b, gap, scheme + parameters
    gravity: float
    forces: list         # dicts: node (index), function (dict)
    ground: dict | None  # function dict, or None
    analysis: dict
    check: dict | None
    digest: str          # sha256 of the file (or of the canonical JSON of a dict scene)
    index: dict = field(default_factory=dict)   # node name -> index
    couplings: list = field(default_factory=list)  # dicts: a, b (indices), value
    extras: dict = field(default_factory=dict)     # what generators ([[bar]]) know of the scene

    def node_index(self, name):
        return -1 if name == GROUND else self.index[name]


# --- helpers ---------------------------------------------------------------------------------

def _kind_ok(kind, v):
    if kind == "any":
        return True
    if kind == "float":
        return isinstance(v, (int, float)) and not isinstance(v, bool)
    if kind == "int":
        return isinstance(v, int) and not isinstance(v, bool)
    return isinstance(v, {"str": str, "bool": bool, "list": list, "table": dict}[kind])


def _fields(src, table, where, spec, extra_ok=()):
    """Validate one table against its spec; return a dict with defaults filled in."""
    if not isinstance(table, dict):
        raise SceneError(src, where, "must be a table", "write it as [name] or { ... }")
    for key in table:
        if key not in spec and key not in extra_ok:
            valid = ", ".join(sorted(set(spec) | set(extra_ok)))
            raise SceneError(src, f"{where}.{key}", "unknown key", f"valid keys here: {valid}")
    out = {}
    for key, (kind, required, check, default) in spec.items():
        path = f"{where}.{key}"
        if key not in table:
            if required:
                raise SceneError(src, path, "missing", f"this field is required ({kind})")
            out[key] = default
            continue
        v = table[key]
        if not _kind_ok(kind, v):
            raise SceneError(src, path, f"has the wrong type ({type(v).__name__})",
                             f"expected {kind}")
        if kind == "float":
            v = float(v)
        if check is not None and kind in ("float", "int"):
            ok, what = check
            if not ok(v):
                raise SceneError(src, path, f"invalid value {v!r}", f"must be {what}")
        out[key] = v
    return out


def _finite_everywhere(src, obj, where):
    """TOML admits nan and inf literals; a scene never may."""
    if isinstance(obj, float) and not math.isfinite(obj):
        raise SceneError(src, where, f"is {obj}", "every number in a scene must be finite")
    if isinstance(obj, dict):
        for k, v in obj.items():
            _finite_everywhere(src, v, f"{where}.{k}" if where else k)
    elif isinstance(obj, list):
        for i, v in enumerate(obj):
            _finite_everywhere(src, v, f"{where}[{i}]")


def _choice(src, path, value, choices):
    if value not in choices:
        raise SceneError(src, path, f"unknown value {value!r}", "valid: " + ", ".join(choices))
    return value


def _function(src, tab, where, base_dir, allow_record):
    if not isinstance(tab, dict):
        raise SceneError(src, where, "must be a table", "e.g. { type = \"sine\", ... }")
    if "type" not in tab:
        raise SceneError(src, f"{where}.type", "missing",
                         "valid: " + ", ".join(FUNCTION_TYPES))
    kinds = list(FUNCTION_TYPES) if allow_record else [k for k in FUNCTION_TYPES if k != "record"]
    kind = _choice(src, f"{where}.type", tab["type"], kinds)
    f = _fields(src, tab, where, FUNCTION_TYPES[kind], extra_ok=("type",))
    f["type"] = kind
    if kind in ("rectangular", "half_sine", "sine") and f["t_end"] <= f["t_start"]:
        raise SceneError(src, f"{where}.t_end", "must be later than t_start")
    if kind == "table":
        t, y = f["t"], f["values"]
        for name, arr in (("t", t), ("values", y)):
            if not all(_kind_ok("float", x) for x in arr):
                raise SceneError(src, f"{where}.{name}", "must be a list of numbers")
        if len(t) < 2 or len(t) != len(y):
            raise SceneError(src, where, f"t has {len(t)} and values {len(y)} entries",
                             "a table needs >= 2 pairs of equal length")
        for i in range(1, len(t)):
            if not t[i] > t[i - 1]:
                raise SceneError(src, f"{where}.t[{i}]", f"{t[i]} does not follow {t[i - 1]}",
                                 "times must increase strictly")
    if kind == "record":
        p = Path(f["file"])
        f["file"] = str(p if p.is_absolute() else (base_dir / p))
        if not Path(f["file"]).exists():
            raise SceneError(src, f"{where}.file", f"{f['file']} does not exist",
                             "paths are relative to the scene file's folder")
    return f


# --- the loader ----------------------------------------------------------------------------

def load(path):
    """Read and validate a scene file."""
    path = Path(path)
    if not path.exists():
        raise SceneError(path, "(file)", "does not exist")
    raw = path.read_bytes()
    try:
        data = tomllib.loads(raw.decode("utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise SceneError(path, "(syntax)", f"not valid TOML: {exc}") from None
    return from_dict(data, source=str(path), base_dir=path.parent,
                     digest=hashlib.sha256(raw).hexdigest())


def from_dict(data, source="<scene>", base_dir=Path("."), digest=None):
    """Validate a scene given as a dict (the parsed TOML)."""
    src = source
    if digest is None:
        digest = hashlib.sha256(json.dumps(data, sort_keys=True, default=str).encode()).hexdigest()
    _finite_everywhere(src, data, "")
    for key in data:
        if key not in TOP_KEYS:
            raise SceneError(src, key, "unknown key", "valid top-level keys: " + ", ".join(sorted(TOP_KEYS)))
    extras = {}
    if "chain" in data:
        data = _expand_chains(src, data)
    if "bar" in data:
        from .bars import expand_bars     # [[bar]]: axial rods meshed into elements (P4)
        data, extras["bars"] = expand_bars(src, data)

    # nodes
    raw_nodes = data.get("node")
    if not isinstance(raw_nodes, list) or not raw_nodes:
        raise SceneError(src, "node", "missing", "a scene needs at least one [[node]]")
    nodes, index = [], {}
    for i, tab in enumerate(raw_nodes):
        where = f"node[{i}]"
        n = _fields(src, tab, where, NODE_KEYS)
        if n["name"] == GROUND:
            raise SceneError(src, f"{where}.name", "'ground' is reserved", "choose another name")
        if n["name"] in index:
            raise SceneError(src, f"{where}.name", f"duplicate name {n['name']!r}", "names must be unique")
        if n["fixed"]:
            if n["mass"] < 0:
                raise SceneError(src, f"{where}.mass", f"invalid value {n['mass']!r}", "must be >= 0 for a fixed node")
        elif not n["mass"] > 0:
            raise SceneError(src, f"{where}.mass", f"invalid value {n['mass']!r}", "must be > 0 (or set fixed = true)")
        index[n["name"]] = i
        nodes.append(n)

    def node_ref(path, name, ground_ok=True):
        if name == GROUND and ground_ok:
            return -1
        if name not in index:
            known = ", ".join(list(index)[:8]) + (", ..." if len(index) > 8 else "")
            raise SceneError(src, path, f"names no node {name!r}",
                             f"use one of: {known}" + (", ground" if ground_ok else ""))
        return index[name]

    for key in ("link", "contact", "mass_coupling"):
        if key in data and not isinstance(data[key], list):
            raise SceneError(src, key, "must be an array of tables", f"write [[{key}]]")
    if "force" in data.get("loads", {}) and not isinstance(data["loads"]["force"], list):
        raise SceneError(src, "loads.force", "must be an array of tables", "write [[loads.force]]")
    # links
    links, lnames = [], set()
    for i, tab in enumerate(data.get("link", [])):
        where = f"link[{i}]"
        if not isinstance(tab, dict) or "type" not in tab:
            raise SceneError(src, f"{where}.type", "missing", "valid: " + ", ".join(LINK_TYPES))
        kind = _choice(src, f"{where}.type", tab["type"], list(LINK_TYPES))
        spec = dict(LINK_COMMON, **LINK_TYPES[kind])
        lk = _fields(src, tab, where, spec)
        lk["a"], lk["b"] = node_ref(f"{where}.a", lk["a"]), node_ref(f"{where}.b", lk["b"])
        if lk["a"] == lk["b"]:
            raise SceneError(src, f"{where}.b", "connects a node to itself", "name two different nodes")
        lk["name"] = lk["name"] or f"link{i}"
        if lk["name"] in lnames:
            raise SceneError(src, f"{where}.name", f"duplicate name {lk['name']!r}", "names must be unique")
        lnames.add(lk["name"])
        if kind == "dashpot" and (lk["c"] is None) == (lk["zeta"] is None):
            raise SceneError(src, where, "needs exactly one of c or zeta",
                             "c = damping [N s/m], or zeta = damping ratio of a node-to-ground oscillator")
        links.append(lk)

    # contacts
    contacts, cnames = [], set()
    for i, tab in enumerate(data.get("contact", [])):
        where = f"contact[{i}]"
        if not isinstance(tab, dict) or "scheme" not in tab:
            raise SceneError(src, f"{where}.scheme", "missing", "valid: " + ", ".join(SCHEMES))
        scheme = _choice(src, f"{where}.scheme", tab["scheme"], SCHEMES)
        c = _fields(src, tab, where, dict(CONTACT_COMMON, **CONTACT_SCHEMES[scheme]))
        if c["name"] in cnames:
            raise SceneError(src, f"{where}.name", f"duplicate name {c['name']!r}", "names must be unique")
        cnames.add(c["name"])
        c["a"], c["b"] = node_ref(f"{where}.a", c["a"]), node_ref(f"{where}.b", c["b"])
        if c["a"] == c["b"]:
            raise SceneError(src, f"{where}.b", "pairs a node with itself", "name two different nodes or ground")
        if scheme == "penalty":
            _choice(src, f"{where}.law", c["law"], LAWS)
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
        contacts.append(c)

    # loads
    loads = data.get("loads", {})
    lt = _fields(src, loads, "loads", {"gravity": ("float", False, ANY, 0.0),
                                       "force": ("list", False, None, []),
                                       "ground_acceleration": ("table", False, None, None)})
    forces = []
    for i, tab in enumerate(lt["force"]):
        where = f"loads.force[{i}]"
        if not isinstance(tab, dict):
            raise SceneError(src, where, "must be a table", "write [[loads.force]]")
        f = _fields(src, tab, where, {"node": ("str", True, None, None),
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
    atype = _choice(src, "analysis.type", an["type"], list(ANALYSIS_TYPES))
    analysis = _fields(src, an, "analysis", ANALYSIS_TYPES[atype], extra_ok=("type",))
    analysis["type"] = atype
    if atype == "dynamic":
        _dynamic_analysis(src, an, analysis, index, contacts, links)
    ground_k = _ground_stiffness(links)
    for i, lk in enumerate(links):
        if lk["type"] == "dashpot" and lk["zeta"] is not None:
            lk["c"] = _dashpot_from_zeta(src, i, lk, ground_k, nodes)

    check = data.get("check")
    if check is not None:
        check = _check_table(src, check)

    # off-diagonal (consistent) mass terms: M(a,b) = M(b,a) += value
    couplings = []
    for i, tab in enumerate(data.get("mass_coupling", [])):
        where = f"mass_coupling[{i}]"
        mc = _fields(src, tab, where, {"a": ("str", True, None, None), "b": ("str", True, None, None),
                                       "value": ("float", True, POSITIVE, None)})
        mc["a"] = node_ref(f"{where}.a", mc["a"], ground_ok=False)
        mc["b"] = node_ref(f"{where}.b", mc["b"], ground_ok=False)
        if mc["a"] == mc["b"]:
            raise SceneError(src, f"{where}.b", "couples a node with itself", "name two different nodes")
        couplings.append(mc)

    meta = {k: data.get(k, "") for k in ("title", "problem", "description")}
    for k, v in meta.items():
        if not isinstance(v, str):
            raise SceneError(src, k, "must be a string")
    return Scene(source=src, title=meta["title"] or Path(src).stem, problem=meta["problem"],
                 description=meta["description"], nodes=nodes, links=links, contacts=contacts,
                 gravity=lt["gravity"], forces=forces, ground=ground, analysis=analysis,
                 check=check, digest=digest, index=index, couplings=couplings, extras=extras)


def _per_item(src, where, value, count, check=None):
    """A scalar for all, or a list of exactly `count` numbers."""
    values = value if isinstance(value, list) else [value] * count
    if len(values) != count:
        raise SceneError(src, where, f"has {len(values)} values", f"give one number or a list of {count}")
    for i, v in enumerate(values):
        path = f"{where}[{i}]" if isinstance(value, list) else where
        if not _kind_ok("float", v):
            raise SceneError(src, path, f"has the wrong type ({type(v).__name__})", "expected float")
        if check is not None and not check[0](float(v)):
            raise SceneError(src, path, f"invalid value {v!r}", f"must be {check[1]}")
    return [float(v) for v in values]


def _expand_chains(src, data):
    """Replace [[chain]] tables by the nodes, links and contacts they stand for."""
    data = dict(data)
    chains = data.pop("chain")
    if not isinstance(chains, list):
        raise SceneError(src, "chain", "must be an array of tables", "write [[chain]]")
    nodes, links, contacts = list(data.get("node", [])), list(data.get("link", [])), list(data.get("contact", []))
    for ci, tab in enumerate(chains):
        w = f"chain[{ci}]"
        ch = _fields(src, tab, w, CHAIN_KEYS)
        n, p = ch["n"], ch["prefix"]
        mass = _per_item(src, f"{w}.mass", ch["mass"], n, POSITIVE)
        k = _per_item(src, f"{w}.k", ch["k"], n, POSITIVE)
        fy = _per_item(src, f"{w}.fy", ch["fy"], n, POSITIVE) if ch["fy"] is not None else None
        rho = _per_item(src, f"{w}.hardening", ch["hardening"] or 0.0, n, _unit_interval(hi_open=True))
        zeta = _per_item(src, f"{w}.zeta", ch["zeta"], n, (lambda x: 0 <= x < 10, "a number in [0, 10)")) \
            if ch["zeta"] is not None else None
        gap = _per_item(src, f"{w}.gap", ch["gap"], n - 1) if n > 1 else []
        u0 = _per_item(src, f"{w}.u0", ch["u0"], n) if ch["u0"] is not None else [0.0] * n
        v0 = _per_item(src, f"{w}.v0", ch["v0"], n) if ch["v0"] is not None else [0.0] * n
        for i in range(n):
            name = f"{p}{i + 1}"
            nodes.append({"name": name, "mass": mass[i], "u0": u0[i], "v0": v0[i]})
            if fy is None:
                links.append({"name": f"{name}.spring", "type": "spring", "a": name, "b": "ground", "k": k[i]})
            else:
                links.append({"name": f"{name}.spring", "type": "bilinear", "a": name, "b": "ground",
                              "k": k[i], "fy": fy[i], "hardening": rho[i]})
            if zeta is not None and zeta[i] > 0:
                links.append({"name": f"{name}.damper", "type": "dashpot", "a": name, "b": "ground",
                              "zeta": zeta[i]})
        if ch["fy"] is None and ch["hardening"] is not None:
            raise SceneError(src, f"{w}.hardening", "given without fy", "give fy (yield force) for a bilinear spring")
        if n == 1 and (ch["contact"] is not None or tab.get("gap") is not None):
            raise SceneError(src, f"{w}.contact" if ch["contact"] is not None else f"{w}.gap",
                             "a chain of one oscillator has no neighbour contact", "remove it or set n > 1")
        for key in ("name", "a", "b", "gap"):
            if ch["contact"] is not None and key in ch["contact"]:
                raise SceneError(src, f"{w}.contact.{key}", "is generated by the chain",
                                 "remove it (set gaps with the chain's own gap key)")
        if ch["contact"] is not None and n > 1:
            for i in range(n - 1):
                c = {"name": f"{p}{i + 1}-{p}{i + 2}", "a": f"{p}{i + 1}", "b": f"{p}{i + 2}", "gap": gap[i]}
                c.update(ch["contact"])
                contacts.append(c)
    data.update(node=nodes, link=links, contact=contacts)
    return data


def _dynamic_analysis(src, raw, an, index, contacts, links):
    integ = _choice(src, "analysis.integrator", an["integrator"], INTEGRATORS)
    allowed = INTEGRATOR_KEYS[integ]
    for key in ALL_SPECIFIC:
        if key in raw and key not in allowed:
            raise SceneError(src, f"analysis.{key}", f"does not apply to integrator {integ}",
                             "valid here: " + ", ".join(sorted(allowed)))
    if integ == "newmark":
        if an["preset"] is not None:
            _choice(src, "analysis.preset", an["preset"], list(NEWMARK_PRESETS))
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
    if integ == "hht" and an["alpha"] is None:
        raise SceneError(src, "analysis.alpha", "missing", "HHT needs alpha in [-1/3, 0]")
    if integ == "generalized-alpha" and an["rho_inf"] is None:
        raise SceneError(src, "analysis.rho_inf", "missing", "generalized-alpha needs rho_inf in [0, 1]")
    for i, c in enumerate(contacts):
        if integ not in COMPATIBLE[c["scheme"]]:
            works = ", ".join(COMPATIBLE[c["scheme"]]) or "none (a static scheme: use analysis type static)"
            raise SceneError(src, f"contact[{i}].scheme",
                             f"scheme {c['scheme']} cannot run on integrator {integ}",
                             f"integrators that can: {works}")
    if an["dt"] > an["t_end"]:
        raise SceneError(src, "analysis.dt", f"{an['dt']} is longer than t_end = {an['t_end']}",
                         "choose dt <= t_end")
    out = _fields(src, an["output"] or {}, "analysis.output", OUTPUT_KEYS)
    names = list(index)
    # default: every node and contact of a small scene; none of a large one (peaks are always there)
    out["nodes"] = out["nodes"] if out["nodes"] is not None else (names if len(names) <= 50 else [])
    contact_names = [c["name"] for c in contacts]
    out["contacts"] = (out["contacts"] if out["contacts"] is not None
                       else (contact_names if len(contact_names) <= 50 else []))
    for i, nm in enumerate(out["nodes"]):
        if nm not in index:
            raise SceneError(src, f"analysis.output.nodes[{i}]", f"names no node {nm!r}",
                             "use node names of this scene")
    for i, nm in enumerate(out["contacts"]):
        if nm not in contact_names:
            raise SceneError(src, f"analysis.output.contacts[{i}]", f"names no contact {nm!r}",
                             "use contact names of this scene")
    link_names = [l["name"] for l in links]
    for i, nm in enumerate(out["links"]):
        if nm not in link_names:
            raise SceneError(src, f"analysis.output.links[{i}]", f"names no link {nm!r}",
                             "use link names of this scene (links without a name are link<i>)")
    an["output"] = out


def _ground_stiffness(links):
    """Sum of the stiffnesses of springs, bilinear springs and bars from each node to ground."""
    k = {}
    for l in links:
        if l["type"] in ("spring", "bilinear", "bar") and -1 in (l["a"], l["b"]):
            node = l["a"] if l["b"] == -1 else l["b"]
            k[node] = k.get(node, 0.0) + (l["EA"] / l["L"] if l["type"] == "bar" else l["k"])
    return k


def _dashpot_from_zeta(src, i, lk, ground_k, nodes):
    """c = 2ζ√(k m) for a dashpot from a node to ground, k the node's springs to ground."""
    where = f"link[{i}].zeta"
    if lk["b"] != -1 and lk["a"] != -1:
        raise SceneError(src, where, "applies to a dashpot between a node and ground",
                         "give c for a dashpot between two nodes")
    node = lk["a"] if lk["b"] == -1 else lk["b"]
    if nodes[node]["fixed"]:
        raise SceneError(src, where, "the node is fixed", "a damping ratio needs a free node")
    k = ground_k.get(node, 0.0)
    if k <= 0:
        raise SceneError(src, where, "the node has no spring to ground to define a frequency",
                         "give c directly")
    return 2.0 * lk["zeta"] * (k * nodes[node]["mass"]) ** 0.5


def _check_table(src, check):
    c = _fields(src, check, "check", {"closed_form": ("str", True, None, None),
                                      "params": ("table", True, None, None),
                                      "compare": ("list", True, None, None)})
    for i, item in enumerate(c["compare"]):
        _fields(src, item, f"check.compare[{i}]", {
            "result": ("str", True, None, None), "oracle": ("str", True, None, None),
            "rtol": ("float", False, NONNEG, None), "atol": ("float", False, NONNEG, None),
            "why": ("str", True, None, None)})
        if "rtol" not in item and "atol" not in item:
            raise SceneError(src, f"check.compare[{i}]", "needs rtol or atol",
                             "state the tolerance and why (rtol = 0 and atol = 0 ask for exact equality)")
    return c
