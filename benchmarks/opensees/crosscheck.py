"""What the OpenSees cross-checks of martello's scenes share (benchmarks/p10/opensees_check.py,
benchmarks/p11/opensees_check.py; docs/p10-case-study.md "OpenSees cross-check",
docs/buildings.md "OpenSees cross-check"): finding an interpreter with openseespy, running a
script's OpenSees half in it on a JSON file of parameters, and, inside that half, the gap
element and the analysis both checks use.

The OpenSees half runs under openseespy's interpreter: this module imports neither martello
nor numpy, and takes `ops` (openseespy.opensees) as an argument."""

import json
import subprocess
import sys
from pathlib import Path


# --- the martello side ------------------------------------------------------------------------

def opensees_python(given):
    """The interpreter of the OpenSees half: given, else this one; None if it cannot import
    openseespy (nothing is installed here)."""
    py = given or sys.executable
    ok = subprocess.run([py, "-c", "import openseespy.opensees"], capture_output=True).returncode == 0
    return py if ok else None


SKIPPED = ("SKIPPED: no openseespy here: give --python with an interpreter that has it "
           "(python -m venv DIR && DIR/bin/pip install openseespy numpy)")


def run_opensees_half(python, script, params, folder):
    """script's OpenSees half (`script --opensees-worker PARAMS RESULT`) under python, on
    params written to folder/params.json: the result it writes to folder/result.json, or None
    after printing why it failed."""
    folder = Path(folder)
    pf, rf = folder / "params.json", folder / "result.json"
    pf.write_text(json.dumps(params))
    r = subprocess.run([python, str(script), "--opensees-worker", str(pf), str(rf)],
                       capture_output=True, text=True)
    if r.returncode != 0:
        print("OpenSees run failed:\n" + r.stdout[-2000:] + r.stderr[-2000:])
        return None
    return json.loads(rf.read_text())


# --- the OpenSees side (under openseespy's interpreter) ----------------------------------------

def gap_element(ops, mat, ele, ni, nj, k, gap):
    """A compression-only gap between nodes ni and nj along x: a zeroLength element of an
    ElasticPPGap material, a linear spring of stiffness k past the gap, no tension (a
    compression gap has negative Fy and gap; Fy so large it never yields)."""
    ops.uniaxialMaterial("ElasticPPGap", mat, k, -1e30, -gap)
    ops.element("zeroLength", ele, ni, nj, "-mat", mat, "-dir", 1)


def newmark_transient(ops, t, accel, constraints):
    """The ground acceleration (t, accel) along x as a Path series (OpenSees interpolates the
    samples linearly, as martello does), and the analysis: Newmark (½, ¼), Newton with a
    displacement-increment test at 1e-12 (50 iterations), RCM numbering, UmfPack; constraints
    "Plain", or "Transformation" where a rigid diaphragm ties nodes."""
    ops.timeSeries("Path", 1, "-time", *t, "-values", *accel)
    ops.pattern("UniformExcitation", 1, 1, "-accel", 1)
    ops.constraints(constraints)
    ops.numberer("RCM")
    ops.system("UmfPack")
    ops.test("NormDispIncr", 1e-12, 50)
    ops.algorithm("Newton")
    ops.integrator("Newmark", 0.5, 0.25)
    ops.analysis("Transient")


def steps(ops, t_end, dt):
    """Runs round(t_end/dt) steps of dt, yielding after each (the caller tracks its peaks
    there); exits naming the step OpenSees failed at."""
    for k in range(int(round(t_end / dt))):
        if ops.analyze(1, dt) != 0:
            raise SystemExit(f"OpenSees failed at step {k + 1}")
        yield k


def version(ops):
    return ops.version() if hasattr(ops, "version") else "?"
