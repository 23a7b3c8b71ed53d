"""Static contact (docs/problems.md P1, P3): every scheme against the closed forms, the penalty
convergence rate, mesh refinement, and the extremes (ε/k to 1e16, grazing, h = 0)."""

import copy
import json

import numpy as np
import pytest

from martello.errors import SolverError
from martello.oracles.p1_p3_static import mass_on_plane_static, two_bars_static
from martello.run import run
from martello.scene.loader import from_dict
from tests.conftest import p1_dict

M, K, H, G = 1.0, 100.0, 0.05, 9.81
R, D, F = 2.1e7, 1.0e-3, 5.0e4


def p1(scheme="lagrange", h=H, **contact):
    d = p1_dict(scheme, **contact)
    d["contact"][0]["gap"] = h
    return run(from_dict(d))


def two_bars(scheme, ne=1, F=F, **contact):
    """P3 with every segment (two in the left bar, one in the right) cut into ne elements."""
    n_left = 2 * ne + 1
    nodes = [{"name": f"L{i}", "mass": 1.0, "fixed": i == 0} for i in range(n_left)]
    nodes += [{"name": f"R{i}", "mass": 1.0, "fixed": i == ne} for i in range(ne + 1)]
    links = [{"type": "bar", "a": f"L{i}", "b": f"L{i + 1}", "EA": R, "L": 1.0 / ne}
             for i in range(2 * ne)]
    links += [{"type": "bar", "a": f"R{i}", "b": f"R{i + 1}", "EA": R, "L": 1.0 / ne}
              for i in range(ne)]
    c = {"name": "ends", "a": f"L{2 * ne}", "b": "R0", "gap": D, "scheme": scheme}
    c.update(contact)
    d = {"node": nodes, "link": links, "contact": [c],
         "loads": {"force": [{"node": f"L{ne}", "value": F}]}, "analysis": {"type": "static"}}
    s = run(from_dict(d))
    u = s["nodes"]
    return np.array([u[f"L{ne}"]["u"], u[f"L{2 * ne}"]["u"], u["R0"]["u"],
                     s["contacts"]["ends"]["force"]]), s


# Lagrange and augmented Lagrange: ≤ 1e-12 relative (the bar set for P1 and P3). The solves are
# 2×2 (P1) and 4×4 (P3) with condition ≲ 10 after scaling: errors are a few ulps, far inside
# 1e-12.
@pytest.mark.parametrize("scheme,extra", [("lagrange", {}), ("augmented-lagrange", {"stiffness": 1e4}),
                                          ("restitution", {"restitution": 0.5})])
def test_p1_lagrange_family_matches_closed_form(scheme, extra):
    ref = mass_on_plane_static(M, K, H, G, scheme="lagrange")
    s = p1(scheme, **extra)
    assert s["nodes"]["mass"]["u"] == pytest.approx(ref.u, rel=1e-12, abs=0)
    assert s["contacts"]["plane"]["lambda"] == pytest.approx(ref.lam, rel=1e-12, abs=0)
    assert s["contacts"]["plane"]["lambda"] == pytest.approx(K * H - M * G, rel=1e-12)  # seed sign
    assert s["contacts"]["plane"]["active"]


def test_p1_penalty_matches_its_closed_form():
    ref = mass_on_plane_static(M, K, H, G, scheme="penalty", eps=1e4)
    s = p1("penalty", stiffness=1e4)
    assert s["nodes"]["mass"]["u"] == pytest.approx(0.0504762376237623762, rel=1e-13)  # problems.md digits
    assert s["nodes"]["mass"]["u"] == pytest.approx(ref.u, rel=1e-13)
    # λ = −εδ: δ = u − h cancels log10(h/δ) ≈ 2 digits of u, so 1e-11 rather than 1e-13
    assert s["contacts"]["plane"]["lambda"] == pytest.approx(ref.lam, rel=1e-11)


@pytest.mark.parametrize("scheme,extra,rtol", [
    ("lagrange", {}, 1e-12), ("augmented-lagrange", {"stiffness": 100 * R}, 1e-12),
    # penalty: P = εδ with δ/d ≈ 1e-2 → two digits cancel
    ("penalty", {"stiffness": 100 * R}, 1e-10)])
def test_p3_matches_closed_form(scheme, extra, rtol):
    ref = two_bars_static(F, R, D, scheme="penalty" if scheme == "penalty" else "lagrange",
                          eps=extra.get("stiffness"))
    got, _ = two_bars(scheme, **extra)
    want = np.array([ref.u1, ref.u2, ref.u3, ref.P])
    np.testing.assert_allclose(got, want, rtol=rtol, atol=0)


@pytest.mark.parametrize("scheme,extra", [("lagrange", {}), ("penalty", {"stiffness": 100 * R}),
                                          ("augmented-lagrange", {"stiffness": 100 * R})])
def test_p3_refinement_leaves_coarse_nodes_unchanged(scheme, extra):
    # Linear FE is nodally exact for point loads: any refinement gives the same nodal values.
    # Dense solves up to 195 unknowns with condition ~1e4·(ne)²: 1e-12 is the bar set for P3.
    coarse, _ = two_bars(scheme, 1, **extra)
    for ne in (2, 8, 64):
        fine, _ = two_bars(scheme, ne, **extra)
        np.testing.assert_allclose(fine, coarse, rtol=1e-12, atol=0, err_msg=f"ne = {ne}")


