"""Hostile inputs for martello, made by mutating the catalogue: scenes, records, histories,
check tables and command lines. Shared by the fuzz campaign (benchmarks/fuzz/campaign.py,
pseudo-random) and the property-based test (tests/test_fuzz.py, Hypothesis), through a
`chooser` that draws every decision: an object with

    choice(seq) -> one element       integer(lo, hi) -> lo <= n <= hi       coin(p) -> bool

so the same mutations are drawn from random.Random in the campaign and from Hypothesis'
data.draw in the test (where a failing case then shrinks). Every case is a `Case`: the
command line, the files to lay out in a fresh folder first, and the output path that must
hold nothing if the command fails. The hostile values are those the issue lists (huge
integers in float fields, scalars for tables, nested lists, denormals, deep nesting,
directories, devices and FIFOs for files, -o naming a file, NPTS=1e400, 1e999, paths out of
the scene's folder, non-UTF-8 bytes, -j -3, h_max = 1e-12) and their relatives."""

from __future__ import annotations

import copy
import json
import math
import re
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
BENCHMARKS = ROOT / "benchmarks"
RECORDS = sorted((ROOT / "tests" / "data" / "records").glob("peer_*")) + \
    [BENCHMARKS / "p8" / "records" / "opcm3274_z2_C_1.csv"]

# Scenes quick enough to run many times (< 1 s each); the big ones are loaded, not run.
QUICK = ["p1/p1_static_lagrange", "p1/p1_static_penalty", "p1/p1_static_augmented",
         "p3/p3_static_lagrange", "p2/p2_restitution_e08", "p2/p2_ida_restitution",
         "p2/p2_ida_penalty_linear", "p5/p5_linear", "p5/p5_hertz", "p5/p5_newton_e03",
         "p5/p5_ida_linear", "p5/p5_moreau_jean_e03", "p5/p5_newmark_lagrange_e03",
         "p5/p5_kelvin", "p6/p6_elastoplastic_rho005", "p7/p7_chain_10",
         "p4/p4_wall_cd_half_cell_courant1", "p4/p4_equal_rods_rk8pd_restitution_e0",
         "p9/p9_davis_restitution", "sdof/sdof_sine_newmark",
         # the features of later sessions: CVODE/ARKODE with events inside the steps, fast
         # nonlinear analysis (modal_vectors), [[building]] (P11); each under 3 s
         "p2/p2_cvode_restitution", "p2/p2_arkode_lagrange", "p7/laws/p7_two_kelvin_arkode",
         "p7/laws/p7_two_linear_cvode", "sdof/sdof_sine_fast_nonlinear",
         "p6/integrators/p6_rho005_fast_nonlinear", "p11/p11_shear_pounding"]


def scene_dict(name):
    return tomllib.loads((BENCHMARKS / f"{name}.toml").read_text())


@dataclass(frozen=True)
class Deep:
    """An array nested `depth` levels around one value, written as TOML text directly (as a
    Python list it would exhaust the writer's recursion)."""
    depth: int
    leaf: object = 1.0


# --- a TOML writer: every table inline, one `key = value` line per top-level key ----------

_BARE = re.compile(r"[A-Za-z0-9_-]+")


def _key(k):
    return k if _BARE.fullmatch(k) else json.dumps(k)


def toml_value(v):
    """A value as TOML text; tables inline (also tests/test_behaviour.py's writer)."""
    if isinstance(v, Deep):
        return "[" * v.depth + toml_value(v.leaf) + "]" * v.depth
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v)
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{_key(str(k))} = {toml_value(x)}" for k, x in v.items()) + "}"
    return json.dumps(str(v))


def to_toml(d):
    if not isinstance(d, dict):
        return f"x = {toml_value(d)}\n"
    return "".join(f"{_key(str(k))} = {toml_value(v)}\n" for k, v in d.items())


# --- values ---------------------------------------------------------------------------------

HUGE_INT = 10 ** 400
NUMBERS = [0, -1, 0.0, -0.0, 1e-320, 5e-324, 1e-310, 1e-300, 1e-12, 1e308, -1e308, 1e300,
           2 ** 31, 2 ** 40, 2 ** 63 - 1, -2 ** 63, HUGE_INT, -HUGE_INT, float("nan"),
           float("inf"), -float("inf"), 1e12, 0.5, 3, 1e-7]
OTHERS = ["", "x", "ground", "nan", "1e999", "../../etc/passwd", "/dev/zero", "a" * 300,
          "\u00e9\u2603", "\u0000", True, False, [], [1.0], [[1.0]], [["m1"]], {}, {"type": "sine"},
          {"a": {"b": {"c": 1}}}]


