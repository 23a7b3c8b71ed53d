"""Metrics of a run against a reference (martello.metrics; docs/problems.md "Metrics"):
history errors, impacts matched before comparing, peaks, restitution, energy, the
closed-form references and the scene digest that keys reference data (martello.reference).
Oracles: martello.oracles."""

import copy
import math
from pathlib import Path

import numpy as np
import pytest

from martello.checks.dispatchers import bouncing_kelvin_events, bouncing_restitution_events
from martello.history import interpolate
from martello.metrics.from_history import summary_from_history
from martello.metrics.score import event_errors, history_errors, score
from martello.oracles.p5_contact_laws import kelvin_damping, kelvin_xi_from_e
from martello.reference.base import Reference, ReferenceError
from martello.reference.closed_form import (closed_form_reference, kelvin_bounce_reference,
                                            restitution_bounce_reference,
                                            two_body_kelvin_reference)
from martello.reference.selection import reference_for_scene
from martello.reference.store import physics_digest
from martello.scene.loader import from_dict, load
from tests.dynamics_helpers import dynamic, two_bodies

ROOT = Path(__file__).resolve().parent.parent
P2 = ROOT / "benchmarks" / "p2"


def ref_of(columns, t, **events):
    """A data Reference with given samples and events."""
    return Reference(name="test", kind="data", t_end=float(t[-1]), columns=tuple(columns),
                     times=np.asarray(t, float), samples={k: np.asarray(v, float) for k, v in columns.items()},
                     events=events)


# --- interpolation and history errors --------------------------------------------------------

def test_hermite_interpolation_is_exact_for_its_degree():
    # quintic Hermite on (u, u', u'') reproduces degree-5 polynomials, cubic on (v, v') cubics:
    # errors at round-off (100 eps relative to the values' scale)
    t = np.linspace(0.0, 1.0, 7)
    tt = np.linspace(0.0, 1.0, 1001)
    u = lambda s: 1 - 2 * s + 3 * s**2 - s**3 + 0.5 * s**4 - 0.7 * s**5
    du = lambda s: -2 + 6 * s - 3 * s**2 + 2 * s**3 - 3.5 * s**4
    ddu = lambda s: 6 - 6 * s + 6 * s**2 - 14 * s**3
    samples = {"u:n": u(t), "v:n": du(t), "a:n": ddu(t)}
    assert np.max(np.abs(interpolate(t, samples, "u:n", tt) - u(tt))) < 100 * np.finfo(float).eps
    v3 = lambda s: 2 - s + 4 * s**3
    samples = {"v:n": v3(t), "a:n": -1 + 12 * t**2}
    assert np.max(np.abs(interpolate(t, samples, "v:n", tt) - v3(tt))) < 100 * np.finfo(float).eps
    # samples that fall on requested times are returned bit for bit
    assert np.array_equal(interpolate(t, {"x:n": t**2}, "x:n", t), t**2)


def test_history_errors_measure_a_known_perturbation():
    t = np.linspace(0.0, 2.0, 401)
    u = np.sin(3 * t)
    ref = ref_of({"u:n": u}, t)
    same = history_errors((["t", "u:n"], np.column_stack([t, u])), ref)
    assert same["max_rel_error"] == 0.0 and same["scd"] == math.inf
    bump = 1e-4 * np.exp(-((t - 1.0) / 0.1) ** 2)
    e = history_errors((["t", "u:n"], np.column_stack([t, u + bump])), ref)
    # normwise: the bump's peak over the peak of |u| (= 1 to 1e-5 on this grid)
    assert e["max_abs_error:u:n"] == pytest.approx(1e-4, rel=1e-12)
    assert e["max_rel_error"] == pytest.approx(1e-4 / np.max(np.abs(u)), rel=1e-12)
    assert e["scd"] == pytest.approx(4.0, abs=1e-4)
    assert e["compare_points"] == len(t)


def test_history_errors_compare_only_at_the_runs_own_times_when_they_fall_on_the_grid():
    # a run sampled at every second reference time is compared at those, not interpolated
    t = np.linspace(0.0, 1.0, 101)
    ref = ref_of({"u:n": np.cos(t)}, t)
    run = (["t", "u:n"], np.column_stack([t[::2], np.cos(t[::2])]))
    e = history_errors(run, ref)
    assert e["compare_points"] == len(t[::2]) and e["max_rel_error"] == 0.0


# --- events ----------------------------------------------------------------------------------

