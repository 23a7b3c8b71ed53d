"""Tests of martello.ground_motion.records: ground-motion record readers (CSV and PEER AT2)."""

import math
import re
import sys
from pathlib import Path

import numpy as np
import pytest

_ROOT = Path(__file__).resolve().parents[1]
if str(_ROOT) not in sys.path:  # the package is not installed in the venv
    sys.path.insert(0, str(_ROOT))

from martello.errors import RecordError  # noqa: E402
from martello.ground_motion.records import (  # noqa: E402
    Record,
    arias_intensity,
    pga,
    read_at2,
    read_csv_record,
    read_record,
    resample_uniform,
    write_csv_record,
)

DATA = Path(__file__).resolve().parent / "data" / "records"
G = 9.80665  # standard gravity, exact by definition

# One product of two doubles is rounded once: relative error <= 2**-53 ~ 1.1e-16;
# ONE_ULP also covers a value compared against the same product rounded differently.
ONE_ULP = 2.3e-16
# x * 0.01 versus the exact decimal x/100: 0.01 itself is rounded once, the product once.
TWO_ULP = 4.5e-16


def at(path, line=None):
    """Regex for the start of a RecordError message: 'file:line: '."""
    return re.escape(f"{path}:{line}: " if line is not None else f"{path}: ")


def write_at2(path, values, npts_line=None, units_line="ACCELERATION TIME SERIES IN UNITS OF G",
              dt=0.005, per_line=5):
    """Write an AT2 file with values in repr form (exact round trip)."""
    if npts_line is None:
        npts_line = f"NPTS= {len(values):6d}, DT= {dt!r} SEC"
    rows = [" ".join(repr(float(v)) for v in values[k:k + per_line])
            for k in range(0, len(values), per_line)]
    path.write_text("\n".join(["TITLE", "EVENT, DATE, STATION", units_line, npts_line] + rows) + "\n")
    return path


# ============================================================== valid AT2 files

@pytest.mark.parametrize("name, npts, dt, title, first, last", [
    ("peer_keyed_comma.AT2", 17, 0.005, "PEER NGA STRONG MOTION DATABASE RECORD",
     2.9552021e-02, 1.7075334e-02),
    ("peer_keyed_space.at2", 12, 0.01, "PEER NGA STRONG MOTION DATABASE RECORD (space variant)",
     0.089121, -0.033287),
    ("peer_fixed.AT2", 23, 0.02,
     "PEER STRONG MOTION DATABASE RECORD. PROCESSING BY PACIFIC ENGINEERING.",
     9.0929743e-02, 2.1051124e-03),
])
def test_at2_header_variants(name, npts, dt, title, first, last):
    rec = read_record(DATA / name)
    assert isinstance(rec, Record)
    assert rec.t.shape == rec.accel.shape == (npts,)
    assert rec.dt == dt  # DT parsed from the header text: same decimal -> same double
    # t_i = i*dt: one correctly rounded product per sample, in the reader as here
    np.testing.assert_array_equal(rec.t, [i * dt for i in range(npts)])
    assert rec.t[0] == 0.0
    # file values are in g: one rounded product each
    np.testing.assert_allclose(rec.accel[[0, -1]], [first * G, last * G], rtol=ONE_ULP, atol=0)
    assert rec.units_in_file == "g"
    assert rec.description == title
    assert rec.source == str(DATA / name)


def test_at2_from_numpy_arrays(tmp_path):
    a_g = np.random.default_rng(7).normal(scale=0.2, size=19)  # 19 = 3 full lines + 4
    path = write_at2(tmp_path / "rand.AT2", a_g, dt=0.01)
    rec = read_at2(path)
    # repr() round-trips exactly, then one product with g
    np.testing.assert_allclose(rec.accel, a_g * G, rtol=ONE_ULP, atol=0)
    assert rec.dt == 0.01
    assert rec.t[-1] == 18 * 0.01  # t0 + i*dt with t0 = 0, one rounded product


