"""The ctypes binding to libmartello: the only place Python touches the C API.

Status codes become exceptions here (as dftd4 raises RuntimeError from its error handle):
negative codes raise, positive ones are returned to the caller as outcomes."""

import ctypes
import os
from functools import lru_cache
from pathlib import Path

import numpy as np

from ..errors import MartelloError, SolverError, DivergenceError

_REPO = Path(__file__).resolve().parents[2]
_DOUBLE_P = np.ctypeslib.ndpointer(dtype=np.float64, flags="C_CONTIGUOUS")
_INT_P = np.ctypeslib.ndpointer(dtype=np.int32, flags="C_CONTIGUOUS")
_VOID_P = ctypes.c_void_p


def library_path():
    """MARTELLO_LIB if set, else the CMake build tree of this checkout."""
    env = os.environ.get("MARTELLO_LIB")
    if env:
        return Path(env)
    return _REPO / "build" / "libmartello.so"


@lru_cache(maxsize=None)
def lib():
    path = library_path()
    if not path.exists():
        raise MartelloError(
            f"native library not found at {path}: build it with ./scripts/build "
            "(or point MARTELLO_LIB at libmartello.so)")
    L = ctypes.CDLL(str(path))
    c_int, c_double, c_char_p = ctypes.c_int, ctypes.c_double, ctypes.c_char_p
    protos = {
        "martello_version": (c_char_p, []),
        "martello_library_versions": (c_int, [c_char_p, c_int]),
        "martello_status_name": (c_char_p, [c_int]),
        "martello_constant": (c_int, [c_char_p, ctypes.POINTER(c_int)]),
        "martello_model_create": (c_int, [c_int] * 5 + [ctypes.POINTER(_VOID_P)]),
        "martello_model_free": (None, [ctypes.POINTER(_VOID_P)]),
        "martello_model_set_node": (c_int, [_VOID_P, c_int, c_double, c_double, c_double, c_int]),
        "martello_model_add_link": (c_int, [_VOID_P, c_int, c_int, c_int, _DOUBLE_P]),
        "martello_model_add_contact": (c_int, [_VOID_P, c_int, c_int, c_double, c_int, c_int,
                                               _DOUBLE_P]),
        "martello_model_add_mass_coupling": (c_int, [_VOID_P, c_int, c_int, c_double]),
        "martello_model_set_gravity": (c_int, [_VOID_P, c_double]),
        "martello_model_add_nodal_force": (c_int, [_VOID_P, c_int, c_int, _DOUBLE_P, c_int,
                                                   _DOUBLE_P, _DOUBLE_P]),
        "martello_model_set_ground_acceleration": (c_int, [_VOID_P, c_int, _DOUBLE_P, c_int,
                                                           _DOUBLE_P, _DOUBLE_P]),
        "martello_model_message": (c_int, [_VOID_P, c_char_p, c_int]),
        "martello_static_solve": (c_int, [_VOID_P, c_double, c_int, _DOUBLE_P, _DOUBLE_P,
                                          _DOUBLE_P, _INT_P, _INT_P, _DOUBLE_P]),
        "martello_run_create": (c_int, [ctypes.POINTER(_VOID_P)]),
        "martello_run_free": (None, [ctypes.POINTER(_VOID_P)]),
        "martello_run_set_integrator": (c_int, [_VOID_P, c_int, _DOUBLE_P]),
        "martello_run_set_outputs": (c_int, [_VOID_P, c_int, _INT_P, c_int, _INT_P]),
        "martello_dynamic_run": (c_int, [_VOID_P, _VOID_P]),
        "martello_run_message": (c_int, [_VOID_P, c_char_p, c_int]),
        "martello_run_history_shape": (c_int, [_VOID_P, ctypes.POINTER(c_int), ctypes.POINTER(c_int)]),
        "martello_run_history": (c_int, [_VOID_P, _DOUBLE_P]),
        "martello_run_events": (c_int, [_VOID_P, ctypes.POINTER(c_int), _VOID_P, _VOID_P]),
        "martello_run_counters": (c_int, [_VOID_P, np.ctypeslib.ndpointer(dtype=np.int64, flags="C_CONTIGUOUS")]),
        "martello_run_peaks": (c_int, [_VOID_P] + [_DOUBLE_P] * 6 + [_INT_P] + [_DOUBLE_P] * 2),
        "martello_run_energy": (c_int, [_VOID_P, _DOUBLE_P, _DOUBLE_P]),
        "martello_run_set_link_outputs": (c_int, [_VOID_P, c_int, _INT_P]),
        "martello_run_link_peaks": (c_int, [_VOID_P, _DOUBLE_P, _DOUBLE_P]),
    }
    for name, (res, args) in protos.items():
        fn = getattr(L, name)
        fn.restype, fn.argtypes = res, args
    return L


@lru_cache(maxsize=None)
def constant(name):
    """A named integer constant of the kernels (law, link kind, scheme, slot, status)."""
    value = ctypes.c_int()
    if lib().martello_constant(name.encode(), ctypes.byref(value)) != 0:
        raise KeyError(f"the native library has no constant {name!r}")
    return value.value


