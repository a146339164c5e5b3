"""The hinge model's range of validity in every run: theta_limit and on_limit ("flag", "stop",
"ignore") of simulate, simulate_distributed, calibrate and simulate_orbits."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest

import thermojitter as tj
from conftest import ENTRY, GEO, PAPER
from thermojitter.beam import eclipse_window

LIMIT = tj.simulate_orbits.__kwdefaults__["theta_limit"]


def test_the_default_limit_is_the_engines() -> None:
    assert LIMIT == tj._core.VALIDITY_LIMIT == pytest.approx(math.radians(20.0))
    for fn in (tj.simulate, tj.simulate_distributed, tj.calibrate):
        assert fn.__kwdefaults__["theta_limit"] == LIMIT
        assert fn.__kwdefaults__["on_limit"] == "flag"


# The case: the 8-node paper panel flutters at its own damping and swings to ±99°.


def test_an_eight_node_run_that_flutters_is_flagged_with_one_warning() -> None:
    with pytest.warns(tj.ValidityLimitWarning, match="theta_limit = 20°") as seen:
        sol = tj.simulate(PAPER, GEO, (0.0, GEO.period), layers=8)
    assert len(seen) == 1
    c = sol.limit_crossing
    assert isinstance(c, tj.LimitCrossing) and not sol.stopped_at_limit
    assert c.orbit == 0 and LIMIT < abs(c.theta) < LIMIT + 1e-9
    # The first crossing: every sample before it is inside, the next one near the limit.
    before = sol.t < c.t
    assert np.all(np.abs(sol.theta[before]) <= LIMIT)
    assert abs(sol.theta[np.searchsorted(sol.t, c.t)]) > LIMIT - 0.02
    assert sol.t[-1] == GEO.period and np.abs(sol.theta).max() > math.radians(90.0)


def test_stop_ends_the_run_at_the_crossing() -> None:
    flagged = tj.simulate(PAPER, GEO, (0.0, GEO.period), layers=8, on_limit="ignore")
    assert flagged.limit_crossing is None
    with pytest.warns(tj.ValidityLimitWarning, match="stopped"):
        sol = tj.simulate(PAPER, GEO, (0.0, GEO.period), layers=8, on_limit="stop")
    c = sol.limit_crossing
    assert c is not None and sol.stopped_at_limit
    assert sol.t[-1] <= c.t < sol.t[-1] + 0.5  # the samples end at the crossing
    assert np.abs(sol.theta).max() <= LIMIT
    assert sol.y_end[-2] == c.theta  # the state at the crossing
    # The same bits as the unwatched run up to there.
    np.testing.assert_array_equal(sol.theta, flagged.theta[: sol.t.size])


def test_ignore_checks_nothing_and_says_nothing() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # "ignore" says nothing
        sol = tj.simulate(PAPER, GEO, (0.0, GEO.period), layers=8, on_limit="ignore")
    assert sol.limit_crossing is None and not sol.stopped_at_limit
    assert np.abs(sol.theta).max() > math.radians(90.0)


def test_a_crossing_between_two_samples_is_caught() -> None:
    """Samples only at the ends of the orbit: the crossing happens between them, and is found
    where it happens (the first peak beyond 20° passes it by only 1e-5 rad)."""
    with pytest.warns(tj.ValidityLimitWarning):
        sol = tj.simulate(PAPER, GEO, (0.0, GEO.period), layers=8, dt_out=GEO.period)
        sampled = tj.simulate(PAPER, GEO, (0.0, GEO.period), layers=8)
    assert sol.t.tolist() == [0.0, GEO.period]
    c = sol.limit_crossing
    assert c is not None and c == sampled.limit_crossing
    near = [c.t - 1e-3, c.t]
    around = tj.simulate(
        PAPER, GEO, (0.0, c.t + 1.0), layers=8, t_eval=near, on_limit="ignore"
    ).theta
    assert abs(around[0]) <= LIMIT < abs(around[1])


def test_the_two_layer_paper_panel_stays_inside_silently() -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # "ignore" says nothing
        sol = tj.simulate(PAPER, GEO, (ENTRY - 60.0, ENTRY + 900.0))
    assert sol.limit_crossing is None


def test_a_release_from_rest_overshoots_a_small_limit_with_either_method() -> None:
    """Released at θ = 0 from the sunlit temperatures, the hinge swings to nearly twice its
    equilibrium angle (4.9°): past a 6° limit within its first half period."""
    eq = tj.steady_state(PAPER)
    y0 = (eq.T_front, eq.T_back, 0.0, 0.0)
    limit = math.radians(6.0)
    for method in ("rk45", "rk4"):
        with pytest.warns(tj.ValidityLimitWarning):
            sol = tj.simulate(
                PAPER,
                GEO,
                (0.0, 60.0),
                y0=y0,
                method=method,  # type: ignore[arg-type]
                dt=0.05,
                theta_limit=limit,
                on_limit="stop",
            )
        c = sol.limit_crossing
        assert c is not None and sol.stopped_at_limit and 0.0 < c.t < 5.0
        assert limit < c.theta < limit + 1e-9 and np.abs(sol.theta).max() <= limit


# The distributed panel: θ_f.

SPAN = eclipse_window(GEO)
COARSE = {"elements": 10, "modes": 2}
THETA_F_LIMIT = 0.12  # between the sunlit equilibrium (0.085 rad) and the jitter's peak (0.157)


def test_distributed_runs_flag_and_stop_at_theta_f_limit() -> None:
    with pytest.warns(tj.ValidityLimitWarning, match="θ_f passed") as seen:
        sol = tj.simulate_distributed(PAPER, GEO, SPAN, theta_limit=THETA_F_LIMIT, **COARSE)
    assert len(seen) == 1
    c = sol.limit_crossing
    assert c is not None and not sol.stopped_at_limit
    assert THETA_F_LIMIT < abs(c.theta) < THETA_F_LIMIT + 1e-9
    assert np.all(np.abs(sol.theta_f[sol.t < c.t]) <= THETA_F_LIMIT)
    assert sol.t[-1] == SPAN[1]
    with pytest.warns(tj.ValidityLimitWarning):
        stopped = tj.simulate_distributed(
            PAPER, GEO, SPAN, theta_limit=THETA_F_LIMIT, on_limit="stop", **COARSE
        )
    assert stopped.stopped_at_limit and stopped.limit_crossing == c
    assert stopped.t[-1] <= c.t and np.abs(stopped.theta_f).max() <= THETA_F_LIMIT
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # "ignore" says nothing
        ignored = tj.simulate_distributed(
            PAPER, GEO, SPAN, theta_limit=THETA_F_LIMIT, on_limit="ignore", **COARSE
        )
    assert ignored.limit_crossing is None
    np.testing.assert_array_equal(ignored.theta_f, sol.theta_f)


def test_distributed_crossing_between_samples_is_caught() -> None:
    with pytest.warns(tj.ValidityLimitWarning):
        fine = tj.simulate_distributed(PAPER, GEO, SPAN, theta_limit=THETA_F_LIMIT, **COARSE)
        ends = tj.simulate_distributed(
            PAPER, GEO, SPAN, theta_limit=THETA_F_LIMIT, dt_out=SPAN[1] - SPAN[0], **COARSE
        )
    assert ends.t.size == 2
    assert ends.limit_crossing == fine.limit_crossing


# Calibration: the fitted model's run is checked, not the trials.

T = np.arange(0.0, 120.0, 0.5)
EQ = tj.steady_state(PAPER)
RELEASED = (EQ.T_front, EQ.T_back, 0.0, 0.0)


def test_calibrate_flags_the_fitted_models_crossing() -> None:
    """The series of a release from rest (it swings past 6° at first); the fit starts from a
    stiffer hinge."""
    sol = tj.simulate(PAPER, GEO, (T[0], T[-1]), t_eval=T, y0=RELEASED, rtol=1e-10, atol=1e-12)
    theta = np.asarray(sol.theta)
    limit = math.radians(6.0)
    fit_args = {"panel": PAPER.replace(hinge_stiffness=4800.0), "orbit": GEO, "y0": RELEASED}
    with pytest.warns(tj.ValidityLimitWarning) as seen:
        fit = tj.calibrate(T, theta, theta_limit=limit, **fit_args)  # type: ignore[arg-type]
    assert len(seen) == 1
    assert fit.parameters["hinge_stiffness"] == pytest.approx(PAPER.hinge_stiffness, rel=1e-4)
    c = fit.limit_crossing
    assert c is not None and 0.0 < c.t < 5.0 and abs(c.theta) > limit
    assert np.all(np.isfinite(fit.theta_model))
    with pytest.warns(tj.ValidityLimitWarning, match="stopped"):
        stopped = tj.calibrate(
            T,
            theta,
            theta_limit=limit,
            on_limit="stop",
            **fit_args,  # type: ignore[arg-type]
        )
    assert stopped.limit_crossing == c
    after = T > c.t
    assert np.all(np.isnan(stopped.theta_model[after]))
    np.testing.assert_array_equal(stopped.theta_model[~after], fit.theta_model[~after])
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # "ignore" says nothing
        ignored = tj.calibrate(
            T,
            theta,
            theta_limit=limit,
            on_limit="ignore",
            **fit_args,  # type: ignore[arg-type]
        )
    assert ignored.limit_crossing is None
    assert ignored.parameters == fit.parameters


# simulate_orbits: "ignore" too, and the same crossing type.


def test_long_runs_take_ignore_and_report_a_limit_crossing() -> None:
    undamped = PAPER.replace(damping=0.0)
    with pytest.warns(tj.ValidityLimitWarning, match="stopped"):
        runs = tj.simulate_orbits(undamped, GEO, 5, theta_limit=math.radians(15.0))
    assert isinstance(runs.limit_crossing, tj.LimitCrossing)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # "ignore" says nothing
        ignored = tj.simulate_orbits(
            undamped, GEO, 2, theta_limit=math.radians(15.0), on_limit="ignore", progress=False
        )
    assert ignored.limit_crossing is None and len(ignored) == 2


# Bad values are refused by name.

BAD_LIMITS = [0.0, -0.1, 2.0, math.nan, math.inf, 20.0]


@pytest.mark.parametrize("value", BAD_LIMITS)
def test_a_bad_theta_limit_is_refused_by_name(value: float) -> None:
    calls = [
        lambda: tj.simulate(PAPER, GEO, (0.0, 10.0), theta_limit=value),
        lambda: tj.simulate(PAPER, GEO, (0.0, 10.0), layers=4, theta_limit=value),
        lambda: tj.simulate(PAPER, GEO, (0.0, 10.0), theta_limit=value, on_limit="ignore"),
        lambda: tj.simulate_distributed(PAPER, GEO, (0.0, 10.0), theta_limit=value, **COARSE),
        lambda: tj.calibrate(T, np.zeros(T.size), theta_limit=value),
        lambda: tj.simulate_orbits(PAPER, GEO, 1, theta_limit=value, on_limit="ignore"),
    ]
    for call in calls:
        with pytest.raises(tj.ParameterError) as err:
            call()
        assert err.value.parameter == "theta_limit"


def test_a_bad_on_limit_is_refused_by_name() -> None:
    calls = [
        lambda: tj.simulate(PAPER, GEO, (0.0, 10.0), on_limit="halt"),  # type: ignore[arg-type]
        lambda: tj.simulate(PAPER, GEO, (0.0, 10.0), layers=4, on_limit="Stop"),  # type: ignore[arg-type]
        lambda: tj.simulate_distributed(PAPER, GEO, (0.0, 10.0), on_limit="", **COARSE),  # type: ignore[arg-type]
        lambda: tj.calibrate(T, np.zeros(T.size), on_limit="warn"),  # type: ignore[arg-type]
        lambda: tj.simulate_orbits(PAPER, GEO, 1, on_limit="halt"),  # type: ignore[arg-type]
    ]
    for call in calls:
        with pytest.raises(tj.ParameterError) as err:
            call()
        assert err.value.parameter == "on_limit"
