"""Two bars in dynamic contact (docs/problems.md P4): the [[bar]] mesher, the wave-theory
oracles of martello.oracles.p4_wave_theory, the rod-impact measures, and what P4 must show
(docs/p4-bars.md): exactness at Courant number 1, convergence rates under refinement,
penetration ~ 1/ε. Oracles: martello.oracles.p4_rod_impact.rod_impact and
martello.oracles.p4_wave_theory (d'Alembert only). docs/p4-bars.md derives every rate and
tolerance used here."""

import math

import numpy as np
import pytest

from martello.checks.measures import attach, rod_impact_measures, run_measured
from martello.errors import DivergenceError, SceneError
from martello.oracles.p4_rod_impact import rod_impact_interface_displacement
from martello.oracles.p4_wave_theory import X_STAR, penalty_rod_impact, rod_point_displacement
from martello.run import run_full
from martello.scene.bars import rod_impact_scene
from martello.scene.loader import from_dict
from tests.dynamics_helpers import slope

E, RHO, A, L, V0 = 2.0e11, 7850.0, 1.0e-4, 1.0, 1.0
C = math.sqrt(E / RHO)
Z = RHO * C * A
EA, RHOA = E * A, RHO * A


def rod(**kw):
    b = {"name": "A", "L": 2.0, "elements": 4, "EA": 3.0e6, "rhoA": 5.0}
    b.update(kw)
    return b


def bar_scene(*bars, analysis=None, **top):
    d = {"bar": list(bars), "analysis": analysis or {"type": "static"}}
    d.update(top)
    return d


def measures_of(d):
    """The rod-impact measures of a run of the scene dict d, as `martello run` reports them."""
    summary, _ = run_measured(from_dict(d))
    return summary["measures"]["rod_impact"]


def measures(**kw):
    return measures_of(rod_impact_scene(**kw))


# --- the mesher --------------------------------------------------------------------------------

@pytest.mark.parametrize("mass,ends", [("lumped", "node"), ("consistent", "node"), ("lumped", "half-cell")])
@pytest.mark.parametrize("N", [2, 3, 17])
def test_mass_matrix_sums_to_rho_A_L(mass, ends, N):
    # 1ᵀM1 = ρAL for every mass matrix (rigid translation carries the whole mass): an identity,
    # so the tolerance is a few ulps of the sum.
    s = from_dict(bar_scene(rod(elements=N, mass=mass, ends=ends)))
    total = sum(n["mass"] for n in s.nodes) + 2.0 * sum(c["value"] for c in s.couplings)
    assert total == pytest.approx(5.0 * 2.0, rel=8 * N * np.finfo(float).eps)


def test_one_element_rod():
    # the degenerate size: two end nodes, one element, half the mass each (lumped)
    s = from_dict(bar_scene(rod(elements=1)))
    assert [n["name"] for n in s.nodes] == ["A.left", "A.right"]
    assert [n["mass"] for n in s.nodes] == [5.0, 5.0]
    assert len(s.links) == 1 and s.links[0]["L"] == 2.0


def test_consistent_mass_entries():
    # ρA L_e/6 [[2, 1], [1, 2]] per element: ends ρAL_e/3, interior 2ρAL_e/3, neighbours ρAL_e/6
    s = from_dict(bar_scene(rod(mass="consistent")))
    me = 5.0 * 0.5
    assert [n["mass"] for n in s.nodes] == pytest.approx([me / 3, 2 * me / 3, 2 * me / 3, 2 * me / 3, me / 3],
                                                         rel=1e-15)
    pairs = [(s.nodes[c["a"]]["name"], s.nodes[c["b"]]["name"], c["value"]) for c in s.couplings]
    assert pairs == [("A.left", "A.1", pytest.approx(me / 6, rel=1e-15)),
                     ("A.1", "A.2", pytest.approx(me / 6, rel=1e-15)),
                     ("A.2", "A.3", pytest.approx(me / 6, rel=1e-15)),
                     ("A.3", "A.right", pytest.approx(me / 6, rel=1e-15))]


def test_names_links_and_info():
    s = from_dict(bar_scene(rod(x0=3.0, v0=2.0)))
    assert [n["name"] for n in s.nodes] == ["A.left", "A.1", "A.2", "A.3", "A.right"]
    assert all(n["v0"] == 2.0 for n in s.nodes)
    assert [(s.nodes[l["a"]]["name"], s.nodes[l["b"]]["name"]) for l in s.links] == \
        [("A.left", "A.1"), ("A.1", "A.2"), ("A.2", "A.3"), ("A.3", "A.right")]
    assert all(l["type"] == "bar" and l["EA"] == 3.0e6 and l["L"] == 0.5 for l in s.links)
    info = s.extras["bars"][0]
    assert info["x"] == [3.0, 3.5, 4.0, 4.5, 5.0]
    assert info["c"] == pytest.approx(math.sqrt(3.0e6 / 5.0), rel=1e-15)
    assert info["impedance"] == pytest.approx(math.sqrt(3.0e6 * 5.0), rel=1e-15)
    assert info["element_stiffness"] == 6.0e6 and info["half_cell_stiffness"] == 1.2e7


