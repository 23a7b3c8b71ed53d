"""The independent reference engine (martello/independent, docs/independent-reference.md)
against closed forms: verification of the oracle itself, before it verifies anything else.
Every expected value comes from martello.oracles (the mathematics), never from the engine."""

import json
import math

import numpy as np
import pytest

from martello import independent
from martello.oracles.linear_sdof import sdof_sine_ground_response
from martello.oracles.p5_contact_laws import (hertz_impact, hunt_crossley_realised_e,
                                               jankowski_realised_e, jankowski_xi,
                                               kelvin_clipped_restitution, kelvin_xi_from_e,
                                               linear_contact_time)
from martello.oracles.p6_hysteresis import elastoplastic_impulse


def two_body(law, **keys):
    """P5's free two-body impact (docs/problems.md P5): m1 = 1 kg at 1 m/s, m2 = 2 kg, 1 mm gap."""
    contact = {"name": "impact", "a": "m1", "b": "m2", "gap": 1e-3, "scheme": "penalty", "law": law, **keys}
    return {"node": [{"name": "m1", "mass": 1.0, "v0": 1.0}, {"name": "m2", "mass": 2.0}],
            "contact": [contact], "analysis": {"type": "dynamic", "t_end": 6e-3}}


MSTAR = 2.0 / 3.0


def phase(ref):
    return ref.contacts["impact"]["phases"][0]


def test_linear_law_contact_time_and_restitution():
    ref = independent.solve(two_body("linear", stiffness=1e6))
    p = phase(ref)
    # a conservative linear impact: e = 1 and t_c = π√(m*/k) exactly; DOP853 at rtol 1e-11
    assert p["contact_time"] == pytest.approx(linear_contact_time(MSTAR, 1e6), rel=1e-9)
    assert p["restitution"] == pytest.approx(1.0, abs=1e-9)
    assert p["max_penetration"] == pytest.approx(math.sqrt(MSTAR / 1e6), rel=1e-10)
    assert ref.trusted_digits >= 8


def test_hertz_law_contact_time_and_peak():
    ref = independent.solve(two_body("hertz", stiffness=1e8))
    h = hertz_impact(MSTAR, 1e8, 1.0)
    p = phase(ref)
    assert p["contact_time"] == pytest.approx(h.t_c, rel=1e-8)
    assert p["max_penetration"] == pytest.approx(h.delta_max, rel=1e-9)
    assert p["max_force"] == pytest.approx(h.force_max, rel=1e-9)


@pytest.mark.parametrize("clipped", [False, True])
def test_kelvin_restitution_clipped_and_not(clipped):
    ref = independent.solve(two_body("kelvin", stiffness=1e6, restitution=0.5, clipped=clipped))
    e = phase(ref)["restitution"]
    expected = kelvin_clipped_restitution(kelvin_xi_from_e(0.5)) if clipped else 0.5
    assert e == pytest.approx(expected, abs=1e-9)


@pytest.mark.parametrize("method", ["DOP853", "Radau"])
def test_a_separation_is_located_at_the_root_not_at_the_arming_band(method):
    # The separation switch is armed past the round-off band of δ at the onset; it was
    # located where δ = −band, band/|δ̇| late, so the unclipped Kelvin law's tension cδ̇
    # acted that much longer: e − 0.5 = −1.5e-11 at every rtol and on both methods (a bias,
    # not an integration error). The unclipped law realises e exactly (docs/problems.md P5):
    # now within the integration's error, 1e-12 at rtol 1e-12.
    e = independent.run_once(two_body("kelvin", stiffness=1e6, restitution=0.5), rtol=1e-12,
                             method=method)["contacts"]["impact"]["phases"][0]["restitution"]
    assert e == pytest.approx(0.5, abs=1e-12)


