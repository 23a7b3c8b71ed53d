"""The oracles of the 3D buildings (docs/buildings.md, "Verification"), each with its error:

    .venv/bin/python benchmarks/p11/oracles.py

Prints, for each oracle, what is compared, the closed form or the independent model, and the
largest relative error measured; nothing is written. The same comparisons are asserted, with
tolerances, by tests/test_buildings.py (and tests/test_plan_contacts.py for the impacts)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from martello.binding import native  # noqa: E402
from martello.run import run_full  # noqa: E402
from martello.scene.loader import from_dict  # noqa: E402

E, G = 3.0e10, 3.0e10 / 2.4
COL = {"E": E, "b2": 0.3, "b3": 0.5}
WALL = {"E": E, "A": 0.5, "I2": 1e-3, "I3": 0.4, "J": 1e-3}


def rect_J(a, b):
    a, b = max(a, b), min(a, b)
    return a * b**3 * (1 / 3 - 0.21 * (b / a) * (1 - (b / a) ** 4 / 12))


def eccentric(**kw):
    b = {"prefix": "B", "storeys": 1, "storey_height": 3.0, "grid_x": [0.0, 6.0], "grid_y": [0.0, 4.0],
         "column": COL, "mass": 2.0e5,
         "member": [{"name": "W", "x": 6.0, "y": 2.0, "angle": 90.0, "section": WALL}]}
    b.update(kw)
    return b


def storey_torsion():
    """K_θθ of a shear storey about its mass centre = Σ (k_x (y − y_c)² + k_y (x − x_c)²) + Σ GJ/h."""
    sc = from_dict({"building": [eccentric()], "analysis": {"type": "static"}})
    h = 3.0
    kx, ky = 12 * E * (0.5 * 0.3**3 / 12) / h**3, 12 * E * (0.3 * 0.5**3 / 12) / h**3
    wx, wy = 12 * E * 1e-3 / h**3, 12 * E * 0.4 / h**3
    k = (sum(kx * (y - 2.0) ** 2 + ky * (x - 3.0) ** 2 for x in (0, 6) for y in (0, 4))
         + wx * 0.0 + wy * 3.0**2 + G * (4 * rect_J(0.3, 0.5) + 1e-3) / h)
    got = sc.blocks[0]["k"][2, 2]
    return abs(got - k) / k, got, k


def coupled_periods():
    """The one-storey eccentric system's three periods: Kan & Chopra's closed form."""
    sc = from_dict({"building": [eccentric()], "analysis": {"type": "static"}})
    m, h = 2.0e5, 3.0
    J = m * (36 + 16) / 12
    kx, ky = 12 * E * (0.5 * 0.3**3 / 12) / h**3, 12 * E * (0.3 * 0.5**3 / 12) / h**3
    wx, wy = 12 * E * 1e-3 / h**3, 12 * E * 0.4 / h**3
    Kx, Ky = 4 * kx + wx, 4 * ky + wy
    xR = (2 * ky * 6.0 + wy * 6.0) / Ky
    KthR = (sum(ky * (x - xR) ** 2 for x in (0, 0, 6, 6)) + wy * (6 - xR) ** 2
            + sum(kx * (y - 2.0) ** 2 for y in (0, 4, 0, 4)) + G * (4 * rect_J(0.3, 0.5) + 1e-3) / h)
    e, r2 = xR - 3.0, J / m
    wy2, wt2 = Ky / m, KthR / J
    a = wy2 * (1 + e * e / r2) + wt2
    d = math.sqrt(a * a - 4 * wy2 * wt2)
    T = sorted(2 * math.pi / math.sqrt(w2) for w2 in (Kx / m, (a - d) / 2, (a + d) / 2))
    got = sorted(md["period"] for md in sc.extras["buildings"][0]["modes"])
    return max(abs(g - t) / t for g, t in zip(got, T)), got, T


def symmetric_is_planar():
    """Three identical frames along x, modal damping 5 %, a sine ground motion along x:
    the building's floors against the planar frame of three times the sections."""
    def rect(b, h, n):
        return {"E": E, "A": n * b * h, "I": n * b * h**3 / 12}
    an = {"type": "dynamic", "integrator": "newmark", "dt": 2e-3, "t_end": 3.0, "tol_residual": 1e-12}
    ground = {"ground_acceleration": {"type": "sine", "amplitude": 3.0, "omega": 9.0}}
    planar = {"frame": [{"prefix": "P", "storeys": 3, "bays": 2, "storey_height": 3.0, "bay_width": 5.0,
                         "column": rect(0.3, 0.5, 3), "beam": rect(0.3, 0.5, 3), "mass": 1.5e5,
                         "zeta": 0.05, "damping": "modal"}], "loads": ground, "analysis": an}
    b3 = {"building": [{"prefix": "B", "storeys": 3, "storey_height": 3.0, "model": "frame",
                        "grid_x": [0.0, 5.0, 10.0], "grid_y": [0.0, 4.5, 9.0],
                        "column": {"E": E, "b2": 0.5, "b3": 0.3}, "beam": {"E": E, "b": 0.3, "h": 0.5},
                        "beam_y": False, "mass": 1.5e5, "zeta": 0.05, "damping": "modal"}],
          "loads": ground, "analysis": an}
    sp, sb = from_dict(planar), from_dict(b3)
    Kp, Kb = sp.blocks[0]["k"], sb.blocks[0]["k"]
    dk = np.abs(Kb[0::3, 0::3] - Kp).max() / np.abs(Kp).max()
    rp, (cp, hp) = run_full(sp)
    rb, (cb, hb) = run_full(sb)
    du = max(np.abs(hp[:, cp.index(f"u:P{f}")] - hb[:, cb.index(f"u:B{f}.ux")]).max()
             / np.abs(hp[:, cp.index(f"u:P{f}")]).max() for f in (1, 2, 3))
    rz = max(np.abs(hb[:, cb.index(f"u:B{f}.rz")]).max() for f in (1, 2, 3))
    ux = max(np.abs(hb[:, cb.index(f"u:B{f}.ux")]).max() for f in (1, 2, 3))
    dm = max(abs(rb["buildings"]["B"]["members"][f"C{s}.{ln}.1"]["M3_i"]["max"]
                 + rp["frames"]["P"]["members"][f"C{s}.{ln}"]["M_i"]["min"] / 3)
             / abs(rp["frames"]["P"]["members"][f"C{s}.{ln}"]["M_i"]["min"] / 3)
             for s in (1, 2, 3) for ln in (0, 1, 2))
    return dk, du, rz, ux, dm


