"""3D buildings ([[building]], docs/buildings.md, docs/problems.md P11): the condensed block
against oracles written here independently of martello.building3d — the storey stiffness of
shear-type storeys (Σ k r² + Σ k_t about the reference point), the coupled lateral–torsional
periods of a one-storey eccentric system in closed form, a Timoshenko cantilever, the
slope-deflection portal, a fixed–fixed column struck between its ends — identities of the
method (the symmetric building is the planar frame of martello.frame2d to round-off; the
choice of the reference point and the direction of the ground motion change nothing
physical), and the block in the native library under every integrator."""

import math

import numpy as np
import pytest

from martello.errors import SceneError
from martello.run import run_full
from martello.scene.loader import from_dict

E = 3.0e10
G = E / 2.4


def building(**kw):
    b = {"prefix": "B", "storeys": 1, "storey_height": 3.0, "grid_x": [0.0, 6.0],
         "grid_y": [0.0, 4.0], "column": {"E": E, "b2": 0.3, "b3": 0.5}, "mass": 2.0e5}
    b.update(kw)
    return b


def scene(*buildings, analysis=None, **extra):
    d = {"building": list(buildings), "analysis": analysis or {"type": "static"}}
    d.update(extra)
    return d


def rect_J(a, b):
    """Roark's torsion constant of an a x b rectangle (table 10.7 case 4), written here."""
    a, b = max(a, b), min(a, b)
    return a * b**3 * (1 / 3 - 0.21 * (b / a) * (1 - (b / a) ** 4 / 12))


def storey_stiffness(members, h, ref):
    """K (3 x 3, about ref) of a shear-type storey: each member (x, y, angle°, I3, I2, J)
    a plan spring 12 E I/h³ along its axes 2 and 3 and GJ/h in torsion; the rigid floor
    moves a point by (u_x − (y − y_o) r_z, u_y + (x − x_o) r_z) (the textbook storey matrix,
    e.g. Chopra, Dynamics of Structures, §9.5)."""
    K = np.zeros((3, 3))
    for x, y, ang, I3, I2, J in members:
        c, s = math.cos(math.radians(ang)), math.sin(math.radians(ang))
        k2, k3 = 12 * E * I3 / h**3, 12 * E * I2 / h**3
        kp = k2 * np.outer([c, s], [c, s]) + k3 * np.outer([-s, c], [-s, c])
        T = np.array([[1.0, 0.0, -(y - ref[1])], [0.0, 1.0, x - ref[0]]])
        K += T.T @ kp @ T
        K[2, 2] += G * J / h
    return K


# --- shear-type storeys --------------------------------------------------------------------

def test_shear_storey_stiffness_is_the_sum_of_k_r2_and_kt():
    """Columns of two sizes at any angle plus a wall, about a stated reference point: the
    condensed 3 x 3 block is the storey matrix written out (Σ k r² + Σ GJ/h in torsion).
    Both are the same few sums in different orders: rtol 1e-12."""
    b = building(grid_x=[0.0, 5.0, 11.0], grid_y=[0.0, 4.5], column_angle=30.0,
                 member=[{"name": "W", "x": 13.0, "y": 2.0, "angle": 90.0,
                          "section": {"E": E, "A": 0.6, "I2": 0.005, "I3": 0.8, "J": 0.02}}],
                 reference=[2.0, 1.0])
    sc = from_dict(scene(b))
    K = sc.blocks[0]["k"]
    Ic3, Ic2, Jc = 0.5 * 0.3**3 / 12, 0.3 * 0.5**3 / 12, rect_J(0.3, 0.5)
    members = [(x, y, 30.0, Ic3, Ic2, Jc) for x in (0.0, 5.0, 11.0) for y in (0.0, 4.5)]
    members.append((13.0, 2.0, 90.0, 0.8, 0.005, 0.02))
    expected = storey_stiffness(members, 3.0, (2.0, 1.0))
    assert K == pytest.approx(expected, rel=1e-12, abs=1e-12 * np.abs(expected).max())
    # about the mass centre (the default) the torsional term is Σ k r² + Σ k_t there
    b.pop("reference")
    sc = from_dict(scene(dict(b, column_angle=0.0)))
    members = [(x, y, 0.0, Ic3, Ic2, Jc) for x in (0.0, 5.0, 11.0) for y in (0.0, 4.5)]
    members.append((13.0, 2.0, 90.0, 0.8, 0.005, 0.02))
    xc, yc = 5.5, 2.25                    # the grid's centre
    ktheta = sum(12 * E * (I3 * (y - yc) ** 2 if ang == 0 else I2 * (y - yc) ** 2) / 27
                 + 12 * E * (I2 * (x - xc) ** 2 if ang == 0 else I3 * (x - xc) ** 2) / 27
                 + G * J / 3 for x, y, ang, I3, I2, J in members)
    assert sc.blocks[0]["k"][2, 2] == pytest.approx(ktheta, rel=1e-12)