def test_E_A_rho_equal_EA_rhoA():
    b = {k: v for k, v in rod().items() if k not in ("EA", "rhoA")}
    a = from_dict(bar_scene(dict(b, E=3.0e10, A=1.0e-4, rho=5.0e4)))
    b = from_dict(bar_scene(rod()))
    assert [n["mass"] for n in a.nodes] == pytest.approx([n["mass"] for n in b.nodes], rel=1e-15)
    assert [l["EA"] for l in a.links] == pytest.approx([l["EA"] for l in b.links], rel=1e-15)


def test_half_cell_layout_and_supports():
    # N cells, a node of mass ρA L_e at each centre, N−1 elements; a held end is tied to
    # ground by the half cell (a bar of L_e/2)
    s = from_dict(bar_scene(rod(ends="half-cell", fixed="both")))
    assert [n["mass"] for n in s.nodes] == [2.5] * 4
    assert s.extras["bars"][0]["x"] == [0.25, 0.75, 1.25, 1.75]
    supports = [l for l in s.links if -1 in (l["a"], l["b"])]
    assert [l["L"] for l in supports] == [0.25, 0.25] and len(s.links) == 5
    assert not any(n["fixed"] for n in s.nodes)


def test_fixed_end_nodes():
    s = from_dict(bar_scene(rod(fixed="left", v0=1.0)))
    assert [n["fixed"] for n in s.nodes] == [True, False, False, False, False]
    assert s.nodes[0]["v0"] == 0.0 and s.nodes[1]["v0"] == 1.0


@pytest.mark.parametrize("output,expected", [("all", ["m", "A.left", "A.1", "A.2", "A.3", "A.right"]),
                                             ("ends", ["m", "A.left", "A.right"]), ("none", ["m"])])
def test_output_nodes(output, expected):
    an = {"type": "dynamic", "integrator": "newmark", "dt": 1e-3, "t_end": 1e-2}
    d = bar_scene(rod(output=output), analysis=an, node=[{"name": "m", "mass": 1.0}])
    assert from_dict(d).analysis["output"]["nodes"] == expected
    an["output"] = {"nodes": ["A.2"]}
    kept = from_dict(bar_scene(rod(output=output), analysis=an)).analysis["output"]["nodes"]
    assert kept[0] == "A.2" and len(kept) == len(set(kept))


@pytest.mark.parametrize("change,field", [
    ({"L": None}, r"bar\[0\]\.L: missing"),
    ({"L": -1.0}, r"bar\[0\]\.L: invalid value"),
    ({"elements": 0}, r"bar\[0\]\.elements: invalid value"),
    ({"elements": 4.0}, r"bar\[0\]\.elements: has the wrong type"),
    ({"EA": None}, r"bar\[0\]\.EA: missing"),
    ({"E": 1.0}, r"bar\[0\]\.E: given together with EA"),
    ({"EA": None, "E": 1.0}, r"bar\[0\]\.A: missing"),
    ({"rhoA": None}, r"bar\[0\]\.rhoA: missing"),
    ({"rho": 1.0}, r"bar\[0\]\.rho: given together with rhoA"),
    ({"A": 1.0}, r"bar\[0\]\.A: is not used"),
    ({"mass": "diagonal"}, r"bar\[0\]\.mass: unknown value"),
    ({"ends": "cells"}, r"bar\[0\]\.ends: unknown value"),
    ({"ends": "half-cell", "mass": "consistent"}, r"bar\[0\]\.mass: a half-cell rod has lumped mass only"),
    ({"ends": "half-cell", "elements": 1}, r"bar\[0\]\.elements: invalid value 1"),
    ({"fixed": "top"}, r"bar\[0\]\.fixed: unknown value"),
    ({"output": "some"}, r"bar\[0\]\.output: unknown value"),
    ({"name": "a.b"}, r"bar\[0\]\.name: invalid name"),
    ({"name": "ground"}, r"bar\[0\]\.name: invalid name"),
    ({"x0": "left"}, r"bar\[0\]\.x0: has the wrong type"),
    ({"colour": "red"}, r"bar\[0\]\.colour: unknown key"),
])
def test_bar_error_paths(change, field):
    b = rod()
    for k, v in change.items():
        if v is None:
            b.pop(k)
        else:
            b[k] = v
    with pytest.raises(SceneError, match=field):
        from_dict(bar_scene(b))


