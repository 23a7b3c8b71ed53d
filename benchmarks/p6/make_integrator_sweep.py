"""Write benchmarks/p6/integrators/: P6's elasto-plastic impulse (docs/problems.md P6,
benchmarks/p6/p6_elastoplastic_rho00.toml and _rho005.toml, which run Newmark) on every other
integrator that runs it, each checked against the closed form `elastoplastic_peak`
(martello.oracles.p6_hysteresis: the peak u_max and its time t_max). Regenerate with

    .venv/bin/python benchmarks/p6/make_integrator_sweep.py

Tolerances, from the mathematics of each method (ω = √(k/m) = 10 rad/s, h = 1e-4 s, ωh = 1e-3):

* fixed steps (HHT, generalized-α, central difference, Moreau–Jean θ = ½, fast nonlinear
  analysis, the seed's Newmark–Lagrange, Newmark with event_split): second order in ωh on
  this smooth-but-for-the-yield motion; the trapezoidal rule's phase error is (ωh)²/12 per
  radian and a yield kink inside a step adds an O(h²) error whose constant depends on where
  it falls, so the bound is 2 (ωh)² = 2e-6 (measured 0.16-0.38 (ωh)² at ωh = 1e-3, 2e-3,
  4e-3 on every one of them: a constant below 1);
* the event-locating integrators (rkf45, rk8pd, IDA at rtol 1e-10, msbdf at 1e-12): the yield
  is a located switch (docs/event-driven.md), the error follows the tolerance, bound 10 rtol
  (measured 7e-14 on rkf45 and rk8pd, 6e-11 on IDA at 1e-10); msbdf, a multistep method
  restarted at the switch, 100 rtol (measured 2.1e-11 at 1e-12, 1.4e-10 at 1e-11; at 1e-10 it is
  9e-8 off, a thousand times its rtol: run at 1e-12); ARKODE at 1e-10 10 rtol (measured 1e-13),
  CVODE at 1e-12 100 rtol (measured 2e-12; 2.7e-10 at 1e-10)."""

import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent / "integrators"
sys.path.insert(0, str(HERE.parents[2]))
# the [check] block and the adaptive tolerances of the sweeps' scenes, defined there once
from benchmarks.sdof.make_integrator_sweep import adaptive_settings, check_block  # noqa: E402
OMEGA_H = 1.0e-3
FIXED = {"newmark_split": ('integrator = "newmark"\npreset = "average-acceleration"\nevent_split = true', None),
         "hht": ('integrator = "hht"\nalpha = -0.05', None),
         "generalized_alpha": ('integrator = "generalized-alpha"\nrho_inf = 0.9', None),
         "central_difference": ('integrator = "central-difference"', None),
         "moreau_jean": ('integrator = "moreau-jean"\ntheta = 0.5', None),
         "fast_nonlinear": ('integrator = "fast-nonlinear"', None),
         "newmark_lagrange": ('integrator = "newmark-lagrange"', None)}
ADAPTIVE = {"rkf45": (1e-10, 10), "rk8pd": (1e-10, 10), "ida": (1e-10, 10), "msbdf": (1e-12, 100),
            "arkode": (1e-10, 10), "cvode": (1e-12, 100)}
CASES = {"rho00": 0.0, "rho005": 0.05}


def scene(case, name, settings, rtol_check, why):
    rho = CASES[case]
    return f'''title = "P6 elasto-plastic impulse, hardening {rho}, {name.replace('_', ' ')}"
problem = "P6"
description = """
An undamped bilinear SDOF (k = 100 N/m, u_y = 0.01 m, F_y = 1 N, post-yield ratio {rho}) starts
from rest with v0 = 0.5 m/s > ω u_y: it yields and reaches u_max at t_max (docs/problems.md P6),
on {name.replace('_', ' ')}. Written by benchmarks/p6/make_integrator_sweep.py (edit it, not this file)."""

[[node]]
name = "m"
mass = 1.0
v0 = 0.5

[[link]]
type = "bilinear"
a = "m"
b = "ground"
k = 100.0
fy = 1.0
hardening = {rho}

[analysis]
type = "dynamic"
{settings}
dt = 1.0e-4
t_end = 1.0

{check_block("elastoplastic_peak", f"{{ m = 1.0, k = 100.0, uy = 0.01, rho = {rho}, v0 = 0.5 }}",
              [("nodes.m.u_peak", "u_max"), ("nodes.m.t_peak", "t_max")], rtol_check, why)}'''


def scenes():
    out = {}
    fixed_why = (f"second order in ωh = {OMEGA_H:g}: the trapezoidal phase error (ωh)²/12 per radian and a "
                 "yield kink inside a step, whose constant depends on where it falls: 2 (ωh)² (measured "
                 "0.16-0.38 (ωh)² at ωh = 1e-3 to 4e-3; benchmarks/p6/make_integrator_sweep.py)")
    for case in CASES:
        for name, (settings, _) in FIXED.items():
            out[f"p6_{case}_{name}"] = scene(case, name, settings, 2.0 * OMEGA_H ** 2, fixed_why)
        for name, (rtol, factor) in ADAPTIVE.items():
            settings = f'integrator = "{name}"\n' + adaptive_settings(rtol)
            why = (f"the yield is a located switch: the error follows rtol = {rtol:.0e}, bound {factor} rtol "
                   "(measured 7e-14 on rkf45 and rk8pd at 1e-10, 6e-11 on IDA at 1e-10, 1e-13 on ARKODE at 1e-10, "
                   "2.1e-11 on msbdf and 2e-12 on CVODE at 1e-12: multistep methods restarted at the switch)")
            out[f"p6_{case}_{name}"] = scene(case, name, settings, factor * rtol, why)
    return out


if __name__ == "__main__":
    HERE.mkdir(exist_ok=True)
    for name, text in scenes().items():
        (HERE / f"{name}.toml").write_text(text)
