"""P8 (seed §5-6): the adjacent-buildings scenes, their gap stiffness rule, the case study's
aggregation and the committed records (docs/p8-case-study.md)."""

import importlib.util
import math
import re
import sys
import tomllib
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[1]
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from martello import ground_motion as gm  # noqa: E402
from martello.ground_motion.records import read_csv_record  # noqa: E402
from martello.run import run_full  # noqa: E402
from martello.scene.loader import from_dict, load  # noqa: E402

P8 = ROOT / "benchmarks" / "p8"
SCENES = {c: P8 / f"p8_{c}.toml" for c in ("bare", "A", "B")}
RECORDS = [P8 / "records" / f"opcm3274_z2_C_{i}.csv" for i in range(1, 6)]
G = 9.80665


def _load_script(name):
    spec = importlib.util.spec_from_file_location(f"p8_{name}", P8 / f"{name}.py")
    mod = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = mod      # dataclasses need the module registered
    spec.loader.exec_module(mod)
    return mod


@pytest.fixture(scope="module")
def cs():
    return _load_script("case_study")


# ------------------------------------------------------------------------------ scenes

@pytest.mark.parametrize("config, damper_floors", [("bare", ()), ("A", (1, 2)), ("B", (2,))])
def test_scenes_load_with_the_seed_layout(config, damper_floors):
    s = load(SCENES[config])
    assert s.problem == "P8" and s.analysis["type"] == "dynamic"
    names = [n["name"] for n in s.nodes]
    assert names == ["b1.f1", "b1.f2", "b2.f1", "b2.f2", "b2.f3", "b2.f4", "b2.f5"]
    storeys = [l for l in s.links if l["type"] == "bilinear"]
    assert len(storeys) == 2 + 5
    # pounding only at the two shared floors, 2 cm joint, linear penalty, no contact damping
    assert len(s.contacts) == 6
    for c in s.contacts:
        assert c["scheme"] == "penalty" and c["law"] == "linear"
        assert c["gap"] == 0.02
        assert c["damping"] is None and c["restitution"] is None
        fa, fb = s.nodes[c["a"]]["name"], s.nodes[c["b"]]["name"]
        assert fa.startswith("b1.") and fb.startswith("b2.") and fa[3:] == fb[3:]
    dampers = [l for l in s.links if l["type"] == "fluid_damper"]
    assert len(dampers) == 5 * len(damper_floors)           # five devices per floor (seed Fig. 11)
    for d in dampers:
        assert d["c"] == 70.0e3                                # seed: 70 kN(s/m)^alpha per device
        fa, fb = s.nodes[d["a"]]["name"], s.nodes[d["b"]]["name"]
        assert int(fa[-1]) in damper_floors and fa[3:] == fb[3:]
    assert Path(s.ground["file"]).exists()


def test_scenes_are_up_to_date_with_the_case_study_parameters(cs):
    assert cs.stale_scenes() == []


def test_beam_axial_stiffness_rule_gives_the_scene_stiffness(cs):
    # Independent statement of the rule: E = 5700 sqrt(Rck) N/mm2 (D.M. 9.1.1996), Rck = 25,
    # a 30 x 50 cm beam of span 4.5 m: EA/L = 28500e6 * 0.15 / 4.5 = 9.5e8 N/m.
    E = 5700.0 * math.sqrt(25.0) * 1e6
    k_rule = E * 0.30 * 0.50 / 4.5
    assert k_rule == pytest.approx(9.5e8, rel=1e-15)
    assert cs.beam_axial_stiffness() == pytest.approx(k_rule, rel=1e-15)
    for path in SCENES.values():
        for c in load(path).contacts:
            assert c["stiffness"] == pytest.approx(k_rule, rel=1e-15)


def test_first_periods_follow_the_stated_rule():
    """T1 = sqrt(2) 0.075 H^(3/4), recomputed from the scene's masses and storey stiffnesses."""
    s = load(SCENES["bare"])
    for prefix, n in (("b1", 2), ("b2", 5)):
        m = np.array([s.nodes[s.index[f"{prefix}.f{i}"]]["mass"] for i in range(1, n + 1)])
        k = [next(l["k"] for l in s.links if l["name"] == f"{prefix}.s{i}") for i in range(1, n + 1)]
        K = np.zeros((n, n))
        for i in range(n):
            K[i, i] += k[i]
            if i + 1 < n:
                K[i, i] += k[i + 1]
                K[i, i + 1] = K[i + 1, i] = -k[i + 1]
        w1 = math.sqrt(np.linalg.eigvalsh(K / np.sqrt(np.outer(m, m)))[0])
        assert 2 * math.pi / w1 == pytest.approx(math.sqrt(2) * 0.075 * (3.0 * n) ** 0.75, rel=1e-9)


