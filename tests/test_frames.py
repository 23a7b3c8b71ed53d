"""Planar frames ([[frame]], docs/problems.md P10): the condensed lateral stiffness block and
the member-force recovery, against oracles written here independently of martello.frame2d
(closed forms of portal frames and cantilevers, the shear-building limit, a plain
direct-stiffness solve in numpy, the uncondensed generalized eigenproblem in scipy), and the
block in the native library under every integrator."""

import math

import numpy as np
import pytest
import scipy.linalg

from martello.binding import native
from martello.errors import SceneError, SolverError
from martello.run import run_full
from martello.scene.loader import from_dict

E = 2.5e10


def frame_scene(storeys=1, bays=1, h=3.0, L=5.0, col=(0.16, 2.1e-3), beam=(0.12, 1.6e-3),
                mass=5e4, analysis=None, **extra):
    fr = {"prefix": "F", "storeys": storeys, "bays": bays, "storey_height": h, "bay_width": L,
          "column": {"E": E, "A": col[0], "I": col[1]}, "beam": {"E": E, "A": beam[0], "I": beam[1]},
          "mass": mass}
    fr.update(extra)
    return {"frame": [fr], "analysis": analysis or {"type": "static"}}


def static(d, forces):
    d = dict(d, loads={"force": [{"node": n, "value": v} for n, v in forces.items()]})
    return run_full(from_dict(d))[0]


# --- an independent direct-stiffness frame (test-only code) --------------------------------

def direct_stiffness(storeys, bays, h, L, col, beam, base="fixed"):
    """K of the whole frame on every free DOF (x, y, θ per joint), written out here from the
    textbook element matrix; returns K and the DOF index of (line, level, component)."""
    index, n = {}, 0
    for j in range(storeys + 1):
        for i in range(bays + 1):
            for c in range(3):
                restrained = j == 0 and (base == "fixed" or c < 2)
                if not restrained:
                    index[(i, j, c)] = n
                    n += 1
    K = np.zeros((n, n))

    def add(e1, e2, A, I, length, vertical):
        ea, ei = E * A / length, E * I / length
        kl = np.array([[ea, 0, 0, -ea, 0, 0],
                       [0, 12 * ei / length**2, 6 * ei / length, 0, -12 * ei / length**2, 6 * ei / length],
                       [0, 6 * ei / length, 4 * ei, 0, -6 * ei / length, 2 * ei],
                       [-ea, 0, 0, ea, 0, 0],
                       [0, -12 * ei / length**2, -6 * ei / length, 0, 12 * ei / length**2, -6 * ei / length],
                       [0, 6 * ei / length, 2 * ei, 0, -6 * ei / length, 4 * ei]])
        c, s = (0.0, 1.0) if vertical else (1.0, 0.0)
        r = np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]])
        T = scipy.linalg.block_diag(r, r)
        kg = T.T @ kl @ T
        dofs = [index.get((*e1, k), -1) for k in range(3)] + [index.get((*e2, k), -1) for k in range(3)]
        for p, a in enumerate(dofs):
            for q, b in enumerate(dofs):
                if a >= 0 and b >= 0:
                    K[a, b] += kg[p, q]
        return kl, T, dofs
    elements = []
    for j in range(storeys):
        for i in range(bays + 1):
            elements.append(("C", add((i, j), (i, j + 1), *col, h, True)))
    for j in range(1, storeys + 1):
        for i in range(bays):
            elements.append(("B", add((i, j), (i + 1, j), *beam, L, False)))
    return K, index, elements


# --- closed forms --------------------------------------------------------------------------

