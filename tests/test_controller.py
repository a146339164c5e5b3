"""The adaptive integrator mirrors scipy's RK45: the same steps on the same problem.

The engine's speed is measured in benches/; here only that it takes the steps scipy's controller
would take (so that a speed-up never comes from taking fewer steps), on spans that cross a shadow
entry or exit, for the coupled non-linear model and the thermal model alone.
"""

from __future__ import annotations

import pytest

import thermojitter as tj
from conftest import ENTRY, EXIT, GEO, PAPER
from thermojitter import reference as ref


def _y0() -> list[float]:
    eq = tj.steady_state(PAPER)
    return [eq.T_front, eq.T_back, eq.theta, 0.0]


@pytest.mark.parametrize("boundary", [ENTRY, EXIT])
@pytest.mark.parametrize("rtol, atol", [(1e-8, 1e-10), (1e-6, 1e-8)])
def test_rk45_takes_scipys_steps_across_a_shadow_boundary(
    boundary: float, rtol: float, atol: float
) -> None:
    span = (boundary - 900.0, boundary + 900.0)
    y0 = _y0()
    sol = tj.simulate(PAPER, GEO, span, rtol=rtol, atol=atol, t_eval=[span[1]], y0=y0)
    peer = ref.simulate(PAPER, GEO, span, rtol=rtol, atol=atol, method="RK45", y0=y0)
    assert peer.n_steps > 500
    # Same method, same controller: equal up to rounding-level differences in a few decisions.
    assert abs(sol.n_steps - peer.n_steps) <= max(2, 0.002 * peer.n_steps), (
        sol.n_steps,
        peer.n_steps,
    )


def test_rk45_thermal_model_takes_scipys_steps() -> None:
    span = (0.0, GEO.period)
    y0 = ref.steady_state(PAPER, coupled=False)[:2]
    sol = tj.simulate_thermal(PAPER, GEO, span, rtol=1e-9, atol=1e-9, t_eval=[span[1]], y0=y0)
    peer = ref.simulate_thermal(PAPER, GEO, span, rtol=1e-9, atol=1e-9, method="RK45", y0=y0)
    assert peer.n_steps > 50
    assert abs(sol.n_steps - peer.n_steps) <= max(2, 0.002 * peer.n_steps), (
        sol.n_steps,
        peer.n_steps,
    )
