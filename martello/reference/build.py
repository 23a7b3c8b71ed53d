"""Building the stored reference data (reference/, scripts/regenerate_reference) and the
references of `martello reference` (cache.py): each is run by the first method of its list
that runs the scene — the independent engine (independent_engine.py) or a library
integrator — checked by refinement and by the next method that runs it, and written with its
provenance, including what could not run the scene and why."""

from __future__ import annotations

import copy
import json
import math
import sys
import time
import tomllib
from pathlib import Path

import numpy as np

from ..batch import execute, run_specs
from ..binding import native
from ..errors import MartelloError
from ..history import history_dict, interpolate
from ..metrics.event_matching import match_events
from ..metrics.score import score
from ..paths import REFERENCE_ROOT, REPO
from ..scene.loader import load
from ..scene.spec import ADAPTIVE
from ..scene.variants import analysis_for, override_contacts, runnable_scene
from .independent_engine import DESCRIPTION as ENGINE_DESCRIPTION, NAME as ENGINE, Unsupported, engine_run
from .store import load_reference, manifest, physics_digest



def _finite(x):
    """Non-finite numbers as None: reference files are strict JSON (RFC 8259 has no NaN)."""
    if isinstance(x, dict):
        return {k: _finite(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_finite(v) for v in x]
    if isinstance(x, float) or hasattr(x, "dtype"):
        x = float(x) if not isinstance(x, bool) and not isinstance(x, (int,)) else x
        return x if not isinstance(x, float) or math.isfinite(x) else None
    return x


def strict_json(meta) -> str:
    """meta as strict JSON: `null` for a value that is not a finite number (an observed order
    that is not asymptotic), never `NaN`; anything not finite left over is an error."""
    return json.dumps(_finite(meta), indent=1, default=float, allow_nan=False)

def _spec(method, scene_dict, scene_path, dt, rtol, store, keep_output=False):
    """The run spec of one method at one step (or tolerance), output every `store` s: every
    node and contact (the loader's default), or the scene's own selection if keep_output."""
    params = {k: v for k, v in method.items() if k not in ("integrator", "dt", "refine", "rtol", "cross_check")}
    every = 1 if method["integrator"] in ADAPTIVE else max(1, int(round(store / dt)))
    d = copy.deepcopy(scene_dict)
    d["analysis"] = analysis_for(d.get("analysis", {}), method["integrator"], params, dt,
                                 d["analysis"]["t_end"], every, rtol)
    if not keep_output:
        d["analysis"]["output"].pop("nodes", None)
        d["analysis"]["output"].pop("contacts", None)
    return {"id": 0, "scene_dict": d, "scene_file": str(scene_path), "base_dir": str(scene_path.parent),
            "repeat": 1}


def _method_runs(entry, method, scene_dict, scene_path, dt, rtol=None):
    """The run spec of a reference entry's method (tests recompute stored data with it)."""
    return _spec(method, scene_dict, scene_path, dt, rtol, float(entry["store_every"]))


def _sampled(result, grid):
    h = history_dict(result["history"])
    return {c: interpolate(h["t"], h, c, grid) for c in h if c != "t"}


def reference_scene(entry):
    """(Scene, scene dict without [check], path) of a reference entry, with its contact
    override applied (a variant of the scene: same file, other physics)."""
    scene_path = (REPO / entry["scene"]).resolve()
    with open(scene_path, "rb") as fh:
        sdict = tomllib.load(fh)
    sdict.pop("check", None)
    if entry.get("contact"):
        sdict = override_contacts(sdict, entry["contact"], scene_path, f"reference {entry['name']}")
        # validated with an integrator the new contacts run on (the analysis does not enter
        # the physics digest)
        return runnable_scene(sdict, scene_path, sdict["analysis"]["t_end"]), sdict, scene_path
    return load(scene_path), sdict, scene_path


def build_reference(entry, root=REFERENCE_ROOT, stream=sys.stderr, jobs=0):
    """Compute one reference (an entry of reference/references.toml) and write
    reference/<name>/history.csv and reference.json (compute_reference says how), then score
    the catalogue's own settings against it."""
    scene, sdict, scene_path = reference_scene(entry)
    out = compute_reference(scene, sdict, scene_path, entry["method"], float(entry["store_every"]),
                            label=entry["name"], kinds=entry.get("columns"),
                            cross_check=entry.get("cross_check", True), jobs=jobs, stream=stream)
    meta = {"name": entry["name"], "scene": entry["scene"], "contact_override": entry.get("contact")}
    meta.update(out["meta"])
    meta["command"] = "scripts/regenerate_reference " + entry["name"]
    folder = Path(root) / entry["name"]
    write_reference(folder, out, meta)
    # the catalogue's own settings against the new reference: what `martello check` expects
    ref = load_reference(folder)
    own = {"status": "skipped"} if entry.get("contact") else execute({"id": 0, "scene_dict": sdict,
                   "scene_file": str(scene_path), "base_dir": str(scene_path.parent), "repeat": 1})
    if own["status"] == "MARTELLO_OK":
        sc = score(own["summary"], own["history"], ref)
        meta["catalogue_error"] = {k: sc.get(k) for k in ("max_rel_error", "impact_time_error",
                                                          "peak_penetration_error", "impact_count_error")}
        meta["catalogue_settings"] = {k: v for k, v in sdict["analysis"].items() if k != "output"}
        (folder / "reference.json").write_text(strict_json(meta) + "\n")
    print(f"  -> {folder}: {len(out['grid'])} rows, digits trusted (min over u) "
          f"{min(v for k, v in out['digits'].items() if k.startswith('u:')):.1f}, "
          f"observed order {out['meta']['observed_order'] or math.nan:.2f}", file=stream)
    return folder


# Columns whose definition is the same in every engine: the cross-check bounds their digits
# too (energy terms are bookkept differently by the engines, e.g. the input of a ground
# motion, so a difference there need not be an error).
CROSS_CHECKED_KINDS = ("u", "v", "penetration", "force")


def _run_levels(method, sdict, scene_path, scene, grid, store, label, jobs, stream, keep_output):
    """The refinement levels of one method, run: (levels, results), or (None, why) when the
    method cannot run the scene (not built, or a part the independent engine does not
    model)."""
    if method["integrator"] == ENGINE:
        rt = float(method["rtol"])
        levels = [(None, rt), (None, rt * 100.0)]
        print(f"{label}: the independent engine (DOP853, event-located) at rtol={rt:g}, {rt * 100:g}",
              file=stream)
        try:
            res = [engine_run(sdict, scene_path.parent, r_, grid, scene.analysis["t_end"])
                   for _, r_ in levels]
        except Unsupported as exc:
            print(f"  {ENGINE}: it does not model {exc}; next method", file=stream)
            return None, f"does not model {exc}"
        return levels, res
    dt = float(method["dt"])
    if method.get("refine") == "h_max":
        # an adaptive method whose error is set by its largest step (kinks it does not
        # locate, such as yield: docs/event-driven.md): refined in h_max, like a fixed step
        h, rt = float(method["h_max"]), float(method["rtol"])
        levels = [(dt, rt, h), (dt, rt, 2 * h), (dt, rt, 4 * h)]
    elif method["integrator"] in ADAPTIVE:
        rt = float(method["rtol"])
        levels = [(dt, rt), (dt, rt * 100.0)]
    else:
        levels = [(dt, None), (2 * dt, None), (4 * dt, None)]
    specs = [dict(_spec(dict(method, h_max=lv[2]) if len(lv) > 2 else method, sdict, scene_path,
                        lv[0], lv[1], store, keep_output), id=i)
             for i, lv in enumerate(levels)]
    print(f"{label}: {method['integrator']} at "
          + ", ".join(f"dt={lv[0]:g}" + (f" rtol={lv[1]:g}" if lv[1] else "")
                      + (f" h_max={lv[2]:g}" if len(lv) > 2 else "") for lv in levels), file=stream)
    res = sorted(run_specs(specs, jobs), key=lambda r: r["id"])
    if any(r["status"] in ("MARTELLO_ERR_UNSUPPORTED", "incompatible") for r in res):
        why = next(r.get("message", "") for r in res if r["status"] in ("MARTELLO_ERR_UNSUPPORTED", "incompatible"))
        print(f"  {method['integrator']}: not available ({why[:80]}); next method", file=stream)
        return None, f"not available: {why}"
    bad = [r for r in res if r["status"] != "MARTELLO_OK"]
    if bad:
        raise MartelloError(f"{label}: reference run failed: {bad[0]['status']}: "
                            f"{bad[0].get('message', '')}")
    return levels, res


def compute_reference(scene, sdict, scene_path, methods, store_every, label="reference",
                      kinds=None, cross_check=True, jobs=0, stream=sys.stderr, keep_output=False):
    """A reference history of a scene, with the digits it can be trusted to.

    methods are tried in order (integrator + its analysis keys + dt, rtol for adaptive
    ones; "independent" is the independent engine, martello.independent): the first that runs the
    scene is used, checked by refinement (Δt, Δt·2, Δt·4 for fixed steps; rtol, rtol·100 for
    adaptive ones): the digits trusted in each column are −log10 of max |y_h − y_2h| over the
    column's peak (the finest run's error for a first-order method, a 3× overestimate for a
    second-order one). The next method of the list that runs is a cross-check: the digits of
    u, v, penetration and force are capped by −log10 of its difference from the reference
    (refinement cannot see an error both levels share; two methods rarely share one).

    Returns {"grid", "columns", "fine" ({column: samples}), "digits", "meta"} (meta: the
    provenance reference.json records)."""
    t_end = scene.analysis["t_end"]
    store = float(store_every)
    grid = np.linspace(0.0, t_end, int(round(t_end / store)) + 1)
    chosen, not_run = None, []
    for method in methods:
        levels, res = _run_levels(method, sdict, scene_path, scene, grid, store, label, jobs, stream,
                                  keep_output)
        if levels is not None:
            chosen = (method, levels, res)
            break
        not_run.append({"method": method["integrator"], "why": res})
    if chosen is None:
        raise MartelloError(f"{label}: none of the reference methods runs ("
                            + "; ".join(f"{n['method']}: {n['why']}" for n in not_run) + ")")
    method, levels, results = chosen
    fine = _sampled(results[0], grid)
    coarse = [_sampled(r, grid) for r in results[1:]]
    digits, refinement = {}, []
    for c, y in fine.items():
        scale = float(np.max(np.abs(y)))
        if c.startswith("energy:") and c not in ("energy:kinetic", "energy:recoverable", "energy:input"):
            continue
        # |y_h − y_2h|, or |y_h − y_4h|/3 if larger: equal to the error of y_h for a
        # first-order method, an overestimate for higher orders, and still a bound when the
        # differences do not shrink (steps that fall differently on contact onsets)
        d1 = max([float(np.max(np.abs(coarse[0][c] - y)))]
                 + [float(np.max(np.abs(cz[c] - y))) / (2 ** (k + 2) - 1) * 1.0
                    for k, cz in enumerate(coarse[1:])])
        digits[c] = min(15.0, -math.log10(d1 / scale)) if scale > 0 and d1 > 0 else 15.0
    for k, cz in enumerate(coarse):
        refinement.append({"level": k + 1, "dt": levels[k + 1][0], "rtol": levels[k + 1][1],
                           **({"h_max": levels[k + 1][2]} if len(levels[k + 1]) > 2 else {}),
                           "max_rel_diff_u": max(float(np.max(np.abs(cz[c] - fine[c])) / max(np.max(np.abs(fine[c])), 1e-300))
                                                 for c in fine if c.startswith("u:"))})
    if len(refinement) >= 2 and refinement[0]["max_rel_diff_u"] > 0:
        # |y_4h − y_h| / |y_2h − y_h| = (4^p − 1)/(2^p − 1) = 2^p + 1 for a method of order p
        ratio = refinement[1]["max_rel_diff_u"] / refinement[0]["max_rel_diff_u"]
        observed = math.log2(ratio - 1.0) if ratio > 2.0 else math.nan   # nan: not asymptotic
    else:
        observed = math.nan
    # events: the finest run's, with their refinement differences
    fs, cs = results[0]["summary"], results[1]["summary"]
    events, peaks, ev_diff = {}, {}, {}
    for name, c in fs["contacts"].items():
        keys = ("impact_times", "separation_times", "approach_speeds", "restitution",
                "phase_max_penetration", "phase_max_force")
        events[name] = {k: c.get(k, []) for k in keys}
        peaks[name] = {"max_penetration": c["max_penetration"], "max_force": c["max_force"]}
        tc = np.asarray(cs["contacts"][name]["impact_times"], float)
        tf = np.asarray(c["impact_times"], float)
        m = match_events(tc, tf, 0.5 * (np.min(np.diff(tf)) if len(tf) > 1 else t_end))
        ev_diff[name] = {"count_fine": len(tf), "count_coarse": len(tc),
                         "max_time_diff": m.max_abs_dt}
    # columns stored: t, then the kinds asked for (default u, v, penetration, force, and the
    # kinetic, recoverable and input energy)
    kinds = kinds or ["u", "v", "penetration", "force", "energy"]
    cols = ["t"] + [c for c in results[0]["history"][0] if c != "t" and c in fine
                    and c.partition(":")[0] in kinds
                    and (not c.startswith("energy:") or c in ("energy:kinetic", "energy:recoverable",
                                                              "energy:input"))]
    digits = {c: v for c, v in digits.items() if c in cols}
    cross = _cross_check(methods, method, scene, sdict, scene_path, grid, store, fine,
                         stream, keep_output, not_run) if cross_check else None
    if cross is not None:
        for c, cap in cross["digits"].items():
            if c in digits and c.partition(":")[0] in CROSS_CHECKED_KINDS and digits[c] > cap:
                digits[c] = cap
    meta = {"scene_sha256": scene.digest, "physics_sha256": physics_digest(scene), "t_end": t_end,
            "method": {k: v for k, v in method.items()}, "refinement": refinement,
            "observed_order": observed, "digits": digits,
            "digits_note": "−log10(max(|y_h − y_2h|, |y_h − y_4h|/3) / max |y_h|) per column "
                           "(adaptive: |y_rtol − y_100rtol|): the error of the stored (finest) "
                           "history for a first-order method, an overestimate for a higher "
                           "order, still a bound when the differences do not shrink; for u, v, "
                           "penetration and force, capped by the difference from the "
                           "cross-check method",
            "stored": {"every_s": store, "rows": len(grid)},
            "events": events, "peaks": peaks, "event_refinement": ev_diff,
            "event_horizon": t_end, "cross_check": cross,
            "engine": ENGINE_DESCRIPTION if method["integrator"] == ENGINE else
            f"the library's {method['integrator']}",
            "not_run": not_run,
            "masses": {n["name"]: n["mass"] for n in scene.nodes},
            "cost": fs["cost"],
            "martello_version": native.version(), "libraries": native.library_versions(),
            "python_numpy": np.__version__,
            "date": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())}
    return {"grid": grid, "columns": cols, "fine": fine, "digits": digits, "meta": meta}


