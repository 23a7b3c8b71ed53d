#!/usr/bin/env python3
"""Cost per simulated second of the reference-quality integrators at n = 300 … 10 000, and the
cost of a contact event at size (docs/sundials-ode.md "Events at size").

Scenes (one process per run, so that its CPU time is its own):
  closing  a row of n oscillators (m = 1e5 kg, k alternating 2e7 / 5e7 N/m, 5 % damping by
           dashpots to ground), linear penalty contacts (1e9 N/m) across 5 mm gaps, every
           other oscillator started towards its right neighbour: every contact
           closes within the window, each at its own time (speeds 0.2 … 0.4 m/s). ida, cvode, arkode at rtol 1e-8; the general
           Newmark path (fused_chain = false) and the fused chain step at dt = 1e-4 s.
  closed   the same row with every contact pre-compressed by 1 mm under a 3 m/s² ground pulse:
           every contact stays closed (moreau-jean, fast-nonlinear, and the others for
           comparison).
Each run is cut at max_wall (default 60 s): the cost per simulated second is then its CPU
time over the time it reached. The exponents are least-squares slopes of log cost over log n.
Prints the machine load with each row (a shared machine: CPU time, not wall time, and ratios
within one run). Writes nothing unless --out is given.

Usage: benchmarks/perf/integrators_at_size.py [--n 300 1000 3000 10000]
       [--integrators ida cvode arkode newmark-general moreau-jean fast-nonlinear]
       [--scene closing|closed] [--t-end 0.1] [--max-wall 60] [--out DIR]"""

import argparse
import json
import math
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

ADAPTIVE = {"ida", "cvode", "arkode", "rk8pd", "rkf45", "msbdf"}


def scene(n, integrator, kind, t_end, max_wall):
    k = [2.0e7 if i % 2 == 0 else 5.0e7 for i in range(n)]
    chain = {"prefix": "b", "n": n, "mass": 1.0e5, "k": k, "zeta": 0.05,
             "contact": {"scheme": "penalty", "law": "linear", "stiffness": 1.0e9}}
    loads = {}
    if kind == "closing":
        chain["gap"] = 5.0e-3
        # speeds 0.2 … 0.4 m/s spread over the row: the contacts close at n/2 different times
        chain["v0"] = [0.3 + 0.1 * math.sin(1.7 * i) if i % 2 == 0 else 0.0 for i in range(n)]
    else:
        chain["gap"] = -1.0e-3
        loads = {"ground_acceleration": {"type": "sine", "amplitude": 3.0, "omega": 12.566370614359172}}
    if integrator == "moreau-jean" and kind == "closed":
        # Moreau–Jean's LCP is for the rigid contacts: the same row with restitution contacts
        # at zero gap (touching, so every contact is in the problem at every step)
        chain["contact"] = {"scheme": "restitution", "restitution": 0.0}
        chain["gap"] = 0.0
    an = {"type": "dynamic", "t_end": t_end, "max_wall": max_wall,
          "output": {"every": 1000000, "nodes": ["b1"], "contacts": []}}
    name = integrator
    if integrator in ADAPTIVE:
        an.update(integrator=integrator, dt=t_end, rtol=1e-8, atol=1e-12)
    elif integrator in ("newmark-general", "newmark-fused"):
        an.update(integrator="newmark", preset="average-acceleration", dt=1e-4,
                  fused_chain=integrator == "newmark-fused")
    else:
        an.update(integrator=integrator, dt=1e-4)
    return {"title": f"{name} n={n}", "chain": [chain], "loads": loads, "analysis": an}


def timed_run(scene_dict):
    """run_full of a scene dict (a failure is returned, not raised), its CPU seconds
    (getrusage of this process: run one scene per child process) and wall seconds (also
    benchmarks/perf/fna_ritz.py's worker)."""
    from martello.run import run_full
    from martello.scene.loader import from_dict
    s = from_dict(scene_dict)
    r0 = resource.getrusage(resource.RUSAGE_SELF)
    t0 = time.perf_counter()
    summary, hist = run_full(s, raise_on_failure=False)
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_SELF)
    return summary, hist, (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime), wall


