"""Stored reference data (reference/<name>/: reference.json and history.csv, listed in
reference/references.toml), keyed to scenes by the digest of their physics."""

from __future__ import annotations

import hashlib
import json
import tomllib
from pathlib import Path

import numpy as np

from ..paths import REFERENCE_ROOT, REPO
from ..scene.items import ItemTable
from .base import Reference, ReferenceError

MANIFEST = "references.toml"


def physics_digest(scene):
    """sha256 of what determines a scene's solution: nodes, links, contacts, loads (not the
    analysis settings, the title or the check table). Reference data are keyed by it, so a
    study that changes only the integrator still finds them, and one that overrides a
    contact does not."""
    ground = dict(scene.ground) if scene.ground else None
    if ground and ground.get("type") == "record":
        ground["file"] = Path(ground["file"]).name
    data = {"nodes": scene.nodes, "links": scene.links, "contacts": scene.contacts,
            "gravity": scene.gravity, "forces": scene.forces, "ground": ground,
            "couplings": scene.couplings,
            # a frame's block is determined by its matrices (empty for scenes without one)
            "blocks": [{"nodes": b["nodes"], "k": np.asarray(b["k"]).tolist(),
                        "c": np.asarray(b["c"]).tolist()} for b in scene.blocks] or None}
    return hashlib.sha256(json.dumps(_canonical(data), sort_keys=True, default=repr).encode()).hexdigest()


def _canonical(x):
    """Unset (None) and false values dropped, so that a loader that learns a new optional
    key (with an unset or false default) does not change the digest of existing scenes."""
    if isinstance(x, dict):
        return {k: _canonical(v) for k, v in x.items() if v is not None and v is not False}
    if isinstance(x, (list, tuple, ItemTable)):        # a scene's item table: its dicts
        return [_canonical(v) for v in x]
    return x


def manifest(root=REFERENCE_ROOT):
    """The entries of reference/references.toml (what the reference data are and how they
    are regenerated), each with its folder."""
    path = Path(root) / MANIFEST
    if not path.exists():
        return []
    with open(path, "rb") as fh:
        data = tomllib.load(fh)
    out = []
    for e in data.get("reference", []):
        e = dict(e)
        e["folder"] = Path(root) / e["name"]
        out.append(e)
    return out


def load_reference(folder):
    """Reference data from reference/<name>/ (reference.json + history.csv)."""
    folder = Path(folder)
    meta_path, hist_path = folder / "reference.json", folder / "history.csv"
    if not meta_path.exists() or not hist_path.exists():
        raise ReferenceError(f"{folder}: no reference data (reference.json and history.csv); "
                             "build it with scripts/regenerate_reference")
    meta = json.loads(meta_path.read_text())
    with open(hist_path) as fh:
        header = fh.readline().strip().split(",")
    data = np.loadtxt(hist_path, delimiter=",", skiprows=1, ndmin=2)
    samples = {c: data[:, i] for i, c in enumerate(header)}
    times = samples.pop("t")
    return Reference(name=f"reference/{folder.name}", kind="data", t_end=float(meta["t_end"]),
                     columns=tuple(samples), times=times, samples=samples,
                     events=meta.get("events", {}), peaks=meta.get("peaks", {}),
                     masses=meta.get("masses", {}), digits=meta.get("digits", {}),
                     event_horizon=float(meta.get("event_horizon", meta["t_end"])),
                     provenance=meta)


def find_reference_data(scene, root=REFERENCE_ROOT):
    """The stored reference whose physics digest matches the scene, else None. A reference
    stored for the same scene file whose digest no longer matches is stale: an error."""
    digest = physics_digest(scene)
    stale = None
    for e in manifest(root):
        meta_path = e["folder"] / "reference.json"
        if not meta_path.exists():
            continue
        meta = json.loads(meta_path.read_text())
        if meta.get("physics_sha256") == digest:
            if scene.analysis.get("t_end", 0.0) > float(meta["t_end"]) * (1 + 1e-12):
                raise ReferenceError(f"{e['folder']}: the reference ends at t = {meta['t_end']} s, "
                                     f"the scene runs to {scene.analysis['t_end']} s")
            return load_reference(e["folder"])
        # stale: the scene *is* the entry's file (loaded as is), and the file has changed
        src = (REPO / e["scene"]).resolve()
        if not e.get("contact") and src.exists() and scene.source and \
                Path(scene.source).resolve() == src and meta.get("scene_sha256") != scene.digest \
                and scene.digest == hashlib.sha256(src.read_bytes()).hexdigest():
            stale = e["folder"]
    if stale is not None:
        raise ReferenceError(f"{stale}: reference data were computed for another version of "
                             f"{scene.source} (the physics digest differs): run "
                             "scripts/regenerate_reference")
    return None
