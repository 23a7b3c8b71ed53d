"""Runs of scene specs on the local cores: a spec is a scene dict with its source (and an id),
run in a worker process; results come back as they finish. Studies, the atlas and the
reference builder run their sweeps through here."""

from __future__ import annotations

import os
import signal
import time
from collections import deque
from contextlib import contextmanager
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path

import numpy as np

from .binding.system import die_with_parent
from .errors import Interrupted, MartelloError, SceneError
from .run import run_full
from .scene.loader import from_dict


def execute(spec):
    """Run one spec in this process (a worker): returns the status, the summary parts the
    metrics need and the history. Never raises for a failed run."""
    out = {"id": spec["id"]}
    try:
        s = from_dict(spec["scene_dict"], source=spec["scene_file"],
                      base_dir=Path(spec["base_dir"]))
    except SceneError as exc:
        return out | {"status": "incompatible", "message": str(exc)}
    try:
        walls = []
        for _ in range(max(1, spec.get("repeat", 1))):
            summary, history = run_full(s, raise_on_failure=False)
            walls.append(summary["cost"]["wall_time_s"])
        summary["cost"]["wall_time_s"] = min(walls)
    except Interrupted:
        raise                     # stopped by its user: no outcome of the run
    except MartelloError as exc:
        return out | {"status": "error", "message": str(exc)}
    keep = {k: summary.get(k) for k in ("status", "message", "t_reached", "contacts", "energy",
                                        "cost", "stability", "provenance", "nodes")}
    return out | {"status": summary["status"], "message": summary.get("message", ""),
                  "summary": keep, "history": (history[0], np.asarray(history[1]))}


# How many times a spec whose worker died is run again, each time alone in a process of its
# own, before its row is marked failed with the reason.
RETRIES = 2
# How often (s) a sweep waiting for its runs looks whether it was asked to stop.
POLL_S = 0.2


def _worker_start(parent):
    """Every worker process, first: it ends with its parent (martello.binding.system: a
    sweep whose process is killed leaves no worker behind); it ignores SIGINT, which a
    Ctrl-C at a terminal sends to the whole process group: stopping is the parent's to
    decide (it keeps the finished rows, then ends the workers)."""
    die_with_parent(parent)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    # a forked worker has its parent's handlers: SIGTERM (how a pool ends a worker, and what
    # a group's SIGTERM brings) ends it as it ends any process. Both signals were blocked
    # while it was forked (_held): one sent before this line waits, and takes effect now.
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    signal.pthread_sigmask(signal.SIG_UNBLOCK, _HELD)


_HELD = {signal.SIGINT, signal.SIGTERM}


@contextmanager
def _held():
    """SIGINT and SIGTERM held (blocked, not lost) in this thread within the block: a worker
    forked there starts with them blocked, so that neither reaches it before _worker_start
    has replaced the handlers it inherited (a study's, which would keep it alive)."""
    old = signal.pthread_sigmask(signal.SIG_BLOCK, _HELD)
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, old)


def _pool(workers):
    return ProcessPoolExecutor(max_workers=workers, initializer=_worker_start,
                               initargs=(os.getpid(),))


def _processes(pool):
    """The worker processes a pool has started (private to concurrent.futures: best effort)."""
    return list((getattr(pool, "_processes", None) or {}).values())


def _end(pool):
    """End a pool now: its workers are killed, whatever they run (a sweep that was asked to
    stop does not wait for runs of minutes to finish), and reaped.

    A worker killed while it sends a result leaves half a message in the pool's result pipe;
    the pool's thread reading it would wait for the rest for ever, and the interpreter joins
    that thread at exit (a study that said "interrupted" and never ended). Once the workers
    are gone, this process's copy of the pipe's writing end is closed: the reader then meets
    the end of the pipe, the pool is broken, and its thread ends (private to
    concurrent.futures: best effort, as _processes)."""
    procs = _processes(pool)
    results = getattr(pool, "_result_queue", None)
    for p in procs:
        try:
            p.kill()
        except (OSError, ValueError):     # already gone, or closed
            pass
    pool.shutdown(wait=False, cancel_futures=True)
    for p in procs:
        try:
            p.join(2.0)
        except (OSError, ValueError, AssertionError):
            pass
    writer = getattr(results, "_writer", None)
    if writer is not None and all(p.exitcode is not None for p in procs):
        try:
            writer.close()
        except OSError:
            pass


def _death(processes):
    """Why a worker died, from the exit codes of a pool's processes (best effort). The pool
    fails its futures before it reaps its processes, and it ends the survivors with SIGTERM:
    wait for the exit codes a moment, and name another signal first."""
    deadline = time.monotonic() + 2.0
    for p in processes:
        # the pool's own thread may be reaping it: its exit code appears when it is done
        while p.exitcode is None and time.monotonic() < deadline:
            time.sleep(0.01)
    codes = [p.exitcode for p in processes if p.exitcode not in (None, 0)]
    codes.sort(key=lambda c: c == -signal.SIGTERM)
    for c in codes:
        if c < 0:
            try:
                name = signal.Signals(-c).name
            except ValueError:
                name = f"signal {-c}"
            hint = " (kill -9, or the out-of-memory killer)" if -c == signal.SIGKILL else ""
            return f"killed by {name}{hint}"
    return f"exit code {codes[0]}" if codes else "ended abruptly"


