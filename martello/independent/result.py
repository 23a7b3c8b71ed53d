"""What a run of the independent engine reports: peaks (node u, |v|, |a|; link |force| and
|elongation|; contact phase penetration and force), final state, contact phases, energies and
a history, all read from the dense output of its pieces (extrema are refined on the
interpolant, not taken at the steps)."""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import minimize_scalar

from .engine import Run
from .scene import GROUND

EPS = np.finfo(float).eps
# samples per solver step in the search for extrema, before each is refined on the interpolant
SAMPLES_PER_STEP = 6


def _piece_times(t0, t1, steps):
    ts = np.unique(np.concatenate([[t0, t1], steps[(steps >= t0) & (steps <= t1)]]))
    if len(ts) < 2:
        return ts
    frac = np.linspace(0.0, 1.0, SAMPLES_PER_STEP + 1)[:-1]
    inner = (ts[:-1, None] + np.diff(ts)[:, None] * frac[None, :]).ravel()
    return np.unique(np.concatenate([inner, [t1]]))


def _refine(f, a, b, sign):
    """max of sign·f on [a, b] from the interpolant (bounded Brent; the value's error is
    quadratic in the abscissa's near a smooth maximum). Brent's bounded search stops within
    √ε·|x| + xatol/3 of the abscissa, so it searches the offset s = x − a: at t = 250 s
    (P9's 60th impact) √ε·t = 4e-6 s would put a contact's peak 1e-5 off (relative)."""
    if b <= a:
        return a, f(a)
    r = minimize_scalar(lambda s: -sign * f(a + s), bounds=(0.0, b - a), method="bounded",
                        options={"xatol": max(4.0 * EPS * max(abs(a), abs(b)), 1e-300)})
    x = a + float(r.x)
    cands = [(a, f(a)), (b, f(b)), (x, f(x))]
    return max(cands, key=lambda p: sign * p[1])


def _sample_absmax(at, rec, field_, key, x, where):
    """rec[field_] ← the largest |x| of a piece's samples; where it is largest is kept in at
    (the sample index and the piece) for the refinement on the interpolant."""
    k = int(np.argmax(np.abs(x)))
    if abs(x[k]) > rec[field_]:
        rec[field_] = float(abs(x[k]))
        at[key] = (k, where)


class Quantities:
    """Element quantities as functions of the state in a piece's modes."""

    def __init__(self, run: Run):
        self.run = run
        self.s = run.system
        self.m = run.model

    def accelerations(self, ts, Y, md):
        """The node accelerations (n × len(ts)) of the states Y at ts in the modes md."""
        n = self.s.n
        return np.array([self.s.rhs(t, Y[:, i], md)[n:2 * n] for i, t in enumerate(ts)]).T

    def contact(self, Y, md, j):
        s, c = self.s, self.m.contacts[j]
        uE = np.vstack([Y[:s.n], np.zeros(Y.shape[1])])
        vE = np.vstack([Y[s.n:2 * s.n], np.zeros(Y.shape[1])])
        d = s.cc[j] @ uE[s.cn[j]] - c.gap              # the contact's row over the samples
        dd = s.cc[j] @ vE[s.cn[j]]
        if not md.active[j] or c.scheme != "penalty":
            return d, np.zeros_like(d)
        p = np.array([c.force(x, xd, md.v_in[j], md.branch[j]) for x, xd in zip(d, dd)])
        return d, p

    def links(self, Y, md):
        """(name, elongation, force) of every link."""
        s = self.s
        uE = np.vstack([Y[:s.n], np.zeros(Y.shape[1])])
        vE = np.vstack([Y[s.n:2 * s.n], np.zeros(Y.shape[1])])
        out = []
        for i, (name, a, b, k) in enumerate(self.m.springs):
            du = uE[s.sa[i]] - uE[s.sb[i]]
            out.append((name, du, k * du))
        for i, (name, a, b, c) in enumerate(self.m.dashpots):
            out.append((name, uE[s.da[i]] - uE[s.db[i]], c * (vE[s.da[i]] - vE[s.db[i]])))
        for i, lk in enumerate(self.m.bilinears):
            du = uE[s.ba[i]] - uE[s.bb[i]]
            fp = (1 - s.brho[i]) * s.bk[i] * (du - md.up[i]) if md.reg[i] == 0 else \
                np.full_like(du, md.reg[i] * (1 - s.brho[i]) * s.bfy[i])
            out.append((lk[0], du, s.brho[i] * s.bk[i] * du + fp))
        for i, lk in enumerate(self.m.dampers):
            dv = s.fD[i] @ vE
            f = s.fsec[i] * dv if md.dreg[i] == 0 else md.dreg[i] * s.fc[i] * np.abs(dv) ** s.falpha[i]
            out.append((lk[0], s.fD[i] @ uE, f))
        return out


