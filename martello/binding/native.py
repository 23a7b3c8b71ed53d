"""The ctypes binding to libmartello: the only place Python touches the C API.

Status codes become exceptions here (as dftd4 raises RuntimeError from its error handle):
negative codes raise, positive ones are returned to the caller as outcomes. Every table the
front end shares with the library (integrators, compatibility, settings and their defaults,
counters, energy terms, constants) is read from the library's registry (registry(), and the
functions built on it), never copied here."""

import ctypes
import os
import signal
import threading
from contextlib import contextmanager
from collections import namedtuple
from functools import lru_cache
from pathlib import Path

import numpy as np

from .. import errors
from ..errors import MartelloError, SolverError, DivergenceError, Interrupted
from ..paths import LIBRARIES
_DOUBLE_P = np.ctypeslib.ndpointer(dtype=np.float64, flags="C_CONTIGUOUS")
_INT_P = np.ctypeslib.ndpointer(dtype=np.int32, flags="C_CONTIGUOUS")
_VOID_P = ctypes.c_void_p
# martello_progress_fn of c/martello.h: (user, t, t_end, steps, elapsed) -> 0 to go on
PROGRESS_FN = ctypes.CFUNCTYPE(ctypes.c_int, ctypes.c_void_p, ctypes.c_double, ctypes.c_double,
                               ctypes.c_longlong, ctypes.c_double)


def library_path():
    """MARTELLO_LIB if set, else the installed package's library, else the CMake build tree
    of this checkout (martello.paths.LIBRARIES)."""
    env = os.environ.get("MARTELLO_LIB")
    if env:
        return Path(env)
    return next((p for p in LIBRARIES if p.exists()), LIBRARIES[-1])


