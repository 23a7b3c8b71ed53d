"""Ground-motion record readers: two-column CSV/text files and PEER NGA ``.AT2`` files.

Every reader returns a :class:`Record` whose acceleration is in m/s^2, whatever the
file used.  Every problem with a file is reported as a :class:`~martello.errors.RecordError`
naming the file, the line where the problem is (when there is one) and how to fix it.

Units
-----
The ``units`` argument accepts exactly ``"g"``, ``"m/s2"`` or ``"cm/s2"``.  Unit text
*inside* files (the 3rd line of an AT2 file, a ``# units:`` comment in a CSV file) may
use the common spellings: ``G``, ``M/S2``, ``M/S/S``, ``M/S^2``, ``CM/S2``, ``CM/S/S``,
``CM/SEC/SEC``, ``GAL`` ... (case-insensitive).  A file that states its units always
wins over a default, and never silently loses to an argument: if the caller passes
``units`` and the file states different units, the read fails (see
:func:`read_csv_record`).
"""

from __future__ import annotations

import dataclasses
import math
import re
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import RecordError
from ..paths import MiB, UnreadableFile, read_input

__all__ = [
    "Record",
    "read_record",
    "read_csv_record",
    "read_at2",
    "write_csv_record",
    "resample_uniform",
    "pga",
    "arias_intensity",
    "STANDARD_GRAVITY",
    "VALID_UNITS",
]

STANDARD_GRAVITY = 9.80665  # m/s^2, exact by definition (CGPM 1901)
VALID_UNITS = ("g", "m/s2", "cm/s2")
_VALID_UNITS_TEXT = '"g", "m/s2" or "cm/s2"'

# Relative tolerance under which the time steps of a record count as uniform.
_UNIFORM_RTOL = 1e-9
# A record file is at most this large: a PEER NGA record is under 1 MB, a million samples of
# CSV about 40 MB.
RECORD_LIMIT = 256 * MiB
# Messages quote at most this many characters of a file: enough for any number, too few to
# copy out a file that is not a record (a scene may name any path; docs/behaviour.md).
_QUOTE = 20


def _quote(text):
    """repr of a piece of a file, cut to _QUOTE characters."""
    text = str(text)
    return repr(text) if len(text) <= _QUOTE else repr(text[:_QUOTE]) + "…"


@dataclass(frozen=True)
class Record:
    """One ground-motion acceleration record.

    The arrays are made read-only so that a frozen record cannot be changed in place;
    copy them (``rec.accel.copy()``) to modify.
    """

    t: np.ndarray  # times [s], strictly increasing, starting where the file says (usually 0)
    accel: np.ndarray  # ground acceleration [m/s^2] (always SI after reading)
    dt: float | None  # uniform step if the samples are uniform (to 1e-9 relative), else None
    source: str  # path as given
    units_in_file: str  # "g", "m/s2", "cm/s2"
    description: str  # header text (AT2 title line) or ""

    def __post_init__(self):
        for name in ("t", "accel"):
            arr = np.array(getattr(self, name), dtype=float)  # own copy
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)


# --------------------------------------------------------------------------- units

def _build_unit_aliases():
    aliases = {"g": "g", "gal": "cm/s2"}
    tails = ("s2", "s^2", "s**2", "s/s", "s²", "sec2", "sec^2", "sec**2", "sec/sec", "sec²")
    for prefix, canon in (("m", "m/s2"), ("cm", "cm/s2")):
        for tail in tails:
            aliases[f"{prefix}/{tail}"] = canon
    return aliases


_UNIT_ALIASES = _build_unit_aliases()


def _units_from_text(text):
    """Canonical unit name for a unit spelling found in a file, or None if unknown."""
    key = re.sub(r"\s+", "", text).lower().rstrip(".,;")
    return _UNIT_ALIASES.get(key)


def _check_units_arg(units, path):
    """Validate the ``units`` argument (exact canonical names only). None passes."""
    if units is None or units in VALID_UNITS:
        return units
    raise RecordError(path, f"units={units!r} is not a valid unit",
                      fix=f"use one of {_VALID_UNITS_TEXT}")


