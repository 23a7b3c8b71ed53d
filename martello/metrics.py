"""Metrics of a run against a reference (PROBLEMS.md "Metrics"; DESIGN.md "Results").

A *reference* is what a run is scored against: the exact history of a closed form
(martello.closed_forms, evaluated at any time), or stored reference data (reference/<name>/,
computed by refinement, with the digits it can be trusted to). The same metrics score
martello's own runs (`martello study`) and other codes' histories (`martello compare`):

* histories: max absolute error per column; max relative error, normwise per column
  (|y − y_ref| over max |y_ref| on the window, because a pointwise relative error is
  undefined where the reference crosses zero); scd = −log10(max relative error); mescd =
  −log10 max |y − y_ref|/(atol/rtol + |y_ref|) pointwise (IVP Test Set, Mazzia &
  Magherini); scd_final at the last common time, componentwise as in the IVP Test Set;
* events: impacts matched one to one before they are compared (closed_forms.match_events),
  so a shifted impact is a small time error, not one missing and one extra impact; impact
  count error, missing and extra impacts, impact time error;
* peaks: peak penetration and peak contact force, overall and per matched contact phase;
* realised restitution of each matched phase; energy: the run's own balance residual and
  the error of the mechanical energy at the end;
* cost: every counter of the run (steps, rejected steps, residual evaluations, Newton
  iterations, factorizations, events, wall time).

Every metric is a plain float in a flat dict (NaN when it does not apply), so that a study
writes them as CSV columns."""

from __future__ import annotations

import hashlib
import json
import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import numpy as np

from . import closed_forms as cf
from .errors import MartelloError

ROOT = Path(__file__).resolve().parent.parent
REFERENCE_ROOT = ROOT / "reference"
MANIFEST = "references.toml"

COST_KEYS = ("steps", "rejected_steps", "newton_iterations", "residual_evaluations",
             "factorizations", "events", "jacobian_evaluations", "root_evaluations",
             "contact_chatter_resolutions", "wall_time_s")
# Columns of a history, by prefix (martello's own history.csv; docs/compare.md).
KINDS = ("u", "v", "a", "penetration", "force", "energy")
# Digits a closed form is trusted to: phase ends are exact to ~1e-15 relative to the phase
# (closed_forms.bouncing_oscillator_kelvin); absolute times carry one rounding per phase.
CLOSED_FORM_DIGITS = 13.0
# A phase whose approach speed is below this fraction of the largest one is a graze: its
# realised restitution −δ̇_out/δ̇_in is a ratio of two tiny numbers and is not scored.
GRAZE_FRACTION = 1e-2


class ReferenceError(MartelloError):
    """No usable reference, or the reference data do not match the scene."""


# =============================================================================================
# References
# =============================================================================================
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


def physics_digest(scene):
    """sha256 of what determines a scene's solution: nodes, links, contacts, loads (not the
    analysis settings, the title or the check table). Reference data are keyed by it, so a
    study that changes only the integrator still finds them, and one that overrides a
    contact does not."""
    ground = dict(scene.ground) if scene.ground else None
    if ground and ground.get("type") == "record":
        ground["file"] = Path(ground["file"]).name
    data = {"nodes": scene.nodes, "links": scene.links, "contacts": scene.contacts,
            "gravity": scene.gravity, "forces": scene.forces, "ground": ground,
            "couplings": scene.couplings}
    return hashlib.sha256(json.dumps(_canonical(data), sort_keys=True, default=repr).encode()).hexdigest()


def _canonical(x):
    """Unset (None) and false values dropped, so that a loader that learns a new optional
    key (with an unset or false default) does not change the digest of existing scenes."""
    if isinstance(x, dict):
        return {k: _canonical(v) for k, v in x.items() if v is not None and v is not False}
    if isinstance(x, (list, tuple)):
        return [_canonical(v) for v in x]
    return x


# --- interpolation ---------------------------------------------------------------------------

