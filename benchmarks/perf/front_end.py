#!/usr/bin/env python3
"""Front-end phases of a large chain run: scene expansion and validation (from_dict), building
the native model (martello.run.build_model), the native run, building the summary from the
library's result arrays, and writing the results (martello.run.write_results, to a temporary
folder) — wall seconds of each, and the process' peak RSS per DOF, in one process per n.

The scene is benchmarks/perf/chain_perf.py's chain (bilinear oscillators, Kelvin contacts
pre-compressed, ground sine), run for --steps steps (default 10: the native time loop is
measured by chain_perf.py; here it only has to produce results to summarise).
Usage: benchmarks/perf/front_end.py [--n 100000 1000000] [--steps 10] [--repeat 1]
To time another version of the Python front end against this library (e.g. `git archive OLD
martello | tar -x -C /tmp/old`): --front-end /tmp/old with MARTELLO_LIB=build/libmartello.so."""

import argparse
import json
import os
import subprocess
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
ROOT = HERE.parents[1]


def one(n, steps, front_end=None, toml=False):
    """Time the phases of one size in this process; print a JSON line."""
    sys.path.insert(0, str(HERE))
    from chain_perf import chain_scene     # (puts this checkout on sys.path)
    if front_end:
        # ahead of the checkout's editable install (a finder on sys.meta_path)
        sys.meta_path[:] = [f for f in sys.meta_path if "Editable" not in type(f).__name__
                            and "editable" not in type(f).__module__]
        sys.path.insert(0, front_end)
    import resource
    import tempfile
    import martello.run as run_module
    from martello.binding import native
    from martello.scene.loader import from_dict
    dt = 1e-3
    parse_s = None
    if toml:
        # chain_vs_opensees.py's scene file (k a list of n numbers): parsed by tomllib, then
        # validated; parse_s is the parser's share
        import tomllib
        from chain_vs_opensees import scene_toml
        text = scene_toml(n, steps)
        t0 = time.perf_counter()
        data = tomllib.loads(text)
        parse_s = time.perf_counter() - t0
        scene = from_dict(data, digest="-")
    else:
        t0 = time.perf_counter()
        scene = from_dict(chain_scene(n, t_end=steps * dt, dt=dt))
    t1 = time.perf_counter()
    model = run_module.build_model(scene)
    t2 = time.perf_counter()
    # the native run's own clock (cost.wall_time_s) splits _dynamic into run and summary
    summary, history = run_module._dynamic(scene, model)[:2]
    t3 = time.perf_counter()
    model.free()
    write_s = None
    if hasattr(run_module, "write_history"):        # this front end writes what it built
        with tempfile.TemporaryDirectory() as tmp:
            t4 = time.perf_counter()
            run_module.write_results(summary, Path(tmp) / "out", history)
            write_s = time.perf_counter() - t4
    native_s = summary["cost"]["wall_time_s"]
    print(json.dumps({"n": n, "steps": summary["cost"]["steps"], "version": native.version(),
                      "front_end": run_module.__file__,
                      "parse_s": parse_s, "expand_s": t1 - t0 - (parse_s or 0.0), "build_model_s": t2 - t1, "native_run_s": native_s,
                      "summary_s": t3 - t2 - native_s, "write_s": write_s,
                      "peak_rss_bytes_per_dof": resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
                      * 1024 / n}))


def main():
    ap = argparse.ArgumentParser(description=__doc__,
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, nargs="*", default=[100000, 1000000])
    ap.add_argument("--steps", type=int, default=10)
    ap.add_argument("--repeat", type=int, default=1)
    ap.add_argument("--front-end", help="a directory holding another martello package to time")
    ap.add_argument("--toml", action="store_true", help="the scene of chain_vs_opensees.py, "
                    "parsed from its TOML text (its k is a list of n numbers)")
    ap.add_argument("--one", type=int, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.one:
        one(args.one, args.steps, args.front_end, args.toml)
        return
    print(f"{os.cpu_count()} cores, load average {os.getloadavg()[0]:.2f}")
    print(f"{'n':>8} {'steps':>6} {'parse s':>8} {'expand s':>9} {'build s':>8} {'run s':>7} {'summary s':>9} "
          f"{'write s':>8} {'B/DOF':>7} {'load':>5}")
    for n in args.n:
        for _ in range(args.repeat):
            p = subprocess.run([sys.executable, __file__, "--one", str(n), "--steps",
                                str(args.steps)] + (["--front-end", args.front_end] if args.front_end else [])
                              + (["--toml"] if args.toml else []),
                               capture_output=True, text=True)
            if p.returncode != 0:
                print(f"{n:>8} failed: {p.stderr.strip().splitlines()[-1]}")
                continue
            r = json.loads(p.stdout.strip().splitlines()[-1])
            w = f"{r['write_s']:>8.2f}" if r.get("write_s") is not None else f"{'-':>8}"
            rss = r.get("peak_rss_bytes_per_dof")
            parse = f"{r['parse_s']:>8.2f}" if r.get("parse_s") is not None else f"{'-':>8}"
            print(f"{r['n']:>8} {r['steps']:>6} {parse} {r['expand_s']:>9.2f} {r['build_model_s']:>8.2f} "
                  f"{r['native_run_s']:>7.2f} {r['summary_s']:>9.2f} {w} "
                  f"{rss if rss is None else format(rss, '7.0f')} {os.getloadavg()[0]:>5.2f}  "
                  f"{r['version']} {r['front_end']}")
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
