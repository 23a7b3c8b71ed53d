"""References a run is scored against: ``base`` (the Reference and its trusted digits),
``closed_form`` (exact histories of the oracles), ``store`` (the stored data in reference/,
keyed by the physics digest), ``selection`` (which reference a scene gets), ``build`` (making
the stored data, scripts/regenerate_reference, and the references of `martello reference`),
``cache`` (those references, cached per physics) and ``independent_engine`` (the independent
engine, martello.independent, as a reference method)."""
