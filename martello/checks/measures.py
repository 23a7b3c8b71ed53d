"""Problem-specific measures added to a dynamic run's summary: the errors of the run
against its problem's oracles. The run itself knows no oracle; the callers that report a run
(`martello run`, `martello check`) run a scene with :func:`run_measured`, which calls
:func:`attach` on its summary and history.

Rod impact (docs/problems.md P4, docs/p4-bars.md). When the scene was built from `[[bar]]`
tables (scene.extras["bars"]) and has exactly one contact, between the end nodes of two
rods or between a rod's end node and ground (a rigid wall), `summary["measures"]
["rod_impact"]` receives the errors of the run against elementary wave theory
(martello.oracles.p4_rod_impact.rod_impact for the plateau force, the duration and the final
velocities; martello.oracles.p4_wave_theory for the displacement field):

No measure depends on how the run is recorded (docs/invariance.md). From what the run tracks
at every step, whatever `output.every` (the summary's contact phases and maxima, the final
state):

* contact duration: first onset to the last separation of the first *episode* (phases
  whose open intervals are shorter than the shortest element transit time L_e/c, or one
  step of a fixed-step method if that is longer, are one impact: a contact that only
  touches zero between two steps has not separated);
* penetration: the maximum, and the maximum over the interface displacement scale v_p τ;
* peak: the contact's `max_force` (docs/results.md: the largest force at the method's steps,
  or a crest inside a step only where the step's cubic resolves it; on an adaptive method
  its located peak) and its error against P0 — not on an event-driven run's instantaneous
  impacts, whose `max_force` is an impulse;
* impulse: the momentum the contact moved from one rod to the other (its error against the
  rectangle's P0 T), from the rods' final momentum — the impulse the method applied, by
  conservation of momentum, whatever the quadrature of its force;
* final mean velocities of the rods (momentum / mass, consistent couplings included) at
  the end of the run, their errors over v0, the share of energy left as vibration, and the
  final energy error (E_kin + E_recoverable − E0) / E0.

From the force, energy and displacement at every step of a fixed-step method — its step
trace (docs/results.md "Step trace": the contact's force, the energies and the rods' nodes'
displacement at every step, whatever `output.every`; the samples of the history at
every = 1), or the history where it holds every step (`every = 1`) when the measures are
attached without the trace (an adaptive run's rows are its output times, not its steps:
there they are left out and a note says why, never computed on the recorded samples):

* the force pulse against the rectangle P0 = Z v0/2 (Z v0 on a wall) on
  [t_on, t_on + 2 L_min/c): L1 error (the force held constant over each step, centred on
  its sample: the impulse a step of central difference applies), total variation (the
  rectangle has 2 P0; the excess is spurious oscillation) and the width of the held pulse;
* energy error: max |E_kin + E_recoverable − E0| / E0 over the steps;
* displacement error: max over the steps and the rod nodes of |u − u_exact|, over v_p τ
  (all nodes, and the two contact nodes alone).

What the measures need from `[analysis.output]`: the contact in `contacts` (default) for
the pulse and the energy; every node of both rods in `nodes` for the impulse, the final
velocities and the displacement field (`[[bar]] output = "all"`, the default, puts them
there). Errors are signed value − reference unless called relative. Quantities that cannot
be formed are left out and `notes` says why; nothing here raises for a scene that does not
fit.
"""

import numpy as np

from ..binding import native
from ..run import run_full, run_traced

REL_SAME = 1e-12     # two rods with c and Z equal to this relative tolerance are "the same bar"
# A held force below this share of P0 is no pulse: rounding-level forces while two faces
# rest against each other after the pulse (unequal rods: from 2 L_A/c to 2 L_B/c) are not.
PULSE_THRESHOLD = 1e-6


