"""P11's case-study buildings taken into OpenSees by `martello export` and scored there
(docs/opensees.md "Buildings"): a cross-check of the exporter against an independent code.

    .venv/bin/python benchmarks/p11/export_check.py -o DIR [--python PY] [--config A]
        [--record 1] [--t-end 2] [--damper-alpha 1]

1. The case-study scene (benchmarks/p11/case_study.py's scene_dict: the 2- and 5-storey RC frame
   buildings on rigid floors, B with its stair well and lift core, gaps along the 2 cm joint,
   the fluid-viscous devices of configuration --config) is written to DIR/scene.toml with what
   the export needs changed, each stated in the report: with --damping rayleigh, Rayleigh
   damping instead of the catalogue's modal damping (which is written as OpenSees' eigen and
   modalDamping: docs/opensees.md "Modal damping"), the devices' exponent --damper-alpha (OpenSees' Newton does not converge across
   the α = 0.15 power law's cusp at rest: docs/opensees.md), t_end.
2. `martello export` writes DIR/opensees/model.py; `model.py --periods` runs OpenSees' eigen
   (fullGenLapack) on the uncondensed 3D frame: every period against martello's modal table of
   the condensed model (cross-check against an independent code: the two share the input
   numbers only).
3. `model.py` runs the time history (Newmark ½, ¼ at the scene's Δt): its floors, gaps and
   the member moments of members.csv against martello's own Newmark run of the condensed
   model (the same discrete equations: they agree to the solvers' tolerances), then
   `martello compare DIR/opensees/history.csv --against DIR/scene.toml` scores it against
   martello's reference for the scene (rk8pd, computed on demand and cached). The plan is
   symmetric about y and the motion along x: every floor's uy is round-off in both codes
   (|u_ref| ~ 1e-17 m), which compare reports as round-off, not scored (docs/compare.md);
   the report gives the per-column digits of the scored columns.

With --variants instead: the exporter's other paths on P11's OpenSees check scene
(benchmarks/p11/opensees_check.py: two frame buildings, eccentric gaps, a sine along x; here
with two linear fluid dampers between plan points, 0.5 s), one change at a time — a reference
point off the mass centres, shear-type storeys, pinned feet, a ground angle of 30°, Timoshenko
columns, a flexible first floor, a split point struck by a floor — each against martello's
own Newmark run as in 3.

Printed and written to DIR/export_check.txt (DIR/variants.txt). openseespy runs under --python
(default: this interpreter)."""

from __future__ import annotations

import argparse
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
sys.path.insert(0, str(ROOT))

from benchmarks.p10.case_study import scene_toml  # noqa: E402
from benchmarks.p11.case_study import SCENES, scene_dict  # noqa: E402


def scene(config, record, t_end, alpha, damping="modal"):
    d = scene_dict(config, record)
    changes = [] if damping == "modal" else ["damping = \"rayleigh\" (rayleigh_modes [1, 2]) instead of modal"]
    for b in d["building"]:
        b["damping"] = damping
        b["histories"] = True
    if d.get("link") and alpha is not None:
        for lk in d["link"]:
            lk["alpha"] = alpha
        changes.append(f"fluid dampers' alpha = {alpha:g} instead of 0.15")
    d["analysis"]["t_end"] = t_end
    changes.append(f"t_end = {t_end:g} s")
    g = d["loads"]["ground_acceleration"]
    g["file"] = str((SCENES / g["file"]).resolve())
    return d, changes


