"""Scenes: the TOML description of a 1D mechanical network and everything that reads it.

``loader`` reads and validates a scene file (``load``, ``from_dict``) into a ``Scene``;
``spec`` is the format's vocabulary, ``fields`` the field checker every table goes through,
``compatibility`` the scheme x integrator table; ``chain`` and ``bars`` are the generators
that expand ``[[chain]]`` and ``[[bar]]`` tables; ``variants`` derives scene dicts with
another analysis or other contacts (studies, reference data); ``catalogue`` lists the
scene files of benchmarks/. docs/scene-input.md documents the format."""
