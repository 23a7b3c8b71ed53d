"""Metrics of a run against a reference (docs/problems.md "Metrics").

A *reference* (martello.reference) is what a run is scored against: the exact history of a
closed form, evaluated at any time, or stored reference data with the digits it can be
trusted to. The same metrics score martello's own runs (`martello study`) and other codes'
histories (`martello compare`):

* histories: max absolute error per column; max relative error, normwise per column
  (|y − y_ref| over max |y_ref| on the window, because a pointwise relative error is
  undefined where the reference crosses zero); scd = −log10(max relative error); mescd =
  −log10 max |y − y_ref|/(atol/rtol + |y_ref|) pointwise (IVP Test Set, Mazzia &
  Magherini); scd_final at the last common time, componentwise as in the IVP Test Set;
* events: impacts matched one to one before they are compared
  (martello.metrics.event_matching), so a shifted impact is a small time error, not one
  missing and one extra impact; impact count error, missing and extra impacts, impact time
  error;
* peaks: peak penetration and peak contact force, overall and per matched contact phase;
* realised restitution of each matched phase; energy: the run's own balance residual and
  the error of the mechanical energy at the end;
* cost: every counter of the run (steps, rejected steps, residual evaluations, Newton
  iterations, factorizations, events, wall time).

Every metric is a plain float in a flat dict (NaN when it does not apply), so that a study
writes them as CSV columns."""

from __future__ import annotations

import math

import numpy as np

from ..history import history_dict, interpolate
from .event_matching import match_events
from .norms import mescd

COST_KEYS = ("steps", "rejected_steps", "newton_iterations", "residual_evaluations",
             "factorizations", "events", "jacobian_evaluations", "root_evaluations",
             "contact_chatter_resolutions", "fused_chain_steps", "wall_time_s")
# A phase whose approach speed is below this fraction of the largest one is a graze: its
# realised restitution −δ̇_out/δ̇_in is a ratio of two tiny numbers and is not scored.
GRAZE_FRACTION = 1e-2


def _nan_metrics(columns):
    out = {k: math.nan for k in ("max_rel_error", "scd", "mescd", "scd_final")}
    out.update({f"max_abs_error:{c}": math.nan for c in columns})
    return out


def history_errors(history, ref, columns=None, times=None, atol=1e-12, rtol=1e-6, points=2001):
    """Errors of the run's histories against the reference on common times.

    columns: the histories compared (default: every u:<node> both have). times: where they
    are compared (default: the reference samples, or `points` uniform times for a closed
    form), limited to the span of the run: at those that are output times of the run when
    there are enough (no interpolation), else at all of them with the run interpolated
    (see interpolate).
    Returns max_abs_error:<column> for each column, and over all columns max_rel_error
    (normwise: |y − y_ref| over max |y_ref|), scd, mescd (pointwise mixed, atol/rtol) and
    scd_final (componentwise at the last common time)."""
    h = history_dict(history) if isinstance(history, tuple) else history
    t_run = h["t"]
    if columns is None:
        columns = [c for c in ref.columns if c.startswith("u:") and c in h]
    columns = [c for c in columns if c in h and c in ref.columns]
    if not columns or len(t_run) < 2:
        return _nan_metrics(columns) | {"compared": ""}
    t = ref.default_times(points) if times is None else np.asarray(times, float)
    span = 1e-9 * max(abs(t_run[-1]), 1.0)
    t = t[(t >= t_run[0] - span) & (t <= t_run[-1] + span)]
    t = t[t <= ref.t_end * (1 + 1e-12)]
    if len(t) < 2:
        return _nan_metrics(columns) | {"compared": ""}
    # Where the run's own output times fall on the comparison times (a fixed step that
    # divides, or is a multiple of, the sample spacing), compare there: no interpolation of
    # the run at all. Otherwise the run is interpolated onto the comparison times.
    tol = 1e-9 * float(np.min(np.diff(t)))
    j = np.clip(np.searchsorted(t_run, t), 1, len(t_run) - 1)
    near = np.minimum(np.abs(t_run[j] - t), np.abs(t_run[j - 1] - t)) <= tol
    if np.count_nonzero(near) >= max(2, 0.5 * min(len(t), len(t_run))):
        t = t[near]
    yref = ref.at(t, columns)
    out, rel, mixed, fin = {}, [], [], []
    for c in columns:
        y = interpolate(t_run, h, c, t)
        yr = yref[c]
        if not np.all(np.isfinite(y)):
            out[f"max_abs_error:{c}"] = math.inf
            rel.append(math.inf)
            mixed.append(math.inf)
            fin.append(math.inf)
            continue
        err = np.abs(y - yr)
        out[f"max_abs_error:{c}"] = float(np.max(err))
        scale = float(np.max(np.abs(yr)))
        rel.append(float(np.max(err)) / scale if scale > 0 else (0.0 if np.max(err) == 0 else math.inf))
        m_ = mescd(y, yr, atol, rtol)
        mixed.append(10.0 ** (-m_) if math.isfinite(m_) else 0.0)
        fin.append(abs(y[-1] - yr[-1]) / abs(yr[-1]) if yr[-1] != 0 else
                   (0.0 if y[-1] == 0 else math.inf))
    e = max(rel)
    out["max_rel_error"] = e
    out["scd"] = -math.log10(e) if 0 < e < math.inf else (math.inf if e == 0 else -math.inf)
    worst = max(mixed)
    out["mescd"] = -math.log10(worst) if 0 < worst < math.inf else (math.inf if worst == 0 else -math.inf)
    ef = max(fin)
    out["scd_final"] = -math.log10(ef) if 0 < ef < math.inf else (math.inf if ef == 0 else -math.inf)
    out["compared"] = " ".join(columns)
    out["compare_t_start"], out["compare_t_end"], out["compare_points"] = float(t[0]), float(t[-1]), len(t)
    return out


