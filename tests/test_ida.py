"""SUNDIALS IDA (docs/ida.md): penalty scenes as implicit ODEs, restarted at every contact
onset and separation of a law whose force jumps there and stepping across the others (their
events located inside the steps), Lagrange/restitution scenes as a stabilised index-2 DAE (GGL) with
IDA's root finding for impacts, closings and releases. Oracles: martello.oracles, coded
independently of the solvers.

Tolerances: IDA controls the local error to rtol·|y| + atol per step; what reaches an event
time is the global error of the flight before it, which accumulates over the steps and the
restarts. Each bound below is the measured error at the stated tolerance times a margin of
about ten (the measured values are in the comments and in docs/ida.md)."""

import math

import numpy as np
import pytest

from martello.checks.dispatchers import bouncing_kelvin_events, two_body_impact
from martello.errors import SolverError
from martello.oracles.p2_bouncing import bouncing_oscillator_restitution
from martello.oracles.p5_contact_laws import linear_contact_time, newton_impact
from tests.dynamics_helpers import dynamic, execute, two_bodies

M, K, H, G = 1.0, 100.0, 0.05, 9.81          # P2 of docs/problems.md


def ida(rtol=1e-10, atol=1e-14, dt=1e-3, t_end=0.7, **extra):
    return dynamic("ida", dt=dt, t_end=t_end, rtol=rtol, atol=atol, **extra)


def p2(contact, analysis, forces=()):
    c = {"name": "plane", "a": "mass", "b": "ground", "gap": H}
    c.update(contact)
    d = {"node": [{"name": "mass", "mass": M}],
         "link": [{"type": "spring", "a": "mass", "b": "ground", "k": K}],
         "contact": [c], "loads": {"gravity": G}, "analysis": analysis}
    if forces:
        d["loads"]["force"] = list(forces)
    return d


def rel(a, b):
    return abs(a - b) / abs(b)


# --- P2 with penalty: the piecewise-linear reference -------------------------------------------

def test_p2_penalty_linear_event_times():
    # Linear penalty eps/k = 1e4 against the exact piecewise-linear solution. The onset and
    # separation are roots of delta = u - h on IDA's interpolant and the integration restarts
    # there. Measured at rtol = 1e-10: impact and separation times 2.3e-9, peak penetration
    # 9.5e-9 (delta = u - h loses log10(u/delta) ~ 1.8 digits to cancellation).
    eps = 1e6
    s, _ = execute(p2({"scheme": "penalty", "law": "linear", "stiffness": eps}, ida()))
    assert s["status"] == "MARTELLO_OK"
    c = s["contacts"]["plane"]
    ref = bouncing_kelvin_events(M, K, H, G, eps, 3)
    for i in range(3):
        assert rel(c["impact_times"][i], ref[f"t_impact_{i}"]) < 3e-8
        assert rel(c["separation_times"][i], ref[f"t_separation_{i}"]) < 3e-8
        assert rel(c["phase_max_penetration"][i], ref[f"max_penetration_{i}"]) < 1e-7


def test_p2_penalty_kelvin_force_jump_is_not_stepped_across():
    # The Kelvin force jumps by c·delta' at delta = 0; fixed steps make an O(h) error there
    # (the Newmark scene needs 1e-5 for the 2nd impact), IDA restarts on the jump. Measured
    # 1.3e-9 on the first three impact and separation times at rtol = 1e-10.
    eps = 1e6
    s, _ = execute(p2({"scheme": "penalty", "law": "kelvin", "stiffness": eps, "restitution": 0.8}, ida()))
    c = s["contacts"]["plane"]
    ref = bouncing_kelvin_events(M, K, H, G, eps, 3, restitution=0.8)
    for i in range(3):
        assert rel(c["impact_times"][i], ref[f"t_impact_{i}"]) < 2e-8
        assert rel(c["separation_times"][i], ref[f"t_separation_{i}"]) < 2e-8


