"""The stability atlas: where each method breaks (docs/studies.md).

Small, exactly solvable contact experiments are swept over the step ratio Δt/Δt_crit (with
Δt_crit = 2/ω_max, ω_max the highest frequency with every contact closed), the penalty
stiffness ratio ε/k, the restitution e, the mass ratio, a zero gap and a Zeno sequence. Each
run is classified

* accurate: max error of the displacement against the exact history, over the range of the
  exact displacement, ≤ accurate_tol (the velocity error is reported, not used: it is O(1)
  wherever an impact is shifted by a fraction of its duration);
* inaccurate: it ran, stayed bounded, and is less accurate than that;
* unstable (energy growth): the divergence detector stopped it, or the energy it made —
  mechanical energy minus initial energy minus input work — exceeds growth_tol times the
  kinetic energy scale of the motion in free flight after an impact, or (persistent
  contact) its error keeps growing: ten times larger in the last third of the window than
  in the first;
* failed: NaN, no Newton convergence, step-size underflow, or another solver failure;
* unavailable: the integrator is not built yet (shown grey; re-run the atlas when it lands),

and drawn as one map per experiment with one panel per method. The experiments and their
exact solutions (martello.reference.closed_form → martello.oracles):

* impact: a mass on a spring (ω_s = 10 rad/s) reaches a rigid wall at 1 m/s after 3 steps
  or 3 contact times, whichever is longer, and is followed for 6 more: one impact on a
  Kelvin (e < 1) or linear (e = 1) wall of stiffness ε;
* two_body: a free mass m1 = 1 hits a free mass m2 = mass_ratio at 1 m/s through a Kelvin
  contact (relative motion exact, centre of mass uniform);
* zero_gap: the mass rests on the wall (gap 0), pressed 1 mm into it by a body force, and
  oscillates with an amplitude of 1/1000 of that: the contact never opens, the system is
  linear, and central difference must become unstable exactly at Δt = 2/ω_max (a test);
* zeno: P2 (m = 1, k = 100, h = 0.05, g = 9.81) on a Kelvin plane: the impacts accumulate and
  the mass settles on the plane.

The atlas file (benchmarks/studies/atlas.toml) is run by `martello study`."""

from __future__ import annotations

import csv
import math
import os
import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..batch import run_specs
from ..binding import native
from ..errors import MartelloError, StudyError
from ..history import history_dict
from ..oracles.p2_bouncing import bouncing_oscillator_restitution
from ..paths import OUTPUT_ROOT, REPO, check_output_folder
from ..reference.closed_form import kelvin_bounce_reference, two_body_kelvin_reference
from ..scene.spec import ADAPTIVE, INTEGRATORS
from .outcome import failed_rows, status_class
from .output import Progress, csv_cell, md_cell, palette_png, slug
from .resume import row_key, run_resumable
from .study_file import read_toml
CLASSES = ("accurate", "inaccurate", "unstable", "failed", "unavailable", "no reference")
CLASS_COLORS = {"accurate": "#2ca02c", "inaccurate": "#ffd92f", "unstable": "#d62728",
                "failed": "#000000", "unavailable": "#cccccc", "no reference": "#9ecae1"}
AXES = ("dt_ratio", "stiffness_ratio", "restitution", "mass_ratio")
EXPERIMENT_DEFAULTS = {
    "impact": {"stiffness_ratio": 1e4, "restitution": 0.8},
    "two_body": {"stiffness_ratio": 1e4, "restitution": 0.8, "mass_ratio": 1.0},
    "zero_gap": {"stiffness_ratio": 1e4, "restitution": 1.0},
    "zeno": {"stiffness_ratio": 1e4, "restitution": 0.8},
}
M, K, G, H = 1.0, 100.0, 9.81, 0.05          # the SDOF of the impact, zero-gap and Zeno experiments
MAX_ROWS = 4000                                # output rows per run (every = steps / MAX_ROWS)


@dataclass
class Experiment:
    scene: dict          # scene dict without [analysis]
    reference: object    # martello.reference.base.Reference
    omega_max: float     # rad/s, every contact closed
    t_end: float
    persistent: bool     # the contact never opens in the exact solution


