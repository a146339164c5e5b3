"""The distributed panel over whole orbits: ``simulate_orbits(..., model="distributed")``.

The fast path (exact linear arcs in sunlight) against the full integration of the same model on
drawn panels and orbits; the summaries against the definitions, computed here from
``simulate_distributed``'s own θ_f and tip series; the refusals by name; the Monte Carlo samples
against their own runs. Small meshes and loose tolerances (the same for both paths) keep it fast.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import thermojitter as tj
from conftest import GEO, PAPER

COLUMNS = (
    "theta_eq", "theta_max", "theta_min", "amplitude", "jitter_rms", "jitter_peak",
    "entry_theta_min", "exit_theta_max", "entry_peak", "exit_peak", "tip_max", "tip_min",
)  # fmt: skip
SOLVER = tj.SolverSettings(rtol=1e-6, atol=1e-9)
SMALL = {"elements": 6, "modes": 2}


def within_gate(name: str, full: np.ndarray, fast: np.ndarray) -> None:
    """Within 2 %, or 1e-6 rad (m for the tip) where the full run's value is below 5e-5; NaN
    matches NaN."""
    for k, (f, h) in enumerate(zip(full, fast, strict=True)):
        if math.isnan(f):
            assert math.isnan(h), f"{name}[{k}]: {h} where the full run has none"
        elif abs(f) < 5e-5:
            assert abs(h - f) <= 1e-6, f"{name}[{k}]: fast {h:e} vs full {f:e}"
        else:
            assert abs(h / f - 1.0) <= 0.02, f"{name}[{k}]: fast {h:e} vs full {f:e}"


# Orbits: the paper's (cylindrical shadow), a spring equinox day (penumbra, eccentric Sun) and
# a day between the seasons (no eclipse).
ORBITS = {
    "equinox": GEO,
    "season": tj.Orbit.geo_year(75.0),
    "no eclipse": tj.Orbit.geo_year(150.0),
}


@settings(max_examples=4)
@given(
    orbit=st.sampled_from(sorted(ORBITS)),
    elements=st.sampled_from([4, 6, 8]),
    modes=st.sampled_from([1, 2]),
    zeta=st.floats(2e-4, 5e-3),
    emissivity=st.floats(0.6, 0.9),
    n_orbits=st.integers(1, 2),
)
def test_linear_arcs_match_the_full_integration(
    orbit: str, elements: int, modes: int, zeta: float, emissivity: float, n_orbits: int
) -> None:
    panel = PAPER.replace(emissivity_front=emissivity)
    o = ORBITS[orbit]
    kw = {
        "model": "distributed",
        "elements": elements,
        "modes": modes,
        "damping_ratio": zeta,
        "solver": SOLVER,
        "progress": False,
    }
    fast = tj.simulate_orbits(panel, o, n_orbits, method="hybrid", **kw)
    full = tj.simulate_orbits(panel, o, n_orbits, method="rk45", **kw)
    for name in COLUMNS:
        within_gate(name, full.columns[name], fast.columns[name])
    p = fast.propagation
    assert p["t_linear"] > 0.5 * n_orbits * o.period, p
    total = p["t_linear"] + p["t_exponential"] + p["t_fallback"]
    assert total == pytest.approx(n_orbits * o.period)
    # The umbra: its temperatures integrated alone, the modes exactly (none between the seasons).
    umbra = np.nansum(full.t_exit - full.t_entry)
    assert (p["t_exponential"] > 0.0) == (umbra > 0.0), p
    assert p["t_exponential"] <= umbra + 1e-6 * o.period
    assert fast.n_steps < full.n_steps
    assert np.allclose(fast.y_end[: elements * 2], full.y_end[: elements * 2], rtol=1e-4)


@pytest.fixture(scope="module")
def one_orbit() -> tuple[tj.OrbitSummaries, tj.DistributedSolution]:
    kw = {"solver": SOLVER, **SMALL}
    run = tj.simulate_orbits(
        PAPER, GEO, 1, model="distributed", method="rk45", progress=False, **kw
    )
    sol = tj.simulate_distributed(PAPER, GEO, (0.0, GEO.period), dt_out=0.25, **kw)
    return run, sol


def test_summaries_are_their_definitions_on_the_time_series(
    one_orbit: tuple[tj.OrbitSummaries, tj.DistributedSolution],
) -> None:
    run, sol = one_orbit
    theta, tip, t = sol.theta_f, sol.deflection[:, -1], sol.t
    # θ_eq: the sunlit equilibrium's θ_f, from the flutter analysis's own equilibrium.
    eq = tj.distributed_flutter(PAPER, flux=1.0, **SMALL).theta_f
    assert run.theta_eq[0] == pytest.approx(eq, rel=1e-9)
    # Extremes over the orbit: the series (read every 0.25 s, T₁ = 7 s) lies inside them and
    # reaches them within a sample's reach.
    span = float(np.max(np.abs(theta - eq)))
    for name, value in (("theta_max", theta.max()), ("theta_min", theta.min())):
        assert abs(run.columns[name][0] - value) <= 1e-3 * span, name
    assert run.amplitude[0] == pytest.approx(span, rel=1e-3)
    assert run.tip_max[0] == pytest.approx(tip.max(), rel=1e-4)
    assert run.tip_min[0] == pytest.approx(tip.min(), rel=1e-4)
    # The umbra: where the series is dark, and the windows after entry and exit.
    dark = t[sol.sunlit == 0.0]
    assert run.t_entry[0] == pytest.approx(dark[0], abs=0.25)
    assert run.t_exit[0] == pytest.approx(dark[-1], abs=0.25)
    entry = (t >= run.t_entry[0]) & (t <= run.t_entry[0] + 600.0)
    exit_ = (t >= run.t_exit[0]) & (t <= run.t_exit[0] + 600.0)
    assert run.entry_theta_min[0] == pytest.approx(theta[entry].min(), abs=1e-3 * span)
    assert run.exit_theta_max[0] == pytest.approx(theta[exit_].max(), abs=1e-3 * span)
    assert run.entry_peak[0] == pytest.approx(np.abs(theta[entry] - eq).max(), rel=1e-3)
    assert run.exit_peak[0] == pytest.approx(np.abs(theta[exit_] - eq).max(), rel=1e-3)
    # The jitter (about the static shape) is a small part of the swing, its RMS below its peak.
    assert 0.0 < run.jitter_rms[0] < run.jitter_peak[0] < 0.2 * span


def test_uniform_frozen_panel_bends_into_the_circular_arc() -> None:
    # With the coupling frozen every element absorbs the same flux and bends under the same
    # moment M = E I κ: the free panel is a circular arc, its tip rise over the centre
    # η = (L/2)² κ / 2, θ_f = asin(2η/L) = asin(L κ / 4), κ = a (T_f − T_b)/d.
    orbit = ORBITS["no eclipse"]
    run = tj.simulate_orbits(
        PAPER, orbit, 1, model="distributed", coupled=False, method="hybrid", progress=False,
        **SMALL,
    )  # fmt: skip
    # θ_eq is the equilibrium at the flux of the orbit's middle: where this run starts.
    mid = 0.5 * orbit.period
    sol = tj.simulate_distributed(PAPER, orbit, (mid, mid + 1.0), coupled=False, **SMALL)
    front, back = sol.T_front[0], sol.T_back[0]
    assert np.ptp(front) < 1e-9 * front[0] and np.ptp(back) < 1e-9 * back[0]
    kappa = PAPER.expansion_coeff * (front[0] - back[0]) / PAPER.thickness
    assert run.theta_eq[0] == pytest.approx(math.asin(PAPER.length * kappa / 4.0), rel=1e-6)
    assert run.theta_max[0] >= run.theta_eq[0] >= run.theta_min[0]


def test_the_run_is_resumable_and_says_how_it_ran(tmp_path) -> None:  # type: ignore[no-untyped-def]
    kw = {"model": "distributed", "solver": SOLVER, "progress": False, **SMALL}
    whole = tj.simulate_orbits(PAPER, GEO, 2, **kw)
    path = tmp_path / "run.ckpt"
    first = tj.simulate_orbits(PAPER, GEO, 1, checkpoint=path, **kw)
    assert len(first) == 1
    again = tj.simulate_orbits(PAPER, GEO, 2, checkpoint=path, **kw)
    for name in COLUMNS:
        np.testing.assert_array_equal(again.columns[name], whole.columns[name])
    assert whole.settings["distributed"]["elements"] == SMALL["elements"]
    assert whole.y_end.size == 2 * SMALL["elements"] + 2 * SMALL["modes"]
    assert 0.0 < whole.nonlinear_fraction < 0.5


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"model": "nonlinear", "elements": 10}, "elements"),
        ({"model": "linear", "modes": 2}, "modes"),
        ({"model": "nonlinear", "damping_ratio": 0.01}, "damping_ratio"),
        ({"model": "nonlinear", "support": "cantilever"}, "support"),
        ({"model": "distributed", "elements": 0}, "elements"),
        ({"model": "distributed", "elements": 2.5}, "elements"),
        ({"model": "distributed", "modes": 0}, "modes"),
        ({"model": "distributed", "damping_ratio": -1.0}, "damping_ratio"),
        ({"model": "distributed", "support": "hinged"}, "support"),
        ({"model": "distributed", "layers": 0}, "layers"),
        ({"model": "distributed", "y0": (300.0, 300.0, 0.0, 0.0)}, "y0"),
        ({"model": "distributed", "window": -1.0}, "window"),
        ({"model": "planar"}, "model"),
    ],
)
def test_bad_requests_are_refused_by_name(kwargs: dict, name: str) -> None:  # type: ignore[type-arg]
    with pytest.raises(tj.ParameterError) as err:
        tj.simulate_orbits(PAPER, GEO, 1, progress=False, **kwargs)
    assert err.value.parameter == name


def test_a_boom_is_not_a_distributed_panel() -> None:
    with pytest.raises(tj.ParameterError) as err:
        tj.simulate_orbits(tj.Boom(30.0, 6e-3, 5e-5), GEO, 1, model="distributed", progress=False)
    assert err.value.parameter == "model"


def test_each_monte_carlo_sample_is_its_own_run() -> None:
    vary = {"damping": ("uniform", 1.0, 3.0), "emissivity_front": ("uniform", 0.7, 0.9)}
    kw = {"method": "hybrid", "solver": SOLVER, **SMALL}
    frame = tj.monte_carlo(
        PAPER, GEO, vary=vary, n=3, seed=7, model="distributed", threads=2, progress=False, **kw
    )
    assert frame.attrs["n_failed"] == 0
    for i in (0, 2):
        panel = PAPER.replace(damping=frame.damping[i], emissivity_front=frame.emissivity_front[i])
        run = tj.simulate_orbits(panel, GEO, 1, model="distributed", progress=False, **kw)
        assert frame.amplitude[i] == run.amplitude[0]
        assert frame.exit_peak[i] == run.exit_peak[0]
        assert frame.jitter_peak[i] == run.jitter_peak[0]
        assert frame.tip_max[i] == run.tip_max[0]
        assert frame.theta_eq[i] == run.theta_eq[0]
        fl = tj.distributed_flutter(panel, **SMALL)
        assert frame.critical_damping[i] == fl.critical_damping
        assert bool(frame.stable[i]) == fl.stable
    # Threads change nothing.
    one = tj.monte_carlo(
        PAPER, GEO, vary=vary, n=3, seed=7, model="distributed", threads=1, progress=False, **kw
    )
    assert one.drop(columns="error").equals(frame.drop(columns="error"))


def test_a_distributed_study_refuses_what_it_does_not_take() -> None:
    with pytest.raises(tj.ParameterError) as err:
        tj.monte_carlo(
            PAPER, GEO, vary={"albedo": ("uniform", 0.1, 0.3)}, n=2, seed=1,
            model="distributed", progress=False,
        )  # fmt: skip
    assert err.value.parameter == "vary.albedo"
    with pytest.raises(tj.ParameterError) as err:
        tj.monte_carlo(
            PAPER, GEO, vary={"damping": ("uniform", 1.0, 3.0)}, n=2, seed=1, elements=8,
            progress=False,
        )  # fmt: skip
    assert err.value.parameter == "elements"


def test_the_critical_damping_year_figure_plots_the_api_values() -> None:
    from thermojitter.reports.plots import cd_year_figure, pyplot

    orbit = tj.Orbit.geo_year("2026-01-01")
    data = tj.critical_damping_year(PAPER, orbit, samples=4, **SMALL)
    fig = cd_year_figure(data)
    try:
        hinge, distributed = fig.axes[0].lines[:2]
        flux_line = fig.axes[1].lines[0]
        days = hinge.get_xdata()
        assert days[0] == 0.0 and days[-1] == pytest.approx(365.25)
        for k, day in enumerate(days):
            t = day * 86400.0
            flux = float(orbit.flux_scale(np.array([t]))[0])
            assert flux_line.get_ydata()[k] == pytest.approx(flux, rel=1e-12)
            want = tj.flutter(PAPER, orbit=orbit, t=t).critical_damping
            assert hinge.get_ydata()[k] == pytest.approx(want, rel=1e-9)
            want = tj.distributed_flutter(PAPER, flux=flux, **SMALL).critical_damping
            assert distributed.get_ydata()[k] == pytest.approx(want, rel=1e-9)
        # Perihelion (early January) heats more than aphelion (early July): the flux falls
        # then rises over the year, and each c_d* follows its own analysis of that flux.
        assert flux_line.get_ydata()[0] > 1.0 > flux_line.get_ydata()[2]
    finally:
        pyplot().close(fig)


def test_the_validity_limit_stops_the_run_at_the_crossing() -> None:
    # θ_f overshoots its equilibrium after the shadow exit (about 0.157 rad on Table 1): a limit
    # of 0.12 rad is crossed there, in the first orbit, where the series crosses it.
    kw = {"model": "distributed", "solver": SOLVER, "progress": False, **SMALL}
    with pytest.warns(tj.ValidityLimitWarning, match="θ_f passed .* the distributed panel's range"):
        run = tj.simulate_orbits(PAPER, GEO, 3, theta_limit=0.12, **kw)
    crossing = run.limit_crossing
    assert crossing is not None and crossing.orbit == 0 and len(run) == 1
    assert 0.12 <= crossing.theta < 0.121
    sol = tj.simulate_distributed(PAPER, GEO, (0.0, GEO.period), dt_out=1.0, **SMALL)
    first = sol.t[np.argmax(sol.theta_f > 0.12)]
    assert crossing.t == pytest.approx(first, abs=1.0)


def test_support_and_layers_pass_through() -> None:
    # A cantilever of three-node elements between the seasons, its incidence frozen (coupled,
    # the Sun-pointing cantilever of Table 1 flutters: distributed_flutter finds a growth rate
    # of about 2e-4 1/s): the settings reach the engine and the fast path matches the full one.
    orbit = ORBITS["no eclipse"]
    kw = {
        "model": "distributed", "support": "cantilever", "layers": 3, "coupled": False,
        "solver": SOLVER, "progress": False, **SMALL,
    }  # fmt: skip
    fast = tj.simulate_orbits(PAPER, orbit, 1, method="hybrid", **kw)
    full = tj.simulate_orbits(PAPER, orbit, 1, method="rk45", **kw)
    assert fast.y_end.size == 3 * SMALL["elements"] + 2 * SMALL["modes"]
    assert fast.settings["distributed"]["support"] == "cantilever"
    for name in COLUMNS:
        within_gate(name, full.columns[name], fast.columns[name])
    # The cantilever's θ_f is asin(tip/L): its tip deflection and θ_eq agree.
    assert math.sin(fast.theta_max[0]) * PAPER.length == pytest.approx(fast.tip_max[0], rel=1e-9)
