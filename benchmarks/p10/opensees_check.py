"""Cross-check of one P10 frame scene against OpenSees (docs/p10-case-study.md, "OpenSees").

    .venv/bin/python benchmarks/p10/opensees_check.py -o DIR [--python PY] [--record 1] [--dt 5e-4]
        [--docs]

The bare scene of benchmarks/p10/case_study.py (frames A and B, gaps at floors 1 and 2, no
dampers), one record, run by martello (Newmark average acceleration) and by OpenSees
(openseespy): the same frames as elasticBeamColumn elements on 3-DOF joints (nothing
condensed: OpenSees carries the vertical and rotational DOFs, massless), the gaps as
zeroLength elements of an ElasticPPGap material (a linear spring past the gap, no tension),
Rayleigh damping per frame by region (a0 M + a1 K of each frame's own elements: condensing
the massless DOFs of a0 M + a1 K gives martello's a0 M + a1 K*), UniformExcitation with the
record as a Path series, Newmark (½, ¼) at the same step, Newton with a displacement test at
1e-12. Printed and written into DIR (with the parameters and the OpenSees result; --docs, for
the default record 1 over 20 s, also to docs/p10/opensees_check.txt, which
docs/p10-case-study.md quotes): the peak |M| of every column and the peak gap penetration from
both codes and their relative differences. The two codes share only the input numbers (sections, masses,
gap stiffness, the Rayleigh coefficients a0 and a1 of each frame as martello's summary
reports them, and the record); the assembly, the solver and the member forces are each
code's own.

The OpenSees half runs under --python (an interpreter that imports openseespy), else under this
one if it does; the script installs nothing, and prints a skip message without one.
"""

import argparse
import json
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
sys.path.insert(0, str(ROOT))

# the interpreter, the run of the OpenSees half, the gap and the analysis: shared with P11's check
from benchmarks.opensees.crosscheck import (SKIPPED, gap_element, newmark_transient,  # noqa: E402
                                            opensees_python, run_opensees_half, steps, version)


# --- the OpenSees half (runs under the openseespy interpreter; no martello import) -------------

def opensees_worker(params_file, out_file):
    import openseespy.opensees as ops
    P = json.loads(Path(params_file).read_text())
    ops.wipe()
    ops.model("basic", "-ndm", 2, "-ndf", 3)
    ops.geomTransf("Linear", 1)
    tag = {"node": 0, "ele": 0}
    node_of, columns, masses = {}, {}, {}
    for fr in P["frames"]:
        nodes, eles = [], []
        for j in range(fr["storeys"] + 1):
            for i in range(fr["bays"] + 1):
                tag["node"] += 1
                n = tag["node"]
                ops.node(n, fr["x0"] + i * fr["bay_width"], j * fr["storey_height"])
                node_of[fr["prefix"], j, i] = n
                if j == 0:
                    ops.fix(n, 1, 1, 1)
                else:
                    nodes.append(n)
        for j in range(1, fr["storeys"] + 1):
            for i in range(fr["bays"] + 1):
                ops.mass(node_of[fr["prefix"], j, i], fr["joint_mass"][f"{j}.{i}"], 0.0, 0.0)
        for s, sec in enumerate(fr["column"]):
            for i in range(fr["bays"] + 1):
                tag["ele"] += 1
                ops.element("elasticBeamColumn", tag["ele"], node_of[fr["prefix"], s, i],
                            node_of[fr["prefix"], s + 1, i], sec["A"], sec["E"], sec["I"], 1)
                columns[f"{fr['prefix']}.C{s + 1}.{i}"] = tag["ele"]
                eles.append(tag["ele"])
        sec = fr["beam"]
        for j in range(1, fr["storeys"] + 1):
            for b in range(fr["bays"]):
                tag["ele"] += 1
                ops.element("elasticBeamColumn", tag["ele"], node_of[fr["prefix"], j, b],
                            node_of[fr["prefix"], j, b + 1], sec["A"], sec["E"], sec["I"], 1)
                eles.append(tag["ele"])
        a0, a1 = fr["rayleigh"]
        # -eleOnly / -nodeOnly: "-ele" and "-node" would also reset the attached nodes/elements
        ops.region(len(masses) + 1, "-eleOnly", *eles, "-rayleigh", 0.0, a1, 0.0, 0.0)
        ops.region(len(masses) + 101, "-nodeOnly", *nodes, "-rayleigh", a0, 0.0, 0.0, 0.0)
        masses[fr["prefix"]] = True
    gaps = []
    for g in P["gaps"]:
        tag["ele"] += 1
        ni, nj = node_of["A", g["floor"], g["line_a"]], node_of["B", g["floor"], g["line_b"]]
        gap_element(ops, len(gaps) + 1, tag["ele"], ni, nj, g["k"], g["gap"])
        gaps.append((ni, nj, g["gap"]))
    newmark_transient(ops, P["record_t"], P["record_a"], "Plain")
    mpeak = {c: 0.0 for c in columns}
    pen = [0.0] * len(gaps)
    for _ in steps(ops, P["t_end"], P["dt"]):
        for c, e in columns.items():
            f = ops.eleResponse(e, "localForce")
            mpeak[c] = max(mpeak[c], abs(f[2]), abs(f[5]))
        for g, (ni, nj, gap) in enumerate(gaps):
            pen[g] = max(pen[g], ops.nodeDisp(ni, 1) - ops.nodeDisp(nj, 1) - gap)
    Path(out_file).write_text(json.dumps({"moments": mpeak, "penetration": pen, "version": version(ops)}))