def test_portal_frame_lateral_stiffness_is_the_slope_deflection_closed_form():
    """Fixed-base single-bay portal with an axially rigid beam (diaphragm): slope-deflection
    with sway gives k = (24 EI_c/h³)(a + 6b)/(4a + 6b), a = I_c/h, b = I_b/L (Chopra,
    Dynamics of Structures, Example 1.1, there with ρ = b/(4a)). The closed form neglects the
    columns' axial strain; A is chosen so that I/(A h²) = 1e-9, whose effect on k is of that
    order, and the condensation loses about log10(EA h²/EI) = 9 of 16 digits: rtol 1e-6."""
    h, L, Ic, Ib = 3.0, 5.0, 2.1e-3, 1.6e-3
    Ac = Ic / (1e-9 * h**2)
    P = 1.0e5
    s = static(frame_scene(col=(Ac, Ic), beam=(0.12, Ib), h=h, L=L), {"F1": P})
    a, b = Ic / h, Ib / L
    k = 24 * E * Ic / h**3 * (a + 6 * b) / (4 * a + 6 * b)
    assert s["nodes"]["F1"]["u"] == pytest.approx(P / k, rel=1e-6)
    # by antisymmetry each column carries P/2, so its end moments (counterclockwise on the
    # member) sum to P h/2; the joints turn clockwise by θ = −6aΔ/(h(4a + 6b)) and the top
    # moment is E a (6Δ/h + 4θ)
    m = s["frames"]["F"]["members"]["C1.0"]
    assert m["M_i"] + m["M_j"] == pytest.approx(P / 2 * h, rel=1e-6)
    delta = P / k
    theta = -6 * a * delta / (h * (4 * a + 6 * b))
    assert m["M_j"] == pytest.approx(E * a * (6 * delta / h + 4 * theta), rel=1e-6)


def test_cantilever_columns_have_3EI_over_h3_and_the_base_moment_P_h():
    """A one-bay frame whose beam is 1e-12 as stiff as the columns (joint masses, so it
    carries no axial force either): two independent cantilevers, k = 3EI/h³ each, the base
    moment P h (counterclockwise on the member's lower end, the direct-stiffness sign) and no
    top moment. The beam's residue is of relative order 1e-12 of the column stiffness."""
    h, I = 3.0, 2.1e-3
    P = 1.0e4
    s = static(frame_scene(h=h, col=(0.16, I), beam=(0.12e-12, 1.6e-15), mass_model="joints"),
               {"F1.0": P})
    k = 3 * E * I / h**3
    # the column's axial strain does not move its top sideways: exact for the closed form
    assert s["nodes"]["F1.0"]["u"] == pytest.approx(P / k, rel=1e-9)
    assert abs(s["nodes"]["F1.1"]["u"]) < 1e-9 * P / k
    m = s["frames"]["F"]["members"]["C1.0"]
    assert m["M_i"] == pytest.approx(P * h, rel=1e-9)
    assert abs(m["M_j"]) < 1e-9 * P * h
    assert s["frames"]["F"]["shear"][0] == pytest.approx(P, rel=1e-9)


def test_rigid_beams_give_the_shear_building():
    """Beams 1e8 times stiffer than the columns (diaphragm): every column is clamped at both
    ends, k_s = Σ 12 EI_c/h³ per storey, and the lateral stiffness is the shear building's
    tridiagonal matrix. The finite beam stiffness leaves a relative error of order
    (I_c/h)/(I_b/L) = 1e-8 plus the columns' axial strain (A large: 1e-9): rtol 1e-6."""
    storeys, bays, h, L, Ic = 4, 2, 3.2, 4.5, 2.1e-3
    Ac = Ic / (1e-9 * h**2)
    d = frame_scene(storeys=storeys, bays=bays, h=h, L=L, col=(Ac, Ic), beam=(Ac, Ic * 1e8 * L / h))
    sc = from_dict(d)
    K = sc.blocks[0]["k"]
    ks = (bays + 1) * 12 * E * Ic / h**3
    shear = np.diag([2 * ks] * (storeys - 1) + [ks]) - ks * (np.eye(storeys, k=1) + np.eye(storeys, k=-1))
    assert np.allclose(K, shear, rtol=0, atol=1e-6 * ks)
    # and the library solves with it: a top load P moves floor s by P·s/k_s
    P = 1e5
    s = static(d, {f"F{storeys}": P})
    for j in range(1, storeys + 1):
        assert s["nodes"][f"F{j}"]["u"] == pytest.approx(P * j / ks, rel=1e-6)


