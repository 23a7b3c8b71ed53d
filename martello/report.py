"""The catalogue report: run every scene, verify it, print the table, write report.md,
verification.csv and plots. Every number says how it was obtained (scene, scheme,
analysis, tolerance, version)."""

import csv
import sys
import time
from pathlib import Path

from .binding import native
from .checks.measures import run_measured
from .checks.independent_rows import verify_independent
from .checks.reference_data import verify_reference_data
from .checks.verify import verify
from . import errors
from .errors import MartelloError
from .paths import REPO
from .reference.store import manifest
from .run import write_results
from .scene.loader import load


def _fmt(x):
    return f"{x:.10g}" if isinstance(x, float) else str(x)


def check_catalogue(files, outdir, plots=True, stream=sys.stdout, require_checks=False):
    """Run and verify the scene files; print the table, write the report; True if nothing
    failed. A scene with nothing to verify (no [check] table, no stored reference data) is
    listed as "ran, not verified"; it is a failure if require_checks (scenes named on the
    command line) or if reference/references.toml lists reference data for it that are
    missing (an installation without its data must not pass as verified)."""
    outdir.mkdir(parents=True, exist_ok=True)
    rows, failures, t_start = [], [], time.perf_counter()
    print(f"martello {native.version()} ({native.library_versions()})", file=stream)
    header = f"{'scene':<44} {'scheme':<19} {'quantity':<36} {'digits':>6} {'tol':>8}  result"
    print(header, file=stream)
    print("-" * len(header), file=stream)
    for k, path in enumerate(files, 1):
        try:
            s = load(path)
            summary, history = run_measured(s)     # with the problem's measures (P4)
            write_results(summary, outdir / "runs" / Path(path).stem, history)
            schemes = ",".join(sorted({c["scheme"] for c in s.contacts})) or "-"
            # closed form where the scene names one, else the stored reference data (reference/)
            rows_here = verify(s, summary) if s.check is not None else []
            for r in rows_here:
                r.setdefault("evidence", "closed form")
            if history is not None:
                # accuracy against the independent engine where it has the scene; else the
                # stored reference data, which only show drift (regression, not verification)
                acc = verify_independent(s, summary, lambda sc: run_measured(sc)[0])
                rows_here += acc or [dict(r, evidence="regression")
                                     for r in verify_reference_data(s, summary, history)]
            if not rows_here:
                missing = _missing_reference_data(path)
                if missing:
                    failures.append(f"{path}: its reference data {missing} are missing "
                                    "(reinstall martello, or rebuild them with "
                                    "scripts/regenerate_reference)")
                elif require_checks:
                    failures.append(f"{path}: nothing to verify: no [check] table "
                                    "(docs/scene-format.md) and no stored reference data for its "
                                    "physics; `martello run` runs a scene without verifying it")
                print(f"{s.title[:44]:<44} (no closed form or reference data: ran, not verified)",
                      file=stream)
                continue
            laws = ",".join(sorted({c["scheme"] if c["scheme"] != "penalty" else c.get("law") or "linear"
                                    for c in s.contacts})) or "-"
            for r in rows_here:
                r.update(integrator=s.analysis.get("integrator") or "static", laws=laws)
                r.update(scheme=schemes, analysis=s.analysis["type"], status=summary["status"],
                         problem=s.problem,
                         digits_lost=summary.get("conditioning", {}).get("digits_lost", 0.0))
                rows.append(r)
                tol = f"{r['rtol']:8.0e}" if r["rtol"] else ("   exact" if r["atol"] < 1e-100
                                                             else f"{r['atol']:8.0e}")
                print(f"{s.title[:44]:<44} {schemes[:19]:<19} {r['quantity'][:36]:<36} "
                      f"{r['digits']:6.1f} {tol}  {'pass' if r['passed'] else 'FAIL'}",
                      file=stream)
                if not r["passed"]:
                    failures.append(f"{path}: {r['quantity']} = {r['value']!r}, "
                                    f"reference {r['reference']!r}")
            for w in summary.get("warnings", []):
                print(f"    warning: {w}", file=stream)
        except MartelloError as exc:
            failures.append(f"{path}: {exc}")
            print(f"{Path(path).stem[:44]:<44} ERROR: {exc}", file=stream)
        except Exception as exc:        # a bug: this scene fails, the others are still checked
            if errors.debug:
                raise
            msg = f"internal error: {type(exc).__name__}: {exc} (a bug in martello: please report it)"
            failures.append(f"{path}: {msg}")
            print(f"{Path(path).stem[:44]:<44} ERROR: {msg}", file=stream)
    elapsed = time.perf_counter() - t_start
    _write_csv(rows, outdir / "verification.csv")
    pngs = _plots(rows, outdir) if plots and rows else []
    _write_markdown(rows, failures, pngs, outdir / "report.md", elapsed)
    (outdir / "coverage.md").write_text(coverage_markdown(rows) + "\n")
    print("\n" + headline(rows, failures, len(files), elapsed) + f" Report: {outdir / 'report.md'}",
          file=stream)
    for f in failures:
        print(f"  FAILED {f}", file=stream)
    return not failures


