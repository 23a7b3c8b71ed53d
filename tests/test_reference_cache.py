"""References for any scene (docs/reference.md): `martello reference` computes one with its
trusted digits and provenance and caches it per scene physics; `martello compare` uses it
for a scene that is not in the catalogue, with a history from a CSV or OpenSees recorder
files. The oracle is a short scipy run written here from the equations of motion of the
scene (not martello's code, not its event-located engine)."""

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from martello.errors import MartelloError
from martello.reference import cache
from martello.scene.loader import from_dict, load

ROOT = Path(__file__).resolve().parent.parent

# Two masses on springs to the ground, a Hertz contact between them (F = K δ^1.5, δ = u1 −
# u2 − gap, docs/scene-input.md), the first thrown at the second: a scene of no catalogue
# problem, with no closed form and no stored reference data.
M1, M2, K1, K2, KC, GAP, V0, T_END = 2.0, 1.0, 50.0, 200.0, 1.0e5, 0.02, 0.5, 2.0
SCENE = f"""
title = "two masses, Hertz contact (test scene)"
[[node]]
name = "m1"
mass = {M1}
v0 = {V0}
[[node]]
name = "m2"
mass = {M2}
[[link]]
type = "spring"
a = "m1"
b = "ground"
k = {K1}
[[link]]
type = "spring"
a = "m2"
b = "ground"
k = {K2}
[[contact]]
name = "c"
a = "m1"
b = "m2"
gap = {GAP}
scheme = "penalty"
law = "hertz"
stiffness = {KC}
[analysis]
type = "dynamic"
integrator = "newmark"
dt = 1.0e-4
t_end = {T_END}
[analysis.output]
every = 10
"""


def scipy_history(times):
    """The scene integrated by scipy's DOP853 from its equations of motion,
    m1 ü1 = −k1 u1 − P, m2 ü2 = −k2 u2 + P, P = K max(δ, 0)^1.5, restarted at every root of
    δ so that no step straddles a contact onset or separation. Returns {column: values}."""
    def rhs(t, y):
        u1, u2, v1, v2 = y
        d = u1 - u2 - GAP
        p = KC * d ** 1.5 if d > 0 else 0.0
        return [v1, v2, (-K1 * u1 - p) / M1, (-K2 * u2 + p) / M2]

    def gap(t, y):
        return y[0] - y[1] - GAP
    gap.terminal = True
    y, t, pieces, touching = np.array([0.0, 0.0, V0, 0.0]), 0.0, [], False
    while t < T_END:
        # the next onset (δ rising through 0) or separation (δ falling through 0) ends a piece
        gap.direction = -1.0 if touching else 1.0
        sol = solve_ivp(rhs, (t, T_END), y, method="DOP853", rtol=1e-12, atol=1e-15,
                        dense_output=True, events=gap)
        pieces.append((t, float(sol.t[-1]), sol.sol))
        y, t = sol.y[:, -1], float(sol.t[-1])
        touching = not touching if sol.status == 1 else touching
    out = np.zeros((len(times), 4))
    for i, tt in enumerate(times):
        for a, b, f in pieces:
            if a <= tt <= b:
                out[i] = f(tt)
                break
        else:
            raise AssertionError(f"t = {tt} in no dense piece")
    d = out[:, 0] - out[:, 1] - GAP
    return {"u:m1": out[:, 0], "u:m2": out[:, 1], "v:m1": out[:, 2], "v:m2": out[:, 3],
            "penetration:c": d, "force:c": KC * np.where(d > 0, d, 0.0) ** 1.5}


