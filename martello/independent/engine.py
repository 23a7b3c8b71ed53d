"""The independent engine's hybrid integration: smooth pieces on scipy's DOP853 or Radau,
every switch located as a root on the dense output and the integration restarted there
(docs/independent-reference.md).

The switches (each a scalar g(y) whose sign change ends a regime):
  * contact onset δ = 0 (δ̇ > 0) and separation δ = 0 (δ̇ < 0); the branch switches of the
    clipped and Jankowski laws (laws.py); a restitution contact's impact (a velocity jump);
  * bilinear links, an elastic spring ρk in parallel with an elastic–perfectly-plastic one
    ((1 − ρ)k, yield (1 − ρ)F_y): yield when k(du − u_p) = ±F_y, unloading when du̇ = 0;
  * fluid dampers: |du̇| = v_reg, where the secant law meets the power law;
  * the instants where a load's time function is not smooth.
A contact or a yield that opens and closes inside one solver step changes no sign at the step
ends; every extremum of the watched quantity is therefore located too (non-terminal events)
and a threshold passed there is found by bisection (docs/problems.md P7 "Grazing contacts")."""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from .scene import GROUND, Model, Unsupported

EPS = np.finfo(float).eps
# an event within this fraction of its own magnitude of zero is at the switch (it is the
# round-off of the located root, not a physical threshold)
AT_SWITCH = 1e-11


@dataclass
class Modes:
    """The discrete state between two switches."""
    active: list
    branch: list
    v_in: list
    up: np.ndarray          # plastic offset of each bilinear's EPP spring
    reg: np.ndarray         # 0 elastic, +1 / −1 yielding in tension / compression
    dreg: np.ndarray        # fluid dampers: 0 secant, +1 / −1 power law

    def copy(self):
        return Modes(list(self.active), list(self.branch), list(self.v_in), self.up.copy(),
                     self.reg.copy(), self.dreg.copy())


@dataclass
class Switch:
    kind: str
    index: int
    g: object               # g(y) -> (value, magnitude)
    gdot: object            # gdot(y, acc) -> rate
    direction: float
    apply: object           # apply(t, y, modes) -> y (velocity jumps)


@dataclass
class Run:
    """One integration: its pieces (dense outputs with their modes) and its events."""
    model: Model
    method: str
    rtol: float
    pieces: list = field(default_factory=list)        # (t0, t1, sol, step_times, modes)
    events: list = field(default_factory=list)        # dicts
    phases: list = field(default_factory=list)        # per contact: list of phase dicts
    impact_energy: list = field(default_factory=list)  # (t, cumulative J)
    steps: int = 0
    rhs_evals: int = 0
    wall: float = 0.0


