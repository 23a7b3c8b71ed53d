"""The study file (docs/studies.md): scenes, contact schemes, integrators and the steps or
tolerances to sweep, read and validated into a Study."""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import StudyError
from ..paths import REPO, MiB, UnreadableFile, read_input
from ..scene.fields import finite_everywhere
from ..scene.spec import ADAPTIVE, INTEGRATORS
from ..scene.variants import override_contacts

STUDY_KEYS = {"title", "description", "output", "t_end", "repeat", "compare", "scene", "scheme",
              "integrator", "atlas", "kind", "scheduler"}
SCENE_KEYS = {"file", "label", "reference", "t_end", "scheme"}
SCHEME_KEYS = {"label", "contact", "reference", "scenes"}
INTEGRATOR_KEYS = {"name", "label", "params", "dt", "rtol", "order", "scenes", "schemes"}
COMPARE_KEYS = {"histories", "atol", "rtol", "points", "plot_metrics", "fit", "window"}
# Integrator parameters that fix a member of a family; the label says them.
FAMILY_KEYS = ("preset", "beta", "gamma", "alpha", "rho_inf", "theta")


@dataclass
class Case:
    """One scene with one contact scheme: the unit that has one reference."""
    label: str
    scene_label: str
    scheme_label: str
    scene_file: Path
    scene_dict: dict
    reference: object          # spec: None/"auto", {closed_form...} or {data...}
    t_end: float


@dataclass
class Method:
    label: str
    name: str
    params: dict
    dts: list
    rtols: list
    order: float | None
    scenes: list | None
    schemes: list | None


@dataclass
class Study:
    path: Path
    title: str
    description: str
    output: str | None
    repeat: int
    compare: dict
    cases: list
    methods: list
    raw: dict = field(default_factory=dict)
    scheduler: str | None = None     # a Dask scheduler's address (--scheduler overrides it)


MAX_LEVELS = 10_000     # steps or tolerances one integrator sweeps


def _number(src, where, value, kind=float, positive=False):
    """A number of a study file: int or float, finite (read_toml checks that), > 0 if asked."""
    ok = isinstance(value, (int, float)) and not isinstance(value, bool)
    if kind is int:
        ok = ok and float(value).is_integer()
    if not ok or (positive and not value > 0):
        raise StudyError(src, where, f"invalid value {value!r}",
                         ("a whole number" if kind is int else "a number") + (" > 0" if positive else ""))
    return kind(value)


def _sweep(src, where, value):
    """A list of numbers, or {from, to, per_decade} for a geometric sweep (from > to)."""
    if value is None:
        return []
    if isinstance(value, (int, float)) and not isinstance(value, bool):
        return [_number(src, where, value, positive=True)]
    if isinstance(value, list):
        if not value or not all(isinstance(x, (int, float)) and not isinstance(x, bool) and x > 0
                                for x in value):
            raise StudyError(src, where, "must be a non-empty list of numbers > 0")
        if len(value) > MAX_LEVELS:
            raise StudyError(src, where, f"has {len(value)} values", f"at most {MAX_LEVELS}")
        return [float(x) for x in value]
    if isinstance(value, dict) and {"from", "to"} <= set(value):
        a = _number(src, f"{where}.from", value["from"], positive=True)
        b = _number(src, f"{where}.to", value["to"], positive=True)
        n = _number(src, f"{where}.per_decade", value.get("per_decade", 4), int, positive=True)
        count = int(round(abs(math.log10(b / a)) * n)) + 1
        if count > MAX_LEVELS:
            raise StudyError(src, where, f"asks for {count} values", f"at most {MAX_LEVELS}")
        return [float(x) for x in np.geomspace(a, b, count)]
    raise StudyError(src, where, f"invalid sweep {value!r}"[:200],
                     "give a list of numbers or { from = 1e-3, to = 1e-6, per_decade = 4 }")


def _check_keys(src, where, table, valid):
    if not isinstance(table, dict):
        raise StudyError(src, where, "must be a table")
    for k in table:
        if k not in valid:
            raise StudyError(src, f"{where}.{k}", "unknown key", "valid: " + ", ".join(sorted(valid)))


