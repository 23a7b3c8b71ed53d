"""Spectrum-compatible synthetic accelerograms (the native martello_gm_synthesize, through
martello.binding.ground_motion), reproducible sets of them, and their CSV files with a
provenance header."""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..binding import ground_motion as native_gm
from ..binding.native import constant, library_versions, version
from ..errors import SolverError
from .arguments import (GroundMotionError, check_finite, check_int, check_positive,
                        check_samples, check_zeta)
from .design_spectra import DesignSpectrum
from .records import Record


@dataclass(frozen=True)
class Envelope:
    """Jennings, Housner & Tsai (1968) type intensity envelope: (t/t_rise)^2, then 1 up to
    t_plateau_end, then exp(-decay (t - t_plateau_end))."""

    t_rise: float
    t_plateau_end: float
    decay: float

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        with np.errstate(divide="ignore", invalid="ignore"):
            rise = (t / self.t_rise) ** 2 if self.t_rise > 0 else np.ones_like(t)
        return np.where(t < self.t_rise, rise,
                        np.where(t <= self.t_plateau_end, 1.0,
                                 np.exp(-self.decay * (t - self.t_plateau_end))))


def default_envelope(duration) -> Envelope:
    """Rise over the first 10 % of the record, stationary to 60 % (10 s of a 20 s record: the
    minimum stationary part EN 1998-1 §3.2.3.1.2 recommends when nothing site-specific is
    known), then an exponential decay down to 5 % at the end."""
    d = check_positive("duration", duration)
    t1, t2 = 0.1 * d, 0.6 * d
    return Envelope(t_rise=t1, t_plateau_end=t2, decay=math.log(20.0) / (d - t2))


@dataclass(frozen=True)
class SynthesisResult:
    accel: np.ndarray  # m/s^2, accel[i] at t = i dt
    dt: float
    seed: int
    iterations: int  # spectral corrections made (all attempts)
    restarts: int  # attempts abandoned for fresh phases
    worst_deviation: float  # max |PSA/target - 1| over the check band, on the native grid
    converged: bool


def _target_arrays(target, t_max_target):
    """(periods, psa, pga, label) from a DesignSpectrum or a (periods, psa) pair."""
    if isinstance(target, DesignSpectrum):
        T, sa = target.tabulate(t_max_target)
        return T, sa, target.pga, target.label
    try:
        periods, psa = target
    except (TypeError, ValueError):
        raise GroundMotionError("target", "must be a DesignSpectrum or a (periods, psa) pair") from None
    T = check_samples("target periods", periods, min_size=2)
    sa = check_samples("target psa", psa, min_size=2)
    if T.size != sa.size:
        raise GroundMotionError("target", f"{T.size} periods but {sa.size} psa values")
    if T[0] < 0 or np.any(np.diff(T) <= 0):
        raise GroundMotionError("target periods", "must be >= 0 and strictly increasing")
    if np.any(sa <= 0):
        raise GroundMotionError("target psa", "must be > 0")
    pga = float(sa[0]) if T[0] == 0.0 else None
    return T, sa, pga, "tabulated target spectrum"


