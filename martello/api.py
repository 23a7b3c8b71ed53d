"""The Python API (docs/python-api.md): what the command line does, from a script or a
notebook, on scenes given as files, catalogue names or dicts.

``import martello`` stays cheap: martello/__init__.py makes these names attributes of the
package lazily; this module is imported the first time one of them is used, and each function
imports what it needs (the run layer, the checks, scipy) when it is first called.

* ``load(path)``, ``Scene.from_dict(d)``: a validated Scene;
* ``run(scene) -> Result``: the summary (a dict, what summary.json holds), the history
  (numpy arrays, ``Result.dataframe()`` with pandas) and a large scene's per-item arrays;
* ``read(folder)``: the Result a run folder holds;
* ``reference(scene)``: the Reference the scene is scored against;
* ``compare(history, against)``: another code's history scored against a scene's reference,
  as ``martello compare`` does;
* ``study(file)`` -> ``StudyResult``, ``check(scenes)`` -> ``CheckResult``, ``plot(folder)``:
  what ``martello study``, ``martello check`` and ``martello plot`` do, their rows given back;
* ``catalogue()``: the catalogue's scene files.

(``martello.closed_forms``, the oracles by name, is a module of its own: martello/closed_forms.py.)

``martello.run``, ``martello.reference``, ``martello.compare``, ``martello.study`` and
``martello.plot`` are also the names of the package's modules (martello/run.py,
martello/reference/, martello/compare.py, martello/study/, martello/plot.py): the package
gives back those modules made callable (martello/__init__.py), and a call goes to the
function of the same name here, so ``martello.run(scene)`` runs a scene and
``from martello.run import run_full`` keeps working."""

from __future__ import annotations

import tempfile
from pathlib import Path

import numpy as np

from .errors import MartelloError, SceneError
from .scene import catalogue as _catalogue
from .scene.loader import Scene

# The run layer (the native library), the checks, the references and compare (scipy) are
# imported by the functions that need them: martello.load and martello.Scene stay light.

__all__ = ["CheckResult", "Result", "Scene", "StudyResult", "catalogue", "check", "compare", "load",
           "plot", "read", "reference", "run", "study"]


def catalogue():
    """The catalogue's scene files (benchmarks/, one problem variant each), sorted: the
    paths ``martello list`` prints, absolute."""
    return list(_catalogue.scene_files())


def load(path):
    """A validated Scene from a scene file (TOML, docs/scene-input.md).

    ``path`` is a file, or a path inside the catalogue such as ``"p2/p2_restitution_e08.toml"``
    (found in benchmarks/ of the checkout or of the installed package) when no such file
    exists where you are. Errors (SceneError) name the file, the field and the fix."""
    p = _catalogue.find(path)
    if not p.exists():
        raise SceneError(p, "(file)", "does not exist here nor in the catalogue",
                         "give a scene file, or a catalogue path such as "
                         "p2/p2_restitution_e08.toml (martello.catalogue() lists them)")
    return Scene.load(p)


def _scene(scene, what="scene"):
    if isinstance(scene, Scene):
        return scene
    if isinstance(scene, dict):
        return Scene.from_dict(scene)
    if isinstance(scene, (str, Path)):
        return load(scene)
    raise MartelloError(f"{what}: a {type(scene).__name__} is not a scene (give a Scene, a scene "
                        "file or catalogue path, or a dict of the scene's tables)")


class Result:
    """What ``martello.run`` gives back: the scene, its summary and its history.

    ``summary`` is the dict ``martello run`` writes as summary.json (docs/results.md):
    ``status``, ``nodes``, ``contacts``, ``energy``, ``cost``, ``provenance``, ...
    For a dynamic run, ``columns`` names the history's columns (``t``, ``u:<node>``,
    ``force:<contact>``, ... as in history.csv), ``data`` is the 2D array (one row per
    sample) and ``history`` the same as {column: 1D array}; a static run has none."""

    def __init__(self, scene, summary, history=None):
        self.scene = scene               # None for a Result read from a folder (read())
        self.summary = summary
        if history is None:
            self.columns, self.data = (), np.empty((0, 0))
        else:
            self.columns, self.data = tuple(history[0]), np.asarray(history[1], float)

    @property
    def status(self):
        """The run's status, e.g. ``MARTELLO_OK``."""
        return self.summary["status"]

    @property
    def arrays(self):
        """A large scene's per-item results as arrays (martello.results.ItemArrays: its
        ``table("nodes")`` is {"name": names, "u_max": array, ...}, ``item("nodes", name)``
        one entry); None for a scene whose summary holds every item (docs/results.md)."""
        from .results import ItemArrays
        arrays = self.summary.get("arrays")
        return arrays if isinstance(arrays, ItemArrays) else None

    def item(self, kind, name):
        """The entry of one node, link or contact ("nodes", "links", "contacts") by name, from
        the summary or, for a large scene, its arrays."""
        from .results import lookup_item
        return lookup_item(self.summary, kind, name)

    @property
    def history(self):
        """{column: 1D array} (views of ``data``); empty for a static run."""
        return {c: self.data[:, i] for i, c in enumerate(self.columns)}

    def dataframe(self):
        """The history as a pandas DataFrame, one column per history column (``t``
        included). Needs pandas (``pip install martello[pandas]``)."""
        if not self.columns:
            raise MartelloError(f"{self.scene.source}: a static run has no history (its values "
                                "are in Result.summary['nodes'] and ['contacts'])")
        try:
            import pandas
        except ImportError:
            raise MartelloError("Result.dataframe() needs pandas: pip install pandas (the "
                                "history is also in Result.history as numpy arrays)") from None
        return pandas.DataFrame(self.data, columns=list(self.columns))

    def write(self, folder):
        """Write summary.json (and history.csv) into folder, as ``martello run -o folder``;
        returns the path of summary.json."""
        from .run import write_results
        history = (list(self.columns), self.data) if self.columns else None
        return write_results(self.summary, Path(folder), history)

    def __repr__(self):
        shape = f", {len(self.data)} samples x {len(self.columns)} columns" if self.columns else ""
        title = self.scene.title if self.scene is not None else self.summary.get("title")
        return f"<martello.Result {title!r}: {self.status}{shape}>"


