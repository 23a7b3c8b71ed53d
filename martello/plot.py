"""`martello plot DIR`: pictures of a run folder (`martello run`: summary.json, history.csv)
or of a study folder (`martello study`: runs.csv, orders.csv), as PNG and SVG with labelled
axes in SI units (docs/plot.md).

A run: displacement and contact-force histories, phase portraits (v against u), contact
force against penetration (a Kelvin or Hunt–Crossley law draws a loop whose area is the
energy it dissipates), link force against elongation (hysteresis loops of bilinear springs
and dampers, when the run wrote link histories) and the energy terms with their balance.
A study: for each case, error against Δt (the measured order in the legend) and
work-precision (error against wall time and against residual evaluations)."""

from __future__ import annotations

import csv
import json
import math
from pathlib import Path

import numpy as np

from .errors import MartelloError
from .history import parse_csv
from .paths import MiB, UnreadableFile, read_input
from .study.output import slug
from .study.sweep import METRIC_LABELS

FORMATS = ("png", "svg")
# The energy terms of history.csv (docs/results.md#energy) a person reads, with their
# meaning; balance is drawn on its own axis (it is ≈ 0, a check of the others).
ENERGY_TERMS = {"kinetic": "kinetic ½vᵀMv", "recoverable": "recoverable (springs, contacts)",
                "input": "input (work of the loads)", "damping": "dissipated by dampers",
                "plastic": "dissipated by yielding", "contact": "dissipated by contact laws",
                "impact": "taken out by impulses", "initial": "initial"}


class PlotError(MartelloError):
    """A folder that holds neither a run nor a study, or an option that names nothing."""


def _pyplot():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    # SVG text stays text (searchable, editable, small); a fixed salt for its ids: the same
    # history gives the same file
    plt.rcParams.update({"svg.fonttype": "none", "svg.hashsalt": "martello"})
    return plt


def _save(fig, outdir, stem, formats):
    # made at the first picture, once the inputs are read: a folder that cannot be plotted
    # leaves nothing behind
    try:
        outdir.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise PlotError(f"{outdir}: cannot create the folder for the pictures: "
                        f"{exc.strerror or exc}") from None
    paths = []
    for fmt in formats:
        p = outdir / f"{stem}.{fmt}"
        # no date in the SVG: the same run gives the same file
        fig.savefig(p, dpi=110, metadata={"Date": None} if fmt == "svg" else None)
        paths.append(p)
    _pyplot().close(fig)
    return paths


def _panels(plt, n, width, height):
    """A grid of n panels, three to a row: (figure, the n axes); unused cells are hidden."""
    ncol = min(3, n)
    nrow = math.ceil(n / ncol)
    fig, axes = plt.subplots(nrow, ncol, figsize=(width * ncol, height * nrow + 0.8), squeeze=False)
    flat = list(axes.ravel())
    for ax in flat[n:]:
        ax.axis("off")
    return fig, flat[:n]


def _finish(fig, title, outdir, stem, formats):
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return _save(fig, outdir, stem, formats)


# what a run folder's files may weigh to be read here (a large scene writes its per-item
# results as arrays, not in summary.json: docs/results.md)
SUMMARY_LIMIT, HISTORY_LIMIT = 1024 * MiB, 4096 * MiB
RERUN = "written by martello run: run the scene again to write it whole"


def _bytes(path, limit):
    try:
        return read_input(path, limit)
    except UnreadableFile as exc:
        raise PlotError(f"{path}: {exc}") from None


def read_run_history(path):
    """history.csv of a run as (columns, {column: values}); NaN is allowed (link columns of
    an integrator that does not report links). A file cut short or edited is one PlotError
    naming the line (martello.history.parse_csv)."""
    def error(problem, fix, line):
        where = f"{path}:{line}" if line else str(path)
        return PlotError(f"{where}: {problem} ({fix or RERUN})")
    header, data = parse_csv(_bytes(path, HISTORY_LIMIT), error, finite=False)
    return header, {c: data[:, i] for i, c in enumerate(header)}


