"""The independent engine (martello.independent, docs/independent-reference.md) as a reference
method: a scene's tables handed to it as written (it reads them with its own code: no
martello.scene, no front-end law or damping conversion), its solution sampled on the
reference's grid and shaped like a library run (martello.batch.execute), so that the
reference builder (build.py) refines and cross-checks it like any method."""

from __future__ import annotations

from pathlib import Path

from .. import independent
from ..independent import Unsupported

NAME = "independent"
DESCRIPTION = ("martello.independent: the scene's equations written again from its file and the "
               "published laws, every switch event-located on scipy's DOP853; no code shared with "
               "the library or the front end")


def engine_run(scene_dict: dict, base_dir, rtol: float, grid, t_end: float | None = None) -> dict:
    """One integration of the scene (its TOML tables) at rtol, sampled on grid: a dict shaped
    like martello.batch.execute's (status, summary with contacts and cost, history). Raises
    Unsupported (naming the part) for a scene the engine does not model."""
    doc = {k: v for k, v in scene_dict.items() if k != "check"}
    model = independent.load_model(doc, t_end=t_end, base=Path(base_dir) if base_dir else None)
    out = independent.run_once(model, rtol=rtol, grid=grid)
    contacts = {}
    for name, c in out["contacts"].items():
        ph = c["phases"]
        contacts[name] = {"impacts": c["impacts"],
                          "impact_times": [p["t_on"] for p in ph],
                          "separation_times": [p["t_off"] for p in ph],
                          "approach_speeds": [p["v_in"] for p in ph],
                          "restitution": [p["restitution"] for p in ph],
                          "phase_max_penetration": [p["max_penetration"] for p in ph],
                          "phase_max_force": [p["max_force"] for p in ph],
                          "max_penetration": c["max_penetration"], "max_force": c["max_force"]}
    prov = out["provenance"]
    summary = {"status": "MARTELLO_OK", "message": "", "contacts": contacts, "nodes": out["nodes"],
               "energy": out["energy"],
               "cost": {"steps": prov["steps"], "residual_evaluations": prov["rhs_evaluations"],
                        "events": prov["switches"], "wall_time_s": prov["wall_time_s"]},
               "provenance": {"engine": "martello.independent", **prov}}
    return {"status": "MARTELLO_OK", "message": "", "summary": summary, "history": out["history"]}


__all__ = ["NAME", "DESCRIPTION", "Unsupported", "engine_run"]
