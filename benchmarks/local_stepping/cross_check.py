"""Local stepping against the global run over the catalogue (docs/sundials-ode.md, "Local
stepping"): every dynamic catalogue scene on cvode, arkode or ida, run as written (the global run:
one integrator instance on the whole scene) and again with analysis.local_stepping = true (one
instance per cluster). Two kinds of evidence, said apart:

* CROSS-CHECK (the same kernels, not verification): every summary number and every history
  column of the local run against the global one, within the two runs' own errors: each run's
  error on a number is how much the number moves when its rtol, atol and event_tol are made 3
  and 10 times looser (the two are different discretisations: a cluster's error test weighs
  its own components only), their sum x 2, plus 100 rtol of its scale and the rounding
  (benchmarks/invariance/relations.py, the allowance of the output-invariance sweep,
  docs/invariance.md). A time of an extreme attained twice within
  that allowance is tied, not compared (relations.tied_times).
* VERIFICATION: the rows `martello check` makes of the scene (its closed form, the independent
  engine, or stored reference data, whose kind martello.checks.kinds says) for both runs:
  rows, rows passed, verification rows passed; none may be lost with local stepping.

A scene the option refuses (MARTELLO_ERR_UNSUPPORTED naming analysis.local_stepping: a rigid
contact, a mass coupling) is counted by its reason; any other stop of the local run is a
failure.

    .venv/bin/python benchmarks/local_stepping/cross_check.py -o /tmp/ls [--only p7/] [-j 2]

writes OUT/cross_check.json and prints one line per scene and the counts."""

from __future__ import annotations

import argparse
import copy
import json
import sys
import time
from collections import Counter
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from benchmarks.invariance import relations  # noqa: E402
from martello.checks import kinds  # noqa: E402
from martello.checks.independent_rows import verify_independent  # noqa: E402
from martello.checks.measures import run_measured  # noqa: E402
from martello.checks.reference_data import verify_reference_data  # noqa: E402
from martello.checks.verify import verify  # noqa: E402
from martello.errors import MartelloError  # noqa: E402
from martello.scene import catalogue  # noqa: E402
from martello.scene.loader import load  # noqa: E402


# the integrators that take analysis.local_stepping
LOCAL = ("cvode", "arkode", "ida")


def runs_locally(path):
    """A dynamic scene on an integrator of LOCAL run globally (the catalogue's local-stepping
    scenes are the local versions of such scenes: benchmarks/p7/local_stepping/)."""
    an = load(path).analysis
    return an["type"] == "dynamic" and an.get("integrator") in LOCAL and not an.get("local_stepping")


def local(data):
    d = copy.deepcopy(data)
    d["analysis"]["local_stepping"] = True
    return d


def history_error(data, base_dir, columns, rows):
    """The global run's own error on each history column: the largest distance of the column
    to the same run 3 and 10 times looser (relations.LOOSER), on the same output grid."""
    err = np.zeros(len(columns))
    for f in relations.LOOSER:
        _, cl, rl = relations.run(relations.loose_scene(data, f), base_dir)
        if cl != columns or rl.shape != rows.shape:
            return None
        with np.errstate(invalid="ignore"):
            err = np.fmax(err, np.nanmax(np.abs(rl - rows), axis=0, initial=0.0))
    return err


def history_mismatches(columns, base, other, err, rtol):
    """Columns of other farther from base than ADAPTIVE_FACTOR x the own errors plus
    GLOBAL_RTOL x rtol and the rounding of the column's scale: [(column, worst, allowed)]."""
    if other.shape != base.shape:
        return [("(rows)", f"{other.shape} vs {base.shape}", 0.0)]
    bad = []
    for i, c in enumerate(columns):
        if c == "t":
            if not np.array_equal(base[:, i], other[:, i]):
                bad.append((c, float(np.max(np.abs(base[:, i] - other[:, i]))), 0.0))
            continue
        scale = float(np.nanmax(np.abs(base[:, i]), initial=0.0))
        allowed = relations.ADAPTIVE_FACTOR * err[i] + \
            (relations.GLOBAL_RTOL * rtol + relations.ROUNDING) * scale
        diff = np.abs(base[:, i] - other[:, i])
        worst = float(np.nanmax(diff, initial=0.0))
        if worst > allowed or np.isnan(base[:, i]).sum() != np.isnan(other[:, i]).sum():
            bad.append((c, worst, float(allowed)))
    return bad


def check_rows(scene):
    """`martello check`'s rows of a loaded scene (martello.report.check_catalogue's): its
    closed form, the independent engine or the stored reference data."""
    summary, history = run_measured(scene)
    rows = verify(scene, summary) if scene.check is not None else []
    for r in rows:
        r.setdefault("evidence", kinds.CLOSED_FORM)
    if history is not None:
        rows += verify_independent(scene, summary, lambda sc: run_measured(sc)[0]) or \
            [dict(r, evidence="regression") for r in verify_reference_data(scene, summary, history)]
    kinds.classify(rows, scene.contacts)
    return {"rows": len(rows), "passed": sum(bool(r["passed"]) for r in rows),
            "verification": sum(r["kind"] == kinds.VERIFICATION for r in rows),
            "verification_passed": sum(r["kind"] == kinds.VERIFICATION and bool(r["passed"])
                                       for r in rows),
            "failed": [r["quantity"] for r in rows if kinds.failed(r)]}


