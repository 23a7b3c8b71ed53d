"""`martello compare THEIR.csv --against SCENE`: score another code's time history with the
metrics martello uses on its own runs (martello.metrics), so a researcher can verify a code
against martello's closed forms and reference data. The CSV format is documented in
docs/compare.md: a header row, then one row per time; column t (s) and any of u:<node>,
v:<node>, a:<node> (m, m/s, m/s²), penetration:<contact> (m, > 0 in contact), force:<contact>
(N, compressive > 0), link_force:<link>, elongation:<link> (N, m) and energy:kinetic,
energy:recoverable (J) — exactly as in martello's own history.csv, so a martello run can be
fed back as a self-check. OpenSees node recorder files (whitespace-separated, a time column,
no header) are read too, their columns named on the command line (read_recorder). A scene
with neither a closed form nor stored reference data gets a reference computed on demand and
cached (martello.reference.cache)."""

from __future__ import annotations

import csv
import json
import math
import sys
from pathlib import Path

import numpy as np

from .checks.verify import digits, lookup, oracle_values
from .errors import MartelloError
from .history import history_dict, parse_csv
from .paths import MiB, UnreadableFile, check_regular, read_input, write_text_atomic
from .metrics.from_history import summary_from_history
from .metrics.score import COST_KEYS, history_errors, score
from .reference.base import CLOSED_FORM_DIGITS
from .reference.selection import reference_for_scene
from .scene.loader import load

NODE_KINDS = ("u", "v", "a")
CONTACT_KINDS = ("penetration", "force")
# martello's own history.csv also records each link's state (docs/results.md): accepted so
# a martello run can be fed back, and scored wherever the reference records the same column
LINK_KINDS = ("link_force", "elongation")
# A history to compare is at most this large (a million rows of 50 columns).
HISTORY_LIMIT = 1024 * MiB
ENERGY_COLUMNS = ("energy:kinetic", "energy:recoverable", "energy:input", "energy:damping",
                  "energy:plastic", "energy:contact", "energy:balance", "energy:initial",
                  "energy:impact")


class HistoryError(MartelloError):
    """A history CSV is unreadable or inconsistent: the message names the file, the row or
    column, and what would be valid."""

    def __init__(self, file, problem, fix=None, row=None):
        where = f"{file}:{row}" if row is not None else str(file)
        super().__init__(f"{where}: {problem}" + (f" ({fix})" if fix else ""))


def _check_names(path, header, scene, hline):
    """Every column names a node or contact of the scene, with a known kind."""
    if scene is None:
        return
    nodes = {n["name"] for n in scene.nodes}
    contacts = {c["name"] for c in scene.contacts}
    links = scene.links.names
    for c in header:
        kind, sep, name = c.partition(":")
        if c == "t" or c in ENERGY_COLUMNS:
            continue
        if not sep or kind not in NODE_KINDS + CONTACT_KINDS + LINK_KINDS:
            raise HistoryError(path, f"unknown column {c!r}",
                               "valid: t, u:<node>, v:<node>, a:<node>, penetration:<contact>, "
                               "force:<contact>, link_force:<link>, elongation:<link>, "
                               "energy:kinetic, energy:recoverable, ...", row=hline)
        if kind in NODE_KINDS and name not in nodes:
            raise HistoryError(path, f"column {c!r} names no node of {scene.source}",
                               "nodes: " + ", ".join(sorted(nodes)), row=hline)
        if kind in CONTACT_KINDS and name not in contacts:
            raise HistoryError(path, f"column {c!r} names no contact of {scene.source}",
                               "contacts: " + ", ".join(sorted(contacts)) if contacts else "it has none",
                               row=hline)
        if kind in LINK_KINDS and name not in links:
            raise HistoryError(path, f"column {c!r} names no link of {scene.source}",
                               "links without a name are link<i>", row=hline)


def read_history(path, scene=None):
    """Read and validate a history CSV; returns (columns, 2D array). Lines starting with #
    are comments. Errors name the line: a missing t column, a column that names no node or
    contact of the scene, a non-numeric or non-finite value, times that do not increase
    (martello.history.parse_csv). A link_force:/elongation: column that is NaN in every row
    is read: the run did not record it (docs/results.md); compare reports it so."""
    path = Path(path)
    try:
        raw = read_input(path, HISTORY_LIMIT)
    except UnreadableFile as exc:
        raise HistoryError(path, exc.problem, exc.fix) from None
    return parse_csv(raw, lambda problem, fix, row: HistoryError(path, problem, fix, row=row),
                     check_header=lambda header, line: _check_names(path, header, scene, line),
                     unrecorded=LINK_KINDS)


