"""A scene file read into the independent engine's own model: tomllib and the format of
docs/scene-input.md, nothing of the front end (martello.scene) or the native library.

Only what the engine integrates is read; a scene it cannot describe exactly raises
Unsupported naming the part. Validation is the front end's business: this reader assumes a
scene that `martello run` accepts, and re-derives from it every quantity the mechanics needs
(node indices, the chain generator, dashpots given by ζ, effective masses, time functions)."""

from __future__ import annotations

import math
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .building import building_block, point_terms
from .errors import Unsupported
from .frame import FrameBlock, frame_block
from .laws import ContactLaw, contact_law

GROUND = -1
STANDARD_GRAVITY = 9.80665        # m/s², a record in g (docs/scene-input.md "Time functions")


@dataclass
class TimeFunction:
    """f(t) of docs/scene-input.md "Time functions", with the instants where it is not
    smooth (the engine restarts there, so no kink sits inside a step)."""
    kind: str
    params: dict
    breaks: list = field(default_factory=list)
    table: tuple | None = None

    def __call__(self, t):
        p, k = self.params, self.kind
        if k == "zero":
            return 0.0
        if k == "constant":
            return p["value"]
        if k == "sine":
            return p["amplitude"] * math.sin(p["omega"] * (t - p["t_start"]) + p["phase"]) \
                if p["t_start"] <= t <= p["t_end"] else 0.0
        if k == "rectangular":
            return p["amplitude"] if p["t_start"] <= t < p["t_end"] else 0.0
        if k == "half_sine":
            t0, t1 = p["t_start"], p["t_end"]
            return p["amplitude"] * math.sin(math.pi * (t - t0) / (t1 - t0)) if t0 <= t <= t1 else 0.0
        ts, vs = self.table
        if t < ts[0] or t > ts[-1]:
            return 0.0
        return p["scale"] * float(np.interp(t, ts, vs))


def _read_csv_record(path: Path, units):
    """Two columns (time, acceleration), '#' comments, one optional text header; a
    '# units: g|m/s2|cm/s2' comment states the file's units (docs/scene-input.md)."""
    ts, vs, file_units = [], [], None
    for line in path.read_text(encoding="latin-1").splitlines():
        s = line.strip()
        if not s:
            continue
        if s.startswith("#"):
            body = s[1:].strip()
            if body.lower().startswith("units"):
                file_units = body.split(":", 1)[1].strip().lower() if ":" in body else \
                    body.split("=", 1)[1].strip().lower()
            continue
        parts = s.replace(",", " ").split()
        try:
            t, a = float(parts[0]), float(parts[1])
        except ValueError:
            continue                    # the header line
        ts.append(t)
        vs.append(a)
    used = _UNITS.get((units or file_units or "m/s2").lower())
    if used is None:
        raise Unsupported(f"record {path}: units {units or file_units!r}")
    factor = {"g": STANDARD_GRAVITY, "m/s2": 1.0, "cm/s2": 0.01}[used]
    return np.array(ts), np.array(vs) * factor


_UNITS = {"g": "g", "m/s2": "m/s2", "cm/s2": "cm/s2", "m/s^2": "m/s2", "gal": "cm/s2", "m/s/s": "m/s2",
          "cm/s/s": "cm/s2", "cm/sec2": "cm/s2", "m/sec2": "m/s2"}


def _read_at2_record(path: Path, units):
    """A PEER NGA .AT2 acceleration file (docs/scene-input.md "record"): a title, an event
    line, the units line (`... IN UNITS OF G`), NPTS and DT on the fourth line (`NPTS= 5590,
    DT= .0050 SEC` or the old `5590 .0050 NPTS, DT`), then the values; t = i DT. The file's
    units win over the scene's."""
    lines = path.read_text(encoding="latin-1").splitlines()
    m = re.search(r"UNITS?\s+(?:OF\s+)?(\S+)", lines[2], re.IGNORECASE)
    used = _UNITS.get(m.group(1).lower() if m else (units or "").lower())
    if used is None:
        raise Unsupported(f"record {path}: units {m.group(1) if m else units!r}")
    head = lines[3]
    fixed = re.match(r"\s*(\S+)\s+(\S+)\s+NPTS\s*,?\s*DT\b", head, re.IGNORECASE)
    if fixed:
        npts, dt = int(float(fixed.group(1))), float(fixed.group(2))
    else:
        npts = int(float(re.search(r"NPTS\s*=\s*([^\s,]+)", head, re.IGNORECASE).group(1)))
        dt = float(re.search(r"DT\s*=\s*([^\s,]+)", head, re.IGNORECASE).group(1))
    values = np.array([float(x) for line in lines[4:] for x in line.split()])
    if len(values) != npts:
        raise Unsupported(f"record {path}: NPTS = {npts}, {len(values)} values")
    factor = {"g": STANDARD_GRAVITY, "m/s2": 1.0, "cm/s2": 0.01}[used]
    return np.arange(npts) * dt, values * factor


