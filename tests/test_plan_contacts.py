"""Contacts and links as rows of the constraint operator (docs/buildings.md, "Contacts between
plan points"): δ = Σ c u(node) − gap. Oracles written here: the eccentric impact of two rigid
floors (impulse P = (1 + e) v_n / w, w = 1/m1 + r1²/J1 + 1/m2 + r2²/J2, and the velocities and
rotation rates after it) under every restitution integrator and the independent engine; the
Kelvin law's exact restitution at the eccentric effective mass 1/w; the plan-point kinematics
of a floor; a torsional dashpot against the matrix exponential; a slab striking a column
between floors in statics; and the identity that symmetric contacts give no torsion."""

import math

import numpy as np
import pytest
import scipy.linalg

from martello.binding import native
from martello.errors import SceneError
from martello.run import build_model, run_full
from martello.scene.loader import from_dict

M1, J1, M2, J2 = 2.0e5, 3.0e6, 1.5e5, 2.0e6
R1, R2 = 4.0, -3.0          # lever arms of the struck points (y_P − y_A, y_Q − y_B)
V0, GAP, E_RES = 0.3, 0.01, 0.6


def eccentric_pair(contact, analysis):
    """Two rigid floors (ux, rz each) flying free, A toward B at V0, joined by a contact at a
    point r1 off A's centre and r2 off B's: the row ux_A − r1 rz_A − ux_B + r2 rz_B − gap
    (docs/buildings.md)."""
    c = {"name": "c", "terms": [{"node": "A.ux", "coef": 1.0}, {"node": "A.rz", "coef": -R1},
                                {"node": "B.ux", "coef": -1.0}, {"node": "B.rz", "coef": R2}],
         "gap": GAP}
    c.update(contact)
    return {"node": [{"name": "A.ux", "mass": M1, "v0": V0}, {"name": "A.rz", "mass": J1},
                     {"name": "B.ux", "mass": M2}, {"name": "B.rz", "mass": J2}],
            "contact": [c], "analysis": analysis}


def closed_form(e):
    """Newton's law on the contact's row: P = (1 + e) v_n / w; the forces −gᵀP."""
    w = 1 / M1 + R1**2 / J1 + 1 / M2 + R2**2 / J2
    P = (1 + e) * V0 / w
    return P, {"A.ux": V0 - P / M1, "A.rz": R1 * P / J1, "B.ux": P / M2, "B.rz": -R2 * P / J2}


@pytest.mark.parametrize("integrator,tol", [
    # event-located impacts and the impulse-level steppers: the impulse solves Newton's law
    # with the exact Delassus W = g M⁻¹ gᵀ, so the velocities are right to round-off
    ("rk8pd", 1e-12), ("rkf45", 1e-12), ("msbdf", 1e-12), ("ida", 1e-10), ("cvode", 1e-10),
    ("arkode", 1e-10), ("moreau-jean", 1e-12), ("newmark-lagrange", 1e-9)])
def test_eccentric_impact_is_the_closed_form_under_every_restitution_integrator(integrator, tol):
    an = {"type": "dynamic", "integrator": integrator, "dt": 1e-3, "t_end": 0.1}
    if integrator in ("rk8pd", "rkf45", "msbdf", "ida", "cvode", "arkode"):
        an.update(rtol=1e-10, atol=1e-14)
    s, (cols, hist) = run_full(from_dict(eccentric_pair(
        {"scheme": "restitution", "restitution": E_RES}, an)))
    assert s["status"] == "MARTELLO_OK", s["message"]
    P, after = closed_form(E_RES)
    for name, v in after.items():
        got = hist[-1, cols.index(f"v:{name}")]
        assert got == pytest.approx(v, rel=tol, abs=tol * V0), name
    assert s["contacts"]["c"]["impacts"] == 1


def test_the_library_effective_mass_is_the_eccentric_one():
    """m* = 1/(g M⁻¹ gᵀ) = 1/w (martello_model_effective_masses), to round-off."""
    sc = from_dict(eccentric_pair({"scheme": "restitution", "restitution": E_RES},
                                  {"type": "dynamic", "integrator": "rk8pd", "dt": 1e-3, "t_end": 0.1}))
    with build_model(sc) as m:
        mstar = m.effective_masses()[0]
    assert mstar == pytest.approx(1 / (1 / M1 + R1**2 / J1 + 1 / M2 + R2**2 / J2), rel=1e-15)


