"""An independent event-located reference for hysteretic pounding scenes (scipy only).

Written apart from martello's kernels and adapters (it shares no code with them): node masses
on bilinear springs with kinematic hardening to the ground (docs/problems.md P6) and optional
dashpots, penalty contacts between nodes (linear, or Kelvin with its tension cut-off,
docs/problems.md P5), a sine ground acceleration. Every switching surface is a terminal
event of scipy's DOP853 (yield, unloading, contact onset and separation, the Kelvin cut-off);
between them the right-hand side is smooth and the integration restarts from the located
state with the new branch. Extrema (node u max/min, peak penetration and contact force) are
located by scipy's root finder on the 7th-order dense output, at rtol 1e-13.

Trusted digits: the run is repeated at rtol 1e-12 (measured difference on the scenes of this
folder, printed by ``python reference.py``): about 1e-11 relative on every quantity, so errors
of the code under test above ~1e-10 are measurable against it.
"""
import math
import sys

import numpy as np
from scipy.integrate import solve_ivp

try:
    import tomllib
except ImportError:  # pragma: no cover
    import tomli as tomllib

ELASTIC, UPPER, LOWER = 0, 1, 2
OPEN, ON, CUT = 0, 1, 2


class Scene:
    """The scene's data read straight from its TOML file, or from the dict of its tables (no
    martello code)."""

    def __init__(self, path):
        if isinstance(path, dict):
            d = path
        else:
            with open(path, "rb") as fh:
                d = tomllib.load(fh)
        self.names = [n["name"] for n in d["node"]]
        idx = {n: i for i, n in enumerate(self.names)}
        self.m = np.array([n["mass"] for n in d["node"]], float)
        self.u0 = np.array([n.get("u0", 0.0) for n in d["node"]], float)
        self.v0 = np.array([n.get("v0", 0.0) for n in d["node"]], float)
        self.springs, self.dashpots = [], []
        for ln in d.get("link", []):
            assert ln["b"] == "ground", "reference: links to the ground only"
            if ln["type"] == "bilinear":
                self.springs.append((idx[ln["a"]], ln["k"], ln["fy"], ln.get("hardening", 0.0)))
            elif ln["type"] == "dashpot":
                self.dashpots.append((idx[ln["a"]], ln["c"]))
            else:
                raise ValueError("reference: link type %s" % ln["type"])
        self.contacts = []
        for c in d.get("contact", []):
            law = c.get("law", "linear")
            k = c["stiffness"]
            damp = c.get("damping", 0.0)
            if law == "kelvin" and "restitution" in c:
                damp = kelvin_damping(c["restitution"], k, self.m, idx[c["a"]], idx[c["b"]])
            self.contacts.append((idx[c["a"]], idx[c["b"]], c["gap"], k, damp,
                                  law == "kelvin" and c.get("clipped", False)))
        g = d["loads"]["ground_acceleration"]
        assert g["type"] == "sine" and g.get("t_start", 0.0) == 0.0
        self.amp, self.omega, self.phase = g["amplitude"], g["omega"], g.get("phase", 0.0)
        self.t_end = d["analysis"]["t_end"]


def kelvin_damping(e, k, m, a, b):
    """Anagnostopoulos (1988): c = 2 zeta sqrt(k m*), zeta = -ln e / sqrt(pi^2 + ln^2 e)."""
    mstar = m[a] * m[b] / (m[a] + m[b])
    le = math.log(e)
    return 2.0 * (-le / math.sqrt(math.pi ** 2 + le ** 2)) * math.sqrt(k * mstar)


