"""Hostile input, through the command line: every input of the fuzz campaign's findings gets
one line on stderr (`martello: error: ...` naming the file and field), exit code 1, no
traceback, and nothing written; a FIFO or a device is refused without being opened. Also the
guarantees behind that: the catch-all for bugs (--debug shows the traceback), results
checked finite and written atomically, the output budget, the range caps."""

import json
import os
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from benchmarks.fuzz.mutations import scene_dict, to_toml
from martello import cli
from martello.errors import ResultError, SceneError
from martello.run import check_budget, write_results
from martello.scene.loader import from_dict, load

ROOT = Path(__file__).resolve().parent.parent
P1 = ROOT / "benchmarks" / "p1" / "p1_static_lagrange.toml"
P5 = ROOT / "benchmarks" / "p5" / "p5_linear.toml"
PEER = ROOT / "tests" / "data" / "records" / "peer_fixed.AT2"


def martello(*args, cwd=ROOT, timeout=120):
    return subprocess.run([sys.executable, "-m", "martello", *map(str, args)], cwd=cwd,
                          capture_output=True, text=True, timeout=timeout,
                          stdin=subprocess.DEVNULL)


def one_line_error(r, *words):
    """The run failed cleanly: exit 1, one line on stderr, no traceback, naming `words`."""
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert r.returncode == 1, (r.returncode, r.stderr)
    assert len(lines) == 1 and "error:" in lines[0], r.stderr
    assert "Traceback" not in r.stderr and "internal error" not in r.stderr, r.stderr
    for w in words:
        assert w in lines[0], (w, lines[0])
    return lines[0]


def write(path, d):
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(d if isinstance(d, str) else to_toml(d))
    return path


def sdof_record(file, **fn):
    """A mass on a spring shaken by a record (the record path as the scene gives it)."""
    return {"node": [{"name": "m", "mass": 1.0}],
            "link": [{"type": "spring", "a": "m", "b": "ground", "k": 100.0}],
            "loads": {"ground_acceleration": dict({"type": "record", "file": file}, **fn)},
            "analysis": {"type": "dynamic", "integrator": "newmark", "dt": 0.01, "t_end": 0.04}}


def run_fails(tmp_path, scene, *words, out="out"):
    f = write(tmp_path / "s.toml", scene)
    r = martello("run", f, "-o", tmp_path / out, cwd=tmp_path)
    line = one_line_error(r, *words)
    assert not (tmp_path / out).exists(), "a failed run wrote its folder"
    return line


# --- the causes the fuzz campaign found, one test each --------------------------------------

def test_scalar_loads_is_refused(tmp_path):
    d = scene_dict("p5/p5_linear")
    d["loads"] = 5
    run_fails(tmp_path, d, "s.toml: loads: must be a table")


def test_nested_lists_in_output_nodes_are_refused(tmp_path):
    d = scene_dict("p5/p5_linear")
    d["analysis"]["output"]["nodes"] = [["m1"]]
    run_fails(tmp_path, d, "analysis.output.nodes[0]: has the wrong type (list)")
    # a rod scene merges its nodes into the list first: the same error
    d = scene_dict("p4/p4_wall_cd_half_cell_courant1")
    d["analysis"]["output"] = {"nodes": [{"a": 1}]}
    run_fails(tmp_path, d, "analysis.output.nodes[0]: has the wrong type (dict)")


def test_denormal_bar_density_is_refused(tmp_path):
    d = scene_dict("p4/p4_wall_cd_half_cell_courant1")
    d["bar"][0]["rho"] = 1e-310                         # subnormal itself
    run_fails(tmp_path, d, "bar[0].rho: is 1e-310, a subnormal number")
    d["bar"][0].update(rho=1e-200, A=1e-200)            # normal, but rho·A underflows to 0
    d["bar"][0].pop("E", None)
    d["bar"][0]["EA"] = 1.0
    run_fails(tmp_path, d, "bar[0].rho: gives rhoA = 0.0")


def test_huge_integers_in_float_fields_are_refused(tmp_path):
    text = P5.read_text().replace("mass = 1.0", "mass = 1" + "0" * 400, 1)
    run_fails(tmp_path, text, "node[0].mass: is an integer of 1329 bits", "64-bit")


