"""Run a scene: build the native model from a validated Scene, run its analysis, and shape
the results as a summary dict (and, for dynamic runs, a history) ready to be written."""

import gc
import json
import os
import time
from contextlib import contextmanager
from pathlib import Path

import numpy as np

from .binding import native
from .binding.native import constant
from .errors import RecordError, ResultError, SceneError
from .paths import folder_replaced
from .results import (ARRAYS_FILE, PHASE_FIELDS, ItemArrays, is_large)
from .scene.chain import ChainContacts, ChainLinks
from .scene.items import ItemTable, Listed, Names
from .scene.rows import element_terms
from .scene.spec import DEFAULT_METHODS

# The names a link's type, a contact's scheme and law take (the library's tables); results
# store them as codes into these (martello.results).
LINK_KINDS, SCHEMES, LAWS = native.names("links"), native.names("schemes"), native.names("laws")
# Default exponent n of each law's elastic part F ~ δ^n (fixed, or Hertz's when the law reads it).
LAW_EXPONENT = {r.name: r.values["exponent"] for r in native.registry("laws")}


def _column(items, idx, key):
    """items[i][key] for i in idx, as float64 (the scene loader checked every value)."""
    return np.fromiter((items[i][key] for i in idx), np.float64, len(idx))


def _groups(names):
    """{name: indices} of a list of names (link types, contact schemes)."""
    arr = np.array(names, dtype=object)
    return {name: np.flatnonzero(arr == name) for name in dict.fromkeys(names)}


# The parameter slots each link type fills: slot -> its scene field (bar: EA/L, below).
LINK_SLOTS = {"spring": {"L_STIFF": "k"}, "dashpot": {"L_DAMP": "c"},
              "bilinear": {"L_STIFF": "k", "L_YIELD": "fy", "L_HARDENING": "hardening"},
              "fluid_damper": {"L_DAMP": "c", "L_ALPHA": "alpha", "L_VREG": "v_reg"}}


def link_arrays(links):
    """(kind, a, b, par[n, NPAR_LINK]) of the scene's links, for Model.add_links."""
    n = len(links)
    kind = np.zeros(n, np.int32)
    par = np.zeros((n, constant("NPAR_LINK")))
    for name, idx in _groups([lk["type"] for lk in links]).items():
        kind[idx] = native.value("links", name)
        for slot, key in LINK_SLOTS.get(name, {}).items():
            par[idx, constant(slot)] = _column(links, idx, key)
        if name == "bar":
            par[idx, constant("L_STIFF")] = _column(links, idx, "EA") / _column(links, idx, "L")
    a = np.fromiter((-1 if lk["a"] is None else lk["a"] for lk in links), np.int32, n)
    b = np.fromiter((-1 if lk["b"] is None else lk["b"] for lk in links), np.int32, n)
    return kind, a, b, par


def _optional(items, idx, key, absent):
    """items[i][key], or absent where it is None or not given."""
    return np.fromiter((absent if items[i].get(key) is None else items[i][key] for i in idx),
                       np.float64, len(idx))


def contact_arrays(contacts):
    """(a, b, gap, scheme, law, par[n, NPAR_CONTACT]) of the scene's contacts, for
    Model.add_contacts. A restitution slot of −1 means none given (docs/c-api.md)."""
    n = len(contacts)
    scheme = np.zeros(n, np.int32)
    law = np.zeros(n, np.int32)
    par = np.zeros((n, constant("NPAR_CONTACT")))
    par[:, constant("P_RESTITUTION")] = -1.0
    for name, idx in _groups([c["scheme"] for c in contacts]).items():
        scheme[idx] = native.value("schemes", name)
        if name == "penalty":
            for law_name, sub in _groups([contacts[i]["law"] for i in idx]).items():
                law[idx[sub]] = native.value("laws", law_name)
                # an exponent of None (or 0) means the law's own (LAW_EXPONENT)
                par[idx[sub], constant("P_EXPONENT")] = np.fromiter(
                    (contacts[i]["exponent"] or LAW_EXPONENT[law_name] for i in idx[sub]),
                    np.float64, len(sub))
            par[idx, constant("P_STIFF")] = _column(contacts, idx, "stiffness")
            par[idx, constant("P_DAMPING")] = _optional(contacts, idx, "damping", 0.0)
            par[idx, constant("P_RESTITUTION")] = _optional(contacts, idx, "restitution", -1.0)
            par[idx, constant("P_CLIP")] = np.fromiter(
                (1.0 if contacts[i]["clipped"] else 0.0 for i in idx), np.float64, len(idx))
        elif name == "augmented-lagrange":
            par[idx, constant("P_STIFF")] = _column(contacts, idx, "stiffness")
        else:
            par[idx, constant("P_RESTITUTION")] = _optional(contacts, idx, "restitution", -1.0)
    a = np.fromiter((-1 if c["a"] is None else c["a"] for c in contacts), np.int32, n)
    b = np.fromiter((-1 if c["b"] is None else c["b"] for c in contacts), np.int32, n)
    gap = np.fromiter((c["gap"] for c in contacts), np.float64, n)
    return a, b, gap, scheme, law, par


def node_arrays(nodes):
    """(mass, u0, v0, fixed) of the scene's nodes, for Model.set_nodes: a listed segment's
    read from its dicts, a generated one's arrays as it gives them (martello.scene.items)."""
    parts = []
    for seg in segments(nodes):
        if isinstance(seg, list):
            parts.append([np.fromiter((nd[key] for nd in seg), dt, len(seg))
                          for key, dt in (("mass", np.float64), ("u0", np.float64),
                                          ("v0", np.float64), ("fixed", np.int32))])
        else:
            parts.append(list(seg.arrays()))
    return tuple(np.concatenate([p[k] for p in parts]) if parts else np.zeros(0)
                 for k in range(4))


def names_of(table):
    """The names of an item table (a Names, or a list for a plain list of dicts)."""
    return table.names if isinstance(table, ItemTable) else [it["name"] for it in table]


def segments(table):
    """The segments of an item table (martello.scene.items); a plain list is one segment."""
    return table.segments if isinstance(table, ItemTable) else [list(table)]


# Generated items go to the library this many at a time: the rows of parameters handed
# over stay a few MB whatever the chain's length (docs/performance.md, "The front end").
CHUNK = 1 << 16


def _runs(items):
    """A listed segment as runs of node pairs (a list) and single rows (a dict with
    "terms": an element between plan points, martello.scene.rows), in order."""
    run = []
    for it in items:
        if it.get("terms") is None:
            run.append(it)
            continue
        if run:
            yield run
            run = []
        yield it
    if run:
        yield run


def _row(item):
    """An element's row for the native door: 0-based nodes and their coefficients."""
    nodes, coefs = zip(*element_terms(item))
    return np.array(nodes, np.int32), np.array(coefs, np.float64)


