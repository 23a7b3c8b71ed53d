"""The field checker of scene tables: every table of a scene (and of its generators,
[[chain]] and [[bar]]) is validated against a spec of its keys, so every error names the
file, the field and what would be valid, in the same words everywhere.

A spec maps each key to (kind, required, check, default). kind is "float", "int", "str",
"bool", "list", "table", "function" or "any". check is (predicate, "what is valid")."""

import math

import numpy as np

from ..errors import SceneError

# The range of an integer field: the library's int (C int, 32 bits; c/martello.h). A larger
# value would wrap when handed over, and `every = 2**40` would read as 0.
INT_MAX = 2**31 - 1
# TOML integers are 64-bit (TOML v1.0.0, "Integer"): a longer one is not a TOML integer,
# whatever the parser makes of it.
TOML_INT_MAX = 2**63 - 1
# How deep a scene's tables and arrays may nest: a scene needs 4 levels
# (check.compare[i].why); a deeper one is a mistake, or an attack on the parser.
MAX_DEPTH = 16
# The smallest normal double (IEEE 754 binary64): below it, a number has lost precision and
# its reciprocal overflows (1/1e-310 = inf). No physical input of a scene is that small.
TINY = 2.2250738585072014e-308
# How many nodes the generators ([[chain]], [[bar]]) may make in one scene, all tables
# together: a million oscillators already write a summary of about 1 GB
# (docs/behaviour.md, "Failures and limits"); more is a typing mistake, not a model.
MAX_GENERATED = 1_000_000

POSITIVE = (lambda x: x > 0, "a number > 0")
NONNEG = (lambda x: x >= 0, "a number >= 0")
ANY = (lambda x: True, "a number")


def unit_interval(lo_open=False, hi_open=False):
    def ok(x):
        return (x > 0 if lo_open else x >= 0) and (x < 1 if hi_open else x <= 1)
    lo, hi = ("(" if lo_open else "["), (")" if hi_open else "]")
    return (ok, f"a number in {lo}0, 1{hi}")


def kind_ok(kind, v):
    if kind == "any":
        return True
    if kind == "float":
        return isinstance(v, (int, float)) and not isinstance(v, bool)
    if kind == "int":
        return isinstance(v, int) and not isinstance(v, bool)
    return isinstance(v, {"str": str, "bool": bool, "list": list, "table": dict}[kind])


# Names of items (and the prefixes of generated ones) head the columns of history.csv
# (u:<node>, link_force:<link>; docs/results.md), which martello compare and plot read back:
# a comma, a quote or a line break in one made a file martello could not read.
NAME_KEYS = ("name", "prefix")
NAME_RULE = ("a name is not empty, has no comma, quote or control character (line break, tab), "
             "and no space at either end")


def name_ok(v):
    return (v != "" and v == v.strip() and not any(c in ',"' or ord(c) < 32 or ord(c) == 127
                                                    for c in v))


def check_fields(src, table, where, spec, extra_ok=()):
    """Validate one table against its spec; return a dict with defaults filled in."""
    if not isinstance(table, dict):
        raise SceneError(src, where, "must be a table", "write it as [name] or { ... }")
    for key in table:
        if key not in spec and key not in extra_ok:
            valid = ", ".join(sorted(set(spec) | set(extra_ok)))
            raise SceneError(src, f"{where}.{key}", "unknown key", f"valid keys here: {valid}")
    out = {}
    for key, (kind, required, check, default) in spec.items():
        path = f"{where}.{key}"
        if key not in table:
            if required:
                raise SceneError(src, path, "missing", f"this field is required ({kind})")
            out[key] = default
            continue
        v = table[key]
        if not kind_ok(kind, v):
            raise SceneError(src, path, f"has the wrong type ({type(v).__name__})",
                             f"expected {kind}")
        if kind == "int" and abs(v) > INT_MAX:
            raise SceneError(src, path, f"invalid value {v!r}",
                             f"must be an integer of at most {INT_MAX} in magnitude")
        if kind == "float":
            v = float(v)
        if key in NAME_KEYS and isinstance(v, str) and not name_ok(v):
            raise SceneError(src, path, f"invalid name {v!r}", NAME_RULE)
        if check is not None and kind in ("float", "int"):
            ok, what = check
            if not ok(v):
                raise SceneError(src, path, f"invalid value {v!r}", f"must be {what}")
        out[key] = v
    return out


def finite_everywhere(src, obj, where, what="a scene", error=SceneError):
    """TOML admits nan and inf literals; a scene never may. Nor integers beyond 64 bits, nor
    tables and arrays nested deeper than MAX_DEPTH (walked without recursion). `what` and
    `error` serve the other TOML files (study files: StudyError)."""
    SceneError = error            # noqa: N806 (the messages below are the same for all)
    todo = [(obj, where, 0)]
    while todo:
        obj, where, depth = todo.pop()
        if isinstance(obj, float) and not math.isfinite(obj):
            raise SceneError(src, where, f"is {obj}", f"every number in {what} must be finite")
        if isinstance(obj, float) and obj != 0 and abs(obj) < TINY:
            raise SceneError(src, where, f"is {obj!r}, a subnormal number",
                             f"every number in {what} is 0 or at least {TINY:.4g} in magnitude")
        if isinstance(obj, int) and not isinstance(obj, bool) and abs(obj) > TOML_INT_MAX:
            raise SceneError(src, where, f"is an integer of {obj.bit_length()} bits",
                             "TOML integers are 64-bit; write a large number as a float, e.g. 1e30")
        if isinstance(obj, (dict, list)) and depth >= MAX_DEPTH:
            raise SceneError(src, where, f"nests tables or arrays deeper than {MAX_DEPTH} levels",
                             f"{what} needs at most 4")
        if isinstance(obj, dict):
            # pushed in reverse: the first offender in the file's order is the one reported
            todo += reversed([(v, f"{where}.{k}" if where else str(k), depth + 1)
                              for k, v in obj.items()])
        elif isinstance(obj, list):
            if len(obj) > 64 and _plain_floats_ok(obj):
                continue          # a long list of numbers (a chain's k): checked at once
            todo += reversed([(v, f"{where}[{i}]", depth + 1) for i, v in enumerate(obj)])


def _plain_floats_ok(values):
    """Whether a list holds floats only, each finite and 0 or normal: what the walk of
    finite_everywhere would find, checked without a step per entry (else the walk runs and
    names the first offender)."""
    if set(map(type, values)) != {float}:
        return False
    x = np.fromiter(values, np.float64, len(values))
    return bool(np.isfinite(x).all() and not ((x != 0) & (np.abs(x) < TINY)).any())


def choice(src, path, value, choices):
    if value not in choices:
        raise SceneError(src, path, f"unknown value {value!r}", "valid: " + ", ".join(choices))
    return value

def per_item(src, where, value, count, check=None):
    """A scalar for all, or a list of exactly `count` numbers."""
    values = value if isinstance(value, list) else [value] * count
    if len(values) != count:
        raise SceneError(src, where, f"has {len(values)} values", f"give one number or a list of {count}")
    for i, v in enumerate(values):
        path = f"{where}[{i}]" if isinstance(value, list) else where
        if not kind_ok("float", v):
            raise SceneError(src, path, f"has the wrong type ({type(v).__name__})", "expected float")
        if check is not None and not check[0](float(v)):
            raise SceneError(src, path, f"invalid value {v!r}", f"must be {check[1]}")
    return [float(v) for v in values]
