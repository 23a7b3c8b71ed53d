"""The summary built column by column (martello.run's _node_results, _first_last_phases,
_link_results) against the element-by-element expressions it replaced.

Kind of evidence: an identity of the method (the same numbers reshaped), not a verification.
Arrays with the edge cases the library returns — NaN and ±inf, −0.0, no peak time (t_peak < 0),
contacts with no, one or several phases, an open last phase — must give equal summaries,
compared as JSON text (so −0.0 against 0.0 or NaN against None would show)."""

import json
from types import SimpleNamespace

import numpy as np

from martello.run import _first_last_phases, _link_results, _node_results, _phase, _phases

RNG = np.random.default_rng(7)
SPECIAL = np.array([np.nan, np.inf, -np.inf, -0.0, 0.0, 1e-300, -1.5])


def with_specials(n):
    x = RNG.normal(size=n)
    x[RNG.integers(0, n, n // 5)] = RNG.choice(SPECIAL, n // 5)
    return x


def text(d):
    return json.dumps(d, allow_nan=True)


def test_node_results_equal_the_per_node_dicts():
    n = 500
    scene = SimpleNamespace(nodes=[{"name": f"b{i}"} for i in range(n)])
    keys = ("u_max", "u_min", "v_absmax", "a_absmax", "u_absmax", "t_absmax")
    peaks = {k: with_specials(n) for k in keys + ("u_peak",)}
    peaks["t_peak"] = np.where(RNG.random(n) < 0.5, -1.0, RNG.random(n))
    expected = {}
    for i, nd in enumerate(scene.nodes):
        expected[nd["name"]] = {k: float(peaks[k][i]) for k in keys}
        if peaks["t_peak"][i] >= 0:
            expected[nd["name"]].update(u_peak=float(peaks["u_peak"][i]),
                                        t_peak=float(peaks["t_peak"][i]))
    assert text(_node_results(scene, peaks)) == text(expected)


def test_first_and_last_phases_equal_each_contacts_slice():
    n_contacts, n_events = 300, 700
    ev_contacts = RNG.integers(0, n_contacts, n_events)      # some contacts get no phase
    ev = RNG.normal(size=(n_events, 6))
    ev[RNG.random(n_events) < 0.3, 1] = -1.0                 # open phases
    order = np.argsort(ev_contacts, kind="stable")
    bounds = np.searchsorted(ev_contacts[order], np.arange(n_contacts + 1))
    first, last = _first_last_phases(ev, order, bounds)
    for j in range(n_contacts):
        mine = ev[order[bounds[j]:bounds[j + 1]]]
        assert text(first[j]) == text(_phase(mine[0]) if len(mine) else None)
        assert text(last[j]) == text(_phase(mine[-1]) if len(mine) else None)
    assert any(f is None for f in first) and any(f is not None for f in first)


def test_link_results_equal_the_per_link_dicts():
    n = 400
    scene = SimpleNamespace(links=[{"name": f"k{i}", "type": "spring"} for i in range(n)])
    f, du = with_specials(n), with_specials(n)
    expected = {l["name"]: {"type": l["type"],
                            "max_abs_force": float(f[i]) if np.isfinite(f[i]) else None,
                            "max_abs_elongation": float(du[i]) if np.isfinite(du[i]) else None}
                for i, l in enumerate(scene.links)}
    assert text(_link_results(scene, f, du)) == text(expected)


def test_phases_equal_phase_row_by_row():
    ev = RNG.normal(size=(200, 6))
    ev[::3, 1] = -1.0
    ev[::7, 2] = -0.0
    assert text(_phases(ev)) == text([_phase(row) for row in ev])