@lru_cache(maxsize=None)
def lib():
    path = library_path()
    if not path.exists():
        raise MartelloError(
            f"native library not found at {path}: build it with ./scripts/build "
            "(or point MARTELLO_LIB at libmartello.so)")
    try:
        L = ctypes.CDLL(str(path))
    except OSError as exc:        # not a shared library, another architecture, a missing dependency
        raise MartelloError(f"cannot load the native library {path}: {' '.join(str(exc).split())} "
                            "(rebuild it with ./scripts/build, or point MARTELLO_LIB at a "
                            "working libmartello.so)") from None
    c_int, c_double, c_char_p = ctypes.c_int, ctypes.c_double, ctypes.c_char_p
    protos = {
        "martello_version": (c_char_p, []),
        "martello_library_versions": (c_int, [c_char_p, c_int]),
        "martello_status_name": (c_char_p, [c_int]),
        "martello_registry_shape": (c_int, [c_char_p, ctypes.POINTER(c_int), ctypes.POINTER(c_int)]),
        "martello_registry_column": (c_int, [c_char_p, c_int, c_char_p, c_int]),
        "martello_registry_entry": (c_int, [c_char_p, c_int, c_char_p, c_int, _VOID_P]),
        "martello_registry_text": (c_int, [c_char_p, c_int, c_char_p, c_int]),
        "martello_registry_find": (c_int, [c_char_p, c_char_p, ctypes.POINTER(c_int)]),
        "martello_model_effective_masses": (c_int, [_VOID_P, _DOUBLE_P]),
        "martello_model_create": (c_int, [c_int] * 5 + [ctypes.POINTER(_VOID_P)]),
        "martello_model_free": (None, [ctypes.POINTER(_VOID_P)]),
        "martello_model_set_node": (c_int, [_VOID_P, c_int, c_double, c_double, c_double, c_int]),
        "martello_model_add_link": (c_int, [_VOID_P, c_int, c_int, c_int, _DOUBLE_P]),
        "martello_model_add_contact": (c_int, [_VOID_P, c_int, c_int, c_double, c_int, c_int,
                                               _DOUBLE_P]),
        "martello_model_set_nodes": (c_int, [_VOID_P, c_int, _DOUBLE_P, _DOUBLE_P, _DOUBLE_P,
                                             _INT_P]),
        "martello_model_add_links": (c_int, [_VOID_P, c_int, _INT_P, _INT_P, _INT_P, _DOUBLE_P]),
        "martello_model_add_contacts": (c_int, [_VOID_P, c_int, _INT_P, _INT_P, _DOUBLE_P, _INT_P,
                                                _INT_P, _DOUBLE_P]),
        "martello_model_add_mass_coupling": (c_int, [_VOID_P, c_int, c_int, c_double]),
        "martello_model_add_link_row": (c_int, [_VOID_P, c_int, c_int, _INT_P, _DOUBLE_P, _DOUBLE_P]),
        "martello_model_add_contact_row": (c_int, [_VOID_P, c_int, _INT_P, _DOUBLE_P, c_double, c_int,
                                                   c_int, _DOUBLE_P]),
        "martello_model_add_chain": (c_int, [_VOID_P, c_int, c_int] + [_VOID_P] * 5
                                     + [c_int, c_int, _VOID_P]),
        "martello_model_add_stiffness_block": (c_int, [_VOID_P, c_int, _INT_P, _DOUBLE_P,
                                                       _DOUBLE_P]),
        "martello_model_set_gravity": (c_int, [_VOID_P, c_double]),
        "martello_model_set_influence": (c_int, [_VOID_P, c_int, _DOUBLE_P]),
        "martello_model_add_nodal_force": (c_int, [_VOID_P, c_int, c_int, _DOUBLE_P, c_int,
                                                   _DOUBLE_P, _DOUBLE_P]),
        "martello_model_set_ground_acceleration": (c_int, [_VOID_P, c_int, _DOUBLE_P, c_int,
                                                           _DOUBLE_P, _DOUBLE_P]),
        "martello_model_message": (c_int, [_VOID_P, c_char_p, c_int]),
        "martello_static_solve": (c_int, [_VOID_P, c_double, c_int, _DOUBLE_P, _DOUBLE_P,
                                          _DOUBLE_P, _INT_P, _INT_P, _DOUBLE_P]),
        "martello_run_create": (c_int, [ctypes.POINTER(_VOID_P)]),
        "martello_run_free": (None, [ctypes.POINTER(_VOID_P)]),
        "martello_settings_default": (c_int, [c_int, _VOID_P]),
        "martello_run_set_settings": (c_int, [_VOID_P, _VOID_P]),
        "martello_run_settings": (c_int, [_VOID_P, _VOID_P]),
        "martello_run_set_outputs": (c_int, [_VOID_P, c_int, _INT_P, c_int, _INT_P]),
        "martello_dynamic_run": (c_int, [_VOID_P, _VOID_P]),
        "martello_run_set_progress": (c_int, [_VOID_P, PROGRESS_FN, _VOID_P]),
        "martello_closed_form": (c_int, [c_char_p, _DOUBLE_P, c_int, _DOUBLE_P,
                                         ctypes.POINTER(c_int)]),
        "martello_run_message": (c_int, [_VOID_P, c_char_p, c_int]),
        "martello_run_history_shape": (c_int, [_VOID_P, ctypes.POINTER(c_int), ctypes.POINTER(c_int)]),
        "martello_run_history": (c_int, [_VOID_P, _DOUBLE_P]),
        "martello_run_events": (c_int, [_VOID_P, ctypes.POINTER(c_int), _VOID_P, _VOID_P]),
        "martello_run_counters": (c_int, [_VOID_P, np.ctypeslib.ndpointer(dtype=np.int64, flags="C_CONTIGUOUS")]),
        "martello_run_peaks": (c_int, [_VOID_P] * 10),
        "martello_run_energy": (c_int, [_VOID_P, _DOUBLE_P, _DOUBLE_P]),
        "martello_run_set_link_outputs": (c_int, [_VOID_P, c_int, _INT_P]),
        "martello_run_set_phase_lists": (c_int, [_VOID_P, c_int]),
        "martello_run_set_tracking": (c_int, [_VOID_P, c_int]),
        "martello_run_link_peaks": (c_int, [_VOID_P] * 3),
        "martello_run_abs_peaks": (c_int, [_VOID_P] * 3),
        "martello_run_set_functionals": (c_int, [_VOID_P, c_int, _INT_P, _INT_P, _DOUBLE_P, c_int, _INT_P]),
        "martello_run_functionals": (c_int, [_VOID_P] * 7),
        "martello_run_set_trace": (c_int, [_VOID_P, c_int]),
        "martello_run_trace": (c_int, [_VOID_P, ctypes.POINTER(c_int), _VOID_P]),
        "martello_run_set_trace_nodes": (c_int, [_VOID_P, c_int, _INT_P]),
        "martello_memory_message": (None, [c_char_p, c_double, c_char_p, c_char_p, c_int]),
        "martello_write_csv": (c_int, [c_char_p, c_char_p, _DOUBLE_P, ctypes.c_int64, c_int]),
    }
    for name, (res, args) in protos.items():
        try:
            fn = getattr(L, name)
        except AttributeError:    # a library of another version of martello
            raise MartelloError(f"the native library {path} has no function {name}: it is not "
                                "the version this package needs (rebuild it with ./scripts/build, "
                                "or point MARTELLO_LIB at the matching libmartello.so)") from None
        fn.restype, fn.argtypes = res, args
    return L


