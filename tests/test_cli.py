"""The command line: run, list, check, help, and non-zero exit codes on every error."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
P1 = ROOT / "benchmarks" / "p1" / "p1_static_lagrange.toml"


def martello(*args, cwd=ROOT, timeout=300):
    return subprocess.run([sys.executable, "-m", "martello", *map(str, args)], cwd=cwd,
                          capture_output=True, text=True, timeout=timeout)


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
    # the whole catalogue (~400 scenes, ~4 min alone on 2 cores; 11 min at a load of 10)
    r = martello("check", "-o", tmp_path, timeout=1800)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "FAIL" not in r.stdout
    assert (tmp_path / "report.md").exists() and (tmp_path / "verification.csv").exists()
    assert (tmp_path / "digits.png").stat().st_size > 1000
    # one set of counts: stdout's headline is report.md's, coverage.md's counts are the
    # headline's, and the committed docs/coverage.md (hence the README's block,
    # tests/test_generated_docs.py) is this run's, cell by cell
    head = next(l for l in r.stdout.splitlines() if l.startswith("verification: ")).split(" Report: ")[0]
    assert f"**{head}**" in (tmp_path / "report.md").read_text()
    fresh = (tmp_path / "coverage.md").read_text()
    assert "**" + head.rsplit(";", 1)[0] + ".**" in fresh
    _assert_coverage_current(fresh, (ROOT / "docs" / "coverage.md").read_text())


def _coverage_cells(text):
    """{(problem, law, integrator): (evidence, digits, tolerance, rows by kind, state)} of a
    coverage page's matrix."""
    out = {}
    for line in text.splitlines():
        f = [x.strip() for x in line.split("|")[1:-1]]
        if len(f) == 8 and f[7] in ("verified", "partly verified", "not verified", "WRONG"):
            num = lambda x: None if x in ("—", "exact") else float(x)
            out[tuple(f[:3])] = (f[3], num(f[4]), num(f[5]), f[6], f[7])
    return out


def _assert_coverage_current(fresh, committed):
    """The committed page against a fresh one: the same counts, cells, evidence, rows by kind
    and states; digits to their printed 0.1, tolerances (printed to one digit) within 20 %."""
    from martello.report import coverage_counts
    again = "docs/coverage.md is stale: run scripts/regenerate_docs coverage (under the heavy lock) " \
            "and commit docs/coverage.md README.md"
    assert coverage_counts(committed) == coverage_counts(fresh), again
    a, b = _coverage_cells(committed), _coverage_cells(fresh)
    assert a.keys() == b.keys(), (again, sorted(set(a) ^ set(b)))
    for key in a:
        (ev, d, tol, k, s), (ev2, d2, tol2, k2, s2) = a[key], b[key]
        assert (ev, k, s) == (ev2, k2, s2), (again, key, a[key], b[key])
        assert (d is None) == (d2 is None) and (d is None or abs(d - d2) <= 0.11), (again, key, d, d2)
        assert (tol is None) == (tol2 is None) and (tol is None or abs(tol - tol2) <= 0.2 * tol), \
            (again, key, tol, tol2)


def test_check_fails_on_a_wrong_reference(tmp_path):
    wrong = tmp_path / "wrong.toml"
    wrong.write_text(P1.read_text().replace("h = 0.05, g = 9.81", "h = 0.05, g = 9.80"))
    r = martello("check", wrong, "-o", tmp_path / "report", "--no-plots")
    assert r.returncode == 1
    assert "FAIL" in r.stdout


@pytest.mark.parametrize("unbuffered", ["1", None])
def test_list_into_a_closed_pipe_stops_quietly(unbuffered):
    # `martello list | head`: the reader is gone before the first line; with stdout
    # unbuffered the first print fails, buffered the flush does: neither is a traceback
    read, write = os.pipe()
    os.close(read)
    env = {k: v for k, v in os.environ.items() if k != "PYTHONUNBUFFERED"}
    if unbuffered:
        env["PYTHONUNBUFFERED"] = unbuffered
    try:
        r = subprocess.run([sys.executable, "-m", "martello", "list"], stdout=write,
                           stderr=subprocess.PIPE, text=True, cwd=ROOT, env=env, timeout=120)
    finally:
        os.close(write)
    assert r.stderr == ""
    assert r.returncode == 141                # 128 + SIGPIPE, as a tool killed by it


