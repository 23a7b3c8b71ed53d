"""[[chain]] kept as arrays (martello/scene/chain.py, martello/scene/items.py) against the same
chain written out by hand as [[node]], [[link]] and [[contact]] tables (the expansion
docs/scene-input.md describes, written here item by item): the same items, names, errors and
physics digest.

Kind of evidence: an identity of the method (the format says a chain IS those tables), checked
against an independent per-item expansion, not a verification of physics."""

import copy

import numpy as np
import pytest

from martello.errors import SceneError
from martello.reference.store import physics_digest
from martello.scene.chain import Alternating, Neighbours
from martello.scene.items import Listed, Names, Numbered
from martello.scene.loader import from_dict


def written_out(data):
    """The scene with every [[chain]] replaced by the tables docs/scene-input.md says it
    stands for, appended after the written ones (one dict per item)."""
    data = copy.deepcopy(data)
    nodes, links, contacts = data.get("node", []), data.get("link", []), data.get("contact", [])
    for ch in data.pop("chain"):
        n, p = ch["n"], ch["prefix"]

        def each(key, count=n, default=None):
            v = ch.get(key, default)
            return v if isinstance(v, list) else [v] * count
        mass, k, fy, rho, zeta = each("mass"), each("k"), each("fy"), each("hardening", default=0.0), each("zeta")
        u0, v0, gap = each("u0", default=0.0), each("v0", default=0.0), each("gap", n - 1, 0.0)
        for i in range(n):
            nm = f"{p}{i + 1}"
            nodes.append({"name": nm, "mass": mass[i], "u0": u0[i], "v0": v0[i]})
            spring = {"name": f"{nm}.spring", "type": "spring", "a": nm, "b": "ground", "k": k[i]}
            if fy[i] is not None:
                spring.update(type="bilinear", fy=fy[i], hardening=rho[i])
            links.append(spring)
            if zeta[i] is not None and zeta[i] > 0:
                links.append({"name": f"{nm}.damper", "type": "dashpot", "a": nm, "b": "ground",
                              "zeta": zeta[i]})
        if ch.get("contact") is not None:
            for i in range(n - 1):
                contacts.append(dict({"name": f"{p}{i + 1}-{p}{i + 2}", "a": f"{p}{i + 1}",
                                      "b": f"{p}{i + 2}", "gap": gap[i]}, **ch["contact"]))
    data.update(node=nodes, link=links, contact=contacts)
    return data


def scene(chains, **extra):
    d = {"chain": chains,
         "analysis": {"type": "dynamic", "integrator": "newmark", "dt": 1e-3, "t_end": 0.01}}
    d.update(extra)
    return d


KELVIN = {"scheme": "penalty", "law": "kelvin", "stiffness": 1e6, "restitution": 0.6}
CASES = {
    "scalars": scene([{"prefix": "b", "n": 60, "mass": 2.0, "k": 100, "zeta": 0.05, "gap": 0.01,
                       "contact": KELVIN}]),
    "lists, some dampers, bilinear": scene([{
        "prefix": "s", "n": 7, "mass": [1.0, 2, 3.0, 4.0, 5.0, 6.0, 7.5], "k": [1e3 + i for i in range(7)],
        "fy": 10.0, "hardening": [0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6],
        "zeta": [0.0, 0.05, 0.0, 0.02, 0.03, 0.0, 9.5], "gap": [0.0, -1e-3, 2e-3, 0.0, 1, 0.5],
        "u0": 0.001, "v0": [0.0, 0.1, 0.0, 0.0, 0.0, 0.0, -0.3],
        "contact": {"scheme": "penalty", "stiffness": 1e5}}]),
    "two chains among written items": scene(
        [{"prefix": "a", "n": 3, "mass": 1.0, "k": 50.0, "zeta": 0.1, "contact": KELVIN},
         {"prefix": "c", "n": 4, "mass": 1.0, "k": 80.0, "contact": {"scheme": "penalty", "stiffness": 1e4}}],
        node=[{"name": "w", "mass": 3.0}, {"name": "a9", "mass": 1.0}],
        # a written spring to ground on a chain node enters its damper's c = 2ζ√(k m)
        link=[{"type": "spring", "a": "w", "b": "ground", "k": 10.0},
              {"name": "extra", "type": "spring", "a": "a2", "b": "ground", "k": 7.0}],
        contact=[{"name": "wall", "a": "c4", "b": "ground", "gap": 0.1, "scheme": "penalty",
                  "stiffness": 1e6}]),
}


def text(items):
    return [repr(sorted(d.items())) for d in items]