def one_storey_eccentric():
    """Four 30 x 50 columns on a 6 x 4 m plan and a wall along y at x = 6 (the stiff side):
    the centre of rigidity lies off the mass centre along x, so uy couples with rz."""
    wall = {"E": E, "A": 0.5, "I2": 1e-3, "I3": 0.4, "J": 1e-3}
    return building(member=[{"name": "W", "x": 6.0, "y": 2.0, "angle": 90.0, "section": wall}])


def test_one_storey_eccentric_periods_are_the_closed_form():
    """Kan & Chopra (1977), Chopra §15 (one-storey unsymmetric plan): with ω_y² = K_y/m,
    ω_θ² = K_θR/J (torsional stiffness about the centre of rigidity R), e the offset of R from
    the mass centre and r² = J/m, ω² = ½[ω_y²(1 + e²/r²) + ω_θ²] ∓ ½√([ω_y²(1 + e²/r²) + ω_θ²]²
    − 4ω_y²ω_θ²); ω_x² = K_x/m uncoupled. K_y, e, K_θR summed here from the members; the
    library's modes come from a generic eigensolver on its condensed block: rtol 1e-10."""
    sc = from_dict(scene(one_storey_eccentric()))
    m, Lx, Ly = 2.0e5, 6.0, 4.0
    J = m * (Lx**2 + Ly**2) / 12
    h = 3.0
    col_kx, col_ky = 12 * E * (0.5 * 0.3**3 / 12) / h**3, 12 * E * (0.3 * 0.5**3 / 12) / h**3
    wall_ky = 12 * E * 0.4 / h**3          # the wall's axis 2 is y: I3 resists y
    wall_kx = 12 * E * 1e-3 / h**3
    Kx, Ky = 4 * col_kx + wall_kx, 4 * col_ky + wall_ky
    xR = (2 * col_ky * 0.0 + 2 * col_ky * 6.0 + wall_ky * 6.0) / Ky
    yR = (2 * col_kx * 0.0 + 2 * col_kx * 4.0 + wall_kx * 2.0) / Kx
    kt = G * (4 * rect_J(0.3, 0.5) + 1e-3) / h
    KthR = (sum(col_ky * (x - xR) ** 2 for x in (0, 0, 6, 6)) + wall_ky * (6 - xR) ** 2
            + sum(col_kx * (y - yR) ** 2 for y in (0, 4, 0, 4)) + wall_kx * (2 - yR) ** 2 + kt)
    ex, ey = xR - 3.0, yR - 2.0
    assert ey == pytest.approx(0.0, abs=1e-12)            # symmetric in y: x stays uncoupled
    wy2, wt2, wx2, r2 = Ky / m, KthR / J, Kx / m, J / m
    a = wy2 * (1 + ex**2 / r2) + wt2
    disc = math.sqrt(a * a - 4 * wy2 * wt2)
    expected = sorted([wx2, (a - disc) / 2, (a + disc) / 2])
    got = sorted(md["omega"] ** 2 for md in sc.extras["buildings"][0]["modes"])
    assert got == pytest.approx(expected, rel=1e-10)
    # the torsional share of the two coupled modes: their rz kinetic energy J φθ² over the total
    shares = sorted(md["torsional_share"] for md in sc.extras["buildings"][0]["modes"])
    assert shares[0] == pytest.approx(0.0, abs=1e-12) and 0 < shares[1] < shares[2] < 1
    assert shares[1] + shares[2] == pytest.approx(1.0, rel=1e-12)     # Σ over modes: one floor