def read_run_summary(path):
    """summary.json of a run as a dict; PlotError if it is not one (cut short, edited)."""
    try:
        summary = json.loads(_bytes(path, SUMMARY_LIMIT))
    except (ValueError, UnicodeDecodeError) as exc:
        raise PlotError(f"{path}: not valid JSON ({' '.join(str(exc).split())}) ({RERUN})") from None
    if not isinstance(summary, dict):
        raise PlotError(f"{path}: holds a {type(summary).__name__}, not a run's summary ({RERUN})")
    return summary


def read_table(path, required):
    """The rows of a study's CSV (runs.csv, orders.csv) as dicts; PlotError naming the file
    and line if it is not one: not UTF-8 text, a column of `required` missing, a row cut
    short or with more cells than the header."""
    try:
        text = _bytes(path, SUMMARY_LIMIT).decode("utf-8")
    except UnicodeDecodeError as exc:
        raise PlotError(f"{path}: byte {exc.start + 1} is not UTF-8 text (written by martello "
                        "study: run the study again to write it whole)") from None
    reader = csv.DictReader(text.splitlines())
    missing = [c for c in required if c not in (reader.fieldnames or [])]
    if missing:
        raise PlotError(f"{path}: no column {', '.join(missing)}: not a file written by martello "
                        "study (run the study again to write it whole)")
    rows = []
    for row in reader:
        if None in row or None in row.values():
            raise PlotError(f"{path}:{reader.line_num}: the row has "
                            f"{'more' if None in row else 'fewer'} cells than the header (the file "
                            "was cut short or edited: run the study again to write it whole)")
        rows.append(row)
    return rows


def _table(d, key):
    """d[key] if it is a table (a dict), else an empty one: what plot_run reads of a summary
    is labels, and a label that is missing or edited is left out, not an error."""
    v = d.get(key) if isinstance(d, dict) else None
    return v if isinstance(v, dict) else {}


def _names(columns, kind):
    return [c.partition(":")[2] for c in columns if c.startswith(kind + ":")]


def _select(available, wanted, what, limit):
    if wanted:
        bad = [w for w in wanted if w not in available]
        if bad:
            raise PlotError(f"--{what}: {', '.join(bad)} not in the history; it has "
                            + (", ".join(available) or "none"))
        return list(wanted)
    return available[:limit]


