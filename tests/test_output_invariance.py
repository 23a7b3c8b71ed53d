"""No result depends on how it is recorded (docs/invariance.md): a sample of the catalogue,
one scene per integrator x scheme, run again with output.every x 7 and x 1000, without a
history, with other recorded items in another order, with each tracking choice, and (the
adaptive integrators) with two other output intervals. Fixed steps give every summary number
bit for bit; an adaptive run within its own tolerance (benchmarks/invariance/relations.py:
twice what a 3 or 10 times looser rtol, atol and event_tol moves the number, 100 rtol of it,
and the rounding). An identity of the method, needing no oracle; the whole catalogue is
benchmarks/invariance/sweep.py."""

from collections import Counter
from pathlib import Path

import pytest

from benchmarks.invariance import relations
from martello.scene import catalogue
from martello.scene.loader import load

ROOT = Path(__file__).resolve().parents[1] / "benchmarks"

# the cheapest scene of each integrator x scheme of the catalogue (measured: 0.002-0.3 s a run)
SAMPLE = {
    ("central-difference", "none"): "sdof/sdof_sine_central_difference.toml",
    ("central-difference", "penalty"): "p2/laws/p2_linear_central_difference.toml",
    ("generalized-alpha", "none"): "sdof/sdof_sine_generalized_alpha.toml",
    ("generalized-alpha", "penalty"): "p2/laws/p2_linear_generalized_alpha.toml",
    ("hht", "none"): "sdof/sdof_sine_hht.toml",
    ("hht", "penalty"): "p2/laws/p2_linear_hht.toml",
    ("newmark", "none"): "p6/p6_elastoplastic_rho005.toml",
    ("newmark", "penalty"): "p2/laws/p2_linear_newmark.toml",
    ("moreau-jean", "penalty"): "p2/laws/p2_linear_moreau_jean.toml",
    ("moreau-jean", "lagrange"): "p5/p5_moreau_jean_lagrange.toml",
    ("moreau-jean", "restitution"): "p5/p5_moreau_jean_e03.toml",
    ("newmark-lagrange", "restitution"): "p5/p5_newmark_lagrange_e03.toml",
    ("rk8pd", "penalty"): "p2/laws/p2_linear_rk8pd.toml",
    ("rk8pd", "restitution"): "p2/p2_restitution_e08.toml",
    ("rkf45", "penalty"): "p2/laws/p2_linear_rkf45.toml",
    ("rkf45", "restitution"): "p5/p5_newton_e0.toml",
    ("msbdf", "penalty"): "p2/laws/p2_linear_msbdf.toml",
    ("msbdf", "restitution"): "p5/p5_newton_e1.toml",
    ("ida", "penalty"): "p2/laws/p2_linear_ida.toml",
    ("ida", "restitution"): "p2/p2_ida_restitution.toml",
    ("ida", "lagrange"): "p2/p2_ida_lagrange.toml",
    ("ida", "none"): "sdof/sdof_sine_ida.toml",
    ("cvode", "none"): "p6/integrators/p6_rho00_cvode.toml",
    ("cvode", "penalty"): "p2/laws/p2_kelvin_cvode.toml",
    ("arkode", "none"): "sdof/sdof_sine_arkode.toml",
    ("arkode", "penalty"): "p2/laws/p2_flores_arkode.toml",
    ("fast-nonlinear", "none"): "p6/integrators/p6_rho005_fast_nonlinear.toml",
    ("moreau-jean", "none"): "p6/integrators/p6_rho00_moreau_jean.toml",
    ("newmark-lagrange", "none"): "p6/integrators/p6_rho005_newmark_lagrange.toml",
    ("rk8pd", "none"): "sdof/sdof_sine_rk8pd.toml",
    ("rkf45", "none"): "sdof/sdof_sine_rkf45.toml",
    ("msbdf", "none"): "sdof/sdof_sine_msbdf.toml",
    ("cvode", "restitution"): "p5/p5_cvode_restitution.toml",
    ("cvode", "lagrange"): "p2/p2_cvode_lagrange.toml",
    ("arkode", "restitution"): "p5/p5_arkode_restitution.toml",
    ("arkode", "lagrange"): "p2/p2_arkode_lagrange.toml",
}


def kind(scene):
    schemes = sorted({c["scheme"] for c in scene.contacts})
    return scene.analysis["integrator"], "+".join(schemes) or "none"


def test_the_sample_covers_every_kind_of_the_catalogue():
    # a new integrator or scheme in the catalogue gets a sample here
    kinds = Counter()
    for p in catalogue.scene_files():
        s = load(p)
        if s.analysis["type"] == "dynamic":
            kinds[kind(s)] += 1
    assert set(kinds) <= set(SAMPLE), sorted(set(kinds) - set(SAMPLE))
    for k, path in SAMPLE.items():
        assert kind(load(ROOT / path)) == k


