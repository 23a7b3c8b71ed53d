"""The generated docs cannot drift (scripts/regenerate_docs makes them): each is checked
against a fresh regeneration of a stated sample or of its deterministic part, so that CI
stays short (the whole catalogue and the case studies take minutes).

* docs/coverage.md: its counts agree with its own matrix, the README's count block is made
  from them, and the cells of a stated sample (one scene each, every kind of oracle) are
  what `martello check` prints for them now;
* docs/p8-case-study.md, docs/p10-case-study.md: their scripts' --check (the scenes current
  with the parameters, this martello version, a stated sample of runs to the report's
  digits).

Kind of evidence: consistency of the docs with the code (regression of generated text), not
verification."""

import importlib.util
import io
import sys
import tomllib
from pathlib import Path

import pytest

from martello.report import check_catalogue, coverage_counts, readme_counts
from martello.scene import catalogue

ROOT = Path(__file__).resolve().parent.parent
COVERAGE = ROOT / "docs" / "coverage.md"
# A stated sample of single-scene cells (asserted below), one per kind of oracle and family of
# integrator: closed forms on a fixed step and an adaptive one, the independent engine on an
# ODE integrator; seconds to run.
SAMPLE = ["benchmarks/p6/integrators/p6_rho00_hht.toml", "benchmarks/p6/integrators/p6_rho005_hht.toml",
          "benchmarks/p10/integrators/p10_linear_cvode.toml", "benchmarks/sdof/sdof_sine_arkode.toml",
          "benchmarks/p2/laws/p2_hertz_cvode.toml"]


def test_the_coverage_counts_are_its_matrix():
    text = COVERAGE.read_text()
    c = coverage_counts(text)
    states = [l.rsplit("|", 2)[-2].strip() for l in text.splitlines()
              if l.startswith("| ") and l.rstrip().endswith(("| verified |", "| partly verified |",
                                                             "| not verified |", "| WRONG |"))]
    assert len(states) == c["cells"]
    assert states.count("verified") == c["cells_verified"]
    assert states.count("partly verified") == c["cells_partly"]
    assert states.count("WRONG") == c["cells_wrong"] == 0
    assert f"{c['cells_verified']} cells verified" in text


def test_the_readme_counts_are_the_coverage_counts():
    readme = (ROOT / "README.md").read_text()
    assert readme_counts(coverage_counts(COVERAGE.read_text())) in readme, \
        "README.md: its count block is not docs/coverage.md's: run scripts/regenerate_docs coverage"


def _cell_of(path):
    """(problem, laws, integrator) of a scene file from its tables, as the report keys cells."""
    d = tomllib.loads(path.read_text())
    contacts = list(d.get("contact", [])) + [ch["contact"] for ch in d.get("chain", []) if "contact" in ch]
    laws = ",".join(sorted({c["scheme"] if c["scheme"] != "penalty" else c.get("law", "linear")
                            for c in contacts})) or "-"
    an = d.get("analysis", {})
    return d.get("problem", ""), laws, an.get("integrator") or "static"


def test_a_sample_of_cells_is_current(tmp_path):
    cells = {}
    for f in catalogue.scene_files():
        cells.setdefault(_cell_of(f), []).append(f.relative_to(ROOT).as_posix())
    sample = [ROOT / s for s in SAMPLE]
    for s in SAMPLE:                     # each sampled cell is the sample's scenes alone
        assert set(cells[_cell_of(ROOT / s)]) <= set(SAMPLE), cells[_cell_of(ROOT / s)]
    out = tmp_path / "check"
    assert check_catalogue(sample, out, plots=False, stream=io.StringIO())
    fresh = [l for l in (out / "coverage.md").read_text().splitlines() if l.startswith("| P") or l.startswith("| SDOF")]
    committed = set(COVERAGE.read_text().splitlines())
    stale = [l for l in fresh if l not in committed]
    assert len(fresh) == 4 and not stale, \
        f"docs/coverage.md is stale (run scripts/regenerate_docs coverage): {stale}"


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