def link_chunks(segs):
    """(kind, a, b, par) arrays of links (segments of the scene's link table), in order, a
    chunk at a time: a listed segment's from its dicts (a link between plan points as
    ("row", kind, nodes, coefs, par)), a generated one's as it gives them."""
    for seg in segs:
        if isinstance(seg, list):
            for run in _runs(seg):
                if isinstance(run, dict):
                    kind, _, _, par = link_arrays([run])
                    yield ("row", kind[0], *_row(run), par[0])
                else:
                    yield link_arrays(run)
        else:
            yield from seg.chunks(CHUNK)


def contact_chunks(segs):
    """(a, b, gap, scheme, law, par) arrays of contacts (segments of the scene's contact
    table), in order, a chunk at a time; a generated segment's contacts share one row of
    parameters, its template's."""
    for seg in segs:
        if isinstance(seg, list):
            for run in _runs(seg):
                if isinstance(run, dict):
                    _, _, gap, scheme, law, par = contact_arrays([run])
                    yield ("row", *_row(run), gap[0], scheme[0], law[0], par[0])
                else:
                    yield contact_arrays(run)
            continue
        _, _, _, scheme, law, row = contact_arrays([seg.template])
        for a, b, gap in seg.chunks(CHUNK):
            m = len(a)
            yield (a, b, gap, np.full(m, scheme[0], np.int32), np.full(m, law[0], np.int32),
                   np.repeat(row, m, axis=0))


def _function_args(fn, source="<scene>", t_end=None):
    """A validated function table -> (kind, par[NPAR_TF], t, y) for the native library. A
    record must start within the run, [0, t_end): one that starts before t = 0 would lose
    its beginning, one that starts at or after t_end would be no load at all."""
    par = np.zeros(constant("NPAR_TF"))
    kind = fn["type"]
    if kind == "constant":
        par[0] = fn["value"]
        return constant("TF_CONSTANT"), par, (), ()
    if kind == "sine":
        par[:] = [fn["amplitude"], fn["omega"], fn["phase"], fn["t_start"], fn["t_end"]]
        return constant("TF_SINE"), par, (), ()
    if kind in ("rectangular", "half_sine"):
        par[:] = [fn["amplitude"], 0.0, 0.0, fn["t_start"], fn["t_end"]]
        return constant("TF_RECTANGULAR" if kind == "rectangular" else "TF_HALF_SINE"), par, (), ()
    if kind == "table":
        par[0] = fn["scale"]
        return constant("TF_TABLE"), par, fn["t"], fn["values"]
    if kind == "record":
        from .ground_motion.records import read_record    # only a scene with a record needs it
        try:
            rec = read_record(fn["file"], fmt=fn["format"], units=fn["units"], scale=fn["scale"])
        except RecordError as exc:
            if "given" not in fn:
                raise
            raise exc.within(source, fn["where"], fn["given"]) from None
        where, given = fn.get("where", "record"), fn.get("given", fn["file"])
        if rec.t[0] < 0:
            raise SceneError(source, where, f"{given} starts at t = {float(rec.t[0])!r} s, before "
                             "the run's t = 0: its samples before 0 would be left out",
                             "shift its times to start at 0 or later")
        if t_end is not None and rec.t[0] >= t_end:
            raise SceneError(source, where, f"{given} starts at t = {float(rec.t[0])!r} s, not "
                             f"before the run's t_end = {t_end!r} s: the run would see none of it",
                             "shift its times, or raise analysis.t_end")
        par[0] = 1.0
        return constant("TF_TABLE"), par, rec.t, rec.accel
    raise AssertionError(kind)


def build_model(scene, chain_door=True):
    """A native Model holding the scene (the caller frees it, or uses a with-block).

    Each [[chain]] goes to the library whole (martello_model_add_chain: the model keeps its
    arrays, the fused chain step reads them as they are), the other items by the bulk doors, so
    that every item has the number the scene gives it: every listed contact first (the scene
    numbers the chains' contacts after them), then the link segments in order, a chain's at
    its call (its springs and dashpots, then its contacts: numbered as if added one by one
    there, docs/c-api.md "Chains"). chain_door=False adds the chains' items by the bulk doors
    instead: the same model, run to the same bits (tests/test_chain_door.py)."""
    link_segs, contact_segs = segments(scene.links), segments(scene.contacts)
    door = chain_door and any(isinstance(seg, ChainLinks) for seg in link_segs)
    if door:
        contact_segs = [seg for seg in contact_segs if not isinstance(seg, ChainContacts)]
    # no capacity for the chains' items: the model keeps them as the chains' arrays
    m = native.Model(len(scene.nodes),
                     sum(len(seg) for seg in link_segs if not (door and isinstance(seg, ChainLinks))),
                     sum(map(len, contact_segs)), len(scene.forces), len(scene.couplings))
    # one call per array, or per chunk of a generator's (docs/c-api.md, "Building a large model")
    m.set_nodes(*node_arrays(scene.nodes))
    if not door:
        for chunk in link_chunks(link_segs):
            _add(m.add_links, m.add_link_row, chunk)
    for chunk in contact_chunks(contact_segs):
        _add(m.add_contacts, m.add_contact_row, chunk)
    # the link segments in order: a chain's at its call (after every listed contact, which
    # the scene numbers before the chains' contacts)
    for seg in link_segs if door else ():
        if isinstance(seg, ChainLinks):
            add_chain(m, seg.block)
        else:
            for chunk in link_chunks([seg]):
                _add(m.add_links, m.add_link_row, chunk)
    for seg in segments(scene.couplings):
        if isinstance(seg, list):
            for mc in seg:
                m.add_mass_coupling(mc["a"], mc["b"], mc["value"])
        else:                       # a rod's consistent mass, from its mesh (no dict each)
            for i, j, value in seg.rod.mesh["couplings"]:
                m.add_mass_coupling(seg.rod.node0 + i, seg.rod.node0 + j, value)
    for b in scene.blocks:
        m.add_stiffness_block(b["nodes"], b["k"], b["c"])
    m.set_gravity(scene.gravity)
    if scene.influence is not None:
        m.set_influence(scene.influence)
    for f in scene.forces:
        m.add_nodal_force(f["node"], *_function_args(f["function"], scene.source))
    if scene.ground is not None:
        m.set_ground_acceleration(*_function_args(scene.ground, scene.source,
                                                  scene.analysis.get("t_end")))
    return m


def _add(bulk, row, chunk):
    """A chunk of link_chunks or contact_chunks to the model: pairs by the bulk door, an
    element between plan points by its row door."""
    if isinstance(chunk[0], str):
        row(*chunk[1:])
    else:
        bulk(*chunk)


def add_chain(model, b):
    """One [[chain]] (a ChainBlock) through the chain door: its arrays as they are, the
    dashpot coefficients per oscillator (0 where it has none), its contacts' one row of
    parameters (its template's)."""
    c = None
    if len(b.dampers):
        c = np.zeros(b.n)
        c[b.dampers] = b.c
    kw = {}
    if b.n_contacts:
        _, _, _, scheme, law, row = contact_arrays([b.template])
        kw = dict(gap=b.gap, scheme=int(scheme[0]), law=int(law[0]), par=row[0])
    model.add_chain(b.node0, b.k, c=c, fy=b.fy, hardening=b.hardening if b.fy is not None else None,
                    **kw)


