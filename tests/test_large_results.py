"""What a large scene's run writes (docs/results.md): the phases of each contact are listed only
for the contacts named in output.contacts once a scene has more than 1000 contacts, and the
summary of more than 10 000 items is written on one line. Identities of the summary: the first
and last phase of a contact are the first and last entries of the lists it would have had."""

import json

from martello.run import run, write_results
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


def test_a_summary_of_more_than_ten_thousand_items_is_one_line(tmp_path):
    s = run(chain())
    assert len(s["nodes"]) + len(s["contacts"]) + len(s["links"]) < 10_000
    write_results(s, tmp_path / "small")
    assert (tmp_path / "small" / "summary.json").read_text().count("\n") > 1000
    s["links"].update({f"extra{i}": {"type": "spring", "max_abs_force": 1.0, "max_abs_elongation": 0.1}
                       for i in range(8000)})
    write_results(s, tmp_path / "large")
    text = (tmp_path / "large" / "summary.json").read_text()
    assert text.count("\n") == 1 and json.loads(text)["links"]["extra7"]["max_abs_force"] == 1.0
