"""Write P8's three buildings scenes (docs/problems.md P8: bare, A, B, record 1) on the
event-locating integrators rkf45, rk8pd, msbdf and IDA (rtol 1e-10, output every 5 ms, the
Newmark scenes' grid), each checked against the independent engine's reference of its
physics (reference/independent/p8_<case>.json, docs/independent-reference.md): every gap
element's impact and separation times, realised e and peak penetration, the floors' extremes
and the energies. Regenerate with

    .venv/bin/python benchmarks/p8/make_integrator_sweep.py

The scenes are the Newmark ones with their [analysis] replaced (edit those, not these)."""

import re
from pathlib import Path

HERE = Path(__file__).resolve().parent
CASES = ("bare", "A", "B")
INTEGRATORS = ("rkf45", "rk8pd", "msbdf", "ida")
ANALYSIS = '''[analysis]
type = "dynamic"
integrator = "{integ}"
rtol = 1.0e-10
atol = 1.0e-14
dt = 0.005
t_end = {t_end}
[analysis.output]
every = 1
'''


def scene(case, integ):
    text = (HERE / f"p8_{case}.toml").read_text()
    title = re.search(r'^title = "(.*)"$', text, re.M).group(1)
    text = text.replace(f'title = "{title}"', f'title = "{title}, {integ}"', 1)
    head, rest = text.split("[analysis]\n", 1)
    t_end = re.search(r"^t_end = (.*)$", rest, re.M).group(1)
    # the output table after [analysis.output]'s every (links, nodes) is kept
    tail = rest.split("[analysis.output]\n", 1)[1]
    tail = re.sub(r"^every = .*\n", "", tail, count=1, flags=re.M)
    note = (f"# Written by benchmarks/p8/make_integrator_sweep.py from p8_{case}.toml, itself "
            "written by case_study.py: edit those, not this file.\n")
    return note + head + ANALYSIS.format(integ=integ, t_end=t_end) + tail


SCENES = {f"p8_{case}_{integ}": f"benchmarks/p8/p8_{case}_{integ}.toml" for case in CASES for integ in INTEGRATORS}

if __name__ == "__main__":
    for case in CASES:
        for integ in INTEGRATORS:
            (HERE / f"p8_{case}_{integ}.toml").write_text(scene(case, integ))
