"""martello export --to opensees run by OpenSees itself (openseespy, installed from
requirements.txt; users: pip install 'martello[opensees]'). Evidence: the exported model
equals an OpenSees model written by hand without the exporter (benchmarks/opensees/
hand_built.py) to round-off, and on a scene whose laws map exactly (Kelvin: ViscoelasticGap)
equals martello's own Newmark to the Newton tolerance; both are identities of one method on
one model, not verification (the scores against references are benchmarks/opensees/)."""

import subprocess
import sys

import numpy as np
from benchmarks.opensees import two_buildings
from martello.export import export
from martello.run import run_full
from martello.scene.loader import load


def test_exported_equals_hand_built_on_peaks_drifts_and_impacts(tmp_path):
    e, b, worst, hist = two_buildings.run(tmp_path)
    assert e["impacts"] == b["impacts"] == 4
    assert worst <= 1e-6            # the bar; measured 8e-16 (the same arithmetic)
    assert hist <= 1e-12            # over the whole history, in m (measured 2e-16)


def test_exported_kelvin_scene_equals_martellos_newmark(tmp_path):
    """P7's two oscillators (Kelvin contact, Newmark Δt = 1e-4 s) over 1 s: OpenSees and
    martello take the same steps of the same equations; they differ by their Newton
    tolerances (martello's 1e-9 residual test, the exported 1e-12 m increment test)."""
    scene = load("benchmarks/p7/p7_two_oscillators.toml")
    export(scene, tmp_path / "x", analysis={"t_end": 1.5})
    r = subprocess.run([sys.executable, "model.py"], cwd=tmp_path / "x", capture_output=True, text=True)
    assert r.returncode == 0, r.stderr[-2000:]
    head = (tmp_path / "x" / "history.csv").read_text().splitlines()[0].split(",")
    os_h = np.loadtxt(tmp_path / "x" / "history.csv", delimiter=",", skiprows=1)
    scene.analysis["t_end"] = 1.5
    summary, (cols, data) = run_full(scene)
    cols = list(cols)
    assert np.array_equal(data[:, cols.index("t")], os_h[:, 0])
    for c in ("u:s1", "u:s2"):
        ref = data[:, cols.index(c)]
        assert np.max(np.abs(os_h[:, head.index(c)] - ref)) <= 1e-7 * np.max(np.abs(ref))
    assert summary["contacts"]["s1-s2"]["impacts"] >= 3
    for c in ("energy:kinetic", "energy:recoverable"):     # the script's own bookkeeping
        ref = data[:, cols.index(c)]
        assert np.max(np.abs(os_h[:, head.index(c)] - ref)) <= 1e-6 * np.max(np.abs(ref)), c


def test_exported_frames_equal_martellos_condensed_frames(tmp_path):
    """P10's bare frames (2 + 5 storeys, joint masses, Rayleigh 5 %, a recorded ground
    motion) uncondensed in OpenSees against martello's condensed blocks, Newmark Δt = 5e-4 s
    over 1 s: the massless DOFs condense exactly (docs/opensees.md "Frames"); measured 2e-12
    of the peak over 2 s."""
    scene = load("benchmarks/p10/p10_bare.toml")
    export(scene, tmp_path / "x", analysis={"t_end": 1.0})
    r = subprocess.run([sys.executable, "model.py"], cwd=tmp_path / "x", capture_output=True, text=True)
    assert r.returncode == 0, r.stderr[-2000:]
    head = (tmp_path / "x" / "history.csv").read_text().splitlines()[0].split(",")
    os_h = np.loadtxt(tmp_path / "x" / "history.csv", delimiter=",", skiprows=1)
    scene.analysis["t_end"] = 1.0
    _, (cols, data) = run_full(scene)
    cols = list(cols)
    for c in (c for c in head if c.startswith("u:")):
        ref = data[:, cols.index(c)]
        assert np.max(np.abs(os_h[:, head.index(c)] - ref)) <= 1e-9 * np.max(np.abs(ref)), c
