"""An OpenSeesModel (martello.export.opensees) written out as a standalone OpenSeesPy script or
a Tcl script: the same commands in both languages, then a loop of single steps that samples
the history every `output.every` steps and writes history.csv only when the run finished
(docs/opensees.md "The exported script")."""

import math

from .opensees import Column, _File

HISTORY = "history.csv"
MEMBERS = "members.csv"
PERIODS = "periods.csv"


def _py(x):
    if isinstance(x, _File):
        return f"os.path.join(HERE, {str(x)!r})"
    if isinstance(x, str):
        return repr(x)
    if isinstance(x, bool):
        return "1" if x else "0"
    if isinstance(x, int):
        return str(x)
    x = float(x)
    if not math.isfinite(x):               # pragma: no cover - the exporter writes finite numbers
        raise ValueError(f"not a finite number: {x}")
    return repr(x)


def _tcl(x):
    if isinstance(x, str):
        return x
    return _py(x)


def _header(model, version, scene_path):
    lines = [f"{model.title}: exported by martello {version} from {model.source}",
             "(docs/opensees.md in martello). It writes history.csv in the format that",
             f"`martello compare history.csv --against {scene_path}` scores.",
             "",
             "martello -> OpenSees:"]
    lines += [f"  {a} -> {b}" for a, b in model.mapping]
    lines += ["", "Differences from martello's model:"]
    lines += [f"  - {d}" for d in model.differences] or \
        ["  none: every item maps onto an OpenSees object with the same law"]
    return lines


def _sample_py(col):
    k, a = col.kind, col.args
    if k == "t":
        return "t"
    if k in ("u", "v", "a"):
        fn = {"u": "nodeDisp", "v": "nodeVel", "a": "nodeAccel"}[k]
        return f"ops.{fn}({a[0]}, {a[1]})"
    if k == "penetration":
        return f"row({a[0]!r}) - {_py(a[1])}"
    if k == "force":
        return f"-ops.eleResponse({a[0]}, 'basicForce')[0]"
    if k == "energy":
        return f"{a[0]}()"
    raise ValueError(k)                    # pragma: no cover


def _energy_py(e):
    """row(), kinetic() and recoverable(): an element's row Σ c·u over (tag, dof, c), ½ vᵀMv
    (with a building's mass couplings), and the stored energy of docs/results.md's
    `recoverable` (springs and bars ½k du², bilinear springs ρk du²/2 + F_p²/(2(1 − ρ)k),
    penalty contacts K δ^(n+1)/(n + 1), frames and buildings ½ uᵀK*u with martello's
    condensed K*)."""
    out = ["def row(terms, f=ops.nodeDisp):",
           "    return sum(c * f(tag, dof) for tag, dof, c in terms)", "", "",
           "def kinetic():",
           f"    w = sum(m * ops.nodeVel(tag, dof) ** 2 for tag, dof, m in {e['kinetic']!r})",
           f"    w += sum(m * ops.nodeVel(*a) * ops.nodeVel(*b) for a, b, m in {e['couplings']!r})",
           "    return 0.5 * w", "", "",
           "def recoverable():", "    w = 0.0",
           f"    for terms, k in {e['springs']!r}:", "        w += 0.5 * k * row(terms) ** 2",
           f"    for ele, terms, k, rho in {e['bilinear']!r}:",
           "        du = row(terms)",
           "        fp = ops.eleResponse(ele, 'basicForce')[0] - rho * k * du",
           "        w += 0.5 * rho * k * du * du + fp * fp / (2.0 * (1.0 - rho) * k)",
           f"    for terms, gap, K, n in {e['contacts']!r}:",
           "        d = row(terms) - gap",
           "        w += K * d ** (n + 1) / (n + 1) if d > 0 else 0.0",
           f"    for tags, K in {e['blocks']!r}:",
           "        x = [ops.nodeDisp(*t) for t in tags]",
           "        w += 0.5 * sum(x[i] * K[i][j] * x[j] for i in range(len(x)) for j in range(len(x)))",
           "    return w"]
    return out


