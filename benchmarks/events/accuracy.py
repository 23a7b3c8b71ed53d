"""Accuracy against tolerance on hysteretic pounding (docs/event-driven.md, measured).

For each scene of this folder and each integrator, runs rtol = 1e-6 ... 1e-12 (atol = 1e-3
rtol m, no step cap; fixed-step integrators: dt = 1e-3 ... 3.1e-5 s; a fixed-step name with
the suffix "+split", e.g. newmark+split, runs it with event_split = true) and prints the worst
relative error on the node extrema (u max and min), the peak penetration and the final
displacements against the independent event-located reference of reference.py, with the
native wall time of the run (summary cost.wall_time_s) (the minimum of three runs) and the
log-log slope of the error against rtol (or dt).

    .venv/bin/python benchmarks/events/accuracy.py [--integrators rk8pd,rkf45,msbdf,ida,newmark,...]
        [--plot docs/studies/hysteretic_pounding_work_precision.png] [scene.toml ...]
"""
import argparse
import copy
import math
import sys
from pathlib import Path

import tomllib

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
import reference  # noqa: E402

import martello.api as api  # noqa: E402

SCENES = ["pounding_bilinear.toml", "pounding_kelvin.toml", "chain_bilinear_kelvin.toml"]
RTOLS = [1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12]
REPEATS = 3     # native time: the minimum of three runs (the machine is shared)
FIXED_STEPS = [1e-3, 5e-4, 2.5e-4, 1.25e-4, 6.25e-5, 3.125e-5]
ADAPTIVE = ("rkf45", "rk8pd", "msbdf", "ida")
# the one parameter these schemes need (a common, mildly dissipative choice)
FIXED_PARAMETERS = {"hht": {"alpha": -0.05}, "generalized-alpha": {"rho_inf": 0.9}}


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
    runs = [api.run(scene).summary for _ in range(REPEATS)]
    s = runs[0]
    s["cost"]["wall_time_s"] = min(r["cost"]["wall_time_s"] for r in runs)
    worst, which = 0.0, None
    for key, ref in refq.items():
        err = abs(lookup(s, key) - ref) / abs(ref)
        if err > worst:
            worst, which = err, key
    return worst, which, s["cost"]["wall_time_s"], s["cost"]["steps"]


def slope(xs, ys):
    lx = [math.log10(x) for x in xs]
    ly = [math.log10(max(y, 1e-300)) for y in ys]
    mx, my = sum(lx) / len(lx), sum(ly) / len(ly)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sum((a - mx) ** 2 for a in lx)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("scenes", nargs="*")
    p.add_argument("--integrators", default="rk8pd")
    p.add_argument("--plot")
    a = p.parse_args(argv)
    paths = [Path(x) for x in a.scenes] or [HERE / s for s in SCENES if (HERE / s).exists()]
    curves = {}
    for path in paths:
        refq = reference_quantities(path)
        print(f"{path.name}: reference {len(refq)} quantities (reference.py, DOP853 rtol 2.3e-14)")
        for integ in a.integrators.split(","):
            errs, times = [], []
            knobs = RTOLS if integ in ADAPTIVE else FIXED_STEPS
            what = "rtol" if integ in ADAPTIVE else "dt"
            for rtol in knobs:
                try:
                    err, which, wall, steps = measure(path, integ, rtol, refq)
                except Exception as exc:   # an integrator that cannot run the scene
                    print(f"  {integ:6s} {what} {rtol:.3g}: {exc}")
                    break
                errs.append(err)
                times.append(wall)
                print(f"  {integ:6s} {what} {rtol:.3g}: worst rel. error {err:.2e} ({which}), "
                      f"{steps} steps, native {1e3 * wall:.1f} ms")
            if len(errs) < 2:
                continue
            print(f"  {integ:6s} slope of log error against log {what}: "
                  f"{slope(knobs[:len(errs)], errs):.2f}")
            curves[(path.stem, integ)] = (times, errs)
    if a.plot:
        write_plot(curves, a.plot)


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
    main()
