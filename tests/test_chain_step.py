"""The fused chain step (docs/run-layer.md "The fused chain step") against the general path.

Kind of evidence: an identity of the method, not a verification. Both paths solve the same
Newmark step equations, so on every catalogue scene the fused step takes, the whole summary
(peaks, final state, every contact phase, link peaks, energy terms) must agree. The general
path's own correctness is verified elsewhere against closed forms and references.

Tolerance. Each path's state is the exact solution of the step equations up to a few ulps of
u (the general path stops when its residual is below 1e-9 of the force scale, after a step
that is exact for these piecewise-linear laws), but the acceleration is a = (u − uₙ − hvₙ)/(βh²)
− …: an ulp of u becomes ε·|u|/(βh²) in a, which on P5's contact (h = 1e-7 s, |u| ≈ 1e-3 m,
|a| ≈ 100 m/s²) is 4e-7 of |a|. Contact phases then carry such differences into the onset and
separation times, and through them into the later motion. Measured worst difference over the
catalogue: 8e-8 of a field's scale (P5's a_absmax); the bound 1e-6 leaves a factor of ten."""

import numpy as np
import pytest

from martello.run import run, run_full
from martello.scene.catalogue import scene_files
from martello.scene.loader import from_dict, load

RTOL = 1e-6
# The chatter scene of docs/p4-bars.md (ε = 10 EA/L_e): its ~120 impacts are sensitive to
# round-off, and the two paths' phases part after about 100 of them (from t ≈ 3.3e-4 s), so
# the comparison stops at t = 2.6e-4 s (~80 impacts).
CHATTER = {"p4_equal_rods_newmark_lumped_eps10.toml": 2.6e-4}


def summaries(scene_of):
    out = []
    for fused in (True, False):
        s = scene_of()
        s.analysis["fused_chain"] = fused
        out.append(run(s))
    return out


def leaves(d, pre=""):
    """Numeric leaves of a summary, by path."""
    if isinstance(d, dict):
        return {k: v for key, sub in d.items() for k, v in leaves(sub, f"{pre}/{key}").items()}
    if isinstance(d, list):
        return {k: v for i, sub in enumerate(d) for k, v in leaves(sub, f"{pre}/{i}").items()}
    if isinstance(d, (int, float)) and not isinstance(d, bool):
        return {pre: float(d)}
    return {}


def field(path):
    """A field without the item it belongs to: nodes/u_max for /nodes/b3/u_max; one energy
    scale for all energy terms (a balance of 1e-13 J is compared with the energies)."""
    parts = path.split("/")
    if parts[1] == "energy":
        return "energy"
    if parts[1] in ("nodes", "contacts", "links"):
        return f"{parts[1]}/{parts[3]}"
    return path


def assert_same_answers(fused, general):
    skip = ("cost", "provenance", "integrator", "analysis")
    a = leaves({k: v for k, v in fused.items() if k not in skip})
    b = leaves({k: v for k, v in general.items() if k not in skip})
    assert set(a) == set(b), sorted(set(a) ^ set(b))[:5]
    scale = {}
    for k, v in b.items():
        scale[field(k)] = max(scale.get(field(k), 0.0), abs(v))
    bad = [(k, a[k], b[k]) for k in b if abs(a[k] - b[k]) > RTOL * (scale[field(k)] or 1.0)]
    assert not bad, bad[:5]


def chain_scenes():
    """Catalogue scenes integrated by Newmark (the fused step decides at run time whether it
    takes them: the test asserts on its counter which did)."""
    out = []
    for p in scene_files():
        an = load(p).analysis
        if an.get("type") == "dynamic" and an.get("integrator") == "newmark":
            out.append(p)
    return out


@pytest.mark.parametrize("path", chain_scenes(), ids=lambda p: p.name)
def test_fused_step_gives_the_general_paths_answers(path):
    def scene(t_end=None):
        s = load(path)
        s.analysis["t_end"] = t_end or CHATTER.get(path.name, s.analysis["t_end"])
        return s
    # a scene outside the fused step's reach runs on the general path alone: nothing to compare
    if run(scene(3 * load(path).analysis["dt"]))["cost"]["fused_chain_steps"] == 0:
        return
    fused, general = summaries(scene)
    assert general["cost"]["fused_chain_steps"] == 0
    # a step whose branches do not settle (a graze: p7_row_3's r1-r2 contact) is handed to
    # the general path by design; every other step is fused
    assert fused["cost"]["fused_chain_steps"] >= fused["cost"]["steps"] - 10
    assert_same_answers(fused, general)


