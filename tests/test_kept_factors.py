"""The general fixed-step path keeps its Newton matrix while no element tangent moves
(docs/integrators.md, kept factors).

Kind of evidence: an identity of the method, not a verification. J = c_m M + (1 − α_f)(K_t +
c_v C_t) is a function of the element tangents alone at a fixed step, so an iterate whose
tangents are the same numbers has the same J: keeping its factors changes no digit of the
Newton iterates. What can fail: a branch change that does not refactor (the answers would then
differ from the fused chain step, which refactors at every branch change, by far more than
round-off), or a path that still refactors at every iterate (the counts)."""

from martello.run import run
from martello.scene.loader import from_dict


def scene(integrator="newmark", law="kelvin", t_end=1.0, extra_link=False, **analysis):
    """Four masses in a row under a ground pulse: linear springs and dashpots, a bilinear
    spring that yields, two penalty contacts that close and open. extra_link: a spring from
    node 1 to node 3 (half-bandwidth 2: the LAPACK band factors instead of the Thomas sweep)."""
    contact = {"scheme": "penalty", "law": law, "stiffness": 2.0e5}
    if law == "kelvin":
        contact["restitution"] = 0.7
    if law == "hertz":
        contact["stiffness"] = 2.0e7
    d = {
        "node": [{"name": f"n{i}", "mass": 1.0 + 0.25 * i} for i in range(1, 5)],
        "link": [{"type": "spring", "a": "n1", "b": "ground", "k": 400.0},
                 {"type": "dashpot", "a": "n1", "b": "ground", "c": 0.5},
                 {"type": "bilinear", "a": "n2", "b": "ground", "k": 600.0, "fy": 3.0,
                  "hardening": 0.05},
                 {"type": "spring", "a": "n3", "b": "ground", "k": 300.0},
                 {"type": "spring", "a": "n4", "b": "ground", "k": 900.0}],
        "contact": [{"name": "c12", "a": "n1", "b": "n2", "gap": 0.005, **contact},
                    {"name": "c34", "a": "n3", "b": "n4", "gap": 0.004, **contact}],
        "loads": {"ground_acceleration": {"type": "sine", "amplitude": 6.0, "omega": 15.0,
                                          "t_end": 0.6}},
        "analysis": {"type": "dynamic", "integrator": integrator, "dt": 1e-4, "t_end": t_end,
                     "output": {"every": 100}, **analysis},
    }
    if extra_link:
        d["link"].append({"type": "spring", "a": "n1", "b": "n3", "k": 50.0})
    return from_dict(d)


def test_factors_are_kept_between_branch_changes():
    for extra in (False, True):
        r = run(scene("hht", alpha=-0.05, extra_link=extra))
        c = r["cost"]
        # the scene switches branches: contacts close and open, the bilinear spring yields
        assert c["events"] >= 4 and r["energy"]["plastic"] > 0
        # one factorisation per tangent change, not per Newton iterate: a branch change costs
        # a few (the iterate that finds it and the ones after), a quiet step none
        assert c["factorizations"] < 0.02 * c["steps"], c
        assert c["newton_iterations"] >= c["steps"]


def test_kept_factors_give_the_fused_steps_answers():
    # Newmark on a chain: the fused step refactors at every branch change by construction
    general = run(scene(fused_chain=False, preset="average-acceleration"))
    fused = run(scene(preset="average-acceleration"))
    assert fused["cost"]["fused_chain_steps"] == fused["cost"]["steps"]
    assert general["cost"]["fused_chain_steps"] == 0
    assert general["cost"]["factorizations"] < 0.02 * general["cost"]["steps"]
    for name in ("n1", "n2", "n3", "n4"):
        for key in ("u_max", "u_min", "v_absmax"):
            a, b = general["nodes"][name][key], fused["nodes"][name][key]
            assert abs(a - b) <= 1e-9 * abs(b), (name, key, a, b)


def test_a_moving_tangent_refactors():
    # Hertz's tangent 1.5 K δ^0.5 moves at every iterate in contact: no factor is kept there,
    # so the factorisations follow the Newton iterates of the steps in contact
    r = run(scene("hht", law="hertz", alpha=-0.05))
    c = r["cost"]
    in_contact = sum(1 for _ in r["contacts"]["c12"]["impact_times"]) + \
        sum(1 for _ in r["contacts"]["c34"]["impact_times"])
    assert in_contact > 0
    assert c["factorizations"] > 0.02 * c["steps"]
    assert c["factorizations"] <= c["newton_iterations"] + 1