def _leaves(obj, path=()):
    """(path, value) of every leaf and container of a parsed scene."""
    out = [(path, obj)]
    if isinstance(obj, dict):
        for k, v in obj.items():
            out += _leaves(v, path + (k,))
    elif isinstance(obj, list):
        for i, v in enumerate(obj):
            out += _leaves(v, path + (i,))
    return out


def _set(root, path, value):
    node = root
    for p in path[:-1]:
        node = node[p]
    node[path[-1]] = value


def _delete(root, path):
    node = root
    for p in path[:-1]:
        node = node[p]
    del node[path[-1]]


def _nested(depth, leaf=1.0):
    return Deep(depth, leaf)


def hostile_value(ch, old=None):
    """A value to put where `old` was."""
    kind = ch.integer(0, 9)
    if kind <= 3:
        return ch.choice(NUMBERS)
    if kind <= 5:   # a copy: a later edit of the scene must not change the shared constants
        return copy.deepcopy(ch.choice(OTHERS))
    if kind == 6 and isinstance(old, (int, float)) and not isinstance(old, bool):
        factor = ch.choice([-1, 0, 1e-300, 1e-9, 1e9, 1e300])
        try:
            return old * factor
        except OverflowError:      # an earlier edit left an integer beyond any float
            return old
    if kind == 7:
        return _nested(ch.choice([3, 20, 100, 2000]))
    if kind == 8 and old is not None:
        return [old, old]
    return ch.choice([5, "5", [5], {"x": 5}])


def mutate_dict(ch, d, edits=None):
    """1 to 3 edits of a parsed scene: replace, delete, add a key, duplicate an item."""
    d = copy.deepcopy(d)
    for _ in range(edits or ch.integer(1, 3)):
        spots = _leaves(d)[1:]
        if not spots:
            break
        path, old = ch.choice(spots)
        op = ch.integer(0, 9)
        try:
            if op <= 5:
                _set(d, path, hostile_value(ch, old))
            elif op == 6:
                _delete(d, path)
            elif op == 7 and isinstance(old, dict):
                old[ch.choice(["extra", "mass", "type", "n", "file", "every", "h_max"])] = \
                    hostile_value(ch)
            elif op == 8 and isinstance(old, list) and old:
                old.append(copy.deepcopy(old[0]))
            else:
                _set(d, path, hostile_value(ch, old))
        except (KeyError, IndexError, TypeError):
            pass
    return d


# targeted edits: the issue's causes, each a function of a parsed scene
def _analysis(d):
    a = d.get("analysis")
    return a if isinstance(a, dict) else d.setdefault("analysis", {})


# --- the features added since the first campaigns: an integrator's own keys, buildings ---

# the keys every dynamic integrator reads; switching integrator keeps only these, so that the
# edit reaches the new integrator's own key instead of stopping at another's
_COMMON = ("type", "dt", "t_end", "output", "max_steps", "max_wall")


def _switch(d, integrator, **keys):
    a = _analysis(d)
    if a.get("integrator") != integrator:
        for k in [k for k in a if k not in _COMMON]:
            del a[k]
        a.update(type="dynamic", integrator=integrator)
        a.setdefault("dt", 1e-3)
        a.setdefault("t_end", 0.01)
    a.update(keys)


def _method_names(integrator=None):
    """The table methods of `integrator` (default: CVODE's and ARKODE's) by name (the
    library's registry), read when a case needs them (not at import)."""
    from martello.scene.spec import METHODS
    return sorted(set(METHODS.get(integrator, ())) if integrator else
                  set(METHODS.get("cvode", ())) | set(METHODS.get("arkode", ())))


BAD_METHODS = ["", "BDF", "Adams", "dormand-prince", "kvaerno-5-3-4 ", "sdirk-2-1-2\u0000",
               "x" * 300, 0, 1, -1, 2 ** 31, 1.5, True, ["bdf"], {"name": "bdf"}, "none", "default"]
LENGTHS = [1e300, 1e-300, 1e308, 5e-324, 0.0, -1.0, float("nan"), float("inf"), 1e-12, 1e12]