def test_at2_in_cm_s2_old_fixed_header():
    rec = read_record(DATA / "peer_cms2.AT2")
    assert rec.units_in_file == "cm/s2"
    assert rec.dt == 0.01  # ".0100" parsed: same double as the literal
    expected = np.array([10, 20, 30, -10, -20, 10, 10, 20, 30, -10, -20, 10]) / 100.0
    np.testing.assert_allclose(rec.accel, expected, rtol=TWO_ULP, atol=0)  # see TWO_ULP


@pytest.mark.parametrize("spelling, factor", [
    ("G", G), ("g", G), ("M/S2", 1.0), ("M/S/S", 1.0), ("M/SEC/SEC", 1.0),
    ("CM/S2", 0.01), ("CM/S/S", 0.01), ("CM/SEC^2", 0.01), ("GAL", 0.01),
])
def test_at2_units_line_spellings(tmp_path, spelling, factor):
    a = np.array([0.5, -1.25, 2.0, 0.75])  # exact binary fractions
    path = write_at2(tmp_path / "u.AT2", a, units_line=f"ACCELERATION TIME SERIES IN UNITS OF {spelling}")
    rec = read_at2(path)
    np.testing.assert_allclose(rec.accel, a * factor, rtol=ONE_ULP, atol=0)  # one product


def test_at2_custom_g(tmp_path):
    a = np.array([0.5, -0.25, 1.0])
    rec = read_at2(write_at2(tmp_path / "g.AT2", a), g=9.81)
    np.testing.assert_allclose(rec.accel, a * 9.81, rtol=ONE_ULP, atol=0)  # one product


# ============================================================== valid CSV files

CSV_G_VALUES = [0.000, 0.012, 0.031, -0.025, -0.047, 0.008, 0.050, 0.019, -0.033, -0.010]


def test_csv_in_g_with_header_and_units_comment():
    rec = read_record(DATA / "csv_g_header.csv")  # units from '# units: g'
    assert rec.units_in_file == "g"
    np.testing.assert_allclose(rec.accel, np.array(CSV_G_VALUES) * G, rtol=ONE_ULP, atol=0)
    np.testing.assert_array_equal(rec.t, [0.00, 0.01, 0.02, 0.03, 0.04, 0.05, 0.06, 0.07, 0.08, 0.09])
    # dt = (0.09 - 0)/9: decimal inputs and one division, a few ulp at most
    assert rec.dt == pytest.approx(0.01, rel=1e-15)
    assert rec.description == ""
    # passing the same units as the file is accepted
    again = read_csv_record(DATA / "csv_g_header.csv", units="g")
    np.testing.assert_array_equal(again.accel, rec.accel)  # same path through the code


def test_csv_whitespace_m_s2_non_uniform():
    rec = read_record(DATA / "csv_ms2_whitespace.txt")
    assert rec.units_in_file == "m/s2"  # no argument, no units comment -> m/s2
    # m/s2 is multiplied by exactly 1.0: values are the parsed decimals, bit for bit
    np.testing.assert_array_equal(rec.t, [0.000, 0.005, 0.010, 0.020, 0.025, 0.040])
    np.testing.assert_array_equal(rec.accel, [0.00, 0.12, -0.31, 0.25, 0.47, -0.08])
    assert rec.dt is None
    assert pga(rec) == 0.47  # max |a|, no arithmetic


def test_csv_from_numpy_arrays_units_argument(tmp_path):
    rng = np.random.default_rng(3)
    t = np.cumsum(rng.uniform(0.001, 0.01, size=15))  # non-uniform, strictly increasing
    a = rng.normal(size=15) * 100
    path = tmp_path / "rand.csv"
    path.write_text("".join(f"{ti!r},  {ai!r}\n" for ti, ai in zip(t.tolist(), a.tolist())))
    rec = read_csv_record(path, units="cm/s2")
    assert rec.units_in_file == "cm/s2"
    np.testing.assert_array_equal(rec.t, t)  # repr() round-trips exactly
    np.testing.assert_allclose(rec.accel, a / 100.0, rtol=TWO_ULP, atol=0)  # see TWO_ULP
    assert rec.dt is None