def _contact(law_e, eps, a="mass", b="ground", gap=0.0, name="wall"):
    c = {"name": name, "a": a, "b": b, "gap": gap, "scheme": "penalty", "stiffness": eps}
    if law_e >= 1.0:
        c["law"] = "linear"
    else:
        c.update(law="kelvin", restitution=law_e)
    return c


def experiment(kind, dt_ratio=1.0, stiffness_ratio=1e4, restitution=0.8, mass_ratio=1.0,
               window=None):
    """The scene, exact reference, ω_max and window of one atlas experiment at one point."""
    e = float(restitution)
    if kind in ("impact", "zero_gap", "zeno"):
        eps = stiffness_ratio * K
        w = math.sqrt((K + eps) / M)
        dt = dt_ratio * 2.0 / w
        tc = math.pi / w
        if kind == "impact":
            ws = math.sqrt(K / M)
            s = max(tc, dt)
            t_pre = min(3.0 * s, 0.5 * math.pi / ws)   # at most a quarter of the free period
            # the free trajectory (about u = 0) that reaches u = H at 1 m/s after t_pre
            u0 = H * math.cos(ws * t_pre) - (1.0 / ws) * math.sin(ws * t_pre)
            v0 = H * ws * math.sin(ws * t_pre) + math.cos(ws * t_pre)
            t_end = window or (t_pre + tc + 6.0 * s)
            d = {"node": [{"name": "mass", "mass": M, "u0": u0, "v0": v0}],
                 "link": [{"type": "spring", "a": "mass", "b": "ground", "k": K}],
                 "contact": [_contact(e, eps, gap=H)]}
            ref = kelvin_bounce_reference(t_end, M, K, H, 0.0, eps,
                                          restitution=e if e < 1 else None,
                                          u0=u0, v0=v0, node="mass", contact="wall")
            return Experiment(d, ref, w, t_end, False)
        if kind == "zero_gap":
            # the load presses the mass 1 mm into the wall whatever ε is (g scaled with ε), so
            # the oscillation (1 µm) stays far above any integrator's absolute tolerance
            g_zg = 1e-3 * (K + eps) / M
            u_eq = M * g_zg / (K + eps)
            v0 = 1e-3 * u_eq * w
            t_end = window or max(20.0 * 2.0 * math.pi / w, 40.0 * dt)
            d = {"node": [{"name": "mass", "mass": M, "u0": u_eq, "v0": v0}],
                 "link": [{"type": "spring", "a": "mass", "b": "ground", "k": K}],
                 "contact": [_contact(e, eps, gap=0.0)], "loads": {"gravity": g_zg}}
            ref = kelvin_bounce_reference(t_end, M, K, 0.0, g_zg, eps,
                                          restitution=e if e < 1 else None,
                                          u0=u_eq, v0=v0, node="mass", contact="wall")
            return Experiment(d, ref, w, t_end, True)
        # zeno: P2, released from rest with the spring unstretched
        seq = bouncing_oscillator_restitution(M, K, H, G, e, 200)
        t_end = window or (1.5 * seq.zeno_time if math.isfinite(seq.zeno_time) else 1.5)
        d = {"node": [{"name": "mass", "mass": M}],
             "link": [{"type": "spring", "a": "mass", "b": "ground", "k": K}],
             "contact": [_contact(e, eps, gap=H)], "loads": {"gravity": G}}
        ref = kelvin_bounce_reference(t_end, M, K, H, G, eps,
                                      restitution=e if e < 1 else None,
                                      node="mass", contact="wall")
        return Experiment(d, ref, w, t_end, False)
    if kind == "two_body":
        m1, m2 = 1.0, float(mass_ratio)
        ms = m1 * m2 / (m1 + m2)
        eps = stiffness_ratio * K
        w = math.sqrt(eps / ms)
        dt = dt_ratio * 2.0 / w
        tc = math.pi / w
        s = max(tc, dt)
        gap = 1.0 * 3.0 * s             # closed at 1 m/s after 3 steps or contact times
        t_end = window or (3.0 * s + tc + 6.0 * s)
        d = {"node": [{"name": "m1", "mass": m1, "v0": 1.0}, {"name": "m2", "mass": m2}],
             "contact": [_contact(e, eps, a="m1", b="m2", gap=gap, name="impact")]}
        ref = two_body_kelvin_reference(t_end, m1, m2, gap, eps,
                                        restitution=e if e < 1 else None,
                                        v1=1.0, node1="m1", node2="m2", contact="impact")
        return Experiment(d, ref, w, t_end, False)
    raise StudyError("atlas", "map.experiment", f"unknown experiment {kind!r}",
                     "valid: " + ", ".join(EXPERIMENT_DEFAULTS))


