"""Every documented error path of the scene loader: one bad field at a time, and the message
must name the file, the field and what would be valid."""

import copy
import math

import pytest

from martello.errors import SceneError
from martello.scene.loader import from_dict, load
from tests.conftest import p1_dict


def bad(mutate):
    d = copy.deepcopy(p1_dict())
    mutate(d)
    return d


CASES = [
    # (id, mutation, field named in the message, words of the fix)
    ("unknown top key", lambda d: d.update(nodes=[]), "nodes", "valid top-level keys"),
    ("unknown node key", lambda d: d["node"][0].update(weight=2.0), "node[0].weight", "valid keys here"),
    ("missing mass", lambda d: d["node"][0].pop("mass"), "node[0].mass", "required"),
    ("zero mass", lambda d: d["node"][0].update(mass=0.0), "node[0].mass", "> 0"),
    ("negative mass", lambda d: d["node"][0].update(mass=-1.0), "node[0].mass", "> 0"),
    ("mass as text", lambda d: d["node"][0].update(mass="1"), "node[0].mass", "expected float"),
    ("nan mass", lambda d: d["node"][0].update(mass=math.nan), "node[0].mass", "finite"),
    ("inf gap", lambda d: d["contact"][0].update(gap=math.inf), "contact[0].gap", "finite"),
    ("nan in check", lambda d: d.update(check={"closed_form": "x", "params": {"m": math.nan},
                                                 "compare": []}), "check.params.m", "finite"),
    ("zero stiffness", lambda d: d["link"][0].update(k=0.0), "link[0].k", "> 0"),
    ("negative stiffness", lambda d: d["link"][0].update(k=-5.0), "link[0].k", "> 0"),
    ("missing stiffness", lambda d: d["link"][0].pop("k"), "link[0].k", "required"),
    ("unknown link type", lambda d: d["link"][0].update(type="rope"), "link[0].type", "spring"),
    ("link to nowhere", lambda d: d["link"][0].update(b="roof"), "link[0].b", "mass, ground"),
    ("contact to nowhere", lambda d: d["contact"][0].update(a="ball"), "contact[0].a", "mass, ground"),
    ("contact on itself", lambda d: d["contact"][0].update(b="mass"), "contact[0].b", "two different"),
    ("unknown scheme", lambda d: d["contact"][0].update(scheme="magic"), "contact[0].scheme", "penalty"),
    ("unknown law", lambda d: d["contact"][0].update(scheme="penalty", law="glue", stiffness=1e4),
     "contact[0].law", "hertz"),
    ("penalty without stiffness", lambda d: d["contact"][0].update(scheme="penalty"),
     "contact[0].stiffness", "required"),
    ("damping and restitution", lambda d: d["contact"][0].update(
        scheme="penalty", law="kelvin", stiffness=1e4, damping=1.0, restitution=0.5),
     "contact[0].damping", "give one"),
    ("restitution above 1", lambda d: d["contact"][0].update(scheme="restitution", restitution=1.5),
     "contact[0].restitution", "[0, 1]"),
    ("clipped on hertz", lambda d: d["contact"][0].update(scheme="penalty", law="hertz",
                                                          stiffness=1e4, clipped=True),
     "contact[0].clipped", "remove"),
    ("duplicate node", lambda d: d["node"].append({"name": "mass", "mass": 1.0}), "node[1].name", "unique"),
    ("node named ground", lambda d: d["node"][0].update(name="ground"), "node[0].name", "another name"),
    ("no nodes", lambda d: d.pop("node"), "node", "at least one"),
    ("missing analysis", lambda d: d.pop("analysis"), "analysis.type", "static"),
    ("unknown analysis", lambda d: d["analysis"].update(type="modal"), "analysis.type", "static"),
    ("unknown analysis key", lambda d: d["analysis"].update(dt=0.1), "analysis.dt", "valid keys"),
    ("hardening 1", lambda d: d["link"][0].update(type="bilinear", fy=1.0, hardening=1.0),
     "link[0].hardening", "[0, 1)"),
    ("force value and function", lambda d: d["loads"].update(force=[{"node": "mass", "value": 1.0,
                                                                      "function": {"type": "constant", "value": 1.0}}]),
     "loads.force[0]", "exactly one"),
    ("force on ground", lambda d: d["loads"].update(force=[{"node": "ground", "value": 1.0}]),
     "loads.force[0].node", "use one of"),
    ("table not increasing", lambda d: d["loads"].update(force=[{"node": "mass", "function": {
        "type": "table", "t": [0.0, 1.0, 1.0], "values": [0.0, 1.0, 2.0]}}]),
     "loads.force[0].function.t[2]", "increase strictly"),
    ("unknown function", lambda d: d["loads"].update(ground_acceleration={"type": "noise"}),
     "loads.ground_acceleration.type", "sine"),
    ("sine window reversed", lambda d: d["loads"].update(ground_acceleration={
        "type": "sine", "amplitude": 1.0, "omega": 2.0, "t_start": 2.0, "t_end": 1.0}),
     "loads.ground_acceleration.t_end", "later than t_start"),
    ("exponent on kelvin", lambda d: d["contact"][0].update(scheme="penalty", law="kelvin", stiffness=1e4,
                                                            exponent=1.5), "contact[0].exponent", "fixed at 1"),
    ("damping on linear", lambda d: d["contact"][0].update(scheme="penalty", law="linear", stiffness=1e4,
                                                           damping=3.0), "contact[0].damping", "elastic"),
    ("flores with e = 0", lambda d: d["contact"][0].update(scheme="penalty", law="flores", stiffness=1e4,
                                                           restitution=0.0), "contact[0].restitution", "e > 0"),
    ("link as a table", lambda d: d.update(link={"type": "spring", "a": "mass", "b": "ground", "k": 1.0}),
     "link", "[[link]]"),
    ("duplicate link name", lambda d: d["link"].append(dict(d["link"][0])), "link[1].name", "unique"),
    ("zeta on a fixed node", lambda d: (d["node"].append({"name": "s", "mass": 0.0, "fixed": True}),
                                        d["link"].append({"type": "dashpot", "a": "s", "b": "ground", "zeta": 0.05})),
     "link[1].zeta", "free node"),
    ("missing record", lambda d: d["loads"].update(ground_acceleration={"type": "record", "file": "no.at2"}),
     "loads.ground_acceleration.file", "relative to the scene"),
    ("check without tolerance", lambda d: d.update(check={"closed_form": "x", "params": {}, "compare": [
        {"result": "nodes.mass.u", "oracle": "u", "why": "w"}]}), "check.compare[0]", "rtol or atol"),
]


