"""References from closed forms: exact histories (martello.oracles) as References, by the
name a study file uses, or implied by a scene's [check] table."""

from __future__ import annotations

import math

import numpy as np

from ..oracles.linear_sdof import sdof_sine_ground_response
from ..oracles.p2_bouncing import bouncing_oscillator_kelvin, bouncing_oscillator_restitution
from ..oracles.p5_contact_laws import kelvin_damping, kelvin_xi_from_e
from .base import CLOSED_FORM_DIGITS, Reference, ReferenceError


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
    (oracles.p2_bouncing.bouncing_oscillator_kelvin), as a Reference. The dashpot comes from a
    target restitution by Anagnostopoulos' formula with m* = mstar (default m), as the
    scene's law does, or is given as c."""
    if c is None:
        c = (kelvin_damping(eps, mstar or m, kelvin_xi_from_e(restitution))
             if restitution is not None else 0.0)
    # as few impacts as cover [0, t_end]: phases past t_end cost time and, for very stiff
    # planes, can trip the closed form's root bracketing
    n = 1
    while True:
        r = bouncing_oscillator_kelvin(m, k, h, g, eps, c, n, clipped=clipped, u0=u0, v0=v0,
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
    (oracles.p2_bouncing.bouncing_oscillator_restitution): harmonic flights about u_s = m g/k that
    leave the plane with e times the impact speed; after the Zeno point the mass rests on the
    plane and the contact carries m g − k h. Impacts slower than graze·v_1 are not listed
    (event_horizon marks where the list stops)."""
    w = math.sqrt(k / m)
    us = m * g / k
    n = 64
    while True:
        seq = bouncing_oscillator_restitution(m, k, h, g, e, n, u0=u0, v0=v0)
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
    gravity (oracles.p2_bouncing.bouncing_oscillator_kelvin with k = g = 0), the centre of
    mass moves uniformly. Exact at any time."""
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
    (oracles.linear_sdof.sdof_sine_ground_response)."""
    def evaluate(t):
        r = sdof_sine_ground_response(m, k, zeta, ag_amp, omega_g, t, u0=u0, v0=v0)
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


def from_check(scene):
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
