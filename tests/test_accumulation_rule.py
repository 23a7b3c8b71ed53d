"""One accumulation rule whatever is recorded (docs/impulse.md §4): a bouncing oscillator and a
Davis oscillator with parameters of their own (not the catalogue's), scored against closed forms
independent of martello's solvers (martello.oracles: the bouncing sequence and its Zeno time;
the Davis flights in closed form, their ends as roots, the accumulation summed). Verification:
the first 15 impact times and the start of the persistent phase within 1e-6 s (the issue's
bound; measured 1e-10 s and better), the impacts in order, and the same number of impacts at
another output interval and output.every. A sample of benchmarks/invariance/accumulation.py,
which runs every integrator at two output intervals x every = 1, 7, 1000."""

import math

import pytest

from benchmarks.invariance import accumulation as A
from martello.oracles.p2_bouncing import bouncing_oscillator_restitution
from martello.oracles.p9_davis import davis_impact_sequence

# one-step, BDF (GSL), DAE (IDA), and SUNDIALS' ODE solvers; each scene on three of them
SAMPLE = [("bouncing", "rk8pd"), ("bouncing", "msbdf"), ("bouncing", "cvode"),
          ("davis", "rkf45"), ("davis", "ida"), ("davis", "arkode")]


@pytest.mark.parametrize("kind,integrator", SAMPLE)
def test_impacts_and_accumulation_time_whatever_is_recorded(kind, integrator):
    dts = A.SCENES[kind][1]
    runs = [A.measure(kind, integrator, dts[0], 1), A.measure(kind, integrator, dts[1], 1000)]
    for r in runs:
        assert r["status"] == "MARTELLO_OK"
        assert r["impact_error"] <= A.LIMIT, r
        assert r["t_inf_error"] <= A.LIMIT, r
        assert r["release_error"] <= A.LIMIT, r
        assert r["in_order"], r["first"]
    # the rule reads the impact sequence, never the output: the same impacts resolved
    assert runs[0]["impacts_before_t_inf"] == runs[1]["impacts_before_t_inf"] > A.N_IMPACTS


def test_the_davis_sequence_is_the_bouncing_oscillators_under_a_constant_load():
    # the oracle checked against another closed form: with eta -> 0 and no damping the load is
    # the constant F, and the Davis oscillator started at x0 = -h is P2's bouncing oscillator
    # (u = x + h, m = k = 1, g = F + h); impacts, speeds and Zeno time to rounding
    F, h, r = 1.5, 0.5, 0.7
    d = davis_impact_sequence(F, 1e-9, r, zeta=0.0, x0=-h, t_end=60.0)
    p2 = bouncing_oscillator_restitution(1.0, 1.0, h, F + h, r, len(d.t))
    assert len(d.t) > 50
    assert max(abs(d.t - p2.t)) < 1e-12
    assert max(abs(d.v - p2.v)) < 1e-12
    assert abs(d.accumulation - p2.zeno_time) < 1e-12
    # the release is where the load turns: eta t = pi/2
    assert math.isclose(d.release, math.pi / 2 / 1e-9, rel_tol=1e-12)