def test_short_run_pounds_by_millimetres_and_balances_energy():
    d = tomllib.loads(SCENES["bare"].read_text())
    d["analysis"]["t_end"] = 6.0
    s = from_dict(d, source=str(SCENES["bare"]), base_dir=P8)
    summary, (cols, hist) = run_full(s)
    assert summary["status"] == "MARTELLO_OK"
    pen = max(c["max_penetration"] for c in summary["contacts"].values())
    assert 1e-4 < pen < 1e-2                # millimetres with the beam-axial stiffness
    assert summary["contacts"]["f2.gap1"]["impacts"] >= 1
    e = summary["energy"]
    assert e["balance_max"] <= 1e-6 * abs(e["input"])
    assert "link_force:b2.s3" in cols and "penetration:f2.gap1" in cols


def test_a_damper_run_uses_the_fluid_law():
    d = tomllib.loads(SCENES["B"].read_text())
    d["analysis"]["t_end"] = 4.0
    d["analysis"]["output"]["every"] = 1
    s = from_dict(d, source=str(SCENES["B"]), base_dir=P8)
    summary, (cols, hist) = run_full(s)
    F = hist[:, cols.index("link_force:f2.fvd1")]
    v = hist[:, cols.index("v:b1.f2")] - hist[:, cols.index("v:b2.f2")]
    fast = np.abs(v) > 1e-3                 # above v_reg: F = c sign(v)|v|^alpha
    assert fast.sum() > 100
    np.testing.assert_allclose(F[fast], 70e3 * np.sign(v[fast]) * np.abs(v[fast]) ** 0.15, rtol=1e-9)


# ---------------------------------------------------------------------- aggregation

def _fake(pen2, drift, shear):
    return {"penetration": {1: 0.0, 2: pen2}, "peak_penetration": pen2,
            "drift": {(2, 3): drift}, "shear": {(2, 3): shear}, "impacts": {2: 3},
            "damper_force": {}, "status": "MARTELLO_OK"}


def test_mean_over_records_and_reductions_on_synthetic_numbers(cs):
    bare = [_fake(2e-3, 0.030, 1000.0), _fake(4e-3, 0.050, 3000.0)]
    treated = [_fake(1e-3, 0.020, 1500.0), _fake(0.0, 0.040, 1500.0)]
    mb, mt = cs.mean_over_records(bare), cs.mean_over_records(treated)
    assert mb["peak_penetration"] == pytest.approx(3e-3)
    assert mb["drift"][(2, 3)] == pytest.approx(0.040)
    assert mt["shear"][(2, 3)] == pytest.approx(1500.0)
    assert mb["impacts"][2] == 3
    assert "status" not in mb                                  # text is not averaged
    assert mb["damper_force"] == {}
    r = cs.reductions(mb, mt)
    assert r["peak_penetration"] == pytest.approx(100 * (1 - 0.5e-3 / 3e-3))   # 83.33 %
    assert r["drift"][(2, 3)] == pytest.approx(25.0)           # 1 - 0.030/0.040
    assert r["shear"][(2, 3)] == pytest.approx(25.0)           # 1 - 1500/2000
    assert r["penetration"][1] is None                         # no bare penetration: undefined
    assert r["penetration"][2] == pytest.approx(100 * (1 - 0.5e-3 / 3e-3))
    assert cs.reduction(10.0, 12.0) == pytest.approx(-20.0)    # an increase is negative
    with pytest.raises(ValueError):
        cs.mean_over_records([])