def test_every_beyond_the_library_int_is_refused(tmp_path):
    # 2**40 used to reach the library as 0 ("need every >= 1")
    text = P5.read_text().replace("every = 100", f"every = {2 ** 40}")
    run_fails(tmp_path, text, "analysis.output.every: invalid value 1099511627776",
              "at most 2147483647")


def test_generators_are_capped(tmp_path):
    d = {"chain": [{"prefix": "p", "n": 10 ** 9, "mass": 1.0, "k": 1.0}],
         "analysis": {"type": "static"}}
    run_fails(tmp_path, d, "chain[0].n: invalid value 1000000000", "at most 1000000 nodes")
    d = scene_dict("p4/p4_wall_cd_half_cell_courant1")
    d["bar"][0]["elements"] = 10 ** 7
    run_fails(tmp_path, d, "bar[0].elements: invalid value 10000000", "at most 1000000 nodes")
    # all tables together: two chains of 600 000
    d = {"chain": [{"prefix": "p", "n": 600_000, "mass": 1.0, "k": 1.0},
                   {"prefix": "q", "n": 600_000, "mass": 1.0, "k": 1.0}],
         "analysis": {"type": "static"}}
    with pytest.raises(SceneError, match=r"chain\[1\]\.n: .*at most 1000000 nodes in all"):
        from_dict(d)


def test_deep_toml_nesting_is_refused(tmp_path):
    run_fails(tmp_path, "x = " + "[" * 5000 + "]" * 5000 + "\n", "(syntax)", "nested too deeply")
    d = scene_dict("p1/p1_static_lagrange")
    d["description"] = [[[[[[[[[[[[[[[[[["x"]]]]]]]]]]]]]]]]]]        # parses, too deep
    run_fails(tmp_path, d, "description", "deeper than 16 levels")


def test_scene_path_that_is_a_directory_or_a_device(tmp_path):
    for path, kind in ((tmp_path, "a directory"), ("/dev/zero", "a character device")):
        r = martello("run", path, "-o", tmp_path / "out", cwd=tmp_path, timeout=30)
        one_line_error(r, f"{path}: (file): is {kind}, not a regular file")
        assert not (tmp_path / "out").exists()


def test_scene_path_that_is_a_fifo_is_not_opened(tmp_path):
    fifo = tmp_path / "scene.toml"
    os.mkfifo(fifo)
    r = martello("run", fifo, "-o", tmp_path / "out", timeout=30)   # would block in open()
    one_line_error(r, "scene.toml: (file): is a FIFO (named pipe), not a regular file")


def test_compared_history_that_is_a_fifo_or_a_device_is_not_opened(tmp_path):
    """`compare` sniffs a history (CSV or OpenSees recorder) before reading it: the sniffing
    must not open a FIFO (it would block for ever) or read /dev/zero (no line ever ends)."""
    fifo = tmp_path / "h.csv"
    os.mkfifo(fifo)
    r = martello("compare", fifo, "--against", P5, timeout=30)
    one_line_error(r, "h.csv: is a FIFO (named pipe), not a regular file")
    r = martello("compare", "/dev/zero", "--against", P5, timeout=30)
    one_line_error(r, "/dev/zero: is a character device, not a regular file")


def test_output_naming_a_file_is_refused(tmp_path):
    (tmp_path / "afile").write_text("mine\n")
    for out in ("afile", "afile/sub"):
        r = martello("run", P1, "-o", tmp_path / out)
        one_line_error(r, "afile")
        assert (tmp_path / "afile").read_text() == "mine\n"


def test_output_naming_a_file_is_refused_before_a_long_run(tmp_path):
    """A run of 7e7 Newmark steps (about a minute here) with -o under a file: refused at once,
    before the run, not after it (the fuzz campaign's one hang of `run`)."""
    (tmp_path / "afile").write_text("mine\n")
    d = scene_dict("p2/p2_penalty_linear")
    d["analysis"]["dt"] = 1e-8
    d["analysis"]["output"] = {"every": 10 ** 9}
    d.pop("check", None)
    f = write(tmp_path / "s.toml", d)
    r = martello("run", f, "-o", tmp_path / "afile" / "sub", "--force", cwd=tmp_path, timeout=20)
    one_line_error(r, "afile is not a folder")
    assert (tmp_path / "afile").read_text() == "mine\n"