def _reference(path, where, ref):
    """A case's `reference`: "auto", { closed_form = NAME, params = {...} } or { data = DIR }
    with DIR relative to the study file's folder (a path that is not there but names one of
    martello's stored references, reference/<name>, is that one)."""
    if ref in (None, "auto"):
        return "auto"
    if isinstance(ref, dict) and set(ref) == {"data"} and isinstance(ref["data"], str) and ref["data"]:
        p = Path(ref["data"])
        if not p.is_absolute():
            beside = path.parent / p
            p = beside if beside.exists() or not (REPO / p).exists() else REPO / p
        return {"data": str(p.resolve())}
    if isinstance(ref, dict) and isinstance(ref.get("closed_form"), str) \
            and set(ref) <= {"closed_form", "params"} and isinstance(ref.get("params", {}), dict):
        return ref
    raise StudyError(path, where, f"invalid value {ref!r}"[:160],
                     'give "auto", { closed_form = NAME, params = { ... } } or { data = "DIR" } '
                     "(a folder of reference.json and history.csv, relative to the study file)")


def method_label(name, params):
    fam = [f"{k}={params[k]}" for k in FAMILY_KEYS if k in params]
    return name + (f" ({', '.join(fam)})" if fam else "")


def read_toml(path):
    """The parsed TOML of a study or atlas file; StudyError if it is missing or invalid."""
    path = Path(path)
    try:
        raw = read_input(path, 64 * MiB)
    except UnreadableFile as exc:
        raise StudyError(path, "(file)", exc.problem, exc.fix) from None
    try:
        data = tomllib.loads(raw.decode("utf-8"))
    except (tomllib.TOMLDecodeError, UnicodeDecodeError, ValueError) as exc:
        raise StudyError(path, "(syntax)", f"not valid TOML: {exc}") from None
    except RecursionError:
        raise StudyError(path, "(syntax)", "tables or arrays nested too deeply to parse") from None
    finite_everywhere(path, data, "", "a study file", StudyError)
    return data


