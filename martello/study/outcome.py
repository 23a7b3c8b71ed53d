"""A run's outcome in words, from its status: the classification every row of a study or an
atlas carries."""


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