def _to_si_factor(units, g):
    return {"g": g, "m/s2": 1.0, "cm/s2": 0.01}[units]


def _finite_float(x):
    """float(x) if x is a finite real number (bool excluded), else None."""
    if isinstance(x, (bool, str, bytes)):
        return None
    try:
        x = float(x)
    except (TypeError, ValueError):
        return None
    return x if math.isfinite(x) else None


def _check_g(g, path):
    value = _finite_float(g)
    if value is None or value <= 0:
        raise RecordError(path, f"g={g!r} must be a positive finite number",
                          fix=f"leave the default g={STANDARD_GRAVITY}")
    return value


# --------------------------------------------------------------------------- file text

def _read_lines(path):
    """Lines of a text file, numbered from 1 as an editor shows them."""
    try:
        raw = read_input(path, RECORD_LIMIT)
    except UnreadableFile as exc:
        if exc.problem == "does not exist":
            raise RecordError(path, "file not found",
                              fix="check the path; relative paths start at the working directory") from None
        if exc.problem.startswith("is a directory"):
            raise RecordError(path, "is a directory, not a record file",
                              fix="give the path of a .AT2, .csv or .txt file") from None
        raise RecordError(path, exc.problem, fix=exc.fix) from None
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError:
        text = raw.decode("latin-1")  # old station names; numbers are ASCII either way
    if not text.strip():
        raise RecordError(path, "file is empty (no samples)",
                          fix="the file holds no data; re-export or re-download the record")
    return text.replace("\r\n", "\n").replace("\r", "\n").split("\n")


_NUMBER_RE = re.compile(r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eEdD][+-]?\d+)?")
_NONFINITE_RE = re.compile(r"[+-]?(?:nan|inf|infinity)", re.IGNORECASE)


def _parse_number(token):
    """float for a plain or scientific number (Fortran D exponent allowed), 'nonfinite' for
    nan/inf spellings, None for anything else."""
    if _NUMBER_RE.fullmatch(token):
        x = float(token.replace("d", "e").replace("D", "E"))
        return x if math.isfinite(x) else "nonfinite"       # 1e999 overflows to inf
    if _NONFINITE_RE.fullmatch(token):
        return "nonfinite"
    return None


def _uniform_step(t):
    """Mean step if every step equals it to _UNIFORM_RTOL relative, else None."""
    h = (t[-1] - t[0]) / (len(t) - 1)
    if np.max(np.abs(np.diff(t) - h)) <= _UNIFORM_RTOL * h:
        return float(h)
    return None


# --------------------------------------------------------------------------- CSV

_UNITS_COMMENT_RE = re.compile(r"#\s*units\s*[:=]\s*(.*?)\s*$", re.IGNORECASE)
_CSV_SPLIT_RE = re.compile(r"\s*,\s*|\s+")