def eccentric_impact():
    """benchmarks/p11/p11_eccentric_impact.toml on every restitution integrator: the speeds and
    rotation rates after the impact against Newton's law with the eccentric w."""
    import tomllib
    from martello.oracles.p11_buildings import eccentric_impact as oracle
    path = ROOT / "benchmarks" / "p11" / "p11_eccentric_impact.toml"
    d = tomllib.loads(path.read_text())
    ref = oracle(**d["check"]["params"])
    out = {}
    for integ in ("rk8pd", "rkf45", "msbdf", "ida", "cvode", "arkode", "moreau-jean", "newmark-lagrange"):
        dd = {k: v for k, v in d.items() if k != "check"}
        an = dict(d["analysis"], integrator=integ)
        if integ in ("moreau-jean", "newmark-lagrange"):
            an = {k: v for k, v in an.items() if k not in ("rtol", "atol")}
        dd["analysis"] = an
        s, (cols, hist) = run_full(from_dict(dd))
        got = {q: hist[-1, cols.index(f"v:{q}")] for q in ("A.ux", "A.rz", "B.ux", "B.rz")}
        want = {"A.ux": ref["v1_after"], "A.rz": ref["w1_after"], "B.ux": ref["v2_after"], "B.rz": ref["w2_after"]}
        out[integ] = max(abs(got[q] - want[q]) / abs(want[q]) for q in got)
    return ref, out


def main():
    print(f"martello {native.version()}; oracles of docs/buildings.md")
    err, got, k = storey_torsion()
    print(f"storey torsional stiffness Σ k r² + Σ GJ/h (shear storey, 4 columns + a wall): "
          f"{got:.10e} vs {k:.10e} N m/rad, rel. error {err:.1e}")
    err, got, T = coupled_periods()
    print("one-storey eccentric periods (Kan & Chopra closed form): "
          + ", ".join(f"{g:.12f}/{t:.12f}" for g, t in zip(got, T)) + f" s, largest rel. error {err:.1e}")
    dk, du, rz, ux, dm = symmetric_is_planar()
    print(f"symmetric building = planar frame (3 storeys, 3 frames, Newmark 2 ms, 3 s sine): "
          f"K rel. diff {dk:.1e}; ux histories rel. diff {du:.1e}; max |rz| {rz:.1e} rad "
          f"(max |ux| {ux:.3e} m); column M3 vs planar M/3 rel. diff {dm:.1e}")
    ref, errs = eccentric_impact()
    print(f"eccentric impact (w = {ref['w']:.6e} 1/kg, P = {ref['impulse']:.6e} N s): largest rel. error of "
          "the speeds and rotation rates after it: " + ", ".join(f"{k} {v:.1e}" for k, v in errs.items()))


if __name__ == "__main__":
    main()