# --- the registry --------------------------------------------------------------------

Row = namedtuple("Row", "name values text")   # values: column name -> number


@lru_cache(maxsize=None)
def registry(table):
    """One of the library's tables (fortran/registry.f90, martello_registry_* of
    c/martello.h) as a tuple of Rows in order; "tables" lists them all."""
    L, buf = lib(), ctypes.create_string_buffer(256)
    rows, cols = ctypes.c_int(), ctypes.c_int()
    if L.martello_registry_shape(table.encode(), ctypes.byref(rows), ctypes.byref(cols)) != 0:
        raise KeyError(f"the native library has no table {table!r}")
    def read(status, what):
        if status != 0:
            raise SolverError(status, status_name(status), f"registry table {table!r}: {what} refused")

    columns = []
    for j in range(cols.value):
        read(L.martello_registry_column(table.encode(), j, buf, len(buf)), f"column {j}")
        columns.append(buf.value.decode())
    out, values = [], np.zeros(max(cols.value, 1))
    for i in range(rows.value):
        read(L.martello_registry_entry(table.encode(), i, buf, len(buf), values.ctypes.data_as(_VOID_P)),
             f"row {i}")
        name = buf.value.decode()
        read(L.martello_registry_text(table.encode(), i, buf, len(buf)), f"text of row {i}")
        out.append(Row(name, dict(zip(columns, map(float, values[:cols.value]))), buf.value.decode()))
    return tuple(out)


def value(table, name):
    """The (first) value of the row named name, as an int: a kind, slot or index."""
    for row in registry(table):
        if row.name == name:
            return int(next(iter(row.values.values())))
    raise KeyError(f"the native table {table!r} has no row {name!r}; "
                   f"valid: {', '.join(r.name for r in registry(table))}")


def names(table):
    """The row names of a table ordered by their value (indices of counters, energy, ...)."""
    return tuple(r.name for r in sorted(registry(table), key=lambda r: next(iter(r.values.values()))))


@lru_cache(maxsize=None)
def constants():
    """Every named constant of c/martello.h without its MARTELLO_ prefix ("LAW_KELVIN",
    "NPAR_LINK", "MARTELLO_ERR_ARGUMENT" for status codes), from the registry."""
    out = {r.name: int(r.values["value"]) for r in registry("status")}
    for t in registry("tables"):
        if t.text:
            prefix = t.text.removeprefix("MARTELLO_")
            for r in registry(t.name):
                out[prefix + r.name.upper().replace("-", "_")] = int(r.values["value"])
    return out


def constant(name):
    """A named integer constant of the kernels (law, link kind, scheme, slot, status)."""
    try:
        return constants()[name]
    except KeyError:
        raise KeyError(f"the native library has no constant {name!r}") from None


def integrators():
    return names("integrators")


def adaptive_integrators():
    return tuple(r.name for r in registry("integrators") if r.values["adaptive"])


def compatibility():
    """scheme -> the integrators that run its contacts (the registry's table compatibility)."""
    rows = registry("compatibility")
    return {s: tuple(r.name for r in rows if r.values[s]) for s in names("schemes")}


def settings_read(integrator):
    """The settings the integrator reads (the registry's table reads)."""
    row = next((r for r in registry("reads") if r.name == integrator), None)
    if row is None:
        raise KeyError(f"no integrator {integrator!r}; valid: {', '.join(integrators())}")
    return {k for k, v in row.values.items() if v}


Range = namedtuple("Range", "lo hi lo_open hi_open text")


def settings_ranges():
    """setting -> its valid Range (text: the range in words, as error messages state it)."""
    return {r.name: Range(r.values["min"], r.values["max"], bool(r.values["min_open"]),
                          bool(r.values["max_open"]), r.text) for r in registry("settings")}


def in_range(rng, x):
    return ((x > rng.lo) if rng.lo_open else (x >= rng.lo)) and \
           ((x < rng.hi) if rng.hi_open else (x <= rng.hi))


@lru_cache(maxsize=None)
def settings_type():
    """The ctypes mirror of martello_settings, built from the registry's table settings."""
    ctype = {"double": ctypes.c_double, "int": ctypes.c_int, "bool": ctypes.c_bool}
    types = {int(r.values["value"]): r.name for r in registry("setting_types")}
    fields = [("kind", ctypes.c_int)] + [(r.name, ctype[types[int(r.values["type"])]])
                                         for r in registry("settings")]
    return type("Settings", (ctypes.Structure,), {"_fields_": fields})


