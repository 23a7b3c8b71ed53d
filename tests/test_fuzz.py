"""Property-based fuzzing (Hypothesis) of the scene loader and of the command line, on the
mutations of the fuzz campaign (benchmarks/fuzz/mutations.py: mutated catalogue scenes,
records, histories, check tables, study files and command lines).

* The loader, in this process: a mutated scene (as a dict, or as damaged TOML text) loads,
  or raises a MartelloError whose message is one line; no other exception.
* `python -m martello ...` on a mutated case: exit 0 with a complete result, or exit 1 with
  one line on stderr, no traceback, and nothing written (benchmarks/fuzz/campaign.py's
  classify); never a crash, and an end within the timeout.

Derandomized, so CI sees the same cases every time; bounded to about a minute. The campaign
(scripts/fuzz) draws many more."""

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings, strategies as st

from benchmarks.fuzz import campaign, mutations
from martello.errors import MartelloError
from martello.scene import catalogue
from martello.scene.loader import from_dict, load

ROOT = Path(__file__).resolve().parent.parent
SCENES = [str(f.relative_to(ROOT / "benchmarks").with_suffix("")) for f in catalogue.scene_files()]


def fuzz(examples):
    return settings(derandomize=True, database=None, deadline=None, max_examples=examples,
                    suppress_health_check=list(HealthCheck))


class DrawChooser:
    """The campaign's chooser, drawing from Hypothesis (so failing cases shrink)."""

    def __init__(self, data):
        self.data = data

    def choice(self, seq):
        return seq[self.data.draw(st.integers(0, len(seq) - 1))]

    def integer(self, lo, hi):
        return self.data.draw(st.integers(lo, hi))

    def coin(self, p=0.5):
        return self.data.draw(st.integers(0, 999)) < 1000 * p


def assert_clean(exc):
    msg = str(exc)
    assert msg and "\n" not in msg, repr(msg)


@fuzz(2000)
@given(st.data())
def test_loader_on_mutated_scenes_loads_or_raises_one_line(data):
    ch = DrawChooser(data)
    name = ch.choice(SCENES)
    d = mutations.scene_dict(name)
    if ch.coin(0.5):
        d = mutations.mutate_dict(ch, d)
    else:
        label = ch.choice(sorted(mutations.TARGETED))
        try:
            mutations.TARGETED[label](d, ch)
        except (AttributeError, TypeError, IndexError, KeyError):
            pass
        if isinstance(d.get("description"), mutations.Deep):
            d["description"] = "x"        # deep nesting is the text test's (a dict cannot hold it)
    src = ROOT / "benchmarks" / f"{name}.toml"
    try:
        from_dict(d, source=str(src), base_dir=src.parent)
    except MartelloError as exc:
        assert_clean(exc)


@fuzz(1000)
@given(st.data())
def test_loader_on_damaged_text_loads_or_raises_one_line(data):
    ch = DrawChooser(data)
    name = ch.choice(SCENES)
    text = (ROOT / "benchmarks" / f"{name}.toml").read_text()
    damaged = mutations.mutate_text(ch, text)
    with tempfile.TemporaryDirectory() as tmp:
        f = Path(tmp) / "s.toml"
        f.write_bytes(damaged)
        try:
            load(f)
        except MartelloError as exc:
            assert_clean(exc)


ENV = dict(os.environ, PYTHONDONTWRITEBYTECODE="1", OPENBLAS_NUM_THREADS="1")


@fuzz(int(os.environ.get("MARTELLO_FUZZ_RUNS", "60")))
@given(st.data())
def test_command_line_on_hostile_cases_fails_cleanly(data):
    case = mutations.make_case(DrawChooser(data))
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        mutations.lay_out(case, folder)
        before = campaign.snapshot(folder)
        try:
            proc = subprocess.run([sys.executable, "-m", "martello", *case.argv], cwd=folder,
                                  env=ENV, capture_output=True, text=True, errors="replace",
                                  timeout=120, stdin=subprocess.DEVNULL)
        except subprocess.TimeoutExpired:
            pytest.fail(f"{case.argv}: no end within 120 s")
        cls, detail = campaign.classify(case, proc, before, campaign.snapshot(folder), folder)
    assert cls in ("ok", "clean error"), (case.label, case.argv, cls, detail, proc.stderr[-800:])


def test_the_classifier_tells_a_traceback_and_a_write_from_a_clean_error(tmp_path):
    """The fuzz property can fail: classify() on made-up outcomes."""
    case = mutations.Case("run", ["run", "s.toml", "-o", "out"], {}, "out")
    P = lambda rc, err="", out="": subprocess.CompletedProcess([], rc, out, err)  # noqa: E731
    clean = "martello: error: s.toml: loads: must be a table (write [loads])\n"
    assert campaign.classify(case, P(1, clean), {}, {}, tmp_path)[0] == "clean error"
    assert campaign.classify(case, P(1, clean), {}, {"out": (0, 1)}, tmp_path)[0] == "unclean error"
    assert campaign.classify(case, P(1, "Traceback (most recent call last):\n  x\nE: y\n"),
                             {}, {}, tmp_path)[0] == "traceback"
    assert campaign.classify(case, P(1, "martello: internal error: KeyError: 'x' (...)\n"),
                             {}, {}, tmp_path)[0] == "traceback"
    assert campaign.classify(case, P(-11), {}, {}, tmp_path) == ("crash", "signal SIGSEGV")
    assert campaign.classify(case, P(0), {}, {}, tmp_path)[0] == "suspicious ok"
    assert campaign.classify(case, P(1, clean * 2), {}, {}, tmp_path)[0] == "unclean error"


