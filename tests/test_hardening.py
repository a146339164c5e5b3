"""Every reproducer of the hardening issue, refused up front with the parameter named: inputs that
used to abort the process, hang, raise a panic, answer silently wrong, raise errors that did not
say what was wrong, or pass a unit slip."""

from __future__ import annotations

import math
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest

import thermojitter as tj
from thermojitter.scenario import ScenarioError, parse_scenario

P = tj.Panel.paper()
GEO = tj.Orbit.geo_equinox()
VARY = {"damping": ("uniform", 1.0, 4.0)}


def refused(call: Callable[[], Any], parameter: str, *words: str) -> tj.ParameterError:
    """Asserts that ``call`` raises a ParameterError naming ``parameter`` (and ``words``)."""
    with pytest.raises(tj.ParameterError) as info:
        call()
    err = info.value
    assert err.parameter == parameter, str(err)
    assert parameter in str(err)
    for word in words:
        assert word in str(err), str(err)
    return err


# --- used to abort the process (lists grown with the span, without a bound) -------------------


def test_huge_spans_are_refused_before_any_list_is_built() -> None:
    # The orbit's methods name their own arguments (t0, t1).
    refused(lambda: GEO.shadow_intervals(0, 1e300), "t1", "1e+11")
    refused(lambda: tj.Orbit.leo().eclipses(0, 1e12), "t1")
    refused(lambda: tj.simulate(P, GEO, (0, 1e300), dt_out=1e299), "t_span[1]")
    # Within the time range, but a million eclipses of a low orbit: counted up front.
    refused(lambda: tj.Orbit.leo().shadow_intervals(0, 9e10), "t_span", "eclipses")


def test_orbits_the_validator_used_to_accept_are_refused() -> None:
    refused(lambda: tj.Orbit(phase0=1e20), "phase0", "modulo 2π")
    refused(lambda: tj.Orbit(period=1e-300), "period", ">= 60 s")
    refused(lambda: tj.Orbit(epoch_day=1e300), "epoch_day")


# --- used to hang -----------------------------------------------------------------------------


def test_loose_tolerances_are_refused() -> None:
    refused(lambda: tj.simulate(P, GEO, (0, 600), atol=1.0), "atol", "1e-3")
    refused(lambda: tj.simulate(P, GEO, (0, 600), rtol=1e300), "rtol")
    with pytest.raises(TypeError, match="atol"):
        tj.simulate(P, GEO, (0, 600), atol=True)


def test_fixed_step_cost_is_known_up_front() -> None:
    refused(lambda: tj.simulate(P, GEO, (0, 600), method="rk4", dt=1e-20), "dt", "steps")


def test_long_run_step_cap_is_bounded() -> None:
    refused(
        lambda: tj.simulate_orbits(P, GEO, 1, steps_per_period=1.7e308, progress=False),
        "steps_per_period",
    )


@pytest.mark.parametrize(
    ("name", "value"),
    [("length", 1e-300), ("specific_heat", 1e-6), ("length", 1e-6), ("damping", 1e10)],
)
def test_absurd_panels_are_refused(name: str, value: float) -> None:
    refused(lambda: tj.Panel(**{name: value}), name, "must be in")


def test_panels_whose_rates_would_need_endless_steps_are_refused() -> None:
    # Each field within its range, together a hinge of ~1e4 rad/s.
    refused(lambda: P.replace(hinge_stiffness=1e12), "hinge_stiffness", "1/s")
    refused(lambda: P.replace(damping=1e8), "damping", "c_d/I_B")
    refused(
        lambda: P.replace(conductance=1e6, mass_per_length=1e-3, specific_heat=10.0),
        "conductance",
        "2K/(m c)",
    )


def test_flutter_of_a_vanishing_panel_is_refused() -> None:
    refused(lambda: tj.flutter(tj.Panel(length=1e-300)), "length")


def test_hinge_moment_beyond_the_model_is_refused() -> None:
    refused(lambda: tj.simulate_hinge(P, 1e300, (0, 200)), "moment", "M/K_el")
    refused(lambda: tj.simulate_hinge(P, [0.0, 1e5], (0, 200), moment_t=[0, 100]), "moment")


def test_scenario_years_with_per_orbit_summaries_is_bounded() -> None:
    from thermojitter.cli.run import run_orbits_command

    scenario = parse_scenario({"simulation": {"years": 1e9, "keep": "orbits"}}, Path("long.toml"))
    args = type("Args", (), {"format": None, "no_progress": True, "no_plots": True})()
    with pytest.raises(ScenarioError) as info:
        run_orbits_command(args, scenario, Path("/nonexistent-never-written"))
    assert info.value.key == "simulation.years"


