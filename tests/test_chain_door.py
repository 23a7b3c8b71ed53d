"""The chain door (martello_model_add_chain, docs/c-api.md "Chains"), through which the front end
hands the library every [[chain]] (martello.run.build_model), against the same chain added
link by link and contact by contact by the bulk doors.

Kind of evidence: an identity of the method, not a verification. A chain held per node is the
model its links and contacts make one by one (numbered as the scene's [[chain]] expansion
numbers them): the fused chain step reads the per-node arrays directly, every other method
gets the links and contacts made from them. A scene built both ways must therefore run to the
same bits: every number of the summary and of the history, compared with ==, no tolerance.
The catalogue's [[chain]] scenes, and chains made here for what they lack (linear contacts on a
long chain, a clipped Kelvin law, items added one by one around a chain, bilinear springs,
integrators other than Newmark)."""

import functools
import tomllib

import numpy as np
import pytest

import martello.run as run_module
from martello.binding import native
from martello.errors import SolverError
from martello.run import run_full
from martello.scene.catalogue import scene_files
from martello.scene.loader import from_dict, load
from tests.test_bulk_model import leaves


def assert_same_bits(data, monkeypatch):
    """The scene run as the front end builds it (each [[chain]] through the chain door) and
    with its chains' links and contacts added by the bulk doors: every number of summary and
    history equal."""
    doors = []
    add_chain = native.Model.add_chain
    monkeypatch.setattr(native.Model, "add_chain",
                        lambda self, *a, **kw: doors.append(a[0]) or add_chain(self, *a, **kw))
    door, door_hist = run_full(from_dict(data))
    assert len(doors) == len(data.get("chain", []))           # the door took every chain
    monkeypatch.setattr(run_module, "build_model",
                        functools.partial(run_module.build_model, chain_door=False))
    items, hist = run_full(from_dict(data))
    monkeypatch.undo()
    skip = ("cost", "provenance")
    a = leaves({k: v for k, v in items.items() if k not in skip})
    b = leaves({k: v for k, v in door.items() if k not in skip})
    assert set(a) == set(b)
    bad = [k for k in a if not (a[k] == b[k] or (a[k] != a[k] and b[k] != b[k]))]
    assert not bad, [(k, a[k], b[k]) for k in bad[:5]]
    assert hist[0] == door_hist[0]
    assert np.array_equal(hist[1], door_hist[1], equal_nan=True)
    # the fused chain step took the same steps either way (it reads the chain whole)
    assert items["cost"]["fused_chain_steps"] == door["cost"]["fused_chain_steps"]
    return door


def catalogue_chains():
    out = []
    for p in scene_files():
        with open(p, "rb") as f:
            if "chain" in tomllib.load(f):
                out.append(p)
    return out


@pytest.mark.parametrize("path", catalogue_chains(), ids=lambda p: p.name)
def test_catalogue_chains_run_to_the_same_bits_through_the_door(path, monkeypatch):
    with open(path, "rb") as f:
        data = tomllib.load(f)
    dt = load(path).analysis["dt"]
    data["analysis"]["t_end"] = min(data["analysis"]["t_end"], 4000 * dt)
    assert_same_bits(data, monkeypatch)


def pounding(n=40, law="linear", integrator="newmark", **extra):
    """The benchmark's chain (benchmarks/perf/chain_vs_opensees.py) at a small n."""
    contact = {"scheme": "penalty", "law": law, "stiffness": 1e5}
    if law == "kelvin":
        contact.update(restitution=0.6, clipped=True)
    d = {"chain": [{"prefix": "b", "n": n, "mass": 1.0,
                    "k": [100.0 if i % 2 == 0 else 400.0 for i in range(n)], "zeta": 0.05,
                    "gap": 0.01, "contact": contact, **extra.pop("chain", {})}],
         "loads": {"ground_acceleration": {"type": "sine", "amplitude": 3.0, "omega": 8.0}},
         "analysis": {"type": "dynamic", "integrator": integrator, "dt": 1e-3, "t_end": 3.0,
                      "output": {"every": 50, "nodes": ["b1", f"b{n}"],
                                 "contacts": ["b1-b2"], "links": ["b2.spring", "b3.damper"]}}}
    d.update(extra)
    return d


@pytest.mark.parametrize("law", ["linear", "kelvin"])
def test_a_pounding_chain_runs_to_the_same_bits(law, monkeypatch):
    r = assert_same_bits(pounding(law=law), monkeypatch)
    assert r["contacts"]["b1-b2"]["impacts"] >= 2          # the chain pounds
    # Kelvin's force jumps to cδ̇ at first touch: a few chattering steps go to the general
    # path, on the model with the chain's links and contacts made one by one
    if law == "linear":
        assert r["cost"]["fused_chain_steps"] == r["cost"]["steps"]
    else:
        assert r["cost"]["steps"] - 10 <= r["cost"]["fused_chain_steps"] < r["cost"]["steps"]