@pytest.fixture(scope="module")
def work(tmp_path_factory):
    """The scene file, the scipy history as a CSV and as OpenSees recorder files, and a
    fresh cache folder."""
    base = tmp_path_factory.mktemp("ondemand")
    scene = base / "two_masses.toml"
    scene.write_text(SCENE)
    times = np.linspace(0.0, T_END, 2001)        # the scene's output times, every 1 ms
    h = scipy_history(times)
    cols = ["u:m1", "u:m2", "v:m1", "v:m2", "penetration:c", "force:c"]
    np.savetxt(base / "their.csv", np.column_stack([times] + [h[c] for c in cols]), delimiter=",",
               header=",".join(["t"] + cols), comments="", fmt="%.17g")
    # OpenSees node recorders (`recorder Node -file disp.out -time -precision 13 -node 1 2
    # -dof 1 disp`): no header, whitespace, time first; OpenSees records after each step,
    # so there is no t = 0 row. The second node's axis points the other way (-u:m2).
    rec = times[1:]
    np.savetxt(base / "disp.out", np.column_stack([rec, h["u:m1"][1:], -h["u:m2"][1:]]), fmt="%.12e")
    np.savetxt(base / "vel.out", np.column_stack([rec, h["v:m1"][1:], -h["v:m2"][1:]]), fmt="%.12e")
    env = dict(os.environ, MARTELLO_CACHE_DIR=str(base / "cache"))
    return {"dir": base, "scene": scene, "env": env, "history": h, "times": times}


def martello(*args, env=None, timeout=300):
    """The command line in a fresh interpreter, as a user runs it."""
    return subprocess.run([sys.executable, "-m", "martello", *map(str, args)], cwd=ROOT,
                          capture_output=True, text=True, timeout=timeout, env=env)


@pytest.fixture
def cli(work, monkeypatch, capsys):
    """The command line in this interpreter (cli.main, what `martello` calls), with the
    test's cache: (exit code, stdout, stderr)."""
    from martello.cli import main
    monkeypatch.setenv("MARTELLO_CACHE_DIR", work["env"]["MARTELLO_CACHE_DIR"])

    def run(*args):
        capsys.readouterr()
        rc = main([str(a) for a in args])
        out, err = capsys.readouterr()
        return subprocess.CompletedProcess(args, rc, out, err)
    return run


def test_compare_computes_and_caches_the_reference_of_a_new_scene(work):
    out = work["dir"] / "score.json"
    r = martello("compare", work["dir"] / "their.csv", "--against", work["scene"], "-o", out,
                 env=work["env"])
    assert r.returncode == 0, r.stderr
    assert "computed and cached" in r.stderr
    rep = json.loads(out.read_text())
    comp = rep["computed_reference"]
    assert comp["method"]["integrator"] == "independent" and not comp["cached"]
    # the trusted digits come from two routes: the independent engine refined, and martello's
    # own best run (rk8pd)
    assert "rk8pd" in comp["digits_basis"]
    # both the reference (its refinement and cross-check say ≥ 8 digits) and the scipy
    # history here (DOP853 at rtol 1e-12 with every onset a located root: ~1e-11) are far
    # more accurate than 1e-8 of the peak: 8 significant digits at least
    assert rep["reference_digits"] >= 8.0
    assert rep["score_scd"] >= 8.0
    m = rep["metrics"]
    assert m["impact_count"] == m["impact_count_ref"] >= 2
    assert m["impacts_missing"] == 0 and m["impacts_extra"] == 0
    # impact times are read from the history's 1 ms samples, as roots of the cubic Hermite
    # interpolant of (δ, δ̇) (docs/compare.md): O(Δ⁴) in the sample spacing Δ, measured
    # 1.4e-8 s here, far above the solutions' own ~1e-11 s: bounded with a factor 7
    assert m["impact_time_error"] < 1e-7
    # the cache has it, keyed by the physics
    folders = list((work["dir"] / "cache" / "references").iterdir())
    assert len(folders) == 1 and (folders[0] / "history.csv").exists()
    meta = json.loads((folders[0] / "reference.json").read_text())
    assert meta["cache_key"] == folders[0].name == cache.cache_key(load(work["scene"]))
    # a second comparison takes it from the cache, and scores the same
    r2 = martello("compare", work["dir"] / "their.csv", "--against", work["scene"], "-o", out,
                  env=work["env"])
    assert r2.returncode == 0 and "taken from the cache" in r2.stderr
    rep2 = json.loads(out.read_text())
    assert rep2["computed_reference"]["cached"] and rep2["score_scd"] == rep["score_scd"]