def test_p2_penalty_error_follows_the_tolerance():
    # The event-time error scales with rtol (the flights are smooth and the kinks are
    # restarts): measured 9.1e-8, 2.3e-9, 2.3e-11 at rtol 1e-8, 1e-10, 1e-12.
    ref = bouncing_kelvin_events(M, K, H, G, 1e6, 3)
    errs = []
    for rtol in (1e-8, 1e-12):
        s, _ = execute(p2({"scheme": "penalty", "law": "linear", "stiffness": 1e6},
                          ida(rtol=rtol, atol=rtol * 1e-4)))
        c = s["contacts"]["plane"]
        errs.append(max(rel(c["impact_times"][i], ref[f"t_impact_{i}"]) for i in range(3)))
    assert errs[0] < 1e-6 and errs[1] < 3e-10
    assert errs[0] / errs[1] > 1e2


# --- P2 with restitution and Lagrange: the index-2 DAE -----------------------------------------

def test_p2_restitution_impacts_zeno_and_resting_force():
    # e = 0.8: impact times and speeds against the closed form. Measured at rtol = 1e-12:
    # 1.2e-11 (times) and 9e-12 (speeds) on the first five. The impacts accumulate (Zeno);
    # the contact closes at the first impact whose next flight IDA does not resolve, and the
    # persistent phase starts at the predicted accumulation point (docs/impulse.md §4;
    # measured 2.3e-9 s from the closed form's, the error of the last impacts: bar 1e-6 s).
    e, rtol, atol = 0.8, 1e-12, 1e-16
    s, hist = execute(p2({"scheme": "restitution", "restitution": e}, ida(rtol, atol, t_end=1.6)))
    c = s["contacts"]["plane"]
    ref = bouncing_oscillator_restitution(M, K, H, G, e, 5)
    for i in range(5):
        assert rel(c["impact_times"][i], ref.t[i]) < 1e-10
        assert rel(c["approach_speeds"][i], ref.v[i]) < 1e-10
        assert c["restitution"][i] == pytest.approx(e, abs=1e-9)
    assert c["separation_times"][-1] is None                      # still closed at the end
    assert abs(c["persistent_from"] - ref.zeno_time) < 1e-6
    assert c["persistent_from"] == c["impact_times"][-1] > c["impact_times"][-2]
    # after t_inf the multiplier is the contact force m g - k h (P1, Lagrange)
    late = hist["t"] > ref.zeno_time
    assert np.all(np.abs(hist["force:plane"][late] / (M * G - K * H) - 1) < 1e-12)
    # all the kinetic energy of the first impact is lost in impacts
    assert rel(s["energy"]["impact"], 0.5 * M * ref.v[0] ** 2) < 1e-9
    assert s["energy"]["balance_relative"] < 1e-9


def test_p2_lagrange_sticks_at_first_impact():
    # Lagrange, e = 0 (default): plastic impact at t1, then the constraint holds and the
    # multiplier is k h - m g in the seed's sign (4.81 N compression). The static phase is
    # linear in P: the Newton solve is exact, measured error 0 (bar 1e-12 relative).
    s, hist = execute(p2({"scheme": "lagrange"}, ida(t_end=1.0)))
    c = s["contacts"]["plane"]
    ref = bouncing_oscillator_restitution(M, K, H, G, 0.0, 1)
    # the plastic impact (an impulse) and the persistent phase from it (a force): two events
    # at t1, as on the event-driven integrator (docs/impulse.md §4)
    assert c["impacts"] == 2 and c["separation_times"] == [c["impact_times"][0], None]
    assert c["impact_times"][1] == c["impact_times"][0] == c["persistent_from"]
    assert rel(c["impact_times"][0], ref.t[0]) < 3e-9            # measured 2.3e-10
    after = hist["t"] > ref.t[0] + 1e-9
    assert np.all(np.abs(hist["force:plane"][after] / abs(K * H - M * G) - 1) < 1e-12)
    assert np.all(hist["u:mass"][after] == pytest.approx(H, abs=1e-15))
    assert np.all(np.abs(hist["v:mass"][after]) < 1e-14)
    assert s["contacts"]["plane"]["max_force"] == pytest.approx(M * G - K * H, rel=1e-12)


