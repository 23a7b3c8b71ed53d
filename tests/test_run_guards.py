"""The run layer's guards on cost and on the caller: 64-bit step counts, the max_steps and
max_wall budget, the progress callback and Ctrl-C through it, a history grown as needed,
and the warning of a run let past its stability limit (docs/behaviour.md "Failures and
limits", docs/scene-input.md). Failures are asserted by message, exit code and the absence of
output."""

import os
import re
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

import martello
from martello.binding import native
from benchmarks.fuzz.mutations import to_toml
from divergence_cases import p2

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def _write(tmp_path, d, name="scene"):
    f = tmp_path / f"{name}.toml"
    f.write_text(to_toml(d))
    return f


def _cli(*args):
    return subprocess.run([sys.executable, "-m", "martello", *map(str, args)], cwd=ROOT,
                          capture_output=True, text=True)


def test_more_steps_than_a_32_bit_int_are_refused_by_the_budget_or_counted(tmp_path):
    """P2 at dt = 1e-10 s to t_end = 0.7 s needs 7e9 steps, past 2^31 = 2.1e9: with the
    default max_steps = 1e8 it is refused before its first step; with max_steps = 1e12 it
    runs (no wrap to one step reported OK) until max_wall = 0.5 s stops it, and the time it
    reached is its step count times dt (each step is dt: t_k = k dt)."""
    d = p2(dt=1e-10, t_end=0.7, output={"every": 10 ** 9})
    assert 0.7 / 1e-10 > 2 ** 31
    r = _cli("run", _write(tmp_path, d), "-o", tmp_path / "o1", "--force")
    err = r.stderr.strip().splitlines()[-1]
    assert r.returncode == 1 and "MARTELLO_ERR_LIMIT" in err
    assert re.search(r"needs at least +7.000E\+09 steps .* max_steps = +1.000E\+08", err), err
    assert not (tmp_path / "o1").exists()
    d["analysis"].update(max_steps=1e12, max_wall=0.5)
    r = _cli("run", _write(tmp_path, d, "wall"), "-o", tmp_path / "o2", "--force")
    err = r.stderr.strip().splitlines()[-1]
    assert r.returncode == 1 and "MARTELLO_ERR_LIMIT" in err and "ran for max_wall" in err
    m = re.search(r"\((\d+) steps\) and reached t = +(\S+) s", err)
    steps, t = int(m.group(1)), float(m.group(2))
    assert steps > 1000 and t == pytest.approx(steps * 1e-10, rel=1e-5)  # t printed to 6 digits
    assert not (tmp_path / "o2").exists()


def test_max_steps_must_be_a_whole_number(tmp_path):
    r = _cli("run", _write(tmp_path, p2(max_steps=1e4 + 0.5)), "-o", tmp_path / "o")
    assert r.returncode == 1 and len(r.stderr.strip().splitlines()) == 1
    assert "analysis.max_steps" in r.stderr and "whole number" in r.stderr


def test_progress_reaches_the_caller_with_growing_time_and_steps():
    """The native loop reports about four times a second: t rises towards t_end, steps with
    it, and t = steps x dt on the fixed step (each report is a state of the grid). The run is
    long (7e7 steps, several seconds); the reporter stops it after its fourth report."""
    calls = []

    class Enough(Exception):
        pass

    def reporter(t, t_end, steps, elapsed):
        calls.append((t, t_end, steps, elapsed))
        if len(calls) == 4:
            raise Enough

    d = p2(dt=1e-8, t_end=0.7, output={"every": 10 ** 9})
    with native.reporting(reporter), pytest.raises(Enough):
        martello.run(martello.Scene.from_dict(d))
    assert len(calls) == 4
    t, t_end, steps, elapsed = map(np.array, zip(*calls))
    assert np.all(np.diff(t) > 0) and np.all(np.diff(steps) > 0) and np.all(np.diff(elapsed) > 0)
    assert np.all(t_end == 0.7) and np.all(t < 0.7)
    assert np.allclose(t, steps * 1e-8, rtol=1e-9)


