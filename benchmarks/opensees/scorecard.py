"""The OpenSees scorecard (docs/opensees-scorecard.md): which catalogue scenes OpenSees can run,
and how well it runs them.

    .venv/bin/python benchmarks/opensees/scorecard.py [-o out/opensees-scorecard] [--only TEXT]
        [--docs]        # regenerate docs/opensees-scorecard.md (both parts)
        [--sample] [--refine N] [--resume] [--from JSONL ...] [--note TEXT]
        [--check]       # compare the committed doc's deterministic part with the catalogue's (CI)

For every dynamic catalogue scene the exporter (martello export --to opensees) either maps it
with its own integrator and step, maps it only with another integrator (an event-driven,
Moreau–Jean or modal scene: OpenSees has none of them), or refuses it with a reason: that
table is deterministic (the catalogue and the exporter only) and CI checks the committed copy
(tests/test_export.py). For the scenes it maps as they are, the script exports them, runs the
exported model.py under this interpreter's openseespy, runs martello on the same scene and
scores both with `martello compare` against martello's reference (closed form, stored data or a
reference computed on demand and cached: docs/reference.md). The three numbers split
OpenSees' error: martello's own digits at the same integrator and step are the numerical error
of the method; OpenSees against martello (max |Δu| over max |u|) is the difference of the two
models (a material law, HHT's state interpolation, Hertzdamp's v_in: docs/opensees.md); the
realised e against the reference's says which of the two moved the law. That part is measured
(it depends on the machine's OpenSees) and is regenerated, not checked, by CI."""

import argparse
import json
import os
import re
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
DOC = ROOT / "docs" / "opensees-scorecard.md"
BEGIN_D, END_D = "<!-- scorecard:deterministic -->", "<!-- /scorecard:deterministic -->"
BEGIN_M, END_M = "<!-- scorecard:measured -->", "<!-- /scorecard:measured -->"
MAX_NODE_STEPS = 2e6      # larger scenes are listed, not run (--cap): OpenSees takes ~50 us a step
sys.path.insert(0, str(ROOT))


def classify():
    """[(scene path relative to benchmarks/, problem, status, integrator, dt, materials, why)]
    for every dynamic catalogue scene: status "as is", "other integrator" or "refused"."""
    from martello.errors import ExportError
    from martello.export import opensees_model
    from martello.scene import catalogue
    from martello.scene.loader import load
    rows = []
    for f in catalogue.scene_files():
        s = load(f)
        rel = str(f.relative_to(catalogue.ROOT))
        an = s.analysis
        mats = lambda m: ", ".join(sorted({f"{law}→{mat}" for _, law, mat in m.contact_materials})) or "-"  # noqa: E731
        try:
            m = opensees_model(s)
            rows.append((rel, s.problem, "as is", an["integrator"], an.get("dt"), mats(m), ""))
            continue
        except ExportError as e:
            why = _reason(e)
        try:
            m = opensees_model(s, analysis={"integrator": "newmark"})
            rows.append((rel, s.problem, "other integrator", an.get("integrator", "-"), an.get("dt"),
                         mats(m), why))
        except ExportError as e:
            rows.append((rel, s.problem, "refused", an.get("integrator", "static"), an.get("dt"), "-",
                         _reason(e)))
    return rows


def _reason(e):
    """A refusal as 'item: why', the item without its position and name (contact[3] (c).)."""
    what = re.sub(r"^\w+\[\d+\] \([^)]*\)[.: ]*", "", getattr(e, "what", str(e)))
    what = re.sub(r" \(.*\)$", "", what)
    return f"{what}: {getattr(e, 'why', '')}".replace("|", "/")


def _short(why):
    return why


