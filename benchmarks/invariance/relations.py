"""Relations that need no oracle (docs/invariance.md): a result does not depend on how it is
recorded (output invariance), nor on how the scene is written down (metamorphic relations).

Output invariance. A scene run again with another `output.every`, another output interval
(the adaptive integrators), other recorded nodes, contacts and links, other tracking, or no
history at all, must give every summary number again. A fixed-step run is the same sequence
of steps whatever is recorded: bit for bit. An adaptive run also stops at every output time
(but CVODE without rigid contacts, whose rows lie on its interpolant, docs/sundials-ode.md),
and a stop changes the step sequence after it, so two runs differ by the errors of two step
sequences, each within the run's own tolerance: the tolerance of a number is ADAPTIVE_FACTOR
times how much it moves when the run's rtol and atol are made 10 times looser (`own_error`,
`loose_scene`), plus the rounding of the number.

Metamorphic relations (`mirrored`, `rescaled`, `renamed`, `chains_as_lists`) map a scene to
another whose summary follows from the first's by a known map; `metamorphic_mismatches`
applies the map and compares.

Used by tests/test_output_invariance.py and tests/test_metamorphic.py (a sample per kind)
and by benchmarks/invariance/sweep.py (the whole catalogue)."""

from __future__ import annotations

import copy
import math
import tomllib
from pathlib import Path

import numpy as np

from martello.run import run_full
from martello.scene.loader import from_dict

ADAPTIVE = ("rkf45", "rk8pd", "msbdf", "ida", "cvode", "arkode")
# An adaptive run's own tolerance on a number: how much the number moves when the run's
# tolerance (rtol, atol, event_tol) is made 3 and 10 times looser (LOOSER), the larger of the
# two. Two step sequences (other stops) at the same tolerance differ by their two errors; a
# looser run's error is a few times the run's (the global error goes as rtol^0.8 ... rtol^1,
# docs/event-driven.md), so its distance bounds that difference, with ADAPTIVE_FACTOR for the
# scatter of errors with where the steps fall (two looser runs: one sample alone was small by
# chance on the work integrals, which ride outside the error control).
LOOSER = (3.0, 10.0)
ADAPTIVE_FACTOR = 2.0
# One sample of that distance can be small by chance (P2 on IDA at rtol 1e-12: 1.0e-12 on the
# first impact speed, where another output interval moved it by 9e-12): the global error of
# an adaptive run is also allowed as GLOBAL_RTOL × rtol of the number (measured on the
# catalogue: IDA's impact times within 12 rtol, docs/ida.md; msbdf's events within 300 rtol,
# docs/event-driven.md).
GLOBAL_RTOL = 100.0
# the rounding of a number computed from the state (a few hundred operations)
ROUNDING = 1e3 * np.finfo(float).eps
# summary entries that describe the run, not its result
NOT_RESULTS = ("title", "problem", "analysis", "integrator", "status", "message", "warnings",
               "tracked", "cost", "provenance")


def read(path):
    """The scene file as a dict (its [check] dropped: the relations compare runs) and its
    folder, where record files are found."""
    path = Path(path)
    with open(path, "rb") as f:
        data = tomllib.load(f)
    data.pop("check", None)
    return data, path.parent


def run(data, base_dir="."):
    """(summary, history columns, history rows) of a scene dict."""
    summary, history = run_full(from_dict(data, base_dir=base_dir))
    columns, rows = history if history is not None else ([], np.zeros((0, 0)))
    return summary, columns, rows


def numbers(summary):
    """Every number of a summary's results as {path: value}; lists are indexed
    (contacts.plane.impact_times.3), None and strings are kept as they are."""
    out = {}

    def walk(x, path):
        if isinstance(x, dict):
            for k, v in x.items():
                walk(v, f"{path}.{k}" if path else str(k))
        elif isinstance(x, (list, tuple)):
            out[path + ".#"] = len(x)
            for i, v in enumerate(x):
                walk(v, f"{path}.{i}")
        else:
            out[path] = x

    walk({k: v for k, v in summary.items() if k not in NOT_RESULTS}, "")
    return out


