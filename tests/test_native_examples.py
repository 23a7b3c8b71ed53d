"""Drive ctest from pytest, so one command runs the C and Fortran self-checking examples
(P1 through the C API, P3 through the Fortran modules, the constitutive-law checks)."""

import shutil
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def test_ctest_examples_pass():
    build = ROOT / "build"
    assert (build / "CTestTestfile.cmake").exists(), "build first: ./scripts/build"
    ctest = shutil.which("ctest")
    assert ctest, "ctest (CMake) not on PATH"
    r = subprocess.run([ctest, "--test-dir", str(build), "--output-on-failure"],
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "tests passed" in r.stdout and "0 tests failed" in r.stdout, r.stdout
