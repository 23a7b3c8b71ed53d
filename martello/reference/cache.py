"""References for any scene (docs/reference.md): computed on demand with the most accurate
methods that run the scene, their trusted digits measured (refinement, and a second method
as a cross-check), and kept in a user cache keyed by the scene's physics, so that
`martello reference` and `martello compare` compute a scene's reference once.

The cache folder is $MARTELLO_CACHE_DIR, else $XDG_CACHE_HOME/martello, else
~/.cache/martello (the XDG base directory specification); each reference is
references/<key>/ with history.csv and reference.json, as in the repository's reference/."""

from __future__ import annotations

import hashlib
import json
import math
import os
import shutil
import sys
import time
import tomllib
from pathlib import Path

from ..binding import native
from ..errors import MartelloError
from ..scene.loader import load
from .base import ReferenceError
from .build import compute_reference, write_reference
from .independent_engine import NAME as ENGINE
from .store import load_reference, physics_digest

ENV_CACHE = "MARTELLO_CACHE_DIR"
# Bumped when the way references are computed here changes: older cache entries are then
# not reused.
FORMAT = 2
# Stored samples: the scene's own output interval, kept between t_end/20000 and t_end/1000
# (the comparison interpolates between them with the quintic Hermite of history.py, whose
# error (Δ ω)⁶/… is far below the trusted digits at ≥ 1000 samples per history).
MIN_ROWS, MAX_ROWS = 1000, 20000
# Newmark's finest step when it is the primary method (hysteretic links, which the
# event-located engines do not locate): 1/100 of the scene's step, but no more than 2e6
# steps, so that its three refinement levels take seconds, not minutes, at ~1e6 steps/s.
NEWMARK_STEPS = 2.0e6
# rk8pd's largest step on scenes with hysteretic links: 1/10 of the scene's step, but no more
# than 5e5 steps (~15 µs a step on ten nodes: seconds).
RK8_STEPS = 5.0e5
# The independent engine is Python: its right-hand side costs ~10 µs per node; beyond this
# many nodes it would take minutes, and a library method is the cross-check instead.
INDEPENDENT_MAX_NODES = 60
# The engine's primary tolerance (its second integration, the refinement level, at 100 ×):
# at 1e-12 its 1e-10 run confirms 8.5 digits of the two-mass Hertz scene of
# tests/test_reference_cache.py, at 1e-11 only 7.75 (the 1e-9 run bounds the digits).
ENGINE_RTOL = 1.0e-12
# Up to this many nodes the loader writes every node's history by default.
OUTPUT_ALL_NODES = 50


def cache_root():
    """The user cache folder of martello (not created here)."""
    env = os.environ.get(ENV_CACHE)
    if env:
        return Path(env).expanduser()
    xdg = os.environ.get("XDG_CACHE_HOME")
    base = Path(xdg).expanduser() if xdg and Path(xdg).is_absolute() else Path.home() / ".cache"
    return base / "martello"


def cache_key(scene):
    """What the cached reference depends on: the physics (store.physics_digest), the bytes of
    a ground-motion record file (the digest keeps only its name), the library version and
    this module's FORMAT."""
    rec = None
    if scene.ground and scene.ground.get("type") == "record":
        rec = hashlib.sha256(Path(scene.ground["file"]).read_bytes()).hexdigest()
    data = {"physics": physics_digest(scene), "record": rec, "martello": native.version(),
            "format": FORMAT}
    return hashlib.sha256(json.dumps(data, sort_keys=True).encode()).hexdigest()[:24]


def store_spacing(scene, every=None):
    """Spacing of the stored samples [s]: `every` if given, else the scene's output interval
    kept between t_end/MAX_ROWS and t_end/MIN_ROWS."""
    t_end = float(scene.analysis["t_end"])
    if every is not None:
        if not (every > 0 and t_end / every <= 10 * MAX_ROWS):
            raise ReferenceError(f"--every {every!r}: must be > 0 and give at most "
                                 f"{10 * MAX_ROWS} samples over t_end = {t_end} s")
        return t_end / max(1, round(t_end / every))
    an = scene.analysis
    out = float(an["dt"]) * int(an.get("output", {}).get("every", 1) or 1)
    spacing = min(max(out, t_end / MAX_ROWS), t_end / MIN_ROWS)
    return t_end / round(t_end / spacing)