def test_p2_lagrange_release_when_the_multiplier_turns_tensile():
    # A pull -10 sin(pi (t - 0.3)/0.4) N on the resting mass: the contact force
    # m g - k h + F(t) reaches 0 at t_r = 0.3 + 0.4 asin(4.81/10)/pi, a root of P that
    # releases the constraint. Measured 1.9e-9 s at rtol = 1e-10.
    pull = {"node": "mass", "function": {"type": "half_sine", "amplitude": -10.0,
                                         "t_start": 0.3, "t_end": 0.7}}
    s, _ = execute(p2({"scheme": "lagrange"}, ida(t_end=0.6), forces=[pull]))
    c = s["contacts"]["plane"]
    t_release = 0.3 + 0.4 * math.asin((M * G - K * H) / 10.0) / math.pi
    # event 0 is the plastic impact, event 1 the persistent phase it starts
    assert c["separation_times"][1] == pytest.approx(t_release, abs=2e-8)
    assert c["phase_max_force"][1] == pytest.approx(M * G - K * H, rel=1e-12)


# --- P5: two bodies ------------------------------------------------------------------------------

@pytest.mark.parametrize("law,k,e", [("linear", 1e6, None), ("kelvin", 1e6, 0.5),
                                     ("hertz", 1e9, None), ("hunt-crossley", 1e9, 0.8)])
def test_p5_penalty_laws(law, k, e):
    # P5 closed forms at rtol = 1e-10 (atol 1e-15): measured <= 2e-9 on e, contact time and
    # peak penetration for all four laws (linear: contact time pi sqrt(m*/k) to 1.5e-11).
    # The Kelvin law's force jump, O(h) for fixed steps (the catalogue's Newmark scene
    # states 5e-4), is a restart here.
    extra = {} if e is None else {"restitution": e}
    s, _ = execute(two_bodies(law, k, 1.0, 2.0, 1.0, gap=1e-3,
                              analysis=ida(rtol=1e-10, atol=1e-15, dt=1e-4, t_end=5e-3), **extra))
    c = s["contacts"]["impact"]
    ref = two_body_impact(law, 1.0, 2.0, 1.0, k, restitution=e)
    assert c["impacts"] == 1
    assert c["restitution"][0] == pytest.approx(ref["restitution"], rel=2e-8)
    if "contact_time" in ref:
        assert c["contact_time"] == pytest.approx(ref["contact_time"], rel=2e-8)
    if "max_penetration" in ref:
        assert c["max_penetration"] == pytest.approx(ref["max_penetration"], rel=2e-8)


def test_p5_linear_contact_time():
    # The P5 check (docs/problems.md): pi sqrt(m*/k), m* = 2/3, k = 1e6. Measured 1.5e-11 at
    # rtol 1e-10.
    s, _ = execute(two_bodies("linear", 1e6, 1.0, 2.0, 1.0, gap=1e-3,
                              analysis=ida(rtol=1e-10, atol=1e-15, dt=1e-4, t_end=5e-3)))
    assert s["contacts"]["impact"]["contact_time"] == pytest.approx(
        linear_contact_time(2.0 / 3.0, 1e6), rel=1e-9)


@pytest.mark.parametrize("e", [0.0, 0.3, 1.0])
@pytest.mark.parametrize("m2", [1e-6, 1.0, 1e6])
def test_p5_newton_velocities(e, m2):
    # Newton's law applied as one impulse at the located impact: velocities exact to round-off
    # (the flight is uniform motion), energy lost = the kinetic-energy jump.
    scheme = {"scheme": "lagrange"} if e == 0.0 else {"scheme": "restitution", "restitution": e}
    d = {"node": [{"name": "m1", "mass": 1.0, "v0": 1.0}, {"name": "m2", "mass": m2, "v0": -0.5}],
         "contact": [{"name": "impact", "a": "m1", "b": "m2", "gap": 1e-3, **scheme}],
         "analysis": ida(rtol=1e-12, atol=1e-15, dt=1e-4, t_end=2e-3)}
    s, _ = execute(d)
    ref = newton_impact(1.0, m2, 1.0, -0.5, e)
    assert s["contacts"]["impact"]["impacts"] == 1
    assert s["nodes"]["m1"]["v_final"] == pytest.approx(ref.v1, rel=1e-12, abs=1e-15)
    assert s["nodes"]["m2"]["v_final"] == pytest.approx(ref.v2, rel=1e-12, abs=1e-15)
    kinetic = 0.5 * 1.0 * 1.0 ** 2 + 0.5 * m2 * 0.5 ** 2   # round-off of the energy difference
    assert s["energy"]["impact"] == pytest.approx(ref.energy_lost, rel=1e-8, abs=64 * 2.2e-16 * kinetic)


