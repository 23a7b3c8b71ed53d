"""Cost of fast nonlinear analysis against direct Newmark as a frame grows (docs/p10-case-study.md,
"Cost"; the seed's claim: FNA keeps the cost near that of a linear analysis).

    .venv/bin/python benchmarks/p10/fna_cost.py [--t-end 5] [--repeat 3]

Scene: the P10 pair of benchmarks/p10/case_study.py (frame A 2 storeys, frame B n storeys,
b bays, joint masses, gaps at the two shared floors, dampers of configuration A), record 1,
Δt = 0.5 ms, for n in 5, 10, 20 and b in 2, 4. Each integrator's best wall time of --repeat
runs (this machine is shared: the best is the least disturbed), with its counters: Newton
iterations (FNA: passes of the pseudo-force iteration) per step, and force evaluations. A
linear reference (the same frames without gaps and dampers, Newmark) shows what "the cost of a
linear analysis" is here. Prints a table; nothing is written.
"""

import argparse
import copy
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent.parent))
sys.path.insert(0, str(HERE))

import case_study as cs  # noqa: E402
from martello.run import run_full  # noqa: E402
from martello.scene.loader import from_dict  # noqa: E402


def scene(storeys, bays, integrator, t_end, linear=False):
    d = copy.deepcopy(cs.scene_dict("A"))
    for fr in d["frame"]:
        fr["bays"] = bays
        if fr["prefix"] == "B":
            fr["storeys"] = storeys
            fr["column"] = [cs.rect(0.3, 0.5)] * 2 + [cs.rect(0.3, 0.4)] * (storeys - 2)
            fr["mass"] = [cs.FLOOR_MASS] * (storeys - 1) + [cs.ROOF_MASS]
    for item in d["contact"] + d["link"]:
        item["a"] = item["a"].rsplit(".", 1)[0] + f".{bays}"
    if linear:
        d["contact"], d["link"] = [], []
        d["analysis"]["output"]["links"] = []
    d["analysis"].update(integrator=integrator, t_end=t_end)
    if integrator == "fast-nonlinear":
        d["analysis"].update(tol_residual=1e-10, max_newton=100)
    d["analysis"]["output"]["nodes"] = []
    return from_dict(d, base_dir=HERE)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--t-end", type=float, default=5.0)
    ap.add_argument("--repeat", type=int, default=3)
    args = ap.parse_args()
    print(f"P10 pair, configuration A, record 1, dt = {cs.DT * 1e3:g} ms, t_end = {args.t_end:g} s; "
          f"best of {args.repeat} (wall time of the native run)")
    print(f"{'storeys':>7} {'bays':>4} {'DOFs':>5} | {'linear Newmark':>14} | {'Newmark':>8} {'it/step':>7} | "
          f"{'FNA':>8} {'it/step':>7} {'Newton passes':>13} | {'FNA/Newmark':>11}")
    for storeys in (5, 10, 20):
        for bays in (2, 4):
            best = {}
            for key, integ, lin in (("lin", "newmark", True), ("nm", "newmark", False),
                                    ("fna", "fast-nonlinear", False)):
                runs = [run_full(scene(storeys, bays, integ, args.t_end, lin))[0] for _ in range(args.repeat)]
                best[key] = min(runs, key=lambda s: s["cost"]["wall_time_s"])
            dofs = (2 + storeys) * (bays + 1)
            nm, fna = best["nm"]["cost"], best["fna"]["cost"]
            print(f"{storeys:>7} {bays:>4} {dofs:>5} | {best['lin']['cost']['wall_time_s']:>12.2f} s | "
                  f"{nm['wall_time_s']:>6.2f} s {nm['newton_iterations'] / nm['steps']:>7.2f} | "
                  f"{fna['wall_time_s']:>6.2f} s {fna['newton_iterations'] / fna['steps']:>7.2f} "
                  f"{fna['jacobian_evaluations']:>13} | {fna['wall_time_s'] / nm['wall_time_s']:>11.2f}",
                  flush=True)


if __name__ == "__main__":
    main()