def _hermite(t0, t1, y0, y1, d0, d1, dd0=None, dd1=None, t=None):
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
            out = _hermite(t0, t1, y[i], y[i + 1], v[i], v[i + 1], a[i], a[i + 1], t=t)
        else:
            out = _hermite(t0, t1, y[i], y[i + 1], v[i], v[i + 1], t=t)
    elif kind == "v" and f"a:{name}" in samples:
        a = np.asarray(samples[f"a:{name}"], float)
        out = _hermite(t0, t1, y[i], y[i + 1], a[i], a[i + 1], t=t)
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


# --- closed-form references ---------------------------------------------------------------

def _names(scene, params):
    node = params.pop("node", None) or (scene.nodes[0]["name"] if scene else "mass")
    contact = params.pop("contact", None) or (scene.contacts[0]["name"] if scene and scene.contacts
                                              else "plane")
    return node, contact


def _phase_force_peaks(fn_force, t_on, t_off, t_end):
    """Largest contact force in each phase [t_on, t_off] of a closed-form history, by dense
    sampling plus a parabola through the three samples about the largest one."""
    peaks = []
    for a, b in zip(t_on, t_off):
        b = min(b if math.isfinite(b) else t_end, t_end)
        if not b > a:
            peaks.append(0.0)
            continue
        s = np.linspace(a, b, 4001)
        f = fn_force(s)
        k = int(np.nanargmax(f))
        best = float(f[k])
        if 0 < k < len(s) - 1:
            y0, y1, y2 = f[k - 1], f[k], f[k + 1]
            den = y0 - 2 * y1 + y2
            if den < 0:
                best = float(y1 - 0.125 * (y0 - y2) ** 2 / den)
        peaks.append(best)
    return peaks


def kelvin_bounce_reference(t_end, m, k, h, g, eps, c=None, restitution=None, clipped=False,
                            u0=0.0, v0=0.0, node="mass", contact="plane", mstar=None):
    """The exact history of P2 with a linear or Kelvin penalty plane
    (closed_forms.bouncing_oscillator_kelvin), as a Reference. The dashpot comes from a
    target restitution by Anagnostopoulos' formula with m* = mstar (default m), as the
    scene's law does, or is given as c."""
    if c is None:
        c = (cf.kelvin_damping(eps, mstar or m, cf.kelvin_xi_from_e(restitution))
             if restitution is not None else 0.0)
    # as few impacts as cover [0, t_end]: phases past t_end cost time and, for very stiff
    # planes, can trip the closed form's root bracketing
    n = 1
    while True:
        r = cf.bouncing_oscillator_kelvin(m, k, h, g, eps, c, n, clipped=clipped, u0=u0, v0=v0,
                                          max_phases=4 * n + 4)
        covered = r.end_reason in ("persistent_contact", "no_impact", "escaped")
        if covered or np.isfinite(r.evaluate(np.array([t_end]))[0][0]) or n > 1_000_000:
            break
        n *= 2

    def force(u, v):
        d = u - h
        f = np.where(d > 0, eps * d + c * v, 0.0)
        return np.maximum(f, 0.0) if clipped else f

    def evaluate(t):
        u, v = r.evaluate(t)
        f = force(u, v)
        a = (m * g - k * u - f) / m
        d = u - h
        e_rec = 0.5 * k * u * u + 0.5 * eps * np.maximum(d, 0.0) ** 2
        return {f"u:{node}": u, f"v:{node}": v, f"a:{node}": a, f"penetration:{contact}": d,
                f"force:{contact}": f, "energy:kinetic": 0.5 * m * v * v,
                "energy:recoverable": e_rec}

    sel = r.t_impact <= t_end
    t_on = r.t_impact[sel]
    t_off = r.t_separation[: len(t_on)]
    v_in = r.v_in[sel]
    v_out = r.v_out[: len(t_on)]
    done = np.isfinite(t_off) & (t_off <= t_end)
    rest = [float(-vo / vi) if (d and vi > 0) else None for vi, vo, d in zip(v_in, v_out, done)]
    fpk = _phase_force_peaks(lambda s: force(*r.evaluate(s)), t_on, t_off, t_end)
    pen = [float(x) for x in r.max_penetration[: len(t_on)]]
    events = {contact: {"impact_times": [float(x) for x in t_on],
                        "separation_times": [float(x) if d else None for x, d in zip(t_off, done)],
                        "approach_speeds": [float(x) for x in v_in], "restitution": rest,
                        "phase_max_penetration": pen, "phase_max_force": fpk}}
    peaks = {contact: {"max_penetration": max(pen, default=0.0), "max_force": max(fpk, default=0.0)}}
    cols = (f"u:{node}", f"v:{node}", f"a:{node}", f"penetration:{contact}", f"force:{contact}",
            "energy:kinetic", "energy:recoverable")
    return Reference(name="closed form bouncing_oscillator_kelvin", kind="closed-form",
                     t_end=t_end, columns=cols, evaluate=evaluate, events=events, peaks=peaks,
                     masses={node: m}, digits={c_: CLOSED_FORM_DIGITS for c_ in cols},
                     provenance={"closed_form": "bouncing_oscillator_kelvin",
                                 "params": dict(m=m, k=k, h=h, g=g, eps=eps, c=c, clipped=clipped,
                                                u0=u0, v0=v0)})