def test_simultaneous_impacts_follow_the_impulse_lcp():
    # Three equal balls, e = 1, the last two touching: the impact is resolved for every
    # contact at zero gap at once (impulse-level LCP, docs/ida.md), which gives
    # (-1/3, 2/3, 2/3) -- momentum and energy conserved -- and not the sequential (0, 0, 1).
    d = {"node": [{"name": "b1", "mass": 1.0, "v0": 1.0}, {"name": "b2", "mass": 1.0},
                  {"name": "b3", "mass": 1.0}],
         "contact": [{"name": "c12", "a": "b1", "b": "b2", "gap": 1e-3, "scheme": "restitution",
                      "restitution": 1.0},
                     {"name": "c23", "a": "b2", "b": "b3", "gap": 0.0, "scheme": "restitution",
                      "restitution": 1.0}],
         "analysis": ida(dt=1e-3, t_end=1e-2)}
    s, _ = execute(d)
    v = [s["nodes"][b]["v_final"] for b in ("b1", "b2", "b3")]
    assert v == pytest.approx([-1 / 3, 2 / 3, 2 / 3], abs=1e-14)
    assert sum(v) == pytest.approx(1.0, abs=1e-14)
    assert s["energy"]["impact"] == pytest.approx(0.0, abs=1e-14)


def test_stacked_lagrange_contacts_settle_on_the_static_multipliers():
    # Three masses on springs fall under gravity onto each other and the ground (Lagrange,
    # one restitution contact): several constraints close at once (coupled through the
    # Delassus matrix), and at rest the multipliers are the static forces
    # P12 = m1 g - k1 u1, P23 = P12 + m2 g - k2 u2, P3g = P23 + m3 g - k3 u3.
    d = {"node": [{"name": "m1", "mass": 1.0}, {"name": "m2", "mass": 2.0}, {"name": "m3", "mass": 1.0}],
         "link": [{"type": "spring", "a": "m1", "b": "ground", "k": 100.0},
                  {"type": "spring", "a": "m2", "b": "ground", "k": 300.0},
                  {"type": "spring", "a": "m3", "b": "ground", "k": 200.0}],
         "contact": [{"name": "c12", "a": "m1", "b": "m2", "gap": 0.01, "scheme": "lagrange"},
                     {"name": "c23", "a": "m2", "b": "m3", "gap": 0.01, "scheme": "restitution",
                      "restitution": 0.5},
                     {"name": "c3g", "a": "m3", "b": "ground", "gap": 0.02, "scheme": "lagrange"}],
         "loads": {"gravity": G}, "analysis": ida(t_end=2.0)}
    s, hist = execute(d)
    u = [0.04, 0.03, 0.02]
    p12 = 1.0 * G - 100.0 * u[0]
    p23 = p12 + 2.0 * G - 300.0 * u[1]
    p3g = p23 + 1.0 * G - 200.0 * u[2]
    for name, p in (("c12", p12), ("c23", p23), ("c3g", p3g)):
        assert hist[f"force:{name}"][-1] == pytest.approx(p, rel=1e-9)
    assert s["energy"]["balance_relative"] < 1e-8


# --- P7: two oscillators, IDA against Newmark ------------------------------------------------------

def test_p7_two_oscillators_ida_against_newmark():
    # benchmarks/p7/p7_two_oscillators.toml (Kelvin contact, ground sine), 13 contacts in 4 s.
    # IDA at rtol = 1e-10 is converged to 1e-7 (against 1e-12). Newmark with Kelvin makes an
    # O(xi w_c h) rebound error at each force jump (xi w_c h = 6e-4 at h = 1e-5) whose sign
    # depends on where delta = 0 falls in the step, amplified by a 0.03 mm third contact:
    # measured 1.8e-3 of the peak displacement at h = 1e-5 (9e-4 at 2e-6): bar 5e-3.
    import tomllib
    from pathlib import Path
    path = Path(__file__).resolve().parent.parent / "benchmarks" / "p7" / "p7_two_oscillators.toml"
    raw = tomllib.loads(path.read_text())
    raw["analysis"] = ida(t_end=4.0)
    s_ida, h_ida = execute(dict(raw))
    raw["analysis"] = dynamic("newmark", dt=1e-5, t_end=4.0, every=100)
    s_nm, h_nm = execute(dict(raw))
    assert np.allclose(h_ida["t"], h_nm["t"], rtol=0, atol=1e-12)
    c_ida, c_nm = s_ida["contacts"]["s1-s2"], s_nm["contacts"]["s1-s2"]
    assert c_ida["impacts"] == c_nm["impacts"] == 13
    assert rel(c_nm["impact_times"][0], c_ida["impact_times"][0]) < 1e-8   # before any jump
    for node in ("s1", "s2"):
        scale = np.max(np.abs(h_ida[f"u:{node}"]))
        assert np.max(np.abs(h_ida[f"u:{node}"] - h_nm[f"u:{node}"])) < 5e-3 * scale