def settings(integrator, **values):
    """martello_settings for the integrator: the library's defaults (martello_settings_default)
    with the given fields set."""
    s = settings_type()()
    if lib().martello_settings_default(value("integrators", integrator), ctypes.byref(s)) != 0:
        raise KeyError(integrator)
    for k, v in values.items():
        if k == "kind" or not hasattr(s, k):
            raise KeyError(f"martello_settings has no field {k!r}")
        setattr(s, k, v)
    return s


def settings_defaults(integrator="newmark"):
    """The library's default settings of an integrator, as a dict (kind left out)."""
    s = settings(integrator)
    return {k: getattr(s, k) for k, _ in s._fields_ if k != "kind"}


def counter_names():
    return names("counters")


def energy_names():
    return names("energy")


def event_names():
    return names("events")


def history_columns(nodes, contacts, links):
    """Column names of martello_run_history for these output nodes, contacts and links
    (the registry's table history): "t", "u:<node>", ..., "energy:<term>"."""
    per = {r.name: int(r.values["value"]) for r in registry("history_per")}
    items = {per["once"]: None, per["node"]: nodes, per["contact"]: contacts,
             per["link"]: links, per["energy_term"]: energy_names()}
    cols = []
    for g in registry("history"):
        each = items[int(g.values["per"])]
        cols += [g.name] if each is None else [f"{g.name}:{x}" for x in each]
    return cols


def version():
    return lib().martello_version().decode()


def library_versions():
    buf = ctypes.create_string_buffer(256)
    st = lib().martello_library_versions(buf, len(buf))
    if st < 0:
        raise SolverError(st, status_name(st), "library versions: the buffer was refused")
    return buf.value.decode()


def status_name(status):
    return lib().martello_status_name(status).decode()


def memory_message(what, nbytes=-1.0, fix=None):
    """The library's one out-of-memory line (fortran/status.f90, docs/behaviour.md "When
    memory runs out"): what could not be allocated, nbytes (< 0: not known) and fix (None: a
    smaller scene)."""
    buf = ctypes.create_string_buffer(512)
    lib().martello_memory_message(what.encode(), float(nbytes), fix.encode() if fix else None,
                                  buf, len(buf))
    return buf.value.decode()


def write_csv(path, columns, data):
    """history.csv (docs/results.md): the header of columns, then each row of data (a 2D
    array, one column per name) as %.17g, written by the library (c/csv_writer.c). OSError
    naming the path if it cannot be written."""
    a = np.ascontiguousarray(data, dtype=np.float64)
    if a.ndim != 2 or a.shape[1] != len(columns):
        raise ValueError(f"history of shape {a.shape} for {len(columns)} columns")
    err = lib().martello_write_csv(os.fsencode(path), ",".join(columns).encode(), a,
                                   a.shape[0], a.shape[1])
    if err:
        raise OSError(err, os.strerror(err), str(path))


def _f64(values, n=None):
    a = np.ascontiguousarray(values, dtype=np.float64)
    if n is not None and a.size != n:
        raise ValueError(f"expected {n} values, got {a.size}")
    return a



def _i32(values, n=None):
    a = np.ascontiguousarray(values, dtype=np.int32)
    if n is not None and a.size != n:
        raise ValueError(f"expected {n} values, got {a.size}")
    return a


def _f64_rows(values, n, width):
    """n parameter rows of width values, C order (row i at [i*width:(i+1)*width])."""
    a = np.ascontiguousarray(values, dtype=np.float64)
    if a.shape != (n, width):
        raise ValueError(f"expected {n} rows of {width} values, got shape {a.shape}")
    return a

class _Handle:
    """A native handle with a lifecycle (create ... free) and a last message; the base of
    Model and Run. free() (or a with-block) releases it."""

    _kind = ""   # "model" or "run": names the C functions martello_<kind>_free/_message

    def _create(self, create, *args):
        self._h = _VOID_P()
        st = create(*args, ctypes.byref(self._h))
        if st < 0:
            raise SolverError(st, status_name(st), f"could not create the {self._kind}")

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.free()

    def __del__(self):
        self.free()

    def free(self):
        if getattr(self, "_h", None) and self._h.value:
            getattr(lib(), f"martello_{self._kind}_free")(ctypes.byref(self._h))

    @property
    def handle(self):
        return self._h

    def message(self):
        buf = ctypes.create_string_buffer(1024)
        getattr(lib(), f"martello_{self._kind}_message")(self._h, buf, len(buf))
        return buf.value.decode(errors="replace")

    def check(self, status, what):
        """Raise on a negative status (DivergenceError for diverged or unstable runs);
        return the status (0 or a positive outcome)."""
        if status < 0:
            cls = DivergenceError if status in (constant("MARTELLO_ERR_DIVERGED"),
                                                constant("MARTELLO_ERR_UNSTABLE")) else SolverError
            if status == constant("MARTELLO_ERR_INTERRUPTED"):
                cls = Interrupted
            raise cls(status, status_name(status), f"{what}: {self.message()}")
        return status


