"""The generated docs cannot drift (scripts/regenerate_docs makes them): each is checked
against a fresh regeneration of a stated sample or of its deterministic part, so that CI
stays short (the whole catalogue and the case studies take minutes).

* docs/p8-case-study.md, docs/p10-case-study.md: their scripts' --check (the scenes current
  with the parameters, this martello version, a stated sample of runs to the report's
  digits).

Kind of evidence: consistency of the docs with the code (regression of generated text), not
verification."""

import importlib.util
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
