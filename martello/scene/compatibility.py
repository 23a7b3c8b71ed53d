"""The scheme x integrator compatibility table of the front end: the loader refuses a scene
whose contacts an integrator cannot run, and the studies pick integrators from it. It is the
library's (the registry's table "compatibility"; tests/test_registry.py): penalty contacts
are smooth forces; lagrange and restitution contacts need event location or impulse-level
time stepping; augmented-lagrange is a static scheme."""

from ..binding import native

COMPATIBLE = native.compatibility()
