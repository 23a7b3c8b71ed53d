"""P11, the case study in 3D (benchmarks/p11/case_study.py, docs/p11-case-study.md): its scenes
are what the script writes, the page's model and modes are what the model gives now (the
generated page's deterministic part, checked without runs), and a short stretch of the bare
scene pounds eccentrically (A, symmetric, turns only through the impacts)."""

import importlib.util
import subprocess
import sys
from pathlib import Path

import numpy as np

from martello.run import run_full

HERE = Path(__file__).resolve().parent.parent / "benchmarks" / "p11"


def case_study():
    spec = importlib.util.spec_from_file_location("p11_case_study", HERE / "case_study.py")
    cs = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(cs)
    return cs


def test_the_case_study_scenes_are_what_the_script_writes():
    cs = case_study()
    for config in cs.CONFIGS:
        assert (cs.SCENES / f"p11_{config}.toml").read_text() == cs.render_scene(config), config
        sc = cs.scene_for(config, 1)
        assert len(sc.blocks) == 2 and len(sc.contacts) == 10
        assert all(c.get("terms") for c in sc.contacts)          # between plan points


def test_the_page_model_and_modes_are_current():
    r = subprocess.run([sys.executable, str(HERE / "case_study.py"), "--check"], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr


def test_a_stretch_of_the_bare_scene_pounds_eccentrically():
    """5 s of record 1 (bare): the five gaps of floor 2 close unevenly along the joint, and
    the symmetric building A, at rest in torsion to round-off until the first impact, turns
    after it — eccentric pounding, which no planar model has."""
    cs = case_study()
    s, (cols, hist) = run_full(cs.scene_for("bare", 1, t_end=5.0))
    assert s["status"] == "MARTELLO_OK"
    pen = [s["contacts"][f"gap2.{j}"]["max_penetration"] for j in range(1, 6)]
    assert min(pen) > 0 and max(pen) > 1.5 * min(pen)
    t_first = min(c["impact_times"][0] for c in s["contacts"].values() if c["impacts"])
    t, rz = hist[:, cols.index("t")], np.abs(hist[:, cols.index("u:A2.rz")])
    assert rz[t < t_first].max() < 1e-15 and rz.max() > 1e-4
