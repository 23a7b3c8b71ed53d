"""What a large scene's run writes (docs/results.md): the phases of each contact are listed only
for the contacts named in output.contacts once a scene has more than 1000 contacts, and a scene
of more than 10 000 items writes them as arrays (results.npz). Identities of the summary: the
first and last phase of a contact are the first and last entries of the lists it would have
had; an item read from the arrays is its entry in summary.json."""

import json

import numpy as np
import pytest

from martello import results
from martello.checks.verify import lookup
from martello.errors import ResultError, SceneError
from martello.run import run, run_full, write_results
from martello.scene.loader import from_dict

N = 1002          # 1001 contacts: past the 1000 of docs/results.md


def chain(named=("b1-b2",)):
    return from_dict({
        "chain": [{"prefix": "b", "n": N, "mass": 1.0,
                   "k": [100.0 if i % 2 == 0 else 400.0 for i in range(N)], "zeta": 0.05,
                   "gap": 0.001, "contact": {"scheme": "penalty", "law": "linear", "stiffness": 1e5}}],
        "loads": {"ground_acceleration": {"type": "sine", "amplitude": 3.0, "omega": 8.0}},
        "analysis": {"type": "dynamic", "integrator": "newmark", "dt": 1e-3, "t_end": 2.0,
                     "output": {"every": 100, "nodes": ["b1"], "contacts": list(named)}}})


def test_a_large_scene_lists_the_phases_of_the_named_contacts_only():
    s = run(chain())
    named, other = s["contacts"]["b1-b2"], s["contacts"]["b3-b4"]
    assert named["impacts"] >= 2 and other["impacts"] >= 2     # the scene pounds
    assert len(named["impact_times"]) == named["impacts"]
    assert "impact_times" not in other and "restitution" not in other
    assert other["first_phase"]["impact_time"] < other["last_phase"]["impact_time"]
    # the same contact named: its lists begin and end with the phases reported alone
    full = run(chain(named=("b3-b4",)))["contacts"]["b3-b4"]
    first, last = other["first_phase"], other["last_phase"]
    assert first["impact_time"] == full["impact_times"][0]
    assert first["separation_time"] == full["separation_times"][0]
    assert first["max_force"] == full["phase_max_force"][0]
    assert last["impact_time"] == full["impact_times"][-1]
    assert last["approach_speed"] == full["approach_speeds"][-1]


def big_chain(n=3400, track=("all",)):
    """n + 2n + (n - 1) items: past the 10 000 of docs/results.md for n = 3400; every result
    tracked unless track says (None: the large scene's default)."""
    output = {"every": 100, "nodes": ["b7"], "contacts": ["b7-b8"], "links": ["b7.spring"]}
    if track is not None:
        output["track"] = list(track)
    return from_dict({
        "chain": [{"prefix": "b", "n": n, "mass": 1.0,
                   "k": [100.0 if i % 2 == 0 else 400.0 for i in range(n)],
                   "zeta": [0.05 if i % 3 else 0.0 for i in range(n)], "fy": 1.0, "hardening": 0.1,
                   "gap": 0.001, "contact": {"scheme": "penalty", "law": "linear", "stiffness": 1e5}}],
        "loads": {"ground_acceleration": {"type": "sine", "amplitude": 3.0, "omega": 8.0}},
        "analysis": {"type": "dynamic", "integrator": "newmark", "dt": 1e-3, "t_end": 0.5,
                     "output": output}})


def test_a_large_scene_writes_its_items_as_arrays_and_names_those_of_output(tmp_path, monkeypatch):
    """Identity of the method: every item's entry read back from results.npz is the entry the
    same run writes into summary.json when the scene counts as small."""
    scene = big_chain()
    assert 10_000 < len(scene.nodes) + len(scene.links) + len(scene.contacts)
    s, history = run_full(scene)
    write_results(s, tmp_path / "large", history)
    assert sorted(p.name for p in (tmp_path / "large").iterdir()) == ["history.csv", "results.npz",
                                                                      "summary.json"]
    small_text = (tmp_path / "large" / "summary.json").read_text()
    assert len(small_text) < 20_000
    back = results.read_summary(tmp_path / "large")
    assert list(back["nodes"]) == ["b7"] and list(back["contacts"]) == ["b7-b8"] \
        and list(back["links"]) == ["b7.spring"]
    monkeypatch.setattr(results, "ARRAY_ITEMS", 10 ** 9)
    full = json.loads(json.dumps(run(scene)))
    assert "arrays" not in full
    arrays = back["arrays"]
    for kind in ("nodes", "links", "contacts"):
        assert arrays[kind]["count"] == len(full[kind])
        got = arrays.entries(kind, range(len(full[kind])))
        for name, entry in full[kind].items():
            if name in back[kind]:           # the named items, as the small form has them
                assert back[kind][name] == entry
                continue
            assert got[name] == entry, (kind, name)
    # it meets contacts that never closed, closed and opened, and are closed at the end
    impacts = arrays.column("contacts", "impacts")
    open_at_end = ~np.isnan(arrays.column("contacts", "last.impact_time")) & \
        np.isnan(arrays.column("contacts", "last.separation_time"))
    assert (impacts == 0).any() and (impacts > 1).any() and open_at_end.any()
    assert lookup(back, "nodes.b3000.u_max") == full["nodes"]["b3000"]["u_max"]
    assert lookup(back, "links.b3000.damper.max_abs_force") == \
        full["links"]["b3000.damper"]["max_abs_force"]