def load_study(path):
    path = Path(path)
    raw = read_toml(path)
    _check_keys(path, "(top level)", raw, STUDY_KEYS)
    compare = raw.get("compare", {})
    _check_keys(path, "compare", compare, COMPARE_KEYS)
    fit = compare.get("fit", [0.0, 0.1])
    if not isinstance(fit, list) or len(fit) != 2:
        raise StudyError(path, "compare.fit", f"invalid value {fit!r}"[:100], "two numbers [lo, hi]")
    metrics = compare.get("plot_metrics", ["max_rel_error"])
    if not isinstance(metrics, list) or not metrics or not all(isinstance(m, str) for m in metrics):
        raise StudyError(path, "compare.plot_metrics", "must be a non-empty list of metric names")
    compare = {"histories": compare.get("histories"),
               "atol": _number(path, "compare.atol", compare.get("atol", 1e-12)),
               "rtol": _number(path, "compare.rtol", compare.get("rtol", 1e-6)),
               "points": _number(path, "compare.points", compare.get("points", 2001), int, True),
               "plot_metrics": list(metrics),
               "fit": [_number(path, f"compare.fit[{i}]", x) for i, x in enumerate(fit)],
               "window": compare.get("window")}
    top_schemes = raw.get("scheme", [])
    for i, sc in enumerate(top_schemes):
        _check_keys(path, f"scheme[{i}]", sc, SCHEME_KEYS)
    for key in ("scene", "integrator", "scheme"):
        if key in raw and not isinstance(raw[key], list):
            raise StudyError(path, key, "must be an array of tables", f"write [[{key}]]")
    cases = []
    if not raw.get("scene"):
        raise StudyError(path, "scene", "missing", "name at least one [[scene]] with file = \"...\"")
    for i, st in enumerate(raw["scene"]):
        where = f"scene[{i}]"
        _check_keys(path, where, st, SCENE_KEYS)
        if "file" not in st:
            raise StudyError(path, f"{where}.file", "missing", "the scene file, relative to the study")
        if not isinstance(st["file"], str):
            raise StudyError(path, f"{where}.file", "must be a string", "the scene file's path")
        f = Path(st["file"])
        f = f if f.is_absolute() else (path.parent / f).resolve()
        if not f.exists():
            raise StudyError(path, f"{where}.file", f"{f} does not exist")
        sdict = read_toml(f)
        sdict.pop("check", None)     # the study's reference decides what is compared
        slabel = st.get("label", f.stem)
        t_end = _number(path, f"{where}.t_end", st.get("t_end", raw.get("t_end", (
            sdict.get("analysis") if isinstance(sdict.get("analysis"), dict) else {}).get("t_end", 0.0))))
        schemes = list(st.get("scheme", [])) + [s for s in top_schemes
                                                 if not s.get("scenes") or slabel in s["scenes"]]
        for j, sc in enumerate(st.get("scheme", [])):
            _check_keys(path, f"{where}.scheme[{j}]", sc, SCHEME_KEYS)
        if not schemes:
            schemes = [{"label": "as in the scene"}]
        for sc in schemes:
            d = override_contacts(sdict, sc.get("contact"), path, f"{where} scheme {sc.get('label')}")
            # the scene's reference is for its own contacts: an override brings its own
            ref = sc.get("reference", "auto") if sc.get("contact") else \
                sc.get("reference", st.get("reference", "auto"))
            ref = _reference(path, f"{where}.reference", ref)
            cases.append(Case(label=f"{slabel} | {sc.get('label', 'scheme')}" if len(schemes) > 1 else slabel,
                              scene_label=slabel, scheme_label=sc.get("label", "as in the scene"),
                              scene_file=f, scene_dict=d, reference=ref, t_end=t_end))
    methods = []
    if not raw.get("integrator"):
        raise StudyError(path, "integrator", "missing", "name at least one [[integrator]]")
    for i, it in enumerate(raw["integrator"]):
        where = f"integrator[{i}]"
        _check_keys(path, where, it, INTEGRATOR_KEYS)
        name = it.get("name")
        if name not in INTEGRATORS:
            raise StudyError(path, f"{where}.name", f"unknown integrator {name!r}",
                             "valid: " + ", ".join(INTEGRATORS))
        params = dict(it.get("params", {}))
        dts = _sweep(path, f"{where}.dt", it.get("dt"))
        rtols = _sweep(path, f"{where}.rtol", it.get("rtol"))
        if not dts:
            raise StudyError(path, f"{where}.dt", "missing",
                             "a list of steps (adaptive integrators: one output step)")
        if rtols and name not in ADAPTIVE:
            raise StudyError(path, f"{where}.rtol", f"applies to adaptive integrators, not {name}",
                             "sweep dt instead")
        methods.append(Method(label=it.get("label", method_label(name, params)), name=name,
                              params=params, dts=dts, rtols=rtols,
                              order=it.get("order"), scenes=it.get("scenes"), schemes=it.get("schemes")))
    scheduler = raw.get("scheduler")
    if scheduler is not None and not (isinstance(scheduler, str) and scheduler.strip()):
        raise StudyError(path, "scheduler", f"is {scheduler!r}"[:100],
                         "the address of a Dask scheduler, e.g. \"tcp://host:8786\", or the path "
                         "of its scheduler file (.json)")
    return Study(path=path, title=raw.get("title", path.stem), description=raw.get("description", ""),
                 output=raw.get("output"), compare=compare, scheduler=scheduler,
                 repeat=_number(path, "repeat", raw.get("repeat", 1), int, True),
                 cases=cases, methods=methods, raw=raw)


def file_kind(path):
    """"atlas" for a stability-atlas file (martello.study.atlas), else "study": both are run
    by `martello study`."""
    raw = read_toml(path)
    return "atlas" if raw.get("kind") == "atlas" or "atlas" in raw else "study"
