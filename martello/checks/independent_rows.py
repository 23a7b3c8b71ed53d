"""Accuracy rows against the independent reference engine (docs/independent-reference.md):
a catalogue run of a scene whose stored independent reference (reference/independent/)
matches its file is compared quantity by quantity with it.

The tolerance of each row comes from the mathematics, not from a previous run: the scene
is run again at 2Δt and 4Δt (an adaptive integrator at 100 and 10⁴ × rtol), and the order p
the three runs show is measured. The reruns bound the error only where they converge at the
method's formal order (formal_order: 2 for the trapezoidal family, 1 for Moreau–Jean,
Newmark with γ > ½ and an adaptive run's error in its tolerance): then the error is bounded by
the difference to the first rerun (any method of order ≥ 1; an error proportional to the
tolerance, and never below rtol of the scale); a maximum taken at the steps adds its
sampling bound max|ẍ| Δt²/8, an event time of an event-locating run its location tolerance
event_tol, and the reference its own uncertainty (10^−digits of the quantity's scale). A row
passes when the error against the reference is within 3 × the bound + the sampling bound +
the reference's uncertainty. The rows of a run whose reruns converge at less than the
formal order (the median of its quantities' orders, ORDER_SLACK below it) are not
verification (martello.checks.kinds "unconverged"): their errors and orders are shown,
nothing is asserted. Differences below the noise of the runs
and the reference (noise_floor) say the quantity has converged, whatever their ratio. Impact
counts must match exactly, except on contacts the reference marks ambiguous (a graze whose
existence its two integrations disagree on).
digits = min(the run's digits against the reference, the reference's trusted digits)."""

from __future__ import annotations

import copy
import json
import math
from pathlib import Path

from ..paths import REFERENCE_ROOT, REPO
from ..reference.store import physics_digest
from .kinds import UNCONVERGED

INDEPENDENT_ROOT = REFERENCE_ROOT / "independent"
FIXED_STEP = ("newmark", "hht", "generalized-alpha", "central-difference", "moreau-jean", "newmark-lagrange",
              "fast-nonlinear")
SAFETY = 3.0          # the Richardson estimate is asymptotic; 3 covers a measured p off by ~1
# The reruns bound the error of a run that converges at its method's order (formal_order):
# the median of its quantities' measured orders at least ORDER_SLACK below it. The median,
# not each quantity's own order: one quantity's erratic constant (an event located where it
# falls in a step, a restitution whose differences sit at the interpolation's noise) moves
# its own three-run order by ±2 while the run converges; a quantity whose bound is then too
# small fails its row (the error is measured against the reference, not estimated), one
# whose bound is large is loose or unconverged (martello.checks.kinds).
ORDER_SLACK = 0.5
ADAPTIVE_FACTOR, FIXED_FACTOR = 100.0, 2.0     # the reruns' factor on rtol, resp. Δt
# Jankowski's damping c δ^(1/4) δ̇ rises as τ^(1/4) after the onset: the trapezoidal rule's
# error over the first steps of a phase sums to O(h^(5/4)) whatever splits the steps
# (Σ h³ f''(kh), f'' ~ t^(−7/4)); event_split makes the convergence regular (measured 1.4-2.1
# on P7 from Δt = 4e-5 to 5e-6, docs/integrators.md) but not second order.
JANKOWSKI_ORDER = 1.25


def formal_order(analysis, contacts=()) -> float:
    """The order a run's error should show in its step (fixed steps) or tolerance (an
    adaptive run: error proportional to rtol, order 1 in rtol) (docs/integrators.md
    "Overview"); a fixed-step run with a Jankowski contact: JANKOWSKI_ORDER."""
    integ = analysis.get("integrator")
    if integ not in FIXED_STEP:
        return 1.0
    if integ in ("moreau-jean", "newmark-lagrange"):
        return 1.0                   # impulses and forces held over a step: first order
    if integ == "newmark" and abs(float(analysis.get("gamma") or 0.5) - 0.5) > 1e-12:
        return 1.0                   # γ > ½ damps at first order
    if any(c.get("law") == "jankowski" for c in contacts):
        return JANKOWSKI_ORDER
    return 2.0


