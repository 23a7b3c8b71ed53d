"""Accuracy against tolerance on hysteretic pounding (docs/event-driven.md, measured).

For each scene of this folder and each integrator, runs rtol = 1e-6 ... 1e-12 (atol = 1e-3
rtol m, no step cap; fixed-step integrators: dt = 1e-3 ... 3.1e-5 s; a fixed-step name with
the suffix "+split", e.g. newmark+split, runs it with event_split = true) and prints the worst
relative error on the node extrema (u max and min), the peak penetration and the final
displacements against the independent event-located reference of reference.py, with the
native wall time of the run (summary cost.wall_time_s) (the minimum of three runs) and the
log-log slope of the error against rtol (or dt).

    .venv/bin/python benchmarks/events/accuracy.py [--integrators rk8pd,rkf45,msbdf,ida,newmark,...]
        [--plot docs/studies/hysteretic_pounding_work_precision.png] [-o DIR] [--docs] [scene.toml ...]
    .venv/bin/python benchmarks/events/accuracy.py --docs --from DIR/accuracy.json
    .venv/bin/python benchmarks/events/accuracy.py --check

-o DIR keeps every run's figures as DIR/accuracy.json; --docs keeps them as
docs/perf/events_accuracy.json and writes the adaptive integrators' table into
docs/event-driven.md (benchmarks/perf/measured_docs.py); --from renders a finished run's
JSON; --check finds the page's table the same as its record's (CI).
"""
import argparse
import copy
import json
import math
import os
import resource
import sys
import time
from pathlib import Path

import tomllib

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parent / "perf"))
import measured_docs  # noqa: E402
import reference  # noqa: E402

import martello.api as api  # noqa: E402

SCENES = ["pounding_bilinear.toml", "pounding_kelvin.toml", "chain_bilinear_kelvin.toml"]
RTOLS = [1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12]
REPEATS = 3     # native time: the minimum of three runs (the machine is shared)
FIXED_STEPS = [1e-3, 5e-4, 2.5e-4, 1.25e-4, 6.25e-5, 3.125e-5]
ADAPTIVE = ("rkf45", "rk8pd", "msbdf", "ida")
# the one parameter these schemes need (a common, mildly dissipative choice)
FIXED_PARAMETERS = {"hht": {"alpha": -0.05}, "generalized-alpha": {"rho_inf": 0.9}}
NAME = "events_accuracy"    # its record docs/perf/events_accuracy.json, its fence in docs/event-driven.md
DOC = measured_docs.ROOT / "docs" / "event-driven.md"
LABELS = {"pounding_bilinear": "two bilinear oscillators, elastic gap (`pounding_bilinear.toml`)",
          "pounding_kelvin": "the same, clipped Kelvin e = 0.65 (`pounding_kelvin.toml`)",
          "chain_bilinear_kelvin": "three bilinear buildings, Kelvin joints (`chain_bilinear_kelvin.toml`)"}


def reference_quantities(path):
    sc, ext = reference.solve(path, rtol=2.3e-14, atol=1e-18)
    q = reference.quantities(sc, ext)
    for c, con in enumerate(_contact_names(path)):
        q["contacts.%s.max_penetration" % con] = ext["pen"][c]
    return q


def _contact_names(path):
    with open(path, "rb") as fh:
        return [c["name"] for c in tomllib.load(fh).get("contact", [])]


def lookup(summary, key):
    x = summary
    parts = key.split(".")
    x = x[parts[0]]
    x = x[".".join(parts[1:-1])] if parts[0] in ("nodes", "contacts") else x
    return x[parts[-1]]


