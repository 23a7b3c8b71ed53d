"""Measure that a study survives its user (docs/studies.md, "Stop and resume"), on a real study:

1. the study run once, uninterrupted (its rows are the yardstick, its duration the estimate);
2. the same study interrupted N times (SIGINT to the process group, what a terminal's Ctrl-C
   sends) and resumed by the same command each time: how long each stop took, the exit code,
   whether any process of the group outlived it, the rows kept; then the last run to the end,
   and its rows against the uninterrupted ones (every column but the measured wall time; the
   kept rows' wall times must stay bit for bit, which shows they were not run again);
3. SIGTERM, then SIGKILL, of the main process alone (a scheduler, the out-of-memory killer, a
   user's `kill PID`): how long until no process of the group is alive, and which temporary
   folders are left beside -o (SIGKILL leaves one, its journal, which the next run takes and
   removes: measured too).

    python benchmarks/studies/interrupt_resume.py benchmarks/studies/p7_two_oscillators.toml \
        -j 1 -o /tmp/resume_bench

Writes only under -o. Prints a progress line per step with an estimate of what is left."""

from __future__ import annotations

import argparse
import csv
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
TIMED = {"wall_time_s"}          # measured, not computed: differs from run to run


def say(text):
    print(text, flush=True)


def start(study, out, jobs):
    return subprocess.Popen([sys.executable, "-m", "martello", "study", str(study), "-o", str(out),
                             "-j", str(jobs), "--no-plots"], cwd=ROOT, stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True, start_new_session=True)


def temporaries(out):
    return sorted(out.parent.glob(f".{out.name}.*.tmp"))


def journal_rows(out):
    n = 0
    for tmp in temporaries(out):
        try:
            n = max(n, len((tmp / "resume.jsonl").read_text().splitlines()) - 1)
        except OSError:
            pass
    return n


def group_alive(pgid):
    try:
        os.killpg(pgid, 0)
        return True
    except ProcessLookupError:
        return False


def seconds_to_die(pgid, limit=30.0):
    """Seconds until no process of the group is alive (None: still alive after limit)."""
    t0 = time.monotonic()
    while group_alive(pgid):
        if time.monotonic() - t0 > limit:
            return None
        time.sleep(0.01)
    return time.monotonic() - t0


def rows(path):
    with open(path, newline="") as fh:
        return list(csv.DictReader(fh))


def wait_rows(proc, out, k):
    while journal_rows(out) < k:
        if proc.poll() is not None:
            raise SystemExit(f"the study ended before {k} rows: {proc.communicate()[1]}")
        time.sleep(0.02)


def differing(a, b, skip=()):
    """Columns where two rows of runs.csv files differ (a column only one file has reads as
    empty in the other: a partial output lacks the columns of rows it does not hold)."""
    return sorted(k for k in set(a) | set(b) if k not in skip and a.get(k, "") != b.get(k, ""))


