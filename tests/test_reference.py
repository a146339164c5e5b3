"""The engine against the independent NumPy/SciPy reference, at tight tolerance."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import thermojitter as tj
from conftest import ENTRY, EXIT, GEO, PAPER, panels
from thermojitter import reference as ref

TIGHT = {"rtol": 1e-10, "atol": 1e-12}
REF_TIGHT = {"rtol": 1e-11, "atol": 1e-13, "method": "DOP853"}


def test_steady_state_matches_reference() -> None:
    for coupled in (True, False):
        eq = tj.steady_state(PAPER, coupled=coupled)
        tf, tb, th = ref.steady_state(PAPER, coupled=coupled)
        assert eq.T_front == pytest.approx(tf, rel=1e-11)
        assert eq.T_back == pytest.approx(tb, rel=1e-11)
        assert eq.theta == pytest.approx(th, rel=1e-9)


def assert_matches_reference(span: tuple[float, float], points: int) -> None:
    t_eval = np.linspace(span[0], span[1], points)
    eq = tj.steady_state(PAPER)
    y0 = (eq.T_front, eq.T_back, eq.theta, 0.0)
    sol = tj.simulate(PAPER, GEO, span, t_eval=t_eval, y0=y0, **TIGHT)
    want = ref.simulate(PAPER, GEO, span, t_eval=t_eval, y0=y0, **REF_TIGHT)
    assert np.max(np.abs(sol.theta - want.theta)) < 1e-6
    assert np.max(np.abs(sol.T_front - want.T_front)) < 1e-6
    # The eclipse really kicked the panel: the comparison is not between two flat lines.
    assert np.ptp(sol.theta) > np.radians(5.0)


def test_eclipse_passage_theta_matches_reference_within_a_microradian() -> None:
    """From the sunlit equilibrium through the whole shadow and the recovery after it."""
    assert_matches_reference((ENTRY - 600.0, EXIT + 1200.0), 2001)


@pytest.mark.slow
def test_whole_orbit_theta_matches_reference_within_a_microradian() -> None:
    assert_matches_reference((0.0, GEO.period), 20001)


@settings(max_examples=12)
@given(
    panel=panels(),
    start=st.floats(ENTRY - 1800.0, EXIT + 600.0),
    length=st.floats(60.0, 2400.0),
    model=st.sampled_from(["nonlinear", "linear"]),
    coupled=st.booleans(),
)
def test_random_panels_and_spans_match_reference(
    panel: tj.Panel, start: float, length: float, model: str, coupled: bool
) -> None:
    span = (start, start + length)
    eq = tj.steady_state(panel, coupled=coupled)
    y0 = (eq.T_front, eq.T_back, eq.theta, 0.0)
    t_eval = np.linspace(*span, 401)
    sol = tj.simulate(panel, GEO, span, model=model, coupled=coupled, y0=y0, t_eval=t_eval, **TIGHT)
    # The oracle must resolve the hinge oscillation: at most a tenth of its period per step.
    max_step = 0.1 / tj.natural_frequency(panel)
    want = ref.simulate(
        panel,
        GEO,
        span,
        model=model,
        coupled=coupled,
        y0=y0,
        t_eval=t_eval,
        max_step=max_step,
        **REF_TIGHT,
    )
    assert np.max(np.abs(sol.theta - want.theta)) < 1e-6
    assert np.max(np.abs(sol.T_front - want.T_front)) < 1e-6 * np.max(want.T_front)
    assert np.max(np.abs(sol.T_back - want.T_back)) < 1e-6 * np.max(want.T_back)


@pytest.mark.parametrize("layers", [1, 2])
def test_thermal_models_match_reference(layers: int) -> None:
    t_eval = np.linspace(0.0, GEO.period, 2001)
    sol = tj.simulate_thermal(PAPER, GEO, (0.0, GEO.period), layers=layers, t_eval=t_eval, **TIGHT)
    want = ref.simulate_thermal(
        PAPER, GEO, (0.0, GEO.period), layers=layers, t_eval=t_eval, **REF_TIGHT
    )
    got = sol.T if layers == 1 else sol.T_front
    assert got is not None
    assert np.max(np.abs(got - want.y[0])) < 1e-6


def test_shadow_intervals_match_reference() -> None:
    span = (-1.0e5, 4.0e5)
    got = GEO.shadow_intervals(*span)
    want = ref.shadow_intervals(GEO, *span)
    assert len(got) == len(want) == 6
    np.testing.assert_allclose(np.array(got), np.array(want), rtol=0, atol=1e-6)