def test_a_shifted_impact_is_a_time_error_not_a_missing_and_an_extra_one():
    ref = ref_of({"u:n": [0, 1]}, [0, 10], c={"impact_times": [1.0, 2.0, 3.0],
                                              "approach_speeds": [1, 1, 1], "restitution": [0.8, 0.8, 0.8]})
    run = {"c": {"impact_times": [1.0, 2.001, 3.0, 3.4], "approach_speeds": [1, 1, 1, 0.5],
                 "restitution": [0.8, 0.79, 0.8, 0.8]}}
    e = event_errors(run, ref)
    assert e["impact_time_error"] == pytest.approx(0.001)
    assert (e["impacts_missing"], e["impacts_extra"], e["impact_count_error"]) == (0, 1, 1)
    assert e["restitution_error"] == pytest.approx(0.01)
    # beyond the reference's event horizon nothing is counted
    ref.event_horizon = 2.5
    e = event_errors(run, ref)
    assert (e["impact_count"], e["impact_count_ref"], e["impacts_extra"]) == (2, 2, 0)


def test_grazing_phases_do_not_score_restitution():
    ref = ref_of({"u:n": [0, 1]}, [0, 10], c={"impact_times": [1.0, 2.0], "approach_speeds": [1.0, 1e-4],
                                              "restitution": [0.8, 0.8]})
    run = {"c": {"impact_times": [1.0, 2.0], "approach_speeds": [1.0, 1e-4], "restitution": [0.8, 0.2]}}
    e = event_errors(run, ref)
    assert e["restitution_error"] == 0.0 and e["restitution"] == 0.8


# --- closed-form references -------------------------------------------------------------------

def test_kelvin_reference_events_are_the_closed_forms():
    ref = kelvin_bounce_reference(0.7, 1.0, 100.0, 0.05, 9.81, 1e6, restitution=0.8)
    oracle = bouncing_kelvin_events(1.0, 100.0, 0.05, 9.81, 1e6, 4, restitution=0.8)
    ev = ref.events["plane"]
    for i in range(4):
        assert ev["impact_times"][i] == oracle[f"t_impact_{i}"]
        assert ev["phase_max_penetration"][i] == oracle[f"max_penetration_{i}"]
    # the history is continuous through the first contact and its force is ε δ + c δ̇ there
    t1, t2 = ev["impact_times"][0], ev["separation_times"][0]
    r = ref.at(np.array([t1, 0.5 * (t1 + t2)]), ["penetration:plane", "force:plane", "v:mass"])
    assert abs(r["penetration:plane"][0]) < 1e-15
    c = kelvin_damping(1e6, 1.0, kelvin_xi_from_e(0.8))
    assert r["force:plane"][1] == pytest.approx(1e6 * r["penetration:plane"][1] + c * r["v:mass"][1], rel=1e-14)
    # the phase peak force is the maximum of the exact force (sampled and refined)
    s = np.linspace(t1, t2, 200001)
    f = ref.at(s, ["force:plane"])["force:plane"]
    assert ev["phase_max_force"][0] == pytest.approx(np.max(f), rel=1e-9)


def test_restitution_reference_flights_and_zeno_point():
    m, k, h, g, e = 1.0, 100.0, 0.05, 9.81, 0.8
    ref = restitution_bounce_reference(1.5, m, k, h, g, e)
    oracle = bouncing_restitution_events(m, k, h, g, e, 3)
    ti = ref.events["plane"]["impact_times"]
    assert ti[:3] == [oracle["t_impact_0"], oracle["t_impact_1"], oracle["t_impact_2"]]
    r = ref.at(np.array([ti[0], ti[1] - 1e-12, ti[1] + 1e-12, 1.4]), ["u:mass", "v:mass", "force:plane"])
    assert r["u:mass"][0] == pytest.approx(h, abs=1e-14)
    assert r["v:mass"][2] == pytest.approx(-e * r["v:mass"][1], rel=1e-9)
    # after t∞ = 1.2997 s the mass rests on the plane and the contact carries m g − k h
    assert r["u:mass"][3] == h and r["force:plane"][3] == pytest.approx(m * g - k * h)


def test_two_body_reference_conserves_momentum_and_realises_e():
    m1, m2, eps, e = 1.0, 3.0, 1e6, 0.65
    ref = two_body_kelvin_reference(0.01, m1, m2, 1e-3, eps, restitution=e, v1=1.0)
    t = np.linspace(0.0, 0.01, 5001)
    r = ref.at(t, ref.columns)
    p = m1 * r["v:m1"] + m2 * r["v:m2"]
    assert np.max(np.abs(p - 1.0)) < 1e-14
    dv = r["v:m1"][-1] - r["v:m2"][-1]
    assert -dv == pytest.approx(e, rel=1e-12)       # unclipped Kelvin realises e exactly


