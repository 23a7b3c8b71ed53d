"""Tests of martello.ground_motion: response spectra (Nigam-Jennings), Fourier amplitude
spectra (FFTW), design spectra (EN 1998-1, OPCM 3274) and spectrum-compatible synthesis.

Oracles are independent of the code under test: scipy.signal.lsim (matrix-exponential
first-order-hold discretisation) and the closed-form response to a ramp for the response
spectrum; numpy.fft and the analytic transform of a sine for the Fourier amplitude spectrum;
the code formulas evaluated by hand for the design spectra; numpy integration for the
baseline residuals."""

import ctypes
import math
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from scipy import signal
from scipy.integrate import cumulative_trapezoid

_ROOT = Path(__file__).resolve().parents[1]
if str(_ROOT) not in sys.path:
    sys.path.insert(0, str(_ROOT))

from martello import ground_motion as gm  # noqa: E402
from martello.errors import MartelloError  # noqa: E402
from martello.ground_motion.records import Record, read_csv_record  # noqa: E402

G = 9.80665  # standard gravity, exact by definition
EPS = np.finfo(float).eps


def lsim_peak(ag, dt, period, zeta):
    """max |u| at the samples of u'' + 2 zeta w u' + w^2 u = -ag, from rest, with ag linear
    between samples: scipy's lsim with interp=True is exact for that input (FOH)."""
    w = 2.0 * math.pi / period
    sys_ = signal.StateSpace([[0.0, 1.0], [-w * w, -2.0 * zeta * w]], [[0.0], [1.0]],
                             [[1.0, 0.0]], [[0.0]])
    t = np.arange(ag.size) * dt
    _, y, _ = signal.lsim(sys_, -ag, t, interp=True)
    return float(np.max(np.abs(y)))


def ramp_response(r, t, period, zeta):
    """u(t) for u'' + 2 zeta w u' + w^2 u = -r t from rest, in closed form:
    u = -(r/w^2)(t - 2 zeta/w) + exp(-zeta w t)(C1 cos wd t + C2 sin wd t)."""
    w = 2.0 * math.pi / period
    wd = w * math.sqrt(1.0 - zeta ** 2)
    c1 = -2.0 * zeta * r / w ** 3
    c2 = (r / w ** 2 + zeta * w * c1) / wd
    return -(r / w ** 2) * (t - 2.0 * zeta / w) + np.exp(-zeta * w * t) * (
        c1 * np.cos(wd * t) + c2 * np.sin(wd * t))


# ===================================================================== response spectrum

# Periods on both sides of the switch between the closed-form step coefficients (w dt >= 0.5)
# and their Taylor series (w dt < 0.5): with dt = 0.01 s the switch is at T = 0.12566 s.
PERIODS = [0.03, 0.05, 0.1256, 0.1257, 0.3, 1.0, 3.0, 10.0]


@pytest.mark.parametrize("zeta", [0.0, 0.02, 0.05, 0.2])
def test_response_spectrum_matches_lsim(zeta):
    rng = np.random.default_rng(7)
    dt, n = 0.01, 1500
    ag = rng.standard_normal(n)
    rs = gm.response_spectrum(ag, dt, PERIODS, zeta)
    for j, T in enumerate(PERIODS):
        ref = lsim_peak(ag, dt, T, zeta)
        # The requirement is 1e-8; both sides are exact recurrences in double
        # precision, so the agreement is in fact ~1e-13 (round-off accumulated over 1500 steps).
        assert rs.sd[j] == pytest.approx(ref, rel=1e-8, abs=0), f"T={T}, zeta={zeta}"
        w = 2.0 * math.pi / T
        # PSV = w Sd and PSA = w^2 Sd are one and two roundings away from Sd (4 ulp covers
        # the rounding of w itself too).
        assert rs.psv[j] == pytest.approx(w * rs.sd[j], rel=4 * EPS)
        assert rs.psa[j] == pytest.approx(w * w * rs.sd[j], rel=4 * EPS)


