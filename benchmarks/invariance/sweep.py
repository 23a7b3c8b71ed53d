"""Output invariance over the whole catalogue (docs/invariance.md): every dynamic scene run as
written (tracking everything) and again with output.every x 7 and x 1000, no history, other
recorded items, each tracking choice, and for the adaptive integrators two other output
intervals; every summary number must come back (fixed steps: bit for bit; adaptive: within
2 x what a 10 x looser rtol, atol and event_tol moves them).
benchmarks/invariance/relations.py holds the relations; tests/test_output_invariance.py runs a
sample per integrator x scheme in CI.

    .venv/bin/python benchmarks/invariance/sweep.py -o /tmp/invariance [--only p2/ p9/] [-j 2]
    .venv/bin/python benchmarks/invariance/sweep.py -o /tmp/invariance --metamorphic

writes OUT/invariance.json (every scene: kind, seconds, the variants that failed with their
worst numbers) and prints one line per scene that failed and a table per integrator x scheme.
--metamorphic instead applies every relation of benchmarks/invariance/metamorphic.py to every
scene (OUT/metamorphic.json: held, failed, or why it does not apply). Large scenes (more than
10 000 nodes, links and contacts) are skipped (--large runs them)."""

from __future__ import annotations

import argparse
import json
import sys
import time
from collections import defaultdict
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))

from benchmarks.invariance import metamorphic, relations  # noqa: E402
from martello.scene import catalogue  # noqa: E402
from martello.scene.loader import load  # noqa: E402


def kind_of(path):
    """(integrator, schemes) of a dynamic scene, None for a static one or a large one."""
    scene = load(path)
    an = scene.analysis
    if an["type"] != "dynamic":
        return None
    schemes = sorted({c["scheme"] for c in scene.contacts}) or ["none"]
    return an["integrator"], "+".join(schemes), len(scene.nodes) + len(scene.links) + \
        len(scene.contacts)


def one(path):
    t0 = time.perf_counter()
    try:
        (integrator, adaptive), found = relations.output_invariance(path)
        failed = [{"variant": name, "mismatches": [[p, repr(x), repr(y), a] for p, x, y, a in bad[:8]],
                   "n_mismatches": len(bad), "missing": lost[:8], "n_missing": len(lost)}
                  for name, bad, lost, _ in found if bad or lost]
        tied = sorted({p for _, _, _, ties in found for p, *_ in ties})
        return {"scene": str(path), "seconds": time.perf_counter() - t0, "variants": len(found),
                "failed": failed, "tied": tied}
    except Exception as exc:              # a scene that fails to run is a finding too
        return {"scene": str(path), "seconds": time.perf_counter() - t0, "variants": 0,
                "failed": [{"variant": "(run)", "error": f"{type(exc).__name__}: {exc}"}]}


def one_metamorphic(path):
    out = {"scene": str(path), "relations": {}}
    for name in metamorphic.RELATIONS:
        t0 = time.perf_counter()
        try:
            tied = []
            bad = metamorphic.check(path, name, tied=tied)
            out["relations"][name] = {"held": not bad, "seconds": time.perf_counter() - t0,
                                      "mismatches": [[p, repr(x), repr(y), a] for p, x, y, a in bad[:8]],
                                      "tied": sorted({p for p, *_ in tied})}
        except metamorphic.Unsupported as exc:
            out["relations"][name] = {"unsupported": str(exc)}
        except Exception as exc:
            out["relations"][name] = {"held": False, "error": f"{type(exc).__name__}: {exc}"}
    return out


def report_metamorphic(results):
    counts = defaultdict(lambda: [0, 0, 0])
    for r in results:
        for name, v in r["relations"].items():
            c = counts[name]
            if "unsupported" in v:
                c[2] += 1
            elif v["held"]:
                c[0] += 1
            else:
                c[1] += 1
                why = v.get("error") or "; ".join(f"{m[0]}: {m[1]} vs {m[2]}" for m in v["mismatches"][:3])
                print(f"FAIL {r['scene']} [{name}] {why}")
    print(f"\n{'relation':18s}  held failed not applicable")
    for name, (held, failed, na) in sorted(counts.items()):
        print(f"{name:18s} {held:5d} {failed:6d} {na:6d}")
    return sum(c[1] for c in counts.values())


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("-o", "--out", required=True, help="folder for invariance.json")
    ap.add_argument("--only", nargs="*", default=[], help="scene paths containing one of these")
    ap.add_argument("-j", "--jobs", type=int, default=1)
    ap.add_argument("--large", action="store_true", help="also the large scenes")
    ap.add_argument("--metamorphic", action="store_true",
                    help="the metamorphic relations instead of the output variants")
    args = ap.parse_args(argv)
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    scenes, kinds = [], {}
    for p in catalogue.scene_files():
        if args.only and not any(s in str(p) for s in args.only):
            continue
        k = kind_of(p)
        if k is None or (k[2] > 10_000 and not args.large):
            continue
        scenes.append(p)
        kinds[str(p)] = k[:2]
    t0 = time.perf_counter()
    if args.metamorphic:
        with ProcessPoolExecutor(args.jobs) as pool:
            results = list(pool.map(one_metamorphic, scenes))
        failed = report_metamorphic(results)
        print(f"{len(results)} scenes, {time.perf_counter() - t0:.0f} s")
        (out / "metamorphic.json").write_text(json.dumps(results, indent=1))
        return 1 if failed else 0
    with ProcessPoolExecutor(args.jobs) as pool:
        results = list(pool.map(one, scenes))
    table = defaultdict(lambda: [0, 0, 0.0])
    for r in results:
        r["kind"] = kinds[r["scene"]]
        row = table[tuple(r["kind"])]
        row[0] += 1
        row[1] += bool(r["failed"])
        row[2] += r["seconds"]
        for f in r["failed"]:
            worst = f.get("error") or "; ".join(f"{m[0]}: {m[1]} vs {m[2]}" for m in f["mismatches"][:3]) \
                or "missing " + ", ".join(f["missing"][:3])
            print(f"FAIL {Path(r['scene']).relative_to(catalogue.ROOT.parent)} [{f['variant']}] {worst}")
    print(f"\n{'integrator':18s} {'schemes':24s} scenes failed seconds")
    for (integ, schemes), (n, bad, sec) in sorted(table.items()):
        print(f"{integ:18s} {schemes:24s} {n:6d} {bad:6d} {sec:7.1f}")
    total = sum(len(r["failed"]) > 0 for r in results)
    print(f"\n{len(results)} scenes, {sum(r['variants'] for r in results)} variant runs, "
          f"{total} scenes with a failed relation, {time.perf_counter() - t0:.0f} s")
    (out / "invariance.json").write_text(json.dumps(results, indent=1))
    return 1 if total else 0


if __name__ == "__main__":
    sys.exit(main())