def deterministic_part(rows):
    from collections import Counter
    n = Counter(r[2] for r in rows)
    out = [BEGIN_D, "",
           f"Of {len(rows)} catalogue scenes, OpenSees runs **{n['as is']}** as they are (their "
           f"integrator and step), **{n['other integrator']}** only with a Newmark-family integrator "
           f"in place of theirs, and **{n['refused']}** not at all.", "",
           "| status | scenes | by integrator | why (the exporter's words, most frequent) |", "|---|---|---|---|"]
    for status in ("as is", "other integrator", "refused"):
        sel = [r for r in rows if r[2] == status]
        by = Counter(r[3] for r in sel)
        whys = Counter(_short(r[6]) for r in sel if r[6])
        out.append(f"| {status} | {len(sel)} | " + ", ".join(f"{k} {v}" for k, v in sorted(by.items()))
                   + " | " + ("; ".join(f"{w} ({c})" for w, c in whys.most_common(3)) or "-") + " |")
    out += ["", "Materials the contacts of the scenes run as they are map onto:", "",
            "| law → material | scenes |", "|---|---|"]
    mats = Counter(m for r in rows if r[2] == "as is" for m in r[5].split(", "))
    out += [f"| {m} | {c} |" for m, c in sorted(mats.items())]
    out += ["", "<details><summary>every scene</summary>", "",
            "| scene | problem | status | integrator | Δt [s] | law → material |", "|---|---|---|---|---|---|"]
    out += [f"| `{r[0]}` | {r[1] or '-'} | {r[2]} | {r[3]} | {r[4] if r[4] is not None else '-'} | {r[5]} |"
            for r in rows]
    out += ["", "</details>", "", END_D]
    return "\n".join(out)


def _history(path):
    head = path.read_text().split("\n", 1)[0].split(",")
    return head, np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)


def score(path, scene, out):
    r = subprocess.run([sys.executable, "-m", "martello", "compare", str(path), "--against", str(scene),
                        "-o", str(out)], capture_output=True, text=True, cwd=ROOT)
    if r.returncode:
        return {"error": r.stderr.strip().splitlines()[-1] if r.stderr.strip() else "compare failed"}
    return json.loads(out.read_text())["metrics"]


def _martello_history(scene, dt, folder):
    """martello's own run of the scene at step dt, its history.csv in folder (the scene's
    other settings unchanged); True when it ran."""
    from martello.run import run_full, write_history
    from martello.scene.loader import load
    s = load(scene)
    s.analysis["dt"] = dt
    try:
        _, (cols, data) = run_full(s)
    except Exception:
        return False
    folder.mkdir(parents=True, exist_ok=True)
    write_history(folder / "history.csv", list(cols), data)
    return True


def sample(rows):
    """One scene per problem × law → material × integrator × Δt among those OpenSees runs as
    they are (the first in catalogue order): the stated, representative sample of --sample."""
    seen, keep = set(), []
    for r in rows:
        key = (r[1], r[5], r[3], r[4])
        if r[2] != "as is" or key in seen:
            continue
        seen.add(key)
        keep.append(r)
    return keep