def find_independent(scene, root=INDEPENDENT_ROOT):
    """The stored independent reference of this scene's physics (nodes, links, contacts,
    loads: martello.reference.store.physics_digest, not the analysis settings) that the
    catalogue uses, or None. A reference that names its `scenes` (paths from the repository
    root) serves those files only: another scene of the same physics keeps its own evidence."""
    if not root.is_dir():
        return None
    digest = physics_digest(scene)
    for f in sorted(root.glob("*.json")):
        ref = json.loads(f.read_text())
        if ref.get("physics_sha256") == digest and ref.get("catalogue", True) and \
                ref.get("t_end") == scene.analysis.get("t_end") and _serves(ref, scene):
            return ref
    return None


def _serves(ref, scene):
    names = ref.get("scenes")
    if not names:
        return True
    try:
        here = Path(scene.source).resolve()
    except (TypeError, OSError):
        return False
    return any(here == (REPO / n).resolve() for n in names)


def _quantities(summary):
    """The compared quantities of a martello summary: name -> (value, kind key)."""
    q = {}
    for nm, c in summary["contacts"].items():
        q[f"contacts.{nm}.impacts"] = c.get("impacts", 0)
        for i, t in enumerate(c.get("impact_times") or []):
            q[f"contacts.{nm}.impact_times.{i}"] = t
        for i, p in enumerate(c.get("phase_max_penetration") or []):
            q[f"contacts.{nm}.phase_max_penetration.{i}"] = p
        for i, t in enumerate(c.get("separation_times") or []):
            q[f"contacts.{nm}.separation_times.{i}"] = t
        for i, e in enumerate(c.get("restitution") or []):
            q[f"contacts.{nm}.restitution.{i}"] = e
    for nm, r in summary["nodes"].items():
        q[f"nodes.{nm}.u_max"] = r["u_max"]
        q[f"nodes.{nm}.u_min"] = r["u_min"]
    e = summary["energy"]
    q["energy.dissipated"] = e.get("damping", 0.0) + e.get("plastic", 0.0) + e.get("contact", 0.0) + \
        e.get("impact", 0.0)
    q["energy.input"] = e.get("input", 0.0)
    return q


def _reference_quantities(ref):
    q, dig, owner = {}, {}, {}
    d = ref["digits"]
    for nm, c in ref["contacts"].items():
        q[f"contacts.{nm}.impacts"] = c["impacts"]
        rows = (d["contacts"].get(nm) or {}).get("phases", [])
        for i, p in enumerate(c["phases"]):
            q[f"contacts.{nm}.impact_times.{i}"] = p["t_on"]
            q[f"contacts.{nm}.phase_max_penetration.{i}"] = p["max_penetration"]
            q[f"contacts.{nm}.separation_times.{i}"] = p["t_off"]
            q[f"contacts.{nm}.restitution.{i}"] = p["restitution"]
            for k in ("impact_times", "phase_max_penetration", "separation_times", "restitution"):
                owner[f"contacts.{nm}.{k}.{i}"] = nm
            if i < len(rows):
                dig[f"contacts.{nm}.separation_times.{i}"] = rows[i]["t_off"]
                dig[f"contacts.{nm}.restitution.{i}"] = rows[i]["restitution"]
            if i < len(rows):
                dig[f"contacts.{nm}.impact_times.{i}"] = rows[i]["t_on"]
                dig[f"contacts.{nm}.phase_max_penetration.{i}"] = rows[i]["max_penetration"]
    for nm, r in ref["nodes"].items():
        for k in ("u_max", "u_min"):
            q[f"nodes.{nm}.{k}"] = r[k]
            dig[f"nodes.{nm}.{k}"] = d["nodes"][nm][k]
    e = ref["energy"]
    q["energy.dissipated"] = e["damping"] + e["plastic"] + e["contact"] + e["impact"]
    q["energy.input"] = e["input"]
    de = d["energy"]
    dig["energy.dissipated"] = min(de[k] for k in ("damping", "plastic", "contact", "impact"))
    dig["energy.input"] = de["input"]
    return q, dig, owner


def _scales(ref, owner):
    """The scale each quantity's error is measured against (the engine's digit scales)."""
    u = max([abs(r["u_max"]) for r in ref["nodes"].values()] + [abs(r["u_min"]) for r in ref["nodes"].values()])
    e = max(abs(ref["energy"]["input"]), abs(ref["energy"]["initial"]), 1e-300)

    def scale(key, value):
        if key.startswith("nodes."):
            return u
        if ".phase_max_penetration." in key:
            return ref["contacts"][owner[key]]["max_penetration"] or 1e-300
        if key.startswith("energy."):
            return e
        if ".restitution." in key:
            return 1.0
        return abs(value) or 1.0       # event times: relative to the time
    return scale