class System:
    """The equations of motion of a Model in modes (docs/problems.md P7 eq. 7):
    y = [u, v, W_input, D_damping, D_contact, D_plastic]."""

    def __init__(self, m: Model):
        self.m = m
        n = self.n = len(m.names)
        self.free = ~m.fixed
        self.minv = np.where(self.free, 1.0 / m.mass, 0.0)

        def idx(lst, i):
            return np.array([x[i] if x[i] != GROUND else n for x in lst], dtype=int)
        self.sa, self.sb = idx(m.springs, 1), idx(m.springs, 2)
        self.sk = np.array([x[3] for x in m.springs])
        self.da, self.db = idx(m.dashpots, 1), idx(m.dashpots, 2)
        self.dc = np.array([x[3] for x in m.dashpots])
        self.ba, self.bb = idx(m.bilinears, 1), idx(m.bilinears, 2)
        self.bk = np.array([x[3] for x in m.bilinears])
        self.bfy = np.array([x[4] for x in m.bilinears])
        self.brho = np.array([x[5] for x in m.bilinears])
        # each fluid damper's row (a node pair: e_a − e_b; between plan points of rigid floors
        # its terms, docs/buildings.md): du̇ = D v, its force F acts on the nodes as −Dᵀ F
        self.fD = np.zeros((len(m.dampers), n + 1))
        for k, terms in enumerate(m.damper_rows):
            for i, c in terms:
                if i != GROUND:
                    self.fD[k, i] += c
        self.fc = np.array([x[3] for x in m.dampers])
        self.falpha = np.array([x[4] for x in m.dampers])
        self.fvreg = np.array([x[5] for x in m.dampers])
        self.fsec = np.where(self.fvreg > 0, self.fc * np.where(self.fvreg > 0, self.fvreg, 1.0)
                             ** (self.falpha - 1.0), 0.0)
        self.blocks = [(ix, K, C) for _, ix, K, C in m.blocks]
        # each contact's row (docs/buildings.md): its nodes (the ground as n, where the
        # extended vectors hold 0) and coefficients; δ = Σ c x(node) − gap
        self.cn = [np.array([i if i != GROUND else n for i, _ in c.terms], dtype=int) for c in m.contacts]
        self.cc = [np.array([cf for _, cf in c.terms]) for c in m.contacts]
        self.nfev = 0
        # the largest speed met so far: the scale of the round-off of a velocity switch
        # (a velocity is 0 at its own switch, so its current size says nothing)
        self.vscale = float(np.max(np.abs(m.v0))) if n else 0.0
        # likewise the largest displacement met so far: a gap of 0 between two bodies at 0
        # (a barrier touched at rest, docs/problems.md P9) gives its own g no size at the root
        self.uscale = max([float(np.max(np.abs(m.u0))) if n else 0.0] + [abs(c.gap) for c in m.contacts])

    # --- elements ----------------------------------------------------------------------
    def ext(self, y):
        n = self.n
        return np.append(y[:n], 0.0), np.append(y[n:2 * n], 0.0)

    def bilinear_force(self, du, modes):
        """F = ρk du + F_p, F_p the EPP spring's force (docs/problems.md P6)."""
        fp = np.where(modes.reg == 0, (1.0 - self.brho) * self.bk * (du - modes.up),
                      modes.reg * (1.0 - self.brho) * self.bfy)
        return self.brho * self.bk * du + fp, fp

    def damper_force(self, dv, modes):
        """F = c sign(dv)|dv|^α, the secant c v_reg^(α−1) dv below v_reg
        (docs/scene-input.md "[[link]]")."""
        return np.where(modes.dreg == 0, self.fsec * dv, modes.dreg * self.fc * np.abs(dv) ** self.falpha)

    def row(self, xE, j):
        """Σ c x(node) over contact j's row (xE extended: the ground at n)."""
        return float(xE[self.cn[j]] @ self.cc[j])

    def row_size(self, xE, j):
        """Σ |c x(node)|: the magnitude row() is computed from."""
        return float(np.abs(xE[self.cn[j]] * self.cc[j]).sum())

    def contact_state(self, uE, vE, j):
        c = self.m.contacts[j]
        return self.row(uE, j) - c.gap, self.row(vE, j)

    def contact_force(self, uE, vE, j, modes):
        if not modes.active[j] or self.m.contacts[j].scheme != "penalty":
            return 0.0
        d, dd = self.contact_state(uE, vE, j)
        return self.m.contacts[j].force(d, dd, modes.v_in[j], modes.branch[j])

    def external(self, t):
        m = self.m
        f = m.mass * (m.gravity - m.ground(t))
        if m.influence is not None:          # a building's floors: (cos α, sin α, 0) of the motion
            f = f * m.influence
        for i, fn in m.forces:
            f[i] += fn(t)
        return np.where(self.free, f, 0.0)

    def rhs(self, t, y, modes):
        self.nfev += 1
        n = self.n
        uE, vE = self.ext(y)
        f = np.zeros(n + 1)
        fs = self.sk * (uE[self.sa] - uE[self.sb])
        dvd = vE[self.da] - vE[self.db]
        fd = self.dc * dvd
        dub = uE[self.ba] - uE[self.bb]
        dvb = vE[self.ba] - vE[self.bb]
        fb, fp = self.bilinear_force(dub, modes)
        dvf = self.fD @ vE
        ff = self.damper_force(dvf, modes)
        for a, b, w in ((self.sa, self.sb, fs), (self.da, self.db, fd), (self.ba, self.bb, fb)):
            if len(w):
                f -= np.bincount(a, w, n + 1)
                f += np.bincount(b, w, n + 1)
        if len(ff):
            f -= self.fD.T @ ff
        dblock = 0.0
        for ix, K, C in self.blocks:          # [[frame]]: f = K u + C v on its nodes
            fc = C @ vE[ix]
            f[ix] -= K @ uE[ix] + fc
            dblock += float(fc @ vE[ix])
        dcon = 0.0
        for j, c in enumerate(self.m.contacts):
            if modes.active[j] and c.scheme == "penalty":
                p = self.contact_force(uE, vE, j, modes)
                d, dd = self.contact_state(uE, vE, j)
                np.subtract.at(f, self.cn[j], self.cc[j] * p)
                dcon += (p - c.elastic(d)) * dd
        fext = self.external(t)
        v = y[n:2 * n]
        acc = (f[:n] + fext) * self.minv
        plast = float(np.sum(np.where(modes.reg != 0, fp * dvb, 0.0)))
        return np.concatenate([np.where(self.free, v, 0.0), acc,
                               [float(fext @ v), float(fd @ dvd + ff @ dvf) + dblock, dcon, plast]])

    def recoverable(self, y, modes):
        uE, _ = self.ext(y)
        e = 0.5 * float(np.sum(self.sk * (uE[self.sa] - uE[self.sb]) ** 2))
        for ix, K, _ in self.blocks:
            e += 0.5 * float(uE[ix] @ K @ uE[ix])
        dub = uE[self.ba] - uE[self.bb]
        _, fp = self.bilinear_force(dub, modes)
        e += float(np.sum(0.5 * self.brho * self.bk * dub ** 2 + fp ** 2 / (2.0 * (1.0 - self.brho) * self.bk)))
        for j, c in enumerate(self.m.contacts):
            if c.scheme == "penalty" and modes.active[j]:
                e += c.energy(self.contact_state(uE, uE, j)[0])
        return e

    def kinetic(self, y):
        n = self.n
        return 0.5 * float(np.sum(self.m.mass * np.where(self.free, y[n:2 * n], 0.0) ** 2))

    # --- the switches of the current modes ---------------------------------------------
    def switches(self, modes) -> list:
        out = []
        for j, c in enumerate(self.m.contacts):
            out.extend(self._contact_switches(j, c, modes))
        for i in range(len(self.bk)):
            out.extend(self._bilinear_switches(i, modes))
        for i in range(len(self.fc)):
            out.extend(self._damper_switches(i, modes))
        return out

    def _contact_switches(self, j, c, modes):
        sysm = self

        def g(y):
            uE, _ = sysm.ext(y)
            d = sysm.row(uE, j) - c.gap
            return d, sysm.row_size(uE, j) + abs(c.gap) + sysm.uscale

        def gdot(y, acc):
            _, vE = sysm.ext(y)
            return sysm.row(vE, j)

        if not modes.active[j]:
            # the onset and separation actions need the run's state: integrate() binds them
            return [Switch("onset", j, g, gdot, 1.0, None)]
        out = [Switch("separation", j, g, gdot, -1.0, None)]
        sw = c.branch_switch(0.0, 0.0, modes.v_in[j], modes.branch[j])
        if sw is not None:
            _, direction, target = sw

            def gb(y, j=j):
                uE, vE = sysm.ext(y)
                d, dd = sysm.contact_state(uE, vE, j)
                val = c.branch_switch(d, dd, modes.v_in[j], modes.branch[j])[0]
                if c.law == "kelvin":
                    return val, abs(c.K * d) + abs(c.c * dd)
                if c.law == "jankowski":
                    return val, sysm.row_size(vE, j) + sysm.vscale
                return val, 1.0 + abs(val - 1.0)

            def gbdot(y, acc, j=j):
                uE, vE = sysm.ext(y)
                aE = np.append(acc, 0.0)
                d, dd = sysm.contact_state(uE, vE, j)
                ddd = sysm.row(aE, j)
                if c.law == "kelvin":
                    return c.K * dd + c.c * ddd
                if c.law == "jankowski":
                    return ddd
                return (c.c / modes.v_in[j] if modes.v_in[j] > 0 else 0.0) * ddd

            def apply(t, y, md, target=target, j=j):
                md.branch[j] = target
                return y
            out.append(Switch(f"branch:{target}", j, gb, gbdot, direction, apply))
        return out

    def _bilinear_switches(self, i, modes):
        sysm = self
        k, fy = self.bk[i], self.bfy[i]

        def du_dv(y):
            uE, vE = sysm.ext(y)
            return uE[sysm.ba[i]] - uE[sysm.bb[i]], vE[sysm.ba[i]] - vE[sysm.bb[i]]

        def dacc(acc):
            aE = np.append(acc, 0.0)
            return aE[sysm.ba[i]] - aE[sysm.bb[i]]
        if modes.reg[i] == 0:
            out = []
            for s in (1.0, -1.0):
                def g(y, s=s):
                    du, _ = du_dv(y)
                    return s * k * (du - modes.up[i]) - fy, k * (abs(du) + abs(modes.up[i])) + fy

                def gdot(y, acc, s=s):
                    return s * k * du_dv(y)[1]

                def apply(t, y, md, s=s):
                    md.reg[i] = int(s)
                    return y
                out.append(Switch("yield+" if s > 0 else "yield-", i, g, gdot, 1.0, apply))
            return out
        r = float(modes.reg[i])

        def g(y):
            _, dv = du_dv(y)
            uE, vE = sysm.ext(y)
            return dv, abs(vE[sysm.ba[i]]) + abs(vE[sysm.bb[i]]) + sysm.vscale

        def gdot(y, acc):
            return dacc(acc)

        def apply(t, y, md):
            du, _ = du_dv(y)
            md.up[i] = du - md.reg[i] * fy / k
            md.reg[i] = 0
            return y
        return [Switch("unload", i, g, gdot, -r, apply)]

    def _damper_switches(self, i, modes):
        sysm = self
        vreg = self.fvreg[i]

        def dv_of(y):
            _, vE = sysm.ext(y)
            return float(sysm.fD[i] @ vE), float(np.abs(sysm.fD[i] * vE).sum()) + vreg + sysm.vscale

        def gdot(y, acc):
            aE = np.append(acc, 0.0)
            return float(sysm.fD[i] @ aE)

        def make(level, direction, target):
            def g(y):
                dv, mag = dv_of(y)
                return dv - level, mag

            def apply(t, y, md):
                md.dreg[i] = target
                return y
            return Switch(f"damper:{target:+d}", i, g, gdot, direction, apply)
        r = modes.dreg[i]
        if r == 0:
            return [make(vreg, 1.0, 1), make(-vreg, -1.0, -1)]
        if vreg == 0.0:
            return [make(0.0, -r, -r)]
        return [make(r * vreg, -r, 0)]

    def watches(self, modes):
        """Non-terminal events at the extrema of the quantities whose threshold a step could
        pass and come back from: the gap of an open contact, the elongation of an elastic
        bilinear."""
        out = []
        for j in range(len(self.m.contacts)):
            if not modes.active[j]:
                out.append(("contact", j))
        for i in range(len(self.bk)):
            if modes.reg[i] == 0:
                out.append(("bilinear", i))
        return out