def run(scene):
    """Run a scene's analysis; a ``Result``.

    ``scene`` is a Scene, a scene file or catalogue path (see ``load``) or a dict of the
    scene's tables (see ``Scene.from_dict``). The run is the one ``martello run`` makes,
    the problem's measures (P4) included. A failed run (diverged, unstable, not converged)
    raises SolverError, with the library's message; nothing is returned as if it were a
    result."""
    from .checks.measures import run_measured
    s = _scene(scene)
    summary, history = run_measured(s)
    return Result(s, summary, history)


def read(folder):
    """The ``Result`` of a run folder (``martello run -o folder``, ``Result.write``):
    summary.json, history.csv if any, and a large scene's results.npz (``Result.arrays``);
    its ``scene`` is None."""
    from .results import read_summary
    folder = Path(folder)
    summary = read_summary(folder)
    history, csv = None, folder / "history.csv"
    if csv.exists():
        with open(csv) as fh:
            columns = fh.readline().strip().split(",")
        history = (columns, np.loadtxt(csv, delimiter=",", skiprows=1, ndmin=2))
    return Result(None, summary, history)


def reference(scene, spec=None, *, compute=True, refresh=False, jobs=0, stream=None):
    """The Reference a scene is scored against (martello.reference.base.Reference):
    stored reference data for its physics (reference/references.toml), else the closed-form
    history its ``[check]`` implies, else — for any other dynamic scene, unless
    ``compute=False`` — one computed as ``martello reference`` does (docs/reference.md): the
    event-complete integrators and the independent engine, its trusted digits measured, kept
    in the user cache per scene hash (computed once; ``refresh=True`` recomputes it; ``jobs``
    processes; progress on ``stream``, default stderr). ``compute="always"`` takes the
    computed one even when stored data or a closed form exists.

    ``spec`` names another, as a study's ``reference`` entry does: ``{"closed_form": NAME,
    "params": {...}}`` or ``{"data": "reference/<name>"}``.

    ``ref.at(t, columns)`` evaluates it at times t; ``ref.trusted_digits()`` says how far it
    can be trusted; a computed one's ``ref.provenance`` holds its method, digits and cache
    key. Raises ReferenceError if the scene has none (a static scene, compute=False)."""
    from .reference.base import ReferenceError
    from .reference.selection import reference_for_scene
    s = _scene(scene)
    ref = None if compute == "always" else reference_for_scene(s, spec=spec)
    if ref is not None:
        return ref
    if not compute:
        raise ReferenceError(f"{s.source}: no reference: no closed-form history ([check]) and no "
                             "stored reference data for its physics (reference/references.toml); "
                             "compute=True computes one")
    from .reference import cache
    if isinstance(scene, dict):
        sdict = {k: v for k, v in scene.items() if k != "check"}
        where = Path.cwd() / "scene.toml"     # relative record paths: from here, as from_dict
        return cache.computed_reference(s, sdict, where, refresh=refresh, jobs=jobs,
                                        stream=stream)[0]
    if not Path(s.source).is_file():
        raise ReferenceError(f"{s.source}: a Scene made from a dict keeps no tables to compute a "
                             "reference from: give martello.reference the dict itself, or a file")
    return cache.reference_for_file(s.source, refresh=refresh, jobs=jobs, stream=stream)[0]


def compare(history, against):
    """Score a time history against a scene's reference, as ``martello compare HISTORY
    --against SCENE`` does (docs/compare.md); the report dict that command writes with -o
    (``score_scd``, ``metrics``, ``per_column``, ``checks``, ...).

    ``history`` is a CSV file in the documented format, or a ``Result`` (written to a
    temporary CSV first, so it is read exactly as a file would be); ``against`` is a scene
    file or catalogue path, or a Scene loaded from a file."""
    from .compare import compare as _compare_history
    if isinstance(against, Scene):
        against = against.source
    if not isinstance(against, (str, Path)) or not Path(against).is_file():
        try:
            against = load(against).source
        except (SceneError, TypeError):
            raise MartelloError(f"compare: against = {against!r} is not a scene file (give the "
                                "path of a scene file or a catalogue path; a scene made from a "
                                "dict has none: write it as TOML)") from None
    if isinstance(history, Result):
        if not history.columns:
            raise MartelloError("compare: a static run has no history to compare")
        from .run import write_history
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "history.csv"
            write_history(path, history.columns, history.data)
            return _compare_history(path, against)
    return _compare_history(history, against)