def provenance(scene):
    return {"martello_version": native.version(), "libraries": native.library_versions(),
            "scene_file": scene.source, "scene_sha256": scene.digest,
            "date": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())}


def run(scene):
    """Run the scene's analysis; return the summary dict (JSON-ready)."""
    return run_full(scene)[0]


def run_full(scene, raise_on_failure=True):
    """(summary, history) — history is None for static runs, else (columns, 2D array).

    With raise_on_failure=False a failed dynamic run (diverged, unstable, not converged)
    returns its summary with the failure status and message instead of raising: studies
    classify such runs; nothing else should write them out as results."""
    with build_model(scene) as model:
        if scene.analysis["type"] == "static":
            return _static(scene, model), None
        return _dynamic(scene, model, raise_on_failure)[:2]


def run_traced(scene, contact, nodes=()):
    """(summary, history, trace) of a dynamic run whose step trace holds this contact and
    these nodes (names): trace = {"t", "force", "kinetic", "recoverable": arrays over every grid
    point of a fixed-step run, "u": {node: array}} (docs/results.md "Step trace"), whatever the
    history records."""
    with build_model(scene) as model:
        return _dynamic(scene, model, True, trace=(names_of(scene.contacts).index(contact),
                                                   [scene.index[n] for n in nodes], list(nodes)))


def integrator_settings(an):
    """The analysis table -> the native settings: the library's defaults, overridden by every
    setting the table gives (output.every is the setting every)."""
    given = {k: an[k] for k in native.settings_defaults() if an.get(k) is not None}
    if "method" in given:   # a name of the library's table methods -> its value
        given["method"] = native.value("methods", given["method"])
    return native.settings(an["integrator"], **given, every=an["output"]["every"])


def integrator_description(an):
    d = {"name": an["integrator"], "dt": an["dt"], "t_end": an["t_end"]}
    if an["integrator"] == "newmark":
        d.update(beta=an["beta"], gamma=an["gamma"], preset=an["preset"])
    elif an["integrator"] == "hht":
        d.update(alpha=an["alpha"])
    elif an["integrator"] == "generalized-alpha":
        d.update(rho_inf=an["rho_inf"])
    elif an["integrator"] == "moreau-jean":
        d.update(theta=an["theta"])
    elif an["integrator"] in ("rkf45", "rk8pd", "msbdf", "ida", "cvode", "arkode"):
        d.update(rtol=an["rtol"], atol=an["atol"], event_tol=an["event_tol"], h_max=an["h_max"])
    if an["integrator"] in ("cvode", "arkode"):
        d.update(method=an.get("method") or DEFAULT_METHODS[an["integrator"]])
    if an["integrator"] in ("newmark", "hht", "generalized-alpha", "newmark-lagrange"):
        d.update(tol_residual=an["tol_residual"], tol_increment=an["tol_increment"],
                 max_newton=an["max_newton"])
    return d


@contextmanager
def _collector_paused():
    """The cyclic garbage collector off for a while. A large scene's summary is millions of
    acyclic dicts and lists: each collection the allocations trigger rescans all of them and
    frees none (at n = 1e6 that doubled the time to build the summary)."""
    was = gc.isenabled()
    gc.disable()
    try:
        yield
    finally:
        if was:
            gc.enable()