def restitution_bounce_reference(t_end, m, k, h, g, e, u0=0.0, v0=0.0, node="mass",
                                 contact="plane", graze=1e-9):
    """The exact history of P2 with Newton's restitution law
    (closed_forms.bouncing_oscillator_restitution): harmonic flights about u_s = m g/k that
    leave the plane with e times the impact speed; after the Zeno point the mass rests on the
    plane and the contact carries m g − k h. Impacts slower than graze·v_1 are not listed
    (event_horizon marks where the list stops)."""
    w = math.sqrt(k / m)
    us = m * g / k
    n = 64
    while True:
        seq = cf.bouncing_oscillator_restitution(m, k, h, g, e, n, u0=u0, v0=v0)
        if len(seq.t) < n or seq.t[-1] > t_end or seq.v[-1] < graze * seq.v[0] or n > 10 ** 6:
            break
        n *= 4
    keep = (seq.t <= t_end) & (seq.v >= graze * (seq.v[0] if len(seq.v) else 1.0))
    t_imp, v_imp = seq.t[keep], seq.v[keep]
    horizon = t_end if len(seq.t) == len(t_imp) else float(seq.t[len(t_imp)] if len(t_imp) < len(seq.t) else t_end)
    zeno = seq.zeno_time

    def evaluate(t):
        t = np.asarray(t, float)
        u = np.empty_like(t)
        v = np.empty_like(t)
        starts = np.concatenate(([0.0], seq.t))
        idx = np.searchsorted(starts, t, side="right") - 1
        for i in np.unique(idx):
            sel = idx == i
            if i == 0:
                x0, vv0, t0 = u0 - us, v0, 0.0
            else:
                x0, vv0, t0 = h - us, -e * seq.v[i - 1], seq.t[i - 1]
            tau = t[sel] - t0
            u[sel] = us + x0 * np.cos(w * tau) + (vv0 / w) * np.sin(w * tau)
            v[sel] = -x0 * w * np.sin(w * tau) + vv0 * np.cos(w * tau)
        rest = t >= zeno
        u = np.where(rest, h, u)
        v = np.where(rest, 0.0, v)
        f = np.where(rest, m * g - k * h, 0.0)
        a = np.where(rest, 0.0, g - (k / m) * u)
        return {f"u:{node}": u, f"v:{node}": v, f"a:{node}": a, f"penetration:{contact}": u - h,
                f"force:{contact}": f, "energy:kinetic": 0.5 * m * v * v,
                "energy:recoverable": 0.5 * k * u * u}

    events = {contact: {"impact_times": [float(x) for x in t_imp],
                        "separation_times": [None] * len(t_imp),
                        "approach_speeds": [float(x) for x in v_imp],
                        "restitution": [float(e)] * len(t_imp),
                        "phase_max_penetration": [0.0] * len(t_imp),
                        "phase_max_force": [None] * len(t_imp)}}
    cols = (f"u:{node}", f"v:{node}", f"a:{node}", f"penetration:{contact}", f"force:{contact}",
            "energy:kinetic", "energy:recoverable")
    return Reference(name="closed form bouncing_oscillator_restitution", kind="closed-form",
                     t_end=t_end, columns=cols, evaluate=evaluate, events=events,
                     peaks={contact: {"max_penetration": 0.0}}, masses={node: m},
                     digits={c_: CLOSED_FORM_DIGITS for c_ in cols}, event_horizon=horizon,
                     provenance={"closed_form": "bouncing_oscillator_restitution",
                                 "params": dict(m=m, k=k, h=h, g=g, e=e, u0=u0, v0=v0)})