class StudyResult:
    """What ``martello.study`` gives back: ``rows`` (one dict per run, the columns of
    runs.csv — or of atlas.csv for an atlas), ``orders`` (the measured orders of orders.csv;
    for an atlas, its stability boundaries), ``folder`` (where it wrote them, with study.md and
    the plots) and ``kind`` ("study" or "atlas")."""

    def __init__(self, kind, rows, orders, folder):
        self.kind, self.rows, self.orders, self.folder = kind, rows, orders, Path(folder)

    def __repr__(self):
        return f"<martello.StudyResult: {self.kind}, {len(self.rows)} runs in {self.folder}>"


def study(file, output=None, *, jobs=0, plots=True, scheduler=None, stream=None):
    """Run a study or atlas file (docs/studies.md) as ``martello study FILE -o OUTPUT`` does;
    a ``StudyResult``.

    ``output`` defaults to the study's ``output`` key, else out/studies/<file name>; ``jobs``
    worker processes (0: every core); ``scheduler`` a Dask scheduler's address to run on
    instead (a study file's own ``scheduler`` key is never used from here: pass it);
    progress on ``stream`` (default stderr). Interrupted (Ctrl-C, SIGTERM), it keeps the
    finished rows in ``output`` and raises martello.errors.Stopped; the same call resumes it
    (docs/studies.md, "A study stops when asked and resumes")."""
    from .study import atlas as _atlas, sweep as _sweep
    from .study.study_file import file_kind, load_study
    path = Path(file)
    if file_kind(path) == "atlas":
        if scheduler:
            raise MartelloError(f"{path}: a stability atlas runs on the local cores, not on a "
                                "Dask cluster (leave scheduler out)")
        spec = _atlas.load_atlas(path)
        out = _atlas.output_folder(path, spec, output)
        rows, bounds = _atlas.run_atlas(spec, out, jobs=jobs, plots=plots, stream=stream)
        return StudyResult("atlas", rows, bounds, out)
    s = load_study(path)
    out = _sweep.output_folder(path, s, output)
    if scheduler:
        from .study.cluster import dask_executor
        origin = "given to martello.study"
        with dask_executor(scheduler, origin) as (executor, workers):
            rows, orders = _sweep.run_study(s, out, plots=plots, stream=stream, executor=executor,
                                            where=f"the Dask cluster at {scheduler} ({origin}; "
                                                  f"{workers} worker(s))")
    else:
        rows, orders = _sweep.run_study(s, out, jobs=jobs, plots=plots, stream=stream)
    return StudyResult("study", rows, orders, out)


class CheckResult:
    """What ``martello.check`` gives back: ``ok`` (no check failed), ``rows`` (the
    verification table, verification.csv as dicts) and ``folder`` (report.md, the runs, the
    plots)."""

    def __init__(self, ok, rows, folder):
        self.ok, self.rows, self.folder = ok, rows, Path(folder)

    def __repr__(self):
        return (f"<martello.CheckResult: {'ok' if self.ok else 'FAILED'}, {len(self.rows)} rows "
                f"in {self.folder}>")


def check(scenes=None, output="out/check", *, plots=False, stream=None):
    """Verify scenes against their closed forms and reference data as ``martello check``
    does (docs/coverage.md): ``scenes`` scene files or catalogue paths (default: the
    whole catalogue; a scene named must have something to verify); the table is printed on
    ``stream`` (default stdout) and report.md, verification.csv (and with ``plots`` the PNGs)
    written in ``output``. A ``CheckResult``."""
    import csv
    import sys
    from .report import check_catalogue
    files = [_catalogue.find(p) for p in scenes] if scenes else _catalogue.scene_files()
    out = Path(output)
    ok = check_catalogue(files, out, plots=plots, stream=stream or sys.stdout,
                         require_checks=bool(scenes))
    table = out / "verification.csv"
    rows = []
    if table.exists():
        with open(table, newline="") as fh:
            rows = list(csv.DictReader(fh))
    return CheckResult(ok, rows, out)


def plot(folder, output=None, *, formats=("png", "svg"), nodes=None, contacts=None, metric=None):
    """The pictures ``martello plot FOLDER`` draws of a run folder (histories, phase
    portraits, force against penetration, hysteresis loops, energy terms) or a study folder
    (error against the step, work-precision), in ``output`` (default FOLDER/plots); the list
    of files written (docs/plot.md)."""
    from .plot import plot_folder
    return plot_folder(folder, output, tuple(formats), nodes=nodes, contacts=contacts,
                       metric=metric)[1]
