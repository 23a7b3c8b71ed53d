"""Write benchmarks/p7/laws/: P7's two oscillators of different period (docs/problems.md P7,
benchmarks/p7/p7_two_oscillators.toml) with every penalty law on the event-locating
integrators (rkf45, rk8pd, msbdf, IDA, CVODE, ARKODE) and Newmark, HHT and generalized-α (the two Kelvin laws
with event_split), each checked against the
independent engine (reference/independent/p7_two_<law>.json, docs/independent-reference.md):
impact and separation times, realised e and peak penetration of every phase, the nodes'
extremes and the energies. Regenerate the scenes with

    .venv/bin/python benchmarks/p7/make_law_sweep.py

and their references with benchmarks/independent/make_references.py (the p7_two_* entries).

The unclipped Kelvin scenes share the physics of benchmarks/p7/p7_two_oscillators.toml; their
reference (p7_two_kelvin) names them, so that scene (Newmark at Δt = 1e-4 without event
split, which misses two of the 13 phases) keeps its regression rows (docs/coverage.md)."""

from pathlib import Path

HERE = Path(__file__).resolve().parent / "laws"
HERTZ_K = 3.0e6          # N/m^1.5, the P7 Hunt–Crossley variant's stiffness (reference/references.toml)
LAWS = {  # law: contact keys (the P7 law variants of benchmarks/independent/make_references.py)
    "linear": 'law = "linear", stiffness = 1.0e5',
    "hertz": f'law = "hertz", stiffness = {HERTZ_K:.1e}',
    "kelvin_clipped": 'law = "kelvin", stiffness = 1.0e5, restitution = 0.65, clipped = true',
    **{law: f'law = "{law}", stiffness = {HERTZ_K:.1e}, restitution = 0.65'
       for law in ("hunt-crossley", "lankarani-nikravesh", "flores", "gonthier", "hertzdamp", "jankowski")}}
INTEGRATORS = ("rkf45", "rk8pd", "msbdf", "ida", "cvode", "arkode")
# fixed steps at Δt = 1e-5 for the laws whose force has no kink inside a phase: linear,
# hertz, the Hunt–Crossley family (which P7 never drives past its cut, 1 + χδ̇ = 0: the
# engine logs no cut here) and jankowski. The Hunt–Crossley family's χ = a/v_in takes the rate
# interpolated to where δ crosses 0 inside the step (fortran/assembly.f90, onset_speed): with
# the larger of the step ends' rates it was first order, and 1–3 of ~51 rows of each of these
# laws failed on Newmark.
FIXED = {"newmark": 'preset = "average-acceleration"', "hht": "alpha = -0.05", "generalized-alpha": "rho_inf = 0.9"}
FIXED_LAWS = ("linear", "hertz", "hunt-crossley", "lankarani-nikravesh", "flores", "gonthier", "hertzdamp",
              "jankowski")
# The two Kelvin laws on fixed steps with event_split = true. The clipped law is cut where its
# formula would pull (F = 0 while δ > 0): a kink inside a phase, which a plain step integrates
# with an error whose constant depends on where it falls in the step (a phase's peak
# penetration 3.2 digits at Δt = 1e-5 on Newmark, HHT, generalized-α, beyond its Richardson
# bound); event_split puts the cut-off on a sub-step boundary (docs/integrators.md), and at
# Δt = 5e-6 every row is within its 2Δt/4Δt bound (≥ 6.5 digits against the engine).
# The unclipped Kelvin law of benchmarks/p7/p7_two_oscillators.toml itself, on every integrator:
# its force jumps by cδ̇ at both ends of a phase, which the Newmark family integrates at
# second order only with event_split = true (each jump on a sub-step boundary,
# docs/integrators.md); a plain step leaves an O(h) error with an erratic constant (measured
# on Newmark: |Δv|/Δt from 0.2 to 22 m/s² over 13 steps from 1e-6 to 1e-5 s;
# docs/independent-reference.md). Δt = 5e-6: at 1e-5 the tenth impact (after a 33 µm phase)
# is not yet asymptotic on HHT (order 1.3 from Δt, 2Δt, 4Δt).
LAWS["kelvin"] = 'law = "kelvin", stiffness = 1.0e5, restitution = 0.65'
KELVIN_FIXED = 'event_split = true\ndt = 5.0e-6'
# The linear law's slope jumps by k at δ = 0 and Jankowski's damping switches off where δ̇
# turns and rises as δ^(1/4) after the onset: on plain steps their P7 rows converged at
# order 1 (linear) and erratically (Jankowski: 0.4-0.6, a phase's penetration 4.2 % off);
# with event_split each switch is a sub-step boundary: second order for the linear law,
# a regular order of 1.4-2.1 for Jankowski (its τ^(1/4) onset caps it at 5/4 asymptotically:
# martello/checks/independent_rows.py, JANKOWSKI_ORDER), whose rows' 2Δt bounds fall below
# 1 % at Δt = 5e-6 (at 1e-5 the third phase's e has 3 × |e_h − e_2h| = 2.3 %).
SPLIT_FIXED = 'event_split = true\ndt = 1.0e-5'
JANKOWSKI_FIXED = 'event_split = true\ndt = 5.0e-6'


