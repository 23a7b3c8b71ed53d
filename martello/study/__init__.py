"""Studies: sweeps of scenes x contact schemes x integrators x steps or tolerances, scored
against references and plotted (``sweep``, run from a ``study_file``), and the stability
``atlas``; ``outcome`` classifies each run and ``output`` writes what they show
(docs/studies.md)."""