def accuracy_rows(scene_title, source, ref, runs, dt=None, order_default=2.0, event_tol=0.0, rtol=0.0,
                  factor=FIXED_FACTOR):
    """Rows comparing run summaries at Δt, 2Δt, 4Δt (runs[0] the catalogue's; an adaptive
    run's at rtol, 100 rtol, 10⁴ rtol with factor = 100) with `ref`. order_default: the
    method's formal order (formal_order), which the reruns must show for a row to be
    verification (else the row is "unconverged": martello.checks.kinds).
    event_tol: the absolute time to which an event-locating run places its events (its
    located state may lie that far past the root, whatever rtol: docs/event-driven.md).
    rtol: an adaptive run's relative tolerance, the least error its estimate may claim (the
    differences to its reruns can vanish by chance for one quantity: P8 B's 7th separation
    on rk8pd moved 1.6e-12 s between rtol 1e-10 and 1e-8 and was 4.4e-11 s off)."""
    q_ref, dig_ref, owner = _reference_quantities(ref)
    scale = _scales(ref, owner)
    qs = [_quantities(s) for s in runs]
    rows = []
    ambiguous = set(ref.get("ambiguous") or [])
    for nm, c in ref["contacts"].items():
        if nm in ambiguous:
            continue
        got = qs[0].get(f"contacts.{nm}.impacts")
        rows.append(_row(scene_title, source, f"contacts.{nm}.impacts", got, c["impacts"], got == c["impacts"],
                         16.0 if got == c["impacts"] else 0.0, 0.0,
                         f"impact count of an event-located reference with no grazing ambiguity: exact"))
    bounded = []
    for key, r in q_ref.items():
        if key.endswith(".impacts") or key not in qs[0] or r is None:
            continue
        nm = owner.get(key)
        if nm in ambiguous or (nm and qs[0].get(f"contacts.{nm}.impacts") != ref["contacts"][nm]["impacts"]):
            continue                   # phases cannot be paired
        v = [q.get(key) for q in qs]
        sc = scale(key, r)
        ref_unc = 10.0 ** -(dig_ref.get(key) if dig_ref.get(key) is not None else 0.0) * sc
        samp = _sampling_bound(key, runs[0], dt, ref) if dt else 0.0
        if key.startswith("energy."):
            # a work summed over the steps carries their round-off, steps × ε of its scale
            samp += runs[0].get("cost", {}).get("steps", 0) * 2.2e-16 * sc
        if ".impact_times." in key or ".separation_times." in key:
            samp += event_tol
        est, p = _richardson(v, factor, noise_floor(sc, ref_unc, samp, rtol))
        est = max(est, rtol * sc)
        tol = SAFETY * est + samp + ref_unc
        err = abs(v[0] - r)
        digits_run = 16.0 if err == 0 else max(0.0, min(16.0, -math.log10(err / sc)))
        digits = min(digits_run, dig_ref.get(key) or 0.0)
        order = "converged to the noise" if p != p else f"{p:.2f}"
        what = "Δt, 2Δt, 4Δt" if factor == FIXED_FACTOR else "rtol, 100 rtol, 10⁴ rtol"
        row = _row(scene_title, source, key, v[0], r, err <= tol, digits, tol,
                   f"error bound from the first rerun {est:.2e} (order measured from {what}: "
                   f"{order}, formal {order_default:g}) × {SAFETY:g} + step sampling of a maximum "
                   f"{samp:.1e} + reference uncertainty {ref_unc:.1e} "
                   f"(10^-{dig_ref.get(key) or 0:.1f} of scale {sc:.3g})")
        row.update(scale=sc, order=p, formal_order=order_default, reruns=v[1:])
        rows.append(row)
        bounded.append(row)
    # the run's order: the median of its quantities' (those above the noise), which one
    # quantity's erratic constant does not move
    orders = sorted(min(max(r["order"], -10.0), 10.0) for r in bounded if r["order"] == r["order"])
    run_order = orders[len(orders) // 2] if orders else math.nan
    run_ok = run_order != run_order or run_order >= order_default - ORDER_SLACK
    for row in bounded:
        p = row["order"]
        if p == p and not run_ok:
            row["kind"] = UNCONVERGED
            row["why"] = (f"not verification: the run converges at order {run_order:.2f} (the median "
                          f"of its quantities'), not at the formal {order_default:g}, so its reruns "
                          f"bound nothing; " + row["why"])
        row["run_order"] = run_order
    return rows


def noise_floor(scale, ref_unc, sampling, rtol):
    """Differences between the runs below this are noise, not a trend: the reference's
    uncertainty, the sampling bound, an adaptive run's rtol and the iterations' tolerance
    (1e-10 of the scale: Newton's increment test, the event location's)."""
    return ref_unc + sampling + (rtol + 1e-10) * scale


def _richardson(v, factor, floor):
    """(error estimate of v[0], measured order) from values at h, 2h, 4h (or rtol, 100 rtol,
    10⁴ rtol: factor 100). For a method of order p ≥ 1, e_h ≤ e_2h/2, so |q_h − q_2h| ≥
    e_2h − e_h ≥ e_h: the difference to the 2h run bounds the error even where the constant
    is erratic (a force jump or a kink anywhere inside a step); d2/2 covers a constant that
    changes between h and 2h. Differences both within `floor` are noise: the order is nan
    (the quantity converged)."""
    if any(x is None for x in v) or len(v) < 3:
        return math.inf, -math.inf
    d1, d2 = abs(v[0] - v[1]), abs(v[1] - v[2])
    if max(d1, d2) <= floor:
        return max(d1, d2 / 2.0), math.nan
    if d1 == 0.0:
        p = math.inf
    elif d2 == 0.0:
        p = -math.inf
    else:
        p = math.log(d2 / d1) / math.log(factor)
    return max(d1, d2 / 2.0), p


def _sampling_bound(key, summary, dt, ref):
    """A maximum taken at the steps (docs/results.md: u_max, phase maxima) is below the true
    one by at most max|ẍ| h²/8 (a parabola through the peak, the step at most h/2 away)."""
    if key.startswith("nodes."):
        nm = key[len("nodes."):].rsplit(".", 1)[0]
        return summary["nodes"][nm].get("a_absmax", 0.0) * dt * dt / 8.0
    if ".phase_max_penetration." in key:
        nm = key[len("contacts."):].rsplit(".", 2)[0]
        c = ref["contacts"][nm]
        a = sum(summary["nodes"][n].get("a_absmax", 0.0) for n in c.get("nodes", [])) or \
            2.0 * max(r.get("a_absmax", 0.0) for r in summary["nodes"].values())
        return a * dt * dt / 8.0
    return 0.0


def _row(title, source, key, value, reference, passed, digits, tol, why):
    value = float(value) if value is not None else math.nan
    reference = float(reference)
    err = abs(value - reference)
    return {"scene": title, "file": source, "quantity": f"{key} vs independent", "value": value,
            "reference": reference, "abs_error": err,
            "rel_error": err / abs(reference) if reference else float("nan"), "digits": float(digits),
            "rtol": 0.0, "atol": float(tol), "passed": bool(passed), "why": why,
            "evidence": "independent reference"}


def verify_independent(scene, summary, run, root=INDEPENDENT_ROOT):
    """Accuracy rows of a fixed-step run against its stored independent reference, or [] if
    there is none; `run(scene)` runs a scene and returns its summary (the 2Δt and 4Δt runs)."""
    ref = find_independent(scene, root)
    if ref is None:
        return []
    fixed = scene.analysis.get("integrator") in FIXED_STEP
    # fixed steps: reruns at 2Δt, 4Δt; adaptive ones (error proportional to the tolerance):
    # at 100 and 10⁴ × rtol, whose difference to the run bounds its error the same way
    key, factors = ("dt", (2.0, 4.0)) if fixed else ("rtol", (1e2, 1e4))
    factor = FIXED_FACTOR if fixed else ADAPTIVE_FACTOR
    runs = [summary]
    for f in factors:
        s2 = copy.deepcopy(scene)
        s2.analysis[key] = scene.analysis[key] * f
        runs.append(run(s2))
    return accuracy_rows(scene.title, scene.source, ref, runs, dt=scene.analysis["dt"] if fixed else None,
                         event_tol=0.0 if fixed else scene.analysis.get("event_tol", 0.0),
                         rtol=0.0 if fixed else scene.analysis.get("rtol", 0.0),
                         order_default=formal_order(scene.analysis, scene.contacts), factor=factor)
