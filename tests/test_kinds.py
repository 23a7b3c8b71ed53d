"""What counts as verification (martello/checks/kinds.py, docs/coverage.md "Kinds of rows"):
a row's kind from its tolerance, the order its run converges at and whether it repeats
another row of its scene; the headline and the coverage cells count only verification rows.

Kind of evidence: tests of the counting itself (synthetic rows and runs with known errors),
and of the catalogue's [check] tables (no tolerance of 10 % or more)."""

import math

import pytest

from martello.checks import kinds
from martello.checks.independent_rows import JANKOWSKI_ORDER, accuracy_rows, formal_order
from martello.checks.verify import oracle_values
from martello.report import coverage, headline, summary_counts
from martello.scene import catalogue
from martello.scene.loader import load


def row(**kw):
    base = {"evidence": "closed form", "quantity": "nodes.m.u", "value": 1.0, "reference": 1.0,
            "rtol": 0.0, "atol": 0.0, "passed": True, "digits": 16.0, "file": "x.toml", "scene": "x"}
    return dict(base, **kw)


def test_a_tolerance_is_relative_to_the_reference_or_to_the_scale_where_it_is_0():
    assert kinds.relative_tolerance(row(rtol=1e-3)) == 1e-3
    assert kinds.relative_tolerance(row(atol=0.005, reference=-0.025)) == pytest.approx(0.2)
    assert kinds.relative_tolerance(row(atol=1e-3, reference=0.0, scale=0.5)) == pytest.approx(2e-3)
    assert kinds.relative_tolerance(row(atol=1e-3, reference=0.0)) == math.inf
    assert kinds.relative_tolerance(row()) == 0.0           # exact


@pytest.mark.parametrize("tol, kind", [(0.0, "verification"), (9.9e-3, "verification"), (1e-2, "loose"),
                                       (9.9e-2, "loose"), (0.1, "unconverged"), (0.92, "unconverged")])
def test_the_kind_follows_the_tolerance(tol, kind):
    assert kinds.kind_of(row(rtol=tol)) == kind
    assert kinds.kind_of(row(rtol=tol, evidence="regression")) == "regression"


def test_parallel_identical_contacts_repeat_the_first():
    s = load(catalogue.ROOT / "p8" / "p8_bare.toml")
    rep = kinds.repeated_contacts(s.contacts)
    assert rep == {"f1.gap2": "f1.gap1", "f1.gap3": "f1.gap1", "f2.gap2": "f2.gap1", "f2.gap3": "f2.gap1"}
    rows = [row(evidence="independent reference", quantity=f"contacts.{c}.impacts vs independent")
            for c in ("f1.gap1", "f1.gap2", "f2.gap3")] + [row(quantity="nodes.b1.f1.u_max")]
    kinds.classify(rows, s.contacts)
    assert [r["kind"] for r in rows] == ["verification", "repeat", "repeat", "verification"]
    assert rows[1]["repeats"] == "f1.gap1"


def _ref(u):
    """A minimal stored reference: one node whose u_max is u, trusted to 14 digits."""
    return {"contacts": {}, "nodes": {"m": {"u_max": u, "u_min": -u}},
            "energy": {"damping": 0.0, "plastic": 0.0, "contact": 0.0, "impact": 0.0, "input": 1.0,
                       "initial": 1.0},
            "digits": {"contacts": {}, "nodes": {"m": {"u_max": 14.0, "u_min": 14.0}},
                       "energy": {k: 14.0 for k in ("damping", "plastic", "contact", "impact", "input")}}}


def _runs(order, c=1e-4):
    """Summaries at h, 2h, 4h whose u_max and u_min are off by c (kh)^order."""
    out = []
    for k in (1, 2, 4):
        e = c * k ** order
        out.append({"contacts": {}, "nodes": {"m": {"u_max": 1.0 + e, "u_min": -1.0 + 0.5 * e, "a_absmax": 0.0}},
                    "energy": {"input": 1.0 + e}, "cost": {"steps": 0}})
    return out


def test_rows_of_a_run_converging_at_its_order_are_verification():
    rows = accuracy_rows("t", "t.toml", _ref(1.0), _runs(2.0), dt=1e-3, order_default=2.0)
    assert rows and all(r.get("kind") is None and r["passed"] for r in rows)
    assert all(kinds.kind_of(r) == "verification" for r in rows)
    assert rows[0]["order"] == pytest.approx(2.0)