def _cross_check(methods, chosen, scene, sdict, scene_path, grid, store, fine, stream, keep_output,
                 not_run=None):
    """The next method of the list that runs the scene, as an independent check of the
    chosen one: its method, max relative difference of u and per-column digits
    (−log10 of the difference over the column's peak: the digits the two agree to), or
    None. A method that cannot run the scene is added to not_run with why."""
    for other in methods:
        if other is chosen or other.get("cross_check") is False:
            continue
        # only the methods after the chosen one: those before it did not run the scene
        if methods.index(other) < methods.index(chosen):
            continue
        if other["integrator"] == ENGINE:
            try:
                r = engine_run(sdict, scene_path.parent, float(other["rtol"]), grid, scene.analysis["t_end"])
            except Unsupported as exc:
                if not_run is not None:
                    not_run.append({"method": ENGINE, "why": f"does not model {exc}"})
                continue
        else:
            spec = _spec(other, sdict, scene_path, float(other["dt"]), other.get("rtol"), store,
                         keep_output)
            r = execute(spec)
        if r["status"] != "MARTELLO_OK":
            if not_run is not None:
                not_run.append({"method": other["integrator"], "why": f"{r['status']}: {r.get('message', '')}"})
            continue
        oy = _sampled(r, grid)
        per = {}
        for c in fine:
            if c in oy and c in fine:
                scale = float(np.max(np.abs(fine[c])))
                diff = float(np.max(np.abs(oy[c] - fine[c])))
                per[c] = min(15.0, -math.log10(diff / scale)) if scale > 0 and diff > 0 else 15.0
        rel_u = max(float(np.max(np.abs(oy[c] - fine[c])) / max(np.max(np.abs(fine[c])), 1e-300))
                    for c in fine if c.startswith("u:"))
        cross = {"method": dict(other), "max_rel_diff_u": rel_u, "digits": per}
        print(f"  cross-check with {other['integrator']}: max rel. difference of u {rel_u:.2e}",
              file=stream)
        return cross
    return None


