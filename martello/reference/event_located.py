"""An independent, event-located reference engine (scipy), for scenes it can describe
exactly: coded from the scene's definition, not from the library's kernels."""

from __future__ import annotations

import math
import time

import numpy as np

from ..binding import native
from ..errors import MartelloError
from ..oracles.p5_contact_laws import HC_FACTORS, kelvin_damping, kelvin_xi_from_e
from ..run import LAW_EXPONENT


class Unsupported(MartelloError):
    """The scene has a part the event-located reference does not model."""


def _tf(fn):
    """A scene time function as a Python callable and its breakpoints (docs/problems.md units;
    the same definitions as fortran/time_functions.f90)."""
    if fn is None:
        return (lambda t: 0.0), []
    k = fn["type"]
    if k == "constant":
        return (lambda t: fn["value"]), []
    if k == "sine":
        a, w, ph, t0, t1 = fn["amplitude"], fn["omega"], fn["phase"], fn["t_start"], fn["t_end"]
        return (lambda t: a * math.sin(w * (t - t0) + ph) if t0 <= t <= t1 else 0.0), [t0, t1]
    if k == "rectangular":
        a, t0, t1 = fn["amplitude"], fn["t_start"], fn["t_end"]
        return (lambda t: a if t0 <= t < t1 else 0.0), [t0, t1]
    if k == "half_sine":
        a, t0, t1 = fn["amplitude"], fn["t_start"], fn["t_end"]
        return (lambda t: a * math.sin(math.pi * (t - t0) / (t1 - t0)) if t0 <= t <= t1 else 0.0), [t0, t1]
    raise Unsupported(f"time function {k!r}")


def _two_mass_mstar(mass, fixed, a, b):
    """m* = m_a m_b/(m_a + m_b) of a contact, a ground (-1) or fixed side infinitely heavy:
    the reference's own, independent of the library's 1/(B M⁻¹ Bᵀ) (it refuses couplings,
    so M is diagonal and the two agree)."""
    ms = [mass[i] for i in (a, b) if i >= 0 and not fixed[i]]
    return math.inf if not ms else ms[0] if len(ms) == 1 else ms[0] * ms[1] / (ms[0] + ms[1])


