"""The summary built column by column (martello.run.item_arrays and phase_rows,
martello.results.ItemArrays)
against the element-by-element expressions it replaced.

Kind of evidence: an identity of the method (the same numbers reshaped), not a verification.
Arrays with the edge cases the library returns — NaN and ±inf, −0.0, no peak time (t_peak < 0),
contacts with no, one or several phases, an open last phase — must give equal summaries,
compared as JSON text (so −0.0 against 0.0 or NaN against None would show)."""

import json
from types import SimpleNamespace

import numpy as np

from martello.run import item_arrays, phase_rows
from martello.scene.spec import TRACKABLE

RNG = np.random.default_rng(7)
SPECIAL = np.array([np.nan, np.inf, -np.inf, -0.0, 0.0, 1e-300, -1.5])


def with_specials(n):
    x = RNG.normal(size=n)
    x[RNG.integers(0, n, n // 5)] = RNG.choice(SPECIAL, n // 5)
    return x


def text(d):
    return json.dumps(d, allow_nan=True)


def phase(row):
    """One contact phase of the event table, written out: onset and separation (null while
    open)."""
    return {"impact_time": float(row[0]), "separation_time": float(row[1]) if row[1] >= 0 else None,
            "approach_speed": float(row[2]), "separation_speed": float(row[3]) if row[1] >= 0 else None,
            "max_penetration": float(row[4]), "max_force": float(row[5])}


def arrays_of(n_nodes=0, n_links=0, n_contacts=0, n_events=0):
    """A made-up run's arrays and its ItemArrays."""
    scene = SimpleNamespace(
        nodes=[{"name": f"b{i}"} for i in range(n_nodes)],
        links=[{"name": f"k{i}", "type": ("spring", "dashpot")[i % 2]} for i in range(n_links)],
        contacts=[{"name": f"c{i}", "scheme": "penalty", "law": ("linear", "kelvin")[i % 2]}
                  for i in range(n_contacts)])
    keys = ("u_max", "u_min", "v_absmax", "a_absmax", "u_absmax", "t_absmax")
    peaks = {k: with_specials(n_nodes) for k in keys + ("u_peak",)}
    peaks["t_peak"] = np.where(RNG.random(n_nodes) < 0.5, -1.0, RNG.random(n_nodes))
    peaks.update(pen_max=RNG.normal(size=n_contacts), force_max=RNG.normal(size=n_contacts),
                 impacts=RNG.integers(0, 5, n_contacts).astype(np.int32))
    f, du = with_specials(n_links), with_specials(n_links)
    ev_contacts = RNG.integers(0, max(n_contacts, 1), n_events)   # some contacts get no phase
    ev = RNG.normal(size=(n_events, 6))
    ev[RNG.random(n_events) < 0.3, 1] = -1.0                      # open phases
    order = np.argsort(ev_contacts, kind="stable")
    bounds = np.searchsorted(ev_contacts[order], np.arange(n_contacts + 1))
    arrays = item_arrays(scene, TRACKABLE, peaks, f, du, ev, *phase_rows(ev_contacts, n_contacts))
    return scene, peaks, f, du, ev, order, bounds, arrays


def test_node_entries_equal_the_per_node_dicts():
    scene, peaks, *_, arrays = arrays_of(n_nodes=500)
    keys = ("u_max", "u_min", "v_absmax", "a_absmax", "u_absmax", "t_absmax")
    expected = {}
    for i, nd in enumerate(scene.nodes):
        expected[nd["name"]] = {k: float(peaks[k][i]) for k in keys}
        if peaks["t_peak"][i] >= 0:
            expected[nd["name"]].update(u_peak=float(peaks["u_peak"][i]),
                                        t_peak=float(peaks["t_peak"][i]))
    assert text(arrays.entries("nodes", range(500))) == text(expected)


def test_contact_entries_hold_each_contacts_first_and_last_phase():
    scene, peaks, f, du, ev, order, bounds, arrays = arrays_of(n_contacts=300, n_events=700)
    got = arrays.entries("contacts", range(300))
    for j, c in enumerate(scene.contacts):
        mine = ev[order[bounds[j]:bounds[j + 1]]]
        pen = peaks["pen_max"][j]
        assert text(got[c["name"]]) == text({
            "scheme": "penalty", "law": c["law"], "max_penetration": float(max(pen, 0.0)),
            "max_force": float(peaks["force_max"][j]), "impacts": int(peaks["impacts"][j]),
            "first_phase": phase(mine[0]) if len(mine) else None,
            "last_phase": phase(mine[-1]) if len(mine) else None})
    assert any(e["first_phase"] is None for e in got.values())
    assert any(e["first_phase"] is not None for e in got.values())


def test_link_entries_equal_the_per_link_dicts():
    scene, peaks, f, du, *_, arrays = arrays_of(n_links=400)
    expected = {l["name"]: {"type": l["type"],
                            "max_abs_force": float(f[i]) if np.isfinite(f[i]) else None,
                            "max_abs_elongation": float(du[i]) if np.isfinite(du[i]) else None}
                for i, l in enumerate(scene.links)}
    assert text(arrays.entries("links", range(400))) == text(expected)


def test_phase_rows_are_the_first_and_last_of_each_contacts_rows():
    ev_contacts = RNG.integers(0, 50, 400)
    first, last = phase_rows(ev_contacts, 60)                # contacts 50..59 have none
    for j in range(60):
        rows = [i for i, c in enumerate(ev_contacts) if c == j]
        assert (first[j], last[j]) == ((rows[0], rows[-1]) if rows else (-1, -1))
