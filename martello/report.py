"""The catalogue report: run every scene, verify it, print the table, write report.md,
verification.csv and plots. Every number says how it was obtained (scene, scheme,
analysis, tolerance, version)."""

import csv
import json
import math
import sys
import time
from pathlib import Path

from .binding import native
from .checks.measures import run_measured
from .checks import kinds
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
    missing (an installation without its data must not pass as verified). Each row's kind
    (martello.checks.kinds) says whether it counts as verification."""
    outdir.mkdir(parents=True, exist_ok=True)
    rows, failures, t_start = [], [], time.perf_counter()
    unchecked = []              # (scene file, title) that ran with nothing to verify
    print(f"martello {native.version()} ({native.library_versions()})", file=stream)
    header = (f"{'scene':<44} {'scheme':<19} {'quantity':<36} {'digits':>6} {'tol':>8}  "
              f"{'result':<6} kind")
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
                r.setdefault("evidence", kinds.CLOSED_FORM)
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
                                    "(docs/scene-input.md) and no stored reference data for its "
                                    "physics; `martello run` runs a scene without verifying it")
                unchecked.append((str(path), s.title))
                print(f"{s.title[:44]:<44} (no closed form or reference data: ran, not verified)",
                      file=stream)
                continue
            kinds.classify(rows_here, s.contacts)
            laws = ",".join(sorted({c["scheme"] if c["scheme"] != "penalty" else c.get("law") or "linear"
                                    for c in s.contacts})) or "-"
            for r in rows_here:
                r.update(integrator=cell_integrator(s.analysis), laws=laws)
                r.update(scheme=schemes, analysis=s.analysis["type"], status=summary["status"],
                         problem=s.problem,
                         digits_lost=summary.get("conditioning", {}).get("digits_lost", 0.0))
                rows.append(r)
                result = "pass" if r["passed"] else "FAIL"
                if not kinds.asserted(r):
                    result = "-"
                print(f"{s.title[:44]:<44} {schemes[:19]:<19} {r['quantity'][:36]:<36} "
                      f"{r['digits']:6.1f} {_tol_short(r)}  {result:<6} {r['kind']}",
                      file=stream)
                if kinds.failed(r):
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
    _write_markdown(rows, failures, pngs, outdir / "report.md", elapsed, len(files), unchecked)
    (outdir / "coverage.md").write_text(coverage_document(rows, failures, len(files), unchecked, elapsed))
    print("\n" + headline(rows, failures, len(files), elapsed) + f" Report: {outdir / 'report.md'}",
          file=stream)
    for f in failures:
        print(f"  FAILED {f}", file=stream)
    return not failures


def _tol_short(r):
    """The tolerance column of the table: relative to the quantity (kinds.relative_tolerance)."""
    if not kinds.asserted(r):
        return "    none"
    t = kinds.relative_tolerance(r)
    return "   exact" if t == 0.0 else f"{t:8.0e}"


VERIFICATION = kinds.INDEPENDENT      # the oracles independent of the solvers


def summary_counts(rows, failures, n_scenes):
    """The counts every report prints the same way (stdout, report.md, coverage.md, the
    README through docs/coverage.md): rows by kind, verified cells, scenes."""
    by = {k: [r for r in rows if kinds.kind_of(r) == k] for k in kinds.KINDS}
    cells = coverage(rows)
    return {"scenes": n_scenes,
            "scenes_with_rows": len({r.get("file") for r in rows}),
            "verification": len(by[kinds.VERIFICATION]),
            "verification_passed": sum(bool(r["passed"]) for r in by[kinds.VERIFICATION]),
            "verification_closed_form": sum(r["evidence"] == kinds.CLOSED_FORM for r in by[kinds.VERIFICATION]),
            "verification_published": sum(r["evidence"] == kinds.PUBLISHED for r in by[kinds.VERIFICATION]),
            "verification_independent": sum(r["evidence"] == kinds.INDEPENDENT_ENGINE
                                            for r in by[kinds.VERIFICATION]),
            "loose": len(by[kinds.LOOSE]), "loose_passed": sum(bool(r["passed"]) for r in by[kinds.LOOSE]),
            "unconverged": len(by[kinds.UNCONVERGED]), "repeat": len(by[kinds.REPEAT]),
            "regression": len(by[kinds.REGRESSION]),
            "regression_passed": sum(bool(r["passed"]) for r in by[kinds.REGRESSION]),
            "cells": len(cells), "cells_verified": sum(c["state"] == "verified" for c in cells),
            "cells_wrong": sum(c["state"] == "WRONG" for c in cells),
            "cells_partly": sum(c["state"] == "partly verified" for c in cells),
            "cells_not_verified": sum(c["state"] == "not verified" for c in cells),
            "failures": len(failures)}


def headline(rows, failures, n_scenes, elapsed):
    """Only rows of kind verification (martello.checks.kinds: an independent oracle, a
    tolerance < 1 %, runs that converge at their order, not a repeat) count as
    verification; the other kinds are counted apart."""
    c = summary_counts(rows, failures, n_scenes)
    return (f"verification: {c['verification_passed']} of {c['verification']} distinct rows passed "
            f"({c['verification_closed_form']} vs closed form, {c['verification_published']} vs published "
            f"value, {c['verification_independent']} vs independent reference; tolerance < 1 %); {c['cells_verified']} of {c['cells']} cells "
            f"verified, {c['cells_partly']} partly, {c['cells_not_verified']} not verified, "
            f"{c['cells_wrong']} wrong; not counted: {c['loose_passed']} of {c['loose']} "
            f"loose rows (tolerance 1-10 %) passed, {c['unconverged']} unconverged (no bound: "
            f"nothing asserted), {c['repeat']} repeats of identical elements, "
            f"{c['regression_passed']} of {c['regression']} regression rows passed; "
            f"{c['failures']} failure(s); {n_scenes} scenes in {elapsed:.1f} s.")


def cell_integrator(analysis):
    """The integrator of a coverage cell: the analysis' own, "static" for a static one, and a
    cell of its own for local stepping (docs/sundials-ode.md, "Local stepping"): another
    discretisation of the same integrator, whose rows must not speak for the global run's."""
    name = analysis.get("integrator") or "static"
    return f"{name} (local stepping)" if analysis.get("local_stepping") else name


