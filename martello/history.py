"""Time histories: the (columns, 2D array) pair a run writes as history.csv, the same as a
dict of columns, and their interpolation between samples (the comparison of a run with a
reference at times that are not samples of both)."""

from __future__ import annotations

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
