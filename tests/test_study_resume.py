"""Studies that stop when asked and resume (martello.study.resume, martello.batch): SIGINT or
SIGTERM, to the process group or to the main process, stops a study within seconds with exit
130 and one line, keeps the finished rows in -o marked partial, and the same command runs
only the others; the rows of a study interrupted three times and resumed are those of an
uninterrupted run. A study's main process killed outright leaves no worker alive, and the
next run of the command takes the rows its journal kept and removes its temporary folder."""

import csv
import json
import os
import signal
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from martello.batch import run_specs
from martello.paths import folder_replaced, stale_temporaries

ROOT = Path(__file__).resolve().parent.parent
P2 = ROOT / "benchmarks" / "p2"

# 3 integrators x 12 steps = 36 runs of P2 to t = 2 s, 0.05 to 0.5 s each here: long enough
# for a signal to find runs in flight, short enough for a test
STUDY = f"""
title = "resumable P2 study"
[compare]
histories = ["u:mass"]
points = 701
[[scene]]
file = "{P2 / 'p2_penalty_linear.toml'}"
label = "linear"
t_end = 2.0
reference = {{ closed_form = "bouncing_oscillator_kelvin", params = {{ m = 1.0, k = 100.0, h = 0.05, g = 9.81, eps = 1.0e6 }} }}
[[integrator]]
name = "newmark"
params = {{ preset = "average-acceleration" }}
dt = {{ from = 1e-4, to = 1e-5, per_decade = 11 }}
[[integrator]]
name = "central-difference"
dt = {{ from = 1e-4, to = 1e-5, per_decade = 11 }}
[[integrator]]
name = "hht"
params = {{ alpha = -0.1 }}
dt = {{ from = 1e-4, to = 1e-5, per_decade = 11 }}
"""
RUNS = 36
TIMED = {"wall_time_s"}          # measured, not computed: differs from run to run


def start(study, out, *extra):
    return subprocess.Popen([sys.executable, "-m", "martello", "study", str(study), "-o", str(out),
                             "-j", "2", "--no-plots", *extra], cwd=ROOT, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True)


def journal_rows(out):
    """Rows journaled so far by the study writing to out (its temporary folder)."""
    n = 0
    for tmp in out.parent.glob(f".{out.name}.*.tmp"):
        try:
            n = max(n, len((tmp / "resume.jsonl").read_text().splitlines()) - 1)
        except OSError:
            pass
    return n


def wait_rows(proc, out, k, timeout=120):
    t0 = time.monotonic()
    while journal_rows(out) < k:
        assert proc.poll() is None, proc.communicate()
        assert time.monotonic() - t0 < timeout, "no rows"
        time.sleep(0.02)


