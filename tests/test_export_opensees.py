"""martello export --to opensees run by OpenSees itself (openseespy, installed from
requirements.txt; users: pip install 'martello[opensees]'). Evidence: the exported model
equals an OpenSees model written by hand without the exporter (benchmarks/opensees/
hand_built.py) to round-off, and on a scene whose laws map exactly (Kelvin: ViscoelasticGap)
equals martello's own Newmark to the Newton tolerance; both are identities of one method on
one model, not verification (the scores against references are benchmarks/opensees/)."""

import subprocess
import sys

import numpy as np
import pytest
from benchmarks.opensees import two_buildings
from martello.export import export
from martello.run import run_full
from martello.scene.loader import from_dict, load


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


def plain_nodes_beside_buildings():
    """tests/test_export.py shear_buildings with plain [[node]]s beside them (x-only nodes at
    the origin in the 3D model): a pair p, q that strikes itself, not joined to a building,
    and a free node w; the ground motion along x (plain nodes move along the scene's axis)."""
    from tests.test_export import shear_buildings
    d = shear_buildings()
    for b in d["building"]:
        b["ground_angle"] = 0.0
    d["node"] = [{"name": "w", "mass": 1e3}, {"name": "p", "mass": 10.0, "v0": 1.0},
                 {"name": "q", "mass": 10.0}]
    d["contact"].append({"name": "pq", "a": "p", "b": "q", "gap": 0.001, "scheme": "penalty",
                         "law": "linear", "stiffness": 2e6})
    return d


def floor_against_a_wall_node():
    """small_buildings with A's first floor striking a fixed [[node]] w on its −x side (normal
    [−1, 0], w side b: martello's row −ux(P) − u_w, u_w ≡ 0): the export refused any normal but
    +x for a plain node's side. Measured: u 1.7e-13, a 1.3e-12, force 9.8e-14 of their peaks."""
    from tests.test_export import small_buildings
    d = small_buildings(reference=False)
    for b in d["building"]:
        b["ground_angle"] = 0.0
    d["node"] = [{"name": "w", "mass": 1e3, "fixed": True}]
    d["contact"].append({"name": "fw", "a": {"floor": "A1", "x": 0.0, "y": 3.0}, "b": "w",
                         "normal": [-1.0, 0.0], "gap": 0.0005, "scheme": "penalty", "law": "linear",
                         "stiffness": 5e8})
    return d


@pytest.mark.parametrize("which", ["frames", "shear", "plain", "modal", "wall"])
def test_exported_buildings_equal_martellos_condensed_buildings(tmp_path, which):
    """Two small 3D frame buildings (tests/test_export.py small_buildings: Timoshenko columns,
    a wall that makes B twist, B's floors referred off their mass centres, a gap and a fluid
    damper between plan points off the centre line, Rayleigh 5 %, a cosine ground motion so
    that a_0 ≠ 0 on every floor) uncondensed in OpenSees on
    rigid diaphragms against martello's condensed blocks and plan-point rows, Newmark 1 ms over
    0.3 s, 2 impacts: the same discrete equations, so they agree to the Newton tolerances
    (measured 9.5e-14 of the floors' peak u, 1.5e-12 of a, 8.7e-13 of the peak penetration,
    3.5e-13 of the largest member moment); the 9 periods from OpenSees' eigen on the 3D frame against
    martello's modal table of the condensed model (measured 8.5e-14). A cross-check against
    another code's assembly, not verification of the step. Likewise two shear-type buildings
    (tests/test_export.py shear_buildings: pinned feet, a flexible floor, a split point struck
    by a floor, a node-pair gap from a joint to a floor, the ground motion at 30°, one impact
    at each gap): measured 1.4e-13 of u, 6.3e-12 of a, 1.3e-12 of the penetration, 3.9e-13 of
    M3, 19 periods 4.7e-13. Likewise with plain nodes beside them (plain_nodes_beside_buildings:
    the export failed on any contact of a plain node in a building scene). Likewise the small
    buildings with martello's modal damping (floors referred to their mass centres), written as
    OpenSees' eigen + modalDamping (docs/opensees.md "Modal damping"; it was refused): with
    modalDamping OpenSees' Newton converges linearly (measured), so its increment test bounds
    the error only through the contraction: at the default 1e-12 m the floors' a differ by
    5.7e-9 of their peak, at 1e-15 m (used here) by 1.8e-11, u 3.8e-14, M3 4.8e-12."""
    from tests.test_export import shear_buildings, small_buildings
    if which == "frames":
        d = small_buildings()
        d["loads"]["ground_acceleration"]["phase"] = np.pi / 2    # a_0 ≠ 0: committed on the masters
    elif which == "shear":
        d = shear_buildings()
    elif which == "plain":
        d = plain_nodes_beside_buildings()
    elif which == "wall":
        d = floor_against_a_wall_node()
    else:
        d = small_buildings(reference=False)
        for b in d["building"]:
            b["damping"] = "modal"
    scene = from_dict(d, source=which)
    export(scene, tmp_path / "x", tol=1e-15 if which == "modal" else None)
    for args in (["--periods"], []):
        r = subprocess.run([sys.executable, "model.py", *args], cwd=tmp_path / "x", capture_output=True, text=True)
        assert r.returncode == 0, r.stderr[-2000:]
    periods = np.loadtxt(tmp_path / "x" / "periods.csv", delimiter=",", skiprows=1)[:, 1]
    ours = sorted((m["period"] for b in scene.extras["buildings"] for m in b["modes"]), reverse=True)
    # the plain nodes' modes have no stiffness (period inf) and come first, displacing as
    # many of the building's shortest periods from the MODES asked for
    free = sum(not n.get("fixed") for n in d.get("node", []))
    assert np.all(np.isinf(periods[:free]))
    assert np.allclose(periods[free:], ours[:len(ours) - free], rtol=1e-9, atol=0)   # eigen's own tolerance, not the step's
    summary, (cols, data) = run_full(scene)
    cols = list(cols)
    assert all(c["impacts"] >= 1 for c in summary["contacts"].values())
    for name in ("history.csv", "members.csv"):
        head = (tmp_path / "x" / name).read_text().splitlines()[0].split(",")
        os_h = np.loadtxt(tmp_path / "x" / name, delimiter=",", skiprows=1)
        assert np.array_equal(os_h[:, 0], data[:, cols.index("t")])
        families = {}
        for c in head[1:]:
            if c in cols:                 # martello records no N, V3, M2 of a rigid floor's beams
                families.setdefault(c.split(":")[0][:2], []).append(c)
        for fam, names in families.items():
            scale = max(np.max(np.abs(data[:, cols.index(c)])) for c in names)
            # the Newton tests: martello's residual 1e-9 of the force scale, the script's 1e-12 m
            worst = max(np.max(np.abs(os_h[:, head.index(c)] - data[:, cols.index(c)])) for c in names)
            assert worst <= 1e-8 * scale, (name, fam, worst / scale)