def results_of(which):
    (integrator, adaptive), found = relations.output_invariance(ROOT / SAMPLE[which])
    assert adaptive == (integrator in relations.ADAPTIVE)
    assert len(found) >= (7 if adaptive else 6)
    return found


@pytest.mark.parametrize("which", sorted(SAMPLE), ids=lambda k: "-".join(k))
def test_no_summary_number_depends_on_the_output(which):
    failed = {name: (bad[:3], lost[:3]) for name, bad, lost, _ in results_of(which)}
    failed = {k: v for k, v in failed.items() if v[0] or v[1]}
    assert not failed, failed


@pytest.mark.parametrize("scene", ["sdof/sdof_sine_generalized_alpha.toml",
                                   "p6/integrators/p6_rho005_fast_nonlinear.toml"])
def test_the_largest_energy_balance_is_taken_on_the_energy_grid_alone(scene):
    # found by this family: the observer also took the largest |balance| at every recorded
    # row, so it moved with output.every (sdof_sine_generalized_alpha 2.3267362e-9 J at
    # every = 1, 2.3267351e-9 J at every = 7). It is taken on the energy grid alone (t = 0,
    # every 16th step of a cheap fixed-step method, the last): bit for bit at every = 1, 7,
    # 1000, and still at least the final |balance|, which the grid always holds
    data, base_dir = relations.read(ROOT / scene)
    got = []
    for every in (1, 7, 1000):
        d = relations.base_scene(data)
        d["analysis"]["output"]["every"] = every
        energy = relations.run(d, base_dir)[0]["energy"]
        assert energy["balance_max"] >= abs(energy["balance"]) > 0.0
        got.append((energy["balance_max"], energy["balance_relative"]))
    assert got[0] == got[1] == got[2], got


def test_the_tolerance_of_an_adaptive_run_is_its_own():
    # the relation is not vacuous: a result recorded otherwise but run at another tolerance
    # (rtol x 1e4) is told apart from the base
    data, base_dir = relations.read(ROOT / SAMPLE[("rk8pd", "restitution")])
    base = relations.numbers(relations.run(relations.base_scene(data), base_dir)[0])
    other = relations.base_scene(data)
    other["analysis"]["rtol"] = 1e-8
    other["analysis"]["atol"] = 1e-10
    moved = relations.numbers(relations.run(other, base_dir)[0])
    error = relations.own_error(base, relations.numbers(
        relations.run(relations.loose_scene(data, 10.0), base_dir)[0]))
    assert relations.mismatches(base, moved, error, relations.run_rtol(data))



def assert_output_interval_x3_keeps_the_numbers(scene, t_end=None):
    """The scene (to t_end if given) at its output interval and at three times it: the same
    numbers within the run's own tolerance, none missing."""
    data, base_dir = relations.read(ROOT / scene)
    if t_end is not None:
        data["analysis"]["t_end"] = t_end
    base = relations.numbers(relations.run(relations.base_scene(data), base_dir)[0])
    error, rtol = relations.tolerance_error(data, base, base_dir)
    sparse = relations.base_scene(data)
    sparse["analysis"]["dt"] = 3 * data["analysis"]["dt"]
    other = relations.numbers(relations.run(sparse, base_dir)[0])
    assert not relations.mismatches(base, other, error, rtol)
    assert not relations.missing(base, other)


def test_a_kink_of_the_load_an_ulp_from_an_output_time_is_one_stop():
    # found by this family: P8 on msbdf (a record sampled every 0.01 s) with outputs every
    # 0.015 s stopped at k 0.015, an ulp or two before the sample's time, then stepped that
    # ulp from a restart and failed (p8_B_msbdf: MARTELLO_ERR_STEP_UNDERFLOW at t = 6.15 s,
    # h = 1.8e-16 s); and a kink restarted msbdf only where it was not also an output time.
    # The scene to 6.2 s at output intervals 0.005 and 0.015 s: the same numbers within the
    # run's own tolerance (docs/event-driven.md, time events)
    assert_output_interval_x3_keeps_the_numbers("p8/p8_B_msbdf.toml", t_end=6.2)


def test_a_switch_root_falling_at_a_restart_is_not_met_again():
    # found by the catalogue sweep: P8 A on IDA with outputs every 0.015 s (0.005 as written)
    # stopped with "contact events keep recurring at t = 4.351 s": a bilinear link unloading at
    # its yield point (a rising root of its unloading switch) commits the elastic branch, whose
    # lower yield surface passes through the committed state; g = 0 there, falling, was reported
    # after every restart 6e-14 s apart. A falling root is now put on the branch's side beyond
    # the rounding, as a rising one is put past its surface (c/ode_events.c past_switch). The
    # two output intervals: the same numbers within the run's own tolerance
    assert_output_interval_x3_keeps_the_numbers("p8/p8_A_ida.toml")


