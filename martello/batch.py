"""Runs of scene specs on the local cores: a spec is a scene dict with its source (and an id),
run in a worker process; results come back as they finish. Studies, the atlas and the
reference builder run their sweeps through here."""

from __future__ import annotations

import os
from concurrent.futures import ProcessPoolExecutor, as_completed
from contextlib import nullcontext
from pathlib import Path

import numpy as np

from .errors import MartelloError, SceneError
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
    except MartelloError as exc:
        return out | {"status": "error", "message": str(exc)}
    keep = {k: summary.get(k) for k in ("status", "message", "t_reached", "contacts", "energy",
                                        "cost", "stability", "provenance", "nodes")}
    return out | {"status": summary["status"], "message": summary.get("message", ""),
                  "summary": keep, "history": (history[0], np.asarray(history[1]))}


def run_specs(specs, jobs=0, progress=None, executor=None):
    """Run specs in worker processes (ProcessPoolExecutor), or on `executor` (any
    concurrent.futures executor, e.g. a Dask cluster's: martello.study.cluster); yield
    results as they finish. Specs with a precomputed status (incompatible combinations) are
    not run."""
    todo = [s for s in specs if "status" not in s]
    for s in specs:
        if "status" in s:
            if progress:
                progress.update(False)
            yield dict(s)
    jobs = jobs or os.cpu_count() or 1
    if executor is None and (jobs == 1 or len(todo) <= 1):
        for s in todo:
            r = execute(s)
            if progress:
                progress.update(r["status"] == "MARTELLO_OK")
            yield r
        return
    with (ProcessPoolExecutor(max_workers=jobs) if executor is None else nullcontext(executor)) as pool:
        futs = [pool.submit(execute, s) for s in todo]
        for f in as_completed(futs):
            try:
                r = f.result()
            except Exception as exc:             # a worker died: keep the row
                r = {"id": todo[futs.index(f)]["id"], "status": "error",
                     "message": f"worker failed: {exc!r}"}
            if progress:
                progress.update(r["status"] == "MARTELLO_OK")
            yield r
