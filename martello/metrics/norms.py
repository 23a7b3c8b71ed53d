"""Error norms of a computed array against a reference and their significant correct
digits (docs/problems.md "Metrics"; IVP Test Set, Mazzia & Magherini)."""

from __future__ import annotations

import math

import numpy as np


def max_abs_error(y, yref):
    """max |y - y_ref| over all entries."""
    y, yref = np.asarray(y, float), np.asarray(yref, float)
    return float(np.max(np.abs(y - yref)))


def max_rel_error(y, yref, floor=0.0):
    """max |y - y_ref| / max(|y_ref|, floor). It is inf if y_ref has zeros, y differs there,
    and floor = 0."""
    y, yref = np.asarray(y, float), np.asarray(yref, float)
    den = np.maximum(np.abs(yref), floor)
    err = np.abs(y - yref)
    with np.errstate(divide="ignore", invalid="ignore"):
        r = np.where(err == 0.0, 0.0, err / den)
    return float(np.max(r))


def scd(y, yref):
    """Significant correct digits, -log10(max relative error) (IVP Test Set, Mazzia &
    Magherini). inf for an exact match."""
    e = max_rel_error(y, yref)
    return math.inf if e == 0.0 else -math.log10(e)


def mescd(y, yref, atol, rtol):
    """Mixed significant correct digits, -log10(max |y - y_ref|/(atol/rtol + |y_ref|))."""
    y, yref = np.asarray(y, float), np.asarray(yref, float)
    e = float(np.max(np.abs(y - yref) / (atol / rtol + np.abs(yref))))
    return math.inf if e == 0.0 else -math.log10(e)
