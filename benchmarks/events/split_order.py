"""Order of the fixed-step Newmark family on penalty impacts whose force is not smooth at
δ = 0 (docs/integrators.md, event-split steps).

Two free masses (m1 = 1 kg at 1 m/s, m2 = 2 kg at rest) collide through a penalty contact
(docs/problems.md P5): Kelvin (k = 1e6 N/m, e = 0.5, unclipped: its force jumps by cδ̇ at onset
and separation) and Hunt–Crossley (K = 1e8, n = 3/2, target e = 0.5: F is continuous, its
derivative is not). The oracle is the closed form (martello.oracles.p5_contact_laws, no run
code): after separation both bodies fly freely with the Newton velocities of the realised
restitution (Kelvin: the target, exactly; Hunt–Crossley: `hunt_crossley_realised_e` of
a = 3(1 − e)/2). Printed: the error of v1 at t_end against dt and the observed order
log2(err(h)/err(h/2)).

With --hysteretic: the hysteretic pounding scenes of this folder (two bilinear oscillators,
linear or clipped Kelvin contact, sine ground motion, 8 s: yields, unloadings, onsets,
separations and cut-offs), the worst relative error of u max/min and u final against the
independent event-located reference (reference.py at rtol 2.3e-14), plain and split.

    .venv/bin/python benchmarks/events/split_order.py [--integrators newmark,hht] [--hysteretic]
"""
import argparse
import copy
import math
import tomllib
from pathlib import Path

import martello.api as api
from martello.oracles.p5_contact_laws import hunt_crossley_realised_e, newton_impact

M1, M2, V0, GAP, E = 1.0, 2.0, 1.0, 1.0137e-3, 0.5
LAWS = {"kelvin": {"stiffness": 1e6, "restitution": E},
        "hunt-crossley": {"stiffness": 1e8, "restitution": E}}
REALISED = {"kelvin": E, "hunt-crossley": hunt_crossley_realised_e(1.5 * (1.0 - E))}
# contact time ~ π√(m*/k) ≈ 2.6e-3 s (Kelvin): 26 ... 416 steps per contact
STEPS = [1e-4, 5e-5, 2.5e-5, 1.25e-5, 6.25e-6]
# the one parameter HHT and generalized-α need (a common, mildly dissipative choice)
EXTRA = {"newmark": {"preset": "average-acceleration"}, "hht": {"alpha": -0.05},
         "generalized-alpha": {"rho_inf": 0.9}}


def scene(law, integrator, dt, gap=GAP, **extra):
    an = {"type": "dynamic", "integrator": integrator, "dt": dt, "t_end": 0.008}
    an.update(EXTRA.get(integrator, {}))
    an.update(extra)
    c = {"name": "impact", "a": "m1", "b": "m2", "gap": gap, "scheme": "penalty", "law": law}
    c.update(LAWS[law])
    return {"node": [{"name": "m1", "mass": M1, "v0": V0}, {"name": "m2", "mass": M2}],
            "contact": [c], "analysis": an}


def v1_error(law, integrator, dt, gap=GAP, **extra):
    s = api.run(scene(law, integrator, dt, gap, **extra)).summary
    exact = newton_impact(M1, M2, V0, 0.0, REALISED[law]).v1
    return abs(s["nodes"]["m1"]["v_final"] - exact)


HERE = Path(__file__).resolve().parent
HYSTERETIC = ["pounding_bilinear.toml", "pounding_kelvin.toml"]
HYSTERETIC_STEPS = [2e-3, 1e-3, 5e-4, 2.5e-4, 1.25e-4, 6.25e-5]


def hysteretic_error(name, integrator, dt, reference_quantities, **extra):
    """Worst relative error of u max/min and u final of a hysteretic pounding scene."""
    d = copy.deepcopy(tomllib.loads((HERE / name).read_text()))
    d["analysis"] = {"type": "dynamic", "integrator": integrator, "dt": dt, "t_end": 8.0,
                     "output": {"every": 10 ** 7}, **EXTRA.get(integrator, {})}
    d["analysis"].update(extra)
    s = api.run(d).summary
    worst = 0.0
    for key, ref in reference_quantities.items():
        kind, node, field = key.split(".")
        worst = max(worst, abs(s[kind][node][field] - ref) / abs(ref))
    return worst, s["cost"]


def hysteretic(integrators):
    import reference
    for name in HYSTERETIC:
        sc, ext = reference.solve(HERE / name, rtol=2.3e-14, atol=1e-18)
        q = reference.quantities(sc, ext)
        for integ in integrators:
            for split in (False, True):
                print(f"{name} {integ} event_split = {str(split).lower()}")
                prev = None
                for dt in HYSTERETIC_STEPS:
                    e, cost = hysteretic_error(name, integ, dt, q, event_split=split)
                    order = "" if prev is None else f"  order {math.log2(prev / e):.2f}"
                    prev = e
                    print(f"  dt = {dt:.3e}  worst relative error {e:.3e}{order}  "
                          f"(newton {cost['newton_iterations']}, steps {cost['steps']})")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--integrators", default="newmark")
    ap.add_argument("--hysteretic", action="store_true")
    args = ap.parse_args()
    if args.hysteretic:
        hysteretic(args.integrators.split(","))
        return
    for integ in args.integrators.split(","):
        for law in LAWS:
            for split in (False, True):
                errs = [v1_error(law, integ, dt, event_split=split) for dt in STEPS]
                print(f"{integ} {law} event_split = {str(split).lower()}")
                for k, (dt, e) in enumerate(zip(STEPS, errs)):
                    order = "" if k == 0 else f"  order {math.log2(errs[k - 1] / e):.2f}"
                    print(f"  dt = {dt:.3e}  |v1 - v1_exact| = {e:.3e}{order}")


if __name__ == "__main__":
    main()
