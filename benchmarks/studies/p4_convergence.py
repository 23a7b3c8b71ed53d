"""P4 convergence study: errors of the rod-impact measures under mesh and step refinement.

Equal steel rods (E = 200 GPa, ρ = 7850 kg/m³, A = 1 cm², L = 1 m, v0 = 1 m/s) meshed into
N = 10 … 640 elements each, dt = C·L_e/c at a fixed Courant number C, so mesh and step are
refined together. For every integrator × mass matrix × contact element the script prints the
errors of the contact duration, the force pulse (L1, relative to P0·T) and the final rod
velocities (max over both rods, relative to v0), and the rates fitted by least squares over
the finest four meshes; it writes a CSV and a plot into out/p4_convergence/ and copies the
plot to docs/p4_convergence.png.

Families (docs/p4-bars.md explains each rate):
  half-cell  lumped mass, the contact element is the two end half cells (ε = EA/L_e): the
             joined mesh is uniform; C = 1 with central difference is exact, C = 1/2 shows the
             dispersion of a second-order scheme on a wave with jumps.
  node       FE mesh with the ends at nodes (lumped or consistent mass) and a penalty spring
             ε = 0.1·EA/L_e: the spring's compliance dominates, an O(h) error predicted by
             martello.oracles.p4_wave_theory.penalty_rod_impact.
  fixed ε    the same meshes with ε = 10·EA/L held fixed, compared with the continuum rods
             joined by that spring (wave_theory.penalty_rod_impact; equal and L_B = 2 L_A):
             the penalty problem is smooth, and the FE converges to it at high order.

Usage:  .venv/bin/python benchmarks/studies/p4_convergence.py [--quick] [--no-plot]
"""

import argparse
import csv
import math
import shutil
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT))

from martello.checks.measures import run_measured            # noqa: E402
from martello.oracles.p4_wave_theory import penalty_rod_impact  # noqa: E402
from martello.scene.bars import rod_impact_scene               # noqa: E402
from martello.scene.loader import from_dict                    # noqa: E402

INTEGRATORS = {   # name -> extra [analysis] keys
    "central-difference": {},
    "newmark": {"preset": "average-acceleration"},
    "hht": {"alpha": -0.1},
    "generalized-alpha": {"rho_inf": 0.8},
}
# (label, ends, mass, eps_factor, courant)
FAMILIES = [
    ("half-cell lumped", "half-cell", "lumped", 1.0, 0.5),
    ("node lumped eps=0.1", "node", "lumped", 0.1, 0.5),
    ("node consistent eps=0.1", "node", "consistent", 0.1, 0.5),
]
ERRORS = ("duration", "pulse_l1", "velocity", "peak")


def errors(N, integrator, ends, mass, eps_factor, courant):
    """The P4 measures of one run, as absolute errors (a dict)."""
    d = rod_impact_scene(N=N, integrator=integrator, ends=ends, mass=mass, eps_factor=eps_factor,
                         courant=courant, **INTEGRATORS[integrator])
    summary, _ = run_measured(from_dict(d))
    m = summary["measures"]["rod_impact"]
    return {"duration": abs(m.get("duration_relative_error", math.nan)),
            "pulse_l1": m.get("pulse_l1_error", math.nan),
            "velocity": max(abs(v) for v in m["v_error"].values()),
            "peak": abs(m.get("peak_error", math.nan)),
            "phases": m["phases"] + m["later_phases"],
            "energy_final": m.get("energy_final_error", math.nan)}


def penalty_errors(N, integrator, mass, L_B, eps_over_rod=10.0):
    """Errors against the continuum rods joined by the same spring ε = eps_over_rod·EA/L:
    penetration, A's final velocity and (equal rods) the duration, all relative."""
    d = rod_impact_scene(N=N, L_B=L_B, integrator=integrator, mass=mass, courant=0.5,
                         eps_factor=eps_over_rod / N, t_end_factor=1.6, **INTEGRATORS[integrator])
    E, rho, A, L = 2.0e11, 7850.0, 1.0e-4, 1.0
    Z, c = math.sqrt(E * rho) * A, math.sqrt(E / rho)
    ref = penalty_rod_impact(Z, 1.0, d["contact"][0]["stiffness"], 2 * L / c, 2 * L_B / c)
    summary, _ = run_measured(from_dict(d))
    m = summary["measures"]["rod_impact"]
    out = {"penetration": abs(m["max_penetration"] / ref["max_penetration"] - 1.0),
           # rod A's mean velocity is v0 − impulse/m_A = −v0·impulse_relative_error
           "velocity": abs(m["v_error"]["A"] + ref["impulse_relative_error"])}
    out["duration"] = (abs(m["duration"] / ref["duration"] - 1.0) if ref["duration"] else math.nan)
    return out