def test_multistorey_static_response_is_the_direct_stiffness_solve():
    """A 3-storey, 2-bay frame with joint masses (every joint its own lateral DOF) under
    lateral loads at every joint: the displacements and every member's end moments equal a
    direct-stiffness solve of the uncondensed frame written in this test (numpy). Both are
    exact; they differ by round-off of systems of condition about 1e4: rtol 1e-9."""
    storeys, bays, h, L = 3, 2, 3.0, 5.0
    col, beam = (0.16, 2.1e-3), (0.12, 1.6e-3)
    loads = {(1, 0): 3e4, (1, 2): -1e4, (2, 1): 5e4, (3, 0): 8e4, (3, 2): 2e4}
    d = frame_scene(storeys=storeys, bays=bays, h=h, L=L, col=col, beam=beam, mass_model="joints")
    s = static(d, {f"F{j}.{i}": p for (j, i), p in loads.items()})
    K, index, elements = direct_stiffness(storeys, bays, h, L, col, beam)
    f = np.zeros(len(K))
    for (j, i), p in loads.items():
        f[index[(i, j, 0)]] = p
    u = np.linalg.solve(K, f)
    scale = np.abs(u).max()
    for j in range(1, storeys + 1):
        for i in range(bays + 1):
            assert s["nodes"][f"F{j}.{i}"]["u"] == pytest.approx(u[index[(i, j, 0)]], abs=1e-9 * scale)
    # member end moments: k_local T u_e of the test's own elements, in the generator's order
    # (columns storey by storey, left to right; then beams floor by floor)
    names = [f"C{j + 1}.{i}" for j in range(storeys) for i in range(bays + 1)] + \
            [f"B{j}.{i + 1}" for j in range(1, storeys + 1) for i in range(bays)]
    mscale = 0.0
    expected = {}
    for name, (_, (kl, T, dofs)) in zip(names, elements):
        ue = np.array([u[q] if q >= 0 else 0.0 for q in dofs])
        fe = kl @ T @ ue
        expected[name] = fe
        mscale = max(mscale, abs(fe[2]), abs(fe[5]))
    for name, fe in expected.items():
        m = s["frames"]["F"]["members"][name]
        assert m["M_i"] == pytest.approx(fe[2], abs=1e-9 * mscale), name
        assert m["M_j"] == pytest.approx(fe[5], abs=1e-9 * mscale), name
        assert m["V_i"] == pytest.approx(fe[1], abs=1e-9 * mscale / h), name


