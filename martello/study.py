"""`martello study` (placeholder until the Studies issue lands it)."""

from .errors import MartelloError


def main(args):
    raise MartelloError("martello study is not built yet")
