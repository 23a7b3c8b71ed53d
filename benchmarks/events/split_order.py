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

    .venv/bin/python benchmarks/events/split_order.py [--integrators newmark,hht]
"""
import argparse
import math

import martello.api as api
from martello.oracles.p5_contact_laws import hunt_crossley_realised_e, newton_impact

M1, M2, V0, GAP, E = 1.0, 2.0, 1.0, 1.0137e-3, 0.5
LAWS = {"kelvin": {"stiffness": 1e6, "restitution": E},
        "hunt-crossley": {"stiffness": 1e8, "restitution": E}}
REALISED = {"kelvin": E, "hunt-crossley": hunt_crossley_realised_e(1.5 * (1.0 - E))}
# contact time ~ π√(m*/k) ≈ 2.6e-3 s (Kelvin): 26 ... 416 steps per contact
STEPS = [1e-4, 5e-5, 2.5e-5, 1.25e-5, 6.25e-6]


def scene(law, integrator, dt, gap=GAP, **extra):
    an = {"type": "dynamic", "integrator": integrator, "dt": dt, "t_end": 0.008}
    if integrator == "newmark":
        an["preset"] = "average-acceleration"
    an.update(extra)
    c = {"name": "impact", "a": "m1", "b": "m2", "gap": gap, "scheme": "penalty", "law": law}
    c.update(LAWS[law])
    return {"node": [{"name": "m1", "mass": M1, "v0": V0}, {"name": "m2", "mass": M2}],
            "contact": [c], "analysis": an}


def v1_error(law, integrator, dt, gap=GAP, **extra):
    s = api.run(scene(law, integrator, dt, gap, **extra)).summary
    exact = newton_impact(M1, M2, V0, 0.0, REALISED[law]).v1
    return abs(s["nodes"]["m1"]["v_final"] - exact)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--integrators", default="newmark")
    args = ap.parse_args()
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