def _same(a, b):
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return a == b


def _list_of(path):
    """contacts.plane.impact_times.3 -> contacts.plane.impact_times (None for a scalar)."""
    head, _, last = path.rpartition(".")
    return head if last.isdigit() else None


def own_error(base, loose):
    """The run's own tolerance on each number of base: its distance to the loose run's. An
    entry of a list is given the largest of its list (events resolved one by one carry the
    errors of those before them, and a looser run may resolve fewer of them)."""
    err = {}
    lists = {}
    for p, x in base.items():
        y = loose.get(p)
        if isinstance(x, (int, float)) and not isinstance(x, bool) and \
                isinstance(y, (int, float)) and not isinstance(y, bool) and \
                math.isfinite(x) and math.isfinite(y):
            err[p] = abs(x - y)
            head = _list_of(p)
            if head is not None:
                lists[head] = max(lists.get(head, 0.0), err[p])
    for p in base:
        head = _list_of(p)
        if head is not None:
            err[p] = max(err.get(p, 0.0), lists.get(head, 0.0))
    return err


# the families of numbers that share a scale (mismatches), by the last name of the path
FAMILIES = {"u_max": "L", "u_min": "L", "u_absmax": "L", "u_final": "L", "u_peak": "L",
            "max_penetration": "L", "penetration_final": "L", "phase_max_penetration": "L",
            "max_abs_elongation": "L", "v_absmax": "V", "v_final": "V", "approach_speeds": "V",
            "separation_speeds": "V", "a_absmax": "A"}


# a frame's or building's extremes (frames.B.members.C1.1.N_i.max): the family of their
# quantity, a force (N, V, V2, V3, shear), a moment (M, M2, M3, T, torque, the resultant)
# or a displacement (drift, a plan point's ux, uy); their times (t_max, t_min, M_i_resultant_t)
STRUCTURES = ("frames.", "buildings.")
STRUCTURE_FAMILIES = (("N", "SF"), ("V", "SF"), ("shear", "SF"), ("M", "SM"), ("T", "SM"),
                      ("torque", "SM"), ("drift", "L"), ("ux", "L"), ("uy", "L"))


def _structure_quantity(path):
    """(quantity, value path) of a frame's or building's extreme or of its time, the value
    path being the path itself for a value; None elsewhere."""
    if not path.startswith(STRUCTURES):
        return None
    head, _, last = path.rpartition(".")
    if last in ("max", "min"):
        return head.rpartition(".")[2], path
    if last in ("t_max", "t_min"):
        return head.rpartition(".")[2], f"{head}.{last[2:]}"
    if last.endswith("_resultant_max"):
        return last, path
    if last.endswith("_resultant_t"):
        return last, f"{head}.{last[:-2]}_max"
    return None


def _family(path):
    if path == "energy.balance_relative":
        return "1"
    if path.startswith("energy."):
        return "E"
    sq = _structure_quantity(path)
    if sq is not None:
        if sq[1] != path:
            return None                    # a time
        if sq[0].startswith("drift"):
            return "L"
        return next((fam for start, fam in STRUCTURE_FAMILIES if sq[0].startswith(start)), None)
    name = _list_of(path) or path
    return FAMILIES.get(name.rpartition(".")[2])


