"""Time histories: the (columns, 2D array) pair a run writes as history.csv, the same as a
dict of columns, and their interpolation between samples (the comparison of a run with a
reference at times that are not samples of both)."""

from __future__ import annotations

import csv

import numpy as np

# Columns of a history, by prefix (martello's own history.csv; docs/compare.md).
KINDS = ("u", "v", "a", "penetration", "force", "energy")


def hermite(t0, t1, y0, y1, d0, d1, dd0=None, dd1=None, t=None):
    """Cubic (value, slope) or quintic (value, slope, curvature) Hermite interpolant on
    [t0, t1], vectorised over intervals."""
    h = t1 - t0
    s = (t - t0) / h
    if dd0 is None:
        h00 = (1 + 2 * s) * (1 - s) ** 2
        h10 = s * (1 - s) ** 2
        h01 = s * s * (3 - 2 * s)
        h11 = s * s * (s - 1)
        return h00 * y0 + h10 * h * d0 + h01 * y1 + h11 * h * d1
    s2, s3 = s * s, s * s * s
    h0 = 1 - 10 * s3 + 15 * s2 * s2 - 6 * s3 * s2
    h1 = s - 6 * s3 + 8 * s2 * s2 - 3 * s3 * s2
    h2 = 0.5 * (s2 - 3 * s3 + 3 * s2 * s2 - s3 * s2)
    h3 = 0.5 * (s3 - 2 * s2 * s2 + s3 * s2)
    h4 = -4 * s3 + 7 * s2 * s2 - 3 * s3 * s2
    h5 = 10 * s3 - 15 * s2 * s2 + 6 * s3 * s2
    return (h0 * y0 + h1 * h * d0 + h2 * h * h * dd0 + h3 * h * h * dd1 + h4 * h * d1
            + h5 * y1)


def interpolate(times, samples, column, t):
    """samples[column] at times t. Displacements use the quintic Hermite interpolant on
    (u, v, a) when both are sampled, velocities the cubic one on (v, a): O(Δ⁶) and O(Δ⁴)
    where the motion is smooth, O(Δ²·jump) across a contact onset. Other columns are
    linear. Samples that fall on a requested time are returned exactly."""
    times = np.asarray(times, float)
    y = np.asarray(samples[column], float)
    t = np.asarray(t, float)
    if len(times) == 1:
        return np.full_like(t, y[0])
    i = np.clip(np.searchsorted(times, t, side="right") - 1, 0, len(times) - 2)
    t0, t1 = times[i], times[i + 1]
    kind, _, name = column.partition(":")
    if kind == "u" and f"v:{name}" in samples:
        v = np.asarray(samples[f"v:{name}"], float)
        if f"a:{name}" in samples:
            a = np.asarray(samples[f"a:{name}"], float)
            out = hermite(t0, t1, y[i], y[i + 1], v[i], v[i + 1], a[i], a[i + 1], t=t)
        else:
            out = hermite(t0, t1, y[i], y[i + 1], v[i], v[i + 1], t=t)
    elif kind == "v" and f"a:{name}" in samples:
        a = np.asarray(samples[f"a:{name}"], float)
        out = hermite(t0, t1, y[i], y[i + 1], a[i], a[i + 1], t=t)
    else:
        s = (t - t0) / (t1 - t0)
        out = (1 - s) * y[i] + s * y[i + 1]
    # exact sample hits (and the right end) without rounding through the interpolant
    tol = 1e-9 * np.min(np.diff(times)) if len(times) > 1 else 0.0
    j = np.clip(np.searchsorted(times, t), 0, len(times) - 1)
    for jj in (j, np.maximum(j - 1, 0)):
        hit = np.abs(times[jj] - t) <= tol
        out = np.where(hit, y[jj], out)
    return out


def history_dict(history):
    """(columns, 2D array) -> {column: 1D array}."""
    columns, data = history
    data = np.asarray(data, float).reshape(-1, len(columns))
    return {c: data[:, i] for i, c in enumerate(columns)}


