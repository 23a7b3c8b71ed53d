#!/usr/bin/env python3
"""The fused chain step against a lean two-sweep kernel of the same chain, side by side
(docs/performance.md "The fused step against a lean kernel").

    .venv/bin/python benchmarks/perf/fused_vs_lean.py -o DIR [--n 100000] [--steps 2000]
        [--repeats 5] [--track contact_peaks] [--lib build] [--native-lib build-native] [--docs]
    .venv/bin/python benchmarks/perf/fused_vs_lean.py --docs --from DIR/fused_vs_lean.json
    .venv/bin/python benchmarks/perf/fused_vs_lean.py --check

A = the library's fused chain step on the benchmark's chain (benchmarks/perf/chain_native.c
through the C API: Newmark average acceleration, Δt = 1 ms, what --track says is measured);
B = benchmarks/perf/lean_chain.f90, the same chain written by hand as two sweeps (reciprocal
pivots kept, a refactorisation where a contact changes branch, nothing measured), compiled
with the library's Fortran flags (its compile command in the build's build.ninja: -O3
-ffp-contract=off, link-time optimisation, and -march=native in a MARTELLO_NATIVE build). Both run the same equations: each run
checks that they end with the same u of the first and last node, to the bit. The runs
alternate (A B A B ..., each its own process; with --native-lib also the native library's
A and a native lean B), and each figure is the median over the repeats of the time loop's own
clock (the library's around martello_dynamic_run, the lean program's around its loop), per
DOF-step; A/B is the median of the pairwise ratios, of the wall times and of the CPU times of
the same loops (on a shared machine a process waits: its CPU time is the time it ran).
Everything is written into DIR (the two programs, fused_vs_lean.json, fused_vs_lean.md);
--docs also keeps the results as docs/perf/fused_vs_lean.json and their table in
docs/performance.md (benchmarks/perf/measured_docs.py), --from records a finished run's JSON,
--check finds the page's table the same as its record's (CI).
"""

import argparse
import json
import os
import re
import statistics
import subprocess
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import measured_docs  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
HERE = Path(__file__).resolve().parent
NAME = "fused_vs_lean"        # its record docs/perf/fused_vs_lean.json, its fence in docs/performance.md


def fortran_flags(build):
    """The flags the build compiles the library's Fortran with (its compile command in
    build.ninja: the project's flags, the Release optimisation, link-time optimisation, a
    MARTELLO_NATIVE build's -march=native), without those of a shared library's objects."""
    text = (Path(build) / "build.ninja").read_text()
    m = re.search(r"^build CMakeFiles/martello\.dir/fortran/\S+\.f90\.o: Fortran_COMPILER\S*.*\n"
                  r"  FLAGS = (.*)$", text, re.M)
    if not m:
        raise SystemExit(f"{build}/build.ninja: no Fortran compile command of the library")
    drop = ("-DNDEBUG", "-fPIC", "-fpreprocessed", "-fno-fat-lto-objects", "-fno-semantic-interposition")
    return [f for f in m.group(1).split() if f not in drop and not f.startswith("-J")]


def build_pair(build, out, tag):
    """chain_native against the library of build, and the lean kernel with its flags."""
    build = Path(build).resolve()
    fused, lean = out / f"chain_native_{tag}", out / f"lean_chain_{tag}"
    subprocess.run(["cc", "-O2", "-I", str(ROOT / "c"), "-I", str(build / "include"),
                    str(HERE / "chain_native.c"), "-o", str(fused), f"-L{build}", "-lmartello",
                    f"-Wl,-rpath,{build}", "-lm"], check=True)
    flags = fortran_flags(build)
    subprocess.run(["gfortran", *flags, "-J", str(out), str(HERE / "lean_chain.f90"), "-o", str(lean)],
                   check=True)
    return {"fused": str(fused), "lean": str(lean), "flags": " ".join(flags)}


def run(cmd):
    r = subprocess.run([str(c) for c in cmd], capture_output=True, text=True)
    if r.returncode != 0:
        raise RuntimeError(f"{cmd[0]} failed: {r.stderr.strip()[-500:]}")
    return json.loads(r.stdout.strip().splitlines()[-1])


