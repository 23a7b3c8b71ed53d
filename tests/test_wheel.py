"""The wheel as a user gets it (docs/install.md): `pip wheel .` (scikit-build-core drives
CMake), installed into a fresh virtual environment, and the installed `martello check` run
from a folder outside the checkout: exit code 0 and every reference-data check verified
against the data the wheel carries, with the library the wheel carries.

Fast enough for every run: the CMake build directory persists in build/wheel
(scikit-build-core's build-dir), so a rebuild compiles only what changed (seconds when
nothing did); --no-build-isolation uses the scikit-build-core of .venv (requirements.txt);
the fresh environment is made without pip and takes numpy, scipy and matplotlib from this
test's environment through a .pth line, while pip installs the wheel alone (--no-deps
--no-index): no network, and nothing of the checkout on its path."""

import csv
import json
import os
import subprocess
import sys
import sysconfig
import zipfile
from pathlib import Path

import pytest

from martello.binding import native
from martello.reference.store import manifest
from martello.scene.catalogue import scene_files

ROOT = Path(__file__).resolve().parent.parent


def sh(*cmd, **kw):
    r = subprocess.run([str(c) for c in cmd], capture_output=True, text=True, **kw)
    assert r.returncode == 0, f"{' '.join(map(str, cmd))} failed:\n{r.stdout}\n{r.stderr}"
    return r.stdout


@pytest.fixture(scope="module")
def wheel(tmp_path_factory):
    out = tmp_path_factory.mktemp("wheel")
    sh(sys.executable, "-m", "pip", "wheel", ROOT, "--no-build-isolation", "--no-deps",
       "--disable-pip-version-check", "-q", "-w", out, "-C", f"build-dir={ROOT / 'build' / 'wheel'}")
    (path,) = out.glob("martello-*.whl")
    return path


@pytest.fixture(scope="module")
def venv(wheel, tmp_path_factory):
    env_dir = tmp_path_factory.mktemp("venv")
    sh(sys.executable, "-m", "venv", "--without-pip", env_dir)
    python = env_dir / "bin" / "python"
    site = sh(python, "-c", "import sysconfig; print(sysconfig.get_paths()['purelib'])").strip()
    # the dependencies from here (a path line: the .pth files there are not run, so nothing
    # of this environment's own martello comes along)
    Path(site, "dependencies.pth").write_text(sysconfig.get_paths()["purelib"] + "\n")
    sh(sys.executable, "-m", "pip", "--python", python, "install", "--no-deps", "--no-index",
       "--disable-pip-version-check", "-q", wheel)
    return env_dir


def clean_env():
    """The environment of a user's shell: no MARTELLO_LIB, no PYTHONPATH into the checkout."""
    return {k: v for k, v in os.environ.items() if k not in ("MARTELLO_LIB", "PYTHONPATH")}


def test_the_wheel_holds_the_library_the_catalogue_and_the_reference_data(wheel):
    names = set(zipfile.ZipFile(wheel).namelist())
    for f in ("martello/_native/lib/libmartello.so", "martello/_native/include/martello.h",
              "martello/_native/lib/cmake/martello/martello-config.cmake",
              "martello/_native/lib/pkgconfig/martello.pc", "martello/cli.py",
              f"martello-{native.version()}.dist-info/licenses/LICENSE"):
        assert f in names, f
    for p in scene_files():
        assert f"martello/data/{p.relative_to(ROOT).as_posix()}" in names, p
    for e in manifest():
        for f in ("reference.json", "history.csv"):
            assert f"martello/data/reference/{e['name']}/{f}" in names, (e["name"], f)
    assert "martello/data/reference/references.toml" in names
    # one library file (a zip has no symbolic links), no checkout scripts among the data
    assert [n for n in names if "libmartello" in n] == ["martello/_native/lib/libmartello.so"]
    assert not [n for n in names if n.startswith("martello/data/") and n.endswith(".py")]
    meta = zipfile.ZipFile(wheel).read(f"martello-{native.version()}.dist-info/METADATA").decode()
    assert f"Version: {native.version()}\n" in meta
    for dep in ("numpy", "scipy", "matplotlib"):
        assert f"Requires-Dist: {dep}\n" in meta


