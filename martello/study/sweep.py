"""`martello study STUDY.toml`: a sweep over scenes × contact schemes × integrators × (Δt or
tolerance), run in parallel on the local cores, scored against a reference, written as a
tidy CSV and plotted (work-precision, error vs Δt with the measured order). docs/studies.md
documents the study file; benchmarks/studies/ holds the committed studies.

Every run is a row, whatever happened to it: a run that diverged, failed to converge, or
asked for an integrator that is not built yet is classified and kept, never dropped. The
reference of each scene is a closed form or stored reference data (martello.reference),
scored by martello.metrics."""

from __future__ import annotations

import copy
import csv
import json
import math
import os
import sys
import time
from pathlib import Path

import numpy as np

from ..batch import run_specs
from ..binding import native
from ..errors import MartelloError, SceneError, StudyError
from ..metrics.score import COST_KEYS, cost, score
from ..paths import OUTPUT_ROOT, REPO, check_output_folder
from ..reference.cache import cache_root, cached_reference
from ..reference.selection import reference_for_scene
from ..scene.loader import from_dict
from ..scene.spec import ADAPTIVE
from ..scene.variants import analysis_for, runnable_scene
from .outcome import failed_rows, status_class
from .output import Progress, csv_cell, md_cell, palette_png, slug
from .resume import row_key, run_resumable
from .study_file import load_study


def _spacing(ref, compare, t_end):
    if ref is not None and ref.times is not None and len(ref.times) > 1:
        return float(np.min(np.diff(ref.times)))
    return t_end / max(compare["points"] - 1, 1)


def snap_step(dt, spacing, adaptive=False):
    """(Δt, output every) such that the run's output times fall on the comparison times:
    Δt = spacing/n (output every n steps) or Δt = n·spacing (every step). A fixed-step run
    is then compared where it has values, never through an interpolant. Adaptive
    integrators take dt as their output interval."""
    if adaptive:
        return spacing, 1
    if dt <= spacing:
        n = max(1, int(round(spacing / dt)))
        return spacing / n, n
    return spacing * max(1, int(round(dt / spacing))), 1


def build_specs(study):
    """Expand the study into run specs (one per case × method × step/tolerance) and the
    references of its cases."""
    specs, refs, notes = [], {}, []
    for ci, case in enumerate(study.cases):
        named = isinstance(case.reference, dict)      # the study file names it: it must load
        try:
            rs = runnable_scene(case.scene_dict, case.scene_file, case.t_end)
            ref = reference_for_scene(rs, spec=case.reference)
            if ref is None:
                ref = cached_reference(rs)      # one `martello reference` computed for it
                if ref is not None:
                    notes.append(f"{case.label}: scored against {ref.name}, cached by martello "
                                 f"reference in {cache_root()}")
            if ref is None:
                notes.append(f"{case.label}: no reference (no closed form, no reference data, "
                             "none cached by martello reference): only energy and cost are "
                             "reported")
        except (MartelloError, SceneError) as exc:
            if named:
                raise StudyError(study.path, f"reference of {case.label}", str(exc)) from None
            ref = None
            notes.append(f"{case.label}: reference unavailable: {exc}")
        refs[ci] = ref
        spacing = _spacing(ref, study.compare, case.t_end)
        for mi, m in enumerate(study.methods):
            if m.scenes and case.scene_label not in m.scenes:
                continue
            if m.schemes and case.scheme_label not in m.schemes:
                continue
            levels = [(dt, None) for dt in m.dts] if not m.rtols else [(m.dts[0], r) for r in m.rtols]
            for dt_asked, rtol in levels:
                dt, every = snap_step(dt_asked, spacing, m.name in ADAPTIVE)
                d = copy.deepcopy(case.scene_dict)
                d["analysis"] = analysis_for(case.scene_dict.get("analysis", {}), m.name, m.params, dt,
                                             case.t_end, every, rtol)
                spec = {"id": len(specs), "case": ci, "method": mi, "dt": dt, "rtol": rtol,
                        "dt_asked": dt_asked,
                        "scene_dict": d, "scene_file": str(case.scene_file),
                        "base_dir": str(case.scene_file.parent), "repeat": study.repeat}
                # impossible combinations are rows too, found without running
                try:
                    from_dict(d, source=str(case.scene_file), base_dir=case.scene_file.parent)
                except SceneError as exc:
                    spec.update(status="incompatible", message=str(exc))
                specs.append(spec)
    return specs, refs, notes


