"""Write benchmarks/p10/integrators/: P10's five-storey RC frame (frame B of the case study,
benchmarks/p10/p10_bare.toml: 2 bays, joint masses, 5 % Rayleigh damping at modes 1 and 2)
alone, linear, under the ground acceleration 2 sin(8 t) m/s² for 2 s, on every integrator
that runs it, each checked against the closed form `frame_sine_ground_final`: modal
superposition of the frame's own stiffness and damping written apart from the front end
(martello.oracles.p10_frames, martello.independent.frame). Regenerate with

    .venv/bin/python benchmarks/p10/make_linear_sweep.py

Tolerances, from the mathematics of each method: the response at t = 2 s is carried by the
first mode (T₁ = 0.987 s, ω₁ = 6.37 rad/s); a second-order step's phase error is
(ω₁h)²/12 per radian, over ω₁ t_end = 12.7 rad, and its amplitude error O((ω₁h)²), so the bound
is (ω₁h)² (1 + ω₁ t_end) relative (5.5e-4 at h = 1e-3: Newmark measured 7.5e-5, HHT 8.6e-5,
generalized-α 7.6e-5; FNA 5.3e-6; central difference 1.7e-6 at 2e-4; Moreau–Jean θ = ½
7.5e-7 at 1e-4, whose bound is 5.5e-6). The event-locating integrators' error follows their
tolerance: 10 rtol for rkf45 and rk8pd at 1e-10 (measured 6e-12, 1e-12), 100 rtol for IDA at
1e-12 (measured 2.7e-11), 1000 rtol for msbdf and CVODE at 1e-12 (measured 1.3e-10 to 3.4e-10
with the scene's output every 0.01 s: multistep methods whose error is 100-350 × rtol on this
stiff frame)."""

import math
import sys
from pathlib import Path

HERE = Path(__file__).resolve().parent / "integrators"
sys.path.insert(0, str(HERE.parents[2]))
from benchmarks.sdof.make_integrator_sweep import check_block  # noqa: E402  (defined there once)
OMEGA1, T_END = 2.0 * math.pi / 0.98668219, 2.0
FRAME = '''[[frame]]
prefix = "B"
storeys = 5
bays = 2
storey_height = 3.0
bay_width = 5.0
column = [{ E = 2.85e10, A = 0.75, I = 0.0078125 }, { E = 2.85e10, A = 0.75, I = 0.0078125 },
          { E = 2.85e10, A = 0.6, I = 0.004 }, { E = 2.85e10, A = 0.6, I = 0.004 },
          { E = 2.85e10, A = 0.6, I = 0.004 }]
beam = { E = 2.85e10, A = 0.75, I = 0.0078125 }
mass = [195000.0, 195000.0, 195000.0, 195000.0, 150000.0]
mass_model = "joints"
zeta = 0.05
'''
PARAMS = ('{ frame = { prefix = "B", storeys = 5, bays = 2, storey_height = 3.0, bay_width = 5.0, '
          'column = [{ E = 2.85e10, A = 0.75, I = 0.0078125 }, { E = 2.85e10, A = 0.75, I = 0.0078125 }, '
          '{ E = 2.85e10, A = 0.6, I = 0.004 }, { E = 2.85e10, A = 0.6, I = 0.004 }, '
          '{ E = 2.85e10, A = 0.6, I = 0.004 }], beam = { E = 2.85e10, A = 0.75, I = 0.0078125 }, '
          'mass = [195000.0, 195000.0, 195000.0, 195000.0, 150000.0], mass_model = "joints", zeta = 0.05 }, '
          'ag_amp = 2.0, omega_g = 8.0, t_end = 2.0 }')
FIXED = {"newmark": ('preset = "average-acceleration"', 1e-3), "hht": ("alpha = -0.05", 1e-3),
         "generalized-alpha": ("rho_inf = 0.9", 1e-3), "fast-nonlinear": ("", 1e-3),
         "central-difference": ("", 2e-4), "moreau-jean": ("theta = 0.5", 1e-4)}
ADAPTIVE = {"rkf45": (1e-10, 10), "rk8pd": (1e-10, 10), "ida": (1e-12, 100), "msbdf": (1e-12, 1000),
            "cvode": (1e-12, 1000)}


def scene(integ, settings, rtol_check, why):
    check = check_block("frame_sine_ground_final", PARAMS,
                        [(f"nodes.{nm}.u_final", f"u_{nm}") for nm in ("B5.0", "B3.1")], rtol_check, why, ".1e")
    return f'''title = "P10 frame B alone, linear, sine ground motion, {integ}"
problem = "P10"
description = """
P10's five-storey RC frame (frame B of benchmarks/p10/p10_bare.toml) alone and linear, from rest
under the ground acceleration 2 sin(8 t) m/s², on {integ}; checked against modal superposition
(frame_sine_ground_final). Written by benchmarks/p10/make_linear_sweep.py (edit it, not this file)."""

{FRAME}
[loads.ground_acceleration]
type = "sine"
amplitude = 2.0
omega = 8.0

[analysis]
type = "dynamic"
integrator = "{integ}"
{settings}t_end = {T_END}

{check}'''


def scenes():
    out = {}
    for integ, (keys, h) in FIXED.items():
        bound = (OMEGA1 * h) ** 2 * (1.0 + OMEGA1 * T_END)
        why = (f"second order: the phase error (ω₁h)²/12 per radian over ω₁ t_end = {OMEGA1 * T_END:.1f} rad "
               f"and the amplitude's O((ω₁h)²): (ω₁h)² (1 + ω₁ t_end) = {bound:.1e} at h = {h:g} "
               "(benchmarks/p10/make_linear_sweep.py: measured 7e-7 to 9e-5)")
        settings = (keys + "\n" if keys else "") + f"dt = {h:g}\n"
        out[f"p10_linear_{integ.replace('-', '_')}"] = scene(integ, settings, bound, why)
    for integ, (rtol, factor) in ADAPTIVE.items():
        why = (f"the error follows rtol = {rtol:g}: bound {factor} rtol "
               "(benchmarks/p10/make_linear_sweep.py: measured 1e-12 to 2.5e-10)")
        settings = f"rtol = {rtol:g}\natol = {rtol * 1e-4:g}\ndt = 0.01\n"
        out[f"p10_linear_{integ}"] = scene(integ, settings, factor * rtol, why)
    return out


if __name__ == "__main__":
    HERE.mkdir(exist_ok=True)
    for name, text in scenes().items():
        (HERE / f"{name}.toml").write_text(text)