def one(path, with_check=True):
    t0 = time.perf_counter()
    out = {"scene": str(Path(path).relative_to(catalogue.ROOT.parent))}
    data, base_dir = relations.read(path)
    base_data = relations.base_scene(data)
    try:
        s_loc, c_loc, r_loc = relations.run(local(base_data), base_dir)
        why = None if s_loc["status"] == "MARTELLO_OK" else f"{s_loc['status']}: {s_loc.get('message', '')}"
    except MartelloError as exc:
        why = f"{type(exc).__name__}: {exc}"
    if why is not None:
        # refused: what the option documents it does not take (MARTELLO_ERR_UNSUPPORTED,
        # naming analysis.local_stepping); any other stop is a failure of the local run
        refused = "UNSUPPORTED" in why and "local_stepping" in why
        out.update({"refused" if refused else "failed": why, "seconds": time.perf_counter() - t0})
        return out
    s_glob, c_glob, r_glob = relations.run(base_data, base_dir)
    base, other = relations.numbers(s_glob), relations.numbers(s_loc)
    error, rtol = relations.tolerance_error(data, base, base_dir)
    error_loc, _ = relations.tolerance_error(local(data), other, base_dir)
    error = {p: error.get(p, 0.0) + error_loc.get(p, 0.0) for p in set(error) | set(error_loc)}
    bad = relations.mismatches(base, other, error, rtol)
    bad, tied = relations.tied_times(base_dir, (base_data, local(base_data)), base, bad, error, rtol)
    lost = relations.missing(base, other)
    hist = []
    if c_loc != c_glob:
        hist = [("(columns)", f"{c_loc} vs {c_glob}", 0.0)]
    elif len(c_glob):
        herr = history_error(data, base_dir, c_glob, r_glob)
        herr_loc = history_error(local(data), base_dir, c_loc, r_loc)
        if herr is None or herr_loc is None:
            hist = [("(looser runs)", "another grid", 0.0)]
        else:
            hist = history_mismatches(c_glob, r_glob, r_loc, herr + herr_loc, rtol)
    out.update(summary_mismatches=[[p, repr(x), repr(y), a] for p, x, y, a in bad[:8]],
               n_summary_mismatches=len(bad), missing=lost[:8], tied=[t[0] for t in tied],
               history_mismatches=[list(h) for h in hist[:8]], n_history_mismatches=len(hist),
               steps=[s_glob["cost"].get("steps"), s_loc["cost"].get("steps")],
               numbers=len(base), columns=len(c_glob))
    if with_check:
        rows = {}
        for name, flag in (("global", False), ("local", True)):
            s = load(path)
            if flag:
                s.analysis["local_stepping"] = True
            rows[name] = check_rows(s)
        out["check"] = rows
    out["seconds"] = time.perf_counter() - t0
    return out


def report(results):
    refused, failed = Counter(), Counter()
    agree = disagree = 0
    rows = Counter()
    for r in results:
        if "failed" in r:
            failed[r["failed"].split(": ", 1)[-1][:90]] += 1
            print(f"FAILED {r['scene']}: {r['failed'][:200]}")
            continue
        if "refused" in r:
            # the reason without the scene's own names and numbers
            reason = r["refused"].split(": ", 1)[-1]
            reason = reason.split(" is rigid")[0].split("(")[0].strip()
            refused["rigid contact" if "rigid" in r["refused"] else
                    "mass coupling" if "coupl" in r["refused"] else reason[:60]] += 1
            continue
        bad = r["n_summary_mismatches"] or r["missing"] or r["n_history_mismatches"]
        agree += not bad
        disagree += bool(bad)
        if bad:
            worst = r["summary_mismatches"][:2] + r["history_mismatches"][:2]
            print(f"DIFFERS {r['scene']}: {worst} missing {r['missing'][:3]}")
        for name in ("global", "local"):
            for k, v in r.get("check", {}).get(name, {}).items():
                if k != "failed":
                    rows[name, k] += v
        lost = r.get("check") and r["check"]["local"]["verification_passed"] < \
            r["check"]["global"]["verification_passed"]
        if lost:
            print(f"LOST ROWS {r['scene']}: {r['check']}")
    print(f"\n{len(results)} scenes: {agree} agree with the global run (cross-check), "
          f"{disagree} differ, {sum(refused.values())} refused, {sum(failed.values())} failed")
    for why, n in refused.most_common():
        print(f"  refused ({n}): {why}")
    for why, n in failed.most_common():
        print(f"  failed ({n}): {why}")
    if rows:
        print(f"\n{'martello check rows':22s} {'rows':>6s} {'passed':>7s} {'verif.':>7s} {'verif. passed':>14s}")
        for name in ("global", "local"):
            print(f"{name:22s} {rows[name, 'rows']:6d} {rows[name, 'passed']:7d} "
                  f"{rows[name, 'verification']:7d} {rows[name, 'verification_passed']:14d}")
    return disagree + sum(failed.values())


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("-o", "--out", required=True, help="folder for cross_check.json")
    ap.add_argument("--only", nargs="*", default=[], help="scene paths containing one of these")
    ap.add_argument("-j", "--jobs", type=int, default=1)
    ap.add_argument("--no-check", action="store_true", help="the cross-check alone")
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    scenes = [p for p in catalogue.scene_files()
              if (not args.only or any(s in str(p) for s in args.only)) and runs_locally(p)]
    t0 = time.perf_counter()
    with ProcessPoolExecutor(args.jobs) as pool:
        results = list(pool.map(one, scenes, [not args.no_check] * len(scenes)))
    for r in results:
        state = "failed" if "failed" in r else "refused" if "refused" in r else \
            ("differs" if r["n_summary_mismatches"] or r["missing"] or r["n_history_mismatches"]
             else "agrees")
        print(f"{r['scene']:60s} {state:8s} {r['seconds']:6.1f} s")
    differ = report(results)
    print(f"{time.perf_counter() - t0:.0f} s")
    (out / "cross_check.json").write_text(json.dumps(results, indent=1))
    return 1 if differ else 0


if __name__ == "__main__":
    sys.exit(main())
