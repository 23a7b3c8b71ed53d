"""Metamorphic relations (docs/invariance.md): a scene written down otherwise, whose summary
follows from the original's by a known map. No oracle is needed: the map is the physics of
the change.

* `mirrored`: the axis flipped (every displacement, velocity, force and acceleration of the
  scene negated) and every contact's and link's sides a and b swapped, so that each
  penetration δ = u_a − u_b − gap and each link elongation is the same number. Negation is
  exact in floating point: the map is node u ↦ −u (u_max ↔ −u_min), v, a ↦ −v, −a, and
  everything else unchanged, bit for bit.
* `rescaled`: the units of mass, length and time multiplied by M, L, T (powers of 2, so that
  every product scales without a new rounding). Each number of the summary scales by its
  dimension (UNITS); the comparison allows the rounding only. The adaptive integrators keep T
  = 1: their atol is one number for displacements and velocities, which scale alike only then.
* `renamed`: every node, link and contact renamed, and the lists reversed (nodes, links,
  contacts, loads): the summary keyed by the new names is the old one.
* `chains_as_lists`: every [[chain]] written out as its [[node]], [[link]] and [[contact]]
  entries (docs/scene-input.md, "Generators"): the same scene.

Each returns the transformed scene dict and a function mapping the original's `numbers` to the
expected ones, or raises Unsupported naming what it does not know how to transform."""

from __future__ import annotations

import copy
import math
from pathlib import Path

from benchmarks.invariance.relations import ADAPTIVE


class Unsupported(Exception):
    """The relation does not know how to transform something in this scene."""


# ---- mirrored ---------------------------------------------------------------------------------

_NEGATED_FUNCTION_KEYS = {"constant": ("value",), "sine": ("amplitude",),
                          "rectangular": ("amplitude",), "half_sine": ("amplitude",),
                          "table": ("scale",), "record": ("scale",)}


def _negate_function(fn):
    keys = _NEGATED_FUNCTION_KEYS.get(fn.get("type"))
    if keys is None:
        raise Unsupported(f"function type {fn.get('type')!r}")
    for k in keys:
        fn[k] = -float(fn.get(k, 1.0))


def mirrored(data):
    for key in ("chain", "bar", "frame", "building", "mass_coupling"):
        if key in data:
            raise Unsupported(f"[{key}] (its orientation is the generator's)")
    d = copy.deepcopy(data)
    for n in d.get("node", []):
        for k in ("u0", "v0"):
            if k in n:
                n[k] = -n[k]
    for item in d.get("link", []) + d.get("contact", []):
        if "terms" in item:                 # a row Σ coef·u: the same δ with every coef negated
            for term in item["terms"]:
                term["coef"] = -term["coef"]
        else:
            item["a"], item["b"] = item["b"], item["a"]
    loads = d.get("loads", {})
    if "gravity" in loads:
        loads["gravity"] = -loads["gravity"]
    for f in loads.get("force", []):
        if "value" in f:
            f["value"] = -f["value"]
        else:
            _negate_function(f["function"])
    if "ground_acceleration" in loads:
        _negate_function(loads["ground_acceleration"])

    def expect(nums):
        out = {}
        for p, x in nums.items():
            head, _, last = p.rpartition(".")
            if p.startswith("nodes.") and last in ("u_peak", "t_peak"):
                continue            # the largest local maximum: its mirror image, the deepest
                                    # minimum, is not reported (docs/results.md)
            if p.startswith("nodes.") and last in ("u_max", "u_min"):
                other = nums.get(head + (".u_min" if last == "u_max" else ".u_max"))
                out[p] = -other if other is not None else None
            elif p.startswith("nodes.") and last in ("u_final", "v_final"):
                out[p] = -x
            else:
                out[p] = x
        return out

    return d, expect


# ---- rescaled ---------------------------------------------------------------------------------

def _dims(M, L, T):
    force = M * L / T ** 2
    return {"M": M, "L": L, "T": T, "V": L / T, "A": L / T ** 2, "F": force,
            "E": force * L, "K": force / L, "C": force / (L / T), "W": 1.0 / T, "P": force * T}