def run_measured(scene):
    """(summary, history) of run_full(scene) with the problem's measures attached: what
    `martello run` writes and `martello check` verifies. A rod impact on a fixed-step method
    keeps its contact's step trace (force and energies at every step, whatever the history
    records: martello.run.run_traced) for the measures that need every step."""
    traced = _traced(scene)
    if traced is None:
        summary, history = run_full(scene)
        steps = None
    else:
        summary, history, steps = run_traced(scene, *traced)
    attach(scene, summary, history, steps)
    return summary, history


def _traced(scene):
    """(contact, nodes): the names of the contact and of the rods' nodes whose step trace
    the rod-impact measures read, or None (not a rod impact, or not a dynamic fixed-step
    run)."""
    rods = scene.extras.get("bars") if scene.extras else None
    an = scene.analysis
    if not (rods and scene.contacts and an["type"] == "dynamic") or \
            an["integrator"] in native.adaptive_integrators():
        return None
    got = _applicability(scene, rods)
    if isinstance(got, str):
        return None
    c, side_a, side_b = got
    return c["name"], [nm for side in (side_a, side_b) if side for nm in side[0]["nodes"]]


def attach(scene, summary, history, steps=None):
    """Add measures that the scene's generators ask for (scene.extras) to the summary of a
    dynamic run (a static run, whose history is None, has none); steps: the rod impact's
    step trace (run_measured), without which the measures that need every step are made
    from the history where it holds every step (output.every = 1)."""
    rods = scene.extras.get("bars") if scene.extras else None
    if rods and scene.contacts and history is not None:
        m = rod_impact_measures(scene, summary, history, steps)
        summary.setdefault("measures", {})["rod_impact"] = m
    return summary


def _rod_of_end(rods, name):
    for r in rods:
        if name in (r["left"], r["right"]):
            return r
    return None


def _applicability(scene, rods):
    """(contact, side_a, side_b) or a reason string; a side is (rod info, end node name)
    or None for ground."""
    if len(scene.contacts) != 1:
        return f"the scene has {len(scene.contacts)} contacts; the rod-impact measures need exactly one"
    c = scene.contacts[0]
    names = [n["name"] for n in scene.nodes]
    sides = []
    for key in ("a", "b"):
        if c[key] < 0:
            sides.append(None)
            continue
        node = names[c[key]]
        r = _rod_of_end(rods, node)
        if r is None:
            return f"contact side {key} ({node}) is not the end node of a [[bar]] rod"
        if r["fixed"] != "none":
            return f"rod {r['name']} has a fixed end; wave theory here is for free rods"
        sides.append((r, node))
    if sides[0] is None and sides[1] is None:
        return "the contact joins ground to ground"
    if scene.forces or scene.gravity != 0.0 or scene.ground is not None:
        return "the scene has loads (forces, gravity or ground motion): not a free rod impact"
    rod_nodes = {}
    for r in rods:
        for nm in r["nodes"]:
            rod_nodes[scene.index[nm]] = r["name"]
    for lk in scene.links:
        ra, rb = rod_nodes.get(lk["a"]), rod_nodes.get(lk["b"])
        if (ra is not None or rb is not None) and (lk["type"] != "bar" or ra != rb):
            return f"link {lk['name']} attaches something else to a rod"
    if all(s is not None for s in sides):
        ra, rb = sides[0][0], sides[1][0]
        if ra is rb:
            return "the contact joins two ends of the same rod"
        if (abs(ra["c"] - rb["c"]) > REL_SAME * ra["c"]
                or abs(ra["impedance"] - rb["impedance"]) > REL_SAME * ra["impedance"]):
            return ("the rods differ in wave speed or impedance: only equal bars have the "
                    "closed forms used here (oracles.p4_rod_impact.impedance_plateau_force gives "
                    "the plateau)")
    if c["gap"] < 0:
        return "negative gap (initial overlap)"
    return c, sides[0], sides[1]