def test_name_clashes():
    with pytest.raises(SceneError, match=r"bar\[1\]\.name: duplicate name 'A'"):
        from_dict(bar_scene(rod(), rod()))
    with pytest.raises(SceneError, match=r"bar\[0\]\.name: generates the node 'A.left'"):
        from_dict(bar_scene(rod(), node=[{"name": "A.left", "mass": 1.0}]))
    with pytest.raises(SceneError, match=r"bar: must be a non-empty array"):
        from_dict(bar_scene())


# --- wave theory (independent oracles) -----------------------------------------------------------

@pytest.mark.parametrize("LB,wall", [(1.0, False), (2.0, False), (1.0, True)])
def test_point_displacement_agrees_with_closed_forms_at_the_face(LB, wall):
    # two independent codings of d'Alembert: images at depth 0 vs p4_rod_impact's pulse integral
    t = np.linspace(0.0, 5.0 * 2 * LB / C, 997)
    uA, uB = rod_impact_interface_displacement(t, E, RHO, L, LB, V0, wall=wall)
    a = V0 * t + rod_point_displacement(0.0, t, C, L, LB, V0, "a", wall=wall)
    assert np.max(np.abs(a - uA)) <= 1e-13 * V0 * L / C
    if not wall:
        b = rod_point_displacement(0.0, t, C, LB, L, V0, "b")
        assert np.max(np.abs(b - uB)) <= 1e-13 * V0 * L / C


def test_penalty_continuum_constants():
    assert (1 + X_STAR) * math.exp(-X_STAR) == pytest.approx(0.5, abs=1e-15)
    ref = penalty_rod_impact(Z, V0, 100 * EA / L, 2 * L / C)
    assert ref["max_penetration"] == pytest.approx(0.5 * Z * V0 / (100 * EA / L), rel=1e-15)
    assert ref["validity"] < 1e-80


# --- What must show: Courant number 1 -----------------------------------------------------------

@pytest.mark.parametrize("case", [{}, {"wall": True}, {"L_B": 2.0}], ids=["equal", "wall", "unequal"])
@pytest.mark.parametrize("N", [10, 100])
def test_half_cells_central_difference_courant_one_is_exact(case, N):
    # Lumped cells with the two end half cells as the contact element (ε = EA/L_e, 2EA/L_e on
    # a wall) make the joined mesh uniform; central difference at c·dt = L_e then propagates
    # the lattice d'Alembert solution, which samples the exact wave when the faces meet half a
    # step after t = 0 (docs/p4-bars.md). Only the rounding of dt = L_e/c remains: measured
    # ≤ 1e-14 in every quantity at N = 100 (2N steps of contact).
    m = measures(N=N, ends="half-cell", courant=1.0, gap_phase=0.5, **case)
    assert m["phases"] == 1 and m["later_phases"] == 0
    dur = "pulse_duration_relative_error" if "L_B" in case else "duration_relative_error"
    assert abs(m[dur]) <= 1e-10
    assert max(abs(v) for v in m["v_error"].values()) <= 1e-10
    assert abs(m["peak_error"]) <= 1e-10 and m["pulse_l1_error"] <= 1e-10
    assert m["displacement_error"] <= 1e-10
    assert abs(m["energy_final_error"]) <= 1e-10 or "L_B" in case


@pytest.mark.parametrize("theta", [0.0, 0.25, 0.75])
@pytest.mark.parametrize("wall", [False, True])
def test_courant_one_exact_duration_and_velocities_for_any_onset(theta, wall):
    # Another onset phase θ adds a static displacement step to the lattice data: it carries no
    # momentum and the faces still part exactly at 2L/c, but the force alternates by
    # ±(1 − 2θ)P0 about the exact value (θ = 0: P0·(2, 0, 2, 0…); the zero steps are not
    # separations: the measures merge them into one episode).
    m = measures(N=20, ends="half-cell", courant=1.0, gap_phase=theta, wall=wall)
    assert abs(m["duration_relative_error"]) <= 1e-10
    assert max(abs(v) for v in m["v_error"].values()) <= 1e-10
    assert m["peak_error"] == pytest.approx(abs(1.0 - 2.0 * theta), abs=1e-10)