def test_a_body_touching_a_barrier_at_rest_is_pressed_and_released():
    # P9's start (docs/problems.md P9): x'' + x = cos(1.5 t), a barrier at x = 0 touched at
    # rest. The gap 0 at the position 0 gave the contact's switch no size (the engine
    # stalled at its own root); the contact closes at t = 0 and, as its stiff spring follows
    # the force quasi-statically, opens where the load turns: x ≈ cos(1.5t)/ε ≈ 0, so
    # cos(1.5 t) = 0 to O(1/ε) in the time of a spring of 1e6 k (t = π/3 + O(1e-4)).
    scene = {"node": [{"name": "x", "mass": 1.0}],
             "link": [{"type": "spring", "a": "x", "b": "ground", "k": 1.0}],
             "contact": [{"name": "barrier", "a": "x", "b": "ground", "gap": 0.0, "scheme": "penalty",
                          "law": "kelvin", "stiffness": 1.0e6, "restitution": 0.8}],
             "loads": {"force": [{"node": "x", "function": {"type": "sine", "amplitude": 1.0, "omega": 1.5,
                                                            "phase": math.pi / 2}}]},
             "analysis": {"type": "dynamic", "t_end": 2.0}}
    r = independent.run_once(scene)
    ph = r["contacts"]["barrier"]["phases"]
    assert len(ph) == 1 and ph[0]["t_on"] == 0.0
    assert ph[0]["t_off"] == pytest.approx(math.pi / 3, abs=1e-3)
    assert r["provenance"]["pieces"] <= 3


@pytest.mark.parametrize("law,target", [("hunt-crossley", 0.5), ("lankarani-nikravesh", 0.8),
                                        ("flores", 0.5), ("gonthier", 0.5), ("hertzdamp", 0.8)])
def test_hunt_crossley_family_realised_restitution(law, target):
    from martello.oracles.p5_contact_laws import HC_FACTORS
    key = {"hunt-crossley": "hunt_crossley", "lankarani-nikravesh": "lankarani_nikravesh",
           "hertzdamp": "lankarani_nikravesh", "flores": "flores", "gonthier": "gonthier"}[law]
    a = HC_FACTORS[key](target)
    ref = independent.solve(two_body(law, stiffness=1e8, restitution=target))
    # the exact relation (1 + e) a = ln[(1 + a)/(1 − e a)], independent of n, K and m*
    assert phase(ref)["restitution"] == pytest.approx(hunt_crossley_realised_e(a), abs=1e-8)


def test_jankowski_realised_restitution():
    ref = independent.solve(two_body("jankowski", stiffness=1e8, restitution=0.65))
    assert phase(ref)["restitution"] == pytest.approx(jankowski_realised_e(jankowski_xi(0.65)), abs=1e-7)


@pytest.mark.parametrize("rho", [0.0, 0.05])
def test_bilinear_yield_is_located(rho):
    scene = {"node": [{"name": "m", "mass": 1.0, "v0": 0.5}],
             "link": [{"type": "bilinear", "a": "m", "b": "ground", "k": 100.0, "fy": 1.0, "hardening": rho}],
             "analysis": {"type": "dynamic", "t_end": 0.8}}
    ref = independent.solve(scene)
    ex = elastoplastic_impulse(1.0, 100.0, 0.01, rho, 0.5)
    assert ref.nodes["m"]["u_max"] == pytest.approx(ex.u_max, rel=1e-10)
    assert ref.nodes["m"]["t_max"] == pytest.approx(ex.t_max, rel=1e-7)    # a flat maximum
    assert ref.events[0]["kind"] == "yield+"
    # bookkeeping of the engine's own energies: plastic work is what the hysteresis takes
    assert abs(ref.energy["balance"]) < 1e-9 * ref.energy["initial"]


def test_sine_ground_motion_on_a_damped_sdof():
    scene = {"node": [{"name": "m", "mass": 2.0}],
             "link": [{"type": "spring", "a": "m", "b": "ground", "k": 800.0},
                      {"type": "dashpot", "a": "m", "b": "ground", "zeta": 0.05}],
             "loads": {"ground_acceleration": {"type": "sine", "amplitude": 3.0, "omega": 13.0}},
             "analysis": {"type": "dynamic", "t_end": 2.0}}
    ref = independent.solve(scene)
    ex = sdof_sine_ground_response(2.0, 800.0, 0.05, 3.0, 13.0, np.array([2.0]))
    assert ref.nodes["m"]["u_final"] == pytest.approx(float(ex.u[0]), abs=1e-11)


