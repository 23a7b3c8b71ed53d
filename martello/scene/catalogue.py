"""The benchmark catalogue: every scene file under benchmarks/ (one problem variant each)."""

from pathlib import Path

from ..paths import BENCHMARKS as ROOT
from .loader import load


# Folders under benchmarks/ that hold no catalogue scene: timing scripts (perf), study files
# (studies), and the inputs of a case-study script (case_study: scenes without a closed form or
# a reference of their own, run and reported by benchmarks/<problem>/case_study.py).
NOT_CATALOGUE = ("perf", "studies", "case_study")


def scene_files(root=ROOT):
    """Scene files of the catalogue, sorted (not those of the NOT_CATALOGUE folders)."""
    return sorted(p for p in root.rglob("*.toml")
                  if not set(NOT_CATALOGUE) & set(p.relative_to(root).parts))


def find(path, root=ROOT):
    """A scene path as given, or, if no such file exists where you are, the catalogue's file
    of that name: "p2/p2_restitution_e08.toml" or "benchmarks/p2/p2_restitution_e08.toml"
    (what `martello list` prints) work from any folder, with the catalogue of the checkout
    or of the installed package. Unchanged if neither exists (the loader then says so)."""
    p = Path(path)
    if p.exists() or p.is_absolute():
        return p
    return next((base / p for base in (root, root.parent) if (base / p).is_file()), p)


def scenes(root=ROOT):
    return [load(p) for p in scene_files(root)]
