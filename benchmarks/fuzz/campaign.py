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
    round trip failed  exit 0, but what it wrote does not read back through martello's own
                   readers (roundtrip.py: the run's history through compare's reader, the
                   exported model parsed and its commands checked, the scores, runs.csv)

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
    from . import mutations, roundtrip
else:                                     # run as a script
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    sys.path.insert(1, str(Path(__file__).resolve().parents[2]))   # martello, for roundtrip
    import mutations  # noqa: E402
    import roundtrip  # noqa: E402

ROOT = mutations.ROOT
CLASSES = ("ok", "clean error", "unclean error", "traceback", "crash", "hang", "suspicious ok",
           "round trip failed")


def progress(t0, done, total):
    """Seconds so far and, at the pace so far, about how many are left."""
    elapsed = time.perf_counter() - t0
    return f"{elapsed:.0f} s (about {elapsed * (total - done) / done:.0f} s left)"


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
        problem = roundtrip.check(case.argv, folder)
        if problem:
            return "round trip failed", problem
        return "ok", ""
    if case.argv[:1] == ["check"] and proc.returncode == 1 and "FAILED" in proc.stdout \
            and not err.strip():
        return "clean error", "check failed: " + proc.stdout.strip().splitlines()[-1][:160]
    lines = [ln for ln in err.splitlines() if ln.strip()]
    # besides the error: warnings, usage, notes, progress bars ([...]) and lines ("t = ...")
    extra = [ln for ln in lines if not ln.startswith(("warning:", "usage:", "  ", "note:", "[", "t = "))]
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
    return run_one(i, mutations.make_case(RandomChooser(f"{args.seed}:{i}"), args.kinds), args, env, work)


def run_one(i, case, args, env, work):
    """Run one Case (`case.env`, if it has one, is added to the environment)."""
    env = dict(env, **getattr(case, "env", {}))
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


# --- the loader campaign: scenes mutated in this process, no command line ------------------

LOADER_CLASSES = ("loads", "clean error", "several lines", "warning", "internal error", "hang")


class _Hang(BaseException):
    pass


def loader_case(i, seed, scenes, tmp):
    """One mutated scene through the loader (as tests/test_fuzz.py's property, drawn from
    random.Random): (class, label, detail)."""
    import warnings
    from martello.errors import MartelloError
    from martello.scene.loader import from_dict, load
    ch = RandomChooser(f"{seed}:loader:{i}")
    name = ch.choice(scenes)
    d = mutations.scene_dict(name)
    how = ch.integer(0, 9)
    src = mutations.BENCHMARKS / f"{name}.toml"
    if how <= 4:
        d, label = mutations.mutate_dict(ch, d), "mutated dict"
    elif how <= 7:
        label = ch.choice(sorted(mutations.TARGETED))
        try:
            mutations.TARGETED[label](d, ch)
        except (AttributeError, TypeError, IndexError, KeyError):
            pass
        if isinstance(d.get("description"), mutations.Deep):
            d["description"] = "x"      # deep nesting is the text cases' (a dict cannot hold it)
    else:
        label = "damaged text"
        (tmp / "s.toml").write_bytes(mutations.mutate_text(ch, src.read_text()))
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            if label == "damaged text":
                load(tmp / "s.toml")
            else:
                from_dict(d, source=str(src), base_dir=src.parent)
            cls, detail = "loads", ""
        except MartelloError as exc:
            msg = str(exc)
            cls, detail = ("clean error" if msg and "\n" not in msg else "several lines"), msg[:200]
        except _Hang:
            cls, detail = "hang", "no end within the timeout"
        except RecursionError as exc:
            cls, detail = "internal error", f"RecursionError: {exc}"[:200]
        except Exception as exc:                         # noqa: BLE001 - what is counted
            cls, detail = "internal error", f"{type(exc).__name__}: {exc}"[:200]
    if caught and cls != "internal error":
        cls, detail = "warning", f"{caught[0].category.__name__}: {caught[0].message}"[:200]
    return cls, f"{name}: {label}", detail


