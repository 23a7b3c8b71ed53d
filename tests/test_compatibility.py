"""The scheme × integrator compatibility table: what the library does at run time must be
what its registry says (the table the front end loads, martello/scene/compatibility.py), and an
impossible pair is an error that names the integrators that would work — at load time and
through the C API."""

import pytest

from martello.binding.native import Model, Run, constant
from martello.errors import SceneError, SolverError
from martello.binding import native
from martello.run import integrator_settings
from martello.scene.compatibility import COMPATIBLE
from martello.scene.loader import from_dict
from martello.scene.spec import INTEGRATORS
from tests.dynamics_helpers import dynamic, two_bodies


@pytest.mark.parametrize("scheme", list(COMPATIBLE))
@pytest.mark.parametrize("integrator", INTEGRATORS)
def test_library_table_agrees_with_scene_table(scheme, integrator):
    # Build a one-contact model through the C API and ask the library to run it: an
    # incompatible pair must come back as MARTELLO_ERR_UNSUPPORTED naming the alternatives.
    m = Model(2, 0, 1, 0)
    m.set_node(0, 1.0, 0.0, 1.0)
    m.set_node(1, 1.0)
    par = [0.0] * constant("NPAR_CONTACT")
    par[constant("P_STIFF")] = 1e6
    par[constant("P_RESTITUTION")] = 0.5
    m.add_contact(0, 1, 0.0, native.value("schemes", scheme), constant("LAW_LINEAR"), par)
    an = from_dict(two_bodies("linear", 1e6, analysis=dynamic(dt=1e-3, t_end=1e-2))).analysis
    an = dict(an, integrator=integrator)
    r = Run()
    r.set_settings(integrator_settings(an))
    st = r.status_of(m)
    message = r.message()
    if integrator in COMPATIBLE[scheme]:
        assert "cannot run" not in message and "static only" not in message, message
    else:
        assert st == constant("MARTELLO_ERR_UNSUPPORTED"), (st, message)
        for other in COMPATIBLE[scheme]:
            assert other in message
        if not COMPATIBLE[scheme]:
            assert "static" in message


def test_scene_error_names_working_integrators():
    d = two_bodies("linear", 1e6, analysis=dynamic(dt=1e-3, t_end=1e-2))
    d["contact"][0] = {"name": "impact", "a": "m1", "b": "m2", "scheme": "restitution",
                       "restitution": 0.5}
    with pytest.raises(SceneError) as info:
        from_dict(d, source="pair.toml")
    assert info.value.field == "contact[0].scheme"
    assert "moreau-jean" in str(info.value) and "rkf45" in str(info.value)