def classify(result, exp, accurate_tol=0.05, growth_tol=0.1):
    """(class, detail dict) of one atlas run (see the module docstring)."""
    status = result.get("status")
    detail = {"error": math.nan, "velocity_error": math.nan, "energy_growth": math.nan,
              "error_growth": math.nan}
    if status == "MARTELLO_ERR_UNSUPPORTED":
        return "unavailable", detail
    if status in ("incompatible", "error"):
        return "failed", detail
    cls = status_class(status, result.get("message", ""))
    if cls == "diverged: NaN":
        return "failed", detail
    if cls.startswith("diverged") or cls.startswith("unstable"):
        return "unstable", detail
    if cls != "ok":
        return "failed", detail
    h = history_dict(result["history"])
    t = h["t"]
    if not all(np.all(np.isfinite(v)) for v in h.values()):
        return "failed", detail
    ref = exp.reference.at(t, exp.reference.columns)
    err_u, err_v, dev = [], [], np.zeros_like(t)
    for c in exp.reference.columns:
        if c.startswith("u:") and c in h:
            rng = float(np.ptp(ref[c])) or 1.0
            d = np.abs(h[c] - ref[c]) / rng
            err_u.append(float(np.max(d)))
            dev = np.maximum(dev, d)
        if c.startswith("v:") and c in h:
            err_v.append(float(np.max(np.abs(h[c] - ref[c]))) / (float(np.max(np.abs(ref[c]))) or 1.0))
    # the class is decided on u: a velocity error is O(1) wherever an impact is shifted by a
    # fraction of its duration (v turns over in it), whatever the shift's size in time
    err = max(err_u)
    detail["error"] = err
    detail["velocity_error"] = max(err_v) if err_v else math.nan
    kin = sum(0.5 * exp.reference.masses[c[2:]] * ref[c] ** 2 for c in ref if c.startswith("v:"))
    e_scale = float(np.max(kin)) or 1.0
    created = (h["energy:kinetic"] + h["energy:recoverable"] - h["energy:initial"]
               - h["energy:input"]) / e_scale
    open_ = np.ones_like(t, bool)
    first = math.inf
    for c in h:
        if c.startswith("penetration:"):
            open_ &= h[c] <= 0
            on = np.nonzero(h[c] > 0)[0]
            first = min(first, t[on[0]] if len(on) else math.inf)
    flight = open_ & (t > first)
    growth = float(np.max(created[flight])) if np.any(flight) else -math.inf
    detail["energy_growth"] = growth
    if exp.persistent and len(t) >= 9:
        n3 = len(t) // 3
        early, late = float(np.max(dev[:n3])), float(np.max(dev[-n3:]))
        detail["error_growth"] = late / early if early > 0 else (math.inf if late > 0 else 1.0)
        if late > 10.0 * early and late > accurate_tol:
            return "unstable", detail
    if growth > growth_tol:
        return "unstable", detail
    return ("accurate" if err <= accurate_tol else "inaccurate"), detail


# =============================================================================================
# The atlas file
# =============================================================================================
ATLAS_KEYS = {"kind", "title", "description", "output", "accurate_tol", "growth_tol", "method",
              "map", "atlas"}
METHOD_KEYS = {"label", "integrator", "params", "rtol"}
MAP_KEYS = {"name", "title", "experiment", "x", "y", "fixed"}


