"""SUNDIALS CVODE and ARKODE (docs/sundials-ode.md): a sample per kind of method.

Kind of evidence: verification against closed forms (P5's two-body impact: realised e,
contact time, peak penetration; the free oscillator's exact motion) for one method of each
kind — BDF and Adams (CVODE), explicit, diagonally implicit and ImEx tables (ARKODE); the full
sweeps (P2, P5, P7, P9) are catalogue scenes. The rest are identities of the method (the
Newton systems converge with the analytic band Jacobian; restarts are counted) and input
errors.

Tolerances. At rtol = 1e-10 every contact onset and separation is a root located to
event_tol = 1e-12 s and the integrator restarts there, so the realised e and the contact time
carry the global error of a smooth stretch, a small multiple of rtol (≤ 1e3·rtol over the
few hundred steps of a phase for BDF, whose global error grows fastest); 1e-7 leaves a factor
of 100 above that."""

import math

import pytest

from martello.checks.dispatchers import two_body_impact
from martello.errors import SceneError
from martello.run import run
from martello.scene.loader import from_dict
from tests.dynamics_helpers import dynamic, two_bodies

METHODS = [("cvode", None), ("cvode", "adams"), ("arkode", None), ("arkode", "verner-8-5-6"),
           ("arkode", "sdirk-5-3-4"), ("arkode", "ark548l2sa-8-4-5")]


def analysis(integrator, method=None, **extra):
    an = dynamic(integrator, dt=1e-4, t_end=0.005, rtol=1e-10, atol=1e-15, **extra)
    if method:
        an["method"] = method
    return an


@pytest.mark.parametrize("integrator,method", METHODS)
def test_two_body_kelvin_impact_against_the_closed_form(integrator, method):
    d = two_bodies("kelvin", 1e6, m1=1.0, m2=2.0, v0=1.0, gap=1e-3, restitution=0.5,
                   analysis=analysis(integrator, method))
    s = run(from_dict(d))
    exact = two_body_impact("kelvin", 1.0, 2.0, 1.0, 1e6, restitution=0.5)
    c = s["contacts"]["impact"]
    assert c["restitution"][0] == pytest.approx(exact["restitution"], rel=1e-7)
    assert c["contact_time"] == pytest.approx(exact["contact_time"], rel=1e-7)
    assert s["cost"]["events"] == 2          # one onset, one separation: two restarts
    implicit = integrator == "cvode" or method in ("sdirk-5-3-4", "ark548l2sa-8-4-5")
    # the implicit methods' Newton systems take the analytic Jacobian; the explicit ones none
    assert (s["cost"]["jacobian_evaluations"] > 0) == implicit


def test_linear_contact_peak_penetration_is_located():
    # the deepest point is a root of the gap rate: v0 sqrt(m*/k) to the integration tolerance
    for integrator in ("cvode", "arkode"):
        d = two_bodies("linear", 1e6, m1=1.0, m2=2.0, v0=1.0, gap=1e-3, analysis=analysis(integrator))
        s = run(from_dict(d))
        exact = two_body_impact("linear", 1.0, 2.0, 1.0, 1e6)
        assert s["contacts"]["impact"]["max_penetration"] == pytest.approx(exact["max_penetration"], rel=1e-7)


def test_a_chain_runs_on_the_band_with_few_newton_failures():
    # 40 oscillators with linear contacts between them: the band Jacobian of half-bandwidth 3;
    # a wrong entry would show as Newton failures (rejected steps) and as many Jacobians
    nodes = [{"name": f"n{i}", "mass": 1.0 + 0.01 * i, "v0": 0.2 if i == 0 else 0.0} for i in range(40)]
    links = [{"type": "spring", "a": f"n{i}", "b": "ground", "k": 100.0 + i} for i in range(40)]
    contacts = [{"name": f"c{i}", "a": f"n{i}", "b": f"n{i + 1}", "gap": 0.002, "scheme": "penalty",
                 "law": "linear", "stiffness": 1e5} for i in range(39)]
    d = {"node": nodes, "link": links, "contact": contacts,
         "analysis": dynamic("cvode", dt=0.01, t_end=0.5, rtol=1e-8, atol=1e-12)}
    s = run(from_dict(d))
    c = s["cost"]
    assert c["events"] >= 10
    assert c["rejected_steps"] <= 0.25 * c["steps"], c
    assert c["jacobian_evaluations"] <= 0.5 * c["steps"], c


def test_free_oscillator_against_its_exact_motion():
    # no contact: u = (v0/ω) sin ωt, its one maximum before t_end at π/(2ω), v0/ω, located
    # inside a step (the output interval 0.01 s does not hold it)
    for integrator, method in METHODS:
        an = dynamic(integrator, dt=0.01, t_end=0.3, rtol=1e-10, atol=1e-14)
        if method:
            an["method"] = method
        d = {"node": [{"name": "m", "mass": 1.0, "v0": 1.0}],
             "link": [{"type": "spring", "a": "m", "b": "ground", "k": 100.0}], "analysis": an}
        s = run(from_dict(d))
        assert s["nodes"]["m"]["u_max"] == pytest.approx(0.1, rel=1e-7), (integrator, method)
        assert s["nodes"]["m"]["t_peak"] == pytest.approx(math.pi / 20.0, rel=1e-6), (integrator, method)


def test_method_errors_name_the_field():
    d = two_bodies("linear", 1e6, analysis=analysis("cvode", "verner-8-5-6"))
    with pytest.raises(SceneError, match="analysis.method"):
        from_dict(d)
    d = two_bodies("linear", 1e6, analysis=analysis("ida", "bdf"))
    with pytest.raises(SceneError, match="analysis.method"):
        from_dict(d)
    d = two_bodies("linear", 1e6, analysis=analysis("arkode"))
    d["contact"][0].update(scheme="restitution", restitution=0.5)
    for key in ("law", "stiffness"):
        d["contact"][0].pop(key)
    with pytest.raises(SceneError, match="cannot run on integrator arkode"):
        from_dict(d)


def test_msbdf_on_a_large_scene_names_cvode():
    # msbdf's Jacobian is dense (2n x 2n by finite differences): a scene past 200 nodes says
    # so before it runs, naming cvode; one of 200 does not
    from martello.run import DENSE_NOTE_NODES, check_budget
    for n, noted in ((DENSE_NOTE_NODES, False), (DENSE_NOTE_NODES + 1, True)):
        d = {"chain": [{"prefix": "b", "n": n, "mass": 1.0, "k": 100.0, "gap": 0.01,
                        "contact": {"scheme": "penalty", "law": "linear", "stiffness": 1e4}}],
             "analysis": dynamic("msbdf", dt=0.01, t_end=0.1)}
        notes = [w for w in check_budget(from_dict(d)) if "cvode" in w]
        assert bool(notes) == noted
        if noted:
            assert f"{2 * n} x {2 * n}" in notes[0]