def test_long_run_whose_end_is_beyond_the_time_range_is_refused() -> None:
    refused(lambda: tj.simulate_orbits(P, GEO, 10**9, progress=False), "n_orbits", "1e+11")


# The fuzz's low orbit: no hybrid speed-up there (the state never settles between eclipses).
LOW = tj.Orbit(radius=7.0e6, period=5828.5)
LOOSE = {"rtol": 1e-6, "atol": 1e-8, "progress": False}


def test_long_runs_beyond_their_step_budget_are_refused_up_front() -> None:
    # 133,970 orbits at T_n/40: ~29,000 steps each, 3.9e9 in all. Refused naming n_orbits,
    # saying how to proceed, before the first step (the call used to run for minutes).
    err = refused(
        lambda: tj.simulate_orbits(P, LOW, 133_970, method="rk45", max_steps=200_000, **LOOSE),
        "n_orbits",
        "max_steps = 200000",
        "method='hybrid'",
    )
    # The least cost is a lower bound: T_n/40 of the paper panel's 8.07 s period, every orbit.
    least = LOW.period * 40.0 * tj.natural_frequency(P)
    assert f"{least:.3g} per orbit" in str(err)
    # The default budget (5e8 steps) refuses 10^5 orbits of rk45 too.
    refused(lambda: tj.simulate_orbits(P, LOW, 100_000, method="rk45", **LOOSE), "n_orbits")


def test_long_run_budget_holds_for_the_whole_run_not_each_orbit() -> None:
    # Error control alone (no step cap, so no bound up front) with the hybrid: each orbit used to
    # get the whole budget. The run stops once the budget is spent, a few orbits in.
    with pytest.raises(tj.IntegrationError, match="max_steps = 200000 reached after"):
        tj.simulate_orbits(P, LOW, 133_970, steps_per_period=0.0, max_steps=200_000, **LOOSE)


