"""Reference data in reference/ (docs/studies.md): each stored history still matches a fresh
computation to the digits it claims, carries its provenance, and is tied to the physics of
its scene; the independent event-located reference engine reproduces a closed form."""

import copy
import json
import math
import shutil
import tomllib
from pathlib import Path

import numpy as np
import pytest

from martello.batch import execute
from martello.checks.reference_data import verify_reference_data
from martello.history import history_dict, interpolate
from martello.metrics.score import score
from martello.reference.base import ReferenceError
from martello.reference.build import _method_runs, reference_scene
from martello.reference.independent_engine import NAME as ENGINE, engine_run
from martello.reference.selection import reference_for_scene
from martello.reference.store import find_reference_data, load_reference, manifest, physics_digest
from martello.scene.loader import from_dict, load

ROOT = Path(__file__).resolve().parent.parent
ENTRIES = manifest()
PROVENANCE = ("scene", "scene_sha256", "physics_sha256", "method", "digits", "refinement",
              "martello_version", "libraries", "date", "events", "t_end")


@pytest.mark.parametrize("entry", ENTRIES, ids=[e["name"] for e in ENTRIES])
def test_stored_reference_has_provenance_and_matches_its_scene(entry):
    ref = load_reference(entry["folder"])
    meta = ref.provenance
    for key in PROVENANCE:
        assert key in meta, key
    sc, _, _ = reference_scene(entry)
    # the data are for this scene's physics as it is now (else: regenerate)
    assert meta["physics_sha256"] == physics_digest(sc)
    assert reference_for_scene(sc).name == ref.name
    u_digits = [d for c, d in meta["digits"].items() if c.startswith("u:")]
    assert min(u_digits) >= 4.0
    assert ref.times[0] == 0.0 and ref.times[-1] == pytest.approx(sc.analysis["t_end"])
    # a cross-check by a second, independent method agrees within the looser of the two
    cc = meta.get("cross_check")
    if cc:
        assert cc["max_rel_diff_u"] < 1e-3


def _fresh(entry):
    """Recompute a reference with its own method at its coarsest refinement level (the
    cheapest run whose difference from the stored data was recorded)."""
    meta = json.loads((entry["folder"] / "reference.json").read_text())
    method = meta["method"]
    ref = load_reference(entry["folder"])
    level = meta["refinement"][-1]
    sc, d, path = reference_scene(entry)
    if method["integrator"] == ENGINE:
        out = engine_run(d, path.parent, level["rtol"], ref.times, sc.analysis["t_end"])
    else:
        spec = _method_runs(entry, method, d, path, level["dt"], level["rtol"])
        out = execute(spec)
    assert out["status"] == "MARTELLO_OK", out.get("message")
    return ref, level, out


@pytest.mark.parametrize("entry", ENTRIES, ids=[e["name"] for e in ENTRIES])
def test_fresh_computation_matches_the_stored_data(entry):
    # The stored history is the finest level; the coarsest level differed from it by
    # level["max_rel_diff_u"] when it was made. A fresh run of that level must differ from
    # the stored data by the same amount (the computation is deterministic), to the trusted
    # digits of the stored data: |d_fresh − d_stored| ≤ 10^-digits.
    ref, level, out = _fresh(entry)
    h = history_dict(out["history"])
    diffs = []
    for c in ref.columns:
        if c.startswith("u:"):
            y = interpolate(h["t"], h, c, ref.times)
            diffs.append(np.max(np.abs(y - ref.samples[c])) / np.max(np.abs(ref.samples[c])))
    trusted = 10.0 ** -min(d for c, d in ref.digits.items() if c.startswith("u:"))
    assert abs(max(diffs) - level["max_rel_diff_u"]) <= trusted
    # and the impacts are the same ones
    for name, ev in ref.events.items():
        assert len(out["summary"]["contacts"][name]["impact_times"]) == len(ev["impact_times"])


def test_the_independent_engine_as_a_reference_reproduces_the_closed_form():
    # P2 with a Kelvin plane: exact piecewise solution
    # (martello.oracles.p2_bouncing.bouncing_oscillator_kelvin); the engine reads the scene's
    # own tables (not the loaded Scene) and its result is scored as a library run's
    path = ROOT / "benchmarks" / "p2" / "p2_penalty_kelvin.toml"
    d = tomllib.loads(path.read_text())
    grid = np.linspace(0.0, 0.7, 1401)
    out = engine_run(d, path.parent, 1e-12, grid)
    ref = reference_for_scene(load(path))
    m = score(out["summary"], out["history"], ref, times=grid)
    assert m["max_rel_error"] < 1e-10
    assert m["impact_time_error"] < 1e-11 and m["impact_count_error"] == 0
    assert m["phase_penetration_error"] < 1e-9 and m["restitution_error"] < 1e-10


def test_the_independent_engine_says_what_it_cannot_run():
    from martello.independent import Unsupported
    d = {"node": [{"name": "m", "mass": 1.0}],
         "contact": [{"name": "c", "a": "m", "b": "ground", "scheme": "lagrange"}],
         "analysis": {"type": "dynamic", "integrator": "rk8pd", "dt": 1e-3, "t_end": 1.0}}
    with pytest.raises(Unsupported, match="lagrange"):
        engine_run(d, ROOT, 1e-10, np.linspace(0.0, 1.0, 11))


def test_stale_reference_data_are_refused(tmp_path):
    # a reference whose scene file has changed since: an error naming the fix
    root = tmp_path / "reference"
    root.mkdir()
    src = ENTRIES[0]
    shutil.copytree(src["folder"], root / src["name"])
    scene_copy = tmp_path / "scene.toml"
    text = (ROOT / src["scene"]).read_text()
    scene_copy.write_text(text.replace("gap = 0.0", "gap = 0.5").replace("gap = 0.01", "gap = 0.011")
                          .replace("gap = 0.02", "gap = 0.021").replace("gap = 0.05", "gap = 0.051"))
    (root / "references.toml").write_text(
        f'[[reference]]\nname = "{src["name"]}"\nscene = "{scene_copy}"\nstore_every = 1.0\n')
    with pytest.raises(ReferenceError, match="regenerate_reference"):
        find_reference_data(load(scene_copy), root)
    # the unchanged scene still finds its data through the physics digest
    assert find_reference_data(load(ROOT / src["scene"]), root) is not None


def test_check_rows_for_scenes_without_closed_form():
    # `martello check` extension: a scene with reference data gets verification rows
    from martello.run import run_full
    sc = load(ROOT / "benchmarks" / "p7" / "p7_two_oscillators.toml")
    summary, hist = run_full(sc)
    rows = verify_reference_data(sc, summary, hist)
    assert rows and all(r["passed"] for r in rows), rows
    assert {"scene", "quantity", "value", "digits", "passed", "why"} <= set(rows[0])
