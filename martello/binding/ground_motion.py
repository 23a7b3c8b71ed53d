"""The ground-motion functions of libmartello (c/ground_motion.c, FFTW and GSL): their
prototypes, declared on the library that martello.binding.native loads, and one call each.

The callers (martello.ground_motion) validate every argument first, so that an error names
it; here arrays go in as C-contiguous float64, a negative status raises SolverError, and the
outputs come back as numpy arrays and Python numbers."""

import ctypes
from functools import lru_cache

import numpy as np

from ..errors import MartelloError, SolverError
from .native import constant, lib, memory_message, status_name

_DOUBLE_P = np.ctypeslib.ndpointer(dtype=np.float64, flags="C_CONTIGUOUS")


@lru_cache(maxsize=None)
def library():
    """The loaded library with the ground-motion prototypes declared on it."""
    L = lib()
    c_int, c_double = ctypes.c_int, ctypes.c_double
    protos = {
        "martello_gm_response_spectrum": (c_int, [_DOUBLE_P, c_int, c_double, c_double,
                                                  _DOUBLE_P, c_int, _DOUBLE_P, _DOUBLE_P,
                                                  _DOUBLE_P]),
        "martello_gm_fourier_amplitude": (c_int, [_DOUBLE_P, c_int, c_double, _DOUBLE_P,
                                                  _DOUBLE_P, ctypes.POINTER(c_int)]),
        "martello_gm_synthesize": (c_int, [_DOUBLE_P, _DOUBLE_P, c_int, c_double, c_double,
                                           c_double, c_int, _DOUBLE_P, c_double, c_double,
                                           c_double, c_int, ctypes.c_ulong, _DOUBLE_P,
                                           ctypes.POINTER(c_int), ctypes.POINTER(c_int),
                                           ctypes.POINTER(c_double)]),
    }
    for name, (res, args) in protos.items():
        try:
            fn = getattr(L, name)
        except AttributeError:
            raise MartelloError(f"the native library has no {name}: rebuild it "
                                "(cmake -S . -B build && cmake --build build)") from None
        fn.restype, fn.argtypes = res, args
    return L


def check_status(status, what, samples):
    """Raise SolverError on a negative status (out of memory: the library's line for the
    workspace of a record of that many samples, which FFTW and GSL allocate); return the
    status otherwise."""
    if status == constant("MARTELLO_ERR_MEMORY"):
        what = memory_message(f"the workspace of the {what} of a record of {samples} samples",
                              fix="use a shorter record (fewer samples)")
    if status < 0:
        raise SolverError(status, status_name(status), what)
    return status


def response_spectrum(accel, dt, zeta, periods):
    """(sd, psv, psa) of the ground acceleration accel at the periods."""
    sd, psv, psa = np.empty(periods.size), np.empty(periods.size), np.empty(periods.size)
    check_status(library().martello_gm_response_spectrum(accel, accel.size, dt, zeta, periods,
                                                         periods.size, sd, psv, psa),
                 "response spectrum", accel.size)
    return sd, psv, psa


def fourier_amplitude(accel, dt):
    """(freq, amp): the one-sided Fourier amplitude spectrum of accel."""
    nf = accel.size // 2 + 1
    freq, amp = np.empty(nf), np.empty(nf)
    count = ctypes.c_int(nf)
    check_status(library().martello_gm_fourier_amplitude(accel, accel.size, dt, freq, amp,
                                                         ctypes.byref(count)),
                 "Fourier amplitude spectrum", accel.size)
    return freq[:count.value], amp[:count.value]


def synthesize(periods, psa, pga, zeta, dt, n, envelope, t_min, t_max, band, max_iter, seed):
    """One spectrum-compatible accelerogram of n samples: (status, accel, iterations,
    restarts, worst deviation). The status is returned, not raised: a positive or
    not-converged status is an outcome the caller reports."""
    accel = np.empty(n)
    it, restarts, dev = ctypes.c_int(), ctypes.c_int(), ctypes.c_double()
    st = library().martello_gm_synthesize(periods, psa, periods.size, pga, zeta, dt, n, envelope,
                                          t_min, t_max, band, max_iter, seed, accel,
                                          ctypes.byref(it), ctypes.byref(restarts),
                                          ctypes.byref(dev))
    return st, accel, it.value, restarts.value, dev.value