def test_the_time_of_an_extreme_attained_twice_is_tied_not_a_mismatch():
    # found by this family: SDND101's undamped swing reaches |u| = v0/omega every period, and
    # t_absmax flipped between 0.188 s and 0.534 s with the output (equal values to rounding);
    # the values are still compared, the times are reported as tied (docs/invariance.md, ties)
    (_, adaptive), found = relations.output_invariance(
        ROOT / "vendor/code_aster_sdnd101_oscillator_on_stop.toml")
    assert adaptive
    assert not [(name, bad, lost) for name, bad, lost, _ in found if bad or lost]
    tied = {p: (a, b) for _, _, _, ties in found for p, a, b, _ in ties}
    assert "nodes.mass.t_absmax" in tied
    a, b = tied["nodes.mass.t_absmax"]
    assert abs(abs(a - b) - 0.3455) < 1e-3      # one period pi/Omega + pi/omega apart


def test_a_time_of_an_extreme_attained_once_stays_a_mismatch():
    # an undamped oscillator at resonance: |u| grows every period, so its largest value is
    # attained once, at the end; a run claiming it half-way is not excused as a tie
    scene = {"title": "resonance", "node": [{"name": "m", "mass": 1.0}],
             "link": [{"type": "spring", "a": "m", "b": "ground", "k": 1.0}],
             "loads": {"ground_acceleration": {"type": "sine", "amplitude": 1.0, "omega": 1.0}},
             "analysis": {"type": "dynamic", "integrator": "rk8pd", "rtol": 1e-10, "atol": 1e-14,
                          "dt": 0.1, "t_end": 30.0}}
    base_scene = relations.base_scene(scene)
    base = relations.numbers(relations.run(base_scene, ".")[0])
    error, rtol = relations.tolerance_error(scene, base, ".")
    t = base["nodes.m.t_absmax"]
    assert t > 25.0
    claim = [("nodes.m.t_absmax", t, 0.5 * t, 0.0)]
    kept, tied = relations.tied_times(".", (base_scene, base_scene), base, claim, error, rtol)
    assert kept == claim and not tied


def test_msbdf_locates_its_velocity_peaks_whatever_the_output():
    # found by this family: msbdf's difference Jacobian (also rk4imp's, which re-integrates
    # the states of the event and peak location) wrote its RHS values into the buffer that
    # held the step end's accelerations, so where an extremum of u was located the |v| and
    # |a| peaks of that step were screened on a stale rate and fell back to the step ends:
    # P10's linear frame, |v| max of B1.1 0.19727939 (every 1), 0.19727830 (every 7),
    # 0.19727737 (one output), against 0.19727953710 on rk8pd. The node numbers alone: the
    # frame members' peaks are another finding (docs/invariance.md)
    (_, adaptive), found = relations.output_invariance(
        ROOT / "p10/integrators/p10_linear_msbdf.toml")
    assert adaptive
    failed = {name: [b for b in bad if b[0].startswith("nodes.")][:3] for name, bad, _, _ in found}
    assert not {k: v for k, v in failed.items() if v}, failed


def test_a_held_contact_and_a_lumped_rod_give_the_same_summary_at_any_output():
    # found by this family: P4's equal rods on rk8pd, e = 0 (the rods held together after the
    # impacts). The held contact's force, its multiplier, was taken at the accepted states
    # only, so its peak moved with the output stops (2163.405 N at every = 1, 2162.575 N at
    # every = 7); it is now located inside the steps (its rate from the jerk, W_H P' = -B_H j:
    # 2163.827 N at every output). And u ~ 1e-150 m ahead of the wave front turned back and
    # forth with the step sequence, so u_peak of 14 nodes came and went: a turn of v inside
    # its tolerance (|v| <= atol at both ends of the step) is no maximum (docs/event-driven.md)
    (_, adaptive), found = relations.output_invariance(
        ROOT / "p4/p4_equal_rods_rk8pd_restitution_e0.toml")
    assert adaptive
    failed = {name: (bad[:3], lost[:3]) for name, bad, lost, _ in found if bad or lost}
    assert not failed, failed


# A frame's and a building's peaks (member end forces, drifts, storey forces, plan points)
# are linear functionals of the state the run tracks at every accepted sample (docs/results.md,
# "Frames and buildings"): found by the whole-catalogue sweep, they were taken over the
# recorded rows (P10's column N_i max 3.60e6 N at every = 1, 1.54e6 N at every = 1000).
# Fixed steps: bit for bit; adaptive: within the run's own tolerance (the relations above).
STRUCTURES = ["p10/integrators/p10_linear_newmark.toml", "p10/integrators/p10_linear_rk8pd.toml",
              "p10/integrators/p10_linear_cvode.toml", "p11/p11_shear_pounding.toml"]


