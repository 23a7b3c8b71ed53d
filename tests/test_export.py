"""martello export --to opensees without OpenSees (docs/opensees.md): the generated OpenSeesPy
script executed against a recording fake of the openseespy API that checks every call
(tests/opensees_fake.py), the Tcl script executed by tclsh against Tcl stand-ins of the same
commands, the materials' parameters against the published formulas written again here, the
refusals, and the half-Kelvin law against an independent integration. The real OpenSees runs
are tests/test_export_opensees.py and benchmarks/opensees/."""

import csv
import math
import runpy
import subprocess
import sys

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from martello.errors import ExportError
from martello.export import export, half_kelvin_e, opensees_model
from martello.scene.loader import from_dict, load
from tests.opensees_fake import FakeOpenSees

P7 = "benchmarks/p7/p7_two_oscillators.toml"


def two_bodies(law="kelvin", integrator="newmark", **contact):
    """Two free masses approaching (P5's two bodies): m1 = 1 kg at 1 m/s, m2 = 2 kg."""
    c = {"name": "c", "a": "m1", "b": "m2", "gap": 0.001, "scheme": "penalty", "law": law,
         "stiffness": 1e6 if law in ("linear", "kelvin") else 1e8}
    c.update(contact)
    an = {"type": "dynamic", "integrator": integrator, "dt": 1e-5, "t_end": 4e-3}
    if integrator == "hht":
        an["alpha"] = -0.1
    if integrator == "generalized-alpha":
        an["rho_inf"] = 0.8
    return {"title": "two bodies", "node": [{"name": "m1", "mass": 1.0, "v0": 1.0},
                                            {"name": "m2", "mass": 2.0}],
            "contact": [c], "analysis": an}


def run_fake(folder):
    """Execute folder/model.py against the fake; returns the fake and history.csv's rows."""
    fake = FakeOpenSees()
    mods = {"openseespy": type(sys)("openseespy"), "openseespy.opensees": fake.module()}
    mods["openseespy"].opensees = mods["openseespy.opensees"]
    saved = {k: sys.modules.get(k) for k in mods}
    sys.modules.update(mods)
    try:
        runpy.run_path(str(folder / "model.py"), run_name="__main__")
    finally:
        for k, v in saved.items():
            if v is None:
                sys.modules.pop(k, None)
            else:
                sys.modules[k] = v
    rows = list(csv.reader(open(folder / "history.csv")))
    return fake, rows


def calls(fake, name, kind=None):
    return [a for n, a in fake.calls if n == name and (kind is None or a[0] == kind)]


def test_p7_kelvin_script_builds_the_scene_and_samples_every_output_step(tmp_path):
    scene = load(P7)
    export(scene, tmp_path / "x")
    fake, rows = run_fake(tmp_path / "x")
    # the nodes: two masses of 1 kg and a fixed ground
    assert sorted(v[0] for v in fake.masses.values()) == [1.0, 1.0]
    assert list(fake.fixed.values()) == [(1,)]
    # springs k = 100 and 400, dashpots c = 2 zeta sqrt(k m) with zeta = 5 %
    el = sorted(a[2] for a in calls(fake, "uniaxialMaterial", "Elastic"))
    assert el == [100.0, 400.0]
    vis = sorted(a[2] for a in calls(fake, "uniaxialMaterial", "Viscous"))
    assert vis == pytest.approx([2 * 0.05 * math.sqrt(100.0), 2 * 0.05 * math.sqrt(400.0)], rel=1e-15)
    # the Kelvin contact: ViscoelasticGap, c = 2 xi sqrt(k m*) with xi from e = 0.65
    (kind, tag, K, C, gap), = calls(fake, "uniaxialMaterial", "ViscoelasticGap")
    xi = -math.log(0.65) / math.sqrt(math.pi ** 2 + math.log(0.65) ** 2)
    assert (K, gap) == (1e5, -0.01)
    assert C == pytest.approx(2 * xi * math.sqrt(1e5 * 0.5), rel=1e-14)
    # its element runs from a (s1) to b (s2): deformation u_b − u_a < −gap is contact
    el = [e for e in fake.elements.values() if e[3][1] == tag][0]
    s1, s2 = [t for t, m in fake.masses.items()]
    assert (el[1], el[2]) == (s1, s2)
    # the springs: from ground (i) to the node (j), deformation u_node
    ground = next(iter(fake.fixed))
    assert all(e[1] == ground for e in fake.elements.values() if e[3][1] != tag)
    # ground motion 3 sin(8 t): Trig of period 2 pi/8, factor 3, UniformExcitation along 1
    (_, _, t0, t1, period, *opts), = calls(fake, "timeSeries", "Trig")
    assert (t0, period, opts) == (0.0, pytest.approx(2 * math.pi / 8), ["-factor", 3.0, "-shift", 0.0])
    assert calls(fake, "integrator") == [("Newmark", 0.5, 0.25)]       # OpenSees: gamma, beta
    # history: t = k dt at every 10th of 40000 steps, and t = 0
    head, data = rows[0], np.array(rows[1:], float)
    assert head == ["t", "u:s1", "v:s1", "a:s1", "u:s2", "v:s2", "a:s2", "penetration:s1-s2",
                    "force:s1-s2", "energy:kinetic", "energy:recoverable"]
    assert len(data) == 4001 and fake.steps == 40000
    assert np.array_equal(data[:, 0], np.arange(4001) * 10 * 1e-4)
    t = data[:, 0]
    # the fake's u = tag·1e-3·sin(t) sampled after the step (t = 0: before the first)
    assert np.allclose(data[:, 1], s1 * 1e-3 * np.sin(t), rtol=0, atol=1e-18)
    assert np.allclose(data[:, 7], (s1 - s2) * 1e-3 * np.sin(t) - 0.01, rtol=0, atol=1e-17)
    assert np.allclose(data[:, 8], tag + t, rtol=0, atol=1e-12)          # P = −basicForce
    # energies: ½ Σ m v² of the fake's velocities; springs 100 and 400 to ground, the
    # contact open (δ < 0) at the fake's displacements
    u1, u2 = s1 * 1e-3 * np.sin(t), s2 * 1e-3 * np.sin(t)
    assert np.allclose(data[:, 9], 0.5 * ((s1 * 1e-3 * np.cos(t)) ** 2 + (s2 * 1e-3 * np.cos(t)) ** 2),
                       rtol=1e-13, atol=0)
    assert np.allclose(data[:, 10], 0.5 * 100 * u1 ** 2 + 0.5 * 400 * u2 ** 2, rtol=1e-13, atol=1e-300)