def version():
    return lib().martello_version().decode()


def library_versions():
    buf = ctypes.create_string_buffer(256)
    lib().martello_library_versions(buf, len(buf))
    return buf.value.decode()


def status_name(status):
    return lib().martello_status_name(status).decode()


def _f64(values, n=None):
    a = np.ascontiguousarray(values, dtype=np.float64)
    if n is not None and a.size != n:
        raise ValueError(f"expected {n} values, got {a.size}")
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

    def add_mass_coupling(self, a, b, value):
        self.check(lib().martello_model_add_mass_coupling(self._h, a, b, value), "mass coupling")

    def set_gravity(self, g):
        self.check(lib().martello_model_set_gravity(self._h, g), "gravity")

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


COUNTER_NAMES = ("steps", "rejected_steps", "newton_iterations", "residual_evaluations",
                 "factorizations", "events", "jacobian_evaluations", "root_evaluations",
                 "contact_chatter_resolutions")
ENERGY_NAMES = ("kinetic", "recoverable", "input", "damping", "plastic", "contact", "balance",
                "initial", "impact")
EVENT_NAMES = ("t_on", "t_off", "v_in", "v_out", "max_penetration", "max_force")


class Run(_Handle):
    """One dynamic run: its integrator settings and, after execute(), its results."""

    _kind = "run"

    def __init__(self):
        self._create(lib().martello_run_create)

    _check = _Handle.check

    def set_integrator(self, kind, par):
        self._check(lib().martello_run_set_integrator(
            self._h, kind, _f64(par, constant("NPAR_INTEGRATOR"))), "integrator")

    def set_outputs(self, nodes, contacts):
        n = np.ascontiguousarray(nodes, dtype=np.int32)
        c = np.ascontiguousarray(contacts, dtype=np.int32)
        self._check(lib().martello_run_set_outputs(self._h, n.size, n, c.size, c), "outputs")

    def set_link_outputs(self, links):
        l = np.ascontiguousarray(links, dtype=np.int32)
        self._check(lib().martello_run_set_link_outputs(self._h, l.size, l), "link outputs")

    def link_peaks(self, n_links):
        f, du = np.zeros(max(n_links, 1)), np.zeros(max(n_links, 1))
        lib().martello_run_link_peaks(self._h, f, du)
        return f[:n_links], du[:n_links]

    def execute(self, model):
        """Run; raises on failure (DivergenceError for diverged/unstable runs)."""
        return self._check(lib().martello_dynamic_run(model.handle, self._h), "dynamic run")

    def status_of(self, model):
        """Run without raising; returns the status code (for studies that classify failures)."""
        return lib().martello_dynamic_run(model.handle, self._h)

    def history(self):
        rows, cols = ctypes.c_int(), ctypes.c_int()
        lib().martello_run_history_shape(self._h, ctypes.byref(rows), ctypes.byref(cols))
        buf = np.zeros(max(rows.value * cols.value, 1))
        lib().martello_run_history(self._h, buf)
        return buf[: rows.value * cols.value].reshape(rows.value, cols.value)

    def events(self):
        n = ctypes.c_int()
        lib().martello_run_events(self._h, ctypes.byref(n), None, None)
        contacts = np.zeros(max(n.value, 1), dtype=np.int32)
        values = np.zeros((max(n.value, 1), constant("NEVENT")))
        lib().martello_run_events(self._h, ctypes.byref(n), contacts.ctypes.data_as(_VOID_P),
                                  values.ctypes.data_as(_VOID_P))
        return contacts[: n.value], values[: n.value]

    def counters(self):
        c = np.zeros(constant("NCOUNTERS"), dtype=np.int64)
        lib().martello_run_counters(self._h, c)
        return dict(zip(COUNTER_NAMES, map(int, c)))

    def peaks(self, n_nodes, n_contacts):
        arrays = [np.zeros(max(n_nodes, 1)) for _ in range(4)] + \
                 [np.zeros(max(n_contacts, 1)) for _ in range(2)]
        impacts = np.zeros(max(n_contacts, 1), dtype=np.int32)
        peak = [np.zeros(max(n_nodes, 1)) for _ in range(2)]
        lib().martello_run_peaks(self._h, *arrays, impacts, *peak)
        names = ("u_max", "u_min", "v_absmax", "a_absmax", "pen_max", "force_max")
        out = {k: a[: (n_nodes if i < 4 else n_contacts)] for i, (k, a) in enumerate(zip(names, arrays))}
        out["impacts"] = impacts[:n_contacts]
        out["u_peak"], out["t_peak"] = peak[0][:n_nodes], peak[1][:n_nodes]
        return out

    def energy(self):
        e, extra = np.zeros(constant("NENERGY")), np.zeros(4)
        lib().martello_run_energy(self._h, e, extra)
        d = dict(zip(ENERGY_NAMES, map(float, e)))
        return d, {"balance_max": float(extra[0]), "omega_max": float(extra[1]),
                   "dt_critical": float(extra[2]), "t_reached": float(extra[3])}