@pytest.mark.parametrize("integrator,dt,tol", [
    # second-order fixed steps: phase error ~(ωh)²ωt/24 at ω ≈ 60 rad/s, h = 1e-4, t = 0.25:
    # 4e-5 of the amplitude; the adaptive ones at rtol 1e-10
    ("newmark", 1e-4, 2e-4), ("hht", 1e-4, 2e-3), ("generalized-alpha", 1e-4, 2e-3),
    ("central-difference", 1e-4, 2e-4), ("moreau-jean", 1e-4, 2e-2), ("fast-nonlinear", 1e-4, 2e-4),
    ("rk8pd", 1e-3, 1e-6), ("ida", 1e-3, 1e-4), ("msbdf", 1e-3, 1e-4)])
def test_step_load_on_an_eccentric_storey_is_modal_superposition_under_every_integrator(
        integrator, dt, tol):
    """A constant force F along y at the mass centre of the eccentric storey, from rest,
    undamped: q(t) = Σ_k φ_k φ_kᵀ F (1 − cos ω_k t)/ω_k² with the modes of the 2 x 2
    (uy, rz) system written from the storey sums (as in the closed-form periods); the
    response excites the torsional mode (rz ≠ 0). Tolerances: each method's error at its
    step (parameters)."""
    an = {"type": "dynamic", "integrator": integrator, "dt": dt, "t_end": 0.25}
    if integrator in ("rk8pd", "ida", "msbdf"):
        an.update(rtol=1e-10, atol=1e-14)
    an.update({"hht": {"alpha": -0.05}, "generalized-alpha": {"rho_inf": 0.9}}.get(integrator, {}))
    F = 1.0e5
    sc = from_dict(scene(one_storey_eccentric(), analysis=an,
                         loads={"force": [{"node": "B1.uy", "value": F}]}))
    K = sc.blocks[0]["k"][1:, 1:]
    m, J = 2.0e5, 2.0e5 * (36 + 16) / 12
    # the 2 x 2 problem's modes from numpy on the library's block (its entries are checked
    # against the storey sums by test_shear_storey_stiffness_is_the_sum_of_k_r2_and_kt)
    Mh = np.diag([1 / math.sqrt(m), 1 / math.sqrt(J)])
    lam, Y = np.linalg.eigh(Mh @ K @ Mh)
    Phi = Mh @ Y
    s, (cols, hist) = run_full(sc)
    assert s["status"] == "MARTELLO_OK", s["message"]
    t = hist[:, cols.index("t")]
    q = np.array([[F * Phi[i, k] * Phi[0, k] for k in range(2)] for i in range(2)])
    exact = [sum(q[i, k] * (1 - np.cos(math.sqrt(lam[k]) * t)) / lam[k] for k in range(2)) for i in range(2)]
    for i, name in enumerate(("B1.uy", "B1.rz")):
        got = hist[:, cols.index(f"u:{name}")]
        assert np.max(np.abs(got - exact[i])) < tol * np.max(np.abs(exact[i])), name
    # x is uncoupled but for the round-off of the condensed block's x–y entries
    assert np.max(np.abs(hist[:, cols.index("u:B1.ux")])) < 1e-14 * np.max(np.abs(exact[0]))


# --- frame mode ------------------------------------------------------------------------------

def test_timoshenko_cantilever_and_torsion():
    """One column, frame mode (its top free to rotate): k = 1/(h³/(3EI) + h/(G A_s)) along
    each axis (Timoshenko beam, e.g. Przemieniecki §5.6) and GJ/h in torsion."""
    sec = {"E": E, "G": G, "A": 0.15, "I2": 3e-3, "I3": 1e-3, "J": 2e-3, "As2": 0.125, "As3": 0.1}
    b = building(model="frame", grid_x=[0.0], grid_y=[0.0], column=sec, inertia=1e4, storey_height=4.0)
    K = from_dict(scene(b)).blocks[0]["k"]
    h = 4.0
    assert K[0, 0] == pytest.approx(1 / (h**3 / (3 * E * 1e-3) + h / (G * 0.125)), rel=1e-12)
    assert K[1, 1] == pytest.approx(1 / (h**3 / (3 * E * 3e-3) + h / (G * 0.1)), rel=1e-12)
    assert K[2, 2] == pytest.approx(G * 2e-3 / h, rel=1e-12)


