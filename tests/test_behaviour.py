"""The items of docs/behaviour.md that no other test exercised, tested through the command
line only (`python -m martello run|check`), so that they keep working while the package is
restructured. Each oracle is independent of the code: a closed form, a physical bound, or the
rule the page states. Every tolerance says where it comes from."""

import csv
import json
import math
import subprocess
import sys
from pathlib import Path

import pytest

from benchmarks.fuzz.mutations import toml_value as _value

ROOT = Path(__file__).resolve().parent.parent
EPS = 2.0 ** -52          # double-precision machine epsilon


# --- a scene as a dict -> TOML text -> the CLI -----------------------------------------------

def _is_table_array(v):
    return isinstance(v, list) and v and all(isinstance(x, dict) for x in v)


def _table(lines, prefix, d):
    """Scalars first, then sub-tables and arrays of tables (TOML's order rule)."""
    for k, v in d.items():
        if not isinstance(v, dict) and not _is_table_array(v):
            lines.append(f"{k} = {_value(v)}")
    for k, v in d.items():
        name = f"{prefix}.{k}" if prefix else k
        if isinstance(v, dict):
            lines.append(f"[{name}]")
            _table(lines, name, v)
        elif _is_table_array(v):
            for item in v:
                lines.append(f"[[{name}]]")
                # inside an array of tables, a nested table is written inline
                for ik, iv in item.items():
                    lines.append(f"{ik} = {_value(iv)}")


def to_toml(scene):
    lines = []
    _table(lines, "", scene)
    return "\n".join(lines) + "\n"


def cli(*args, cwd=ROOT):
    return subprocess.run([sys.executable, "-m", "martello", *map(str, args)], cwd=cwd,
                          capture_output=True, text=True)


def run_scene(tmp_path, scene, name="scene", expect_ok=True):
    """Write the scene, `martello run` it; return (process, summary or None, history or None).
    history maps each column name to its list of values."""
    f = tmp_path / f"{name}.toml"
    f.write_text(scene if isinstance(scene, str) else to_toml(scene))
    out = tmp_path / f"out_{name}"
    r = cli("run", f, "-o", out)
    if expect_ok:
        assert r.returncode == 0, r.stderr
    summary = json.loads((out / "summary.json").read_text()) if (out / "summary.json").exists() else None
    hist = None
    if (out / "history.csv").exists():
        with open(out / "history.csv") as fh:
            rows = list(csv.reader(fh))
        hist = {c: [float(row[i]) for row in rows[1:]] for i, c in enumerate(rows[0])}
    return r, summary, hist


def sdof(m=1.0, k=100.0, v0=0.0, **node):
    return {"node": [dict({"name": "m", "mass": m, "v0": v0}, **node)],
            "link": [{"name": "spring", "type": "spring", "a": "m", "b": "ground", "k": k}]}


def dynamic(integrator="newmark", dt=1e-3, t_end=0.1, **keys):
    return dict({"type": "dynamic", "integrator": integrator, "dt": dt, "t_end": t_end}, **keys)


def p2_penalty(eps=1e6, **analysis):
    """P2 of docs/problems.md: m = 1 kg on k = 100 N/m released at u = 0, gravity 9.81 m/s²,
    a linear penalty plane ε at h = 0.05 m."""
    d = sdof()
    d["contact"] = [{"name": "plane", "a": "m", "b": "ground", "gap": 0.05, "scheme": "penalty",
                     "stiffness": eps}]
    d["loads"] = {"gravity": 9.81}
    d["analysis"] = dynamic(**analysis)
    return d


def p2_first_peak_penetration(m=1.0, k=100.0, h=0.05, g=9.81, eps=1e6):
    """Closed form (docs/problems.md P2): flight u = u_s(1 − cos ωt) reaches the plane with
    v₁ = u_s ω sin(ω t₁); in contact δ = u − h obeys m δ̈ = m g − k h − (k + ε) δ, a harmonic
    motion about δ_eq = (m g − k h)/(k + ε) with amplitude √(δ_eq² + v₁²/ω_c²)."""
    w, us = math.sqrt(k / m), m * g / k
    t1 = math.acos(1.0 - h / us) / w
    v1 = us * w * math.sin(w * t1)
    wc = math.sqrt((k + eps) / m)
    d_eq = (m * g - k * h) / (k + eps)
    return d_eq + math.sqrt(d_eq ** 2 + (v1 / wc) ** 2)


