"""The library under AddressSanitizer + UndefinedBehaviorSanitizer (scripts/sanitize): a
separate instrumented build whose ctest examples and the whole catalogue (every scheme and
integrator, through the Python front end) must run without a single report. A memory error
or undefined behaviour aborts the process (abort_on_error, halt_on_error), so the exit code
and the closing lines say whether the run was clean."""

import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent


def test_catalogue_clean_under_asan_and_ubsan():
    r = subprocess.run([str(ROOT / "scripts/sanitize")], capture_output=True, text=True,
                       timeout=1800)
    out = r.stdout + r.stderr
    assert r.returncode == 0, out[-4000:]
    assert "ERROR: AddressSanitizer" not in out and "runtime error:" not in out, out[-4000:]
    assert "0 tests failed" in out, out[-2000:]
    assert " 0 failure(s)" in out, out[-2000:]