def mismatches(base, other, error=None, rtol=0.0, exact=None, factor=ADAPTIVE_FACTOR):
    """The numbers present in both summaries (as `numbers`) that differ: bit for bit (exact;
    by default when no error is given), or by more than factor × the run's own error (error:
    {path: error}, or None), GLOBAL_RTOL × the relative tolerance rtol of the number, and the
    rounding. Counts (the `#` entries, integers) must agree exactly. Returns
    [(path, base, other, allowed)]."""
    if exact is None:
        exact = error is None
    error = error or {}
    bad = []
    # a number rounds on the scale of the numbers it is a difference of: an energy term on
    # the largest energy, a penetration or a final displacement on the largest displacement,
    # a final velocity on the largest speed (FAMILIES); an adaptive run integrates the works
    # outside its error control, and the error it reports on them is its energy balance
    scales = {fam: max([abs(v) for k, v in base.items() if _family(k) == fam
                        and isinstance(v, float) and math.isfinite(v)] + [0.0])
              for fam in set(FAMILIES.values()) | {"E", "SF", "SM"}}
    scales["1"] = 1.0           # balance_relative: a fraction of the energy scale
    balance = max(abs(base.get("energy.balance_max") or 0.0),
                  abs(other.get("energy.balance_max") or 0.0)) if error else 0.0
    for p, x in base.items():
        if p not in other:
            continue
        y = other[p]
        if exact or not (isinstance(x, float) and isinstance(y, float)):
            if not _same(x, y):
                bad.append((p, x, y, 0.0))
            continue
        if not (math.isfinite(x) and math.isfinite(y)):
            if not _same(x, y):
                bad.append((p, x, y, 0.0))
            continue
        sq = _structure_quantity(p)
        if sq is not None and sq[1] != p:
            # the time of a structure's extreme that is rounding alone (the axial force of
            # a symmetric frame's middle column under a lateral load: 1e-9 N of 1e6 N) is
            # any time: compared only where the extreme stands above its rounding
            value = [abs(v) for v in (base.get(sq[1]), other.get(sq[1])) if isinstance(v, float)]
            if value and max(value) <= ROUNDING * scales.get(_family(sq[1]), 0.0):
                continue
        scale = max(abs(x), abs(y), scales.get(_family(p), 0.0))
        allowed = factor * error.get(p, 0.0) + (GLOBAL_RTOL * rtol + ROUNDING) * scale
        if _family(p) == "E":
            allowed += factor * balance
        elif _family(p) == "1" and scales["E"] > 0:
            allowed += factor * balance / scales["E"]
        if abs(x - y) > allowed:
            bad.append((p, x, y, allowed))
    return bad


# the final state of a node or contact is read from the history's last row: only for the
# recorded ones (docs/results.md)
FROM_HISTORY = (".u_final", ".v_final", ".penetration_final", ".force_final", ".lambda_final")


def missing(base, other):
    """Result paths of base absent from other that recording cannot remove: every number but
    the final states read from the history (FROM_HISTORY)."""
    return [p for p in base if p not in other and not p.endswith(FROM_HISTORY)]


# ---- output variants ----------------------------------------------------------------------

def _output(data):
    an = data.setdefault("analysis", {})
    return an.setdefault("output", {})


def output_variants(data, adaptive):
    """(name, scene dict) of the same scene recorded otherwise. The base is the scene with
    track = ["all"] (every quantity kept), so that a variant's numbers are a subset."""
    an = data["analysis"]
    every = int(an.get("output", {}).get("every", 1))
    nodes = [n["name"] for n in data.get("node", [])]
    contacts = [c["name"] for c in data.get("contact", []) if "name" in c]

    def variant(**out):
        d = copy.deepcopy(data)
        o = _output(d)
        o.setdefault("track", ["all"])
        for k, v in out.items():
            if k == "dt":
                d["analysis"]["dt"] = v
            else:
                o[k] = v
        return d

    yield "every 7", variant(every=every * 7)
    yield "every 1000", variant(every=every * 1000)
    yield "no history", variant(nodes=[], contacts=[], links=[])
    if len(nodes) > 1 or len(contacts) > 1:
        yield "some outputs, reordered", variant(nodes=nodes[::-2], contacts=contacts[::-2])
    yield "track contact_peaks", variant(track=["contact_peaks"])
    yield "track node_peaks, phases", variant(track=["node_peaks", "phases"])
    yield "track link_peaks", variant(track=["link_peaks"])
    if adaptive:
        dt, t_end = float(an["dt"]), float(an["t_end"])
        yield "output interval x 0.37", variant(dt=dt * 0.37)
        if 3 * dt <= t_end:
            yield "output interval x 3", variant(dt=dt * 3)


