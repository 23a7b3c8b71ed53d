"""Verification of scenes without a closed form (for `martello check`): a run against the
stored reference data of its scene, within what the scene's own settings showed when the
reference was made."""

from __future__ import annotations

import math

from ..metrics.score import score
from ..paths import REFERENCE_ROOT
from ..reference.store import find_reference_data


def verify_reference_data(scene, summary, history, root=REFERENCE_ROOT, slack=1.0):
    """Rows for the catalogue verification table (the same keys as
    martello.checks.verify.verify) comparing a run of a scene with its stored reference data,
    or [] if it has none.

    The tolerance of each row is measured, not guessed: the stored data say how far the
    scene's own analysis settings (integrator, Δt) were from the reference when it was made
    (`catalogue_error` in reference.json, one value per metric). A row passes if the fresh
    error is at most 2·that + 10^-(digits trusted) (times `slack`), i.e. if neither the
    solver nor the reference has drifted."""
    ref = find_reference_data(scene, root)
    if ref is None or ref.kind != "data":
        return []
    m = score(summary, history, ref)
    expected = ref.provenance.get("catalogue_error", {})
    floor = 10.0 ** (-ref.trusted_digits()) if math.isfinite(ref.trusted_digits()) else 0.0
    rows = []
    for key, why in (("max_rel_error", "history u (normwise relative)"),
                     ("impact_time_error", "impact times after matching (s)"),
                     ("peak_penetration_error", "peak penetration (relative)"),
                     ("impact_count_error", "impact count (run − reference)")):
        value = m.get(key, math.nan)
        if value is None or (isinstance(value, float) and math.isnan(value)):
            continue
        exp = expected.get(key)
        if key == "impact_count_error":
            tol = abs(exp) if exp is not None else 0.0
            passed = abs(value) <= tol
        else:
            tol = slack * (2.0 * (exp if exp is not None else 0.0) + floor)
            passed = value <= tol
        digits = (max(0.0, min(16.0, -math.log10(value))) if key != "impact_count_error" and value > 0
                  else (16.0 if value == 0 else 0.0))
        rows.append({"scene": scene.title, "file": scene.source, "quantity": f"{key} vs {ref.name}",
                     "value": float(value), "reference": 0.0, "abs_error": float(abs(value)),
                     "rel_error": float("nan"), "digits": digits, "rtol": 0.0, "atol": float(tol),
                     "passed": bool(passed),
                     "why": f"{why}; reference trusted to {ref.trusted_digits():.1f} digits; "
                            f"error of these settings when the reference was made: {exp}"})
    return rows
