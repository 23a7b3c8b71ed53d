#!/usr/bin/env python3
"""martello and OpenSeesPy side by side on the same chain scenes (docs/performance.md).

The scene: n oscillators in a row, m = 1 kg, k alternating 100 and 400 N/m (P7's two
buildings repeated), 5 % damping as a dashpot to ground, 10 mm gaps closed by linear
compression-only contacts (ε = 1e5 N/m; OpenSees: zeroLength + ElasticPPGap, as
benchmarks/perf/opensees_compare.py), ground acceleration 3 sin 8t m/s²; Newmark average
acceleration, Δt = 1 ms. Every pair of neighbours pounds: the contacts close and open
throughout the run. OpenSees: the compact model — one fixed ground node that every
oscillator's spring and dashpot (zeroLength) join, the oscillators numbered in a row after it
(the Plain handler takes the fixed DOF out of the system, so BandGeneral's band is the
chain's) — BandGeneral, Newton, NormDispIncr 1e-12 (30 iterations).

Each run is its own process (peak RSS is that run's), the two codes alternate, and each
figure is the median of the repeats. Reported per n: the time loop in ns per DOF per step
(martello: the library's own clock around its time loop, `cost.wall_time_s`; OpenSees: the
clock around `analyze`), their ratio, the whole process (martello: `martello run` from scene
file to summary.json written), peak RSS per DOF, the Python share of martello's process, and
the agreement of the two codes on every node's peak |u| (martello locates each peak inside
its step, docs/results.md, OpenSees' EnvelopeNode takes the samples: martello's is the larger
by the located excess, and below OpenSees' nowhere by more than round-off, the samples being
the same solution's; both are printed). Then the cost exponent in n (least
squares on log t against log n), a STREAM-like triad (benchmarks/perf/triad.c) for the memory
floor, and P7's two oscillators with the linear contact, whole process against whole process.

OpenSeesPy runs in an environment of the caller's (--opensees-python PY, a Python that imports
openseespy: `python -m venv DIR && DIR/bin/pip install openseespy`, outside the checkout); the
script installs nothing, and without one it measures martello alone and says so. Everything
it writes goes into the folder -o names (scenes, runs, the compiled programs, the JSON
results); --docs NAME also keeps them as docs/perf/<name>.json and their table in
docs/performance.md (benchmarks/perf/measured_docs.py; --check: the page's tables are their
records', in CI). The machine is shared: the load average is printed with every figure, and
the CPU time beside the wall time.

--library measures the library alone instead: benchmarks/perf/chain_native.c (compiled here
against build/libmartello.so) builds the same chain through the C API, as a chain held per node
(martello_model_add_chain) or with --items as links and contacts, runs it and reports the
library's clock around martello_dynamic_run, the process' CPU time, and its resident memory per
DOF: the model once built, and the peak of the run over the memory before the model; --track
keeps only what it lists (martello_run_set_tracking).

    .venv/bin/python benchmarks/perf/chain_vs_opensees.py -o DIR [--n 1000 10000 100000]
        [--steps 8000] [--repeats 3] [--opensees-python PY] [--opensees-max-n 10000]
        [--docs NAME]
    .venv/bin/python benchmarks/perf/chain_vs_opensees.py --docs NAME --from DIR/chain_vs_opensees.json
    .venv/bin/python benchmarks/perf/chain_vs_opensees.py --check
    .venv/bin/python benchmarks/perf/chain_vs_opensees.py -o DIR --library [--items]
        [--track node_peaks,contact_peaks] --n 1000 10000 100000 1000000 --steps 8000
"""

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(Path(__file__).resolve().parent))
import measured_docs  # noqa: E402

# the measured tables of docs/performance.md this script writes (--docs NAME): the side by
# side with OpenSees, and a million oscillators alone (at the page's commit, and a run on a
# quiet machine kept beside it: the clock of a shared machine is its load)
DOCS = ("chain_vs_opensees", "chain_1e6", "chain_1e6_quiet")
M, K1, K2, ZETA, GAP, EPS, AMP, OMEGA, DT = 1.0, 100.0, 400.0, 0.05, 0.01, 1.0e5, 3.0, 8.0, 1e-3


