"""What a run tracks (martello_run_set_tracking, docs/c-api.md "What a run tracks").

Kind of evidence: an identity of the method. Tracking less changes no number the run keeps:
what it still tracks is bit for bit what a run that tracks everything gives, what it does not
track reads NaN (no phase rows), and every contact's number of phases is counted either way.
On the fused chain step, the general path and an adaptive C integrator (each measures through
the observer its own way)."""

import numpy as np
import pytest

from martello.binding import native
from martello.run import build_model, integrator_settings
from martello.scene.loader import from_dict

WHAT = ("node_peaks", "link_peaks", "contact_peaks", "phases")


def pounding(integrator):
    n = 8
    an = {"type": "dynamic", "integrator": integrator, "dt": 1e-3, "t_end": 2.0,
          "output": {"every": 100, "nodes": ["b1"], "contacts": ["b1-b2"]}}
    if integrator == "hht":
        an["alpha"] = -0.1
    if integrator == "rkf45":
        an.update(rtol=1e-8, atol=1e-10)
    return from_dict({
        "chain": [{"prefix": "b", "n": n, "mass": 1.0,
                   "k": [100.0 if i % 2 == 0 else 400.0 for i in range(n)], "zeta": 0.05,
                   "gap": 0.005, "contact": {"scheme": "penalty", "law": "linear",
                                             "stiffness": 1e5}}],
        "loads": {"ground_acceleration": {"type": "sine", "amplitude": 3.0, "omega": 8.0}},
        "analysis": an})


def results(scene, *what):
    with build_model(scene) as model, native.Run() as r:
        r.set_settings(integrator_settings(scene.analysis))
        r.set_outputs([0], [0])
        if what:
            r.set_tracking(*what)
        r.execute(model)
        peaks = r.peaks(len(scene.nodes), len(scene.contacts))
        link_f, link_du = r.link_peaks(len(scene.links))
        ev_contacts, ev = r.events()
        return dict(peaks=peaks, link_f=link_f, link_du=link_du, ev=ev, ev_contacts=ev_contacts,
                    hist=r.history(), counters=r.counters())


NODE_KEYS = ("u_max", "u_min", "v_absmax", "a_absmax", "u_peak", "t_peak", "u_absmax", "t_absmax")


@pytest.mark.parametrize("integrator", ["newmark", "hht", "rkf45"])
@pytest.mark.parametrize("kept", [(), ("node_peaks",), ("contact_peaks", "phases"),
                                  ("link_peaks",), ("node_peaks", "phases")], ids=str)
def test_tracking_less_keeps_the_same_numbers(integrator, kept):
    scene = pounding(integrator)
    full = results(scene)
    part = results(scene, *kept) if kept else results(scene, "node_peaks")
    kept = kept or ("node_peaks",)
    assert full["counters"]["fused_chain_steps"] == part["counters"]["fused_chain_steps"]
    assert np.array_equal(full["hist"], part["hist"], equal_nan=True)
    assert np.array_equal(full["peaks"]["impacts"], part["peaks"]["impacts"])
    assert full["peaks"]["impacts"].sum() > 0                     # the chain pounds
    for key in NODE_KEYS:
        want = full["peaks"][key] if "node_peaks" in kept else np.full_like(full["peaks"][key], np.nan)
        assert np.array_equal(part["peaks"][key], want, equal_nan=True), key
    for key in ("pen_max", "force_max"):
        want = full["peaks"][key] if "contact_peaks" in kept else np.full_like(full["peaks"][key], np.nan)
        assert np.array_equal(part["peaks"][key], want, equal_nan=True), key
    for key in ("link_f", "link_du"):
        want = full[key] if "link_peaks" in kept else np.full_like(full[key], np.nan)
        assert np.array_equal(part[key], want, equal_nan=True), key
    if "phases" in kept:
        assert np.array_equal(part["ev"], full["ev"]) and len(full["ev"]) > 0
    else:
        assert len(part["ev"]) == 0


def test_an_unknown_flag_is_refused():
    with native.Run() as r:
        st = native.lib().martello_run_set_tracking(r._h, 16)
        assert st == native.constant("MARTELLO_ERR_ARGUMENT")
        assert "set_tracking: an OR of MARTELLO_TRACK_" in r.message()
