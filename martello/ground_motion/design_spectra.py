"""Elastic design spectra of the codes, tabulated code data evaluated in Python:
EN 1998-1:2004 §3.2.2.2 (Type 1 and 2, ground types A-E) and OPCM 3274 (2003) Allegato 2
§3.2.3 (soil classes A-E, seismic zones 1-4). The four branches and the damping correction
are in the package docstring (martello.ground_motion)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .arguments import GroundMotionError, check_finite, check_positive
from .records import STANDARD_GRAVITY


# EN 1998-1:2004 §3.2.2.2(2)P, Table 3.2: recommended Type 1 spectrum (surface-wave
# magnitude Ms > 5.5).  (S, T_B [s], T_C [s], T_D [s]) per ground type.
# Checked against two independent transcriptions of the table: the TCVN 9386:2012 table
# (Vietnam's adoption of EN 1998-1) and the `streng` EC8 module (spectra.py, S/TB/TC/TD).
EC8_TYPE1 = {
    "A": (1.00, 0.15, 0.40, 2.0),
    "B": (1.20, 0.15, 0.50, 2.0),
    "C": (1.15, 0.20, 0.60, 2.0),
    "D": (1.35, 0.20, 0.80, 2.0),
    "E": (1.40, 0.15, 0.50, 2.0),
}
# EN 1998-1:2004 Table 3.3: recommended Type 2 spectrum (Ms <= 5.5).  Same check (the
# `streng` module; a COMSOL EC8 example gives the same row for ground type C).
EC8_TYPE2 = {
    "A": (1.00, 0.05, 0.25, 1.2),
    "B": (1.35, 0.05, 0.25, 1.2),
    "C": (1.50, 0.10, 0.25, 1.2),
    "D": (1.80, 0.10, 0.30, 1.2),
    "E": (1.60, 0.05, 0.25, 1.2),
}
# OPCM 3274 (2003), Allegato 2 §3.2.3 (text as corrected by OPCM 3316, 2 Oct 2003): the
# table of the horizontal elastic spectrum's parameters, B, C and E sharing one row.
# NOT VERIFIED against the Gazzetta Ufficiale text: the search tool found no transcription
# of this table, so these are the values as recalled, with two independent confirmations
# only: soil C's S = 1.25 is the factor the seed paper applies for its soil C, and the shape
# (A as EC8 Type 1 A; D with T_B 0.20, T_C 0.80) is that of EN 1998-1's 2003 drafts, from
# which the ordinance took its spectrum.  Check before relying on soils B, D and E.
OPCM3274_SOIL = {
    "A": (1.00, 0.15, 0.40, 2.0),
    "B": (1.25, 0.15, 0.50, 2.0),
    "C": (1.25, 0.15, 0.50, 2.0),
    "D": (1.35, 0.20, 0.80, 2.0),
    "E": (1.25, 0.15, 0.50, 2.0),
}
# OPCM 3274 (2003), Allegato 1 and Allegato 2 §3.2.1: a_g on type A ground, in g, per zone.
OPCM3274_ZONE_AG = {1: 0.35, 2: 0.25, 3: 0.15, 4: 0.05}

_CODE_T_VALID = 4.0  # s: both codes give the four branches for T <= 4 s only


def damping_correction(damping_percent):
    """eta = sqrt(10/(5 + xi)) >= 0.55, xi the viscous damping in percent (EN 1998-1 eq. 3.6;
    OPCM 3274 Allegato 2 §3.2.3 uses the same expression)."""
    xi = check_finite("damping", damping_percent)
    if xi < 0:
        raise GroundMotionError("damping", f"{damping_percent!r} % must be >= 0",
                                fix="viscous damping in percent, e.g. 5")
    return max(math.sqrt(10.0 / (5.0 + xi)), 0.55)


@dataclass(frozen=True)
class DesignSpectrum:
    """A code's horizontal elastic acceleration spectrum Se(T) [m/s^2].

    ``ag`` is the design ground acceleration on type A ground [m/s^2]; the PGA of the
    spectrum, Se(0), is ``ag * S``."""

    code: str
    ground_type: str
    ag: float
    S: float
    TB: float
    TC: float
    TD: float
    damping: float  # percent
    eta: float
    label: str
    t_valid: float = _CODE_T_VALID

    @property
    def pga(self) -> float:
        return self.ag * self.S

    def psa(self, periods):
        """Se(T) for T >= 0 (scalar or array), EN 1998-1 eqs 3.2-3.5."""
        T = np.asarray(periods, dtype=float)
        if np.any(~np.isfinite(T)) or np.any(T < 0):
            raise GroundMotionError("periods", "must be finite and >= 0")
        top = self.ag * self.S * 2.5 * self.eta
        with np.errstate(divide="ignore", invalid="ignore"):
            se = np.where(
                T <= self.TB, self.ag * self.S * (1.0 + T / self.TB * (2.5 * self.eta - 1.0)),
                np.where(T <= self.TC, top,
                         np.where(T <= self.TD, top * self.TC / T,
                                  top * self.TC * self.TD / T ** 2)))
        return se if se.ndim else float(se)

    def tabulate(self, t_max=None, n=2001):
        """(periods, psa) on [0, t_max] with n uniform points plus T_B, T_C, T_D exactly.

        The native synthesis interpolates linearly between the points; with 2001 points on
        [0, 4] s the chord of the 1/T and 1/T^2 branches is within 3e-6 relative of the curve
        (the chord error of x^-p over a step h is about p(p+1)/8 (h/T)^2)."""
        t_max = self.t_valid if t_max is None else check_positive("t_max", t_max)
        T = np.unique(np.concatenate([np.linspace(0.0, t_max, int(n)),
                                      [c for c in (self.TB, self.TC, self.TD) if c < t_max]]))
        return T, np.asarray(self.psa(T), dtype=float)


def _ground_type(ground_type, table, name="ground_type"):
    key = str(ground_type).strip().upper()
    if key not in table:
        raise GroundMotionError(name, f"{ground_type!r} is not one of {', '.join(table)}")
    return key


def eurocode8_spectrum(ag, ground_type, spectrum_type=1, damping=5.0):
    """EN 1998-1:2004 §3.2.2.2 horizontal elastic spectrum; ``ag`` in m/s^2 (a_g = gamma_I
    a_gR), ``spectrum_type`` 1 (Table 3.2) or 2 (Table 3.3), ``damping`` in percent."""
    ag = check_positive("ag", ag)
    if spectrum_type not in (1, 2):
        raise GroundMotionError("spectrum_type", f"{spectrum_type!r} must be 1 or 2",
                                fix="Type 1 for Ms > 5.5, Type 2 otherwise (EN 1998-1 3.2.2.2(2)P)")
    table = EC8_TYPE1 if spectrum_type == 1 else EC8_TYPE2
    key = _ground_type(ground_type, table)
    S, TB, TC, TD = table[key]
    eta = damping_correction(damping)
    return DesignSpectrum(code=f"EN 1998-1 Type {spectrum_type}", ground_type=key, ag=ag, S=S,
                          TB=TB, TC=TC, TD=TD, damping=float(damping), eta=eta,
                          label=f"EN 1998-1 Type {spectrum_type}, ground {key}, "
                                f"ag = {ag / STANDARD_GRAVITY:.4g} g, xi = {damping:g} %")


def opcm3274_spectrum(zone, ground_type, damping=5.0):
    """OPCM 3274 (2003) Allegato 2 §3.2.3 horizontal elastic spectrum for seismic ``zone`` 1-4
    (a_g = 0.35, 0.25, 0.15, 0.05 g) and soil class A-E; ``damping`` in percent.

    Zone 2 on soil C is the seed's case: PGA = 0.25 g x 1.25."""
    if isinstance(zone, bool) or zone not in OPCM3274_ZONE_AG:
        raise GroundMotionError("zone", f"{zone!r} must be 1, 2, 3 or 4")
    key = _ground_type(ground_type, OPCM3274_SOIL)
    S, TB, TC, TD = OPCM3274_SOIL[key]
    ag = OPCM3274_ZONE_AG[zone] * STANDARD_GRAVITY
    eta = damping_correction(damping)
    return DesignSpectrum(code="OPCM 3274", ground_type=key, ag=ag, S=S, TB=TB, TC=TC, TD=TD,
                          damping=float(damping), eta=eta,
                          label=f"OPCM 3274 zone {zone}, soil {key}, xi = {damping:g} %")
