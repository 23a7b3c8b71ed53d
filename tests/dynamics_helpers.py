"""Scene builders and history readers shared by the dynamics tests."""

import numpy as np

from martello.run import run_full
from martello.scene.loader import from_dict


def dynamic(integrator="newmark", dt=1e-3, t_end=1.0, every=1, **extra):
    an = {"type": "dynamic", "integrator": integrator, "dt": dt, "t_end": t_end,
          "output": {"every": every}}
    an.update(extra)
    return an


def two_bodies(law, stiffness, m1=1.0, m2=1.0, v0=1.0, gap=0.0, analysis=None, **contact):
    c = {"name": "impact", "a": "m1", "b": "m2", "gap": gap, "scheme": "penalty", "law": law,
         "stiffness": stiffness}
    c.update(contact)
    return {"node": [{"name": "m1", "mass": m1, "v0": v0}, {"name": "m2", "mass": m2}],
            "contact": [c], "analysis": analysis}


def sdof(m=1.0, k=100.0, analysis=None, links=(), **node):
    n = {"name": "m", "mass": m}
    n.update(node)
    return {"node": [n], "link": [{"type": "spring", "a": "m", "b": "ground", "k": k}, *links],
            "analysis": analysis}


def execute(d):
    summary, (columns, data) = run_full(from_dict(d))
    return summary, {c: data[:, i] for i, c in enumerate(columns)}


def interpolated_peak(t, u, v, a):
    """Max of u from the first + to − sign change of v, by the local quadratic
    u_k + v_k τ + ½ a_k τ² with τ = −v_k/a_k (O(h³) in u, O(h²) in t)."""
    k = np.nonzero((v[:-1] > 0) & (v[1:] <= 0))[0][0]
    tau = -v[k] / a[k]
    return u[k] + v[k] * tau + 0.5 * a[k] * tau ** 2, t[k] + tau


def slope(h, err):
    return np.polyfit(np.log(h), np.log(err), 1)[0]