def child(args):
    """A script's --one worker run in a child process (args after the interpreter): the JSON
    line it prints as a dict, else None and the last line of its stderr."""
    p = subprocess.run([sys.executable, *map(str, args)], capture_output=True, text=True)
    line = next((ln for ln in p.stdout.splitlines() if ln.startswith("{")), None)
    if line is None:
        return None, p.stderr.strip().splitlines()[-1:]
    return json.loads(line), None


def one(n, integrator, kind, t_end, max_wall):
    # max_wall stops a slow one: its rate stands
    r, _, cpu, wall = timed_run(scene(n, integrator, kind, t_end, max_wall))
    c = r["cost"]
    t_reached = r.get("t_reached", t_end) or t_end
    print(json.dumps({"n": n, "integrator": integrator, "scene": kind, "status": r["status"],
                      "t_reached": t_reached, "cpu_s": cpu, "wall_s": wall,
                      "cpu_per_sim_s": cpu / max(t_reached, 1e-300), "cost": c,
                      "load": os.getloadavg()[0]}))


def fit(ns, ys):
    xs = [math.log(n) for n in ns]
    ls = [math.log(y) for y in ys]
    mx, my = sum(xs) / len(xs), sum(ls) / len(ls)
    den = sum((x - mx) ** 2 for x in xs)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ls)) / den if den > 0 else float("nan")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, nargs="*", default=[300, 1000, 3000, 10000])
    ap.add_argument("--integrators", nargs="*",
                    default=["ida", "cvode", "arkode", "newmark-general", "newmark-fused"])
    ap.add_argument("--scene", choices=("closing", "closed"), default="closing")
    ap.add_argument("--t-end", type=float, default=0.1)
    ap.add_argument("--max-wall", type=float, default=60.0)
    ap.add_argument("--out")
    ap.add_argument("--one", nargs=2, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.one:
        one(int(args.one[0]), args.one[1], args.scene, args.t_end, args.max_wall)
        return
    from martello.binding import native
    print(f"martello {native.version()} ({native.library_versions()}); {os.cpu_count()} cores; "
          f"scene {args.scene}, t_end {args.t_end} s, max_wall {args.max_wall} s")
    print(f"{'integrator':>16} {'n':>6} {'status':>7} {'t_reached':>9} {'CPU s':>8} {'CPU/sim s':>10} "
          f"{'steps':>8} {'RHS':>9} {'events':>7} {'steps/ev':>8} {'RHS/ev':>8} {'fact':>7} {'load':>5}")
    rows = []
    for integ in args.integrators:
        for n in args.n:
            row, err = child([__file__, "--one", n, integ, "--scene", args.scene,
                              "--t-end", args.t_end, "--max-wall", args.max_wall])
            if row is None:
                print(f"{integ:>16} {n:>6} failed: {err}")
                continue
            rows.append(row)
            c, ev = row["cost"], max(row["cost"]["events"], 1)
            print(f"{integ:>16} {n:>6} {row['status']:>7} {row['t_reached']:9.4g} {row['cpu_s']:8.3g} "
                  f"{row['cpu_per_sim_s']:10.4g} {c['steps']:8d} {c['residual_evaluations']:9d} "
                  f"{c['events']:7d} {c['steps'] / ev:8.3g} {c['residual_evaluations'] / ev:8.3g} "
                  f"{c['factorizations']:7d} {row['load']:5.2f}", flush=True)
    print("\nexponents of CPU per simulated second in n (least squares over the sizes run):")
    for integ in args.integrators:
        mine = [r for r in rows if r["integrator"] == integ and r["cpu_per_sim_s"] > 0]
        if len(mine) >= 2:
            ns = [r["n"] for r in mine]
            print(f"  {integ:>16}: n^{fit(ns, [r['cpu_per_sim_s'] for r in mine]):.2f} "
                  f"over n = {', '.join(map(str, ns))}")
    if args.out:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        (out / f"integrators_at_size_{args.scene}.json").write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
