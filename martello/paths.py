"""The folders of the checkout that the package reads: the repository root, the benchmark
catalogue (benchmarks/) and the stored reference data (reference/)."""

from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
BENCHMARKS = REPO / "benchmarks"
REFERENCE_ROOT = REPO / "reference"