def time_function(fn, base: Path | None) -> TimeFunction:
    if fn is None:
        return TimeFunction("zero", {})
    kind = fn["type"]
    p = dict(fn)
    if kind == "constant":
        return TimeFunction(kind, p)
    if kind in ("sine", "rectangular", "half_sine"):
        p.setdefault("phase", 0.0)
        p.setdefault("t_start", 0.0)
        p.setdefault("t_end", 1e300)
        return TimeFunction(kind, p, [p["t_start"], p["t_end"]])
    if kind in ("table", "record"):
        if kind == "table":
            ts, vs = np.array(p["t"], float), np.array(p["values"], float)
        else:
            path = Path(p["file"])
            if not path.is_absolute():
                path = (base or Path.cwd()) / path
            fmt = (p.get("format") or path.suffix.lstrip(".")).lower()
            if fmt in ("at2", "peer"):
                ts, vs = _read_at2_record(path, p.get("units"))
            elif fmt in ("csv", "txt"):
                ts, vs = _read_csv_record(path, p.get("units"))
            else:
                raise Unsupported(f"ground-motion record format {fmt!r} (AT2 and CSV)")
        p.setdefault("scale", 1.0)
        return TimeFunction("table", p, list(ts), (ts, vs))
    raise Unsupported(f"time function {kind!r}")


def _per_item(value, n, key):
    if isinstance(value, list):
        if len(value) != n:
            raise Unsupported(f"chain.{key}: {len(value)} values for {n} items")
        return list(value)
    return [value] * n


def expand_chains(doc: dict) -> dict:
    """docs/scene-input.md "[[chain]]": n oscillators in a row, appended after the written
    entries."""
    nodes, links, contacts = list(doc.get("node", [])), list(doc.get("link", [])), \
        list(doc.get("contact", []))
    for ch in doc.get("chain", []):
        n, p = ch["n"], ch["prefix"]
        mass, k = _per_item(ch["mass"], n, "mass"), _per_item(ch["k"], n, "k")
        fy = _per_item(ch.get("fy"), n, "fy")
        rho = _per_item(ch.get("hardening", 0.0), n, "hardening")
        zeta = _per_item(ch.get("zeta", 0.0), n, "zeta")
        u0, v0 = _per_item(ch.get("u0", 0.0), n, "u0"), _per_item(ch.get("v0", 0.0), n, "v0")
        gaps = _per_item(ch.get("gap", 0.0), n - 1, "gap") if n > 1 else []
        for i in range(n):
            name = f"{p}{i + 1}"
            nodes.append({"name": name, "mass": mass[i], "u0": u0[i], "v0": v0[i]})
            if fy[i] is None:
                links.append({"name": f"{name}.spring", "type": "spring", "a": name, "b": "ground", "k": k[i]})
            else:
                links.append({"name": f"{name}.spring", "type": "bilinear", "a": name, "b": "ground",
                              "k": k[i], "fy": fy[i], "hardening": rho[i]})
            if zeta[i] and zeta[i] > 0:
                links.append({"name": f"{name}.damper", "type": "dashpot", "a": name, "b": "ground",
                              "c": 2.0 * zeta[i] * math.sqrt(k[i] * mass[i])})
        if "contact" in ch:
            for i in range(n - 1):
                links_c = dict(ch["contact"])
                links_c.update(name=f"{p}{i + 1}-{p}{i + 2}", a=f"{p}{i + 1}", b=f"{p}{i + 2}", gap=gaps[i])
                contacts.append(links_c)
    out = dict(doc)
    out.update(node=nodes, link=links, contact=contacts)
    out.pop("chain", None)
    return out