@pytest.mark.parametrize("jitter, uniform", [(1e-11, True), (1e-7, False)])
def test_csv_uniform_step_detection(tmp_path, jitter, uniform):
    t = np.arange(12) * 0.02
    t[5] += jitter * 0.02  # one step off by `jitter` relative to dt (limit is 1e-9)
    path = tmp_path / "u.csv"
    path.write_text("".join(f"{ti!r} 0.0\n" for ti in t.tolist()))
    rec = read_csv_record(path)
    if uniform:
        # mean step (t[-1]-t[0])/11: a few roundings, far below the 1e-9 threshold
        assert rec.dt == pytest.approx(0.02, rel=1e-14)
    else:
        assert rec.dt is None


def test_scale_applies_after_unit_conversion():
    rec = read_record(DATA / "csv_g_header.csv", scale=1.25)
    # a*g then *1.25 (a power of two fraction of 5/4): two roundings at most
    np.testing.assert_allclose(rec.accel, np.array(CSV_G_VALUES) * G * 1.25, rtol=TWO_ULP, atol=0)
    assert rec.units_in_file == "g"


def test_fmt_overrides_extension():
    rec = read_record(DATA / "record.dat", fmt="csv")
    np.testing.assert_array_equal(rec.accel, [0.01, 0.02])  # m/s2, parsed decimals exactly


def test_write_csv_record_round_trip(tmp_path):
    src = read_record(DATA / "peer_keyed_comma.AT2")
    out = tmp_path / "out.csv"
    write_csv_record(out, src)
    text = out.read_text()
    assert "# units: m/s2" in text
    assert f"# source: {src.source}" in text
    assert "time,accel_m_s2" in text
    back = read_csv_record(out)  # the '# units: m/s2' comment sets the units
    assert back.units_in_file == "m/s2"
    # 17 significant digits round-trip doubles exactly
    np.testing.assert_array_equal(back.t, src.t)
    np.testing.assert_array_equal(back.accel, src.accel)
    assert back.dt == pytest.approx(src.dt, rel=1e-14)  # mean step of i*dt: a few roundings


def test_record_arrays_are_read_only():
    rec = read_record(DATA / "csv_ms2_whitespace.txt")
    with pytest.raises(ValueError):
        rec.accel[0] = 1.0


# ============================================================== resample, pga, Arias

def _linear_record(t):
    t = np.asarray(t, dtype=float)
    return Record(t=t, accel=2.0 * t + 1.0, dt=None, source="mem", units_in_file="m/s2", description="")


def test_resample_uniform_linear_is_exact_and_stops_at_last_sample():
    rec = _linear_record([0.0, 0.1, 0.35, 0.5, 0.8, 1.0])
    res = resample_uniform(rec, 0.3)
    np.testing.assert_allclose(res.t, [0.0, 0.3, 0.6, 0.9], rtol=0, atol=1e-15)  # k*0.3, one rounding
    assert res.t[-1] <= rec.t[-1]  # no extrapolation past the last sample
    # linear data are reproduced by linear interpolation up to round-off of a few operations
    np.testing.assert_allclose(res.accel, 2.0 * res.t + 1.0, rtol=1e-14, atol=0)
    assert res.dt == 0.3


def test_resample_uniform_keeps_end_point_despite_round_off():
    rec = _linear_record([0.0, 0.07, 0.3])
    res = resample_uniform(rec, 0.1)  # 0.3/0.1 = 2.9999999999999996 in floating point
    assert len(res.t) == 4
    assert res.t[-1] == 0.3  # placed exactly on the last sample, not past it
    assert res.accel[-1] == rec.accel[-1]  # interpolation at a sample returns the sample