def write_reference(folder, out, meta):
    """Write a computed reference: folder/history.csv (the samples) and reference.json (its
    provenance)."""
    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    digits, cols, grid, fine = out["digits"], out["columns"], out["grid"], out["fine"]
    # two digits beyond the trusted ones: rounding adds < 1 % to the reference's error
    prec = int(min(17, max(8, math.ceil(max(digits.values(), default=12.0)) + 2)))
    data = np.column_stack([grid] + [fine[c] for c in cols[1:]])
    np.savetxt(folder / "history.csv", data, delimiter=",", header=",".join(cols), comments="",
               fmt=f"%.{prec - 1}e")
    meta = dict(meta)
    meta["stored"] = dict(meta.get("stored", {}), significant_digits=prec)
    (folder / "reference.json").write_text(strict_json(meta) + "\n")
    return folder


def regenerate_references(names=None, root=REFERENCE_ROOT, stream=sys.stderr, jobs=0):
    entries = manifest(root)
    if names:
        unknown = set(names) - {e["name"] for e in entries}
        if unknown:
            raise MartelloError(f"unknown reference(s) {', '.join(sorted(unknown))}; known: "
                                + ", ".join(e["name"] for e in entries))
        entries = [e for e in entries if e["name"] in names]
    return [build_reference(e, root, stream, jobs) for e in entries]
