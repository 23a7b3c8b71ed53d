"""Accuracy against tolerance on hysteretic pounding (docs/event-driven.md, measured).

For each scene of this folder and each adaptive integrator, runs rtol = 1e-6 ... 1e-12 (atol
= 1e-3 rtol m, no step cap) and prints the worst relative error on the node extrema (u max and
min), the peak penetration and the final displacements against the independent event-located
reference of reference.py, with the native wall time of the run (summary cost.wall_time_s)
and the log-log slope of the error against rtol.

    .venv/bin/python benchmarks/events/accuracy.py [--integrators rk8pd,rkf45,msbdf,ida]
        [--plot docs/studies/hysteretic_pounding_wp.png] [scene.toml ...]
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
    with open(path, "rb") as fh:
        d = tomllib.load(fh)
    d = copy.deepcopy(d)
    d["analysis"].update(integrator=integrator, rtol=rtol, atol=1e-3 * rtol)
    d["analysis"].pop("h_max", None)
    res = api.run(api.Scene.from_dict(d, base_dir=str(path.parent)))
    s = res.summary
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
            for rtol in RTOLS:
                err, which, wall, steps = measure(path, integ, rtol, refq)
                errs.append(err)
                times.append(wall)
                print(f"  {integ:6s} rtol {rtol:.0e}: worst rel. error {err:.2e} ({which}), "
                      f"{steps} steps, native {1e3 * wall:.1f} ms")
            print(f"  {integ:6s} slope of log error against log rtol: {slope(RTOLS, errs):.2f}")
            curves[(path.stem, integ)] = (times, errs)
    if a.plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(6.4, 4.6))
        for (scene, integ), (times, errs) in curves.items():
            ax.loglog(times, errs, "o-", label=f"{integ} ({scene})")
        ax.set_xlabel("native wall time [s]")
        ax.set_ylabel("worst relative error (extrema, penetration, final u)")
        ax.set_title("Work-precision, rtol 1e-6 ... 1e-12 (atol = 1e-3 rtol)")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(a.plot, dpi=120)
        print("wrote", a.plot)


if __name__ == "__main__":
    main()
