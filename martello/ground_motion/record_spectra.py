"""Spectra of a record: the linear SDOF response spectrum (Nigam & Jennings 1969) and the
Fourier amplitude spectrum, computed in the native library (martello.binding.ground_motion)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..binding import ground_motion as native_gm
from .arguments import GroundMotionError, check_positive, check_samples, check_zeta
from .records import Record


@dataclass(frozen=True)
class ResponseSpectrum:
    periods: np.ndarray  # s
    sd: np.ndarray  # relative displacement spectrum [m]
    psv: np.ndarray  # pseudo-velocity w Sd [m/s]
    psa: np.ndarray  # pseudo-acceleration w^2 Sd [m/s^2]
    zeta: float


def response_spectrum(accel, dt, periods, zeta=0.05) -> ResponseSpectrum:
    """Linear SDOF response spectrum of a ground acceleration sampled every ``dt`` seconds.

    Exact for the piecewise-linear record (Nigam & Jennings 1969), peaks taken at the samples;
    T = 0 gives Sd = PSV = 0 and PSA = PGA.  ``accel`` may be a :class:`Record` (then ``dt``
    may be None and the record's uniform step is used)."""
    if isinstance(accel, Record):
        if dt is None:
            if accel.dt is None:
                raise GroundMotionError(
                    "dt", f"record {accel.source} is not uniformly sampled",
                    fix="resample it with martello.ground_motion.records.resample_uniform")
            dt = accel.dt
        accel = accel.accel
    a = check_samples("accel", accel)
    dt = check_positive("dt", dt)
    T = check_samples("periods", periods, scalar_ok=True)
    if np.any(T < 0):
        j = int(np.flatnonzero(T < 0)[0])
        raise GroundMotionError("periods", f"period {float(T[j])!r} at index {j} is negative",
                                fix="periods are >= 0 s (0 gives the PGA)")
    zeta = check_zeta(zeta)
    sd, psv, psa = native_gm.response_spectrum(a, dt, zeta, T)
    return ResponseSpectrum(periods=T, sd=sd, psv=psv, psa=psa, zeta=zeta)


def fourier_amplitude(accel, dt):
    """One-sided Fourier amplitude spectrum: (freq [Hz], amp) with freq_k = k/(n dt) and
    amp_k = dt |X_k|, X the FFTW r2c transform, k = 0 .. n//2 (units of accel times s)."""
    a = check_samples("accel", accel)
    dt = check_positive("dt", dt)
    return native_gm.fourier_amplitude(a, dt)