def test_the_command_names_the_span_key_and_the_budget_key(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from thermojitter.cli import main

    text = '[orbit]\npreset = "geo_year"\n[simulation]\nyears = 10\nkeep = "orbits"\n'
    scenario = tmp_path / "full.toml"
    scenario.write_text(text + 'method = "rk45"\n')
    assert main(["run", str(scenario), "--out", str(tmp_path / "out"), "--no-progress"]) == 2
    err = capsys.readouterr().err
    orbits = round(10 * 365.25 * 86400.0 / tj.Orbit.geo_year().period)  # 3663 sidereal days
    assert f"{scenario}: simulation.years: {orbits} orbits needs at least" in err
    assert "max_steps" in err and "method='hybrid'" in err
    # The scenario sets the budget of the run (here one that allows it).
    parsed = parse_scenario({"simulation": {"max_steps": 2 * 10**9}}, Path("s.toml"))
    assert parsed.simulation.solver.max_steps == 2 * 10**9
    with pytest.raises(ScenarioError, match="simulation.max_steps"):
        parse_scenario({"simulation": {"max_steps": 1.5}}, Path("s.toml"))


def test_ensembles_beyond_their_step_budget_are_refused_up_front() -> None:
    # Three million samples of one orbit, and two samples of 11,586 orbits.
    refused(lambda: tj.monte_carlo(P, LOW, vary=VARY, n=3_178_506, seed=1, **LOOSE), "n")
    refused(
        lambda: tj.monte_carlo(
            P, LOW, vary=VARY, n=2, seed=1, horizon=11_586, method="rk45", max_steps=10**6, **LOOSE
        ),
        "horizon",
        "per orbit",
    )
    refused(
        lambda: tj.sweep(
            P, LOW, {"damping": list(np.linspace(1, 4, 40))}, max_steps=10**5, **LOOSE
        ),
        "grid",
    )


def test_hybrid_samples_stop_at_their_budget_every_step_counted() -> None:
    # The hybrid's least cost is not known up front; its fallback stretches used to get the
    # budget each. Each sample now stops at it, with its error kept in the frame.
    # A budget of a few orbits (~30,000 steps each here), every fallback stretch within it: a
    # panel whose thermal rates are not slow against its hinge, so that the hybrid's slow time
    # gives every orbit of this low orbit back to the full integration.
    # Every sample fails, so the study raises, with the frame.
    fast = P.replace(specific_heat=300.0)
    with pytest.raises(tj.AllSamplesFailedError) as caught:
        tj.monte_carlo(
            fast,
            LOW,
            vary=VARY,
            n=2,
            seed=1,
            horizon=500,
            method="hybrid",
            max_steps=100_000,
            **LOOSE,
        )
    frame = caught.value.samples
    assert frame["error"].str.contains("max_steps = 100000 reached").all()


def test_designs_too_large_to_hold_are_refused() -> None:
    refused(lambda: tj.monte_carlo(P, LOW, vary=VARY, n=2**40, seed=1, **LOOSE), "n")
    axis = list(np.linspace(1.0, 4.0, 1000))
    refused(
        lambda: tj.sweep(P, LOW, {"damping": axis, "conductance": axis, "length": axis}, **LOOSE),
        "grid",
    )


def test_monte_carlo_threads_are_bounded() -> None:
    # 2**63 threads used to be spawned until the system refused (load averages in the hundreds).
    err = refused(
        lambda: tj.monte_carlo(P, LOW, vary=VARY, n=2, seed=1, threads=2**63, **LOOSE), "threads"
    )
    assert str(tj._core.MAX_THREADS) in str(err)


def test_hinge_energy_of_states_beyond_the_model_is_refused_not_inf() -> None:
    refused(lambda: tj.hinge_energy(P, [1e300], [0.0], 400.0), "theta", "π/2")
    refused(lambda: tj.hinge_energy(P, [0.1], [1e200], 400.0), "theta_dot", "float")
    refused(lambda: tj.hinge_energy(P, [0.1], [0.0], 1e300), "moment", "M/K_el")
    # Within the model's range, the closed form: kinetic + spring − M θ.
    e = tj.hinge_energy(P, [0.1], [0.0], 400.0, model="linear")[0]
    assert e == pytest.approx(0.5 * P.hinge_stiffness * 0.01 - 40.0, rel=1e-12)


def test_linearisation_temperature_beyond_any_material_is_refused_not_inf() -> None:
    # T_star = 1e300 K gave q = inf (the σT³ term) with no error.
    refused(lambda: tj.linear_thermal_response(P, T_star=1e300), "T_star", "K")
    refused(lambda: tj.linear_thermal_response(P, T_star=-3784.0), "T_star")
    assert math.isfinite(tj.linear_thermal_response(P, T_star=1e4).q)


@pytest.mark.parametrize("flux", [5e-324, 3e-63, 540.0, 2395.0, 1e12, 1.7976931348623157e308])
def test_flux_factors_beyond_any_orbit_are_refused_not_a_failed_newton(flux: float) -> None:
    # These used to end in "steady state did not converge" (a singular Jacobian, a panel folded
    # beyond 90°, Newton giving up) without naming the flux.
    refused(lambda: tj.steady_state(P, flux=flux), "flux", "1 au")
    refused(lambda: tj.flutter(P, flux=flux), "flux")
    refused(lambda: tj.linear_thermal_response(P, omega=1e16, flux=flux), "flux")


# --- used to raise a PanicException (a BaseException) -----------------------------------------


def test_monte_carlo_horizon_overflow_is_a_parameter_error() -> None:
    refused(
        lambda: tj.monte_carlo(P, GEO, vary=VARY, n=2, horizon=2**63, seed=1, progress=False),
        "horizon",
    )


# --- used to answer silently wrong ------------------------------------------------------------


@pytest.mark.parametrize("value", [None, "no", 0, 1])
def test_coupled_must_be_a_bool(value: object) -> None:
    with pytest.raises(TypeError, match="coupled"):
        tj.simulate(P, GEO, (0, 10), coupled=value)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="coupled"):
        tj.steady_state(P, coupled=value)  # type: ignore[arg-type]


def test_numbers_given_as_strings_or_bools_are_type_errors() -> None:
    with pytest.raises(TypeError, match="flux"):
        tj.flutter(P, flux="1.0")  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="rtol"):
        tj.simulate(P, GEO, (0, 10), rtol=None)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="length"):
        tj.Panel(length=True)


def test_times_that_are_not_finite_are_refused_not_nan() -> None:
    year = tj.Orbit.geo_year()
    refused(lambda: year.illumination([math.nan]), "t")
    refused(lambda: year.flux_scale(math.inf), "t")
    refused(lambda: year.declination([0.0, -math.inf]), "t")


def test_stiffness_of_an_absurd_panel_is_refused_not_inf() -> None:
    refused(lambda: tj.Panel(bending_inertia=1e300), "bending_inertia")
    # The largest accepted panel still gives a finite stiffness.
    big = P.replace(bending_inertia=1e3, youngs_modulus=1e13, length=1e4)
    assert math.isfinite(tj.hinge_stiffness(big, "frequency"))


def test_huge_rtol_from_a_scenario_is_refused_with_file_and_key() -> None:
    scenario = parse_scenario({"simulation": {"rtol": 1e300}}, Path("loose.toml"))
    with pytest.raises(tj.ParameterError) as info:
        tj.simulate(P, GEO, (0, 200), rtol=scenario.simulation.rtol)
    assert info.value.parameter == "rtol"


# --- errors that did not say what was wrong ---------------------------------------------------