VERIFICATION = ("closed form", "independent reference")


def headline(rows, failures, n_scenes, elapsed):
    """Only rows against a closed form or the independent reference count as verification;
    regression rows (drift from stored data) and identities are counted apart."""
    ver = [r for r in rows if r.get("evidence") in VERIFICATION]
    other = [r for r in rows if r.get("evidence") not in VERIFICATION]
    kinds = ", ".join(f"{sum(r['evidence'] == k for r in ver)} vs {k}" for k in VERIFICATION)
    return (f"verification: {sum(r['passed'] for r in ver)} of {len(ver)} checks passed ({kinds}); "
            f"regression, not verification: {sum(r['passed'] for r in other)} of {len(other)} passed; "
            f"{len(failures)} failure(s); {n_scenes} scenes in {elapsed:.1f} s.")


def coverage(rows):
    """The coverage matrix: one cell per problem × contact law (or scheme) × integrator, with
    its kind of evidence (the strongest of its rows: closed form, then independent reference,
    else regression only: self-consistent), its fewest digits among the verifying rows, and
    whether every row of the cell passed."""
    cells = {}
    for r in rows:
        key = (r.get("problem") or "-", r.get("laws", "-"), r.get("integrator", "-"))
        c = cells.setdefault(key, {"kinds": set(), "digits": [], "n": 0, "ok": True, "files": {}})
        c["kinds"].add(r.get("evidence", "regression"))
        c["n"] += 1
        c["ok"] &= bool(r["passed"])
        if r.get("evidence") in VERIFICATION:
            c["digits"].append(r["digits"])
        verified = c["files"].setdefault(r.get("file", "?"), False)
        c["files"][r.get("file", "?")] = verified or r.get("evidence") in VERIFICATION
    out = []
    for (problem, laws, integ), c in sorted(cells.items()):
        kind = next((k for k in VERIFICATION if k in c["kinds"]), "regression only (self-consistent)")
        # scenes of a verified cell whose own rows are regression only are named, so that a
        # cell's state never speaks for a scene it does not cover
        apart = sorted(Path(f).stem for f, v in c["files"].items() if not v) if kind in VERIFICATION else []
        out.append({"problem": problem, "law": laws, "integrator": integ, "evidence": kind,
                    "digits": min(c["digits"]) if c["digits"] else None, "rows": c["n"],
                    "regression_only_scenes": apart,
                    "state": "verified" if c["ok"] and kind in VERIFICATION else
                    ("WRONG" if not c["ok"] else "self-consistent only")})
    return out


def coverage_markdown(rows):
    cells = coverage(rows)
    n_ver = sum(c["state"] == "verified" for c in cells)
    n_bad = sum(c["state"] == "WRONG" for c in cells)
    n_self = sum(c["state"] == "self-consistent only" for c in cells)
    lines = [f"{n_ver} cells verified against a closed form or the independent reference, "
             f"{n_bad} wrong, {n_self} self-consistent only (regression against data martello made), "
             f"of {len(cells)} problem × law/scheme × integrator cells that `martello check` ran.", "",
             "| problem | law / scheme | integrator | evidence | fewest digits | rows | state |",
             "|---|---|---|---|---|---|---|"]
    for c in cells:
        d = f"{c['digits']:.1f}" if c["digits"] is not None else "—"
        ev = c["evidence"]
        if c["regression_only_scenes"]:
            ev += "; regression only: " + ", ".join(f"`{n}`" for n in c["regression_only_scenes"])
        lines.append(f"| {c['problem']} | {c['law']} | {c['integrator']} | {ev} | {d} | "
                     f"{c['rows']} | {c['state']} |")
    return "\n".join(lines)


def _missing_reference_data(path):
    """The folder of the reference data references.toml lists for this scene file as is
    (no contact override), if they are not there; else None."""
    for e in manifest():
        if not e.get("contact") and (REPO / e["scene"]).resolve() == Path(path).resolve() \
                and not (e["folder"] / "reference.json").is_file():
            return e["folder"]
    return None


def _write_csv(rows, path):
    keys = ["scene", "file", "scheme", "analysis", "evidence", "quantity", "value", "reference", "abs_error",
            "rel_error", "digits", "rtol", "atol", "passed", "status", "digits_lost", "why"]
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys, extrasaction="ignore")
        w.writeheader()
        w.writerows(rows)