def test_the_classifier_reads_what_an_exit_0_run_wrote_back(tmp_path):
    """An exit-0 case is "ok" only if its output reads back (benchmarks/fuzz/roundtrip.py):
    a history.csv whose header compare cannot read, a summary or scores with NaN, an exported
    model with a convergence tolerance of 0 or unclosed Tcl, a runs.csv plot cannot read are
    "round trip failed"; martello's own results of the same scene are "ok"."""
    from martello.export import export
    P0 = subprocess.CompletedProcess([], 0, "", "")
    scene_text = (ROOT / "benchmarks" / "p5" / "p5_linear.toml").read_bytes()

    def folder(name, files):
        f = tmp_path / name
        mutations.lay_out(mutations.Case(name, [], {"a/b/scene.toml": scene_text, **files}), f)
        return f

    def verdict(argv, f, output=None):
        case = mutations.Case("x", argv, {}, output)
        return campaign.classify(case, P0, {}, {}, f)

    ok_summary = json.dumps({"status": "MARTELLO_OK"}).encode()
    good = "t,u:m1,u:m2,penetration:impact\n0,0,0,-1e-3\n1e-5,1e-5,0,-9.9e-4\n"
    run = ["run", "a/b/scene.toml", "-o", "out/run"]
    f = folder("good", {"out/run/summary.json": ok_summary, "out/run/history.csv": good.encode()})
    assert verdict(run, f, "out/run") == ("ok", "")
    # the class of a node named 'a,b' (history.csv's header split in two): exit 0, unreadable
    for n, bad in enumerate([good.replace("u:m2", "u:m2,b"), good.replace("u:m2", "u:m1"),
                             good.replace("1e-5,", "0,", 1)]):
        f = folder(f"badhist{n}", {"out/run/summary.json": ok_summary, "out/run/history.csv": bad.encode()})
        cls, detail = verdict(run, f, "out/run")
        assert cls == "round trip failed" and "history.csv" in detail, (bad, cls, detail)
    f = folder("nan", {"out/run/summary.json": b'{"status": "MARTELLO_OK", "x": NaN}'})
    assert verdict(run, f, "out/run")[0] == "round trip failed"

    # export: martello's own model reads back; the same with tol = 0 (what `export --tol 0`
    # wrote before the command line refused it) or with model.tcl cut does not
    from martello.scene.loader import load
    scene = load(ROOT / "benchmarks" / "p5" / "p5_linear.toml")
    ex = ["export", str(ROOT / "benchmarks" / "p5" / "p5_linear.toml"), "-o", "ex", "--tcl"]
    export(scene, tmp_path / "e1" / "ex", tcl=True)
    assert verdict(ex, tmp_path / "e1") == ("ok", "")
    export(scene, tmp_path / "e2" / "ex", tcl=True, tol=0.0)
    cls, detail = verdict(ex, tmp_path / "e2")
    assert cls == "round trip failed" and "ops.test" in detail, detail
    tcl = tmp_path / "e1" / "ex" / "model.tcl"
    text = tcl.read_text()
    tcl.write_text(text[:text.rindex("}")])                   # a block left open
    assert verdict(ex, tmp_path / "e1")[0] == "round trip failed"

    # compare's scores and a study's runs.csv
    cmp = ["compare", "h.csv", "--against", "a/b/scene.toml", "-o", "scores.json"]
    assert verdict(cmp, folder("s1", {"scores.json": b'{"scd": 3.5}'}))[0] == "ok"
    assert verdict(cmp, folder("s2", {"scores.json": b'{"scd": Infinity}'}))[0] == "round trip failed"
    study = ["study", "st.toml", "-o", "out/study"]
    runs = mutations.RUNS_CSV.encode()
    assert verdict(study, folder("t1", {"out/study/runs.csv": runs}))[0] == "ok"
    assert verdict(study, folder("t2", {"out/study/runs.csv": runs.replace(b"rtol,", b"", 1)}))[0] \
        == "round trip failed"


def test_the_campaign_cases_are_reproducible():
    a = mutations.make_case(campaign.RandomChooser("seed:7"))
    b = mutations.make_case(campaign.RandomChooser("seed:7"))
    assert (a.argv, a.files) == (b.argv, b.files)
    kinds = {mutations.make_case(campaign.RandomChooser(f"seed:{i}")).label.split(":")[0]
             for i in range(300)}
    assert kinds == {"run", "check", "compare", "study", "argv", "plot", "export"}


def test_the_fast_targeted_cases_have_their_outcome(tmp_path):
    """A sample of the targeted campaign (benchmarks/fuzz/targeted.py; all of it:
    scripts/fuzz --targeted): the cases that end in about a second, each with the outcome it
    must have."""
    import argparse
    from benchmarks.fuzz import targeted
    fast = [c for c in targeted.cases() if c.sigint_after is None and c.timeout <= 60
            and c.argv[0] in ("run", "plot") and "--progress" not in c.argv]
    assert len(fast) >= 10
    args = argparse.Namespace(python=sys.executable, memory=4.0, keep=False, out=str(tmp_path / "r"))
    env = dict(ENV, MARTELLO_LIB=str(ROOT / "build" / "libmartello.so"))
    real = targeted.cases
    targeted.cases = lambda: fast
    try:
        assert campaign.targeted_campaign(args, env, tmp_path / "work") == 0
    finally:
        targeted.cases = real
