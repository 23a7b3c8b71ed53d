"""Studies on a Dask cluster (docs/studies.md#on-a-dask-cluster): the same study run on local
processes and on a Dask LocalCluster gives the same rows (every column but the measured wall
time), and a scheduler that does not answer is one clear error."""

import csv
import subprocess
import sys
import time
from pathlib import Path

import pytest

from martello.cli import main
from martello.errors import MartelloError
from martello.study.cluster import dask_executor
from tests.test_study import TINY

ROOT = Path(__file__).resolve().parent.parent

# tests/test_study.py's P2 study (two contact schemes, Newmark, and central difference with
# a run beyond its stability limit) plus an adaptive integrator: every kind of row.
STUDY = TINY + """
[[integrator]]
name = "rk8pd"
dt = 1e-3
rtol = [1e-6, 1e-8, 1e-10]
"""

# Starts a LocalCluster of two worker processes (one thread each, as docs/studies.md asks of
# real workers) and runs the study on it through the command line, the cluster named by the
# study file's own `scheduler` key (written at the top of a copy of it), which the command
# line must allow (--use-study-scheduler).
DASK_RUN = """
import sys, time
from pathlib import Path
from distributed import LocalCluster
from martello.cli import main
if __name__ == "__main__":
    t0 = time.perf_counter()
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=":0") as cluster:
        t1 = time.perf_counter()
        study = Path(sys.argv[1]).with_name("on_dask.toml")
        study.write_text(f'scheduler = "{cluster.scheduler_address}"\\n' + Path(sys.argv[1]).read_text())
        rc = main(["study", str(study), "-o", sys.argv[2], "--use-study-scheduler"])
        print(f"cluster start {t1 - t0:.1f} s, study {time.perf_counter() - t1:.1f} s")
    sys.exit(rc)
"""

# Measured, not compared: the wall time of a run depends on the machine and its load.
TIMED = {"wall_time_s"}


def rows(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def test_dask_study_equals_the_local_study_row_for_row(tmp_path):
    study = tmp_path / "study.toml"
    study.write_text(STUDY)
    t0 = time.perf_counter()
    assert main(["study", str(study), "-o", str(tmp_path / "local"), "-j", "2"]) == 0
    local_s = time.perf_counter() - t0
    script = tmp_path / "dask_run.py"
    script.write_text(DASK_RUN)
    # bounded: a cluster that hangs fails the test instead of blocking the suite
    r = subprocess.run([sys.executable, str(script), str(study), str(tmp_path / "dask")], cwd=ROOT,
                       capture_output=True, text=True, timeout=240)
    assert r.returncode == 0, r.stderr[-3000:]
    assert "runs on the Dask cluster at tcp://127.0.0.1:" in r.stderr and "2 worker(s))" in r.stderr
    assert "on_dask.toml, used by --use-study-scheduler" in r.stderr
    a, b = rows(tmp_path / "local" / "runs.csv"), rows(tmp_path / "dask" / "runs.csv")
    assert len(a) == len(b) == 16
    assert list(a[0]) == list(b[0])                   # the same columns, in the same order
    for ra, rb in zip(a, b):
        diff = {k: (ra[k], rb[k]) for k in ra if k not in TIMED and ra[k] != rb[k]}
        assert not diff, f"run {ra['run']}: {diff}"
    # every kind of outcome went through the cluster, not only successes
    assert {r["classification"] for r in b} >= {"ok", "incompatible"}
    assert any(r["classification"] not in ("ok", "incompatible") for r in b)
    assert all(r["wall_time_s"] for r in b if r["classification"] == "ok")
    print(f"local study {local_s:.1f} s; {r.stdout.strip()}")


def test_a_scheduler_that_does_not_answer_is_one_error_saying_where_the_address_came_from():
    # port 9 (discard) on the loopback: nothing listens there
    t0 = time.perf_counter()
    with pytest.raises(MartelloError, match=r"the Dask scheduler tcp://127.0.0.1:9 \(given by "
                                            r"--scheduler\): no Dask scheduler answers there .*"
                                            r"start one with `dask scheduler`"):
        with dask_executor("tcp://127.0.0.1:9", timeout=2):
            pass
    assert time.perf_counter() - t0 < 30
    with pytest.raises(MartelloError, match=r"tcp://127.0.0.1:9 \(the scheduler of s.toml, used "
                                            r"by --use-study-scheduler\): no Dask scheduler"):
        with dask_executor("tcp://127.0.0.1:9", "the scheduler of s.toml, used by "
                           "--use-study-scheduler", timeout=2):
            pass


def test_a_study_file_does_not_choose_the_machine_its_runs_go_to(tmp_path, capsys):
    """A study file's `scheduler` is not used unless the command line says so: the study runs
    on local processes (nothing listens at port 9: connecting there would fail) and a note
    says why."""
    study = tmp_path / "s.toml"
    study.write_text('scheduler = "tcp://127.0.0.1:9"\n' + TINY)
    assert main(["study", str(study), "-o", str(tmp_path / "out"), "-j", "2", "--no-plots"]) == 0
    err = capsys.readouterr().err
    assert (f"note: {study} names a Dask scheduler (scheduler = 'tcp://127.0.0.1:9'), not used: "
            "the runs go to local processes (--use-study-scheduler runs them there)") in err
    assert "worker(s)" in err and "Dask cluster" not in err
    t0 = time.perf_counter()
    rc = main(["study", str(study), "-o", str(tmp_path / "out2"), "--use-study-scheduler"])
    assert rc == 1 and "tcp://127.0.0.1:9 (the scheduler of" in capsys.readouterr().err
    assert not (tmp_path / "out2").exists()


def test_the_atlas_refuses_a_scheduler(capsys):
    rc = main(["study", str(ROOT / "benchmarks" / "studies" / "atlas.toml"), "--scheduler",
               "tcp://127.0.0.1:9"])
    err = capsys.readouterr().err
    assert rc == 1 and "a stability atlas runs on the local cores" in err and "drop --scheduler" in err