@pytest.mark.parametrize("dt, text", [(0.0, "must be a positive"), (-0.01, "must be a positive"),
                                      (5.0, "longer than the record")])
def test_resample_uniform_bad_step(dt, text):
    with pytest.raises(RecordError, match=at("mem") + f"resample step dt={dt}.*{text}"):
        resample_uniform(_linear_record([0.0, 0.5, 1.0]), dt)


def test_pga_in_si():
    rec = read_record(DATA / "csv_g_header.csv")
    assert pga(rec) == pytest.approx(0.050 * G, rel=ONE_ULP)  # |-0.047| < 0.050; one product


def test_arias_constant_record():
    t = np.linspace(0.0, 4.0, 9)
    rec = Record(t=t, accel=np.full(9, 3.0), dt=0.5, source="mem", units_in_file="m/s2", description="")
    # integral of 9 over 4 s = 36 exactly; trapezoid exact for a constant; few roundings
    assert arias_intensity(rec) == pytest.approx(math.pi / (2 * G) * 36.0, rel=1e-15)


def test_arias_sine_whole_periods():
    amp, f, T, n = 2.5, 2.0, 3.0, 601
    t = np.linspace(0.0, T, n)
    rec = Record(t=t, accel=amp * np.sin(2 * np.pi * f * t), dt=T / (n - 1), source="mem",
                 units_in_file="m/s2", description="")
    # trapezoid of sin^2 over whole periods with >2 points/period equals A^2 T/2 exactly;
    # only summation round-off of 600 terms remains (~1e-13 relative worst case)
    assert arias_intensity(rec) == pytest.approx(math.pi / (2 * G) * amp**2 * T / 2, rel=1e-12)


def test_arias_non_uniform_by_hand():
    rec = Record(t=np.array([0.0, 1.0, 3.0]), accel=np.array([1.0, 2.0, 0.0]), dt=None,
                 source="mem", units_in_file="m/s2", description="")
    # trapezoids: (1+4)/2*1 + (4+0)/2*2 = 6.5 exactly; then pi/(2g) times it, few roundings
    assert arias_intensity(rec) == pytest.approx(math.pi / (2 * G) * 6.5, rel=1e-15)


# ============================================================== error paths

def _raises(path, line, text, **kw):
    with pytest.raises(RecordError, match=at(path, line) + text) as info:
        read_record(path, **kw)
    assert info.value.file == str(path)
    assert info.value.line == line
    assert info.value.fix  # every error says how to fix it
    return info.value


def test_error_file_missing(tmp_path):
    _raises(tmp_path / "nope.AT2", None, "file not found")


def test_error_empty_csv():
    _raises(DATA / "empty.csv", None, r"file is empty \(no samples\)")


def test_error_empty_at2():
    _raises(DATA / "empty.AT2", None, r"file is empty \(no samples\)")


def test_error_csv_header_only_no_samples():
    _raises(DATA / "csv_header_only.csv", None, r"no samples")


def test_error_at2_npts_zero_no_samples():
    _raises(DATA / "at2_no_samples.AT2", 4, r"no samples \(NPTS=0, 0 values\)")


def test_error_csv_one_sample():
    _raises(DATA / "csv_one_sample.csv", 2, "only 1 sample; a record needs at least 2")


def test_error_at2_one_sample():
    _raises(DATA / "at2_one_sample.AT2", 4, "only 1 sample; a record needs at least 2")


def test_error_at2_nan_value():
    _raises(DATA / "at2_nan.AT2", 6, "value 'NaN' is not finite")


def test_error_csv_nan_value():
    _raises(DATA / "csv_nan.csv", 4, "acceleration value 'nan' is not finite")


def test_error_csv_inf_value():
    _raises(DATA / "csv_inf.csv", 3, "acceleration value 'inf' is not finite")


