"""Cross-check of a two-building 3D scene with eccentric pounding against OpenSees
(docs/buildings.md, "OpenSees cross-check").

    .venv/bin/python benchmarks/p11/opensees_check.py --python /path/to/venv/bin/python \\
        [--t-end 6] [--dt 1e-3] [--no-contacts] [-o DIR]

Two buildings side by side along x with a 2 cm joint: A (2 storeys, symmetric) and B (4
storeys, a stiff wall at one end of its plan, so that its floors twist), 3D frames on rigid
floors, gaps at the facing column nodes of the two shared floors along the joint (four per
floor: the impacts are eccentric), a sine ground motion along x. martello runs the scene
([[building]] frames condensed to ux, uy, rz per floor; contacts between plan points) with
Newmark average acceleration; OpenSees (openseespy, under --python) builds the same frames
uncondensed: elasticBeamColumn elements on 6-DOF nodes, a rigidDiaphragm per floor to a master
node at the mass centre carrying m, m and J, zeroLength gaps of an ElasticPPGap material
between the facing nodes, Rayleigh damping a0 M + a1 K with martello's coefficients (condensing
the massless DOFs of a1 K gives martello's a1 K*), UniformExcitation, Newmark (½, ¼) at the
same step, Newton with a displacement test at 1e-12 and the Transformation handler. The two
share only the input numbers; assembly, condensation, contact kinematics, solver and member
forces are each code's own.

Printed: the peak |ux|, |rz| of every floor, the peak penetration of every gap and the peak
|M3| of the joint-side columns from both codes, with their relative differences; with -o the
same table is also written to DIR/opensees_check.txt. openseespy is not a requirement of
martello: the OpenSees half runs under the interpreter given by --python (a venv of your own,
e.g. python -m venv /work/venvs/opensees && .../pip install openseespy numpy), else under this
one if it imports openseespy; without one the script prints a skip message."""

from __future__ import annotations

import argparse
import json
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

# the interpreter, the run of the OpenSees half, the gap and the analysis: shared with P10's check
from benchmarks.opensees.crosscheck import (SKIPPED, gap_element, newmark_transient,  # noqa: E402
                                            opensees_python, run_opensees_half, steps, version)

E = 3.0e10
G = E / 2.4
H = 3.0
GRID_X = [0.0, 5.0]                 # each building: one bay along x (its own origin)
GRID_Y = [0.0, 4.0, 8.0, 12.0]      # the joint's length: four frame lines across it
COLUMN = {"E": E, "b2": 0.4, "b3": 0.4, "cracked": 0.5}
BEAM = {"E": E, "b": 0.3, "h": 0.5, "cracked": 0.5}
WALL = {"E": E, "G": G, "A": 0.5, "I2": 2e-3, "I3": 0.6, "J": 5e-3}   # along x at B's far end
MASS = 1.2e5
JOINT = 0.02
GAP_K = 5.0e8
ZETA = 0.05


def building(prefix, storeys, x0, wall):
    b = {"prefix": prefix, "storeys": storeys, "storey_height": H, "model": "frame",
         "grid_x": [x0 + x for x in GRID_X], "grid_y": GRID_Y, "column": COLUMN, "beam": BEAM,
         "mass": MASS, "zeta": ZETA, "rayleigh_modes": [1, 3]}
    if wall:
        b["member"] = [{"name": "W", "x": x0 + 2.5, "y": GRID_Y[-1], "angle": 0.0, "section": WALL}]
    return b


def ground(t_end):
    """The record both codes read: 4 m/s² sin(8 t) sampled at 1 ms (a table: both codes
    interpolate the same samples linearly)."""
    import numpy as np
    t = np.arange(0.0, t_end + 1e-9, 1e-3)
    return t, 4.0 * np.sin(8.0 * t)


def scene(t_end, dt, contacts=True):
    xa = GRID_X[-1]                              # A's joint face; B starts 2 cm further
    xb = xa + JOINT
    t, acc = ground(t_end)
    d = {"title": "P11 OpenSees cross-check: two 3D frame buildings, eccentric pounding",
         "building": [building("A", 2, 0.0, False), building("B", 4, xb, True)],
         "loads": {"ground_acceleration": {"type": "table", "t": t.tolist(), "values": acc.tolist()}},
         "analysis": {"type": "dynamic", "integrator": "newmark", "dt": dt, "t_end": t_end,
                      "tol_residual": 1e-12, "output": {"contacts": []}}}
    if contacts:
        d["contact"] = [{"name": f"g{f}.{j}", "a": {"floor": f"A{f}", "x": xa, "y": y},
                         "b": {"floor": f"B{f}", "x": xb, "y": y}, "normal": [1.0, 0.0],
                         "gap": JOINT, "scheme": "penalty", "law": "linear", "stiffness": GAP_K}
                        for f in (1, 2) for j, y in enumerate(GRID_Y)]
        d["analysis"]["output"]["contacts"] = [c["name"] for c in d["contact"]]
    return d


# --- the OpenSees half (runs under the openseespy interpreter; no martello import) ------------

