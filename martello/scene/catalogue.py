"""The benchmark catalogue: every scene file under benchmarks/ (one problem variant each)."""

from ..paths import BENCHMARKS as ROOT
from .loader import load


def scene_files(root=ROOT):
    """Scene files of the catalogue, sorted; benchmarks/perf holds timing scripts, not scenes."""
    return sorted(p for p in root.rglob("*.toml") if "perf" not in p.relative_to(root).parts
                  and "studies" not in p.relative_to(root).parts)


def scenes(root=ROOT):
    return [load(p) for p in scene_files(root)]