def rate(Ns, errs, last=4):
    """Least-squares slope of log(error) against log(L_e) over the finest `last` meshes."""
    n = np.asarray(Ns[-last:], float)
    e = np.asarray(errs[-last:], float)
    ok = np.isfinite(e) & (e > 0)
    if ok.sum() < 2:
        return math.nan
    return float(np.polyfit(np.log(1.0 / n[ok]), np.log(e[ok]), 1)[0])


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="N up to 160 only")
    ap.add_argument("--no-plot", action="store_true")
    ap.add_argument("-o", "--output", default=str(ROOT / "out" / "p4_convergence"))
    args = ap.parse_args(argv)
    Ns = [10, 20, 40, 80, 160] if args.quick else [10, 20, 40, 80, 160, 320, 640]
    out = Path(args.output)
    out.mkdir(parents=True, exist_ok=True)
    rows, table, t0 = [], {}, time.perf_counter()
    cases = [(f, i) for f in FAMILIES for i in INTEGRATORS]
    cases.append((("half-cell lumped C=1", "half-cell", "lumped", 1.0, 1.0), "central-difference"))
    for k, ((label, ends, mass, eps_factor, courant), integ) in enumerate(cases, 1):
        key = (label, integ)
        table[key] = {e: [] for e in ERRORS}
        for N in Ns:
            try:
                r = errors(N, integ, ends, mass, eps_factor, courant)
            except Exception as exc:      # a refused or failed run is a data point, not a crash
                print(f"  {label} {integ} N={N}: {exc}", file=sys.stderr)
                r = {e: math.nan for e in ERRORS} | {"phases": 0, "energy_final": math.nan}
            for e in ERRORS:
                table[key][e].append(r[e])
            rows.append({"family": label, "integrator": integ, "N": N, "courant": courant,
                         "eps_factor": eps_factor, **r})
        print(f"[{k}/{len(cases)}] {label} / {integ} done ({time.perf_counter() - t0:.0f} s)",
              file=sys.stderr)

    # the penalty problem itself: fixed ε against the continuum with the same spring
    pen_Ns = [50, 100, 200, 400, 800] if not args.quick else [50, 100, 200, 400]
    pen_table = {}
    for integ, mass, L_B in (("central-difference", "lumped", 1.0), ("central-difference", "lumped", 2.0),
                             ("newmark", "lumped", 2.0), ("newmark", "consistent", 2.0)):
        key = (f"fixed eps {mass} L_B={L_B:g}", integ)
        pen_table[key] = {e: [] for e in ("duration", "velocity", "penetration")}
        for N in pen_Ns:
            r = penalty_errors(N, integ, mass, L_B)
            for e in pen_table[key]:
                pen_table[key][e].append(r[e])
            rows.append({"family": key[0], "integrator": integ, "N": N, "courant": 0.5,
                         "eps_factor": 10.0 / N, "duration": r["duration"], "pulse_l1": math.nan,
                         "velocity": r["velocity"], "peak": math.nan, "phases": math.nan,
                         "energy_final": math.nan})
        print(f"{key[0]} / {integ} done ({time.perf_counter() - t0:.0f} s)", file=sys.stderr)

    with open(out / "p4_convergence.csv", "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)

    print(f"P4 equal rods, errors vs N (elements per rod); rates = slope in L_e over N = {Ns[-4:]}")
    print(f"{'family':<26} {'integrator':<19} {'error':<9} " + " ".join(f"{n:>9d}" for n in Ns) + "   rate")
    for (label, integ), errs in table.items():
        for e in ERRORS:
            vals = " ".join(f"{x:9.2e}" for x in errs[e])
            r = rate(Ns, errs[e]) if "C=1" not in label else math.nan
            print(f"{label:<26} {integ:<19} {e:<9} {vals}   {r:5.2f}")

    print(f"\nfixed eps = 10 EA/L: errors against the continuum rods joined by the same spring "
          f"(wave_theory.penalty_rod_impact); rates over N = {pen_Ns[-4:]}")
    print(f"{'family':<26} {'integrator':<19} {'error':<11} " + " ".join(f"{n:>9d}" for n in pen_Ns) + "   rate")
    for (label, integ), errs in pen_table.items():
        for e, vals in errs.items():
            if all(math.isnan(x) for x in vals):
                continue
            print(f"{label:<26} {integ:<19} {e:<11} " + " ".join(f"{x:9.2e}" for x in vals)
                  + f"   {rate(pen_Ns, vals):5.2f}")

    if not args.no_plot:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, axes = plt.subplots(1, 4, figsize=(20, 5))
        styles = {"central-difference": "o-", "newmark": "s--", "hht": "^:", "generalized-alpha": "d-."}
        colors = {"half-cell lumped": "C0", "node lumped eps=0.1": "C1",
                  "node consistent eps=0.1": "C2", "half-cell lumped C=1": "k"}
        h = 1.0 / np.array(Ns)
        for ax, e, title in zip(axes, ("duration", "pulse_l1", "velocity"),
                                ("contact duration |ΔT|/T", "force pulse L1 / (P0 T)",
                                 "final velocities max|Δv|/v0")):
            for (label, integ), errs in table.items():
                y = np.array(errs[e], float)
                if "C=1" in label:   # exact to rounding: written on the panel, off the scale
                    ax.text(0.03, 0.03, f"half cells, central difference, C = 1: max {np.nanmax(y):.1e}",
                            transform=ax.transAxes, fontsize=8)
                    continue
                ax.loglog(h, y, styles[integ], color=colors[label], ms=4, lw=1,
                          label=f"{label}, {integ}")
            for p, yref in ((0.5, 0.3), (2.0 / 3.0, 0.05), (1.0, 0.02)):
                ax.loglog(h, yref * (h / h[0]) ** p, color="0.7", lw=0.8)
                ax.text(h[-1], yref * (h[-1] / h[0]) ** p, f" h^{p:.2g}", color="0.5", fontsize=7)
            ax.set_title(title)
            ax.set_ylim(1e-5, 1.0)
            ax.set_xlabel("L_e / L  (dt = C L_e / c)")
            ax.grid(True, which="both", alpha=0.3)
        ax = axes[3]
        hp = 1.0 / np.array(pen_Ns)
        for k, ((label, integ), errs) in enumerate(pen_table.items()):
            for e, mk in (("penetration", "o-"), ("velocity", "s--")):
                ax.loglog(hp, errs[e], mk, color=f"C{k + 4}", ms=4, lw=1, label=f"{label}, {integ}: {e}")
        for p, yref in ((1.0, 0.2), (3.0, 1e-2)):
            ax.loglog(hp, yref * (hp / hp[0]) ** p, color="0.7", lw=0.8)
            ax.text(hp[-1], yref * (hp[-1] / hp[0]) ** p, f" h^{p:.0f}", color="0.5", fontsize=7)
        ax.set_title("fixed eps = 10 EA/L vs the penalty continuum")
        ax.set_xlabel("L_e / L")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=6, loc="lower right")
        axes[0].set_ylabel("relative error")
        axes[2].legend(fontsize=6, loc="upper left")
        fig.suptitle("P4 two equal rods, penalty contact: convergence under mesh and step refinement "
                     "at Courant C = 0.5 (errors against rigid-contact wave theory; right: against the "
                     "penalty continuum)")
        fig.tight_layout()
        png = out / "p4_convergence.png"
        fig.savefig(png, dpi=110)
        docs = ROOT / "docs" / "p4_convergence.png"
        shutil.copyfile(png, docs)
        print(f"plot: {png} (copied to {docs})")
    print(f"csv: {out / 'p4_convergence.csv'}  ({time.perf_counter() - t0:.0f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