def measure(path, integrator, rtol, refq):
    """rtol: the tolerance of an adaptive integrator, the step of a fixed-step one."""
    with open(path, "rb") as fh:
        d = tomllib.load(fh)
    d = copy.deepcopy(d)
    if integrator in ADAPTIVE:
        d["analysis"].update(integrator=integrator, rtol=rtol, atol=1e-3 * rtol)
        d["analysis"].pop("h_max", None)
    else:
        every = int(round(d["analysis"]["dt"] / rtol))
        name, split = integrator.removesuffix("+split"), integrator.endswith("+split")
        d["analysis"] = {"type": "dynamic", "integrator": name, "dt": rtol,
                         "t_end": d["analysis"]["t_end"], "output": {"every": every}}
        d["analysis"].update(FIXED_PARAMETERS.get(name, {}))
        if split:
            d["analysis"]["event_split"] = True
    scene = api.Scene.from_dict(d, base_dir=str(path.parent))
    runs, cpu = [], []
    for _ in range(REPEATS):
        r0 = resource.getrusage(resource.RUSAGE_SELF)
        runs.append(api.run(scene).summary)
        r1 = resource.getrusage(resource.RUSAGE_SELF)
        cpu.append(r1.ru_utime - r0.ru_utime + r1.ru_stime - r0.ru_stime)
    s = runs[0]
    s["cost"]["wall_time_s"] = min(r["cost"]["wall_time_s"] for r in runs)
    s["cost"]["cpu_s"] = min(cpu)    # the whole api.run (set-up and summary included)
    worst, which = 0.0, None
    for key, ref in refq.items():
        err = abs(lookup(s, key) - ref) / abs(ref)
        if err > worst:
            worst, which = err, key
    return worst, which, s["cost"]["wall_time_s"], s["cost"]["steps"], s["cost"]["cpu_s"]