def solve(path, rtol=1e-13, atol=1e-16):
    sc = Scene(path)
    n, ns, nc = len(sc.m), len(sc.springs), len(sc.contacts)
    br = [ELASTIC] * ns
    fc = [k * sc.u0[i] for (i, k, fy, rho) in sc.springs]     # committed force and elongation
    uc = [sc.u0[i] for (i, k, fy, rho) in sc.springs]
    cm = [OPEN] * nc
    y = np.concatenate([sc.u0, sc.v0])
    t = 0.0
    ext = {"u_max": sc.u0.copy(), "u_min": sc.u0.copy(), "pen": np.zeros(nc),
           "force": np.zeros(nc), "impacts": np.zeros(nc, int)}

    def spring_force(s, u):
        i, k, fy, rho = sc.springs[s]
        r = (1 - rho) * fy
        if br[s] == ELASTIC:
            return fc[s] + k * (u[i] - uc[s])
        return rho * k * u[i] + (r if br[s] == UPPER else -r)

    def contact_force(c, u, v):
        a, b, gap, k, damp, clip = sc.contacts[c]
        if cm[c] != ON:
            return 0.0
        return k * (u[a] - u[b] - gap) + damp * (v[a] - v[b])

    def rhs(tt, yy):
        u, v = yy[:n], yy[n:]
        f = -sc.m * sc.amp * math.sin(sc.omega * tt + sc.phase)
        for s in range(ns):
            f[sc.springs[s][0]] -= spring_force(s, u)
        for i, c in sc.dashpots:
            f[i] -= c * v[i]
        for c in range(nc):
            a, b = sc.contacts[c][:2]
            fcn = contact_force(c, u, v)
            f[a] -= fcn
            f[b] += fcn
        return np.concatenate([v, f / sc.m])

    def switches():
        """(function, direction) of every terminal event of the current modes."""
        ev = []
        for s in range(ns):
            i, k, fy, rho = sc.springs[s]
            r = (1 - rho) * fy
            if br[s] == ELASTIC:
                ev.append((lambda tt, yy, s=s, i=i, k=k, rho=rho, r=r:
                           spring_force(s, yy[:n]) - rho * k * yy[i] - r, 1))
                ev.append((lambda tt, yy, s=s, i=i, k=k, rho=rho, r=r:
                           -(spring_force(s, yy[:n]) - rho * k * yy[i]) - r, 1))
            else:
                sgn = -1 if br[s] == UPPER else 1
                ev.append((lambda tt, yy, i=i: yy[n + i], sgn))
        for c in range(nc):
            a, b, gap, k, damp, clip = sc.contacts[c]
            pen = lambda tt, yy, a=a, b=b, gap=gap: yy[a] - yy[b] - gap
            if cm[c] == OPEN:
                ev.append((pen, 1))
            else:
                ev.append((pen, -1))
                if clip:
                    kel = lambda tt, yy, a=a, b=b, gap=gap, k=k, damp=damp: \
                        k * (yy[a] - yy[b] - gap) + damp * (yy[n + a] - yy[n + b])
                    ev.append((kel, -1 if cm[c] == ON else 1))
        return ev

    peaks = [lambda tt, yy, i=i: yy[n + i] for i in range(n)]          # u extrema
    pen_peaks = [lambda tt, yy, a=a, b=b: yy[n + a] - yy[n + b] for (a, b, *_r) in sc.contacts]

    while t < sc.t_end:
        sw = switches()
        evs = []
        for fn, d in sw:
            fn.terminal, fn.direction = True, d
            evs.append(fn)
        for fn in peaks + pen_peaks:
            fn.terminal, fn.direction = False, 0
            evs.append(fn)
        sol = solve_ivp(rhs, (t, sc.t_end), y, method="DOP853", rtol=rtol, atol=atol,
                        events=evs, dense_output=False)
        # extrema inside this piece
        for i in range(n):
            for yy in sol.y_events[len(sw) + i]:
                ext["u_max"][i] = max(ext["u_max"][i], yy[i])
                ext["u_min"][i] = min(ext["u_min"][i], yy[i])
        for c in range(nc):
            if cm[c] != OPEN:
                a, b, gap = sc.contacts[c][:3]
                for tt, yy in zip(sol.t_events[len(sw) + n + c], sol.y_events[len(sw) + n + c]):
                    ext["pen"][c] = max(ext["pen"][c], yy[a] - yy[b] - gap)
                # Kelvin: the force peaks where its rate vanishes; sample densely in the piece
        for i in range(n):
            ext["u_max"][i] = max(ext["u_max"][i], sol.y[i, -1])
            ext["u_min"][i] = min(ext["u_min"][i], sol.y[i, -1])
        t, y = sol.t[-1], sol.y[:, -1].copy()
        if sol.status != 1:
            break
        # the terminal switch that fired: change its branch
        fired = [j for j in range(len(sw)) if len(sol.t_events[j]) > 0]
        u, v = y[:n], y[n:]
        j = fired[0]
        k_sw = 0
        for s in range(ns):
            cnt = 2 if br[s] == ELASTIC else 1
            if k_sw <= j < k_sw + cnt:
                i, k, fy, rho = sc.springs[s]
                f_now = spring_force(s, u)
                if br[s] == ELASTIC:
                    br[s] = UPPER if j == k_sw else LOWER
                else:
                    br[s] = ELASTIC
                fc[s], uc[s] = f_now, u[i]
            k_sw += cnt
        for c in range(nc):
            a, b, gap, k, damp, clip = sc.contacts[c]
            cnt = 1 if cm[c] == OPEN else (2 if clip else 1)
            if k_sw <= j < k_sw + cnt:
                if cm[c] == OPEN:
                    cm[c] = ON
                    ext["impacts"][c] += 1
                elif j == k_sw:
                    cm[c] = OPEN
                else:
                    cm[c] = CUT if cm[c] == ON else ON
            k_sw += cnt
    ext["u_final"] = y[:n].copy()
    ext["t"] = t
    return sc, ext


def quantities(sc, ext):
    """name -> value of the compared quantities (the keys of martello's summary.json)."""
    q = {}
    for i, name in enumerate(sc.names):
        q["nodes.%s.u_max" % name] = ext["u_max"][i]
        q["nodes.%s.u_min" % name] = ext["u_min"][i]
        q["nodes.%s.u_final" % name] = ext["u_final"][i]
    return q


if __name__ == "__main__":
    for path in sys.argv[1:]:
        sc, a = solve(path)
        _, b = solve(path, rtol=1e-12, atol=1e-15)
        qa, qb = quantities(sc, a), quantities(sc, b)
        print(path)
        for key in qa:
            print("  %-28s %.15e  (rtol 1e-12 differs by %.1e)" % (key, qa[key],
                  abs(qa[key] - qb[key]) / abs(qa[key])))
        print("  max penetration", a["pen"], b["pen"])