def test_ends_at_nodes_cannot_be_exact_at_courant_one():
    # With the ends at nodes, the half-mass end nodes already put ω_max at exactly 2/dt at
    # c·dt = L_e; any contact spring pushes it over: the run is refused, and without the
    # check it diverges.
    with pytest.raises(DivergenceError, match="central difference is unstable"):
        measures(N=10, ends="node", courant=1.0)
    with pytest.raises(DivergenceError, match="diverged|created energy"):
        measures(N=10, ends="node", courant=1.0, check_stability=False)


# --- What must show: convergence under mesh and step refinement ----------------------------------

@pytest.mark.parametrize("integrator,extra", [("central-difference", {}), ("newmark", {}),
                                              ("generalized-alpha", {"rho_inf": 0.8})])
def test_half_cells_converge_like_a_dispersive_front(integrator, extra):
    # At C = 1/2 the second-order schemes disperse the jumps of the wave: the front spreads
    # over (h² c t)^{1/3} (duration, velocities ~ h^{2/3}) and leaves an Airy tail whose L1
    # norm is ~ h^{1/2} (docs/p4-bars.md); the overshoot (~44 %) does not decay. Measured over
    # N = 40…320: rates 0.57–0.63 (duration), 0.65–0.66 (velocity), 0.50–0.57 (L1).
    Ns = [40, 80, 160, 320]
    ms = [measures(N=N, ends="half-cell", courant=0.5, integrator=integrator, **extra) for N in Ns]
    h = 1.0 / np.array(Ns)
    dur = slope(h, [abs(m["duration_relative_error"]) for m in ms])
    vel = slope(h, [max(abs(v) for v in m["v_error"].values()) for m in ms])
    l1 = slope(h, [m["pulse_l1_error"] for m in ms])
    assert 0.5 <= dur <= 0.85 and 0.55 <= vel <= 0.8 and 0.42 <= l1 <= 0.7
    peaks = [m["peak_error"] for m in ms]
    assert max(peaks) - min(peaks) <= 1e-3 and 0.3 < peaks[0] < 0.5


@pytest.mark.parametrize("mass,integrator", [("lumped", "central-difference"), ("lumped", "newmark"),
                                             ("consistent", "newmark")])
def test_penalty_compliance_is_first_order_and_predicted(mass, integrator):
    # ε = 0.1 EA/L_e: the spring's compliance lengthens the contact by x*·τ_c,
    # τ_c = Z/(2ε) = 5 L_e/c (wave_theory.penalty_rod_impact), an O(h) error that dominates
    # the O(h^{2/3}) dispersion on coarse meshes: measured within 4.1 % of the prediction for
    # N <= 80 (the dispersion share grows as h^{-1/3} relative: 10 % at N = 160), rates
    # 0.94–1.0 over N = 20…160.
    Ns = [20, 40, 80, 160]
    ms = [measures(N=N, ends="node", mass=mass, integrator=integrator, eps_factor=0.1) for N in Ns]
    errs = [m["duration_relative_error"] for m in ms]
    for N, e in zip(Ns[:3], errs):
        assert e == pytest.approx(X_STAR / (4 * 0.1 * N), rel=0.06)
    assert 0.85 <= slope(1.0 / np.array(Ns), errs) <= 1.1


@pytest.mark.parametrize("integrator", ["central-difference", "newmark"])
def test_fixed_penalty_converges_to_the_penalty_continuum(integrator):
    # ε = 10 EA/L held fixed while the mesh is refined: the FE solution converges to the
    # continuum rods joined by that spring, whose force is smooth (exponential rise, τ_c = T/40)
    # — A rebounds at −v0 τ_c/T after the unequal-rod impact. Measured rates ≈ 2.8–2.9
    # (penetration and velocity, lumped mass).
    Ns = [100, 200, 400]
    ref = penalty_rod_impact(Z, V0, 10 * EA / L, 2 * L / C, 4 * L / C)
    ms = [measures(N=N, L_B=2.0, integrator=integrator, eps_factor=10.0 / N, t_end_factor=1.6)
          for N in Ns]
    pen = [abs(m["max_penetration"] / ref["max_penetration"] - 1) for m in ms]
    vel = [abs(m["v_error"]["A"] + ref["impulse_relative_error"]) for m in ms]
    h = 1.0 / np.array(Ns)
    assert slope(h, pen) >= 2.5 and slope(h, vel) >= 2.5
    assert pen[-1] <= 1e-4 and vel[-1] <= 2e-6


# --- What must show: penalty penetration ~ 1/ε ----------------------------------------------------