# --- the martello half --------------------------------------------------------------------------

def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-o", "--out", help="the folder the run's files and the table are written into")
    ap.add_argument("--python", help="an interpreter with openseespy (default: this one)")
    ap.add_argument("--docs", action="store_true",
                    help="also write the table to docs/p10/opensees_check.txt (record 1, 20 s)")
    ap.add_argument("--record", type=int, default=1)
    ap.add_argument("--dt", type=float, default=5e-4)
    ap.add_argument("--t-end", type=float, default=20.0)
    ap.add_argument("--opensees-worker", nargs=2, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.opensees_worker:
        return opensees_worker(*args.opensees_worker)
    if not args.out:
        ap.error("give -o DIR, the folder the run's files are written into")
    sys.path.insert(0, str(HERE))
    import case_study as cs
    from martello.ground_motion.records import read_record
    from martello.run import run_full
    py = opensees_python(args.python)
    if py is None:
        print(SKIPPED)
        return 0
    sc = cs.scene_for("bare", args.record, dt=args.dt, t_end=args.t_end, tol_residual=1e-12)
    s, _ = run_full(sc)
    rec = read_record(sc.ground["file"], fmt=sc.ground["format"], units=sc.ground["units"])
    frames = []
    for fr_tab, fr in zip(cs.scene_dict("bare")["frame"], sc.extras["frames"]):
        masses = dict(zip((n.split(".", 1)[0][1:] + "." + n.split(".", 1)[1] for n in fr["nodes"]),
                          fr["frame"].lateral_masses().tolist()))
        frames.append({"prefix": fr_tab["prefix"], "storeys": fr_tab["storeys"], "bays": fr_tab["bays"],
                       "storey_height": fr_tab["storey_height"], "bay_width": fr_tab["bay_width"],
                       "x0": 0.0 if fr_tab["prefix"] == "A" else fr_tab["bays"] * fr_tab["bay_width"],
                       "column": fr_tab["column"], "beam": fr_tab["beam"], "joint_mass": masses,
                       "rayleigh": list(fr["rayleigh"])})
    params = {"frames": frames, "dt": args.dt, "t_end": args.t_end,
              "gaps": [{"floor": f, "line_a": cs.BAYS, "line_b": 0, "k": cs.GAP_K, "gap": cs.JOINT} for f in (1, 2)],
              "record_t": rec.t.tolist(), "record_a": rec.accel.tolist()}
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    os_res = run_opensees_half(py, __file__, params, out)
    if os_res is None:
        return 1
    lines = []
    emit = lines.append      # the table is printed and written to docs/p10
    emit(f"P10 bare, record {args.record}, Newmark (1/2, 1/4), dt = {args.dt:g} s, t_end = {args.t_end:g} s; "
          f"OpenSees {os_res['version']} (openseespy)")
    emit(f"{'column':>10} {'martello |M| [N m]':>20} {'OpenSees |M| [N m]':>20} {'rel. diff':>10}")
    worst = 0.0
    for frame in ("A", "B"):
        for name, m in cs.column_peaks(s, frame).items():
            o = os_res["moments"][f"{frame}.{name}"]
            d = abs(m - o) / abs(o)
            worst = max(worst, d)
            emit(f"{frame + '.' + name:>10} {m:>20.9e} {o:>20.9e} {d:>10.2e}")
    for f in (1, 2):
        m = s["contacts"][f"gap{f}"]["max_penetration"]
        o = max(os_res["penetration"][f - 1], 0.0)
        emit(f"{'gap' + str(f):>10} {m:>20.9e} {o:>20.9e} {abs(m - o) / max(abs(o), 1e-300):>10.2e}  (penetration [m])")
    emit(f"worst relative difference of the column moments: {worst:.2e}")
    text = "\n".join(lines)
    sys.stdout.write(text + "\n")
    table = "benchmarks/p10/opensees_check.py --record %d --dt %g\n" % (args.record, args.dt) + text + "\n"
    (out / "opensees_check.txt").write_text(table)
    if args.docs:
        if not (args.t_end == 20.0 and args.record == 1):
            print("--docs: docs/p10-case-study.md quotes record 1 over 20 s; not written")
            return 1
        (ROOT / "docs" / "p10").mkdir(exist_ok=True)
        (ROOT / "docs" / "p10" / "opensees_check.txt").write_text(table)
        print("written: docs/p10/opensees_check.txt")
    return 0


if __name__ == "__main__":
    sys.exit(main())