@_collector_paused()
def _dynamic(scene, model, raise_on_failure=True, trace=None):
    an = scene.analysis
    out_nodes = [scene.index[n] for n in an["output"]["nodes"]]
    out_contacts = [names_of(scene.contacts).index(c) for c in an["output"]["contacts"]]
    with native.Run() as r:
        r.set_settings(integrator_settings(an))
        r.set_outputs(out_nodes, out_contacts)
        out_links = [names_of(scene.links).index(n) for n in an["output"]["links"]]
        r.set_link_outputs(out_links)
        # only what the summary and results list (docs/results.md): the library allocates
        # nothing for the rest
        tracked = an["output"]["track"]
        r.set_tracking(*tracked)
        structures = _structure_functionals(scene)
        if structures.rows:
            r.set_functionals(structures.matrix(), structures.nodes, structures.pairs)
        if trace is not None:
            r.set_trace(*trace[:2])
        t0 = time.perf_counter()
        st = r.execute(model) if raise_on_failure else r.status_of(model)
        if st == native.constant("MARTELLO_ERR_INTERRUPTED"):
            r.check(st, "dynamic run")   # stopped by its user: raised, never an outcome
        wall = time.perf_counter() - t0
        hist = r.history()
        ev_contacts, ev = r.events()
        # the results of what it tracked alone (a large scene's untracked columns would be
        # arrays of NaN as large as the run's state)
        peaks = r.peaks(len(scene.nodes), len(scene.contacts), "node_peaks" in tracked,
                        "contact_peaks" in tracked)
        energy, extra = r.energy()
        link_f, link_du = r.link_peaks(len(scene.links)) if "link_peaks" in tracked else (None, None)
        counters = r.counters()
        message = r.message()
        if structures.rows:
            structures.read(r)
        steps = r.trace() if trace is not None else None

    columns = native.history_columns(an["output"]["nodes"], an["output"]["contacts"],
                                     an["output"]["links"])
    col = {name: i for i, name in enumerate(columns)}
    arrays = item_arrays(scene, tracked, peaks, link_f, link_du, ev,
                         *phase_rows(ev_contacts, len(scene.contacts)))
    # a large scene: the items named in output in summary.json, all of them as arrays
    # (docs/results.md, "Results as arrays"); a small one: every item in summary.json
    large = is_large(scene)
    pick = (lambda kind, named: list(dict.fromkeys(named))) if large else \
        (lambda kind, named: range(len(arrays.names[kind])))
    nodes = arrays.entries("nodes", pick("nodes", out_nodes))
    for name in an["output"]["nodes"]:
        if f"u:{name}" in col and len(hist):
            nodes[name].update(u_final=float(hist[-1, col[f"u:{name}"]]),
                               v_final=float(hist[-1, col[f"v:{name}"]]))
    contacts = arrays.entries("contacts", pick("contacts", out_contacts))
    every_phase = len(scene.contacts) <= PHASE_LISTS or set(an["output"]["contacts"])
    if "phases" not in tracked:
        every_phase = set()                  # no phase kept: none listed
    if every_phase is True:
        # the events grouped by contact once (each contact's rows in the table's order)
        order = np.argsort(ev_contacts, kind="stable")
        bounds = np.searchsorted(ev_contacts[order], np.arange(len(scene.contacts) + 1))
        rows_of = lambda j: order[bounds[j]:bounds[j + 1]]          # noqa: E731
    else:       # a few named contacts of many: their rows found without sorting the table
        rows_of = lambda j: np.flatnonzero(ev_contacts == j)       # noqa: E731
    for name, e in contacts.items():
        if every_phase is not True and name not in every_phase:
            continue       # a scene of many contacts: the first and last phase (docs/results.md)
        mine = ev[rows_of(arrays.names["contacts"].position(name))]
        closed = mine[mine[:, 1] >= 0]
        e.pop("first_phase"), e.pop("last_phase")
        e.update({
            "impact_times": [float(x) for x in mine[:, 0]],
            "separation_times": [float(x) if x >= 0 else None for x in mine[:, 1]],
            "approach_speeds": [float(x) for x in mine[:, 2]],
            "separation_speeds": [float(x) for x in closed[:, 3]],
            # realised restitution of each completed contact phase: −δ̇_out/δ̇_in
            "restitution": [float(-vo / vi) if vi > 0 else None for vi, vo in closed[:, 2:4]],
            "phase_max_penetration": [float(x) for x in mine[:, 4]],
            "phase_max_force": [float(x) for x in mine[:, 5]]})
        if len(closed):
            e["contact_time"] = float(closed[0, 1] - closed[0, 0])  # first phase
        if name in an["output"]["contacts"] and len(hist):
            # the state at t_end: a persistent contact's multiplier (e.g. k h − m g after Zeno)
            e["penetration_final"] = float(hist[-1, col[f"penetration:{name}"]])
            e["force_final"] = float(hist[-1, col[f"force:{name}"]])
            e["lambda_final"] = 0.0 - e["force_final"]  # seed sign
        if e["scheme"] in ("restitution", "lagrange"):
            # the start of the first lasting contact phase: the accumulation (Zeno) time of
            # an impact sequence, or a plastic impact's instant (impacts have t_off = t_on)
            lasting = [row for row in mine if row[1] < 0 or row[1] > row[0]]
            if lasting:
                e["persistent_from"] = float(lasting[0][0])
    scale = max(abs(energy["initial"]), abs(energy["input"]), 1e-300)
    energy.update(balance_max=extra["balance_max"], balance_relative=extra["balance_max"] / scale)
    warnings = []
    if extra["dt_critical"] > 0 and an["integrator"] not in native.adaptive_integrators() \
            and an["dt"] > extra["dt_critical"]:
        # check_stability = false let it run past the limit (docs/behaviour.md)
        warnings.append(f"dt = {an['dt']!r} s is past the stability limit dt_crit = "
                        f"{extra['dt_critical']:.6g} s (check_stability = false): the result "
                        "may be wrong although no guard stopped it")
    if dense_note(an, len(scene.nodes)):
        warnings.append(dense_note(an, len(scene.nodes)))
    if atol_note(scene):
        warnings.append(atol_note(scene))
    if held_note(scene):
        warnings.append(held_note(scene))
    if st >= 0 and energy["balance_relative"] > 1e-2:
        warnings.append(f"energy balance error {100 * energy['balance_relative']:.1f} % of the energy put in: "
                        "the step is too large for this scene (the result is inaccurate)")
    frames = {}
    for fr in scene.extras.get("frames", []):
        frames[fr["prefix"]], extra_cols = frame_results(fr, columns, hist, structures.of(fr["prefix"]))
        if fr["histories"] and len(hist):
            columns = columns + list(extra_cols)
            hist = np.hstack([hist, np.column_stack(list(extra_cols.values()))])
    buildings = {}
    for b in scene.extras.get("buildings", []):
        buildings[b["prefix"]], extra_cols = building_results(b, columns, hist, structures.of(b["prefix"]))
        if b["histories"] and len(hist):
            columns = columns + list(extra_cols)
            hist = np.hstack([hist, np.column_stack(list(extra_cols.values()))])
    summary = {
        "title": scene.title, "problem": scene.problem,
        "analysis": {k: v for k, v in an.items() if k != "output"} | {"output_every": an["output"]["every"]},
        "integrator": integrator_description(an),
        "status": native.status_name(st),
        "message": message,
        "warnings": warnings,
        "t_reached": extra["t_reached"],
        "tracked": list(tracked),
        "nodes": nodes, "contacts": contacts, "energy": energy,
        "links": arrays.entries("links", pick("links", out_links)),
        **({"arrays": arrays} if large else {}),
        **({"frames": frames} if frames else {}),
        **({"buildings": buildings} if buildings else {}),
        "stability": {"omega_max": extra["omega_max"] or None,
                      "dt_critical": extra["dt_critical"] or None},
        "cost": counters | {"wall_time_s": wall},
        "provenance": provenance(scene),
    }
    if steps is not None:
        steps = dict(zip(("t", "force", "kinetic", "recoverable"), steps[:, :4].T),
                     u=dict(zip(trace[2], steps[:, 4:].T)))
    return summary, (columns, hist), steps


# The library's per-node peaks that are a node's results, in the order summary.json lists
# them (docs/results.md, "Nodes"); a new peak of martello_run_peaks is a new name here.
NODE_PEAKS = ("u_max", "u_min", "v_absmax", "a_absmax", "u_absmax", "t_absmax")


def phase_rows(ev_contacts, n_contacts):
    """Each contact's first and last row of the event table (−1 where it has none), in one
    pass over the table's contact column, without sorting it (at 23.5 million phases a
    stable sort took ~10 s and 0.3 GB)."""
    rows = np.arange(len(ev_contacts), dtype=np.int64)
    first = np.full(n_contacts, len(ev_contacts), np.int64)
    last = np.full(n_contacts, -1, np.int64)
    np.minimum.at(first, ev_contacts, rows)
    np.maximum.at(last, ev_contacts, rows)
    first[first == len(ev_contacts)] = -1
    return first, last


def item_arrays(scene, tracked, peaks, link_f, link_du, ev, first, last):
    """The per-item results of a dynamic run as columns (martello.results.ItemArrays) from
    the library's arrays: peaks (martello_run_peaks), link peaks, and the event table ev with
    each contact's first and last row of it (phase_rows); the columns of what the run did not
    track (spec.TRACKABLE) left out."""
    f64 = lambda x: np.asarray(x, np.float64)             # noqa: E731
    nodes, links, contacts = {}, {"type": _codes(scene.links, "type", LINK_KINDS)}, {
        "scheme": _codes(scene.contacts, "scheme", SCHEMES),
        "law": _codes(scene.contacts, "law", LAWS)}
    if "node_peaks" in tracked:
        t_peak = f64(peaks["t_peak"])
        has_peak = t_peak >= 0                              # else: no local maximum of u
        nodes = {k: f64(peaks[k]) for k in NODE_PEAKS}
        nodes["u_peak"] = np.where(has_peak, f64(peaks["u_peak"]), np.nan)
        nodes["t_peak"] = np.where(has_peak, t_peak, np.nan)
    if "link_peaks" in tracked:
        f, du = f64(link_f), f64(link_du)
        links["max_abs_force"] = np.where(np.isfinite(f), f, np.nan)     # null: not reported
        links["max_abs_elongation"] = np.where(np.isfinite(du), du, np.nan)
    if "contact_peaks" in tracked:
        pen = f64(peaks["pen_max"])
        contacts["max_penetration"] = np.where(0.0 > pen, 0.0, pen)     # max(pen, 0), NaN kept
        contacts["max_force"] = f64(peaks["force_max"])
    contacts["impacts"] = np.asarray(peaks["impacts"]).astype(np.int64)
    for p, rows in (("first", first), ("last", last)) if "phases" in tracked else ():
        has = rows >= 0
        phase = _phases(ev, rows[has], has)
        for k, field in enumerate(PHASE_FIELDS):
            contacts[f"{p}.{field}"] = phase[:, k]
    names = {kind: _names(table) for kind, table in
             (("nodes", scene.nodes), ("links", scene.links), ("contacts", scene.contacts))}
    return ItemArrays(names, {"nodes": nodes, "links": links, "contacts": contacts},
                      {"links": {"type": list(LINK_KINDS)},
                       "contacts": {"scheme": list(SCHEMES), "law": list(LAWS)}})