@pytest.mark.parametrize("mass_model", ["diaphragm", "joints"])
def test_highest_frequency_is_the_uncondensed_generalized_eigenproblem(mass_model):
    """The library's ω_max (LAPACK dsbgvx on the condensed block, the stability summary) and
    the condensed modes equal the finite eigenvalues of the uncondensed K φ = ω² M φ solved by
    scipy with the vertical and rotational DOFs massless (their eigenvalues are infinite).
    A diaphragm is the uncondensed frame with its floor's x DOFs tied: the test ties them by
    a transformation. Both eigen-solvers are backward stable: rtol 1e-9."""
    storeys, bays, h, L, m = 3, 2, 3.0, 5.0, 4e4
    col, beam = (0.16, 2.1e-3), (0.12, 1.6e-3)
    K, index, _ = direct_stiffness(storeys, bays, h, L, col, beam)
    n = len(K)
    M = np.zeros(n)
    w = np.array([L / 2] + [L] * (bays - 1) + [L / 2]) / (bays * L)
    for j in range(1, storeys + 1):
        for i in range(bays + 1):
            M[index[(i, j, 0)]] = m * w[i]
    if mass_model == "diaphragm":
        # tie: x of every joint at floor j = U_j (a column of A per floor, identity elsewhere)
        keep = [q for q in range(n) if not any(q == index[(i, j, 0)] for j in range(1, storeys + 1)
                                               for i in range(bays + 1))]
        A = np.zeros((n, storeys + len(keep)))
        for j in range(1, storeys + 1):
            for i in range(bays + 1):
                A[index[(i, j, 0)], j - 1] = 1.0
        for c, q in enumerate(keep):
            A[q, storeys + c] = 1.0
        K, Mm = A.T @ K @ A, A.T @ np.diag(M) @ A
    else:
        Mm = np.diag(M)
    lam = scipy.linalg.eigvals(K, Mm)
    lam = np.sort(lam[np.isfinite(lam)].real)
    expected = np.sqrt(lam)
    d = frame_scene(storeys=storeys, bays=bays, h=h, L=L, col=col, beam=beam, mass=m,
                    mass_model=mass_model,
                    analysis={"type": "dynamic", "integrator": "central-difference", "dt": 1e-5,
                              "t_end": 1e-4})
    s = run_full(from_dict(d))[0]
    assert s["stability"]["omega_max"] == pytest.approx(expected[-1], rel=1e-9)
    sc = from_dict(d)
    from martello.frame2d import natural_frequencies
    got = natural_frequencies(sc.blocks[0]["k"], [nd["mass"] for nd in sc.nodes])
    assert got == pytest.approx(expected, rel=1e-9)


# --- the block under the integrators -------------------------------------------------------

@pytest.mark.parametrize("integrator,dt,rtol", [
    # average acceleration: period error (ωh)²/12 = 1.6e-5 at ωh = 0.0138 → phase ~3e-4 at
    # t_end; the adaptive ones at rtol 1e-10
    ("newmark", 2e-4, 2e-3), ("central-difference", 2e-4, 2e-3), ("ida", 1e-3, 1e-5),
    ("rk8pd", 1e-3, 1e-5), ("moreau-jean", 2e-4, 2e-3)])
def test_free_vibration_of_a_portal_is_the_closed_form_under_every_integrator(integrator, dt, rtol):
    """An undamped one-storey portal released from u0: u(t) = u0 cos ωt with ω² = k/m, k the
    slope-deflection closed form (axially stiff columns, as in the static test). Tolerances
    from each integrator's error at its step (comment of the parameters)."""
    h, L, Ic, Ib, m = 3.0, 5.0, 2.1e-3, 1.6e-3, 5e4
    Ac = Ic / (1e-9 * h**2)
    a, b = Ic / h, Ib / L
    k = 24 * E * Ic / h**3 * (a + 6 * b) / (4 * a + 6 * b)
    omega = math.sqrt(k / m)
    an = {"type": "dynamic", "integrator": integrator, "dt": dt, "t_end": 0.3}
    if integrator in ("ida", "rk8pd"):
        an.update(rtol=1e-10, atol=1e-14)
    d = frame_scene(col=(Ac, Ic), beam=(0.12, Ib), mass=m, analysis=an)
    sc = from_dict(d)
    sc.nodes[0]["u0"] = 0.01
    s, (cols, hist) = run_full(sc)
    t, u = hist[:, cols.index("t")], hist[:, cols.index("u:F1")]
    assert np.max(np.abs(u - 0.01 * np.cos(omega * t))) < rtol * 0.01
    # the block's energy is in the balance: an undamped run conserves it
    assert s["energy"]["balance_relative"] < 1e-6


