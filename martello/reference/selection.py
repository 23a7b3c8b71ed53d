"""The reference a scene is scored against: named by a study, or found for it (stored data
for its physics, else the closed-form history its [check] implies)."""

from __future__ import annotations

from pathlib import Path

from .base import ReferenceError
from .closed_form import closed_form_reference, from_check
from ..paths import REFERENCE_ROOT, REPO
from .store import find_reference_data, load_reference


def reference_for_scene(scene, root=REFERENCE_ROOT, spec=None):
    """The reference a scene is scored against.

    spec (a study's `reference` entry) may be None or "auto", {closed_form = NAME, params =
    {...}} or {data = "reference/<name>"}. "auto" takes stored reference data for the
    scene's physics if any, else the closed-form history its [check] implies, else None."""
    t_end = scene.analysis.get("t_end")
    if isinstance(spec, dict) and "closed_form" in spec:
        return closed_form_reference(spec["closed_form"], spec.get("params", {}), t_end, scene)
    if isinstance(spec, dict) and "data" in spec:
        p = Path(spec["data"])
        return load_reference(p if p.is_absolute() else REPO / p)
    if spec not in (None, "auto"):
        raise ReferenceError(f"reference {spec!r}: give \"auto\", {{ closed_form = ..., params = ... }} "
                             "or { data = \"reference/<name>\" }")
    ref = find_reference_data(scene, root)
    return ref if ref is not None else from_check(scene)