def test_output_through_a_symbolic_link_fills_the_folder_it_points_at(tmp_path):
    (tmp_path / "real").mkdir()
    (tmp_path / "link").symlink_to(tmp_path / "real")
    r = martello("run", P1, "-o", tmp_path / "link")
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "link").is_symlink() and (tmp_path / "real" / "summary.json").is_file()
    r = martello("run", P1, "-o", tmp_path / "link")       # again: replaced in place
    assert r.returncode == 0, r.stderr
    assert (tmp_path / "link").is_symlink() and (tmp_path / "real" / "summary.json").is_file()
    (tmp_path / "dangling").symlink_to(tmp_path / "nowhere")
    one_line_error(martello("run", P1, "-o", tmp_path / "dangling"),
                   "dangling: is a symbolic link to no folder")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["dangling", "link", "real"]


def test_output_folder_of_something_else_is_not_replaced(tmp_path):
    (tmp_path / "notes").mkdir()
    (tmp_path / "notes" / "mine.txt").write_text("keep\n")
    r = martello("run", P1, "-o", tmp_path / "notes")
    one_line_error(r, "holds files of something else (mine.txt)")
    assert sorted(p.name for p in (tmp_path / "notes").iterdir()) == ["mine.txt"]


def test_at2_header_npts_1e400(tmp_path):
    rec = PEER.read_text().splitlines()
    rec[3] = "NPTS=1e400, DT= .0200 SEC"
    (tmp_path / "r.AT2").write_text("\n".join(rec) + "\n")
    run_fails(tmp_path, sdof_record("r.AT2"), "s.toml: loads.ground_acceleration.file: r.AT2:4:",
              "NPTS '1e400' is not a non-negative whole number")


def test_record_value_1e999_names_the_file_and_line(tmp_path):
    (tmp_path / "r.csv").write_text("0.0, 0.0\n0.01, 0.5\n0.02, 1e999\n0.03, 0.0\n")
    run_fails(tmp_path, sdof_record("r.csv"), "loads.ground_acceleration.file: r.csv:3:",
              "acceleration value '1e999' is not finite")


def test_record_at_dev_zero_or_a_fifo_is_refused_unopened(tmp_path):
    run_fails(tmp_path, sdof_record("/dev/zero", format="csv"),
              "loads.ground_acceleration.file: /dev/zero is a character device")
    os.mkfifo(tmp_path / "pipe.csv")
    opened = []
    # a writer that would be released if the run opened the FIFO for reading
    t = threading.Thread(target=lambda: opened.append(os.open(tmp_path / "pipe.csv", os.O_WRONLY)),
                         daemon=True)
    t.start()
    run_fails(tmp_path, sdof_record("pipe.csv"), "pipe.csv is a FIFO (named pipe), not a regular file")
    t.join(0.5)
    assert not opened, "the run opened the FIFO"
    fd = os.open(tmp_path / "pipe.csv", os.O_RDONLY | os.O_NONBLOCK)    # release the writer
    t.join(5)
    os.close(fd)
    for w in opened:
        os.close(w)


def test_record_path_out_of_the_scene_folder_is_shown_as_given_and_not_echoed(tmp_path):
    # the scene two folders down names ../../etc/passwd: a file that is no record
    secret = ["root:x:0:0:root:/root:/bin/bash",
              "admin:x:1000:1000:The Secret Admin Line:/home/admin:/bin/bash"]
    (tmp_path / "etc").mkdir()
    (tmp_path / "etc" / "passwd").write_text("\n".join(secret) + "\n")
    for fmt in ("csv", "at2"):
        f = write(tmp_path / "a" / "b" / "s.toml", sdof_record("../../etc/passwd", format=fmt))
        r = martello("run", f, "-o", tmp_path / "out", cwd=tmp_path)
        line = one_line_error(r, "a/b/s.toml: loads.ground_acceleration.file: ../../etc/passwd:")
        assert not any(part in line for s in secret for part in s.split(":") if len(part) > 4), line
        assert "Secret" not in line and not (tmp_path / "out").exists()


