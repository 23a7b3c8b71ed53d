"""An independent reference engine (docs/independent-reference.md): its own reading of the
scene (tomllib), its own effective masses and force laws, every switch event-located on
scipy's DOP853 or Radau, and trusted digits measured against a second integration.

A leaf of the package: numpy and scipy only, no martello.scene, martello.binding or native
library, so that it checks the library instead of repeating it.

    >>> from martello import independent
    >>> ref = independent.solve("benchmarks/p5/p5_kelvin.toml")
    >>> ref.contacts["impact"]["phases"][0]["restitution"]      # doctest: +SKIP
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, field

import numpy as np

from .engine import integrate
from .result import summarise
from .scene import Model, Unsupported, load_model

DIGITS_CAP = 15.0


@dataclass
class Reference:
    """One scene solved twice; the first solution's values, the digits the second confirms."""
    title: str
    nodes: dict
    links: dict
    contacts: dict
    energy: dict
    events: list
    history: tuple
    digits: dict = field(default_factory=dict)
    ambiguous: list = field(default_factory=list)
    provenance: dict = field(default_factory=dict)

    @property
    def trusted_digits(self) -> float:
        """The fewest digits of any compared quantity."""
        vals = [v for v in _leaves(self.digits) if v is not None]
        return min(vals) if vals else DIGITS_CAP

    def to_json(self) -> dict:
        """The report as strict JSON (non-finite numbers become null)."""
        return _finite({"title": self.title, "nodes": self.nodes, "links": self.links,
                        "contacts": self.contacts, "energy": self.energy, "events": self.events,
                        "digits": self.digits, "trusted_digits": self.trusted_digits,
                        "ambiguous": self.ambiguous, "provenance": self.provenance})


def _leaves(d):
    if isinstance(d, dict):
        for v in d.values():
            yield from _leaves(v)
    elif isinstance(d, list):
        for v in d:
            yield from _leaves(v)
    else:
        yield d