# --- static runs -----------------------------------------------------------------------------

def test_static_run_evaluates_forces_at_t_zero(tmp_path):
    """A sine of zero phase is 0 at t = 0 and a rectangular pulse from t_start = 0 is its
    amplitude: u = F_rect/k exactly (one division: correctly rounded, so compared exactly).
    Only the inputs named in the rule appear in the warning; the restitution of a contact that
    is never reached is ignored without a word."""
    d = sdof(k=200.0, v0=0.3)
    d["link"].append({"type": "dashpot", "a": "m", "b": "ground", "c": 5.0})
    d["contact"] = [{"name": "far", "a": "m", "b": "ground", "gap": 10.0, "scheme": "lagrange",
                     "restitution": 0.5}]
    d["loads"] = {"force": [
        {"node": "m", "function": {"type": "sine", "amplitude": 7.0, "omega": 3.0}},
        {"node": "m", "function": {"type": "rectangular", "amplitude": 4.0, "t_end": 0.5}}]}
    d["analysis"] = {"type": "static"}
    r, s, _ = run_scene(tmp_path, d)
    assert s["nodes"]["m"]["u"] == 4.0 / 200.0
    assert s["warnings"] == ["static analysis ignores: dashpots and fluid dampers, initial velocities, "
                             "time dependence of nodal forces (evaluated at t = 0)"]
    assert "warning: static analysis ignores" in r.stderr


def test_mass_couplings_load_a_static_run_through_gravity(tmp_path):
    """Gravity is M·1·g (docs/scene-input.md): a coupling c between m1 and m2 adds c·g to
    both rows, so u_i = (m_i + c) g / k_i. Two springs to ground, no contact: each u is one
    product and one division, compared to 4 ulps."""
    d = {"node": [{"name": "m1", "mass": 1.0}, {"name": "m2", "mass": 2.0}],
         "link": [{"type": "spring", "a": "m1", "b": "ground", "k": 100.0},
                  {"type": "spring", "a": "m2", "b": "ground", "k": 300.0}],
         "mass_coupling": [{"a": "m1", "b": "m2", "value": 0.5}],
         "loads": {"gravity": 10.0}, "analysis": {"type": "static"}}
    _, s, _ = run_scene(tmp_path, d)
    assert s["nodes"]["m1"]["u"] == pytest.approx(1.5 * 10.0 / 100.0, rel=4 * EPS)
    assert s["nodes"]["m2"]["u"] == pytest.approx(2.5 * 10.0 / 300.0, rel=4 * EPS)
    assert s["warnings"] == []


def test_contact_without_a_free_side_carries_no_static_force(tmp_path):
    """A fixed node overlapping a wall: no free degree of freedom can carry the force, so the
    contact is reported active with force 0 and its penetration u0 − gap (exact)."""
    d = {"node": [{"name": "support", "mass": 0.0, "fixed": True, "u0": 0.01},
                  {"name": "m", "mass": 1.0}],
         "link": [{"type": "spring", "a": "m", "b": "ground", "k": 100.0}],
         "contact": [{"name": "c", "a": "support", "b": "ground", "gap": 0.004, "scheme": "lagrange"}],
         "analysis": {"type": "static"}}
    _, s, _ = run_scene(tmp_path, d)
    c = s["contacts"]["c"]
    assert c["active"] is True and c["force"] == 0.0 and c["lambda"] == 0.0
    assert c["penetration"] == pytest.approx(0.01 - 0.004, rel=4 * EPS)