def _building_edit(d, ch):
    """A [[building]] of P11 (its shear-type pair, or the one-storey eccentric storey) with
    one field, or one field of a section, member or split, replaced by a hostile value."""
    src = scene_dict(ch.choice(["p11/p11_shear_pounding", "p11/p11_eccentric_storey"]))
    b = copy.deepcopy(src["building"][0])
    spots = [p for p, _ in _leaves(b)[1:]]
    path = ch.choice(spots)
    value = ch.choice(LENGTHS + [[1e308, 1e308], [0.0], [], "x", Deep(20), {"E": 1.0}])
    old = b
    for k in path:
        old = old[k]
    if isinstance(old, float) and ch.coin(0.5):         # in range, far from the catalogue's
        value = old * ch.choice([1e-6, 1e-3, 0.5, 2.0, 1e3, 1e6])
    if ch.coin(0.2):
        _delete(b, path)
    else:
        _set(b, path, copy.deepcopy(value))
    extra = ch.choice([None, None, "diaphragm", "slab", "split", "point", "model", "damping"])
    if extra == "diaphragm":
        b["diaphragm"] = ch.choice([False, [False], [True, False, True], "no", 0])
    elif extra == "slab":
        b.update(diaphragm=False, slab=ch.choice([{"E": 3e10, "thickness": ch.choice(LENGTHS)},
                                                   {"E": 3e10}, {}, 5]))
    elif extra == "split":
        b["split"] = [{"name": "s", "line": ch.choice(["0.0", "9.9", ""]), "storey": ch.choice(
            [1, 0, 99, 2 ** 40]), "height": ch.choice(LENGTHS), "mass": ch.choice(LENGTHS)}]
    elif extra == "point":
        b["point"] = [{"name": "p", "floor": ch.choice([1, 0, 99]), "x": ch.choice(LENGTHS),
                       "y": 0.0}]
    elif extra == "model":
        b.update(model=ch.choice(["frame", "shear", "x"]), beam=ch.choice(
            [{"E": 3e10, "b": 0.3, "h": ch.choice(LENGTHS)}, None, False]))
    elif extra == "damping":
        b.update(damping=ch.choice(["modal", "rayleigh", "x"]), zeta=ch.choice([0.05, 0.0, 0.99, 1.0, -0.1]),
                 rayleigh_modes=ch.choice([[1, 2], [1, 99], [0, 1], [2 ** 40, 1], [1]]))
    d["building"] = [b] + (copy.deepcopy(src["building"][1:]) if ch.coin(0.5) else [])
    for k in ("node", "link", "contact", "frame", "chain", "bar", "mass_coupling"):
        if k in src:
            d[k] = copy.deepcopy(src[k])
        else:
            d.pop(k, None)


TARGETED = {
    "scalar loads": lambda d, ch: d.__setitem__("loads", ch.choice([5, "g", [1.0], True])),
    "nested output nodes": lambda d, ch: _analysis(d).setdefault("output", {}).__setitem__(
        "nodes", ch.choice([[["m1"]], [[[]]], [{"a": 1}], [1], "m1"])),
    "huge int in a float field": lambda d, ch: d.setdefault("node", [{}])[0].__setitem__(
        ch.choice(["mass", "u0", "v0"]), ch.choice([HUGE_INT, 2 ** 64, -2 ** 70])),
    "every huge": lambda d, ch: _analysis(d).setdefault("output", {}).__setitem__(
        "every", ch.choice([2 ** 40, 2 ** 31, 2 ** 63 - 1, -2 ** 31, 0])),
    "h_max tiny": lambda d, ch: _analysis(d).update(h_max=ch.choice([1e-12, 1e-300, 5e-324])),
    "dt tiny": lambda d, ch: _analysis(d).update(dt=ch.choice([1e-12, 1e-15, 1e-320])),
    "t_end huge": lambda d, ch: _analysis(d).update(t_end=ch.choice([1e9, 1e300, 1e15])),
    "chain n huge": lambda d, ch: d.update(chain=[{"prefix": "p", "n": ch.choice(
        [10 ** 9, 2 ** 31 - 1, 10 ** 7, 2 ** 62]), "mass": 1.0, "k": 1.0}]),
    "bar elements huge": lambda d, ch: d.update(bar=[{"name": "A", "L": 1.0, "EA": 1.0,
                                                        "rhoA": 1.0, "elements": ch.choice(
                                                            [10 ** 9, 10 ** 7, 2 ** 31 - 1])}]),
    "denormal bar density": lambda d, ch: d.update(bar=[{"name": "A", "L": 1.0, "E": 2e11,
                                                           "A": ch.choice([1e-4, 1e-200]),
                                                           "rho": ch.choice([1e-310, 5e-324, 1e-200]),
                                                           "elements": 4}]),
    "deep nesting": lambda d, ch: d.update(description=_nested(ch.choice([20, 500, 5000]), "x")),
    "check path to a non-number": lambda d, ch: d.update(check={
        "closed_form": ch.choice(["two_body_impact", "no_such_form", "print"]),
        "params": ch.choice([{}, {"law": "linear"}, {"m1": "x"}, {"law": [1]}]),
        "compare": [{"result": ch.choice(["contacts", "nodes", "contacts.impact", "title",
                                          "provenance.libraries", "cost"]),
                     "oracle": ch.choice(["restitution", "contact_time", "nope"]),
                     "rtol": 1e-3, "why": "fuzz"}]}),
    # a later review's findings: lengths and products past the doubles
    "frame lengths past the doubles": lambda d, ch: d.update(frame=[dict(
        _P10_FRAME, prefix="fz", **{ch.choice(["bay_width", "storey_height"]):
                                    ch.choice([1e300, 1e-300, 1e200, 5e-324])})]),
    "chain damping overflow": lambda d, ch: d.update(chain=[{
        "prefix": "q", "n": 3, "mass": ch.choice([1e5, 1e300]), "k": ch.choice([1e308, 1e300, 1e-300]),
        "zeta": ch.choice([0.05, 9.0])}]),
    "record path": lambda d, ch: d.setdefault("loads", {}).__setitem__(
        "ground_acceleration", {"type": "record", "file": ch.choice(
            ["../../etc/passwd", "/dev/zero", "fifo.csv", ".", "records", "missing.AT2",
             "/proc/self/status", "\u0000x.csv", "x" * 5000, "record.AT2", "record.csv"]),
                                **ch.choice([{}, {"format": "csv"}, {"format": "at2"},
                                             {"format": "wav"}, {"units": "furlongs"}])}),
    # later features
    "modal vectors": lambda d, ch: _switch(d, "fast-nonlinear", modal_vectors=ch.choice(
        [-1, 0, 1, 2, 3, 7, 10 ** 6, 2 ** 31, 2 ** 63 - 1, HUGE_INT, 1.5, 2.0, "2", True,
         float("nan"), [2]])),
    "integrator method": lambda d, ch: _switch(d, (i := ch.choice(["cvode", "arkode"])), method=ch.choice(
        _method_names(i) if ch.coin(0.6) else _method_names() + BAD_METHODS), **ch.choice([{}, {"rtol": ch.choice([1e-300, 1.0, 0.0, 1e-3])},
                                                  {"atol": ch.choice([1e-300, 0.0, 1e300])},
                                                  {"event_tol": ch.choice([1e-300, 1.0, 0.0])},
                                                  {"h_max": ch.choice([1e-9, 0.0, 1e300])}])),
    "building fields": _building_edit,
}


