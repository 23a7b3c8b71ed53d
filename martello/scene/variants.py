"""Variants of a scene dict (the parsed TOML, before validation): the same physics with
another analysis, or other contacts. Studies sweep them; reference data are built on them."""

import copy

from ..errors import StudyError
from .compatibility import COMPATIBLE
from .loader import from_dict
from .spec import ALL_SPECIFIC, INTEGRATORS


def override_contacts(data, override, src, where):
    """Apply a contact override to every [[contact]] and every [[chain]].contact of a scene
    dict. A new scheme replaces the contact's scheme-specific keys; otherwise keys update."""
    data = copy.deepcopy(data)
    if not override:
        return data
    keep = ("name", "a", "b", "gap")

    def apply(c):
        if "scheme" in override and override["scheme"] != c.get("scheme"):
            c = {k: v for k, v in c.items() if k in keep}
        elif "law" in override and override["law"] != c.get("law"):
            c = {k: v for k, v in c.items() if k in keep + ("scheme", "stiffness")}
        c.update(override)
        return c
    found = False
    if "contact" in data:
        data["contact"] = [apply(c) for c in data["contact"]]
        found = found or bool(data["contact"])
    for ch in data.get("chain", []):
        if ch.get("contact") is not None:
            ch["contact"] = apply(ch["contact"])
            found = True
    if not found:
        raise StudyError(src, where, "the scene has no contact to override")
    return data


def analysis_for(base, integrator, params, dt, t_end, every=1, rtol=None):
    """The scene's [analysis] table with the integrator replaced: its family and tolerance
    keys are dropped, the study's ones set."""
    an = {k: v for k, v in base.items() if k not in ALL_SPECIFIC and k != "integrator"}
    an.update(type="dynamic", integrator=integrator, dt=float(dt), t_end=float(t_end))
    an.update(params)
    if rtol is not None:
        an["rtol"] = float(rtol)
    out = dict(base.get("output", {}))
    out["every"] = int(max(1, every))
    an["output"] = out
    return an


def runnable_scene(scene_dict, scene_file, t_end):
    """The scene of scene_dict (read from the Path scene_file) to t_end, validated with an
    integrator its contacts run on: its own if it can, else the first compatible one (a
    reference depends on the physics and t_end only, not on the analysis)."""
    d = copy.deepcopy(scene_dict)
    base = d.get("analysis", {})
    schemes = set()
    for c in d.get("contact", []):
        schemes.add(c.get("scheme"))
    for ch in d.get("chain", []):
        if ch.get("contact"):
            schemes.add(ch["contact"].get("scheme"))
    ok = [i for i in INTEGRATORS if all(i in COMPATIBLE.get(s, ()) for s in schemes)]
    integ = base.get("integrator") if base.get("integrator") in ok else (ok[0] if ok else "newmark")
    keep = {k: base[k] for k in ("preset", "beta", "gamma", "alpha", "rho_inf") if k in base} \
        if integ == base.get("integrator") else {}
    d["analysis"] = analysis_for(base, integ, keep, base.get("dt", t_end / 1000), t_end)
    return from_dict(d, source=str(scene_file), base_dir=scene_file.parent)