def _sample_tcl(col):
    k, a = col.kind, col.args
    if k == "t":
        return "$t"
    if k in ("u", "v", "a"):
        fn = {"u": "nodeDisp", "v": "nodeVel", "a": "nodeAccel"}[k]
        return f"[{fn} {a[0]} {a[1]}]"
    if k == "penetration":
        terms = " + ".join(f"{_tcl(c)} * [nodeDisp {t} {d}]" for t, d, c in a[0])
        return f"[expr {{{terms or '0.0'} - {_tcl(a[1])}}}]"
    if k == "force":
        return f"[expr {{-[lindex [eleResponse {a[0]} basicForce] 0]}}]"
    raise ValueError(k)                    # pragma: no cover


def python_script(model, version, scene_path):
    out = ['#!/usr/bin/env python3'] + ["# " + line if line else "#"
                                        for line in _header(model, version, scene_path)]
    out += ["# Run inside this folder, with OpenSeesPy installed: python model.py", "",
            '"""A martello scene rebuilt in OpenSeesPy (the comments above say which)."""', "",
           "import math", "import os", "import sys", "",
           "import openseespy.opensees as ops", "",
           "HERE = os.path.dirname(os.path.abspath(__file__))",
           f"DT = {_py(model.dt)}",
           f"STEPS = {model.steps}",
           f"EVERY = {model.every}",
           f"COLUMNS = {[c.name for c in model.columns]!r}",
           f"MEMBERS = {model.members!r}   # a building's members: name, element (members.csv)",
           f"MODES = {model.modes}   # a building's mass DOFs (python model.py --periods)", "", "",
           "def build():",
           '    """The scene as an OpenSees domain and a transient analysis."""']
    for name, args in model.commands:
        if name != "endPattern":              # Tcl's closing brace of a Plain pattern
            out.append(f"    ops.{name}({', '.join(_py(a) for a in args)})")
    out += ["", ""] + _energy_py(model.energy) + ["", "",
            "def sample(t):",
            "    return [" + ", ".join(_sample_py(c) for c in model.columns) + "]",
            "", "",
            "def member_names():",
            "    return ['t'] + [f'{q}_{end}:{name}' for name, _ in MEMBERS for end in 'ij' for q in ('M2', 'M3')]",
            "", "",
            "def sample_members(t):",
            "    # eleResponse localForce: N, Vy, Vz, T, My, Mz at end i, then end j; y, z are martello's",
            "    # local axes 2, 3 (vecxz = axis 3), so My, Mz are M2, M3 as martello recovers them",
            "    row = [t]",
            "    for _, ele in MEMBERS:",
            "        f = ops.eleResponse(ele, 'localForce')",
            "        row += [f[4], f[5], f[10], f[11]]",
            "    return row",
            "", "",
            "def write(name, header, rows):",
            "    path = os.path.join(HERE, name)",
            "    with open(path + '.part', 'w') as f:",
            "        f.write(','.join(header) + '\\n')",
            "        for row in rows:",
            "            f.write(','.join(f'{x:.17g}' for x in row) + '\\n')",
            "    os.replace(path + '.part', path)",
            "    return path",
            "", "",
            "def period(lam):",
            "    \"\"\"2 pi / sqrt(lam); inf for a mode without stiffness (a free node: lam = 0 up to",
            "    round-off, which may leave it slightly negative).\"\"\"",
            "    return 2.0 * math.pi / math.sqrt(lam) if lam > 0.0 else math.inf",
            "", "",
            "def periods():",
            f"    \"\"\"The periods of the building's first MODES modes (eigen on the model) -> {PERIODS}.\"\"\"",
            "    build()",
            "    # every mass DOF's mode: ARPACK's Krylov space is bounded by the mass's rank (about half",
            "    # of them), fullGenLapack solves the dense problem (its eigenvalues are those of K, M)",
            "    lam = ops.eigen('-fullGenLapack', MODES)",
            "    path = write(" + repr(PERIODS) + ", ['mode', 'period'],",
            "                 [[k + 1, period(x)] for k, x in enumerate(lam)])",
            "    ops.wipe()",
            "    print(f'model.py: {len(lam)} periods -> {path}')",
            "", "",
            "def main():",
            "    if '--periods' in sys.argv[1:]:",
            "        return periods()",
            "    build()",
            "    rows, members = [sample(0.0)], [sample_members(0.0)] if MEMBERS else []",
            "    for k in range(1, STEPS + 1):",
            "        if ops.analyze(1, DT) != 0:",
            "            sys.exit(f'model.py: OpenSees failed at step {k} of {STEPS} '",
            "                     f'(t = {k * DT:.6g} s): no history written')",
            "        if k % EVERY == 0 or k == STEPS:",
            "            rows.append(sample(k * DT))",
            "            if MEMBERS:",
            "                members.append(sample_members(k * DT))",
            "    for row in rows:",
            "        bad = [COLUMNS[j] for j, x in enumerate(row) if not math.isfinite(x)]",
            "        if bad:",
            "            sys.exit(f'model.py: {bad[0]} is not finite at t = {row[0]:.6g} s '",
            "                     '(the run diverged): no history written')",
            f"    path = write({HISTORY!r}, COLUMNS, rows)",
            "    if MEMBERS:",
            f"        write({MEMBERS!r}, member_names(), members)",
            "    ops.wipe()",
            "    print(f'model.py: {STEPS} steps of {DT:g} s, {len(rows)} rows -> {path}')",
            "", "",
            "if __name__ == '__main__':",
            "    main()", ""]
    return "\n".join(out)