class Model(_Handle):
    """Owns one native model."""

    _kind = "model"

    def __init__(self, n_nodes, max_links, max_contacts, max_forces, max_couplings=0):
        self._create(lib().martello_model_create, n_nodes, max_links, max_contacts, max_forces,
                     max_couplings)
        self.n_nodes, self.n_contacts = n_nodes, 0

    def set_node(self, i, mass, u0=0.0, v0=0.0, fixed=False):
        self.check(lib().martello_model_set_node(self._h, i, mass, u0, v0, int(fixed)),
                   f"node {i}")

    def add_link(self, kind, a, b, par):
        self.check(lib().martello_model_add_link(self._h, kind, a, b,
                                                 _f64(par, constant("NPAR_LINK"))), "link")

    def add_contact(self, a, b, gap, scheme, law, par):
        self.check(lib().martello_model_add_contact(self._h, a, b, gap, scheme, law,
                                                    _f64(par, constant("NPAR_CONTACT"))),
                   "contact")
        self.n_contacts += 1

    # The bulk doors (docs/c-api.md, "Building a large model"): one call per array.
    def set_nodes(self, mass, u0, v0, fixed):
        mass = _f64(mass, self.n_nodes)
        self.check(lib().martello_model_set_nodes(self._h, len(mass), mass, _f64(u0, len(mass)),
                                                  _f64(v0, len(mass)), _i32(fixed, len(mass))),
                   "nodes")

    def add_links(self, kind, a, b, par):
        kind = _i32(kind)
        n = len(kind)
        self.check(lib().martello_model_add_links(
            self._h, n, kind, _i32(a, n), _i32(b, n), _f64_rows(par, n, constant("NPAR_LINK"))),
            "links")

    def add_contacts(self, a, b, gap, scheme, law, par):
        a = _i32(a)
        n = len(a)
        self.check(lib().martello_model_add_contacts(
            self._h, n, a, _i32(b, n), _f64(gap, n), _i32(scheme, n), _i32(law, n),
            _f64_rows(par, n, constant("NPAR_CONTACT"))), "contacts")
        self.n_contacts += n

    def add_chain(self, first, k, c=None, fy=None, hardening=None, gap=None, scheme=0, law=0,
                  par=None):
        """A chain held per node (docs/c-api.md "Chains"): nodes first … first + len(k) − 1
        (0-based), each with a spring k to ground (bilinear with fy, hardening), a dashpot c
        where c > 0, and contacts between neighbours through gap (len(k) − 1 values) with one
        scheme, law and parameter row par."""
        k = _f64(k)
        n = len(k)
        keep = [k]

        def ptr(x, size):
            if x is None:
                return None
            arr = _f64(x, size)
            keep.append(arr)
            return arr.ctypes.data
        args = [ptr(c, n), ptr(fy, n), ptr(hardening, n), ptr(gap, n - 1)]
        row = ptr(par, constant("NPAR_CONTACT")) if gap is not None else None
        self.check(lib().martello_model_add_chain(self._h, first, n, k.ctypes.data, *args,
                                                  scheme, law, row), "chain")
        if gap is not None:
            self.n_contacts += n - 1

    def add_link_row(self, kind, nodes, coef, par):
        """A link whose elongation is Σ coef·u(node) (0-based nodes)."""
        nodes, coef = _i32(nodes), _f64(coef)
        self.check(lib().martello_model_add_link_row(self._h, kind, nodes.size, nodes, coef,
                                                     _f64(par, constant("NPAR_LINK"))), "link")

    def add_contact_row(self, nodes, coef, gap, scheme, law, par):
        """A contact whose penetration is Σ coef·u(node) − gap (0-based nodes)."""
        nodes, coef = _i32(nodes), _f64(coef)
        self.check(lib().martello_model_add_contact_row(self._h, nodes.size, nodes, coef, gap, scheme,
                                                        law, _f64(par, constant("NPAR_CONTACT"))),
                   "contact")
        self.n_contacts += 1

    def add_mass_coupling(self, a, b, value):
        self.check(lib().martello_model_add_mass_coupling(self._h, a, b, value), "mass coupling")

    def add_stiffness_block(self, nodes, k, c=None):
        """Symmetric stiffness k and damping c (n x n; None: undamped) between the nodes
        (0-based, no ground)."""
        nodes = np.ascontiguousarray(nodes, dtype=np.int32)
        k = np.asarray(k, dtype=np.float64)
        c = np.zeros_like(k) if c is None else np.asarray(c, dtype=np.float64)
        self.check(lib().martello_model_add_stiffness_block(
            self._h, len(nodes), nodes, np.ascontiguousarray(k.ravel(order="F")),
            np.ascontiguousarray(c.ravel(order="F"))), "stiffness block")

    def effective_masses(self):
        """m* = 1/(B M⁻¹ Bᵀ) of every contact, as the library computes it (inf: immovable)."""
        out = np.zeros(max(self.n_contacts, 1))
        self.check(lib().martello_model_effective_masses(self._h, out), "effective masses")
        return out[: self.n_contacts]

    def set_gravity(self, g):
        self.check(lib().martello_model_set_gravity(self._h, g), "gravity")

    def set_influence(self, iota):
        """ι of every node: gravity and the ground acceleration load M·ι (default 1)."""
        iota = _f64(iota)
        self.check(lib().martello_model_set_influence(self._h, iota.size, iota), "influence")

    def add_nodal_force(self, node, kind, par, t=(), y=()):
        t, y = _f64(t), _f64(y)
        self.check(lib().martello_model_add_nodal_force(
            self._h, node, kind, _f64(par, constant("NPAR_TF")), t.size, t, y), "nodal force")

    def set_ground_acceleration(self, kind, par, t=(), y=()):
        t, y = _f64(t), _f64(y)
        self.check(lib().martello_model_set_ground_acceleration(
            self._h, kind, _f64(par, constant("NPAR_TF")), t.size, t, y), "ground acceleration")

    def static_solve(self, tol, max_iter):
        """Static equilibrium with unilateral contacts; returns a dict of arrays and counters."""
        nc = self.n_contacts
        u = np.zeros(self.n_nodes)
        force, pen = np.zeros(max(nc, 1)), np.zeros(max(nc, 1))
        active = np.zeros(max(nc, 1), dtype=np.int32)
        counters = np.zeros(3, dtype=np.int32)
        cond = np.zeros(4)
        st = lib().martello_static_solve(self._h, tol, max_iter, u, force, pen, active,
                                         counters, cond)
        self.check(st, "static analysis")
        return {
            "status": status_name(st),
            "warning": self.message() if st > 0 else "",
            "u": u, "force": force[:nc], "penetration": pen[:nc], "active": active[:nc] != 0,
            "active_set_iterations": int(counters[0]), "uzawa_iterations": int(counters[1]),
            "linear_solves": int(counters[2]),
            "rcond": float(cond[0]), "digits_lost": float(cond[1]),
            "penalty_ratio": float(cond[2]), "penalised_rcond": float(cond[3]),
        }