@pytest.mark.parametrize("mutate,field,fix", [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_scene_error_names_file_field_and_fix(mutate, field, fix):
    with pytest.raises(SceneError) as info:
        from_dict(bad(mutate), source="bad.toml")
    msg = str(info.value)
    assert msg.startswith("bad.toml: "), msg
    assert info.value.field == field, msg
    assert fix in msg, msg


def test_valid_p1_loads():
    s = from_dict(p1_dict(), source="ok.toml")
    assert s.nodes[0]["u0"] == 0.0 and s.contacts[0]["a"] == 0 and s.contacts[0]["b"] == -1


def test_fixed_node_may_be_massless():
    d = p1_dict()
    d["node"].append({"name": "support", "mass": 0.0, "fixed": True})
    assert from_dict(d).nodes[1]["fixed"]


def test_file_errors_name_the_file(tmp_path):
    with pytest.raises(SceneError, match="does not exist"):
        load(tmp_path / "missing.toml")
    broken = tmp_path / "broken.toml"
    broken.write_text("[[node]\nname = 'x'\n")
    with pytest.raises(SceneError, match=r"broken\.toml: \(syntax\): not valid TOML"):
        load(broken)
    nan_file = tmp_path / "nan.toml"
    nan_file.write_text("[[node]]\nname = 'x'\nmass = nan\n[analysis]\ntype = 'static'\n")
    with pytest.raises(SceneError, match=r"nan\.toml: node\[0\]\.mass: is nan"):
        load(nan_file)


def test_every_catalogue_scene_is_valid():
    from martello.scene import catalogue
    files = catalogue.scene_files()
    assert files, "the catalogue must not be empty"
    for f in files:
        load(f)


@pytest.mark.parametrize("check,field,words", [
    ({"closed_form": "field", "params": {}, "compare": []}, "check.closed_form", "public function"),
    ({"closed_form": "math", "params": {}, "compare": []}, "check.closed_form", "public function"),
    ({"closed_form": "linear_contact_time", "params": {"mstar": 1.0, "k": 1.0},
      "compare": [{"result": "nodes.mass.u", "oracle": "u", "rtol": 1e-9, "why": "w"}]},
     "check.closed_form", "named values"),
    ({"closed_form": "mass_on_plane_static", "params": {"m": 1.0},
      "compare": [{"result": "nodes.mass.u", "oracle": "u", "rtol": 1e-9, "why": "w"}]},
     "check.params", "parameters"),
    ({"closed_form": "mass_on_plane_static", "params": {"m": 1.0, "k": 100.0, "h": 0.05, "g": 9.81},
      "compare": [{"result": "nodes.mass.u", "oracle": "nope", "rtol": 1e-9, "why": "w"}]},
     "check.compare[0].oracle", "valid:"),
    ({"closed_form": "mass_on_plane_static", "params": {"m": 1.0, "k": 100.0, "h": 0.05, "g": 9.81},
      "compare": [{"result": "nodes.ball.u", "oracle": "u", "rtol": 1e-9, "why": "w"}]},
     "check.compare[0].result", "dotted path"),
])
def test_check_table_errors_name_the_field(check, field, words):
    from martello.checks.verify import verify
    from martello.run import run
    d = p1_dict()
    d["check"] = check
    s = from_dict(d, source="chk.toml")
    with pytest.raises(SceneError) as info:
        verify(s, run(s))
    assert info.value.field == field and words in str(info.value), str(info.value)


def test_static_run_names_what_it_ignores():
    from martello.run import run
    d = p1_dict()
    d["node"][0]["v0"] = 1.0
    d["link"].append({"type": "dashpot", "a": "mass", "b": "ground", "c": 1.0})
    w = run(from_dict(d))["warnings"]
    assert any("static analysis ignores: dashpots and fluid dampers, initial velocities" in x for x in w), w