def _phases(ev, rows, has):
    """One phase per contact as rows of PHASE_FIELDS: the event rows ev[rows] where `has`,
    NaN elsewhere; the separation fields NaN while a phase is open (t_off < 0)."""
    out = np.full((len(has), len(PHASE_FIELDS)), np.nan)
    out[has] = ev[rows]
    open_ = has & ~(out[:, 1] >= 0)
    out[open_, 1] = out[open_, 3] = np.nan
    return out


def _names(table):
    """The Names of an item table (a plain list of dicts: its names listed)."""
    return table.names if isinstance(table, ItemTable) else Names([Listed([it["name"] for it in table])])


def _codes(table, key, categories):
    """Codes of a category column (index into categories, −1 where None), segment by
    segment: a generated one's as it gives them."""
    at = {c: i for i, c in enumerate(categories)}
    parts = []
    for seg in segments(table):
        if isinstance(seg, list):
            parts.append(np.fromiter((at.get(it.get(key), -1) for it in seg), np.int8, len(seg)))
        else:
            parts.append(seg.codes(key, at))
    return np.concatenate(parts) if parts else np.zeros(0, np.int8)


class _Functionals:
    """The linear functionals of the state a run's frames and buildings track at every
    accepted sample (martello_run_set_functionals; docs/results.md, "Frames and buildings"):
    per structure (by prefix) its operator blocks stacked into rows over its nodes, and the
    pairs of rows whose resultant is tracked (a building's M2, M3 at each member end)."""

    def __init__(self):
        self.blocks, self.nodes, self.pairs, self.rows = [], [], [], 0
        self.at = {}

    def add(self, prefix, nodes, operators, pairs=()):
        """The structure's operators (dense, rows x len(nodes)) stacked; pairs: rows of the
        stack (0-based in it)."""
        R = np.vstack(operators) if operators else np.zeros((0, len(nodes)))
        self.blocks.append((R, len(self.nodes)))
        self.at[prefix] = (self.rows, self.rows + R.shape[0], len(self.pairs), len(self.pairs) + len(pairs))
        self.pairs += [(self.rows + i, self.rows + j) for i, j in pairs]
        self.nodes += list(nodes)
        self.rows += R.shape[0]

    def matrix(self):
        """The stacked rows over all the structures' nodes (block diagonal)."""
        M = np.zeros((self.rows, len(self.nodes)))
        r = 0
        for R, c in self.blocks:
            M[r:r + R.shape[0], c:c + R.shape[1]] = R
            r += R.shape[0]
        return M

    def read(self, run):
        self.values = run.functionals(self.rows, len(self.pairs))

    def of(self, prefix):
        """(q_max, t_max, q_min, t_min, res_max, t_res) of one structure's rows and pairs."""
        r0, r1, p0, p1 = self.at[prefix]
        return [x[r0:r1] for x in self.values[:4]] + [x[p0:p1] for x in self.values[4:]]


def _structure_functionals(scene):
    """The functionals of every frame and building of the scene (their rows in the order
    frame_results and building_results read them)."""
    fq = _Functionals()
    for fr in scene.extras.get("frames", []):
        fq.add(fr["prefix"], [scene.index[n] for n in fr["nodes"]],
               [fr["recovery"], fr["drift"], fr["shear"]])
    for b in scene.extras.get("buildings", []):
        bd = b["building"]
        ops = [b["recovery"], b["storey"]] + [bd.point_operator(p["floor"], p["x"], p["y"])
                                             for p in b["points"]]
        pairs = [(12 * e + off + 4, 12 * e + off + 5) for e in range(len(bd.elements)) for off in (0, 6)]
        fq.add(b["prefix"], [scene.index[n] for n in b["nodes"]], ops, pairs)
    return fq


def _tracked_extremes(values, row):
    """Signed extremes of tracked row `row` and their times (None without a sample)."""
    q_max, t_max, q_min, t_min = (x[row] for x in values[:4])
    if not t_max >= 0:
        return {"max": None, "min": None, "t_max": None, "t_min": None}
    return {"max": float(q_max), "min": float(q_min), "t_max": float(t_max), "t_min": float(t_min)}


def frame_results(fr, columns, hist, tracked):
    """A frame's peaks: signed extremes of every member's end moments and shears with their
    times, of every storey's drifts and shear — linear functionals of the state the run
    tracked at every accepted sample and inside the steps whatever it records (tracked:
    _Functionals.of; docs/results.md, "Frames and buildings"). Also the member histories, by
    column name (martello.frame2d's recovery operators on the recorded samples)."""
    col = {name: i for i, name in enumerate(columns)}
    U = hist[:, [col[f"u:{n}"] for n in fr["nodes"]]] if len(hist) else np.zeros((0, len(fr["nodes"])))
    frame = fr["frame"]
    n_rec = fr["recovery"].shape[0]
    members, series = {}, {}
    for e, m in enumerate(frame.members):
        members[m.name] = {"kind": m.kind}
        for k, q in enumerate(("N_i", "V_i", "M_i", "N_j", "V_j", "M_j")):
            if q.startswith("N") and m.kind == "beam" and frame.mass_model == "diaphragm":
                continue          # a rigid diaphragm's beams have no axial deformation
            members[m.name][q] = _tracked_extremes(tracked, 6 * e + k)
            if q in ("M_i", "M_j", "V_i"):
                series[f"{q}:{fr['prefix']}.{m.name}"] = U @ fr["recovery"][6 * e + k]
    nl = frame.bays + 1
    n_drift = fr["drift"].shape[0]
    storeys = {str(s + 1): {"drift": {str(i): _tracked_extremes(tracked, n_rec + s * nl + i) for i in range(nl)},
                            "shear": _tracked_extremes(tracked, n_rec + n_drift + s)}
               for s in range(frame.storeys)}
    return {"members": members, "storeys": storeys,
            "rayleigh": {"a0": fr["rayleigh"][0], "a1": fr["rayleigh"][1], "zeta": fr["zeta"]}}, series