def scene_toml(n, steps, dt=DT, every=None, track=None):
    """The chain as a martello scene ([[chain]]); records two nodes, every 1000th step; track:
    what the run keeps (analysis.output.track; None: the scene's default, docs/results.md)."""
    ks = ", ".join("100.0" if i % 2 == 0 else "400.0" for i in range(n))
    every = every or max(1, min(steps, 1000))
    return f"""title = "chain of {n} pounding oscillators (linear contacts)"
[[chain]]
prefix = "b"
n = {n}
mass = {M}
k = [{ks}]
zeta = {ZETA}
gap = {GAP}
contact = {{ scheme = "penalty", law = "linear", stiffness = {EPS} }}
[loads.ground_acceleration]
type = "sine"
amplitude = {AMP}
omega = {OMEGA}
[analysis]
type = "dynamic"
integrator = "newmark"
preset = "average-acceleration"
dt = {dt}
t_end = {steps * dt!r}
[analysis.output]
every = {every}
nodes = ["b1", "b{n}"]
contacts = []
""" + (f"track = {json.dumps(list(track))}\n" if track is not None else "")


def opensees_one(n, steps, dt, out):
    """Runs inside the OpenSeesPy environment: the same chain, the time loop timed."""
    t_start = time.perf_counter()
    import openseespy.opensees as ops
    ops.wipe()
    ops.model("basic", "-ndm", 1, "-ndf", 1)
    # the compact model: one fixed ground node (tag 1), oscillator i is node i + 1; the Plain
    # constraint handler takes the fixed DOF out of the equations and the Plain numberer
    # numbers the oscillators in a row, so BandGeneral's band is the chain's
    ground = 1
    ops.node(ground, 0.0)
    ops.fix(ground, 1)
    for i in range(1, n + 1):
        ops.node(i + 1, 0.0)
        ops.mass(i + 1, M)
    c1, c2 = 2 * ZETA * math.sqrt(K1 * M), 2 * ZETA * math.sqrt(K2 * M)
    ops.uniaxialMaterial("Elastic", 1, K1)
    ops.uniaxialMaterial("Elastic", 2, K2)
    ops.uniaxialMaterial("Viscous", 3, c1, 1.0)
    ops.uniaxialMaterial("Viscous", 4, c2, 1.0)
    # contact i, i+1: deformation u_i − u_{i+1} (node j minus node i of the element), a
    # linear spring in tension past the gap (F_y far beyond any force)
    ops.uniaxialMaterial("ElasticPPGap", 5, EPS, 1.0e12, GAP)
    e = 0
    for i in range(1, n + 1):
        odd = i % 2 == 1                        # b1, b3, ...: k = 100 (martello's k[0], k[2] ...)
        e += 1
        ops.element("zeroLength", e, ground, i + 1, "-mat", 1 if odd else 2, "-dir", 1)
        e += 1
        ops.element("zeroLength", e, ground, i + 1, "-mat", 3 if odd else 4, "-dir", 1)
    for i in range(1, n):
        e += 1
        ops.element("zeroLength", e, i + 2, i + 1, "-mat", 5, "-dir", 1)
    ops.timeSeries("Trig", 1, 0.0, 1.0e6, 2 * math.pi / OMEGA, "-factor", AMP)
    ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
    env = Path(out) / "envelope.out"
    ops.recorder("EnvelopeNode", "-file", str(env), "-precision", 16, "-node",
                 *range(2, n + 2), "-dof", 1, "disp")
    ops.constraints("Plain")
    ops.numberer("Plain")
    ops.system("BandGeneral")
    ops.test("NormDispIncr", 1.0e-12, 30)
    ops.algorithm("Newton")
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")
    t0, c0 = time.perf_counter(), time.process_time()
    ok = ops.analyze(steps, dt)
    loop, loop_cpu = time.perf_counter() - t0, time.process_time() - c0
    ops.wipe()                                  # flushes the recorder
    rows = [list(map(float, line.split())) for line in env.read_text().split("\n") if line.strip()]
    print(json.dumps({"ok": ok == 0, "loop_s": loop, "loop_cpu_s": loop_cpu, "setup_s": t0 - t_start,
                      "absmax": rows[2] if len(rows) >= 3 else None}))