def test_none_for_a_model_object_is_a_type_error_naming_it() -> None:
    with pytest.raises(TypeError, match="orbit must be a thermojitter.Orbit"):
        tj.simulate(P, None, (0, 10))  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="panel must be a thermojitter.Panel"):
        tj.natural_frequency(None)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="panel"):
        tj.hinge_stiffness(None)  # type: ignore[arg-type]


def test_integers_too_large_for_a_float_name_the_parameter() -> None:
    refused(lambda: tj.Panel(length=10**400), "length", "too large")
    refused(lambda: tj.simulate(P, GEO, (0, 10**400)), "t_span[1]")
    refused(lambda: tj.Orbit.leo(1e300), "altitude")
    # Whole numbers of orbits are compared before they are multiplied by the period.
    err = refused(lambda: tj.simulate_orbits(P, GEO, 10**400, progress=False), "n_orbits")
    assert len(str(err)) < 200  # the 401 digits are not all shown
    refused(lambda: tj.monte_carlo(P, GEO, vary=VARY, n=2, horizon=2**70, seed=1), "horizon")
    for table, key in [("panel", "youngs_modulus"), ("panel", "length"), ("simulation", "orbits")]:
        with pytest.raises(ScenarioError) as info:
            parse_scenario({table: {key: 10**400}}, Path("big.toml"))
        assert info.value.key == f"{table}.{key}" and "too large" in str(info.value)


def test_bad_start_states_name_y0() -> None:
    refused(lambda: tj.simulate(P, GEO, (0, 10), y0=np.zeros((2, 2))), "y0", "one-dimensional")
    with pytest.raises(TypeError, match="y0"):
        tj.simulate(P, GEO, (0, 10), y0="abcd")  # type: ignore[arg-type]
    refused(lambda: tj.simulate(P, GEO, (0, 10), y0=(300.0, 290.0)), "y0", "4")


def test_scenario_with_absurd_modulus_names_file_and_key() -> None:
    with pytest.raises(ScenarioError) as info:
        parse_scenario({"panel": {"youngs_modulus": 1e300}}, Path("stiff.toml"))
    assert info.value.key == "panel.youngs_modulus"
    assert str(info.value).startswith("stiff.toml: panel.youngs_modulus = 1e+300 is invalid")


# --- unit slips -------------------------------------------------------------------------------


def test_leo_altitude_in_km_is_caught() -> None:
    err = refused(lambda: tj.Orbit.leo(540), "altitude", "km")
    assert "540 km = 540000 m" in str(err)
    assert tj.Orbit.leo(540e3).radius == pytest.approx(6378.137e3 + 540e3)


def test_theta_limit_in_degrees_is_caught() -> None:
    err = refused(
        lambda: tj.simulate_orbits(P, GEO, 1, theta_limit=20.0, progress=False), "theta_limit"
    )
    assert "20° = 0.349066 rad" in str(err)


def test_start_angle_in_degrees_is_caught() -> None:
    err = refused(lambda: tj.simulate(P, GEO, (0, 10), y0=(300, 290, 4.89, 0)), "y0[2]")
    assert "degrees" in str(err) and "0.085347 rad" in str(err)
    refused(lambda: tj.simulate_hinge(P, 0.0, (0, 10), y0=(4.89, 0.0)), "y0[0]", "degrees")


# --- the last line of defence -----------------------------------------------------------------


def test_internal_error_is_a_runtime_error_not_a_base_exception() -> None:
    # No reproducer is left that panics; the mapping is checked on the type itself.
    assert issubclass(tj.InternalError, RuntimeError)
    assert not issubclass(tj.ParameterError, RuntimeError)


# --- found by benches/fuzz.py on a2f9ee7 (seed 0, 10,000 calls) --------------------------------


def test_overdamped_beam_modes_are_refused_not_minutes_of_steps() -> None:
    # damping_ratio = 2e5 ran for minutes: an overdamped mode's rate 2ζω sets the step.
    beam = tj.FreeFreeBeam(P, n_elements=20)
    kw: dict[str, Any] = {"times": [0.0, 10.0, 20.0], "moments": [400.0, 350.0, 300.0]}
    refused(lambda: beam.response(**kw, damping_ratio=217546.0), "damping_ratio", "10")
    assert beam.response(**kw, damping_ratio=10.0).t[-1] == 20.0


def test_fitted_names_that_are_not_strings_are_refused_naming_fit() -> None:
    # An array of numbers as fit raised "unhashable type: 'numpy.ndarray'".
    t = np.linspace(0.0, 600.0, 40)
    refused(lambda: tj.calibrate(t, 0.01 * np.ones(40), fit=np.zeros((2, 2))), "fit")  # type: ignore[arg-type]
    refused(lambda: tj.calibrate(t, 0.01 * np.ones(40), fit=[1.0]), "fit")  # type: ignore[list-item]