def two_body_kelvin_reference(t_end, m1, m2, gap, eps, restitution=None, c=None, u1=0.0, u2=0.0,
                              v1=0.0, v2=0.0, node1="m1", node2="m2", contact="impact"):
    """Two free bodies and a linear or Kelvin penalty contact between them (P5): the
    relative coordinate x = u1 − u2 is P2's penalty bounce with mass m*, no spring and no
    gravity (closed_forms.bouncing_oscillator_kelvin with k = g = 0), the centre of mass moves
    uniformly. Exact at any time."""
    ms = m1 * m2 / (m1 + m2)
    rel = kelvin_bounce_reference(t_end, ms, 0.0, gap, 0.0, eps, c=c, restitution=restitution,
                                  u0=u1 - u2, v0=v1 - v2, node="x", contact=contact, mstar=ms)
    mt = m1 + m2
    xc0, vc = (m1 * u1 + m2 * u2) / mt, (m1 * v1 + m2 * v2) / mt

    def evaluate(t):
        r = rel.evaluate(t)
        x, xd, xdd = r["u:x"], r["v:x"], r["a:x"]
        xc = xc0 + vc * np.asarray(t, float)
        ua, ub = xc + (m2 / mt) * x, xc - (m1 / mt) * x
        va, vb = vc + (m2 / mt) * xd, vc - (m1 / mt) * xd
        d = x - gap
        return {f"u:{node1}": ua, f"u:{node2}": ub, f"v:{node1}": va, f"v:{node2}": vb,
                f"a:{node1}": (m2 / mt) * xdd, f"a:{node2}": -(m1 / mt) * xdd,
                f"penetration:{contact}": d, f"force:{contact}": r[f"force:{contact}"],
                "energy:kinetic": 0.5 * m1 * va * va + 0.5 * m2 * vb * vb,
                "energy:recoverable": 0.5 * eps * np.maximum(d, 0.0) ** 2}

    cols = (f"u:{node1}", f"u:{node2}", f"v:{node1}", f"v:{node2}", f"a:{node1}", f"a:{node2}",
            f"penetration:{contact}", f"force:{contact}", "energy:kinetic", "energy:recoverable")
    return Reference(name="closed form two-body penalty impact (bouncing_oscillator_kelvin, k = g = 0)",
                     kind="closed-form", t_end=t_end, columns=cols, evaluate=evaluate,
                     events=rel.events, peaks=rel.peaks, masses={node1: m1, node2: m2},
                     digits={c_: CLOSED_FORM_DIGITS for c_ in cols},
                     provenance={"closed_form": "bouncing_oscillator_kelvin (relative motion)",
                                 "params": dict(m1=m1, m2=m2, gap=gap, eps=eps, c=c,
                                                restitution=restitution)})