def measure(rows, out, only=None, cap=MAX_NODE_STEPS, refine=1, skip=()):
    """Run the scenes OpenSees takes as they are, at their step and (refine > 1) at the step
    halved refine − 1 times; returns measured rows, each also appended to out/measured.jsonl as
    it is made (a long sweep stopped half-way keeps what it measured)."""
    from martello.scene import catalogue
    from martello.scene.loader import load
    res = []
    wanted = [w for w in (only or "").split(",") if w]
    todo = [(rel, problem, integ, dt / 2 ** k, mats, k) for rel, problem, status, integ, dt, mats, _ in rows
            if status == "as is" and (not wanted or any(w in rel for w in wanted)) for k in range(refine)
            if (rel, dt / 2 ** k) not in skip]
    log = (out / "measured.jsonl").open("a")
    keep = res.append

    def record(row):
        keep(row)
        log.write(json.dumps(row, default=str) + "\n")
        log.flush()
    for rel, problem, integ, dt, mats, k in todo:
        scene = catalogue.ROOT / rel
        s = load(scene)
        size = len(s.nodes) * s.analysis["t_end"] / dt
        if size > cap:
            record({"scene": rel, "problem": problem, "integrator": integ, "dt": dt, "materials": mats,
                    "opensees": f"not measured: {size:.2g} node-steps (cap {cap:.0e})"})
            continue
        work = out / (rel.replace("/", "__").removesuffix(".toml") + (f"__dt{k}" if k else ""))
        t0 = time.time()
        r = subprocess.run([sys.executable, "-m", "martello", "export", str(scene), "-o", str(work / "os")]
                           + (["--dt", repr(dt)] if k else []), capture_output=True, text=True, cwd=ROOT)
        row = {"scene": rel, "problem": problem, "integrator": integ, "dt": dt, "materials": mats}
        if r.returncode == 0:
            try:
                r = subprocess.run([sys.executable, "model.py"], capture_output=True, text=True,
                                   cwd=work / "os", timeout=3600)
            except subprocess.TimeoutExpired:
                r = subprocess.CompletedProcess([], 1, "", "model.py did not finish in 3600 s")
        if r.returncode:
            lines = [x for x in r.stderr.strip().splitlines() if x.strip() and "Terminating" not in x]
            said = [x for x in lines if x.startswith(("model.py:", "error:"))]
            row["opensees"] = "failed: " + (said or lines or ["?"])[-1][:160]
            record(row)
            print(f"{rel}: {row['opensees']}", flush=True)
            continue
        row["opensees_seconds"] = time.time() - t0
        m_ok = _martello_history(scene, dt, work / "m")
        os_score = score(work / "os" / "history.csv", scene, work / "os_score.json")
        m_score = score(work / "m" / "history.csv", scene, work / "m_score.json") if m_ok else {}
        ho, do = _history(work / "os" / "history.csv")
        if m_ok:
            hm, dm = _history(work / "m" / "history.csv")
            us = [c for c in ho if c.startswith("u:") and c in hm]
            n = min(len(do), len(dm))
            if us and n and np.array_equal(do[:n, 0], dm[:n, 0]):
                diff = max(np.max(np.abs(do[:n, ho.index(c)] - dm[:n, hm.index(c)])) for c in us)
                peak = max(np.max(np.abs(dm[:n, hm.index(c)])) for c in us)
                row["os_vs_martello"] = float(diff / peak) if peak > 0 else float(diff)
        row.update(os=os_score, martello=m_score)
        record(row)
        print(f"{rel}: OpenSees scd {os_score.get('scd')}, martello scd {m_score.get('scd')}, "
              f"|OS - martello| {row.get('os_vs_martello')}", flush=True)
    return res


def _f(x, fmt):
    return "–" if x is None or (isinstance(x, float) and not np.isfinite(x)) else format(x, fmt)


def _i(x):
    return "–" if x is None else str(x)


def _num(x):
    return x if isinstance(x, (int, float)) and np.isfinite(x) else None


CAUSES = (("GeneralizedAlpha forms the inertia", "GeneralizedAlpha's inertia at t_{n+1}"),
          ("interpolated state", "state interpolation of HHT/GA"),
          ("Hertzdamp takes v_in", "Hertzdamp's v_in"),
          ("damped only while approaching", "half-Kelvin"),
          ("event_split", "no event split"),
          ("fluid damper", "Viscous below v_reg"),
          ("condenses out", "frames uncondensed"),
          ("u_{-1} = u_0", "CentralDifference's start from a_0 = 0"))


def causes(rel, dt):
    """The differences of the two models the exporter states for a scene at step dt (the
    candidates for a model finding), as short names."""
    from martello.export import opensees_model
    from martello.scene import catalogue
    from martello.scene.loader import load
    diff = opensees_model(load(catalogue.ROOT / rel), analysis={"dt": dt}).differences
    return [short for key, short in CAUSES if any(key in d for d in diff)]