def building_description(b):
    """What a building's summary says of it whatever the run: its modes and damping."""
    return {"model": b["building"].model, "dofs": len(b["nodes"]), "modes": b["modes"],
            "damping": {"kind": b["damping"], "zeta": b["zeta"], "a0": b["rayleigh"][0],
                        "a1": b["rayleigh"][1]},
            "ground_angle": b["ground_angle"]}


def building_results(b, columns, hist, tracked):
    """A building's peaks: signed extremes of every member's end forces (N, V2, V3, T, M2,
    M3 at ends i and j; a rigid floor's beams carry no in-plane forces, so no N, V3, M2)
    with their times and the largest biaxial moment √(M2² + M3²) at each end and its time;
    per storey the shears along x and y and the torque about the floor's reference point;
    per requested plan point its ux, uy — linear functionals of the state (martello.building3d's
    operators) the run tracked at every accepted sample whatever it records, the resultant at
    the samples (tracked: _Functionals.of; docs/results.md, "Frames and buildings"). Also the
    member histories (M2, M3 at both ends, by column name) on the recorded samples."""
    col = {name: i for i, name in enumerate(columns)}
    U = hist[:, [col[f"u:{n}"] for n in b["nodes"]]] if len(hist) else np.zeros((0, len(b["nodes"])))
    bd = b["building"]
    res_max, t_res = tracked[4], tracked[5]
    members, series = {}, {}
    for e, m in enumerate(bd.elements):
        rigid_beam = m.kind == "beam" and bd.floors[m.storey - 1].rigid
        out = {"kind": m.kind, "storey" if m.kind != "beam" else "floor": m.storey}
        for p, (end, off) in enumerate((("i", 0), ("j", 6))):
            for k, q in enumerate(("N", "V2", "V3", "T", "M2", "M3")):
                if rigid_beam and q in ("N", "V3", "M2"):
                    continue
                out[f"{q}_{end}"] = _tracked_extremes(tracked, 12 * e + off + k)
                if q in ("M2", "M3"):
                    series[f"{q}_{end}:{b['prefix']}.{m.name}"] = U @ b["recovery"][12 * e + off + k]
            has = t_res[2 * e + p] >= 0
            out[f"M_{end}_resultant_max"] = float(res_max[2 * e + p]) if has else None
            out[f"M_{end}_resultant_t"] = float(t_res[2 * e + p]) if has else None
        members[m.name] = out
    n_rec = b["recovery"].shape[0]
    storeys = {str(s + 1): {q: _tracked_extremes(tracked, n_rec + 3 * s + k)
                            for k, q in enumerate(("shear_x", "shear_y", "torque"))}
               for s in range(bd.storeys)}
    n_st = b["storey"].shape[0]
    points = {}
    for i, p in enumerate(b["points"]):
        r = n_rec + n_st + 2 * i
        points[p["name"]] = {"floor": p["floor"], "x": p["x"], "y": p["y"],
                             "ux": _tracked_extremes(tracked, r), "uy": _tracked_extremes(tracked, r + 1)}
    return building_description(b) | {"members": members, "storeys": storeys, "points": points}, series


def _static_building(b, scene, u):
    """A building's member end forces, storey shears and torques at the static solution."""
    U = np.array([u[scene.index[n]] for n in b["nodes"]])
    F = b["recovery"] @ U
    S = b["storey"] @ U
    members = {m.name: dict(zip([f"{q}_{e}" for e in "ij" for q in ("N", "V2", "V3", "T", "M2", "M3")],
                                map(float, F[12 * k:12 * k + 12])))
               for k, m in enumerate(b["building"].elements)}
    return building_description(b) | {
        "members": members,
        "storeys": {str(s + 1): dict(zip(("shear_x", "shear_y", "torque"), map(float, S[3 * s:3 * s + 3])))
                    for s in range(b["building"].storeys)},
        "points": {p["name"]: dict(zip(("ux", "uy"), map(float, b["building"].point_operator(
            p["floor"], p["x"], p["y"]) @ U))) for p in b["points"]}}


def _static_frame(fr, scene, u):
    """A frame's member end forces, storey drifts and shears at the static solution."""
    U = np.array([u[scene.index[n]] for n in fr["nodes"]])
    F = fr["recovery"] @ U
    members = {m.name: dict(zip(("N_i", "V_i", "M_i", "N_j", "V_j", "M_j"), map(float, F[6 * e:6 * e + 6])))
               for e, m in enumerate(fr["frame"].members)}
    return {"members": members, "drift": [float(x) for x in fr["drift"] @ U],
            "shear": [float(x) for x in fr["shear"] @ U]}


def _static(scene, model):
    t0 = time.perf_counter()
    r = model.static_solve(scene.analysis["tol"], scene.analysis["max_iter"])
    wall = time.perf_counter() - t0
    contacts = {}
    for j, c in enumerate(scene.contacts):
        contacts[c["name"]] = {
            "scheme": c["scheme"], "force": float(r["force"][j]),
            "lambda": 0.0 - float(r["force"][j]),  # the seed's sign: λ < 0 in compression (no −0)
            "penetration": float(r["penetration"][j]), "active": bool(r["active"][j])}
    warnings = [r["warning"]] if r["warning"] else []
    ignored = [w for w, present in (
        ("ground acceleration", scene.ground is not None),
        ("dashpots and fluid dampers", any(l["type"] in ("dashpot", "fluid_damper") for l in scene.links)),
        ("initial velocities", any(n["v0"] != 0 for n in scene.nodes)),
        ("initial displacements of free nodes", any(n["u0"] != 0 and not n["fixed"] for n in scene.nodes)),
        ("time dependence of nodal forces (evaluated at t = 0)",
         any(f["function"]["type"] != "constant" for f in scene.forces))) if present]
    if ignored:
        warnings.append("static analysis ignores: " + ", ".join(ignored))
    return {
        "title": scene.title, "problem": scene.problem,
        "analysis": dict(scene.analysis),
        "status": r["status"],
        "warnings": warnings,
        "nodes": {n["name"]: {"u": float(r["u"][i])} for i, n in enumerate(scene.nodes)},
        "contacts": contacts,
        **({"frames": {fr["prefix"]: _static_frame(fr, scene, r["u"])
                       for fr in scene.extras["frames"]}} if scene.extras.get("frames") else {}),
        **({"buildings": {b["prefix"]: _static_building(b, scene, r["u"])
                          for b in scene.extras["buildings"]}} if scene.extras.get("buildings") else {}),
        "conditioning": {"rcond": r["rcond"],
                         "condition_estimate": _finite_or_none(1.0 / r["rcond"]) if r["rcond"] > 0 else None,
                         "digits_lost": r["digits_lost"],
                         "penalty_ratio": r["penalty_ratio"],
                         "penalised_stiffness_condition": _finite_or_none(1.0 / r["penalised_rcond"])
                         if r["penalised_rcond"] > 0 else None},
        "cost": {"active_set_iterations": r["active_set_iterations"],
                 "uzawa_iterations": r["uzawa_iterations"], "linear_solves": r["linear_solves"],
                 "wall_time_s": wall},
        "provenance": provenance(scene),
    }