@pytest.mark.parametrize("integrator,courant", [("central-difference", 0.9), ("newmark", 1.0)])
def test_penalty_penetration_scales_like_one_over_eps(integrator, courant):
    # In the impedance regime EA/L ≪ ε ≪ EA/L_e the contact force settles at Z v0 (wall) over
    # τ_c = Z/ε and the penetration is P0/ε (wave_theory.penalty_rod_impact). N = 1000,
    # ε = 10…80 EA/L: measured slope −0.99996 and |δ ε/P0 − 1| ≤ 1.3e-4. Outside the regime the
    # slope is −1/2 (rigid rods below, bouncing end nodes above: docs/p4-bars.md).
    N, factors = 1000, [10.0, 20.0, 40.0, 80.0]
    pens = []
    for f in factors:
        eps = f * EA / L
        m = measures(N=N, wall=True, integrator=integrator, courant=courant, output="none", every=10 ** 6,
                     eps_factor=eps / (2 * EA * N / L), t_end_factor=1.02)
        pens.append(m["max_penetration"])
        assert m["max_penetration"] * eps / (Z * V0) == pytest.approx(1.0, abs=3e-4)
    assert slope(np.array(factors), pens) == pytest.approx(-1.0, abs=1e-3)


# --- the measures ---------------------------------------------------------------------------------

def test_measures_need_one_contact_between_free_rod_ends():
    d = rod_impact_scene(N=4)
    d["contact"].append(dict(d["contact"][0], name="other"))
    m = measures_of(d)
    assert m["applicable"] is False and "2 contacts" in m["notes"][0]
    d = rod_impact_scene(N=4)
    d["bar"][1]["fixed"] = "right"
    assert "fixed end" in measures_of(d)["notes"][0]


def test_measures_are_attached_by_the_reporting_layer_not_by_the_run():
    # the run layer knows no oracle: run_full leaves the summary without measures, attach
    # (called by `martello run` and `martello check` through run_measured) adds them
    s = from_dict(rod_impact_scene(N=4))
    summary, history = run_full(s)
    assert "measures" not in summary
    attach(s, summary, history)
    assert summary["measures"]["rod_impact"] == rod_impact_measures(s, summary, history)
    assert list(summary)[-1] == "measures"


def test_measures_say_what_is_missing_from_the_output():
    m = measures(N=10, output="ends")
    assert "v_final" not in m and "duration" in m
    assert any("output.nodes" in n for n in m["notes"])
    m = measures(N=10, every=3)        # the every-step measures from the step trace
    assert "pulse_l1_error" in m and "displacement_error" in m
    m = measures(N=10, integrator="rk8pd")
    assert "pulse_l1_error" not in m and any("output times" in n for n in m["notes"])


def test_no_measure_depends_on_output_every():
    # A measure is taken from what the run tracks at every step (the contact phases and
    # maxima, the final state, and the step trace: the contact's force, the energies and the
    # rods' displacements at every step, whatever is recorded; docs/results.md "Step
    # trace"): never from recorded samples. The unequal rods on Newmark had 1 phase at
    # every = 1 and 7 at every = 16 (the episode merged gaps shorter than an output
    # interval), force_peak 1984.376 vs 1984.347 N; the pulse's L1, total variation and width,
    # the energy error and the displacement error existed at every = 1 alone. Every = 1, 7,
    # 16 and 1000 give the same numbers, bit for bit,
    # and the same as the rows at every = 1 (attach without the trace): the trace holds the
    # samples of those rows. An identity of the method, no oracle.
    import tomllib
    from pathlib import Path
    path = Path(__file__).resolve().parents[1] / "benchmarks/p4/p4_unequal_rods_newmark_lumped_eps0.1.toml"
    data = tomllib.loads(path.read_text())
    data.pop("check")
    got = {}
    for every in (1, 7, 16, 1000):
        data["analysis"]["output"]["every"] = every
        got[every] = run_measured(from_dict(data, base_dir=path.parent))[0]["measures"]["rod_impact"]
    data["analysis"]["output"]["every"] = 1
    s = from_dict(data, base_dir=path.parent)
    summary, history = run_full(s)
    rows = rod_impact_measures(s, summary, history)
    one = got[1]
    for every in (7, 16, 1000):
        for key in ("onset_time", "duration", "phases", "later_phases", "max_penetration",
                    "force_peak", "peak_error", "impulse_error", "v_final", "energy_final_error",
                    "vibration_energy_fraction", "pulse_l1_error", "force_total_variation",
                    "spurious_variation", "pulse_duration", "energy_error", "displacement_error",
                    "end_displacement_error"):
            assert got[every][key] == one[key] == rows[key], (every, key)
        assert not any("every" in n for n in got[every]["notes"]), got[every]["notes"]
