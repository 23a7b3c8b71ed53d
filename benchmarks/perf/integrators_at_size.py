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
  row      fast-nonlinear only: benchmarks/perf/fna_ritz.py's row (4 contacts among n
           oscillators, weak neighbour springs, a 2 Hz ground sine; dt 1 ms), where a few Ritz
           vectors are accurate (that script measures their error against all modes).
Integrators: ida, cvode, arkode (their default methods: BDF, Dormand–Prince 5(4)), cvode-local,
arkode-local and ida-local (with analysis.local_stepping = true: cluster by cluster), msbdf, rk8pd,
rkf45, newmark-general (fused_chain = false), newmark-fused, moreau-jean, fast-nonlinear (all
modes) and fast-nonlinear:M (M load-dependent Ritz vectors, analysis.modal_vectors = M).
Each run is cut at max_wall (default 60 s): the cost per simulated second is then its CPU
time over the time t it reached, marked: the events fall late in the window, so its rate
compares only with runs over the same [0, t]. The exponents are least-squares slopes of log
cost over log n among the rows of one window (t_end, or the time a cut run reached, to 3
digits). Every row keeps the machine load before and after the run,
the process' nice value and the commit measured (a shared machine: CPU time of the run's own
process, not wall time). The counts (steps, RHS, Jacobians, factorisations, events) do not
depend on the load.

Writes nothing unless told: --out DIR keeps the rows as DIR/integrators_at_size_<scene>.json;
--docs keeps them (with --from, the rows of finished runs, .json or .jsonl, several files merged)
in docs/perf/integrators_at_size.json, a new row replacing the record's row of the same scene,
integrator, n and window, and writes their table into docs/performance.md
(benchmarks/perf/measured_docs.py); --check finds the page's table the same as its record's (CI).

Usage: benchmarks/perf/integrators_at_size.py [--n 300 1000 3000 10000]
       [--integrators ida cvode arkode newmark-general moreau-jean fast-nonlinear:40 ...]
       [--scene closing|closed|row] [--t-end 0.1] [--max-wall 60] [--out DIR] [--docs]
       benchmarks/perf/integrators_at_size.py --docs --from DIR/a.json DIR/b.json ...
       benchmarks/perf/integrators_at_size.py --check"""

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
sys.path.insert(0, str(Path(__file__).resolve().parent))
import measured_docs  # noqa: E402

NAME = "integrators_at_size"  # its record docs/perf/integrators_at_size.json, its fence in docs/performance.md

ADAPTIVE = {"ida", "cvode", "arkode", "rk8pd", "rkf45", "msbdf", "cvode-local", "arkode-local", "ida-local"}


def row(n, m, t_end, record_all=True):
    """Scene `row` (benchmarks/perf/fna_ritz.py states it) on fast-nonlinear with m Ritz vectors
    (0: all modes), dt 1 ms; every node and contact recorded ~50 times unless record_all is false."""
    nodes = [{"name": f"b{i}", "mass": 1.0e5} for i in range(1, n + 1)]
    links = []
    for i in range(1, n + 1):
        k = 2.0e7 if i % 2 else 5.0e7
        links.append({"type": "spring", "a": f"b{i}", "b": "ground", "k": k})
        links.append({"type": "dashpot", "a": f"b{i}", "b": "ground", "c": 2 * 0.05 * math.sqrt(k * 1.0e5)})
        if i < n:
            links.append({"type": "spring", "a": f"b{i}", "b": f"b{i + 1}", "k": 1.0e6})
    contacts = [{"name": f"gap{j}", "a": f"b{j * n // 5}", "b": f"b{j * n // 5 + 1}", "gap": 2.0e-3,
                 "scheme": "penalty", "law": "linear", "stiffness": 1.0e9} for j in range(1, 5)]
    every = max(1, int(round(t_end / 1e-3 / 50)))
    output = ({"every": every, "nodes": [x["name"] for x in nodes], "contacts": [c["name"] for c in contacts]}
              if record_all else {"every": 1000000, "nodes": ["b1"], "contacts": []})
    return {"title": f"row n={n} m={m}", "node": nodes, "link": links, "contact": contacts,
            "loads": {"ground_acceleration": {"type": "sine", "amplitude": 3.0, "omega": 4 * math.pi}},
            "analysis": {"type": "dynamic", "integrator": "fast-nonlinear", "dt": 1e-3, "t_end": t_end,
                         "tol_residual": 1e-10, "max_newton": 100, "modal_vectors": m, "output": output}}


def scene(n, integrator, kind, t_end, max_wall, active=None, spread=0.1):
    """active: on `closing`, only b1 … b_active move (the rest stay at rest behind 1 m gaps:
    2(n − active) unknowns that never change, the events those of n = active); spread: the
    speeds' spread about 0.3 m/s (a smaller one puts the same events closer in time)."""
    if kind == "row":
        base, _, m = integrator.partition(":")
        if base != "fast-nonlinear":
            raise SystemExit("scene row is for fast-nonlinear and fast-nonlinear:M")
        sc = row(n, int(m or 0), t_end, record_all=False)
        sc["analysis"]["max_wall"] = max_wall
        return sc
    k = [2.0e7 if i % 2 == 0 else 5.0e7 for i in range(n)]
    chain = {"prefix": "b", "n": n, "mass": 1.0e5, "k": k, "zeta": 0.05,
             "contact": {"scheme": "penalty", "law": "linear", "stiffness": 1.0e9}}
    loads = {}
    if kind == "closing":
        act = n if active is None else active
        chain["gap"] = 5.0e-3 if act == n else [5.0e-3 if i < act else 1.0 for i in range(n - 1)]
        # speeds 0.2 … 0.4 m/s spread over the row: the contacts close at n/2 different times
        chain["v0"] = [0.3 + spread * math.sin(1.7 * i) if i % 2 == 0 and i < act else 0.0 for i in range(n)]
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
    integrator, _, m = integrator.partition(":")
    if m:
        an["modal_vectors"] = int(m)
    if integrator in ("cvode-local", "arkode-local", "ida-local"):
        # cluster by cluster (docs/sundials-ode.md, local stepping)
        an.update(integrator=integrator.split("-")[0], dt=t_end, rtol=1e-8, atol=1e-12, local_stepping=True)
    elif integrator in ADAPTIVE:
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


