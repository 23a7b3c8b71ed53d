"""Local stepping (analysis.local_stepping = true on cvode, arkode and ida; docs/sundials-ode.md, local
stepping).

Verification: catalogue rows of P7 (penalty contacts between oscillators, each its own cluster
until they touch) against the independent engine (martello.independent, stored in
reference/independent/), with the catalogue's own bounds (martello.checks.independent_rows).
Cross-check: `closing` (n oscillators, linear contacts closing and opening) against the global
CVODE run. Identities of the method (no oracle): clusters that never meet equal separate runs;
results do not depend on the output interval; a scene that is one cluster equals the global run.
Cross-check and verification of two catalogue scenes the catalogue sweep once stopped on (P10's
frame of stiffness blocks on cvode, P5's two bodies on arkode): as global, and their closed-form
rows kept.
"""

import copy
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest

from martello.checks import kinds
from martello.checks.independent_rows import verify_independent
from martello.errors import SceneError
from martello.run import run_full
from martello.scene.loader import from_dict, load

ROOT = Path(__file__).resolve().parents[1]
P7 = ROOT / "benchmarks" / "p7"


def closing(n, t_end=0.05, every=1000000, rtol=1e-8, local=True, gap=5.0e-3, dt=None, integrator="cvode"):
    """benchmarks/perf/integrators_at_size.py's `closing`: n oscillators (m = 1e5 kg, k 2e7 / 5e7
    N/m to ground, 5 % damping), linear penalty contacts of 1e9 N/m across 5 mm gaps, every other
    oscillator started at 0.2 ... 0.4 m/s towards its neighbour: every contact closes and opens."""
    chain = {"prefix": "b", "n": n, "mass": 1.0e5, "k": [2.0e7 if i % 2 == 0 else 5.0e7 for i in range(n)],
             "zeta": 0.05, "gap": gap,
             "v0": [0.3 + 0.1 * math.sin(1.7 * i) if i % 2 == 0 else 0.0 for i in range(n)],
             "contact": {"scheme": "penalty", "law": "linear", "stiffness": 1.0e9}}
    an = {"type": "dynamic", "integrator": integrator, "dt": dt or t_end, "t_end": t_end, "rtol": rtol,
          "atol": 1e-12, "output": {"every": every}}
    if local:
        an["local_stepping"] = True
    return {"title": f"closing n={n}", "chain": [chain], "analysis": an}


def run(d):
    summary, (columns, data) = run_full(from_dict(d))
    return summary, {c: data[:, i] for i, c in enumerate(columns)}


def _phases(summary):
    return {nm: list(zip(c["impact_times"], c["separation_times"], c["phase_max_penetration"]))
            for nm, c in summary["contacts"].items()}


# --- verification against the independent engine -----------------------------------------------

@pytest.mark.parametrize("integrator", ["cvode", "arkode", "ida"])
@pytest.mark.parametrize("path", ["laws/p7_two_linear_{}.toml", "laws/p7_two_hertz_{}.toml",
                                  "laws/p7_two_kelvin_{}.toml", "p7_chain_10_split.toml"])
def test_catalogue_rows_against_the_independent_engine(path, integrator):
    # Verification: the catalogue's scene on cvode with local stepping (each oscillator its own
    # cluster until a contact closes; linear and Hertz contacts stepped across, Kelvin's force
    # jump a root and a restart inside the cluster; the chain's bilinear springs yield inside
    # theirs), its rows against the stored independent reference with the catalogue's own bounds
    # (reruns at 100 and 1e4 x rtol, the reference's trusted digits).
    s = load(P7 / path.format(integrator))
    for k in ("preset", "beta", "gamma", "event_split", "fused_chain"):
        s.analysis.pop(k, None)
    s.analysis.update(integrator=integrator, local_stepping=True)
    s.analysis.setdefault("rtol", 1e-8)
    s.analysis.setdefault("atol", 1e-12)
    s.check = None
    summary, _ = run_full(s)
    rows = verify_independent(s, summary, lambda sc: run_full(sc)[0])
    assert rows, f"{path}: no stored independent reference"
    kinds.classify(rows, s.contacts)
    failed = [(r["quantity"], r["value"], r["reference"]) for r in rows if not r["passed"]]
    assert not failed, failed
    assert sum(r["kind"] == kinds.VERIFICATION for r in rows) >= 0.9 * len(rows)


