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
         "p9/p9_davis_restitution", "sdof/sdof_sine_newmark"]


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


# targeted edits: the causes, each a function of a parsed scene
def _analysis(d):
    a = d.get("analysis")
    return a if isinstance(a, dict) else d.setdefault("analysis", {})


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


def scene_case(ch):
    name = ch.choice(QUICK)
    d = scene_dict(name)
    files = {"fifo.csv": "fifo", "records": "dir", "etc/passwd":
             b"root:x:0:0:root:/root:/bin/bash\nsecret:x:1:1:the secret line:/home/s:/bin/sh\n"}
    how = ch.integer(0, 9)
    if how <= 3:
        d = mutate_dict(ch, d)
        label = "mutated scene"
    elif how <= 7:
        label = ch.choice(sorted(TARGETED))
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


KINDS = [(scene_case, 70), (path_case, 6), (check_case, 8), (compare_case, 9), (study_case, 3),
         (argv_case, 4), (plot_case, 6), (reference_case, 3), (scheduler_case, 1)]


def make_case(ch):
    total = sum(w for _, w in KINDS)
    n = ch.integer(1, total)
    for fn, w in KINDS:
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