def summarise(run: Run, grid=None) -> dict:
    """The run's report (docs/independent-reference.md "What it reports")."""
    m, s, q = run.model, run.system, Quantities(run)
    n = s.n
    nodes = {nm: {"u_max": -math.inf, "u_min": math.inf, "v_absmax": 0.0, "a_absmax": 0.0}
             for nm in m.names}
    links = {}
    link_at = {}
    absmax_at = {}      # (kind, name) -> (value, (sol, ts, k, md)): |v|, |a|, |du| refined below
    phase_best = [[[0.0, None, 0.0, None] for _ in ph] for ph in run.phases]   # pen, t, force, t
    node_at = {}
    for (t0, t1, sol, steps, md) in run.pieces:
        ts = _piece_times(t0, t1, steps)
        Y = sol(ts)
        for i, nm in enumerate(m.names):
            u, v = Y[i], Y[n + i]
            k = int(np.argmax(u))
            if u[k] > nodes[nm]["u_max"]:
                nodes[nm]["u_max"] = float(u[k])
                node_at[(nm, 1)] = (sol, ts, k, t0, t1)
            k = int(np.argmin(u))
            if u[k] < nodes[nm]["u_min"]:
                nodes[nm]["u_min"] = float(u[k])
                node_at[(nm, -1)] = (sol, ts, k, t0, t1)
            _sample_absmax(absmax_at, nodes[nm], "v_absmax", ("v", nm), v, (sol, ts, md))
        A = q.accelerations(ts, Y, md)
        for i, nm in enumerate(m.names):
            _sample_absmax(absmax_at, nodes[nm], "a_absmax", ("a", nm), A[i], (sol, ts, md))
        for name, du, f in q.links(Y, md):
            rec = links.setdefault(name, {"max_abs_force": 0.0, "max_abs_elongation": 0.0})
            k = int(np.argmax(np.abs(f)))
            if abs(f[k]) > rec["max_abs_force"]:
                rec["max_abs_force"] = float(abs(f[k]))
                link_at[name] = (sol, ts, k, t0, t1, md)
            _sample_absmax(absmax_at, rec, "max_abs_elongation", ("du", name), du, (sol, ts, md))
        for j in range(len(m.contacts)):
            if not md.active[j]:
                continue
            ph = _phase_index(run.phases[j], t0)
            if ph is None:
                continue
            d, p = q.contact(Y, md, j)
            best = phase_best[j][ph]
            k = int(np.argmax(d))
            if d[k] > best[0]:
                best[0], best[1] = float(d[k]), (sol, ts, k, t0, t1, md)
            k = int(np.argmax(p))
            if p[k] > best[2]:
                best[2], best[3] = float(p[k]), (sol, ts, k, t0, t1, md)
    # refine the extrema on the interpolant
    for (nm, sign), (sol, ts, k, t0, t1) in node_at.items():
        i = m.names.index(nm)
        tt, val = _refine(lambda x: float(sol(x)[i]), ts[max(k - 1, 0)], ts[min(k + 1, len(ts) - 1)], sign)
        nodes[nm]["u_max" if sign > 0 else "u_min"] = val
        nodes[nm]["t_max" if sign > 0 else "t_min"] = tt
    for nm, rec in nodes.items():
        rec["u_absmax"] = max(abs(rec["u_max"]), abs(rec["u_min"]))
    for (kind, name), (k, (sol, ts, md)) in absmax_at.items():
        def fabs(x, kind=kind, name=name, sol=sol, md=md):
            Yx = sol(np.array([x]))
            if kind == "v":
                return abs(float(Yx[n + m.names.index(name)][0]))
            if kind == "a":
                return abs(float(q.accelerations(np.array([x]), Yx, md)[m.names.index(name)][0]))
            return abs(float(next(du for nm_, du, _ in q.links(Yx, md) if nm_ == name)[0]))
        _, val = _refine(fabs, ts[max(k - 1, 0)], ts[min(k + 1, len(ts) - 1)], 1.0)
        if kind == "du":
            links[name]["max_abs_elongation"] = max(val, links[name]["max_abs_elongation"])
        else:
            field_ = "v_absmax" if kind == "v" else "a_absmax"
            nodes[name][field_] = max(val, nodes[name][field_])
    for name, (sol, ts, k, t0, t1, md) in link_at.items():
        def fabs(x, name=name, sol=sol, md=md):
            Yx = sol(np.array([x]))
            return abs(float(next(f for nm_, _, f in q.links(Yx, md) if nm_ == name)[0]))
        tt, val = _refine(fabs, ts[max(k - 1, 0)], ts[min(k + 1, len(ts) - 1)], 1.0)
        links[name]["max_abs_force"] = max(val, links[name]["max_abs_force"])
        links[name]["t_max_abs_force"] = tt
    contacts = {}
    for j, c in enumerate(m.contacts):
        phases = []
        for ph, best in zip(run.phases[j], phase_best[j]):
            pen, force = best[0], best[2]
            for slot, col in ((1, 0), (3, 1)):
                if best[slot] is None:
                    continue
                sol, ts, k, t0, t1, md = best[slot]
                f = (lambda x, sol=sol, md=md, col=col:
                     float(q.contact(sol(np.array([x])), md, j)[col][0]))
                _, val = _refine(f, ts[max(k - 1, 0)], ts[min(k + 1, len(ts) - 1)], 1.0)
                if col == 0:
                    pen = max(pen, val)
                else:
                    force = max(force, val)
            rec = {"t_on": ph["t_on"], "t_off": ph.get("t_off"), "v_in": ph["v_in"],
                   "v_out": ph.get("v_out"), "max_penetration": pen, "max_force": force}
            if c.scheme == "restitution":
                rec["max_force"] = ph["impulse"]          # an impulse, N s (docs/results.md)
            rec["restitution"] = (-rec["v_out"] / rec["v_in"]) if rec["v_out"] is not None and rec["v_in"] > 0 \
                else None
            rec["contact_time"] = (rec["t_off"] - rec["t_on"]) if rec["t_off"] is not None else None
            phases.append(rec)
        contacts[c.name] = {"impacts": len(phases), "phases": phases,
                            "max_penetration": max((p["max_penetration"] for p in phases), default=0.0),
                            "max_force": max((p["max_force"] for p in phases), default=0.0)}
    # final state and energies
    t_last, (t0, t1, sol, steps, md) = m.t_end, run.pieces[-1]
    yf = sol(t1)
    for i, nm in enumerate(m.names):
        nodes[nm]["u_final"], nodes[nm]["v_final"] = float(yf[i]), float(yf[n + i])
    energy = energies_at(run, np.array([t_last]))
    energy = {k: float(v[0]) for k, v in energy.items()}
    hist = history(run, np.linspace(0.0, m.t_end, 2001) if grid is None else np.asarray(grid, float))
    bal = hist[1][:, hist[0].index("energy:balance")]
    energy["balance_max"] = float(np.max(np.abs(bal)))
    return {"nodes": nodes, "links": links, "contacts": contacts, "energy": energy,
            "events": run.events, "history": hist}


