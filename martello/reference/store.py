"""Stored reference data (reference/<name>/: reference.json and history.csv, listed in
reference/references.toml), keyed to scenes by the digest of their physics."""

from __future__ import annotations

import hashlib
import json
import math
import tomllib
from pathlib import Path

import numpy as np

from ..history import parse_csv
from ..paths import MiB, REFERENCE_ROOT, REPO, UnreadableFile, read_input
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


# what a reference's files may weigh to be read (a reference of 20 000 samples of a few
# columns is a few MB)
META_LIMIT, HISTORY_LIMIT = 64 * MiB, 1024 * MiB
REWRITE = ("reference data are written by martello reference or scripts/regenerate_reference: "
           "write them again")


def _bad(path, problem, line=None):
    return ReferenceError(f"{path}{f':{line}' if line else ''}: {problem} ({REWRITE})")


def _number(x):
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def _description(path):
    """reference.json as a dict whose fields the scoring reads are of their kinds; a
    ReferenceError naming the file and field otherwise."""
    try:
        meta = json.loads(read_input(path, META_LIMIT))
    except UnreadableFile as exc:
        raise _bad(path, str(exc)) from None
    except (ValueError, UnicodeDecodeError) as exc:
        raise _bad(path, f"not valid JSON ({' '.join(str(exc).split())})") from None
    if not isinstance(meta, dict):
        raise _bad(path, f"holds a {type(meta).__name__}, not a reference's description")
    if not (_number(meta.get("t_end")) and meta["t_end"] > 0):
        raise _bad(path, f"t_end: {meta.get('t_end')!r} is not a time > 0")
    if "event_horizon" in meta and not (_number(meta["event_horizon"]) or meta["event_horizon"] is None):
        raise _bad(path, f"event_horizon: {meta['event_horizon']!r} is not a time")
    for key in ("events", "peaks", "masses", "digits"):
        table = meta.get(key, {})
        if not isinstance(table, dict):
            raise _bad(path, f"{key}: must be a table")
        for name, v in table.items():
            if key in ("masses", "digits"):
                ok = _number(v)
            elif key == "peaks":
                ok = isinstance(v, dict) and all(_number(x) or x is None for x in v.values())
            else:
                ok = isinstance(v, dict) and all(
                    isinstance(x, list) and all(_number(y) or y is None for y in x) for x in v.values())
            if not ok:
                raise _bad(path, f"{key}.{name}: {str(v)[:60]} is not of the form martello "
                                 "writes (numbers" + (")" if key in ("masses", "digits") else
                                                      " by name)"))
    return meta


def load_reference(folder):
    """Reference data from reference/<name>/ (reference.json + history.csv). Files that are
    not what martello writes (cut short, edited, another kind of file, too large) are one
    ReferenceError naming the file, the line or field."""
    folder = Path(folder)
    meta_path, hist_path = folder / "reference.json", folder / "history.csv"
    if not meta_path.exists() or not hist_path.exists():
        raise ReferenceError(f"{folder}: no reference data (reference.json and history.csv); "
                             "build it with scripts/regenerate_reference")
    meta = _description(meta_path)
    try:
        raw = read_input(hist_path, HISTORY_LIMIT)
    except UnreadableFile as exc:
        raise _bad(hist_path, str(exc)) from None
    header, data = parse_csv(raw, lambda problem, fix, line: _bad(hist_path, problem, line))
    samples = {c: data[:, i] for i, c in enumerate(header)}
    times = samples.pop("t")
    horizon = meta.get("event_horizon")
    return Reference(name=f"reference/{folder.name}", kind="data", t_end=float(meta["t_end"]),
                     columns=tuple(samples), times=times, samples=samples,
                     events=meta.get("events", {}), peaks=meta.get("peaks", {}),
                     masses=meta.get("masses", {}), digits=meta.get("digits", {}),
                     event_horizon=float(meta["t_end"] if horizon is None else horizon),
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
