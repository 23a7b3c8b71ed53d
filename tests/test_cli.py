"""The command line: run, list, check, help, and non-zero exit codes on every error."""

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
P1 = ROOT / "benchmarks" / "p1" / "p1_static_lagrange.toml"


def martello(*args, cwd=ROOT):
    return subprocess.run([sys.executable, "-m", "martello", *map(str, args)], cwd=cwd,
                          capture_output=True, text=True, timeout=300)


def test_help_teaches():
    r = martello("--help")
    assert r.returncode == 0
    for word in ("run", "list", "check", "scene", "examples"):
        assert word in r.stdout


def test_no_command_is_an_error():
    assert martello().returncode != 0


def test_run_writes_summary(tmp_path):
    r = martello("run", P1, "-o", tmp_path)
    assert r.returncode == 0, r.stderr
    s = json.loads((tmp_path / "summary.json").read_text())
    assert s["nodes"]["mass"]["u"] == 0.05
    assert s["provenance"]["scene_sha256"] and "lapack" in s["provenance"]["libraries"]
    assert s["cost"]["linear_solves"] >= 1


def test_run_bad_scene_fails_with_message(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text(P1.read_text().replace("mass = 1.0 ", "mass = -1.0 "))
    r = martello("run", bad, "-o", tmp_path / "out")
    assert r.returncode == 1
    assert "bad.toml: node[0].mass" in r.stderr and "Traceback" not in r.stderr
    assert not (tmp_path / "out" / "summary.json").exists()


def test_run_missing_file_fails():
    r = martello("run", "nope.toml")
    assert r.returncode == 1 and "does not exist" in r.stderr


def test_list_shows_one_line_per_scene():
    r = martello("list")
    assert r.returncode == 0
    lines = [l for l in r.stdout.splitlines() if l.strip()]
    from martello.scene import catalogue
    assert len(lines) == len(catalogue.scene_files()) >= 30
    assert any("P1" in l and "lagrange" in l for l in lines)


def test_check_passes_on_catalogue_and_writes_report(tmp_path):
    r = martello("check", "-o", tmp_path)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "FAIL" not in r.stdout
    assert (tmp_path / "report.md").exists() and (tmp_path / "verification.csv").exists()
    assert (tmp_path / "digits.png").stat().st_size > 1000


def test_check_fails_on_a_wrong_reference(tmp_path):
    wrong = tmp_path / "wrong.toml"
    wrong.write_text(P1.read_text().replace("h = 0.05, g = 9.81", "h = 0.05, g = 9.80"))
    r = martello("check", wrong, "-o", tmp_path / "report", "--no-plots")
    assert r.returncode == 1
    assert "FAIL" in r.stdout
