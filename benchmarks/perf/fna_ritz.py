#!/usr/bin/env python3
"""Fast nonlinear analysis with Wilson's load-dependent Ritz vectors (analysis.modal_vectors = m)
against all modes: accuracy and cost as the scene grows (docs/integrators.md "fast nonlinear
analysis").

Scene `row` (size-independent local dynamics, global coupling): n oscillators of m = 1e5 kg on
springs to ground (k alternating 2e7 / 5e7 N/m) with 5 % dashpots to ground, neighbours joined by
weak springs (1e6 N/m: the linear part couples every node, half-bandwidth 1), a 3 m/s² sine
ground acceleration at 2 Hz, and 4 linear penalty contacts (1e9 N/m, 2 mm gaps) between
neighbours at n/5, 2n/5, 3n/5, 4n/5: the oscillators' different frequencies close them.
fast-nonlinear, dt 1 ms, t_end 0.5 s, tol_residual 1e-10.

For each n: all modes where n <= --modes-max (the reference; its dense eigensolve is O(n³)),
then each m of --m: CPU seconds of the run (getrusage of a child process: its own), the basis
size kept, Newton passes a step, and the error against all modes — max |u − u_all| over every
node and output time / max |u_all|, and the contacts' largest force, relative. The exponents
are least-squares slopes of CPU per simulated second over n. Writes nothing unless --out DIR.

Scene `closed` (--scene closed): benchmarks/perf/integrators_at_size.py's row with every contact
closed (a contact between every pair of neighbours), dt 1e-4 s, every node recorded.

Usage: benchmarks/perf/fna_ritz.py [--n 300 1000 3000 10000] [--m 10 20 40] [--modes-max 1000]
       [--t-end 0.5] [--scene row|closed] [--out DIR]"""

import argparse
import json
import os
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

# the log-log slope, the timed run and the child process: defined there once
from benchmarks.perf import integrators_at_size as at_size  # noqa: E402
from benchmarks.perf.integrators_at_size import child, fit, timed_run  # noqa: E402


scene = at_size.row    # the row: defined there once


def closed(n, m, t_end):
    """integrators_at_size.py's scene `closed` (a contact between every pair, all closed) on
    fast-nonlinear with m vectors, every node's u recorded ~50 times."""
    sc = at_size.scene(n, f"fast-nonlinear:{m}" if m else "fast-nonlinear", "closed", t_end, 1.0e9)
    sc["analysis"]["output"] = {"every": max(1, int(round(t_end / 1e-4 / 50))),
                                "nodes": [f"b{i}" for i in range(1, n + 1)]}
    return sc


def one(n, m, t_end, dump, kind="row"):
    import numpy as np
    summary, hist, cpu, _ = timed_run((closed if kind == "closed" else scene)(n, m, t_end))
    cols = [i for i, k in enumerate(hist[0]) if k.startswith("u:")]
    np.save(dump, np.asarray(hist[1])[:, cols])
    print(json.dumps({"n": n, "m": m, "status": summary["status"], "cpu_s": cpu,
                      "cpu_per_sim_s": cpu / t_end, "cost": summary["cost"],
                      "forces": {k: c["max_force"] for k, c in summary["contacts"].items()},
                      "load": os.getloadavg()[0]}))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, nargs="*", default=[300, 1000, 3000, 10000])
    ap.add_argument("--m", type=int, nargs="*", default=[10, 20, 40])
    ap.add_argument("--modes-max", type=int, default=1000)
    ap.add_argument("--t-end", type=float, default=0.5)
    ap.add_argument("--scene", choices=("row", "closed"), default="row",
                    help="row (above) or integrators_at_size.py's closed row (dt 1e-4 s; a contact "
                    "between every pair: the patterns need m ~ n vectors)")
    ap.add_argument("--out")
    ap.add_argument("--one", nargs=3, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.one:
        one(int(args.one[0]), int(args.one[1]), args.t_end, args.one[2], args.scene)
        return
    import tempfile
    import numpy as np
    from martello.binding import native
    print(f"martello {native.version()}; {os.cpu_count()} cores; scene {args.scene}, fast-nonlinear, "
          f"dt {'1e-4 s' if args.scene == 'closed' else '1 ms'}, t_end {args.t_end} s")
    print(f"{'n':>6} {'m':>5} {'kept':>5} {'status':>12} {'CPU s':>8} {'CPU/sim s':>10} {'passes/step':>11} "
          f"{'u error':>9} {'force error':>11} {'load':>5}")
    rows = []
    with tempfile.TemporaryDirectory() as tmp:
        for n in args.n:
            ref = None
            for m in ([0] if n <= args.modes_max else []) + args.m:
                if m > n:
                    continue
                dump = os.path.join(tmp, f"u_{n}_{m}.npy")
                row, err = child([__file__, "--one", n, m, dump, "--t-end", args.t_end, "--scene", args.scene])
                if row is None:
                    print(f"{n:>6} {m:>5} failed: {err}")
                    continue
                u = np.load(dump)
                if m == 0:
                    ref = (u, row["forces"])
                uerr = ferr = float("nan")
                if ref is not None and u.shape == ref[0].shape:
                    uerr = float(np.abs(u - ref[0]).max() / np.abs(ref[0]).max())
                    fmax = max(ref[1].values())
                    ferr = max(abs(row["forces"][k] - ref[1][k]) for k in ref[1]) / fmax if fmax > 0 else float("nan")
                row.update(u_error=uerr, force_error=ferr)
                rows.append(row)
                c = row["cost"]
                print(f"{n:>6} {m if m else 'all':>5} {c['modes']:>5} {row['status']:>12} {row['cpu_s']:8.3g} "
                      f"{row['cpu_per_sim_s']:10.4g} {c['newton_iterations'] / max(c['steps'], 1):11.2f} "
                      f"{uerr:9.2e} {ferr:11.2e} {row['load']:5.2f}", flush=True)
    print("\nexponents of CPU per simulated second in n (least squares over the sizes run):")
    for m in [0] + args.m:
        mine = [r for r in rows if r["m"] == m and r["status"] == "MARTELLO_OK"]
        if len(mine) >= 2:
            print(f"  m = {m if m else 'all':>4}: n^{fit([r['n'] for r in mine], [r['cpu_per_sim_s'] for r in mine]):.2f}"
                  f" over n = {', '.join(str(r['n']) for r in mine)}")
    if args.out:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        (out / "fna_ritz.json").write_text(json.dumps(rows, indent=1))


if __name__ == "__main__":
    main()
