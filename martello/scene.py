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
    "dashpot": {"c": ("float", True, POSITIVE, None)},
    "bilinear": {"k": ("float", True, POSITIVE, None), "fy": ("float", True, POSITIVE, None),
                 "hardening": ("float", False, _unit_interval(hi_open=True), 0.0)},
    "fluid_damper": {"c": ("float", True, POSITIVE, None),
                     "alpha": ("float", False, (lambda x: 0 < x <= 2, "a number in (0, 2]"), 1.0),
                     "v_reg": ("float", False, NONNEG, 1e-6)},
    "bar": {"EA": ("float", True, POSITIVE, None), "L": ("float", True, POSITIVE, None)},
}

SCHEMES = ("penalty", "lagrange", "augmented-lagrange", "restitution")
LAWS = ("linear", "hertz", "kelvin", "hunt-crossley", "lankarani-nikravesh", "flores",
        "gonthier", "hertzdamp", "jankowski")
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

ANALYSIS_TYPES = {
    "static": {"tol": ("float", False, POSITIVE, 1e-14),
               "max_iter": ("int", False, POSITIVE, 500)},
}

TOP_KEYS = {"title", "problem", "description", "node", "link", "contact", "loads", "analysis",
            "check"}


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

    def node_index(self, name):
        return -1 if name == GROUND else self.index[name]


# --- helpers ---------------------------------------------------------------------------------

def _kind_ok(kind, v):
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

    # links
    links = []
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

    check = data.get("check")
    if check is not None:
        check = _check_table(src, check)

    meta = {k: data.get(k, "") for k in ("title", "problem", "description")}
    for k, v in meta.items():
        if not isinstance(v, str):
            raise SceneError(src, k, "must be a string")
    return Scene(source=src, title=meta["title"] or Path(src).stem, problem=meta["problem"],
                 description=meta["description"], nodes=nodes, links=links, contacts=contacts,
                 gravity=lt["gravity"], forces=forces, ground=ground, analysis=analysis,
                 check=check, digest=digest, index=index)


def _check_table(src, check):
    c = _fields(src, check, "check", {"closed_form": ("str", True, None, None),
                                      "params": ("table", True, None, None),
                                      "compare": ("list", True, None, None)})
    for i, item in enumerate(c["compare"]):
        _fields(src, item, f"check.compare[{i}]", {
            "result": ("str", True, None, None), "oracle": ("str", True, None, None),
            "rtol": ("float", False, POSITIVE, None), "atol": ("float", False, POSITIVE, None),
            "why": ("str", True, None, None)})
        if "rtol" not in item and "atol" not in item:
            raise SceneError(src, f"check.compare[{i}]", "needs rtol or atol", "state the tolerance and why")
    return c
