"""The scheme x integrator compatibility table of the front end: the loader refuses a scene
whose contacts an integrator cannot run, and the studies pick integrators from it."""

from .spec import INTEGRATORS

# Which contact schemes each integrator runs (fortran/integrator_settings.f90 holds the same
# table for the C API; tests/test_compatibility.py checks they agree). Penalty contacts are
# smooth forces; lagrange and restitution contacts need event location or impulse-level
# time stepping; augmented-lagrange is a static scheme.
COMPATIBLE = {
    "penalty": tuple(i for i in INTEGRATORS if i != "newmark-lagrange"),
    "lagrange": ("moreau-jean", "newmark-lagrange", "rkf45", "rk8pd", "msbdf", "ida"),
    "restitution": ("moreau-jean", "newmark-lagrange", "rkf45", "rk8pd", "msbdf", "ida"),
    "augmented-lagrange": (),
}
