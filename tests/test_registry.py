"""The library's registry (fortran/registry.f90) is the one definition of every table the C
header, the C integrators and the Python front end share. These tests enumerate every
registry table and check each copy against it: the enums and the settings struct of
c/martello.h (parsed from the text, both ways), the local index enums of the C adapters, the
Python binding and the scene loader, and the library's own behaviour (status names, the
settings it validates, the history layout it writes)."""

import ctypes
import math
import re
from pathlib import Path

import numpy as np
import pytest

from martello import run
from martello.binding import native
from martello.scene import spec as scene
from martello.scene.compatibility import COMPATIBLE
from martello.errors import SolverError
from martello.binding.native import Model, Run, constant
from tests.dynamics_helpers import dynamic, execute, sdof

ROOT = Path(__file__).resolve().parent.parent
HEADER = (ROOT / "c" / "martello.h").read_text()
TABLES = [t.name for t in native.registry("tables")]


def _code(text):
    """C text without comments."""
    return re.sub(r"/\*.*?\*/", " ", text, flags=re.S)


def header_constants():
    """Every MARTELLO_* constant of the header with a value: enumerators and #defines."""
    code, out = _code(HEADER), {}
    for body in re.findall(r"enum\s*\w*\s*\{(.*?)\}", code, flags=re.S):
        for item in filter(str.strip, body.split(",")):
            name, _, val = item.partition("=")
            assert val.strip(), f"enumerator without an explicit value: {item.strip()}"
            out[name.strip()] = int(val)
    for name, val in re.findall(r"#define\s+(MARTELLO_\w+)\s+\(?(-?\d+)\)?", code):
        out[name] = int(val)
    return out


def registry_constants():
    """What the registry says the header must define: status codes by name, and every row of
    a table whose "tables" row names a prefix (laws' hunt-crossley: MARTELLO_LAW_HUNT_CROSSLEY)."""
    out = {r.name: int(r.values["value"]) for r in native.registry("status")}
    for t in native.registry("tables"):
        for r in native.registry(t.name) if t.text else ():
            ident = t.text + r.name.upper().replace("-", "_")
            assert ident not in out, f"two registry rows map to {ident}"
            out[ident] = int(r.values["value"])
    return out


def test_tables_list_themselves_with_their_shapes():
    assert TABLES[0] == "tables"
    for t in native.registry("tables"):
        rows = native.registry(t.name)
        assert len(rows) == t.values["rows"] > 0, t.name
        assert all(len(r.values) == t.values["cols"] for r in rows), t.name
        assert len({r.name for r in rows}) == len(rows), f"{t.name}: duplicate names"
    with pytest.raises(KeyError, match="no table"):
        native.registry("no such table")


@pytest.mark.parametrize("table", TABLES)
def test_every_row_has_a_name_and_a_text(table):
    for r in native.registry(table):
        assert re.fullmatch(r"[A-Za-z_][A-Za-z0-9_-]*", r.name), (table, r.name)
        # the prefix column of "tables" may be empty (no C constants); every other text says
        # what the row is
        assert r.text or table == "tables", (table, r.name)


def test_every_header_constant_is_the_registrys():
    have, want = header_constants(), registry_constants()
    assert len(have) > 90
    wrong = {k: (v, want.get(k)) for k, v in have.items() if want.get(k) != v}
    assert not wrong, f"header constant -> (header value, registry value): {wrong}"


def test_every_registry_row_has_its_header_constant():
    have, want = header_constants(), registry_constants()
    missing = sorted(set(want) - set(have))
    assert not missing, f"registry rows without a constant in c/martello.h: {missing}"


def test_settings_struct_is_the_registrys_table_field_by_field():
    body = re.search(r"typedef struct martello_settings\s*\{(.*?)\}\s*martello_settings;",
                     _code(HEADER), flags=re.S).group(1)
    fields = [tuple(f.split()) for f in body.split(";") if f.strip()]
    types = {int(r.values["value"]): r.name for r in native.registry("setting_types")}
    want = [("int", "kind")] + [(types[int(r.values["type"])], r.name)
                                for r in native.registry("settings")]
    assert fields == want
    assert [f for f, _ in native.settings_type()._fields_] == [n for _, n in want]