def initial_modes(sysm: System, y0) -> Modes:
    m = sysm.m
    nc = len(m.contacts)
    modes = Modes([False] * nc, ["push"] * nc, [0.0] * nc, np.zeros(len(sysm.bk)),
                  np.zeros(len(sysm.bk), dtype=int), np.zeros(len(sysm.fc), dtype=int))
    uE, vE = sysm.ext(y0)
    dub = uE[sysm.ba] - uE[sysm.bb]
    if np.any(sysm.bk * np.abs(dub) > sysm.bfy):
        raise Unsupported("a bilinear link starts beyond yield")
    dvf = sysm.fD @ vE
    modes.dreg[:] = np.where(dvf >= sysm.fvreg, 1, np.where(dvf <= -sysm.fvreg, -1, 0)) if len(dvf) else []
    for i in range(len(dvf)):
        if sysm.fvreg[i] == 0.0:
            modes.dreg[i] = 1 if dvf[i] >= 0 else -1
    for j, c in enumerate(m.contacts):
        d, dd = sysm.contact_state(uE, vE, j)
        if c.scheme == "penalty" and (d > 0 or (d == 0 and dd > 0)):
            modes.active[j] = True
            modes.v_in[j] = dd
            modes.branch[j] = c.first_branch(dd)
    return modes