def last_line(text):
    lines = text.strip().splitlines()
    return lines[-1] if lines else ""


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("study", type=Path)
    ap.add_argument("-o", "--out", type=Path, required=True, help="folder for the outputs")
    ap.add_argument("-j", "--jobs", type=int, default=1)
    ap.add_argument("--interrupts", type=int, default=3)
    ap.add_argument("--reuse-whole", action="store_true",
                    help="take the uninterrupted run from -o/whole when it is there")
    a = ap.parse_args(argv)
    a.out.mkdir(parents=True, exist_ok=True)
    study = a.study.resolve()
    failures = []

    say(f"[1/3] uninterrupted run of {a.study} (-j {a.jobs})")
    t0 = time.monotonic()
    if a.reuse_whole and (a.out / "whole" / "runs.csv").is_file():
        whole = rows(a.out / "whole" / "runs.csv")
        whole_s = sum(float(r["wall_time_s"] or 0) for r in whole)
        say(f"      reused {a.out / 'whole'} (its runs' own times: {whole_s:.0f} s)")
    else:
        p = start(study, a.out / "whole", a.jobs)
        _, err = p.communicate()
        whole_s = time.monotonic() - t0
        if p.returncode != 0:
            raise SystemExit(f"the uninterrupted study failed ({p.returncode}): {err}")
        whole = rows(a.out / "whole" / "runs.csv")
    n = len(whole)
    say(f"      {n} runs in {whole_s:.1f} s; the rest takes about {2 * whole_s:.0f} s")

    say(f"[2/3] {a.interrupts} interrupts (SIGINT to the process group) and resumes")
    out = a.out / "interrupted"
    kept, t_all = {}, time.monotonic()
    for i in range(a.interrupts):
        # stop after a share of the remaining rows, so that every stop finds runs in flight
        target = len(kept) + max(1, (n - len(kept)) // (a.interrupts + 1 - i))
        p = start(study, out, a.jobs)
        wait_rows(p, out, min(target, n - 1))
        t1 = time.monotonic()
        os.killpg(p.pid, signal.SIGINT)
        _, err = p.communicate()
        stopped = time.monotonic() - t1
        left = seconds_to_die(p.pid, 5.0)
        part = rows(out / "runs.csv")
        changed = [r["run"] for r in part if r["run"] in kept and differing(r, kept[r["run"]])]
        say(f"      interrupt {i + 1}: exit {p.returncode} after {stopped:.2f} s, "
            f"{len(part)} of {n} rows kept, group alive after: {'no' if left is not None else 'YES'}, "
            f"kept rows changed: {len(changed)}; last line: {last_line(err)}")
        if p.returncode != 130 or left is None or changed or "Traceback" in err:
            failures.append(f"interrupt {i + 1}")
        kept = {r["run"]: r for r in part}
        done = time.monotonic() - t_all
        say(f"      {done:.0f} s so far in this step; about {whole_s * (1 - len(kept) / n):.0f} s "
            "of runs left")
    p = start(study, out, a.jobs)
    _, err = p.communicate()
    final = rows(out / "runs.csv")
    resumed = [ln for ln in err.splitlines() if ln.startswith("resuming")]
    order = [r["run"] for r in final] == [str(k) for k in range(n)]
    diff = [(b["run"], k) for b, c in zip(final, whole) for k in differing(b, c, TIMED)]
    rerun = [r["run"] for r in final if r["run"] in kept and differing(r, kept[r["run"]])]
    say(f"      resumed: exit {p.returncode}; {resumed[0] if resumed else 'no resume line'}")
    say(f"      rows: {len(final)} of {n}, each once in order: {order}; columns differing from "
        f"the uninterrupted run (all but {sorted(TIMED)}): {len(diff)}; kept rows run again: "
        f"{len(rerun)}; temporaries left: {len(temporaries(out))}")
    if p.returncode != 0 or not order or diff or rerun or temporaries(out):
        failures.append("resume")

    say("[3/3] SIGTERM, then SIGKILL, of the main process alone")
    for sig in (signal.SIGTERM, signal.SIGKILL):
        out = a.out / f"main_{sig.name.lower()}"
        p = start(study, out, a.jobs)
        wait_rows(p, out, max(1, n // 4))
        p.send_signal(sig)
        _, err = p.communicate()
        gone = seconds_to_die(p.pid)
        tmps = temporaries(out)
        say(f"      {sig.name}: exit {p.returncode}, no process of the group alive after "
            f"{gone:.2f} s" if gone is not None else f"      {sig.name}: GROUP STILL ALIVE after 30 s")
        say(f"      temporaries beside -o: {len(tmps)}; last line: {last_line(err) or '(none)'}")
        if gone is None or gone > 5 or (sig == signal.SIGTERM and (tmps or p.returncode != 130)):
            failures.append(sig.name)
        if sig == signal.SIGKILL:
            journaled = journal_rows(out)
            p = start(study, out, a.jobs)
            _, err = p.communicate()
            resumed = [ln for ln in err.splitlines() if ln.startswith("resuming")]
            after = temporaries(out)
            say(f"      next run: exit {p.returncode}, {journaled} journaled rows; "
                f"{resumed[0] if resumed else 'no resume line'}; temporaries left: {len(after)}")
            if p.returncode != 0 or after or len(rows(out / "runs.csv")) != n:
                failures.append("resume after SIGKILL")
    say("all as it must be" if not failures else f"FAILED: {', '.join(failures)}")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