def loader_campaign(args):
    """--loader N: N scenes of the catalogue mutated (dict edits, the targeted values, damaged
    text) through the loader in this process, each within --timeout seconds (SIGALRM)."""
    import signal as _signal
    from martello.scene import catalogue
    scenes = [str(f.relative_to(mutations.BENCHMARKS).with_suffix("")) for f in catalogue.scene_files()]
    counts, examples = Counter(), defaultdict(list)
    t0 = time.perf_counter()

    def alarm(signum, frame):
        raise _Hang

    _signal.signal(_signal.SIGALRM, alarm)
    with tempfile.TemporaryDirectory(prefix="martello-loader-fuzz-") as tmp:
        for i in range(args.loader):
            _signal.setitimer(_signal.ITIMER_REAL, args.timeout)
            try:
                cls, label, detail = loader_case(i, args.seed, scenes, Path(tmp))
            finally:
                _signal.setitimer(_signal.ITIMER_REAL, 0)
            counts[cls] += 1
            if cls not in ("loads", "clean error") and len(examples[cls]) < 25:
                examples[cls].append({"case": i, "label": label, "detail": detail})
            if (i + 1) % 2000 == 0:
                print(f"  {i + 1} scenes, {progress(t0, i + 1, args.loader)}: "
                      + ", ".join(f"{counts[c]} {c}" for c in LOADER_CLASSES if counts[c]),
                      file=sys.stderr, flush=True)
    elapsed = time.perf_counter() - t0
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    report = {"kind": "loader", "seed": args.seed, "scenes": args.loader,
              "elapsed_s": round(elapsed, 1), "counts": {c: counts[c] for c in LOADER_CLASSES},
              "examples": examples}
    (out / "loader.json").write_text(json.dumps(report, indent=1) + "\n")
    print(f"{args.loader} scenes through the loader in {elapsed:.0f} s: "
          + ", ".join(f"{counts[c]} {c}" for c in LOADER_CLASSES))
    for c in LOADER_CLASSES[2:]:
        for r in examples[c][:5]:
            print(f"  {c}: case {r['case']} ({r['label']}): {r['detail']}")
    return 1 if any(counts[c] for c in LOADER_CLASSES[2:]) else 0


# --- the targeted campaign: each review finding with the outcome it must have ---------------

