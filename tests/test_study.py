"""`martello study`: the study file, the sweep, parallel runs, the tidy CSV (failed runs are
rows, never dropped), the measured orders and the plots. Tiny sweeps only: the committed
studies (benchmarks/studies/) are run by the CLI, not here."""

import csv
import io
import math
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from martello.errors import MartelloError
from martello.study.outcome import status_class
from martello.study.output import Progress, md_cell
from martello.study.study_file import _sweep, load_study
from martello.study.sweep import fit_order, snap_step

ROOT = Path(__file__).resolve().parent.parent
P2 = ROOT / "benchmarks" / "p2"

TINY = f"""
title = "tiny P2 study"
[compare]
histories = ["u:mass"]
points = 701
plot_metrics = ["max_rel_error", "impact_time_error"]

[[scene]]
file = "{P2 / 'p2_penalty_linear.toml'}"
label = "linear"
reference = {{ closed_form = "bouncing_oscillator_kelvin", params = {{ m = 1.0, k = 100.0, h = 0.05, g = 9.81, eps = 1.0e6 }} }}
[[scene.scheme]]
label = "penalty linear"
[[scene.scheme]]
label = "restitution e=0.8"
contact = {{ scheme = "restitution", restitution = 0.8 }}
reference = {{ closed_form = "bouncing_oscillator_restitution", params = {{ m = 1.0, k = 100.0, h = 0.05, g = 9.81, e = 0.8 }} }}

[[integrator]]
name = "newmark"
label = "Newmark average acceleration"
params = {{ preset = "average-acceleration" }}
dt = [2e-4, 1e-4, 5e-5]
order = 2

[[integrator]]
name = "central-difference"
dt = [5e-3, 1e-4]
"""


def write(tmp_path, text, name="study.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


def martello(*args):
    return subprocess.run([sys.executable, "-m", "martello", *map(str, args)], cwd=ROOT,
                          capture_output=True, text=True, timeout=300)


def table_cells(line):
    """The cells of a Markdown table row: split at every | that is not escaped as \\|."""
    return [c.strip() for c in re.split(r"(?<!\\)\|", line.strip())[1:-1]]


def test_md_cell_keeps_a_table_row_one_row():
    row = f"| {md_cell('a | b')} | {md_cell('two' + chr(10) + 'lines')} |"
    assert table_cells(row) == [r"a \| b", "two lines"]


def test_tiny_study_end_to_end(tmp_path):
    # an earlier study's folder: replaced whole, its stale file gone (docs/studies.md)
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "runs.csv").write_text("old\n")
    (tmp_path / "out" / "stale.png").write_text("old\n")
    r = martello("study", write(tmp_path, TINY), "-o", tmp_path / "out", "-j", "2")
    assert r.returncode == 0, r.stderr
    assert not (tmp_path / "out" / "stale.png").exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out", "study.toml"]  # no temporaries
    rows = list(csv.DictReader(open(tmp_path / "out" / "runs.csv")))
    # one row per run, failed or not: 2 schemes x (3 + 2) steps
    assert len(rows) == 10
    by = {(x["scheme"], x["integrator"], float(x["dt"])): x for x in rows}
    # Δt = 5e-3 exceeds 2/ω_max = 2e-3: central difference refuses it, and the row says so
    cd = by[("penalty linear", "central-difference", 5e-3)]
    assert cd["classification"].startswith("unstable") and "dt_crit" in cd["message"]
    # restitution contacts cannot run on Newmark: an incompatible row naming what would work
    inc = by[("restitution e=0.8", "newmark", 1e-4)]
    assert inc["classification"] == "incompatible" and "moreau-jean" in inc["message"]
    ok = [x for x in rows if x["classification"] == "ok"]
    assert len(ok) >= 4
    for x in ok:
        for key in ("max_rel_error", "scd", "impact_time_error", "impact_count_error", "steps",
                    "residual_evaluations", "wall_time_s", "energy_balance_error", "reference"):
            assert x[key] != "", key
    # Newmark is second order on the linear penalty bounce: each halving of Δt gains ~4x
    nm = sorted((float(x["dt"]), float(x["max_rel_error"])) for x in ok
                if x["integrator"] == "newmark" and x["scheme"] == "penalty linear")
    assert nm[0][1] < nm[-1][1] / 4
    orders = list(csv.DictReader(open(tmp_path / "out" / "orders.csv")))
    assert any(o["method"] == "Newmark average acceleration" and o["metric"] == "max_rel_error"
               for o in orders)
    pngs = list((tmp_path / "out").glob("*.png"))
    assert len(pngs) == 2 and all(p.stat().st_size > 10000 for p in pngs)
    md = (tmp_path / "out" / "study.md").read_text()
    assert "measured order" in md
    # the case labels are "linear | penalty linear": each table row keeps the header's cells
    table = [ln for ln in md.splitlines() if ln.startswith("|")]
    assert len(table) >= 4 and all(len(table_cells(ln)) == 9 for ln in table), table
    assert any(table_cells(ln)[0] == r"linear \| penalty linear" for ln in table)
    assert "/10 runs" in r.stderr            # the progress bar
    assert "p = " in r.stdout