def opensees_worker(params_file, out_file):
    import math
    import openseespy.opensees as ops
    P = json.loads(Path(params_file).read_text())
    ops.wipe()
    ops.model("basic", "-ndm", 3, "-ndf", 6)
    tags = {"node": 0, "ele": 0, "transf": 0}
    node_at, masters, columns = {}, {}, {}

    def new(kind):
        tags[kind] += 1
        return tags[kind]

    def transf(axis3):
        t = new("transf")
        ops.geomTransf("Linear", t, *axis3)          # vecxz = local axis 3
        return t
    for b in P["buildings"]:
        pre, ns = b["prefix"], b["storeys"]
        lines = [(f"{i}.{j}", x, y, 0.0, b["column"]) for i, x in enumerate(b["grid_x"])
                 for j, y in enumerate(b["grid_y"])]
        lines += [(m["name"], m["x"], m["y"], m["angle"], m["section"]) for m in b["members"]]
        eles = []
        for name, x, y, ang, _ in lines:
            for s in range(ns + 1):
                n = new("node")
                ops.node(n, x, y, s * P["H"])
                node_at[pre, name, s] = n
                if s == 0:
                    ops.fix(n, 1, 1, 1, 1, 1, 1)
        for s in range(1, ns + 1):
            xc, yc = b["centre"]
            mn = new("node")
            ops.node(mn, xc, yc, s * P["H"])
            ops.fix(mn, 0, 0, 1, 1, 1, 0)
            ops.mass(mn, b["mass"], b["mass"], 0.0, 0.0, 0.0, b["inertia"])
            masters[pre, s] = mn
            ops.rigidDiaphragm(3, mn, *[node_at[pre, name, s] for name, *_ in lines])
        for name, x, y, ang, sec in lines:
            c, sn = math.cos(math.radians(ang)), math.sin(math.radians(ang))
            t = transf([-sn, c, 0.0])
            for s in range(1, ns + 1):
                e = new("ele")
                ops.element("elasticBeamColumn", e, node_at[pre, name, s - 1], node_at[pre, name, s],
                            sec["A"], sec["E"], sec["G"], sec["J"], sec["I2"], sec["I3"], t)
                columns[f"{pre}.{name}.{s}"] = e
                eles.append(e)
        bs = b["beam"]
        nx, ny = len(b["grid_x"]), len(b["grid_y"])
        for s in range(1, ns + 1):
            for i in range(nx):
                for j in range(ny):
                    for di, dj, axis3 in ((1, 0, [0.0, -1.0, 0.0]), (0, 1, [1.0, 0.0, 0.0])):
                        if i + di >= nx or j + dj >= ny:
                            continue
                        e = new("ele")
                        ops.element("elasticBeamColumn", e, node_at[pre, f"{i}.{j}", s],
                                    node_at[pre, f"{i + di}.{j + dj}", s],
                                    bs["A"], bs["E"], bs["G"], bs["J"], bs["I2"], bs["I3"], transf(axis3))
                        eles.append(e)
        a0, a1 = b["rayleigh"]
        ops.region(len(masters) + 1000, "-eleOnly", *eles, "-rayleigh", 0.0, a1, 0.0, 0.0)
        ops.region(len(masters) + 2000, "-nodeOnly", *[masters[pre, s] for s in range(1, ns + 1)],
                   "-rayleigh", a0, 0.0, 0.0, 0.0)
    gaps = []
    for g in P["gaps"]:
        ni, nj = node_at["A", g["line_a"], g["floor"]], node_at["B", g["line_b"], g["floor"]]
        gap_element(ops, len(gaps) + 1, new("ele"), ni, nj, g["k"], g["gap"])
        gaps.append((g["name"], ni, nj, g["gap"]))
    newmark_transient(ops, P["t"], P["a"], "Transformation")
    peak = {k: 0.0 for k in [f"{p}{s}.{q}" for (p, s) in masters for q in ("ux", "rz")]}
    pen = {name: 0.0 for name, *_ in gaps}
    mom = {c: 0.0 for c in columns}
    for _ in steps(ops, P["t_end"], P["dt"]):
        for (p, s), mn in masters.items():
            peak[f"{p}{s}.ux"] = max(peak[f"{p}{s}.ux"], abs(ops.nodeDisp(mn, 1)))
            peak[f"{p}{s}.rz"] = max(peak[f"{p}{s}.rz"], abs(ops.nodeDisp(mn, 6)))
        for name, ni, nj, gap in gaps:
            pen[name] = max(pen[name], ops.nodeDisp(ni, 1) - ops.nodeDisp(nj, 1) - gap)
        for c, e in columns.items():
            f = ops.eleResponse(e, "localForce")     # N Vy Vz T My Mz at i, then j
            mom[c] = max(mom[c], abs(f[5]), abs(f[11]))
    Path(out_file).write_text(json.dumps({"peak": peak, "penetration": pen, "moments": mom,
                                          "version": version(ops)}))


# --- the martello half ------------------------------------------------------------------------