def read_csv_record(path, *, units=None, g=STANDARD_GRAVITY) -> Record:
    """Read a two-column (time [s], acceleration) text record.

    Format:

    * columns separated by a comma (spaces around it allowed) or by whitespace;
    * blank lines are ignored; lines whose first non-blank character is ``#`` are comments;
    * at most one header line, which must come before the first sample and in which no
      field is a number (e.g. ``time,accel``); it is skipped, its text is not interpreted;
    * every other line holds exactly two numbers: time, then acceleration.  Times must be
      finite and strictly increasing, accelerations finite; at least 2 samples.

    Units rule (a comment ``# units: <u>`` anywhere in the file declares the file's units):

    =====================  ========================  ==========================
    ``units`` argument      file has ``# units:``     units used
    =====================  ========================  ==========================
    None (default)          no                        m/s2
    None                    yes                       the file's
    given                   no                        the argument's
    given                   yes, same units           those units
    given                   yes, different units      RecordError (conflict)
    =====================  ========================  ==========================

    A conflict is an error rather than a silent choice because either choice is wrong by
    a factor of up to 981 for someone.  Two ``# units:`` lines that disagree are an error.

    ``g`` converts records in g to m/s^2.  ``Record.dt`` is the mean step when all steps
    equal it to 1e-9 relative, else None.
    """
    _check_units_arg(units, path)
    g = _check_g(g, path)
    lines = _read_lines(path)

    file_units = None  # (canonical, line number)
    header_seen = False
    times, accels, where = [], [], []
    prev_text = None
    for num, raw in enumerate(lines, start=1):
        line = raw.strip()
        if not line:
            continue
        if line.startswith("#"):
            m = _UNITS_COMMENT_RE.match(line)
            if m:
                canon = _units_from_text(m.group(1))
                if canon is None:
                    raise RecordError(path, f"unknown units {_quote(m.group(1))} in the units comment",
                                      line=num,
                                      fix=f"write '# units: g', '# units: m/s2' or '# units: cm/s2'")
                if file_units is not None and file_units[0] != canon:
                    raise RecordError(path, f"units comment says {canon!r} but line "
                                            f"{file_units[1]} already said {file_units[0]!r}",
                                      line=num, fix="keep a single '# units:' line")
                file_units = (canon, num)
            continue

        fields = _CSV_SPLIT_RE.split(line)
        values = [_parse_number(f) for f in fields]
        if not times and not header_seen and all(v is None for v in values):
            header_seen = True  # the one optional header line
            continue
        if len(fields) != 2:
            raise RecordError(path, f"expected 2 columns (time, acceleration), found {len(fields)}",
                              line=num,
                              fix="keep exactly two columns separated by a comma or whitespace")
        for col, (field, value) in enumerate(zip(fields, values)):
            name = ("time", "acceleration")[col]
            if value is None:
                problem = f"{name} value {_quote(field)} is not a number"
                fix = "fix the value"
                if not times and header_seen:
                    fix += "; only one header line is allowed, make other text lines '#' comments"
                elif not times:
                    fix += "; a header line must be all text"
                raise RecordError(path, problem, line=num, fix=fix)
            if value == "nonfinite":
                raise RecordError(path, f"{name} value {_quote(field)} is not finite", line=num,
                                  fix="replace the NaN/inf by a measured value or trim the record")
        t, a = values
        if times and not t > times[-1]:
            kind = "repeated" if t == times[-1] else "decreasing"
            raise RecordError(path, f"{kind} time: t={_quote(fields[0])[1:-1]} on line {num} "
                                    f"after t={_quote(prev_text)[1:-1]} "
                                    f"on line {where[-1]}",
                              line=num, fix="times must be strictly increasing; remove or reorder samples")
        prev_text = fields[0]
        times.append(t)
        accels.append(a)
        where.append(num)

    if not times:
        raise RecordError(path, "no samples (only comments/header)",
                          fix="add 'time, acceleration' lines after the header")
    if len(times) < 2:
        raise RecordError(path, "only 1 sample; a record needs at least 2", line=where[0],
                          fix="check the file is complete")

    if units is not None and file_units is not None and units != file_units[0]:
        raise RecordError(path, f"the file declares units {file_units[0]!r} but units={units!r} was passed",
                          line=file_units[1],
                          fix="drop the units argument to use the file's, or correct the '# units:' line")
    used = units or (file_units[0] if file_units else "m/s2")

    t = np.asarray(times, dtype=float)
    accel = np.asarray(accels, dtype=float) * _to_si_factor(used, g)
    return Record(t=t, accel=accel, dt=_uniform_step(t), source=str(path),
                  units_in_file=used, description="")


# --------------------------------------------------------------------------- PEER AT2

# The smallest DT taken (1 MHz): accelerographs and shake tables sample at 50 Hz to 10 kHz,
# and a subnormal DT would put a whole record into the first femtoseconds of a run.
MIN_DT = 1e-6
_AT2_FORMS = ("'NPTS=  5590, DT=   .0050 SEC', 'NPTS= 5590 DT= 0.0050 SEC' "
              "or '  5590    .0050    NPTS, DT'")