def test_items_one_by_one_around_a_chain_keep_their_numbers(monkeypatch):
    # a wall node before the chain, a link and a contact written one by one that join it to
    # the chain's first node, a nodal force on the last: numbered before the chain's items
    d = pounding(n=6)
    d["node"] = [{"name": "wall", "mass": 0.0, "fixed": True}]
    d["link"] = [{"name": "tie", "type": "spring", "a": "wall", "b": "b1", "k": 50.0}]
    d["contact"] = [{"name": "stop", "a": "wall", "b": "b1", "gap": 0.02, "scheme": "penalty",
                     "law": "linear", "stiffness": 2e4}]
    d["loads"]["force"] = [{"node": "b6", "function": {"type": "sine", "amplitude": 5.0,
                                                       "omega": 3.0}}]
    d["analysis"]["output"]["links"] = ["tie", "b2.spring"]
    d["analysis"]["output"]["contacts"] = ["stop", "b1-b2"]
    r = assert_same_bits(d, monkeypatch)
    assert r["contacts"]["stop"]["impacts"] > 0


def test_bilinear_springs_and_other_integrators_take_the_chain_one_by_one(monkeypatch):
    # the door's bilinear springs and every method but the fused step get the links made from
    # the chain's arrays
    assert_same_bits(pounding(chain={"fy": 3.0, "hardening": 0.05}), monkeypatch)
    for integrator in ("hht", "central-difference"):
        d = pounding(integrator=integrator)
        if integrator == "hht":
            d["analysis"]["alpha"] = -0.1
        if integrator == "central-difference":
            d["analysis"]["dt"] = 1e-4
            d["analysis"]["t_end"] = 0.5
        r = assert_same_bits(d, monkeypatch)
        assert r["cost"]["fused_chain_steps"] == 0


def test_a_bad_chain_entry_is_named():
    par = np.zeros(native.constant("NPAR_CONTACT"))
    par[native.constant("P_STIFF")] = 1e5
    par[native.constant("P_RESTITUTION")] = -1.0
    lin, pen = native.value("laws", "linear"), native.value("schemes", "penalty")
    with native.Model(4, 0, 0, 0) as m:
        m.set_nodes([1.0] * 4, [0.0] * 4, [0.0] * 4, [0] * 4)
        with pytest.raises(SolverError, match=r"chain entry 2: add_link: parameters must be finite"):
            m.add_chain(0, [1.0, 2.0, float("nan"), 1.0])
        with pytest.raises(SolverError, match=r"chain entry 1: add_chain: dashpot c must be finite and >= 0"):
            m.add_chain(0, [1.0] * 4, c=[0.1, -0.1, 0.0, 0.0])
        with pytest.raises(SolverError, match=r"chain entry 0: add_contact: gap and parameters must be finite"):
            m.add_chain(0, [1.0] * 4, gap=[float("inf"), 0.0, 0.0], scheme=pen, law=lin, par=par)
        with pytest.raises(SolverError, match=r"add_chain: its nodes first \.\.\. first \+ n - 1"):
            m.add_chain(2, [1.0] * 3)


def test_a_chain_between_written_links_and_a_rod_keeps_every_number(monkeypatch):
    # the front end's order (martello.run.build_model): the links written before the
    # generators, every listed contact, the chain's items at its call, then a rod's bars; a
    # rod's end pounds the chain's first node, a link joins its other end to the chain's last
    d = pounding(n=5)
    d["bar"] = [{"name": "R", "L": 0.5, "elements": 4, "E": 2.0e5, "A": 1.0e-4, "rho": 800.0,
                 "mass": "lumped", "v0": 0.3}]
    d["link"] = [{"name": "tie", "type": "spring", "a": "R.right", "b": "b5", "k": 20.0}]
    d["contact"] = [{"name": "hit", "a": "R.left", "b": "b1", "gap": 0.005, "scheme": "penalty",
                     "law": "linear", "stiffness": 5e3}]
    d["analysis"]["output"]["links"] = ["tie", "b2.spring", "R.e1"]
    d["analysis"]["output"]["contacts"] = ["hit", "b1-b2"]
    r = assert_same_bits(d, monkeypatch)
    assert r["contacts"]["hit"]["impacts"] > 0 and r["contacts"]["b1-b2"]["impacts"] > 0


def test_a_rod_after_a_chain_keeps_its_numbers_without_written_links(monkeypatch):
    # no link written in the file: the scene numbers the chain's links first, then the rod's
    d = pounding(n=4)
    d["bar"] = [{"name": "R", "L": 0.5, "elements": 3, "E": 2.0e5, "A": 1.0e-4, "rho": 800.0,
                 "mass": "lumped", "v0": 0.3}]
    d["contact"] = [{"name": "hit", "a": "R.left", "b": "b1", "gap": 0.005, "scheme": "penalty",
                     "law": "linear", "stiffness": 5e3}]
    d["analysis"]["output"]["links"] = ["b2.spring", "R.e1"]
    r = assert_same_bits(d, monkeypatch)
    assert r["contacts"]["hit"]["impacts"] > 0