# a planar frame's table ([[frame]] of P10), to place with extreme dimensions
_P10_FRAME = {k: v for k, v in scene_dict("p10/p10_bare")["frame"][0].items() if k != "prefix"}


def mutate_text(ch, text):
    """Byte-level damage to a scene or record file."""
    b = bytearray(text.encode("utf-8", "surrogatepass"))
    op = ch.integer(0, 5)
    if op == 0 and b:
        del b[ch.integer(0, len(b) - 1):]                          # truncated
    elif op == 1 and b:
        b[ch.integer(0, len(b) - 1)] = ch.choice([0xff, 0xc3, 0x00, 0x22, 0x5b, 0x0a])
    elif op == 2:
        b[ch.integer(0, len(b)):0] = ch.choice([b"\xff\xfe", b"[[[[", b"= =", b"\x00", b"\"\"\"",
                                               b"\n[analysis]\n", b"\r"])
    elif op == 3:
        b += b"\n" + b"x = " + b"[" * 5000 + b"]" * 5000 + b"\n"
    elif op == 4 and b:
        i = ch.integer(0, len(b) - 1)
        b[i:i + 1] = b[i:i + 1] * ch.choice([2, 1000])
    else:
        b = bytearray(re.sub(rb"\d+\.\d+|\d+", lambda m: ch.choice(
            [b"1e999", b"nan", b"1e400", b"-0", b"1" * 400, m.group(0)]), bytes(b), count=3))
    return bytes(b)


def mutate_record(ch, text):
    """A damaged record: a value 1e999 or NaN, NPTS=1e400, lines lost or swapped, junk."""
    lines = text.split("\n")
    op = ch.integer(0, 6)
    i = ch.integer(0, max(len(lines) - 1, 0))
    if op == 0:
        lines[i] = re.sub(r"-?\d+\.\d+(E[-+]\d+)?", ch.choice(["1e999", "nan", "inf", "1d999", "x"]),
                          lines[i], count=1)
    elif op == 1:
        lines = [re.sub(r"NPTS\s*=\s*\d+|^\s*\d+(?=\s+\.\d+\s+NPTS)", ch.choice(
            ["NPTS=1e400", "NPTS=-5", "NPTS=1e30", "NPTS=2.5", "NPTS=0"]), ln) for ln in lines]
    elif op == 2 and len(lines) > 2:
        del lines[i]
    elif op == 3 and len(lines) > 6:
        lines[i], lines[-2] = lines[-2], lines[i]
    elif op == 4:
        lines.insert(i, ch.choice(["root:x:0:0:root:/root:/bin/bash", "\x00\x01", "1,2,3",
                                   "# units: furlongs", "DT= 1e-320"]))
    elif op == 5:
        lines = lines[:ch.integer(0, 6)]
    else:
        return mutate_text(ch, text)
    return "\n".join(lines).encode("utf-8", "surrogatepass")