def test_portal_frame_in_3d_is_the_slope_deflection_closed_form():
    """Two columns and one beam along x on a rigid floor (the 3D frame's portal): k =
    (24 EI_c/h³)(a + 6b)/(4a + 6b), a = I_c/h, b = I_b/L (Chopra, Example 1.1); columns
    axially stiff (I/(A h²) = 1e-9) as the closed form assumes: rtol 1e-6."""
    h, L, Ic, Ib = 3.0, 5.0, 2.1e-3, 1.6e-3
    col = {"E": E, "A": Ic / (1e-9 * h**2), "I2": Ic, "I3": Ic, "J": 1e-3}
    beam = {"E": E, "A": 0.12, "I2": 1e-3, "I3": Ib, "J": 1e-9}
    b = building(model="frame", grid_x=[0.0, L], grid_y=[0.0], column=col, beam=beam, inertia=1e4)
    K = from_dict(scene(b)).blocks[0]["k"]
    a, bb = Ic / h, Ib / L
    assert K[0, 0] == pytest.approx(24 * E * Ic / h**3 * (a + 6 * bb) / (4 * a + 6 * bb), rel=1e-6)


def test_symmetric_building_is_the_planar_frame():
    """Three identical frames along x (beams along x only), symmetric plan, modal damping:
    the building's ux block is the planar frame's (its sections three times) to round-off,
    no x–rz coupling, and under a ground motion along x its floors follow the planar frame's
    history to the Newton tolerance, rz stays at round-off and every column's M3 is the
    planar column's moment shared by the three frames (M3 about +y = −M counterclockwise in
    the x–z plane)."""
    def rect(b, h, n):
        return {"E": E, "A": n * b * h, "I": n * b * h**3 / 12}
    an = {"type": "dynamic", "integrator": "newmark", "dt": 2e-3, "t_end": 1.5,
          "tol_residual": 1e-12}
    ground = {"ground_acceleration": {"type": "sine", "amplitude": 3.0, "omega": 9.0}}
    planar = {"frame": [{"prefix": "P", "storeys": 3, "bays": 2, "storey_height": 3.0, "bay_width": 5.0,
                         "column": rect(0.3, 0.5, 3), "beam": rect(0.3, 0.5, 3), "mass": 1.5e5,
                         "zeta": 0.05, "damping": "modal"}],
              "loads": ground, "analysis": an}
    b3 = {"building": [building(storeys=3, model="frame", grid_x=[0.0, 5.0, 10.0], grid_y=[0.0, 4.5, 9.0],
                                column={"E": E, "b2": 0.5, "b3": 0.3}, beam={"E": E, "b": 0.3, "h": 0.5},
                                beam_y=False, mass=1.5e5, zeta=0.05, damping="modal")],
          "loads": ground, "analysis": an}
    sp, sb = from_dict(planar), from_dict(b3)
    Kp, Kb = sp.blocks[0]["k"], sb.blocks[0]["k"]
    scale = np.abs(Kp).max()
    assert np.abs(Kb[0::3, 0::3] - Kp).max() < 1e-14 * scale
    assert np.abs(Kb[0::3, 2::3]).max() < 1e-14 * scale
    rp, (cp, hp) = run_full(sp)
    rb, (cb, hb) = run_full(sb)
    for f in (1, 2, 3):
        up, ub = hp[:, cp.index(f"u:P{f}")], hb[:, cb.index(f"u:B{f}.ux")]
        assert np.abs(up - ub).max() < 1e-9 * np.abs(up).max()
        assert np.abs(hb[:, cb.index(f"u:B{f}.rz")]).max() < 1e-15
        assert np.abs(hb[:, cb.index(f"u:B{f}.uy")]).max() < 1e-15
    for s_ in (1, 2, 3):
        for line in (0, 1, 2):
            mp = rp["frames"]["P"]["members"][f"C{s_}.{line}"]["M_i"]
            for j in (0, 1, 2):
                mb = rb["buildings"]["B"]["members"][f"C{s_}.{line}.{j}"]["M3_i"]
                assert mb["max"] == pytest.approx(-mp["min"] / 3, rel=1e-8)
    # no M2 here: the biaxial resultant's peak is |M3|'s, at its time; both are located inside
    # the steps on the same cubic Hermite (docs/results.md, "Frames and buildings"), so they
    # agree to rounding (the resultant's maximum bisected: 60 halvings of the step). Taken at
    # the steps alone, the resultant fell 2.8e-5 short, 0.7 ms early (h = 2 ms)
    c = rb["buildings"]["B"]["members"]["C1.0.0"]
    peak = max(c["M3_i"]["max"], -c["M3_i"]["min"])
    at = c["M3_i"]["t_max"] if c["M3_i"]["max"] >= -c["M3_i"]["min"] else c["M3_i"]["t_min"]
    h = rb["integrator"]["dt"]
    assert c["M_i_resultant_max"] == pytest.approx(peak, rel=1e-12)
    assert abs(c["M_i_resultant_t"] - at) <= 1e-9 * h