@pytest.mark.parametrize("case", CASES)
def test_a_chain_is_the_tables_it_stands_for(case):
    s, w = from_dict(CASES[case]), from_dict(written_out(CASES[case]))
    for kind in ("nodes", "links", "contacts"):
        got, want = getattr(s, kind), getattr(w, kind)
        # repr of each item: 0.1 and np.float64(0.1) or 1 and 1.0 would differ
        assert text(got) == text(want), kind
        assert list(got.names) == [it["name"] for it in want]
        assert all(got.names.index(it["name"]) == i for i, it in enumerate(want))
    assert s.analysis == w.analysis and s.index == w.index
    assert physics_digest(s) == physics_digest(w)


def test_a_large_chain_builds_no_dict():
    s = from_dict(scene([{"prefix": "b", "n": 200_000, "mass": 1.0, "k": 1.0, "zeta": 0.05,
                          "gap": 0.01, "contact": KELVIN}]))
    assert [len(seg) for seg in s.nodes.segments] == [200_000]
    assert not any(isinstance(seg, list) for t in (s.nodes, s.links, s.contacts) for seg in t.segments)
    assert s.links[399_999]["name"] == "b200000.damper" and s.contacts.names.index("b7-b8") == 6
    assert s.index["b123456"] == 123_455 and "b200001" not in s.index and "b0" not in s.index


def fails(data):
    with pytest.raises(SceneError) as e:
        from_dict(data)
    return str(e.value)


@pytest.mark.parametrize("chain,message", [
    ({"mass": [1.0, "x", -1.0]}, "chain[0].mass[1]: has the wrong type (str) (expected float)"),
    ({"mass": [1.0, -1, "x"]}, "chain[0].mass[1]: invalid value -1 (must be a number > 0)"),
    ({"mass": [1.0, 2.0, True]}, "chain[0].mass[2]: has the wrong type (bool) (expected float)"),
    ({"k": -2}, "chain[0].k: invalid value -2 (must be a number > 0)"),
    ({"k": "stiff"}, "chain[0].k: has the wrong type (str) (expected float)"),
    ({"mass": [1.0, 2.0]}, "chain[0].mass: has 2 values (give one number or a list of 3)"),
    ({"gap": [0.1, 0.2, 0.3]}, "chain[0].gap: has 3 values (give one number or a list of 2)"),
    ({"hardening": [0.1, 1.0, 0.0], "fy": 1.0}, "chain[0].hardening[1]: invalid value 1.0 (must be a number in [0, 1))"),
    ({"zeta": [0.0, 0.1, 10]}, "chain[0].zeta[2]: invalid value 10 (must be a number in [0, 10))"),
])
def test_a_bad_entry_of_a_chain_list_is_named_by_its_index(chain, message):
    d = scene([dict({"prefix": "b", "n": 3, "mass": 1.0, "k": 1.0}, **chain)])
    assert fails(d).endswith(message)


@pytest.mark.parametrize("extra", [
    {"node": [{"name": "m", "mass": 1.0}, {"name": "b2", "mass": 1.0}]},      # a written node
    {"link": [{"name": "b3.damper", "type": "spring", "a": "b1", "b": "ground", "k": 1.0}]},
    {"contact": [{"name": "b2-b3", "a": "b1", "b": "ground", "scheme": "lagrange"}]},
    {"chain2": {"prefix": "b", "n": 2, "mass": 1.0, "k": 1.0}},                 # the same prefix
    {"chain2": {"prefix": "b1", "n": 3, "mass": 1.0, "k": 1.0}},                # b1 + 1 = b11
])
def test_a_generated_name_taken_already_is_named_where_the_written_out_scene_has_it(extra):
    chains = [{"prefix": "b", "n": 12, "mass": 1.0, "k": 1.0, "zeta": 0.1, "contact": KELVIN}]
    if "chain2" in extra:
        chains.append(extra.pop("chain2"))
    d = scene(chains, **extra)
    got = fails(d)
    assert "duplicate name" in got and got == fails(written_out(d))


@pytest.mark.parametrize("contact", [
    {"law": "kelvin", "stiffness": 1.0},                                        # no scheme
    {"scheme": "penalty", "law": "linear", "stiffness": -1.0},
    {"scheme": "penalty", "law": "linear", "stiffness": 1.0, "restitution": 0.5},
    {"scheme": "penalty", "stiffness": 1.0, "colour": "red"},
    {"scheme": "lagrange", "restitution": 0.5},                                 # not on newmark
])
def test_a_chain_contact_table_error_names_its_first_contact(contact):
    d = scene([{"prefix": "b", "n": 4, "mass": 1.0, "k": 1.0, "contact": contact}],
              contact=[{"name": "w", "a": "b1", "b": "ground", "scheme": "penalty", "stiffness": 1.0}])
    got = fails(d)
    assert "contact[1]" in got and got == fails(written_out(d))