def test_lost_digits_are_capped_at_double_precision(tmp_path):
    """P1 with ε/k = 1e16: a warning, not an error; the summary is written and digits_lost is
    capped at −log10(ε_mach) = 15.654 (the digits a double has, 52·log10 2)."""
    d = sdof()
    d["contact"] = [{"name": "plane", "a": "m", "b": "ground", "gap": 0.05, "scheme": "penalty",
                     "stiffness": 1e18}]
    d["loads"] = {"gravity": 9.81}
    d["analysis"] = {"type": "static"}
    r, s, _ = run_scene(tmp_path, d)
    assert s["status"] == "MARTELLO_ILL_CONDITIONED" and "ill-conditioned" in r.stderr
    assert s["conditioning"]["digits_lost"] == pytest.approx(52 * math.log10(2.0), rel=1e-12)


# --- contact laws and schemes -------------------------------------------------------------------

def _hc_realised_e(a):
    """Realised restitution of F = K δ^n (1 + χ δ̇) with a = χ v₀ (docs/problems.md P5): the
    root e in (0, 1) of (1 + e) a = ln[(1 + a)/(1 − e a)], by bisection: the residual
    (1 + e) a − ln[(1 + a)/(1 − e a)] is a − ln(1 + a) > 0 at e = 0 and changes sign once."""
    f = lambda e: (1.0 + e) * a - math.log((1.0 + a) / (1.0 - e * a))
    lo, hi = 0.0, min(1.0, 1.0 / a)
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if f(mid) > 0 else (lo, mid)
    return 0.5 * (lo + hi)


def test_penalty_restitution_is_the_published_damping_not_the_target(tmp_path):
    """Hunt–Crossley with target e = 0.5 gets a = 3(1 − e)/2 = 0.75, which realises 0.66296
    by the exact relation, not 0.5. The run (free two-body impact, Newmark at ωh ≈ 1.2e-4,
    force continuous at δ = 0) matches the relation to O((ωh)²) ≈ 1e-8; 1e-6 leaves room."""
    d = {"node": [{"name": "m1", "mass": 1.0, "v0": 1.0}, {"name": "m2", "mass": 2.0}],
         "contact": [{"name": "impact", "a": "m1", "b": "m2", "gap": 1e-3, "scheme": "penalty",
                      "law": "hunt-crossley", "stiffness": 1e8, "restitution": 0.5}],
         "analysis": dynamic(dt=1e-7, t_end=5e-3, output={"every": 1000})}
    _, s, _ = run_scene(tmp_path, d)
    e_real = s["contacts"]["impact"]["restitution"][0]
    assert e_real == pytest.approx(_hc_realised_e(0.75), abs=1e-6)
    assert e_real - 0.5 > 0.16


@pytest.mark.parametrize("integrator,dt", [("moreau-jean", 3e-4), ("newmark-lagrange", 3e-4),
                                           ("rk8pd", 1e-3), ("ida", 1e-3)])
def test_lagrange_contact_without_restitution_is_plastic(tmp_path, integrator, dt):
    """Newton's law with e = 0: m1 = 1 kg at 1 m/s hits m2 = 3 kg at rest; both leave at the
    common velocity m1 v0/(m1 + m2) = 0.25 m/s (momentum conserved, relative velocity 0).
    Free flight before and after is exact for every scheme, so the velocities carry only the
    rounding of the impulse and of the steps after it: 1e-9 m/s is far above that (IDA: its
    Newton tolerance on v, rtol·|v| ~ 1e-9 at rtol = 1e-8) and far below the 0.25 m/s a
    restitution e > 0 would separate them by."""
    d = {"node": [{"name": "m1", "mass": 1.0, "v0": 1.0}, {"name": "m2", "mass": 3.0}],
         "contact": [{"name": "c", "a": "m1", "b": "m2", "gap": 1e-3, "scheme": "lagrange"}],
         "analysis": dynamic(integrator, dt=dt, t_end=0.01)}
    _, s, h = run_scene(tmp_path, d)
    assert h["v:m1"][-1] == pytest.approx(0.25, abs=1e-9)
    assert h["v:m2"][-1] == pytest.approx(0.25, abs=1e-9)


