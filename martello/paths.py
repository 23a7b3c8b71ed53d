"""The folders the package reads: the catalogue (benchmarks/), the stored reference data
(reference/) and the native library.

Two layouts (docs/install.md):

* a checkout of the repository (also an editable install of it): the repository's
  benchmarks/ and reference/, and the CMake build tree's build/libmartello.so;
* an installed wheel: the same folders as package data, martello/data/benchmarks and
  martello/data/reference, and the library in martello/_native/lib/.

``REPO`` is the folder that holds benchmarks/ and reference/ in either layout: paths in the
catalogue and in reference/references.toml (``benchmarks/p2/...``) are relative to it."""

from pathlib import Path

PACKAGE = Path(__file__).resolve().parent
_DATA = PACKAGE / "data"
INSTALLED = (_DATA / "benchmarks").is_dir()
REPO = _DATA if INSTALLED else PACKAGE.parent
BENCHMARKS = REPO / "benchmarks"
REFERENCE_ROOT = REPO / "reference"
# A study's `output` folder is relative to the repository in a checkout, to the working
# directory when installed (never inside site-packages).
OUTPUT_ROOT = Path(".") if INSTALLED else REPO
# The native library, the first that exists: the wheel's, then the checkout's build tree.
LIBRARIES = (PACKAGE / "_native" / "lib" / "libmartello.so",
             PACKAGE.parent / "build" / "libmartello.so")