def test_study_output_folder_of_something_else_is_refused_before_any_run(tmp_path):
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "notes.txt").write_text("mine\n")
    r = martello("study", write(tmp_path, TINY), "-o", tmp_path / "out")
    assert r.returncode == 1 and len(r.stderr.strip().splitlines()) == 1
    assert "holds files of something else (notes.txt)" in r.stderr and "runs" not in r.stdout
    assert [p.name for p in (tmp_path / "out").iterdir()] == ["notes.txt"]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out", "study.toml"]


@pytest.mark.parametrize("text,match", [
    ("title = 'x'\n[[integrator]]\nname = 'newmark'\ndt = [1e-3]\n", "scene: missing"),
    (TINY.replace('name = "central-difference"', 'name = "leapfrog"'), "unknown integrator 'leapfrog'"),
    (TINY.replace("dt = [5e-3, 1e-4]", "dt = []"), "non-empty list"),
    (TINY.replace("[compare]", "[compare]\nfoo = 1"), "compare.foo: unknown key"),
    (TINY.replace("p2_penalty_linear.toml", "nope.toml"), "does not exist"),
    (TINY.replace("dt = [5e-3, 1e-4]", "dt = [1e-4]\nrtol = [1e-6]"), "applies to adaptive"),
])
def test_study_file_errors_name_the_field(tmp_path, text, match):
    with pytest.raises(MartelloError, match=match):
        load_study(write(tmp_path, text))


def test_scheme_override_replaces_the_laws_keys(tmp_path):
    s = load_study(write(tmp_path, TINY))
    assert [c.scheme_label for c in s.cases] == ["penalty linear", "restitution e=0.8"]
    c = s.cases[1].scene_dict["contact"][0]
    assert c["scheme"] == "restitution" and "stiffness" not in c and "law" not in c
    assert s.cases[1].reference["closed_form"] == "bouncing_oscillator_restitution"
    # geometric sweeps: from, to, per_decade
    assert _sweep("f", "dt", {"from": 1e-2, "to": 1e-4, "per_decade": 2}) == \
        pytest.approx([1e-2, 10 ** -2.5, 1e-3, 10 ** -3.5, 1e-4])


def test_steps_are_snapped_to_the_comparison_times():
    assert snap_step(3e-5, 1e-4) == (1e-4 / 3, 3)
    assert snap_step(2.6e-4, 1e-4) == (pytest.approx(3e-4, rel=1e-15), 1)
    assert snap_step(1e-6, 5e-4, adaptive=True) == (5e-4, 1)


def test_status_classes():
    assert status_class("MARTELLO_OK") == "ok"
    assert status_class("MARTELLO_ERR_DIVERGED", "diverged at t = 1: non-finite state") == "diverged: NaN"
    assert status_class("MARTELLO_ERR_DIVERGED", "mechanical energy exceeds") == "diverged: energy growth"
    assert status_class("MARTELLO_ERR_NOT_CONVERGED") == "failed: no Newton convergence"
    assert status_class("MARTELLO_ERR_STEP_UNDERFLOW") == "failed: step-size underflow"
    assert status_class("MARTELLO_ERR_UNSUPPORTED") == "unsupported"


