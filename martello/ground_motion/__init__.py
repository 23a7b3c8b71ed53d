"""Ground motion: elastic design spectra, response spectra, Fourier amplitude spectra and
spectrum-compatible synthetic accelerograms.

The numerics run in the native library (``c/ground_motion.c``, FFTW and GSL, bound in
martello.binding.ground_motion); this package validates every argument before the call (so
that an error names the argument) and turns status codes into exceptions.  The design
spectra are tabulated code data and are evaluated here, in Python.

Modules: ``records`` (record readers), ``design_spectra``, ``record_spectra`` (response and
Fourier spectra of a record), ``synthesis`` (spectrum-compatible accelerograms and their
files), ``arguments`` (the argument checks).  The package re-exports their public names, so
``martello.ground_motion.generate_records`` is the name the record files' provenance gives.

Units are SI: periods and times in s, accelerations in m/s^2 (``g`` where a code gives a
value in g is ``martello.ground_motion.records.STANDARD_GRAVITY``).

Design spectra
--------------
* :func:`eurocode8_spectrum`: EN 1998-1:2004 §3.2.2.2, horizontal elastic spectrum,
  recommended Type 1 (Table 3.2) and Type 2 (Table 3.3), ground types A-E.
* :func:`opcm3274_spectrum`: Ordinanza P.C.M. 3274 (20 March 2003), Allegato 2 §3.2.3,
  horizontal elastic spectrum, soil classes A-E, seismic zones 1-4.

Both use the same four branches (EN 1998-1 eqs 3.2-3.5) and the damping correction
eta = sqrt(10/(5 + xi)) >= 0.55 (eq. 3.6, xi in percent)::

    0    <= T <= T_B:  Se = a_g S [1 + T/T_B (2.5 eta - 1)]
    T_B  <= T <= T_C:  Se = a_g S 2.5 eta
    T_C  <= T <= T_D:  Se = a_g S 2.5 eta T_C / T
    T_D  <= T <= 4 s:  Se = a_g S 2.5 eta T_C T_D / T^2

Beyond 4 s neither code gives this formula (EN 1998-1 refers to its Annex A); the T^-2
branch is simply continued, and :attr:`DesignSpectrum.t_valid` says where the code ends.
"""

from .arguments import GroundMotionError
from .design_spectra import (EC8_TYPE1, EC8_TYPE2, OPCM3274_SOIL, OPCM3274_ZONE_AG,
                             DesignSpectrum, damping_correction, eurocode8_spectrum,
                             opcm3274_spectrum)
from .record_spectra import ResponseSpectrum, fourier_amplitude, response_spectrum
from .synthesis import (Envelope, SynthesisResult, SyntheticRecord, default_envelope,
                        generate_records, synthesize, write_record_csv, write_records_csv)

__all__ = [
    "GroundMotionError",
    "DesignSpectrum", "eurocode8_spectrum", "opcm3274_spectrum", "damping_correction",
    "EC8_TYPE1", "EC8_TYPE2", "OPCM3274_SOIL", "OPCM3274_ZONE_AG",
    "ResponseSpectrum", "response_spectrum", "fourier_amplitude",
    "Envelope", "default_envelope",
    "SynthesisResult", "synthesize",
    "SyntheticRecord", "generate_records", "write_record_csv", "write_records_csv",
]