def test_error_at2_non_numeric_value():
    _raises(DATA / "at2_non_numeric.AT2", 6, "value '2.00000O0E-02' is not a number")


def test_error_csv_non_numeric_value():
    _raises(DATA / "csv_non_numeric.csv", 3, "acceleration value '0.0x2' is not a number")


def test_error_csv_second_header_line():
    err = _raises(DATA / "csv_two_header_lines.csv", 2, "time value 'seconds' is not a number")
    assert "only one header line" in err.fix


def test_error_csv_non_monotone_time():
    _raises(DATA / "csv_non_monotone.csv", 5, "decreasing time: t=0.015 on line 5 after t=0.02 on line 4")


def test_error_csv_repeated_time():
    _raises(DATA / "csv_repeated_time.csv", 4, "repeated time: t=0.01 on line 4 after t=0.01 on line 3")


def test_error_at2_zero_dt():
    _raises(DATA / "at2_zero_dt.AT2", 4, r"DT=\.0000 is not positive")


def test_error_at2_negative_dt(tmp_path):
    path = write_at2(tmp_path / "neg.AT2", [0.1, 0.2, 0.3], npts_line="NPTS= 3 DT= -0.005 SEC")
    _raises(path, 4, "DT=-0.005 is not positive")


def test_error_at2_missing_npts_dt_line():
    _raises(DATA / "at2_no_npts_line.AT2", 4, "header line has no NPTS and DT")


def test_error_at2_missing_dt():
    _raises(DATA / "at2_no_dt.AT2", 4, "header line has no DT: 'NPTS=   12'")


def test_error_at2_short_header():
    _raises(DATA / "at2_short_header.AT2", 2, "header incomplete: 2 line")


def test_error_at2_npts_mismatch():
    _raises(DATA / "at2_npts_mismatch.AT2", 4, r"NPTS=14 in the header but 12 values follow \(lines 5-7\)")


def test_error_csv_wrong_number_of_columns():
    _raises(DATA / "csv_three_columns.csv", 2, r"expected 2 columns \(time, acceleration\), found 3")


def test_error_csv_bad_units_line():
    err = _raises(DATA / "csv_bad_units_line.csv", 1, "unknown units 'mm/s2' in the units comment")
    assert "m/s2" in err.fix and "cm/s2" in err.fix and "g" in err.fix


def test_error_csv_conflicting_units_lines():
    _raises(DATA / "csv_two_units_lines.csv", 2, "units comment says 'cm/s2' but line 1 already said 'g'")


def test_error_csv_units_argument_conflicts_with_file():
    _raises(DATA / "csv_g_header.csv", 2, "the file declares units 'g' but units='m/s2' was passed",
            units="m/s2")


def test_error_at2_units_argument_conflicts_with_file():
    _raises(DATA / "peer_fixed.AT2", 3, "the file declares units 'g' but units='cm/s2' was passed",
            units="cm/s2")


def test_error_invalid_units_argument():
    err = _raises(DATA / "csv_ms2_whitespace.txt", None, "units='m/s\\^2' is not a valid unit", units="m/s^2")
    assert '"g", "m/s2" or "cm/s2"' in err.fix


def test_error_at2_unknown_units():
    _raises(DATA / "at2_bad_units.AT2", 3, "unknown units 'IN/S/S'")


def test_error_at2_velocity_file():
    _raises(DATA / "at2_velocity.AT2", 3, "this is a velocity record, not an acceleration record")


def test_error_unknown_extension():
    err = _raises(DATA / "record.dat", None, r"unknown record extension '\.dat'; accepted: \.AT2 \(PEER NGA\), "
                                             r"\.csv or \.txt")
    assert "fmt=" in err.fix


def test_error_unknown_fmt():
    _raises(DATA / "record.dat", None, "unknown format fmt='xls'", fmt="xls")
