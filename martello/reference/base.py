"""The Reference a run is scored against, and how far it can be trusted."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from ..errors import MartelloError
from ..history import interpolate

# Digits a closed form is trusted to: phase ends are exact to ~1e-15 relative to the phase
# (oracles.p2_bouncing.bouncing_oscillator_kelvin); absolute times carry one rounding per phase.
CLOSED_FORM_DIGITS = 13.0


class ReferenceError(MartelloError):
    """No usable reference, or the reference data do not match the scene."""


@dataclass
class Reference:
    """What a run is scored against.

    Histories come either from `evaluate(t) -> {column: values}` (closed forms, exact at any
    time) or from `times`/`samples` (stored data). `events[contact]` holds lists:
    impact_times, separation_times, approach_speeds, restitution, phase_max_penetration,
    phase_max_force; `peaks[contact]` holds max_penetration, max_force. `digits[column]` is
    how many significant digits (relative to the column's peak) the reference is trusted to.
    Events are complete up to `event_horizon` (a Zeno sequence has infinitely many)."""
    name: str
    kind: str                                  # "closed-form" | "data"
    t_end: float
    columns: tuple
    evaluate: Callable | None = None
    times: np.ndarray | None = None
    samples: dict = field(default_factory=dict)
    events: dict = field(default_factory=dict)
    peaks: dict = field(default_factory=dict)
    masses: dict = field(default_factory=dict)
    digits: dict = field(default_factory=dict)
    event_horizon: float = math.inf
    provenance: dict = field(default_factory=dict)

    def default_times(self, n=2001):
        """Comparison times: the stored samples, or a uniform grid over [0, t_end]."""
        if self.times is not None:
            return self.times
        return np.linspace(0.0, self.t_end, n)

    def at(self, t, columns):
        """{column: values at times t} for the columns it has."""
        t = np.asarray(t, float)
        if self.evaluate is not None:
            vals = self.evaluate(t)
            return {c: np.asarray(vals[c], float) for c in columns if c in vals}
        out = {}
        for c in columns:
            if c in self.samples:
                out[c] = interpolate(self.times, self.samples, c, t)
        return out

    def trusted_digits(self, columns=None):
        cols = [c for c in (columns or self.columns) if c in self.digits]
        return min((self.digits[c] for c in cols), default=CLOSED_FORM_DIGITS
                   if self.kind == "closed-form" else math.nan)
