"""The exported model against a hand-built one, and its score (docs/opensees.md, "Exported
against hand-built").

    .venv/bin/python benchmarks/opensees/two_buildings.py [-o out/opensees-two-buildings] [--no-compare]

The scene two_buildings.scene (beside this file; not in the catalogue): two one-storey
buildings with bilinear columns and a hertzdamp joint. It is exported with `martello export
--to opensees`, the exported model.py is run by OpenSeesPy, the hand-built model of
hand_built.py (written without the exporter) is run too, and the two are compared on the
storeys' peak drifts (a one-storey building's drift is its u), the peak penetration and the
impact count; then `martello compare` scores the exported history against martello's
reference for the scene (computed on demand and cached: docs/reference.md). Needs openseespy
in the interpreter that runs it (requirements.txt; pip install 'martello[opensees]')."""

import argparse
import json
import subprocess
import sys
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
SCENE = HERE / "two_buildings.scene"
GAP = 0.01


def measures(t, u_left, u_right):
    """Peak drifts, peak penetration and the impacts (upward zero crossings of the
    penetration u_left − u_right − gap) of a history sampled every step."""
    pen = u_left - u_right - GAP
    onsets = np.flatnonzero((pen[:-1] <= 0) & (pen[1:] > 0))
    return {"drift_left": float(np.max(np.abs(u_left))), "drift_right": float(np.max(np.abs(u_right))),
            "penetration": float(max(np.max(pen), 0.0)), "impacts": int(len(onsets)),
            "first_impact_step": int(onsets[0]) + 1 if len(onsets) else -1}


def run(out, python=sys.executable):
    """Export, run both models; returns (exported measures, hand-built measures, worst
    relative difference, largest history difference [m])."""
    out = Path(out)
    exp = out / "exported"
    r = subprocess.run([python, "-m", "martello", "export", str(SCENE), "-o", str(exp)],
                       capture_output=True, text=True, cwd=ROOT)
    if r.returncode:
        raise SystemExit(r.stderr)
    for cmd, cwd in (([python, "model.py"], exp), ([python, str(HERE / "hand_built.py"), str(out / "hand")], ROOT)):
        r = subprocess.run(cmd, capture_output=True, text=True, cwd=cwd)
        if r.returncode:
            raise SystemExit(f"{' '.join(cmd)} failed:\n{r.stdout[-2000:]}{r.stderr[-2000:]}")
    head = (exp / "history.csv").read_text().splitlines()[0].split(",")
    h = np.loadtxt(exp / "history.csv", delimiter=",", skiprows=1)
    hb = np.loadtxt(out / "hand" / "disp.out")          # recorders: no t = 0 row
    e = measures(h[1:, 0], h[1:, head.index("u:left")], h[1:, head.index("u:right")])
    b = measures(hb[:, 0], hb[:, 1], hb[:, 2])
    worst = max(abs(e[k] - b[k]) / abs(b[k]) for k in ("drift_left", "drift_right", "penetration"))
    if e["impacts"] != b["impacts"] or e["first_impact_step"] != b["first_impact_step"]:
        worst = float("inf")
    hist = float(max(np.max(np.abs(h[1:, head.index("u:left")] - hb[:, 1])),
                     np.max(np.abs(h[1:, head.index("u:right")] - hb[:, 2]))))
    return e, b, worst, hist


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-o", "--output", default="out/opensees-two-buildings")
    ap.add_argument("--no-compare", action="store_true", help="skip martello compare")
    args = ap.parse_args()
    import openseespy.opensees as ops
    e, b, worst, hist = run(args.output)
    print(f"OpenSees {ops.version()} (openseespy), scene {SCENE.relative_to(ROOT)}, Newmark (1/2, 1/4), dt = 5e-4 s")
    print(f"{'measure':<20} {'exported':>22} {'hand-built':>22}")
    for k in e:
        print(f"{k:<20} {e[k]!r:>22} {b[k]!r:>22}")
    print(f"worst relative difference of peaks: {worst:.2e}; largest |u| difference over the history: {hist:.2e} m")
    if not args.no_compare:
        score = Path(args.output) / "score.json"
        r = subprocess.run([sys.executable, "-m", "martello", "compare",
                            str(Path(args.output) / "exported" / "history.csv"), "--against", str(SCENE),
                            "-o", str(score)], capture_output=True, text=True, cwd=ROOT)
        if r.returncode:
            raise SystemExit(r.stderr)
        m = json.loads(score.read_text())["metrics"]
        print("martello compare of the exported history against martello's reference: "
              + ", ".join(f"{k} {m.get(k)!r}" for k in ("scd", "impact_count", "impact_count_ref",
                                                        "impact_time_error", "restitution",
                                                        "restitution_ref", "peak_penetration_error")))
    return 0 if worst <= 1e-6 else 1


if __name__ == "__main__":
    sys.exit(main())