def slope(xs, ys):
    lx = [math.log10(x) for x in xs]
    ly = [math.log10(max(y, 1e-300)) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sum((a - mx) ** 2 for a in lx)


def render(result):
    """The adaptive integrators' table (rtol 1e-8, 1e-10, 1e-12, the slope, the native time at
    1e-12) of a run's figures (accuracy.json)."""
    lo, hi = result["load"]
    lines = [f"{result['date_utc']} UTC, commit {result['commit']}, load {lo:.1f}–{hi:.1f} (nice "
             f"{result['nice']}); worst relative error; CPU = the CPU time of the whole `api.run` "
             f"(set-up and summary included), native = the library's wall clock of the run "
             f"(`cost.wall_time_s`, which counts the waits of a loaded machine), each the minimum "
             f"of {REPEATS} runs", "",
             "| scene (8 s) | integrator | rtol 1e-8 | rtol 1e-10 | rtol 1e-12 | slope (1e-6…1e-12) | CPU at 1e-12 (native wall) |",
             "|---|---|---|---|---|---|---|"]
    last = None
    for c in result["curves"]:
        if c["integrator"] not in ADAPTIVE:
            continue
        at = {k: e for k, e in zip(c["knobs"], c["errors"])}
        cell = lambda r: f"{at[r]:.1e}".replace("e-0", "e-") if r in at else "—"   # noqa: E731
        k12 = c["knobs"].index(1e-12) if 1e-12 in c["knobs"] else None
        ms = lambda x: f"{1e3 * x:.3g}" if x < 0.1 else f"{1e3 * x:.0f}"   # noqa: E731
        wall = f"{ms(c['cpu_s'][k12])} ms ({ms(c['wall_s'][k12])} ms)" if k12 is not None else "—"
        first = LABELS.get(c["scene"], c["scene"]) if c["scene"] != last else ""
        last = c["scene"]
        lines.append(f"| {first} | {c['integrator']} | {cell(1e-8)} | {cell(1e-10)} | {cell(1e-12)} "
                     f"| {c['slope']:.2f} | {wall} |")
    return "\n".join(lines)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("scenes", nargs="*")
    p.add_argument("--integrators", default="rk8pd")
    p.add_argument("--plot")
    p.add_argument("-o", "--out", help="the folder accuracy.json is written into")
    p.add_argument("--docs", action="store_true", help="keep the figures as docs/perf/events_accuracy.json "
                   "and their table in docs/event-driven.md")
    p.add_argument("--from", dest="source", help="a finished run's accuracy.json (no run)")
    p.add_argument("--check", action="store_true", help="the page's table is its record's (CI)")
    a = p.parse_args(argv)
    if a.check:
        problem = measured_docs.check(NAME, render, DOC)
        print(problem or f"docs/event-driven.md: the table of {NAME} is its record's")
        return 1 if problem else 0
    if a.source:
        result = json.loads(Path(a.source).read_text())
        print(render(result))
        if a.docs:
            measured_docs.record(NAME, result, render(result), DOC)
        return 0
    paths = [Path(x) for x in a.scenes] or [HERE / s for s in SCENES if (HERE / s).exists()]
    curves = {}
    result = {"date_utc": time.strftime("%Y-%m-%d %H:%M", time.gmtime()), "commit": measured_docs.commit(),
              "nice": os.nice(0), "load": [os.getloadavg()[0]], "curves": []}
    for path in paths:
        refq = reference_quantities(path)
        print(f"{path.name}: reference {len(refq)} quantities (reference.py, DOP853 rtol 2.3e-14)")
        for integ in a.integrators.split(","):
            errs, times, cpus, whichs, steps_ = [], [], [], [], []
            knobs = RTOLS if integ in ADAPTIVE else FIXED_STEPS
            what = "rtol" if integ in ADAPTIVE else "dt"
            for rtol in knobs:
                try:
                    err, which, wall, steps, cpu = measure(path, integ, rtol, refq)
                except Exception as exc:   # an integrator that cannot run the scene
                    print(f"  {integ:6s} {what} {rtol:.3g}: {exc}")
                    break
                errs.append(err)
                times.append(wall)
                cpus.append(cpu)
                whichs.append(which)
                steps_.append(steps)
                print(f"  {integ:6s} {what} {rtol:.3g}: worst rel. error {err:.2e} ({which}), "
                      f"{steps} steps, native {1e3 * wall:.1f} ms")
            if len(errs) < 2:
                continue
            sl = slope(knobs[:len(errs)], errs)
            print(f"  {integ:6s} slope of log error against log {what}: {sl:.2f}")
            curves[(path.stem, integ)] = (times, errs)
            result["curves"].append({"scene": path.stem, "integrator": integ, "knob": what,
                                     "knobs": knobs[:len(errs)], "errors": errs, "worst_quantity": whichs,
                                     "wall_s": times, "cpu_s": cpus, "steps": steps_, "slope": sl})
    result["load"] = [min(result["load"][0], os.getloadavg()[0]), max(result["load"][0], os.getloadavg()[0])]
    if a.out:
        Path(a.out).mkdir(parents=True, exist_ok=True)
        (Path(a.out) / "accuracy.json").write_text(json.dumps(result, indent=1))
    if a.plot:
        write_plot(curves, a.plot)
    if a.docs:
        measured_docs.record(NAME, result, render(result), DOC)
    return 0


def write_plot(curves, path):
    """One panel per scene, one colour per integrator; the numbers beside it as CSV."""
    import csv
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    scenes = sorted({sc for sc, _ in curves}, key=lambda x: [Path(s).stem for s in SCENES].index(x)
                    if x in [Path(s).stem for s in SCENES] else 99)
    integrators = list(dict.fromkeys(i for _, i in curves))
    colours = {i: plt.cm.tab10(k % 10) for k, i in enumerate(integrators)}
    fig, axes = plt.subplots(1, len(scenes), figsize=(5.0 * len(scenes), 4.6), squeeze=False)
    for ax, scene in zip(axes[0], scenes):
        for integ in integrators:
            if (scene, integ) not in curves:
                continue
            times, errs = curves[(scene, integ)]
            style = "o-" if integ in ADAPTIVE else "s--"
            ax.loglog(times, errs, style, color=colours[integ], label=integ, ms=4)
        ax.set_title(scene, fontsize=9)
        ax.set_xlabel("native wall time [s] (min of 3)")
        ax.grid(True, which="both", alpha=0.3)
    axes[0][0].set_ylabel("worst relative error (u extrema, peak penetration, final u)")
    axes[0][0].legend(fontsize=7)
    fig.suptitle("Hysteretic pounding, 8 s: adaptive rtol 1e-6 ... 1e-12 (atol = 1e-3 rtol, "
                 "no step cap), fixed steps dt 1e-3 ... 3.1e-5 s", fontsize=9)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    with open(Path(path).with_suffix(".csv"), "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["scene", "integrator", "knob", "wall_time_s", "worst_relative_error"])
        for (scene, integ), (times, errs) in curves.items():
            knobs = RTOLS if integ in ADAPTIVE else FIXED_STEPS
            for k, t, e in zip(knobs, times, errs):
                w.writerow([scene, integ, k, f"{t:.6g}", f"{e:.4g}"])
    print("wrote", path, "and", Path(path).with_suffix(".csv"))


if __name__ == "__main__":
    sys.exit(main())