def test_reference_point_and_ground_direction_change_nothing_physical():
    """Identities of the method: (1) the eccentric storey about its mass centre or about a
    corner (a dense mass matrix, mass couplings in the native model) has the same periods and,
    under the same ground motion, the same displacement of a plan point; (2) a ground motion
    along y (ground_angle 90) of a building is the motion along x of the building turned by
    90° (grid x and y swapped, the wall turned)."""
    an = {"type": "dynamic", "integrator": "newmark", "dt": 1e-3, "t_end": 1.0, "tol_residual": 1e-12}
    ground = {"ground_acceleration": {"type": "sine", "amplitude": 2.0, "omega": 20.0}}
    pt = [{"name": "corner", "floor": 1, "x": 6.0, "y": 4.0}]
    base = dict(one_storey_eccentric(), point=pt, ground_angle=90.0)
    a = from_dict(scene(base, analysis=an, loads=ground))
    b = from_dict(scene(dict(base, reference=[0.0, 0.0]), analysis=an, loads=ground))
    assert len(b.couplings) > 0 and len(a.couplings) == 0
    wa = [md["omega"] for md in a.extras["buildings"][0]["modes"]]
    wb = [md["omega"] for md in b.extras["buildings"][0]["modes"]]
    assert wb == pytest.approx(wa, rel=1e-10)
    ra, rb = run_full(a)[0], run_full(b)[0]
    for q in ("ux", "uy"):
        pa, pb = ra["buildings"]["B"]["points"]["corner"][q], rb["buildings"]["B"]["points"]["corner"][q]
        assert pb["max"] == pytest.approx(pa["max"], rel=1e-8, abs=1e-12)
    # turned by 90°: x' = y, y' = −x maps the plan; the wall at (6, 2) along y goes to
    # (2, −6) along x' (angle 0), columns turn with it
    turned = building(grid_x=[0.0, 4.0], grid_y=[-6.0, 0.0], column_angle=-90.0,
                      member=[{"name": "W", "x": 2.0, "y": -6.0, "angle": 0.0,
                               "section": {"E": E, "A": 0.5, "I2": 1e-3, "I3": 0.4, "J": 1e-3}}])
    c = from_dict(scene(turned, analysis=an, loads=ground))
    rc, ra2 = run_full(c)[0], ra
    assert rc["nodes"]["B1.ux"]["u_max"] == pytest.approx(ra2["nodes"]["B1.uy"]["u_max"], rel=1e-8)
    assert rc["nodes"]["B1.rz"]["u_max"] == pytest.approx(ra2["nodes"]["B1.rz"]["u_max"], rel=1e-8)