def plot_run(folder, outdir, formats=FORMATS, nodes=None, contacts=None, limit=6):
    """The pictures of one run; returns the files written."""
    folder = Path(folder)
    summary = read_run_summary(folder / "summary.json")
    if not (folder / "history.csv").exists():
        raise PlotError(f"{folder}: a static run (summary.json, no history.csv): nothing to plot "
                        "over time; its numbers are in summary.json")
    columns, h = read_run_history(folder / "history.csv")
    plt = _pyplot()
    t = h["t"]
    an = _table(summary, "analysis")
    spacing = float(np.median(np.diff(t)))
    dt = an.get("dt")
    title = (f"{summary.get('title', folder.name)}\n{an.get('integrator', '')}"
             + (f", Δt = {dt:g} s" if isinstance(dt, (int, float)) else "")
             + f", samples every {spacing:.3g} s — {summary.get('status', '')}")
    all_nodes, all_contacts = _names(columns, "u"), _names(columns, "force")
    node_sel = _select(all_nodes, nodes, "nodes", limit)
    contact_sel = _select(all_contacts, contacts, "contacts", limit)
    shown = lambda sel, all_, word: (f" ({len(sel)} of {len(all_)} {word}; choose with --{word})"
                                     if len(sel) < len(all_) else "")
    files = []

    # displacement and contact-force histories
    rows = 2 if contact_sel else 1
    fig, axes = plt.subplots(rows, 1, figsize=(9, 3.2 * rows + 0.8), sharex=True, squeeze=False)
    for n in node_sel:
        axes[0, 0].plot(t, h[f"u:{n}"], lw=1.1, label=n)
    axes[0, 0].set_ylabel("displacement u [m]")
    axes[0, 0].set_title("displacement" + shown(node_sel, all_nodes, "nodes"), fontsize=9)
    if contact_sel:
        for c in contact_sel:
            axes[1, 0].plot(t, h[f"force:{c}"], lw=1.1, label=c)
        axes[1, 0].set_ylabel("contact force P [N]\n(compressive > 0)")
        axes[1, 0].set_title("contact force" + shown(contact_sel, all_contacts, "contacts"), fontsize=9)
    axes[-1, 0].set_xlabel("time t [s]")
    for ax in axes[:, 0]:
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=7, loc="best", ncol=2)
    files += _finish(fig, title, outdir, "histories", formats)

    # phase portraits
    with_v = [n for n in node_sel if f"v:{n}" in h]
    if with_v:
        fig, axes = _panels(plt, len(with_v), 4.2, 3.6)
        for ax, n in zip(axes, with_v):
            ax.plot(h[f"u:{n}"], h[f"v:{n}"], lw=0.9)
            ax.plot(h[f"u:{n}"][0], h[f"v:{n}"][0], "o", ms=4, color="k", label="t = 0")
            ax.ticklabel_format(style="sci", scilimits=(-2, 4), useMathText=True)
            ax.set_xlabel(f"u:{n} [m]")
            ax.set_ylabel(f"v:{n} [m/s]")
            ax.set_title(f"phase portrait of {n}", fontsize=9)
            ax.grid(True, alpha=0.3)
            ax.legend(fontsize=7)
        files += _finish(fig, title, outdir, "phase", formats)

    # force against penetration, one line per contact phase (no line across the open gap)
    loops = [c for c in contact_sel if f"penetration:{c}" in h]
    if loops:
        fig, axes = plt.subplots(1, len(loops), figsize=(max(6.5, 4.6 * len(loops)), 4.4),
                                 squeeze=False)
        for k, c in enumerate(loops):
            ax = axes[0, k]
            d, p = h[f"penetration:{c}"], h[f"force:{c}"]
            on = (d > 0) | (p != 0)
            edges = np.flatnonzero(np.diff(np.concatenate([[0], on.astype(int), [0]])))
            for a, b in zip(edges[::2], edges[1::2]):
                ax.plot(d[a:b], p[a:b], lw=1.0, color="C0", marker=".", ms=2)
            ax.axvline(0.0, color="k", lw=0.6, alpha=0.5)
            ax.ticklabel_format(axis="x", style="sci", scilimits=(-2, 3), useMathText=True)
            ax.set_xlabel(f"penetration δ of {c} [m] (> 0 in contact)")
            ax.set_ylabel("contact force P [N]")
            law = _table(_table(summary, "contacts"), c)
            ax.set_title(f"{c}: {law.get('scheme', '')} {law.get('law') or ''}, "
                         f"{len(edges) // 2} contact phase(s)", fontsize=9)
            ax.grid(True, alpha=0.3)
        files += _finish(fig, title, outdir, "force_penetration", formats)

    # link force against elongation (hysteresis loops)
    links = [ln for ln in _names(columns, "link_force")
             if f"elongation:{ln}" in h and np.all(np.isfinite(h[f"link_force:{ln}"]))][:limit]
    if links:
        fig, axes = _panels(plt, len(links), 4.4, 3.8)
        for ax, ln in zip(axes, links):
            ax.plot(h[f"elongation:{ln}"], h[f"link_force:{ln}"], lw=0.9)
            ax.ticklabel_format(style="sci", scilimits=(-2, 4), useMathText=True)
            kind = _table(_table(summary, "links"), ln).get("type", "")
            ax.set_xlabel("elongation u_a − u_b [m]")
            ax.set_ylabel("link force f [N]")
            ax.set_title(f"{ln} ({kind})", fontsize=9)
            ax.grid(True, alpha=0.3)
        files += _finish(fig, title, outdir, "hysteresis", formats)

    # energy terms and their balance
    present = [k for k in ENERGY_TERMS if f"energy:{k}" in h]
    big = max((float(np.max(np.abs(h[f"energy:{k}"]))) for k in present), default=0.0)
    # terms that are round-off (below 1e-9 of the largest) are left out of the legend
    terms = [k for k in present if float(np.max(np.abs(h[f"energy:{k}"]))) > 1e-9 * big]
    if terms:
        fig, axes = plt.subplots(2, 1, figsize=(9, 6.2), sharex=True,
                                 gridspec_kw={"height_ratios": [3, 1.3]})
        for k in terms:
            axes[0].plot(t, h[f"energy:{k}"], lw=1.1, label=ENERGY_TERMS[k])
        axes[0].set_ylabel("energy [J]")
        axes[0].set_title("energy terms (docs/results.md#energy)", fontsize=9)
        axes[0].legend(fontsize=7, loc="best")
        if "energy:balance" in h:
            axes[1].plot(t, h["energy:balance"], lw=1.0, color="k")
        axes[1].set_ylabel("balance [J]\n(≈ 0)")
        axes[1].set_xlabel("time t [s]")
        for ax in axes:
            ax.grid(True, alpha=0.3)
        files += _finish(fig, title, outdir, "energy", formats)
    return files