def test_kelvin_restitution_is_exact_at_the_eccentric_effective_mass():
    """Kelvin's unclipped law with c = 2ξ√(k m*) realises e exactly for a free two-body impact
    (Anagnostopoulos 1988; docs/problems.md P5) — with m* = 1/w for two rigid floors struck off
    their centres. rk8pd at rtol 1e-12: the realised e to 1e-8."""
    an = {"type": "dynamic", "integrator": "rk8pd", "dt": 1e-3, "t_end": 0.2, "rtol": 1e-12, "atol": 1e-15}
    s = run_full(from_dict(eccentric_pair({"scheme": "penalty", "law": "kelvin", "stiffness": 5e8,
                                           "restitution": E_RES}, an)))[0]
    c = s["contacts"]["c"]
    assert c["restitution"][0] == pytest.approx(E_RES, rel=1e-8)
    assert c["approach_speeds"][0] == pytest.approx(V0, rel=1e-12)


def test_the_independent_engine_reads_rows():
    """martello.independent on the same scene (its own reading of the row, its own effective
    mass and impulse): the velocities and rotation rates after the impact."""
    from martello import independent
    d = eccentric_pair({"scheme": "restitution", "restitution": E_RES},
                       {"type": "dynamic", "integrator": "rk8pd", "dt": 1e-3, "t_end": 0.1})
    ref = independent.solve(d)
    _, after = closed_form(E_RES)
    for name, v in after.items():
        assert ref.nodes[name]["v_final"] == pytest.approx(v, rel=1e-12, abs=1e-15), name


# --- rows from plan points ----------------------------------------------------------------------

def shear_building(prefix, x0, **kw):
    b = {"prefix": prefix, "storeys": 1, "storey_height": 3.0, "grid_x": [x0, x0 + 6.0],
         "grid_y": [0.0, 8.0], "column": {"E": 3e10, "b2": 0.3, "b3": 0.5}, "mass": 1e5}
    b.update(kw)
    return b


def test_a_plan_point_row_is_the_rigid_floor_kinematics():
    """A point (x, y) of floor A1 and one of B1, normal n: the row is n·(P_A q_A − P_B q_B)
    with ux(P) = ux − (y − y_o) rz, uy(P) = uy + (x − x_o) rz about each floor's centre."""
    n = (0.8, 0.6)
    d = {"building": [shear_building("A", 0.0), shear_building("B", 6.02, mass_centre=[9.0, 3.0])],
         "contact": [{"name": "c", "a": {"floor": "A1", "x": 6.0, "y": 7.0},
                      "b": {"floor": "B1", "x": 6.02, "y": 7.0}, "normal": [4.0, 3.0], "gap": 0.02,
                      "scheme": "penalty", "law": "linear", "stiffness": 1e8}],
         "analysis": {"type": "static"}}
    sc = from_dict(d)
    terms = dict(sc.contacts[0]["terms"])
    ix = sc.index
    expected = {"A1.ux": n[0], "A1.uy": n[1], "A1.rz": -n[0] * (7.0 - 4.0) + n[1] * (6.0 - 3.0),
                "B1.ux": -n[0], "B1.uy": -n[1], "B1.rz": n[0] * (7.0 - 3.0) - n[1] * (6.02 - 9.0)}
    for name, c in expected.items():
        assert terms.get(ix[name], 0.0) == pytest.approx(c, rel=1e-15, abs=1e-15), name


def test_a_torque_against_a_point_wall_is_resisted_by_the_lever_arm():
    """Statics: floor B1 turned by a torque T (clockwise: the point (6, 8) moves along +x)
    against a rigid wall there (a contact of the point to ground, Lagrange): the KKT system
    written here from the block and the point's kinematics, [K gᵀ; g 0] [q; P] = [f; gap]
    (the contact pushes back with −gᵀP)."""
    T = -2.0e6
    d = {"building": [shear_building("B", 0.0)],
         "contact": [{"name": "wall", "a": {"floor": "B1", "x": 6.0, "y": 8.0}, "b": "ground",
                      "gap": 0.0, "scheme": "lagrange"}],
         "loads": {"force": [{"node": "B1.rz", "value": T}]}, "analysis": {"type": "static"}}
    sc = from_dict(d)
    s = run_full(sc)[0]
    K = sc.blocks[0]["k"]
    g = np.array([1.0, 0.0, -(8.0 - 4.0)])        # ux − (y − y_c) rz, centre (3, 4)
    kkt = np.block([[K, g[:, None]], [g[None, :], np.zeros((1, 1))]])
    sol = np.linalg.solve(kkt, np.array([0.0, 0.0, T, 0.0]))
    assert s["contacts"]["wall"]["force"] == pytest.approx(sol[3], rel=1e-9) and sol[3] > 0
    for k, q in enumerate(("ux", "uy", "rz")):
        assert s["nodes"][f"B1.{q}"]["u"] == pytest.approx(sol[k], rel=1e-9, abs=1e-15)