def base_scene(data):
    d = copy.deepcopy(data)
    _output(d).setdefault("track", ["all"])
    return d


def run_rtol(data):
    """The scene's rtol (the library's default when not given)."""
    from martello.binding import native
    return float(data["analysis"].get("rtol", native.settings_defaults()["rtol"]))


# the integrators that solve a nonlinear system a step by Newton's method, and the tolerances
# they solve it to (the last: the relative tolerance of the solution)
NEWTON = {"newmark": ("tol_residual", "tol_increment"), "hht": ("tol_residual", "tol_increment"),
          "generalized-alpha": ("tol_residual", "tol_increment"),
          "newmark-lagrange": ("tol_residual", "tol_increment"),
          "fast-nonlinear": ("tol_residual",)}


def loose_scene(data, factor):
    """The same run solved to a factor times looser tolerance: an adaptive run's rtol, atol
    and event_tol, a Newton method's tol_residual and tol_increment (the library's defaults
    when not given); None for a method that solves its steps exactly."""
    from martello.binding import native
    d = base_scene(data)
    an = d["analysis"]
    integrator = an["integrator"]
    keys = ("rtol", "atol", "event_tol") if integrator in ADAPTIVE else NEWTON.get(integrator, ())
    if not keys:
        return None
    defaults = native.settings_defaults()
    for k in keys:
        an[k] = float(an.get(k, defaults[k])) * factor
    return d


def free_scene(data):
    """The run with one output at the end: an adaptive stepper's steps limited by nothing but
    its tolerance (the output times are stops)."""
    d = base_scene(data)
    d["analysis"]["dt"] = float(d["analysis"]["t_end"])
    return d


# The Newmark family (Newmark, HHT, generalized-α, Newmark–Lagrange) moves u, v and a by Newton
# increments (docs/invariance.md, "Rounding of the Newmark family"): the rounding of u, ε|u|, is
# no acceleration any more. One cancellation is left: a step's first iterate from u = u_n has
# a₀ = −v_n/(βh) − (½ − β)/β·a_n, to which Δu/(βh²) adds back as much (the generalized-α
# family's linearised first iterate, the fused chain step), and a held Newmark–Lagrange contact
# turns its relative speed's rounding into −B v_n/(βh): a node's a rounds by up to
# q = ε·max|v|/(βh) twice a step (a₀ formed, then summed), its v by 2γh·q ≤ 2h·q a step (γ ≤ 1)
# and its u by h·(that) and its own ulp, ε|u|: ceilings 2q, 2q·t_end and q·t_end² + N·ε·max|u|
# over N = t_end/h steps, twice these for a number that is a difference of two nodes
# (newmark_rounding). It used to be q = ε·max|u|/(βh²) — a from u — and the runs fell on a few
# discrete outcomes that one probe could miss (P5 Hertz-damp, generalized-α, masses × (1 + kε),
# k = −16…16: m2's final speed at 0, 5.5e-8 or 1.1e-7 relative), so they were probed six times.
# With increments the same spread is 2e-12 relative and continuous (30 and more distinct values
# over the 32 k), the new ceiling is 2e4 times the old on P5 (h = 0.1 µs, |u| 2 mm, |v| 1 m/s),
# and one probe, as for every other integrator, is enough: over every Newmark-family scene of
# the catalogue (135) and relation that applies to it (148 pairs: rescaled, renamed, chains as
# lists), no pair fails with one probe and this ceiling; the tightest, P5 Hertz-damp on
# generalized-α renamed (|a| max 9.4e-9 m/s² apart, 1.2 q), passes with its allowance 100 times
# smaller (the Newton tolerance's share of it dominates).
DISPLACEMENT_FORM = ("newmark", "hht", "generalized-alpha", "newmark-lagrange")