# --- cross-check against the global run --------------------------------------------------------

@pytest.mark.parametrize("integrator", ["cvode", "ida"])
def test_closing_agrees_with_the_global_run(integrator):
    # Cross-check (not verification: the same kernels): `closing` with 8 oscillators, every
    # contact closing and opening once in 0.05 s, at rtol 1e-10 with and without local
    # stepping. Both locate each phase to their global error, ~rtol x the time scale of the
    # motion (T ~ 0.1 s): 1e-9 s; the penetrations (~1e-5 m) to rtol x 1e-3 m (the
    # displacement scale); 100 x leaves room for the error's growth over the events.
    local, _ = run(closing(8, rtol=1e-10, integrator=integrator))
    glob, _ = run(closing(8, rtol=1e-10, local=False, integrator=integrator))
    pl, pg = _phases(local), _phases(glob)
    assert pl.keys() == pg.keys()
    assert sum(len(v) for v in pl.values()) == 4       # the four contacts, each once
    for nm in pl:
        assert len(pl[nm]) == len(pg[nm]), nm
        for a, b in zip(pl[nm], pg[nm]):
            assert abs(a[0] - b[0]) < 1e-7 and abs(a[1] - b[1]) < 1e-7, (nm, a, b)
            assert abs(a[2] - b[2]) < 1e-9, (nm, a, b)
    for nm, node in local["nodes"].items():
        assert abs(node["u_max"] - glob["nodes"][nm]["u_max"]) < 1e-9, nm
    assert local["cost"]["events"] == glob["cost"]["events"] == 8   # o+s of four contacts


# --- identities of the method ------------------------------------------------------------------

def test_clusters_that_never_meet_equal_separate_runs():
    # Identity: oscillators behind 1 m gaps never touch: each is its own cluster throughout, on
    # its own CVODE instance, and must equal a run of that oscillator alone, bit for bit.
    d = closing(4, t_end=0.05, every=1, dt=1e-3, gap=1.0)
    s_all, h_all = run(d)
    for i in range(4):
        alone = copy.deepcopy(d)
        ch = alone["chain"][0]
        alone["chain"] = []
        k = ch["k"][i]
        alone["node"] = [{"name": f"b{i + 1}", "mass": ch["mass"], "v0": ch["v0"][i]}]
        alone["link"] = [{"type": "spring", "a": f"b{i + 1}", "b": "ground", "k": k},
                         {"type": "dashpot", "a": f"b{i + 1}", "b": "ground", "zeta": ch["zeta"]}]
        del alone["chain"]
        alone["analysis"]["local_stepping"] = False
        s1, h1 = run(alone)
        assert np.array_equal(h_all[f"u:b{i + 1}"], h1[f"u:b{i + 1}"]), i
        assert s_all["nodes"][f"b{i + 1}"]["u_max"] == s1["nodes"][f"b{i + 1}"]["u_max"], i


@pytest.mark.parametrize("integrator", ["cvode", "ida"])
def test_results_do_not_depend_on_the_output_interval(integrator):
    # Identity: rows are read on the clusters' interpolants; they change no step.
    a, _ = run(closing(6, every=1000000, integrator=integrator))
    b, hb = run(closing(6, every=1, dt=1e-3, integrator=integrator))
    assert a["cost"]["steps"] == b["cost"]["steps"]
    pa, pb = _phases(a), _phases(b)
    if integrator == "cvode":
        assert pa == pb
    else:
        # IDA: the phases' times bit for bit; a penetration peak located on a stretch that a row
        # splits differs by rounding, as in the global IDA run on this scene (measured: 3e-15
        # relative, global and local alike); 64 eps bounds the bracketing's rounding
        assert pa.keys() == pb.keys()
        for nm in pa:
            assert [p[:2] for p in pa[nm]] == [p[:2] for p in pb[nm]], nm
            for p, q in zip(pa[nm], pb[nm]):
                assert abs(p[2] - q[2]) <= 64 * np.finfo(float).eps * abs(p[2]), (nm, p, q)
    for nm in a["nodes"]:
        assert a["nodes"][nm]["u_max"] == b["nodes"][nm]["u_max"], nm
    # the works are integrated stretch by stretch (3-point Gauss on the interpolant) and a row
    # splits a stretch, as in the global run: the sums differ by the quadrature's error, far
    # below the integrator's own (rtol of the energy scale)
    assert abs(a["energy"]["balance"] - b["energy"]["balance"]) <= 1e-8 * a["energy"]["initial"]
    assert len(hb["t"]) == 51


