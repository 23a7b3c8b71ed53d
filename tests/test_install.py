"""The installed library as another project sees it: `cmake --install` into a fresh prefix,
then a CMake project outside the tree (tests/data/outside_project) finds it with
find_package(martello) and builds the repository's self-checking C and Fortran examples
against it, and a C file compiles with the flags of `pkg-config martello`. The examples
check themselves against closed forms (P1, P3) and exit non-zero on any failure."""

import os
import shutil
import subprocess
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
BUILD = ROOT / "build"


def sh(*cmd, **kw):
    r = subprocess.run(cmd, capture_output=True, text=True, **kw)
    assert r.returncode == 0, f"{' '.join(map(str, cmd))} failed:\n{r.stdout}\n{r.stderr}"
    return r.stdout


@pytest.fixture(scope="module")
def prefix(tmp_path_factory):
    p = tmp_path_factory.mktemp("prefix")
    sh("cmake", "--install", str(BUILD), "--prefix", str(p))
    return p


def test_install_layout(prefix):
    libdirs = [d for d in prefix.glob("lib*/**/libmartello.so*")]
    assert libdirs, "no libmartello.so installed"
    for header in ("martello.h", "martello_version.h", "martello_ground_motion.h"):
        assert (prefix / "include" / header).is_file(), header
    mods = list((prefix / "include" / "martello" / "fortran").glob("*.mod"))
    assert {"martello.mod", "martello_model.mod"} <= {m.name for m in mods}   # `use martello`
    assert list(prefix.glob("lib*/**/cmake/martello/martello-config.cmake"))
    assert list(prefix.glob("lib*/**/pkgconfig/martello.pc"))


def test_outside_cmake_project(prefix, tmp_path):
    build = tmp_path / "outside"
    sh("cmake", "-S", str(ROOT / "tests/data/outside_project"), "-B", str(build), "-G", "Ninja",
       f"-DCMAKE_PREFIX_PATH={prefix}", f"-DEXAMPLES={ROOT}")
    sh("cmake", "--build", str(build))
    for exe in ("p1_static_outside", "p3_static_outside"):
        out = sh(str(build / exe))
        assert " 0 failed" in out, out


def test_pkg_config(prefix, tmp_path):
    pc = next(prefix.glob("lib*/**/pkgconfig/martello.pc")).parent
    env = dict(os.environ, PKG_CONFIG_PATH=str(pc))
    flags = sh("pkg-config", "--cflags", "--libs", "martello", env=env).split()
    src = tmp_path / "version.c"
    src.write_text('#include <stdio.h>\n#include <string.h>\n#include "martello.h"\n'
                   '#include "martello_version.h"\n'
                   'int main(void) { puts(martello_version());\n'
                   '  return strcmp(martello_version(), MARTELLO_VERSION_STRING) != 0; }\n')
    exe = tmp_path / "version"
    libdir = next(prefix.glob("lib*/**/libmartello.so")).parent
    sh(shutil.which("cc") or "cc", str(src), *flags, f"-Wl,-rpath,{libdir}", "-o", str(exe))
    assert sh(str(exe)).strip() == sh("cat", str(BUILD / "include/martello_version.h")) \
        .split('MARTELLO_VERSION_STRING "')[1].split('"')[0]