def tcl_script(model, version, scene_path):
    out = ["# " + line if line else "#" for line in _header(model, version, scene_path)]
    out += ["# Run inside this folder: OpenSees model.tcl", ""]
    for name, args in model.commands:
        if name == "endPattern":
            out.append("}")
        elif name == "pattern" and args[0] == "Plain":
            out.append(" ".join([name] + [_tcl(a) for a in args]) + " {")
        else:
            out.append(("    " if out[-1].endswith("{") or out[-1].startswith("    load") else "")
                       + " ".join([name] + [_tcl(a) for a in args]))
    cols = [c for c in model.columns if c.kind != "energy"]    # the energies: model.py only
    fmt = ",".join(["%.17g"] * len(cols))
    out += ["",
            f"set dt {_tcl(model.dt)}",
            f"set steps {model.steps}",
            f"set every {model.every}",
            "proc sample {t} {",
            f"    return [format \"{fmt}\" " + " ".join(_sample_tcl(c) for c in cols) + "]",
            "}",
            "# a building's members (members.csv): M2, M3 at ends i and j from localForce (model.py's)",
            "set members {" + " ".join(str(ele) for _, ele in model.members) + "}",
            "set mnames {t " + " ".join(f"{q}_{e}:{name}" for name, _ in model.members for e in "ij"
                                       for q in ("M2", "M3")) + "}",
            "proc sample_members {t} {",
            "    global members",
            "    set row [list [format %.17g $t]]",
            "    foreach ele $members {",
            "        set f [eleResponse $ele localForce]",
            "        foreach k {4 5 10 11} { lappend row [format %.17g [lindex $f $k]] }",
            "    }",
            "    return $row",
            "}",
            "set rows [list [sample 0.0]]",
            "set mrows {}",
            "if {[llength $members]} { lappend mrows [sample_members 0.0] }",
            "for {set k 1} {$k <= $steps} {incr k} {",
            "    if {[analyze 1 $dt] != 0} {",
            "        puts stderr \"model.tcl: OpenSees failed at step $k of $steps: no history written\"",
            "        exit 1",
            "    }",
            "    if {$k % $every == 0 || $k == $steps} {",
            "        lappend rows [sample [expr {$k * $dt}]]",
            "        if {[llength $members]} { lappend mrows [sample_members [expr {$k * $dt}]] }",
            "    }",
            "}",
            f"set f [open {HISTORY}.part w]",
            f"puts $f \"{','.join(c.name for c in cols)}\"",
            "foreach r $rows { puts $f $r }",
            "close $f",
            f"file rename -force {HISTORY}.part {HISTORY}",
            "if {[llength $members]} {",
            f"    set f [open {MEMBERS}.part w]",
            "    puts $f [join $mnames ,]",
            "    foreach r $mrows { puts $f [join $r ,] }",
            "    close $f",
            f"    file rename -force {MEMBERS}.part {MEMBERS}",
            "}",
            "wipe", ""]
    return "\n".join(out)


__all__ = ["python_script", "tcl_script", "HISTORY", "Column"]
