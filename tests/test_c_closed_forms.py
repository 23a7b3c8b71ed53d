"""The library's closed forms (martello_closed_form, fortran/closed_forms.f90; docs/c-api.md
"Closed forms") against the Python oracles of martello/oracles/ (a separate implementation
of the formulas of docs/problems.md) and, for P2's first impact, against an event-located
rk8pd run of the P2 scene (a numerical integration: independent of either formula)."""

import math

import pytest

import martello
from martello.binding import native
from martello.errors import SolverError
from martello.oracles.p1_p3_static import mass_on_plane_static
from martello.oracles.p5_contact_laws import hertz_impact, linear_contact_time, newton_impact

# the same formula evaluated in another order: a few roundings
RT = 1e-13


@pytest.mark.parametrize("m,k,h,g,eps", [(1.0, 100.0, 0.05, 9.81, 1e6),    # the plane reached
                                         (1.0, 100.0, 0.2, 9.81, 1e6)])    # free: mg/k < h
def test_p1_static_matches_the_oracle(m, k, h, g, eps):
    for scheme, par in (("lagrange", [m, k, h, g]), ("penalty", [m, k, h, g, eps])):
        got = native.closed_form(f"p1_static_{scheme}", par)
        want = mass_on_plane_static(m, k, h, g, scheme=scheme, eps=eps if scheme == "penalty" else None)
        assert got[0] == pytest.approx(want.u, rel=RT)
        assert got[1] == pytest.approx(want.lam, rel=RT, abs=1e-300)
        assert got[2] == pytest.approx(-want.lam, rel=RT, abs=1e-300)


@pytest.mark.parametrize("m1,m2,v1,v2,e", [(1.0, 2.0, 1.0, 0.0, 0.5), (1e-6, 1e6, 3.0, -1.0, 1.0),
                                           (2.0, 2.0, 1.0, 1.0, 0.0)])
def test_p5_newton_matches_the_oracle(m1, m2, v1, v2, e):
    got = native.closed_form("p5_newton", [m1, m2, v1, v2, e])
    want = newton_impact(m1, m2, v1, v2, e)
    assert got == pytest.approx([want.v1, want.v2, want.energy_lost], rel=RT, abs=1e-15)


def test_p5_linear_and_hertz_match_the_oracles():
    ms = 1.0 * 3.0 / 4.0
    lin = native.closed_form("p5_linear", [1.0, 3.0, 1e4, 2.0])
    assert lin[1] == pytest.approx(linear_contact_time(ms, 1e4), rel=RT)
    assert lin[0] == pytest.approx(2.0 * math.sqrt(ms / 1e4), rel=RT)
    hz = native.closed_form("p5_hertz", [1.0, 3.0, 1e9, 2.0])
    want = hertz_impact(ms, 1e9, 2.0)
    assert hz == pytest.approx([want.delta_max, want.t_c, want.force_max], rel=1e-12)


def test_p2_first_impact_matches_an_event_located_run():
    """P2 (m = 1, k = 100, h = 0.05, g = 9.81) on rk8pd with a restitution plane: the located
    impact time and approach speed agree with the closed form to the tolerance of the
    integration (rtol 1e-12; event location 1e-12 s): 1e-9."""
    t_i, v_i = native.closed_form("p2_first_impact", [1.0, 100.0, 0.05, 9.81])
    d = {"node": [{"name": "m", "mass": 1.0}],
         "link": [{"type": "spring", "a": "m", "b": "ground", "k": 100.0}],
         "contact": [{"name": "plane", "a": "m", "b": "ground", "gap": 0.05,
                      "scheme": "restitution", "restitution": 0.8}],
         "loads": {"gravity": 9.81},
         "analysis": {"type": "dynamic", "integrator": "rk8pd", "dt": 1e-3, "t_end": 0.2,
                      "rtol": 1e-12, "atol": 1e-15}}
    c = martello.run(d).summary["contacts"]["plane"]
    assert c["impact_times"][0] == pytest.approx(t_i, rel=1e-9)
    assert c["approach_speeds"][0] == pytest.approx(v_i, rel=1e-9)


@pytest.mark.parametrize("name,par", [("no_such_form", [1.0]), ("p5_newton", [1.0, 2.0]),
                                      ("p5_newton", [1.0, 2.0, 1.0, 0.0, 1.5]),
                                      ("p2_first_impact", [1.0, 100.0, 1.0, 9.81])])
def test_unknown_forms_and_bad_parameters_are_refused(name, par):
    with pytest.raises(SolverError, match="MARTELLO_ERR_ARGUMENT"):
        native.closed_form(name, par)