# A scene with more contacts than this lists every phase only for the contacts named in
# output.contacts (docs/results.md "Contacts"): 1e5 pounding neighbours have millions.
PHASE_LISTS = 1000


def _finite_or_none(x):
    return float(x) if np.isfinite(x) else None


# --- what a run may cost and write ------------------------------------------------------------

# Without force (`martello run --force`), a run is refused when it needs more work than this,
# in node-steps (steps x nodes: a step costs about its nodes' worth; the integrators count
# steps in 32 bits up to 2.1e9, and a billion node-steps is minutes), or would write more
# than OUTPUT_LIMIT; above OUTPUT_WARN it is run with a warning (docs/behaviour.md,
# "Failures and limits").
MAX_WORK = 1e9
OUTPUT_WARN = 100e6
OUTPUT_LIMIT = 1e9
# Bytes per value of history.csv (%.17g and a comma; 23 on average) and, in summary.json, per
# node, contact (without its events), event and link: measured on the catalogue, rounded up;
# in results.npz per node, link and contact: their columns' bytes (martello.run.item_arrays).
_CSV_VALUE, _NODE, _CONTACT, _EVENT, _LINK, _BASE = 24, 200, 600, 200, 150, 6000
_NPZ_NODE, _NPZ_LINK, _NPZ_CONTACT = 64, 17, 122


def output_estimate(scene):
    """What a run of the scene will take and write, estimated before it starts: steps (a
    lower bound for the adaptive integrators: t_end/h_max, or t_end/dt), history rows and
    columns, and the sizes of history.csv and summary.json in bytes (one impact per contact
    assumed). Static runs take no steps and write a summary only."""
    an = scene.analysis
    n_nodes, n_contacts, n_links = len(scene.nodes), len(scene.contacts), len(scene.links)
    est = {"steps": 0.0, "rows": 0.0, "columns": 0,
           "summary_bytes": float(_BASE + _NODE * n_nodes + _LINK * n_links
                                  + (_CONTACT + _EVENT) * n_contacts)}
    if an["type"] == "dynamic":
        out = an["output"]
        if is_large(scene):
            # the named items in summary.json, every item in results.npz
            est["summary_bytes"] = float(
                _BASE + _NODE * len(out["nodes"]) + _LINK * len(out["links"])
                + (_CONTACT + _EVENT) * len(out["contacts"])
                + _NPZ_NODE * n_nodes + _NPZ_LINK * n_links + _NPZ_CONTACT * n_contacts)
        intervals = an["t_end"] / an["dt"]
        if an["integrator"] in native.adaptive_integrators():
            # dt is the output interval; h_max (when > 0) caps every step
            steps = an["t_end"] / an["h_max"] if an.get("h_max") else intervals
            rows = intervals / out["every"] + 2      # every every-th output time
        else:
            steps = float(np.ceil(intervals))
            rows = steps / out["every"] + 2
        est.update(steps=steps, rows=rows, columns=len(native.history_columns(
            out["nodes"], out["contacts"], out["links"])))
    est["history_bytes"] = est["rows"] * est["columns"] * _CSV_VALUE
    est["bytes"] = est["history_bytes"] + est["summary_bytes"]
    return est


def _size(b):
    # the last unit takes what the others leave (below 1 kB: bytes, no unit)
    return next(f"{b / d:.3g} {u}" for d, u in ((1e9, "GB"), (1e6, "MB"), (1e3, "kB"), (1, ""))
                if b >= d or d == 1).strip()


def _g(x):
    """3 digits, exponents without + and leading zeros: 7e11, 1e9, 2.5e5, 18."""
    return f"{x:.3g}".replace("e+0", "e").replace("e+", "e").replace("e-0", "e-")


# msbdf (GSL) builds a dense Jacobian of the 2n-dimensional state by finite differences and
# factorises it densely (docs/event-driven.md): past this many nodes a run says so and names
# cvode, the same variable-order BDF on the library's analytic band Jacobian (docs/sundials-ode.md).
DENSE_NOTE_NODES = 200


def dense_note(an, nodes):
    """The note a scene of `nodes` nodes gets when its analysis chose msbdf, or None."""
    if an.get("type") != "dynamic" or an.get("integrator") != "msbdf" or nodes <= DENSE_NOTE_NODES:
        return None
    return (f"msbdf forms and factorises a dense {2 * nodes} x {2 * nodes} Jacobian by finite "
            f"differences ({2 * nodes + 2} force evaluations and O(n^3) work each time, "
            f"{_size(8.0 * (2 * nodes) ** 2)} of memory): for {nodes} nodes use integrator = "
            '"cvode" (the same variable-order BDF, analytic band Jacobian, O(n))')


# While a rigid contact is held, CVODE, ARKODE and IDA find every tensile dip of its multiplier
# when the multiplier's second derivative is one harmonic between the stops: the loads' harmonic
# terms share one frequency (docs/sundials-ode.md "Held contacts"); with two, a dip shorter than a
# held step can be missed, and the run says so.
def _frequency(f):
    """The angular frequency of a load's time function dict, None for a non-harmonic one."""
    if f is None:
        return None
    if f.get("type") == "sine":
        return abs(float(f["omega"]))
    if f.get("type") == "half_sine":
        return np.pi / (float(f["t_end"]) - float(f.get("t_start", 0.0)))
    return None


def held_note(scene):
    """The warning a scene gets when its integrator's held-contact release is not guaranteed:
    cvode, arkode or ida, a rigid contact, loads with harmonic terms of two or more frequencies."""
    an = scene.analysis
    if an.get("type") != "dynamic" or an.get("integrator") not in ("cvode", "arkode", "ida"):
        return None
    funcs = [f["function"] for f in scene.forces] + [scene.ground]
    omegas = sorted({w for w in map(_frequency, funcs) if w})
    if len(omegas) < 2 or not any(c["scheme"] in ("restitution", "lagrange") for c in scene.contacts):
        return None
    return (f"the loads have harmonic terms of {len(omegas)} frequencies ({', '.join(_g(w) for w in omegas)} "
            f"rad/s): while a rigid contact is held, {an['integrator']} finds every release whose "
            "tension lasts longer than a held step (the shortest period / 16), but a shorter tensile "
            "dip of its force may be missed (docs/sundials-ode.md \"Held contacts\"); a smaller "
            "analysis.h_max shortens the held steps")


def state_scale(scene):
    """The size of a scene's state before it moves: the largest |u0|, |v0| of its nodes and
    |gap| of its contacts (m, m/s)."""
    scale = 0.0
    for seg in scene.nodes.segments:
        u0, v0 = ((np.array([n["u0"] for n in seg]), np.array([n["v0"] for n in seg]))
                  if isinstance(seg, list) else seg.arrays()[1:3])
        scale = max(scale, float(np.max(np.abs(u0), initial=0.0)), float(np.max(np.abs(v0), initial=0.0)))
    for seg in scene.contacts.segments:
        gap = np.array([c["gap"] for c in seg]) if isinstance(seg, list) else seg.block.gap
        scale = max(scale, float(np.max(np.abs(gap), initial=0.0)))
    return scale