def _chain10(contact=None):
    import tomllib
    from pathlib import Path
    path = Path(__file__).resolve().parent.parent / "benchmarks" / "p7" / "p7_chain_10.toml"
    raw = tomllib.loads(path.read_text())
    if contact is not None:
        raw["chain"][0]["contact"] = contact
    return raw


def test_p7_chain_band_solver_against_newmark():
    # benchmarks/p7/p7_chain_10.toml (elasto-plastic links committed at every accepted step,
    # Kelvin contacts) on IDA's band solver (half-bandwidth 3 in the interleaved layout)
    # against Newmark at h = 1e-5 over 3 s: measured 9.1e-6 of the peak displacement.
    raw = _chain10()
    raw["analysis"] = ida(rtol=1e-8, atol=1e-12, t_end=3.0)
    s_ida, h_ida = execute(raw)
    raw = _chain10()
    raw["analysis"] = dynamic("newmark", dt=1e-5, t_end=3.0, every=100)
    s_nm, h_nm = execute(raw)
    u = [f"u:b{i}" for i in range(1, 11)]
    scale = max(np.max(np.abs(h_ida[c])) for c in u)
    assert max(np.max(np.abs(h_ida[c] - h_nm[c])) for c in u) < 1e-4 * scale
    impacts = [sum(c["impacts"] for c in s["contacts"].values()) for s in (s_ida, s_nm)]
    assert impacts[0] == impacts[1] > 0


@pytest.mark.parametrize("contact", [{"scheme": "lagrange"},
                                     {"scheme": "restitution", "restitution": 0.65}])
def test_p7_chain_rigid_contacts_never_penetrate(contact):
    # The same chain with rigid contacts: closed contacts are held by the GGL constraints
    # (delta = 0 and delta' = 0), open ones by the impact law, so no gap goes below 0 beyond
    # what IDA's Newton iteration leaves of a linear constraint (exact with a current
    # Jacobian, off by the c_j-ratio scaling of a stale one; the restarts at the storeys'
    # yield and unloading switches make those frequent: measured 4.8e-14 m, against the
    # absolute position tolerance atol = 1e-12 m) and no multiplier is tensile.
    raw = _chain10(contact)
    raw["analysis"] = ida(rtol=1e-8, atol=1e-12, t_end=3.0)
    s, hist = execute(raw)
    pen = np.array([v for k, v in hist.items() if k.startswith("penetration:")])
    force = np.array([v for k, v in hist.items() if k.startswith("force:")])
    assert np.max(pen) < 1e-12
    assert np.min(force) >= 0.0
    assert sum(c["impacts"] for c in s["contacts"].values()) > 0
    assert s["energy"]["balance_relative"] < 1e-5                     # measured 1.4e-7


# --- cost, grazing, failures --------------------------------------------------------------------

def test_ida_counters_are_reported():
    # IDA's own counters, summed over the restarts (IDAReInit zeroes them): steps, error-test
    # and convergence failures, Newton iterations, residual evaluations (including the
    # difference-quotient Jacobian's), linear-solver setups, Jacobians, root evaluations.
    s, _ = execute(p2({"scheme": "penalty", "law": "kelvin", "stiffness": 1e6, "restitution": 0.8},
                      ida(rtol=1e-8, atol=1e-12)))
    cost = s["cost"]
    for key in ("steps", "newton_iterations", "residual_evaluations", "factorizations",
                "jacobian_evaluations", "root_evaluations", "events"):
        assert cost[key] > 0, key
    assert cost["rejected_steps"] >= 0 and cost["contact_chatter_resolutions"] == 0
    assert cost["residual_evaluations"] >= cost["newton_iterations"]
    assert cost["jacobian_evaluations"] == cost["factorizations"]   # one DQ Jacobian per setup
    assert cost["root_evaluations"] >= cost["steps"]
    assert cost["events"] == 2 * s["contacts"]["plane"]["impacts"]  # onsets and separations