def coverage(rows):
    """The coverage matrix: one cell per problem × contact law (or scheme) × integrator. A
    cell is verified when it holds verification rows (kinds.VERIFICATION), no loose or
    unconverged row and no failed one: every quantity it compares is verified to < 1 %;
    partly verified when it also holds loose or unconverged rows (named, with their
    orders); WRONG when an asserted row failed; else not verified (loose or unconverged rows
    only, or regression only). Per cell: the evidence of its verification rows, their
    fewest digits and largest tolerance, the rows by kind."""
    cells = {}
    for r in rows:
        key = (r.get("problem") or "-", r.get("laws", "-"), r.get("integrator", "-"))
        c = cells.setdefault(key, {"kinds": {k: 0 for k in kinds.KINDS}, "evidence": set(), "digits": [],
                                   "tol": [], "orders": [], "ok": True, "files": {}})
        kind = kinds.kind_of(r)
        c["kinds"][kind] += 1
        c["ok"] &= not kinds.failed(r)
        if kind == kinds.VERIFICATION:
            c["evidence"].add(r["evidence"])
            c["digits"].append(r["digits"])
            c["tol"].append(kinds.relative_tolerance(r))
        o = r.get("run_order", r.get("order"))
        if kind == kinds.UNCONVERGED and isinstance(o, float) and math.isfinite(o):
            c["orders"].append(o)
        f = r.get("file", "?")
        c["files"][f] = c["files"].get(f, False) or kind == kinds.VERIFICATION
    out = []
    for (problem, laws, integ), c in sorted(cells.items()):
        n = c["kinds"]
        has = n[kinds.VERIFICATION] > 0
        evidence = ", ".join(k for k in VERIFICATION if k in c["evidence"])
        parts = []
        if n[kinds.LOOSE]:
            parts.append(f"{n[kinds.LOOSE]} loose")
        if n[kinds.UNCONVERGED]:
            orders = c["orders"]
            parts.append(f"{n[kinds.UNCONVERGED]} unconverged" +
                         (f" (order {min(orders):.2f}" + (f" to {max(orders):.2f}" if max(orders) > min(orders) else "")
                          + ")" if orders else " (tolerance ≥ 10 %)"))
        if has:
            why = evidence + (": not verification: " + ", ".join(parts) if parts else "")
        elif parts:
            why = ", ".join(parts) + " rows only"
        else:
            why = "regression only (self-consistent)"
        # scenes of a verified cell with no verification row of their own are named, so that
        # a cell's state never speaks for a scene it does not cover
        apart = sorted(Path(f).stem for f, v in c["files"].items() if not v) if has else []
        state = ("WRONG" if not c["ok"] else "verified" if has and not parts
                 else "partly verified" if has else "not verified")
        out.append({"problem": problem, "law": laws, "integrator": integ, "evidence": why,
                    "digits": min(c["digits"]) if c["digits"] else None,
                    "tolerance": max(c["tol"]) if c["tol"] else None,
                    "rows": sum(n.values()), "by_kind": dict(n),
                    "unverified_scenes": apart, "state": state})
    return out