@pytest.mark.parametrize("period", [0.05, 0.5, 2.0, 20.0])
@pytest.mark.parametrize("zeta", [0.0, 0.05])
def test_response_spectrum_ramp_closed_form(period, zeta):
    dt, n, r = 0.005, 2001, 0.7  # ag = r t is piecewise linear, so the recurrence is exact
    t = np.arange(n) * dt
    rs = gm.response_spectrum(r * t, dt, [period], zeta)
    ref = np.max(np.abs(ramp_response(r, t, period, zeta)))
    # Closed form evaluated in double precision; for T = 20 s the two halves of u cancel to
    # 3 digits at early times, still far inside 1e-8.
    assert rs.sd[0] == pytest.approx(ref, rel=1e-8, abs=0)


def test_response_spectrum_rigid_limit_is_pga():
    rng = np.random.default_rng(3)
    ag = rng.standard_normal(800)
    pga = np.max(np.abs(ag))
    rs = gm.response_spectrum(ag, 0.01, [0.0, 1e-9, 1e-3, 0.004], 0.05)
    assert rs.psa[0] == pga and rs.sd[0] == 0.0 and rs.psv[0] == 0.0  # T = 0: exact
    assert rs.psa[1] == pga  # T <= 1e-6 dt: treated as rigid, exact by definition
    # T = 1e-3 s and 4e-3 s are stepped: the oscillator follows the quasi-static
    # u = -(ag - 2 zeta ag'/w)/w^2, so PSA/PGA - 1 = O(2 zeta max|dag|/(w dt PGA)): 5e-4 and 2e-3
    # for unit-variance noise at dt = 0.01 s.
    for j, T in ((2, 1e-3), (3, 4e-3)):
        w = 2 * math.pi / T
        bound = 2 * 0.05 * np.max(np.abs(np.diff(ag))) / (w * 0.01 * pga)
        assert abs(rs.psa[j] / pga - 1) <= bound


def test_response_spectrum_accepts_a_record():
    rng = np.random.default_rng(5)
    a = rng.standard_normal(300)
    rec = Record(t=np.arange(300) * 0.02, accel=a, dt=0.02, source="mem", units_in_file="m/s2",
                 description="")
    assert np.array_equal(gm.response_spectrum(rec, None, [0.5]).psa,
                          gm.response_spectrum(a, 0.02, [0.5]).psa)


# ===================================================================== Fourier amplitude

@pytest.mark.parametrize("n", [1000, 999])
def test_fourier_amplitude_of_a_bin_sine(n):
    dt, m, amp0 = 0.01, 50, 2.5
    t = np.arange(n) * dt
    f_m = m / (n * dt)
    freq, amp = gm.fourier_amplitude(amp0 * np.sin(2 * math.pi * f_m * t), dt)
    assert freq.size == n // 2 + 1
    assert np.argmax(amp) == m
    assert freq[m] == pytest.approx(f_m, rel=2 * EPS)
    # |X_m| = amp0 n / 2 exactly for a sine on a bin, so |A| = dt amp0 n/2 = amp0 * duration/2;
    # FFT round-off is O(eps log2 n) relative to the peak: 1e-12 leaves a wide margin.
    assert amp[m] == pytest.approx(amp0 * n * dt / 2, rel=1e-12)
    others = np.delete(amp, m)
    assert np.max(others) <= 1e-12 * amp[m]


def test_fourier_amplitude_matches_numpy():
    rng = np.random.default_rng(11)
    a, dt = rng.standard_normal(777), 0.005
    freq, amp = gm.fourier_amplitude(a, dt)
    ref = dt * np.abs(np.fft.rfft(a))
    # two FFT implementations: O(eps log n) round-off relative to the largest coefficient
    assert np.max(np.abs(amp - ref)) <= 1e-12 * np.max(ref)
    assert np.allclose(freq, np.fft.rfftfreq(777, dt), rtol=4 * EPS, atol=0)


# ===================================================================== design spectra