def default_methods(scene, store):
    """The methods a scene's reference is computed with, the most accurate first; the first
    that runs is refined, the next that runs cross-checks it (build.compute_reference), and
    each one that cannot run the scene is recorded with why.

    - first the independent engine (martello.independent via independent_engine.py: the
      scene's equations written again from its file, every switch event-located on scipy's
      DOP853, at rtol 1e-11 and 1e-9), for a scene of at most INDEPENDENT_MAX_NODES nodes it
      models (every penalty law, restitution without accumulating impacts, springs, dashpots,
      bilinear links, fluid dampers, [[frame]], gravity, forces and ground motion by every
      time function); cross-checked by martello's own best run:
    - penalty contacts only: rk8pd (GSL's 8th-order Runge–Kutta–Prince–Dormand with event
      location, docs/event-driven.md) at rtol 1e-12, then Newmark at a small step;
    - Lagrange or restitution contacts: rk8pd, then rkf45 (another pair of the same
      event-driven integrator: it shares the event handling, not the stepping);
    - hysteretic (bilinear) links: rk8pd with a largest step h_max, refined in h_max (the
      error of a step over a kink is set by its length, and shrinks as h_max² — measured on
      P7's chain of ten: 1.7e-5, 1.5e-7, 4e-8 at h_max = 1e-3, 1e-4, 3e-5 s), then Newmark
      (average acceleration) at a small step."""
    an = scene.analysis
    t_end = float(an["t_end"])
    schemes = {c["scheme"] for c in scene.contacts}
    rk8 = {"integrator": "rk8pd", "dt": store, "rtol": 1.0e-12, "atol": 1.0e-15}
    dt_nm = max(t_end / NEWMARK_STEPS, float(an["dt"]) / 100.0)
    dt_nm = store / math.ceil(store / dt_nm)            # output times fall on the samples
    newmark = {"integrator": "newmark", "preset": "average-acceleration", "dt": dt_nm,
               "tol_residual": 1.0e-12, "tol_increment": 1.0e-14}
    if schemes - {"penalty"}:
        library = [rk8, {"integrator": "rkf45", "dt": store, "rtol": 1.0e-12, "atol": 1.0e-15}]
    elif any(lk["type"] == "bilinear" for lk in scene.links):
        h = max(float(an["dt"]) / 10.0, t_end / RK8_STEPS)
        library = [dict(rk8, h_max=h, refine="h_max"), newmark]
    else:
        library = [rk8, newmark]
    engine = [{"integrator": ENGINE, "rtol": ENGINE_RTOL}] if len(scene.nodes) <= INDEPENDENT_MAX_NODES else []
    return engine + library


def engine_skipped(scene):
    """Why the independent engine is not tried on a scene, or None."""
    if len(scene.nodes) > INDEPENDENT_MAX_NODES:
        return (f"{len(scene.nodes)} nodes, more than {INDEPENDENT_MAX_NODES}: its Python right-hand "
                "side would take minutes")
    return None


INDEPENDENCE = {
    ENGINE: "the independent engine (martello.independent: the scene's equations written again "
            "from its file, every switch event-located on scipy's DOP853; no code shared with the "
            "library or the front end)",
    "rkf45": "same library, another Runge–Kutta pair (shares the model and the event handling)",
    "rk8pd": "martello's own best run (the library's rk8pd with event location)",
    "newmark": "same library, another integrator (shares the model's force kernels)",
}


def _scene_dict(path):
    with open(path, "rb") as fh:
        d = tomllib.load(fh)
    d.pop("check", None)
    return d