def coverage_markdown(rows):
    cells = coverage(rows)
    n = {s: sum(c["state"] == s for c in cells) for s in ("verified", "partly verified", "not verified", "WRONG")}
    lines = [f"{n['verified']} cells verified (every row of the cell verification: an independent "
             f"oracle, a tolerance < 1 %, runs converging at their order), {n['partly verified']} partly "
             f"verified, {n['not verified']} not verified, {n['WRONG']} wrong, of {len(cells)} "
             "problem × law/scheme × integrator cells that `martello check` ran.", "",
             "| problem | law / scheme | integrator | evidence | fewest digits | largest tolerance | "
             "rows: verification / loose / unconverged / repeat / regression | state |",
             "|---|---|---|---|---|---|---|---|"]
    for c in cells:
        d = f"{c['digits']:.1f}" if c["digits"] is not None else "—"
        tol = f"{c['tolerance']:.0e}" if c["tolerance"] else ("exact" if c["tolerance"] == 0.0 else "—")
        ev = c["evidence"]
        if c["unverified_scenes"]:
            ev += "; scenes without a verification row: " + ", ".join(f"`{n}`" for n in c["unverified_scenes"])
        k = c["by_kind"]
        lines.append(f"| {c['problem']} | {c['law']} | {c['integrator']} | {ev} | {d} | {tol} | "
                     f"{k['verification']} / {k['loose']} / {k['unconverged']} / {k['repeat']} / "
                     f"{k['regression']} | {c['state']} |")
    return "\n".join(lines)


COVERAGE_INTRO = """\
One cell per problem × contact law (or scheme) × integrator; the kind of every row
(martello/checks/kinds.py) says whether it counts:

* **verification**: an oracle independent of the solvers — a `[check]` closed form of
  `martello.oracles`, a value published in a vendor's verification manual to its printed
  digits (*published value*: the `printed_*` fields of `martello.oracles.vendor`,
  [vendor-problems.md](vendor-problems.md)), or the independent engine `martello.independent`
  ([independent-reference.md](independent-reference.md): digits = min(the run's digits against
  it, the reference's trusted digits)) — with a tolerance below 1 % of the quantity (relative
  to the reference, or to the comparison's `scale` where the reference is 0), and, against the
  engine, reruns at 2Δt and 4Δt (adaptive integrators: 100 and 10⁴ × rtol) whose median
  measured order is within ½ of the method's formal order (2 for the trapezoidal family,
  central difference and fast nonlinear analysis; 1 for Moreau–Jean, Newmark–Lagrange, Newmark
  with γ > ½ and an adaptive run's error in its tolerance; 5/4 for a fixed step on a Jankowski
  contact, whose damping rises as δ^(1/4)): the tolerance is then 3 × the first rerun's
  difference + the step sampling of a maximum + the reference's uncertainty;
* **loose**: a tolerance of 1 % to 10 % of the quantity: asserted, shown, not counted;
* **unconverged**: a run whose reruns do not show its order, or a bound of 10 % or more: the
  error and the order are shown, nothing is asserted (there is no bound to assert);
* **repeat**: the row of a contact identical to an earlier one of its scene (P8's three gap
  elements per floor), counted once;
* **regression**: stored data martello made itself (`reference/<name>/`): drift, not accuracy.

A cell is **verified** when every one of its rows is verification (repeats and the
regression rows of other scenes aside, which it names), **partly verified** when it also
holds loose or unconverged rows, **not verified** when none of its rows is verification,
**wrong** when an asserted row failed. The energy balance is a bookkeeping identity of the
integrators ([results.md](results.md#energy)) and is not a row here. Why the unverified cells
are not: [independent-reference.md](independent-reference.md#open)."""


def coverage_document(rows, failures, n_scenes, unchecked=(), elapsed=0.0):
    """The whole coverage page (`coverage.md` of `martello check`, copied to docs/coverage.md
    by scripts/regenerate_docs): how it was made, the counts (also as a JSON comment, which the
    README's count block is generated from and tests/test_generated_docs.py reads), the kinds,
    the scenes without a verification row, and the matrix."""
    c = summary_counts(rows, failures, n_scenes)
    missing = not_verified_scenes(rows, unchecked)
    lines = ["# Coverage: what `martello check` verifies, and how", "",
             f"Generated by `martello check` (`scripts/regenerate_docs` copies its `coverage.md` here; do "
             f"not edit by hand): martello {native.version()} ({native.library_versions()}), "
             f"{n_scenes} catalogue scenes in {elapsed:.0f} s.", "",
             f"<!-- counts: {json.dumps(c, sort_keys=True)} -->", "",
             "**" + headline(rows, failures, n_scenes, elapsed).rsplit(";", 1)[0] + ".**", "",
             COVERAGE_INTRO, "",
             f"## Scenes without a verification row ({len(missing)} of {n_scenes})", ""]
    lines += [f"- `{stem}`: {why}" for stem, _, why in missing]
    lines += ["", "## The matrix", "", coverage_markdown(rows)]
    return "\n".join(lines) + "\n"