@pytest.mark.parametrize("integrator", ["cvode", "ida"])
def test_one_cluster_equals_the_global_run(integrator):
    # Identity: P7's two oscillators joined by a spring are one cluster all along: the same
    # CVODE (IDA) steps on the same model, the same rows.
    raw = tomllib.loads((P7 / "laws" / "p7_two_linear_cvode.toml").read_text())
    raw.pop("check", None)
    raw["link"] = [{"type": "spring", "a": "s1", "b": "s2", "k": 1.0}]
    an = raw["analysis"]
    for k in ("preset", "beta", "gamma"):
        an.pop(k, None)
    an.update(integrator=integrator, rtol=1e-8, atol=1e-12)
    glob, hg = run(raw)
    an["local_stepping"] = True
    local, hl = run(raw)
    assert local["cost"]["steps"] == glob["cost"]["steps"]
    for c in hg:
        if integrator == "ida" and c.startswith("a:"):
            # the samples of the local stepping carry the model's a = M^-1 (f_ext - f_int) at
            # the state (docs/sundials-ode.md, local stepping); IDA's global run its BDF y',
            # the derivative of the step's polynomial, whose error the test on y bounds only
            # through the order's constants: within 1e3 rtol of the acceleration scale
            assert np.max(np.abs(hg[c] - hl[c])) <= 1e3 * 1e-8 * np.max(np.abs(hg[c])), c
            continue
        assert np.array_equal(hg[c], hl[c]), c


# --- what it refuses ---------------------------------------------------------------------------

def test_other_integrators_refuse_the_key():
    d = closing(4)
    d["analysis"]["integrator"] = "msbdf"
    with pytest.raises(SceneError, match="local_stepping"):
        from_dict(d)


def test_rigid_contacts_are_refused_with_the_fix():
    d = closing(4)
    d["chain"][0]["contact"] = {"scheme": "restitution", "restitution": 0.5}
    s, _ = run_full(from_dict(d), raise_on_failure=False)
    assert s["status"] != "MARTELLO_OK"
    assert "local_stepping" in s["message"] and "rigid" in s["message"]


def test_every_cluster_step_counts_against_the_budget():
    # max_steps bounds the steps of all clusters together (martello_observer_step)
    d = closing(6)
    d["analysis"]["max_steps"] = 100
    s, _ = run_full(from_dict(d), raise_on_failure=False)
    assert s["status"] == "MARTELLO_ERR_LIMIT" and "max_steps" in s["message"]
    assert s["cost"]["steps"] <= 101


# --- scenes the cross-check over the catalogue stopped on (benchmarks/local_stepping/cross_check.py)

def _cross_check(scene):
    # the cross-check of every summary number and history column against the global run within
    # both runs' own errors (same kernels: not verification), and `martello check`'s rows of the
    # scene with local stepping (closed form: verification), none lost against the global run
    from benchmarks.local_stepping import cross_check
    r = cross_check.one(ROOT / "benchmarks" / scene)
    assert "refused" not in r and "failed" not in r, r
    assert r["n_summary_mismatches"] == 0 and not r["missing"], r["summary_mismatches"]
    assert r["n_history_mismatches"] == 0, r["history_mismatches"]
    assert r["numbers"] > 10                               # it compared something
    g, loc = r["check"]["global"], r["check"]["local"]
    assert loc["verification"] > 0 and not loc["failed"], loc
    assert loc["verification_passed"] >= g["verification_passed"], r["check"]


def test_a_stiffness_block_joins_its_nodes_into_one_cluster():
    # P10's frame: its beams and columns are stiffness blocks over the joints; a block acts
    # whatever the state, so its nodes are one cluster (as a link's). The driver once split the
    # frame into clusters of one node (the sub-model then refused the cut block).
    _cross_check("p10/integrators/p10_linear_cvode.toml")


def test_arkode_clusters_without_root_functions_run():
    # P5's two free bodies: each its own cluster, their one contact between the clusters, so a
    # cluster's ARKODE instance has no root functions (its counters were once read as a failure).
    _cross_check("p5/laws/p5_linear_arkode.toml")