def parse_csv(raw, error, finite=True, check_header=None, unrecorded=()):
    """(columns, 2D array) of the bytes of a history CSV (martello's history.csv, a
    reference's, another code's: docs/compare.md): a header row naming the columns, one of
    them t, then rows of one number per column, t increasing strictly; lines starting with #
    are comments. Anything else is error(problem, fix, line) (the caller's exception naming
    its file, raised here), never numpy's or Python's own: text that is not UTF-8, a missing
    or repeated column, a row of the wrong length, a value that is not a number or, with
    finite=True, not finite (NaN is a value of martello's own histories where an integrator
    does not report a link); a column of a kind in unrecorded (e.g. "link_force") that is NaN
    in every row is such a column, not an error. check_header(header, line), if given, sees
    the columns before the rows are read. The caller reads the file
    (martello.paths.read_input: bounded, a regular file)."""
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        raise error(f"byte {exc.start + 1} is not UTF-8 text",
                    "a history is a UTF-8 (or ASCII) CSV file", line) from None
    lines = [(i + 1, ln) for i, ln in enumerate(text.splitlines())
             if ln.strip() and not ln.lstrip().startswith("#")]
    if not lines:
        raise error("is empty", "a header row (t,u:<node>,...) and data rows", None)
    hline, header = lines[0][0], [c.strip() for c in next(csv.reader([lines[0][1]]))]
    if "t" not in header:
        raise error("missing column t", "the first row must name the columns, one of them t "
                    "(time in s); see docs/compare.md", hline)
    if len(set(header)) != len(header):
        dup = sorted({c for c in header if header.count(c) > 1})
        raise error(f"duplicate column(s) {', '.join(dup)}", None, hline)
    if check_header is not None:
        check_header(header, hline)
    body = lines[1:]
    data = None
    try:        # numpy's parser first (fast); the loop below says what is wrong, and where
        if body:    # (no rows: numpy would warn; the loop gives the empty array)
            data = np.loadtxt([ln for _, ln in body], delimiter=",", ndmin=2, dtype=float)
            if data.shape != (len(body), len(header)):
                data = None
    except ValueError:
        data = None
    if data is None:
        data = _rows(header, body, error)
    if finite:
        ok = np.isfinite(data)
        for j, c in enumerate(header):
            if c.partition(":")[0] in unrecorded and np.isnan(data[:, j]).all():
                ok[:, j] = True         # not recorded by that run (docs/results.md)
        if not ok.all():
            i, j = np.argwhere(~ok)[0]
            cell = next(csv.reader([body[i][1]]))[j].strip()
            raise error(f"column {header[j]} is {cell} (NaN or inf)",
                        "a history must be finite; cut it before the solver failed", body[i][0])
    return _increasing(header, data, [n for n, _ in body], error)


def _rows(header, body, error):
    """The rows of body [(line, text)] one by one, once numpy's parser has refused them: the
    error names the line and the cell."""
    rows = []
    for lineno, ln in body:
        cells = next(csv.reader([ln]))
        if len(cells) != len(header):
            raise error(f"{len(cells)} values for {len(header)} columns", None, lineno)
        vals = []
        for c, cell in zip(header, cells):
            try:
                vals.append(float(cell))
            except ValueError:
                raise error(f"column {c}: {cell.strip()!r} is not a number", None, lineno) from None
        rows.append(vals)
    return np.array(rows, float).reshape(len(rows), len(header))


def _increasing(header, data, lines, error):
    """(header, data) once its times are checked: at least two, increasing strictly."""
    if len(data) < 2:
        raise error(f"{len(data)} data row(s)", "a history needs at least two times", None)
    t = data[:, header.index("t")]
    bad = np.nonzero(~(np.diff(t) > 0))[0]
    if len(bad):
        i = int(bad[0]) + 1
        raise error(f"t = {float(t[i])!r} does not follow t = {float(t[i - 1])!r}",
                    "times must increase strictly: remove repeated or unsorted rows", lines[i])
    return header, data