# The dimension of each summary number, by the last part of its path (docs/results.md).
UNITS = {"u_max": "L", "u_min": "L", "u_absmax": "L", "u_final": "L", "v_absmax": "V",
         "v_final": "V", "a_absmax": "A", "t_absmax": "T", "max_penetration": "L",
         "penetration_final": "L", "force_final": "F", "lambda_final": "F", "impact_times": "T",
         "separation_times": "T", "approach_speeds": "V", "separation_speeds": "V",
         "restitution": None, "phase_max_penetration": "L", "contact_time": "T",
         "persistent_from": "T", "impacts": None, "max_abs_force": "F",
         "max_abs_elongation": "L", "omega_max": "W", "dt_critical": "T", "t_reached": "T",
         "balance_relative": None, "first_phase": None, "last_phase": None, "scheme": None,
         "law": None, "type": None, "#": None, "u_peak": "L", "t_peak": "T", "max_force": "F",
         "phase_max_force": "F"}


def rescaled(data, M=4.0, L=0.5, T=2.0):
    """The scene in units where mass, length and time numbers are M, L, T times larger."""
    for key in ("chain", "bar", "frame", "building", "mass_coupling"):
        if key in data:
            raise Unsupported(f"[{key}]")
    d = copy.deepcopy(data)
    an = d["analysis"]
    if an["integrator"] in ADAPTIVE:
        T = 1.0
    u = _dims(M, L, T)
    event_driven = an["integrator"] in ADAPTIVE
    for n in d.get("node", []):
        n["mass"] *= M
        for k, dim in (("u0", "L"), ("v0", "V")):
            if k in n:
                n[k] *= u[dim]
    for lk in d.get("link", []):
        t = lk["type"]
        if t == "spring":
            lk["k"] *= u["K"]
        elif t == "dashpot":
            if "c" in lk:
                lk["c"] *= u["C"]
        elif t == "bilinear":
            lk["k"] *= u["K"]
            lk["fy"] *= u["F"]
        else:
            raise Unsupported(f"link type {t!r}")
    for c in d.get("contact", []):
        c["gap"] = c.get("gap", 0.0) * L
        if c["scheme"] == "penalty":
            law = c.get("law", "linear")
            if law not in ("linear", "hertz") or "damping" in c:
                raise Unsupported(f"penalty law {law!r}" + (" with damping" if "damping" in c else ""))
            c["stiffness"] *= u["F"] / L ** (1.0 if law == "linear" else 1.5)
        elif c["scheme"] == "augmented-lagrange":
            c["stiffness"] *= u["K"]
    loads = d.get("loads", {})
    if "gravity" in loads:
        loads["gravity"] *= u["A"]
    for f in loads.get("force", []):
        if "value" in f:
            f["value"] *= u["F"]
        else:
            _scale_function(f["function"], u["F"], T)
    if "ground_acceleration" in loads:
        _scale_function(loads["ground_acceleration"], u["A"], T)
    for k, dim in (("dt", "T"), ("t_end", "T"), ("event_tol", "T"), ("h_max", "T")):
        if k in an:
            an[k] *= u[dim]
    if "atol" in an:
        an["atol"] *= L
    elif an["integrator"] in ADAPTIVE:
        from martello.binding import native
        an["atol"] = native.settings_defaults()["atol"] * L
    if an["integrator"] in ADAPTIVE and "event_tol" not in an:
        pass                                   # T = 1: event_tol is unchanged

    def expect(nums):
        out = {}
        for p, x in nums.items():
            parts = p.split(".")
            name = next((q for q in reversed(parts) if not q.isdigit()), parts[-1])
            if name not in UNITS and not p.startswith("energy."):
                raise Unsupported(f"the dimension of {p}")
            dim = "E" if p.startswith("energy.") and name != "balance_relative" else UNITS.get(name)
            if name == "phase_max_force" and event_driven:
                # an instantaneous phase (an impact, t_on = t_off) of the event-driven
                # integrators lists its impulse (Moreau–Jean its mean force p/h: a force)
                head, _, i = p.rpartition(".")
                base = head.rpartition(".")[0]
                on, off = nums.get(f"{base}.impact_times.{i}"), nums.get(f"{base}.separation_times.{i}")
                dim = "P" if on is not None and on == off else "F"
            if isinstance(x, float) and dim is not None:
                out[p] = x * u[dim]
            else:
                out[p] = x
        return out

    return d, expect


def _scale_function(fn, value_scale, T):
    t = fn.get("type")
    if t == "constant":
        fn["value"] *= value_scale
    elif t in ("sine", "rectangular", "half_sine"):
        fn["amplitude"] *= value_scale
        if "omega" in fn:
            fn["omega"] /= T
        for k in ("t_start", "t_end"):
            if k in fn:
                fn[k] *= T
    elif t == "table":
        fn["scale"] = fn.get("scale", 1.0) * value_scale
        fn["t"] = [x * T for x in fn["t"]]
    elif t == "record" and T == 1.0:
        fn["scale"] = fn.get("scale", 1.0) * value_scale
    else:
        raise Unsupported(f"function type {t!r} with T = {T}")


