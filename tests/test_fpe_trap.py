"""The library under Fortran runtime checks and floating-point traps (scripts/fpe-trap,
CMake option MARTELLO_FPE_TRAP: -fcheck=all -ffpe-trap=invalid,zero,overflow): a separate
build whose examples, kernel checks and a run of P2 on every integrator (penalty and
restitution planes) must finish with no trapped operation, and whose negative control (a
division by zero) must trap, so that a green run means the traps were on."""

import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def test_examples_and_every_integrator_clean_under_fpe_traps():
    r = subprocess.run([str(ROOT / "scripts/fpe-trap")], capture_output=True, text=True,
                       timeout=1200)
    out = r.stdout + r.stderr
    assert r.returncode == 0, out[-4000:]
    assert "100% tests passed" in out and "fpe_traps_are_on" in out and "fpe_trap_check" in out
    assert "Numerical" not in out, out[-4000:]