def _num(x):
    try:
        return float(x) if x not in ("", None) else math.nan
    except ValueError:
        return math.nan


def plot_study(folder, outdir, formats=FORMATS, metric="max_rel_error"):
    """The pictures of a study folder, from its runs.csv (and orders.csv): per case, error
    against Δt and work-precision. Returns the files written."""
    folder = Path(folder)
    runs = read_table(folder / "runs.csv", ("case", "method", "classification", "dt", "rtol"))
    if not runs:
        raise PlotError(f"{folder / 'runs.csv'}: no runs")
    if metric not in runs[0]:
        metrics = [k for k in runs[0] if k in METRIC_LABELS or k.endswith("_error")]
        raise PlotError(f"--metric {metric}: not a column of {folder / 'runs.csv'}; it has "
                        + ", ".join(metrics))
    orders = []
    if (folder / "orders.csv").exists():
        orders = read_table(folder / "orders.csv", ("case", "method", "metric", "order"))
    plt = _pyplot()
    files = []
    study = runs[0].get("study", folder.name)
    ylabel = METRIC_LABELS.get(metric, metric)
    for case in dict.fromkeys(r["case"] for r in runs):
        mine = [r for r in runs if r["case"] == case]
        digits = _num(mine[0].get("reference_digits"))
        if not abs(digits) < 300:      # not a number of digits a reference can have
            digits = math.nan
        fig, axes = plt.subplots(1, 3, figsize=(15, 4.6))
        for mi, method in enumerate(dict.fromkeys(r["method"] for r in mine)):
            rs = [r for r in mine if r["method"] == method and r["classification"] == "ok"]
            bad = [r for r in mine if r["method"] == method and r["classification"] not in
                   ("ok", "incompatible", "unsupported")]
            adaptive = any(_num(r["rtol"]) == _num(r["rtol"]) for r in rs)
            x = np.array([_num(r["rtol"] if adaptive else r["dt"]) for r in rs])
            e = np.array([_num(r.get(metric)) for r in rs])
            wall = np.array([_num(r.get("wall_time_s")) for r in rs])
            res = np.array([_num(r.get("residual_evaluations")) for r in rs])
            order = next((o for o in orders if o["case"] == case and o["method"] == method
                          and o["metric"] == metric), None)
            p = _num(order["order"]) if order else math.nan
            tag = method + (f": {'slope vs rtol' if adaptive else 'p'} = {p:.2f}" if p == p else "")
            style = dict(marker="osD^v<>pPX*h"[mi % 12], color=f"C{mi % 10}", ms=4, lw=1.2)
            srt = np.argsort(x)
            good = np.isfinite(e[srt]) & (e[srt] > 0)
            if not adaptive and np.any(good):
                axes[0].loglog(x[srt][good], e[srt][good], label=tag, **style)
            if np.any(good):
                order_w = np.argsort(wall)
                ok_w = np.isfinite(e[order_w]) & (e[order_w] > 0)
                axes[1].loglog(wall[order_w][ok_w], e[order_w][ok_w], label=tag, **style)
                order_r = np.argsort(res)
                ok_r = np.isfinite(e[order_r]) & (e[order_r] > 0)
                axes[2].loglog(res[order_r][ok_r], e[order_r][ok_r], label=method, **style)
            if bad and not adaptive:
                axes[0].plot([_num(r["dt"]) for r in bad], [1.0] * len(bad), ls="none", marker="x",
                             color=style["color"], ms=8, label=f"{method}: diverged or failed")
        for ax, xl, ti in ((axes[0], "time step Δt [s] (fixed-step methods)", "error against Δt"),
                           (axes[1], "wall time [s]", "work-precision: wall time"),
                           (axes[2], "residual evaluations [count]", "work-precision: residual evaluations")):
            ax.set_xlabel(xl)
            ax.set_ylabel(ylabel)
            ax.set_title(ti, fontsize=9)
            ax.grid(True, which="both", alpha=0.3)
            lo = min((float(np.nanmin(ln.get_ydata())) for ln in ax.get_lines()
                      if len(ln.get_ydata())), default=math.inf)
            if metric == "max_rel_error" and digits == digits and 10.0 ** -digits > lo / 1e3:
                # only where it bounds what the plot shows (as the study's own plots)
                ax.axhline(10.0 ** -digits, color="k", ls=":", lw=1,
                           label=f"reference trusted to {digits:.1f} digits")
            if ax.get_legend_handles_labels()[0]:
                ax.legend(fontsize=7, loc="best", framealpha=0.7)
        ref = mine[0].get("reference") or "none"
        fig.suptitle(f"{study}\n{case} — reference: {ref}", fontsize=10)
        fig.tight_layout()
        files += _save(fig, outdir, f"study__{slug(case)}", formats)
    return files