def test_gsl_impact_max_force_is_the_impulse(tmp_path):
    """On the event-driven integrators an instantaneous impact has no finite force: its
    phase_max_force is the impulse P = (1 + e) m* v₀ in N·s (Newton's law, docs/problems.md
    P5). m* = 2/3 kg, v₀ = 1 m/s, e = 0.5: P = 1 N·s; one division of the gap rate by the
    Delassus number, ≤ 4 ulps measured (docs/event-driven.md), asserted at 1e-12."""
    d = {"node": [{"name": "m1", "mass": 1.0, "v0": 1.0}, {"name": "m2", "mass": 2.0}],
         "contact": [{"name": "c", "a": "m1", "b": "m2", "gap": 1e-3, "scheme": "restitution",
                      "restitution": 0.5}],
         "analysis": dynamic("rk8pd", dt=1e-3, t_end=0.01, rtol=1e-12, atol=1e-14)}
    _, s, _ = run_scene(tmp_path, d)
    c = s["contacts"]["c"]
    assert c["impacts"] == 1 and c["impact_times"][0] == c["separation_times"][0]
    assert c["phase_max_force"][0] == pytest.approx((1 + 0.5) * (2.0 / 3.0) * 1.0, rel=1e-12)
    assert c["restitution"][0] == pytest.approx(0.5, rel=1e-12)


# --- time grid, events, output -------------------------------------------------------------

def test_fixed_steps_overrun_t_end_that_is_not_a_multiple_of_dt(tmp_path):
    """Free flight at 1 m/s, dt = 0.3 s, t_end = 1.0 s: ceil(1.0/0.3) = 4 whole steps, so the
    run ends at 1.2 s, and says so (t_reached and the last history row). Free flight is exact
    for Newmark: u = 1.2 m to a few roundings of 4 steps (1e-14)."""
    d = {"node": [{"name": "m", "mass": 1.0, "v0": 1.0}], "analysis": dynamic(dt=0.3, t_end=1.0)}
    _, s, h = run_scene(tmp_path, d)
    assert s["cost"]["steps"] == 4
    assert s["t_reached"] == pytest.approx(1.2, abs=1e-14)
    assert h["t"][-1] == pytest.approx(1.2, abs=1e-14)
    assert s["nodes"]["m"]["u_final"] == pytest.approx(1.2, abs=1e-14)


def test_contact_closed_at_t_zero_opens_a_phase_at_t_zero(tmp_path):
    """gap = −1 mm: δ(0) = 1 mm > 0. The first phase starts at t = 0 exactly with the
    'approach speed' δ̇(0) = v0 = 0.5 m/s (not located: nothing approached); it counts in
    impacts but not in cost.events, which counts located onsets."""
    d = sdof(v0=0.5)
    d["contact"] = [{"name": "w", "a": "m", "b": "ground", "gap": -1e-3, "scheme": "penalty",
                     "stiffness": 1e4}]
    d["analysis"] = dynamic(dt=1e-4, t_end=0.5)
    _, s, _ = run_scene(tmp_path, d)
    c = s["contacts"]["w"]
    assert c["impact_times"][0] == 0.0 and c["approach_speeds"][0] == 0.5
    assert c["impacts"] == len(c["impact_times"]) >= 2
    assert s["cost"]["events"] == c["impacts"] - 1


def test_open_phase_at_t_end_has_no_separation(tmp_path):
    """Linear penalty between m1 = 1 kg at 1 m/s and m2 = 2 kg: contact from 1 ms for
    π√(m*/k) = 2.565 ms (k = 1e6 N/m, m* = 2/3 kg). Ending at 2 ms leaves it open: one onset,
    separation_times [null], no separation speed, no restitution, no contact_time."""
    d = {"node": [{"name": "m1", "mass": 1.0, "v0": 1.0}, {"name": "m2", "mass": 2.0}],
         "contact": [{"name": "impact", "a": "m1", "b": "m2", "gap": 1e-3, "scheme": "penalty",
                      "stiffness": 1e6}],
         "analysis": dynamic(dt=1e-6, t_end=2e-3)}
    assert math.pi * math.sqrt((2.0 / 3.0) / 1e6) > 1e-3
    _, s, _ = run_scene(tmp_path, d)
    c = s["contacts"]["impact"]
    assert c["impacts"] == 1 and c["separation_times"] == [None]
    assert len(c["approach_speeds"]) == len(c["phase_max_force"]) == 1
    assert c["separation_speeds"] == [] and c["restitution"] == []
    assert "contact_time" not in c