def _rel(a, b):
    if a is None or b is None or not (math.isfinite(a) and math.isfinite(b)):
        return math.nan
    return abs(a - b) / abs(b) if b != 0 else (0.0 if a == 0 else math.inf)


def event_errors(contacts, ref, t_reached=math.inf, window=None):
    """Impact, peak and restitution errors of each contact the reference knows, with
    impacts matched first (martello.metrics.event_matching).

    contacts: the run's summary["contacts"] (impact_times, separation_times,
    approach_speeds, restitution, phase_max_penetration, phase_max_force, max_penetration,
    max_force). The match window is half the shortest interval between reference impacts
    (capped by `window`), so two impacts can never swap partners. Only events up to
    min(t_reached, reference event horizon) are counted. Aggregates over contacts:
    impact_count / impact_count_ref / impact_count_error (signed, run − reference),
    impacts_missing, impacts_extra, impact_time_error (max |Δt| over matched impacts, s),
    peak_penetration_error and peak_force_error (relative, overall maxima),
    phase_penetration_error and phase_force_error (relative, max over matched phases),
    restitution_error (max |e − e_ref| over matched non-grazing phases) and restitution (mean
    realised e of the run's non-grazing phases)."""
    keys = ("impact_count", "impact_count_ref", "impact_count_error", "impacts_missing",
            "impacts_extra", "impact_time_error", "peak_penetration_error", "peak_force_error",
            "phase_penetration_error", "phase_force_error", "restitution_error", "restitution",
            "restitution_ref")
    out = {k: math.nan for k in keys}
    if not ref.events:
        return out
    if not any(name in contacts for name in ref.events):
        return out          # the run (or history) says nothing about these contacts
    horizon = min(t_reached, ref.event_horizon, ref.t_end)
    tot = dict(n=0, nref=0, miss=0, extra=0)
    dts, pen_e, force_e, ph_pen, ph_force, e_err, e_run, e_ref = [], [], [], [], [], [], [], []
    for name, rev in ref.events.items():
        run = contacts.get(name)
        if run is None:
            continue
        tr = np.asarray(rev.get("impact_times", []), float)
        keep_r = tr <= horizon + 1e-12
        tr = tr[keep_r]
        t = np.asarray(run.get("impact_times", []), float)
        keep = t <= horizon + 1e-12
        t = t[keep]
        w = window if window is not None else math.inf
        if len(tr) > 1:
            w = min(w, 0.5 * float(np.min(np.diff(np.sort(tr)))))
        elif len(tr) == 1:
            w = min(w, 0.5 * ref.t_end)
        else:
            w = min(w, 1e-300)
        m = match_events(t, tr, w)
        tot["n"] += len(t)
        tot["nref"] += len(tr)
        tot["miss"] += m.n_missing
        tot["extra"] += m.n_extra
        dts.extend(np.abs(m.dt).tolist())
        # overall peaks: only a run that reached the end has its overall peak
        rp = ref.peaks.get(name, {})
        if t_reached >= ref.t_end * (1 - 1e-12):
            if rp.get("max_penetration") is not None and run.get("max_penetration") is not None \
                    and rp["max_penetration"] > 0:
                pen_e.append(_rel(run["max_penetration"], rp["max_penetration"]))
            if rp.get("max_force") is not None and run.get("max_force") is not None and rp["max_force"] > 0:
                force_e.append(_rel(run["max_force"], rp["max_force"]))
        v_ref = [abs(x) for x in rev.get("approach_speeds", []) if x is not None]
        vmax = max(v_ref, default=0.0)
        idx_r = np.nonzero(keep_r)[0]
        idx = np.nonzero(keep)[0]

        def get(lst, i):
            return lst[i] if lst is not None and i < len(lst) else None
        for i, j in m.pairs:
            i0, j0 = idx[i], idx_r[j]
            p, pr = get(run.get("phase_max_penetration"), i0), get(rev.get("phase_max_penetration"), j0)
            if p is not None and pr:
                ph_pen.append(_rel(p, pr))
            f, fr = get(run.get("phase_max_force"), i0), get(rev.get("phase_max_force"), j0)
            if f is not None and fr:
                ph_force.append(_rel(f, fr))
            e, er = get(run.get("restitution"), i0), get(rev.get("restitution"), j0)
            va = get(rev.get("approach_speeds"), j0)
            if e is not None and er is not None and va is not None and abs(va) >= GRAZE_FRACTION * vmax:
                e_err.append(abs(e - er))
        speeds = run.get("approach_speeds") or []
        vrun = max((abs(x) for x in speeds), default=0.0)
        for i0 in idx:
            e, va = get(run.get("restitution"), i0), get(speeds, i0)
            if e is not None and va is not None and abs(va) >= GRAZE_FRACTION * vrun:
                e_run.append(e)
        for j0 in idx_r:
            er, va = get(rev.get("restitution"), j0), get(rev.get("approach_speeds"), j0)
            if er is not None and va is not None and abs(va) >= GRAZE_FRACTION * vmax:
                e_ref.append(er)

    def mx(x):
        x = [v for v in x if v is not None and not math.isnan(v)]
        return max(x) if x else math.nan
    out.update(impact_count=tot["n"], impact_count_ref=tot["nref"],
               impact_count_error=tot["n"] - tot["nref"], impacts_missing=tot["miss"],
               impacts_extra=tot["extra"], impact_time_error=mx(dts) if dts else
               (0.0 if tot["nref"] == 0 else math.nan),
               peak_penetration_error=mx(pen_e), peak_force_error=mx(force_e),
               phase_penetration_error=mx(ph_pen), phase_force_error=mx(ph_force),
               restitution_error=mx(e_err),
               restitution=float(np.mean(e_run)) if e_run else math.nan,
               restitution_ref=float(np.mean(e_ref)) if e_ref else math.nan)
    return out