def test_grazing_contact_inside_a_step_is_found():
    # A free oscillation of amplitude 0.1 m grazes a plane 0.1 um deep: each contact lasts
    # 0.28 ms, while IDA's steps average 0.8 ms. The root on the gap rate stops at the apex,
    # where the gap is positive, and the onset is located on the step's interpolant
    # (docs/problems.md P7: never step over a contact). Peak penetration measured 7.6e-5 low at
    # rtol = 1e-12 (the global error of u ~ 1e-13 m against a 1e-7 m depth).
    depth = 1e-7
    d = {"node": [{"name": "m", "mass": 1.0, "v0": 1.0}],
         "link": [{"type": "spring", "a": "m", "b": "ground", "k": 100.0}],
         "contact": [{"name": "plane", "a": "m", "b": "ground", "gap": 0.1 - depth,
                      "scheme": "penalty", "law": "linear", "stiffness": 1e4}],
         "analysis": ida(rtol=1e-12, atol=1e-12, dt=0.1, t_end=1.0)}
    s, _ = execute(d)
    c = s["contacts"]["plane"]
    assert c["impacts"] == 2
    assert s["cost"]["steps"] < 1.0 / 0.28e-3
    for pen in c["phase_max_penetration"]:
        assert pen == pytest.approx(depth, rel=1e-3)


def test_absurd_tolerance_fails_cleanly():
    with pytest.raises(SolverError, match=r"MARTELLO_ERR_EXTERNAL.*IDA_TOO_MUCH_ACC"):
        execute(p2({"scheme": "penalty", "law": "linear", "stiffness": 1e6}, ida(rtol=1e-30, atol=1e-30)))


def test_rigid_contact_starting_penetrated_is_refused():
    d = p2({"scheme": "lagrange"}, ida())
    d["node"][0]["u0"] = H + 1e-3
    with pytest.raises(SolverError, match=r"MARTELLO_ERR_ARGUMENT.*starts penetrated"):
        execute(d)


def test_an_error_test_failure_at_an_atol_below_the_rounding_says_so():
    # a Davis oscillator (benchmarks/invariance/accumulation.py) at rtol 1e-12, atol 1e-16
    # over 3 s: near an apex (v = 0, t = 1.312 s) the error weight of v is atol alone, below the
    # rounding of velocities ~1 (2e-16), and IDA's error test fails at every step; the message
    # says what to loosen. atol 1e-15 runs. (Whether a step lands where the test cannot pass is
    # chance: over 1.3 s the same scene ran through at 1e-16, failed at 3e-17.)
    from benchmarks.invariance.accumulation import davis_scene
    from martello.run import run_full
    from martello.scene.loader import from_dict
    from martello.run import check_budget
    scene, _ = davis_scene("ida", 0.37, 1, t_end=3.0)
    scene["analysis"].update(rtol=1e-12, atol=1e-16)
    # said before the run too (martello.run.atol_note): the oscillator starts at u0 = -0.3 m,
    # whose rounding (4 eps x 0.3 = 2.7e-16) is above that atol; the warning names the field
    # and the value to set
    before = [w for w in check_budget(from_dict(scene)) if w.startswith("analysis.atol = 1e-16 is below")]
    assert len(before) == 1 and "set analysis.atol to at least 2.7e-16" in before[0], before
    with pytest.raises(SolverError, match="IDA_ERR_FAIL.*loosen analysis.atol"):
        run_full(from_dict(scene))
    scene["analysis"]["atol"] = 1e-15
    assert not any("analysis.atol" in w for w in check_budget(from_dict(scene)))
    assert run_full(from_dict(scene))[0]["status"] == "MARTELLO_OK"


