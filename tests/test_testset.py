"""martello testset (docs/testset.md): one JSON file and one page per problem, the reference
values recomputed here from the physics, the digits of printed values, the regression kind."""

import json
import math
import subprocess
import sys
from pathlib import Path

from martello.scene.loader import load
from martello.testset import build, page, problem

ROOT = Path(__file__).resolve().parent.parent


def test_the_catalogue_set_has_a_problem_per_closed_form_scene(tmp_path):
    r = subprocess.run([sys.executable, "-m", "martello", "testset", "-o", str(tmp_path / "ts")],
                       capture_output=True, text=True, cwd=ROOT)
    assert r.returncode == 0, r.stderr
    index = json.loads((tmp_path / "ts" / "index.json").read_text())
    with_check = [p for p in (ROOT / "benchmarks").rglob("*.toml")
                  if "perf" not in p.parts and "studies" not in p.parts
                  and "\n[check]" in "\n" + p.read_text()]
    assert index["problems"] == len(with_check) > 100
    rows = sum(p.read_text().count("[[check.compare]]") for p in with_check)
    assert index["reference_values"] == rows
    for f in index["files"]:
        assert (tmp_path / "ts" / f["json"]).is_file() and (tmp_path / "ts" / f["page"]).is_file()
    assert index["martello"] in (tmp_path / "ts" / "README.md").read_text()


def test_a_problem_file_states_model_references_digits_and_provenance(tmp_path):
    s = load(ROOT / "benchmarks/vendor/ansys_vm65_ball_on_spring.toml")
    p = problem(s, ROOT / "benchmarks", "0.test")
    assert p["id"] == "vendor.ansys_vm65_ball_on_spring"
    (c,) = p["model"]["contacts"]
    assert (c["law"], c["gap"], c["a"], c["b"]) == ("linear", 0.0254, "ball", "ground")
    h, g = 0.0254, 386 * 0.0254
    ref = {(r["quantity"], r["source"]): r for r in p["references"]}
    exact = ref[("contacts.surface.impact_times.0", "closed form")]
    assert exact["value"] == math.sqrt(2 * h / g) and exact["trusted_digits"] == 15
    printed = ref[("contacts.surface.impact_times.0", "printed by the vendor's manual")]
    assert printed["value"] == 0.071982 and printed["trusted_digits"] == 5
    speed = ref[("contacts.surface.approach_speeds.0", "printed by the vendor's manual")]
    assert speed["trusted_digits"] == 5                            # -27.785 in/s
    assert p["provenance"]["scene_sha256"] == s.digest and p["provenance"]["martello"] == "0.test"
    text = page(p)
    assert "## Reference solution" in text and "0.071982" in text


def test_regression_kind_is_martellos_own_value(tmp_path):
    """With --run each reference gains martello's value at the scene's settings; it lies
    within the analytic tolerance of the reference (the scene passes its check)."""
    scenes = [load(ROOT / "benchmarks/p5/p5_newton_e03.toml")]
    index = build(tmp_path / "ts", scenes, ROOT / "benchmarks", "0.test", run=True)
    assert index["problems"] == 1
    p = json.loads((tmp_path / "ts" / f"{index['files'][0]['id']}.json").read_text())
    m1, m2, v1, v2, e = (p["provenance"]["params"][k] for k in ("m1", "m2", "v1", "v2", "e"))
    newton = {"v1": v1 - (1 + e) * m2 * (v1 - v2) / (m1 + m2), "v2": v2 + (1 + e) * m1 * (v1 - v2) / (m1 + m2)}
    for r in p["references"]:
        field = r["oracle"].split(".")[-1]
        if field in newton:
            assert math.isclose(r["value"], newton[field], rel_tol=1e-14, abs_tol=1e-15)
        reg, an = r["tolerance"]["regression"], r["tolerance"]["analytic"]
        assert abs(reg["value"] - r["value"]) <= an["atol"] + an["rtol"] * abs(r["value"])