def test_p3_in_contact_stiffness_is_three_r():
    # Seed: in contact the F–u2 stiffness is 3r. Two loads in contact: ΔF/Δu2 = 3r.
    (a, _), (b, _) = two_bars("lagrange", F=4e4), two_bars("lagrange", F=6e4)
    assert (6e4 - 4e4) / (b[1] - a[1]) == pytest.approx(3 * R, rel=1e-10)


def log_slope(x, y):
    return np.polyfit(np.log10(x), np.log10(y), 1)[0]


def test_p1_penalty_error_is_first_order_in_one_over_eps():
    lam_exact = K * H - M * G
    ratios = 10.0 ** np.arange(2, 9)
    err = np.array([abs(p1("penalty", stiffness=K * q)["contacts"]["plane"]["lambda"] - lam_exact)
                    / abs(lam_exact) for q in ratios])
    # predicted relative error k/(k+ε) (docs/problems.md P1); δ keeps ≥ 6 digits at ε/k = 1e8
    np.testing.assert_allclose(err, 1.0 / (1.0 + ratios), rtol=1e-3)
    assert log_slope(ratios, err) == pytest.approx(-1.0, abs=0.02)


def test_p3_penalty_error_is_first_order_in_one_over_eps():
    p_exact = (F - R * D) / 3
    ratios = 10.0 ** np.arange(2, 9)
    err = np.array([abs(two_bars("penalty", stiffness=R * q)[0][3] - p_exact) / p_exact
                    for q in ratios])
    np.testing.assert_allclose(err, 1.0 / (1.0 + 3 * ratios), rtol=1e-3)   # docs/problems.md P3
    assert log_slope(ratios, err) == pytest.approx(-1.0, abs=0.02)


@pytest.mark.parametrize("ratio", [1e10, 1e12, 1e14, 1e16])
def test_extreme_penalty_finishes_and_reports_lost_digits(ratio):
    s = p1("penalty", stiffness=K * ratio)
    json.dumps(s, allow_nan=False)          # nothing NaN or inf in the summary
    assert np.isfinite(s["nodes"]["mass"]["u"]) and np.isfinite(s["contacts"]["plane"]["force"])
    lost = s["conditioning"]["digits_lost"]
    # δ = (mg − kh)/(k + ε) against u ≈ h: about log10(ε/k) + 2 digits cancel
    assert lost >= np.log10(ratio) - 1
    if lost > 8:
        assert s["status"] == "MARTELLO_ILL_CONDITIONED"
        assert "penalty" in s["warnings"][0] and "digits" in s["warnings"][0]
    if ratio == 1e16:
        assert s["status"] == "MARTELLO_ILL_CONDITIONED"


def test_extreme_penalty_on_p3_reports_lapack_condition():
    got, s = two_bars("penalty", stiffness=R * 1e16)
    c = s["conditioning"]
    assert c["penalised_stiffness_condition"] > 1e15     # dpocon on K + εBBᵀ sees ε/r
    assert c["condition_estimate"] < 1e3                 # the mixed system actually solved does not
    assert c["digits_lost"] > 15 and s["status"] == "MARTELLO_ILL_CONDITIONED"
    # ...so the force keeps its digits: P → the Lagrange value with relative error 1/(1+3ε/r)
    assert got[3] == pytest.approx((F - R * D) / 3, rel=1e-14)


@pytest.mark.parametrize("scheme,extra", [("lagrange", {}), ("penalty", {"stiffness": 1e4}),
                                          ("augmented-lagrange", {"stiffness": 1e4})])
def test_grazing_contact_settles(scheme, extra):
    # m g = k h exactly: the mass just touches; force 0 within round-off of m g.
    h = M * G / K
    s = p1(scheme, h=h, **extra)
    assert s["nodes"]["mass"]["u"] == pytest.approx(h, rel=1e-14)
    assert abs(s["contacts"]["plane"]["force"]) <= 1e-12 * M * G
    assert s["cost"]["active_set_iterations"] <= 4


def test_zero_gap_lagrange():
    s = p1("lagrange", h=0.0)
    assert s["nodes"]["mass"]["u"] == 0.0
    assert s["contacts"]["plane"]["force"] == pytest.approx(M * G, rel=1e-14)


def test_mass_held_only_by_contact():
    # No spring: without the contact K is singular; the solver must start from the active set.
    d = p1_dict("lagrange")
    d.pop("link")
    s = run(from_dict(d))
    assert s["nodes"]["mass"]["u"] == pytest.approx(H, rel=1e-15)
    assert s["contacts"]["plane"]["force"] == pytest.approx(M * G, rel=1e-14)


def test_unheld_mass_is_reported_singular():
    d = p1_dict("lagrange")
    d.pop("link")
    d["loads"]["gravity"] = -9.81        # pulled away from the plane: nothing holds it
    with pytest.raises(SolverError, match="not held"):
        run(from_dict(d))


def test_static_rejects_elastoplastic_spring_and_nonlinear_penalty():
    d = p1_dict("lagrange")
    d["link"][0].update(type="bilinear", fy=1.0)
    with pytest.raises(SolverError, match="elasto-plastic spring needs a dynamic analysis"):
        run(from_dict(d))
    d = p1_dict("penalty", law="hertz", stiffness=1e4)
    with pytest.raises(SolverError, match="static penalty supports law linear only"):
        run(from_dict(d))


def test_uzawa_iterations_are_reported_and_bounded():
    s = p1("augmented-lagrange", stiffness=1e4)
    # contraction k/(k+ε) ≈ 1e-2 per iteration: ~8 iterations to 1e-14
    assert 3 <= s["cost"]["uzawa_iterations"] <= 12