def test_fit_order_uses_the_asymptotic_range_only():
    h = np.array([1e-1, 5e-2, 2.5e-2, 1.25e-2, 6.25e-3])
    err = 3.0 * h**2
    err[0] = 0.9                         # pre-asymptotic: excluded by hi = 0.5
    p, n = fit_order(h, err, 0.0, 0.5)
    assert p == pytest.approx(2.0, abs=1e-12) and n == 4
    assert math.isnan(fit_order(h[:2], err[:2])[0])


def test_progress_bar_plain_text():
    buf = io.StringIO()
    p = Progress(20, stream=buf)
    for i in range(20):
        p.update(ok=i != 3)
    lines = buf.getvalue().splitlines()
    assert 5 <= len(lines) <= 11 and "20/20 runs" in lines[-1] and "1 not ok" in lines[-1]
    assert "not run" not in lines[-1]


def test_progress_counts_combinations_that_do_not_apply_apart_from_failures():
    buf = io.StringIO()
    p = Progress(10, stream=buf)
    for i in range(10):
        p.update(ok=i != 9, not_run=i < 3)
    assert "10/10 runs" in buf.getvalue() and "1 not ok, 3 not run" in buf.getvalue()


DATA_STUDY = """
title = "own reference data"
[[scene]]
file = "{scene}"
reference = {reference}
t_end = 0.5
[[integrator]]
name = "newmark"
dt = [1e-3]
"""


def _copy_reference(src, dest, **meta):
    import json
    import shutil
    shutil.copytree(src, dest)
    m = json.loads((dest / "reference.json").read_text())
    m.update(meta)
    (dest / "reference.json").write_text(json.dumps(m))


def test_a_reference_folder_is_found_beside_the_study_file(tmp_path, capsys):
    """`reference = { data = DIR }` relative to the study file's folder (it was resolved in
    the repository, or site-packages once installed)."""
    from martello.cli import main
    _copy_reference(ROOT / "reference" / "p7_two_oscillators", tmp_path / "mine")
    study = write(tmp_path, DATA_STUDY.format(scene=ROOT / "benchmarks" / "p7" / "p7_two_oscillators.toml",
                                              reference='{ data = "mine" }'))
    assert main(["study", str(study), "-o", str(tmp_path / "out"), "-j", "1", "--no-plots"]) == 0
    row = next(csv.DictReader(open(tmp_path / "out" / "runs.csv")))
    assert row["reference"] == "reference/mine" and float(row["max_rel_error"]) < 1e-2


def test_a_study_uses_the_reference_martello_reference_cached(tmp_path, monkeypatch, capsys):
    """A scene with no closed form and no stored data: the study scores it against the
    reference `martello reference` cached for its physics (it reported "no reference")."""
    from martello import load
    from martello.cli import main
    from martello.reference import cache
    from martello.reference.store import physics_digest
    scene = tmp_path / "heavier.toml"
    scene.write_text((ROOT / "benchmarks" / "p7" / "p7_two_oscillators.toml").read_text()
                     .replace("mass = 1.0", "mass = 1.25", 1))
    monkeypatch.setenv(cache.ENV_CACHE, str(tmp_path / "cache"))
    s = load(scene)
    assert s.nodes[0]["mass"] == 1.25
    # a stand-in for what `martello reference heavier.toml` writes (its numbers are not
    # checked here: the test is which reference the study takes)
    _copy_reference(ROOT / "reference" / "p7_two_oscillators",
                    tmp_path / "cache" / "references" / cache.cache_key(s),
                    physics_sha256=physics_digest(s), format=cache.FORMAT)
    study = write(tmp_path, DATA_STUDY.format(scene=scene, reference='"auto"'))
    assert main(["study", str(study), "-o", str(tmp_path / "out"), "-j", "1", "--no-plots"]) == 0
    err = capsys.readouterr().err
    row = next(csv.DictReader(open(tmp_path / "out" / "runs.csv")))
    assert row["reference"].startswith("computed reference " + cache.cache_key(s)), row["reference"]
    assert "cached by martello reference" in err and row["max_rel_error"]