class Run(_Handle):
    """One dynamic run: its integrator settings and, after execute(), its results."""

    _kind = "run"

    def __init__(self):
        self._create(lib().martello_run_create)

    _check = _Handle.check

    def set_settings(self, settings):
        """Hand the run its settings (a Settings from settings()); the library validates them."""
        self._check(lib().martello_run_set_settings(self._h, ctypes.byref(settings)), "settings")

    def set_outputs(self, nodes, contacts):
        n = np.ascontiguousarray(nodes, dtype=np.int32)
        c = np.ascontiguousarray(contacts, dtype=np.int32)
        self._check(lib().martello_run_set_outputs(self._h, n.size, n, c.size, c), "outputs")

    def set_link_outputs(self, links):
        l = np.ascontiguousarray(links, dtype=np.int32)
        self._check(lib().martello_run_set_link_outputs(self._h, l.size, l), "link outputs")

    def set_phase_lists(self, max_contacts):
        """Every contact's phases listed up to max_contacts contacts (< 0: always); past it the
        output contacts', the others' first and last phase (c/martello.h)."""
        self._check(lib().martello_run_set_phase_lists(self._h, int(max_contacts)), "phase lists")

    def set_tracking(self, *what):
        """Track only what is named (rows of the registry's table "tracking": "node_peaks",
        "link_peaks", "contact_peaks", "phases"); the rest reads NaN, or no phase rows."""
        flags = 0
        for w in what:
            flags |= value("tracking", w)
        self._check(lib().martello_run_set_tracking(self._h, flags), "tracking")

    def set_functionals(self, R, nodes, pairs=()):
        """Track the rows of R (dense, rows x len(nodes); column c on the 0-based node
        nodes[c]) as linear functionals of the state at every accepted sample, and the
        resultant of each pair of its rows (c/martello.h, martello_run_set_functionals)."""
        R = np.asarray(R, dtype=np.float64).reshape(-1, len(nodes))
        rows, cols = np.nonzero(R)                   # row by row: compressed rows
        ptr = np.zeros(R.shape[0] + 1, np.int32)
        np.cumsum(np.bincount(rows, minlength=R.shape[0]), out=ptr[1:])
        col = np.ascontiguousarray(np.asarray(nodes, dtype=np.int32)[cols], dtype=np.int32)
        val = np.ascontiguousarray(R[rows, cols])
        pr = np.ascontiguousarray(np.asarray(pairs, dtype=np.int32).reshape(-1))
        # ctypes wants a buffer even where nothing is read
        self._check(lib().martello_run_set_functionals(
            self._h, R.shape[0], ptr, col if col.size else np.zeros(1, np.int32),
            val if val.size else np.zeros(1), pr.size // 2, pr if pr.size else np.zeros(2, np.int32)),
            "functionals")

    def functionals(self, n, n_pairs):
        """(q_max, t_max, q_min, t_min, res_max, t_res) of the tracked functionals."""
        out = [np.zeros(max(n, 1)) for _ in range(4)] + [np.zeros(max(n_pairs, 1)) for _ in range(2)]
        self._check(lib().martello_run_functionals(self._h, *(o.ctypes.data for o in out)), "functionals")
        return [o[:n] for o in out[:4]] + [o[:n_pairs] for o in out[4:]]

    def set_trace(self, contact, nodes=()):
        """Keep the step trace of this 0-based contact and the displacement of these 0-based
        nodes (c/martello.h, martello_run_set_trace, _set_trace_nodes)."""
        self._check(lib().martello_run_set_trace(self._h, int(contact)), "trace")
        nd = np.ascontiguousarray(nodes, dtype=np.int32)
        self._check(lib().martello_run_set_trace_nodes(self._h, nd.size, nd if nd.size else np.zeros(1, np.int32)),
                    "trace nodes")
        self._trace_width = 4 + nd.size

    def trace(self):
        """The step trace: an array of rows [t, force, kinetic, recoverable, u of the traced
        nodes], one per grid point of the run."""
        n = ctypes.c_int()
        self._check(lib().martello_run_trace(self._h, ctypes.byref(n), None), "trace")
        buf = np.zeros((max(n.value, 1), self._trace_width))
        self._check(lib().martello_run_trace(self._h, ctypes.byref(n), buf.ctypes.data), "trace")
        return buf[:n.value]

    def link_peaks(self, n_links):
        f, du = np.zeros(max(n_links, 1)), np.zeros(max(n_links, 1))
        self._check(lib().martello_run_link_peaks(self._h, f.ctypes.data, du.ctypes.data), "link peaks")
        return f[:n_links], du[:n_links]

    def execute(self, model):
        """Run; raises on failure (DivergenceError for diverged/unstable runs, Interrupted
        after Ctrl-C)."""
        return self._check(self.status_of(model), "dynamic run")

    def status_of(self, model):
        """Run without raising; returns the status code (for studies that classify failures).
        The native loop calls back about four times a second: the reporter of ``reporting``
        (if any) sees its progress, and Ctrl-C (SIGINT, in the main thread) stops it cleanly
        with MARTELLO_ERR_INTERRUPTED instead of waiting for the end of the run."""
        with _watch() as callback:
            self._check(lib().martello_run_set_progress(self._h, callback, None), "progress")
            try:
                return lib().martello_dynamic_run(model.handle, self._h)
            finally:
                self._check(lib().martello_run_set_progress(self._h, PROGRESS_FN(), None), "progress")

    def history(self):
        rows, cols = ctypes.c_int(), ctypes.c_int()
        self._check(lib().martello_run_history_shape(self._h, ctypes.byref(rows), ctypes.byref(cols)),
                    "history shape")
        buf = np.zeros(max(rows.value * cols.value, 1))
        self._check(lib().martello_run_history(self._h, buf), "history")
        return buf[: rows.value * cols.value].reshape(rows.value, cols.value)

    def events(self):
        n = ctypes.c_int()
        self._check(lib().martello_run_events(self._h, ctypes.byref(n), None, None), "events")
        contacts = np.zeros(max(n.value, 1), dtype=np.int32)
        values = np.zeros((max(n.value, 1), constant("NEVENT")))
        self._check(lib().martello_run_events(self._h, ctypes.byref(n), contacts.ctypes.data_as(_VOID_P),
                                              values.ctypes.data_as(_VOID_P)), "events")
        return contacts[: n.value], values[: n.value]

    def counters(self):
        c = np.zeros(constant("NCOUNTERS"), dtype=np.int64)
        self._check(lib().martello_run_counters(self._h, c), "counters")
        return dict(zip(counter_names(), map(int, c)))

    def peaks(self, n_nodes, n_contacts, nodes=True, contacts=True):
        """The node peaks (nodes=False: none copied out) and the contact maxima (contacts=False:
        none), with every contact's number of phases, as a dict of arrays."""
        def out_array(n, wanted, dtype=np.float64):
            return np.zeros(max(n, 1), dtype) if wanted else None
        names = ("u_max", "u_min", "v_absmax", "a_absmax", "pen_max", "force_max", "impacts",
                 "u_peak", "t_peak")
        arrays = [out_array(n_nodes, nodes) for _ in range(4)] + \
                 [out_array(n_contacts, contacts) for _ in range(2)] + \
                 [out_array(n_contacts, True, np.int32)] + [out_array(n_nodes, nodes) for _ in range(2)]
        self._check(lib().martello_run_peaks(self._h, *(None if a is None else a.ctypes.data for a in arrays)),
                    "peaks")
        out = {k: a[: (n_contacts if 4 <= i <= 6 else n_nodes)]
               for i, (k, a) in enumerate(zip(names, arrays)) if a is not None}
        if nodes:
            absmax = [np.zeros(max(n_nodes, 1)) for _ in range(2)]
            self._check(lib().martello_run_abs_peaks(self._h, absmax[0].ctypes.data, absmax[1].ctypes.data),
                        "peaks")
            out["u_absmax"], out["t_absmax"] = absmax[0][:n_nodes], absmax[1][:n_nodes]
        return out

    def energy(self):
        e, extra = np.zeros(constant("NENERGY")), np.zeros(4)
        self._check(lib().martello_run_energy(self._h, e, extra), "energy")
        d = dict(zip(energy_names(), map(float, e)))
        return d, {"balance_max": float(extra[0]), "omega_max": float(extra[1]),
                   "dt_critical": float(extra[2]), "t_reached": float(extra[3])}


def closed_form(name, par):
    """The library's closed form `name` (docs/c-api.md "Closed forms") at the parameters par:
    the list of its values. SolverError (MARTELLO_ERR_ARGUMENT) for an unknown name or
    parameters outside its domain."""
    p = np.ascontiguousarray(par, dtype=np.float64)
    out, n = np.zeros(4), ctypes.c_int()
    st = lib().martello_closed_form(str(name).encode(), p if p.size else np.zeros(1), p.size,
                                    out, ctypes.byref(n))
    if st < 0:
        raise SolverError(st, status_name(st), f"closed form {name!r} at {list(map(float, p))}: "
                          "unknown, or parameters outside its domain (docs/c-api.md)")
    return [float(x) for x in out[:n.value]]


# --- progress and Ctrl-C of a running native loop ------------------------------------

_reporter = None


@contextmanager
def reporting(reporter):
    """Within the block, every dynamic run calls reporter(t, t_end, steps, elapsed) about
    four times a second (martello run's progress line). A reporter that raises stops the
    run; the exception is raised when the run returns."""
    global _reporter
    old, _reporter = _reporter, reporter
    try:
        yield
    finally:
        _reporter = old


@contextmanager
def _watch():
    """The progress callback of one run: Ctrl-C (SIGINT, caught here while the native loop
    runs, when Python's default handler is in place in the main thread) makes it return 1,
    so the loop stops at its next look at the clock; reports go to the reporter."""
    state = {"stop": False, "error": None}
    reporter = _reporter

    def on_sigint(signum, frame):
        state["stop"] = True

    def progress(user, t, t_end, steps, elapsed):
        if reporter is not None and not state["stop"]:
            try:
                reporter(t, t_end, steps, elapsed)
            except BaseException as exc:       # noqa: BLE001 - raised after the run
                state["error"] = exc
                return 1
        return 1 if state["stop"] else 0

    callback = PROGRESS_FN(progress)
    old = None
    if (threading.current_thread() is threading.main_thread()
            and signal.getsignal(signal.SIGINT) in (signal.default_int_handler,
                                                    errors.record_sigint)):
        old = signal.signal(signal.SIGINT, on_sigint)
    try:
        yield callback
    finally:
        if old is not None:
            signal.signal(signal.SIGINT, old)
    if state["error"] is not None:
        raise state["error"]