def newmark_beta(an):
    """β of a Newmark-family run (generalized_alpha_coefficients in fortran/generalized_alpha.f90;
    Newmark–Lagrange: the average acceleration)."""
    from martello.binding import native
    defaults = native.settings_defaults()
    integrator = an["integrator"]
    if integrator == "hht":
        return 0.25 * (1.0 - float(an.get("alpha", defaults["alpha"]))) ** 2
    if integrator == "generalized-alpha":
        rho = float(an.get("rho_inf", defaults["rho_inf"]))
        am, af = (2.0 * rho - 1.0) / (rho + 1.0), rho / (rho + 1.0)
        return 0.25 * (1.0 - am + af) ** 2
    if integrator == "newmark":
        return float(an.get("beta", defaults["beta"]))
    return 0.25


def newmark_rounding(data, base):
    """The ceiling of the rounding of a Newmark-family run on each acceleration, velocity and
    displacement of base (docs/invariance.md, "Rounding of the Newmark family"): q = ε·V/(βh),
    V the largest |v| of the run, U the largest |u|, N = t_end/h steps: 4q, 4q·t_end and
    2q·t_end² + 2N·ε·U (a difference of two nodes, each within 2q, 2q·t_end, q·t_end² + N·ε·U);
    {} for the other integrators."""
    an = data["analysis"]
    if an["integrator"] not in DISPLACEMENT_FORM:
        return {}

    def largest(names):
        return max([abs(x) for p, x in base.items() if p.startswith("nodes.") and isinstance(x, float)
                    and p.rpartition(".")[2] in names and math.isfinite(x)] + [0.0])
    U, V = largest(("u_max", "u_min", "u_absmax")), largest(("v_absmax",))
    h, T = float(an["dt"]), float(an["t_end"])
    eps = np.finfo(float).eps
    q = eps * V / (newmark_beta(an) * h)
    ceiling = {"A": 4.0 * q, "V": 4.0 * q * T, "L": 2.0 * q * T * T + 2.0 * (T / h) * eps * U}
    return {p: ceiling[_family(p)] for p in base if _family(p) in ceiling}


def rounding_scene(data, k=4.0):
    """The scene with every mass scaled by 1 + k eps (nodes and chains; None when it has no
    mass given so): what that moves a number is what rounding moves it in this run (k = 4: the
    size of the rounding a reordered or rescaled sum leaves in a number). A stiff
    contact met by a long sequence of short steps amplifies it far beyond ROUNDING (measured:
    P5 Hertz on Newmark, 5e4 steps of 1e-7 s: |a| max moved 1.5e-8 relative by a mass change
    of 1 ulp)."""
    d = base_scene(data)
    items = [n for n in d.get("node", []) if "mass" in n] + \
        [c for c in d.get("chain", []) if "mass" in c]
    if not items:
        return None
    f = 1.0 + k * np.finfo(float).eps
    for item in items:
        m = item["mass"]
        item["mass"] = [x * f for x in m] if isinstance(m, list) else m * f
    return d


def tolerance_error(data, base, base_dir, mapped=None, rounding=False):
    """The run's own error on each number of base (own_error over the LOOSER runs; empty for
    a method that solves its steps exactly), and its relative tolerance (rtol for an
    adaptive run, tol_increment for a Newton method, else 0); mapped maps the errors into
    another scene's terms (a metamorphic relation's expectation). An adaptive run is probed
    twice, as given and with its steps free of output stops (free_scene): stops bound the
    steps, so loosening the tolerance of a run with dense outputs moves little, while the
    same run recorded sparsely takes the long steps its tolerance allows (P6 on CVODE at rtol
    1e-12: |a| max moved 1.5e-10 with every = 1000, 0 with the tolerance 10 times looser)."""
    error = {}
    an = data["analysis"]
    probes = [(data, base)]
    if an["integrator"] in ADAPTIVE:
        free = free_scene(data)
        probes.append((free, numbers(run(free, base_dir)[0])))
    for scene, ref in probes:
        for f in LOOSER:
            loose = loose_scene(scene, f)
            if loose is None:
                break
            for p, e in own_error(ref, numbers(run(loose, base_dir)[0])).items():
                error[p] = max(error.get(p, 0.0), e)
    if rounding:
        # a relation that reorders or rescales the arithmetic: the run's own rounding, probed
        probe = rounding_scene(data)
        if probe is not None:
            for p, e in own_error(base, numbers(run(probe, base_dir)[0])).items():
                error[p] = max(error.get(p, 0.0), e)
        for p, e in newmark_rounding(data, base).items():
            error[p] = max(error.get(p, 0.0), e)
    from martello.binding import native
    rtol = 0.0
    if an["integrator"] in ADAPTIVE:
        rtol = run_rtol(data)
    elif an["integrator"] in NEWTON:
        key = NEWTON[an["integrator"]][-1]
        rtol = float(an.get(key, native.settings_defaults()[key]))
    return (mapped(error) if mapped else error), rtol