def test_a_wrong_history_scores_low(work, monkeypatch):
    # the score can fail: u of m1 off by 1e-4 of its peak scores about 4 digits, not 8
    h = dict(work["history"])
    h["u:m1"] = h["u:m1"] + 1e-4 * np.max(np.abs(h["u:m1"])) * np.sin(7.0 * work["times"])
    p = work["dir"] / "wrong.csv"
    np.savetxt(p, np.column_stack([work["times"], h["u:m1"], h["u:m2"]]), delimiter=",",
               header="t,u:m1,u:m2", comments="", fmt="%.17g")
    from martello import compare
    monkeypatch.setenv("MARTELLO_CACHE_DIR", work["env"]["MARTELLO_CACHE_DIR"])
    rep = compare.compare(p, work["scene"])
    assert 3.5 < rep["score_scd"] < 4.5


def test_compare_reads_opensees_recorder_files(work, cli):
    out = work["dir"] / "score_opensees.json"
    r = cli("compare", work["dir"] / "disp.out", work["dir"] / "vel.out", "--against",
                 work["scene"], "--columns", "u:m1,-u:m2", "--columns", "v:m1,-v:m2", "-o", out)
    assert r.returncode == 0, r.stderr
    rep = json.loads(out.read_text())
    assert rep["compared_columns"] == ["u:m1", "u:m2", "v:m1", "v:m2"]
    # 13 significant digits written (-precision 13): the score is the reference's, ≥ 8
    assert rep["score_scd"] >= 8.0
    assert rep["metrics"]["impacts_missing"] == 0
    # without the sign flip, u of m2 is wrong by twice itself: the score says so
    r = cli("compare", work["dir"] / "disp.out", "--against", work["scene"],
                 "--columns", "u:m1,u:m2", "-o", out)
    assert r.returncode == 0
    assert json.loads(out.read_text())["per_column"]["u:m2"]["scd"] < 0.5
    # two value columns, two free nodes: read as u of the free nodes, and said so
    r = cli("compare", work["dir"] / "disp.out", "--against", work["scene"])
    assert r.returncode == 0 and "reading its 2 value column(s) as u:m1, u:m2" in r.stderr


@pytest.mark.parametrize("content, args, message", [
    ("0.1 1 2\n0.2 1 2\n", ["--columns", "u:m1"], "--columns names 1 column(s), the file has 2"),
    ("0.1 1 2 3\n0.2 1 2 3\n", [], "3 value column(s) after the time column and no --columns"),
    ("1.0 0.1\n0.5 0.2\n", ["--columns", "u:m1"], "give the recorder -time"),
    ("0.1 1\n0.2 nan\n", ["--columns", "u:m1"], "NaN or inf"),
    ("0.1 1\n0.2 1 2\n", ["--columns", "u:m1"], "3 values, the first row has 2"),
    ("0.1 1\n0.2 2\n", ["--columns", "u:m9"], "names no node"),
])
def test_recorder_errors_are_one_line(work, cli, content, args, message):
    p = work["dir"] / "bad.out"
    p.write_text(content)
    r = cli("compare", p, "--against", work["scene"], *args)
    assert r.returncode == 1 and message in r.stderr, r.stderr
    assert len(r.stderr.strip().splitlines()) == 1 and "Traceback" not in r.stderr


def test_reference_command_writes_digits_and_provenance(work, cli, tmp_path):
    r = cli("reference", work["scene"], "-o", tmp_path / "ref")
    assert r.returncode == 0, r.stderr
    # the independent engine computes it, martello's own best run (rk8pd) cross-checks it
    assert "reference by independent" in r.stdout and "engine: martello.independent" in r.stdout
    assert "trusted digits from refinement of independent and its difference from rk8pd" in r.stdout
    assert "the two agree to" in r.stdout
    meta = json.loads((tmp_path / "ref" / "reference.json").read_text())
    for key in ("scene", "scene_sha256", "physics_sha256", "method", "refinement", "cross_check",
                "digits", "digits_basis", "martello_version", "libraries", "date", "cache_key"):
        assert key in meta, key
    # the digits are measured, not asserted: the column that differs most between the two
    # refinement levels, and between the two methods, has at most −log10 of that difference
    ref_diff = meta["refinement"][0]["max_rel_diff_u"]
    cross = meta["cross_check"]["max_rel_diff_u"]
    u_digits = min(d for c, d in meta["digits"].items() if c.startswith("u:"))
    assert u_digits <= -math.log10(ref_diff) + 1e-9 and u_digits <= -math.log10(cross) + 1e-9
    # and the history agrees with the scipy oracle to those digits: the difference is the
    # reference's error (≤ 10^-digits) plus the oracle's (~1e-11, below it): a factor 2
    data = np.loadtxt(tmp_path / "ref" / "history.csv", delimiter=",", skiprows=1)
    u1 = data[:, 1]
    assert np.max(np.abs(u1 - work["history"]["u:m1"])) / np.max(np.abs(u1)) \
        <= 2 * 10.0 ** -meta["digits"]["u:m1"]