_NPTS_KEYED_RE = re.compile(r"\bNPTS\s*=\s*([^\s,]*)", re.IGNORECASE)
_DT_KEYED_RE = re.compile(r"\bDT\s*=\s*([^\s,]*)", re.IGNORECASE)
_FIXED_RE = re.compile(r"\s*(\S+)\s+(\S+)\s+NPTS\s*,?\s*DT\b", re.IGNORECASE)
_UNITS_LINE_RE = re.compile(r"\bUNITS?\s+(?:OF\s+)?(\S+)", re.IGNORECASE)


def _parse_npts_dt(path, line):
    """(npts, dt) from the 4th header line, in any of the common variants."""
    m = _FIXED_RE.match(line)
    if m:
        npts_txt, dt_txt = m.group(1), m.group(2)
    else:
        mn, md = _NPTS_KEYED_RE.search(line), _DT_KEYED_RE.search(line)
        if not mn or not md:
            missing = " and ".join(k for k, mm in (("NPTS", mn), ("DT", md)) if not mm)
            raise RecordError(path, f"header line has no {missing}: {_quote(line.strip())}", line=4,
                              fix=f"the 4th line of a PEER AT2 file reads like {_AT2_FORMS}")
        npts_txt, dt_txt = mn.group(1), md.group(1)

    npts = _parse_number(npts_txt)
    if not isinstance(npts, float) or npts != int(npts) or npts < 0:   # "nonfinite": 1e400
        raise RecordError(path, f"NPTS {_quote(npts_txt)} is not a non-negative whole number", line=4,
                          fix="NPTS is the number of samples, e.g. 'NPTS=  5590'")
    dt = _parse_number(dt_txt)
    if not isinstance(dt, float):
        raise RecordError(path, f"DT {_quote(dt_txt)} is not a finite number", line=4,
                          fix="DT is the time step in seconds, e.g. 'DT=   .0050 SEC'")
    if not dt > 0:
        raise RecordError(path, f"DT={dt_txt} is not positive", line=4,
                          fix="DT is the time step in seconds and must be > 0")
    if dt < MIN_DT:
        raise RecordError(path, f"DT={dt_txt} s is no sampling step of an accelerogram", line=4,
                          fix=f"DT is the time step in seconds, at least {MIN_DT:g} s (instruments "
                              "sample at 50 Hz to 10 kHz): is the header misread?")
    return int(npts), dt


def _parse_at2_units(path, line):
    upper = line.upper()
    for kind in ("VELOCITY", "DISPLACEMENT"):
        if kind in upper:
            raise RecordError(path, f"this is a {kind.lower()} record, not an acceleration record",
                              line=3, fix="use the .AT2 (acceleration) file of the record")
    m = _UNITS_LINE_RE.search(line)
    if not m:
        raise RecordError(path, "no units on the units line", line=3,
                          fix="the 3rd line of a PEER AT2 file reads 'ACCELERATION TIME SERIES IN UNITS OF G'")
    canon = _units_from_text(m.group(1))
    if canon is None:
        raise RecordError(path, f"unknown units {_quote(m.group(1))}", line=3,
                          fix="known units are G, M/S2 (M/S/S) and CM/S2 (CM/S/S, GAL)")
    return canon


