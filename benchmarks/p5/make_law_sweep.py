"""Write benchmarks/p5/laws/: P5's free two-body impact (docs/problems.md P5) for every
penalty law on every integrator that runs it, besides Newmark (benchmarks/p5/p5_<law>.toml),
each checked against `two_body_impact`. Regenerate with

    .venv/bin/python benchmarks/p5/make_law_sweep.py

The tolerance of each row follows from the law's smoothness and the integrator's order (the
`why` of each row says which); nothing is calibrated on a run."""

from pathlib import Path

HERE = Path(__file__).resolve().parent / "laws"
LAWS = {  # law: (stiffness, target e, clipped)
    "linear": (1e6, None, False), "hertz": (1e8, None, False), "kelvin": (1e6, 0.5, False),
    "kelvin_clipped": (1e6, 0.5, True), "hunt-crossley": (1e8, 0.5, False),
    "lankarani-nikravesh": (1e8, 0.8, False), "flores": (1e8, 0.5, False), "gonthier": (1e8, 0.5, False),
    "hertzdamp": (1e8, 0.8, False), "jankowski": (1e8, 0.65, False)}
FIXED = {"hht": 'alpha = -0.05', "generalized-alpha": 'rho_inf = 0.9', "central-difference": "",
         "moreau-jean": "theta = 0.5"}
ADAPTIVE = ("rkf45", "rk8pd", "msbdf", "ida", "cvode", "arkode")


def tolerance(law, integ):
    """(rtol, why) of the realised e."""
    jump = law in ("kelvin", "kelvin_clipped")
    if integ in ADAPTIVE:
        return 1e-6, ("adaptive, rtol 1e-10, every contact onset and separation located: the "
                      "realised e carries the global error, ≤ 1e4 × rtol over the ~1e3 steps of a phase")
    if law == "jankowski":
        return 2e-4, ("the damping 2ξ√(β√δ m*) has an unbounded derivative at first touch: fixed steps "
                      "lose order there, O(h^(5/4)) at ωh ≈ 2e-4")
    if jump:
        return 1e-3, ("the force jumps by cδ̇ at δ = 0: fixed steps integrate the jump with an O(h) "
                      "error whose constant depends on where δ = 0 falls in the step, ≈ ξωh = 2.6e-5; "
                      "1e-3 covers a constant of 40")
    if integ == "moreau-jean":
        return 1e-4, ("one linearisation of the smooth force per step (the start-of-step tangent): "
                      "O(h) in the force, ωh ≈ 2e-4 at the peak stiffness")
    return 1e-6, ("force continuous at both ends of the contact: second order, (ωh)² ≈ 5e-8 at "
                  "the peak tangent stiffness; 1e-6 covers a constant of 20")


def scene(law, integ):
    K, e, clipped = LAWS[law]
    name = "kelvin" if law == "kelvin_clipped" else law
    keys = [f'law = "{name}"', f"stiffness = {K:.1e}"]
    params = [f'law = "{name}"', "m1 = 1.0", "m2 = 2.0", "v0 = 1.0", f"stiffness = {K:.1e}"]
    if e is not None:
        keys.append(f"restitution = {e}")
        params.append(f"restitution = {e}")
    if clipped:
        keys.append("clipped = true")
        params.append("clipped = true")
    rtol, why = tolerance(law, integ)
    if integ in ADAPTIVE:
        an = f'integrator = "{integ}"\ndt = 1.0e-5\nt_end = 0.005\nrtol = 1.0e-10\natol = 1.0e-14'
    else:
        extra = FIXED[integ]
        an = f'integrator = "{integ}"\n' + (extra + "\n" if extra else "") + "dt = 1.0e-7\nt_end = 0.005"
    return f'''title = "P5 two bodies, {law}, {integ}"
problem = "P5"
description = """
P5's free two-body impact (m1 = 1 kg at 1 m/s, m2 = 2 kg at rest, 1 mm gap) with the {law}
law on {integ}; written by benchmarks/p5/make_law_sweep.py (edit it, not this file)."""

[[node]]
name = "m1"
mass = 1.0
v0 = 1.0
[[node]]
name = "m2"
mass = 2.0

[[contact]]
name = "impact"
a = "m1"
b = "m2"
gap = 1.0e-3
scheme = "penalty"
{chr(10).join(keys)}

[analysis]
type = "dynamic"
{an}
[analysis.output]
every = 1000

[check]
closed_form = "two_body_impact"
params = {{ {", ".join(params)} }}
[[check.compare]]
result = "contacts.impact.restitution.0"
oracle = "restitution"
rtol = {rtol:.0e}
why = "{why}"
'''


if __name__ == "__main__":
    HERE.mkdir(exist_ok=True)
    for law in LAWS:
        for integ in (*FIXED, *ADAPTIVE):
            if integ == "moreau-jean" and law == "jankowski":
                continue            # refused (fortran/run_checks.f90)
            (HERE / f"p5_{law.replace('-', '_')}_{integ.replace('-', '_')}.toml").write_text(scene(law, integ))
