"""Scoring: the metrics of a run (or of another code's history) against a reference
(docs/problems.md "Metrics"). ``score`` computes them all; ``norms`` holds the error norms
and significant digits, ``event_matching`` pairs impacts one to one, ``from_history``
recovers a summary from a bare history."""
