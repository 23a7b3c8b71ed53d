"""One version number (CHANGELOG.md, "Versions and tags"): written in CMakeLists.txt, read by
the library, the package metadata and martello.__version__, and described in CHANGELOG.md."""

import re
from importlib.metadata import version
from pathlib import Path

import martello
from martello.binding import native

ROOT = Path(__file__).resolve().parent.parent


def cmake_version():
    text = (ROOT / "CMakeLists.txt").read_text()
    return re.search(r"project\(martello VERSION (\d+\.\d+\.\d+)", text).group(1)


def test_one_version_everywhere():
    v = cmake_version()
    assert native.version() == v                 # the library (martello_version())
    assert version("martello") == v              # the package metadata (pyproject.toml)
    assert martello.__version__ == v


def test_the_changelog_has_a_section_for_this_version():
    text = (ROOT / "CHANGELOG.md").read_text()
    sections = re.findall(r"^## (\d+\.\d+\.\d+) — (unreleased|\d{4}-\d{2}-\d{2})$", text, re.M)
    assert sections and sections[0][0] == cmake_version()
    # newest first, each version once
    versions = [tuple(map(int, v.split("."))) for v, _ in sections]
    assert versions == sorted(set(versions), reverse=True)
    assert "`vX.Y.Z`" in text                    # the tag scheme is stated