PARAM_COLUMNS = ("run", "study", "case", "scene", "scene_file", "scheme", "contact_schemes",
                 "contact_laws", "contact_stiffness", "method", "integrator", "family", "dt_asked", "dt",
                 "rtol", "mean_step", "t_end", "status", "classification", "message")
METRIC_ORDER = ("max_rel_error", "scd", "mescd", "scd_final", "impact_count", "impact_count_ref",
                "impact_count_error", "impacts_missing", "impacts_extra", "impact_time_error",
                "peak_penetration_error", "peak_force_error", "phase_penetration_error",
                "phase_force_error", "restitution", "restitution_ref", "restitution_error",
                "energy_balance_error", "energy_error", "energy_created")
TAIL_COLUMNS = ("reference", "reference_digits", "below_reference_accuracy", "compared",
                "compare_t_start", "compare_t_end", "compare_points")


def _contact_desc(d):
    cs = list(d.get("contact", [])) + [ch["contact"] for ch in d.get("chain", []) if ch.get("contact")]
    j = lambda key: " ".join(sorted({str(c.get(key)) for c in cs if c.get(key) is not None}))
    return j("scheme"), j("law"), j("stiffness")


def make_row(study, spec, result, ref):
    case, m = study.cases[spec["case"]], study.methods[spec["method"]]
    schemes, laws, stiff = _contact_desc(spec["scene_dict"])
    status = result.get("status")
    row = {"run": spec["id"], "study": study.title, "case": case.label, "scene": case.scene_label,
           "scene_file": os.path.relpath(case.scene_file, REPO), "scheme": case.scheme_label,
           "contact_schemes": schemes, "contact_laws": laws, "contact_stiffness": stiff,
           "method": m.label, "integrator": m.name,
           "family": json.dumps({k: m.params[k] for k in m.params}, sort_keys=True) if m.params else "",
           "dt_asked": spec.get("dt_asked", spec["dt"]), "dt": spec["dt"],
           "rtol": spec["rtol"] if spec["rtol"] is not None else math.nan,
           "t_end": case.t_end, "status": status,
           "classification": status_class(status, result.get("message", "")),
           "message": (result.get("message") or "").strip()}
    summary = result.get("summary")
    if summary is not None and status in ("MARTELLO_OK", "MARTELLO_ILL_CONDITIONED", "MARTELLO_ROOT_FOUND"):
        row.update(score(summary, result["history"], ref, columns=study.compare["histories"],
                         atol=study.compare["atol"], rtol=study.compare["rtol"],
                         window=study.compare["window"], points=study.compare["points"]))
        steps = summary["cost"].get("steps") or 0
        row["mean_step"] = case.t_end / steps if steps else math.nan
        d = row.get("reference_digits", math.nan)
        e = row.get("max_rel_error", math.nan)
        row["below_reference_accuracy"] = bool(d == d and e == e and e < 10 * 10.0 ** (-d))
    elif summary is not None:
        # a failed run: its cost is real, its accuracy metrics are not
        row.update(cost(summary))
        row["t_reached"] = summary.get("t_reached")
    return row