def test_a_torsional_dashpot_between_plan_points_is_the_matrix_exponential():
    """A dashpot from a plan point of floor B1 to the ground along y (a link row): the free
    vibration from an initial twist is exp(A t) x0 with A = [[0, I], [−M⁻¹K, −M⁻¹c ggᵀ]], K the
    block and g the point's kinematics written here. Average acceleration at h = 2e-4 s: its
    phase error (ωh)²ωt/12 at the highest ω over 0.5 s bounds the difference (twice it)."""
    c = 2.0e6
    d = {"building": [shear_building("B", 0.0)],
         "link": [{"name": "dp", "type": "dashpot", "a": {"floor": "B1", "x": 6.0, "y": 8.0}, "b": "ground",
                   "direction": [0.0, 1.0], "c": c}],
         "analysis": {"type": "dynamic", "integrator": "newmark", "dt": 2e-4, "t_end": 0.5}}
    sc = from_dict(d)
    for nd in sc.nodes:
        if nd["name"] == "B1.rz":
            nd["u0"] = 1e-3
    s, (cols, hist) = run_full(sc)
    K = sc.blocks[0]["k"]
    M = np.diag([nd["mass"] for nd in sc.nodes])
    g = np.array([0.0, 1.0, 6.0 - 3.0])           # uy + (x − x_c) rz
    Minv = np.linalg.inv(M)
    A = np.block([[np.zeros((3, 3)), np.eye(3)], [-Minv @ K, -Minv @ (c * np.outer(g, g))]])
    x0 = np.array([0.0, 0.0, 1e-3, 0.0, 0.0, 0.0])
    t = hist[:, cols.index("t")]
    exact = np.array([scipy.linalg.expm(A * tt) @ x0 for tt in t[::50]])
    got = hist[::50, cols.index("u:B1.rz")]
    w = np.sqrt(np.linalg.eigvalsh(np.sqrt(Minv) @ K @ np.sqrt(Minv))).max()
    assert np.max(np.abs(got - exact[:, 2])) < 2 * (w * 2e-4) ** 2 * w * 0.5 / 12 * 1e-3
    assert s["links"]["dp"]["max_abs_force"] > 0


def test_symmetric_contacts_between_floors_give_no_torsion():
    """Two identical shear buildings side by side, two contacts at points symmetric about
    the floors' centres: no rz (to round-off), and ux is the planar pair's — nodes with the
    buildings' lateral stiffness joined by one contact of twice the stiffness (an identity)."""
    an = {"type": "dynamic", "integrator": "newmark", "dt": 1e-3, "t_end": 2.0, "tol_residual": 1e-12}
    ground = {"ground_acceleration": {"type": "sine", "amplitude": 6.0, "omega": 14.0}}
    A, B = shear_building("A", 0.0), shear_building("B", 6.02, storey_height=4.0)
    d = {"building": [A, B],
         "contact": [{"name": f"c{k}", "a": {"floor": "A1", "x": 6.0, "y": y}, "b": {"floor": "B1", "x": 6.02, "y": y},
                      "gap": 0.01, "scheme": "penalty", "law": "linear", "stiffness": 2e8}
                     for k, y in enumerate((1.0, 7.0))],
         "loads": ground, "analysis": an}
    sc = from_dict(d)
    s, (cols, hist) = run_full(sc)
    kA, kB = (sc.blocks[i]["k"][0, 0] for i in (0, 1))
    planar = {"node": [{"name": "a", "mass": 1e5}, {"name": "b", "mass": 1e5}],
              "link": [{"type": "spring", "a": "a", "b": "ground", "k": kA},
                       {"type": "spring", "a": "b", "b": "ground", "k": kB}],
              "contact": [{"name": "c", "a": "a", "b": "b", "gap": 0.01, "scheme": "penalty",
                           "law": "linear", "stiffness": 4e8}], "loads": ground, "analysis": an}
    sp, (cp, hp) = run_full(from_dict(planar))
    assert sp["contacts"]["c"]["impacts"] > 0
    for bn, pn in (("A1", "a"), ("B1", "b")):
        ub, up = hist[:, cols.index(f"u:{bn}.ux")], hp[:, cp.index(f"u:{pn}")]
        assert np.abs(ub - up).max() < 1e-8 * np.abs(up).max()
        assert np.abs(hist[:, cols.index(f"u:{bn}.rz")]).max() < 1e-14


