"""Write benchmarks/sdof/sdof_sine_<integrator>.toml for the integrators the hand-written
scenes (Newmark, HHT, generalized-α, central difference) leave out: the damped SDOF under a
sine ground motion (m = 2 kg, k = 800 N/m, ζ = 5 %, 3 sin(13 t) m/s², 2 s) against its closed
form `sdof_sine_ground_final`. Regenerate with

    .venv/bin/python benchmarks/sdof/make_integrator_sweep.py

Tolerances: Moreau–Jean (θ = ½) and fast nonlinear analysis at ωh = 2e-3 are second order,
1e-5 as the hand-written scenes (measured 1.0e-6 and 1.4e-7); the event-locating
integrators' error follows their tolerance: 10 rtol for rkf45, rk8pd and ARKODE at 1e-10
(measured 1e-11, 4e-16, 3e-12), 1000 rtol for the multistep methods IDA, msbdf and CVODE at
1e-12 (2.6e-10 msbdf, 2.2e-10 CVODE; IDA 5e-11 to 1.6e-10 with its masses x (1 + k eps),
k = -8 … 8, and 6e-11 to 1.8e-10 with its analytic Jacobian: at 100 rtol the bound was
passed or not by chance)."""

from pathlib import Path

HERE = Path(__file__).resolve().parent
FIXED = {"moreau-jean": "theta = 0.5\ndt = 1.0e-4", "fast-nonlinear": "dt = 1.0e-4"}
ADAPTIVE = {"rkf45": (1e-10, 10), "rk8pd": (1e-10, 10), "arkode": (1e-10, 10), "ida": (1e-12, 1000),
            "msbdf": (1e-12, 1000), "cvode": (1e-12, 1000)}


def scene(integ, settings, rtol_check, why):
    return f'''title = "SDOF under sine ground motion, {integ}"
problem = "SDOF"
description = """
A linear damped oscillator (m = 2 kg, k = 800 N/m, ζ = 5 %) from rest under the ground
acceleration 3 sin(13 t) m/s²; exact solution in closed_forms.sdof_sine_ground_response.
Written by benchmarks/sdof/make_integrator_sweep.py (edit it, not this file)."""

[[node]]
name = "m"
mass = 2.0

[[link]]
type = "spring"
a = "m"
b = "ground"
k = 800.0

[[link]]
type = "dashpot"
a = "m"
b = "ground"
zeta = 0.05

[loads.ground_acceleration]
type = "sine"
amplitude = 3.0
omega = 13.0

[analysis]
type = "dynamic"
integrator = "{integ}"
{settings}
t_end = 2.0

{check_block("sdof_sine_ground_final",
              "{ m = 2.0, k = 800.0, zeta = 0.05, ag_amp = 3.0, omega_g = 13.0, t_end = 2.0 }",
              [("nodes.m.u_final", "u"), ("nodes.m.v_final", "v")], rtol_check, why)}'''


def check_block(closed_form, params, pairs, rtol, why, fmt=".0e"):
    """The [check] block of a sweep's scene (also benchmarks/p6 and benchmarks/p10's sweeps):
    the closed form with params (an inline table's text), and each (result, oracle) of pairs
    compared to rtol (written with fmt) for one reason, why."""
    return (f'[check]\nclosed_form = "{closed_form}"\nparams = {params}\n'
            + "".join(f'[[check.compare]]\nresult = "{result}"\noracle = "{oracle}"\n'
                      f'rtol = {rtol:{fmt}}\nwhy = "{why}"\n' for result, oracle in pairs))


def adaptive_settings(rtol):
    """An event-locating integrator's tolerances in these sweeps (also benchmarks/p6's):
    atol = 1e-4 rtol [m]: the scenes' displacements are millimetres or more, so the relative
    test governs."""
    return f"rtol = {rtol:.0e}\natol = {rtol * 1e-4:.0e}"


def scenes():
    out = {}
    for integ, settings in FIXED.items():
        out[f"sdof_sine_{integ.replace('-', '_')}"] = scene(
            integ, settings, 1e-5, "second order at ωh = 2e-3, as the Newmark family's scenes: measured "
            "1.0e-6 (Moreau–Jean θ = ½), 1.4e-7 (fast nonlinear analysis)")
    for integ, (rtol, factor) in ADAPTIVE.items():
        out[f"sdof_sine_{integ}"] = scene(
            integ, adaptive_settings(rtol) + "\ndt = 1.0e-3", factor * rtol,
            f"the error follows rtol = {rtol:.0e}: bound {factor} rtol (benchmarks/sdof/make_integrator_sweep.py)")
    return out


if __name__ == "__main__":
    for name, text in scenes().items():
        (HERE / f"{name}.toml").write_text(text)
