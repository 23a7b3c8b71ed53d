"""The Python API (docs/python-api.md, martello/api.py): the page's examples run as written;
load, Scene.from_dict, run -> Result, reference, compare and closed_forms give what the
command line gives; the package's names load lazily; bad input is one clear message."""

import copy
import os
import inspect
import json
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import martello
from martello.errors import MartelloError, SceneError
from martello.reference.base import ReferenceError
from tests.conftest import p1_dict

ROOT = Path(__file__).resolve().parent.parent
DOC = ROOT / "docs" / "python-api.md"
P2 = ROOT / "benchmarks" / "p2" / "p2_restitution_e08.toml"
P7 = ROOT / "benchmarks" / "p7" / "p7_two_oscillators.toml"


def python_blocks(text):
    return re.findall(r"^```python\n(.*?)^```", text, re.S | re.M)


def test_the_pages_examples_run_outside_the_checkout(tmp_path, monkeypatch, capsys):
    blocks = python_blocks(DOC.read_text())
    assert len(blocks) >= 6
    monkeypatch.chdir(tmp_path)            # catalogue paths work from anywhere
    namespace = {}
    for i, block in enumerate(blocks):
        exec(compile(block, f"{DOC.name}, python block {i + 1}", "exec"), namespace)
    out = capsys.readouterr().out
    assert "node[0].mass" in out           # the error the page shows names the field
    assert "reference/p7_two_oscillators" in out


