"""References a run is scored against: ``base`` (the Reference and its trusted digits),
``closed_form`` (exact histories of the oracles), ``store`` (the stored data in reference/,
keyed by the physics digest), ``selection`` (which reference a scene gets), ``build`` (making
the stored data, scripts/regenerate_reference) and ``event_located`` (the independent
scipy engine some of them are built with)."""
