#!/usr/bin/env python3
"""The fuzz campaign: N command-line runs of martello on hostile inputs (mutated catalogue
scenes, records, histories, check tables, study files and command lines; mutations.py),
each `python -m martello ...` in a fresh folder of its own, classified as

    ok             exit 0 and, for `run`, a complete result (summary.json that parses)
    clean error    exit 1 (or argparse's 2), one line `...: error: ...` on stderr (warnings
                   aside), no traceback, and nothing written (the folder as it was)
    unclean error  exit 1 or 2, but more than one line, or files written
    traceback      a Python traceback on stderr, or the catch-all's "internal error" (a bug)
    crash          killed by a signal, or an exit code other than 0, 1, 2
    hang           no end within --timeout seconds (the run is killed)
    suspicious ok  exit 0 without a complete result

Case i is drawn from random.Random(f"{seed}:{i}"), so a campaign is reproducible and any
case can be rerun alone (--only i --keep shows its folder). The figures of the closing note
of the reliability work (docs/behaviour.md, "Failures and limits") were made with

    scripts/fuzz -n 10000 -j 2

and, for the code before it, the same with --root pointing at a checkout of that code.
"""

from __future__ import annotations

import argparse
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from collections import Counter, defaultdict
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

if __package__:                           # imported as benchmarks.fuzz.campaign (the tests)
    from . import mutations
else:                                     # run as a script
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import mutations  # noqa: E402

ROOT = mutations.ROOT
CLASSES = ("ok", "clean error", "unclean error", "traceback", "crash", "hang", "suspicious ok")


class RandomChooser:
    def __init__(self, seed):
        self.r = random.Random(seed)

    def choice(self, seq):
        return seq[self.r.randrange(len(seq))]

    def integer(self, lo, hi):
        return self.r.randint(lo, hi)

    def coin(self, p=0.5):
        return self.r.random() < p


def snapshot(folder):
    out = {}
    for dirpath, dirnames, filenames in os.walk(folder):
        for n in dirnames + filenames:
            p = Path(dirpath) / n
            try:
                st = p.lstat()
            except OSError:
                continue
            out[str(p.relative_to(folder))] = (st.st_mode, st.st_size if not p.is_dir() else 0)
    return out


def classify(case, proc, before, after, folder):
    """(class, detail) of one finished run."""
    err = proc.stderr
    if proc.returncode < 0:
        try:
            name = signal.Signals(-proc.returncode).name
        except ValueError:
            name = str(-proc.returncode)
        return "crash", f"signal {name}"
    if proc.returncode not in (0, 1, 2):
        return "crash", f"exit code {proc.returncode}"
    if "Traceback (most recent call last)" in err:
        return "traceback", err.strip().splitlines()[-1][:200]
    if "internal error" in err:
        return "traceback", err.strip().splitlines()[-1][:200]
    if proc.returncode == 0:
        if case.argv[:1] == ["run"] and case.output and "--help" not in case.argv:
            s = folder / case.output / "summary.json"
            try:
                summary = json.loads(s.read_text())
                assert summary.get("status", "").startswith("MARTELLO_")
            except Exception as exc:                     # noqa: BLE001
                return "suspicious ok", f"exit 0 but {case.output}/summary.json: {exc!r}"[:200]
        return "ok", ""
    if case.argv[:1] == ["check"] and proc.returncode == 1 and "FAILED" in proc.stdout \
            and not err.strip():
        return "clean error", "check failed: " + proc.stdout.strip().splitlines()[-1][:160]
    lines = [ln for ln in err.splitlines() if ln.strip()]
    extra = [ln for ln in lines if not ln.startswith(("warning:", "usage:", "  ", "note:", "["))]
    one = len(extra) == 1 and "error:" in extra[0]
    if case.argv[:1] in (["check"], ["study"]) and one:
        return "clean error", extra[0][:200]       # their reports are written by design
    changed = sorted(k for k in set(before) | set(after) if before.get(k) != after.get(k))
    if one and not changed:
        return "clean error", extra[0][:200]
    why = f"{len(extra)} lines" if not one else f"wrote {', '.join(changed[:3])}"
    return "unclean error", f"{why}: {(extra[-1] if extra else '')[:160]}"


def _limit_memory(gib):
    """In the child: an address-space limit, so that a run reading /dev/zero or building a
    billion nodes meets MemoryError instead of the machine's other users."""
    import resource
    limit = int(gib * (1 << 30))
    resource.setrlimit(resource.RLIMIT_AS, (limit, limit))