def section_props(sec, kind):
    from martello.scene.building import section
    s = section("<check>", "section", sec, kind)
    return {"E": s.E, "G": s.G, "A": s.A, "I2": s.I2, "I3": s.I3, "J": s.J}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--python", help="an interpreter with openseespy (default: this one)")
    ap.add_argument("--dt", type=float, default=1e-3)
    ap.add_argument("--t-end", type=float, default=6.0)
    ap.add_argument("--no-contacts", action="store_true", help="the two buildings alone (no gaps)")
    ap.add_argument("-o", "--output", help="a folder for opensees_check.txt (nothing written without it)")
    ap.add_argument("--opensees-worker", nargs=2, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.opensees_worker:
        return opensees_worker(*args.opensees_worker)
    py = opensees_python(args.python)
    if py is None:
        print(SKIPPED)
        return 0
    import numpy as np
    from martello.binding import native
    from martello.run import run_full
    from martello.scene.loader import from_dict
    d = scene(args.t_end, args.dt, contacts=not args.no_contacts)
    sc = from_dict(d)
    s, (cols, hist) = run_full(sc)
    if s["status"] != "MARTELLO_OK":
        print(f"martello failed: {s['message']}")
        return 1
    t, acc = ground(args.t_end)
    buildings = []
    for tab, b in zip(d["building"], sc.extras["buildings"]):
        fl = b["building"].floors[0]
        buildings.append({"prefix": tab["prefix"], "storeys": tab["storeys"], "grid_x": tab["grid_x"],
                          "grid_y": tab["grid_y"], "column": section_props(COLUMN, "column"),
                          "beam": section_props(BEAM, "beam"),
                          "members": [dict(m, section=section_props(m["section"], "column"))
                                      for m in tab.get("member", [])],
                          "mass": fl.mass, "inertia": fl.inertia, "centre": list(fl.centre),
                          "rayleigh": list(b["rayleigh"])})
    gaps = [{"name": c["name"], "floor": int(c["a"]["floor"][1:]), "line_a": f"{len(GRID_X) - 1}.{j}",
             "line_b": f"0.{j}", "k": GAP_K, "gap": JOINT}
            for c in d.get("contact", []) for j in [GRID_Y.index(c["a"]["y"])]]
    params = {"buildings": buildings, "gaps": gaps, "H": H, "dt": args.dt, "t_end": args.t_end,
              "t": t.tolist(), "a": acc.tolist()}
    with tempfile.TemporaryDirectory() as tmp:
        os_res = run_opensees_half(py, __file__, params, tmp)
    if os_res is None:
        return 1
    lines = [f"P11 OpenSees cross-check (benchmarks/p11/opensees_check.py --dt {args.dt:g} --t-end {args.t_end:g}"
             f"{' --no-contacts' if args.no_contacts else ''}): martello {native.version()}, "
             f"OpenSees {os_res['version']} (openseespy); Newmark (1/2, 1/4), sine 4 m/s2 at 8 rad/s along x",
             f"{'quantity':>16} {'martello':>18} {'OpenSees':>18} {'rel. diff':>10}"]
    worst = 0.0

    def row(name, m, o, unit):
        nonlocal worst
        dd = abs(m - o) / max(abs(o), 1e-300)
        worst = max(worst, dd)
        lines.append(f"{name:>16} {m:>18.10e} {o:>18.10e} {dd:>10.2e}  {unit}")
    # peaks over the samples of both codes (martello's summary locates its peaks inside the
    # steps; OpenSees has its samples only)
    sampled = lambda c: float(np.max(np.abs(hist[:, cols.index(c)])))       # noqa: E731
    for k, o in os_res["peak"].items():
        m = sampled(f"u:{k}")
        if max(m, o) < 1e-12:
            lines.append(f"{k:>16} {m:>18.10e} {o:>18.10e} {'round-off':>10}  (symmetric building)")
            continue
        row(k, m, o, "[m]" if k.endswith("ux") else "[rad]")
    for name, o in os_res["penetration"].items():
        m = float(np.max(hist[:, cols.index(f"penetration:{name}")]))
        row(name, max(m, 0.0), max(o, 0.0), "penetration [m]")
    for c, o in os_res["moments"].items():
        pre, line, st = c.split(".", 1)[0], c.split(".", 1)[1].rsplit(".", 1)[0], int(c.rsplit(".", 1)[1])
        if line == "W":
            mname = f"W.{st}"
        elif (pre == "A" and line.startswith(f"{len(GRID_X) - 1}.")) or (pre == "B" and line.startswith("0.")):
            mname = f"C{st}.{line}"
        else:
            continue
        mm = s["buildings"][pre]["members"][mname]
        m = max(abs(mm[q][k]) for q in ("M3_i", "M3_j") for k in ("max", "min"))
        row(f"{pre}.{mname} |M3|", m, o, "[N m]")
    lines.append(f"worst relative difference: {worst:.2e}")
    text = "\n".join(lines)
    print(text)
    if args.output:
        out = Path(args.output)
        out.mkdir(parents=True, exist_ok=True)
        (out / "opensees_check.txt").write_text(text + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
