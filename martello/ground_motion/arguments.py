"""Argument checks of the ground-motion functions: every bad argument raises
GroundMotionError, whose message starts with the argument's name."""

from __future__ import annotations

import math

import numpy as np

from ..errors import MartelloError


class GroundMotionError(MartelloError):
    """A bad argument to a ground-motion function; the message starts with its name."""

    def __init__(self, argument, problem, fix=None):
        self.argument, self.problem, self.fix = argument, problem, fix
        msg = f"{argument}: {problem}"
        if fix:
            msg += f" ({fix})"
        super().__init__(msg)


def check_finite(name, value):
    if isinstance(value, (bool, str, bytes)):
        raise GroundMotionError(name, f"{value!r} is not a number")
    try:
        x = float(value)
    except (TypeError, ValueError):
        raise GroundMotionError(name, f"{value!r} is not a number") from None
    if not math.isfinite(x):
        raise GroundMotionError(name, f"{value!r} is not finite")
    return x


def check_positive(name, value):
    x = check_finite(name, value)
    if not x > 0:
        raise GroundMotionError(name, f"{value!r} must be > 0")
    return x


def check_zeta(zeta):
    z = check_finite("zeta", zeta)
    if not 0.0 <= z < 1.0:
        raise GroundMotionError("zeta", f"{zeta!r} must satisfy 0 <= zeta < 1",
                                fix="a damping ratio, e.g. 0.05 for 5 %")
    return z


def check_samples(name, values, min_size=1, scalar_ok=False):
    if isinstance(values, (str, bytes)):
        raise GroundMotionError(name, "is not an array of numbers")
    try:
        a = np.ascontiguousarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise GroundMotionError(name, "is not an array of numbers") from None
    if scalar_ok and a.ndim == 0:
        a = a.reshape(1)
    if a.ndim != 1:
        raise GroundMotionError(name, f"must be one-dimensional, has shape {a.shape}")
    if a.size < min_size:
        raise GroundMotionError(name, f"has {a.size} values, needs at least {min_size}"
                                if a.size else "is empty")
    bad = np.flatnonzero(~np.isfinite(a))
    if bad.size:
        raise GroundMotionError(name, f"value {float(a[bad[0]])!r} at index {bad[0]} is not finite",
                                fix="remove or repair NaN/inf samples")
    return a


def check_int(name, value, low):
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)):
        raise GroundMotionError(name, f"{value!r} is not an integer")
    if value < low:
        raise GroundMotionError(name, f"{value!r} must be >= {low}")
    return int(value)
