"""A summary from a bare time history, for codes that only give histories (`martello
compare`): the events, peaks and final values that martello's own runs report, recovered
from the samples."""

from __future__ import annotations

import numpy as np

from ..history import hermite, history_dict
from ..scene.rows import element_terms


def _crossings(t, d, rate, upward):
    """Times where d crosses 0 (upward or downward) between samples; with the rate the
    crossing is the root of the cubic Hermite interpolant, else linear."""
    s = np.sign(d)
    if upward:
        k = np.nonzero((s[:-1] <= 0) & (s[1:] > 0))[0]
    else:
        k = np.nonzero((s[:-1] > 0) & (s[1:] <= 0))[0]
    out = []
    for i in k:
        t0, t1 = t[i], t[i + 1]
        tc = t0 + (t1 - t0) * d[i] / (d[i] - d[i + 1]) if d[i] != d[i + 1] else t0
        if rate is not None:
            for _ in range(3):         # Newton on the Hermite interpolant, from the secant root
                y = hermite(t0, t1, d[i], d[i + 1], rate[i], rate[i + 1], t=np.array(tc))
                dt_ = 1e-7 * (t1 - t0)
                yp = (hermite(t0, t1, d[i], d[i + 1], rate[i], rate[i + 1], t=np.array(tc + dt_)) - y) / dt_
                if yp == 0:
                    break
                tn = float(tc - y / yp)
                if not t0 <= tn <= t1:
                    break
                tc = tn
        out.append((int(i), float(tc)))
    return out


def _phase_peak(t, d, rate, i, j):
    """Largest penetration over samples i..j+1, refined where the rate changes sign next to
    the largest sample: the root of the linearly interpolated rate, the value from the
    cubic Hermite interpolant of (δ, δ̇) there (O(Δ⁴) instead of the samples' O(Δ²))."""
    lo, hi = i, min(j + 1, len(t) - 1)
    k = lo + int(np.argmax(d[lo:hi + 1]))
    best = float(d[k])
    for a_, b_ in ((k - 1, k), (k, k + 1)):
        if a_ < 0 or b_ >= len(t) or not (rate[a_] > 0 >= rate[b_]):
            continue
        tau = t[a_] + (t[b_] - t[a_]) * rate[a_] / (rate[a_] - rate[b_])
        best = max(best, float(hermite(t[a_], t[b_], d[a_], d[b_], rate[a_], rate[b_], t=np.array(tau))))
    return max(best, 0.0)


def summary_from_history(scene, history):
    """A summary dict (the parts `score` and the scene's [check] use) computed from a bare
    time history, for codes that only give histories: per contact, impact (onset) and
    separation times from the sign changes of the penetration, the approach and separation
    rates δ̇ (from the velocity columns, else by differences), realised restitution, maxima
    of penetration and force overall and per phase; per node, u_max, u_min, u_final and
    v_final."""
    h = history_dict(history) if isinstance(history, tuple) else history
    t = h["t"]
    nodes = {}
    for n in scene.nodes:
        name = n["name"]
        if f"u:{name}" in h:
            u = h[f"u:{name}"]
            nodes[name] = {"u_max": float(np.max(u)), "u_min": float(np.min(u)),
                           "u_final": float(u[-1])}
            if f"v:{name}" in h:
                nodes[name]["v_final"] = float(h[f"v:{name}"][-1])
    contacts = {}
    for c in scene.contacts:
        name = c["name"]
        d = h.get(f"penetration:{name}")

        terms = element_terms(c)         # (a, +1), (b, −1) of a pair; a plan-point row's terms

        def row_col(kind):
            """Σ c·x over the contact's row (docs/buildings.md), None if a column is missing."""
            cols = [h.get(f"{kind}:{scene.nodes[k]['name']}") for k, _ in terms]
            if any(x is None for x in cols):
                return None
            return sum((cf * x for (_, cf), x in zip(terms, cols)), np.zeros_like(t))
        u_row = row_col("u")
        if d is None and u_row is not None:
            d = u_row - c["gap"]
        if d is None:
            continue
        rate = row_col("v")
        rate = np.gradient(d, t) if rate is None else rate
        acc = row_col("a")

        def free_side_rate(tc, k):
            """δ̇ at a crossing, extrapolated from sample k on the free side (the rate's
            slope jumps at the crossing for a dashpot law: interpolating across it would
            mix the two sides)."""
            if acc is not None:
                return float(rate[k] + acc[k] * (tc - t[k]))
            k2 = k - 1 if tc >= t[k] else k + 1
            k2 = min(max(k2, 0), len(t) - 1)
            slope = (rate[k] - rate[k2]) / (t[k] - t[k2]) if k2 != k else 0.0
            return float(rate[k] + slope * (tc - t[k]))
        f = h.get(f"force:{name}")
        on = _crossings(t, d, rate, True)
        off = _crossings(t, d, rate, False)
        if len(d) and d[0] > 0:
            on.insert(0, (0, float(t[0])))
        t_on, t_off, v_in, v_out, pmax, fmax, rest = [], [], [], [], [], [], []
        for i, tc in on:
            nxt = [(j, tj) for j, tj in off if tj > tc]
            j, tj = nxt[0] if nxt else (len(t) - 1, None)
            r_in = free_side_rate(tc, i)
            seg = slice(i, j + 2)
            t_on.append(tc)
            t_off.append(tj)
            v_in.append(r_in)
            pmax.append(_phase_peak(t, d, rate, i, j))
            fmax.append(float(np.max(f[seg])) if f is not None else None)
            if tj is not None:
                r_out = free_side_rate(tj, min(j + 1, len(t) - 1))
                v_out.append(r_out)
                rest.append(-r_out / r_in if r_in > 0 else None)
            else:
                rest.append(None)
        contacts[name] = {"impact_times": t_on, "separation_times": t_off,
                          "approach_speeds": v_in, "separation_speeds": v_out,
                          "restitution": rest, "phase_max_penetration": pmax,
                          "phase_max_force": fmax, "impacts": len(t_on),
                          "max_penetration": float(max(np.max(d), 0.0)),
                          "max_force": float(np.max(f)) if f is not None else None}
        closed = [k for k, x in enumerate(t_off) if x is not None]
        if closed:
            contacts[name]["contact_time"] = t_off[closed[0]] - t_on[closed[0]]
    return {"nodes": nodes, "contacts": contacts, "t_reached": float(t[-1]) if len(t) else 0.0}