def test_a_grazing_contact_inside_one_step_is_found():
    # an undamped SDOF of amplitude A against a plane at A(1 − 1e-8): the contact lasts
    # ~2√(2·1e-8)/ω, far inside one DOP853 step, and no step end sees δ > 0
    A, w = 0.01, 10.0
    scene = {"node": [{"name": "m", "mass": 1.0, "v0": A * w}],
             "link": [{"type": "spring", "a": "m", "b": "ground", "k": w * w}],
             "contact": [{"name": "plane", "a": "m", "b": "ground", "gap": A * (1 - 1e-8),
                          "scheme": "penalty", "law": "linear", "stiffness": 1e3}],
             "analysis": {"type": "dynamic", "t_end": 1.0}}
    run = independent.run_once(scene, rtol=1e-10)
    c = run["contacts"]["plane"]
    assert c["impacts"] == 2                         # at ωt ≈ π/2 and 5π/2
    assert c["phases"][0]["t_on"] == pytest.approx(math.pi / 2 / w, rel=1e-3)


def test_restitution_scheme_impulse():
    scene = two_body("linear", stiffness=1.0)
    scene["contact"][0] = {"name": "impact", "a": "m1", "b": "m2", "gap": 1e-3, "scheme": "restitution",
                           "restitution": 0.3}
    ref = independent.solve(scene)
    # Newton's law: v1' = v1 − (1 + e) m2 v0/(m1 + m2)
    assert ref.nodes["m1"]["v_final"] == pytest.approx(1.0 - 1.3 * 2.0 / 3.0, rel=1e-14)
    assert ref.energy["impact"] == pytest.approx(0.5 * (1 - 0.09) * MSTAR, rel=1e-14)


def test_identical_neighbours_never_touch():
    # docs/problems.md P7: identical oscillators with the same initial state move together
    scene = {"chain": [{"prefix": "s", "n": 3, "mass": 1.0, "k": 100.0, "zeta": 0.05, "gap": 0.001,
                        "contact": {"scheme": "penalty", "law": "kelvin", "stiffness": 1e5, "restitution": 0.65}}],
             "loads": {"ground_acceleration": {"type": "sine", "amplitude": 3.0, "omega": 8.0}},
             "analysis": {"type": "dynamic", "t_end": 2.0}}
    run = independent.run_once(scene)
    assert all(c["impacts"] == 0 for c in run["contacts"].values())


def test_the_report_is_strict_json():
    ref = independent.solve(two_body("linear", stiffness=1e6))
    text = independent.dumps(ref.to_json())
    json.loads(text, parse_constant=lambda c: pytest.fail(f"{c} in the report"))
    with pytest.raises(ValueError):
        json.dumps({"x": float("nan")}, allow_nan=False)
    assert independent.dumps({"x": float("nan")}) == '{\n "x": null\n}'


def test_unsupported_parts_are_refused():
    scene = two_body("linear", stiffness=1e6)
    scene["contact"][0]["scheme"] = "lagrange"
    with pytest.raises(independent.Unsupported, match="lagrange"):
        independent.solve(scene)


# --- [[frame]]: the engine's own frame model (martello/independent/frame.py) ---------------------

def _portal(base, beam_I):
    return {"prefix": "P", "storeys": 1, "bays": 1, "storey_height": 3.0, "bay_width": 6.0,
            "column": {"E": 3e10, "A": 1e6, "I": 2e-3}, "beam": {"E": 3e10, "A": 1e6, "I": beam_I},
            "mass": 1e4, "base": base}


@pytest.mark.parametrize("base, k", [("fixed", 24.0), ("pinned", 6.0)])
def test_a_portal_with_a_rigid_beam_has_the_textbook_lateral_stiffness(base, k):
    # verification against closed forms: two columns fixed at both ends sway with 12EI/h³
    # each, pinned at the base with 3EI/h³ (Chopra, Dynamics of Structures, §1.3)
    from martello.independent.frame import frame_block
    fb = frame_block(_portal(base, 1e6))
    assert fb.K.shape == (1, 1) and fb.nodes == ["P1"]
    assert fb.K[0, 0] == pytest.approx(k * 3e10 * 2e-3 / 27.0, rel=1e-6)


def test_the_engines_frame_and_the_front_ends_agree():
    # two codes of one model (the engine's martello/independent/frame.py and the front end's
    # martello.frame2d): a cross-check of two implementations, to round-off
    import tomllib
    from pathlib import Path
    from martello.independent.frame import frame_block
    from martello.scene.frame import expand_frames
    root = Path(__file__).resolve().parent.parent
    d = tomllib.loads((root / "benchmarks" / "p10" / "p10_A.toml").read_text())
    _, frames = expand_frames("p10_A.toml", d)
    for fr, tab in zip(frames, d["frame"]):
        fb = frame_block(tab)
        assert fb.nodes == fr["nodes"]
        assert np.max(np.abs(fb.K - fr["K"])) <= 1e-12 * np.max(np.abs(fr["K"]))
        assert np.max(np.abs(fb.C - fr["C"])) <= 1e-12 * np.max(np.abs(fr["C"]))