def integrate(m: Model, method: str = "DOP853", rtol: float = 1e-11, atol_scale: float | None = None,
              max_events: int = 2_000_000) -> Run:
    """Integrate the model from 0 to t_end; return the pieces and the located events."""
    t_wall = time.perf_counter()
    sysm = System(m)
    n = sysm.n
    run = Run(m, method, rtol)
    run.phases = [[] for _ in m.contacts]
    y = np.concatenate([m.u0, m.v0, [0.0, 0.0, 0.0, 0.0]])
    modes = initial_modes(sysm, y)
    for j, c in enumerate(m.contacts):
        if modes.active[j]:
            uE, vE = sysm.ext(y)
            run.phases[j].append({"t_on": 0.0, "v_in": float(sysm.contact_state(uE, vE, j)[1])})
    impact = [0.0]

    def onset(t, y, md, j):
        c = m.contacts[j]
        uE, vE = sysm.ext(y)
        _, dd = sysm.contact_state(uE, vE, j)
        if c.scheme == "restitution":
            # Newton's law (docs/problems.md P5): the impulse (1 + e) m* δ̇ on both sides
            if c.e == 0.0:
                raise Unsupported(f"contact {c.name}: a plastic impact sticks (persistent contact)")
            if dd <= 0.0:
                return y                  # at the root but already opening: no impulse
            if dd <= AT_SWITCH * sysm.vscale:
                # the impacts accumulate (Zeno): the motion continues as a persistent
                # contact, which this engine does not model
                raise Unsupported(f"contact {c.name}: impacts accumulate at t = {t:.9g} s (Zeno); "
                                  "persistent contact is not modelled")
            p = (1.0 + c.e) * c.mstar * dd
            y = y.copy()
            for i, cf in c.terms:         # Δv = −M⁻¹ gᵀ p on the free nodes
                if i != GROUND and sysm.free[i]:
                    y[n + i] -= cf * p / m.mass[i]
            impact[0] += 0.5 * (1.0 - c.e ** 2) * c.mstar * dd * dd
            run.impact_energy.append((t, impact[0]))
            run.phases[j].append({"t_on": t, "v_in": dd, "t_off": t, "v_out": -c.e * dd, "impulse": p})
            return y
        md.active[j] = True
        md.v_in[j] = dd
        md.branch[j] = c.first_branch(dd)
        run.phases[j].append({"t_on": t, "v_in": dd})
        return y

    def separation(t, y, md, j):
        uE, vE = sysm.ext(y)
        _, dd = sysm.contact_state(uE, vE, j)
        md.active[j] = False
        ph = run.phases[j][-1]
        ph["t_off"], ph["v_out"] = t, dd
        return y

    def bound(sw):
        if sw.kind == "onset":
            sw.apply = lambda t, y, md, j=sw.index: onset(t, y, md, j)
        elif sw.kind == "separation":
            sw.apply = lambda t, y, md, j=sw.index: separation(t, y, md, j)
        return sw

    def switches(md):
        return [bound(s) for s in sysm.switches(md)]

    def settle(t, y, md, forced):
        """Apply the located switch, then every other switch the state sits on (equal roots:
        parallel contacts close together) or has passed, until the modes are consistent."""
        done = set()
        for _ in range(64):
            acc = sysm.rhs(t, y, md)[n:2 * n]
            chosen = forced
            forced = None
            if chosen is None:
                for s in switches(md):
                    gv, mag = s.g(y)
                    tol = AT_SWITCH * mag + 1e-300
                    # at a root (|g| within round-off) the rate decides, but never for an
                    # element switched at this instant already: its reverse switch sits at
                    # the same root (a turning point), and only a clear crossing counts
                    at_root = abs(gv) <= tol and s.gdot(y, acc) * s.direction > 0 and \
                        _element(m, s) not in done
                    crossed = gv * s.direction > tol
                    if crossed and s.kind == "onset" and m.contacts[s.index].scheme == "restitution":
                        # an impact needs an approach: a slightly penetrated pair that is
                        # already opening (just after its impulse) is left to open
                        crossed = s.gdot(y, acc) > 0.0
                    if crossed or at_root:
                        chosen = s
                        break
            if chosen is None:
                return y
            done.add(_element(m, chosen))
            run.events.append({"t": float(t), "kind": chosen.kind, "element": _element(m, chosen)})
            y = chosen.apply(t, y, md)
        raise RuntimeError(f"independent engine: switches do not settle at t = {t}")

    y = settle(0.0, y, modes, None)
    scale_u = max(float(np.max(np.abs(m.u0))) if n else 0.0, *(abs(c.gap) for c in m.contacts), 1e-3)
    scale_v = max(float(np.max(np.abs(m.v0))) if n else 0.0, 1e-3)
    atol_u = rtol * (atol_scale or 1e-3) * scale_u
    atol = np.concatenate([np.full(n, atol_u), np.full(n, rtol * (atol_scale or 1e-3) * scale_v),
                           np.full(4, np.inf)])
    stops = m.breaks + [m.t_end]
    t = 0.0
    while t < m.t_end:
        t_stop = next(s for s in stops if s > t)
        sws = switches(modes)
        evs, offs = [], []
        for s in sws:
            # a switch that starts at its own root (the reverse of the one just applied, or
            # a turning point) is armed past the round-off of g: its sign there is noise
            g0, mag0 = s.g(y)
            off = s.direction * AT_SWITCH * mag0 if abs(g0) <= AT_SWITCH * mag0 else 0.0
            offs.append(off)

            def ev(tt, yy, s=s, off=off):
                return s.g(yy)[0] - off
            ev.terminal = True
            ev.direction = s.direction
            evs.append(ev)
        watch = sysm.watches(modes)
        for kind, i in watch:
            def wv(tt, yy, kind=kind, i=i):
                _, vE = sysm.ext(yy)
                if kind == "contact":
                    return sysm.row(vE, i)
                return vE[sysm.ba[i]] - vE[sysm.bb[i]]
            wv.terminal = False
            wv.direction = 0.0
            evs.append(wv)
        md = modes.copy()
        sol = solve_ivp(lambda tt, yy: sysm.rhs(tt, yy, md), (t, t_stop), y, method=method, rtol=rtol,
                        atol=atol, dense_output=True, events=evs or None)
        if sol.status < 0:
            raise RuntimeError(f"independent engine: {method} failed at t = {sol.t[-1]}: {sol.message}")
        run.steps += len(sol.t) - 1
        sysm.vscale = max(sysm.vscale, float(np.max(np.abs(sol.y[n:2 * n]))))
        sysm.uscale = max(sysm.uscale, float(np.max(np.abs(sol.y[:n]))))
        t_end_piece = float(sol.t[-1])
        forced = None
        if sol.status == 1:
            for k, s in enumerate(sws):
                if len(sol.t_events[k]) and sol.t_events[k][-1] == t_end_piece:
                    forced = s
                    if offs[k] != 0.0:
                        t_end_piece = _unbiased_root(s, sol, t, t_end_piece)
                    break
        # a threshold passed between two steps and back: find it at the watched extrema
        missed = _missed_threshold(switches, sol, watch, len(sws), md, t, t_end_piece)
        if missed is not None:
            t_end_piece, forced = missed
        run.pieces.append((t, t_end_piece, sol.sol, sol.t[sol.t <= t_end_piece], md))
        y = sol.sol(t_end_piece) if t_end_piece < sol.t[-1] else sol.y[:, -1]
        y = np.array(y, dtype=float)
        t = t_end_piece
        y = settle(t, y, modes, forced)
        if len(run.events) > max_events:
            raise RuntimeError("independent engine: too many switches (chattering)")
    run.rhs_evals = sysm.nfev
    run.wall = time.perf_counter() - t_wall
    run.system = sysm
    run.impact_total = impact[0]
    return run