def finding(r):
    """Which side of OpenSees' error against the law is the numerical error and which the model
    difference. OpenSees' error = martello's error at the same integrator and step (the method's
    numerical error: the reference is independent of both) + |OS − m| (the two models). Returns
    (class, words)."""
    o, m = r.get("os", {}), r.get("martello", {})
    so, sm, d = _num(o.get("scd")), _num(m.get("scd")), _num(r.get("os_vs_martello"))
    if so is None or sm is None or d is None:
        return "unscored", "no score for one side"
    err_m = 10.0 ** -sm
    notes = []
    eo, em, er = _num(o.get("restitution")), _num(m.get("restitution")), _num(o.get("restitution_ref"))
    if None not in (eo, em, er) and abs(eo - er) > abs(em - er) + 1e-3:
        notes.append(f"e {eo:.4f} vs martello's {em:.4f} (law {er:.4f}): the material moved e")
    io, im, iref = o.get("impact_count"), m.get("impact_count"), o.get("impact_count_ref")
    if None not in (io, iref) and io != iref:
        notes.append(f"impacts {io} / {iref}" + (" (martello too: numerical)" if im == io else
                                                 f" (martello {im}: model)"))
    if d <= 0.1 * err_m:
        cls, words = "numerical", (f"numerical: \\|OS − m\\| {d:.1e} ≪ the method's error {err_m:.1e}; "
                                   "OpenSees' error is the method's")
    elif so < sm - 0.1:
        cls, words = "model", (f"model: \\|OS − m\\| {d:.1e} vs the method's error {err_m:.1e}; the "
                               f"mapping costs OpenSees {sm - so:.2f} digits")
    elif so > sm + 0.1:
        cls, words = "model (OpenSees closer)", (f"model: \\|OS − m\\| {d:.1e}; OpenSees' formulation is "
                                                 f"{so - sm:.2f} digits closer to the law")
    else:
        cls, words = "both", (f"both: \\|OS − m\\| {d:.1e} comparable to the method's error {err_m:.1e}, "
                              "same digits")
    if cls != "numerical" and r.get("causes"):
        words += " (stated differences: " + ", ".join(r["causes"]) + ")"
    return cls, "; ".join([words] + notes)


def _digits_bin(x):
    for lo, hi in ((None, 2), (2, 4), (4, 6), (6, 8), (8, None)):
        if (lo is None or x >= lo) and (hi is None or x < hi):
            return f"< {hi}" if lo is None else (f"≥ {lo}" if hi is None else f"{lo}–{hi}")