def run_case(i, args, env, work):
    case = mutations.make_case(RandomChooser(f"{args.seed}:{i}"))
    folder = Path(work) / f"case{i:06d}"
    folder.mkdir(parents=True)
    try:
        mutations.lay_out(case, folder)
        before = snapshot(folder)
        t0 = time.perf_counter()
        try:
            proc = subprocess.run([args.python, "-m", "martello", *case.argv], cwd=folder,
                                  env=env, capture_output=True, text=True, errors="replace",
                                  timeout=args.timeout, stdin=subprocess.DEVNULL,
                                  start_new_session=True,
                                  preexec_fn=lambda: _limit_memory(args.memory))
            cls, detail = classify(case, proc, before, snapshot(folder), folder)
        except subprocess.TimeoutExpired:
            cls, detail = "hang", f"no end within {args.timeout:g} s"
            proc = None
        wall = time.perf_counter() - t0
        return {"case": i, "label": case.label, "argv": case.argv, "class": cls,
                "detail": detail, "wall_s": round(wall, 3),
                "stderr": (proc.stderr[-600:] if proc is not None else "")}
    finally:
        if not args.keep:
            shutil.rmtree(folder, ignore_errors=True)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                 formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("-n", type=int, default=1000, help="command-line runs (default 1000)")
    ap.add_argument("--seed", default="martello", help="campaign seed (default 'martello')")
    ap.add_argument("-j", "--jobs", type=int, default=2, help="runs at a time (default 2)")
    ap.add_argument("--timeout", type=float, default=30.0,
                    help="seconds after which a run counts as a hang (default 30)")
    ap.add_argument("--root", default=str(ROOT),
                    help="checkout whose martello package is run (default: this one)")
    ap.add_argument("--lib", help="libmartello.so to load (default: ROOT/build/libmartello.so)")
    ap.add_argument("--python", default=sys.executable, help="interpreter (default: this one)")
    ap.add_argument("--memory", type=float, default=4.0,
                    help="address-space limit of each run in GiB (default 4)")
    ap.add_argument("--only", type=int, nargs="*", help="run only these case numbers")
    ap.add_argument("--keep", action="store_true", help="keep each case's folder")
    ap.add_argument("--out", default="out/fuzz", help="report folder (default out/fuzz)")
    args = ap.parse_args(argv)

    root = Path(args.root).resolve()
    env = dict(os.environ, PYTHONPATH=str(root), PYTHONDONTWRITEBYTECODE="1",
               OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1",
               MARTELLO_LIB=str(Path(args.lib).resolve() if args.lib
                                else root / "build" / "libmartello.so"))
    env.pop("MARTELLO_DEBUG", None)
    work = tempfile.mkdtemp(prefix="martello-fuzz-")
    cases = args.only if args.only else range(args.n)
    counts, by_label, examples, results = Counter(), defaultdict(Counter), defaultdict(list), []
    t0 = time.perf_counter()
    try:
        with ThreadPoolExecutor(max_workers=max(1, args.jobs)) as ex:
            for k, r in enumerate(ex.map(lambda i: run_case(i, args, env, work), cases), 1):
                results.append(r)
                counts[r["class"]] += 1
                by_label[r["label"]][r["class"]] += 1
                if r["class"] not in ("ok", "clean error") and len(examples[r["class"]]) < 25:
                    examples[r["class"]].append(r)
                if k % 500 == 0:
                    print(f"  {k} runs, {time.perf_counter() - t0:.0f} s: "
                          + ", ".join(f"{counts[c]} {c}" for c in CLASSES if counts[c]),
                          file=sys.stderr, flush=True)
    finally:
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)
    elapsed = time.perf_counter() - t0
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    report = {"root": str(root), "seed": args.seed, "runs": len(results), "timeout_s": args.timeout,
              "elapsed_s": round(elapsed, 1), "counts": {c: counts[c] for c in CLASSES},
              "by_label": {k: dict(v) for k, v in sorted(by_label.items())},
              "examples": examples}
    (out / "fuzz.json").write_text(json.dumps(report, indent=1) + "\n")
    with open(out / "cases.jsonl", "w") as fh:
        for r in results:
            fh.write(json.dumps({k: r[k] for k in ("case", "label", "class", "detail", "wall_s")}) + "\n")
    print(f"{len(results)} runs in {elapsed:.0f} s ({root}): "
          + ", ".join(f"{counts[c]} {c}" for c in CLASSES))
    for c in CLASSES[2:]:
        for r in examples[c][:5]:
            print(f"  {c}: case {r['case']} ({r['label']}): {r['detail']}")
    bad = sum(counts[c] for c in ("unclean error", "traceback", "crash", "hang", "suspicious ok"))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