def _phase_index(phases, t0):
    for k in range(len(phases) - 1, -1, -1):
        if phases[k]["t_on"] <= t0 * (1 + 1e-15) + 1e-300:
            return k
    return None


def _at(run: Run, ts):
    """(Y, modes) of every requested time, piece by piece."""
    starts = np.array([p[0] for p in run.pieces])
    which = np.clip(np.searchsorted(starts, ts, side="right") - 1, 0, len(run.pieces) - 1)
    out = []
    for k in np.unique(which):
        sel = np.nonzero(which == k)[0]
        out.append((sel, run.pieces[k][2](ts[sel]), run.pieces[k][4]))
    return out


def energies_at(run: Run, ts) -> dict:
    """The energy terms of docs/results.md "Energy" at the times ts."""
    s, n = run.system, run.system.n
    names = ("kinetic", "recoverable", "input", "damping", "plastic", "contact", "impact", "initial", "balance")
    out = {k: np.zeros(len(ts)) for k in names}
    y0 = run.pieces[0][2](run.pieces[0][0])
    e0 = s.kinetic(y0) + s.recoverable(y0, run.pieces[0][4])
    imp_t = np.array([x[0] for x in run.impact_energy])
    imp_v = np.array([x[1] for x in run.impact_energy])
    for sel, Y, md in _at(run, np.asarray(ts, float)):
        for col, k in zip(range(Y.shape[1]), sel):
            y = Y[:, col]
            out["kinetic"][k] = s.kinetic(y)
            out["recoverable"][k] = s.recoverable(y, md)
            out["input"][k], out["damping"][k], out["contact"][k], out["plastic"][k] = y[2 * n:2 * n + 4]
            nimp = int(np.searchsorted(imp_t, ts[k], side="right")) if len(imp_t) else 0
            out["impact"][k] = imp_v[nimp - 1] if nimp else 0.0
    out["initial"][:] = e0
    out["balance"] = (out["initial"] + out["input"] - out["kinetic"] - out["recoverable"] - out["damping"]
                      - out["plastic"] - out["contact"] - out["impact"])
    return out


def history(run: Run, ts) -> tuple:
    """Columns and rows (docs/results.md "history.csv" names) at the times ts."""
    m, s, q = run.model, run.system, Quantities(run)
    n = s.n
    cols = ["t"] + [f"u:{x}" for x in m.names] + [f"v:{x}" for x in m.names] \
        + [f"penetration:{c.name}" for c in m.contacts] + [f"force:{c.name}" for c in m.contacts]
    data = np.zeros((len(ts), len(cols)))
    data[:, 0] = ts
    for sel, Y, md in _at(run, np.asarray(ts, float)):
        data[sel, 1:1 + 2 * n] = Y[:2 * n].T
        for j in range(len(m.contacts)):
            d, p = q.contact(Y, md, j)
            data[sel, 1 + 2 * n + j] = d
            data[sel, 1 + 2 * n + len(m.contacts) + j] = p
    en = energies_at(run, ts)
    cols += [f"energy:{k}" for k in en]
    data = np.hstack([data, np.column_stack(list(en.values()))])
    return cols, data


__all__ = ["summarise", "history", "energies_at", "GROUND"]