def test_static_scene_is_refused(tmp_path):
    r = martello("reference", ROOT / "benchmarks" / "p1" / "p1_static_penalty.toml",
                 env=dict(os.environ, MARTELLO_CACHE_DIR=str(tmp_path)))
    assert r.returncode == 1 and "a static scene has no time history" in r.stderr
    assert len(r.stderr.strip().splitlines()) == 1


def test_every_is_checked(work, cli):
    r = cli("reference", work["scene"], "--every", "-1")
    assert r.returncode == 1 and "--every -1.0: must be > 0" in r.stderr


def test_cache_folder_follows_the_environment(monkeypatch, tmp_path):
    monkeypatch.setenv("MARTELLO_CACHE_DIR", str(tmp_path / "own"))
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "xdg"))
    assert cache.cache_root() == tmp_path / "own"
    monkeypatch.delenv("MARTELLO_CACHE_DIR")
    assert cache.cache_root() == tmp_path / "xdg" / "martello"
    # a relative XDG_CACHE_HOME is invalid (XDG base directory specification): ignored
    monkeypatch.setenv("XDG_CACHE_HOME", "relative")
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert cache.cache_root() == tmp_path / "home" / ".cache" / "martello"


def test_cache_key_is_the_physics(work):
    base = load(work["scene"])
    same = SCENE.replace("dt = 1.0e-4", "dt = 2.0e-4").replace('"newmark"', '"rk8pd"')
    other = SCENE.replace(f"stiffness = {KC}", "stiffness = 2.0e5")
    import tomllib
    k = lambda text: cache.cache_key(from_dict(tomllib.loads(text)))
    # the integrator does not change the solution; the contact stiffness does
    assert k(same) == cache.cache_key(base) != k(other)


def test_methods_follow_the_scene():
    p7 = load(ROOT / "benchmarks" / "p7" / "p7_two_oscillators.toml")
    assert [m["integrator"] for m in cache.default_methods(p7, 1e-3)] == ["independent", "rk8pd", "newmark"]
    e = load(ROOT / "benchmarks" / "p2" / "p2_restitution_e08.toml")
    assert [m["integrator"] for m in cache.default_methods(e, 1e-3)] == ["independent", "rk8pd", "rkf45"]
    chain = load(ROOT / "benchmarks" / "p7" / "p7_chain_10.toml")
    ms = cache.default_methods(chain, 6e-3)[1:]
    assert ms[0]["integrator"] == "rk8pd" and ms[0]["refine"] == "h_max" and ms[1]["integrator"] == "newmark"
    big = load(ROOT / "benchmarks" / "p7" / "p7_chain_1000.toml")
    assert cache.default_methods(big, 1e-2)[0]["integrator"] == "rk8pd"
    assert "1000 nodes" in cache.engine_skipped(big)
    # Newmark's step divides the sample spacing: its outputs fall on the stored samples
    assert (6e-3 / ms[1]["dt"]) == pytest.approx(round(6e-3 / ms[1]["dt"]), abs=1e-9)


def test_compare_without_computing_still_refuses(work):
    from martello import compare
    with pytest.raises(MartelloError, match="martello reference"):
        compare.compare(work["dir"] / "their.csv", work["scene"], compute=False)