def scene_members(scene):
    return [(f"{b['prefix']}.{e.name}", None) for b in scene.extras["buildings"] for e in b["building"].elements]


@pytest.mark.parametrize("which", ["two bodies", "two buildings"])
def test_tcl_script_issues_the_same_commands(tmp_path, which):
    """model.tcl, run by tclsh with every OpenSees command a Tcl procedure that logs its
    arguments, issues the same commands with the same numbers as model.py (a building's too:
    rigidDiaphragm, geomTransf with vecxz, oriented zeroLength elements, its rows' penetration)."""
    if which == "two bodies":
        scene = from_dict(two_bodies("hunt-crossley", restitution=0.5, exponent=1.5), source="tb")
    else:
        scene = from_dict(small_buildings(t_end=0.005), source="sb")
    export(scene, tmp_path / "x", tcl=True)
    fake, _ = run_fake(tmp_path / "x")
    names = sorted({n for n, _ in fake.calls})
    stubs = "".join(f"proc {n} args {{ puts [concat CALL {n} $args] }}\n" for n in names)
    stubs += ("proc analyze args { return 0 }\nproc nodeDisp args { return 0.0 }\n"
              "proc nodeVel args { return 0.0 }\nproc nodeAccel args { return 0.0 }\n"
              "proc eleResponse args { return {0.0 1.0 2.0 3.0 4.0 5.0 6.0 7.0 8.0 9.0 10.0 11.0} }\n")
    (tmp_path / "run.tcl").write_text(stubs + "source model.tcl\n")
    r = subprocess.run(["tclsh", str(tmp_path / "run.tcl")], cwd=tmp_path / "x", capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    got = [line.split()[1:] for line in r.stdout.splitlines() if line.startswith("CALL")]
    want = [[n] + list(a) for n, a in fake.calls if n not in ("analyze",)]
    assert len(got) == len(want)
    for g, w in zip(got, want):
        assert g[0] == w[0] and len(g) == len(w), (g, w)
        for x, y in zip(g[1:], w[1:]):
            if isinstance(y, str):
                assert x == y
            else:
                assert float(x) == float(y), (g, w)
    assert (tmp_path / "x" / "history.csv").read_text().startswith(
        "t,u:m1," if which == "two bodies" else "t,u:A1.ux,")
    if which == "two buildings":         # Tcl's members.csv: model.py's columns, localForce's 4, 5, 10, 11
        rows = (tmp_path / "x" / "members.csv").read_text().splitlines()
        assert rows[0] == ",".join(["t"] + [f"{q}_{e}:{n}" for n, _ in scene_members(scene) for e in "ij"
                                            for q in ("M2", "M3")])
        assert rows[-1].split(",")[1:5] == ["4", "5", "10", "11"]


@pytest.mark.parametrize("law, e, a", [
    ("hunt-crossley", 0.5, 1.5 * (1 - 0.5)),                 # Hunt & Crossley (1975)
    ("lankarani-nikravesh", 0.8, 0.75 * (1 - 0.64)),        # Lankarani & Nikravesh (1990)
    ("flores", 0.5, 8 * (1 - 0.5) / (5 * 0.5)),             # Flores et al. (2011)
    ("gonthier", 0.5, (1 - 0.25) / 0.5),                    # Gonthier et al. (2004)
    ("hertzdamp", 0.8, 0.75 * (1 - 0.64)),                  # Muthukumar & DesRoches (2006)
])
def test_hunt_crossley_family_is_hertzdamp_with_xinorm_the_published_factor(tmp_path, law, e, a):
    """OpenSees' Hertzdamp force is (Kh + ξ_N·Kh/v_in·δ̇)·δ^n: the family's K δ^n (1 + χ δ̇)
    with χ = a/v_in, so xiNorm = a."""
    extra = {} if law == "hertzdamp" else {"exponent": 1.3}
    m = opensees_model(from_dict(two_bodies(law, restitution=e, **extra), source="tb"))
    (mat,) = [c.args for c in m.commands if c.name == "uniaxialMaterial" and c.args[0] == "Hertzdamp"]
    assert mat[2] == 1e8 and mat[3] == pytest.approx(a, rel=1e-15) and mat[4] == -0.001
    assert mat[5] == (1.5 if law == "hertzdamp" else 1.3)
    assert any("v_in" in d for d in m.differences)


def test_hertz_linear_and_jankowski_materials():
    m = opensees_model(from_dict(two_bodies("hertz", exponent=1.5), source="tb"))
    assert [c.args for c in m.commands if c.name == "uniaxialMaterial"] == [("Hertzdamp", 1, 1e8, 0.0, -0.001, 1.5)]
    m = opensees_model(from_dict(two_bodies("linear"), source="tb"))
    (mat,) = [c.args for c in m.commands if c.name == "uniaxialMaterial"]
    assert mat[:3] == ("ElasticPPGap", 1, 1e6) and mat[3] < -1e100 and mat[4] == -0.001
    m = opensees_model(from_dict(two_bodies("jankowski", restitution=0.65), source="tb"))
    (mat,) = [c.args for c in m.commands if c.name == "uniaxialMaterial"]
    xi = 4.5 * math.sqrt(5) * (1 - 0.65 ** 2) / (0.65 * (0.65 * (9 * math.pi - 16) + 16))   # Jankowski (2005)
    assert mat[0] == "JankowskiImpact" and mat[2] == 1e8 and mat[3] == pytest.approx(xi, rel=1e-15)
    assert mat[4] == pytest.approx(2.0 / 3.0, rel=1e-15) and mat[5:] == (-0.001, 1.5)   # m*, gap, n


def test_integrators_map_onto_opensees_conventions():
    m = opensees_model(from_dict(two_bodies("kelvin", integrator="hht"), source="tb"))
    (integ,) = [c.args for c in m.commands if c.name == "integrator"]
    # OpenSees' HHT weighs the new state: alpha_OS = 1 + alpha, gamma = 1/2 − alpha, beta = (1 − alpha)²/4
    assert integ == ("HHT", pytest.approx(0.9), pytest.approx(0.6), pytest.approx(0.3025))
    m = opensees_model(from_dict(two_bodies("kelvin", integrator="generalized-alpha"), source="tb"))
    (integ,) = [c.args for c in m.commands if c.name == "integrator"]
    rho = 0.8                      # Chung & Hulbert (1993) eq. 25, weights of the new state
    am, af = 1 - (2 * rho - 1) / (rho + 1), 1 - rho / (rho + 1)
    # the two-number form (OpenSees' four-number form swaps γ and β: docs/opensees.md)
    assert integ == ("GeneralizedAlpha", pytest.approx(am), pytest.approx(af))
    assert any("interpolated state" in d for d in m.differences)
    assert any("first-order accurate" in d for d in m.differences)
    m = opensees_model(from_dict(two_bodies("kelvin"), source="tb"),
                       analysis={"integrator": "newmark", "beta": 1 / 6})
    assert [c.args for c in m.commands if c.name == "integrator"] == [("Newmark", 0.5, 1 / 6)]


def test_overrides_replace_an_event_driven_integrator():
    d = two_bodies("kelvin", integrator="rk8pd")
    with pytest.raises(ExportError, match="integrator = rk8pd.*no event-driven, ODE or DAE"):
        opensees_model(from_dict(d, source="tb"))
    m = opensees_model(from_dict(d, source="tb"), analysis={"integrator": "newmark", "dt": 2e-5})
    assert m.dt == 2e-5 and m.steps == 200
    with pytest.raises(ExportError, match="analysis.alpha: missing for integrator hht"):
        opensees_model(from_dict(d, source="tb"), analysis={"integrator": "hht"})


@pytest.mark.parametrize("over, match", [
    # t_end/dt = inf: was an internal OverflowError (int(inf))
    ({"dt": 1e-320}, r"^--dt: t_end/dt = 0.004/1e-320 = inf steps, more than 2\^53.*raise --dt"),
    # ~1e303 steps were written without a budget
    ({"t_end": 1e300}, r"^--t-end: .* = 1e305 steps, more than 2\^53.*shorten --t-end"),
    # past `martello run`'s budget (1e9 node-steps): 2e9 steps of 2 nodes
    ({"t_end": 2e4}, r"^--t-end: .*= 2e9 steps of 2 nodes, more than the 1e9 node-steps.*--force"),
    ({"dt": 1e-14}, r"^--dt: .*more than the 1e9 node-steps.*raise --dt or shorten analysis.t_end"),
    # an integrator's own key on a scene of another integrator without --integrator: was ignored
    ({"alpha": -0.1}, "^--alpha: applies to integrator hht, not newmark .the scene's integrator.: "
                      "it would be ignored .remove it, or give --integrator hht."),
    ({"rho_inf": 0.5}, "^--rho-inf: applies to integrator generalized-alpha, not newmark"),
])
def test_overrides_the_model_would_not_honour_are_refused_naming_the_flag(over, match):
    with pytest.raises(ExportError, match=match):
        opensees_model(from_dict(two_bodies("kelvin"), source="tb"), analysis=over)
    d = two_bodies("kelvin", integrator="hht")
    with pytest.raises(ExportError, match="^--beta: applies to integrator newmark, not hht"):
        opensees_model(from_dict(d, source="tb"), analysis={"beta": 0.3})


def test_other_options_the_model_would_not_honour_are_refused(tmp_path):
    """--tol on central-difference (no Newton test), --material for a law no contact has, and
    --force past the budget writes the model (its step count as asked)."""
    d = two_bodies("linear", integrator="central-difference")
    d["node"][0]["v0"], d["node"][1]["u0"] = 0.0, -0.002
    opensees_model(from_dict(d, source="tb"))
    with pytest.raises(ExportError, match="^--tol: central-difference is explicit.*remove it"):
        opensees_model(from_dict(d, source="tb"), tol=1e-9)
    with pytest.raises(ExportError, match=r"^--material hertz=HertzLinear: no penalty contact of the "
                                          r"scene has law hertz \(kelvin\)"):
        opensees_model(from_dict(two_bodies("kelvin"), source="tb"), materials={"hertz": "HertzLinear"})
    m = opensees_model(from_dict(two_bodies("kelvin"), source="tb"), analysis={"t_end": 2e4},
                       force=True)
    assert m.steps == 2_000_000_000


@pytest.mark.parametrize("change, match", [
    ({"scheme": "restitution", "restitution": 0.5}, "scheme = restitution.*no Newton restitution"),
    ({"scheme": "lagrange"}, "scheme = lagrange.*Lagrange multipliers"),
    ({"clipped": True, "restitution": 0.5}, "clipped = true.*no OpenSees material clips"),
    ({"gap": -1e-4, "restitution": 0.5}, "initial overlap"),
])
def test_what_opensees_cannot_express_is_refused_naming_what_and_why(change, match):
    c = {"name": "c", "a": "m1", "b": "m2", "gap": 0.001, "scheme": "penalty", "law": "kelvin",
         "stiffness": 1e6}
    c.update(change)
    for k in [k for k in ("stiffness", "law") if change.get("scheme") not in (None, "penalty")]:
        c.pop(k)
    d = two_bodies()
    d["contact"] = [c]
    if change.get("scheme") in ("restitution", "lagrange"):
        d["analysis"]["integrator"] = "rk8pd"
    with pytest.raises(ExportError, match=match):
        opensees_model(from_dict(d, source="tb"), analysis={"integrator": "newmark"})


def test_static_mass_coupling_and_central_difference_refusals():
    with pytest.raises(ExportError, match="static"):
        opensees_model(load("benchmarks/p1/p1_static_penalty.toml"))
    with pytest.raises(ExportError, match="mass_coupling"):
        opensees_model(load("benchmarks/p4/p4_equal_rods_newmark_consistent_eps0.1.toml"))
    with pytest.raises(ExportError, match="central-difference with v0 != 0.*drops the initial velocity"):
        opensees_model(from_dict(two_bodies("linear", integrator="central-difference"), source="tb"))
    d = two_bodies("kelvin", integrator="central-difference", restitution=0.5)
    with pytest.raises(ExportError, match="velocity-dependent forces \\(c\\)"):
        opensees_model(from_dict(d, source="tb"))


def small_buildings(t_end=0.3, reference=True, zeta=0.05):
    """Two frame buildings side by side along x with a 1 mm joint (docs/buildings.md): A, one
    storey, 2 x 2 columns with shear areas (Timoshenko members); B, two storeys, a stiff wall at
    one end of its plan (its floors twist), its floors referred to a point off their mass
    centre (mass couplings); a linear gap and a fluid damper between plan points of the shared
    floor, off the centre line; a sine along x, Rayleigh 5 %, Newmark 1 ms."""
    col = {"E": 3e10, "b2": 0.4, "b3": 0.4, "cracked": 0.5}
    beam = {"E": 3e10, "b": 0.3, "h": 0.5, "cracked": 0.5}
    a = {"prefix": "A", "storeys": 1, "storey_height": 3.0, "model": "frame", "grid_x": [0.0, 5.0],
         "grid_y": [0.0, 6.0], "column": dict(col, As2=0.13, As3=0.12), "beam": beam, "mass": 1.0e5,
         "zeta": zeta, "histories": True}
    b = {"prefix": "B", "storeys": 2, "storey_height": 3.0, "model": "frame", "grid_x": [5.001, 10.001],
         "grid_y": [0.0, 6.0], "column": col, "beam": beam, "mass": 1.2e5, "zeta": zeta,
         "rayleigh_modes": [1, 3], "histories": True,
         "member": [{"name": "W", "x": 7.5, "y": 6.0, "section": {"E": 3e10, "A": 0.5, "I2": 2e-3,
                                                                    "I3": 0.6, "J": 5e-3}}]}
    if reference:
        b["reference"] = [6.0, 1.0]
    return {"title": "two small buildings", "building": [a, b],
            "contact": [{"name": "g", "a": {"floor": "A1", "x": 5.0, "y": 1.0},
                         "b": {"floor": "B1", "x": 5.001, "y": 1.0}, "normal": [1.0, 0.0], "gap": 0.001,
                         "scheme": "penalty", "law": "linear", "stiffness": 5e8}],
            "link": [{"name": "d", "type": "fluid_damper", "a": {"floor": "A1", "x": 5.0, "y": 5.0},
                      "b": {"floor": "B1", "x": 5.001, "y": 5.0}, "direction": [1.0, 0.0], "c": 2e5,
                      "alpha": 1.0, "v_reg": 0.0}],
            "loads": {"ground_acceleration": {"type": "sine", "amplitude": 6.0, "omega": 12.0}},
            "analysis": {"type": "dynamic", "integrator": "newmark", "dt": 1e-3, "t_end": t_end}}


def shear_buildings(t_end=0.3):
    """Two shear-type buildings (docs/buildings.md "Members"): A, 2 storeys on pinned feet, its
    first floor flexible (joints with their tributary masses), heavier than B; B, columns turned
    by 90°, storeys 3 and 3.5 m, a split point on a column of its second storey struck by A's
    second floor between plan point and point, a node-pair gap from A's joint to B's floor; the
    ground motion at 30° in plan, starting towards B (phase π), Rayleigh 5 %, Newmark 1 ms."""
    col = {"E": 3e10, "b2": 0.4, "b3": 0.3, "cracked": 0.5}
    a = {"prefix": "A", "storeys": 2, "storey_height": 3.0, "grid_x": [0.0, 5.0], "grid_y": [0.0, 6.0],
         "column": col, "mass": [5.0e5, 4.0e5], "zeta": 0.05, "ground_angle": 30.0, "base": "pinned",
         "diaphragm": [False, True], "histories": True}
    b = {"prefix": "B", "storeys": 2, "storey_height": [3.0, 3.5], "grid_x": [5.002, 10.002],
         "grid_y": [0.0, 6.0], "column": col, "mass": 1.2e5, "zeta": 0.05, "ground_angle": 30.0,
         "column_angle": 90.0, "histories": True,
         "split": [{"name": "S", "line": "0.0", "storey": 2, "height": 1.5, "mass": 500.0}]}
    return {"title": "two shear buildings", "building": [a, b],
            "contact": [{"name": "g", "a": {"floor": "A2", "x": 5.0, "y": 0.0}, "b": {"point": "B.S"},
                         "normal": [1.0, 0.0], "gap": 0.0002, "scheme": "penalty", "law": "linear",
                         "stiffness": 2e8},
                        {"name": "j", "a": "A1.1.1.ux", "b": "B1.ux", "gap": 0.0005, "scheme": "penalty",
                         "law": "linear", "stiffness": 2e8}],
            "loads": {"ground_acceleration": {"type": "sine", "amplitude": 6.0, "omega": 15.0,
                                              "phase": math.pi}},
            "analysis": {"type": "dynamic", "integrator": "newmark", "dt": 1e-3, "t_end": t_end}}


def test_a_building_is_a_3d_frame_on_rigid_diaphragms(tmp_path):
    """[[building]] (docs/opensees.md "Buildings"): 6-DOF nodes, one rigidDiaphragm per floor
    to a master at the reference point, the floor's m, m, J on the master or on a node at the
    mass centre tied to it, members with vecxz such that OpenSees' local y is martello's axis 2
    (docs/buildings.md: a vertical member's axis 2 at `angle` from x, a beam's vertical; I3
    resists displacement along axis 2, so OpenSees' Iz = I3), plan-point elements oriented
    along their normal with both nodes on the row's line of action, the floors' DOFs sampled
    on the masters and the member moments in members.csv."""
    scene = from_dict(small_buildings(), source="sb")
    m = export(scene, tmp_path / "x")
    fake, rows = run_fake(tmp_path / "x")
    assert (fake.ndm, fake.ndf) == (3, 6)
    dia = calls(fake, "rigidDiaphragm")
    assert len(dia) == 3 + 4                 # A1, B1, B2; a node of each side of the gap and the damper
    floors = [d for d in dia if len(d) > 3]
    assert len(floors) == 3
    masses = {a[0]: a[1:] for a in calls(fake, "mass")}
    # A1: the reference is the mass centre (2.5, 3): m, m and J = m (5² + 6²)/12 on the master
    a1 = floors[0]
    assert fake.nodes[a1[1]] == (2.5, 3.0, 3.0)
    assert masses[a1[1]] == (1.0e5, 1.0e5, 0.0, 0.0, 0.0, 1.0e5 * (25 + 36) / 12)
    assert sorted(fake.nodes[t] for t in a1[2:]) == [(0.0, 0.0, 3.0), (0.0, 6.0, 3.0), (5.0, 0.0, 3.0),
                                                     (5.0, 6.0, 3.0)]
    # B1: master at the reference (6, 1), the mass on a tied node at the centre (7.501, 3)
    b1 = floors[1]
    assert fake.nodes[b1[1]] == (6.0, 1.0, 3.0) and b1[1] not in masses
    centre = [t for t in b1[2:] if t in masses]
    assert len(centre) == 1 and fake.nodes[centre[0]] == pytest.approx((7.501, 3.0, 3.0), abs=1e-12)
    # members: local y = vecxz × x is axis 2 (x for a column at angle 0, up for a beam)
    transf = {a[1]: np.array(a[2:]) for a in calls(fake, "geomTransf")}
    beams = calls(fake, "element", "elasticBeamColumn") + calls(fake, "element", "ElasticTimoshenkoBeam")
    assert len(calls(fake, "element", "ElasticTimoshenkoBeam")) == 4        # A's columns: As2, As3
    assert len(beams) == 4 + 4 + 2 * (4 + 1 + 4)                            # columns, beams, the wall
    for e in beams:
        i, j = np.array(fake.nodes[e[2]]), np.array(fake.nodes[e[3]])
        x = (j - i) / np.linalg.norm(j - i)
        y = np.cross(transf[e[-1]], x)
        want = np.array([1.0, 0.0, 0.0]) if x[2] == 1.0 else np.array([0.0, 0.0, 1.0])
        assert np.allclose(y, want, atol=1e-15), (e, y)
    wall = [e for e in calls(fake, "element", "elasticBeamColumn") if e[4:10] == (0.5, 3e10, 1.25e10, 5e-3, 2e-3, 0.6)]
    assert len(wall) == 2                                                   # A E G J Iy=I2 Iz=I3
    # the gap and the damper: zeroLength along x between two nodes on y = 1 and y = 5
    zl = calls(fake, "element", "zeroLength")
    assert len(zl) == 2 and all(e[8:] == ("-orient", 1.0, 0.0, 0.0, 0.0, 1.0, 0.0) for e in zl)
    for e, y in zip(zl, (5.0, 1.0)):                # links are written before contacts
        assert fake.nodes[e[2]][1] == pytest.approx(y, abs=1e-12)
        assert fake.nodes[e[3]][1] == pytest.approx(y, abs=1e-12)
    assert [p[2] for p in calls(fake, "pattern", "UniformExcitation")] == [1]
    assert len(calls(fake, "region")) == 4
    # the floors' ux, uy, rz are the masters' DOFs 1, 2, 6
    head, data = rows[0], np.array(rows[1:], float)
    t = data[:, 0]
    for nm, dof in (("A1.ux", 1), ("B2.rz", 6)):
        master = floors[0][1] if nm == "A1.ux" else floors[2][1]
        assert np.allclose(data[:, head.index(f"u:{nm}")], master * 1e-3 * np.sin(t), rtol=0, atol=1e-15)
    mhead = open(tmp_path / "x" / "members.csv").readline().strip().split(",")
    assert mhead[:5] == ["t", "M2_i:A.C1.0.0", "M3_i:A.C1.0.0", "M2_j:A.C1.0.0", "M3_j:A.C1.0.0"]
    assert len(mhead) == 1 + 4 * len(beams)
    assert any("rigidDiaphragm" in b for _, b in m.mapping)


def test_a_building_reports_its_periods(tmp_path):
    """model.py --periods: eigen on every mass DOF (fullGenLapack) -> periods.csv."""
    export(from_dict(small_buildings(), source="sb"), tmp_path / "x")
    saved = sys.argv
    sys.argv = ["model.py", "--periods"]
    try:
        fake = FakeOpenSees()
        mods = {"openseespy": type(sys)("openseespy"), "openseespy.opensees": fake.module()}
        mods["openseespy"].opensees = mods["openseespy.opensees"]
        old = {k: sys.modules.get(k) for k in mods}
        sys.modules.update(mods)
        runpy.run_path(str(tmp_path / "x" / "model.py"), run_name="__main__")
    finally:
        sys.argv = saved
        for k, v in old.items():
            if v is None:
                sys.modules.pop(k, None)
            else:
                sys.modules[k] = v
    assert calls(fake, "eigen") == [("-fullGenLapack", 9)]            # 3 rigid floors x 3
    p = np.loadtxt(tmp_path / "x" / "periods.csv", delimiter=",", skiprows=1)
    assert np.allclose(p[:, 1], 2 * np.pi / np.arange(1, 10))           # the fake's ω = 1, 2, ...
    assert not (tmp_path / "x" / "history.csv").exists()


def test_modal_damping_is_eigen_then_modal_damping_with_the_masters_numbered_last():
    """Modal damping (docs/opensees.md "Modal damping"): eigen -fullGenLapack on every mass DOF,
    then modalDamping ζ, before the analysis; no Rayleigh region; every floor's master tagged
    above every other node (OpenSees writes the equations' eigenvectors in node-tag order and a
    slave's over its master's). Before, modal damping was refused."""
    d = small_buildings(reference=False)
    for b in d["building"]:
        b["damping"] = "modal"
    m = opensees_model(from_dict(d, source="sb"))
    names = [c.name for c in m.commands]
    assert [c.args for c in m.commands if c.name in ("eigen", "modalDamping")] == [("-fullGenLapack", 9), (0.05,)]
    assert names.index("eigen") < names.index("modalDamping") < names.index("analysis")
    assert "region" not in names
    masters = {c.args[1] for c in m.commands if c.name == "rigidDiaphragm"}
    others = {c.args[0] for c in m.commands if c.name == "node"} - masters
    assert len(masters) == 3 and min(masters) > max(others)


@pytest.mark.parametrize("change, match", [
    (lambda d: d["building"][1].update(damping="modal"),
     r"building damping = A: rayleigh 0.05, B: modal 0.05: cannot be exported.*one list of factors.*"
     r"the same zeta, or damping = \"rayleigh\""),
    (lambda d: [b.update(damping="modal") for b in d["building"]],
     r"building B: damping = \"modal\" with floor 1's reference point off its mass centre: cannot be "
     r"exported.*does not M-normalise.*remove reference"),
    (lambda d: ([b.update(damping="modal") for b in d["building"]], d["building"][1].pop("reference"),
                d["link"].append({"name": "s", "type": "spring", "a": "A1.ux", "b": "B1.ux", "k": 1e6})),
     r"building damping = \"modal\" with link s: cannot be exported.*couples the modes"),
    (lambda d: d["building"][0]["column"].pop("As3"),
     r"building A: member C1.0.0: one shear area.*give both As2 and As3"),
    (lambda d: (d["building"][0].update(diaphragm=False, slab={"E": 3e10, "thickness": 0.2}),
                d.update(link=[], contact=[])),
     r"building A: slab: cannot be exported.*incompatible-mode.*remove slab"),
    (lambda d: d["building"][1].update(ground_angle=30.0),
     r"building.ground_angle = 0, 30: cannot be exported.*one direction.*same ground_angle"),
    (lambda d: d["loads"].update(gravity=9.81), r"loads.gravity = 9.81 with \[\[building\]\].*remove gravity"),
    (lambda d: d.update(frame=[{"prefix": "F", "storeys": 1, "bays": 1, "storey_height": 3.0, "bay_width": 5.0,
                                "column": {"E": 3e10, "A": 0.16, "I": 2e-3}, "beam": {"E": 3e10, "A": 0.15,
                                                                                     "I": 3e-3}, "mass": 1e5}]),
     r"\[\[frame\]\] with \[\[building\]\]: cannot be exported.*two scenes"),
    (lambda d: d["contact"][0].update(a=None, b=None, normal=None, terms=[{"node": "A1.ux", "coef": 2.0},
                                                                         {"node": "B1.ux", "coef": -2.0}]),
     r"contact\[0\] \(g\)\.terms: cannot be exported.*unit plan direction"),
])
def test_what_a_building_export_cannot_write_is_refused(change, match):
    d = small_buildings()
    change(d)
    d["contact"] = [{k: v for k, v in c.items() if v is not None} for c in d["contact"]]
    with pytest.raises(ExportError, match=match):
        opensees_model(from_dict(d, source="sb"))


def test_a_row_of_terms_is_refused_naming_the_contact():
    """A contact between plan points or written as terms (docs/buildings.md) deforms by a row
    Σ c·u over several DOFs: no zeroLength element is that, and the exporter says so."""
    d = {"node": [{"name": "A.ux", "mass": 2e5, "v0": 0.3}, {"name": "A.rz", "mass": 3e6},
                  {"name": "B.ux", "mass": 1.5e5}],
         "contact": [{"name": "c", "terms": [{"node": "A.ux", "coef": 1.0}, {"node": "A.rz", "coef": -4.0},
                                            {"node": "B.ux", "coef": -1.0}],
                      "gap": 0.01, "scheme": "penalty", "law": "linear", "stiffness": 1e8}],
         "analysis": {"type": "dynamic", "integrator": "newmark", "dt": 1e-4, "t_end": 0.1}}
    with pytest.raises(ExportError, match=r"contact\[0\] \(c\)\.terms: cannot be exported.*zeroLength acts "
                                          r"between two nodes"):
        opensees_model(from_dict(d, source="rows"))


def test_a_full_kelvin_is_never_mapped_onto_a_half_kelvin_silently(tmp_path):
    """JankowskiImpact with n = 1 damps only while approaching: asked for, the change of law
    and both restitutions are stated in the differences, the script and on stderr."""
    scene = from_dict(two_bodies("kelvin", restitution=0.65), source="tb")
    m = opensees_model(scene)
    assert [c.args[0] for c in m.commands if c.name == "uniaxialMaterial"] == ["ViscoelasticGap"]
    with pytest.raises(ExportError, match="law kelvin as Hertzdamp"):
        opensees_model(scene, materials={"kelvin": "Hertzdamp"})
    m = export(scene, tmp_path / "h", materials={"kelvin": "JankowskiImpact"})
    (mat,) = [c.args for c in m.commands if c.name == "uniaxialMaterial"]
    xi = -math.log(0.65) / math.sqrt(math.pi ** 2 + math.log(0.65) ** 2)
    assert mat[0] == "JankowskiImpact" and mat[3] == pytest.approx(xi, rel=1e-14) and mat[6] == 1.0
    (note,) = [d for d in m.differences if "half-Kelvin" in d]
    assert "e = 0.821" in note and "0.65" in note
    assert "e = 0.821" in (tmp_path / "h" / "model.py").read_text()
    from martello.cli import main
    r = subprocess.run([sys.executable, "-m", "martello", "export", "benchmarks/p7/p7_two_oscillators.toml",
                        "-o", str(tmp_path / "cli"), "--material", "kelvin=JankowskiImpact"],
                       capture_output=True, text=True)
    assert r.returncode == 0 and "note: kelvin contact s1-s2 as JankowskiImpact" in r.stderr
    assert main(["export", P7, "-o", str(tmp_path / "bad"), "--material", "glue=Elastic"]) == 1


def test_half_kelvin_restitution_against_an_independent_integration():
    """e = exp(−(ξ/ν)·atan(ν/ξ)), ν = √(1 − ξ²), against scipy's integration of
    m*δ̈ = −kδ − cδ̇ while approaching and −kδ while restoring; 0.8214 at the ξ that gives
    0.65 for the full Kelvin law (scipy's rtol 1e-12: the digits asserted)."""
    for xi in (0.05, 0.1358, 0.3, 0.6, 0.9):
        w = 1.0

        def f(t, y):
            d, dd = y
            return [dd, -w * w * d - (2 * xi * w * dd if dd > 0 else 0.0)]

        turn = lambda t, y: y[1]                       # noqa: E731
        turn.terminal, turn.direction = True, -1
        out = lambda t, y: y[0]                        # noqa: E731
        out.terminal, out.direction = True, -1
        a = solve_ivp(f, (0, 10), [0.0, 1.0], rtol=1e-12, atol=1e-14, events=turn, method="DOP853")
        b = solve_ivp(f, (a.t[-1], a.t[-1] + 10), a.y[:, -1], rtol=1e-12, atol=1e-14, events=out,
                      method="DOP853")
        assert -b.y_events[0][0][1] == pytest.approx(half_kelvin_e(xi), rel=1e-9)
    xi65 = -math.log(0.65) / math.sqrt(math.pi ** 2 + math.log(0.65) ** 2)
    assert round(half_kelvin_e(xi65), 4) == 0.8214
    assert half_kelvin_e(0.0) == 1.0


def test_initial_state_and_loads(tmp_path):
    """P2 released above a plane under gravity: a0 = g is committed (OpenSees' Newmark takes
    the committed acceleration as a_0), gravity is a Plain pattern of m·g; a rectangular
    pulse ends one ulp before t_end (martello's window is half-open)."""
    scene = load("benchmarks/p2/p2_penalty_kelvin.toml")
    m = opensees_model(scene)
    acc = [c.args for c in m.commands if c.name == "setNodeAccel"]
    assert acc == [(1, 1, scene.gravity, "-commit")]
    loads = [c.args for c in m.commands if c.name == "load"]
    assert loads == [(1, scene.nodes[0]["mass"] * scene.gravity)]
    d = two_bodies("linear")
    d["loads"] = {"force": [{"node": "m2", "function": {"type": "rectangular", "amplitude": 5.0,
                                                        "t_start": 0.0, "t_end": 1e-3}}]}
    m = opensees_model(from_dict(d, source="tb"))
    (rect,) = [c.args for c in m.commands if c.name == "timeSeries"]
    assert rect[0] == "Rectangular" and rect[3] == math.nextafter(1e-3, 0) and rect[5] == 5.0
    assert [c.args for c in m.commands if c.name == "setNodeAccel"] == [(2, 1, 2.5, "-commit")]


def test_scorecard_doc_deterministic_part_is_current():
    """docs/opensees-scorecard.md's first part (which catalogue scenes OpenSees runs as they
    are, with another integrator, or not, and why) is regenerated from the catalogue and the
    exporter and must equal the committed copy (benchmarks/opensees/scorecard.py --docs)."""
    r = subprocess.run([sys.executable, "benchmarks/opensees/scorecard.py", "--check"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr


def test_modal_damping_of_repeated_frequencies_is_refused():
    """shear_buildings has two modes at √60 rad/s: LAPACK's dggev returns any basis of that
    eigenspace, not M-orthogonal (measured with OpenSeesPy 3.7.1.2: |ΦᵀMΦ − I| = 2.3e-3 and the
    exported run 2e-5 off martello's), so modal damping is refused there."""
    d = shear_buildings()
    for b in d["building"]:
        b["damping"], b["zeta"] = "modal", 0.05
    with pytest.raises(ExportError, match=r"two modes at 7.74596669 and 7.74596669 rad/s.*M-orthogonal"):
        opensees_model(from_dict(d, source="sh"))


def test_a_plain_node_side_follows_martellos_row():
    """martello's row of a contact between a floor point and a [[node]] is n·u(P) − u_node:
    the node's term is −1 whatever the normal (martello.scene.rows side_terms). A fixed node
    (a wall) is the ground here, so any normal exports (normal [−1, 0] was refused); a free
    node moves along x in the 3D model, so a normal that is not +x from a to b is refused
    naming the node and the fix (before: a bare "not a row" message)."""
    for fixed, n in ((True, [-1.0, 0.0]), (True, [0.6, 0.8]), (False, [1.0, 0.0]), (False, [-1.0, 0.0])):
        d = small_buildings(reference=False)
        for b in d["building"]:
            b["ground_angle"] = 0.0
        d["node"] = [{"name": "w", "mass": 1e3, "fixed": fixed}]
        d["contact"].append({"name": "fw", "a": {"floor": "A1", "x": 0.0, "y": 3.0}, "b": "w", "normal": n,
                             "gap": 0.001, "scheme": "penalty", "law": "linear", "stiffness": 1e8})
        if not fixed and n[0] < 0:
            with pytest.raises(ExportError, match=r"contact\[1\] \(fw\): node w with normal \(-1, 0\).*along "
                                                  r"the element's normal.*swap a and b"):
                opensees_model(from_dict(d, source="fw"))
            continue
        m = opensees_model(from_dict(d, source="fw"))
        (el,) = [c.args for c in m.commands if c.name == "element" and c.args[0] == "zeroLength"][-1:]
        orient = el[el.index("-orient") + 1:el.index("-orient") + 3]
        assert orient == pytest.approx(tuple(n))
