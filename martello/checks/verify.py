"""Verification of a run against its scene's closed form (the `[check]` table).

The oracle is evaluated from the parameters written in the check table itself, by a closed
form of martello.oracles (or a catalogue dispatcher combining them), which never calls the
solvers: a scene and its reference are two independent statements of the same problem."""

import math

from ..errors import SceneError
from ..results import KINDS, ItemArrays
from . import kinds
from .oracle_names import closed_form

DIGITS_CAP = 16.0   # a double carries ~15.95 digits; an exact match is reported as 16


def lookup(summary, path):
    """Follow a dotted path; names may contain dots themselves (chain links such as
    b1.spring): at each level the longest key that the rest of the path starts with wins.
    A large scene's nodes, links and contacts not in summary.json are read from its arrays
    (martello.results)."""
    kind, _, rest = path.partition(".")
    arrays = summary.get("arrays") if isinstance(summary, dict) else None
    if kind in KINDS and isinstance(arrays, ItemArrays) and rest:
        names = arrays.names[kind]
        # the longest name the rest of the path starts with, as below
        heads = [i for i in range(len(rest), 0, -1) if i == len(rest) or rest[i] == "."]
        for i in heads:
            if rest[:i] not in (summary.get(kind) or {}) and rest[:i] in names:
                return lookup({kind: {rest[:i]: arrays.item(kind, rest[:i])}}, path)
    node, rest = summary, path
    while rest:
        if isinstance(node, list):
            head, _, tail = rest.partition(".")
            if not (head.isdigit() and int(head) < len(node)):
                raise KeyError(path)
            node, rest = node[int(head)], tail
        elif isinstance(node, dict):
            keys = [k for k in node if rest == k or rest.startswith(k + ".")]
            if not keys:
                raise KeyError(path)
            k = max(keys, key=len)
            node, rest = node[k], rest[len(k) + 1:]
        else:
            raise KeyError(path)
    if node is None:
        raise KeyError(path)
    return node


def oracle_values(check, source="<scene>"):
    name = check["closed_form"]
    fn = closed_form(name)
    if fn is None:
        raise SceneError(source, "check.closed_form", f"unknown closed form {name!r}",
                         "name a public function of martello.oracles or "
                         "martello.checks.dispatchers")
    try:
        result = fn(**check["params"])
    except (TypeError, ValueError) as exc:
        raise SceneError(source, "check.params", f"{name}: {exc}", "match the closed form's parameters") from None
    if isinstance(result, dict):
        return result
    if hasattr(result, "__dataclass_fields__"):
        return vars(result)
    raise SceneError(source, "check.closed_form", f"{name} returns a {type(result).__name__}, not named values",
                     "use a closed form that returns a dataclass or dict (e.g. two_body_impact)")


def _number(x):
    """float(x) for a number (a bool counts as 0 or 1), else None."""
    if isinstance(x, (str, bytes)) or not hasattr(x, "__float__"):
        return None
    try:
        return float(x)
    except (TypeError, ValueError, OverflowError):
        return None


def digits(value, reference):
    """Significant correct digits −log10 |rel. error| (absolute error when the reference is 0)."""
    err = abs(value - reference)
    scale = abs(reference) if reference != 0 else 1.0
    if err == 0:
        return DIGITS_CAP
    return max(0.0, min(DIGITS_CAP, -math.log10(err / scale)))


def verify(scene, summary):
    """Rows (dicts) of the verification table for one run."""
    check = scene.check
    ref = oracle_values(check, scene.source)
    rows = []
    for i, item in enumerate(check["compare"]):
        if item["oracle"] not in ref:
            raise SceneError(scene.source, f"check.compare[{i}].oracle", f"{item['oracle']!r} is not an output of "
                             f"{check['closed_form']}", "valid: " + ", ".join(ref))
        try:
            found = lookup(summary, item["result"])
        except KeyError:
            raise SceneError(scene.source, f"check.compare[{i}].result", f"{item['result']!r} is not in the summary",
                             "use a dotted path such as nodes.<name>.u or contacts.<name>.force") from None
        value = _number(found)
        if value is None:
            raise SceneError(scene.source, f"check.compare[{i}].result",
                             f"{item['result']!r} is a {type(found).__name__} in the summary, not a number",
                             "name a number, e.g. contacts.<name>.restitution.0 for a list's first entry")
        reference = _number(ref[item["oracle"]])
        if reference is None or not math.isfinite(reference):
            raise SceneError(scene.source, f"check.compare[{i}].oracle",
                             f"{check['closed_form']} gives {item['oracle']} = {ref[item['oracle']]!r}, "
                             "not a finite number", "compare a quantity the closed form defines here")
        rtol, atol = item.get("rtol") or 0.0, item.get("atol") or 0.0
        err = abs(value - reference)
        rows.append({
            "scene": scene.title, "file": scene.source, "quantity": item["result"],
            "value": value, "reference": reference, "abs_error": err,
            "rel_error": err / abs(reference) if reference != 0 else float("nan"),
            "digits": digits(value, reference), "rtol": rtol, "atol": atol,
            "scale": item.get("scale") or abs(reference),
            "passed": bool(err <= atol + rtol * abs(reference)), "why": item["why"],
            "evidence": kinds.evidence_of(item["oracle"])})
    return rows
