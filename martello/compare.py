"""`martello compare` (placeholder until the Studies issue lands it)."""

from .errors import MartelloError


def main(args):
    raise MartelloError("martello compare is not built yet")
