"""The kind of evidence a check row is, and what counts as verification (docs/coverage.md
"Kinds of rows").

A row is **verification** when its oracle is independent of the solvers (a closed form of
martello.oracles, a value published in a vendor's verification manual and its stated digits,
the independent engine martello.independent: the row's `evidence`), its tolerance is below 1 %
of the quantity (LOOSE_AT), and, where the tolerance is an error bound of the run itself
(the rows against the independent engine: reruns at 2Δt and 4Δt, or 100 and 10⁴ × rtol),
the run converges at the method's formal order (martello.checks.independent_rows,
ORDER_SLACK): a run that converges badly has no trusted bound, and 3 × its own Δt-vs-2Δt
difference would be loose exactly there. The other kinds are shown apart and never counted:

* **loose**: the tolerance is 1 % to 10 % of the quantity (asserted: a failure is a failure);
* **unconverged**: the run's reruns do not show the method's order, or the bound they give
  is ≥ 10 % (UNRESOLVED_AT) of the quantity: the error and the measured order are shown,
  and nothing is asserted — there is no bound to assert;
* **repeat**: the row repeats a row of the same scene (a contact identical to an earlier
  one: P8's three gap elements per floor give three equal rows), counted once;
* **regression**: against stored data martello made itself (drift, not accuracy).

Tolerances are relative to the reference value, or, where it is 0, to the quantity's scale
(`scale` of a `[check]` comparison, the independent engine's scale of that kind)."""

from __future__ import annotations

import math

VERIFICATION, LOOSE, UNCONVERGED, REPEAT, REGRESSION = (
    "verification", "loose", "unconverged", "repeat", "regression")
KINDS = (VERIFICATION, LOOSE, UNCONVERGED, REPEAT, REGRESSION)
# the oracles independent of the solvers (the `evidence` of a row): a closed form, a value
# printed in a vendor's manual (an oracle field `printed_*`, martello.oracles.vendor:
# docs/vendor-problems.md), the independent engine's solution
CLOSED_FORM, PUBLISHED, INDEPENDENT_ENGINE = "closed form", "published value", "independent reference"
INDEPENDENT = (CLOSED_FORM, PUBLISHED, INDEPENDENT_ENGINE)
PRINTED = "printed_"
LOOSE_AT = 0.01          # a tolerance of 1 % of the quantity or more is not verification
UNRESOLVED_AT = 0.10     # ... and of 10 % or more is no check at all


def evidence_of(oracle) -> str:
    """The evidence of a `[check]` row by the closed form's field it compares with: a printed
    value (`printed_*`) is a published value, any other field the closed form's own."""
    return PUBLISHED if oracle.startswith(PRINTED) else CLOSED_FORM


def relative_tolerance(row) -> float:
    """What a row allows, relative to its reference (or to its `scale` where the reference
    is 0): rtol + atol/|reference|. An exact row (rtol = atol = 0) allows 0."""
    rtol, atol = float(row.get("rtol") or 0.0), float(row.get("atol") or 0.0)
    if atol == 0.0:
        return rtol
    ref = abs(float(row.get("reference") or 0.0))
    scale = ref if ref > 0.0 else abs(float(row.get("scale") or 0.0))
    return rtol + (atol / scale if scale > 0.0 else math.inf)


def kind_of(row) -> str:
    """The kind of one row (its `kind` if already set: a repeat, an unconverged row)."""
    if row.get("kind"):
        return row["kind"]
    if row.get("evidence") not in INDEPENDENT:
        return REGRESSION
    t = relative_tolerance(row)
    if t >= UNRESOLVED_AT:
        return UNCONVERGED
    return LOOSE if t >= LOOSE_AT else VERIFICATION


def repeated_contacts(contacts) -> dict:
    """{name: the earlier identical contact's name} for the contacts of a scene that repeat
    another (the same pair, gap, scheme and law parameters: parallel gap elements). Their
    rows carry the same numbers as the first one's."""
    first, out = {}, {}
    for c in contacts:
        key = tuple(sorted((k, repr(v)) for k, v in dict(c).items() if k != "name"))
        if key in first:
            out[c["name"]] = first[key]
        else:
            first[key] = c["name"]
    return out


def _contact_of(quantity, names):
    """The contact a row's quantity is about (contacts.<name>.…, the longest name that
    fits: names may hold dots), or None."""
    if not quantity.startswith("contacts."):
        return None
    rest = quantity[len("contacts."):]
    fits = [n for n in names if rest.startswith(n + ".")]
    return max(fits, key=len) if fits else None


def classify(rows, contacts=()):
    """Set `kind` on every row of one scene's run (in place) and return the rows."""
    repeats = repeated_contacts(contacts)
    for r in rows:
        if r.get("evidence") in INDEPENDENT and _contact_of(r["quantity"], repeats) is not None:
            r["kind"] = REPEAT
            r["repeats"] = repeats[_contact_of(r["quantity"], repeats)]
        r["kind"] = kind_of(r)
        r["tolerance_relative"] = relative_tolerance(r)
    return rows


def counted(rows):
    """The rows that count as verification."""
    return [r for r in rows if kind_of(r) == VERIFICATION]


def asserted(row) -> bool:
    """Whether a row asserts its tolerance (an unconverged row has none to assert)."""
    return kind_of(row) != UNCONVERGED


def failed(row) -> bool:
    return asserted(row) and not row["passed"]
