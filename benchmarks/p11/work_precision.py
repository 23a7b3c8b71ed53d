"""Every integrator on a 3D scene: work against precision (docs/p11-case-study.md, "Every
integrator").

    .venv/bin/python benchmarks/p11/work_precision.py -o DIR [--t-end 6] [--quick]

The P11 scene of configuration A (benchmarks/p11/case_study/p11_A.toml: two 3D frame buildings on rigid
floors, ten gap elements between plan points along the joint, ten fluid-viscous devices,
record 1), cut at --t-end, run by every integrator that takes penalty contacts at a ladder of
steps (the fixed-step ones) or tolerances (the adaptive ones), against a reference: rk8pd at
rtol 1e-12 (its own convergence checked against rtol 1e-11 and printed). Error: the largest
difference of the tall building's roof displacement ux over the 1 ms output grid, relative to
its largest value; and the relative error of the peak penetration of the most loaded gap.
Cost: wall time of the native run (the machine's load is printed with it) and steps.
Writes DIR/work_precision.csv, DIR/work_precision.png and DIR/work_precision.md; nothing
else."""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
sys.path.insert(0, str(ROOT))

import tomllib  # noqa: E402

from martello.binding import native  # noqa: E402
from martello.run import run_full  # noqa: E402
from martello.scene.loader import from_dict  # noqa: E402

OUT_DT = 1e-3
FIXED = {"newmark": {}, "hht": {"alpha": -0.05}, "generalized-alpha": {"rho_inf": 0.8},
         "central-difference": {}, "moreau-jean": {"theta": 0.5}, "fast-nonlinear": {"tol_residual": 1e-10, "max_newton": 100}}
ADAPTIVE = ("rkf45", "rk8pd", "msbdf", "ida", "cvode", "arkode")
STEPS = (2e-3, 1e-3, 5e-4, 2.5e-4, 1.25e-4)
TOLS = (1e-4, 1e-5, 1e-6, 1e-7, 1e-8)


def scene(integ, t_end, every=1, **an):
    """p11_A.toml (record 1) with the integrator, its settings, t_end and output.every."""
    d = tomllib.loads((HERE / "case_study" / "p11_A.toml").read_text())
    d["analysis"].update(integrator=integ, t_end=t_end, **an)
    d["analysis"]["output"]["every"] = every
    d["analysis"]["output"]["contacts"] = []        # the peaks are in the summary
    return from_dict(d, base_dir=HERE / "case_study", source=str(HERE / "case_study" / "p11_A.toml"))


def run(integ, t_end, **an):
    sc = scene(integ, t_end, **an)
    t0 = time.perf_counter()
    s, (cols, hist) = run_full(sc, raise_on_failure=False)
    wall = time.perf_counter() - t0
    if s["status"] != "MARTELLO_OK":
        return None
    t = hist[:, cols.index("t")]
    u = hist[:, cols.index("u:B5.ux")]
    grid = np.arange(0.0, t_end + 1e-12, OUT_DT)
    pen = max(c["max_penetration"] for c in s["contacts"].values())
    return {"u": np.interp(grid, t, u), "pen": pen, "wall": wall,
            "native": s["cost"]["wall_time_s"], "steps": s["cost"].get("steps", 0)}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-o", "--output", required=True, help="a folder for the table and the figure")
    ap.add_argument("--t-end", type=float, default=6.0)
    ap.add_argument("--quick", action="store_true", help="two steps or tolerances per integrator")
    args = ap.parse_args()
    out = Path(args.output)
    out.mkdir(parents=True, exist_ok=True)
    steps = STEPS[1:4:2] if args.quick else STEPS
    tols = TOLS[1:4:2] if args.quick else TOLS
    load = os.getloadavg()[0]
    ref = run("rk8pd", args.t_end, rtol=1e-12, atol=1e-14, dt=OUT_DT)
    ref2 = run("rk8pd", args.t_end, rtol=1e-11, atol=1e-13, dt=OUT_DT)
    scale = np.abs(ref["u"]).max()
    ref_err = np.abs(ref2["u"] - ref["u"]).max() / scale
    rows = []

    def add(integ, setting, r):
        if r is None:
            rows.append((integ, setting, np.nan, np.nan, np.nan, 0))
            return
        err = np.abs(r["u"] - ref["u"]).max() / scale
        # no pounding within t_end: no penetration to compare (nan, not a division by 0)
        perr = abs(r["pen"] - ref["pen"]) / ref["pen"] if ref["pen"] > 0 else float("nan")
        rows.append((integ, setting, err, perr, r["native"], r["steps"]))
        print(f"{integ:>18} {setting:>10} error {err:.2e}  penetration {perr:.2e}  {r['native']:.2f} s  "
              f"{r['steps']} steps", flush=True)
    for integ, extra in FIXED.items():
        for h in steps:
            add(integ, f"dt={h:g}", run(integ, args.t_end, dt=h, every=max(1, round(OUT_DT / h)), **extra))
    for integ in ADAPTIVE:
        for tol in tols:
            add(integ, f"rtol={tol:g}", run(integ, args.t_end, dt=OUT_DT, rtol=tol, atol=tol * 1e-3))
    with open(out / "work_precision.csv", "w") as f:
        f.write("integrator,setting,error_roof_ux,error_peak_penetration,native_s,steps\n")
        for r in rows:
            f.write(",".join(str(x) for x in r) + "\n")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(8, 5.5))
    for integ in list(FIXED) + list(ADAPTIVE):
        pts = [(r[4], r[2]) for r in rows if r[0] == integ and np.isfinite(r[2]) and r[2] > 0]
        if pts:
            x, y = zip(*pts)
            ax.loglog(x, y, "o-" if integ in FIXED else "s--", label=integ, ms=4)
    ax.set_xlabel(f"native run time [s] (load {load:.1f})")
    ax.set_ylabel("max |ux of B's roof − reference| / max |reference|")
    ax.set_title(f"P11 configuration A, record 1, {args.t_end:g} s: every integrator")
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(out / "work_precision.png", dpi=110)
    plt.close(fig)
    L = [f"P11 A, record 1, t_end = {args.t_end:g} s, martello {native.version()}; reference rk8pd rtol 1e-12 "
         f"(against rtol 1e-11: {ref_err:.1e}); load {load:.1f} during the runs",
         "", "| integrator | step / tolerance | roof ux error | peak penetration error | native time [s] | steps |",
         "|---|---|---|---|---|---|"]
    for r in rows:
        L.append(f"| {r[0]} | {r[1]} | {r[2]:.1e} | {r[3]:.1e} | {r[4]:.2f} | {r[5]} |")
    (out / "work_precision.md").write_text("\n".join(L) + "\n")
    print(f"wrote {out}/work_precision.{{csv,png,md}}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
