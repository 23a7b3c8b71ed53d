"""Tests that would have caught each finding of the verification audit (docs/coverage.md
"Kinds of evidence"): a wrong cell reported as success (Moreau–Jean × Jankowski), a drift
row passing with a missed impact, NaN in a JSON reference file, the energy balance read as
accuracy. Each says what kind of evidence it is."""

import copy
import hashlib
import json
import math
from pathlib import Path

import pytest

from martello.checks.independent_rows import INDEPENDENT_ROOT, accuracy_rows, find_independent
from martello.checks.measures import run_measured
from martello.errors import SceneError
from martello.oracles.linear_sdof import sdof_free_response
from martello.report import headline
from martello.run import run_full
from martello.scene.loader import from_dict, load

ROOT = Path(__file__).resolve().parent.parent


def test_every_reference_file_is_strict_json():
    # RFC 8259 has no NaN or Infinity; Python's json writes them unless told not to
    files = sorted((ROOT / "reference").rglob("*.json"))
    assert len(files) >= 20
    for f in files:
        json.loads(f.read_text(), parse_constant=lambda c, f=f: pytest.fail(f"{c} in {f}"))


def test_the_reference_writer_refuses_nan():
    from martello.reference.build import strict_json
    assert json.loads(strict_json({"observed_order": math.nan})) == {"observed_order": None}


def jankowski_on(integrator):
    text = (ROOT / "benchmarks/p5/p5_jankowski.toml").read_text()
    text = text.replace('integrator = "newmark"', f'integrator = "{integrator}"') \
        .replace('preset = "average-acceleration"\n', "")
    return text


def test_moreau_jean_refuses_jankowski(tmp_path):
    # it bounced with e ≈ 1 instead of 0.647 (status OK, no warning): now refused, with the fix
    p = tmp_path / "mj_jankowski.toml"
    p.write_text(jankowski_on("moreau-jean"))
    with pytest.raises(SceneError, match="law jankowski cannot run on integrator moreau-jean"):
        load(p)


def test_the_library_refuses_moreau_jean_with_jankowski_too(tmp_path):
    # a caller that skips the loader meets the same refusal in fortran/run_checks.f90
    p = tmp_path / "nm.toml"
    p.write_text(jankowski_on("newmark").replace("t_end = 0.005", "t_end = 0.0011"))
    s = load(p)
    s.analysis.update(integrator="moreau-jean", theta=0.5)
    for k in ("beta", "gamma", "tol_residual", "tol_increment", "max_newton", "preset"):
        s.analysis.pop(k, None)
    from martello.errors import MartelloError
    with pytest.raises(MartelloError, match="jankowski cannot run on moreau-jean"):
        run_full(s)


def p8_bare():
    s = load(ROOT / "benchmarks/p8/p8_bare.toml")
    ref = find_independent(s)
    assert ref is not None and ref["name"] == "p8_bare"
    return s, ref


def test_an_accuracy_row_fails_on_a_missed_impact():
    # the drift rows passed with one impact missed (tolerance = the old count error); an
    # accuracy row against the independent reference needs the exact count
    s, ref = p8_bare()
    summary = run_measured(s)[0]
    rows = accuracy_rows(s.title, s.source, ref, [summary, summary, summary], dt=s.analysis["dt"])
    assert rows and all(r["passed"] for r in rows if r["quantity"].endswith(".impacts vs independent"))
    missed = copy.deepcopy(summary)
    c = missed["contacts"]["f2.gap1"]
    c["impacts"] -= 1
    for k in ("impact_times", "phase_max_penetration"):
        c[k] = c[k][:-1]
    rows = accuracy_rows(s.title, s.source, ref, [missed] * 3, dt=s.analysis["dt"])
    count = {r["quantity"]: r["passed"] for r in rows if r["quantity"].endswith(".impacts vs independent")}
    assert count.pop("contacts.f2.gap1.impacts vs independent") is False
    assert all(count.values())


def test_p8_is_verified_against_the_independent_engine():
    # verification against an independent reference: peaks, every impact, dissipated energy
    s, ref = p8_bare()
    summary = run_measured(s)[0]
    runs = [summary]
    for f in (2.0, 4.0):
        s2 = copy.deepcopy(s)
        s2.analysis["dt"] *= f
        runs.append(run_measured(s2)[0])
    rows = accuracy_rows(s.title, s.source, ref, runs, dt=s.analysis["dt"])
    assert len(rows) > 100 and all(r["passed"] for r in rows), [r for r in rows if not r["passed"]][:2]
    assert {r["evidence"] for r in rows} == {"independent reference"}
    energy = [r for r in rows if r["quantity"].startswith("energy.")]
    assert len(energy) == 2 and min(r["digits"] for r in energy) >= 4


def test_the_energy_balance_is_an_identity_not_accuracy():
    # trapezoidal Newmark: an SDOF at ωΔt = 0.5 is far off the exact solution while its
    # work-energy balance is exact to round-off; the balance must not be read as accuracy
    scene = {"node": [{"name": "m", "mass": 1.0, "u0": 0.01}],
             "link": [{"type": "spring", "a": "m", "b": "ground", "k": 100.0}],
             "analysis": {"type": "dynamic", "integrator": "newmark", "dt": 0.05, "t_end": 2.0,
                          "output": {"nodes": ["m"]}}}
    summary, _ = run_full(from_dict(scene))
    exact = float(sdof_free_response(1.0, 100.0, 0.0, [2.0], u0=0.01).u[0])
    assert abs(summary["energy"]["balance_relative"]) < 1e-12
    assert abs(summary["nodes"]["m"]["u_final"] - exact) > 0.3 * 0.01