def provenance(python):
    """What the numbers were obtained with: martello's version and commit (with "+changes" when
    the checkout differs from it), the openseespy version under `python` and the OpenSees
    version it reports."""
    from martello.binding import native
    git = ["git", "-C", str(ROOT)]
    commit = subprocess.run(git + ["rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    dirty = subprocess.run(git + ["status", "--porcelain", "--untracked-files=no"],
                           capture_output=True, text=True).stdout.strip()
    r = subprocess.run([python, "-c", "import importlib.metadata as m, openseespy.opensees as ops; "
                        "print(m.version('openseespy'), ops.version())"], capture_output=True, text=True)
    os_v = r.stdout.split()[:2] if r.returncode == 0 else ["?", "?"]
    return (f"martello {native.version()} at {commit or 'unknown commit'}{' +changes' if dirty else ''}, "
            f"OpenSeesPy {os_v[0]} (OpenSees {os_v[1]})")


def family_errors(head, rows, cols, data):
    """max |OpenSees − martello| over each column family (u, v, a, penetration, ...), divided
    by the family's largest |martello| value."""
    scale, err = {}, {}
    for c in head[1:]:
        if c not in cols:
            continue
        k = c.split(":")[0]
        scale[k] = max(scale.get(k, 0.0), float(np.max(np.abs(data[:, cols.index(c)]))))
    for c in head[1:]:
        if c not in cols:
            continue
        k = c.split(":")[0]
        e = float(np.max(np.abs(rows[:, head.index(c)] - data[:, cols.index(c)])))
        err[k] = max(err.get(k, 0.0), e / scale[k] if scale[k] > 0 else e)
    return err, scale


def variants(t_end=0.5):
    """(name, scene dict) of the check scene's variants (--variants)."""
    from benchmarks.p11 import opensees_check as oc

    def base():
        d = oc.scene(t_end + 0.01, 1e-3)          # the table reaches past t_end
        d["analysis"]["t_end"] = t_end
        for b in d["building"]:
            b["histories"] = True
        d["link"] = [{"name": f"fvd{f}", "type": "fluid_damper", "a": {"floor": f"A{f}", "x": 5.0, "y": 6.0},
                      "b": {"floor": f"B{f}", "x": 5.02, "y": 6.0}, "direction": [1.0, 0.0], "c": 2e5,
                      "alpha": 1.0, "v_reg": 0.0} for f in (1, 2)]
        return d
    out = [("as written", base())]
    d = base()
    d["building"][1]["reference"] = [11.0, 3.0]
    out.append(("B's reference off its mass centres", d))
    d = base()
    for b in d["building"]:
        b["model"] = "shear"
        b.pop("beam")
    out.append(("shear-type storeys", d))
    d = base()
    d["building"][0]["base"] = "pinned"
    out.append(("A's feet pinned", d))
    d = base()
    for b in d["building"]:
        b["ground_angle"] = 30.0
    out.append(("ground angle 30 degrees", d))
    d = base()
    d["building"][1]["column"] = dict(oc.COLUMN, As2=0.13, As3=0.12)
    out.append(("B's columns Timoshenko", d))
    d = base()
    d["building"][0]["diaphragm"] = [False, True]
    d["contact"] = [c for c in d["contact"] if not c["a"]["floor"].endswith("1")]
    d["link"] = [lk for lk in d["link"] if not lk["a"]["floor"].endswith("1")]
    d["analysis"]["output"]["contacts"] = [c["name"] for c in d["contact"]]
    out.append(("A's first floor flexible", d))
    d = base()
    d["building"][1]["split"] = [{"name": "S", "line": "0.1", "storey": 2, "height": 1.5, "mass": 1000.0}]
    d["contact"].append({"name": "gs", "a": {"floor": "A2", "x": 5.0, "y": 4.0}, "b": {"point": "B.S"},
                         "normal": [1.0, 0.0], "gap": 0.02, "scheme": "penalty", "law": "linear", "stiffness": 5e8})
    d["analysis"]["output"]["contacts"].append("gs")
    out.append(("A2 strikes a split point of B's column", d))
    return out


def run_variants(args, out):
    from martello.export import export
    from martello.run import run_full
    from martello.scene.loader import from_dict
    lines = [f"P11 check scene's variants exported and run by OpenSees against martello's Newmark run "
             f"({provenance(args.python)}; benchmarks/p11/export_check.py --variants; Newmark 1 ms, 0.5 s); "
             "largest difference over a column family / the family's largest value"]
    for k, (name, d) in enumerate(variants()):
        sc = from_dict(d, source=f"variant {k}")
        folder = out / f"variant{k}"
        export(sc, folder)
        r = subprocess.run([args.python, "model.py"], cwd=folder, capture_output=True, text=True)
        if r.returncode:
            lines.append(f"{name}: OpenSees failed: {r.stdout.strip()[-300:]}")
            continue
        summary, (cols, data) = run_full(sc)
        cols = list(cols)
        err = {}
        for f in ("history.csv", "members.csv"):
            head = (folder / f).read_text().splitlines()[0].split(",")
            err.update(family_errors(head, np.loadtxt(folder / f, delimiter=",", skiprows=1), cols, data)[0])
        impacts = sum(c["impacts"] for c in summary["contacts"].values())
        lines.append(f"  {name} ({impacts} impacts): " + ", ".join(f"{q} {e:.1e}" for q, e in err.items()))
    text = "\n".join(lines)
    print(text)
    (out / "variants.txt").write_text(text + "\n")
    return 0


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-o", "--output", required=True, help="a folder for the scene, the export and the report")
    ap.add_argument("--python", default=sys.executable, help="an interpreter with openseespy")
    ap.add_argument("--config", default="A", choices=("bare", "A", "B"))
    ap.add_argument("--record", type=int, default=1)
    ap.add_argument("--t-end", type=float, default=2.0)
    ap.add_argument("--damper-alpha", type=float, default=1.0)
    ap.add_argument("--damping", default="modal", choices=("modal", "rayleigh"),
                    help="the buildings' damping (the catalogue's: modal)")
    ap.add_argument("--variants", action="store_true", help="the check scene's variants instead")
    args = ap.parse_args()
    from martello.binding import native
    from martello.export import export
    from martello.run import run_full
    from martello.scene.loader import load
    out = Path(args.output)
    out.mkdir(parents=True, exist_ok=True)
    if args.variants:
        return run_variants(args, out)
    d, changes = scene(args.config, args.record, args.t_end, args.damper_alpha, args.damping)
    path = out / "scene.toml"
    path.write_text(scene_toml(d, ("building", "contact", "link")))
    sc = load(path)
    folder = out / "opensees"
    export(sc, folder)
    lines = [f"P11 case study {args.config}, record {args.record}, exported by {provenance(args.python)} "
             f"(benchmarks/p11/export_check.py --config {args.config} --record {args.record} --t-end "
             f"{args.t_end:g} --damper-alpha {args.damper_alpha:g} --damping {args.damping}); changed from "
             "the catalogue scene: " + "; ".join(changes)]
    r = subprocess.run([args.python, "model.py", "--periods"], cwd=folder, capture_output=True, text=True)
    if r.returncode:
        sys.exit("model.py --periods failed:\n" + r.stderr[-2000:])
    os_T = np.loadtxt(folder / "periods.csv", delimiter=",", skiprows=1, ndmin=2)[:, 1]
    m_T = sorted((md["period"] for b in sc.extras["buildings"] for md in b["modes"]), reverse=True)
    lines.append(f"periods: {len(m_T)} modes of both buildings (martello's condensed model, OpenSees' eigen "
                 "-fullGenLapack on the 3D frame)")
    lines.append(f"{'mode':>5} {'martello [s]':>16} {'OpenSees [s]':>16} {'rel. diff':>10}")
    worst_T = 0.0
    for k, (a, b) in enumerate(zip(m_T, os_T)):
        rel = abs(a - b) / a
        worst_T = max(worst_T, rel)
        lines.append(f"{k + 1:>5} {a:>16.10f} {b:>16.10f} {rel:>10.2e}")
    lines.append(f"worst relative difference of the periods: {worst_T:.2e}")
    t0 = time.perf_counter()
    r = subprocess.run([args.python, "model.py"], cwd=folder, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    if r.returncode:
        lines.append("OpenSees' time history failed: " + r.stdout.strip()[-300:])
        print("\n".join(lines))
        (out / "export_check.txt").write_text("\n".join(lines) + "\n")
        return 1
    summary, (cols, data) = run_full(sc)
    cols = list(cols)
    head = (folder / "history.csv").read_text().splitlines()[0].split(",")
    rows = np.loadtxt(folder / "history.csv", delimiter=",", skiprows=1)
    err, scale = family_errors(head, rows, cols, data)
    mhead = (folder / "members.csv").read_text().splitlines()[0].split(",")
    mrows = np.loadtxt(folder / "members.csv", delimiter=",", skiprows=1)
    merr, mscale = family_errors(mhead, mrows, cols, data)
    an = sc.analysis
    lines.append(f"time history: Newmark (1/2, 1/4), dt = {an['dt']:g} s, {an['t_end']:g} s; OpenSees "
                 f"{wall:.0f} s wall; against martello's own Newmark run of the condensed model (largest "
                 "difference over a column family / the family's largest value):")
    for k in err:
        lines.append(f"  {k:>12}: {err[k]:.2e}  (scale {scale[k]:.4g})")
    for k in merr:
        lines.append(f"  {k + ' of members':>12}: {merr[k]:.2e}  (scale {mscale[k]:.4g} N m)")
    impacts = sum(c["impacts"] for c in summary["contacts"].values())
    lines.append(f"  impacts in martello's run: {impacts}")
    r = subprocess.run([sys.executable, "-m", "martello", "compare", str(folder / "history.csv"),
                        "--against", str(path), "-o", str(out / "compare.json")],
                       capture_output=True, text=True, cwd=ROOT)
    lines.append("martello compare (its reference for the scene; -o compare.json):")
    lines += ["  " + ln for ln in r.stdout.splitlines() if ln.split(" ")[0] in (
        "reference:", "scd", "max_rel_error", "impact_count", "impact_count_ref", "impact_time_error",
        "peak_penetration_error", "energy_error")]
    if r.returncode:
        lines.append("  failed: " + r.stderr.strip()[-500:])
    else:
        import json
        full = json.loads((out / "compare.json").read_text())
        rep = full["per_column"]
        for kind in ("u", "v"):
            scd = [v["scd"] for c, v in rep.items() if c.startswith(f"{kind}:") and not v.get("round_off")]
            if scd:
                lines.append(f"  per-column scd of {kind} (scored columns): {min(scd):.2f} to {max(scd):.2f}")
        uy = [c for c in cols if c.startswith("u:") and c.endswith(".uy")]
        peak = max((float(np.max(np.abs(data[:, cols.index(c)]))) for c in uy), default=0.0)
        lines.append(f"  round-off, not scored by compare: {', '.join(full.get('round_off_columns', [])) or 'none'} "
                     f"(largest |uy| of martello's run {peak:.1e} m)")
    text = "\n".join(lines)
    print(text)
    (out / "export_check.txt").write_text(text + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