def _unbiased_root(s, sol, t0, t1):
    """The root g = 0 of a switch armed past its round-off band (located at g = ±band at t1):
    the band is a guard against the noise of g at the piece's start, not a shift of the
    switch, which would bias it by band/|ġ| (a separation of P9's Kelvin barrier 8e-12 s
    late, 1e-9 in e). Brent on the dense output from the last time before t1 on the branch's
    side; t1 if there is none (a root within the band of the start)."""
    def g(x):
        return s.g(sol.sol(x))[0]
    if g(t1) * s.direction <= 0.0:
        return t1                 # a band below the noise of g: t1 is the root to round-off
    for lo in sol.t[::-1]:
        if lo < t1 and g(lo) * s.direction < 0.0:
            return brentq(g, lo, t1, xtol=4 * EPS * max(abs(t1), 1e-300), rtol=4 * EPS)
    if t0 < t1 and g(t0) * s.direction < 0.0:
        return brentq(g, t0, t1, xtol=4 * EPS * max(abs(t1), 1e-300), rtol=4 * EPS)
    return t1


def _element(m, sw):
    if sw.kind in ("onset", "separation") or sw.kind.startswith("branch"):
        return m.contacts[sw.index].name
    if sw.kind.startswith(("yield", "unload")):
        return m.bilinears[sw.index][0]
    return m.dampers[sw.index][0]


def _missed_threshold(switches, sol, watch, offset, md, t0, t1):
    """The earliest threshold (contact gap 0, yield) passed at a watched extremum inside the
    piece but not at the step ends: (its time, its switch), or None."""
    best = None
    for w, (kind, i) in enumerate(watch):
        for te in sol.t_events[offset + w]:
            if te >= t1:
                continue
            sws = [s for s in switches(md)
                   if s.index == i and ((kind == "contact" and s.kind == "onset") or
                                        (kind == "bilinear" and s.kind.startswith("yield")))]
            for s in sws:
                gv, mag = s.g(sol.sol(te))
                if gv <= AT_SWITCH * mag:
                    continue
                left = sol.t[sol.t < te]
                lo = float(left[-1]) if len(left) else t0
                if s.g(sol.sol(lo))[0] > 0:
                    continue
                tc = brentq(lambda x: s.g(sol.sol(x))[0], lo, te, xtol=4 * EPS * max(abs(te), 1e-300),
                            rtol=4 * EPS)
                if best is None or tc < best[0]:
                    best = (tc, s)
    return best