def test_import_martello_is_cheap_and_names_load_on_use():
    code = ("import sys, martello\n"
            "before = sorted(m for m in sys.modules if m.startswith(('martello', 'scipy', 'numpy')))\n"
            "martello.closed_forms\n"
            "after = 'scipy' in sys.modules and 'martello.run' not in sys.modules\n"
            "print(before, after, sorted(dir(martello)) == sorted(set(dir(martello))))")
    r = subprocess.run([sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True,
                       check=True)
    # closed_forms loads the oracles (scipy), not the run layer nor the library
    assert r.stdout.split() == ["['martello']", "True", "True"]
    assert set(martello.__all__) <= set(dir(martello))


def test_unknown_attribute_is_an_attribute_error():
    with pytest.raises(AttributeError, match="no attribute 'nope'"):
        martello.nope


def test_load_a_file_or_a_catalogue_path(tmp_path, monkeypatch):
    s = martello.load(P2)
    assert isinstance(s, martello.Scene) and s.title.startswith("P2")
    monkeypatch.chdir(tmp_path)
    for name in ("p2/p2_restitution_e08.toml", "benchmarks/p2/p2_restitution_e08.toml"):
        assert martello.load(name).digest == s.digest
    # a file where you are comes before the catalogue
    (tmp_path / "p2").mkdir()
    mine = (tmp_path / "p2" / "p2_restitution_e08.toml")
    mine.write_text(P2.read_text().replace('title = "P2', 'title = "mine'))
    assert martello.load("p2/p2_restitution_e08.toml").title.startswith("mine")
    assert martello.catalogue() and all(p.is_file() and p.suffix == ".toml"
                                        for p in martello.catalogue())
    assert P2.resolve() in [p.resolve() for p in martello.catalogue()]


def test_load_a_missing_file_names_the_fix(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    with pytest.raises(SceneError) as e:
        martello.load("p2/nope.toml")
    msg = str(e.value)
    assert "\n" not in msg and "p2/nope.toml" in msg and "martello.catalogue()" in msg


def test_from_dict_is_the_file_and_leaves_the_dict_alone():
    import tomllib
    with open(P2, "rb") as fh:
        d = tomllib.load(fh)
    before = copy.deepcopy(d)
    s = martello.Scene.from_dict(d)
    assert d == before
    f = martello.load(P2)
    assert (s.nodes, s.links, s.contacts, s.analysis, s.check) == \
        (f.nodes, f.links, f.contacts, f.analysis, f.check)


@pytest.mark.parametrize("bad,match", [
    ([1, 2], r"\(scene\): is a list \(give a dict of the scene file's tables"),
    ({"node": [{"name": "m", "mass": -1.0}]}, r"node\[0\]\.mass"),
])
def test_from_dict_bad_input_is_one_line(bad, match):
    with pytest.raises(SceneError, match=match) as e:
        martello.Scene.from_dict(bad)
    assert "\n" not in str(e.value)


def test_run_is_what_the_command_line_writes(tmp_path):
    from martello.cli import main
    assert main(["run", str(P2), "-o", str(tmp_path / "cli")]) == 0
    result = martello.run(P2)
    cli = json.loads((tmp_path / "cli" / "summary.json").read_text())
    for key in ("status", "nodes", "contacts", "energy", "t_reached"):
        assert result.summary[key] == cli[key], key
    header = (tmp_path / "cli" / "history.csv").read_text().splitlines()[0].split(",")
    data = np.loadtxt(tmp_path / "cli" / "history.csv", delimiter=",", skiprows=1)
    assert list(result.columns) == header
    np.testing.assert_array_equal(result.data, data)       # %.17g: bit for bit
    assert set(result.history) == set(header)
    np.testing.assert_array_equal(result.history["u:mass"], data[:, header.index("u:mass")])
    # write() is `martello run -o`
    result.write(tmp_path / "api")
    np.testing.assert_array_equal(
        np.loadtxt(tmp_path / "api" / "history.csv", delimiter=",", skiprows=1), data)
    assert "MARTELLO_OK" in repr(result) and f"{len(data)} samples" in repr(result)


def test_run_accepts_a_scene_a_path_or_a_dict():
    from_path = martello.run(str(ROOT / "benchmarks" / "p1" / "p1_static_lagrange.toml"))
    from_dict = martello.run(p1_dict())
    from_scene = martello.run(martello.Scene.from_dict(p1_dict()))
    for r in (from_path, from_dict, from_scene):
        assert r.status == "MARTELLO_OK" and r.columns == () and r.history == {}
    assert from_dict.summary["nodes"] == from_scene.summary["nodes"] == from_path.summary["nodes"]
    with pytest.raises(MartelloError, match="a static run has no history"):
        from_dict.dataframe()


def test_run_bad_input_is_one_line():
    with pytest.raises(MartelloError, match=r"scene: a int is not a scene \(give a Scene") as e:
        martello.run(42)
    assert "\n" not in str(e.value)


def test_a_failed_run_raises_and_returns_nothing():
    from martello.errors import SolverError
    d = p1_dict("penalty", law="linear", stiffness=1.0e6)
    d["analysis"] = {"type": "dynamic", "integrator": "central-difference", "dt": 1.0, "t_end": 10.0}
    with pytest.raises(SolverError):
        martello.run(d)


def test_dataframe_is_the_history():
    import pandas as pd
    r = martello.run(P2)
    df = r.dataframe()
    assert isinstance(df, pd.DataFrame) and list(df.columns) == list(r.columns)
    np.testing.assert_array_equal(df.to_numpy(), r.data)


def test_dataframe_without_pandas_says_what_to_install(monkeypatch):
    r = martello.run(P2)
    monkeypatch.setitem(sys.modules, "pandas", None)        # import pandas -> ImportError
    with pytest.raises(MartelloError, match="needs pandas: pip install pandas") as e:
        r.dataframe()
    assert "\n" not in str(e.value)


def test_run_reference_compare_are_the_modules_too():
    from martello.run import run_full
    import martello.compare as compare_module
    assert callable(martello.run) and martello.run.__name__ == "martello.run"
    assert martello.run.run_full is run_full and martello.compare is compare_module
    assert martello.reference.store.manifest           # the subpackage's modules
    assert list(inspect.signature(martello.run).parameters) == ["scene"]
    assert list(inspect.signature(martello.compare).parameters) == ["history", "against"]


def test_the_modules_are_callable_whatever_was_imported_first():
    # importing a submodule sets the package attribute of its name: it must stay callable
    code = ("import martello.checks.measures, martello.compare, martello.reference.store\n"
            "import martello\n"
            "print(martello.run('p1/p1_static_lagrange.toml').status, "
            "martello.reference('p7/p7_two_oscillators.toml').name)")
    r = subprocess.run([sys.executable, "-c", code], cwd=ROOT / "tests", capture_output=True,
                       text=True)
    assert r.returncode == 0, r.stderr
    assert r.stdout.split() == ["MARTELLO_OK", "reference/p7_two_oscillators"]


def test_reference_is_the_stored_data_or_the_closed_form():
    ref = martello.reference(P7)
    assert ref.kind == "data" and ref.name == "reference/p7_two_oscillators"
    assert ref.trusted_digits() > 5
    assert martello.reference(P2).kind == "closed-form"
    d = p1_dict("penalty", law="linear", stiffness=1.0e4)
    d["analysis"] = {"type": "dynamic", "integrator": "newmark", "dt": 1e-3, "t_end": 0.1}
    with pytest.raises(ReferenceError, match="no reference") as e:
        martello.reference(d, compute=False)
    assert "\n" not in str(e.value)


def test_compare_a_result_or_its_csv_is_the_command_line(tmp_path):
    result = martello.run(P7)
    result.write(tmp_path)
    subprocess.run([sys.executable, "-m", "martello", "compare", str(tmp_path / "history.csv"),
                    "--against", str(P7), "-o", str(tmp_path / "score.json")], cwd=ROOT,
                   capture_output=True, check=True)
    cli = json.loads((tmp_path / "score.json").read_text())
    for rep in (martello.compare(result, against=P7),
                martello.compare(tmp_path / "history.csv", against=martello.load(P7))):
        assert rep["reference"] == cli["reference"] == "reference/p7_two_oscillators"
        assert rep["score_scd"] == cli["score_scd"]
        assert rep["compared_columns"] == cli["compared_columns"]


def test_compare_against_a_dict_scene_names_the_fix():
    r = martello.run(P2)
    with pytest.raises(MartelloError, match="not a scene file .* write it as TOML") as e:
        martello.compare(r, against=martello.Scene.from_dict(p1_dict()))
    assert "\n" not in str(e.value)


def test_closed_forms_are_every_oracle_by_name():
    import inspect as _inspect
    import pkgutil
    from martello import oracles
    from martello.oracles import p5_contact_laws
    cf = martello.closed_forms
    assert cf.newton_impact is p5_contact_laws.newton_impact
    expected = set()
    for info in pkgutil.iter_modules(oracles.__path__):
        mod = __import__(f"martello.oracles.{info.name}", fromlist=["x"])
        expected |= {n for n, f in vars(mod).items() if _inspect.isfunction(f)
                     and f.__module__ == mod.__name__ and not n.startswith("_")}
    assert expected and expected <= set(cf.__all__)
    # a value from the page of problems: two equal masses, one at rest, e = 1/2 (Newton)
    r = cf.newton_impact(1.0, 1.0, 1.0, 0.0, 0.5)
    assert (r.v1, r.v2) == (0.25, 0.75)


def test_reference_of_a_scene_with_none_stored_is_computed_and_cached(tmp_path, monkeypatch):
    """martello.reference of a dict scene outside the catalogue (m = 2 kg on k = 200 N/m from
    u0 = 1 cm: u = u0 cos(10 t), the closed form is the independent oracle) computes the
    reference as `martello reference` does, into the user cache, and reuses it. rk8pd at rtol
    1e-12 on a smooth oscillation: 1e-9 of the amplitude is far above its error."""
    import numpy as np
    import martello
    from martello.reference.base import ReferenceError
    monkeypatch.setenv("MARTELLO_CACHE_DIR", str(tmp_path / "cache"))
    d = {"node": [{"name": "m", "mass": 2.0, "u0": 0.01}],
         "link": [{"type": "spring", "a": "m", "b": "ground", "k": 200.0}],
         "analysis": {"type": "dynamic", "integrator": "newmark", "dt": 1e-3, "t_end": 2.0}}
    with pytest.raises(ReferenceError, match="compute=True computes one"):
        martello.reference(d, compute=False)
    ref = martello.reference(d, stream=open(os.devnull, "w"))
    assert ref.kind == "data" and ref.name.startswith("computed reference")
    assert ref.trusted_digits() > 8
    t = np.linspace(0.0, 2.0, 201)
    assert np.max(np.abs(ref.at(t, ["u:m"])["u:m"] - 0.01 * np.cos(10.0 * t))) < 1e-11
    key = ref.provenance["cache_key"]
    assert (tmp_path / "cache" / "references" / key / "history.csv").is_file()
    again = martello.reference(d)            # from the cache: the same stored samples
    assert again.provenance["cache_key"] == key and again.provenance["date"] == ref.provenance["date"]
