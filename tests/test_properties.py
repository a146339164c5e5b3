"""Physical and numerical properties: convergence order, conservation, fixed points, geometry."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import thermojitter as tj
from conftest import ENTRY, EXIT, GEO, PAPER, panels


def test_paper_numbers() -> None:
    eq = tj.steady_state(PAPER)
    assert 4.5 < eq.theta_deg < 5.5  # "about 5°"
    assert 69.0 < GEO.eclipse_duration / 60 < 70.0  # "about 70 min"
    assert tj.beam_frequency(PAPER) == pytest.approx(0.144, abs=5e-4)  # f_n = 0.144 Hz
    # Deflection-criterion K_el gives a jitter frequency about 12 % below f_n.
    mismatch = 1 - tj.natural_frequency(PAPER) / tj.beam_frequency(PAPER)
    assert 0.10 < mismatch < 0.14


def test_one_orbit_reports_entry_and_exit_transients() -> None:
    sol = tj.simulate(PAPER, GEO, (0.0, GEO.period))
    assert sol.t[0] == 0.0 and sol.t[-1] == pytest.approx(GEO.period)
    assert np.all(np.isfinite(sol.y))
    eq = tj.steady_state(PAPER)
    after_entry = (sol.t > ENTRY) & (sol.t < ENTRY + 600)
    after_exit = (sol.t > EXIT) & (sol.t < EXIT + 600)
    # Entry: the gradient collapses and reverses, the panel swings below zero; exit overshoots.
    assert sol.theta[after_entry].min() < 0.0
    assert sol.theta[after_exit].max() > 1.5 * eq.theta
    assert np.all(sol.sunlit[(sol.t > ENTRY + 1) & (sol.t < EXIT - 1)] == 0.0)
    assert sol.n_steps > 0 and sol.n_rhs >= 6 * sol.n_steps


def _theta_end_rk4(dt: float, span: tuple[float, float], y0: tuple[float, ...]) -> float:
    return float(
        tj.simulate(PAPER, GEO, span, method="rk4", dt=dt, y0=y0, t_eval=[span[1]]).theta[-1]
    )


def test_rk4_converges_at_fourth_order_through_shadow_entry() -> None:
    span = (ENTRY - 200.0, ENTRY + 400.0)
    eq = tj.steady_state(PAPER)
    y0 = (eq.T_front, eq.T_back, eq.theta, 0.0)
    exact = tj.simulate(PAPER, GEO, span, y0=y0, rtol=1e-12, atol=1e-14, t_eval=[span[1]]).theta[-1]
    errors = [abs(_theta_end_rk4(dt, span, y0) - exact) for dt in (0.4, 0.2, 0.1)]
    ratios = [errors[0] / errors[1], errors[1] / errors[2]]
    for r in ratios:
        assert 13.0 < r < 19.0, (errors, ratios)


@settings(max_examples=25)
@given(
    panel=panels(),
    moment=st.floats(-800.0, 800.0),
    theta0=st.floats(-0.5, 0.5),
    rate0=st.floats(-0.3, 0.3),
    model=st.sampled_from(["nonlinear", "linear"]),
)
def test_undamped_hinge_conserves_energy(
    panel: tj.Panel, moment: float, theta0: float, rate0: float, model: str
) -> None:
    p = panel.replace(damping=0.0)
    sol = tj.simulate_hinge(
        p, moment, (0.0, 200.0), y0=(theta0, rate0), model=model, rtol=1e-11, atol=1e-13, dt_out=1.0
    )
    energy = tj.hinge_energy(p, sol.theta, sol.theta_dot, moment, model=model)
    scale = 0.5 * p.hinge_stiffness * max(np.max(np.abs(sol.theta)), 1e-3) ** 2
    assert np.max(np.abs(energy - energy[0])) < 1e-7 * scale


def test_damped_hinge_loses_energy() -> None:
    sol = tj.simulate_hinge(PAPER.replace(damping=50.0), 300.0, (0.0, 100.0), dt_out=1.0)
    energy = tj.hinge_energy(PAPER, sol.theta, sol.theta_dot, 300.0)
    assert np.all(np.diff(energy) <= 1e-9)
    assert energy[-1] < energy[0]


@settings(max_examples=15)
@given(panel=panels(), coupled=st.booleans(), model=st.sampled_from(["nonlinear", "linear"]))
def test_sunlit_equilibrium_is_a_fixed_point(panel: tj.Panel, coupled: bool, model: str) -> None:
    eq = tj.steady_state(panel, coupled=coupled)
    y0 = (eq.T_front, eq.T_back, eq.theta, 0.0)

    def drift(rtol: float) -> tuple[float, float]:
        sol = tj.simulate(
            panel,
            GEO,
            (0.0, 0.9 * ENTRY),
            model=model,
            coupled=coupled,
            y0=y0,
            dt_out=100.0,
            rtol=rtol,
            atol=rtol * 1e-2,
            on_limit="ignore",  # a fixed point is one at any angle the model takes
        )
        return (
            float(np.max(np.abs(sol.theta - eq.theta))),
            float(np.max(np.abs(sol.T_front - eq.T_front))),
        )

    loose, tight = drift(1e-8), drift(1e-11)
    # At a true fixed point the only motion is integration error, which follows the tolerance.
    # Below the critical damping the fixed point is unstable: that error then grows as e^(g t),
    # with g the growth rate of the linear analysis.
    growth = max(tj.flutter(panel, model, coupled=coupled).growth_rate, 0.0)
    amplification = math.exp(growth * 0.9 * ENTRY)
    assert tight[0] < 1e-8 * amplification and tight[1] < 1e-7 * amplification
    if growth == 0.0:
        # Stable: the drift is pure truncation error, so it shrinks with the tolerance. (When
        # unstable, round-off is amplified by e^(g t) too and the tolerance no longer rules it.)
        assert tight[0] <= loose[0] / 100 + 1e-14
    assert abs(eq.thermal_moment - panel.hinge_stiffness * eq.theta) < 1e-8 * abs(eq.thermal_moment)


@settings(max_examples=50)
@given(
    radius=st.floats(6.6e6, 5e8),
    period=st.floats(3000.0, 3e6),
    phase0=st.floats(-10.0, 10.0),
    t0=st.floats(-1e7, 1e7),
    n_orbits=st.floats(0.1, 20.0),
)
def test_shadow_intervals_have_their_analytic_length(
    radius: float, period: float, phase0: float, t0: float, n_orbits: float
) -> None:
    orbit = tj.Orbit(radius=radius, period=period, phase0=phase0)
    t1 = t0 + n_orbits * period
    duration = period * math.asin(orbit.earth_radius / radius) / math.pi
    intervals = orbit.shadow_intervals(t0, t1)
    assert len(intervals) >= math.floor(n_orbits) - 1
    for a, b in intervals:
        assert t0 <= a < b <= t1
        if t0 < a and b < t1:  # not clipped
            assert b - a == pytest.approx(duration, rel=1e-9, abs=1e-6)
            mid = 0.5 * (a + b)
            beta = 2 * math.pi * mid / period + phase0
            assert math.cos(beta) == pytest.approx(-1.0, abs=1e-9)
    # Consecutive eclipses are one period apart.
    starts = [a for a, _ in intervals if a > t0]
    assert np.allclose(np.diff(starts), period, rtol=1e-9)
    # The illumination agrees with the intervals just inside and outside each one.
    for a, b in intervals:
        if b - a > 1e-3 * duration:
            assert orbit.illumination(0.5 * (a + b))[0] == 0.0


def test_frozen_area_keeps_the_flux_of_a_flat_panel() -> None:
    coupled = tj.steady_state(PAPER, coupled=True)
    frozen = tj.steady_state(PAPER, coupled=False)
    assert frozen.theta > coupled.theta  # cos θ < 1 reduces the absorbed flux
    assert frozen.T_front > coupled.T_front


def test_linear_and_nonlinear_agree_for_the_paper_panel() -> None:
    span = (ENTRY - 60.0, ENTRY + 900.0)
    eq = tj.steady_state(PAPER)
    y0 = (eq.T_front, eq.T_back, eq.theta, 0.0)
    a = tj.simulate(PAPER, GEO, span, model="nonlinear", y0=y0, dt_out=1.0)
    b = tj.simulate(PAPER, GEO, span, model="linear", y0=y0, dt_out=1.0)
    diff = np.max(np.abs(a.theta - b.theta))
    assert 0 < diff < np.radians(0.5)  # "almost indistinguishable" (paper Figs. 19–20)


def test_exports() -> None:
    sol = tj.simulate(PAPER, GEO, (0.0, 100.0), dt_out=10.0)
    frame = sol.to_pandas()
    assert list(frame.columns) == [
        "T_front",
        "T_back",
        "theta",
        "theta_dot",
        "thermal_moment",
        "sunlit",
    ]
    assert len(frame) == 11 and frame.index.name == "t"
    ds = sol.to_xarray()
    assert ds["theta"].shape == (11,)
    assert sol.y.shape == (4, 11)