def test_output_defaults_of_a_large_scene(tmp_path):
    """51 oscillators (more than 50 nodes) and 50 contacts: no node is recorded unless
    listed, all 50 contacts are; links only if listed. u_final exists only for recorded
    nodes, but peaks exist for every node."""
    d = {"chain": [{"prefix": "b", "n": 51, "mass": 1.0, "k": 100.0, "gap": 0.01,
                    "contact": {"scheme": "penalty", "stiffness": 1e4}}],
         "analysis": dynamic(dt=1e-3, t_end=0.01)}
    _, s, h = run_scene(tmp_path, d)
    assert not any(c.startswith(("u:", "v:", "a:", "link_force:")) for c in h)
    assert sum(c.startswith("penetration:") for c in h) == 50
    assert "u_final" not in s["nodes"]["b1"] and "u_max" in s["nodes"]["b51"]
    d["analysis"]["output"] = {"nodes": ["b7"], "links": ["b7.spring"]}
    _, s, h = run_scene(tmp_path, d, name="listed")
    assert [c for c in h if c.startswith("u:")] == ["u:b7"] and "link_force:b7.spring" in h
    assert "u_final" in s["nodes"]["b7"] and "u_final" not in s["nodes"]["b8"]


def test_u_peak_is_absent_when_u_never_turns_back(tmp_path):
    """Free flight has no local maximum: no u_peak. An undamped SDOF from u = 0 at v0 has
    its first maximum v0/ω at t = π/(2ω) (ω = 10 rad/s: 0.1 m at 0.15708 s); the interpolated
    peak is O(h²): at ωh = 1e-3 the value is within (ωh)²·v0/ω ≈ 1e-7 m, asserted at 1e-6."""
    d = {"node": [{"name": "m", "mass": 1.0, "v0": 1.0}], "analysis": dynamic(dt=1e-2, t_end=0.5)}
    _, s, _ = run_scene(tmp_path, d)
    assert "u_peak" not in s["nodes"]["m"] and "t_peak" not in s["nodes"]["m"]
    d = sdof(v0=1.0)
    d["analysis"] = dynamic(dt=1e-4, t_end=0.3)
    _, s, _ = run_scene(tmp_path, d, name="sdof")
    assert s["nodes"]["m"]["u_peak"] == pytest.approx(0.1, rel=1e-6)
    assert s["nodes"]["m"]["t_peak"] == pytest.approx(math.pi / 20.0, rel=1e-6)


@pytest.mark.parametrize("integrator", ["newmark", "rk8pd", "ida"])
def test_every_integrator_reports_link_states(tmp_path, integrator):
    """Every integrator reports link states (the observer samples them at each accepted
    step): the spring's peak force is k·v0/ω = 10 N. The maximum is taken over steps, not
    located: with steps h ≤ 1e-3 s at ω = 10 rad/s a sample misses the crest by at most
    1 − cos(ωh/2) ≈ (ωh)²/8 = 1.25e-5 relative (plus the method's own error, ≤ 1e-6 here),
    so 2e-5 is asserted; the history columns are finite."""
    d = sdof(v0=1.0)
    if integrator == "newmark":
        d["analysis"] = dynamic("newmark", dt=1e-4, t_end=0.5, output={"links": ["spring"]})
    else:
        d["analysis"] = dynamic(integrator, dt=1e-2, t_end=0.5, h_max=1e-3, rtol=1e-10,
                                atol=1e-12, output={"links": ["spring"]})
    _, s, h = run_scene(tmp_path, d)
    assert s["links"]["spring"]["max_abs_force"] == pytest.approx(10.0, rel=2e-5)
    assert s["links"]["spring"]["max_abs_elongation"] == pytest.approx(0.1, rel=2e-5)
    assert all(math.isfinite(x) for x in h["link_force:spring"])