def test_rayleigh_damping_of_the_block_decays_the_first_mode_at_zeta():
    """zeta = 0.05 at modes 1 and 2: a one-storey frame (one mode, a0 = ζω, a1 = ζ/ω) decays
    as exp(−ζωt) exactly; the logarithmic decrement over 4 periods of an adaptive run at rtol
    1e-10 equals 2π ζ/√(1−ζ²) per period to 1e-5."""
    zeta = 0.05
    d = frame_scene(zeta=zeta, analysis={"type": "dynamic", "integrator": "rk8pd", "dt": 1e-4,
                                         "t_end": 1.0, "rtol": 1e-10, "atol": 1e-14})
    sc = from_dict(d)
    sc.nodes[0]["u0"] = 0.01
    s, (cols, hist) = run_full(sc)
    t, u = hist[:, cols.index("t")], hist[:, cols.index("u:F1")]
    k, m = sc.blocks[0]["k"][0, 0], sc.nodes[0]["mass"]
    wn = math.sqrt(k / m)
    wd = wn * math.sqrt(1 - zeta**2)
    exact = 0.01 * np.exp(-zeta * wn * t) * (np.cos(wd * t) + zeta / math.sqrt(1 - zeta**2) * np.sin(wd * t))
    assert np.max(np.abs(u - exact)) < 1e-5 * 0.01
    assert s["energy"]["balance_relative"] < 1e-6


def test_member_peaks_are_signed_and_located():
    """The summary's peaks of a member force are the extremes of the recovered history, with
    their times, or located inside a step next to them (docs/results.md, "Frames and
    buildings": the cubic Hermite of (q, q̇), which can only raise them, by at most the
    step's sampling error (ω h)²/8 of the peak, ω = 12 rad/s the load's); histories = true
    appends the member histories to the run's history."""
    d = frame_scene(storeys=2, bays=2, zeta=0.05, histories=True,
                    analysis={"type": "dynamic", "integrator": "newmark", "dt": 1e-3, "t_end": 1.0})
    d["loads"] = {"ground_acceleration": {"type": "sine", "amplitude": 2.0, "omega": 12.0}}
    s, (cols, hist) = run_full(from_dict(d))
    m = s["frames"]["F"]["members"]["C1.0"]["M_i"]
    x = hist[:, cols.index("M_i:F.C1.0")]
    t = hist[:, cols.index("t")]
    assert m["min"] < 0 < m["max"]
    sampling = (12.0 * 1e-3) ** 2 / 8 * np.abs(x).max()
    assert x.max() <= m["max"] <= x.max() + sampling
    assert x.min() - sampling <= m["min"] <= x.min()
    assert abs(t[np.argmax(x)] - m["t_max"]) <= 1e-3 and abs(t[np.argmin(x)] - m["t_min"]) <= 1e-3


def test_bad_blocks_and_frames_are_refused_with_the_field():
    with native.Model(2, 0, 0, 0) as mdl:
        mdl.set_node(0, 1.0); mdl.set_node(1, 1.0)
        with pytest.raises(SolverError, match="symmetric"):
            mdl.add_stiffness_block([0, 1], np.array([[2.0, -1.0], [-1.1, 2.0]]))
        with pytest.raises(SolverError, match="ground"):
            mdl.add_stiffness_block([0, -1], np.eye(2))
    with pytest.raises(SceneError, match=r"frame\[0\]\.column"):
        from_dict(dict(frame_scene(storeys=2), frame=[dict(frame_scene(storeys=2)["frame"][0],
                                                            column=[{"E": 1.0, "A": 1.0, "I": 1.0}])]))
    with pytest.raises(SceneError, match=r"frame\[0\]\.base"):
        from_dict(frame_scene(base="hinged"))