def test_eurocode8_type1_hand_values():
    ag = 0.3 * G
    sp = gm.eurocode8_spectrum(ag, "B", spectrum_type=1)  # Table 3.2: S 1.2, 0.15/0.5/2.0 s
    plateau = ag * 1.2 * 2.5  # eq. 3.3 with eta = 1 at 5 %
    # Values below are one to three roundings from the formulas: 4 ulp.
    tol = dict(rel=4 * EPS, abs=0)
    assert sp.psa(0.0) == pytest.approx(ag * 1.2, **tol)
    assert sp.psa(0.075) == pytest.approx(ag * 1.2 * (1 + 0.5 * 1.5), **tol)  # eq. 3.2 at T_B/2
    assert sp.psa(0.15) == pytest.approx(plateau, **tol)
    assert sp.psa(0.3) == pytest.approx(plateau, **tol)
    assert sp.psa(0.5) == pytest.approx(plateau, **tol)
    assert sp.psa(1.0) == pytest.approx(plateau * 0.5 / 1.0, **tol)  # eq. 3.4
    assert sp.psa(2.0) == pytest.approx(plateau * 0.5 / 2.0, **tol)
    assert sp.psa(3.0) == pytest.approx(plateau * 0.5 * 2.0 / 9.0, **tol)  # eq. 3.5
    assert sp.pga == pytest.approx(ag * 1.2, **tol)


def test_eurocode8_type2_and_damping():
    sp = gm.eurocode8_spectrum(0.1 * G, "c", spectrum_type=2, damping=10.0)
    assert (sp.S, sp.TB, sp.TC, sp.TD) == (1.5, 0.10, 0.25, 1.2)  # Table 3.3, ground C
    eta = math.sqrt(10 / 15)  # eq. 3.6 at xi = 10 %
    assert sp.eta == pytest.approx(eta, rel=2 * EPS)
    assert sp.psa(0.2) == pytest.approx(0.1 * G * 1.5 * 2.5 * eta, rel=4 * EPS)
    assert gm.damping_correction(30.0) == 0.55  # sqrt(10/35) = 0.5345 < 0.55: the floor
    assert gm.damping_correction(5.0) == 1.0


def test_opcm3274_zone2_soil_c_is_the_seed_case():
    sp = gm.opcm3274_spectrum(2, "C")
    assert sp.ag == pytest.approx(0.25 * G, rel=2 * EPS)
    assert sp.pga == pytest.approx(0.25 * G * 1.25, rel=4 * EPS)  # P8: 0.25 g x 1.25
    assert sp.psa(0.3) == pytest.approx(0.25 * G * 1.25 * 2.5, rel=4 * EPS)
    assert sp.psa(1.0) == pytest.approx(0.25 * G * 1.25 * 2.5 * 0.5, rel=4 * EPS)
    for zone, ag in ((1, 0.35), (3, 0.15), (4, 0.05)):
        assert gm.opcm3274_spectrum(zone, "A").pga == pytest.approx(ag * G, rel=2 * EPS)


@pytest.mark.parametrize("make", [
    *[lambda s=s, k=k: gm.eurocode8_spectrum(0.25 * G, s, k) for s in "ABCDE" for k in (1, 2)],
    *[lambda s=s: gm.opcm3274_spectrum(2, s, damping=7.0) for s in "ABCDE"],
])
def test_design_spectra_are_continuous_at_the_corners(make):
    sp = make()
    for c in (sp.TB, sp.TC, sp.TD):
        lo, hi = sp.psa(c * (1 - 1e-12)), sp.psa(c * (1 + 1e-12))
        # each branch moves by O(1e-12) relative over the 2e-12 step; a jump in the code
        # data (a wrong corner) would be O(1)
        assert hi == pytest.approx(lo, rel=1e-11), f"{sp.label} at T={c}"


# ===================================================================== synthesis (P8 records)

BAND, T_MIN, T_MAX = 0.10, 0.15, 2.0


@pytest.fixture(scope="module")
def p8_records():
    """The seed's input: five records for OPCM 3274 zone 2, soil C (PGA 0.25 g x 1.25)."""
    target = gm.opcm3274_spectrum(2, "C")
    t0 = time.perf_counter()
    records = gm.generate_records(target, 5, seed=2003, duration=20.0, dt=0.01)
    elapsed = time.perf_counter() - t0
    print(f"\n5 P8 records in {elapsed:.2f} s: " + "; ".join(
        f"{r.provenance_dict()['iterations']} corrections, {r.provenance_dict()['restarts']} "
        f"restarts, deviation {float(r.provenance_dict()['worst deviation']):.4f}"
        for r in records))
    return target, records, elapsed


