"""The closed forms a scene's [check] table may name: every public function of the oracle
modules (martello.oracles) and of the catalogue dispatchers (martello.checks.dispatchers),
by its bare name. Names are unique across those modules."""

import inspect
from functools import lru_cache

from ..oracles import (integrators, linear_sdof, p1_p3_static, p2_bouncing, p4_rod_impact,
                       p4_wave_theory, p5_contact_laws, p6_hysteresis, p9_davis, p10_frames, p11_buildings, vendor)
from . import dispatchers

MODULES = (p1_p3_static, p2_bouncing, p4_rod_impact, p4_wave_theory, p5_contact_laws,
           p6_hysteresis, p9_davis, p10_frames, p11_buildings, vendor, linear_sdof, integrators, dispatchers)


@lru_cache(maxsize=None)
def closed_forms():
    """{name: function} of every nameable closed form (read it, do not change it)."""
    out = {}
    for mod in MODULES:
        for name, fn in vars(mod).items():
            own = inspect.isfunction(fn) and fn.__module__ == mod.__name__
            if own and not name.startswith("_"):
                if name in out:
                    raise AssertionError(f"closed form {name} is defined in {out[name].__module__} "
                                         f"and {mod.__name__}")
                out[name] = fn
    return out


def closed_form(name):
    """The closed form called name, or None."""
    return closed_forms().get(name)