def test_storey_shears_and_torques_balance_the_floor_loads():
    """Statics: the storey shear is the sum of the forces on the floors above it and the
    storey torque their moment about the floor's reference (equilibrium), in frame mode with
    beams, a wall and a mass centre off the plan's centre."""
    b = dict(one_storey_eccentric(), storeys=2, model="frame", beam={"E": E, "b": 0.3, "h": 0.5},
             mass_centre=[2.0, 1.5])
    d = scene(b, loads={"force": [{"node": "B2.ux", "value": 3e4}, {"node": "B2.uy", "value": -2e4},
                                  {"node": "B2.rz", "value": 5e4}, {"node": "B1.uy", "value": 1e4}]})
    s = run_full(from_dict(d))[0]["buildings"]["B"]["storeys"]
    assert s["2"]["shear_x"] == pytest.approx(3e4, rel=1e-9)
    assert s["2"]["shear_y"] == pytest.approx(-2e4, rel=1e-9)
    assert s["2"]["torque"] == pytest.approx(5e4, rel=1e-9)
    assert s["1"]["shear_y"] == pytest.approx(-1e4, rel=1e-9)
    assert s["1"]["torque"] == pytest.approx(5e4, rel=1e-9)   # both floors' centres at (2, 1.5)


def test_a_column_struck_between_floors_is_the_fixed_fixed_beam():
    """An offset floor: a point kept at height a of a column whose floor is held by a wall
    10⁸ times stiffer; a force P there deflects it by P a³ b³/(3 E I L³) (fixed–fixed beam
    under a point load, Roark table 8.1 case 1e) to 1e-7, and the column's shear jumps by P
    at the point (equilibrium, round-off). The seed's rule for the gap stiffness is 1.5–2
    times the column's 12 E I/h³."""
    from martello.building3d import Section, gap_stiffness_offset
    wall = {"E": E, "A": 1.0, "I2": 1e5, "I3": 1e5, "J": 1e5}
    b = building(grid_x=[0.0], grid_y=[0.0], storey_height=3.0, inertia=1e4,
                 member=[{"name": "W", "x": 5.0, "y": 0.0, "section": wall}],
                 split=[{"name": "S", "line": "0.0", "storey": 1, "height": 1.0, "mass": 500.0}])
    P = 1.0e4
    s = run_full(from_dict(scene(b, loads={"force": [{"node": "B.S.ux", "value": P}]})))[0]
    I = 0.5 * 0.3**3 / 12
    a_, b_, L = 1.0, 2.0, 3.0
    assert s["nodes"]["B.S.ux"]["u"] == pytest.approx(P * a_**3 * b_**3 / (3 * E * I * L**3), rel=1e-7)
    m = s["buildings"]["B"]["members"]
    # the section shear of the lower segment is V2_j of its top end, of the upper one −V2_i
    # of its foot: the jump V2_j(a) + V2_i(b) is the point's equilibrium with P
    assert m["C1.0.0.a"]["V2_j"] + m["C1.0.0.b"]["V2_i"] == pytest.approx(P, rel=1e-9)
    sec = Section(E, G, 0.15, 0.0, I, 1.0)
    assert gap_stiffness_offset(sec, 3.0, 1.5) == pytest.approx(1.5 * 12 * E * I / 27)
    with pytest.raises(ValueError, match="1.5"):
        gap_stiffness_offset(sec, 3.0, 2.5)


def test_modal_table_identities():
    """Complete modes: the effective masses along x and y sum to 1 and the torsional shares
    to the number of rigid floors (Σ_k J φ_k,rz² = J (M⁻¹)_rz,rz = 1 per floor about its
    mass centre) — identities of any eigensolution, to round-off."""
    b = dict(one_storey_eccentric(), storeys=3, mass=[2e5, 2e5, 1.5e5], model="frame",
             beam={"E": E, "b": 0.3, "h": 0.5}, mass_centre=[[3.0, 2.0], [3.5, 2.0], [3.0, 2.5]])
    modes = from_dict(scene(b)).extras["buildings"][0]["modes"]
    assert sum(md["mass_ratio_x"] for md in modes) == pytest.approx(1.0, rel=1e-10)
    assert sum(md["mass_ratio_y"] for md in modes) == pytest.approx(1.0, rel=1e-10)
    assert sum(md["torsional_share"] for md in modes) == pytest.approx(3.0, rel=1e-10)