def split_unrecorded(columns, data):
    """(columns, data) without the link columns that are NaN in every row, and their names:
    an integrator that does not report links writes NaN there (docs/results.md), so the run
    did not record them; a NaN among finite values is an error of read_history's."""
    gone = [j for j, c in enumerate(columns)
            if c.partition(":")[0] in LINK_KINDS and np.isnan(data[:, j]).all()]
    keep = [j for j in range(len(columns)) if j not in gone]
    return [columns[j] for j in keep], data[:, keep], [columns[j] for j in gone]


def is_recorder_file(path):
    """True for a whitespace-separated numeric file without a header (an OpenSees recorder's
    output), False for a CSV with a header row. Only a regular file is opened (a FIFO would
    block the sniffing for ever): anything else is left to read_history's error."""
    try:
        check_regular(path)
    except UnreadableFile:
        return False
    try:
        with open(path) as fh:
            for ln in fh:
                if ln.strip() and not ln.lstrip().startswith("#"):
                    cells = ln.split()
                    if "," in ln or len(cells) < 2:
                        return False
                    try:
                        [float(c) for c in cells]
                    except ValueError:
                        return False
                    return True
    except (OSError, UnicodeDecodeError):
        return False
    return False


def _recorder_names(path, spec, count, scene):
    """The column names of a recorder file's value columns: `spec` ("u:a,-u:b": a leading −
    flips the sign) or, without one, u of every free node of the scene in its order when
    the file has that many value columns. Returns [(name, sign)]."""
    if spec:
        names = [c.strip() for c in spec.split(",") if c.strip()]
    elif scene is not None and count == sum(1 for n in scene.nodes if not n["fixed"]):
        names = [f"u:{n['name']}" for n in scene.nodes if not n["fixed"]]
        print(f"note: {path}: reading its {count} value column(s) as "
              + ", ".join(names) + " (the scene's free nodes in order; name them with --columns)",
              file=sys.stderr)
    else:
        free = [n["name"] for n in scene.nodes if not n["fixed"]] if scene is not None else []
        raise HistoryError(path, f"{count} value column(s) after the time column and no --columns "
                           "naming them", "e.g. --columns " + ",".join(f"u:{n}" for n in free[:count] or ["NODE"])
                           + " (docs/compare.md#opensees-recorder-files)")
    if len(names) != count:
        raise HistoryError(path, f"--columns names {len(names)} column(s), the file has {count} after "
                           "the time column", "one name per recorded value, in the recorder's order")
    return [(n[1:], -1.0) if n.startswith("-") else (n, 1.0) for n in names]


def read_recorder(path, spec=None, scene=None):
    """Read an OpenSees node recorder file (`recorder Node -file F -time -node ... -dof 1
    disp`): whitespace-separated rows, the time first, then one value per node and dof. The
    value columns are named by spec (see _recorder_names); returns (columns, 2D array) as a
    history CSV would give, validated the same way."""
    path = Path(path)
    if not path.exists():
        raise HistoryError(path, "does not exist")
    rows, width = [], None
    with open(path) as fh:
        for i, ln in enumerate(fh, 1):
            if not ln.strip() or ln.lstrip().startswith("#"):
                continue
            cells = ln.split()
            if width is None:
                width = len(cells)
            if len(cells) != width:
                raise HistoryError(path, f"{len(cells)} values, the first row has {width}", row=i)
            try:
                vals = [float(c) for c in cells]
            except ValueError:
                bad = next(c for c in cells if not _is_float(c))
                raise HistoryError(path, f"{bad!r} is not a number", row=i) from None
            if not all(math.isfinite(x) for x in vals):
                raise HistoryError(path, "NaN or inf", "a history must be finite; cut it before the "
                                   "solver failed", row=i)
            rows.append(vals)
    if not rows:
        raise HistoryError(path, "is empty", "rows of time and values (an OpenSees recorder with -time)")
    names = _recorder_names(path, spec, width - 1, scene)
    columns = ["t"] + [n for n, _ in names]
    data = np.array(rows, float)
    data[:, 1:] *= np.array([sg for _, sg in names])
    if len(data) < 2:
        raise HistoryError(path, f"{len(data)} data row(s)", "a history needs at least two times")
    bad = np.nonzero(np.diff(data[:, 0]) <= 0)[0]
    if len(bad):
        i = int(bad[0]) + 1
        raise HistoryError(path, f"time {data[i, 0]!r} (row {i + 1}) does not follow {data[i - 1, 0]!r}",
                           "the first column must be the time, increasing: give the recorder -time")
    _check_names(path, columns, scene, None)
    return columns, data