def test_run_and_check_take_the_paths_list_prints_from_any_folder(tmp_path):
    r = martello("run", "benchmarks/p1/p1_static_lagrange.toml", "-o", tmp_path / "p1", cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert json.loads((tmp_path / "p1" / "summary.json").read_text())["status"] == "MARTELLO_OK"
    r = martello("check", "p1/p1_static_lagrange.toml", "-o", tmp_path / "c", "--no-plots", cwd=tmp_path)
    assert r.returncode == 0 and "0 failure(s)" in r.stdout, r.stdout
    r = martello("run", "p1/nope.toml", cwd=tmp_path)
    assert r.returncode == 1 and "p1/nope.toml: (file): does not exist" in r.stderr


def test_check_a_scene_with_nothing_to_verify_fails(tmp_path):
    bare = tmp_path / "bare.toml"
    bare.write_text(P1.read_text().split("[check]")[0])
    r = martello("check", bare, "-o", tmp_path / "report", "--no-plots")
    assert r.returncode == 1
    assert "ran, not verified" in r.stdout
    assert f"FAILED {bare}: nothing to verify: no [check] table" in r.stdout


def test_check_fails_when_listed_reference_data_are_missing(tmp_path, monkeypatch):
    # an installation without its reference data must not pass as verified
    import io
    import shutil
    from martello import report
    from martello.reference import store
    shutil.copytree(ROOT / "reference", tmp_path / "reference")
    (tmp_path / "reference" / "p7_two_oscillators" / "reference.json").unlink()
    real = store.manifest
    for module in (store, report):
        monkeypatch.setattr(module, "manifest", lambda root=None: real(tmp_path / "reference"))
    out = io.StringIO()
    p7 = ROOT / "benchmarks" / "p7" / "p7_two_oscillators.toml"
    assert report.check_catalogue([p7], tmp_path / "out", plots=False, stream=out) is False
    assert "p7_two_oscillators are missing (reinstall martello" in out.getvalue()
    # with the data there, the same call verifies the scene
    for module in (store, report):
        monkeypatch.setattr(module, "manifest", real)
    assert report.check_catalogue([p7], tmp_path / "out2", plots=False, stream=io.StringIO())


@pytest.mark.parametrize("lib, why", [("/nonexistent/libmartello.so", "native library not found"),
                                      (str(P1), "cannot load the native library")])
def test_help_needs_no_library_and_a_command_says_why_in_one_line(lib, why):
    """The native library is loaded when a command first needs it: --help and usage errors
    work without one; a command that needs it says, in one line, what is wrong with it."""
    env = dict(os.environ, MARTELLO_LIB=lib)
    run = lambda *a: subprocess.run([sys.executable, "-m", "martello", *a], cwd=ROOT, env=env,
                                    capture_output=True, text=True, timeout=120)
    r = run("--help")
    assert r.returncode == 0 and "examples" in r.stdout, r.stderr
    r = run("run", "--help")
    assert r.returncode == 0 and "--force" in r.stdout
    for args in (("list",), ("run", str(P1), "-o", "/nonexistent/x"), ("version",)):
        r = run(*args)
        assert r.returncode == 1 and r.stderr.count("\n") == 1, r.stderr
        assert r.stderr.startswith("martello: error: ") and why in r.stderr and lib in r.stderr


def test_an_empty_output_path_is_refused_not_taken_for_the_default(tmp_path):
    r = martello("run", P1, "-o", "", cwd=tmp_path)
    assert r.returncode == 1 and r.stderr.count("\n") == 1
    assert "-o/--output: is empty" in r.stderr
    assert not any(tmp_path.iterdir())


# The seam of the Ctrl-C test: a sitecustomize that the child `python -m martello` loads first
# sends SIGINT to its own process at the AT-th audit event (sys.addaudithook: imports, file
# opens, compiles, the library's dlopen, ...) counted from the moment martello's SIGINT handler
# is in place; before it, the interpreter and runpy end on SIGINT as Python does. HOW=direct
# sends it from the hook; HOW=string from code the hook runs from a string, as a signal taken
# while namedtuple or dataclasses run the methods they build from strings (docs/behaviour.md,
# "A Ctrl-C at any moment"). AT=0 counts the events up to summary.json's opening into COUNT.
SIGINT_SEAM = """
import os, signal
if signal.getsignal(signal.SIGINT) is signal.SIG_IGN:     # a shell's background job: as a terminal's
    signal.signal(signal.SIGINT, signal.default_int_handler)
AT, HOW, COUNT = int(os.environ["SEAM_AT"]), os.environ["SEAM_HOW"], os.environ["SEAM_COUNT"]
state = {"armed": False, "n": 0, "done": False}

def hook(event, args):
    if state["done"]:
        return
    if not state["armed"]:
        state["armed"] = signal.getsignal(signal.SIGINT) is not signal.default_int_handler
        if not state["armed"]:
            return
    state["n"] += 1
    if AT == 0 and event == "open" and str(args[0]).endswith("summary.json") and "w" in str(args[1]):
        state["done"] = True
        with open(COUNT, "w") as f:
            f.write(str(state["n"]))
    elif state["n"] == AT:
        state["done"] = True
        if HOW == "string":
            exec("kill(pid, SIGINT)", {"kill": os.kill, "pid": os.getpid(), "SIGINT": signal.SIGINT})
        else:
            os.kill(os.getpid(), signal.SIGINT)

import sys
sys.addaudithook(hook)
"""


def test_ctrl_c_at_any_moment_of_a_command_is_one_line_and_exit_130(tmp_path):
    """SIGINT at points spread over `python -m martello run`, from the moment its handler is in
    place (the rest of the imports, the library, the run) to the writing of summary.json,
    each point an audit event of the process (the seam above: the same points on every run, on
    any load). Never a traceback; exit 130 with one line, or exit 0 with the result when the
    interrupt came after the result was complete. Sent from code run from a string, it ended
    the process by SIGINT after the one line (CPython's mark, errors.forget_handled_interrupts)."""
    (tmp_path / "seam").mkdir()
    (tmp_path / "seam" / "sitecustomize.py").write_text(SIGINT_SEAM)

    def run(at, how, out):
        path = os.pathsep.join(p for p in (str(tmp_path / "seam"), os.environ.get("PYTHONPATH")) if p)
        env = dict(os.environ, PYTHONPATH=path, SEAM_AT=str(at), SEAM_HOW=how,
                   SEAM_COUNT=str(tmp_path / "count"))
        return subprocess.run([sys.executable, "-m", "martello", "run", str(P1), "-o", str(out)],
                              cwd=ROOT, env=env, capture_output=True, text=True, timeout=120)

    r = run(0, "count", tmp_path / "o0")
    assert r.returncode == 0 and (tmp_path / "o0" / "summary.json").exists(), r.stderr
    total = int((tmp_path / "count").read_text())
    assert total > 100, total           # the imports of the command and the library come after
    points = sorted({max(1, round(f * total)) for f in (0.01, 0.05, 0.15, 0.3, 0.5, 0.7, 0.9, 1.0)})
    for k, at in enumerate(points):
        how = ("direct", "string")[k % 2]
        out = tmp_path / f"o{at}"
        r = run(at, how, out)
        assert "Traceback" not in r.stderr and "internal error" not in r.stderr, (at, how, r.stderr)
        assert r.returncode in (0, 130), (at, how, total, r.returncode, r.stderr)
        if r.returncode == 130:
            assert r.stderr.count("\n") == 1 and "interrupted" in r.stderr, (at, how, r.stderr)
        else:
            assert (out / "summary.json").exists() and not r.stderr, (at, how, r.stderr)