def test_flexible_floors_are_the_planar_frame_with_joint_masses():
    """A single frame line along x with flexible floors: every joint keeps ux (and uy); under
    a motion along x it is the planar frame with mass_model = "joints" and the same joint
    masses, given joint by joint ([[frame]] per-joint masses)."""
    def rect(b, h):
        return {"E": E, "A": b * h, "I": b * h**3 / 12}
    an = {"type": "dynamic", "integrator": "newmark", "dt": 2e-3, "t_end": 1.0, "tol_residual": 1e-12}
    ground = {"ground_acceleration": {"type": "sine", "amplitude": 3.0, "omega": 9.0}}
    masses = [[1.25e4, 2.5e4, 1.25e4], [1.0e4, 2.0e4, 1.0e4]]
    planar = {"frame": [{"prefix": "P", "storeys": 2, "bays": 2, "storey_height": 3.0, "bay_width": 5.0,
                         "column": rect(0.3, 0.5), "beam": rect(0.3, 0.5), "mass": masses,
                         "mass_model": "joints"}], "loads": ground, "analysis": an}
    b3 = {"building": [building(storeys=2, model="frame", grid_x=[0.0, 5.0, 10.0], grid_y=[0.0],
                                column={"E": E, "b2": 0.5, "b3": 0.3}, beam={"E": E, "b": 0.3, "h": 0.5},
                                mass=[5e4, 4e4], diaphragm=False)], "loads": ground, "analysis": an}
    sp, sb = from_dict(planar), from_dict(b3)
    assert [n["mass"] for n in sp.nodes] == [m for row in masses for m in row]
    rp, (cp, hp) = run_full(sp)
    rb, (cb, hb) = run_full(sb)
    for f in (1, 2):
        for line in (0, 1, 2):
            up, ub = hp[:, cp.index(f"u:P{f}.{line}")], hb[:, cb.index(f"u:B{f}.{line}.0.ux")]
            assert np.abs(up - ub).max() < 1e-9 * np.abs(up).max()


def test_a_slab_panel_is_exact_in_constant_strain_and_pure_bending():
    """The flexible floor's slab panel (martello.building3d.membrane_stiffness) against the
    strain energy of elasticity written here: a uniform strain state, t A εᵀDε/2 (the patch
    test), and pure in-plane bending u = κxy, v = −κ(x² + νy²)/2 about the centre,
    E κ² t lx ly³/24 (Timoshenko & Goodier, Theory of Elasticity, §22) — exact for the
    incompatible-mode element on a rectangle, not for the bilinear one (which locks in
    bending). Rigid motions carry no force."""
    from martello.building3d import membrane_stiffness
    lx, ly, t, nu = 5.0, 4.5, 0.2, 0.2
    K = membrane_stiffness(lx, ly, t, E, nu)
    X, Y = np.array([0.0, lx, lx, 0.0]), np.array([0.0, 0.0, ly, ly])
    D = E / (1 - nu**2) * np.array([[1, nu, 0], [nu, 1, 0], [0, 0, (1 - nu) / 2]])
    eps = np.array([1e-4, -3e-5, 2e-5])
    u = np.ravel(np.column_stack([eps[0] * X + eps[2] / 2 * Y, eps[1] * Y + eps[2] / 2 * X]))
    assert u @ K @ u / 2 == pytest.approx(t * lx * ly * eps @ D @ eps / 2, rel=1e-12)
    x, y, k = X - lx / 2, Y - ly / 2, 1e-4
    u = np.ravel(np.column_stack([k * x * y, -k / 2 * (x**2 + nu * y**2)]))
    assert u @ K @ u / 2 == pytest.approx(E * k**2 * t * lx * ly**3 / 24, rel=1e-12)
    rigid = np.ravel(np.column_stack([1.0 - 0.3 * Y, 2.0 + 0.3 * X]))
    assert np.abs(K @ rigid).max() < 1e-12 * np.abs(K).max() * lx