def synthesize(target, *, duration=20.0, dt=0.01, seed=0, pga=None, zeta=0.05, envelope=None,
               band=0.10, t_min=0.15, t_max=2.0, max_iter=1000, t_max_target=None) -> SynthesisResult:
    """One spectrum-compatible accelerogram (the native martello_gm_synthesize; its header
    explains the method).  ``target``: a :class:`DesignSpectrum` or a (periods, psa) pair;
    ``pga`` defaults to the target at T = 0.  ``seed`` is the unsigned 32-bit seed of GSL's
    mt19937.  ``max_iter`` bounds the spectral corrections over all attempts (about 7 ms each
    for a 20 s record at dt = 0.01 s; the OPCM 3274 zone 2 soil C target needed 7-252, median
    65, over 30 seeds).  Does not raise when the band is missed: look at ``converged``."""
    T, sa, pga_target, _ = _target_arrays(target, t_max_target)
    if pga is None:
        if pga_target is None:
            raise GroundMotionError("pga", "the target has no T = 0 point: give pga")
        pga = pga_target
    pga = check_positive("pga", pga)
    duration, dt = check_positive("duration", duration), check_positive("dt", dt)
    n = int(round(duration / dt)) + 1
    if n < 8:
        raise GroundMotionError("duration", f"{duration} s at dt = {dt} s gives {n} samples, "
                                            "needs at least 8")
    zeta = check_zeta(zeta)
    env = default_envelope((n - 1) * dt) if envelope is None else envelope  # as generate_records
    if not isinstance(env, Envelope):
        try:
            env = Envelope(*env)
        except TypeError:
            raise GroundMotionError("envelope", "must be an Envelope or (t_rise, t_plateau_end, "
                                                "decay)") from None
    e = np.array([check_finite("envelope.t_rise", env.t_rise),
                  check_finite("envelope.t_plateau_end", env.t_plateau_end),
                  check_finite("envelope.decay", env.decay)])
    if e[0] < 0 or e[1] < e[0] or e[2] <= 0:
        raise GroundMotionError("envelope", f"{env} needs 0 <= t_rise <= t_plateau_end and decay > 0")
    band = check_positive("band", band)
    t_min, t_max = check_positive("t_min", t_min), check_positive("t_max", t_max)
    t_first = T[0] if T[0] > 0 else T[1]
    if not t_min < t_max:
        raise GroundMotionError("t_min", f"t_min = {t_min} must be < t_max = {t_max}")
    if t_min < max(t_first, 2 * dt):
        raise GroundMotionError("t_min", f"{t_min} s is below {max(t_first, 2 * dt)} s, the "
                                         "shortest period the target and dt allow")
    if t_max > T[-1]:
        raise GroundMotionError("t_max", f"{t_max} s is beyond the target's last period {T[-1]} s")
    max_iter = check_int("max_iter", max_iter, 0)
    seed = check_int("seed", seed, 0)
    if seed >= 2 ** 32:
        raise GroundMotionError("seed", f"{seed} must be < 2**32 (GSL mt19937 uses 32 bits)")

    st, accel, iterations, restarts, deviation = native_gm.synthesize(
        T, sa, pga, zeta, dt, n, e, t_min, t_max, band, max_iter, seed)
    converged = st == 0
    if not converged and st != constant("MARTELLO_ERR_NOT_CONVERGED"):
        native_gm.check_status(st, "spectrum-compatible synthesis", n)
    accel.setflags(write=False)
    return SynthesisResult(accel=accel, dt=dt, seed=seed, iterations=iterations,
                           restarts=restarts, worst_deviation=deviation, converged=converged)


@dataclass(frozen=True)
class SyntheticRecord(Record):
    """A :class:`Record` made by :func:`generate_records`; ``provenance`` holds (key, value)
    text pairs that :func:`write_record_csv` writes into the file header."""

    provenance: tuple = ()

    def provenance_dict(self):
        return dict(self.provenance)


def _record_seed(seed, index):
    """32-bit native seed of record ``index`` of a set: numpy's SeedSequence hashing, which
    is specified bit for bit, so it is the same on every platform."""
    return int(np.random.SeedSequence(entropy=seed, spawn_key=(index,)).generate_state(1)[0])