def test_p8_records_match_the_target_band(p8_records):
    target, records, elapsed = p8_records
    # Periods mostly between the points of the native check grid (600 per decade, 0.38 %
    # steps).  A record's PSA is a max over response peaks and has kinks, so between grid
    # points it can exceed the band met on the grid by about slope x half step: at most
    # 0.4 % over 10 records checked on 36000 points per decade.  Hence band + 0.5 %.
    periods = np.geomspace(T_MIN, T_MAX, 37)  # 675 grid steps / 36: mostly between grid points
    expected = target.psa(periods)
    for k, rec in enumerate(records):
        assert isinstance(rec, Record) and rec.dt == 0.01 and rec.accel.size == 2001
        got = np.array([lsim_peak(rec.accel, rec.dt, T, 0.05) for T in periods])
        got *= (2 * math.pi / periods) ** 2
        dev = np.max(np.abs(got / expected - 1))
        assert dev <= BAND + 0.005, f"record {k}: PSA deviation {dev:.4f}"
        assert float(rec.provenance_dict()["worst deviation"]) <= BAND


def test_p8_records_pga_is_exact(p8_records):
    target, records, _ = p8_records
    for rec in records:
        # the record is scaled by pga/max|a|: one rounding of the factor, one of the product
        assert np.max(np.abs(rec.accel)) == pytest.approx(target.pga, rel=1e-12, abs=0)


def test_p8_records_end_at_rest(p8_records):
    _, records, _ = p8_records
    for rec in records:
        a, h = rec.accel, rec.dt
        v = cumulative_trapezoid(a, dx=h, initial=0.0)
        # displacement, exact for piecewise-linear a: d_{i+1} = d_i + h v_i + h^2(a_i/3 + a_{i+1}/6)
        d_end = np.sum(h * v[:-1] + h * h * (a[:-1] / 3 + a[1:] / 6))
        # Rounding only: sums of 2000 terms of size <= 3 m/s^2 x 0.01 s give ~1e-14;
        # 1e-12 is 100 times that.
        assert abs(v[-1]) <= 1e-12
        assert abs(d_end) <= 1e-12
        # Trapezoid applied twice differs from the exact integral by h^2/12 (a_N - a_0)
        # (the per-step differences telescope); a_0 = 0 under the envelope.
        d_trap = cumulative_trapezoid(v, dx=h)[-1]
        assert a[0] == 0.0
        assert d_trap == pytest.approx(h * h / 12 * (a[-1] - a[0]), abs=1e-12)
        assert abs(d_trap) <= h * h / 12 * 0.1 * np.max(np.abs(a))  # envelope 5 % at the end


def test_same_seed_same_record_other_seed_other_record(p8_records):
    target, records, _ = p8_records
    again = gm.generate_records(target, 1, seed=2003)[0]
    assert np.array_equal(again.accel, records[0].accel)
    other = gm.generate_records(target, 1, seed=2004)[0]
    assert np.max(np.abs(other.accel - records[0].accel)) > 0.1 * target.pga
    assert len({r.provenance_dict()["native seed"] for r in records}) == 5


def test_records_written_with_provenance_read_back_exactly(p8_records, tmp_path):
    _, records, _ = p8_records
    paths = gm.write_records_csv(records[:2], tmp_path, stem="p8")
    text = paths[0].read_text().splitlines()
    head = [line for line in text if line.startswith("#")]
    assert "# seed: 2003" in head and "# units: m/s2" in head
    assert any(line.startswith("# target: OPCM 3274 zone 2, soil C") for line in head)
    back = read_csv_record(paths[0])
    assert np.array_equal(back.accel, records[0].accel) and np.array_equal(back.t, records[0].t)


def test_synthesis_reports_a_missed_band():
    target = gm.opcm3274_spectrum(2, "C")
    res = gm.synthesize(target, seed=1, band=0.01, max_iter=3)  # 1 % is out of reach
    assert not res.converged and res.iterations == 3 and res.worst_deviation > 0.01
    assert np.max(np.abs(res.accel)) == pytest.approx(target.pga, rel=1e-12, abs=0)
    with pytest.raises(MartelloError, match="NOT_CONVERGED"):
        gm.generate_records(target, 1, seed=1, band=0.01, max_iter=3)


# ===================================================================== bad input

GOOD = np.linspace(0.0, 1.0, 50)