def test_a_stiff_slab_makes_a_flexible_floor_rigid():
    """Flexible floors of a 2-storey frame building with a slab of growing E: the periods
    converge to those of the rigid-diaphragm building with the same mass and the rotational
    inertia of the lumped joint masses, the difference falling as 1/E_slab (identity of the
    method in the limit; without the slab the floors are held in plane by the beams alone).
    The columns' St Venant torsion and the beams' in-plane bending are made negligible: a
    rigid floor ties its joints' θz to rz, a membrane (no drilling DOF) leaves them free, so
    with them the torsional modes would converge to a limit of their own (4e-4, 1.6e-3 here)."""
    gx, gy = [0.0, 5.0, 10.0], [0.0, 4.5, 9.0]
    column = {"E": E, "A": 0.12, "I2": 0.4 * 0.3**3 / 12, "I3": 0.3 * 0.4**3 / 12, "J": 1e-12}
    beam = {"E": E, "A": 0.15, "I2": 1e-12, "I3": 0.3 * 0.5**3 / 12, "J": 2.6e-3}
    base = dict(storeys=2, model="frame", grid_x=gx, grid_y=gy, mass=[2e5, 1.5e5],
                column=column, beam=beam, mass_centre=[5.0, 4.5])
    tx = np.array([2.5, 5.0, 2.5]) / 10
    ty = np.array([2.25, 4.5, 2.25]) / 9
    r2 = sum(tx[i] * ty[j] * ((gx[i] - 5.0) ** 2 + (gy[j] - 4.5) ** 2) for i in range(3) for j in range(3))
    rigid = from_dict(scene(building(**base, inertia=[2e5 * r2, 1.5e5 * r2]))).extras["buildings"][0]["modes"]
    T_rigid = np.array([m["period"] for m in rigid])

    def periods(**kw):
        md = from_dict(scene(building(**base, diaphragm=False, **kw))).extras["buildings"][0]["modes"]
        return np.array([m["period"] for m in md[:6]])
    errs = [np.abs(periods(slab={"E": E * f, "thickness": 0.2}) / T_rigid - 1).max() for f in (1e2, 1e4)]
    assert errs[1] < 2e-7 and 50 < errs[0] / errs[1] < 200
    loose = np.abs(periods() / T_rigid - 1).max()
    real = np.abs(periods(slab={"E": E, "thickness": 0.2}) / T_rigid - 1).max()
    assert errs[0] < real < loose


def test_bad_buildings_are_refused_with_the_field():
    cases = [({"model": "solid"}, "building[0].model"),
             ({"grid_x": [0.0, 0.0]}, "building[0].grid_x"),
             ({"omit": ["7.7"]}, "building[0].omit[0]"),
             ({"beam": {"E": E, "b": 0.3, "h": 0.5}}, "building[0].beam"),
             ({"split": [{"name": "S", "line": "9.9", "storey": 1, "height": 1.0, "mass": 1.0}]},
              "building[0].split[0].line"),
             ({"column": {"E": E, "b2": 0.3}}, "building[0].column.b3"),
             ({"column": None, "member": []}, "building[0]"),
             ({"slab": {"E": E, "thickness": 0.2}}, "building[0].slab"),
             ({"diaphragm": False, "slab": {"E": E}}, "building[0].slab.thickness")]
    for change, where in cases:
        b = building(**{k: v for k, v in change.items() if v is not None})
        if change.get("column", 1) is None:
            b.pop("column")
        with pytest.raises(SceneError, match=where.replace("[", r"\[").replace("]", r"\]")):
            from_dict(scene(b))
    # a floor no member holds in torsion: one column, no torsion stiffness would be fine;
    # a mechanism is a floor of a single pinned column (no lateral stiffness)
    with pytest.raises(SceneError, match="positive definite|singular"):
        from_dict(scene(building(grid_x=[0.0], grid_y=[0.0], base="pinned", model="frame")))


def test_the_independent_engine_reads_frame_joint_masses():
    """[[frame]]'s per-joint masses reach the independent engine's model as given (its own
    reading of the scene, martello.independent)."""
    from martello.independent.scene import load_model
    masses = [[1.25e4, 2.5e4, 1.25e4], [1.0e4, 2.0e4, 1.0e4]]
    d = {"frame": [{"prefix": "P", "storeys": 2, "bays": 2, "storey_height": 3.0, "bay_width": 5.0,
                    "column": {"E": E, "A": 0.15, "I": 3e-3}, "beam": {"E": E, "A": 0.15, "I": 3e-3},
                    "mass": masses, "mass_model": "joints"}],
         "analysis": {"type": "dynamic", "integrator": "newmark", "dt": 1e-3, "t_end": 0.1}}
    model = load_model(d)
    assert list(model.mass) == [m for row in masses for m in row]