def test_the_catalogue_chains_take_the_fused_step():
    # the scenes the fused step is built for (docs/run-layer.md): P7's rows of buildings,
    # lumped rods (P4), P5/P6's piecewise-linear laws, the SDOF
    taken = set()
    for p in chain_scenes():
        s = load(p)
        s.analysis["t_end"] = s.analysis["dt"] * 3
        if run(s)["cost"]["fused_chain_steps"] == 3:
            taken.add(p.name)
    assert {"p7_chain_10.toml", "p7_chain_1000.toml", "p7_two_oscillators.toml",
            "p4_unequal_rods_newmark_lumped_eps0.1.toml", "p6_elastoplastic_rho00.toml",
            "p5_kelvin_clipped.toml", "sdof_sine_newmark.toml"} <= taken
    # a nonlinear law (Hertz) and a consistent mass (P4's couplings) take the general path
    assert "p5_hertz.toml" not in taken and "p4_wall_newmark_consistent_eps1.toml" not in taken


def small_chain(**analysis):
    """Three masses between two walls: node w1 fixed, a spring and dashpot to ground on each
    mass, neighbour springs, a linear contact with ground written ground-first (its δ is
    −u − gap) and a Kelvin contact written right-to-left: the orientations and the fixed row
    the fused step handles apart from a [[chain]]."""
    d = {
        "node": [{"name": "w1", "mass": 0.0, "fixed": True, "u0": 0.0},
                 {"name": "a", "mass": 1.0, "v0": -0.5}, {"name": "b", "mass": 2.0, "v0": 0.8},
                 {"name": "c", "mass": 1.5}],
        "link": [{"name": "s1", "type": "spring", "a": "w1", "b": "a", "k": 50.0},
                 {"name": "d1", "type": "dashpot", "a": "a", "b": "w1", "c": 0.3},
                 {"name": "s2", "type": "spring", "a": "a", "b": "b", "k": 80.0},
                 {"name": "y3", "type": "bilinear", "a": "c", "b": "ground", "k": 120.0, "fy": 2.0,
                  "hardening": 0.1},
                 {"name": "d2", "type": "dashpot", "a": "b", "b": "ground", "c": 0.2}],
        "contact": [{"name": "floor", "a": "ground", "b": "a", "gap": 0.02, "scheme": "penalty",
                     "law": "linear", "stiffness": 1.0e4},
                    {"name": "bc", "a": "c", "b": "b", "gap": 0.01, "scheme": "penalty",
                     "law": "kelvin", "stiffness": 2.0e4, "restitution": 0.7}],
        "loads": {"ground_acceleration": {"type": "sine", "amplitude": 4.0, "omega": 9.0}},
        "analysis": {"type": "dynamic", "integrator": "newmark", "preset": "average-acceleration",
                     "dt": 1e-4, "t_end": 3.0,
                     "output": {"every": 100, "links": ["s1", "d1", "s2", "y3", "d2"]}, **analysis},
    }
    return from_dict(d)


def test_fixed_rows_ground_contacts_and_orientation_agree():
    (fused, hf), (general, hg) = (run_full(small_chain(fused_chain=f)) for f in (True, False))
    # the history too: the fused step builds the link states for the recorded rows only
    assert hf[0] == hg[0] and any(c.startswith("link_force:") for c in hf[0])
    scale = np.abs(hg[1]).max(axis=0)
    energy = np.array([c.startswith("energy:") for c in hg[0]])
    scale[energy] = scale[energy].max()          # a balance of 1e-13 J against the energies
    assert np.all(np.abs(hf[1] - hg[1]) <= RTOL * scale)
    assert fused["cost"]["fused_chain_steps"] == fused["cost"]["steps"] == 30000
    # the scene exercises what it says: both contacts close, the bilinear spring yields
    assert len(fused["contacts"]["floor"]["impact_times"]) > 0
    assert len(fused["contacts"]["bc"]["impact_times"]) > 0
    assert fused["energy"]["plastic"] > 0
    assert fused["nodes"]["w1"]["u_max"] == fused["nodes"]["w1"]["u_min"] == 0.0
    assert_same_answers(fused, general)


