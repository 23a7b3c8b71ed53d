"""A run's outcome in words, from its status: the classification every row of a study or an
atlas carries; and the exit code of a study from its rows."""

import sys


def status_class(status, message=""):
    """A run's outcome in words: ok, diverged (NaN or energy growth), unstable (step past the
    explicit limit), failed (Newton, step-size underflow, ...), unsupported (not built or not
    possible), incompatible (the scene cannot run on this integrator), error."""
    table = {"MARTELLO_OK": "ok", "MARTELLO_ILL_CONDITIONED": "ok", "MARTELLO_ROOT_FOUND": "ok",
             "MARTELLO_ERR_UNSTABLE": "unstable: step beyond the explicit limit",
             "MARTELLO_ERR_NOT_CONVERGED": "failed: no Newton convergence",
             "MARTELLO_ERR_STEP_UNDERFLOW": "failed: step-size underflow",
             "MARTELLO_ERR_UNSUPPORTED": "unsupported"}
    if status == "MARTELLO_ERR_DIVERGED":
        return "diverged: NaN" if "non-finite" in (message or "") else "diverged: energy growth"
    if status in table:
        return table[status]
    if status in ("incompatible", "error"):
        return status
    return f"failed: {status}"


def failed_rows(rows, key, table, stream=None):
    """Exit code of a study: 1 when a row has no outcome (status "error": the run raised, or
    its worker died however often it was run), saying how many; diverged, unstable or
    unconverged runs are outcomes of the sweep, not failures of the study."""
    bad = [r for r in rows if r.get(key) == "error"]
    if not bad:
        return 0
    first = (bad[0].get("message") or "").strip()
    print(f"martello: error: {len(bad)} of {len(rows)} runs failed without a result "
          f"(status error; the first: {first}); see {table}", file=stream or sys.stderr)
    return 1