def sdof_ground_reference(t_end, m, k, zeta, ag_amp, omega_g, u0=0.0, v0=0.0, node="m"):
    """The exact response of a damped SDOF to A sin(Ωt) ground acceleration
    (closed_forms.sdof_sine_ground_response)."""
    def evaluate(t):
        r = cf.sdof_sine_ground_response(m, k, zeta, ag_amp, omega_g, t, u0=u0, v0=v0)
        return {f"u:{node}": r.u, f"v:{node}": r.v, f"a:{node}": r.a}
    cols = (f"u:{node}", f"v:{node}", f"a:{node}")
    return Reference(name="closed form sdof_sine_ground_response", kind="closed-form", t_end=t_end,
                     columns=cols, evaluate=evaluate, masses={node: m},
                     digits={c_: CLOSED_FORM_DIGITS for c_ in cols},
                     provenance={"closed_form": "sdof_sine_ground_response",
                                 "params": dict(m=m, k=k, zeta=zeta, ag_amp=ag_amp, omega_g=omega_g)})


# Closed forms with a full history, by the name a study file (or a scene's [check]) uses.
HISTORY_CLOSED_FORMS = {
    "bouncing_oscillator_kelvin": kelvin_bounce_reference,
    "bouncing_oscillator_restitution": restitution_bounce_reference,
    "two_body_kelvin": two_body_kelvin_reference,
    "sdof_sine_ground_response": sdof_ground_reference,
}


def closed_form_reference(name, params, t_end, scene=None):
    """A closed-form Reference by name (HISTORY_CLOSED_FORMS) with the study's params."""
    if name not in HISTORY_CLOSED_FORMS:
        raise ReferenceError(f"no closed-form history named {name!r} "
                             f"(valid: {', '.join(HISTORY_CLOSED_FORMS)})")
    params = dict(params)
    if name in ("bouncing_oscillator_kelvin", "bouncing_oscillator_restitution"):
        params["node"], params["contact"] = _names(scene, params)
    try:
        return HISTORY_CLOSED_FORMS[name](t_end, **params)
    except TypeError as exc:
        raise ReferenceError(f"closed form {name}: {exc}") from None


def _from_check(scene):
    """A closed-form history implied by the scene's [check] table, when the check's closed
    form is exact for the whole history of that scene (not only for the quantities it
    checks: a Hertz bounce is checked against the restitution formula's first impact, which
    says nothing about later ones)."""
    chk = scene.check
    if not chk or scene.analysis.get("type") != "dynamic":
        return None
    p, t_end = dict(chk["params"]), scene.analysis["t_end"]
    schemes = {c["scheme"] for c in scene.contacts}
    laws = {c.get("law") for c in scene.contacts}
    name = chk["closed_form"]
    if name == "bouncing_kelvin_events" and schemes == {"penalty"} and laws <= {"linear", "kelvin"} \
            and len(scene.nodes) == 1:
        c = scene.contacts[0]
        return kelvin_bounce_reference(t_end, p["m"], p["k"], p["h"], p["g"], p["eps"],
                                       c=p.get("damping") if p.get("restitution") is None else None,
                                       restitution=p.get("restitution"), clipped=p.get("clipped", False),
                                       node=scene.nodes[0]["name"], contact=c["name"])
    if name == "bouncing_restitution_events" and schemes <= {"restitution", "lagrange"} \
            and len(scene.nodes) == 1:
        return restitution_bounce_reference(t_end, p["m"], p["k"], p["h"], p["g"], p["e"],
                                            node=scene.nodes[0]["name"],
                                            contact=scene.contacts[0]["name"])
    if name == "sdof_sine_ground_final" and not scene.contacts and len(scene.nodes) == 1:
        n = scene.nodes[0]
        return sdof_ground_reference(t_end, p["m"], p["k"], p["zeta"], p["ag_amp"], p["omega_g"],
                                     u0=n["u0"], v0=n["v0"], node=n["name"])
    if name == "two_body_impact" and p.get("law") in ("linear", "kelvin") and not p.get("clipped") \
            and len(scene.nodes) == 2 and len(scene.contacts) == 1 and not scene.links \
            and scene.gravity == 0.0:
        c = scene.contacts[0]
        a, b = scene.nodes[c["a"]], scene.nodes[c["b"]]
        return two_body_kelvin_reference(t_end, a["mass"], b["mass"], c["gap"], c["stiffness"],
                                         restitution=c.get("restitution"),
                                         c=c.get("damping") if c.get("restitution") is None else None,
                                         u1=a["u0"], u2=b["u0"], v1=a["v0"], v2=b["v0"],
                                         node1=a["name"], node2=b["name"], contact=c["name"])
    return None