# IDA's error weight of a component is rtol |y| + atol: where one crosses zero it is atol
# alone, and the arithmetic on a state of size S resolves no better than a few rounding units
# of it (the sum of a few terms of size S: 4 eps S), so an atol below that asks the error test
# for what the arithmetic cannot give (docs/ida.md "Failures")
ATOL_ROUNDING = 4.0 * np.finfo(float).eps


def atol_note(scene):
    """The warning a dynamic scene on IDA gets, before its run, when analysis.atol is below the
    rounding of its state's size as it starts (state_scale), or None. The state may grow past
    that size in the run: IDA's failure message then says the same afterwards."""
    an = scene.analysis
    if an.get("type") != "dynamic" or an.get("integrator") != "ida" or "atol" not in an:
        return None
    floor = ATOL_ROUNDING * state_scale(scene)
    if an["atol"] >= floor:
        return None
    return (f"analysis.atol = {an['atol']!r} is below the rounding of the state (4 eps x its size "
            f"{state_scale(scene):.3g} at the start = {floor:.2g}): where a component crosses zero "
            "IDA's error weight is atol alone, and its error test may fail at every step "
            f"(docs/ida.md \"Failures\"); set analysis.atol to at least {floor:.2g}")


def check_budget(scene, force=False):
    """Refuse (SceneError naming the field) a run that needs more than MAX_WORK node-steps or
    would write more than OUTPUT_LIMIT, unless force; return the warnings to print (output
    above OUTPUT_WARN, or above the limits when forced)."""
    est, an, warnings = output_estimate(scene), scene.analysis, []
    nodes = max(1, len(scene.nodes))
    if dense_note(an, nodes):
        warnings.append(dense_note(an, nodes))
    if atol_note(scene):
        warnings.append(atol_note(scene))
    if held_note(scene):
        warnings.append(held_note(scene))
    if est["steps"] * nodes > MAX_WORK:
        adaptive = an["type"] == "dynamic" and an["integrator"] in native.adaptive_integrators()
        key = "h_max" if adaptive and an.get("h_max") else "dt"
        what = f"at least {_g(est['steps'])} steps (t_end/{key} = {an['t_end']!r}/{an[key]!r})"
        if nodes > 1:
            what += f" of {nodes} nodes"
        if not force:
            raise SceneError(scene.source, f"analysis.{key}", f"needs {what}, more than the "
                             f"{_g(MAX_WORK)} node-steps a run may take",
                             f"raise {key} or shorten t_end; --force runs it anyway")
        warnings.append(f"the run needs {what}: it may take very long")
    if est["bytes"] > OUTPUT_WARN:
        what = (f"up to about {_size(est['bytes'])} (history.csv: {_g(est['rows'])} rows x "
                f"{est['columns']} columns, {_size(est['history_bytes'])}; summary.json: "
                f"{_size(est['summary_bytes'])})")
        if est["bytes"] > OUTPUT_LIMIT and not force:
            key = ("analysis.output.every" if est["history_bytes"] > est["summary_bytes"]
                   else "(size)")
            raise SceneError(scene.source, key, f"the run would write {what}, more than the "
                             f"{_size(OUTPUT_LIMIT)} written without --force",
                             "record less (output.every, output.nodes, output.contacts) "
                             "or pass --force")
        warnings.append(f"the run will write {what}")
    return warnings


def _first_nonfinite(obj, path=""):
    """The dotted path of the first number in a summary that is not finite, or None."""
    if isinstance(obj, (float, np.floating)):
        return None if np.isfinite(obj) else path
    if isinstance(obj, dict):
        items = obj.items()
    elif isinstance(obj, (list, tuple)):
        items = enumerate(obj)
    else:
        return None
    for k, v in items:
        bad = _first_nonfinite(v, f"{path}.{k}" if path else str(k))
        if bad is not None:
            return bad
    return None


def check_finite(summary, history=None):
    """ResultError unless every number of the summary and the history is finite. A history
    column of link states that is NaN throughout is a state the integrator does not report
    (the adaptive integrators; docs/behaviour.md), not a result."""
    try:     # the C encoder finds a NaN or inf at once; the walk below only says where it is
        json.dumps(summary, allow_nan=False, default=float)
        bad = None
    except ValueError:
        bad = _first_nonfinite(summary)
    if bad is not None:
        value = summary
        for part in bad.split("."):
            value = value[int(part)] if isinstance(value, list) else value[part]
        raise ResultError(f"the run's result {bad} is {value}: a result must be finite "
                          "(nothing written)")
    if history is not None:
        columns, data = history
        data = np.asarray(data, float)
        if data.size and not np.isfinite(data).all():
            for j, c in enumerate(columns):
                col = data[:, j]
                unreported = c.startswith(("link_force:", "elongation:")) and np.isnan(col).all()
                if not unreported and not np.isfinite(col).all():
                    i = int(np.flatnonzero(~np.isfinite(col))[0])
                    raise ResultError(f"the run's history column {c} is {col[i]} at row {i} "
                                      f"(t = {data[i, 0]!r}): a result must be finite "
                                      "(nothing written)")


RESULT_FILES = ("summary.json", "history.csv", ARRAYS_FILE)


def write_results(summary, outdir, history=None):
    """Write summary.json (and history.csv, and a large scene's results.npz) as the folder
    outdir, atomically: they are written to a temporary folder beside it, which is renamed
    into place, so outdir holds one complete run or none, never a part of one nor files of an
    earlier run. An existing outdir is replaced only if it is empty or an earlier run's (it
    holds a summary.json); every result must be finite (check_finite, and
    ItemArrays.check_finite). ResultError for anything that stops it; nothing is written
    then."""
    check_finite(summary, history)
    arrays = summary.get("arrays")
    if isinstance(arrays, ItemArrays):
        arrays.check_finite()
    text = json.dumps(summary, indent=2, allow_nan=False, default=float) + "\n"
    given = Path(outdir)
    with folder_replaced(outdir, "summary.json", ResultError) as tmp:
        try:
            if history is not None:
                write_history(tmp / "history.csv", *history)
            if isinstance(arrays, ItemArrays):
                arrays.write(tmp)
            (tmp / "summary.json").write_text(text)
        except OSError as exc:
            raise ResultError(f"{os.path.abspath(outdir)}: cannot write the results: "
                              f"{exc.strerror or exc}") from None
    return given / "summary.json"


def write_history(path, columns, data):
    """history.csv: a header, then one line per row, %.17g (docs/results.md), written by the
    library (native.write_csv: ~0.3 µs a number where Python's formatting took ~0.55)."""
    native.write_csv(path, columns, data)
