"""The bulk model doors (docs/c-api.md, "Building a large model") against the one-entry doors.

Kind of evidence: an identity of the method, not a verification. The bulk doors check and store
each entry exactly as the one-entry doors do, so a scene built both ways must run to the same
bits: every number of the summary and of the history, compared with ==, no tolerance. The
one-entry builder below is the front end's former element-by-element code, kept here as the
reference path."""

import numpy as np
import pytest

import martello.run as run_module
from martello.binding import native
from martello.binding.native import constant
from martello.errors import SolverError
from martello.run import LAW_EXPONENT, run_full
from martello.scene.catalogue import scene_files
from martello.scene.loader import load


def _link_par(lk):
    par = np.zeros(constant("NPAR_LINK"))
    if lk["type"] == "spring":
        par[constant("L_STIFF")] = lk["k"]
    elif lk["type"] == "dashpot":
        par[constant("L_DAMP")] = lk["c"]
    elif lk["type"] == "bilinear":
        par[constant("L_STIFF")] = lk["k"]
        par[constant("L_YIELD")] = lk["fy"]
        par[constant("L_HARDENING")] = lk["hardening"]
    elif lk["type"] == "fluid_damper":
        par[constant("L_DAMP")] = lk["c"]
        par[constant("L_ALPHA")] = lk["alpha"]
        par[constant("L_VREG")] = lk["v_reg"]
    elif lk["type"] == "bar":
        par[constant("L_STIFF")] = lk["EA"] / lk["L"]
    return par


def _contact_par(c):
    par = np.zeros(constant("NPAR_CONTACT"))
    par[constant("P_RESTITUTION")] = -1.0
    law = 0
    if c["scheme"] == "penalty":
        law = native.value("laws", c["law"])
        par[constant("P_STIFF")] = c["stiffness"]
        par[constant("P_EXPONENT")] = c["exponent"] or LAW_EXPONENT[c["law"]]
        if c["damping"] is not None:
            par[constant("P_DAMPING")] = c["damping"]
        if c["restitution"] is not None:
            par[constant("P_RESTITUTION")] = c["restitution"]
        par[constant("P_CLIP")] = 1.0 if c["clipped"] else 0.0
    elif c["scheme"] == "augmented-lagrange":
        par[constant("P_STIFF")] = c["stiffness"]
    elif c.get("restitution") is not None:
        par[constant("P_RESTITUTION")] = c["restitution"]
    return law, par


def build_by_element(scene):
    """The model built by one C call per node, link and contact."""
    m = native.Model(len(scene.nodes), len(scene.links), len(scene.contacts), len(scene.forces),
                     len(scene.couplings))
    for i, n in enumerate(scene.nodes):
        m.set_node(i, n["mass"], n["u0"], n["v0"], n["fixed"])
    for lk in scene.links:
        if lk.get("terms"):                 # a row over several DOFs (docs/buildings.md)
            nodes, coefs = zip(*lk["terms"])
            m.add_link_row(native.value("links", lk["type"]), nodes, coefs, _link_par(lk))
        else:
            m.add_link(native.value("links", lk["type"]), lk["a"], lk["b"], _link_par(lk))
    for c in scene.contacts:
        law, par = _contact_par(c)
        if c.get("terms"):
            nodes, coefs = zip(*c["terms"])
            m.add_contact_row(nodes, coefs, c["gap"], native.value("schemes", c["scheme"]), law, par)
        else:
            m.add_contact(c["a"], c["b"], c["gap"], native.value("schemes", c["scheme"]), law, par)
    for mc in scene.couplings:
        m.add_mass_coupling(mc["a"], mc["b"], mc["value"])
    for b in scene.blocks:
        m.add_stiffness_block(b["nodes"], b["k"], b["c"])
    m.set_gravity(scene.gravity)
    for f in scene.forces:
        m.add_nodal_force(f["node"], *run_module._function_args(f["function"], scene.source))
    if scene.ground is not None:
        m.set_ground_acceleration(*run_module._function_args(scene.ground, scene.source))
    return m


def kinds(scene):
    """What a scene exercises in the parameter rows: link types, contact schemes and laws."""
    return ({("link", lk["type"]) for lk in scene.links}
            | {("contact", c["scheme"], c.get("law")) for c in scene.contacts})


def covering_scenes():
    """Dynamic catalogue scenes, chosen so that together they hold every link type and
    contact scheme/law the catalogue uses (each adds at least one new kind)."""
    seen, out = set(), []
    for p in scene_files():
        s = load(p)
        new = kinds(s) - seen
        if s.analysis.get("type") == "dynamic" and new:
            seen |= new
            out.append(p)
    return out


def leaves(d, pre=""):
    if isinstance(d, dict):
        return {k: v for key, sub in d.items() for k, v in leaves(sub, f"{pre}/{key}").items()}
    if isinstance(d, list):
        return {k: v for i, sub in enumerate(d) for k, v in leaves(sub, f"{pre}/{i}").items()}
    return {pre: d}


def short(path):
    s = load(path)
    # 400 steps reach the first contacts of most scenes and keep the test fast
    s.analysis["t_end"] = min(s.analysis["t_end"], 400 * s.analysis["dt"])
    return s


@pytest.mark.parametrize("path", covering_scenes(), ids=lambda p: p.name)
def test_bulk_and_element_built_models_run_to_the_same_bits(path, monkeypatch):
    bulk, bulk_hist = run_full(short(path))
    monkeypatch.setattr(run_module, "build_model", build_by_element)
    one, one_hist = run_full(short(path))
    skip = ("cost", "provenance")
    a = leaves({k: v for k, v in bulk.items() if k not in skip})
    b = leaves({k: v for k, v in one.items() if k not in skip})
    assert set(a) == set(b)
    bad = [k for k in a if not (a[k] == b[k] or (a[k] != a[k] and b[k] != b[k]))]
    assert not bad, [(k, a[k], b[k]) for k in bad[:5]]
    assert bulk_hist[0] == one_hist[0]
    assert np.array_equal(bulk_hist[1], one_hist[1], equal_nan=True)


def test_the_covering_scenes_hold_every_kind():
    # the comparison above means something only if it meets links and several contact kinds
    got = set().union(*(kinds(load(p)) for p in covering_scenes()))
    assert {k[1] for k in got if k[0] == "link"} >= {"spring", "dashpot"}
    assert len({k[1] for k in got if k[0] == "contact"}) >= 2


def test_a_bad_entry_is_named_by_its_index():
    with native.Model(4, 2, 1, 0) as m:
        with pytest.raises(SolverError, match=r"entry 2: set_node: mass must be > 0"):
            m.set_nodes([1.0, 1.0, 0.0, 1.0], [0.0] * 4, [0.0] * 4, [0, 0, 0, 0])
        m.set_nodes([1.0] * 4, [0.0] * 4, [0.0] * 4, [0] * 4)
        par = np.zeros((2, constant("NPAR_LINK")))
        par[:, constant("L_STIFF")] = 1.0            # a valid spring (k > 0)
        with pytest.raises(SolverError, match=r"entry 1: add_link: nodes out of range"):
            m.add_links([native.value("links", "spring")] * 2, [0, 1], [1, 1], par)