# --- [[building]]: the engine's own shear-type storeys (martello/independent/building.py) ------

def test_the_engines_storeys_are_the_textbook_one_storey_system():
    # verification against the closed form of P11's one-storey eccentric system (the
    # catalogue's p11_eccentric_storey.toml: its members' 12EI/h³ and GJ/h worked out by hand,
    # martello.oracles.p11_buildings.one_storey_periods) on the engine's own storey matrix
    import tomllib
    from pathlib import Path
    from scipy.linalg import eigh
    from martello.independent.building import building_block
    from martello.oracles.p11_buildings import one_storey_periods
    root = Path(__file__).resolve().parent.parent
    d = tomllib.loads((root / "benchmarks" / "p11" / "p11_eccentric_storey.toml").read_text())
    bb = building_block(d["building"][0])
    assert bb.nodes == ["B1.ux", "B1.uy", "B1.rz"]
    w2 = eigh(bb.K, np.diag(bb.mass), eigvals_only=True)
    want = one_storey_periods(**d["check"]["params"])
    got = sorted(2 * np.pi / np.sqrt(w2), reverse=True)
    assert got == pytest.approx([want["T1"], want["T2"], want["T3"]], rel=1e-12)


def test_the_engines_buildings_and_the_front_ends_agree():
    # two codes of one model (the engine's martello/independent/building.py and the front
    # end's martello.building3d condensing its 3D beam-columns): K, C, masses, the ground's
    # influence and the plan-point rows of P11's shear-type pair, to round-off
    from pathlib import Path
    from martello.independent.scene import load_model
    from martello.scene.loader import load
    path = Path(__file__).resolve().parent.parent / "benchmarks" / "p11" / "p11_shear_pounding.toml"
    sc, m = load(path), load_model(path)
    for b, (name, nodes, K, C) in zip(sc.extras["buildings"], m.blocks):
        assert [m.names[i] for i in nodes] == b["nodes"]
        assert np.max(np.abs(K - b["K"])) <= 1e-12 * np.max(np.abs(b["K"]))
        assert np.max(np.abs(C - b["C"])) <= 1e-12 * np.max(np.abs(b["C"]))
        assert np.allclose(np.diag(b["M"]), m.mass[nodes], rtol=1e-15, atol=0)
        assert np.array_equal(m.influence[nodes], b["influence"])
    names = [n["name"] for n in sc.nodes]
    for c, law in zip(sc.contacts, m.contacts):
        front = {names[i]: v for i, v in c["terms"]}
        assert {m.names[i]: v for i, v in law.terms} == pytest.approx(front, rel=1e-15)
    fD = {lk[0]: row for lk, row in zip(m.dampers, m.damper_rows)}
    for lk in sc.links:
        assert {m.names[i]: v for i, v in fD[lk["name"]]} == pytest.approx(
            {names[i]: v for i, v in lk["terms"]}, rel=1e-15)
    # what the engine's storeys do not model is refused, never approximated
    frame = Path(__file__).resolve().parent.parent / "benchmarks" / "p11" / "case_study" / "p11_A.toml"
    with pytest.raises(independent.Unsupported, match="frame"):
        load_model(frame)


def test_the_engine_reads_peer_at2_records():
    # a user's ground motion as PEER gives it: the engine's own reader (martello/independent/
    # scene.py) and the front end's (martello.ground_motion.records) read the same samples in
    # m/s² (two implementations of one format, cross-checked)
    from pathlib import Path
    from martello.ground_motion.records import read_at2
    from martello.independent.scene import _read_at2_record
    data = Path(__file__).resolve().parent / "data" / "records"
    files = sorted(data.glob("peer_*"))       # the valid ones (the others test the front end's errors)
    assert files
    for f in files:
        t, a = _read_at2_record(f, None)
        rec = read_at2(f)
        assert np.array_equal(t, rec.t) and np.allclose(a, rec.accel, rtol=1e-15, atol=0.0), f.name