def test_rows_of_a_badly_converging_run_are_not_verification():
    # order 0.4 where the method's is 2: 3 × |q_h − q_2h| would be 3 × 0.32 e_h, no bound
    rows = accuracy_rows("t", "t.toml", _ref(1.0), _runs(0.4), dt=1e-3, order_default=2.0)
    rows = [r for r in rows if r["order"] == r["order"]]      # not the dissipation, 0 in every run
    assert len(rows) == 3 and all(r["kind"] == "unconverged" for r in rows)
    assert all(not kinds.asserted(r) and not kinds.failed(r) for r in rows)
    assert "converges at order 0.40" in rows[0]["why"]


def test_a_first_order_method_is_held_to_its_own_order():
    assert all(kinds.kind_of(r) == "verification"
               for r in accuracy_rows("t", "t.toml", _ref(1.0), _runs(1.0), dt=1e-3, order_default=1.0))
    assert formal_order({"integrator": "moreau-jean"}) == 1.0
    assert formal_order({"integrator": "newmark", "gamma": 0.6}) == 1.0
    assert formal_order({"integrator": "hht"}) == 2.0
    assert formal_order({"integrator": "rk8pd"}) == 1.0            # error proportional to rtol
    assert formal_order({"integrator": "newmark", "gamma": 0.5}, [{"law": "jankowski"}]) == JANKOWSKI_ORDER


def test_the_headline_counts_verification_rows_only():
    rows = [row(), row(rtol=0.05), row(rtol=0.2), row(evidence="regression"),
            row(evidence="independent reference", kind="repeat")]
    c = summary_counts(rows, [], 5)
    assert (c["verification"], c["loose"], c["unconverged"], c["regression"], c["repeat"]) == (1, 1, 1, 1, 1)
    text = headline(rows, [], 5, 1.0)
    assert text.startswith("verification: 1 of 1 distinct rows passed (1 vs closed form, 0 vs published value, "
                           "0 vs independent")
    assert "1 of 1 loose rows" in text and "5 scenes" in text


def test_a_printed_value_is_verification_of_its_own_evidence():
    # a value printed in a vendor's manual (the closed form's `printed_*` fields,
    # martello.oracles.vendor) is an oracle independent of the solvers: verification,
    # counted apart from the closed forms; a cell holding both names both
    from martello.checks.kinds import evidence_of
    assert evidence_of("printed_t_impact") == "published value" and evidence_of("t_impact") == "closed form"
    base = {"problem": "vendor", "laws": "linear", "integrator": "rk8pd"}
    rows = [row(**base), row(evidence="published value", **base), row(evidence="published value", rtol=0.05, **base)]
    c = summary_counts(rows, [], 1)
    assert (c["verification"], c["verification_closed_form"], c["verification_published"], c["loose"]) == (2, 1, 1, 1)
    assert "(1 vs closed form, 1 vs published value, 0 vs independent reference" in headline(rows, [], 1, 1.0)
    cell = coverage(rows)[0]
    assert cell["evidence"] == "closed form, published value: not verification: 1 loose"
    assert cell["state"] == "partly verified"


def test_a_cell_is_verified_only_when_every_row_is_verification():
    base = {"problem": "P7", "laws": "kelvin", "integrator": "newmark"}
    assert coverage([row(**base)])[0]["state"] == "verified"
    assert coverage([row(**base), row(rtol=0.05, **base)])[0]["state"] == "partly verified"
    assert coverage([row(rtol=0.05, **base)])[0]["state"] == "not verified"
    assert coverage([row(**base), row(passed=False, **base)])[0]["state"] == "WRONG"
    # an unconverged row asserts nothing: it cannot make a cell wrong
    assert coverage([row(**base), row(rtol=0.5, passed=False, **base)])[0]["state"] == "partly verified"


def test_no_catalogue_check_allows_ten_percent():
    # docs/coverage.md: a check allowing 10 % or more is no check; 1-10 % is loose
    over = []
    for f in catalogue.scene_files():
        s = load(f)
        if s.check is None:
            continue
        ref = oracle_values(s.check, s.source)
        for item in s.check["compare"]:
            r = row(rtol=item.get("rtol") or 0.0, atol=item.get("atol") or 0.0,
                    reference=float(ref[item["oracle"]]), scale=item.get("scale"))
            if kinds.relative_tolerance(r) >= kinds.UNRESOLVED_AT:
                over.append(f"{f.name}: {item['result']}")
    assert not over, over