def _is_float(x):
    try:
        float(x)
        return True
    except ValueError:
        return False


def read_histories(paths, columns=None, scene=None):
    """One history from several files (CSV with a header, or OpenSees recorder files whose
    value columns `columns[i]` names): the first file's times; each further file must have
    the same times, its columns are added. Returns (columns, 2D array)."""
    paths = [paths] if isinstance(paths, (str, Path)) else list(paths)
    columns = list(columns or [])
    if len(columns) > len(paths):
        raise MartelloError(f"--columns given {len(columns)} times for {len(paths)} history file(s): "
                            "give it once per recorder file, in the files' order")
    merged = None
    for i, p in enumerate(paths):
        spec = columns[i] if i < len(columns) else None
        if is_recorder_file(p):
            h = read_recorder(p, spec, scene)
        else:
            if spec:
                raise HistoryError(p, "--columns names the columns of a recorder file; this is a CSV "
                                   "with a header row", "drop --columns for it (or give it last)")
            h = read_history(p, scene)
        if merged is None:
            merged = (list(h[0]), h[1])
            continue
        t0, t1 = merged[1][:, merged[0].index("t")], h[1][:, h[0].index("t")]
        if len(t0) != len(t1) or not np.allclose(t0, t1, rtol=1e-12, atol=0.0):
            raise HistoryError(p, f"its {len(t1)} times differ from those of {paths[0]} ({len(t0)})",
                               "record every file at the same times (OpenSees: the same -dT or none)")
        dup = sorted(set(merged[0]) & set(h[0]) - {"t"})
        if dup:
            raise HistoryError(p, f"column(s) {', '.join(dup)} also in an earlier file")
        keep = [j for j, c in enumerate(h[0]) if c != "t"]
        merged = (merged[0] + [h[0][j] for j in keep], np.column_stack([merged[1], h[1][:, keep]]))
    return merged


def comparable(columns, ref):
    """The columns of a history that the reference also has, u first."""
    order = {"u": 0, "v": 1, "a": 2, "penetration": 3, "force": 4, "link_force": 5, "elongation": 6,
             "energy": 7}
    cols = [c for c in columns if c != "t" and c in ref.columns]
    return sorted(cols, key=lambda c: (order.get(c.partition(":")[0], 9), c))