def test_a_reporter_that_fails_stops_the_run_and_its_error_is_raised():
    d = p2(dt=1e-7, t_end=0.7, output={"every": 10 ** 6})
    seen = []

    def reporter(t, t_end, steps, elapsed):
        seen.append(t)
        raise RuntimeError("reporter broke")

    t0 = time.perf_counter()
    with native.reporting(reporter), pytest.raises(RuntimeError, match="reporter broke"):
        martello.run(martello.Scene.from_dict(d))
    assert len(seen) == 1 and time.perf_counter() - t0 < 3.0    # stopped at the first report


def test_ctrl_c_stops_the_native_loop_says_so_exits_130_and_writes_nothing(tmp_path):
    """A run of about 50 s (P2 at dt = 1e-8 s): once its progress line shows it running,
    SIGINT stops it within a second or two, with one line 'interrupted at t = ...: nothing
    written' and exit code 130; no output folder appears."""
    d = p2(dt=1e-8, t_end=0.7, output={"every": 10 ** 9})
    out = tmp_path / "o"
    p = subprocess.Popen([sys.executable, "-m", "martello", "run", str(_write(tmp_path, d)),
                          "-o", str(out), "--progress", "--force"], cwd=ROOT, text=True,
                         stderr=subprocess.PIPE, stdout=subprocess.DEVNULL,
                         # a background job may inherit SIGINT ignored: restore the default
                         preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    lines = []
    try:
        while True:
            line = p.stderr.readline()
            assert line, f"the run ended before reporting progress: {lines}"
            lines.append(line)
            if line.startswith("t = "):
                break
        assert re.match(r"t = \S+ of 0.7 s \(\S+ %\), \S+ steps, \S+ steps/s, ETA ", line), line
        p.send_signal(signal.SIGINT)
        t0 = time.perf_counter()
        _, rest = p.communicate(timeout=20)
        waited = time.perf_counter() - t0
    finally:
        if p.poll() is None:
            p.kill()
    assert p.returncode == 130 and waited < 5.0
    last = rest.strip().splitlines()
    assert len([l for l in last if not l.startswith("t = ")]) == 1
    assert re.fullmatch(r"martello: interrupted at t = +\S+ s \(\d+ steps\): nothing written", last[-1])
    assert not out.exists() and not any(tmp_path.glob(".o.*"))


def test_a_short_run_prints_no_progress_line_in_a_log(tmp_path):
    """stderr not a terminal, no --progress: a run under ProgressLine.SPARSE_FIRST (30 s)
    writes no progress line (its log is what it was)."""
    d = p2(dt=1e-7, t_end=0.2, output={"every": 10 ** 6})   # 2e6 steps: over a second
    r = _cli("run", _write(tmp_path, d), "-o", tmp_path / "o")
    assert r.returncode == 0 and not [l for l in r.stderr.splitlines() if l.startswith("t = ")]


class _Log(list):
    """A stream that is not a terminal (a log file), keeping what was written."""

    def write(self, text):
        self.append(text)

    def flush(self):
        pass

    def isatty(self):
        return False


def test_a_long_run_in_a_log_says_it_is_alive_without_flooding_it():
    """The progress line in a log (nohup, a batch system; cli.ProgressLine, sparse): a run of
    an hour reported four times a second, as the native loop does, writes 15 lines, at 30 s,
    1, 2, 4, 8 min and then every 5 min, each with t, share, steps, rate, ETA and the time so
    far; --progress in a log: every 5 s; the next run of the same command starts again."""
    from martello.cli import ProgressLine
    rate, t_end = 1e4, 3600.0

    def feed(line, seconds, start=0.0):
        for k in range(int(seconds * 4) + 1):
            e = k / 4
            line(t_end * (start + e) / 3600.0, t_end, int(rate * e), e)

    log = _Log()
    feed(ProgressLine(log, sparse=True), 3600.0)
    assert len(log) == 15, log
    shares = [float(re.search(r"\((\S+) %\)", x).group(1)) for x in log]
    expected = [30, 60, 120, 240, 480] + [480 + 300 * k for k in range(1, 11)]
    assert shares == pytest.approx([100 * e / 3600 for e in expected], abs=0.05)
    for x in log:
        assert re.fullmatch(r"t = \S+ of 3600 s \(\S+ %\), \S+ steps, 1e\+04 steps/s, "
                            r"ETA \S+ (s|min|h) \(\S+ (s|min|h) so far\)\n", x), x
    assert log[0].endswith("ETA 60 min (30 s so far)\n") and log[-1].endswith("(58 min so far)\n")
    log = _Log()
    line = ProgressLine(log, sparse=True)
    feed(line, 29.75)
    assert log == []                                  # a run under 30 s: nothing
    feed(line, 40.0)                                  # the next run: its own 30 s
    assert len(log) == 1 and "(30 s so far)" in log[0]
    log = _Log()
    feed(ProgressLine(log), 60.0)                     # --progress: every 5 s from 1 s
    assert len(log) == 12 and "(1 s so far)" in log[0] and "(56 s so far)" in log[-1]


def test_the_progress_lines_change_no_result(tmp_path, monkeypatch, capsys):
    """The same run without and with its progress lines (in a log, every report printed):
    history.csv byte for byte, summary.json but for its wall time and date."""
    import json
    from martello import cli
    d = p2(dt=1e-7, t_end=0.2, output={"every": 10 ** 4})   # 2e6 steps: over a second
    scene = _write(tmp_path, d)
    assert cli.main(["run", str(scene), "-o", str(tmp_path / "quiet"), "--no-progress"]) == 0
    monkeypatch.setattr(cli.ProgressLine, "SPARSE_FIRST", 0.0)
    monkeypatch.setattr(cli.ProgressLine, "SPARSE_CAP", 0.0)
    capsys.readouterr()
    assert cli.main(["run", str(scene), "-o", str(tmp_path / "shown")]) == 0
    err = capsys.readouterr().err
    assert [x for x in err.splitlines() if x.startswith("t = ")], err

    def summary(name):
        s = json.loads((tmp_path / name / "summary.json").read_text())
        del s["cost"]["wall_time_s"], s["provenance"]["date"]
        return s
    assert summary("quiet") == summary("shown")
    assert (tmp_path / "quiet" / "history.csv").read_bytes() == \
        (tmp_path / "shown" / "history.csv").read_bytes()


def test_history_grows_past_its_first_allocation():
    """The history starts at 4096 rows and doubles as needed: 20 000 steps recorded each give
    20 001 rows at t = k dt (free flight at 1 m/s: u = t, an identity of any method)."""
    d = {"node": [{"name": "m", "mass": 1.0, "v0": 1.0}],
         "analysis": {"type": "dynamic", "integrator": "newmark", "dt": 1e-4, "t_end": 2.0,
                      "output": {"every": 1}}}
    res = martello.run(martello.Scene.from_dict(d))
    t, u = res.data[:, 0], res.data[:, res.columns.index("u:m")]
    assert len(t) == 20001
    assert np.allclose(t, np.arange(20001) * 1e-4, rtol=0, atol=1e-12)
    assert np.allclose(u, t, rtol=0, atol=1e-10)   # 2e4 roundings of u + h v, ~2e-16 each


def test_a_run_let_past_its_stability_limit_says_so_first(tmp_path):
    """check_stability = false, central difference at dt = 0.21 s > 2/omega = 0.2 s on a
    10 rad/s oscillator, for 2 steps: the energy has not grown tenfold yet, so no guard stops
    it; the summary's first warning says it is past the limit."""
    d = {"node": [{"name": "m", "mass": 1.0, "u0": 0.01}],
         "link": [{"type": "spring", "a": "m", "b": "ground", "k": 100.0}],
         "analysis": {"type": "dynamic", "integrator": "central-difference", "dt": 0.21,
                      "t_end": 0.42, "check_stability": False}}
    res = martello.run(martello.Scene.from_dict(d))
    assert res.status == "MARTELLO_OK"
    assert res.summary["stability"]["dt_critical"] == pytest.approx(0.2, rel=1e-12)
    assert "past the stability limit dt_crit = 0.2 s" in res.summary["warnings"][0]


def test_the_pace_limit_stops_a_run_that_would_take_past_the_budget():
    """martello run's estimate from the pace (cli.PaceLimit): checked once, PILOT_S into a
    run; past BUDGET_S the run is stopped naming the setting (rtol for an adaptive
    integrator, dt for a fixed step) and --force; a run within the budget goes on; the next
    run of the same command (P4's measures) is checked again."""
    from martello.cli import PaceLimit
    from martello.errors import SceneError

    class S:
        source = "s.toml"
    lim = PaceLimit(S(), adaptive=True)
    lim(1e-4, 1.0, 10, 5.0)                         # before the pilot: nothing said
    with pytest.raises(SceneError, match=r"s.toml: analysis.rtol: at its pace over its first "
                       r"10 s \(t = 0.001 of 1 s, 100 steps\) the run would take about 2.8 h, "
                       r"more than the 60 min a run may take without --force \(loosen rtol.*"
                       r"--force runs it anyway\)"):
        lim(1e-3, 1.0, 100, 10.0)                   # 10 s for 1/1000 of the run: 2.8 h
    lim(2e-3, 1.0, 200, 20.0)                       # checked once only
    fixed = PaceLimit(S(), adaptive=False)
    fixed(0.5, 1.0, 100, 10.0)                      # 20 s in all: goes on
    fixed(0.01, 1.0, 100, 0.5)                      # the next run: elapsed starts again
    with pytest.raises(SceneError, match=r"analysis.dt: .* would take about unknown.*raise dt"):
        fixed(0.0, 1.0, 5, 10.0)                    # not advanced at all in 10 s


def test_a_run_past_the_budget_is_stopped_early_in_one_line(tmp_path, monkeypatch, capsys):
    """IDA on a 1e14 N/m spring with no step cap (a review measured it running 300 s with
    no word): stopped once its pilot shows the budget passed, one line, nothing written.
    The pilot and budget are shortened here (10 s and 1 h in martello run)."""
    from martello.cli import PaceLimit, main
    monkeypatch.setattr(PaceLimit, "PILOT_S", 0.5)
    monkeypatch.setattr(PaceLimit, "BUDGET_S", 30.0)
    d = {"node": [{"name": "m", "mass": 1.0, "u0": 0.01}],
         "link": [{"type": "spring", "a": "m", "b": "ground", "k": 1e14}],
         "analysis": {"type": "dynamic", "integrator": "ida", "dt": 1e-3, "t_end": 10.0}}
    t0 = time.perf_counter()
    assert main(["run", str(_write(tmp_path, d)), "-o", str(tmp_path / "o")]) == 1
    err = capsys.readouterr().err
    assert time.perf_counter() - t0 < 30, "not stopped early"
    assert "scene.toml: analysis.rtol: at its pace over its first" in err and "--force" in err
    assert len(err.strip().splitlines()) == 1 and not (tmp_path / "o").exists()


def test_a_slow_step_reports_at_once():
    """The library looks at the clock after every sample while samples come more than 1 ms
    apart (observer_watch's stride): msbdf on the 100-element P4 rod, whose first steps take
    around a second, reports within its first steps (it reported every 32)."""
    import tomllib
    scene = martello.load("p4/p4_equal_rods_rk8pd_restitution_e0.toml")
    d = tomllib.loads(open(scene.source).read().replace('integrator = "rk8pd"',
                                                        'integrator = "msbdf"'))
    d.pop("check", None)
    steps = []

    def reporter(t, t_end, n, elapsed):
        steps.append(n)
        if len(steps) == 3:
            raise KeyboardInterrupt
    with pytest.raises(KeyboardInterrupt), native.reporting(reporter):
        martello.run(d)
    assert steps[0] < 32 and steps == sorted(steps), steps
