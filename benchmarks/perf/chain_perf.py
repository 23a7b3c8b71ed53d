#!/usr/bin/env python3
"""Chain performance benchmark: time per DOF per step of average-acceleration Newmark
on chains of n elasto-plastic oscillators whose contacts are all active, and peak memory.

Each n runs in its own process so that peak memory (ru_maxrss) belongs to that n alone.
The scene: m = 1e5 kg, k = 3e7 N/m, bilinear (F_y 4.9e4 N, 2 % hardening), 5 % damping,
Kelvin contacts (ε = 1e9 N/m, e = 0.65) pre-compressed by 1 mm so every contact stays
closed, ground acceleration 3 sin(4πt) m/s²; Δt = 1e-3 s, 8 s (8000 steps).
Usage: benchmarks/perf/chain_perf.py -o DIR [--n 10 100 1000] (the table and the plot go into DIR)"""

import argparse
import csv
import json
import os
import resource
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))


def chain_scene(n, t_end=8.0, dt=1e-3):
    return {
        "title": f"perf chain n={n}",
        "chain": [{"prefix": "b", "n": n, "mass": 1e5, "k": 3e7, "fy": 4.9e4, "hardening": 0.02,
                   "zeta": 0.05, "gap": -1e-3,
                   "contact": {"scheme": "penalty", "law": "kelvin", "stiffness": 1e9,
                               "restitution": 0.65}}],
        "loads": {"ground_acceleration": {"type": "sine", "amplitude": 3.0, "omega": 12.566370614359172}},
        "analysis": {"type": "dynamic", "integrator": "newmark", "preset": "average-acceleration",
                     "dt": dt, "t_end": t_end,
                     "output": {"every": 1000, "nodes": ["b1"], "contacts": []}},
    }


def one(n):
    """Run one size in this process; print a JSON line."""
    from martello.run import run
    from martello.scene.loader import from_dict
    s = from_dict(chain_scene(n))
    t0 = time.perf_counter()
    r = run(s)
    wall = time.perf_counter() - t0
    native = r["cost"]["wall_time_s"]
    steps = r["cost"]["steps"]
    from martello.results import lookup_item
    active = sum(1 for name in s.contacts.names if lookup_item(r, "contacts", name)["max_force"] > 0) \
        if "arrays" not in r else int((r["arrays"].column("contacts", "max_force") > 0).sum())
    print(json.dumps({
        "n": n, "steps": steps, "native_s": native, "total_s": wall,
        "ns_per_dof_step": native / (n * steps) * 1e9,
        "newton_per_step": r["cost"]["newton_iterations"] / steps,
        "residuals_per_step": r["cost"]["residual_evaluations"] / steps,
        "active_contacts": active, "contacts": len(s.contacts),
        "peak_rss_mib": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024,
        "status": r["status"], "energy_balance_relative": r["energy"]["balance_relative"]}))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, nargs="*", default=[10, 100, 1000, 10000, 100000])
    ap.add_argument("-o", "--out", required=True, help="the folder the table and the plot are written into")
    ap.add_argument("--one", type=int, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.one:
        one(args.one)
        return
    from martello.binding import native
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    print(f"martello {native.version()} ({native.library_versions()}); {os.cpu_count()} cores")
    print("average-acceleration Newmark, dt = 1e-3 s, 8 s; contacts pre-compressed (all active)")
    print(f"{'n':>8} {'steps':>6} {'native s':>9} {'ns/DOF/step':>12} {'Newton/step':>11} "
          f"{'active':>8} {'peak MiB':>9}")
    for n in args.n:
        p = subprocess.run([sys.executable, __file__, "--one", str(n)], capture_output=True, text=True)
        if p.returncode != 0:
            print(f"{n:>8} failed: {p.stderr.strip().splitlines()[-1]}")
            continue
        r = json.loads(p.stdout.strip().splitlines()[-1])
        rows.append(r)
        print(f"{r['n']:>8} {r['steps']:>6} {r['native_s']:>9.3f} {r['ns_per_dof_step']:>12.1f} "
              f"{r['newton_per_step']:>11.3f} {r['active_contacts']:>8} {r['peak_rss_mib']:>9.1f}", flush=True)
    with open(out / "chain_perf.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    ns = [r["n"] for r in rows]
    ax[0].semilogx(ns, [r["ns_per_dof_step"] for r in rows], "o-")
    ax[0].axhline(100, color="r", ls="--", label="target 100 ns")
    ax[0].set_xlabel("oscillators n"); ax[0].set_ylabel("ns per DOF per step"); ax[0].legend()
    ax[1].loglog(ns, [r["peak_rss_mib"] for r in rows], "o-")
    ax[1].set_xlabel("oscillators n"); ax[1].set_ylabel("peak resident memory [MiB]")
    fig.suptitle(f"martello {native.version()}: chain cost (Newmark avg. acc., dt = 1 ms, 8 s)")
    fig.tight_layout()
    fig.savefig(out / "chain_perf.png", dpi=110)
    print(f"table: {out / 'chain_perf.csv'}, plot: {out / 'chain_perf.png'}")


if __name__ == "__main__":
    main()