# --- cases ------------------------------------------------------------------------------------

@dataclass
class Case:
    label: str
    argv: list                      # after `martello`
    files: dict = field(default_factory=dict)   # relative path -> bytes, or "fifo", or "dir"
    output: str | None = None       # what must not exist after a failure


def _record_files(ch):
    src = ch.choice(RECORDS)
    text = src.read_text()
    ext = src.suffix
    data = mutate_record(ch, text) if ch.coin(0.7) else text.encode()
    return {f"record{ext}": data, "record.AT2" if ext != ".AT2" else "record.csv": data}


# the targeted edits and quick scenes of the features added since the first campaigns
LATER_TARGETS = ["modal vectors", "integrator method", "building fields"]
LATER_QUICK = QUICK[QUICK.index("p2/p2_cvode_restitution"):]


def later_scene_case(ch):
    """scene_case on the later features only: their scenes mutated, or their targeted edits."""
    return scene_case(ch, LATER_QUICK, LATER_TARGETS)


def scene_case(ch, scenes=QUICK, targets=None):
    name = ch.choice(scenes)
    d = scene_dict(name)
    files = {"fifo.csv": "fifo", "records": "dir", "etc/passwd":
             b"root:x:0:0:root:/root:/bin/bash\nsecret:x:1:1:the secret line:/home/s:/bin/sh\n"}
    how = ch.integer(0, 9)
    if how <= 3:
        d = mutate_dict(ch, d)
        label = "mutated scene"
    elif how <= 7:
        label = ch.choice(targets or sorted(TARGETED))
        try:
            TARGETED[label](d, ch)
        except (AttributeError, TypeError, IndexError, KeyError):
            pass
        if label == "record path" or ch.coin(0.2):
            files.update(_record_files(ch))
    else:
        label = "damaged text"
    text = to_toml(d).encode("utf-8", "surrogatepass")
    if how >= 8:
        text = mutate_text(ch, text.decode("utf-8", "surrogatepass"))
    files["a/b/scene.toml"] = text
    # the scene sits two folders down, so ../../etc/passwd is the case's own etc/passwd
    files = {("a/b/" + k if k not in ("etc/passwd", "a/b/scene.toml") else k): v
             for k, v in files.items()}
    out = ch.choice(["out/run", "out/run", "out/run", "afile", "afile/sub", "out/nonempty"])
    if out == "afile" or out == "afile/sub":
        files["afile"] = b"not a folder\n"
    if out == "out/nonempty":
        files["out/nonempty/notes.txt"] = b"keep me\n"
    argv = ["run", "a/b/scene.toml", "-o", out]
    if ch.coin(0.1):
        argv.append("--print")
    return Case(f"run: {label}", argv, files, out if out != "out/nonempty" else None)


def path_case(ch):
    """The scene path itself is hostile: a directory, /dev/zero, a FIFO, missing."""
    target = ch.choice([".", "/dev/zero", "fifo.toml", "missing.toml", "/dev/null", "/proc/self/mem",
                        "\u00e9.toml", "a" * 5000])
    return Case(f"run: scene path {target[:20]}", ["run", target, "-o", "out/run"],
                {"fifo.toml": "fifo"}, "out/run")


def check_case(ch):
    d = scene_dict(ch.choice(["p5/p5_linear", "p1/p1_static_lagrange", "p2/p2_restitution_e08"]))
    TARGETED["check path to a non-number"](d, ch) if ch.coin(0.6) else None
    d = mutate_dict(ch, d, 1) if ch.coin(0.3) else d
    files = {"s.toml": to_toml(d).encode("utf-8", "surrogatepass")}
    return Case("check: hostile check table", ["check", "s.toml", str(BENCHMARKS / "p1" /
                                                                      "p1_static_lagrange.toml"),
                                               "-o", "out/check", "--no-plots"], files, None)


HISTORY = "t,u:m1,u:m2,v:m1,v:m2\n" + "".join(
    f"{t:.6g},{min(t, 1e-3):.6g},0,{1.0 if t < 1e-3 else 0.0},0\n" for t in
    [i * 1e-4 for i in range(50)])