def _episode(summary_contact, t_merge):
    """(t_on, t_off or None, phases in the episode, phases after it)."""
    on = summary_contact["impact_times"]
    off = summary_contact["separation_times"]
    if not on:
        return None, None, 0, 0
    k = 0
    while k + 1 < len(on) and off[k] is not None and on[k + 1] - off[k] <= t_merge:
        k += 1
    return on[0], off[k], k + 1, len(on) - (k + 1)


def _cells(t):
    """Edges (lo, hi) of the cells centred on the samples: midpoints between samples, the
    end cells stopping at the first and last sample."""
    if len(t) == 1:
        return t.copy(), t.copy()
    mid = 0.5 * (t[1:] + t[:-1])
    return np.concatenate(([t[0]], mid)), np.concatenate((mid, [t[-1]]))


def _hold_l1(t, p, t0, t1, level):
    """∫ |P_h − level·1[t0, t1)| dt with P_h the samples held over their cells."""
    lo, hi = _cells(t)
    overlap = np.clip(np.minimum(hi, t1) - np.maximum(lo, t0), 0.0, None)
    return float(np.sum(np.abs(p - level) * overlap + np.abs(p) * (hi - lo - overlap)))


def rod_impact_measures(scene, summary, history, steps=None):
    # the wave-theory oracles: only for a scene of rods (a plain run does not load them)
    from ..oracles.p4_rod_impact import rod_impact
    from ..oracles.p4_wave_theory import rod_point_displacement, vibration_energy_fraction
    rods = scene.extras["bars"]
    got = _applicability(scene, rods)
    if isinstance(got, str):
        return {"applicable": False, "notes": [got]}
    c, side_a, side_b = got
    notes = []
    wall = side_a is None or side_b is None
    rod_a = side_a[0] if side_a else None
    rod_b = side_b[0] if side_b else None
    va0 = rod_a["v0"] if rod_a else 0.0
    vb0 = rod_b["v0"] if rod_b else 0.0
    v_rel = va0 - vb0
    if not v_rel > 0:
        return {"applicable": False, "notes": [f"the rods do not approach (v_a − v_b = {v_rel:g})"]}
    some = rod_a or rod_b
    EA, rhoA = some["EA"], some["rhoA"]
    if wall:
        rod = rod_a or rod_b
        ref = rod_impact(EA, rhoA, 1.0, rod["L"], rod["L"], v_rel, wall=True)
        v_ref = {rod["name"]: -(va0 if rod_a else vb0)}
    else:
        ref = rod_impact(EA, rhoA, 1.0, rod_a["L"], rod_b["L"], v_rel)
        v_ref = {rod_a["name"]: vb0 + ref.vA, rod_b["name"]: vb0 + ref.vB}
    t_on_ref = c["gap"] / v_rel
    P0, T = ref.force, ref.duration
    vp = P0 / ref.impedance
    an = scene.analysis
    adaptive = an["integrator"] in native.adaptive_integrators()
    # the method's steps: its step trace (the contact's force and the energies at every
    # step, whatever is recorded), else the history of a fixed-step run recorded at every step
    rows_every_step = not adaptive and an["output"]["every"] == 1
    every_step = not adaptive and (steps is not None or rows_every_step)
    involved = [r for r in (rod_a, rod_b) if r is not None]
    # one step of a fixed-step method (an adaptive run's phases are located, its dt is an
    # output interval: not a length of the physics or the method)
    h = 0.0 if adaptive else an["dt"]
    t_merge = max(min(r["transit_time"] for r in involved), h) * (1.0 + 1e-9)

    m = {"applicable": True, "contact": c["name"],
         "rods": {"a": rod_a["name"] if rod_a else "ground", "b": rod_b["name"] if rod_b else "ground"},
         "approach_speed": v_rel,
         "reference": {"onset_time": t_on_ref, "duration": T, "force": P0,
                       "v_final": v_ref, "impedance": ref.impedance, "c": ref.c}}

    # contact phases (from the summary: every integrator reports them)
    sc = summary["contacts"][c["name"]]
    t_on, t_off, n_in, n_after = _episode(sc, t_merge)
    m.update(phases=n_in, later_phases=n_after)
    if t_on is None:
        notes.append("no contact occurred")
    else:
        m.update(onset_time=t_on, onset_error=t_on - t_on_ref)
        if t_off is None:
            notes.append("the contact is still closed at the end of the run: no duration")
        else:
            m.update(duration=t_off - t_on, duration_error=(t_off - t_on) - T,
                     duration_relative_error=((t_off - t_on) - T) / T)
    m["max_penetration"] = sc["max_penetration"]
    m["penetration_relative"] = sc["max_penetration"] / (vp * T)
    # the peak the observer takes at every step, whatever is recorded (an event-driven run's
    # instantaneous impacts report their impulse there, N s: no force peak)
    if sc.get("max_force") is None:
        notes.append(f"contact {c['name']} has no max_force (tracking): no force peak")
    elif adaptive and c["scheme"] != "penalty":
        notes.append("an event-driven run's max_force of an instantaneous contact is an impulse: no force peak")
    else:
        m["force_peak"] = sc["max_force"]
        m["peak_error"] = (sc["max_force"] - P0) / P0

    columns, data = history if history is not None else ([], np.zeros((0, 0)))
    col = {name: i for i, name in enumerate(columns)}
    if len(data) == 0:
        notes.append("empty history: no pulse, energy or velocity measures")
        m["notes"] = notes
        return m
    t = data[:, col["t"]]
    why = ("an adaptive run's history holds its output times, not its steps" if adaptive
           else f"output every {an['output']['every']} steps")
    if not every_step:
        notes.append(why + ": no pulse L1, total variation or width, energy error over the run or "
                     "displacement error (they need the force, energy and displacement at every "
                     "step of the method)")

    fkey = f"force:{c['name']}"
    # the force and the energies at every step: the step trace, else the rows (every = 1)
    ts, p, e_steps = None, None, None
    if steps is not None:
        ts, p = steps["t"], steps["force"]
        e_steps = steps["kinetic"] + steps["recoverable"]
    elif every_step and fkey in col:
        ts, p = t, data[:, col[fkey]]
    if not every_step:
        pass
    elif p is not None:
        l1 = _hold_l1(ts, p, t_on_ref, t_on_ref + T, P0)
        m["pulse_l1_error"] = l1 / (P0 * T)
        if t_on is not None:
            end = t_off if t_off is not None else ts[-1]
            i0 = max(int(np.searchsorted(ts, t_on, side="right")) - 1, 0)
            i1 = min(int(np.searchsorted(ts, end, side="left")), len(ts) - 1)
            tv = float(np.sum(np.abs(np.diff(p[i0:i1 + 1])))) if i1 > i0 else 0.0
            m["force_total_variation"] = tv / P0
            m["spurious_variation"] = tv / P0 - 2.0
            # width of the held pulse: cells with P > PULSE_THRESHOLD·P0 in the episode
            lo, hi = _cells(ts)
            inside = (hi > t_on) & (lo < end + t_merge) & (p > PULSE_THRESHOLD * P0)
            if np.any(inside):
                k = np.nonzero(inside)[0]
                width = float(hi[k[-1]] - lo[k[0]])
                m.update(pulse_duration=width, pulse_duration_error=width - T,
                         pulse_duration_relative_error=(width - T) / T)
    else:
        notes.append(f"contact {c['name']} is not in analysis.output.contacts: no pulse measures")

    ekeys = ("energy:kinetic", "energy:recoverable", "energy:initial")
    if all(k in col for k in ekeys):
        e = data[:, col["energy:kinetic"]] + data[:, col["energy:recoverable"]]
        e0 = data[0, col["energy:initial"]]
        if e_steps is None and rows_every_step:
            e_steps = e
        if e0 > 0:
            if e_steps is not None:
                m["energy_error"] = float(np.max(np.abs(e_steps - e0)) / e0)
            m["energy_final_error"] = float((e[-1] - e0) / e0)

    # final mean velocities and the displacement field need every node of the rods
    missing = [r["name"] for r in involved
               if any(f"v:{nm}" not in col for nm in r["nodes"])]
    if missing:
        notes.append("rod(s) " + ", ".join(missing) + " not fully in analysis.output.nodes "
                     "([[bar]] output = \"all\"): no final velocities or displacement field")
    else:
        def momentum(row, r):
            v = np.array([row[col[f"v:{nm}"]] for nm in r["nodes"]])
            mom = float(np.dot(r["node_mass"], v))
            pos = {nm: i for i, nm in enumerate(r["nodes"])}
            for na, nb, val in r["couplings"]:
                mom += val * (v[pos[na]] + v[pos[nb]])
            return mom

        v_fin, v_err, impulse = {}, {}, None
        for r in involved:
            mom = momentum(data[-1], r)
            v_fin[r["name"]] = mom / r["mass_total"]
            v_err[r["name"]] = (v_fin[r["name"]] - v_ref[r["name"]]) / v_rel
            if impulse is None:
                # the contact pushes side a back and side b on (δ = u_a − u_b − gap); the
                # first row is t = 0 (recorded at any every)
                impulse = (mom - momentum(data[0], r)) * (-1.0 if r is rod_a else 1.0)
        m["v_final"], m["v_error"] = v_fin, v_err
        m["impulse_error"] = (impulse - P0 * T) / (P0 * T)
        if t_off is None or t[-1] < t_off:
            notes.append("the run ends before the contact opens: final velocities are not post-impact")
        ma = rod_a["mass_total"] if rod_a else None
        mb = rod_b["mass_total"] if rod_b else None
        if wall:
            r = involved[0]
            frac = vibration_energy_fraction(r["mass_total"], None, r["v0"], 0.0, v_fin[r["name"]], 0.0)
            frac_ref = vibration_energy_fraction(r["mass_total"], None, r["v0"], 0.0, v_ref[r["name"]], 0.0)
        else:
            frac = vibration_energy_fraction(ma, mb, va0, vb0, v_fin[rod_a["name"]], v_fin[rod_b["name"]])
            frac_ref = vibration_energy_fraction(ma, mb, va0, vb0, v_ref[rod_a["name"]], v_ref[rod_b["name"]])
        m["vibration_energy_fraction"] = frac
        m["vibration_energy_reference"] = frac_ref

        if every_step:
            # displacement field against d'Alembert (free rods of equal bars), at every step:
            # the step trace's, else the rows' (every = 1)
            tu = steps["t"] if steps is not None else t
            u_of = (lambda nm: steps["u"][nm]) if steps is not None else (lambda nm: data[:, col[f"u:{nm}"]])
            err_all, err_end = 0.0, 0.0
            scale = vp * T
            for side, r, end_node in (("a", rod_a, side_a and side_a[1]), ("b", rod_b, side_b and side_b[1])):
                if r is None:
                    continue
                face = r["x0"] + r["L"] if end_node == r["right"] else r["x0"]
                other = (rod_b if side == "a" else rod_a)
                L_other = other["L"] if other is not None else r["L"]
                for nm, x in zip(r["nodes"], r["x"]):
                    s = min(max(abs(face - x), 0.0), r["L"])
                    u_ex = r["v0"] * tu + rod_point_displacement(s, tu - t_on_ref, ref.c, r["L"], L_other,
                                                                 v_rel, side, wall=wall)
                    e_node = float(np.max(np.abs(u_of(nm) - u_ex))) / scale
                    err_all = max(err_all, e_node)
                    if nm == end_node:
                        err_end = max(err_end, e_node)
            m["displacement_error"] = err_all
            m["end_displacement_error"] = err_end
    m["notes"] = notes
    return m