def peak_agreement(martello, opensees):
    """The largest relative difference of the two codes' peak |u| over the nodes, and the
    largest amount, relative, by which martello's (located inside the steps) is below
    OpenSees' (the largest sample): round-off where both solve the same equations."""
    rel = [(x - y) / max(abs(y), 1e-300) for x, y in zip(martello, opensees)]
    return max(abs(d) for d in rel), max(-d for d in rel)


def run_child(cmd):
    """cmd in a child process, measured by a wrapper that reports its own rusage."""
    wrapper = ("import json, os, resource, subprocess, sys, time\n"
               "t0 = time.perf_counter(); p = subprocess.run(sys.argv[1:], capture_output=True, text=True)\n"
               "w = time.perf_counter() - t0; r = resource.getrusage(resource.RUSAGE_CHILDREN)\n"
               "print(json.dumps({'rc': p.returncode, 'wall': w, 'cpu': r.ru_utime + r.ru_stime,\n"
               "  'rss': r.ru_maxrss * 1024, 'out': p.stdout, 'err': p.stderr[-2000:]}))\n")
    p = subprocess.run([sys.executable, "-c", wrapper, *map(str, cmd)], capture_output=True, text=True)
    r = json.loads(p.stdout)
    if r["rc"] != 0:
        raise RuntimeError(f"{cmd[0]} ... failed: {r['err'].strip()[-600:]}")
    return r


def martello_once(scene, out):
    # --force: the output-size estimate assumes every contact phase listed (docs/results.md)
    r = run_child([sys.executable, "-m", "martello", "run", scene, "-o", out, "--force"])
    import numpy as np
    from martello.results import read_summary         # summary.json, and a large scene's arrays
    s = read_summary(out)
    if "node_peaks" not in s["tracked"]:
        absmax = None                   # not tracked (a large scene's default)
    elif "arrays" in s:
        absmax = np.maximum(np.abs(s["arrays"].column("nodes", "u_max")),
                            np.abs(s["arrays"].column("nodes", "u_min"))).tolist()
    else:
        absmax = [max(abs(v["u_max"]), abs(v["u_min"])) for v in s["nodes"].values()]
    r.update(native=s["cost"]["wall_time_s"], steps=s["cost"]["steps"],
             fused=s["cost"].get("fused_chain_steps"), status=s["status"], absmax=absmax)
    return r


def opensees_once(py, n, steps, out):
    r = run_child([py, __file__, "--opensees-one", n, steps, DT, out])
    r.update(json.loads(r["out"].strip().splitlines()[-1]))
    return r


def opensees_python(path):
    """The caller's Python with openseespy (--opensees-python), checked; None, and a message
    saying how to make one, without it (nothing is installed here)."""
    how = ("give --opensees-python PY, a Python with openseespy (python -m venv DIR && "
           "DIR/bin/pip install openseespy, outside the checkout)")
    if not path:
        print(f"OpenSees comparison skipped: {how}")
        return None
    r = subprocess.run([path, "-c", "import openseespy.opensees"], capture_output=True, text=True)
    if r.returncode != 0:
        print(f"OpenSees comparison skipped: {path} cannot import openseespy; {how}")
        return None
    return path


def triad_gbs(out):
    exe = Path(out) / "triad"
    src = Path(__file__).with_name("triad.c")
    subprocess.run(["cc", "-O2", "-o", str(exe), str(src)], check=True)
    return float(subprocess.run([str(exe), "20000000", "10"], capture_output=True, text=True,
                                check=True).stdout)