def compare_case(ch):
    text = HISTORY
    op = ch.integer(0, 5)
    data = text.encode()
    if op == 0:
        data = text.encode("utf-16")
    elif op == 1:
        data = text.encode().replace(b"0.0001", b"\xff\xfe", 1)
    elif op == 2:
        data = mutate_record(ch, text)
    elif op == 3:
        data = text.replace("t,", "time,").encode()
    elif op == 4:
        data = mutate_text(ch, text)
    against = ch.choice(["p5/p5_linear.toml", "a/b/scene.toml"])
    files = {"h.csv": data, "fifo.csv": "fifo"}
    if against.startswith("a/"):
        files[against] = to_toml(mutate_dict(ch, scene_dict("p5/p5_linear"), 1)).encode(
            "utf-8", "surrogatepass")
    else:
        against = str(BENCHMARKS / "p5" / against)
    hist = ch.choice(["h.csv", "h.csv", "h.csv", "fifo.csv", "/dev/zero", ".", "missing.csv"])
    out = ch.choice([None, "scores.json", "afile/x.json", "."])
    argv = ["compare", hist, "--against", against] + (["-o", out] if out else [])
    if out == "afile/x.json":
        files["afile"] = b"x"
    return Case("compare: hostile history", argv, files, None)


def study_text(dts="[1e-4, 5e-5]", extra=""):
    return (f'title = "fuzz"\n{extra}[[scene]]\nfile = "{BENCHMARKS / "p5" / "p5_linear.toml"}"\n'
            f'[[integrator]]\nname = "newmark"\nparams = {{ preset = "average-acceleration" }}\n'
            f'dt = {dts}\n').encode()


def study_case(ch):
    jobs = ch.choice(["-3", "0", "1", "2", "x", "99999999999999999999", "-0", "1e3", "257"])
    dts = ch.choice(["[1e-4, 5e-5]", "[-1.0]", "[]", "[1e-320]", '"x"', "[1e400]", "1e-4"])
    return Case("study: hostile -j or sweep", ["study", "st.toml", "-j", jobs, "-o", "out/study"],
                {"st.toml": study_text(dts)}, None)


def argv_case(ch):
    argv = ch.choice([["run"], ["run", "--nope"], ["frobnicate"], ["run", "-o"], ["--version"],
                      ["run", "a/b/scene.toml", "-o", ""], ["study", "x.toml", "-o", ""],
                      ["list", "extra"], ["check", "--no-plots", "-o", "afile"],
                      ["compare", "x.csv"], ["study"], ["run", "\udcff.toml"], ["-h"],
                      ["run", "a/b/scene.toml", "--force", "-o", "out/run"]])
    files = {"afile": b"x", "a/b/scene.toml": to_toml(scene_dict("p1/p1_static_lagrange")).encode()}
    return Case("argv: " + " ".join(argv)[:30], list(argv), files, None)


# A run folder and a study folder as martello writes them (small), for plot to draw once
# damaged.
RUN_SUMMARY = {"title": "fuzz", "status": "MARTELLO_OK",
               "analysis": {"integrator": "newmark", "dt": 1e-3},
               "contacts": {"c": {"scheme": "penalty", "law": "linear"}}, "links": {}}
RUN_HISTORY = "t,u:m,v:m,penetration:c,force:c,energy:kinetic\n" + "".join(
    f"{i * 1e-3:.6g},{0.01 * i:.6g},0.1,{0.001 * (i % 3) - 0.001:.6g},{10.0 * (i % 3):.6g},"
    f"{0.5 * i:.6g}\n" for i in range(40))
RUNS_CSV = ("run,study,case,method,integrator,dt,rtol,status,classification,max_rel_error,"
            "wall_time_s,residual_evaluations,reference,reference_digits\n" + "".join(
                f"{i},fuzz,P2,newmark,newmark,{1e-3 / 2 ** i!r},,MARTELLO_OK,ok,{1e-2 / 4 ** i!r},"
                f"{0.01 * 2 ** i!r},{100 * 2 ** i},closed form,13.0\n" for i in range(5)))


def plot_case(ch):
    """martello plot on a run or study folder, one of its files cut short, edited or replaced."""
    run = ch.coin(0.6)
    files = ({"f/summary.json": json.dumps(RUN_SUMMARY).encode(), "f/history.csv": RUN_HISTORY.encode()}
             if run else {"f/runs.csv": RUNS_CSV.encode()})
    name = ch.choice(sorted(files))
    text = files[name].decode()
    op = ch.integer(0, 5)
    if op == 0:
        files[name] = text[:ch.integer(0, len(text))].encode()
    elif op == 1:
        files[name] = mutate_text(ch, text)
    elif op == 2 and name.endswith(".json"):
        files[name] = json.dumps(mutate_dict(ch, copy.deepcopy(RUN_SUMMARY), 2),
                                 default=str).encode()
    elif op == 2:
        files[name] = mutate_record(ch, text)
    elif op == 3:
        files[name] = ch.choice([b"", b"[]", b"null", b"\xff\xfe\x00", b"t\n1\n", b"{}"])
    elif op == 4:
        files[name] = "dir"
    argv = ["plot", "f", "-o", "out/plots", "--format", ch.choice(["png", "svg", "png,svg"])]
    if ch.coin(0.3):
        argv += [ch.choice(["--nodes", "--contacts", "--metric"]),
                 ch.choice(["m", "c", "x", "", ",", "max_rel_error", "wall_time_s"])]
    return Case(f"plot: damaged {name.rpartition('/')[2]}", argv, files, "out/plots")