def test_the_installed_package_uses_its_own_library_and_data(venv, tmp_path):
    code = ("import martello, martello.paths as p, martello.binding.native as n\n"
            "print(n.library_path()); print(p.REPO); print(martello.__version__)\n"
            "print(martello.run('p1/p1_static_lagrange.toml').status)")
    lib, data, version, status = sh(venv / "bin" / "python", "-c", code, cwd=tmp_path,
                                    env=clean_env()).split()
    site = Path(sh(venv / "bin" / "python", "-c", "import sysconfig; "
                   "print(sysconfig.get_paths()['platlib'])").strip())
    assert Path(lib) == site / "martello" / "_native" / "lib" / "libmartello.so"
    assert Path(data) == site / "martello" / "data"
    assert version == native.version() and status == "MARTELLO_OK"
    # the paths `martello list` prints name the installed catalogue from any folder
    listed = sh(venv / "bin" / "martello", "list", cwd=tmp_path, env=clean_env()).split()
    assert "benchmarks/p2/p2_restitution_e08.toml" in listed
    sh(venv / "bin" / "martello", "run", "benchmarks/p2/p2_restitution_e08.toml", "-o", "p2",
       cwd=tmp_path, env=clean_env())
    assert json.loads((tmp_path / "p2" / "summary.json").read_text())["status"] == "MARTELLO_OK"


def test_the_installed_check_verifies_every_reference(venv, tmp_path):
    # the whole catalogue (449 scenes: ~4 min alone on 2 cores, ~11 at a load of 10): the
    # timeout of tests/test_cli.py's catalogue run
    r = subprocess.run([venv / "bin" / "martello", "check", "-o", tmp_path / "check", "--no-plots"],
                       cwd=tmp_path, env=clean_env(), capture_output=True, text=True, timeout=1800)
    assert r.returncode == 0, r.stdout[-3000:] + r.stderr
    rows = list(csv.DictReader(open(tmp_path / "check" / "verification.csv")))
    # every asserted row passed (an unconverged row has no bound: nothing is asserted)
    assert rows and all(row["passed"] == "True" for row in rows if row["kind"] != "unconverged")
    # verification counts only rows against an oracle independent of the solvers (a closed
    # form, the independent engine) with a tolerance < 1 % (martello.checks.kinds): the
    # headline's numbers are recounted here from the rows, kind by kind, so a headline that
    # counted loose, repeated or regression rows as verification fails
    by = {k: [row for row in rows if row["kind"] == k]
          for k in ("verification", "loose", "unconverged", "repeat", "regression")}
    assert len(rows) == sum(map(len, by.values()))
    ver = by["verification"]
    assert ver and all(row["evidence"] in ("closed form", "published value", "independent reference")
                       and float(row["tolerance_relative"]) < 0.01 for row in ver)
    closed = sum(row["evidence"] == "closed form" for row in ver)
    published = sum(row["evidence"] == "published value" for row in ver)
    assert (f"verification: {len(ver)} of {len(ver)} distinct rows passed ({closed} vs closed form, "
            f"{published} vs published value, {len(ver) - closed - published} vs independent reference; "
            "tolerance < 1 %)") in r.stdout
    n = {k: len(v) for k, v in by.items()}
    assert (f"not counted: {n['loose']} of {n['loose']} loose rows (tolerance 1-10 %) passed, "
            f"{n['unconverged']} unconverged (no bound: nothing asserted), {n['repeat']} repeats of "
            f"identical elements, {n['regression']} of {n['regression']} regression rows passed; "
            "0 failure(s)") in r.stdout
    # every reference stored for a catalogue scene as it is (no contact override) verified it
    verified = {row["quantity"].split(" vs ")[1] for row in rows if " vs reference/" in row["quantity"]}
    listed = {f"reference/{e['name']}" for e in manifest() if not e.get("contact")}
    assert listed and verified == listed
    # the installed catalogue was run, not the checkout's
    assert all("/martello/data/benchmarks/" in row["file"] for row in rows)