README_BLOCK = ("<!-- generated: coverage counts (scripts/regenerate_docs) -->",
                "<!-- /generated: coverage counts -->")


def coverage_counts(coverage_text):
    """The counts a coverage page carries (its JSON comment)."""
    line = next(x for x in coverage_text.splitlines() if x.startswith("<!-- counts: "))
    return json.loads(line[len("<!-- counts: "):-len(" -->")])


def readme_with_counts(readme_text, coverage_text):
    """The README with its count block made from a coverage page's counts."""
    start, end = README_BLOCK
    i, j = readme_text.index(start) + len(start), readme_text.index(end)
    return readme_text[:i] + "\n" + readme_counts(coverage_counts(coverage_text)) + "\n" + readme_text[j:]


def readme_counts(c):
    """The README's sentence of counts (between its `<!-- generated: coverage counts -->`
    markers), from the counts of docs/coverage.md."""
    return (f"`martello check` ({c['scenes']} scenes): {c['verification_passed']} of "
            f"{c['verification']} distinct verification rows pass ({c['verification_closed_form']} "
            f"against closed forms, {c['verification_published']} against values published in "
            f"vendors' verification manuals, {c['verification_independent']} against the independent "
            f"engine; each with a tolerance below 1 %); {c['cells_verified']} of {c['cells']} problem × "
            f"law/scheme × integrator cells are verified ([docs/coverage.md](docs/coverage.md)), "
            f"{c['cells_partly']} partly, {c['cells_not_verified']} not verified, {c['cells_wrong']} "
            f"wrong. Not counted: {c['loose']} loose "
            f"rows (1-10 %), {c['unconverged']} unconverged, {c['repeat']} repeats of identical "
            f"elements, {c['regression']} regression rows.")


def _missing_reference_data(path):
    """The folder of the reference data references.toml lists for this scene file as is
    (no contact override), if they are not there; else None."""
    for e in manifest():
        if not e.get("contact") and (REPO / e["scene"]).resolve() == Path(path).resolve() \
                and not (e["folder"] / "reference.json").is_file():
            return e["folder"]
    return None


def _write_csv(rows, path):
    keys = ["scene", "file", "problem", "laws", "integrator", "scheme", "analysis", "evidence", "kind",
            "quantity", "value", "reference", "abs_error", "rel_error", "digits", "rtol", "atol", "scale",
            "tolerance_relative", "order", "run_order", "formal_order", "reruns", "repeats", "passed", "status",
            "digits_lost", "why"]
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
        tol = kinds.relative_tolerance(r)
        need = -np.log10(tol) if kinds.asserted(r) and 0 < tol < math.inf else 0.0
        key = f"{Path(r['file']).stem}"
        d = scenes.setdefault(key, {"got": 16.0, "need": 0.0, "margin": np.inf, "ok": True, "n": 0})
        if r["digits"] - need < d["margin"]:
            d.update(got=r["digits"], need=need, margin=r["digits"] - need)
        d["ok"] &= not kinds.failed(r)
        d["n"] += 1
    names = list(scenes)
    y = np.arange(len(names))
    fig, ax = plt.subplots(figsize=(10, 0.2 * len(names) + 1.6))
    ax.barh(y, [scenes[n]["got"] for n in names],
            color=["tab:green" if scenes[n]["ok"] else "tab:red" for n in names], alpha=0.8,
            label="correct digits of the scene's tightest check")
    ax.scatter([scenes[n]["need"] for n in names], y, marker="|", s=120, color="k",
               label="digits that check's tolerance asks for (relative to the quantity)")
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
    if not kinds.asserted(r):
        return "none"
    t = kinds.relative_tolerance(r)
    return "exact" if t == 0.0 else f"{t:.0e}"