def test_an_atol_below_the_rounding_of_the_gap_is_a_warning_before_and_after_the_run():
    # P2's plane 0.05 m away sets the state's size before it moves (4 eps x 0.05 = 4.4e-17):
    # atol 1e-17 is below it and the run still completes (a warning, not a refusal: the
    # error test's failure is not certain), with the warning in its summary; atol 1e-16 is
    # above it (tests/test_ida.py's restitution case runs there) and gets none
    from martello.run import atol_note, run_full
    from martello.scene.loader import from_dict
    d = p2({"scheme": "restitution", "restitution": 0.8}, ida(1e-12, 1e-17, t_end=0.2))
    s, _ = run_full(from_dict(d))
    assert s["status"] == "MARTELLO_OK"
    assert any(w.startswith("analysis.atol = 1e-17 is below the rounding") for w in s["warnings"]), s["warnings"]
    d["analysis"]["atol"] = 1e-16
    assert atol_note(from_dict(d)) is None
    d["analysis"]["integrator"] = "cvode"
    d["analysis"]["atol"] = 1e-17
    assert atol_note(from_dict(d)) is None          # IDA's error test only (measured: docs/ida.md)


# --- output rows on IDA's interpolant: no result depends on the output -----------------------------

@pytest.mark.parametrize("path", ["benchmarks/p2/laws/p2_linear_ida.toml",
                                  "benchmarks/p2/p2_ida_restitution.toml",
                                  "benchmarks/p7/laws/p7_two_kelvin_ida.toml"])
def test_rows_on_the_interpolant_keep_output_invariance(path):
    # Identity of the method (no oracle). IDA stops only at the loads' kinks, its events and
    # t_end; an output row inside a step is the state on the step's interpolant (docs/ida.md,
    # output rows), so the steps are those of every output variant (the output interval x 0.37
    # and x 3, every x 7 and x 1000): step counts equal, and every number equal up to
    # - a located time (an event, an extremum): bisected on the same polynomial in other
    #   brackets, it stops anywhere within event_tol (1e-12 s) of the crossing;
    # - a value: interpolated at other points, the rounding of its terms, ROUNDING (1e3 eps)
    #   of its family's scale (relations.mismatches);
    # - an energy: the works' 3-point Gauss over stretches split at the rows: the rounding of
    #   their sums, ROUNDING of the largest energy term. The largest |balance| is taken over
    #   the steps alone, never the rows (martello_observer_row): it moves only with them.
    # Measured (P2's linear plane stepped across, P2's bouncing mass with its held contact,
    # P7's Kelvin contact restarted): every number
    # but the energies and located times to the bit; times within 3.4e-13 s, a peak force
    # 3.8e-14 relative, energies 3.2e-15 J of 0.76 J; P2's balance_max 3.5e-16 J of
    # 4.2e-9 J, with 0.042 J of energy (it moved by 2.9e-14 J while the rows were samples
    # of it: more than ROUNDING x 0.042 J = 9.3e-15 J).
    import sys
    from pathlib import Path
    root = Path(__file__).resolve().parents[1]
    sys.path.insert(0, str(root / "benchmarks" / "invariance"))
    import relations
    data, base_dir = relations.read(root / path)
    s0 = relations.run(relations.base_scene(data), base_dir)[0]
    base = relations.numbers(s0)
    fams = {f: max([abs(v) for k, v in base.items() if relations._family(k) == f
                    and isinstance(v, float) and math.isfinite(v)] + [0.0]) for f in ("L", "V", "A", "E")}
    event_tol = 1e-12
    energy = relations.ROUNDING * fams["E"]
    relative = s0["energy"]["balance_relative"] / s0["energy"]["balance"]   # 1 / its scale
    variants = [(n, v) for n, v in relations.output_variants(data, True) if n.startswith(("every", "output"))]
    assert len(variants) == 4
    for name, variant in variants:
        s = relations.run(variant, base_dir)[0]
        assert s["cost"]["steps"] == s0["cost"]["steps"], name
        other = relations.numbers(s)
        moved = []
        for p, x in base.items():
            y = other.get(p, x)
            if relations._same(x, y) or p.startswith(("cost", "wall")):
                continue
            last = p.rsplit(".", 2)
            if p == "energy.balance_relative":
                ok = abs(x - y) <= energy * relative
            elif p.startswith("energy."):
                ok = abs(x - y) <= energy
            elif any(w.startswith("t_") or w.endswith("_times") for w in last):
                ok = abs(x - y) <= event_tol
            else:
                fam = relations._family(p)
                ok = abs(x - y) <= relations.ROUNDING * max(abs(x), abs(y), fams.get(fam, 0.0))
            if not ok:
                moved.append((p, x, y))
        assert not moved, (name, moved)