def test_check_path_to_a_non_number_fails_that_scene_only(tmp_path):
    text = P5.read_text().replace('result = "contacts.impact.restitution.0"',
                                  'result = "contacts.impact"')
    f = write(tmp_path / "s.toml", text)
    r = martello("check", f, P1, "-o", tmp_path / "report", "--no-plots")
    assert r.returncode == 1 and "Traceback" not in r.stderr + r.stdout
    assert "'contacts.impact' is a dict in the summary, not a number" in r.stdout
    assert "P1 mass on plane" in r.stdout and "1 failure(s); 2 scenes" in r.stdout


def test_infinite_reference_fails_its_check(monkeypatch):
    """A reference of inf used to pass any check with 16 digits; now it is an error."""
    from martello.checks import verify as v
    s = load(P5)
    monkeypatch.setattr(v, "oracle_values", lambda check, source: {
        "restitution": float("inf"), "contact_time": 1.0, "max_penetration": 1.0})
    summary = {"contacts": {"impact": {"restitution": [1.0], "contact_time": 1.0,
                                       "max_penetration": 1.0}}}
    with pytest.raises(SceneError, match=r"check\.compare\[0\]\.oracle: two_body_impact gives "
                                         r"restitution = inf, not a finite number"):
        v.verify(s, summary)


def test_compare_of_non_utf8_history(tmp_path):
    (tmp_path / "h.csv").write_bytes(b"t,u:m1\n0,0\n0.001,\xff\xfe\n")
    r = martello("compare", tmp_path / "h.csv", "--against", P5, "-o", tmp_path / "sc.json")
    one_line_error(r, "h.csv:3: byte", "is not UTF-8 text")
    assert not (tmp_path / "sc.json").exists()


def test_study_with_negative_jobs(tmp_path):
    r = martello("study", ROOT / "benchmarks" / "studies" / "atlas.toml", "-j", "-3",
                 "-o", tmp_path / "out")
    one_line_error(r, "martello study: error: argument -j/--jobs: -3 is not in 0 to 256")
    assert not (tmp_path / "out").exists()


def test_h_max_that_would_run_for_ever_is_refused(tmp_path):
    text = (ROOT / "benchmarks" / "p2" / "p2_ida_penalty_linear.toml").read_text().replace(
        'integrator = "ida"', 'integrator = "ida"\nh_max = 1e-12')
    line = run_fails(tmp_path, text, "s.toml: analysis.h_max: needs at least 7e11 steps",
                     "--force runs it anyway")
    assert "more than the 1e9 node-steps a run may take" in line
    # two rods of 202 nodes: 6e8 steps are 1.2e11 node-steps (it used to pass: 6e8 < 1e9 steps)
    d = scene_dict("p4/p4_equal_rods_rk8pd_restitution_e0")
    d["analysis"]["h_max"] = 1e-12
    run_fails(tmp_path, d, "analysis.h_max: needs at least 5.95e8 steps", "of 202 nodes")


def test_usage_errors_are_one_line(tmp_path):
    for args in (["run"], ["frobnicate"], ["run", P1, "--nope"]):
        one_line_error(martello(*args), "(see martello")


# --- the guarantees behind them ---------------------------------------------------------------