# --- energy, stability, divergence -------------------------------------------------------------

def test_balance_max_is_taken_on_the_energy_grid_whatever_is_recorded(tmp_path):
    """The fixed-step integrators evaluate the energy terms at every 16th step, at t = 0 and
    at the end (the energy grid), and at the recorded rows; balance_max is the largest
    |balance| on the grid alone, so output.every does not move it (docs/invariance.md). With
    rows every 16 steps the history holds the grid exactly, and balance_max is the largest
    |energy:balance| of history.csv; with rows every 37 steps the same number (a recorded row
    between grid points may show a larger |balance|). θ = 1 on P2's Kelvin scene makes
    Moreau–Jean's balance non-trivial (the linearised Kelvin force jump), HHT's numerical
    damping HHT's."""
    base = p2_penalty(dt=1e-4, t_end=0.3)
    base["contact"][0].update(law="kelvin", restitution=0.8)
    for integrator, keys in (("moreau-jean", {"theta": 1.0}), ("hht", {"alpha": -0.3})):
        got = {}
        for every in (16, 37):
            base["analysis"] = dynamic(integrator, dt=1e-4, t_end=0.3, output={"every": every}, **keys)
            _, s, h = run_scene(tmp_path, base, name=f"{integrator}_{every}")
            got[every] = s["energy"]["balance_max"], max(abs(x) for x in h["energy:balance"])
        assert got[16][0] == got[16][1] > 0, got
        assert got[37][0] == got[16][0], got


def test_energy_balance_above_one_percent_is_a_warning(tmp_path):
    """The rule: a completed run whose balance_relative exceeds 1e-2 carries a warning (and
    prints it), with status OK. HHT α = −1/3 at ωh = 0.5 dissipates a large share of a free
    SDOF's energy (its numerical damping); at ωh = 1e-3 it dissipates almost none."""
    for name, dt in (("coarse", 0.05), ("fine", 1e-4)):
        d = sdof(v0=1.0)
        d["analysis"] = dynamic("hht", dt=dt, t_end=5.0, alpha=-1.0 / 3.0)
        r, s, _ = run_scene(tmp_path, d, name=name)
        warned = any("energy balance error" in w for w in s["warnings"])
        assert s["status"] == "MARTELLO_OK"
        assert warned == (s["energy"]["balance_relative"] > 1e-2) == (name == "coarse")
        assert warned == ("warning: energy balance error" in r.stderr)


def test_central_difference_past_its_limit_fails_when_its_contacts_create_energy(tmp_path):
    """check_stability = false at dt = 2.5e-3 s on P2's penalty plane (Δt_crit = 2/ω_max =
    1.9999e-3 s, ω_max = √((k + ε)/m)): the run goes past the limit, and its elastic contact
    gives back more energy than it took (the realised restitution exceeds 1): a failure, exit
    1 and nothing written, though the energy balance alone would not show it (central
    difference balances ½vᵀMv − (h²/8)aᵀMa to round-off at any step)."""
    d = p2_penalty(integrator="central-difference", dt=2.5e-3, t_end=0.5, check_stability=False)
    assert 2.5e-3 > 2.0 / math.sqrt((100.0 + 1e6) / 1.0)
    r, s, _ = run_scene(tmp_path, d, expect_ok=False)
    assert r.returncode == 1 and s is None
    assert "MARTELLO_ERR_DIVERGED" in r.stderr and "created energy at its contacts" in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize("law,damped", [("hertz", False), ("linear", False), ("linear", True)])
