"""history.csv as the library writes it (c/csv_writer.c, docs/results.md "history.csv"): the
bytes Python's own %.17g formatting gives (an independent implementation of the same
printf rule), every number reading back to the double it was, and a path that cannot be
written is an OSError naming it."""

import errno
import math
import struct
from pathlib import Path

import numpy as np
import pytest

from martello.binding import native
from martello.run import run_full, write_results
from martello.scene.loader import load

ROOT = Path(__file__).resolve().parent.parent

# doubles whose text is easy to get wrong: signed zero, the subnormal ends, the largest, 17
# digits needed (0.1, 1/3), integers past 2^53, exponents of two and three digits
HARD = [0.0, -0.0, 5e-324, -2.2250738585072009e-308, 2.2250738585072014e-308,
        1.7976931348623157e308, 0.1, 1.0 / 3.0, -2.0 / 3.0, 9007199254740993.0, 1e16, 1e17,
        123456789.0, 1e-5, 1e-100, 6.02214076e23, -1.5, 1.0]


def _expected(columns, data):
    return ",".join(columns) + "\n" + "".join(
        ",".join("%.17g" % x for x in row) + "\n" for row in data.tolist())


def test_the_library_writes_what_pythons_17g_writes(tmp_path):
    rng = np.random.default_rng(7)
    bits = rng.integers(0, 2**63 - 1, size=3000, dtype=np.int64)
    rand = bits.view(np.float64)                      # doubles from every binade
    rand = rand[np.isfinite(rand)]
    values = np.concatenate([HARD, rand, rng.standard_normal(1000) * 1e-3])
    cols = 7
    values = values[: values.size // cols * cols]
    data = values.reshape(-1, cols)
    columns = ["t"] + [f"u:n{i}" for i in range(1, cols)]
    path = tmp_path / "history.csv"
    native.write_csv(path, columns, data)
    text = path.read_text()
    assert text == _expected(columns, data)
    back = np.array([[float(x) for x in line.split(",")] for line in text.splitlines()[1:]])
    # bit for bit, -0.0 included
    assert [struct.pack("<d", x) for x in back.ravel()] == [struct.pack("<d", x) for x in data.ravel()]


def test_a_run_writes_its_history_through_the_library(tmp_path):
    scene = load(ROOT / "benchmarks/p7/p7_two_oscillators.toml")
    summary, (columns, data) = run_full(scene)
    write_results(summary, tmp_path / "out", (columns, data))
    text = (tmp_path / "out" / "history.csv").read_text()
    assert text == _expected(columns, np.asarray(data, float))
    assert len(text.splitlines()) == len(data) + 1 and not math.isnan(float(text.splitlines()[-1].split(",")[1]))


def test_a_history_that_cannot_be_written_is_an_oserror_naming_it(tmp_path):
    target = tmp_path / "no" / "such" / "folder" / "history.csv"
    with pytest.raises(OSError) as e:
        native.write_csv(target, ["t"], np.zeros((2, 1)))
    assert e.value.errno == errno.ENOENT and str(target) in str(e.value)
    with pytest.raises(ValueError, match="3 columns"):
        native.write_csv(tmp_path / "h.csv", ["t", "a", "b"], np.zeros((2, 2)))