def read_at2(path, *, g=STANDARD_GRAVITY) -> Record:
    """Read a PEER NGA ``.AT2`` acceleration file.

    Layout: line 1 title (kept as ``description``), line 2 event/date/station, line 3
    ``ACCELERATION TIME SERIES IN UNITS OF G`` (units G, M/S2, CM/S2 and their usual
    spellings are understood), line 4 NPTS and DT in one of the variants
    ``NPTS=  5590, DT=   .0050 SEC``, ``NPTS= 5590 DT= 0.0050 SEC`` or the old fixed
    ``  5590    .0050    NPTS, DT``; then the NPTS values, any number per line, separated
    by whitespace.  The number of values must equal NPTS.  ``t = i*DT`` (t0 = 0),
    ``Record.dt = DT``, acceleration converted to m/s^2 with ``g``.
    """
    g = _check_g(g, path)
    lines = _read_lines(path)
    while lines and not lines[-1].strip():
        lines.pop()
    if len(lines) < 4:
        raise RecordError(path, f"header incomplete: {len(lines)} line(s), a PEER AT2 header has 4",
                          line=len(lines),
                          fix="lines: title, event/date/station, 'ACCELERATION TIME SERIES IN UNITS OF G', "
                              "NPTS/DT")
    description = lines[0].strip()
    units = _parse_at2_units(path, lines[2])
    npts, dt = _parse_npts_dt(path, lines[3])

    values = []
    first_line = last_line = None
    for num, raw in enumerate(lines[4:], start=5):
        tokens = raw.split()
        if not tokens:
            continue
        for tok in tokens:
            v = _parse_number(tok)
            if v is None:
                raise RecordError(path, f"value {_quote(tok)} is not a number", line=num,
                                  fix="values are plain or scientific numbers separated by whitespace")
            if v == "nonfinite":
                raise RecordError(path, f"value {_quote(tok)} is not finite", line=num,
                                  fix="replace the NaN/inf by a measured value or re-download the record")
            values.append(v)
        first_line = first_line or num
        last_line = num

    if npts == 0 or not values:
        raise RecordError(path, f"no samples (NPTS={npts}, {len(values)} values)", line=4,
                          fix="the file holds no data; re-download the record")
    if len(values) != npts:
        raise RecordError(path, f"NPTS={npts} in the header but {len(values)} values follow "
                                f"(lines {first_line}-{last_line})",
                          line=4, fix="the file may be truncated; re-download it or correct NPTS")
    if npts < 2:
        raise RecordError(path, "only 1 sample; a record needs at least 2", line=4,
                          fix="check the file is complete")

    t = np.arange(npts) * dt
    if not math.isfinite(t[-1]):
        raise RecordError(path, f"NPTS x DT = {npts} x {dt!r} s is no finite duration", line=4,
                          fix="DT is the time step in seconds, e.g. 'DT=   .0050 SEC'")
    accel = np.asarray(values, dtype=float) * _to_si_factor(units, g)
    return Record(t=t, accel=accel, dt=dt, source=str(path), units_in_file=units,
                  description=description)


# --------------------------------------------------------------------------- dispatch

_FORMATS = {"at2": "at2", "peer": "at2", "csv": "csv", "txt": "csv"}
_EXTENSIONS = {".at2": "at2", ".csv": "csv", ".txt": "csv"}


def read_record(path, *, fmt=None, units=None, scale=1.0, g=STANDARD_GRAVITY) -> Record:
    """Read a ground-motion record, PEER ``.AT2`` or two-column CSV/text.

    ``fmt``: ``"at2"`` (alias ``"peer"``) or ``"csv"`` (alias ``"txt"``); None chooses by
    extension: ``.at2`` (any case) -> PEER, ``.csv``/``.txt`` (any case) -> CSV.

    ``units``: see :func:`read_csv_record` for the rule.  AT2 files always state their
    units; passing different ``units`` for one is an error.

    ``scale`` multiplies the acceleration after conversion to m/s^2 (e.g. 1.25 for a soil
    factor); ``Record.units_in_file`` still tells the file's units.
    """
    _check_units_arg(units, path)
    scale_value = _finite_float(scale)
    if scale_value is None:
        raise RecordError(path, f"scale={scale!r} must be a finite number", fix="e.g. scale=1.25")

    if fmt is None:
        ext = Path(str(path)).suffix.lower()
        kind = _EXTENSIONS.get(ext)
        if kind is None:
            raise RecordError(path, f"unknown record extension {ext or '(none)'!r}; accepted: "
                                    ".AT2 (PEER NGA), .csv or .txt (two-column time, acceleration)",
                              fix="rename the file or pass fmt='at2' or fmt='csv'")
    else:
        kind = _FORMATS.get(str(fmt).lower())
        if kind is None:
            raise RecordError(path, f"unknown format fmt={fmt!r}", fix="use fmt='at2' (PEER NGA) or fmt='csv'")

    if kind == "at2":
        rec = read_at2(path, g=g)
        if units is not None and units != rec.units_in_file:
            raise RecordError(path, f"the file declares units {rec.units_in_file!r} but units={units!r} was passed",
                              line=3, fix="drop the units argument; AT2 files state their own units")
    else:
        rec = read_csv_record(path, units=units, g=g)

    if scale_value != 1.0:
        rec = dataclasses.replace(rec, accel=rec.accel * scale_value)
    return rec