@pytest.mark.parametrize("scene", STRUCTURES)
def test_no_frame_or_building_peak_depends_on_the_output(scene):
    (integrator, adaptive), found = relations.output_invariance(ROOT / scene)
    failed = {name: (bad[:3], lost[:3]) for name, bad, lost, _ in found if bad or lost}
    assert not failed, failed


def test_a_building_resultant_is_located_inside_adaptive_steps():
    # The biaxial resultant √(M2² + M3²) is located inside the steps where its square turns,
    # on the rows' own Hermites (docs/results.md, "Frames and buildings"). Taken at the steps
    # alone, it moved with the output stops of an adaptive run: P11's shear pounding on rk8pd
    # (rtol 1e-8, 1 s), column A C2.0.1 M_i resultant 152143.32 N m at every = 1, 152130.79 at
    # every = 7 (8e-5 relative; the allowance 5.5 N m).
    data, base_dir = relations.read(ROOT / "p11/p11_shear_pounding.toml")
    an = data["analysis"]
    for key in ("beta", "gamma", "alpha", "rho_inf"):
        an.pop(key, None)
    an.update(integrator="rk8pd", rtol=1e-8, t_end=1.0)
    (integrator, adaptive), found = relations.output_invariance(data, base_dir)
    failed = {name: (bad[:3], lost[:3]) for name, bad, lost, _ in found if bad or lost}
    assert adaptive and not failed, failed


def test_a_frame_peak_is_every_steps_not_the_recorded_rows():
    # every = 1000 records three rows (t = 0, 1.0 s, 2.0 s): the peaks are still every
    # step's, equal to those of every = 1 bit for bit, and at least the largest of the rows
    # every = 1 records (the located extrema inside the steps can only raise them)
    data, base_dir = relations.read(ROOT / STRUCTURES[0])
    got = {}
    for every in (1, 1000):
        d = relations.base_scene(data)
        d["analysis"]["output"]["every"] = every
        got[every] = relations.run(d, base_dir)
    (s1, cols, rows), (s1000, _, rows1000) = got[1], got[1000]
    assert len(rows1000) == 3 < len(rows)
    for name, frame in s1["frames"].items():
        for member, peaks in frame["members"].items():
            for q, e in peaks.items():
                if q == "kind":
                    continue
                assert e == s1000["frames"][name]["members"][member][q], (member, q)
                if f"{q}:{name}.{member}" in cols:
                    x = rows[:, cols.index(f"{q}:{name}.{member}")]
                    assert e["max"] >= x.max() and e["min"] <= x.min(), (member, q)


@pytest.mark.parametrize("integrator", ["arkode", "cvode", "ida"])
def test_an_output_row_inside_a_step_leaves_the_steps_as_they_were(integrator):
    # found on ARKODE: P7's chain of 10 took 1 546 / 1 547 / 1 543 steps at output.every
    # 1 / 7 / 50 — a row inside a step committed the elements' states there, and the steps
    # after it started from that commit. A row is now committed for its own values and the
    # step's states restored (c/ode_events.c oe_rows_inside). Identity of the method, no
    # oracle: the steps, and the rows the three runs share, equal to the bit (before: 398 /
    # 396 / 396 steps on ARKODE over [0, 1.5 s])
    data, base_dir = relations.read(ROOT / "p7/p7_chain_10.toml")
    data["analysis"] = {"type": "dynamic", "integrator": integrator, "dt": 0.01, "t_end": 1.5,
                        "rtol": 1e-8, "atol": 1e-12}
    runs = {}
    for every in (1, 7, 50):
        scene = relations.base_scene(data)
        scene["analysis"]["output"] = {"every": every}
        runs[every] = relations.run(scene, base_dir)
    steps = {every: run[0]["cost"]["steps"] for every, run in runs.items()}
    assert len(set(steps.values())) == 1, steps
    # the states; the works (energy columns) are split at the rows, their rounding moves
    columns = runs[1][1]
    state = [k for k, c in enumerate(columns) if c == "t" or c.split(":")[0] in ("u", "v", "a")]
    dense = {row[0]: row[state].tolist() for row in runs[1][2]}
    for every in (7, 50):
        assert runs[every][1] == columns
        shared = [row for row in runs[every][2] if row[0] in dense]
        assert len(shared) >= len(runs[every][2]) - 1      # all but t_end off the 0.01 s grid
        assert all(row[state].tolist() == dense[row[0]] for row in shared), every