# --- stored reference data ------------------------------------------------------------------

def manifest(root=REFERENCE_ROOT):
    """The entries of reference/references.toml (what the reference data are and how they
    are regenerated), each with its folder."""
    path = Path(root) / MANIFEST
    if not path.exists():
        return []
    with open(path, "rb") as fh:
        data = tomllib.load(fh)
    out = []
    for e in data.get("reference", []):
        e = dict(e)
        e["folder"] = Path(root) / e["name"]
        out.append(e)
    return out


def load_reference(folder):
    """Reference data from reference/<name>/ (reference.json + history.csv)."""
    folder = Path(folder)
    meta_path, hist_path = folder / "reference.json", folder / "history.csv"
    if not meta_path.exists() or not hist_path.exists():
        raise ReferenceError(f"{folder}: no reference data (reference.json and history.csv); "
                             "build it with scripts/regenerate_reference")
    meta = json.loads(meta_path.read_text())
    with open(hist_path) as fh:
        header = fh.readline().strip().split(",")
    data = np.loadtxt(hist_path, delimiter=",", skiprows=1, ndmin=2)
    samples = {c: data[:, i] for i, c in enumerate(header)}
    times = samples.pop("t")
    return Reference(name=f"reference/{folder.name}", kind="data", t_end=float(meta["t_end"]),
                     columns=tuple(samples), times=times, samples=samples,
                     events=meta.get("events", {}), peaks=meta.get("peaks", {}),
                     masses=meta.get("masses", {}), digits=meta.get("digits", {}),
                     event_horizon=float(meta.get("event_horizon", meta["t_end"])),
                     provenance=meta)


def find_reference_data(scene, root=REFERENCE_ROOT):
    """The stored reference whose physics digest matches the scene, else None. A reference
    stored for the same scene file whose digest no longer matches is stale: an error."""
    digest = physics_digest(scene)
    stale = None
    for e in manifest(root):
        meta_path = e["folder"] / "reference.json"
        if not meta_path.exists():
            continue
        meta = json.loads(meta_path.read_text())
        if meta.get("physics_sha256") == digest:
            if scene.analysis.get("t_end", 0.0) > float(meta["t_end"]) * (1 + 1e-12):
                raise ReferenceError(f"{e['folder']}: the reference ends at t = {meta['t_end']} s, "
                                     f"the scene runs to {scene.analysis['t_end']} s")
            return load_reference(e["folder"])
        # stale: the scene *is* the entry's file (loaded as is), and the file has changed
        src = (ROOT / e["scene"]).resolve()
        if not e.get("contact") and src.exists() and scene.source and \
                Path(scene.source).resolve() == src and meta.get("scene_sha256") != scene.digest \
                and scene.digest == hashlib.sha256(src.read_bytes()).hexdigest():
            stale = e["folder"]
    if stale is not None:
        raise ReferenceError(f"{stale}: reference data were computed for another version of "
                             f"{scene.source} (the physics digest differs): run "
                             "scripts/regenerate_reference")
    return None


def reference_for_scene(scene, root=REFERENCE_ROOT, spec=None):
    """The reference a scene is scored against.

    spec (a study's `reference` entry) may be None or "auto", {closed_form = NAME, params =
    {...}} or {data = "reference/<name>"}. "auto" takes stored reference data for the
    scene's physics if any, else the closed-form history its [check] implies, else None."""
    t_end = scene.analysis.get("t_end")
    if isinstance(spec, dict) and "closed_form" in spec:
        return closed_form_reference(spec["closed_form"], spec.get("params", {}), t_end, scene)
    if isinstance(spec, dict) and "data" in spec:
        p = Path(spec["data"])
        return load_reference(p if p.is_absolute() else ROOT / p)
    if spec not in (None, "auto"):
        raise ReferenceError(f"reference {spec!r}: give \"auto\", {{ closed_form = ..., params = ... }} "
                             "or { data = \"reference/<name>\" }")
    ref = find_reference_data(scene, root)
    return ref if ref is not None else _from_check(scene)