def compare(history_path, scene_path, columns=None, compute=True, stream=None):
    """Score a history (a CSV, an OpenSees recorder file, or several of them: read_histories)
    against a scene's reference; returns the report dict. A scene with no closed form and no
    stored reference data gets one computed (or taken from the cache) unless compute is
    False (martello.reference.cache)."""
    stream = stream or sys.stderr
    sc = load(scene_path)
    if sc.analysis.get("type") != "dynamic":
        raise MartelloError(f"{scene_path}: a static scene has no time history to compare with "
                            "(compare its nodal values with `martello check`)")
    columns, data, unrecorded = split_unrecorded(*read_histories(history_path, columns, sc))
    history_path = ", ".join(map(str, history_path)) if isinstance(history_path, (list, tuple)) \
        else history_path
    ref = reference_for_scene(sc)
    computed = None
    if ref is None and compute:
        from .reference.cache import reference_for_file
        ref, folder, cached = reference_for_file(scene_path, stream=stream)
        computed = {"folder": str(folder), "cached": cached,
                    "method": ref.provenance["method"], "digits_basis": ref.provenance["digits_basis"]}
        print(f"reference: no closed form and no stored data for {scene_path}: "
              + ("taken from the cache" if cached else "computed and cached") + f" in {folder}",
              file=stream)
    if ref is None:
        raise MartelloError(f"{scene_path}: no reference to compare with: no closed-form history "
                            "and no stored reference data (reference/references.toml; "
                            "scripts/regenerate_reference; or `martello reference` to compute one)")
    cols = comparable(columns, ref)
    if not cols:
        raise HistoryError(history_path, "no column can be compared with the reference"
                           + (f" ({', '.join(unrecorded)}: not recorded by this run, NaN throughout)"
                              if unrecorded else ""),
                           "the reference has " + ", ".join(c for c in ref.columns))
    h = history_dict((columns, data))
    t = h["t"]
    if t[0] > ref.t_end or t[-1] < 0:
        raise HistoryError(history_path, f"its times [{t[0]}, {t[-1]}] s miss the reference's "
                           f"[0, {ref.t_end}] s")
    # a closed form is exact anywhere: compare at their times; stored data at its samples
    times = t[t <= ref.t_end * (1 + 1e-12)] if ref.kind == "closed-form" else None
    summary = summary_from_history(sc, (columns, data))
    span_t = times if times is not None else ref.default_times()
    span_t = span_t[(span_t >= t[0]) & (span_t <= min(t[-1], ref.t_end))]
    rounding, bound = round_off_columns(ref, cols, span_t)
    u_cols = [c for c in cols if c.startswith("u:") and c not in rounding] or \
        [c for c in cols if c not in rounding][:1] or cols[:1]
    m = score(summary, (columns, data), ref, columns=u_cols, times=times)
    per_column = {}
    for c in cols:
        e = history_errors((columns, data), ref, [c], times)
        per_column[c] = {"max_abs_error": e.get(f"max_abs_error:{c}"), "max_rel_error": e["max_rel_error"],
                         "scd": e["scd"], "mescd": e["mescd"], "round_off": c in rounding}
    checks = []
    if sc.check:
        try:
            oracle = oracle_values(sc.check, sc.source)
        except MartelloError:
            oracle = {}
        for item in sc.check["compare"]:
            try:
                value = float(lookup(summary, item["result"]))
            except (KeyError, TypeError, ValueError):
                checks.append({"quantity": item["result"], "note": "not derivable from a history"})
                continue
            try:
                refv = float(oracle[item["oracle"]])
            except (KeyError, TypeError, ValueError):
                checks.append({"quantity": item["result"], "note": "the closed form gives no such value"})
                continue
            tol = (item.get("atol") or 0.0) + (item.get("rtol") or 0.0) * abs(refv)
            checks.append({"quantity": item["result"], "value": value, "reference": refv,
                           "digits": digits(value, refv), "tolerance": tol,
                           "within_catalogue_tolerance": abs(value - refv) <= tol})
    span = [float(t[0]), float(min(t[-1], ref.t_end))]
    return {"history": str(history_path), "scene": str(scene_path), "reference": ref.name,
            "reference_kind": ref.kind, "reference_digits": ref.trusted_digits(u_cols),
            "compared_columns": cols, "unrecorded_columns": unrecorded, "time_span": span, "rows": int(len(t)),
            "score_scd": m.get("scd"), "scored_columns": u_cols, "round_off_columns": rounding,
            "round_off_bound": bound,
            "metrics": {k: v for k, v in m.items() if k not in COST_KEYS},
            "per_column": per_column, "checks": checks, "computed_reference": computed,
            "derived_events": {k: {kk: v[kk] for kk in ("impact_times", "restitution",
                                                        "phase_max_penetration")}
                               for k, v in summary["contacts"].items()}}


def round_off_columns(ref, cols, t):
    """The columns whose reference is round-off: its largest |y_ref| over the compared times is
    not above the reference's own absolute error on that kind of quantity (u, v, a, ...),
    B_kind = max over the kind's columns of max |y_ref| · 10^−digits (the digits it is
    trusted to: a closed form's 13, a computed reference's from its refinement, at most 15).
    Such a column is not known to one digit (a symmetric plan's uy: |uy| ~ 1e-17 m beside
    ux ~ 1e-2 m; a body at rest before an impact: exactly 0), so its relative error says
    nothing: it is reported, not scored (docs/compare.md "Round-off columns"). Returns (the
    columns, {kind: B})."""
    if len(t) == 0:
        return [], {}
    y = ref.at(t, cols)
    peak = {c: float(np.max(np.abs(y[c]))) for c in cols}
    digits = getattr(ref, "digits", {}) or {}
    bound = {}
    for c in cols:
        d = digits.get(c, CLOSED_FORM_DIGITS if ref.kind == "closed-form" else math.nan)
        err = peak[c] * 10.0 ** -min(d, 15.0) if d == d else 0.0
        kind = c.partition(":")[0]
        bound[kind] = max(bound.get(kind, 0.0), err)
    return [c for c in cols if peak[c] <= bound[c.partition(":")[0]]], bound


