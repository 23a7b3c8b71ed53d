"""The vendor problems' closed forms (martello/oracles/vendor.py, docs/vendor-problems.md)
against the numbers the manuals print, and their physics against an independent integration."""

import math

import pytest
from scipy.integrate import solve_ivp

from martello.oracles.vendor import (INCH, LBF, abaqus_1_3_15_printed, abaqus_1_3_15_reference,
                                     ball_on_spring_surface, oscillator_on_stop, vm65_printed,
                                     vm65_reference)

M, K, H, G = 0.5 * LBF / INCH, 30 * LBF / INCH, INCH, 386 * INCH


def test_vm65_exact_values_agree_with_the_printed_digits():
    ex = ball_on_spring_surface(M, K, H, G)
    for key, (value, half) in vm65_printed().items():
        assert abs(getattr(ex, key) - value) <= half, key
    assert ex.ke_impact / (LBF * INCH) == pytest.approx(193.0, rel=1e-14)     # m g h, exactly
    w_k = 193.0 / 30.0                          # W/k in inches
    assert ex.max_compression / INCH == pytest.approx(w_k + math.sqrt(w_k ** 2 + 2 * w_k), rel=1e-12)


def test_vm65_compression_against_an_integration():
    ex = ball_on_spring_surface(M, K, H, G)
    ev = lambda t, y: y[1]                      # noqa: E731
    ev.terminal, ev.direction = True, -1
    r = solve_ivp(lambda t, y: [y[1], G - K / M * y[0]], (0, 2), [0.0, ex.v_impact], events=ev,
                  rtol=1e-12, atol=1e-15, method="DOP853")
    assert r.y_events[0][0][0] == pytest.approx(ex.max_compression, rel=1e-10)
    assert ex.t_impact + r.t_events[0][0] == pytest.approx(ex.t_max, rel=1e-10)


def test_abaqus_printed_values_and_where_they_differ():
    ref = abaqus_1_3_15_reference(2e11, 7800.0, 0.2, 2.0, 1.5, 0.001)
    p = abaqus_1_3_15_printed()
    for key in ("t_impact", "c", "duration", "force", "momentum_change"):
        value, half = p[key]
        assert abs(ref[key] - value) <= half, key
    assert ref["momentum_change"] == pytest.approx(9360.0, rel=1e-14)   # "9.36 kg m/s" is 9.36e3
    c = math.sqrt(2e11 / 7800.0)
    stated = 7800.0 * 1.5 * (c + 1.5) * 0.2                  # the manual's own F = rho v0 (c + v0) A
    assert round(stated / 1e6, 1) == 11.9 and round(ref["force"] / 1e6, 1) == 11.8
    assert ref["printed_v_after"] == pytest.approx(-1.5, rel=1e-12)


def test_sdnd101_period_against_an_integration():
    ex = oscillator_on_stop(100.0, 1e4, 1e6, 1.0)
    f = lambda t, y: [y[1], -(1e4 * y[0] + (1e6 * y[0] if y[0] > 0 else 0.0)) / 100.0]   # noqa: E731
    ev = lambda t, y: y[0]                      # noqa: E731
    ev.direction = 1
    r = solve_ivp(f, (1e-9, 0.5), [1e-9, 1.0], events=ev, rtol=1e-12, atol=1e-15, method="DOP853",
                  max_step=1e-3)
    assert r.t_events[0][0] == pytest.approx(ex.t_second_impact, rel=1e-8)
    assert ex.max_force == pytest.approx(1e6 / math.sqrt(1.01e6 / 100.0), rel=1e-15)