def load():
    return os.getloadavg()[0]


def chain_native(out):
    """benchmarks/perf/chain_native.c compiled into out against build/libmartello.so."""
    exe = out / "chain_native"
    lib = ROOT / "build"
    subprocess.run(["cc", "-O2", "-I", str(ROOT / "c"), "-I", str(lib / "include"),
                    str(Path(__file__).with_name("chain_native.c")), "-o", str(exe),
                    f"-L{lib}", "-lmartello", f"-Wl,-rpath,{lib}", "-lm"], check=True)
    return exe


def library_alone(a, out):
    """The chain through the C API alone (chain_native.c): per n, the median of the repeats
    of the library's ns per DOF-step (its clock and the process' CPU time), the model's and
    the run's resident bytes per DOF, and the cost exponent of the time loop in n."""
    exe = chain_native(out)
    opts = (["--items"] if a.items else []) + (["--track", a.track] if a.track is not None else [])
    print(f"the library alone ({'links and contacts' if a.items else 'a chain held per node'}; "
          f"tracking {a.track or 'all'}); {os.cpu_count()} cores")
    print(f"{'n':>8} {'steps':>5} {'ns/DOF-step':>11} {'CPU ns':>7} {'model B/DOF':>11} "
          f"{'peak B/DOF':>10} {'Newton/step':>11} {'fused':>6} {'load':>5}")
    rows = []
    for n in a.n:
        runs, loads = [], []
        for _ in range(a.repeats):
            loads.append(load())
            r = run_child([str(exe), n, a.steps, *opts])
            r.update(json.loads(r["out"]))
            runs.append(r)
        dofsteps = n * a.steps
        row = {"n": n, "steps": a.steps, "load": statistics.median(loads),
               "ns_per_dof_step": statistics.median(r["wall_s"] for r in runs) / dofsteps * 1e9,
               "cpu_ns_per_dof_step": statistics.median(r["cpu"] for r in runs) / dofsteps * 1e9,
               "model_bytes_per_dof": statistics.median(r["model_B_per_dof"] for r in runs),
               "peak_bytes_per_dof": statistics.median(r["peak_B_per_dof"] for r in runs),
               "newton_per_step": runs[-1]["newton"] / a.steps, "fused": runs[-1]["fused"],
               "wall_s": [r["wall_s"] for r in runs]}
        rows.append(row)
        print(f"{n:>8} {a.steps:>5} {row['ns_per_dof_step']:>11.1f} {row['cpu_ns_per_dof_step']:>7.1f} "
              f"{row['model_bytes_per_dof']:>11.0f} {row['peak_bytes_per_dof']:>10.0f} "
              f"{row['newton_per_step']:>11.3f} {row['fused']:>6} {row['load']:>5.2f}", flush=True)
    if len(rows) >= 2:
        xs = [math.log(r["n"]) for r in rows]
        ys = [math.log(r["ns_per_dof_step"] * r["n"]) for r in rows]
        mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
        slope = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
        print(f"cost exponent (library time loop ~ n^p, n = {rows[0]['n']} ... {rows[-1]['n']}): "
              f"p = {slope:.3f}")
    (out / "chain_library.json").write_text(json.dumps({"rows": rows}, indent=1))
    print(f"results: {out / 'chain_library.json'}")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, nargs="+", default=[1000, 10000, 100000])
    ap.add_argument("--steps", type=int, default=8000)
    ap.add_argument("--repeats", type=int, default=3)
    ap.add_argument("-o", "--out", help="the folder everything is written into (required)")
    ap.add_argument("--opensees-python", help="a Python with openseespy (none: martello alone)")
    ap.add_argument("--opensees-max-n", type=int, default=10000,
                    help="largest n OpenSees runs (it takes ~2 µs per DOF-step)")
    ap.add_argument("--skip-pounding", action="store_true")
    ap.add_argument("--library", action="store_true",
                    help="the library alone through the C API (benchmarks/perf/chain_native.c)")
    ap.add_argument("--items", action="store_true",
                    help="--library: the chain as links and contacts, not held per node")
    ap.add_argument("--track", help="what the run keeps (node_peaks,link_peaks,contact_peaks,"
                                    "phases,all; default: --library all, else the scene's "
                                    "default and node_peaks where OpenSees runs)")
    ap.add_argument("--docs", metavar="NAME", choices=DOCS, help="keep the results as "
                    "docs/perf/<name>.json and their table in docs/performance.md (NAME: "
                    + ", ".join(DOCS) + ")")
    ap.add_argument("--from", dest="source", help="with --docs: a finished run's chain_vs_opensees.json")
    ap.add_argument("--check", action="store_true", help="the page's tables are their records' (CI)")
    ap.add_argument("--opensees-one", nargs=4, help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.opensees_one:
        n, steps, dt, out = a.opensees_one
        opensees_one(int(n), int(steps), float(dt), out)
        return
    if a.check:
        problems = [p for p in (measured_docs.check(name, render) for name in DOCS) if p]
        print("\n".join(problems) or "docs/performance.md: the tables of " + ", ".join(DOCS)
              + " are their records'")
        return 1 if problems else 0
    if a.source:
        if not a.docs:
            ap.error("--from records a finished run: give --docs NAME")
        result = json.loads(Path(a.source).read_text())
        print(render(result))
        measured_docs.record(a.docs, result, render(result))
        return 0
    if not a.out:
        ap.error("give -o DIR, the folder everything is written into")
    out = Path(a.out)
    out.mkdir(parents=True, exist_ok=True)
    if a.library:
        library_alone(a, out)
        return
    wants = not a.skip_pounding or any(n <= a.opensees_max_n for n in a.n)
    py = opensees_python(a.opensees_python) if wants else None
    sys.path.insert(0, str(ROOT))
    from martello.binding import native
    start = time.strftime("%Y-%m-%d %H:%M", time.gmtime())
    print(f"martello {native.version()}; {os.cpu_count()} cores; "
          f"{os.uname().machine} {os.uname().release}; load {load():.2f}")
    gbs = triad_gbs(out)
    exe = chain_native(out) if py else None
    print(f"triad (STREAM-like, 3 x 160 MB): {gbs:.1f} GB/s -> {140 / gbs:.1f} ns per DOF-step "
          f"at 140 B/DOF/step (a tridiagonal implicit step with contacts and peaks)")
    rows = []
    hdr = (f"{'n':>8} {'steps':>5} {'martello ns':>11} {'OpenSees ns':>11} {'ratio':>6} "
           f"{'m. process s':>12} {'py share':>8} {'m. B/DOF':>9} {'OS B/DOF':>9} "
           f"{'peak |u| rel':>12} {'m. below':>9} {'load':>5}")
    print(hdr)
    for n in a.n:
        d = out / f"n{n}"
        d.mkdir(exist_ok=True)
        scene = d / "scene.toml"
        with_os = py is not None and n <= a.opensees_max_n
        track = a.track.split(",") if a.track else None
        if with_os:         # the two codes' peak |u| compared
            track = sorted(set(track or ["contact_peaks"]) | {"node_peaks"})
        scene.write_text(scene_toml(n, a.steps, track=track))
        mr, orr, lib = [], [], []
        loads = []
        for rep in range(a.repeats):
            loads.append(load())
            order = ("m", "o") if rep % 2 == 0 else ("o", "m")
            for who in order:
                if who == "m":
                    mr.append(martello_once(scene, d / "martello"))
                elif with_os:
                    (d / "opensees").mkdir(exist_ok=True)
                    orr.append(opensees_once(py, n, a.steps, d / "opensees"))
                    # the same time loop's CPU time (the library alone, tracking as the
                    # scene): beside OpenSees' CPU time, a ratio the load moves little
                    r = run_child([exe, n, a.steps, "--track", ",".join(track)])
                    lib.append(json.loads(r["out"]))
        dofsteps = n * a.steps
        m_ns = statistics.median(r["native"] for r in mr) / dofsteps * 1e9
        m_wall = statistics.median(r["wall"] for r in mr)
        m_rss = statistics.median(r["rss"] for r in mr) / n
        share = statistics.median((r["wall"] - r["native"]) / r["wall"] for r in mr)
        row = {"n": n, "steps": a.steps, "martello_ns_per_dof_step": m_ns, "martello_process_s": m_wall,
               "martello_peak_rss_bytes_per_dof": m_rss, "python_share": share,
               "fused_steps": mr[-1]["fused"], "load": statistics.median(loads),
               "martello_native_s": [r["native"] for r in mr],
               "martello_process_s_all": [r["wall"] for r in mr], "martello_process_cpu_s": [r["cpu"] for r in mr]}
        o_ns = o_rss = agree = below = ratio = None
        if orr:
            o_ns = statistics.median(r["loop_s"] for r in orr) / dofsteps * 1e9
            o_rss = statistics.median(r["rss"] for r in orr) / n
            ratio = o_ns / m_ns
            om = orr[-1]["absmax"]
            agree, below = peak_agreement(mr[-1]["absmax"], om)
            row.update(opensees_ns_per_dof_step=o_ns, ratio=ratio, opensees_peak_rss_bytes_per_dof=o_rss,
                       peak_u_max_rel_diff=agree, peak_u_martello_below=below, opensees_loop_s=[r["loop_s"] for r in orr],
                       opensees_loop_cpu_s=[r["loop_cpu_s"] for r in orr],
                       library_loop_cpu_s=[r["cpu_s"] for r in lib],
                       cpu_ratio=statistics.median(o["loop_cpu_s"] / m["cpu_s"] for o, m in zip(orr, lib)))
        rows.append(row)
        f = lambda x, fmt: format(x, fmt) if x is not None else "-"
        print(f"{n:>8} {a.steps:>5} {m_ns:>11.1f} {f(o_ns, '11.1f'):>11} {f(ratio, '6.1f'):>6} "
              f"{m_wall:>12.2f} {share:>8.1%} {m_rss:>9.0f} {f(o_rss, '9.0f'):>9} "
              f"{f(agree, '12.1e'):>12} {f(below, '9.1e'):>9} {row['load']:>5.2f}", flush=True)
    big = [r for r in rows if r["n"] >= 1000]
    if len(big) >= 2:
        xs = [math.log(r["n"]) for r in big]
        ys = [math.log(r["martello_ns_per_dof_step"] * r["n"]) for r in big]
        mx, my = sum(xs) / len(xs), sum(ys) / len(ys)
        slope = sum((x - mx) * (y - my) for x, y in zip(xs, ys)) / sum((x - mx) ** 2 for x in xs)
        print(f"cost exponent (time loop ~ n^p, n = {big[0]['n']} ... {big[-1]['n']}): p = {slope:.3f}")
    if not a.skip_pounding:
        pounding(py, out, a.repeats, rows)
    result = {"triad_gbs": gbs, "rows": rows, "machine": list(os.uname()),
              "martello": native.version(), "commit": measured_docs.commit(), "track": a.track,
              "date_utc": [start, time.strftime("%Y-%m-%d %H:%M", time.gmtime())],
              "load_end": load()}
    (out / "chain_vs_opensees.json").write_text(json.dumps(result, indent=1))
    print(f"results: {out / 'chain_vs_opensees.json'}")
    if a.docs:
        measured_docs.record(a.docs, result, render(result))


def render(result):
    """The table of a run's results (chain_vs_opensees.json): per n, martello's time loop
    per DOF-step, OpenSees' and their ratios where it ran (wall; CPU against the library
    alone on the same chain), martello's whole process (wall and CPU), its peak memory per
    DOF and the load; medians of the repeats."""
    med = statistics.median
    rows = [r for r in result["rows"] if "n" in r]
    with_os = any(r.get("ratio") is not None for r in rows)
    dates = result["date_utc"]
    track = result["track"] or "the scene's default (node peaks too where OpenSees runs)"
    head = (f"{dates[0]} – {dates[1][-5:]} UTC, martello {result['martello']} at commit "
            f"{result['commit']}, tracking {track}; medians of {len(rows[0]['martello_native_s'])} "
            f"run(s){', the codes alternating' if with_os else ''}; load at the start of each "
            f"size in the table, {result['load_end']:.1f} at the end; triad {result['triad_gbs']:.1f} GB/s")
    cols = ["n", "steps", "martello time loop ns/DOF-step (wall)"]
    if with_os:
        cols += ["OpenSees ns/DOF-step (its CPU/wall)", "OpenSees/martello, wall",
                 "OpenSees/martello, CPU (the library alone's ns/DOF-step)"]
    cols += ["martello process s (CPU s)", "peak B/DOF"]
    if with_os:
        cols += ["peak \\|u\\| rel. diff"]
    cols += ["load"]
    lines = [head, "", "| " + " | ".join(cols) + " |", "|" + "---|" * len(cols)]
    for r in rows:
        cells = [f"{r['n']}", f"{r['steps']}", f"{r['martello_ns_per_dof_step']:.1f}"]
        if with_os:
            cells += ["–"] * 3
            if r.get("ratio") is not None:
                share = med(c / w for c, w in zip(r["opensees_loop_cpu_s"], r["opensees_loop_s"]))
                lib_ns = med(r["library_loop_cpu_s"]) / (r["n"] * r["steps"]) * 1e9
                cells[-3:] = [f"{r['opensees_ns_per_dof_step']:.0f} ({share:.2f})", f"{r['ratio']:.0f}×",
                              f"**{r['cpu_ratio']:.0f}×** ({lib_ns:.1f})"]
        cells += [f"{r['martello_process_s']:.1f} ({med(r['martello_process_cpu_s']):.1f})",
                  f"{r['martello_peak_rss_bytes_per_dof']:.0f}"]
        if with_os:
            d = r.get("peak_u_max_rel_diff")
            cells += [f"{d:.1e}" if d is not None else "–"]
        cells += [f"{r['load']:.1f}"]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def pounding(py, out, repeats, rows):
    """P7's two oscillators with the linear contact (benchmarks/perf/opensees_compare.py's
    scene), Δt = 1e-4 s for 4 s: both codes run Newmark average acceleration at the same step,
    so they have the same accuracy (their peaks agree to the figure printed); whole process
    against whole process."""
    d = out / "pounding"
    d.mkdir(exist_ok=True)
    scene = d / "scene.toml"
    scene.write_text(scene_toml(2, 40000, dt=1e-4, every=10))
    mw, ow, agree, below = [], [], None, None
    for rep in range(repeats):
        for who in (("m", "o") if rep % 2 == 0 else ("o", "m")):
            if who == "m":
                mr = martello_once(scene, d / "martello")
                mw.append(mr["wall"])
            elif py:
                (d / "opensees").mkdir(exist_ok=True)
                r = run_child([py, __file__, "--opensees-one", 2, 40000, 1e-4, d / "opensees"])
                ow.append(r["wall"])
                om = json.loads(r["out"].strip().splitlines()[-1])["absmax"]
                agree, below = peak_agreement(mr["absmax"], om)
    line = (f"P7 two oscillators, linear contact, Newmark dt = 1e-4 s, 40000 steps: whole process "
            f"martello {statistics.median(mw):.3f} s")
    if ow:
        line += (f", OpenSeesPy {statistics.median(ow):.3f} s; peak |u| agree to {agree:.1e}, "
                 f"martello's below OpenSees' by at most {below:.1e}")
    print(line + f" (load {load():.2f})")
    rows.append({"pounding_martello_process_s": mw, "pounding_opensees_process_s": ow,
                 "pounding_peak_u_rel_diff": agree, "pounding_peak_u_martello_below": below})


if __name__ == "__main__":
    main()