def test_c_adapters_keep_no_copy_of_the_registry_indices():
    # The C integrators index counters, energy terms and event values with the header's
    # MARTELLO_COUNTER_* / MARTELLO_ENERGY_* / MARTELLO_EVENT_* (generated from the registry,
    # checked above): a local enum of the same quantities would be a second copy to drift.
    for src in ("event_driven.c", "ida.c"):
        code = _code((ROOT / "c" / src).read_text())
        for body in re.findall(r"enum\s*\{(.*?)\}", code, flags=re.S):
            items = [x.split("=")[0].strip() for x in body.split(",") if x.strip()]
            for quantity in ("STEPS", "KINETIC", "T_ON"):
                assert not any(i.endswith(quantity) for i in items), (src, items)
        assert "MARTELLO_COUNTER_STEPS" in code, src


def test_status_names_are_the_registrys():
    for r in native.registry("status"):
        assert native.status_name(int(r.values["value"])) == r.name
    assert native.status_name(12345) == "MARTELLO_UNKNOWN_STATUS"


def test_integrator_kinds_are_their_rows_in_order():
    # the library indexes its integrator table by kind
    assert [int(r.values["value"]) for r in native.registry("integrators")] == \
        list(range(1, len(native.integrators()) + 1))
    families = set(native.names("families"))
    assert {native.registry("families")[int(r.values["family"]) - 1].name
            for r in native.registry("integrators")} == families


def test_loader_tables_are_the_librarys():
    assert scene.INTEGRATORS == native.integrators()
    assert scene.ADAPTIVE == native.adaptive_integrators() == ("rkf45", "rk8pd", "msbdf", "ida", "cvode", "arkode")
    assert COMPATIBLE == native.compatibility()
    assert set(COMPATIBLE) == set(scene.SCHEMES) == set(native.names("schemes"))
    assert scene.LAWS == native.names("laws")
    laws = {r.name: r for r in native.registry("laws")}
    assert scene.FIXED_EXPONENT == {k: r.values["exponent"] for k, r in laws.items()
                                    if r.values["exponent_fixed"]}
    assert run.LAW_EXPONENT == {k: r.values["exponent"] for k, r in laws.items()}
    for integ in scene.INTEGRATORS:
        common = set.intersection(*map(native.settings_read, scene.INTEGRATORS))
        assert scene.INTEGRATOR_KEYS[integ] - {"preset"} == native.settings_read(integ) - common


def test_loader_defaults_and_ranges_are_the_librarys():
    spec = scene.ANALYSIS_TYPES["dynamic"] | {"every": scene.OUTPUT_KEYS["every"]}
    ranges = native.settings_ranges()
    for name, default in native.settings_defaults().items():
        kind, required, check, scene_default = spec[name]
        if name == "method":   # a name in the scene (a row of the table methods), a value in the library
            assert kind == "str" and scene_default is None
            assert set().union(*scene.METHODS.values()) == set(native.names("methods"))
            continue
        if not required and name not in ("beta", "gamma", "alpha", "rho_inf"):
            assert scene_default == default and type(scene_default) is type(default), name
        if kind != "bool":
            assert check[1] == ranges[name].text, name
            rng = ranges[name]
            for x in (rng.lo, rng.hi):
                if math.isfinite(x):
                    closed = not (rng.lo_open if x == rng.lo else rng.hi_open)
                    assert check[0](x) == closed, (name, x)


def test_defaults_are_the_registrys_for_every_integrator():
    rows = native.registry("settings")
    for integ in native.integrators():
        s = native.settings(integ)
        assert s.kind == native.value("integrators", integ)
        for r in rows:
            assert getattr(s, r.name) == r.values["default"], (integ, r.name)
    with pytest.raises(KeyError):
        native.settings("no-such-integrator")


def _outside(rng):
    """A value just outside a setting's range (NaN if it has no finite bound)."""
    if math.isfinite(rng.lo):
        return rng.lo if rng.lo_open else rng.lo - 1.0
    return rng.hi if rng.hi_open else rng.hi + 1.0


@pytest.mark.parametrize("integrator", native.integrators())
def test_set_settings_checks_exactly_what_the_integrator_reads(integrator):
    # Field by field through ctypes: a bad value of a field the integrator reads is refused
    # with a message naming the field (so the library reads the field where the header puts
    # it), and a bad value of a field it does not read is accepted.
    ranges, reads = native.settings_ranges(), native.settings_read(integrator)
    types = dict(native.settings_type()._fields_)
    for name, rng in ranges.items():
        if types[name] is ctypes.c_bool:
            continue          # a bool has no bad value: see test_check_stability_is_read_where_the_header_puts_it
            # and tests/test_chain_step.py (fused_chain)
        bad = _outside(rng)
        s = native.settings(integrator, **(dict(dt=1e-3, t_end=1.0) | {
            name: int(bad) if types[name] is ctypes.c_int else bad}))
        r = Run()
        if name in reads:
            with pytest.raises(SolverError) as info:
                r.set_settings(s)
            assert info.value.status == constant("MARTELLO_ERR_ARGUMENT")
            assert f"settings.{name} = " in r.message() and f"invalid for {integrator}" in r.message()
            assert rng.text in r.message()
        else:
            r.set_settings(s)