def test_names_by_rule_find_their_own_names_only():
    sec = np.array([True, False, True])
    names = Names([Listed(["x", "b1"]), Numbered("b", "", 2, 3), Alternating("b", "spring", "damper", 1, sec),
                   Neighbours("b", 1, 2), Numbered("r.", "", numbers=np.array([1, 5, 9]))])
    every = ["x", "b1", "b2", "b3", "b4", "b1.spring", "b1.damper", "b2.spring", "b3.spring",
             "b3.damper", "b1-b2", "b2-b3", "r.1", "r.5", "r.9"]
    assert list(names) == every and [names[i] for i in range(len(every))] == every
    assert [names.index(nm) for nm in every] == list(range(len(every)))
    for nm in ("b5", "b02", "b2.damper", "b1-b3", "b3-b4", "r.2", "b", "b-1", "b٣", "r.09"):
        assert nm not in names, nm
    arrays = {}
    assert list(Names.from_spec(names.spec(arrays), arrays)) == every


def rods_written_out(data):
    """The scene with every [[bar]] replaced by the tables docs/p4-bars.md says it stands for
    (lumped or consistent mass, node or half-cell ends, held ends), one dict per item."""
    data = copy.deepcopy(data)
    nodes, links, couplings = data.get("node", []), data.get("link", []), data.get("mass_coupling", [])
    for b in data.pop("bar"):
        name, N, L, EA, rhoA = b["name"], b["elements"], b["L"], b["EA"], b["rhoA"]
        Le, ends, mass = L / N, b.get("ends", "node"), b.get("mass", "lumped")
        fixed, v0 = b.get("fixed", "none"), b.get("v0", 0.0)
        me = rhoA * Le
        n = N + 1 if ends == "node" else N
        names = [f"{name}.left"] + [f"{name}.{i}" for i in range(1, n - 1)] + [f"{name}.right"]
        for i, nm in enumerate(names):
            end = i in (0, n - 1)
            m = me if ends != "node" else ((me / 3.0 if end else 2.0 * me / 3.0) if mass == "consistent"
                                           else (0.5 * me if end else me))
            node = {"name": nm, "mass": m}
            held = ends == "node" and ((i == 0 and fixed in ("left", "both"))
                                       or (i == n - 1 and fixed in ("right", "both")))
            if held:
                node["fixed"] = True
            elif v0:
                node["v0"] = v0
            nodes.append(node)
        for k in range(n - 1):
            links.append({"name": f"{name}.e{k + 1}", "type": "bar", "a": names[k], "b": names[k + 1],
                          "EA": EA, "L": Le})
            if mass == "consistent":
                couplings.append({"a": names[k], "b": names[k + 1], "value": me / 6.0})
        if ends == "half-cell" and fixed in ("left", "both"):
            links.append({"name": f"{name}.support.left", "type": "bar", "a": "ground", "b": names[0],
                          "EA": EA, "L": 0.5 * Le})
        if ends == "half-cell" and fixed in ("right", "both"):
            links.append({"name": f"{name}.support.right", "type": "bar", "a": names[-1], "b": "ground",
                          "EA": EA, "L": 0.5 * Le})
    data.update(node=nodes, link=links, mass_coupling=couplings)
    return data


ROD = {"L": 1.0, "EA": 2e7, "rhoA": 0.785, "output": "none"}
ROD_CASES = {
    "lumped, held left, moving": [dict(ROD, name="A", elements=7, fixed="left", v0=1.5)],
    "consistent, two rods": [dict(ROD, name="A", elements=5, mass="consistent", fixed="both"),
                             dict(ROD, name="B", elements=3, mass="consistent", v0=-0.0)],
    "half-cell, both held": [dict(ROD, name="H", elements=6, ends="half-cell", fixed="both")],
}


@pytest.mark.parametrize("case", ROD_CASES)
def test_a_rod_is_the_tables_it_stands_for(case):
    d = {"bar": ROD_CASES[case], "node": [{"name": "w", "mass": 1.0}],
         "contact": [{"name": "c", "a": ROD_CASES[case][0]["name"] + ".right", "b": "w",
                      "scheme": "penalty", "stiffness": 1e6}],
         "link": [{"type": "dashpot", "a": "w", "b": "ground", "c": 1.0}],
         "analysis": {"type": "dynamic", "integrator": "newmark", "dt": 1e-5, "t_end": 1e-3,
                      "output": {"nodes": ["w"]}}}
    s, w = from_dict(d), from_dict(rods_written_out(d))
    for kind in ("nodes", "links", "contacts", "couplings"):
        assert text(getattr(s, kind)) == text(getattr(w, kind)), kind
    assert list(s.nodes.names) == [n["name"] for n in w.nodes] and s.index == w.index
    assert list(s.links.names) == [lk["name"] for lk in w.links]
    assert physics_digest(s) == physics_digest(w)


def test_a_rod_node_taken_already_is_the_rods_error():
    d = scene([{"prefix": "A.", "n": 3, "mass": 1.0, "k": 1.0}],
              bar=[dict(ROD, name="A", elements=4)])
    assert fails(d).endswith("bar[0].name: generates the node 'A.1', which already exists "
                             "(choose another rod name)")