def reference_case(ch):
    """A study whose `reference = { data = DIR }` holds what martello does not write."""
    meta = {"t_end": 1.0, "digits": {"u:mass": 9.0}, "events": {}, "peaks": {}}
    hist = "t,u:mass\n" + "".join(f"{i * 0.01:.6g},{0.05 - 1e-4 * i:.6g}\n" for i in range(101))
    op = ch.integer(0, 3)
    meta_bytes = json.dumps(mutate_dict(ch, meta, 2) if op == 0 else meta, default=str).encode()
    hist_bytes = hist.encode()
    if op == 1:
        meta_bytes = meta_bytes[:ch.integer(0, len(meta_bytes))]
    elif op == 2:
        hist_bytes = mutate_record(ch, hist)
    elif op == 3:
        meta_bytes = ch.choice([b"[]", b"{}", b"1e999", b"\xff", b'{"t_end": "x"}', b'{"t_end": -1}'])
    study = study_text("[1e-3]").decode().replace(
        "[[integrator]]", 'reference = { data = "ref" }\nt_end = 0.1\n[[integrator]]', 1)
    return Case("study: malformed reference data", ["study", "st.toml", "-o", "out/study",
                                                    "--no-plots", "-j", "1"],
                {"st.toml": study.encode(), "ref/reference.json": meta_bytes,
                 "ref/history.csv": hist_bytes}, "out/study")


def scheduler_case(ch):
    """A study file that names a scheduler: never connected to without --use-study-scheduler
    (nothing listens at 127.0.0.1:9: a connection would fail)."""
    address = ch.choice(['"tcp://127.0.0.1:9"', '"cluster.json"', '""', "5", '"tcp://[::1]:9"'])
    return Case("study: scheduler in the file", ["study", "st.toml", "-o", "out/study",
                                                  "--no-plots", "-j", "1"],
                {"st.toml": study_text(extra=f"scheduler = {address}\n")}, None)


# scenes the exporter writes (a chain of nodes, a planar frame on a record given by an
# absolute path) and some it refuses (IDA, a building, a static scene)
EXPORTABLE = ["p5/p5_linear", "p5/p5_hertz", "p5/p5_kelvin", "p2/p2_restitution_e08",
              "p7/p7_chain_10", "p6/p6_elastoplastic_rho005", "sdof/sdof_sine_newmark",
              "p7/laws/p7_two_kelvin_newmark", "p2/p2_ida_penalty_linear", "p11/p11_shear_pounding",
              "p1/p1_static_lagrange"]
EXPORT_FLAGS = {"--integrator": ["newmark", "hht", "generalized-alpha", "central-difference",
                                 "cvode", "ida", "x", ""],
                "--dt": ["0", "-1", "nan", "inf", "1e-320", "1e400", "1e-5", "1", "x", ""],
                "--t-end": ["0", "-0", "nan", "1e300", "1e-9", "0.001", "x"],
                "--beta": ["0", "-1", "0.25", "nan", "1e300"],
                "--gamma": ["0.5", "0.4", "nan", "2"],
                "--alpha": ["-0.1", "0", "0.1", "-1", "nan"],
                "--rho-inf": ["0", "0.8", "1", "2", "-1", "nan"],
                "--tol": ["0", "-1", "nan", "inf", "1e-12", "1e300"],
                "--material": ["kelvin=JankowskiImpact", "linear=Elastic", "x", "=", "linear=",
                               "=ENT", "hertz=ImpactMaterial", "linear=ENT,hertz=x"],
                "--to": ["opensees", "abaqus", ""],
                "--tcl": None}