def targeted_campaign(args, env, work):
    """--targeted: the cases of targeted.py, one by one, each classified as the random
    campaign's are and compared with the outcome it must have."""
    import re
    if __package__:
        from . import targeted
    else:
        import targeted  # noqa: E402
    results, t_start = [], time.perf_counter()
    for i, case in enumerate(targeted.cases()):
        folder = Path(work) / f"targeted{i:03d}"
        folder.mkdir(parents=True)
        mutations.lay_out(case, folder)
        before = snapshot(folder)
        t0 = time.perf_counter()
        p = subprocess.Popen([args.python, "-m", "martello", *case.argv], cwd=folder,
                             env=dict(env, **case.env), stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True, errors="replace",
                             stdin=subprocess.DEVNULL, start_new_session=True,
                             preexec_fn=lambda: _limit_memory(args.memory))
        try:
            if case.sigint_after is not None:
                time.sleep(case.sigint_after)
                try:
                    os.killpg(p.pid, signal.SIGINT)
                except ProcessLookupError:
                    pass
            out, err = p.communicate(timeout=case.timeout)
            proc = subprocess.CompletedProcess(case.argv, p.returncode, out, err)
            lines = [ln for ln in err.splitlines()
                     if ln.strip() and not ln.startswith(("t = ", "[", "warning:", "note:"))]
            if case.expect == "interrupted" and p.returncode == 130:
                # one line says it, the last (a study's header line comes before)
                ok1 = (sum("interrupted" in ln for ln in lines) == 1 and "interrupted" in lines[-1]
                       and "Traceback" not in err and "error" not in err)
                got, detail = ("interrupted" if ok1 else "unclean interrupt"), (lines[-1] if lines else "")[:200]
            elif case.expect == "interrupted" and p.returncode == 0:
                got, detail = "interrupted", "ended before the signal (exit 0)"
            else:
                got, detail = classify(mutations.Case(case.label, case.argv, case.files, case.output),
                                       proc, before, snapshot(folder), folder)
            if case.forbid and re.search(case.forbid, err):
                got, detail = "forbidden text", f"{case.forbid!r} in {err.strip()[-160:]}"
        except subprocess.TimeoutExpired:
            os.killpg(p.pid, signal.SIGKILL)
            p.communicate()
            got, detail, err = "hang", f"no end within {case.timeout:g} s", ""
        finally:
            if not args.keep:
                shutil.rmtree(folder, ignore_errors=True)
        wall = time.perf_counter() - t0
        results.append({"case": case.label, "expected": case.expect, "got": got,
                        "passed": got == case.expect, "detail": detail, "wall_s": round(wall, 2),
                        "stderr": err[-400:]})
        print(f"{'ok  ' if got == case.expect else 'FAIL'} {case.label[:70]:<70} {got:<14} "
              f"{wall:6.1f} s  {detail[:90]}", flush=True)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    (out / "targeted.json").write_text(json.dumps(results, indent=1) + "\n")
    bad = [r for r in results if not r["passed"]]
    print(f"{len(results)} targeted cases in {time.perf_counter() - t_start:.0f} s: "
          f"{len(results) - len(bad)} as expected, {len(bad)} not")
    return 1 if bad else 0


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
    ap.add_argument("--python", help="interpreter (default: ROOT/.venv/bin/python if --root has "
                    "one, else this one: an interpreter with another checkout installed editable "
                    "imports that checkout's martello whatever PYTHONPATH says)")
    ap.add_argument("--memory", type=float, default=4.0,
                    help="address-space limit of each run in GiB (default 4)")
    ap.add_argument("--only", type=int, nargs="*", help="run only these case numbers")
    ap.add_argument("--keep", action="store_true", help="keep each case's folder")
    ap.add_argument("--kinds", type=lambda t: [k for k in t.split(",") if k],
                    help="draw only these kinds of case (mutations.KINDS by name, comma-separated; "
                    "e.g. later_scene_case,export_case,compare_columns_case: the features added "
                    "since the first campaigns)")
    ap.add_argument("--out", default="out/fuzz", help="report folder (default out/fuzz)")
    ap.add_argument("--loader", type=int, metavar="N",
                    help="instead: N mutated scenes through the loader in this process "
                    "(no command line; --timeout per scene)")
    ap.add_argument("--targeted", action="store_true",
                    help="instead: the command lines of targeted.py, each with the outcome it "
                    "must have (the bad inputs reviews found, one by one)")
    args = ap.parse_args(argv)
    unknown = set(args.kinds or ()) - {fn.__name__ for fn, _ in mutations.KINDS}
    if unknown:
        ap.error(f"--kinds: unknown {', '.join(sorted(unknown))} (valid: "
                 f"{', '.join(fn.__name__ for fn, _ in mutations.KINDS)})")
    if args.loader:
        return loader_campaign(args)

    root = Path(args.root).resolve()
    if args.python is None:
        venv = root / ".venv" / "bin" / "python"
        args.python = str(venv) if venv.exists() else sys.executable
    env = dict(os.environ, PYTHONPATH=str(root), PYTHONDONTWRITEBYTECODE="1",
               OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1",
               MARTELLO_LIB=str(Path(args.lib).resolve() if args.lib
                                else root / "build" / "libmartello.so"))
    env.pop("MARTELLO_DEBUG", None)
    work = tempfile.mkdtemp(prefix="martello-fuzz-")
    if args.targeted:
        try:
            return targeted_campaign(args, env, work)
        finally:
            if not args.keep:
                shutil.rmtree(work, ignore_errors=True)
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
                if k % 100 == 0:
                    print(f"  {k} runs, {progress(t0, k, len(cases))}: "
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
    bad = sum(counts[c] for c in CLASSES[2:])
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