def test_stability_limit_leaves_out_hertz_contacts_and_damping(tmp_path, law, damped):
    """ω_max counts springs and linear/Kelvin contacts as closed, not Hertz-type ones, and no
    damping: with a Hertz plane Δt_crit = 2/√(k/m) = 0.2 s, with a linear one 2/√((k + ε)/m),
    with a dashpot of ζ = 0.5 as well still 2/√((k + ε)/m) (the damped explicit limit,
    (2/ω)(√(1 + ζ²) − ζ), would be lower). dsbgvx on a 1×1 problem: a few ulps, 1e-12."""
    d = p2_penalty(eps=1e4, integrator="central-difference", dt=1e-4, t_end=1e-3)
    d["contact"][0]["law"] = law
    if damped:
        d["link"].append({"type": "dashpot", "a": "m", "b": "ground", "zeta": 0.5})
    dt_crit = 2.0 / math.sqrt(100.0 + (1e4 if law == "linear" else 0.0))
    _, s, _ = run_scene(tmp_path, d)
    assert s["stability"]["dt_critical"] == pytest.approx(dt_crit, rel=1e-12)


def test_conditionally_stable_newmark_is_refused_past_its_limit(tmp_path):
    """β = 0.1, γ = ½ (2β < γ) is stable only for ω h ≤ 1/√(γ/2 − β) = 2.582 (Hughes 1987,
    §9.1). With ω_c = √((k + ε)/m) ≈ 1000 rad/s the limit is 2.58 ms: 5 ms is refused before
    its first step (MARTELLO_ERR_UNSTABLE naming dt_crit, exit 1, nothing written), with
    check_stability = false it runs and fails as diverged, and 0.2 ms runs (at 2 ms, below
    the limit, its contact realises e > 1: a failure too, docs/behaviour.md)."""
    h_crit = 1.0 / math.sqrt(0.5 / 2 - 0.1) / math.sqrt((100.0 + 1e6) / 1.0)
    d = p2_penalty(dt=5e-3, t_end=0.5, beta=0.1, gamma=0.5)
    assert 5e-3 > h_crit > 2e-3
    r, s, _ = run_scene(tmp_path, d, expect_ok=False)
    assert r.returncode == 1 and "MARTELLO_ERR_UNSTABLE" in r.stderr and s is None
    crit = float(r.stderr.split("dt_crit = 1/(omega_max sqrt(gamma/2 - beta)) = ")[1].split()[0])
    assert crit == pytest.approx(h_crit, rel=1e-5)       # printed to 6 digits
    d["analysis"]["check_stability"] = False
    r, s, _ = run_scene(tmp_path, d, expect_ok=False, name="unchecked")
    assert r.returncode == 1 and "MARTELLO_ERR_DIVERGED" in r.stderr and s is None
    d["analysis"]["dt"] = 2e-4
    d["analysis"]["check_stability"] = True
    _, s, _ = run_scene(tmp_path, d, name="stable")
    assert s["status"] == "MARTELLO_OK"
    assert s["stability"]["dt_critical"] == pytest.approx(h_crit, rel=1e-10)


@pytest.mark.parametrize("coupling,ok", [(1.3, True), (1.5, False)])
def test_mass_coupling_that_breaks_positive_definiteness_is_refused_at_run_time(tmp_path, coupling, ok):
    """M = [[m1, c], [c, m2]] is positive definite iff c² < m1 m2 = 2 kg². The loader accepts
    both; the dynamic run refuses c = 1.5 (c² = 2.25) and runs c = 1.3 (1.69)."""
    d = {"node": [{"name": "m1", "mass": 1.0, "v0": 1.0}, {"name": "m2", "mass": 2.0}],
         "mass_coupling": [{"a": "m1", "b": "m2", "value": coupling}],
         "analysis": dynamic(dt=1e-3, t_end=0.01)}
    assert (coupling ** 2 < 1.0 * 2.0) == ok
    r, s, _ = run_scene(tmp_path, d, expect_ok=False)
    if ok:
        assert r.returncode == 0 and s["status"] == "MARTELLO_OK"
    else:
        assert r.returncode == 1 and s is None
        assert "MARTELLO_ERR_ARGUMENT" in r.stderr and "not positive definite" in r.stderr


# --- generators, checks, records -------------------------------------------------------------

