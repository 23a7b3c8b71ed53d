"""`martello plot` (docs/plot.md): the pictures of a run folder and of a study folder are
written as PNG and SVG, with their axes labelled in SI units, and are not blank; a folder
that is neither is one clear error."""

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from martello.cli import main
from tests.test_study_dask import STUDY

ROOT = Path(__file__).resolve().parent.parent
P7 = ROOT / "benchmarks" / "p7"


@pytest.fixture(scope="module")
def p7_run(tmp_path_factory):
    out = tmp_path_factory.mktemp("p7run")
    assert main(["run", str(P7 / "p7_two_oscillators.toml"), "-o", str(out)]) == 0
    return out


@pytest.fixture(scope="module")
def chain_run(tmp_path_factory):
    # P7's chain of ten with the histories of two bilinear springs and a dashpot written
    # ([analysis.output] links, docs/results.md#historycsv): hysteresis loops to draw
    base = tmp_path_factory.mktemp("chain")
    text = (P7 / "p7_chain_10.toml").read_text().replace(
        "every = 50", 'every = 10\nlinks = ["b1.spring", "b2.spring", "b1.damper"]')
    scene = base / "chain.toml"
    scene.write_text(text)
    assert main(["run", str(scene), "-o", str(base / "run")]) == 0
    return base / "run"


def ink(png):
    """Fraction of pixels that are not the white background, and the number of pixels of
    matplotlib's first line colour (C0 = #1f77b4, within a small distance)."""
    a = np.asarray(Image.open(png).convert("RGB"), float)
    not_white = np.mean(np.any(a < 245, axis=2))
    c0 = np.sum(np.linalg.norm(a - np.array([31, 119, 180]), axis=2) < 40)
    return not_white, c0


def svg_texts(svg):
    return set(re.findall(r"<text[^>]*>([^<]*)</text>", Path(svg).read_text()))


def test_a_run_gives_every_picture_in_png_and_svg(p7_run, capsys):
    assert main(["plot", str(p7_run)]) == 0
    assert "run, 8 file(s)" in capsys.readouterr().out
    plots = p7_run / "plots"
    for stem in ("histories", "phase", "force_penetration", "energy"):
        png, svg = plots / f"{stem}.png", plots / f"{stem}.svg"
        assert png.exists() and svg.exists(), stem
        with Image.open(png) as im:
            assert im.size[0] >= 600 and im.size[1] >= 400, (stem, im.size)
        # not blank: axes, labels and at least one drawn curve of the first colour
        frac, c0 = ink(png)
        assert 0.01 < frac < 0.6 and c0 > 300, (stem, frac, c0)
    labels = svg_texts(plots / "histories.svg")
    assert {"displacement u [m]", "time t [s]", "s1", "s2", "s1-s2"} <= labels
    assert any(t.startswith("contact force P [N]") for t in labels)
    assert {"u:s1 [m]", "v:s1 [m/s]"} <= svg_texts(plots / "phase.svg")
    assert {"contact force P [N]"} <= svg_texts(plots / "force_penetration.svg")
    assert any("penetration δ of s1-s2 [m]" in t for t in svg_texts(plots / "force_penetration.svg"))
    assert {"energy [J]", "time t [s]"} <= svg_texts(plots / "energy.svg")
    # no link histories were written: no hysteresis picture
    assert not (plots / "hysteresis.png").exists()


def test_the_same_run_gives_the_same_svg(p7_run, tmp_path):
    assert main(["plot", str(p7_run), "-o", str(tmp_path / "a"), "--format", "svg"]) == 0
    assert main(["plot", str(p7_run), "-o", str(tmp_path / "b"), "--format", "svg"]) == 0
    assert sorted(p.name for p in (tmp_path / "a").iterdir()) == sorted(
        p.name for p in (tmp_path / "b").iterdir())
    assert all(not p.name.endswith(".png") for p in (tmp_path / "a").iterdir())
    for p in (tmp_path / "a").iterdir():
        assert p.read_bytes() == (tmp_path / "b" / p.name).read_bytes(), p.name


def test_hysteresis_loops_of_the_links_a_run_wrote(chain_run):
    assert main(["plot", str(chain_run), "--nodes", "b1,b2", "--format", "png,svg"]) == 0
    plots = chain_run / "plots"
    png = plots / "hysteresis.png"
    frac, c0 = ink(png)
    assert c0 > 300, c0
    labels = svg_texts(plots / "hysteresis.svg")
    assert {"b1.spring (bilinear)", "b2.spring (bilinear)", "b1.damper (dashpot)",
            "link force f [N]", "elongation u_a − u_b [m]"} <= labels
    # --nodes chooses the phase portraits, and the title says how many of how many
    assert {"phase portrait of b1", "phase portrait of b2"} <= svg_texts(plots / "phase.svg")
    assert "phase portrait of b3" not in svg_texts(plots / "phase.svg")
    assert any("(2 of 10 nodes" in t for t in svg_texts(plots / "histories.svg"))


