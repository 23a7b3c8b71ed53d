"""Verification: a run against its scene's closed form (``verify``, the [check] table, with
the names it may use in ``oracle_names`` and the catalogue ``dispatchers``), against stored
reference data (``reference_data``), and the problem-specific ``measures`` (P4 rod impact)
that `martello run` and `martello check` add to a summary."""
