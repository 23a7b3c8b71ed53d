"""Every closed form of martello.oracles by its bare name, in one namespace:
``martello.closed_forms.mass_on_plane_static(m, k, h, g)``,
``martello.closed_forms.newton_impact(m1, m2, v1, v2, e)``, ...

The functions are those of the oracle modules (one per problem, docs/problems.md), coded
from the mathematics alone: see ``martello.oracles`` for what each module covers and how
(explicit formulas, scalar root finding, quadrature). Their results are small frozen
dataclasses, exported here too (``BounceSequence``, ``NewtonImpact``, ...);
``dataclasses.asdict(result)`` gives a plain dict. Names are unique across the modules."""

import dataclasses
import importlib
import inspect
import pkgutil

from . import oracles

__all__ = []


def _collect():
    for info in sorted(pkgutil.iter_modules(oracles.__path__), key=lambda i: i.name):
        mod = importlib.import_module(f"{oracles.__name__}.{info.name}")
        for name, obj in vars(mod).items():
            own = getattr(obj, "__module__", None) == mod.__name__
            public = own and not name.startswith("_") and (
                inspect.isfunction(obj) or (inspect.isclass(obj) and dataclasses.is_dataclass(obj)))
            if not public:
                continue
            if name in globals() and name in __all__:
                raise AssertionError(f"closed form {name} is defined in {globals()[name].__module__} "
                                     f"and {mod.__name__}")
            globals()[name] = obj
            __all__.append(name)
    __all__.sort()


_collect()
