"""Events of a run paired one to one with the reference's before they are compared
(docs/problems.md "Metrics"), so that a shifted impact is a small time error, not one
missing and one extra impact."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy import optimize


@dataclass(frozen=True)
class EventMatch:
    pairs: np.ndarray     #: (n_matched, 2) int array: index into t, index into t_ref
    dt: np.ndarray        #: t[i] - t_ref[j] for each pair
    n_matched: int
    n_missing: int        #: reference events with no computed partner
    n_extra: int          #: computed events with no reference partner
    missing: np.ndarray   #: indices into t_ref
    extra: np.ndarray     #: indices into t
    max_abs_dt: float     #: max |dt| over pairs (0 if none)


def match_events(t, t_ref, window) -> EventMatch:
    """Pair computed event times t with reference times t_ref one to one. A pair is allowed
    only if |t_i - t_ref_j| <= window. The pairing maximises the number of pairs, then
    minimises the sum of |dt|. This is an exact assignment (scipy linear_sum_assignment),
    solved independently in each cluster of events whose windows chain together. A shifted
    impact therefore shows up as a small dt, not as one missing and one extra event."""
    t = np.asarray(t, float).ravel()
    tr = np.asarray(t_ref, float).ravel()
    allt = np.concatenate((t, tr))
    src = np.concatenate((np.zeros(len(t), int), np.ones(len(tr), int)))
    idx = np.concatenate((np.arange(len(t)), np.arange(len(tr))))
    order = np.argsort(allt, kind="stable")
    allt, src, idx = allt[order], src[order], idx[order]
    pairs = []
    start = 0
    nall = len(allt)
    for end in range(1, nall + 1):
        if end == nall or allt[end] - allt[end - 1] > window:
            ci = idx[start:end][src[start:end] == 0]
            cj = idx[start:end][src[start:end] == 1]
            if len(ci) and len(cj):
                D = np.abs(t[ci][:, None] - tr[cj][None, :])
                big = (window + 1.0) * (len(ci) + len(cj) + 1) + 1.0
                cost = np.where(D <= window, D, big)
                r_, c_ = optimize.linear_sum_assignment(cost)
                for a_, b_ in zip(r_, c_):
                    if D[a_, b_] <= window:
                        pairs.append((ci[a_], cj[b_]))
            start = end
    pairs = np.array(sorted(pairs, key=lambda p: p[1]), dtype=int).reshape(-1, 2)
    dt = t[pairs[:, 0]] - tr[pairs[:, 1]] if len(pairs) else np.zeros(0)
    missing = np.setdiff1d(np.arange(len(tr)), pairs[:, 1])
    extra = np.setdiff1d(np.arange(len(t)), pairs[:, 0])
    return EventMatch(pairs, dt, len(pairs), len(missing), len(extra), missing, extra,
                      float(np.max(np.abs(dt))) if len(dt) else 0.0)