def test_a_study_gives_error_against_step_and_work_precision(tmp_path, capsys):
    study = tmp_path / "study.toml"
    study.write_text(STUDY)      # P2, two contact schemes, fixed-step and adaptive methods
    assert main(["study", str(study), "-o", str(tmp_path / "out"), "-j", "1"]) == 0
    capsys.readouterr()
    assert main(["plot", str(tmp_path / "out"), "-o", str(tmp_path / "pics")]) == 0
    assert "study, 4 file(s)" in capsys.readouterr().out
    png = tmp_path / "pics" / "study__linear_penalty_linear.png"
    svg = tmp_path / "pics" / "study__linear_penalty_linear.svg"
    frac, c0 = ink(png)
    assert 0.01 < frac < 0.6 and c0 > 100, (frac, c0)
    labels = svg_texts(svg)
    assert {"time step Δt [s] (fixed-step methods)", "wall time [s]", "residual evaluations [count]",
            "max relative error of u (normwise)", "error against Δt"} <= labels
    # the measured order of the fixed-step method is in the legend (orders.csv)
    assert any(re.fullmatch(r"Newmark average acceleration: p = \d\.\d\d", t) for t in labels)
    assert any(t.startswith("rk8pd: slope vs rtol = ") for t in labels)


@pytest.mark.parametrize("args, message", [
    (["--format", "pdf"], "--format pdf: give png, svg or png,svg"),
    (["--nodes", "s9"], "--nodes: s9 not in the history; it has s1, s2"),
])
def test_bad_options_are_one_line(p7_run, capsys, args, message):
    assert main(["plot", str(p7_run), *args]) == 1
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1


def test_a_folder_that_is_neither_is_refused(tmp_path):
    r = subprocess.run([sys.executable, "-m", "martello", "plot", str(tmp_path)], cwd=ROOT,
                       capture_output=True, text=True, timeout=120)
    assert r.returncode == 1 and "neither a run folder" in r.stderr and "Traceback" not in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1


def test_a_static_run_has_nothing_over_time(tmp_path, capsys):
    assert main(["run", str(ROOT / "benchmarks" / "p1" / "p1_static_penalty.toml"), "-o",
                 str(tmp_path)]) == 0
    assert main(["plot", str(tmp_path)]) == 1
    assert "a static run" in capsys.readouterr().err


@pytest.mark.parametrize("name, damage, message", [
    ("summary.json", lambda t: t[:300], "summary.json: not valid JSON"),
    ("summary.json", lambda t: "[1, 2]", "summary.json: holds a list, not a run's summary"),
    ("history.csv", lambda t: t[:len(t) // 2].rsplit(",", 1)[0], "values for"),
    ("history.csv", lambda t: t.replace("\n0.", "\nx.", 1), "is not a number"),
    ("history.csv", lambda t: "", "history.csv: is empty"),
])
def test_a_run_folder_cut_short_or_edited_is_one_line_and_nothing_drawn(p7_run, tmp_path, capsys,
                                                                        name, damage, message):
    """A run folder whose summary.json or history.csv was cut short or edited: one line
    naming the file (and line), exit 1, no pictures folder (it was a JSONDecodeError or
    numpy's ValueError)."""
    folder = tmp_path / "run"
    folder.mkdir()
    for f in ("summary.json", "history.csv"):
        text = (p7_run / f).read_text()
        (folder / f).write_text(damage(text) if f == name else text)
    assert main(["plot", str(folder), "-o", str(tmp_path / "pics")]) == 1
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1, err
    assert "internal error" not in err and not (tmp_path / "pics").exists()


def test_a_study_folder_cut_short_or_edited_is_one_line(tmp_path, capsys):
    folder = tmp_path / "study"
    folder.mkdir()
    (folder / "runs.csv").write_text("case,method,classification,dt,rtol\na,b,ok,0.1,\nc,d\n")
    assert main(["plot", str(folder), "-o", str(tmp_path / "pics")]) == 1
    assert "runs.csv:3: the row has fewer cells than the header" in capsys.readouterr().err
    (folder / "runs.csv").write_bytes(b"\xff\xfe binary")
    assert main(["plot", str(folder)]) == 1
    assert "runs.csv: byte 1 is not UTF-8 text" in capsys.readouterr().err
    assert not (tmp_path / "pics").exists() and not (folder / "plots").exists()
