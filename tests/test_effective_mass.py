"""The effective mass of a contact is the library's: m* = 1/(B M⁻¹ Bᵀ) from the node masses
and the mass couplings (fortran/effective_mass.f90), a ground or fixed side infinitely
heavy. The Kelvin damping derived from a target restitution uses it, so with a coupling the
target is realised, which the two-mass formula m₁m₂/(m₁ + m₂) would miss."""

import math

import numpy as np
import pytest

from martello.binding import native
from martello.errors import SolverError
from martello.binding.native import Model, constant
from tests.dynamics_helpers import dynamic, execute


def _model(masses, contacts, couplings=(), fixed=()):
    m = Model(len(masses), 0, len(contacts), 0, len(couplings))
    for i, mass in enumerate(masses):
        m.set_node(i, mass, fixed=i in fixed)
    par = np.zeros(constant("NPAR_CONTACT"))
    par[constant("P_STIFF")] = 1e6
    for a, b in contacts:
        m.add_contact(a, b, 0.0, constant("SCHEME_PENALTY"), constant("LAW_LINEAR"), par)
    for a, b, c in couplings:
        m.add_mass_coupling(a, b, c)
    return m


def test_uncoupled_contacts_see_the_two_mass_formula_exactly():
    m = _model([1.0, 2.0, 3.0, 5.0], [(0, 1), (1, -1), (-1, 2), (2, 3), (3, 0)], fixed=(3,))
    # bit for bit the formula the front end used to pass in (no result moves)
    assert list(m.effective_masses()) == [1.0 * 2.0 / (1.0 + 2.0), 2.0, 3.0, 3.0, 1.0]


def test_a_contact_nothing_can_move_is_infinitely_heavy():
    m = _model([1.0, 2.0], [(0, -1), (0, 1)], fixed=(0, 1))
    assert list(m.effective_masses()) == [math.inf, math.inf]


def test_two_coupled_masses():
    # M = [[m1, c], [c, m2]]: B M⁻¹ Bᵀ = (m1 + m2 + 2c)/(m1 m2 − c²) for B = (1, −1)
    m1, m2, c = 1.0, 2.0, 0.3
    m = _model([m1, m2], [(0, 1), (0, -1)], couplings=[(0, 1, c)])
    want = [(m1 * m2 - c * c) / (m1 + m2 + 2 * c), (m1 * m2 - c * c) / m2]
    assert m.effective_masses() == pytest.approx(want, rel=1e-15)


def test_coupled_chain_against_a_dense_inverse():
    # a consistent-mass bar of 6 nodes, its end fixed, with contacts inside and to ground
    n, rho = 6, 0.7
    masses = [2.0 * rho] * n
    couplings = [(i, i + 1, rho) for i in range(n - 1)]
    contacts = [(1, 3), (4, -1), (0, 5), (2, 4)]
    m = _model(masses, contacts, couplings, fixed=(5,))
    M = np.diag(masses)
    for a, b, c in couplings:
        M[a, b] = M[b, a] = c
    free = [i for i in range(n) if i != 5]
    Minv = np.linalg.inv(M[np.ix_(free, free)])
    want = []
    for a, b in contacts:
        B = np.zeros(len(free))
        for node, sign in ((a, 1.0), (b, -1.0)):
            if node in free:
                B[free.index(node)] = sign
        want.append(1.0 / (B @ Minv @ B))
    # the condition of M is ~10: a few ulps of it
    assert m.effective_masses() == pytest.approx(want, rel=1e-13)


def test_indefinite_mass_matrix_is_an_argument_error():
    m = _model([1.0, 1.0], [(0, 1)], couplings=[(0, 1, 2.0)])
    with pytest.raises(SolverError, match="not positive definite"):
        m.effective_masses()


def test_nodes_must_be_set_first():
    m = Model(2, 0, 1, 0)
    m.set_node(0, 1.0)
    par = np.zeros(constant("NPAR_CONTACT"))
    m.add_contact(0, 1, 0.0, constant("SCHEME_LAGRANGE"), 0, par)
    with pytest.raises(SolverError, match="MARTELLO_ERR_STATE"):
        m.effective_masses()


def test_the_reserved_slot_of_the_old_mstar_is_refused():
    m = Model(2, 0, 1, 0)
    par = np.zeros(constant("NPAR_CONTACT"))
    par[5] = 0.5
    with pytest.raises(SolverError, match="reserved and must be 0"):
        m.add_contact(0, 1, 0.0, constant("SCHEME_PENALTY"), constant("LAW_LINEAR"), par)


def _coupled_kelvin_impact(coupling):
    d = {"node": [{"name": "m1", "mass": 1.0, "v0": 1.0}, {"name": "m2", "mass": 2.0}],
         "contact": [{"name": "impact", "a": "m1", "b": "m2", "scheme": "penalty",
                      "law": "kelvin", "stiffness": 1e4, "restitution": 0.5}],
         "analysis": dynamic("rk8pd", dt=1e-3, t_end=0.2, rtol=1e-11, atol=1e-14)}
    if coupling:
        d["mass_coupling"] = [{"a": "m1", "b": "m2", "value": coupling}]
    return execute(d)[0]["contacts"]["impact"]["restitution"]


@pytest.mark.parametrize("coupling", [0.0, 0.3])
def test_kelvin_target_restitution_is_realised_with_a_coupling(coupling):
    # The unclipped Kelvin law realises e exactly (Anagnostopoulos 1988) when its damping is
    # 2ξ√(k m*) with the m* of the relative motion, here (m1 m2 − c²)/(m1 + m2 + 2c) = 0.53
    # for c = 0.3 (the two-mass 2/3 would realise e = 0.457). rk8pd at rtol 1e-11 locates the
    # separation to ~1e-10: 1e-8 is a margin of 100.
    e = _coupled_kelvin_impact(coupling)
    assert len(e) == 1 and e[0] == pytest.approx(0.5, abs=1e-8)