def test_summary_from_a_sampled_exact_history_finds_the_impacts():
    ref = kelvin_bounce_reference(0.7, 1.0, 100.0, 0.05, 9.81, 1e6, restitution=0.8)
    t = np.linspace(0.0, 0.7, 70001)
    r = ref.at(t, ref.columns)
    cols = ["t"] + list(r)
    sc = load(P2 / "p2_penalty_kelvin.toml")
    s = summary_from_history(sc, (cols, np.column_stack([t] + [r[c] for c in r])))
    ev = ref.events["plane"]
    got = s["contacts"]["plane"]
    assert len(got["impact_times"]) == len(ev["impact_times"]) == 4
    # onsets: roots of the cubic Hermite interpolant of δ between samples 1e-5 s apart
    assert np.max(np.abs(np.subtract(got["impact_times"], ev["impact_times"]))) < 1e-9
    assert got["restitution"][0] == pytest.approx(ev["restitution"][0], abs=1e-4)


# --- scoring a martello run -----------------------------------------------------------------

def test_score_of_a_run_against_its_closed_form():
    # P2 linear penalty with Newmark at Δt = 1e-5 (ω_c Δt = 0.01): second order, the onset is
    # not located by the integrator: the error is measured ≈ 3e-5 of the peak |u|
    from martello.run import run_full
    d = load(P2 / "p2_penalty_linear.toml")
    summary, hist = run_full(d)
    ref = reference_for_scene(d)
    assert ref.kind == "closed-form"
    m = score(summary, hist, ref)
    assert 1e-6 < m["max_rel_error"] < 1e-4
    assert m["impact_count_error"] == 0 and m["impacts_missing"] == 0
    assert m["impact_time_error"] < 1e-5
    assert m["restitution"] == pytest.approx(1.0, abs=1e-3)
    assert m["energy_balance_error"] < 1e-8
    assert m["steps"] == 70000 and m["wall_time_s"] > 0


def test_physics_digest_ignores_the_analysis_and_sees_the_contacts():
    base = load(P2 / "p2_penalty_hertz.toml")
    import tomllib
    d = tomllib.loads((P2 / "p2_penalty_hertz.toml").read_text())
    d2 = copy.deepcopy(d)
    d2["analysis"].update(dt=1e-4, integrator="central-difference")
    d2["analysis"].pop("preset")
    assert physics_digest(from_dict(d2)) == physics_digest(base)
    d3 = copy.deepcopy(d)
    d3["contact"][0]["stiffness"] = 2e6
    assert physics_digest(from_dict(d3)) != physics_digest(base)


def test_reference_for_scene_chooses_data_closed_form_or_nothing():
    hertz = reference_for_scene(load(P2 / "p2_penalty_hertz.toml"))
    assert hertz.kind == "data" and hertz.name == "reference/p2_penalty_hertz"
    kelvin = reference_for_scene(load(P2 / "p2_penalty_kelvin.toml"))
    assert kelvin.kind == "closed-form"
    sdof = reference_for_scene(load(ROOT / "benchmarks" / "sdof" / "sdof_sine_newmark.toml"))
    assert sdof.kind == "closed-form" and "u:m" in sdof.columns
    d = two_bodies("kelvin", 1e4, restitution=0.5, analysis=dynamic(t_end=0.1))
    assert reference_for_scene(from_dict(d)) is None     # no [check], no data
    with pytest.raises(ReferenceError, match="no closed-form history named"):
        closed_form_reference("nope", {}, 1.0)


def test_a_plan_point_contact_is_scored_from_its_row():
    """A contact between plan points (docs/buildings.md) has no nodes a, b: a history without
    its penetration column is scored from the row Σ c·u of the floors' columns (martello
    compare on another code's history of a building scene). Here martello's own history with
    the contact's columns dropped: the penetration rebuilt from the row equals the recorded
    one to rounding and the impacts are those of the run (identity of the method)."""
    from martello.run import run_full
    from tests.test_export import small_buildings
    scene = from_dict(small_buildings(t_end=0.3), source="sb")
    summary, (cols, data) = run_full(scene)
    cols = list(cols)
    keep = [k for k, c in enumerate(cols) if not c.endswith(":g")]
    rebuilt = summary_from_history(scene, ([cols[k] for k in keep], data[:, keep]))["contacts"]["g"]
    recorded = summary_from_history(scene, (cols, data))["contacts"]["g"]
    assert rebuilt["impacts"] == recorded["impacts"] == summary["contacts"]["g"]["impacts"] == 2
    assert rebuilt["impact_times"] == pytest.approx(recorded["impact_times"], abs=1e-3)   # one step
    # δ = g·u − gap in two orders of summation: rounding of u (~0.07 m) only
    assert rebuilt["max_penetration"] == pytest.approx(recorded["max_penetration"], abs=1e-15)
