"""The generated docs cannot drift (scripts/regenerate_docs makes them): each is checked
against a fresh regeneration of a stated sample or of its deterministic part, so that CI
stays short (the whole catalogue and the case studies take minutes).

* docs/p8-case-study.md, docs/p10-case-study.md: their scripts' --check (the scenes current
  with the parameters, this martello version, a stated sample of runs to the report's
  digits).
* docs/performance.md's measured tables: rendered again from the runs' results kept in
  docs/perf/ (a timing cannot be repeated to the bit; its record and the page can be held to
  each other).

Kind of evidence: consistency of the docs with the code (regression of generated text), not
verification."""

import importlib.util
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def _script(path):
    spec = importlib.util.spec_from_file_location(path.stem + "_under_test", path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod
    spec.loader.exec_module(mod)
    return mod


@pytest.mark.parametrize("problem", ["p8", "p10"])
def test_the_case_study_is_current(problem, capsys):
    mod = _script(ROOT / "benchmarks" / problem / "case_study.py")
    rc = mod.main(["--check"])
    assert rc == 0, capsys.readouterr().out


@pytest.mark.parametrize("script", ["fused_vs_lean.py", "chain_vs_opensees.py"])
def test_the_measured_tables_are_their_records(script):
    """docs/performance.md's measured tables are what their scripts render from the runs'
    results kept in docs/perf/*.json (benchmarks/perf/measured_docs.py): no figure of them
    edited by hand or left behind by a new measurement."""
    r = subprocess.run([sys.executable, str(ROOT / "benchmarks" / "perf" / script), "--check"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