def energy_errors(summary, history, ref):
    """energy_balance_error: the run's own balance residual (initial + input − kinetic −
    recoverable − dissipated), max over the run, relative to max(|initial|, |input|).
    energy_error: |E − E_ref| of the mechanical energy E = kinetic + recoverable at the last
    common time, relative to the largest |E_ref| on the window. energy_created: the largest
    E − initial − input over the run (energy the integrator made), relative to the same
    scale; > 0 means energy growth."""
    out = {"energy_balance_error": math.nan, "energy_error": math.nan, "energy_created": math.nan}
    en = (summary or {}).get("energy") or {}
    if "balance_relative" in en:
        out["energy_balance_error"] = float(en["balance_relative"])
    h = history_dict(history) if isinstance(history, tuple) else history
    need = ("energy:kinetic", "energy:recoverable")
    if not all(c in h for c in need) or len(h["t"]) == 0:
        return out
    E = h["energy:kinetic"] + h["energy:recoverable"]
    if ref is not None and all(c in ref.columns for c in need):
        t = h["t"]
        tt = t[t <= ref.t_end * (1 + 1e-12)]
        if len(tt):
            grid = np.unique(np.concatenate((ref.default_times()[ref.default_times() <= tt[-1]], [tt[-1]])))
            r = ref.at(grid, need)
            Er = r["energy:kinetic"] + r["energy:recoverable"]
            scale = float(np.max(np.abs(Er)))
            if scale > 0:
                out["energy_error"] = abs(float(E[len(tt) - 1]) - float(Er[-1])) / scale
    if "energy:initial" in h and "energy:input" in h:
        created = E - h["energy:initial"] - h["energy:input"]
        scale = max(float(np.max(np.abs(h["energy:initial"]))), float(np.max(np.abs(h["energy:input"]))),
                    float(np.max(np.abs(E))), 1e-300)
        out["energy_created"] = float(np.max(created)) / scale
    return out


def cost(summary):
    """Every cost counter of the run (NaN when the run did not report it)."""
    c = (summary or {}).get("cost") or {}
    return {k: c.get(k, math.nan) for k in COST_KEYS}


def score(summary, history, ref, columns=None, times=None, atol=1e-12, rtol=1e-6, window=None,
          points=2001):
    """All metrics of one run (summary dict and history (columns, data)) against ref, as a
    flat dict: history errors, event and peak errors, restitution, energy, cost."""
    out = {}
    if ref is not None:
        out.update(history_errors(history, ref, columns, times, atol, rtol, points))
        out.update(event_errors((summary or {}).get("contacts", {}), ref,
                                (summary or {}).get("t_reached", math.inf), window))
        out["reference"] = ref.name
        out["reference_digits"] = ref.trusted_digits(out.get("compared", "").split() or None)
    out.update(energy_errors(summary, history, ref))
    out.update(cost(summary))
    return out