def _finite(x):
    if isinstance(x, dict):
        return {k: _finite(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_finite(v) for v in x]
    if isinstance(x, (float, np.floating)):
        return float(x) if math.isfinite(x) else None
    if isinstance(x, np.integer):
        return int(x)
    return x


def dumps(obj) -> str:
    """Strict JSON: refuses NaN and infinities instead of writing them."""
    return json.dumps(_finite(obj), indent=1, allow_nan=False)


def run_once(scene, method="DOP853", rtol=1e-11, t_end=None, contact=None, grid=None) -> dict:
    """One integration of a scene (path, TOML text, dict or Model): the summary dict."""
    m = scene if isinstance(scene, Model) else load_model(scene, t_end=t_end, contact=contact)
    run = integrate(m, method=method, rtol=rtol)
    out = summarise(run, grid)
    out["provenance"] = {"method": method, "rtol": rtol, "steps": run.steps, "rhs_evaluations": run.rhs_evals,
                         "pieces": len(run.pieces), "switches": len(run.events), "wall_time_s": run.wall}
    out["title"] = m.title
    return out


def _digits(a, b, scale):
    if a is None or b is None:
        return None
    err = abs(a - b)
    if err == 0.0:
        return DIGITS_CAP
    return float(min(DIGITS_CAP, max(0.0, -math.log10(err / max(scale, 1e-300)))))


def compare(a: dict, b: dict) -> tuple[dict, list]:
    """Digits of agreement of two solutions of one scene, per quantity, each relative to the
    scale of its kind (displacements to the largest displacement, a force to the element's
    largest force, times to the time itself); contacts whose phases differ in number, or
    whose smallest phase is within the displacement uncertainty, are ambiguous (grazing)."""
    dig = {"nodes": {}, "links": {}, "contacts": {}, "energy": {}}
    uscale = max([r["u_absmax"] for r in a["nodes"].values()] + [1e-300])
    vscale = max([r["v_absmax"] for r in a["nodes"].values()] + [1e-300])
    for nm, ra in a["nodes"].items():
        rb = b["nodes"][nm]
        dig["nodes"][nm] = {"u_max": _digits(ra["u_max"], rb["u_max"], uscale),
                            "u_min": _digits(ra["u_min"], rb["u_min"], uscale),
                            "u_final": _digits(ra["u_final"], rb["u_final"], uscale),
                            "v_final": _digits(ra["v_final"], rb["v_final"], vscale)}
    for nm, ra in a["links"].items():
        rb = b["links"][nm]
        dig["links"][nm] = {"max_abs_force": _digits(ra["max_abs_force"], rb["max_abs_force"], ra["max_abs_force"])}
    u_err = max([10 ** -d * uscale for r in dig["nodes"].values() for d in r.values() if d is not None] + [0.0])
    ambiguous = []
    for nm, ca in a["contacts"].items():
        cb = b["contacts"][nm]
        if ca["impacts"] != cb["impacts"]:
            ambiguous.append(nm)
            dig["contacts"][nm] = {"impacts": 0.0}
            continue
        if any(0.0 < p["max_penetration"] <= 100.0 * u_err for p in ca["phases"]):
            ambiguous.append(nm)          # a penalty phase within the uncertainty: a graze
        rows = []
        for pa, pb in zip(ca["phases"], cb["phases"]):
            rows.append({"t_on": _digits(pa["t_on"], pb["t_on"], abs(pa["t_on"]) or 1.0),
                         "t_off": _digits(pa["t_off"], pb["t_off"], abs(pa["t_off"] or 1.0)),
                         "restitution": _digits(pa["restitution"], pb["restitution"], 1.0),
                         "max_penetration": _digits(pa["max_penetration"], pb["max_penetration"],
                                                    ca["max_penetration"] or 1e-300),
                         "max_force": _digits(pa["max_force"], pb["max_force"], ca["max_force"] or 1e-300)})
        dig["contacts"][nm] = {"impacts": DIGITS_CAP, "phases": rows}
    escale = max(abs(a["energy"]["initial"]), abs(a["energy"]["input"]), a["energy"]["kinetic"], 1e-300)
    for k in ("kinetic", "recoverable", "input", "damping", "plastic", "contact", "impact"):
        dig["energy"][k] = _digits(a["energy"][k], b["energy"][k], escale)
    return dig, ambiguous


def solve(scene, rtol: float = 1e-11, method: str = "DOP853", second: str = "tolerance",
          t_end: float | None = None, contact: dict | None = None, grid=None) -> Reference:
    """Solve a scene (a path to its TOML file, TOML text or the parsed dict) and measure its
    trusted digits against a second integration: `second = "tolerance"` repeats `method` at
    100 × rtol, `second = "radau"` integrates with scipy's Radau IIA (order 5) at 100 × rtol,
    an implicit method with nothing in common with DOP853 but the event logic.
    `contact` overrides every contact's scheme keys, `t_end` the end time."""
    m = scene if isinstance(scene, Model) else load_model(scene, t_end=t_end, contact=contact)
    a = run_once(m, method=method, rtol=rtol, grid=grid)
    second_method = "Radau" if second == "radau" else method
    b = run_once(m, method=second_method, rtol=rtol * 100.0, grid=grid)
    digits, ambiguous = compare(a, b)
    prov = {"engine": "martello.independent", "primary": a["provenance"], "second": b["provenance"],
            "scipy_version": __import__("scipy").__version__, "numpy_version": np.__version__}
    return Reference(title=a["title"], nodes=a["nodes"], links=a["links"], contacts=a["contacts"],
                     energy=a["energy"], events=a["events"], history=a["history"], digits=digits,
                     ambiguous=ambiguous, provenance=prov)


__all__ = ["solve", "run_once", "compare", "Reference", "Unsupported", "load_model", "dumps"]