def write_csv(rows, path):
    keys = list(PARAM_COLUMNS)
    metric_keys = [k for k in METRIC_ORDER if any(k in r for r in rows)]
    abs_keys = sorted({k for r in rows for k in r if k.startswith("max_abs_error:")})
    cost_keys = [k for k in COST_KEYS]
    rest = sorted({k for r in rows for k in r} - set(keys) - set(metric_keys) - set(abs_keys)
                  - set(cost_keys) - set(TAIL_COLUMNS))
    keys += metric_keys + abs_keys + cost_keys + rest + list(TAIL_COLUMNS)
    with open(path, "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=keys, extrasaction="ignore")
        w.writeheader()
        for r in sorted(rows, key=lambda r: r["run"]):
            w.writerow({k: csv_cell(r.get(k)) for k in keys})
    return keys


# --- orders ----------------------------------------------------------------------------------

def fit_order(x, err, lo=0.0, hi=math.inf):
    """Least-squares slope of log(err) against log(x) over the points with lo < err <= hi
    (the asymptotic range: below hi the method is past its pre-asymptotic regime, above lo
    the reference is still more accurate than the run). Returns (slope, n_points)."""
    x, err = np.asarray(x, float), np.asarray(err, float)
    sel = np.isfinite(x) & np.isfinite(err) & (err > lo) & (err <= hi) & (x > 0)
    if np.count_nonzero(sel) < 3:
        return math.nan, int(np.count_nonzero(sel))
    p = np.polyfit(np.log(x[sel]), np.log(err[sel]), 1)
    return float(p[0]), int(np.count_nonzero(sel))


def orders(study, rows, refs):
    """Measured convergence order of every (case, method) for every plotted metric: the
    slope of error vs Δt (fixed step) or vs rtol (adaptive: tolerance proportionality),
    fitted on the runs classified ok whose error lies in the study's fit range and, for the
    history error, above 100x the reference's trusted accuracy."""
    out = []
    for ci, case in enumerate(study.cases):
        ref = refs.get(ci)
        hist_cols = study.compare["histories"] or ([c for c in ref.columns if c.startswith("u:")] if ref else [])
        digits = ref.trusted_digits(hist_cols) if ref is not None else math.nan
        # errors within 100x the reference's own accuracy measure the reference: not fitted
        floor = 100 * 10.0 ** (-digits) if digits == digits else 0.0
        for mi, m in enumerate(study.methods):
            mine = [r for r in rows if r["case"] == case.label and r["method"] == m.label
                    and r["classification"] == "ok"]
            all_rows = [r for r in rows if r["case"] == case.label and r["method"] == m.label]
            if not all_rows:
                continue
            for metric in study.compare["plot_metrics"]:
                x = [r["rtol"] if m.rtols else r["dt"] for r in mine]
                e = [r.get(metric, math.nan) for r in mine]
                lo = max(study.compare["fit"][0], floor if metric == "max_rel_error" else 0.0)
                p, n = fit_order(x, e, lo, study.compare["fit"][1])
                out.append({"case": case.label, "method": m.label, "integrator": m.name,
                            "metric": metric, "against": "rtol" if m.rtols else "dt",
                            "order": p, "theoretical": m.order if m.order is not None else math.nan,
                            "points_fitted": n, "runs": len(all_rows), "runs_ok": len(mine),
                            "not_ok": ", ".join(sorted({r["classification"] for r in all_rows
                                                        if r["classification"] != "ok"})),
                            "min_error": min((v for v in e if v == v), default=math.nan),
                            "wall_time_s": sum(r.get("wall_time_s", 0.0) or 0.0 for r in mine)})
    return out


# --- plots -----------------------------------------------------------------------------------

METRIC_LABELS = {"max_rel_error": "max relative error of u (normwise)",
                 "impact_time_error": "impact time error after matching [s]",
                 "peak_penetration_error": "peak penetration error (relative)",
                 "peak_force_error": "peak force error (relative)",
                 "restitution_error": "restitution error |e − e_ref|",
                 "energy_error": "mechanical energy error at the end (relative)"}


def plot_case(study, case, ci, rows, order_rows, ref, outdir):
    """One PNG per case: a row per plotted metric; columns: error vs Δt for the fixed-step
    methods (legend: measured order p), error vs wall time (legend: the adaptive methods'
    slope against rtol), error vs residual evaluations. Runs that diverged or failed are
    crosses at the top of the first panel; the reference's trusted accuracy is a dotted line
    where it bounds what is shown."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.lines import Line2D

    mets = study.compare["plot_metrics"]
    fig, axes = plt.subplots(len(mets), 3, figsize=(14, 3.9 * len(mets) + 0.9), squeeze=False)
    colors = plt.rcParams["axes.prop_cycle"].by_key()["color"] + ["#444444", "#a0522d", "#008080"]
    markers = "osD^v<>pPX*h"
    hist_cols = study.compare["histories"] or ([c for c in ref.columns if c.startswith("u:")] if ref else [])
    digits = ref.trusted_digits(hist_cols) if ref is not None else math.nan
    handles = []
    for mi, m in enumerate(study.methods):
        mine = sorted([r for r in rows if r["case"] == case.label and r["method"] == m.label],
                      key=lambda r: (r["rtol"] if m.rtols else r["dt"]))
        if not mine:
            continue
        col, mk = colors[mi % len(colors)], markers[mi % len(markers)]
        ok = [r for r in mine if r["classification"] == "ok"]
        bad = [r for r in mine if r["classification"] not in ("ok", "incompatible", "unsupported")]
        if ok or bad:
            handles.append(Line2D([], [], color=col, marker=mk, ms=5, label=m.label))
        for k, metric in enumerate(mets):
            o = next((x for x in order_rows if x["case"] == case.label and x["method"] == m.label
                      and x["metric"] == metric), None)
            p = o["order"] if o else math.nan
            tag = f"p = {p:.2f}" if p == p else "p = –"
            if m.rtols:
                tag = f"slope vs rtol = {p:.2f}" if p == p else "slope vs rtol = –"
            if m.order is not None:
                tag += f" (theory {m.order:g})"
            e = np.array([r.get(metric, math.nan) for r in ok], float)
            good = np.isfinite(e) & (e > 0)
            wall = np.array([r.get("wall_time_s", math.nan) for r in ok], float)
            res = np.array([r.get("residual_evaluations", math.nan) for r in ok], float)
            if np.any(good):
                if not m.rtols:      # adaptive steps are bounded by the output interval: no Δt
                    axes[k, 0].loglog(np.array([r["dt"] for r in ok], float)[good], e[good],
                                      marker=mk, color=col, ms=4, lw=1.2, label=f"{m.label}: {tag}")
                axes[k, 1].loglog(wall[good], e[good], marker=mk, color=col, ms=4, lw=1.2,
                                  label=f"{m.label}: {tag}" if m.rtols else None)
                axes[k, 2].loglog(res[good], e[good], marker=mk, color=col, ms=4, lw=1.2)
            if bad and k == 0 and not m.rtols:
                axes[k, 0].plot([r["dt"] for r in bad], [1.0] * len(bad), ls="none", marker="x",
                                color=col, ms=8, label=f"{m.label}: diverged/failed")
    for k, metric in enumerate(mets):
        for j, xl in enumerate(("Δt [s] (fixed-step methods)", "wall time [s]",
                                "residual evaluations")):
            ax = axes[k, j]
            ax.set_xlabel(xl, fontsize=8)
            ax.set_ylabel(METRIC_LABELS.get(metric, metric), fontsize=8)
            ax.tick_params(labelsize=7)
            ax.grid(True, which="both", alpha=0.3)
            lo = min((ln.get_ydata().min() for ln in ax.get_lines() if len(ln.get_ydata())),
                     default=math.inf)
            if metric == "max_rel_error" and digits == digits and 10.0 ** (-digits) > lo / 1e3:
                # only where it bounds what the plot shows
                ax.axhline(10.0 ** (-digits), color="k", ls=":", lw=1,
                           label=f"reference trusted to {digits:.1f} digits" if j < 2 else None)
            if j < 2 and ax.get_legend_handles_labels()[0]:
                ax.legend(fontsize=6, loc="best", framealpha=0.7)
        axes[k, 0].set_title("error vs step (measured order p)", fontsize=9)
        axes[k, 1].set_title("work-precision: wall time", fontsize=9)
        axes[k, 2].set_title("work-precision: residual evaluations", fontsize=9)
    trust = f", trusted to {digits:.1f} digits" if digits == digits else ""
    fig.suptitle(f"{study.title}\n{case.label} — reference: {ref.name if ref else 'none'}{trust}",
                 fontsize=10)
    if handles:
        fig.legend(handles=handles, loc="lower center", ncol=min(len(handles), 6), fontsize=7,
                   frameon=False)
    fig.tight_layout(rect=(0, 0.05, 1, 1))
    p = outdir / f"{slug(study.path.stem)}__{slug(case.label)}.png"
    # a palette image: a fraction of the size of a full-colour one, for plots meant for docs/
    fig.savefig(p, dpi=80)
    palette_png(p)
    plt.close(fig)
    return p


def _markdown(study, rows, order_rows, refs, notes, pngs, elapsed, path, of=None):
    """study.md; `of` (the number of runs of the study) for a partial output: the rows so far,
    no orders or plots."""
    lines = [f"# {study.title}", "", study.description.strip(), ""]
    if of is not None:
        lines += [f"**Partial: {len(rows)} of {of} runs** (the study was interrupted; the same "
                  f"command runs the other {of - len(rows)} and writes the orders and plots; "
                  "resume.jsonl holds the rows it keeps).", ""]
    lines += [f"{len(rows)} runs in {elapsed:.1f} s; martello {native.version()} "
              f"({native.library_versions()}); {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}.", ""]
    counts = {}
    for r in rows:
        counts[r["classification"]] = counts.get(r["classification"], 0) + 1
    lines += ["Outcomes: " + ", ".join(f"{v} {k}" for k, v in sorted(counts.items())), ""]
    lines += ["| case | method | metric | measured order | theory | points fitted | runs ok/all | smallest error | not ok |",
              "|---|---|---|---|---|---|---|---|---|"]
    for o in order_rows:
        lines.append(f"| {md_cell(o['case'])} | {md_cell(o['method'])} | "
                     f"{md_cell(o['metric'])} ({md_cell(o['against'])}) | "
                     f"{o['order']:.2f} | {o['theoretical']:g} | {o['points_fitted']} | "
                     f"{o['runs_ok']}/{o['runs']} | {o['min_error']:.2e} | {o['not_ok']} |"
                     .replace("nan", "–"))
    lines += ["", "References:", ""]
    for ci, case in enumerate(study.cases):
        ref = refs.get(ci)
        lines.append(f"- {case.label}: {ref.name if ref else 'none'}"
                     + (f", trusted to {ref.trusted_digits():.1f} digits" if ref else ""))
    if notes:
        lines += ["", "Notes:", ""] + [f"- {n}" for n in notes]
    for p in pngs:
        lines += ["", f"![{p.stem}]({p.name})"]
    path.write_text("\n".join(lines) + "\n")


def _key(study, spec, ref):
    """What a row's values depend on (martello.study.resume): the run (its scene and
    settings), its case and method, the reference and the scoring, the version."""
    case, m = study.cases[spec["case"]], study.methods[spec["method"]]
    reference = None if ref is None else (ref.name, ref.kind, ref.t_end, ref.columns, ref.digits,
                                          ref.provenance)
    return row_key({k: v for k, v in spec.items() if k != "id"}, study.title, study.compare,
                   case.label, case.scene_label, case.scheme_label, str(case.scene_file),
                   case.t_end, m.label, m.name, m.params, reference, native.version())


def run_study(study, outdir, jobs=0, plots=True, stream=None, executor=None, where=None):
    """Run a loaded study; write runs.csv, orders.csv, study.md and the plots in outdir.
    The runs go to local processes, or to `executor` (a Dask cluster's: study.cluster),
    described by `where`. A signal stops it, keeping the rows finished in outdir, and the
    same call resumes it (martello.study.resume: Stopped is raised). Returns (rows,
    order_rows)."""
    stream = stream or sys.stderr
    t0 = time.perf_counter()
    specs, refs, notes = build_specs(study)
    by_id = {s["id"]: s for s in specs}
    keys = {s["id"]: _key(study, s, refs.get(s["case"])) for s in specs}
    check_output_folder(outdir, "runs.csv", MartelloError)     # before anything is said
    print(f"{study.title}: {len(study.cases)} case(s) x {len(study.methods)} method(s): "
          f"{len(specs)} runs on {where or f'{jobs or os.cpu_count()} worker(s)'}", file=stream)
    order_rows = []

    def run(ids, stop):
        progress = Progress(len(ids), stream=stream)
        for res in run_specs([by_id[i] for i in ids], jobs, progress, executor=executor, stop=stop):
            spec = by_id[res["id"]]
            yield res["id"], make_row(study, spec, res, refs.get(spec["case"]))

    def finish(folder, rows):
        order_rows[:] = orders(study, rows, refs)
        write_csv(rows, folder / "runs.csv")
        with open(folder / "orders.csv", "w", newline="") as fh:
            if order_rows:
                w = csv.DictWriter(fh, fieldnames=list(order_rows[0]))
                w.writeheader()
                w.writerows({k: csv_cell(v) for k, v in o.items()} for o in order_rows)
        pngs = []
        if plots:
            for ci, case in enumerate(study.cases):
                if any(r["case"] == case.label for r in rows):
                    pngs.append(plot_case(study, case, ci, rows, order_rows, refs.get(ci), folder))
        _markdown(study, rows, order_rows, refs, notes, pngs, time.perf_counter() - t0,
                  folder / "study.md")

    def partial(folder, rows):
        write_csv(rows, folder / "runs.csv")
        _markdown(study, rows, [], refs, notes, [], time.perf_counter() - t0, folder / "study.md",
                  of=len(specs))

    # the folder is refused before any run if it is not a study's, and replaced whole once
    # everything is written (docs/studies.md)
    rows = run_resumable(outdir, "runs.csv", keys, run, finish, partial, stream)
    for n in notes:
        print(f"note: {n}", file=stream)
    return rows, order_rows


def scheduler_of(args, study, stream=None):
    """(address, where it came from) of the Dask scheduler the study runs on, or (None, None)
    for local processes. Only the command line names one: --scheduler ADDRESS, or the study
    file's `scheduler` when --use-study-scheduler says so (Dask exchanges pickled objects with
    its scheduler: a study file from someone else must not make this machine connect to a
    server of their choosing). A file's scheduler not used is said in a note."""
    given = getattr(args, "scheduler", None)
    if given:
        return given, "given by --scheduler"
    if not study.scheduler:
        return None, None
    if not getattr(args, "use_study_scheduler", False):
        print(f"note: {study.path} names a Dask scheduler (scheduler = {study.scheduler!r}), "
              "not used: the runs go to local processes (--use-study-scheduler runs them there)",
              file=stream or sys.stderr)
        return None, None
    address = study.scheduler
    if address.endswith(".json") and not Path(address).is_absolute():
        address = str(study.path.parent / address)     # a scheduler file beside the study file
    return address, f"the scheduler of {study.path}, used by --use-study-scheduler"