@dataclass
class Model:
    """The mechanics of a scene as arrays (docs/problems.md P7 eq. 7 without the matrices)."""
    title: str
    names: list
    mass: np.ndarray
    fixed: np.ndarray
    u0: np.ndarray
    v0: np.ndarray
    springs: list            # (name, a, b, k)
    dashpots: list           # (name, a, b, c)
    bilinears: list          # (name, a, b, k, fy, rho)
    dampers: list            # (name, a, b, c, alpha, v_reg); a, b unused for a row's
    contacts: list           # ContactLaw
    gravity: float
    ground: TimeFunction
    forces: list             # (node index, TimeFunction)
    t_end: float
    blocks: list = field(default_factory=list)   # (name, node indices, K, C): [[frame]], [[building]]
    damper_rows: list = field(default_factory=list)   # each damper's [(node index, coefficient)]
    influence: np.ndarray | None = None          # the ground motion's share on each node (1)

    @property
    def breaks(self):
        bs = set(self.ground.breaks)
        for _, f in self.forces:
            bs.update(f.breaks)
        return sorted(b for b in bs if 0.0 < b < self.t_end)


def effective_mass(mass, fixed, terms):
    """m* = 1/Σ c²/m over the contact's row on its free nodes: m_a m_b/(m_a + m_b) for a
    node pair (docs/problems.md P5), 1/(1/m1 + r1²/J1 + 1/m2 + r2²/J2) between points of two
    rigid floors (docs/buildings.md); a ground or fixed side is infinitely heavy."""
    w = sum(c * c / mass[i] for i, c in terms if i != GROUND and not fixed[i])
    return math.inf if w == 0.0 else 1.0 / w


def contact_terms(c: dict, idx: dict, buildings=(), direction="normal") -> list:
    """An element's row [(node index, coefficient)] (docs/scene-input.md "[[contact]]"): its
    terms; (a, +1), (b, −1) of a node pair, GROUND kept (its displacement is 0); or, where a
    side is a plan point of a building's rigid floor, n·u(P_a) − n·u(P_b) along the plan
    direction n (docs/buildings.md "Contacts between plan points")."""
    if "terms" in c:
        return [(idx[t["node"]], float(t["coef"])) for t in c["terms"]]
    if not (isinstance(c["a"], dict) or isinstance(c["b"], dict)):
        return [(idx[c["a"]], 1.0), (idx[c["b"]], -1.0)]
    nx, ny = c.get(direction) or (1.0, 0.0)
    norm = math.hypot(nx, ny)
    n = (nx / norm, ny / norm)
    terms = {}
    for side, sign in ((c["a"], 1.0), (c["b"], -1.0)):
        part = point_terms(side, buildings, idx, n, sign) if isinstance(side, dict) else \
            ([] if side == "ground" else [(idx[side], sign)])
        for i, cf in part:
            terms[i] = terms.get(i, 0.0) + cf
    return [(i, cf) for i, cf in terms.items() if cf != 0.0]