def test_interface_link_helpers_follow_the_seed_rules():
    """The seed's gap stiffness rules (after Muthukumar & DesRoches 2006), by hand: aligned
    floors, the axial stiffness EA/L of the two connected beams (harmonic mean = their common
    value when equal; series and sum readings); offset floors, 1.5–2 × 12EI/h³ of the struck
    column; out-of-range factors refused."""
    from martello.frame2d import PlanarFrame, gap_stiffness_aligned, gap_stiffness_offset
    a = PlanarFrame([3.0], [4.0, 5.0], [[(E, 0.1, 1e-3)] * 3], [[(E, 0.2, 1e-3), (E, 0.15, 1e-3)]], [1.0])
    b = PlanarFrame([3.0, 3.0], [6.0], [[(E, 0.1, 1e-3)] * 2, [(E, 0.1, 2e-3)] * 2],
                    [[(E, 0.3, 1e-3)], [(E, 0.3, 1e-3)]], [1.0, 1.0])
    ka, kb = E * 0.15 / 5.0, E * 0.3 / 6.0          # a's last bay, b's first bay at floor 1
    assert gap_stiffness_aligned(a, b, 1) == pytest.approx(2 / (1 / ka + 1 / kb), rel=1e-15)
    assert gap_stiffness_aligned(a, b, 1, "series") == pytest.approx(1 / (1 / ka + 1 / kb), rel=1e-15)
    assert gap_stiffness_aligned(a, b, 1, "sum") == pytest.approx(ka + kb, rel=1e-15)
    assert gap_stiffness_aligned(b, b, 2) == pytest.approx(E * 0.3 / 6.0, rel=1e-15)
    assert gap_stiffness_offset(b, 2, 1, 1.5) == pytest.approx(1.5 * 12 * E * 2e-3 / 27.0, rel=1e-15)
    with pytest.raises(ValueError, match="factor"):
        gap_stiffness_offset(b, 2, 1, 3.0)


def test_the_p10_catalogue_scenes_are_what_the_case_study_writes():
    """benchmarks/p10/p10_*.toml are written by case_study.py --write-scenes from its model
    block; a hand edit (or a stale file after a model change) is caught here."""
    import importlib.util
    from pathlib import Path
    here = Path(__file__).resolve().parent.parent / "benchmarks" / "p10"
    spec = importlib.util.spec_from_file_location("p10_case_study", here / "case_study.py")
    cs = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(cs)
    for config in cs.CONFIGS:
        path = here / f"p10_{config}.toml"
        assert path.read_text() == cs.render_scene(config), path
        sc = cs.scene_for(config, 1)
        assert len(sc.blocks) == 2 and len(sc.contacts) == 2


def test_modal_damping_decays_every_mode_at_zeta():
    """damping = "modal": a 2-storey frame released in its second mode (the mode from scipy's
    generalized eigensolver on the block, independent of martello.frame2d) stays in it and
    decays as exp(−ζω₂t) with the damped frequency, the closed form of one damped mode; rk8pd
    at rtol 1e-10: 1e-6 of the amplitude."""
    zeta = 0.05
    d = frame_scene(storeys=2, zeta=zeta, damping="modal",
                    analysis={"type": "dynamic", "integrator": "rk8pd", "dt": 1e-4, "t_end": 0.5,
                              "rtol": 1e-10, "atol": 1e-14})
    sc = from_dict(d)
    K = sc.blocks[0]["k"]
    M = np.diag([n["mass"] for n in sc.nodes])
    lam, phi = scipy.linalg.eigh(K, M)
    w2, shape = math.sqrt(lam[1]), phi[:, 1] / np.abs(phi[:, 1]).max() * 0.01
    for i, n in enumerate(sc.nodes):
        n["u0"] = float(shape[i])
    s, (cols, hist) = run_full(sc)
    t = hist[:, cols.index("t")]
    wd = w2 * math.sqrt(1 - zeta**2)
    g = np.exp(-zeta * w2 * t) * (np.cos(wd * t) + zeta / math.sqrt(1 - zeta**2) * np.sin(wd * t))
    for i, n in enumerate(sc.nodes):
        assert np.max(np.abs(hist[:, cols.index(f"u:{n['name']}")] - shape[i] * g)) < 1e-6 * 0.01
