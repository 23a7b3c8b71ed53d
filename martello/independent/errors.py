"""The one error of the independent engine."""


class Unsupported(ValueError):
    """The scene has a part the independent engine does not model."""