def _usable(folder, scene, every):
    """The cached reference in folder if it serves the scene: the same physics, long enough,
    at the spacing asked for (if one was)."""
    try:
        meta = json.loads((folder / "reference.json").read_text())
        if not (folder / "history.csv").exists():
            return None
    except (OSError, ValueError):
        return None
    if meta.get("physics_sha256") != physics_digest(scene) or meta.get("format") != FORMAT:
        return None
    if float(meta.get("t_end", 0.0)) < float(scene.analysis["t_end"]) * (1 - 1e-12):
        return None
    if every is not None and not math.isclose(meta["stored"]["every_s"], store_spacing(scene, every),
                                              rel_tol=1e-9):
        return None
    return meta


def _publish(tmp, folder):
    """Move a finished reference folder into place in one rename (a reader never sees half a
    reference; two processes computing the same one leave one of them)."""
    old = folder.with_name(folder.name + f".old-{os.getpid()}")
    if folder.exists():
        folder.rename(old)
    try:
        tmp.rename(folder)
    except OSError:
        if folder.exists():             # another process published the same reference first
            shutil.rmtree(tmp, ignore_errors=True)
        elif old.exists():
            old.rename(folder)
            raise
        else:
            raise
    shutil.rmtree(old, ignore_errors=True)


def cached_reference(scene):
    """The reference `martello reference` cached for the scene's physics, if one serves it
    (long enough), else None; nothing is computed."""
    if scene.analysis.get("type") != "dynamic":
        return None
    folder = cache_root() / "references" / cache_key(scene)
    if _usable(folder, scene, None) is None:
        return None
    return _named(load_reference(folder), folder)


def reference_for_file(scene_path, refresh=False, every=None, jobs=0, stream=None):
    """The reference of the scene in scene_path, from the cache or computed (then cached).

    Returns (Reference, folder, cached) where folder holds history.csv and reference.json
    and cached says whether it was reused. Raises ReferenceError (a static scene, a scene no
    method runs) with one line naming the fix."""
    scene_path = Path(scene_path)
    return computed_reference(load(scene_path), _scene_dict(scene_path), scene_path, refresh,
                              every, jobs, stream)


def computed_reference(scene, sdict, scene_path, refresh=False, every=None, jobs=0, stream=None):
    """reference_for_file for a loaded scene: its Scene, the scene dict it was loaded from
    (without [check]) and the path its relative files are read from (a dict scene: any file
    in the folder they are relative to)."""
    stream = stream or sys.stderr
    scene_path = Path(scene_path)
    if scene.analysis.get("type") != "dynamic":
        raise ReferenceError(f"{scene_path}: a static scene has no time history: its reference is "
                             "the static solution (martello run, martello check)")
    root = cache_root() / "references"
    key = cache_key(scene)
    folder = root / key
    if not refresh and _usable(folder, scene, every) is not None:
        return _named(load_reference(folder), folder), folder, True
    store = store_spacing(scene, every)
    methods = default_methods(scene, store)
    t0 = time.perf_counter()
    # a large scene keeps its own output selection (the loader writes every node only up to
    # 50 of them: docs/scene-input.md)
    keep = len(scene.nodes) > OUTPUT_ALL_NODES
    if keep and not scene.analysis["output"]["nodes"]:
        raise ReferenceError(f"{scene_path}: [analysis.output] nodes is empty: name the nodes to "
                             f"compare (a scene of {len(scene.nodes)} nodes writes none by default)")
    out = compute_reference(scene, sdict, scene_path.resolve(), methods, store,
                            label=scene_path.name, jobs=jobs, stream=stream, keep_output=keep)
    elapsed = time.perf_counter() - t0
    meta = out["meta"]
    cross = meta.get("cross_check")
    basis = (f"refinement of {meta['method']['integrator']} and its difference from "
             f"{cross['method']['integrator']}: {INDEPENDENCE.get(cross['method']['integrator'], '')}"
             if cross else f"refinement of {meta['method']['integrator']} only: no second method runs "
             "this scene, so an error both refinement levels share is not seen")
    skipped = engine_skipped(scene)
    if skipped:
        meta["not_run"] = [{"method": ENGINE, "why": skipped}] + meta["not_run"]
    if cross:
        # the digits the two agree to, per column (the digits stored are at most these)
        meta["digits_agreed"] = {c: cross["digits"][c] for c in meta["digits"] if c in cross["digits"]}
    meta = {"name": scene_path.stem, "scene": str(scene_path.resolve()), "format": FORMAT,
            "cache_key": key, **meta, "digits_basis": basis,
            "methods_tried": [m["integrator"] for m in methods],
            "compute_time_s": elapsed,
            "command": f"martello reference {scene_path}"}
    root.mkdir(parents=True, exist_ok=True)
    tmp = root / f".{key}.tmp-{os.getpid()}"
    shutil.rmtree(tmp, ignore_errors=True)
    try:
        write_reference(tmp, out, meta)
        _publish(tmp, folder)
    except OSError as exc:
        shutil.rmtree(tmp, ignore_errors=True)
        raise MartelloError(f"{root}: cannot write the reference cache ({exc.strerror}); set "
                            f"{ENV_CACHE} to a writable folder") from None
    return _named(load_reference(folder), folder), folder, False