def load_atlas(path):
    path = Path(path)
    raw = read_toml(path)
    for k in raw:
        if k not in ATLAS_KEYS:
            raise StudyError(path, k, "unknown key", "valid: " + ", ".join(sorted(ATLAS_KEYS)))
    methods = []
    for i, m in enumerate(raw.get("method", [])):
        for k in m:
            if k not in METHOD_KEYS:
                raise StudyError(path, f"method[{i}].{k}", "unknown key", "valid: " + ", ".join(sorted(METHOD_KEYS)))
        if m.get("integrator") not in INTEGRATORS:
            raise StudyError(path, f"method[{i}].integrator", f"unknown integrator {m.get('integrator')!r}",
                             "valid: " + ", ".join(INTEGRATORS))
        methods.append({"label": m.get("label", m["integrator"]), "integrator": m["integrator"],
                        "params": dict(m.get("params", {})), "rtol": list(m.get("rtol", []))})
    maps = []
    for i, mp in enumerate(raw.get("map", [])):
        for k in mp:
            if k not in MAP_KEYS:
                raise StudyError(path, f"map[{i}].{k}", "unknown key", "valid: " + ", ".join(sorted(MAP_KEYS)))
        if mp.get("experiment") not in EXPERIMENT_DEFAULTS:
            raise StudyError(path, f"map[{i}].experiment", f"unknown experiment {mp.get('experiment')!r}",
                             "valid: " + ", ".join(EXPERIMENT_DEFAULTS))
        for ax in ("x", "y"):
            tab = mp.get(ax)
            if not isinstance(tab, dict) or len(tab) != 1 or next(iter(tab)) not in AXES:
                raise StudyError(path, f"map[{i}].{ax}", "must name one axis and its values",
                                 "e.g. { dt_ratio = [0.1, 1, 10] }; axes: " + ", ".join(AXES))
        maps.append({"name": mp.get("name", f"map{i}"), "title": mp.get("title", ""),
                     "experiment": mp["experiment"], "x": mp["x"], "y": mp["y"],
                     "fixed": dict(mp.get("fixed", {}))})
    if not methods or not maps:
        raise StudyError(path, "method/map", "an atlas needs at least one [[method]] and one [[map]]")
    return {"path": path, "title": raw.get("title", path.stem), "description": raw.get("description", ""),
            "output": raw.get("output"), "accurate_tol": float(raw.get("accurate_tol", 0.05)),
            "growth_tol": float(raw.get("growth_tol", 0.1)), "methods": methods, "maps": maps}