def rows(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def same(a, b):
    """Two rows of runs.csv files are the same (a column only one file has is empty)."""
    return all(a.get(k, "") == b.get(k, "") for k in set(a) | set(b))


def group_alive(pgid):
    try:
        os.killpg(pgid, 0)
        return True
    except ProcessLookupError:
        return False


@pytest.fixture(scope="module")
def uninterrupted(tmp_path_factory):
    folder = tmp_path_factory.mktemp("whole")
    study = folder / "s.toml"
    study.write_text(STUDY)
    p = start(study, folder / "out")
    _, err = p.communicate(timeout=600)
    assert p.returncode == 0, err
    return rows(folder / "out" / "runs.csv")


def test_interrupted_three_times_and_resumed_the_rows_are_those_of_an_uninterrupted_run(
        tmp_path, uninterrupted):
    study, out = tmp_path / "s.toml", tmp_path / "out"
    study.write_text(STUDY)
    kept = {}                              # run -> its row in a partial output
    how = [("SIGINT to the group", lambda p: os.killpg(p.pid, signal.SIGINT)),
           ("SIGTERM to the main process", lambda p: p.send_signal(signal.SIGTERM)),
           ("SIGTERM to the group", lambda p: os.killpg(p.pid, signal.SIGTERM))]
    for i, (what, send) in enumerate(how):
        p = start(study, out)
        wait_rows(p, out, len(kept) + 4)
        t0 = time.monotonic()
        send(p)
        _, err = p.communicate(timeout=60)
        stopped = time.monotonic() - t0
        assert p.returncode == 130, (what, err)
        assert stopped < 5, (what, stopped)
        last = err.strip().splitlines()[-1]
        assert last.startswith("martello: interrupted (SIG") and "marked partial" in last, err
        assert "Traceback" not in err and "error" not in err, err
        part = rows(out / "runs.csv")
        assert len(part) > len(kept) and (out / "resume.jsonl").is_file(), what
        assert "**Partial:" in (out / "study.md").read_text()
        assert not group_alive(p.pid), f"{what}: a process of the study is still alive"
        # a kept row is never run again: its measured wall time stays the same, bit for bit
        for r in part:
            if r["run"] in kept:
                assert same(r, kept[r["run"]]), (what, r["run"])
        kept = {r["run"]: r for r in part}
        if i:
            assert f"resuming: {len(kept_before)} of {RUNS} runs kept" in err
        kept_before = dict(kept)
    p = start(study, out)
    _, err = p.communicate(timeout=600)
    assert p.returncode == 0, err
    assert f"resuming: {len(kept)} of {RUNS} runs kept" in err
    final = rows(out / "runs.csv")
    assert [r["run"] for r in final] == [str(i) for i in range(RUNS)]     # each once
    assert not (out / "resume.jsonl").exists() and "Partial" not in (out / "study.md").read_text()
    for r in final:
        if r["run"] in kept:
            assert same(r, kept[r["run"]]), r["run"]
    assert list(final[0]) == list(uninterrupted[0])
    for a, b in zip(final, uninterrupted):
        diff = {k: (a[k], b[k]) for k in a if k not in TIMED and a[k] != b[k]}
        assert not diff, f"run {a['run']}: {diff}"
    assert not list(tmp_path.glob(".out.*"))


def test_a_killed_study_leaves_no_process_and_its_rows_are_resumed(tmp_path):
    """SIGKILL of the main process (as by the out-of-memory killer): its workers end with it
    (parent-death signal, or their watchdog); the next run of the command takes the rows its
    journal holds from the temporary folder left behind, and removes that folder."""
    study, out = tmp_path / "s.toml", tmp_path / "out"
    study.write_text(STUDY)
    p = start(study, out)
    wait_rows(p, out, 6)
    p.kill()
    p.communicate(timeout=60)
    t0 = time.monotonic()
    while group_alive(p.pid) and time.monotonic() - t0 < 5:
        time.sleep(0.05)
    assert not group_alive(p.pid), "a worker outlived its study by 5 s"
    left = list(tmp_path.glob(".out.*.tmp"))
    assert len(left) == 1 and not out.exists()
    journaled = len((left[0] / "resume.jsonl").read_text().splitlines()) - 1
    p = start(study, out)
    _, err = p.communicate(timeout=600)
    assert p.returncode == 0, err
    assert f"resuming: {journaled} of {RUNS} runs kept" in err
    assert len(rows(out / "runs.csv")) == RUNS and not list(tmp_path.glob(".out.*"))


def sleeper(spec):
    time.sleep(0.05 if spec["id"] < 4 else 600)
    return {"id": spec["id"], "status": "MARTELLO_OK", "message": ""}


def test_a_stopped_sweep_yields_what_finished_and_ends_the_runs_in_flight():
    stop = threading.Event()
    specs = [{"id": i} for i in range(8)]
    got, t0 = [], time.monotonic()
    for r in run_specs(specs, jobs=2, fn=sleeper, stop=stop):
        got.append(r["id"])
        if len(got) == 4:
            stop.set()
    assert sorted(got) == [0, 1, 2, 3]
    assert time.monotonic() - t0 < 20            # the 600 s runs were ended, not waited for


# A sweep stopped while a worker is half way through sending its result (a long history
# under load): the worker writes a message's header and 16 of its bytes, then runs on; the
# sweep is stopped, its workers killed. The script must end: the pool's thread, left reading
# a message that never completes, was joined at exit for ever.
HALF_SENT = """
import os, struct, sys, threading, time
from martello.batch import run_specs
marker = sys.argv[1]

def half_sent(spec):
    if spec["id"] == 1:
        f = sys._getframe()
        while f.f_code.co_name != "_process_worker":      # concurrent.futures' worker loop
            f = f.f_back
        os.write(f.f_locals["result_queue"]._writer.fileno(), struct.pack("!i", 1 << 20) + bytes(16))
        open(marker, "w").close()
        time.sleep(600)
    return {"id": spec["id"], "status": "MARTELLO_OK", "message": ""}

stop = threading.Event()

def stop_once_half_sent():
    while not os.path.exists(marker):
        time.sleep(0.01)
    stop.set()

threading.Thread(target=stop_once_half_sent, daemon=True).start()
print([r["id"] for r in run_specs([{"id": 0}, {"id": 1}], jobs=1, fn=half_sent, stop=stop)])
"""


def test_a_sweep_stopped_while_a_result_is_half_sent_ends(tmp_path):
    p = subprocess.Popen([sys.executable, "-c", HALF_SENT, str(tmp_path / "half_sent")], cwd=ROOT,
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                         start_new_session=True)
    try:
        out, err = p.communicate(timeout=60)     # it ends within a second or two; else it hangs
    except subprocess.TimeoutExpired:
        os.killpg(p.pid, signal.SIGKILL)
        p.communicate()
        pytest.fail("the stopped sweep never ended (its pool's thread waits for the rest of a "
                    "message from a killed worker)")
    assert p.returncode == 0 and out.strip() == "[0]", (p.returncode, out, err)
    assert not group_alive(p.pid)


def test_a_temporary_folder_is_cleaned_only_once_its_writer_is_gone(tmp_path):
    out = tmp_path / "out"
    dead = tmp_path / ".out.abc.tmp"
    dead.mkdir()
    (dead / "half.csv").write_text("x")
    with folder_replaced(out, "marker", RuntimeError) as tmp:
        assert not dead.exists()                         # nobody held it
        assert stale_temporaries(out) == []              # ours is held while we write
        code = f"from martello.paths import stale_temporaries as s; print(len(s({str(out)!r})))"
        r = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True)
        assert r.stdout.strip() == "0", r.stderr        # another process sees it held too
        (tmp / "marker").write_text("done")
    assert (out / "marker").read_text() == "done" and not list(tmp_path.glob(".out.*"))