def _named(ref, folder):
    ref.name = f"computed reference {folder.name} ({ref.provenance['method']['integrator']})"
    ref.kind = "data"
    return ref


def describe(ref, folder, cached, scene_path=None, stream=None):
    """What a computed reference is and how far it is trusted, for a person."""
    stream = stream or sys.stdout
    meta = ref.provenance
    m = meta["method"]
    how = f"rtol {m['rtol']:g}" if "rtol" in m else f"Δt {m['dt']:g} s"
    how += f", h_max {m['h_max']:g} s" if m.get("h_max") else ""
    when = (f"from the cache (computed {meta['date']} for {meta['scene']})" if cached
            else f"computed in {meta.get('compute_time_s', 0.0):.1f} s")
    print(f"{scene_path or meta['scene']}: reference by {m['integrator']} ({how}), {when}", file=stream)
    print(f"  engine: {meta.get('engine', m['integrator'])}", file=stream)
    for n in meta.get("not_run", []):
        print(f"  could not run: {n['method']}: {n['why']}", file=stream)
    print(f"  trusted digits from {meta['digits_basis']}", file=stream)
    agreed = meta.get("digits_agreed")
    if agreed:
        low = min(agreed, key=agreed.get)
        print(f"  the two agree to {agreed[low]:.1f} digits at least ({low}); per column below, "
              "the stored digits are at most the agreed ones", file=stream)
    width = max(len(c) for c in meta["digits"])
    for c, d in meta["digits"].items():
        print(f"  {c:<{width}}  {d:5.1f} digits", file=stream)
    print(f"  {meta['stored']['rows']} samples every {meta['stored']['every_s']:g} s to "
          f"t = {meta['t_end']:g} s; martello {meta['martello_version']} ({meta['libraries']})",
          file=stream)
    if not meta.get("cross_check"):
        print("  warning: no second method runs this scene: the digits are from refinement only",
              file=stream)


def main(args):
    """`martello reference SCENE -o DIR`."""
    ref, folder, cached = reference_for_file(args.scene, refresh=args.refresh, every=args.every,
                                             jobs=args.jobs or 0)
    out = Path(args.output) if args.output else Path("out") / "reference" / Path(args.scene).stem
    out.mkdir(parents=True, exist_ok=True)
    for name in ("history.csv", "reference.json"):
        shutil.copyfile(folder / name, out / name)
    describe(ref, folder, cached, args.scene)
    print(f"-> {out / 'history.csv'} and {out / 'reference.json'} (cache: {folder})")
    from .selection import reference_for_scene
    own = reference_for_scene(load(args.scene))
    if own is not None:
        print(f"note: the scene also has {own.name}, which martello compare and check use for it")
    return 0