def test_the_headline_counts_only_verification():
    rows = [{"evidence": "closed form", "passed": True, "rtol": 1e-6, "reference": 1.0, "digits": 9.0},
            {"evidence": "independent reference", "passed": True, "rtol": 0.0, "atol": 1e-9, "reference": 1.0,
             "digits": 9.0},
            {"evidence": "regression", "passed": True}]
    text = headline(rows, [], 3, 1.0)
    assert text.startswith("verification: 2 of 2 distinct rows passed (1 vs closed form, 0 vs published value, "
                           "1 vs independent reference")
    assert "0 of 1 regression rows passed" not in text and "1 of 1 regression rows passed" in text


def test_stored_independent_references_say_what_they_are():
    for f in sorted(INDEPENDENT_ROOT.glob("*.json")):
        ref = json.loads(f.read_text())
        assert ref["provenance"]["engine"] == "martello.independent"
        assert ref["trusted_digits"] is not None and ref["name"] == f.stem


def test_every_stored_independent_reference_still_serves_its_scene():
    # A reference is found by the digest of its scene's physics, full-precision matrices
    # included (martello.reference.store.physics_digest): a last-bit change of how a frame's
    # damping is made (eigh's eigenvalues for eigvalsh's) left P10's three scenes without
    # their 239 verification rows, silently ("ran, not verified"). Loading only, no run.
    # Those named after their scene file and computed from it as it is (the others are a
    # file with a law or a setting changed: their scenes are found by the catalogue check).
    lost, served = [], 0
    for f in sorted(INDEPENDENT_ROOT.glob("*.json")):
        ref = json.loads(f.read_text())
        path = ROOT / ref["scene"]
        if not ref.get("catalogue", True) or ref["name"] != path.stem or \
                ref["scene"] not in ref.get("scenes", [ref["scene"]]) or \
                hashlib.sha256(path.read_bytes()).hexdigest() != ref["scene_sha256"]:
            continue
        scene = load(path)
        if ref.get("t_end") != scene.analysis.get("t_end"):
            continue                          # a longer or shorter run of the file's physics
        served += 1
        if find_independent(scene) is None:
            lost.append(ref["scene"])
    assert served >= 4                       # P10's three frames and P11's buildings at least
    assert not lost, f"stored independent references no longer found for {lost}"


@pytest.mark.parametrize("law", ["linear", "hertz", "lankarani_nikravesh"])
def test_moreau_jean_penalty_restitution_is_that_of_its_own_velocities(law):
    # It reported e from a separation velocity extrapolated with the step's mean acceleration
    # (which holds the contact force): 0.99999993 on the linear law at h = 1e-6 while its
    # final velocities gave 0.99999939. P5's bodies are free after the contact, so the
    # summary's e must be −(v1 − v2)/(v1 − v2)_0 of the last state to round-off (an identity
    # of the method's own states), and that e must match the closed form two_body_impact
    # (verification): Moreau–Jean linearises the force once a step, O(ωh) with ωh = 1.2e-3
    # at h = 1e-6 (ω = √(K/m*) = 1.2e3 /s on the linear law, √(1.5 K √δ_max / m*) ≈ 2.3e3 /s
    # at the Hertz and LN peak tangent); 5 ωh covers an O(ωh) constant of 5.
    from martello.checks.dispatchers import two_body_impact
    s = load(ROOT / f"benchmarks/p5/laws/p5_{law}_moreau_jean.toml")
    s.analysis["dt"] = 1e-6
    s.analysis["output"]["every"] = 1
    summary, (cols, data) = run_full(s)
    e = summary["contacts"]["impact"]["restitution"]
    assert len(e) == 1
    v_rel0 = 1.0
    e_states = -(data[-1, cols.index("v:m1")] - data[-1, cols.index("v:m2")]) / v_rel0
    assert e[0] == pytest.approx(e_states, rel=1e-12, abs=1e-13)
    p = s.check["params"]
    closed = two_body_impact(**p)
    mstar = 2.0 / 3.0
    tangent = p["stiffness"] if law == "linear" else 1.5 * p["stiffness"] * math.sqrt(closed["max_penetration"])
    omega_h = math.sqrt(tangent / mstar) * 1e-6
    assert abs(e[0] - closed["restitution"]) <= 5.0 * omega_h


def test_a_verified_cell_names_its_regression_only_scenes():
    # P7's Kelvin Newmark cell holds the verified event-split scenes and p7_two_oscillators
    # (Newmark at Δt = 1e-4 without a split: regression rows only); the cell's state must not
    # speak for the latter
    from martello.report import coverage, coverage_markdown
    base = {"problem": "P7", "laws": "kelvin", "integrator": "newmark", "passed": True, "digits": 4.7,
            "rtol": 1e-6, "reference": 1.0}
    rows = [dict(base, evidence="independent reference", file="laws/p7_two_kelvin_newmark.toml"),
            dict(base, evidence="regression", file="p7/p7_two_oscillators.toml")]
    (cell,) = coverage(rows)
    assert cell["state"] == "verified" and cell["unverified_scenes"] == ["p7_two_oscillators"]
    assert "scenes without a verification row: `p7_two_oscillators`" in coverage_markdown(rows)
