"""Round trips of what an exit-0 command wrote (campaign.classify): a result must read back
through martello's own readers, in the formats docs/results.md, docs/compare.md and
docs/opensees.md describe. An exit-0 case whose output does not is "round trip failed":
a value the writer should have refused (an exported model with a convergence tolerance of 0)
or a file the reader cannot take (a history.csv whose header compare cannot read).

    run      summary.json strict JSON (no NaN or Infinity: the writer's allow_nan=False) with
             a MARTELLO_ status (results.read_summary); history.csv, when written, through
             compare's reader against the scene that was run (compare.read_history: every
             column names an item of the scene, values finite, times increasing)
    export   model.py compiles; DT finite > 0, STEPS and EVERY whole numbers >= 1; its build()
             run against a recording stand-in for openseespy (OpenSees is not needed): every
             number it hands OpenSees finite, NormDispIncr's tolerance > 0 and its iteration
             count >= 1; a history headed by its COLUMNS read by compare's reader against the
             scene; model.tcl (with --tcl) complete Tcl (tclsh's `info complete`) with the same
             dt and steps; the data files one finite number a line
    compare  the -o scores: strict JSON
    study    runs.csv through plot's reader (plot.read_table, the columns plot needs)

Each check returns None (it reads back) or one line saying what did not. The readers are
this checkout's: a campaign with --root on an older checkout reads its results with them."""

from __future__ import annotations

import ast
import builtins
import json
import math
import shutil
import subprocess
import tempfile
import types
from pathlib import Path


def _strict_json(path):
    """The JSON of path; ValueError on NaN/Infinity (not JSON: the writers refuse them)."""
    def refuse(name):
        raise ValueError(f"{name} is not JSON")
    return json.loads(Path(path).read_text(), parse_constant=refuse)


def _option(argv, *names):
    """The value of the last of the options `names` in argv (either `-o X` or `-o=X`)."""
    value = None
    for i, a in enumerate(argv):
        for n in names:
            if a == n and i + 1 < len(argv):
                value = argv[i + 1]
            elif a.startswith(n + "="):
                value = a[len(n) + 1:]
    return value


def check(argv, folder):
    """None if what `martello *argv` wrote in folder (an exit-0 case, run in folder) reads
    back, else why not. Commands without a written result (-o), and help, are not looked at."""
    from martello.scene.catalogue import find
    out = _option(argv, "-o", "--output")
    if out is None or len(argv) < 2 or "--help" in argv or "-h" in argv:
        return None
    folder = Path(folder)

    def scene():                   # a path from the case's folder, or a catalogue name
        return find(folder / argv[1]) if (folder / argv[1]).exists() else find(argv[1])
    checks = {"run": lambda: check_run(scene(), folder / out),
              "export": lambda: check_export(scene(), folder / out),
              "compare": lambda: check_json(folder / out),
              "study": lambda: check_study(folder / out)}
    if argv[0] not in checks:
        return None
    try:
        return checks[argv[0]]()
    except Exception as exc:                              # noqa: BLE001 - what is reported
        return f"{argv[0]}: reading back raised {type(exc).__name__}: {' '.join(str(exc).split())}"[:300]


def check_run(scene_path, out):
    from martello import results
    from martello.compare import read_history
    from martello.errors import MartelloError
    from martello.scene.loader import load
    try:
        summary = _strict_json(out / "summary.json")
    except (OSError, ValueError) as exc:
        return f"summary.json: {' '.join(str(exc).split())}"[:300]
    if not str(summary.get("status", "")).startswith("MARTELLO_"):
        return f"summary.json: status {summary.get('status')!r}"
    results.read_summary(out)
    history = out / "history.csv"
    if not history.exists():
        return None
    try:
        scene = load(scene_path)
    except MartelloError as exc:          # ran, but this checkout's loader refuses it
        return f"the scene run does not load here: {exc}"[:300]
    try:
        read_history(history, scene)
    except MartelloError as exc:
        return f"history.csv does not read back: {exc}"[:300]
    return None


class _Recorder:
    """A stand-in for openseespy.opensees: every call recorded as (name, args)."""

    def __init__(self):
        self.calls = []

    def __getattr__(self, name):
        def call(*args):
            self.calls.append((name, args))
            return 0
        return call


def _numbers(args):
    for a in args:
        if isinstance(a, (int, float)) and not isinstance(a, bool):
            yield a
        elif isinstance(a, (list, tuple)):
            yield from _numbers(a)


