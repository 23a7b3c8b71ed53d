"""Closed-form oracles, one module per problem of the catalogue (docs/problems.md P1-P9,
"Integrators").

Every function here is coded from the mathematics in docs/problems.md and the papers it
cites; none of them time-steps the equations the solvers integrate, and nothing here imports
the run layer or the native binding. The tools used are explicit formulas, scalar root
finding (``scipy.optimize.brentq``) on closed-form functions, quadrature and special
functions. Two helpers are *semi-analytic*, and their docstrings say so:

* ``p2_bouncing.bouncing_oscillator_kelvin``: exact piecewise closed forms, with phase ends
  found as roots of closed-form scalar functions.
* ``p5_contact_laws.jankowski_realised_e``: a tight-tolerance ODE quadrature of the scaled
  energy equation in phase-plane variables. It does not integrate the equation of motion in
  time.

Units are SI. Sign conventions follow docs/problems.md. Displacements are positive toward
the obstacle. In P1 the multiplier ``lam = k h - m g`` is negative in contact (the seed's
sign), and ``force = -lam >= 0`` is the compressive force magnitude.

Results come back as small frozen dataclasses with named fields. Call
``dataclasses.asdict(result)`` to get a plain dict.

Modules: ``linear_sdof`` (the damped linear oscillator, shared), ``p1_p3_static``,
``p2_bouncing``, ``p4_rod_impact`` and ``p4_wave_theory``, ``p5_contact_laws``,
``p6_hysteresis``, ``p9_davis``, ``integrators``.
"""