def export_case(ch):
    """martello export of a (sometimes mutated) scene with hostile overrides and -o."""
    name = ch.choice(EXPORTABLE)
    files = {"afile": b"x"}
    if ch.coin(0.3):
        d = scene_dict(name)
        d = mutate_dict(ch, d, 1) if ch.coin(0.5) else d
        if ch.coin(0.3):
            TARGETED[ch.choice(["modal vectors", "integrator method", "frame lengths past the doubles",
                                "building fields", "chain damping overflow"])](d, ch)
        files["s.toml"] = to_toml(d).encode("utf-8", "surrogatepass")
        scene = "s.toml"
    else:
        scene = str(BENCHMARKS / f"{name}.toml")
    argv = ["export", scene]
    for _ in range(ch.integer(0, 3)):
        flag = ch.choice(sorted(EXPORT_FLAGS))
        argv += [flag] if EXPORT_FLAGS[flag] is None else [flag, ch.choice(EXPORT_FLAGS[flag])]
    out = ch.choice(["ex", "ex", "ex", "afile", "afile/sub", "."])
    argv += ["-o", out]
    return Case("export: hostile overrides", argv, files, out if out == "ex" else None)


# a history as martello writes it for a scene with links (sdof_sine_newmark: link0 the
# spring, link1 the dashpot), and recorder files (whitespace, no header, time first)
SDOF = "sdof/sdof_sine_newmark"


def compare_columns_case(ch):
    """compare's link columns (NaN throughout: not recorded; NaN among values: an error) and
    OpenSees recorder files with hostile --columns."""
    import math as _m
    n = ch.choice([0, 1, 2, 50, 200])
    cols = ch.choice([["u:m"], ["u:m", "link_force:link0"], ["u:m", "elongation:link1", "v:m"],
                      ["link_force:link0"], ["u:m", "link_force:link9"], ["u:m", "link_force:"],
                      ["u:m", "link_force:link0", "link_force:link0"], ["force:link0"]])
    how = ch.choice(["nan", "nan", "finite", "some nan", "inf", "empty"])

    def cell(c, i):
        if c.startswith(("link_force", "elongation")):
            if how == "nan" or (how == "some nan" and i % 2):
                return "nan"
            if how == "inf" and i == n // 2:
                return "inf"
            if how == "empty":
                return ""
        return f"{1e-3 * _m.sin(0.01 * i):.6g}"
    files = {}
    if ch.coin(0.5):
        text = ",".join(["t"] + cols) + "\n" + "".join(
            ",".join([f"{0.01 * i:.6g}"] + [cell(c, i) for c in cols]) + "\n" for i in range(n))
        files["h.csv"] = text.encode()
        argv = ["compare", "h.csv"]
    else:
        k = ch.integer(1, 3)
        text = "".join(" ".join([f"{0.01 * i:.6g}"] + [cell("link_force" if j and how != "finite" else "u", i)
                                                     for j in range(k)]) + "\n" for i in range(n))
        files["r.out"] = text.encode()
        argv = ["compare", "r.out"]
        if ch.coin(0.3):
            files["r2.out"] = text.encode()
            argv.append("r2.out")
        for _ in range(ch.choice([0, 1, 1, 2])):
            argv.append("--columns=" + ch.choice(
                ["u:m", "u:m,link_force:link0", "-u:m", "u:m,-link_force:link0,elongation:link1",
                 ",", "", "u:nope", "u:m,u:m,u:m,u:m", "--", "v:m,a:m", "force:c", "t"]))
    argv += ["--against", str(BENCHMARKS / f"{SDOF}.toml")]
    if ch.coin(0.3):
        argv += ["-o", ch.choice(["scores.json", "afile/x.json", "."])]
        files["afile"] = b"x"
    return Case("compare: link columns and recorder files", argv, files, None)


KINDS = [(scene_case, 70), (path_case, 6), (check_case, 8), (compare_case, 9), (study_case, 3),
         (argv_case, 4), (plot_case, 6), (reference_case, 3), (scheduler_case, 1),
         (export_case, 8), (compare_columns_case, 5), (later_scene_case, 8)]


def make_case(ch, kinds=None):
    """One case of a kind drawn by weight (of those named in `kinds`, if given)."""
    pool = [(fn, w) for fn, w in KINDS if not kinds or fn.__name__ in kinds]
    total = sum(w for _, w in pool)
    n = ch.integer(1, total)
    for fn, w in pool:
        if n <= w:
            return fn(ch)
        n -= w
    raise AssertionError


def lay_out(case, folder):
    """Create the case's files under folder."""
    import os
    folder = Path(folder)
    for rel, data in case.files.items():
        p = folder / rel
        p.parent.mkdir(parents=True, exist_ok=True)
        if isinstance(data, str) and data.startswith("->"):       # a symbolic link
            p.symlink_to(data[2:])
        elif data == "fifo":
            if not p.exists():
                os.mkfifo(p)
        elif data == "dir":
            p.mkdir(exist_ok=True)
        else:
            p.write_bytes(data)