def variant(kind, active, spread):
    """The scene's name in a row: `closing`, or `closing, active 300`, `closing, spread 0.01`."""
    return kind + (f", active {active}" if active is not None else "") + (
        f", spread {spread:g}" if spread != 0.1 else "")


def one(n, integrator, kind, t_end, max_wall, active=None, spread=0.1):
    from martello.scene.spec import DEFAULT_METHODS
    # max_wall stops a slow one: its rate stands, marked as cut
    load0, at = os.getloadavg()[0], measured_docs.commit()   # the commit whose library the run loads
    sc = scene(n, integrator, kind, t_end, max_wall, active, spread)
    r, _, cpu, wall = timed_run(sc)
    c = r["cost"]
    t_reached = r.get("t_reached", t_end)    # 0 for a run stopped before its first step
    an = sc["analysis"]
    print(json.dumps({"n": n, "integrator": integrator, "scene": variant(kind, active, spread), "status": r["status"],
                      "t_end": t_end, "t_reached": t_reached,
                      "cut": r["status"] != "MARTELLO_OK" or t_reached < t_end * (1 - 1e-9),
                      "cpu_s": cpu, "wall_s": wall, "cpu_per_sim_s": cpu / t_reached if t_reached > 0 else None,
                      "cost": c, "method": DEFAULT_METHODS.get(an["integrator"]),
                      "setting": {k: an[k] for k in ("preset", "dt", "rtol", "atol", "modal_vectors", "local_stepping")
                                  if k in an and not (k == "dt" and "rtol" in an)},
                      "contact": sc["chain"][0]["contact"] if "chain" in sc else
                      {k: sc["contact"][0][k] for k in ("scheme", "law", "stiffness")}, "load": [load0, os.getloadavg()[0]],
                      "nice": os.nice(0), "commit": at,
                      "date_utc": time.strftime("%Y-%m-%d %H:%M", time.gmtime())}))