def model_from_dict(doc: dict, base: Path | None = None, t_end: float | None = None) -> Model:
    doc = expand_chains(doc)
    if doc.get("mass_coupling") or doc.get("bar"):
        raise Unsupported("bars and mass couplings (the engine takes a diagonal mass matrix)")
    frames = [frame_block(tab) for tab in doc.get("frame", [])]
    buildings = [building_block(tab) for tab in doc.get("building", [])]
    if frames or buildings:
        doc = dict(doc)
        doc["node"] = list(doc.get("node", [])) + [{"name": nm, "mass": float(mm)} for fb in frames + buildings
                                                    for nm, mm in zip(fb.nodes, fb.mass)]
    an = doc.get("analysis", {})
    if an.get("type") != "dynamic" and t_end is None:
        raise Unsupported("a static analysis")
    nodes = doc["node"]
    names = [nd["name"] for nd in nodes]
    idx = {nm: i for i, nm in enumerate(names)}
    idx["ground"] = GROUND
    mass = np.array([float(nd["mass"]) for nd in nodes])
    fixed = np.array([bool(nd.get("fixed", False)) for nd in nodes])
    u0 = np.array([float(nd.get("u0", 0.0)) for nd in nodes])
    v0 = np.array([0.0 if nd.get("fixed", False) else float(nd.get("v0", 0.0)) for nd in nodes])
    springs, dashpots, bilinears, dampers = [], [], [], []
    to_ground_k = np.zeros(len(nodes))
    raw = doc.get("link", [])
    damper_rows = []

    def is_row(lk):
        return "terms" in lk or isinstance(lk.get("a"), dict) or isinstance(lk.get("b"), dict)
    for i, lk in enumerate(raw):
        if is_row(lk):
            if lk["type"] != "fluid_damper":
                raise Unsupported(f"link {lk.get('name', '?')}: a {lk['type']} between plan points or "
                                  "with terms (the engine takes fluid dampers there)")
            damper_rows.append(contact_terms(lk, idx, buildings, "direction"))
            dampers.append((lk.get("name", f"link{i}"), GROUND, GROUND, float(lk["c"]),
                            float(lk.get("alpha", 1.0)), float(lk.get("v_reg", 1e-6))))
    for i, lk in enumerate(raw):
        if is_row(lk):
            continue
        a, b = idx[lk["a"]], idx[lk["b"]]
        kind = lk["type"]
        k = {"spring": lambda: lk["k"], "bar": lambda: lk["EA"] / lk["L"],
             "bilinear": lambda: lk["k"]}.get(kind, lambda: 0.0)()
        if GROUND in (a, b) and k:
            to_ground_k[a if a != GROUND else b] += k
    for i, lk in enumerate(raw):
        if is_row(lk):
            continue
        name = lk.get("name", f"link{i}")
        a, b = idx[lk["a"]], idx[lk["b"]]
        kind = lk["type"]
        if kind == "spring":
            springs.append((name, a, b, float(lk["k"])))
        elif kind == "bar":
            springs.append((name, a, b, lk["EA"] / lk["L"]))
        elif kind == "dashpot":
            if "c" in lk:
                c = float(lk["c"])
            else:                       # c = 2ζ√(k m) of the node's springs to ground
                j = a if a != GROUND else b
                c = 2.0 * lk["zeta"] * math.sqrt(to_ground_k[j] * mass[j])
            dashpots.append((name, a, b, c))
        elif kind == "bilinear":
            bilinears.append((name, a, b, float(lk["k"]), float(lk["fy"]), float(lk.get("hardening", 0.0))))
        elif kind == "fluid_damper":
            damper_rows.append([(a, 1.0), (b, -1.0)])
            dampers.append((name, a, b, float(lk["c"]), float(lk.get("alpha", 1.0)), float(lk.get("v_reg", 1e-6))))
        else:
            raise Unsupported(f"link type {kind!r}")
    contacts = []
    for c in doc.get("contact", []):
        terms = contact_terms(c, idx, buildings)
        contacts.append(contact_law(c, terms, effective_mass(mass, fixed, terms)))
    blocks = [(fb.name, np.array([idx[nm] for nm in fb.nodes]), fb.K, fb.C) for fb in frames + buildings]
    influence = np.ones(len(nodes))
    for bb in buildings:
        influence[[idx[nm] for nm in bb.nodes]] = bb.influence
    loads = doc.get("loads", {})
    forces = []
    for f in loads.get("force", []):
        fn = f.get("function", {"type": "constant", "value": f.get("value", 0.0)})
        forces.append((idx[f["node"]], time_function(fn, base)))
    return Model(title=doc.get("title", "<scene>"), names=names, mass=mass, fixed=fixed, u0=u0, v0=v0,
                 springs=springs, dashpots=dashpots, bilinears=bilinears, dampers=dampers,
                 contacts=contacts, gravity=float(loads.get("gravity", 0.0)),
                 ground=time_function(loads.get("ground_acceleration"), base), forces=forces,
                 t_end=float(t_end if t_end is not None else an["t_end"]), blocks=blocks,
                 damper_rows=damper_rows, influence=influence)


def load_model(scene, t_end: float | None = None, contact: dict | None = None,
               base: Path | None = None) -> Model:
    """A scene path, TOML text or dict as a Model; `contact` overrides every contact's
    scheme keys (as a study's variant does); `t_end` the end time; `base` the folder a
    dict's or text's record files are relative to (a path's: its own folder)."""
    if isinstance(scene, (str, Path)) and Path(scene).suffix == ".toml" and Path(scene).exists():
        base = Path(scene).resolve().parent
        doc = tomllib.loads(Path(scene).read_text())
        doc.setdefault("title", Path(scene).stem)
    elif isinstance(scene, str):
        doc = tomllib.loads(scene)
    else:
        doc = dict(scene)
    if contact is not None:
        doc = expand_chains(doc)
        keep = ("name", "a", "b", "gap")
        doc["contact"] = [{**{k: c[k] for k in keep if k in c}, **contact} for c in doc["contact"]]
    return model_from_dict(doc, base, t_end)


__all__ = ["Model", "Unsupported", "TimeFunction", "ContactLaw", "FrameBlock", "load_model",
           "model_from_dict", "effective_mass", "expand_chains", "GROUND"]