def event_located_run(sc, rtol=1e-12, grid=None):
    """Integrate a scene with scipy's DOP853 (an 8th-order embedded Runge–Kutta pair with
    dense output) and exact event location: every contact onset and separation is a root
    of δ(t) = u_a − u_b − gap, found on the dense output, and the integration restarts
    there, so the Kelvin force jump never sits inside a step. Independent of the library's
    kernels: it is coded here from the scene's definition (docs/scene-format.md: nodes, links,
    contacts, loads), to cross-check them and to give references more digits than a fixed
    step can on scenes with near-grazing impacts.

    Models linear springs, bars, dashpots, penalty contacts with the linear, hertz and
    unclipped Kelvin laws, gravity, ground acceleration and nodal forces given by constant,
    sine, rectangular and half-sine functions; anything else raises Unsupported. Returns a
    dict shaped like the result of martello.batch.execute: status, summary (contacts with
    events and peaks, energy, cost, provenance) and history on `grid`."""
    from scipy.integrate import solve_ivp
    t0_wall = time.perf_counter()
    n = len(sc.nodes)
    if sc.couplings:
        raise Unsupported("consistent-mass couplings")
    if sc.blocks:
        raise Unsupported("stiffness blocks ([[frame]])")
    mass = np.array([nd["mass"] for nd in sc.nodes])
    fixed = np.array([nd["fixed"] for nd in sc.nodes])
    springs, dashpots = [], []
    for lk in sc.links:
        if lk["type"] in ("spring", "bar"):
            springs.append((lk["a"], lk["b"], lk["k"] if lk["type"] == "spring" else lk["EA"] / lk["L"]))
        elif lk["type"] == "dashpot":
            dashpots.append((lk["a"], lk["b"], lk["c"]))
        else:
            raise Unsupported(f"link type {lk['type']!r}")
    contacts, hc = [], []
    hc_laws = {"hunt-crossley": "hunt_crossley", "lankarani-nikravesh": "lankarani_nikravesh",
               "hertzdamp": "lankarani_nikravesh", "flores": "flores", "gonthier": "gonthier"}
    for c in sc.contacts:
        if c["scheme"] != "penalty" or c["law"] not in ("linear", "kelvin", "hertz", *hc_laws) \
                or c["clipped"]:
            raise Unsupported(f"contact {c['name']}: {c['scheme']} {c.get('law')}")
        damp, a_hc = 0.0, None
        if c["law"] == "kelvin":
            damp = c["damping"] if c["damping"] is not None else \
                kelvin_damping(c["stiffness"], _two_mass_mstar(mass, fixed, c["a"], c["b"]),
                               kelvin_xi_from_e(c["restitution"]))
        elif c["law"] in hc_laws:
            # Hunt & Crossley family: F = K δ^n (1 + χ δ̇), χ = a / v_in, never pulling
            a_hc = c["damping"] if c["damping"] is not None else \
                (HC_FACTORS[hc_laws[c["law"]]](c["restitution"]) if c["restitution"] is not None else 0.0)
        expo = 1.0 if c["law"] in ("linear", "kelvin") else \
            (1.5 if c["law"] == "hertzdamp" else (c["exponent"] or LAW_EXPONENT[c["law"]]))
        contacts.append((c["a"], c["b"], c["gap"], c["stiffness"], damp, expo, c["name"]))
        hc.append(a_hc)
    ground, gbreaks = _tf(sc.ground)
    forces = [(f["node"], *_tf(f["function"])) for f in sc.forces]
    breaks = sorted({b for b in gbreaks + [b for f in forces for b in f[2]] if 0 < b < sc.analysis["t_end"]})
    g = sc.gravity
    t_end = sc.analysis["t_end"]
    free = ~fixed

    def uv(y, i):
        return (y[i], y[n + i]) if i >= 0 else (0.0, 0.0)

    def gap_of(y, j):
        a, b, gp = contacts[j][:3]
        return uv(y, a)[0] - uv(y, b)[0] - gp

    vin = [0.0] * len(sc.contacts)        # approach speed at the onset of each open phase

    def forces_at(t, y, active, vin_=None):
        vin_ = vin if vin_ is None else vin_
        u, v = y[:n], y[n:2 * n]
        f = np.zeros(n)
        for a, b, k in springs:
            du = (u[a] if a >= 0 else 0.0) - (u[b] if b >= 0 else 0.0)
            if a >= 0: f[a] -= k * du
            if b >= 0: f[b] += k * du
        for a, b, c in dashpots:
            dv = (v[a] if a >= 0 else 0.0) - (v[b] if b >= 0 else 0.0)
            if a >= 0: f[a] -= c * dv
            if b >= 0: f[b] += c * dv
        pc = np.zeros(len(contacts))
        for j, (a, b, gp, k, c, ex, _) in enumerate(contacts):
            if not active[j]:
                continue
            d = gap_of(y, j)
            dd = uv(y, a)[1] - uv(y, b)[1]
            if hc[j] is not None:
                chi = hc[j] / vin_[j] if vin_[j] > 0 else 0.0
                p = k * max(d, 0.0) ** ex * max(1.0 + chi * dd, 0.0)
            else:
                p = k * max(d, 0.0) ** ex + c * dd
            pc[j] = p
            if a >= 0: f[a] -= p
            if b >= 0: f[b] += p
        fext = (g - ground(t)) * mass
        for node, fn, _ in forces:
            fext[node] += fn(t)
        return f + fext, fext, pc

    def rhs_for(active, vin_):
        def rhs(t, y):
            f, fext, _ = forces_at(t, y, active, vin_)
            acc = np.where(free, f / mass, 0.0)
            vel = np.where(free, y[n:2 * n], 0.0)
            return np.concatenate([vel, acc, [float(np.dot(fext, vel))]])
        return rhs

    y = np.concatenate([[nd["u0"] for nd in sc.nodes], [0.0 if nd["fixed"] else nd["v0"] for nd in sc.nodes], [0.0]])
    active = [gap_of(y, j) > 0 or (gap_of(y, j) == 0 and (uv(y, contacts[j][0])[1] - uv(y, contacts[j][1])[1]) > 0)
              for j in range(len(contacts))]
    scale = max(float(np.max(np.abs(y[:2 * n]))), 1e-3)
    pieces, t, steps, rhs_evals = [], 0.0, 0, 0
    ev_on = {j: [] for j in range(len(contacts))}
    ev_off = {j: [] for j in range(len(contacts))}
    stops = breaks + [t_end]
    for j in range(len(contacts)):
        if active[j]:
            ev_on[j].append((0.0, uv(y, contacts[j][0])[1] - uv(y, contacts[j][1])[1]))
            vin[j] = ev_on[j][-1][1]
    guard = 0
    while t < t_end * (1 - 1e-15):
        guard += 1
        if guard > 1_000_000:
            raise MartelloError("event-located reference: too many events (chattering?)")
        t_stop = next(s for s in stops if s > t * (1 + 1e-15) or s == t_end)

        def make_event(j, act=tuple(active)):
            def ev(tt, yy):
                return gap_of(yy, j)
            ev.terminal = True
            ev.direction = -1.0 if act[j] else 1.0
            return ev

        def make_rate_event(j):
            # a local maximum of the gap (δ̇ from + to −): a sign test of δ at step ends can
            # miss a contact that opens and closes inside one step (docs/problems.md P7), so the
            # gap is also checked at each of its maxima
            def ev(tt, yy):
                a_, b_ = contacts[j][0], contacts[j][1]
                return uv(yy, a_)[1] - uv(yy, b_)[1]
            ev.terminal = False
            ev.direction = -1.0
            return ev
        events = [make_event(j) for j in range(len(contacts))] + \
                 [make_rate_event(j) for j in range(len(contacts))]
        sol = solve_ivp(rhs_for(tuple(active), tuple(vin)), (t, t_stop), y, method="DOP853", rtol=rtol,
                        atol=rtol * 1e-3 * scale, dense_output=True, events=events or None)
        if sol.status < 0:
            return {"status": "MARTELLO_ERR_NOT_CONVERGED", "message": sol.message}
        steps += len(sol.t) - 1
        rhs_evals += sol.nfev
        t_piece_end = float(sol.t[-1])
        missed = None
        nc = len(contacts)
        for j in range(nc):
            if active[j] or not len(sol.t_events):
                continue
            for te in sol.t_events[nc + j]:
                if te >= t_piece_end or gap_of(sol.sol(te), j) <= 0.0:
                    continue
                s_ = np.linspace(t, te, 401)
                gs = np.array([gap_of(sol.sol(x), j) for x in s_])
                k = int(np.argmax(gs > 0.0))
                lo = s_[k - 1] if k > 0 else t
                from scipy.optimize import brentq as _brentq
                tc = _brentq(lambda x: gap_of(sol.sol(x), j), lo, s_[k], xtol=1e-300, rtol=4 * np.finfo(float).eps)
                if missed is None or tc < missed[0]:
                    missed = (tc, j)
                break
        if missed is not None:
            tc, j = missed
            pieces.append((t, tc, sol.sol, tuple(active), tuple(vin)))
            y = sol.sol(tc).copy()
            t = float(tc)
            ev_on[j].append((t, uv(y, contacts[j][0])[1] - uv(y, contacts[j][1])[1]))
            vin[j] = ev_on[j][-1][1]
            active[j] = True
            continue
        pieces.append((t, t_piece_end, sol.sol, tuple(active), tuple(vin)))
        y = sol.y[:, -1].copy()
        t = t_piece_end
        if sol.status == 1:
            # events found by solve_ivp: those at the earliest time flip the active set
            for j in range(nc):
                te = sol.t_events[j]
                if len(te) and abs(te[0] - t) <= 1e-14 * max(t, 1.0):
                    rate = uv(y, contacts[j][0])[1] - uv(y, contacts[j][1])[1]
                    if active[j]:
                        ev_off[j].append((t, rate))
                    else:
                        ev_on[j].append((t, rate))
                        vin[j] = rate
                    active[j] = not active[j]
    # --- sample the history and the per-phase maxima on the dense output --------------------
    grid = np.linspace(0.0, t_end, 2001) if grid is None else np.asarray(grid, float)
    starts = np.array([p[0] for p in pieces])

    def state(tt):
        k = int(np.clip(np.searchsorted(starts, tt, side="right") - 1, 0, len(pieces) - 1))
        return pieces[k][2](tt), pieces[k][3], pieces[k][4]
    names = [nd["name"] for nd in sc.nodes]
    cols = (["t"] + [f"u:{x}" for x in names] + [f"v:{x}" for x in names] + [f"a:{x}" for x in names]
            + [f"penetration:{c[6]}" for c in contacts] + [f"force:{c[6]}" for c in contacts]
            + ["energy:kinetic", "energy:recoverable", "energy:input", "energy:initial"])

    def energies(yy, act):
        u, v = yy[:n], yy[n:2 * n]
        kin = 0.5 * float(np.sum(mass * np.where(free, v, 0.0) ** 2))
        rec = 0.0
        for a, b, k in springs:
            du = (u[a] if a >= 0 else 0.0) - (u[b] if b >= 0 else 0.0)
            rec += 0.5 * k * du * du
        for j, (a, b, gp, k, c, ex, _) in enumerate(contacts):
            d = max(gap_of(yy, j), 0.0)
            rec += k * d ** (ex + 1) / (ex + 1)
        return kin, rec
    y0 = pieces[0][2](0.0)
    e0 = sum(energies(y0, pieces[0][3]))
    rows = []
    for tt in grid:
        yy, act, vv = state(tt)
        f, fext, pc = forces_at(tt, yy, act, vv)
        acc = np.where(free, f / mass, 0.0)
        kin, rec = energies(yy, act)
        rows.append([tt, *yy[:n], *yy[n:2 * n], *acc, *[gap_of(yy, j) for j in range(len(contacts))],
                     *pc, kin, rec, yy[2 * n], e0])
    data = np.array(rows)
    # events and per-phase maxima (penetration at δ̇ = 0, force by sampling the phase densely)
    from scipy.optimize import brentq
    summ_contacts = {}
    for j, (a, b, gp, k, c, ex, name) in enumerate(contacts):
        on, off = ev_on[j], ev_off[j]
        t_on = [x[0] for x in on]
        t_off = [off[i][0] if i < len(off) else None for i in range(len(on))]
        v_in = [x[1] for x in on]
        v_out = [off[i][1] for i in range(min(len(on), len(off)))]
        pmax, fmax = [], []
        for i, ta in enumerate(t_on):
            tb = t_off[i] if t_off[i] is not None else t_end
            s = np.linspace(ta, tb, 2001)
            dvals = np.array([gap_of(state(x)[0], j) for x in s])
            fvals = np.array([forces_at(x, *state(x))[2][j] for x in s])  # state: y, active, v_in
            kk = int(np.argmax(dvals))
            best = dvals[kk]
            if 0 < kk < len(s) - 1:
                rate = lambda x: uv(state(x)[0], a)[1] - uv(state(x)[0], b)[1]
                try:
                    tm = brentq(rate, s[kk - 1], s[kk + 1], xtol=1e-300, rtol=4 * np.finfo(float).eps)
                    best = max(best, gap_of(state(tm)[0], j))
                except ValueError:
                    pass
            pmax.append(float(best))
            fmax.append(float(np.max(fvals)))
        rest = [(-v_out[i] / v_in[i]) if (i < len(v_out) and v_in[i] > 0) else None for i in range(len(on))]
        summ_contacts[name] = {"impact_times": t_on, "separation_times": t_off, "approach_speeds": v_in,
                               "separation_speeds": v_out, "restitution": rest,
                               "phase_max_penetration": pmax, "phase_max_force": fmax,
                               "max_penetration": max(pmax, default=0.0), "max_force": max(fmax, default=0.0),
                               "impacts": len(t_on)}
    wall = time.perf_counter() - t0_wall
    summary = {"status": "MARTELLO_OK", "message": "", "t_reached": t_end, "contacts": summ_contacts,
               "energy": {}, "nodes": {},
               "cost": {"steps": steps, "residual_evaluations": rhs_evals, "wall_time_s": wall,
                        "events": sum(len(v) for v in ev_on.values()) + sum(len(v) for v in ev_off.values())},
               "provenance": {"engine": "scipy.integrate.solve_ivp DOP853 with event location",
                              "rtol": rtol, "scipy_version": __import__("scipy").__version__,
                              "martello_version": native.version(),
                              "libraries": native.library_versions()}}
    return {"status": "MARTELLO_OK", "message": "", "summary": summary, "history": (cols, data)}