def measured_part(res, version, sample_note=""):
    """The measured block: counts, the digits distribution, one row per problem × law → material
    × integrator × Δt, then every scene."""
    from collections import Counter, defaultdict
    for r in res:
        if "causes" not in r and not r.get("opensees", "").startswith("not measured"):
            r["causes"] = causes(r["scene"], r["dt"])
    ran = [r for r in res if "os" in r]
    other = [r for r in res if "os" not in r]
    cls = Counter(finding(r)[0] for r in ran)
    bins = ("< 2", "2–4", "4–6", "6–8", "≥ 8")
    dist_o = Counter(_digits_bin(r["os"]["scd"]) for r in ran if _num(r["os"].get("scd")) is not None)
    dist_m = Counter(_digits_bin(r["martello"]["scd"]) for r in ran
                     if _num(r["martello"].get("scd")) is not None)
    out = [BEGIN_M, "",
           f"Measured with OpenSees {version} (openseespy), `benchmarks/opensees/scorecard.py`: each "
           "scene at its own integrator and step (with --refine, also at the step halved). " + (sample_note + " " if sample_note else "")
           + "scd: significant correct digits of u against martello's reference ([compare.md](compare.md)); "
           "impacts: found / in the reference; e: mean realised restitution / the reference's; energy: "
           "error of kinetic + recoverable energy at the end over the reference's largest (OpenSees' "
           "own bookkeeping in model.py); |OS − m|: OpenSees against martello at the same settings, "
           "max |Δu| over max |u|.", "",
           f"**{len(ran)}** runs scored ({len({r['scene'] for r in ran})} scenes), **{len(other)}** not: "
           + (", ".join(f"{k} {v}" for k, v in sorted(Counter(r['opensees'].split(':')[0]
                                                           for r in other).items())) or "none") + ".", "",
           "| scd of u | " + " | ".join(bins) + " |", "|---|" + "---|" * len(bins),
           "| OpenSees | " + " | ".join(str(dist_o.get(b, 0)) for b in bins) + " |",
           "| martello (same integrator, same Δt) | " + " | ".join(str(dist_m.get(b, 0)) for b in bins) + " |",
           "", "Where OpenSees' error against the law comes from (see *How to read a row*):", "",
           "| finding | runs |", "|---|---|"]
    out += [f"| {k} | {v} |" for k, v in sorted(cls.items())]
    groups = defaultdict(list)
    for r in ran:
        groups[(r["problem"] or "-", r["materials"], r["integrator"], r["dt"])].append(r)

    def rng(vals, fmt):
        vals = [v for v in vals if v is not None]
        if not vals:
            return "–"
        lo, hi = min(vals), max(vals)
        return format(lo, fmt) if format(lo, fmt) == format(hi, fmt) else f"{format(lo, fmt)}–{format(hi, fmt)}"

    def mean(vals):
        vals = [v for v in vals if v is not None]
        return sum(vals) / len(vals) if vals else None
    out += ["", "### Per problem × law → material × integrator × Δt", "",
            "| problem | law → material | integrator | Δt [s] | runs | scd OpenSees | scd martello | "
            "impacts OS / ref | e OS / ref | energy OS | \\|OS − m\\| | finding |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for key in sorted(groups, key=lambda k: (k[0], k[1], k[2], k[3] or 0)):
        g = groups[key]
        os_, ms = [r["os"] for r in g], [r["martello"] for r in g]
        io = [x.get("impact_count") for x in os_]
        ir = [x.get("impact_count_ref") for x in os_]
        imp = f"{sum(i for i in io if i)} / {sum(i for i in ir if i)}" if any(i is not None for i in ir) else "–"
        eo, er = mean(_num(x.get("restitution")) for x in os_), mean(_num(x.get("restitution_ref")) for x in os_)
        en = [_num(x.get("energy_error")) for x in os_]
        en = [abs(v) for v in en if v is not None]
        fc = Counter(finding(r)[0] for r in g)
        out.append(f"| {key[0]} | {key[1]} | {key[2]} | {key[3]:g} | {len(g)} | "
                   f"{rng([_num(x.get('scd')) for x in os_], '.2f')} | {rng([_num(x.get('scd')) for x in ms], '.2f')} | "
                   f"{imp} | {_f(eo, '.4f')} / {_f(er, '.4f')} | {_f(max(en) if en else None, '.1e')} | "
                   f"{_f(max((_num(r.get('os_vs_martello')) for r in g if _num(r.get('os_vs_martello')) is not None), default=None), '.1e')} | "
                   + ", ".join(f"{k} {v}" for k, v in sorted(fc.items())) + " |")
    out += ["", "<details><summary>every run</summary>", "",
            "| scene | law → material | integrator | Δt [s] | scd OpenSees | scd martello | impacts OS / ref | "
            "e OS / ref | energy OS | \\|OS − m\\| | which side |",
            "|---|---|---|---|---|---|---|---|---|---|---|"]
    for r in sorted(res, key=lambda r: (r["scene"], -(r["dt"] or 0))):
        if "os" not in r:
            stated = ("stated differences: " + ", ".join(r["causes"])) if r.get("causes") else ""
            out.append(f"| `{r['scene']}` | {r['materials']} | {r['integrator']} | {r['dt']:g} | "
                       f"{r.get('opensees')} | | | | | | {stated} |")
            continue
        o, m = r["os"], r["martello"]
        e = f"{_f(o.get('restitution'), '.4f')} / {_f(o.get('restitution_ref'), '.4f')}"
        out.append(f"| `{r['scene']}` | {r['materials']} | {r['integrator']} | {r['dt']:g} | "
                   f"{_f(o.get('scd'), '.2f')} | {_f(m.get('scd'), '.2f')} | "
                   f"{_i(o.get('impact_count'))} / {_i(o.get('impact_count_ref'))} | {e} | "
                   f"{_f(o.get('energy_error'), '.1e')} | {_f(r.get('os_vs_martello'), '.1e')} | {finding(r)[1]} |")
    out += ["", "</details>", "", END_M]
    return "\n".join(out)


def read_measured(paths):
    """Measured rows from measured.jsonl files; a later row for the same scene and Δt wins."""
    rows = {}
    for p in paths:
        for line in Path(p).read_text().splitlines():
            if line.strip():
                r = json.loads(line)
                rows[(r["scene"], r["dt"])] = r
    return list(rows.values())


def _replace(text, begin, end, block):
    i, j = text.find(begin), text.find(end)
    if i < 0 or j < 0:
        return text.rstrip() + "\n\n" + block + "\n"
    return text[:i] + block + text[j + len(end):]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("-o", "--output", default="out/opensees-scorecard")
    ap.add_argument("--only", help="measure only scenes whose path contains one of these texts (comma-separated)")
    ap.add_argument("--docs", action="store_true", help=f"regenerate {DOC.relative_to(ROOT)}")
    ap.add_argument("--check", action="store_true", help="check the committed doc's deterministic part")
    ap.add_argument("--deterministic", action="store_true", help="regenerate only the doc's deterministic "
                    "part (seconds, no OpenSees): after adding catalogue scenes")
    ap.add_argument("--cap", type=float, default=MAX_NODE_STEPS, help="largest nodes x steps to run")
    ap.add_argument("--refine", type=int, default=1, help="also run at the step halved REFINE − 1 times")
    ap.add_argument("--sample", action="store_true", help="one scene per problem × law → material × "
                    "integrator × Δt, not every scene")
    ap.add_argument("--resume", action="store_true", help="keep the runs already in OUTPUT/measured.jsonl "
                    "and make only the missing ones")
    ap.add_argument("--from", dest="sources", nargs="+", metavar="JSONL", help="make no run: the measured "
                    "part from these measured.jsonl files (a later run of a scene and Δt wins)")
    ap.add_argument("--note", default="", help="a sentence the measured part states (e.g. what was sampled)")
    args = ap.parse_args()
    rows = classify()
    det = deterministic_part(rows)
    if args.check:
        text = DOC.read_text()
        i, j = text.find(BEGIN_D), text.find(END_D)
        ok = i >= 0 and text[i:j + len(END_D)] == det
        print("docs/opensees-scorecard.md: deterministic part " + ("up to date" if ok else
              "differs from the catalogue's: run .venv/bin/python benchmarks/opensees/scorecard.py "
              "--deterministic"))
        return 0 if ok else 1
    if args.deterministic:
        DOC.write_text(_replace(DOC.read_text(), BEGIN_D, END_D, det))
        return 0
    import openseespy.opensees as ops
    out = Path(args.output)
    out.mkdir(parents=True, exist_ok=True)
    if args.sources:
        res = read_measured(args.sources)
    else:
        # a resumed sweep keeps what it scored and what it did not run (over the cap); a failed
        # run is made again (the exporter may have changed since)
        done = [r for r in read_measured([out / "measured.jsonl"]) if "os" in r or "not measured" in r["opensees"]] \
            if args.resume and (out / "measured.jsonl").exists() else []
        if not args.resume and (out / "measured.jsonl").exists():
            (out / "measured.jsonl").unlink()
        todo = sample(rows) if args.sample else rows
        res = done + measure(todo, out, args.only, args.cap, args.refine, {(r["scene"], r["dt"]) for r in done})
    (out / "scorecard.json").write_text(json.dumps({"classification": rows, "measured": res}, indent=1, default=str))
    meas = measured_part(res, ops.version(), args.note)
    print(meas)
    if args.docs:
        text = DOC.read_text() if DOC.exists() else "# The OpenSees scorecard\n"
        DOC.write_text(_replace(_replace(text, BEGIN_D, END_D, det), BEGIN_M, END_M, meas))
    return 0


if __name__ == "__main__":
    sys.exit(main())