def _problem_table(rows, n_scenes):
    """Per problem: the scenes with rows, rows by kind, and the fewest digits of its
    verification rows; a last line sums them (the headline's counts; the scenes without
    rows are the list below it)."""
    by = {}
    for r in rows:
        key = r.get("problem") or r["scene"].split()[0]
        d = by.setdefault(key, {"scenes": set(), "min": None, **{k: 0 for k in kinds.KINDS}, "failed": 0})
        d["scenes"].add(r["file"])
        kind = kinds.kind_of(r)
        d[kind] += 1
        d["failed"] += kinds.failed(r)
        if kind == kinds.VERIFICATION:
            d["min"] = r["digits"] if d["min"] is None else min(d["min"], r["digits"])
    lines = ["| problem | scenes with rows | verification | loose | unconverged | repeat | regression | failed | "
             "fewest digits (verification rows) |", "|---|---|---|---|---|---|---|---|---|"]
    for k in sorted(by):
        d = by[k]
        low = "-" if d["min"] is None else f"{d['min']:.1f}"
        lines.append(f"| {k} | {len(d['scenes'])} | {d['verification']} | {d['loose']} | {d['unconverged']} | "
                     f"{d['repeat']} | {d['regression']} | {d['failed']} | {low} |")
    total = {k: sum(d[k] for d in by.values()) for k in (*kinds.KINDS, "failed")}
    lows = [d["min"] for d in by.values() if d["min"] is not None]
    lines.append(f"| all | {sum(len(d['scenes']) for d in by.values())} of {n_scenes} | "
                 f"{total['verification']} | {total['loose']} | {total['unconverged']} | {total['repeat']} | "
                 f"{total['regression']} | {total['failed']} | {f'{min(lows):.1f}' if lows else '-'} |")
    return "\n".join(lines)


def not_verified_scenes(rows, unchecked):
    """The scenes no verification row covers, by name, with why: nothing to check, or only
    rows of other kinds."""
    out = [(Path(f).stem, title, "ran, not verified: no closed form or reference data")
           for f, title in unchecked]
    files = {}
    for r in rows:
        files.setdefault(r["file"], [r["scene"], set()])[1].add(kinds.kind_of(r))
    for f, (title, ks) in sorted(files.items()):
        if kinds.VERIFICATION not in ks:
            out.append((Path(f).stem, title, "rows of kind " + ", ".join(sorted(ks)) + " only"))
    return sorted(out)


def _write_markdown(rows, failures, pngs, path, elapsed, n_scenes, unchecked=()):
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
             "**" + headline(rows, failures, n_scenes, elapsed) + "**", "",
             "Kinds of rows (martello/checks/kinds.py, docs/coverage.md): *verification* — an "
             "oracle independent of the solvers (a closed form; a value published in a vendor's "
             "manual, docs/vendor-problems.md; the independent engine, "
             "docs/independent-reference.md: digits = min(the run's, the reference's trusted "
             "digits)), a tolerance below 1 % of the quantity, and for rows against the "
             "engine, reruns at 2Δt and 4Δt (adaptive: 100 and 10⁴ × rtol) that converge at "
             "the method's formal order; *loose* — a tolerance of 1-10 %: asserted, not "
             "counted; *unconverged* — reruns that do not show the formal order, or bound "
             "nothing below 10 %: the error and the order are shown, nothing is asserted; "
             "*repeat* — the row of a contact identical to an earlier one of the scene (counted "
             "once); *regression* — drift from stored data made by martello itself.", "",
             _problem_table(rows, n_scenes), "", "## Scenes not verified", ""]
    missing = not_verified_scenes(rows, unchecked)
    lines += [f"{len(missing)} of {n_scenes} scenes have no verification row:", ""] + \
        [f"- `{stem}` ({title}): {why}" for stem, title, why in missing]
    lines += ["", "## Coverage", "", coverage_markdown(rows), "", "## Rows", "",
              "| scene | scheme | analysis | evidence | kind | quantity | value | reference | digits | "
              "tolerance | order | pass |",
              "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        order = r.get("order")
        order = "" if order is None else ("noise" if order != order else f"{order:.2f}")
        ok = "—" if not kinds.asserted(r) else ("yes" if r["passed"] else "**NO**")
        lines.append(f"| {r['scene']} | {r['scheme']} | {r['analysis']} | {r.get('evidence', '')} | "
                     f"{kinds.kind_of(r)} | `{r['quantity']}` | {_fmt(r['value'])} | {_fmt(r['reference'])} | "
                     f"{r['digits']:.1f} | {_tol(r)} | {order} | {ok} |")
    if failures:
        lines += ["", "## Failures", ""] + [f"- {f}" for f in failures]
    for p in pngs:
        lines += ["", f"![{p.stem}]({p.name})"]
    path.write_text("\n".join(lines) + "\n")