def test_an_unexpected_exception_is_one_line_with_a_report_hint(monkeypatch, capsys):
    def boom(args):
        raise ZeroDivisionError("float division by zero\nsecond line")
    monkeypatch.setattr(cli, "cmd_list", boom)
    assert cli.main(["list"]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert err.startswith("martello: internal error: ZeroDivisionError: float division by zero second line")
    assert "please report" in err and "--debug" in err
    with pytest.raises(ZeroDivisionError):          # --debug: the exception, traceback and all
        cli.main(["--debug", "list"])
    with pytest.raises(ZeroDivisionError):
        cli.main(["list", "--debug"])


def test_out_of_memory_and_system_errors_are_one_line(monkeypatch, capsys):
    def oom(args):
        raise MemoryError()
    monkeypatch.setattr(cli, "cmd_list", oom)
    assert cli.main(["list"]) == 1
    err = capsys.readouterr().err
    assert err.startswith("martello: error: out of memory") and err.count("\n") == 1


def _summary():
    return {"status": "MARTELLO_OK", "nodes": {"m": {"u": 1.0, "list": [0.5, 2.0]}}}


def test_results_must_be_finite_to_be_written(tmp_path):
    s = _summary()
    s["nodes"]["m"]["list"][1] = float("inf")
    with pytest.raises(ResultError, match=r"nodes\.m\.list\.1 is inf"):
        write_results(s, tmp_path / "out")
    with pytest.raises(ResultError, match=r"history column u:m is nan at row 1"):
        write_results(_summary(), tmp_path / "out",
                      (["t", "u:m"], [[0.0, 0.0], [1.0, float("nan")]]))
    assert not (tmp_path / "out").exists() and not list(tmp_path.iterdir())
    # link states that are NaN throughout are unreported (adaptive integrators), not results
    write_results(_summary(), tmp_path / "out",
                  (["t", "u:m", "link_force:s"], [[0.0, 0.0, float("nan")], [1.0, 1.0, float("nan")]]))
    assert (tmp_path / "out" / "history.csv").exists()


def test_results_replace_an_earlier_run_whole(tmp_path):
    out = tmp_path / "run"
    write_results(_summary(), out, (["t", "u:m"], [[0.0, 0.0], [1.0, 1.0]]))
    (out / "plot.png").write_bytes(b"stale")
    write_results(_summary() | {"status": "MARTELLO_ILL_CONDITIONED"}, out)   # a static run
    assert sorted(p.name for p in out.iterdir()) == ["summary.json"]      # stale files gone
    assert json.loads((out / "summary.json").read_text())["status"] == "MARTELLO_ILL_CONDITIONED"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["run"]          # no temporary left
    # a failed write leaves the earlier run as it was
    bad = _summary()
    bad["nodes"]["m"]["u"] = float("nan")
    with pytest.raises(ResultError):
        write_results(bad, out)
    assert json.loads((out / "summary.json").read_text())["status"] == "MARTELLO_ILL_CONDITIONED"


def test_a_failed_run_keeps_the_earlier_results(tmp_path):
    out = tmp_path / "out"
    assert martello("run", P1, "-o", out).returncode == 0
    before = (out / "summary.json").read_text()
    bad = write(tmp_path / "bad.toml", P1.read_text().replace("mass = 1.0 ", "mass = -1.0 "))
    one_line_error(martello("run", bad, "-o", out), "node[0].mass")
    assert (out / "summary.json").read_text() == before


def test_output_budget_warns_refuses_and_yields_to_force(tmp_path):
    d = scene_dict("p5/p5_linear")
    d["analysis"]["output"]["every"] = 1
    d["analysis"]["dt"] = 2e-8                      # 2.5e5 rows x 18 columns: ~100 MB
    assert "up to about 108 MB" in check_budget(from_dict(d))[0]
    d["analysis"]["dt"] = 1e-9                      # 5e6 rows: > 1 GB
    with pytest.raises(SceneError, match=r"analysis\.output\.every: the run would write up to "
                                         r"about 2\.16 GB .*more than the 1 GB"):
        check_budget(from_dict(d))
    assert "2.16 GB" in check_budget(from_dict(d), force=True)[0]
    d["analysis"]["dt"] = 1e-12                     # 5e9 steps
    with pytest.raises(SceneError, match=r"analysis\.dt: needs at least 5e9 steps"):
        check_budget(from_dict(d))
    # and on the command line: refused in one line, nothing written
    f = write(tmp_path / "big.toml", d)
    r = martello("run", f, "-o", tmp_path / "out")
    one_line_error(r, "analysis.dt: needs at least 5e9 steps")
    assert not (tmp_path / "out").exists()


def test_a_bug_in_one_scene_does_not_stop_martello_check(tmp_path, monkeypatch):
    import io
    from martello import report
    real = report.run_measured

    def flaky(scene):
        if scene.problem == "P5":
            raise KeyError("a bug")
        return real(scene)
    monkeypatch.setattr(report, "run_measured", flaky)
    out = io.StringIO()
    ok = report.check_catalogue([P5, P1], tmp_path, plots=False, stream=out)
    text = out.getvalue()
    assert not ok and "internal error: KeyError: 'a bug'" in text
    assert "P1 mass on plane" in text and "1 failure(s); 2 scenes" in text


# --- the bad inputs of a later review (issue "one line for every bad input") -----------------

def test_a_subnormal_at2_step_is_refused(tmp_path):
    rec = PEER.read_text().splitlines()
    rec[3] = "NPTS=   10, DT= 5e-324 SEC"
    (tmp_path / "r.AT2").write_text("\n".join(rec[:4] + ["0.1 0.2 0.3 0.4 0.5"] * 2) + "\n")
    run_fails(tmp_path, sdof_record("r.AT2"), "loads.ground_acceleration.file: r.AT2:4:",
              "DT=5e-324 s is no sampling step of an accelerogram")


@pytest.mark.parametrize("times, words", [
    ((-1.0, 0.0, 0.01), "r.csv starts at t = -1.0 s, before the run's t = 0"),
    ((0.05, 0.06, 0.07), "r.csv starts at t = 0.05 s, not before the run's t_end = 0.04 s")])
def test_a_record_that_starts_outside_the_run_is_refused(tmp_path, times, words):
    (tmp_path / "r.csv").write_text("".join(f"{t}, 0.5\n" for t in times))
    run_fails(tmp_path, sdof_record("r.csv"), "s.toml: loads.ground_acceleration.file: " + words)


@pytest.mark.parametrize("width", ["1e300", "1e-300"])
def test_frame_lengths_past_the_doubles_are_one_line(tmp_path, width):
    text = (ROOT / "benchmarks" / "p10" / "p10_bare.toml").read_text()
    text = "\n".join(f"bay_width = {width}" if ln.startswith("bay_width") else ln
                     for ln in text.splitlines())
    run_fails(tmp_path, text, "s.toml: frame[0]: the condensed stiffness is not finite")


def test_a_chain_damping_past_the_doubles_names_the_field_in_one_line(tmp_path):
    """[[chain]] k = 1e308, mass = 1e5: c = 2 zeta sqrt(k m) overflows. One line naming the
    chain's zeta (it printed numpy's RuntimeWarnings, then the library's message)."""
    text = (ROOT / "benchmarks" / "p7" / "p7_chain_10.toml").read_text()
    text = "\n".join("k = 1e308" if ln.startswith("k = [") else ln for ln in text.splitlines())
    line = run_fails(tmp_path, text, "s.toml: chain[0].zeta: the damping c = 2 zeta sqrt(k m) of "
                     "node b1 is not a finite number")
    assert "RuntimeWarning" not in line


STUDY_OF_DATA = """
title = "data reference"
[[scene]]
file = "{scene}"
reference = {{ data = "{data}" }}
t_end = 0.1
[[integrator]]
name = "newmark"
dt = [1e-3]
"""


@pytest.mark.parametrize("meta, history, words", [
    ("{}", "t,u:mass\n0,0\n1,1\n", "reference.json: t_end: None is not a time > 0"),
    ("[1, 2]", "t,u:mass\n0,0\n1,1\n", "reference.json: holds a list"),
    ('{"t_end": 1.0}', "t,u:mass\n0,0\n1,x\n", "history.csv:3: column u:mass: 'x' is not a number"),
    ('{"t_end": 1.0}', "t,u:mass\n0,0\n1", "history.csv:3: 1 values for 2 columns"),
    ('{"t_end": 1.0, "events": [3]}', "t,u:mass\n0,0\n1,1\n", "reference.json: events: must be a table"),
    ('{"t_end": 1', "t,u:mass\n0,0\n1,1\n", "reference.json: not valid JSON")])
def test_a_malformed_reference_named_by_a_study_is_one_line(tmp_path, meta, history, words):
    """A study's `reference = { data = DIR }`, resolved beside the study file, holding what
    martello does not write: one line naming the study, the case and the file, nothing
    written (it was a KeyError, a TypeError or a ValueError)."""
    (tmp_path / "ref").mkdir()
    (tmp_path / "ref" / "reference.json").write_text(meta)
    (tmp_path / "ref" / "history.csv").write_text(history)
    study = write(tmp_path / "study.toml", STUDY_OF_DATA.format(
        scene=ROOT / "benchmarks" / "p2" / "p2_penalty_linear.toml", data="ref"))
    r = martello("study", study, "-o", tmp_path / "out", "--no-plots", cwd=ROOT)
    one_line_error(r, "study.toml: reference of ", f"{tmp_path / 'ref'}/" + words.split(":")[0],
                   words.partition(": ")[2] if ": " in words else words)
    assert not (tmp_path / "out").exists()


def test_a_storey_mass_past_the_doubles_is_one_line_naming_the_masses(tmp_path):
    """A storey of 1e-300 kg: the stiffness over the masses overflows (it was numpy's
    LinAlgError 'Eigenvalues did not converge' from the Rayleigh damping; loader fuzz case)."""
    text = (ROOT / "benchmarks" / "p10" / "p10_bare.toml").read_text()
    text = "\n".join("mass = [195000.0, 1e-300]" if ln.startswith("mass = [195000.0, 150000.0]")
                     else ln for ln in text.splitlines())
    assert "1e-300" in text
    run_fails(tmp_path, text, "s.toml: frame[0].mass: the stiffness over the masses")


def test_an_error_raised_while_a_ctrl_c_is_delivered_is_the_interrupt(monkeypatch, capsys):
    """A Ctrl-C while numpy imports came back as numpy's ImportError, not chaining the
    KeyboardInterrupt ('PyCapsule_Import could not import module "datetime"'), and was
    reported as a bug: the command's first SIGINT handler (martello.__main__) records it."""
    from types import SimpleNamespace
    from martello import errors

    def importing(args):
        raise ImportError('PyCapsule_Import could not import module "datetime"')
    args = SimpleNamespace(func=importing, debug=False)
    assert cli.run_command(args) == 1 and "internal error" in capsys.readouterr().err
    monkeypatch.setattr(errors, "sigint_seen", True)
    assert cli.run_command(args) == 130
    assert capsys.readouterr().err == "martello: interrupted\n"


def _edited(name, path, value):
    d = scene_dict(name)
    node = d
    for p in path[:-1]:
        node = node[p]
    node[path[-1]] = value
    return d


@pytest.mark.parametrize("name, path, value, words", [
    # the condensation's powers of a storey height leave the doubles (ZeroDivisionError at
    # 1e-300 m, OverflowError at 1e300 m)
    ("p11/p11_eccentric_storey", ("building", 0, "storey_height"), 1e-300,
     "building[0]: the condensed stiffness is not finite"),
    ("p11/p11_eccentric_storey", ("building", 0, "storey_height"), 1e300,
     "building[0]: the condensed stiffness is not finite"),
    # z = cumsum(heights) overflows (numpy's RuntimeWarning, then NaN)
    ("p11/p11_shear_pounding", ("building", 0, "storey_height"), [1e308, 1e308],
     "building[0].storey_height: the building's height leaves the doubles"),
    # b2 b3³/12 of a 1e300 m side (OverflowError)
    ("p11/p11_eccentric_storey", ("building", 0, "column", "b2"), 1e300,
     "building[0].column: the rectangle's area, second moments or torsion constant"),
    # m (lx² + ly²)/12 of a grid 1e300 m wide (OverflowError)
    ("p11/p11_eccentric_storey", ("building", 0, "grid_x", 1), 1e300,
     "building[0].inertia: the floors' polar inertia"),
    # K M^-1 overflows (numpy's RuntimeWarning in the modal table)
    ("p11/p11_eccentric_storey", ("building", 0, "mass"), 1e-300,
     "building[0].mass: the frequencies of the building could not be computed"),
    # masses 1e17 apart: a computed ω² <= 0 was clipped to a zero frequency, then 0/0 in the
    # Rayleigh coefficients (NaN damping, numpy's RuntimeWarning)
    ("p11/p11_shear_pounding", ("building", 0, "mass", 0), 1e-12,
     "building[0].mass: the frequencies of the building could not be computed"),
    ("p10/p10_bare", ("frame", 0, "mass", 1), 1e-12,
     "frame[0].mass: the frequencies of the frame could not be computed"),
    ("p10/p10_bare", ("frame", 1, "bay_width"), 1e308,
     "frame[1].bay_width: the frame's height or width leaves the doubles"),
])
def test_buildings_and_frames_past_the_doubles_are_one_line_naming_the_field(name, path, value, words):
    """Loader fuzz of every [[building]] and [[frame]] field (session 5): these raised
    ZeroDivisionError / OverflowError, or loaded with numpy's RuntimeWarnings and NaN or
    clipped frequencies. Now a SceneError naming the field, and no warning."""
    import warnings
    src = ROOT / "benchmarks" / f"{name}.toml"
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(SceneError) as e:
            from_dict(_edited(name, path, value), source=str(src), base_dir=src.parent)
    msg = str(e.value)
    assert "\n" not in msg and words in msg, msg


def test_a_building_past_the_doubles_is_one_line_on_the_command_line(tmp_path):
    run_fails(tmp_path, _edited("p11/p11_eccentric_storey", ("building", 0, "storey_height"), 1e-300),
              "s.toml: building[0]: the condensed stiffness is not finite")


def test_modes_refuse_a_frequency_that_is_not_positive():
    """martello.modes: K and M positive definite, so a computed ω² <= 0 or NaN is round-off
    past the problem's conditioning (the p11 case above): LinAlgError, where it was clipped
    to a zero frequency."""
    import numpy as np
    from martello.modes import modes
    K = np.array([[2.0, -1.0], [-1.0, 1.0]]) * 1e9
    w, phi = modes(K, np.array([1e5, 2e5]))
    assert np.all(w > 0) and np.allclose(phi.T @ np.diag([1e5, 2e5]) @ phi, np.eye(2))
    for bad_K, M in ((np.diag([1.0, -1.0]), np.ones(2)), (np.diag([1.0, 0.0]), np.eye(2)),
                     (K, np.array([1e5, 1e-320]))):
        with pytest.raises(np.linalg.LinAlgError):
            modes(bad_K, M)


@pytest.mark.parametrize("flags, words", [
    (["--dt", "0"], "--dt: invalid value 0.0 (must be a number > 0"),          # ZeroDivisionError
    (["--dt", "-1"], "--dt: invalid value -1.0"),                               # was written
    (["--dt", "nan"], "--dt: invalid value nan"),                               # ValueError
    (["--t-end", "inf"], "--t-end: invalid value inf"),                         # OverflowError
    (["--integrator", "newmark", "--beta", "-1"], "--beta: invalid value -1.0"),  # was written
    (["--integrator", "hht", "--alpha", "5"], "--alpha: invalid value 5.0 (must be a number in [-1/3, 0]"),
    (["--integrator", "generalized-alpha", "--rho-inf", "2"], "--rho-inf: invalid value 2.0"),
    (["--integrator", "hht", "--alpha", "-0.1", "--beta", "0.3"],
     "--beta: applies to --integrator newmark, not hht"),                       # was ignored
    (["--tol", "0"], "--tol: invalid value 0.0 (must be a number > 0"),         # was written
    (["--tol", "1e400"], "--tol: invalid value inf"),                           # ValueError
])
def test_export_overrides_are_checked_as_the_scene_keys_they_replace(tmp_path, capsys, flags, words):
    """`martello export`'s --dt, --t-end, --beta, --gamma, --alpha, --rho-inf and --tol
    (CLI fuzz of export, session 5): an internal error, or a model.py written with the bad
    value. Now one line naming the flag and the range of the scene key it replaces, nothing
    written."""
    out = tmp_path / "ex"
    assert cli.main(["export", str(P5), "-o", str(out), *flags]) == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("martello: error: ") and words in err, err
    assert not out.exists()


def test_export_overrides_in_range_still_export(tmp_path, capsys):
    out = tmp_path / "ex"
    assert cli.main(["export", str(P5), "-o", str(out), "--integrator", "hht", "--alpha", "-0.1",
                     "--dt", "1e-5", "--tol", "1e-9"]) == 0
    assert "HHT" in (out / "model.py").read_text()


def test_a_value_starting_with_a_dash_is_shown_how_to_write_it(capsys):
    """`--columns -u:s2` (a leading - flips the sign, as its help says) reads to argparse as an
    option without its value: the usage error says to write --columns=-u:s2 (it said only
    'expected one argument'); an option where the value should be gets no such hint."""
    for argv, hint in ((["compare", "h.csv", "--against", "s.toml", "--columns", "-u:s2"],
                        "(a value that starts with '-' is written --columns=-u:s2)"),
                       (["run", "s.toml", "-o", "--force"], None)):
        with pytest.raises(SystemExit) as e:
            cli.main(argv)
        err = capsys.readouterr().err
        assert e.value.code == 1 and err.count("\n") == 1 and "expected one argument" in err, err
        assert (hint in err) if hint else "written" not in err, err