def plot_folder(folder, output=None, formats=FORMATS, **options):
    """The pictures of a run or a study folder, written to output (default DIR/plots)."""
    folder = Path(folder)
    if not folder.is_dir():
        raise PlotError(f"{folder}: no such folder (give a folder written by martello run or "
                        "martello study)")
    bad = [f for f in formats if f not in FORMATS]
    if bad or not formats:
        raise PlotError(f"--format {','.join(formats)}: give png, svg or png,svg")
    outdir = Path(output) if output else folder / "plots"
    if (folder / "summary.json").exists():
        kind, fn = "run", plot_run
        options.pop("metric", None)
    elif (folder / "runs.csv").exists():
        kind, fn = "study", plot_study
        options = {"metric": options["metric"]} if options.get("metric") else {}
    else:
        raise PlotError(f"{folder}: neither a run folder (summary.json and history.csv, written by "
                        "martello run) nor a study folder (runs.csv, written by martello study)")
    return kind, fn(folder, outdir, formats, **{k: v for k, v in options.items() if v is not None})


def main(args):
    formats = tuple(f.strip() for f in args.format.split(",") if f.strip())
    split = lambda s: [x.strip() for x in s.split(",") if x.strip()] if s else None
    kind, files = plot_folder(args.folder, args.output, formats, nodes=split(args.nodes),
                              contacts=split(args.contacts), metric=args.metric)
    stems = sorted({f.stem for f in files})
    print(f"{args.folder}: {kind}, {len(files)} file(s) in {files[0].parent if files else '-'}: "
          + ", ".join(stems) + f" ({', '.join(formats)})")
    return 0