@pytest.mark.parametrize("call, match", [
    (lambda: gm.response_spectrum(GOOD, -0.01, [0.5]), r"^dt: -0\.01 must be > 0"),
    (lambda: gm.response_spectrum(GOOD, 0.01, [0.5], zeta=1.0), r"^zeta: 1\.0 must satisfy"),
    (lambda: gm.response_spectrum(GOOD, 0.01, [0.5], zeta=-0.1), r"^zeta: "),
    (lambda: gm.response_spectrum([], 0.01, [0.5]), r"^accel: is empty"),
    (lambda: gm.response_spectrum(np.r_[GOOD[:3], np.nan, GOOD[4:]], 0.01, [0.5]),
     r"^accel: value nan at index 3 is not finite"),
    (lambda: gm.response_spectrum(GOOD, 0.01, [0.5, -1.0]),
     r"^periods: period -1\.0 at index 1 is negative"),
    (lambda: gm.response_spectrum(GOOD, 0.01, [np.inf]), r"^periods: value inf"),
    (lambda: gm.response_spectrum(GOOD, float("nan"), [0.5]), r"^dt: nan is not finite"),
    (lambda: gm.fourier_amplitude(GOOD, 0.0), r"^dt: 0\.0 must be > 0"),
    (lambda: gm.fourier_amplitude(np.zeros((3, 3)), 0.01), r"^accel: must be one-dimensional"),
    (lambda: gm.eurocode8_spectrum(0.3 * G, "F"), r"^ground_type: 'F'"),
    (lambda: gm.eurocode8_spectrum(0.3 * G, "A", spectrum_type=3), r"^spectrum_type: 3"),
    (lambda: gm.opcm3274_spectrum(5, "A"), r"^zone: 5"),
    (lambda: gm.synthesize(gm.opcm3274_spectrum(2, "C"), dt=-0.01), r"^dt: "),
    (lambda: gm.synthesize(gm.opcm3274_spectrum(2, "C"), t_min=0.01), r"^t_min: "),
    (lambda: gm.synthesize(gm.opcm3274_spectrum(2, "C"), t_max=9.0), r"^t_max: "),
    (lambda: gm.synthesize(gm.opcm3274_spectrum(2, "C"), seed=-1), r"^seed: "),
    (lambda: gm.synthesize(([0.0, 1.0], [1.0, -1.0])), r"^target psa: must be > 0"),
    (lambda: gm.generate_records(gm.opcm3274_spectrum(2, "C"), 0, seed=1), r"^n_records: "),
])
def test_bad_input_names_the_argument(call, match):
    with pytest.raises(gm.GroundMotionError, match=match):
        call()
    assert issubclass(gm.GroundMotionError, MartelloError)


def test_native_argument_checks_one_at_a_time():
    """The C entry points check their arguments too (LAPACK-style error exits: one bad
    argument per call, the code returned checked), for callers that bypass Python."""
    from martello.binding.ground_motion import library
    L = library()
    ag, T = np.ones(10), np.array([0.5])
    out = [np.zeros(1) for _ in range(3)]
    rs = L.martello_gm_response_spectrum
    assert rs(ag, 10, 0.01, 0.05, T, 1, *out) == 0
    assert rs(ag, 0, 0.01, 0.05, T, 1, *out) == -1  # n = 0
    assert rs(ag, 10, -0.01, 0.05, T, 1, *out) == -1  # dt < 0
    assert rs(ag, 10, 0.01, 1.0, T, 1, *out) == -1  # zeta = 1
    assert rs(ag, 10, 0.01, 0.05, np.array([-0.5]), 1, *out) == -1  # T < 0
    assert rs(np.r_[ag[:9], np.nan], 10, 0.01, 0.05, T, 1, *out) == -1  # NaN sample
    freq, amp, nf = np.zeros(6), np.zeros(6), ctypes.c_int(5)
    fa = L.martello_gm_fourier_amplitude
    assert fa(ag, 10, 0.01, freq, amp, ctypes.byref(nf)) == -1 and nf.value == 6  # capacity
    assert fa(ag, 10, 0.01, freq, amp, ctypes.byref(nf)) == 0 and nf.value == 6
    assert fa(ag, 1, 0.01, freq, amp, ctypes.byref(nf)) == 0 and nf.value == 1  # n = 1