def measure(a):
    out = Path(a.out).resolve()
    out.mkdir(parents=True, exist_ok=True)
    builds = {"generic": build_pair(a.lib, out, "generic")}
    if a.native_lib:
        builds["native"] = build_pair(a.native_lib, out, "native")
    runs = {(tag, kind): [] for tag in builds for kind in ("fused", "lean")}
    loads = []
    order = [(tag, kind) for tag in builds for kind in ("fused", "lean")]
    for rep in range(a.repeats):
        loads.append(os.getloadavg()[0])
        for tag, kind in (order if rep % 2 == 0 else order[::-1]):
            b = builds[tag]
            cmd = ([b["fused"], a.n, a.steps, "--track", a.track] if kind == "fused"
                   else [b["lean"], a.n, a.steps])
            runs[tag, kind].append(run(cmd))
    loads.append(os.getloadavg()[0])
    same = True
    u_ref = (runs["generic", "lean"][0]["u_first"], runs["generic", "lean"][0]["u_last"])
    for rs in runs.values():
        for r in rs:
            same = same and (float(r["u_first"]), float(r["u_last"])) == (float(u_ref[0]), float(u_ref[1]))
    per = a.n * a.steps / 1e9
    ns = {f"{t}/{k}": [r["wall_s"] / per for r in rs] for (t, k), rs in runs.items()}
    cpu = {f"{t}/{k}": [r["cpu_s"] / per for r in rs] for (t, k), rs in runs.items()}
    return {"n": a.n, "steps": a.steps, "track": a.track, "repeats": a.repeats,
            "date_utc": time.strftime("%Y-%m-%d %H:%M", time.gmtime()), "commit": measured_docs.commit(),
            "load": [min(loads), max(loads)], "same_u_to_the_bit": same,
            "ns_per_dof_step": ns, "cpu_ns_per_dof_step": cpu,
            "flags": {t: b["flags"] for t, b in builds.items()},
            "newton_per_step": runs["generic", "fused"][-1]["newton"] / a.steps,
            "fused_steps": runs["generic", "fused"][-1]["fused"]}


def pairs(result, key, a, b):
    """The median of the pairwise ratios a/b of the figures under key."""
    return statistics.median(x / y for x, y in zip(result[key][a], result[key][b]))


def render(result):
    """The table of a run's results (fused_vs_lean.json)."""
    builds = list(result["flags"])
    med = {k: statistics.median(v) for k, v in result["ns_per_dof_step"].items()}
    cmed = {k: statistics.median(v) for k, v in result["cpu_ns_per_dof_step"].items()}
    lo, hi = result["load"]
    lines = [f"n = {result['n']}, {result['steps']} steps, the fused step measuring "
             f"{result['track']}; {result['repeats']} runs of each, alternating; "
             f"{result['date_utc']} UTC, commit {result['commit']}, load {lo:.1f}–{hi:.1f}; "
             f"the same u at the end to the bit: {'yes' if result['same_u_to_the_bit'] else 'NO'}",
             "",
             "| build | fused ns/DOF-step (CPU) | lean ns/DOF-step (CPU) | fused/lean, wall | fused/lean, CPU |",
             "|---|---|---|---|---|"]
    for t in builds:
        f, l = f"{t}/fused", f"{t}/lean"
        lines.append(f"| {t} (`{result['flags'][t]}`) | {med[f]:.2f} ({cmed[f]:.2f}) | "
                     f"{med[l]:.2f} ({cmed[l]:.2f}) | {pairs(result, 'ns_per_dof_step', f, l):.2f}× | "
                     f"**{pairs(result, 'cpu_ns_per_dof_step', f, l):.2f}×** |")
    if "native" in builds:
        g = {k: pairs(result, "cpu_ns_per_dof_step", f"generic/{k}", f"native/{k}") for k in ("fused", "lean")}
        gw = {k: pairs(result, "ns_per_dof_step", f"generic/{k}", f"native/{k}") for k in ("fused", "lean")}
        lines += ["", f"The native build's gain (generic/native, median of the pairs; CPU, wall): "
                      f"fused step {g['fused']:.2f}×, {gw['fused']:.2f}×; lean kernel "
                      f"{g['lean']:.2f}×, {gw['lean']:.2f}×"]
    return "\n".join(lines)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-o", "--out", help="the folder everything is written into")
    ap.add_argument("--n", type=int, default=100000)
    ap.add_argument("--steps", type=int, default=2000)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--track", default="contact_peaks", help="what the fused step measures "
                    "(chain_native --track: contact_peaks, all, none, ...)")
    ap.add_argument("--lib", default=str(ROOT / "build"), help="the build of the library (A)")
    ap.add_argument("--native-lib", help="a second build with -DMARTELLO_NATIVE=ON, measured beside it")
    ap.add_argument("--docs", action="store_true", help="keep the results as docs/perf/fused_vs_lean.json "
                    "and their table in docs/performance.md")
    ap.add_argument("--from", dest="source", help="a finished run's fused_vs_lean.json (no run)")
    ap.add_argument("--check", action="store_true", help="the page's table is its record's (CI)")
    a = ap.parse_args()
    if a.check:
        problem = measured_docs.check(NAME, render)
        print(problem or f"docs/performance.md: the table of {NAME} is its record's")
        return 1 if problem else 0
    if a.source:
        result = json.loads(Path(a.source).read_text())
    elif a.out:
        result = measure(a)
        out = Path(a.out).resolve()
        (out / "fused_vs_lean.json").write_text(json.dumps(result, indent=1))
    else:
        ap.error("-o DIR (a run), --from JSON or --check")
    table = render(result)
    print(table)
    if a.out and not a.source:
        (out / "fused_vs_lean.md").write_text(table + "\n")
        print(f"results: {out / 'fused_vs_lean.json'}, {out / 'fused_vs_lean.md'}")
    if a.docs:
        measured_docs.record(NAME, result, table)
    return 0 if result["same_u_to_the_bit"] else 1


if __name__ == "__main__":
    sys.exit(main())
