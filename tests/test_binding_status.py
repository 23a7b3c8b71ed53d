"""Every getter of the binding checks the status the library returns (martello/binding/
native.py): a run handle the library refuses (freed: NULL) makes each raise SolverError
naming what it asked for, instead of handing back the zeros of its unfilled buffers."""

import pytest

from martello.binding import native
from martello.errors import SolverError


@pytest.mark.parametrize("getter, args", [
    ("history", ()), ("events", ()), ("counters", ()), ("peaks", (3, 2)), ("energy", ()),
    ("link_peaks", (2,))])
def test_a_refused_getter_raises_naming_what(getter, args):
    run = native.Run()
    run.free()
    assert not run.handle.value              # freed: the library sees NULL
    with pytest.raises(SolverError, match="MARTELLO_ERR_ARGUMENT"):
        getattr(run, getter)(*args)


def test_the_registry_reads_are_checked_too():
    with pytest.raises(KeyError, match="no table"):
        native.registry("no such table")
    assert native.registry("tables")         # and a table that exists reads whole