def fit(ns, ys):
    xs = [math.log(n) for n in ns]
    ls = [math.log(y) for y in ys]
    mx, my = sum(xs) / len(xs), sum(ls) / len(ls)
    den = sum((x - mx) ** 2 for x in xs)
    return sum((x - mx) * (y - my) for x, y in zip(xs, ls)) / den if den > 0 else float("nan")


LABEL = {"ida": "IDA (BDF)", "cvode": "CVODE BDF", "cvode-local": "CVODE BDF, local stepping",
         "arkode-local": "ARKODE Dormand–Prince 5(4), local stepping", "ida-local": "IDA (BDF), local stepping", "arkode": "ARKODE Dormand–Prince 5(4)",
         "newmark-general": "Newmark general path", "newmark-fused": "Newmark fused chain step",
         "moreau-jean": "Moreau–Jean", "fast-nonlinear": "fast nonlinear, all modes",
         "msbdf": "GSL msbdf", "rk8pd": "GSL rk8pd", "rkf45": "GSL rkf45"}
GOAL = 1.3   # the exponent the cost per simulated second should not exceed (docs/performance.md)


def label(row):
    """What was run: integrator, method, step or tolerance, the scene and its contacts."""
    integ, _, m = row["integrator"].partition(":")
    name = f"fast nonlinear, {m} Ritz vectors" if m else LABEL.get(integ, integ)
    st = row["setting"]
    how = (f"rtol {st['rtol']:g}, atol {st['atol']:g}" if "rtol" in st
           else f"Δt {st['dt']:g} s" + (f", {st['preset']}" if "preset" in st else ""))
    c = row["contact"]
    law = (f"restitution e = {c['restitution']:g}" if c["scheme"] == "restitution"
           else f"{c['scheme']} {c['law']} {c['stiffness']:g} N/m")
    where = "`row` (4 contacts)" if row["scene"] == "row" else f"`{row['scene']}`"
    return f"{name}; {how}; {where}, {law}"


def window(row):
    """The simulated time a row's cost is rated over: t_end, or the time a cut run reached
    (3 digits: a run cut within 0.1 % of a window belongs to it)."""
    return float(f"{row['t_reached'] if row['cut'] else row['t_end']:.3g}")


def merged(rows):
    """Rows keyed by (scene, integrator, n, window), a later row replacing an earlier one, in a
    fixed order of scenes and integrators, then by window and n."""
    out = {}
    for r in rows:
        out[r["scene"], r["integrator"], r["n"], window(r)] = r
    scenes, integs = ["closing", "closed", "row"], ["ida", "ida-local", "cvode", "cvode-local", "arkode", "arkode-local", "newmark-general",
                                                    "newmark-fused", "moreau-jean", "fast-nonlinear"]

    def key(r):
        base, _, m = r["integrator"].partition(":")
        sc = r["scene"].split(",")[0]
        return (scenes.index(sc) if sc in scenes else 9, r["scene"], integs.index(base) if base in integs else 9,
                int(m) if m else 10**9, base, -window(r), r["n"])
    return sorted(out.values(), key=key)


def _i(x):
    return f"{x:,}".replace(",", " ")


def _g(x):
    return f"{x:,.3g}".replace(",", " ") if x < 1e3 else f"{x:,.0f}".replace(",", " ")


def counted(row):
    """What a row's `events` counts: the event-driven integrators locate every onset and every
    separation of a contact (`o+s`: n on `closing` over [0, 0.05 s]); the fixed-step methods,
    Moreau–Jean and fast nonlinear analysis count a contact's phases as they open (`o`: the
    onsets, or impacts, alone: n/2 there)."""
    return "o+s" if row["integrator"].partition(":")[0] in ADAPTIVE else "o"


EVENTS_KEY = ("events: `o+s` = contact onsets and separations located (event-driven integrators), "
              "`o` = contact phases opened, onsets or impacts only (fixed-step methods, Moreau–Jean, "
              "fast nonlinear); steps / event and RHS / event divide by that count")