def name(law, integ):
    return f"p7_two_{law.replace('-', '_')}_{integ.replace('-', '_')}"


def settings(integ, law=None):
    if integ in FIXED and law in ("kelvin", "kelvin_clipped"):
        return FIXED[integ] + "\n" + KELVIN_FIXED
    if integ in FIXED and law == "jankowski":
        return FIXED[integ] + "\n" + JANKOWSKI_FIXED
    if integ in FIXED and law == "linear":
        return FIXED[integ] + "\n" + SPLIT_FIXED
    if integ in FIXED:
        return FIXED[integ] + "\ndt = 1.0e-5"
    if integ in ("msbdf", "cvode", "ida"):
        # msbdf (variable-order BDF, at most fifth order) at rtol 1e-10 confirmed only 5.98
        # digits of the linear and Kelvin contacts' e and peaks; at 1e-12 it reaches the
        # references' own digits (7.0). IDA: the grazing phases (2.7e-5 and 4.3e-5 m of 1e-3 m
        # peaks) err by 7e-3 and 2e-3 of themselves at 10^4 x rtol = 1e-6, more than a verified
        # row's 1 % bound allows from that rerun (docs/coverage.md); CVODE errs alike (5e-3).
        # At 1e-10 only output stops every 1 ms had capped the reruns' steps; IDA's steps no
        # longer depend on the output (docs/ida.md, output rows)
        # atol: a velocity's absolute error where it crosses zero (its weight is atol alone
        # there); below 1e3 eps x the velocities' size (0.6 m/s here: 1.3e-13) the error test
        # asks for less than the arithmetic resolves (1e-16 is below one ulp of 0.6) and
        # passes or fails by chance (docs/ida.md, failures: at 1e-16 IDA's Hertz scene with its
        # masses x (1 + 4 eps) failed its error test down to h = 9e-11 s where v2 = 0). CVODE
        # and msbdf have the same error weights: at 1e-16 they did not fail (0 of 100 such
        # probes each) but took 25-30 % (CVODE) and 4-18 % (msbdf) more steps than at 1e-13
        return "rtol = 1.0e-12\natol = 1.0e-13\ndt = 1.0e-4"
    return "rtol = 1.0e-10\natol = 1.0e-14\ndt = 1.0e-4"


def scene(law, integ):
    return f'''title = "P7 two oscillators, {law} contact, {integ}"
problem = "P7"
description = """
P7's two damped oscillators (periods 0.63 s and 0.31 s, 5 % damping, 10 mm gap) under the
ground acceleration 3 sin(8 t) m/s² for 4 s with the {law} penalty law, on {integ}; verified
against the independent engine. Written by benchmarks/p7/make_law_sweep.py (edit it, not this file)."""

[[chain]]
prefix = "s"
n = 2
mass = 1.0
k = [100.0, 400.0]
zeta = 0.05
gap = 0.01
contact = {{ scheme = "penalty", {LAWS[law]} }}

[loads.ground_acceleration]
type = "sine"
amplitude = 3.0
omega = 8.0

[analysis]
type = "dynamic"
integrator = "{integ}"
{settings(integ, law)}
t_end = 4.0
[analysis.output]
every = {100 if integ in FIXED else 10}
'''


PAIRS = [(law, integ) for law in LAWS for integ in INTEGRATORS] + \
    [(law, integ) for law in FIXED_LAWS + ("kelvin", "kelvin_clipped") for integ in FIXED]
SCENES = {name(law, integ): f"benchmarks/p7/laws/{name(law, integ)}.toml" for law, integ in PAIRS}

if __name__ == "__main__":
    HERE.mkdir(exist_ok=True)
    for law, integ in PAIRS:
        (HERE / f"{name(law, integ)}.toml").write_text(scene(law, integ))