def test_a_large_scene_tracks_its_contact_maxima_unless_output_track_says(tmp_path):
    """Identity of the method: what a large scene tracks by default (docs/results.md, "What a
    large scene tracks") is written bit for bit as a run that tracks everything writes it, the
    rest is absent (no column, no key); output.track asks for more."""
    everything = run(big_chain())
    s, history = run_full(big_chain(track=None))
    assert s["tracked"] == ["contact_peaks"] and everything["tracked"] == \
        ["node_peaks", "link_peaks", "contact_peaks", "phases"]
    write_results(s, tmp_path / "run", history)
    back = results.read_summary(tmp_path / "run")
    arrays, full = back["arrays"], everything["arrays"]
    assert arrays["nodes"]["columns"] == [] and arrays["links"]["columns"] == ["type"]
    assert arrays["contacts"]["columns"] == ["scheme", "law", "max_penetration", "max_force",
                                             "impacts"]
    for column in arrays["contacts"]["columns"]:
        assert np.array_equal(arrays.column("contacts", column), full.column("contacts", column))
    assert arrays.column("contacts", "impacts").sum() > 0          # the chain pounds
    assert set(back["nodes"]["b7"]) == {"u_final", "v_final"}
    assert "impact_times" not in back["contacts"]["b7-b8"] and "first_phase" not in back["contacts"]["b7-b8"]
    assert set(back["links"]["b7.spring"]) == {"type"}
    some = run(big_chain(track=("node_peaks", "phases")))
    assert some["tracked"] == ["node_peaks", "phases"]
    assert "max_penetration" not in some["arrays"]["contacts"]["columns"]
    assert np.array_equal(some["arrays"].column("nodes", "a_absmax"), full.column("nodes", "a_absmax"))
    assert some["contacts"]["b7-b8"]["impact_times"] == everything["contacts"]["b7-b8"]["impact_times"]
    with pytest.raises(SceneError, match=r"analysis\.output\.track\[0\]: unknown value 'peaks' "
                                         r"\(valid: node_peaks, link_peaks, contact_peaks, phases, all\)"):
        big_chain(track=("peaks",))


def test_a_large_scene_with_a_value_that_is_not_finite_writes_nothing(tmp_path):
    s = run(big_chain())
    s["arrays"].columns["nodes"]["u_max"][1234] = float("inf")
    with pytest.raises(ResultError, match=r"nodes\.b1235\.u_max is inf: a result must be finite"):
        write_results(s, tmp_path / "out")
    assert not (tmp_path / "out").exists()


def test_a_run_folder_without_its_arrays_is_refused_by_name(tmp_path):
    s, history = run_full(big_chain(n=3400))
    write_results(s, tmp_path / "run", history)
    (tmp_path / "run" / "results.npz").unlink()
    with pytest.raises(ResultError, match=r"results\.npz: cannot be read .*run the scene again"):
        results.read_summary(tmp_path / "run")


def test_martello_run_writes_and_names_the_arrays_of_a_large_scene(tmp_path):
    import subprocess
    import sys
    scene = tmp_path / "chain.toml"
    scene.write_text('[[chain]]\nprefix = "b"\nn = 3400\nmass = 1.0\nk = 100.0\nzeta = 0.05\n'
                     'gap = 0.001\ncontact = { scheme = "penalty", stiffness = 1e5 }\n'
                     '[loads.ground_acceleration]\ntype = "sine"\namplitude = 3.0\nomega = 8.0\n'
                     '[analysis]\ntype = "dynamic"\nintegrator = "newmark"\ndt = 1e-3\nt_end = 0.1\n')
    r = subprocess.run([sys.executable, "-m", "martello", "run", scene, "-o", tmp_path / "out"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip().endswith("history.csv and " + str(tmp_path / "out" / "results.npz"))
    import martello
    back = martello.read(tmp_path / "out")
    assert back.summary["nodes"] == {} and back.arrays["nodes"]["count"] == 3400
    assert back.item("links", "b3400.damper")["type"] == "dashpot"