# --------------------------------------------------------------------------- writing

def write_csv_record(path, record) -> None:
    """Write ``record`` as CSV ``time,accel_m_s2`` (acceleration in m/s^2).

    The file starts with comment lines giving the source, the original units, the
    description and ``# units: m/s2``, so :func:`read_csv_record` reads it back in the
    right units.  Numbers are written with 17 significant digits, so reading the file
    back reproduces ``t`` and ``accel`` exactly.
    """
    def one_line(s):
        return " ".join(str(s).split())

    head = [
        "# martello ground-motion record",
        f"# source: {one_line(record.source)}",
        f"# original units: {record.units_in_file}",
    ]
    if record.description:
        head.append(f"# description: {one_line(record.description)}")
    head += ["# units: m/s2", "time,accel_m_s2"]
    body = [f"{t:.17g},{a:.17g}" for t, a in zip(record.t.tolist(), record.accel.tolist())]
    try:
        Path(path).write_text("\n".join(head + body) + "\n", encoding="utf-8")
    except OSError as exc:
        raise RecordError(path, f"cannot write file: {exc.strerror or exc}",
                          fix="check that the directory exists and is writable") from None


# --------------------------------------------------------------------------- processing

def resample_uniform(record, dt) -> Record:
    """Linear interpolation of ``record`` onto the uniform grid ``t0 + k*dt``.

    The grid starts at the first sample and stops at the last grid point not after the
    last sample (a point within 1e-9*dt of it counts as on it and is placed exactly on
    it); nothing is extrapolated, so a tail shorter than ``dt`` is dropped.  No
    anti-alias filter is applied: when ``dt`` is coarser than the record's step, peaks
    between grid points are lost.
    """
    step = _finite_float(dt)
    if step is None or step <= 0:
        raise RecordError(record.source, f"resample step dt={dt!r} must be a positive finite number",
                          fix="e.g. dt=0.005")
    dt = step
    t0, t_end = float(record.t[0]), float(record.t[-1])
    n_steps = int(math.floor((t_end - t0) / dt + 1e-9))
    if n_steps < 1:
        raise RecordError(record.source, f"resample step dt={dt} is longer than the record "
                                         f"({t_end - t0} s)", fix="use a smaller dt")
    t = t0 + np.arange(n_steps + 1) * dt
    t[-1] = min(t[-1], t_end)
    accel = np.interp(t, record.t, record.accel)
    return Record(t=t, accel=accel, dt=float(dt), source=record.source,
                  units_in_file=record.units_in_file, description=record.description)


def pga(record) -> float:
    """Peak ground acceleration: max |accel| over the samples [m/s^2]."""
    return float(np.max(np.abs(record.accel)))


def arias_intensity(record, *, g=STANDARD_GRAVITY) -> float:
    """Arias intensity  Ia = pi/(2g) * integral a(t)^2 dt  [m/s].

    The integral is the trapezoidal rule over the record's own samples (uniform or not);
    ``a`` is in m/s^2 and ``g`` is gravity in m/s^2 (standard gravity by default).
    """
    g = _check_g(g, record.source)
    a2 = np.square(record.accel)
    return float(math.pi / (2.0 * g) * np.trapezoid(a2, record.t))