# =============================================================================================
# Metrics
# =============================================================================================
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
        m_ = cf.mescd(y, yr, atol, rtol)
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
    impacts matched first (closed_forms.match_events).

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
        m = cf.match_events(t, tr, w)
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


# =============================================================================================
# A summary from a bare history (for other codes' output)
# =============================================================================================
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
                y = _hermite(t0, t1, d[i], d[i + 1], rate[i], rate[i + 1], t=np.array(tc))
                dt_ = 1e-7 * (t1 - t0)
                yp = (_hermite(t0, t1, d[i], d[i + 1], rate[i], rate[i + 1], t=np.array(tc + dt_)) - y) / dt_
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
        best = max(best, float(_hermite(t[a_], t[b_], d[a_], d[b_], rate[a_], rate[b_], t=np.array(tau))))
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

        def node_col(kind, i):
            if i < 0:
                return np.zeros_like(t)
            return h.get(f"{kind}:{scene.nodes[i]['name']}")
        ua, ub = node_col("u", c["a"]), node_col("u", c["b"])
        if d is None and ua is not None and ub is not None:
            d = ua - ub - c["gap"]
        if d is None:
            continue
        va, vb = node_col("v", c["a"]), node_col("v", c["b"])
        rate = va - vb if (va is not None and vb is not None) else np.gradient(d, t)
        aa, ab = node_col("a", c["a"]), node_col("a", c["b"])
        acc = aa - ab if (aa is not None and ab is not None) else None

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


# =============================================================================================
# Verification of scenes without a closed form (for `martello check`)
# =============================================================================================
def verify_reference_data(scene, summary, history, root=REFERENCE_ROOT, slack=1.0):
    """Rows for the catalogue verification table (the same keys as check.verify) comparing a
    run of a scene with its stored reference data, or [] if it has none.

    The tolerance of each row is measured, not guessed: the stored data say how far the
    scene's own analysis settings (integrator, Δt) were from the reference when it was made
    (`catalogue_error` in reference.json, one value per metric). A row passes if the fresh
    error is at most 2·that + 10^-(digits trusted) (times `slack`), i.e. if neither the
    solver nor the reference has drifted."""
    ref = find_reference_data(scene, root)
    if ref is None or ref.kind != "data":
        return []
    m = score(summary, history, ref)
    expected = ref.provenance.get("catalogue_error", {})
    floor = 10.0 ** (-ref.trusted_digits()) if math.isfinite(ref.trusted_digits()) else 0.0
    rows = []
    for key, why in (("max_rel_error", "history u (normwise relative)"),
                     ("impact_time_error", "impact times after matching (s)"),
                     ("peak_penetration_error", "peak penetration (relative)"),
                     ("impact_count_error", "impact count (run − reference)")):
        value = m.get(key, math.nan)
        if value is None or (isinstance(value, float) and math.isnan(value)):
            continue
        exp = expected.get(key)
        if key == "impact_count_error":
            tol = abs(exp) if exp is not None else 0.0
            passed = abs(value) <= tol
        else:
            tol = slack * (2.0 * (exp if exp is not None else 0.0) + floor)
            passed = value <= tol
        digits = (max(0.0, min(16.0, -math.log10(value))) if key != "impact_count_error" and value > 0
                  else (16.0 if value == 0 else 0.0))
        rows.append({"scene": scene.title, "file": scene.source, "quantity": f"{key} vs {ref.name}",
                     "value": float(value), "reference": 0.0, "abs_error": float(abs(value)),
                     "rel_error": float("nan"), "digits": digits, "rtol": 0.0, "atol": float(tol),
                     "passed": bool(passed),
                     "why": f"{why}; reference trusted to {ref.trusted_digits():.1f} digits; "
                            f"error of these settings when the reference was made: {exp}"})
    return rows