def run_specs(specs, jobs=0, progress=None, *, fn=None, retries=RETRIES, executor=None,
              stop=None):
    """Run specs in worker processes (ProcessPoolExecutor), or on `executor` (any
    concurrent.futures executor, e.g. a Dask cluster's: martello.study.cluster, which
    reschedules the work of a lost worker itself); yield results as they finish. Specs with
    a precomputed status (incompatible combinations) are not run.

    Every run is in a worker process, even with jobs = 1: the calling process stays free to
    answer a Ctrl-C at once (a native run holds its thread until the run looks at the
    clock), and a run that crashes takes only its worker. The workers end with the calling
    process, however it ends (_worker_start).

    A worker that dies (killed, out of memory, a crash in the native library) breaks its
    pool and fails every spec running in it. Those specs are run again, each alone in a
    process of its own, so the one that kills its worker is found and the others finish;
    one whose worker still dies after `retries` further runs gives a row with status
    "error" and the reason. Specs not yet started go to a fresh pool. Every spec gives a
    row, unless `stop` (a threading.Event) is set: then the results already finished are
    yielded, the runs in flight are ended (their workers killed, a cluster's futures
    cancelled) and the generator returns without the others, within about POLL_S. `fn` runs
    one spec (default: execute)."""
    fn = fn or execute
    todo = [s for s in specs if "status" not in s]
    for s in specs:
        if "status" in s:
            if progress:
                progress.update(False, not_run=True)
            yield dict(s)
    jobs = jobs or os.cpu_count() or 1
    stopped = stop.is_set if stop is not None else (lambda: False)

    def done(r):
        if progress:
            progress.update(r["status"] == "MARTELLO_OK")
        return r

    if executor is not None:
        futs = {executor.submit(fn, s): s for s in todo}
        pending = set(futs)
        try:
            while pending and not stopped():
                finished, pending = wait(pending, timeout=POLL_S, return_when=FIRST_COMPLETED)
                for f in finished:
                    try:
                        r = f.result()
                    except Exception as exc:      # the cluster gave up on the case: keep the row
                        r = {"id": futs[f]["id"], "status": "error",
                             "message": f"worker failed: {exc!r}"}
                    yield done(r)
        finally:
            for f in pending:
                f.cancel()
        return
    waiting = deque(todo)          # not started
    alone = deque()                # to run again, each in a process of its own
    deaths = {}                    # spec id -> worker deaths while it ran
    running = {}                   # future -> (spec, pool, alone?)
    workers = {}                   # pool -> its processes, for the exit codes
    shared = None
    complete = False
    try:
        while (waiting or alone or running) and not stopped():
            with _held():                     # submit() forks the workers
                while alone and len(running) < jobs:
                    s = alone.popleft()
                    pool = _pool(1)
                    running[pool.submit(fn, s)] = (s, pool, True)
                    workers[pool] = _processes(pool)
                while waiting and len(running) < jobs:
                    shared = shared or _pool(jobs)
                    s = waiting.popleft()
                    try:
                        running[shared.submit(fn, s)] = (s, shared, False)
                        known = workers.setdefault(shared, [])
                        known += [p for p in _processes(shared) if p not in known]
                    except BrokenProcessPool:     # broke since its last result: a fresh one
                        waiting.appendleft(s)
                        shared.shutdown(wait=False, cancel_futures=True)
                        shared = None
            finished, _ = wait(running, timeout=POLL_S, return_when=FIRST_COMPLETED)
            for f in finished:
                s, pool, isolated = running.pop(f)
                try:
                    r = f.result()
                except BrokenProcessPool:
                    if stopped():             # ended by the stop, not by its run
                        continue
                    deaths[s["id"]] = deaths.get(s["id"], 0) + 1
                    why = _death(workers.get(pool, []))
                    pool.shutdown(wait=False)
                    if pool is shared:
                        shared = None         # the specs not started go to a fresh pool
                    if deaths[s["id"]] <= retries:
                        alone.append(s)
                        continue
                    r = {"id": s["id"], "status": "error",
                         "message": f"worker process died running this case, "
                                    f"{deaths[s['id']]} times ({why})"}
                except Exception as exc:      # e.g. a result that cannot be pickled
                    r = {"id": s["id"], "status": "error", "message": f"worker failed: {exc!r}"}
                if isolated:
                    pool.shutdown(wait=False)
                    workers.pop(pool, None)
                yield done(r)
        complete = not (waiting or alone or running)
    finally:
        pools = {id(p): p for _, p, _ in running.values()}
        if shared is not None:
            pools[id(shared)] = shared
        for pool in pools.values():
            if complete:
                pool.shutdown(wait=True)
            else:                 # stopped, or the caller went away: nothing to wait for
                _end(pool)