def point_spec(mp, method, xv, yv, ident):
    """(spec, Experiment, parameters) of one atlas run."""
    (xa, _), (ya, _) = next(iter(mp["x"].items())), next(iter(mp["y"].items()))
    par = dict(EXPERIMENT_DEFAULTS[mp["experiment"]], dt_ratio=1.0)
    par.update(mp["fixed"])
    adaptive = method["integrator"] in ADAPTIVE
    par[ya] = yv
    if not (adaptive and xa == "dt_ratio"):
        par[xa] = xv
    exp = experiment(mp["experiment"], **par)
    dt = par["dt_ratio"] * 2.0 / exp.omega_max
    an = {"type": "dynamic", "integrator": method["integrator"], "t_end": exp.t_end}
    an.update(method["params"])
    if adaptive:
        an["dt"] = exp.t_end / 400.0          # the output interval
        an["rtol"] = xv if xa == "dt_ratio" else an.get("rtol", 1e-8)
        every = 1
    else:
        steps = max(1, int(round(exp.t_end / dt)))
        an["dt"] = dt
        every = max(1, steps // MAX_ROWS)
    an["output"] = {"every": every}
    d = dict(exp.scene, analysis=an)
    spec = {"id": ident, "scene_dict": d, "scene_file": "<atlas>", "base_dir": str(REPO), "repeat": 1}
    return spec, exp, par


def _row(res, info, specs, atlas):
    mp, method, xv, yv, exp, par = info[res["id"]]
    if exp is None:
        cls, det = "no reference", {"error": math.nan, "velocity_error": math.nan,
                                    "energy_growth": math.nan, "error_growth": math.nan}
    else:
        cls, det = classify(res, exp, atlas["accurate_tol"], atlas["growth_tol"])
    s = res.get("summary") or {}
    cost = s.get("cost") or {}
    stab = s.get("stability") or {}
    (xa, _), (ya, _) = next(iter(mp["x"].items())), next(iter(mp["y"].items()))
    adaptive = method["integrator"] in ADAPTIVE
    return {"run": res["id"], "map": mp["name"], "experiment": mp["experiment"],
            "method": method["label"], "integrator": method["integrator"],
            "x_axis": "rtol" if (adaptive and xa == "dt_ratio") else xa, "x": xv,
            "y_axis": ya, "y": yv, "dt_ratio": par["dt_ratio"] if not adaptive else math.nan,
            "stiffness_ratio": par.get("stiffness_ratio", math.nan),
            "restitution": par.get("restitution", math.nan),
            "mass_ratio": par.get("mass_ratio", math.nan),
            "omega_max": exp.omega_max if exp else math.nan,
            "dt_critical": 2.0 / exp.omega_max if exp else math.nan,
            "dt_critical_reported": stab.get("dt_critical") or math.nan,
            "dt": res_dt(specs[res["id"]]), "t_end": exp.t_end if exp else math.nan,
            "class": cls, "status": res.get("status"),
            "message": (res.get("message") or "").strip()[:300], **det,
            "steps": cost.get("steps", math.nan),
            "residual_evaluations": cost.get("residual_evaluations", math.nan),
            "wall_time_s": cost.get("wall_time_s", math.nan)}


def run_atlas(atlas, outdir, jobs=0, plots=True, stream=sys.stderr):
    """Run an atlas into outdir: atlas.csv, a map per [[map]], atlas.md. Stopped by a signal
    it keeps the finished rows and the same call resumes it (martello.study.resume)."""
    check_output_folder(outdir, "atlas.csv", MartelloError)   # before hours of runs, not after
    t0 = time.perf_counter()
    specs, info = [], {}
    for mp in atlas["maps"]:
        (xa, xs), (ya, ys) = next(iter(mp["x"].items())), next(iter(mp["y"].items()))
        for method in atlas["methods"]:
            adaptive = method["integrator"] in ADAPTIVE
            xvals = method["rtol"] if (adaptive and xa == "dt_ratio") else xs
            for yv in ys:
                for xv in xvals:
                    try:
                        spec, exp, par = point_spec(mp, method, xv, yv, len(specs))
                    except (ValueError, RuntimeError) as exc:
                        # the closed form could not be evaluated here: the point is kept,
                        # marked, and not run (it could not be classified)
                        spec = {"id": len(specs), "status": "no reference",
                                "message": f"closed form failed: {exc}"}
                        exp, par = None, {"dt_ratio": xv if xa == "dt_ratio" else math.nan, ya: yv}
                    specs.append(spec)
                    info[spec["id"]] = (mp, method, xv, yv, exp, par)
    print(f"{atlas['title']}: {len(atlas['maps'])} map(s) x {len(atlas['methods'])} method(s): "
          f"{len(specs)} runs on {jobs or os.cpu_count()} worker(s)", file=stream)
    by_id = {s["id"]: s for s in specs}
    # what a row depends on (martello.study.resume)
    keys = {s["id"]: row_key({k: v for k, v in s.items() if k != "id"}, info[s["id"]][0]["name"],
                             info[s["id"]][0]["experiment"], info[s["id"]][1], info[s["id"]][2:4],
                             info[s["id"]][5], atlas["accurate_tol"], atlas["growth_tol"],
                             native.version())
            for s in specs}
    bounds = []

    def run(ids, stop):
        for res in run_specs([by_id[i] for i in ids], jobs, Progress(len(ids), stream=stream),
                             stop=stop):
            yield res["id"], _row(res, info, specs, atlas)

    def write(folder, rows, of=None):
        with open(folder / "atlas.csv", "w", newline="") as fh:
            w = csv.DictWriter(fh, fieldnames=list(rows[0]) if rows else [])
            w.writeheader()
            w.writerows({k: csv_cell(v) for k, v in r.items()} for r in rows)
        if of is not None:
            _markdown(atlas, rows, [], [], time.perf_counter() - t0, folder / "atlas.md", of=of)
            return
        bounds[:] = boundaries(rows)
        pngs = [plot_map(atlas, mp, rows, folder) for mp in atlas["maps"]] if plots else []
        _markdown(atlas, rows, bounds, pngs, time.perf_counter() - t0, folder / "atlas.md")

    # the folder is replaced whole once everything is written (docs/studies.md)
    rows = run_resumable(outdir, "atlas.csv", keys, run, write,
                         lambda folder, rows: write(folder, rows, of=len(specs)), stream)
    return rows, bounds


def res_dt(spec):
    return spec["scene_dict"]["analysis"]["dt"] if "scene_dict" in spec else math.nan


def boundaries(rows):
    """For each map, method and y: the largest Δt/Δt_crit still stable (accurate or
    inaccurate) below the smallest unstable one, and that smallest unstable one."""
    out = []
    keyset = sorted({(r["map"], r["method"], r["y"]) for r in rows if r["x_axis"] == "dt_ratio"},
                    key=lambda k: (k[0], k[1], k[2]))
    for mp, meth, y in keyset:
        pts = sorted((r for r in rows if (r["map"], r["method"], r["y"]) == (mp, meth, y)),
                     key=lambda r: r["x"])
        unstable = [r["x"] for r in pts if r["class"] == "unstable"]
        first_bad = min(unstable) if unstable else math.inf
        stable = [r["x"] for r in pts if r["class"] in ("accurate", "inaccurate") and r["x"] < first_bad]
        accurate = [r["x"] for r in pts if r["class"] == "accurate"]
        out.append({"map": mp, "method": meth, "y": y,
                    "largest_stable_ratio": max(stable) if stable else math.nan,
                    "smallest_unstable_ratio": first_bad,
                    "largest_accurate_ratio": max(accurate) if accurate else math.nan})
    return out


def plot_map(atlas, mp, rows, outdir):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.patches import Patch

    mine = [r for r in rows if r["map"] == mp["name"]]
    methods = [m["label"] for m in atlas["methods"]]
    fig, axes = plt.subplots(1, len(methods), figsize=(4.6 * len(methods), 4.2), squeeze=False)
    for ax, meth in zip(axes[0], methods):
        pts = [r for r in mine if r["method"] == meth]
        if not pts:
            ax.set_axis_off()
            continue
        xs = sorted({r["x"] for r in pts})
        ys = sorted({r["y"] for r in pts})
        for r in pts:
            i, j = xs.index(r["x"]), ys.index(r["y"])
            ax.add_patch(plt.Rectangle((i - 0.5, j - 0.5), 1, 1, color=CLASS_COLORS[r["class"]],
                                       ec="white", lw=0.8))
            if r["class"] in ("accurate", "inaccurate") and r["error"] == r["error"]:
                ax.text(i, j, f"{r['error']:.0e}".replace("e-0", "e-").replace("e+0", "e"),
                        ha="center", va="center", fontsize=5.5, color="k")
        ax.set_xlim(-0.5, len(xs) - 0.5)
        ax.set_ylim(-0.5, len(ys) - 0.5)
        ax.set_xticks(range(len(xs)), [f"{x:g}" for x in xs], fontsize=7, rotation=45)
        ax.set_yticks(range(len(ys)), [f"{y:g}" for y in ys], fontsize=7)
        x_axis = pts[0]["x_axis"]
        ax.set_xlabel({"dt_ratio": "Δt / Δt_crit  (Δt_crit = 2/ω_max)", "rtol": "rtol"}.get(x_axis, x_axis))
        ax.set_ylabel({"stiffness_ratio": "ε / k", "restitution": "e", "mass_ratio": "m2 / m1",
                       "dt_ratio": "Δt / Δt_crit"}.get(pts[0]["y_axis"], pts[0]["y_axis"]))
        if x_axis == "dt_ratio" and 1.0 not in xs:
            pos = np.interp(0.0, np.log(xs), np.arange(len(xs)))   # where Δt = Δt_crit falls
            ax.axvline(pos, color="k", ls="--", lw=1)
        elif x_axis == "dt_ratio":
            ax.axvline(xs.index(1.0), color="k", ls="--", lw=1)
        ax.set_title(meth, fontsize=9)
    handles = [Patch(color=CLASS_COLORS[c], label=c) for c in CLASSES]
    fig.legend(handles=handles, loc="lower center", ncol=len(CLASSES), fontsize=8, frameon=False)
    fig.suptitle(f"{atlas['title']}: {mp['title'] or mp['name']}  (dashed: Δt = 2/ω_max; "
                 f"numbers: max error, accurate ≤ {atlas['accurate_tol']:g})", fontsize=9)
    fig.tight_layout(rect=(0, 0.07, 1, 0.93))
    p = outdir / f"atlas__{slug(mp['name'])}.png"
    fig.savefig(p, dpi=90)
    palette_png(p)
    plt.close(fig)
    return p


def _markdown(atlas, rows, bounds, pngs, elapsed, path, of=None):
    """atlas.md; `of` (the number of runs of the atlas) for a partial output."""
    counts = {}
    for r in rows:
        counts[(r["method"], r["class"])] = counts.get((r["method"], r["class"]), 0) + 1
    lines = [f"# {atlas['title']}", "", atlas["description"].strip(), ""]
    if of is not None:
        lines += [f"**Partial: {len(rows)} of {of} runs** (the atlas was interrupted; the same "
                  f"command runs the other {of - len(rows)} and draws the maps; resume.jsonl "
                  "holds the rows it keeps).", ""]
    lines += [f"{len(rows)} runs in {elapsed:.1f} s; martello {native.version()}; accurate ≤ "
             f"{atlas['accurate_tol']:g}, energy growth > {atlas['growth_tol']:g} is unstable.", "",
             "| map | method | y | largest stable Δt/Δt_crit | smallest unstable | largest accurate |",
             "|---|---|---|---|---|---|"]
    for b in bounds:
        lines.append(f"| {md_cell(b['map'])} | {md_cell(b['method'])} | {b['y']:g} | {b['largest_stable_ratio']:g} | "
                     f"{b['smallest_unstable_ratio']:g} | {b['largest_accurate_ratio']:g} |")
    lines += ["", "| method | " + " | ".join(CLASSES) + " |", "|---|" + "---|" * len(CLASSES)]
    for m in atlas["methods"]:
        lines.append(f"| {md_cell(m['label'])} | " + " | ".join(str(counts.get((m["label"], c), 0)) for c in CLASSES) + " |")
    for p in pngs:
        lines += ["", f"![{p.stem}]({p.name})"]
    path.write_text("\n".join(lines) + "\n")


def output_folder(path, atlas, output=None):
    """The folder an atlas writes (as a study's: martello.study.sweep.output_folder)."""
    if output:
        return Path(output)
    return OUTPUT_ROOT / atlas["output"] if atlas["output"] else Path("out") / "studies" / Path(path).stem


def main(args):
    if getattr(args, "scheduler", None):
        raise StudyError(args.study, "--scheduler", "a stability atlas runs on the local cores; "
                         "only sweep studies run on a Dask cluster", "drop --scheduler (use -j)")
    atlas = load_atlas(args.study)
    out = output_folder(args.study, atlas, args.output)
    rows, bounds = run_atlas(atlas, out, jobs=getattr(args, "jobs", 0) or 0,
                             plots=not getattr(args, "no_plots", False))
    counts = {}
    for r in rows:
        counts[r["class"]] = counts.get(r["class"], 0) + 1
    print(f"{atlas['title']}: {len(rows)} runs (" + ", ".join(f"{v} {k}" for k, v in sorted(counts.items()))
          + f") -> {out / 'atlas.csv'}")
    return failed_rows(rows, "status", out / "atlas.csv")