def _extreme_of(path, base):
    """The extreme whose time a path is (nodes.m.t_absmax -> nodes.m.u_absmax, t_peak ->
    u_peak, a member's N_i.t_max -> N_i.max), None if path is no such time."""
    head, _, last = path.rpartition(".")
    if not last.startswith("t_"):
        return None
    for name in ("u_" + last[2:], last[2:]):
        if f"{head}.{name}" in base:
            return f"{head}.{name}"
    return None


def tied_times(base_dir, scenes, base, bad, error, rtol):
    """Split an adaptive run's mismatches into (mismatches, tied). scenes: the base scene and
    the variant's (dicts), whose summaries gave base and bad. The time of an extreme
    (t_absmax, t_peak, ...) on which the two runs agree in value but not in time is tied
    when the run that reports the later time, run again to the midpoint of the two times,
    already reaches the value within the allowance: that run attains it before the midpoint
    and (its own report) again after it, so the extreme is attained more than once, and
    which time a run reports depends on the rounding of two equal values (docs/invariance.md,
    ties). Nothing else is excused: the value itself is still compared, and a later time
    whose run falls short of the value before the midpoint stays a mismatch."""
    if error is None:
        return bad, []
    moved = {p for p, _, _, _ in bad}
    kept, tied = [], []
    for entry in bad:
        p, t_a, t_b = entry[:3]
        value = _extreme_of(p, base)
        if value is None or value in moved or not (isinstance(t_a, float) and isinstance(t_b, float)):
            kept.append(entry)
            continue
        early = copy.deepcopy(scenes[1] if t_b > t_a else scenes[0])
        early["analysis"]["t_end"] = 0.5 * (t_a + t_b)
        early["analysis"]["dt"] = min(float(early["analysis"]["dt"]), early["analysis"]["t_end"])
        reached = numbers(run(early, base_dir)[0]).get(value)
        if isinstance(reached, float) and \
                not mismatches(base, {**base, value: reached}, error, rtol):
            tied.append(entry)
        else:
            kept.append(entry)
    return kept, tied


def output_invariance(path_or_data, base_dir=None):
    """Run a scene and its output variants; returns (kind, [(variant, mismatches, missing,
    tied)]), kind = (integrator, adaptive); tied: the times of extremes attained more than
    once within the allowance (tied_times), not compared."""
    if isinstance(path_or_data, (str, Path)):
        data, base_dir = read(path_or_data)
    else:
        data = path_or_data
    base_dir = base_dir or "."
    integrator = data["analysis"]["integrator"]
    adaptive = integrator in ADAPTIVE
    base_data = base_scene(data)
    base = numbers(run(base_data, base_dir)[0])
    error, rtol = tolerance_error(data, base, base_dir) if adaptive else (None, 0.0)
    found = []
    for name, d in output_variants(data, adaptive):
        other = numbers(run(d, base_dir)[0])
        # tracking chooses which quantities are kept: a tracked subset is no loss
        lost = [] if name.startswith("track") else missing(base, other)
        bad, tied = tied_times(base_dir, (base_data, d), base, mismatches(base, other, error, rtol),
                               error, rtol)
        found.append((name, bad, lost, tied))
    return (integrator, adaptive), found