def _plots(rows, outdir):
    """One bar per scene file: its check with the smallest margin between the digits obtained
    and the digits its rtol asks for (a row per check would be unreadable for a catalogue)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np

    # per scene file: the check with the smallest margin (digits obtained − digits asked)
    scenes = {}
    for r in rows:
        need = -np.log10(r["rtol"]) if r["rtol"] else 0.0
        key = f"{Path(r['file']).stem}"
        d = scenes.setdefault(key, {"got": 16.0, "need": 0.0, "margin": np.inf, "ok": True, "n": 0})
        if r["digits"] - need < d["margin"]:
            d.update(got=r["digits"], need=need, margin=r["digits"] - need)
        d["ok"] &= r["passed"]
        d["n"] += 1
    names = list(scenes)
    y = np.arange(len(names))
    fig, ax = plt.subplots(figsize=(10, 0.2 * len(names) + 1.6))
    ax.barh(y, [scenes[n]["got"] for n in names],
            color=["tab:green" if scenes[n]["ok"] else "tab:red" for n in names], alpha=0.8,
            label="correct digits of the scene's tightest check")
    ax.scatter([scenes[n]["need"] for n in names], y, marker="|", s=120, color="k",
               label="digits that check's rtol asks for (atol-only checks: 0)")
    ax.set_yticks(y, [f"{n[:60]} ({scenes[n]['n']})" for n in names], fontsize=7)
    ax.invert_yaxis()
    ax.set_xlim(0, 16.5)
    ax.set_xlabel("significant correct digits vs. closed form or reference data")
    ax.set_title(f"martello {native.version()}: catalogue verification, {len(rows)} checks "
                 f"in {len(names)} scenes")
    ax.legend(loc="lower right", fontsize=8)
    fig.tight_layout()
    p = outdir / "digits.png"
    fig.savefig(p, dpi=100)
    plt.close(fig)
    return [p]


def _tol(r):
    if r["rtol"]:
        return f"{r['rtol']:.0e}"
    return "exact" if not r["atol"] else f"atol {r['atol']:.0e}"


def _problem_table(rows):
    """Per problem: scenes, checks, passed, and the fewest digits of its verification rows
    (regression rows measure drift from stored data, not accuracy: counted apart)."""
    by = {}
    for r in rows:
        key = r.get("problem") or r["scene"].split()[0]
        d = by.setdefault(key, {"scenes": set(), "n": 0, "ok": 0, "min": None, "reg": 0})
        d["scenes"].add(r["scene"]); d["n"] += 1; d["ok"] += r["passed"]
        if r.get("evidence") in VERIFICATION:
            d["min"] = r["digits"] if d["min"] is None else min(d["min"], r["digits"])
        else:
            d["reg"] += 1
    lines = ["| problem | scenes | checks | passed | of them regression | fewest digits "
             "(verification rows) |", "|---|---|---|---|---|---|"]
    for k in sorted(by):
        d = by[k]
        low = "-" if d["min"] is None else f"{d['min']:.1f}"
        lines.append(f"| {k} | {len(d['scenes'])} | {d['n']} | {d['ok']} | {d['reg']} | {low} |")
    return "\n".join(lines)


def _write_markdown(rows, failures, pngs, path, elapsed):
    lines = [f"# martello catalogue verification", "",
             f"martello {native.version()}; {native.library_versions()}; "
             f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}; {elapsed:.1f} s.", "",
             "Each row compares one quantity of one run with the closed form named in the "
             "scene's `[check]` table (martello.oracles, coded independently of the "
             "solvers), with the independent reference engine's stored solution "
             "(martello.independent), or, as regression only, with stored data martello made "
             "itself in `reference/` (such a row passes when the error is within twice what "
             "this scene's own settings showed when the data were made: it checks for drift, "
             "not accuracy). "
             "digits = −log10 of the relative error (16 = exact to round-off).", "",
             "**" + headline(rows, failures, len({r['file'] for r in rows}), elapsed) + "** "
             "Kinds of evidence: *closed form* (martello.oracles), *independent reference* "
             "(martello.independent, docs/independent-reference.md: digits = min(the run's, the "
             "reference's trusted digits), tolerance from the run's measured order), "
             "*regression* (drift from stored data made by martello itself: not verification).", "",
             _problem_table(rows), "", "## Coverage", "", coverage_markdown(rows), "", "## Rows", "",
             "| scene | scheme | analysis | evidence | quantity | value | reference | digits | rtol | pass |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        lines.append(f"| {r['scene']} | {r['scheme']} | {r['analysis']} | {r.get('evidence', '')} | `{r['quantity']}` | "
                     f"{_fmt(r['value'])} | {_fmt(r['reference'])} | {r['digits']:.1f} | "
                     f"{_tol(r)} | {'yes' if r['passed'] else '**NO**'} |")
    if failures:
        lines += ["", "## Failures", ""] + [f"- {f}" for f in failures]
    for p in pngs:
        lines += ["", f"![{p.stem}]({p.name})"]
    path.write_text("\n".join(lines) + "\n")
