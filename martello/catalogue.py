"""The benchmark catalogue: every scene file under benchmarks/ (one problem variant each)."""

from pathlib import Path

from . import scene as scene_mod

ROOT = Path(__file__).resolve().parent.parent / "benchmarks"


def scene_files(root=ROOT):
    """Scene files of the catalogue, sorted; benchmarks/perf holds timing scripts, not scenes."""
    return sorted(p for p in root.rglob("*.toml") if "perf" not in p.relative_to(root).parts
                  and "studies" not in p.relative_to(root).parts)


def scenes(root=ROOT):
    return [scene_mod.load(p) for p in scene_files(root)]