def test_fused_chain_false_takes_the_general_path():
    # the setting reaches the library where c/martello.h puts it
    r = run(small_chain(fused_chain=False, t_end=0.01))
    assert r["cost"]["fused_chain_steps"] == 0
    r = run(small_chain(t_end=0.01))
    assert r["cost"]["fused_chain_steps"] == r["cost"]["steps"] == 100


def test_one_solve_per_step_while_no_branch_flips():
    # the kept factors: a linear chain whose contacts never change state is factorised once,
    # and every step is one solve (its residual is then zero to round-off: the answers above)
    s = small_chain(t_end=0.05)
    r = run(s)
    c = r["cost"]
    assert c["factorizations"] < 0.05 * c["steps"]
    assert c["newton_iterations"] <= c["steps"] + 2 * c["factorizations"]


def test_a_chattering_step_is_taken_by_the_general_path():
    # A Kelvin contact of low restitution (large c) at first touch: its force jumps to cδ̇ at
    # δ = 0, the iterates flip it on and off and never settle, so the fused step hands the
    # step to the general path, whose chatter rule holds the contact open (docs/integrators.md).
    # Everything else is fused; the answers are still the general path's.
    def scene():
        return from_dict({
            "node": [{"name": "a", "mass": 1.0, "v0": 2.0}, {"name": "b", "mass": 1.0}],
            "link": [{"type": "spring", "a": "b", "b": "ground", "k": 10.0}],
            "contact": [{"name": "c", "a": "a", "b": "b", "gap": 0.01, "scheme": "penalty",
                         "law": "kelvin", "stiffness": 1e6, "restitution": 0.05}],
            "analysis": {"type": "dynamic", "integrator": "newmark", "preset": "average-acceleration",
                         "dt": 1e-3, "t_end": 0.5, "output": {"every": 10}}})
    fused, general = summaries(scene)
    c = fused["cost"]
    assert c["contact_chatter_resolutions"] == general["cost"]["contact_chatter_resolutions"] == 1
    assert c["fused_chain_steps"] == c["steps"] - 1
    assert_same_answers(fused, general)


def test_the_benchmarks_chain_of_linear_contacts_agrees():
    # The chain of benchmarks/perf/chain_vs_opensees.py at a small n: springs and dashpots to
    # ground, one linear contact law and gap for every pair, one mass. The fused step runs it
    # through its kernels specialised for that case (chain_newmark.f90: the flags and strides
    # as constants), which no catalogue scene (Kelvin contacts) reaches. Forty pounding
    # neighbours part from round-off exponentially in time: the two paths' largest difference
    # of a node peak was measured 1e-13 of the peaks' scale at 0.5 s, 4e-11 at 2 s, 1e-7 at
    # 3 s: compared at 2 s, where RTOL is far above it.
    n = 40

    def scene():
        return from_dict({
            "chain": [{"prefix": "b", "n": n, "mass": 1.0,
                       "k": [100.0 if i % 2 == 0 else 400.0 for i in range(n)], "zeta": 0.05,
                       "gap": 0.01, "contact": {"scheme": "penalty", "law": "linear",
                                                "stiffness": 1e5}}],
            "loads": {"ground_acceleration": {"type": "sine", "amplitude": 3.0, "omega": 8.0}},
            "analysis": {"type": "dynamic", "integrator": "newmark", "dt": 1e-3, "t_end": 2.0,
                         "output": {"every": 100, "nodes": ["b1", f"b{n}"],
                                    "contacts": ["b1-b2"], "links": ["b1.spring", "b2.damper"]}}})
    fused, general = summaries(scene)
    assert fused["cost"]["fused_chain_steps"] == fused["cost"]["steps"] == 2000
    assert sum(c["impacts"] for c in fused["contacts"].values()) > 2 * n    # it pounds
    assert_same_answers(fused, general)