def table(rows):
    lines = ["| integrator; step or tolerance; scene, contacts | n | t_end s | CPU s per sim. s | CPU s "
             "| steps | RHS | Jacobians | factorisations | events | steps / event | RHS / event "
             "| load (nice) | commit, UTC |",
             "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        c, ev = r["cost"], r["cost"]["events"]
        per = (lambda k: _g(c[k] / ev)) if ev else (lambda k: "–")
        lo, hi = r["load"]
        rate = (_g(r["cpu_per_sim_s"]) + (f"* over [0, {r['t_reached']:.4g} s]" if r["cut"] else "")
                if r["cpu_per_sim_s"] else f"no step in {r['wall_s']:.0f} s of wall clock")
        lines.append(f"| {label(r)} | {_i(r['n'])} | {r['t_end']:g} | {rate} | {_g(r['cpu_s'])} | {_i(c['steps'])} "
                     f"| {_i(c['residual_evaluations'])} | {_i(c['jacobian_evaluations'])} "
                     f"| {_i(c['factorizations'])} | {_i(ev)} {counted(r)} | {per('steps')} | {per('residual_evaluations')} "
                     f"| {lo:.1f}–{hi:.1f} ({r['nice']}) | {r['commit']}, {r['date_utc'][5:]} |")
    return lines


def render(rows):
    """The table of the rows (docs/perf/integrators_at_size.json), the exponents, and the rows
    of the variants of `closing` (--active, --spread) apart."""
    rows = merged(rows)
    main = [r for r in rows if "," not in r["scene"]]
    lines = [EVENTS_KEY + ".", ""] + table(main)
    lines += ["", "| integrator; scene | exponent of CPU s per sim. s in n (least squares) | n → n' "
              "(pairwise) | ≤ 1.3 |", "|---|---|---|---|"]
    for key in dict.fromkeys((r["scene"], r["integrator"], window(r)) for r in main):
        mine = [r for r in main if (r["scene"], r["integrator"], window(r)) == key and r["cpu_per_sim_s"]]
        if len(mine) < 2:
            continue
        ns, ys = [r["n"] for r in mine], [r["cpu_per_sim_s"] for r in mine]
        e = fit(ns, ys)
        pw = ", ".join(f"{a}→{b}: {fit([a, b], [ya, yb]):.2f}"
                       for a, b, ya, yb in zip(ns, ns[1:], ys, ys[1:]))
        name = label(mine[0]).split(";")[0]
        lines.append(f"| {name}; `{key[0]}`, over [0, {key[2]:g} s] | n^{e:.2f} over n = "
                     f"{', '.join(map(str, ns))}{' (* included)' if any(r['cut'] for r in mine) else ''} "
                     f"| {pw} | {'yes' if e <= GOAL else '**no**'} |")
    variants = [r for r in rows if "," in r["scene"]]
    if variants:
        lines += ["", "Variants of `closing` (--active K: only b1 … b_K move, the rest at rest behind 1 m "
                  "gaps; --spread S: speeds 0.3 ± S m/s):", ""] + table(variants)
    return "\n".join(lines)


def read_rows(path):
    """The rows of a run: its .json list or its .jsonl lines (kept as they came)."""
    text = Path(path).read_text()
    return [json.loads(ln) for ln in text.splitlines() if ln.strip()] if path.endswith(".jsonl") else json.loads(text)


def keep(rows):
    """The record docs/perf/integrators_at_size.json merged with rows (a new row replaces the
    record's row of the same scene, integrator, n and window) and its table in docs/performance.md."""
    path = measured_docs.RECORDS / f"{NAME}.json"
    old = json.loads(path.read_text()) if path.exists() else []
    rows = merged(old + list(rows))
    measured_docs.record(NAME, rows, render(rows))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--n", type=int, nargs="*", default=[300, 1000, 3000, 10000])
    ap.add_argument("--integrators", nargs="*",
                    default=["ida", "cvode", "arkode", "newmark-general", "newmark-fused"])
    ap.add_argument("--scene", choices=("closing", "closed", "row"), default="closing")
    ap.add_argument("--t-end", type=float, default=0.1)
    ap.add_argument("--max-wall", type=float, default=60.0)
    ap.add_argument("--active", type=int, help="closing: only b1 … b_ACTIVE move, the rest at rest "
                    "behind 1 m gaps (the error norm's dilution, docs/sundials-ode.md)")
    ap.add_argument("--spread", type=float, default=0.1, help="closing: the speeds' spread about "
                    "0.3 m/s (default 0.1: the contacts close over 12.5 … 25 ms)")
    ap.add_argument("-o", "--out", help="the folder the rows are written into")
    ap.add_argument("--docs", action="store_true", help="keep the rows as docs/perf/integrators_at_size.json "
                    "and their table in docs/performance.md")
    ap.add_argument("--from", dest="source", nargs="*", help="finished runs' JSON rows (no run), merged")
    ap.add_argument("--check", action="store_true", help="the page's table is its record's (CI)")
    ap.add_argument("--one", nargs=2, help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.one:
        one(int(args.one[0]), args.one[1], args.scene, args.t_end, args.max_wall, args.active, args.spread)
        return 0
    if args.check:
        problem = measured_docs.check(NAME, render)
        print(problem or f"docs/performance.md: the table of {NAME} is its record's")
        return 1 if problem else 0
    if args.source:
        rows = merged([r for f in args.source for r in read_rows(f)])
        print(render(rows))
        if args.docs:
            keep(rows)
        return 0
    if not (args.out or args.docs):
        print("(nothing is written: -o DIR keeps the rows, --docs the table)")
    from martello.binding import native
    print(f"martello {native.version()} ({native.library_versions()}); {os.cpu_count()} cores; "
          f"scene {args.scene}, t_end {args.t_end} s, max_wall {args.max_wall} s")
    print(f"{'integrator':>16} {'n':>6} {'status':>7} {'t_reached':>9} {'CPU s':>8} {'CPU/sim s':>10} "
          f"{'steps':>8} {'RHS':>9} {'events':>7} {'steps/ev':>8} {'RHS/ev':>8} {'fact':>7} {'load':>5}")
    rows = []
    for integ in args.integrators:
        for n in args.n:
            row, err = child([__file__, "--one", n, integ, "--scene", args.scene,
                              "--t-end", args.t_end, "--max-wall", args.max_wall, "--spread", args.spread]
                             + (["--active", args.active] if args.active is not None else []))
            if row is not None and args.out:   # kept as it comes: a long sweep stopped keeps its rows
                Path(args.out).mkdir(parents=True, exist_ok=True)
                with open(Path(args.out) / f"integrators_at_size_{args.scene}.jsonl", "a") as f:
                    f.write(json.dumps(row) + "\n")
            if row is None:
                print(f"{integ:>16} {n:>6} failed: {err}")
                continue
            rows.append(row)
            c, ev = row["cost"], max(row["cost"]["events"], 1)
            print(f"{integ:>16} {n:>6} {row['status']:>7} {row['t_reached']:9.4g} {row['cpu_s']:8.3g} "
                  f"{row['cpu_per_sim_s'] or float('nan'):10.4g} {c['steps']:8d} {c['residual_evaluations']:9d} "
                  f"{c['events']:7d} {c['steps'] / ev:8.3g} {c['residual_evaluations'] / ev:8.3g} "
                  f"{c['factorizations']:7d} {row['load'][1]:5.2f}", flush=True)
    print("\nexponents of CPU per simulated second in n (least squares over the sizes run):")
    for integ in args.integrators:
        mine = [r for r in rows if r["integrator"] == integ and r["cpu_per_sim_s"] and not r["cut"]]
        if len(mine) >= 2:
            ns = [r["n"] for r in mine]
            print(f"  {integ:>16}: n^{fit(ns, [r['cpu_per_sim_s'] for r in mine]):.2f} "
                  f"over n = {', '.join(map(str, ns))}")
    if args.out:
        out = Path(args.out)
        out.mkdir(parents=True, exist_ok=True)
        (out / f"integrators_at_size_{args.scene}.json").write_text(json.dumps(rows, indent=1))
    if args.docs:
        keep(rows)
    return 0


if __name__ == "__main__":
    sys.exit(main())