# ---- renamed and reordered ----------------------------------------------------------------------

def renamed(data, prefix="r_"):
    for key in ("chain", "bar", "frame", "building", "mass_coupling"):
        if key in data:
            raise Unsupported(f"[{key}] (its items are named by the generator)")
    d = copy.deepcopy(data)
    nodes = {n["name"]: prefix + n["name"] for n in d.get("node", [])}

    def ref(x):
        return nodes.get(x, x)                   # "ground" stays

    names = {}
    for kind in ("link", "contact"):
        for i, item in enumerate(d.get(kind, [])):
            if "terms" in item:
                for term in item["terms"]:
                    term["node"] = ref(term["node"])
            else:
                item["a"], item["b"] = ref(item["a"]), ref(item["b"])
            old = item.get("name", f"link{i}" if kind == "link" else None)
            if old is not None:
                item["name"] = prefix + old
                names[old] = item["name"]
    for n in d.get("node", []):
        n["name"] = nodes[n["name"]]
    for f in d.get("loads", {}).get("force", []):
        f["node"] = ref(f["node"])
    out = d.get("analysis", {}).get("output", {})
    for k, table in (("nodes", nodes), ("contacts", names), ("links", names)):
        if k in out:
            out[k] = [table.get(x, x) for x in out[k]]
    for k in ("node", "link", "contact"):
        if k in d:
            d[k] = d[k][::-1]
    if "force" in d.get("loads", {}):
        d["loads"]["force"] = d["loads"]["force"][::-1]
    every = {**nodes, **names}

    def expect(nums):
        out = {}
        for p, x in nums.items():
            parts = p.split(".")
            if parts[0] in ("nodes", "contacts", "links") and len(parts) > 1:
                parts[1] = every.get(parts[1], parts[1])
            out[".".join(parts)] = x
        return out

    return d, expect


# ---- chains as lists -------------------------------------------------------------------------

def _per_item(value, count):
    return list(value) if isinstance(value, list) else [value] * count


def chains_as_lists(data):
    """Every [[chain]] written out as the [[node]], [[link]] and [[contact]] entries the
    documentation says it makes (docs/scene-input.md, "[[chain]]"; written here from the
    documented layout, not by the loader's expansion), after the scene's own entries, in the
    order chain by chain, oscillator by oscillator. A Newmark run on [[chain]] takes the fused
    chain step, on lists the general path: the relation also compares the two paths."""
    if "chain" not in data:
        raise Unsupported("no [[chain]]")
    if "bar" in data or "frame" in data:
        raise Unsupported("[[chain]] with later generators (their items follow the chain's)")
    d = copy.deepcopy(data)
    nodes, links, contacts = d.setdefault("node", []), d.setdefault("link", []), []
    for ch in d.pop("chain"):
        p, n = ch["prefix"], ch["n"]
        mass, k = _per_item(ch["mass"], n), _per_item(ch["k"], n)
        u0, v0 = _per_item(ch.get("u0", 0.0), n), _per_item(ch.get("v0", 0.0), n)
        fy = _per_item(ch["fy"], n) if "fy" in ch else None
        hard = _per_item(ch.get("hardening", 0.0), n)
        zeta = _per_item(ch["zeta"], n) if "zeta" in ch else [0.0] * n
        gap = _per_item(ch.get("gap", 0.0), n - 1)
        for i in range(n):
            nodes.append({"name": f"{p}{i + 1}", "mass": mass[i], "u0": u0[i], "v0": v0[i]})
            spring = {"name": f"{p}{i + 1}.spring", "a": f"{p}{i + 1}", "b": "ground"}
            if fy is None:
                spring.update(type="spring", k=k[i])
            else:
                spring.update(type="bilinear", k=k[i], fy=fy[i], hardening=hard[i])
            links.append(spring)
            if zeta[i] > 0:
                links.append({"name": f"{p}{i + 1}.damper", "type": "dashpot", "a": f"{p}{i + 1}",
                              "b": "ground", "zeta": zeta[i]})
        if "contact" in ch:
            for i in range(n - 1):
                contacts.append({**ch["contact"], "name": f"{p}{i + 1}-{p}{i + 2}",
                                 "a": f"{p}{i + 1}", "b": f"{p}{i + 2}", "gap": gap[i]})
    d.setdefault("contact", []).extend(contacts)
    return d, (lambda nums: dict(nums))