def generate_records(target, n_records, seed, duration=20.0, dt=0.01, *, zeta=0.05,
                     envelope=None, band=0.10, t_min=0.15, t_max=2.0, max_iter=1000,
                     t_max_target=None, require_band=True):
    """``n_records`` spectrum-compatible accelerograms for ``target`` (a :class:`DesignSpectrum`
    or a (periods, psa) pair), reproducible from ``seed`` (a non-negative integer).

    Record i is synthesised with the native seed derived from (seed, i) by
    :func:`numpy.random.SeedSequence`; each record's PGA equals the target's PGA, its PSA is
    within ``band`` of the target on [t_min, t_max] (checked on the native period grid, 600
    points per decade; between its points the PSA, which has kinks, may stray up to a few
    tenths of a percent further) and its final velocity and displacement are zero to
    rounding.
    With ``require_band`` a record that misses the band raises :class:`SolverError`."""
    n_records = check_int("n_records", n_records, 1)
    seed = check_int("seed", seed, 0)
    _, _, _, label = _target_arrays(target, t_max_target)
    duration, dt = check_positive("duration", duration), check_positive("dt", dt)
    env = default_envelope(round(duration / dt) * dt) if envelope is None else envelope
    records = []
    for i in range(n_records):
        native_seed = _record_seed(seed, i)
        res = synthesize(target, duration=duration, dt=dt, seed=native_seed, zeta=zeta,
                         envelope=env, band=band, t_min=t_min, t_max=t_max, max_iter=max_iter,
                         t_max_target=t_max_target)
        if require_band and not res.converged:
            raise SolverError(constant("MARTELLO_ERR_NOT_CONVERGED"), "MARTELLO_ERR_NOT_CONVERGED",
                              f"record {i} (seed {seed}, native seed {native_seed}) is "
                              f"{res.worst_deviation:.1%} off the target after {res.iterations} "
                              f"corrections, band {band:.0%}: raise max_iter or widen the band")
        t = np.arange(res.accel.size) * dt
        env_obj = env if isinstance(env, Envelope) else Envelope(*env)
        provenance = (
            ("generator", f"martello {version()} martello_gm_synthesize"),
            ("native libraries", library_versions()),
            ("target", label),
            ("pga m/s2", f"{float(np.max(np.abs(res.accel))):.17g}"),
            ("seed", str(seed)),
            ("record index", f"{i} of {n_records}"),
            ("native seed", str(native_seed)),
            ("zeta", f"{zeta:g}"),
            ("band", f"{band:g} on [{t_min:g}, {t_max:g}] s"),
            ("envelope", f"t_rise={env_obj.t_rise:g} s, t_plateau_end={env_obj.t_plateau_end:g} s, "
                         f"decay={env_obj.decay:.6g} 1/s"),
            ("baseline", "envelope-weighted linear correction: final velocity (trapezoid) and "
                         "displacement (exact, piecewise-linear) zero"),
            ("iterations", str(res.iterations)),
            ("restarts", str(res.restarts)),
            ("worst deviation", f"{res.worst_deviation:.6g}"),
        )
        records.append(SyntheticRecord(
            t=t, accel=res.accel, dt=dt, source="martello.ground_motion.generate_records",
            units_in_file="m/s2",
            description=f"synthetic, {label}, seed {seed} record {i + 1}/{n_records}, "
                        f"PSA within {res.worst_deviation:.1%} on [{t_min:g}, {t_max:g}] s",
            provenance=provenance))
    return records


def write_record_csv(path, record) -> Path:
    """Write ``record`` as CSV ``time,accel_m_s2`` with a provenance header.

    The header is ``#`` comment lines: the source and description, one ``# key: value`` line
    per provenance entry of a :class:`SyntheticRecord`, then ``# units: m/s2`` and the column
    line, so :func:`martello.ground_motion.records.read_csv_record` reads the file back exactly
    (numbers have 17 significant digits)."""
    def one_line(s):
        return " ".join(str(s).split())

    head = ["# martello ground-motion record",
            f"# source: {one_line(record.source)}",
            f"# original units: {record.units_in_file}"]
    if record.description:
        head.append(f"# description: {one_line(record.description)}")
    for key, value in getattr(record, "provenance", ()):
        key = one_line(key)
        if key.lower().startswith("units"):  # '# units:' is the line the reader interprets
            key = "provenance " + key
        head.append(f"# {key}: {one_line(value)}")
    head += ["# units: m/s2", "time,accel_m_s2"]
    body = [f"{t:.17g},{a:.17g}" for t, a in zip(record.t.tolist(), record.accel.tolist())]
    p = Path(path)
    try:
        p.write_text("\n".join(head + body) + "\n", encoding="utf-8")
    except OSError as exc:
        raise GroundMotionError("path", f"cannot write {p}: {exc.strerror or exc}",
                                fix="check that the directory exists and is writable") from None
    return p


def write_records_csv(records, directory, stem="record"):
    """Write each record to ``directory/<stem>_<i>.csv`` (i from 1); returns the paths."""
    d = Path(directory)
    d.mkdir(parents=True, exist_ok=True)
    return [write_record_csv(d / f"{stem}_{i}.csv", r) for i, r in enumerate(records, start=1)]