def check_export(scene_path, out):
    from martello.compare import read_history
    from martello.errors import MartelloError
    from martello.scene.loader import load
    script = out / "model.py"
    if not script.exists():
        return "export: no model.py"
    source = script.read_text()
    tree = ast.parse(source, str(script))
    consts = {t.id: ast.literal_eval(node.value) for node in tree.body
              if isinstance(node, ast.Assign) for t in node.targets
              if isinstance(t, ast.Name) and t.id in ("DT", "STEPS", "EVERY", "COLUMNS")}
    dt, steps, every = consts.get("DT"), consts.get("STEPS"), consts.get("EVERY")
    if not (isinstance(dt, float) and math.isfinite(dt) and dt > 0):
        return f"model.py: DT = {dt!r} (a step must be a finite number > 0)"
    for name, n in (("STEPS", steps), ("EVERY", every)):
        if not (isinstance(n, int) and n >= 1):
            return f"model.py: {name} = {n!r} (must be a whole number >= 1)"
    # build() against the stand-in: the commands OpenSees would be given, as it would get them
    ops = _Recorder()

    def importer(name, *args, **kwargs):
        if name == "openseespy.opensees":         # `import a.b as c` takes b from a
            return types.SimpleNamespace(opensees=ops)
        return builtins.__import__(name, *args, **kwargs)
    namespace = {"__name__": "model", "__file__": str(script),
                 "__builtins__": dict(vars(builtins), __import__=importer)}
    exec(compile(tree, str(script), "exec"), namespace)      # noqa: S102 - martello's own output
    namespace["build"]()
    for name, args in ops.calls:
        bad = [x for x in _numbers(args) if not math.isfinite(x)]
        if bad:
            return f"model.py: ops.{name}{args!r:.120} hands OpenSees {bad[0]!r}"
        if name == "test":
            tol, iters = args[1], args[2]
            if not (tol > 0 and isinstance(iters, int) and iters >= 1):
                return f"model.py: ops.test{args!r}: the tolerance must be > 0 and the iterations >= 1"
    # the history the model writes, read by compare against the scene
    columns = consts.get("COLUMNS")
    with tempfile.TemporaryDirectory(prefix="martello-roundtrip-") as tmp:
        h = Path(tmp) / "history.csv"
        h.write_text(",".join(columns) + "\n" + "".join(
            ",".join(repr(k * dt) if c == "t" else "0.0" for c in columns) + "\n" for k in (0, 1)))
        try:
            scene = load(scene_path)
        except MartelloError as exc:
            return f"the scene exported does not load here: {exc}"[:300]
        try:
            read_history(h, scene)
        except MartelloError as exc:
            return f"model.py's history header does not read back: {exc}"[:300]
    for name in sorted(p.name for p in out.iterdir()):
        if name.endswith(".txt"):
            for k, line in enumerate((out / name).read_text().splitlines(), 1):
                if not math.isfinite(float(line)):
                    return f"{name}:{k}: {line!r} is not a finite number"
    if (out / "model.tcl").exists():
        return _check_tcl(out / "model.tcl", dt, steps)
    return None


TCL_COMPLETE = ("set f [open [lindex $argv 0]]; set s [read $f]; close $f\n"
                "puts [info complete $s]\n")


def _check_tcl(path, dt, steps):
    """model.tcl complete Tcl (tclsh's `info complete`: no unclosed brace, bracket or quote),
    its `set dt` and `set steps` those of model.py."""
    import re
    tclsh = shutil.which("tclsh")
    if tclsh is not None:                               # scripts/setup installs it
        with tempfile.TemporaryDirectory(prefix="martello-roundtrip-") as tmp:
            checker = Path(tmp) / "complete.tcl"
            checker.write_text(TCL_COMPLETE)
            proc = subprocess.run([tclsh, str(checker), str(path)], capture_output=True,
                                  text=True, timeout=30)
        if proc.returncode != 0 or proc.stdout.strip() != "1":
            return f"model.tcl: not complete Tcl {proc.stderr.strip()[-200:]}".strip()
    text = path.read_text()
    got = {k: re.findall(rf"^set {k} (\S+)$", text, re.M) for k in ("dt", "steps")}
    if got["dt"] != [repr(dt)] or got["steps"] != [str(steps)]:
        return f"model.tcl: set dt {got['dt']}, set steps {got['steps']}; model.py: {dt!r}, {steps}"
    return None


def check_json(path):
    if path.is_dir() or not path.exists():       # `-o .`: compare wrote nothing it could name
        return None
    try:
        _strict_json(path)
    except ValueError as exc:
        return f"{path.name}: {' '.join(str(exc).split())}"[:300]
    return None


def check_study(out):
    from martello.errors import MartelloError
    from martello.plot import read_table
    runs = out / "runs.csv"
    if not runs.exists():
        return None
    try:
        read_table(runs, ("case", "method", "classification", "dt", "rtol"))
    except MartelloError as exc:
        return f"runs.csv does not read back: {exc}"[:300]
    return None