RELATIONS = {"mirrored": mirrored, "rescaled": rescaled, "renamed": renamed,
             "chains_as_lists": chains_as_lists}


# Mirroring is exact in floating point where every operation is odd in the state. SUNDIALS'
# difference-quotient Jacobian steps each component by +inc where its y' is 0 (not by the
# sign of y), so IDA's Newton iterates differ at its own tolerance: there the relation holds
# to it (P5 on IDA: 6e-11 relative on the displacements, rtol 1e-10).
MIRROR_TO_TOLERANCE = ("ida", "cvode", "arkode")


def check(path_or_data, relation, base_dir=None, tied=None):
    """Run a scene and its transform by relation; returns the mismatches [(path, expected,
    got, allowed)] (relations.mismatches). `mirrored` is bit for bit: negation is exact
    (MIRROR_TO_TOLERANCE aside). The others change the order or the scale of the
    arithmetic, so a result comes back to its rounding, or to the tolerance its method solves
    to, measured as in the output invariance: what a 3 and 10 times looser tolerance (an
    adaptive run's rtol, atol and event_tol; a Newton method's tol_residual and
    tol_increment) moves it, and 100 times that relative tolerance; and the run's own
    rounding, what scaling every mass by 1 + 4 eps moves it (relations.rounding_scene; the
    Newmark family also within the ceiling relations.newmark_rounding).
    The time of an extreme attained more than once within that allowance is not compared
    (relations.tied_times' rule, docs/invariance.md, ties); such mismatches go to the list
    `tied` when one is given. Raises Unsupported."""
    from benchmarks.invariance import relations as R
    if isinstance(path_or_data, (str, Path)):
        data, base_dir = R.read(path_or_data)
    else:
        data = path_or_data
    base_dir = base_dir or "."
    data = R.base_scene(data)
    other, expect = RELATIONS[relation](data)
    got = R.numbers(R.run(other, base_dir)[0])
    base = R.numbers(R.run(data, base_dir)[0])
    if relation == "mirrored" and data["analysis"]["integrator"] not in MIRROR_TO_TOLERANCE:
        return R.mismatches(expect(base), got, exact=True)
    error, rtol = R.tolerance_error(data, base, base_dir, mapped=lambda e: _errors(e, expect),
                                    rounding=True)
    expected = expect(base)
    bad = R.mismatches(expected, got, error, rtol, exact=False)
    return _untied(bad, (data, other), base, expected, expect, base_dir, error, rtol,
                   [] if tied is None else tied)


def _untied(bad, scenes, base, expected, expect, base_dir, error, rtol, tied):
    """bad without the times of extremes attained more than once (relations.tied_times, in the
    transformed scene's terms): the scene reporting the later time, run again to the midpoint
    of the two, already reaches the value within the allowance. The base scene's run is mapped
    by expect; its time by the relation's scale of that time (expected / base)."""
    from benchmarks.invariance import relations as R
    moved = {p for p, *_ in bad}
    kept = []
    for entry in bad:
        p, t_exp, t_got = entry[:3]
        value = R._extreme_of(p, expected)
        if value is None or value in moved or not all(isinstance(x, float) and x > 0
                                                      for x in (t_exp, t_got, base.get(p))):
            kept.append(entry)
            continue
        later_is_other = t_got > t_exp
        early = copy.deepcopy(scenes[1] if later_is_other else scenes[0])
        t_mid = 0.5 * (t_exp + t_got) / (1.0 if later_is_other else t_exp / base[p])
        early["analysis"]["t_end"] = t_mid
        early["analysis"]["dt"] = min(float(early["analysis"]["dt"]), t_mid)
        reached = R.numbers(R.run(early, base_dir)[0])
        reached = (reached if later_is_other else expect(reached)).get(value)
        if isinstance(reached, float) and \
                not R.mismatches(expected, {**expected, value: reached}, error, rtol):
            tied.append(entry)
        else:
            kept.append(entry)
    return kept


def _errors(error, expect):
    """Errors mapped like the numbers, as magnitudes (a mirrored u_max takes u_min's)."""
    return {p: abs(x) if isinstance(x, float) else x for p, x in expect(error).items()
            if x is not None}