def test_measure_reads_the_summary(cs):
    d = tomllib.loads(SCENES["A"].read_text())
    d["analysis"]["t_end"] = 3.0
    summary, _ = run_full(from_dict(d, source=str(SCENES["A"]), base_dir=P8))
    m = cs.measure(summary)
    assert m["drift"][(2, 3)] == summary["links"]["b2.s3"]["max_abs_elongation"]
    assert m["shear"][(1, 2)] == summary["links"]["b1.s2"]["max_abs_force"]
    assert m["peak_penetration"] == max(summary["contacts"][f"f{f}.gap{j}"]["max_penetration"]
                                        for f in (1, 2) for j in (1, 2, 3))
    assert set(m["damper_force"]) == {1, 2}


# ---------------------------------------------------------------------------- records

@pytest.fixture(scope="module")
def records():
    return [read_csv_record(p) for p in RECORDS]


def test_records_have_the_target_pga(records):
    target = gm.opcm3274_spectrum(2, "C")
    assert target.pga == pytest.approx(0.25 * 1.25 * G, rel=1e-15)
    for rec in records:
        assert rec.dt == pytest.approx(0.01) and rec.accel.size == 2001
        assert np.max(np.abs(rec.accel)) == pytest.approx(target.pga, rel=1e-12, abs=0)


def test_records_match_the_target_within_the_band(records):
    target = gm.opcm3274_spectrum(2, "C")
    # the grid of the headers' "achieved" line: within the stated +-10 %
    T = np.geomspace(0.15, 2.0, 2000)
    # other periods (between those points): the PSA has kinks, allow 0.5 % more
    T_off = np.sqrt(T[:-1] * T[1:])
    for rec in records:
        dev = gm.response_spectrum(rec, None, T, zeta=0.05).psa / target.psa(T) - 1
        assert np.max(np.abs(dev)) <= 0.10
        dev_off = gm.response_spectrum(rec, None, T_off, zeta=0.05).psa / target.psa(T_off) - 1
        assert np.max(np.abs(dev_off)) <= 0.105


def test_record_headers_document_the_generation():
    for i, p in enumerate(RECORDS):
        head = [l for l in p.read_text().splitlines() if l.startswith("#")]
        text = "\n".join(head)
        for needle in ("# seed: 2003", f"# record index: {i} of 5", "# duration s: 20",
                       "# dt s: 0.01", "# envelope: t_rise=2 s, t_plateau_end=12 s",
                       "# band: 0.1 on [0.15, 2] s", "# achieved: PSA/target - 1",
                       "# target: OPCM 3274 zone 2, soil C"):
            assert needle in text, (p.name, needle)


def test_records_regenerate_bit_identically(tmp_path):
    # every byte but the version in the "# generator: martello X.Y.Z" line, which names the
    # version that wrote the committed file: versions move on (CHANGELOG.md), samples must not
    def without_version(data):
        return re.sub(rb"(?m)^(# generator: martello )\d+\.\d+\.\d+ ", rb"\1", data)
    mr = _load_script("make_records")
    for p in mr.write(tmp_path):
        new, committed = p.read_bytes(), (P8 / "records" / p.name).read_bytes()
        assert b"# generator: martello " in committed
        assert without_version(new) == without_version(committed), p.name


def test_record_check_tells_round_off_from_a_changed_record(tmp_path):
    """make_records --check: a copy differing by a few ulps of the PGA (another build) agrees
    to round-off; one sample moved by 1e-9 of the PGA, or a changed header, does not."""
    mr = _load_script("make_records")
    committed = P8 / "records" / "opcm3274_z2_C_1.csv"
    lines = committed.read_text().splitlines()
    data = [i for i, l in enumerate(lines) if l and not l.startswith("#") and l[0] in "-0123456789"]
    pga = max(abs(float(lines[i].split(",")[1])) for i in data)

    def moved(by, header=None):
        out = list(lines)
        t, a = out[data[100]].split(",")
        out[data[100]] = f"{t},{float(a) + by * pga!r}"
        if header:
            out[0] = header
        p = tmp_path / f"r{len(list(tmp_path.iterdir()))}.csv"
        p.write_text("\n".join(out) + "\n")
        return p

    assert mr.compare(committed, committed) == (True, "regenerated bit-identically")
    ok, why = mr.compare(moved(3e-15), committed)
    assert ok and "round-off" in why
    ok, why = mr.compare(moved(1e-9), committed)
    assert not ok and "more than round-off" in why
    assert mr.compare(moved(0.0, header="# something else"), committed) == (False, "headers differ")