def output_folder(path, study, output=None):
    """The folder a study writes: `output` if given, else the study's `output` key (relative
    to the repository in a checkout, to the working folder once installed), else
    out/studies/<file name>."""
    if output:
        return Path(output)
    return OUTPUT_ROOT / study.output if study.output else Path("out") / "studies" / Path(path).stem


def main(args):
    path = Path(args.study)
    study = load_study(path)
    out = output_folder(path, study, args.output)
    scheduler, origin = scheduler_of(args, study)
    plots = not getattr(args, "no_plots", False)
    if scheduler:
        from .cluster import dask_executor
        with dask_executor(scheduler, origin) as (executor, workers):
            rows, order_rows = run_study(study, out, executor=executor, plots=plots,
                                         where=f"the Dask cluster at {scheduler} ({origin}; "
                                               f"{workers} worker(s))")
    else:
        rows, order_rows = run_study(study, out, jobs=getattr(args, "jobs", 0) or 0, plots=plots)
    counts = {}
    for r in rows:
        counts[r["classification"]] = counts.get(r["classification"], 0) + 1
    print(f"{study.title}: {len(rows)} runs (" + ", ".join(f"{v} {k}" for k, v in sorted(counts.items()))
          + f") -> {out / 'runs.csv'}")
    for o in order_rows:
        if o["metric"] == study.compare["plot_metrics"][0]:
            print(f"  {o['case'][:40]:<40} {o['method'][:44]:<44} p = {o['order']:5.2f}"
                  + (f" (theory {o['theoretical']:g})" if o["theoretical"] == o["theoretical"] else ""))
    return failed_rows(rows, "status", out / "runs.csv")

