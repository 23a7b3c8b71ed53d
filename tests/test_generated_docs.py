"""The generated docs cannot drift (scripts/regenerate_docs makes them): each is checked
against a fresh regeneration of a stated sample or of its deterministic part, so that CI
stays short (the whole catalogue and the case studies take minutes).

* docs/coverage.md (`martello check`'s coverage.md): its counts agree with its own matrix,
  it covers the catalogue's scenes as they are (their number), the README's count block is
  made from its counts, and the cells of a stated sample (one scene each, every kind of
  oracle) are what `martello check` prints for them now; the whole page against a fresh
  catalogue run: tests/test_cli.py (test_check_passes_on_catalogue_and_writes_report, which
  runs the catalogue anyway);
* docs/p8-case-study.md, docs/p10-case-study.md: their scripts' --check (the scenes current
  with the parameters, this martello version, a stated sample of runs to the report's
  digits).
* docs/performance.md's measured tables (and docs/event-driven.md's accuracy table): rendered
  again from the runs' results kept in docs/perf/ (a timing cannot be repeated to the bit; its
  record and the page can be held to each other).

A failure names what to run: `flock /work/coord/heavy.lock nice -n 5 scripts/regenerate_docs
coverage` (the whole catalogue: ~5 min alone, ~12 at a load of 10), then commit
docs/coverage.md and README.md.

Kind of evidence: consistency of the docs with the code (regression of generated text), not
verification."""

import importlib.util
import io
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

from martello.report import cell_integrator, check_catalogue, coverage_counts, readme_counts
from martello.scene import catalogue

ROOT = Path(__file__).resolve().parent.parent
COVERAGE = ROOT / "docs" / "coverage.md"
REGENERATE = "run scripts/regenerate_docs coverage (under the heavy lock) and commit docs/coverage.md README.md"
# A stated sample of single-scene cells (asserted below), one per kind of oracle and family of
# integrator: closed forms on a fixed step and an adaptive one, the independent engine on an
# ODE integrator; seconds to run.
SAMPLE = ["benchmarks/p6/integrators/p6_rho00_hht.toml", "benchmarks/p6/integrators/p6_rho005_hht.toml",
          "benchmarks/p10/integrators/p10_linear_cvode.toml", "benchmarks/sdof/sdof_sine_arkode.toml",
          "benchmarks/p2/laws/p2_hertz_cvode.toml"]
STATES = ("verified", "partly verified", "not verified", "WRONG")


def _cell_lines(text):
    """The matrix's rows of a coverage page."""
    return [l for l in text.splitlines()
            if l.startswith("| ") and l.rstrip().endswith(tuple(f"| {s} |" for s in STATES))]


def test_the_coverage_counts_are_its_matrix():
    text = COVERAGE.read_text()
    c = coverage_counts(text)
    states = [l.rsplit("|", 2)[-2].strip() for l in _cell_lines(text)]
    assert len(states) == c["cells"]
    assert states.count("verified") == c["cells_verified"]
    assert states.count("partly verified") == c["cells_partly"]
    assert states.count("not verified") == c["cells_not_verified"]
    assert states.count("WRONG") == c["cells_wrong"] == 0
    # the rows by kind: the matrix's column "verification / loose / unconverged / repeat / regression"
    per_kind = [sum(int(l.split("|")[-3].split("/")[i]) for l in _cell_lines(text)) for i in range(5)]
    assert per_kind == [c["verification"], c["loose"], c["unconverged"], c["repeat"], c["regression"]]
    assert c["verification_passed"] == c["verification"] == (c["verification_closed_form"] + c["verification_published"]
                                                             + c["verification_independent"])
    assert f"{c['cells_verified']} cells verified" in text
    assert f"{c['verification']} of {c['verification']} distinct rows passed" in text


def test_the_coverage_covers_the_catalogue_as_it_is():
    c = coverage_counts(COVERAGE.read_text())
    n = len(catalogue.scene_files())
    assert c["scenes"] == n, f"docs/coverage.md was made from {c['scenes']} scenes, the catalogue has {n}: {REGENERATE}"


def test_the_readme_counts_are_the_coverage_counts():
    readme = (ROOT / "README.md").read_text()
    assert readme_counts(coverage_counts(COVERAGE.read_text())) in readme, \
        f"README.md: its count block is not docs/coverage.md's: {REGENERATE}"


def _cell_of(path):
    """(problem, laws, integrator) of a scene file from its tables, as the report keys cells."""
    d = tomllib.loads(path.read_text())
    contacts = list(d.get("contact", [])) + [ch["contact"] for ch in d.get("chain", []) if "contact" in ch]
    laws = ",".join(sorted({c["scheme"] if c["scheme"] != "penalty" else c.get("law", "linear")
                            for c in contacts})) or "-"
    return d.get("problem", ""), laws, cell_integrator(d.get("analysis", {}))


def test_a_sample_of_cells_is_current(tmp_path):
    cells = {}
    for f in catalogue.scene_files():
        cells.setdefault(_cell_of(f), []).append(f.relative_to(ROOT).as_posix())
    for s in SAMPLE:                     # each sampled cell is the sample's scenes alone
        others = set(cells[_cell_of(ROOT / s)]) - set(SAMPLE)
        assert not others, f"the sampled cell of {s} now holds {sorted(others)}: add them to SAMPLE or sample another cell"
    out = tmp_path / "check"
    assert check_catalogue([ROOT / s for s in SAMPLE], out, plots=False, stream=io.StringIO())
    fresh = _cell_lines((out / "coverage.md").read_text())
    committed = set(COVERAGE.read_text().splitlines())
    stale = [l for l in fresh if l not in committed]
    assert len(fresh) == 4 and not stale, f"docs/coverage.md is stale: {REGENERATE}: {stale}"


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


@pytest.mark.parametrize("script", ["perf/fused_vs_lean.py", "perf/chain_vs_opensees.py",
                                    "perf/integrators_at_size.py", "events/accuracy.py"])
def test_the_measured_tables_are_their_records(script):
    """docs/performance.md's measured tables (docs/event-driven.md's accuracy table) are what
    their scripts render from the runs' results kept in docs/perf/*.json (benchmarks/perf/measured_docs.py): no figure of them
    edited by hand or left behind by a new measurement."""
    r = subprocess.run([sys.executable, str(ROOT / "benchmarks" / script), "--check"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