def test_check_paths_reach_names_with_dots(tmp_path):
    """A [[chain]] names its springs b1.spring: a [check] compares links.b1.spring.* all the
    same. One bilinear oscillator (chain of n = 1): its spring's largest elongation is the
    elasto-plastic peak u_max = 0.1066479 m (docs/problems.md P6). Newmark at dt = 1e-4 s:
    measured 2.1e-7 relative (docs/problems.md P6 scenes); rtol 2e-6."""
    text = to_toml({
        "chain": [{"prefix": "b", "n": 1, "mass": 1.0, "k": 100.0, "fy": 1.0, "hardening": 0.05,
                   "v0": 0.5}],
        "analysis": dynamic(dt=1e-4, t_end=1.0)})
    text += """
[check]
closed_form = "elastoplastic_peak"
params = { m = 1.0, k = 100.0, uy = 0.01, rho = 0.05, v0 = 0.5 }
[[check.compare]]
result = "links.b1.spring.max_abs_elongation"
oracle = "u_max"
rtol = 2e-6
why = "second order, step maxima at a smooth peak: measured 2e-7"
"""
    f = tmp_path / "dots.toml"
    f.write_text(text)
    r = cli("check", f, "-o", tmp_path / "check", "--no-plots")
    assert r.returncode == 0, r.stdout + r.stderr
    with open(tmp_path / "check" / "verification.csv") as fh:
        rows = list(csv.DictReader(fh))
    assert [row["quantity"] for row in rows] == ["links.b1.spring.max_abs_elongation"]
    assert rows[0]["passed"] == "True"


@pytest.mark.parametrize("chain,field", [
    ({"contact": {"name": "x", "scheme": "penalty", "stiffness": 1.0}}, "chain[0].contact.name"),
    ({"contact": {"gap": 0.1, "scheme": "penalty", "stiffness": 1.0}}, "chain[0].contact.gap"),
    ({"hardening": 0.1}, "chain[0].hardening"),
    ({"n": 1, "gap": 0.1}, "chain[0].gap"),
    ({"n": 1, "contact": {"scheme": "penalty", "stiffness": 1.0}}, "chain[0].contact"),
])
def test_chain_keys_it_would_ignore_are_errors(tmp_path, chain, field):
    """The rule: a chain key that could not take effect is refused, naming the field."""
    d = {"chain": [dict({"prefix": "b", "n": 3, "mass": 1.0, "k": 1.0}, **chain)],
         "analysis": dynamic()}
    r, s, _ = run_scene(tmp_path, d, expect_ok=False)
    assert r.returncode == 1 and s is None
    assert f"scene.toml: {field}: " in r.stderr, r.stderr


def test_record_is_read_at_run_time_relative_to_the_scene(tmp_path):
    """A `record` path is resolved against the scene's folder (the run starts elsewhere); the
    file is read when the model is built, even for a static run that then ignores the ground
    motion, so a malformed record fails `martello run` of a static scene."""
    folder = tmp_path / "scenes"
    (folder / "motions").mkdir(parents=True)
    (folder / "motions" / "good.csv").write_text("0.0, 0.0\n0.01, 0.5\n0.02, 0.0\n")
    (folder / "motions" / "bad.csv").write_text("0.0, 0.0\n0.01, x\n")
    for name, ok in (("good", True), ("bad", False)):
        d = sdof()
        d["loads"] = {"ground_acceleration": {"type": "record", "file": f"motions/{name}.csv"}}
        d["analysis"] = {"type": "static"}
        f = folder / f"{name}.toml"
        f.write_text(to_toml(d))
        r = cli("run", f, "-o", tmp_path / f"out_{name}", cwd=tmp_path)
        assert (r.returncode == 0) == ok, r.stderr
        if ok:
            s = json.loads((tmp_path / "out_good" / "summary.json").read_text())
            assert s["warnings"] == ["static analysis ignores: ground acceleration"]
        else:
            assert "bad.csv:2" in r.stderr and not (tmp_path / "out_bad").exists()