DESCRIPTIONS = [
    ("scd", "significant correct digits of u, −log10(max error / peak |u_ref|)"),
    ("max_rel_error", "max |u − u_ref| / max |u_ref| (normwise, over the compared span)"),
    ("mescd", "mixed significant correct digits (atol 1e-12, rtol 1e-6), pointwise"),
    ("scd_final", "correct digits of u at the last common time"),
    ("impact_count", "impacts found in the history (penetration sign changes)"),
    ("impact_count_ref", "impacts of the reference over the same span"),
    ("impacts_missing", "reference impacts with no partner in the history"),
    ("impacts_extra", "history impacts with no partner in the reference"),
    ("impact_time_error", "max |Δt| of matched impacts [s]"),
    ("peak_penetration_error", "relative error of the largest penetration"),
    ("peak_force_error", "relative error of the largest contact force"),
    ("phase_penetration_error", "max relative error of each matched phase's peak penetration"),
    ("restitution", "mean realised restitution −δ̇_out/δ̇_in of the history"),
    ("restitution_ref", "the same for the reference"),
    ("restitution_error", "max |e − e_ref| over matched, non-grazing phases"),
    ("energy_error", "error of kinetic + recoverable energy at the end (relative)"),
]


def _fmt(v):
    if v is None or (isinstance(v, float) and math.isnan(v)):
        return "–"
    if isinstance(v, float):
        return f"{v:.6g}"
    return str(v)


def print_report(rep, stream=sys.stdout):
    print(f"{rep['history']} against {rep['scene']}", file=stream)
    print(f"reference: {rep['reference']} (trusted to {rep['reference_digits']:.1f} digits); "
          f"{rep['rows']} rows over [{rep['time_span'][0]:g}, {rep['time_span'][1]:g}] s; "
          f"compared: {', '.join(rep['compared_columns'])}", file=stream)
    if rep["unrecorded_columns"]:
        print(f"not recorded by this run (NaN throughout): {', '.join(rep['unrecorded_columns'])}",
              file=stream)
    print(f"{'metric':<26} {'value':>14}  meaning", file=stream)
    print("-" * 100, file=stream)
    for key, what in DESCRIPTIONS:
        if key in rep["metrics"]:
            print(f"{key:<26} {_fmt(rep['metrics'][key]):>14}  {what}", file=stream)
    print(f"\n{'column':<26} {'max abs error':>14} {'max rel error':>14} {'scd':>6}", file=stream)
    for c, e in rep["per_column"].items():
        print(f"{c:<26} {_fmt(e['max_abs_error']):>14} {_fmt(e['max_rel_error']):>14} "
              f"{_fmt(round(e['scd'], 2) if e['scd'] == e['scd'] else e['scd']):>6}"
              + ("  round-off, not scored" if e.get("round_off") else ""), file=stream)
    if rep["checks"]:
        print("\nscene [check] quantities, from the history:", file=stream)
        for c in rep["checks"]:
            if "note" in c:
                print(f"  {c['quantity']:<40} {c['note']}", file=stream)
            else:
                print(f"  {c['quantity']:<40} {c['value']:.10g} vs {c['reference']:.10g}: "
                      f"{c['digits']:.1f} digits", file=stream)
    if rep.get("round_off_columns"):
        print(f"\nround-off, not scored: {', '.join(rep['round_off_columns'])} (their reference's largest "
              "value is not above the reference's own error on that kind of quantity, " + ", ".join(
                  f"{k} {b:.2g}" for k, b in rep["round_off_bound"].items()
                  if any(c.startswith(k + ":") for c in rep["round_off_columns"]))
              + ": not known to one digit; the metrics above leave them out)", file=stream)
    d = rep["reference_digits"]
    if rep["score_scd"] is not None and d == d and rep["score_scd"] > d - 0.5:
        print(f"\nnote: the history agrees with the reference to about the reference's own accuracy "
              f"({d:.1f} digits): the score is limited by the reference, not by the history", file=stream)


def main(args):
    rep = compare(args.history, args.against, columns=getattr(args, "columns", None))
    print_report(rep)
    if args.output:
        out = Path(args.output)
        try:
            out.parent.mkdir(parents=True, exist_ok=True)
            write_text_atomic(out, json.dumps(_finite(rep), indent=1, default=_json_default) + "\n")
        except OSError as exc:
            raise MartelloError(f"{out}: cannot write the scores: {exc.strerror or exc}") from None
    return 0


def _finite(x):
    """NaN and inf become null: the JSON stays strict (readable by any parser)."""
    if isinstance(x, dict):
        return {k: _finite(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_finite(v) for v in x]
    if isinstance(x, (float, np.floating)) and not math.isfinite(x):
        return None
    return x


def _json_default(x):
    if isinstance(x, (np.floating, np.integer)):
        return x.item()
    if isinstance(x, np.ndarray):
        return x.tolist()
    return str(x)