def test_unknown_kind_is_refused_by_name():
    s = native.settings("newmark", dt=1e-3, t_end=1.0)
    s.kind = 99
    r = Run()
    with pytest.raises(SolverError, match="settings"):
        r.set_settings(s)
    assert "settings.kind = 99 is no integrator" in r.message()


def test_check_stability_is_read_where_the_header_puts_it():
    # central difference beyond its limit (dt = 0.5 > 2/omega = 0.2): refused when the flag
    # is set, run (and diverging or not, no longer refused as unstable) when it is not
    d = sdof(m=1.0, k=100.0, u0=0.01, analysis=dynamic("central-difference", dt=0.5, t_end=5.0,
                                                       check_stability=True))
    with pytest.raises(SolverError, match="MARTELLO_ERR_UNSTABLE"):
        execute(d)
    d["analysis"]["check_stability"] = False
    try:
        execute(d)
    except SolverError as exc:
        assert exc.status != constant("MARTELLO_ERR_UNSTABLE"), exc


def test_history_columns_are_what_the_library_writes():
    d = sdof(m=2.0, k=50.0, u0=0.1, v0=0.3, analysis=dynamic("newmark", dt=1e-3, t_end=1e-2),
             links=[{"name": "damper", "type": "dashpot", "a": "m", "b": "ground", "c": 0.5}])
    d["analysis"]["output"]["links"] = ["damper"]
    summary, h = execute(d)
    cols = native.history_columns(["m"], [], ["damper"])
    assert list(h) == cols
    assert cols[0] == "t" and cols[-len(native.energy_names()):] == \
        [f"energy:{e}" for e in native.energy_names()]
    assert h["t"][0] == 0.0 and h["u:m"][0] == 0.1 and h["v:m"][0] == 0.3
    # energies and the dashpot's force c·v at t = 0: a few roundings, 1e-14
    assert h["energy:kinetic"][0] == pytest.approx(0.5 * 2.0 * 0.3 ** 2, rel=1e-14)
    assert h["energy:initial"][-1] == pytest.approx(0.5 * 2.0 * 0.3 ** 2 + 0.5 * 50.0 * 0.1 ** 2,
                                                    rel=1e-14)
    assert h["link_force:damper"][0] == pytest.approx(0.5 * 0.3, rel=1e-14)
    assert set(summary["cost"]) == set(native.counter_names()) | {"wall_time_s"}


def test_constants_come_from_the_registry():
    # native.constant(): the header's names without MARTELLO_ (status codes keep theirs)
    status = set(native.names("status"))
    assert native.constants() == {(k if k in status else k.removeprefix("MARTELLO_")): v
                                  for k, v in registry_constants().items()}
    with pytest.raises(KeyError):
        constant("P_MSTAR")           # gone: the library computes m* itself
    assert not any(hasattr(native, k) for k in ("COUNTER_NAMES", "ENERGY_NAMES", "EVENT_NAMES"))
    assert len(native.event_names()) == constant("NEVENT")
    assert len(native.counter_names()) == constant("NCOUNTERS")
    assert len(native.energy_names()) == constant("NENERGY")


def test_registry_c_api_refuses_short_buffers_and_bad_rows():
    L, buf = native.lib(), ctypes.create_string_buffer(7)
    assert L.martello_registry_entry(b"integrators", 0, buf, 7, None) == \
        constant("MARTELLO_ERR_ARGUMENT")                         # "newmark" needs 8 bytes
    big = ctypes.create_string_buffer(8)
    assert L.martello_registry_entry(b"integrators", 0, big, 8, None) == 0
    assert big.value == b"newmark"
    assert L.martello_registry_entry(b"integrators", 10, big, 8, None) != 0
    assert L.martello_registry_entry(b"integrators", -1, big, 8, None) != 0
    row = ctypes.c_int()
    assert L.martello_registry_find(b"laws", b"kelvin", ctypes.byref(row)) == 0 and row.value == 2
    assert L.martello_registry_find(b"laws", b"nope", ctypes.byref(row)) != 0 and row.value == -1
    values = np.zeros(3)
    assert L.martello_registry_entry(b"laws", 1, None, 0, values.ctypes.data_as(ctypes.c_void_p)) == 0
    assert list(values) == [constant("LAW_HERTZ"), 1.5, 0.0]