def test_a_slab_striking_a_column_between_floors_loads_its_shear():
    """Offset floors in statics: building A's floor (3 m high) pushed against a point kept at
    1.5 m on B's edge column (B's storeys 4.5 m): the contact force is the jump of the struck
    column's shear at the point (equilibrium of the point, round-off), and the seed's stiffness
    rule gives the contact 2 × 12EI/h³ of the struck column."""
    from martello.building3d import gap_stiffness_offset, column_section
    sec = column_section(3e10, 0.3, 0.5)
    k = gap_stiffness_offset(sec, 4.5, 2.0)
    A = shear_building("A", 0.0)
    B = shear_building("B", 6.02, storey_height=4.5,
                       split=[{"name": "S", "line": "0.0", "storey": 1, "height": 3.0, "mass": 800.0}])
    d = {"building": [A, B],
         "contact": [{"name": "c", "a": {"floor": "A1", "x": 6.0, "y": 0.0}, "b": {"point": "B.S"},
                      "gap": 0.0, "scheme": "penalty", "law": "linear", "stiffness": k}],
         "loads": {"force": [{"node": "A1.ux", "value": 4e5}]}, "analysis": {"type": "static"}}
    s = run_full(from_dict(d))[0]
    F = s["contacts"]["c"]["force"]
    assert F > 0
    m = s["buildings"]["B"]["members"]
    assert m["C1.0.0.a"]["V2_j"] + m["C1.0.0.b"]["V2_i"] == pytest.approx(F, rel=1e-9)


def test_every_penalty_law_runs_through_a_plan_point_contact():
    """The laws read the same row: each runs the eccentric pair, closes and reopens the
    contact, and the damped ones dissipate (0 < e < 1; Kelvin exactly above)."""
    an = {"type": "dynamic", "integrator": "rk8pd", "dt": 1e-3, "t_end": 0.2, "rtol": 1e-10, "atol": 1e-14}
    for law in ("linear", "hertz", "hunt-crossley", "lankarani-nikravesh", "flores", "jankowski"):
        c = {"scheme": "penalty", "law": law, "stiffness": 5e8 if law == "linear" else 5e10}
        if law not in ("linear", "hertz"):
            c["restitution"] = E_RES
        s = run_full(from_dict(eccentric_pair(c, an)))[0]
        assert s["status"] == "MARTELLO_OK", (law, s["message"])
        e = s["contacts"]["c"]["restitution"][0]
        assert (e == pytest.approx(1.0, rel=1e-6)) if law in ("linear", "hertz") else (0.3 < e < 1.0), (law, e)


def test_rows_are_refused_with_the_field():
    base = {"node": [{"name": "a", "mass": 1.0}], "analysis": {"type": "static"}}
    cases = [({"terms": [{"node": "a", "coef": 1.0}], "a": "a"}, "contact[0].a"),
             ({"terms": [{"node": "ground", "coef": 1.0}]}, "contact[0].terms"),
             ({"terms": [{"node": "zz", "coef": 1.0}]}, r"contact\[0\].terms\[0\].node"),
             ({"a": "a"}, "contact[0].b"),
             ({"a": "a", "b": "ground", "normal": [1.0, 0.0]}, "contact[0].normal"),
             ({"a": {"floor": "X1", "x": 0.0, "y": 0.0}, "b": "ground"}, "contact[0].a.floor")]
    for extra, where in cases:
        c = {"name": "c", "scheme": "penalty", "law": "linear", "stiffness": 1.0}
        c.update(extra)
        with pytest.raises(SceneError, match=where.replace("[0]", r"\[0\]") if "\\" not in where else where):
            from_dict(dict(base, contact=[c]))


def test_the_row_doors_check_their_input():
    with native.Model(2, 1, 1, 0) as m:
        m.set_nodes([1.0, 1.0], [0.0, 0.0], [0.0, 0.0], [0, 0])
        with pytest.raises(Exception, match="no term on a node"):
            m.add_contact_row([-1], [1.0], 0.0, 0, 0, np.zeros(native.constant("NPAR_CONTACT")))
        with pytest.raises(Exception, match="finite"):
            m.add_contact_row([0, 1], [1.0, math.inf], 0.0, 0, 0, np.zeros(native.constant("NPAR_CONTACT")))
        with pytest.raises(Exception, match="out of range"):
            m.add_link_row(0, [0, 7], [1.0, -1.0], np.zeros(native.constant("NPAR_LINK")))
