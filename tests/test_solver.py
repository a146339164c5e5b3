"""The solver-settings object: defaults from the engine, one validation, the settings reported."""

from __future__ import annotations

import math

import numpy as np
import pytest

import thermojitter as tj
from thermojitter import _core
from thermojitter.scenario import parse_scenario


def test_defaults_are_the_engines() -> None:
    s = tj.SolverSettings()
    assert s.as_dict() == dict(_core.SOLVER_DEFAULTS)
    assert (s.method, s.rtol, s.atol, s.dt, s.max_step) == ("rk45", 1e-8, 1e-10, None, math.inf)


@pytest.mark.parametrize(
    ("changes", "parameter"),
    [
        ({"rtol": 0.5}, "rtol"),
        ({"atol": -1.0}, "atol"),
        ({"max_step": 0.0}, "max_step"),
        ({"max_steps": 0}, "max_steps"),
        ({"method": "euler"}, "method"),
        ({"method": "rk4"}, "dt"),
        ({"method": "rk4", "dt": -0.1}, "dt"),
    ],
)
def test_bad_values_are_refused_naming_the_parameter(changes: dict, parameter: str) -> None:
    with pytest.raises(tj.ParameterError) as info:
        tj.SolverSettings(**changes)
    assert info.value.parameter == parameter


@pytest.mark.parametrize("value", [True, "1e-8", None])
def test_a_number_must_be_a_number(value: object) -> None:
    with pytest.raises(TypeError, match="rtol"):
        tj.SolverSettings(rtol=value)


def test_the_object_and_the_keywords_give_the_same_run() -> None:
    panel, orbit = tj.Panel.paper(), tj.Orbit.geo_equinox()
    entry = orbit.shadow_intervals(0.0, orbit.period)[0][0]
    span = (entry - 60.0, entry + 240.0)
    by_keywords = tj.simulate(panel, orbit, span, rtol=1e-9, atol=1e-11, max_step=5.0)
    settings = tj.SolverSettings(rtol=1e-9, atol=1e-11, max_step=5.0)
    by_object = tj.simulate(panel, orbit, span, solver=settings)
    assert np.array_equal(by_keywords.theta, by_object.theta)
    assert by_keywords.n_steps == by_object.n_steps
    # the engine reports what it used
    assert by_object.solver == settings
    assert by_keywords.solver == settings


def test_giving_both_with_different_values_is_refused() -> None:
    panel, orbit = tj.Panel.paper(), tj.Orbit.geo_equinox()
    with pytest.raises(tj.ParameterError) as info:
        tj.simulate(panel, orbit, (0.0, 10.0), solver=tj.SolverSettings(rtol=1e-9), atol=1e-6)
    assert info.value.parameter == "solver"
    with pytest.raises(TypeError, match="solver"):
        tj.simulate(panel, orbit, (0.0, 10.0), solver={"rtol": 1e-9})
    # the same value twice is not a conflict
    sol = tj.simulate(
        panel, orbit, (0.0, 10.0), solver=tj.SolverSettings(method="rk4", dt=0.5), method="rk4"
    )
    assert sol.method == "rk4" and sol.n_steps == 20


def test_the_fixed_step_is_reported() -> None:
    panel, orbit = tj.Panel.paper(), tj.Orbit.geo_equinox()
    sol = tj.simulate_thermal(panel, orbit, (0.0, 100.0), method="rk4", dt=2.0)
    assert sol.solver is not None and (sol.solver.method, sol.solver.dt) == ("rk4", 2.0)
    hinge = tj.simulate_hinge(panel, 1e-3, (0.0, 10.0), solver=tj.SolverSettings(rtol=1e-7))
    assert hinge.solver is not None and hinge.solver.rtol == 1e-7


def test_the_layered_run_reports_its_settings_as_the_two_layer_run_does() -> None:
    panel, orbit = tj.Panel.paper(), tj.Orbit.geo_equinox()
    for settings in (tj.SolverSettings(method="rk4", dt=0.5), tj.SolverSettings(rtol=1e-7)):
        two = tj.simulate(panel, orbit, (0.0, 10.0), solver=settings)
        nodes = tj.simulate(panel, orbit, (0.0, 10.0), solver=settings, layers=4)
        assert nodes.solver is not None and nodes.solver == two.solver
        assert nodes.solver.rtol == settings.rtol and nodes.solver.method == settings.method


def test_the_beam_reports_its_settings() -> None:
    beam = tj.beam.FreeFreeBeam(tj.Panel.paper(), n_elements=10)
    settings = tj.SolverSettings(rtol=1e-7, atol=1e-9)
    r = beam.response([0.0, 20.0], [1e-3, 2e-3], solver=settings)
    assert r.solver == settings


def test_orbits_accept_the_object() -> None:
    panel, orbit = tj.Panel.paper(), tj.Orbit.geo_equinox()
    a = tj.simulate_orbits(panel, orbit, 1, method="rk45", rtol=1e-7, progress=False)
    b = tj.simulate_orbits(
        panel, orbit, 1, method="rk45", solver=tj.SolverSettings(rtol=1e-7), progress=False
    )
    assert np.array_equal(a.columns["exit_peak"], b.columns["exit_peak"])
    assert a.settings == b.settings


def test_the_scenario_gives_one_settings_object() -> None:
    loose = parse_scenario({"simulation": {"rtol": 0.5}}).simulation
    with pytest.raises(tj.ParameterError) as info:
        loose.solver  # noqa: B018
    assert info.value.parameter == "rtol"
    sim = parse_scenario({"simulation": {"method": "rk4", "dt": 0.25}}).simulation
    assert sim.solver == tj.SolverSettings(method="rk4", dt=0.25)


ASKED = tj.SolverSettings(rtol=1e-7, atol=1e-9, max_step=0.5, max_steps=10**7)
"""Settings away from every default, for the runs that must report them."""


@pytest.mark.parametrize("layers", [None, 2, 4])
@pytest.mark.parametrize("method", ["rk45", "hybrid"])
def test_long_runs_report_the_settings_the_engine_ran_with(layers: int | None, method: str) -> None:
    panel, orbit = tj.Panel.paper(), tj.Orbit.leo()
    run = tj.simulate_orbits(
        panel, orbit, 1, method=method, solver=ASKED, layers=layers, progress=False
    )
    # hybrid runs report their rk45 fallback's settings
    assert run.solver == ASKED
    assert run.settings["rtol"] == ASKED.rtol  # the request as given, as before


def test_long_runs_report_the_fixed_step_and_the_engines_defaults() -> None:
    panel, orbit = tj.Panel.paper(), tj.Orbit.leo()
    fixed = tj.simulate_orbits(panel, orbit, 1, method="rk4", dt=0.25, progress=False)
    assert fixed.solver is not None and (fixed.solver.method, fixed.solver.dt) == ("rk4", 0.25)
    plain = tj.simulate_orbits(panel, orbit, 1, progress=False)
    assert plain.solver is not None
    assert plain.solver.as_dict() == dict(_core.SOLVER_DEFAULTS)


def test_a_run_resumed_whole_from_its_checkpoint_reports_its_settings(tmp_path) -> None:
    panel, orbit = tj.Panel.paper(), tj.Orbit.leo()
    path = tmp_path / "run.ckpt"
    kw = {"method": "rk45", "solver": ASKED, "checkpoint": path, "progress": False}
    first = tj.simulate_orbits(panel, orbit, 1, **kw)
    again = tj.simulate_orbits(panel, orbit, 1, **kw)
    assert again.n_steps == first.n_steps  # read, not run again
    assert first.solver == again.solver == ASKED


@pytest.mark.parametrize("method", ["rk45", "hybrid"])
def test_monte_carlo_reports_the_settings_the_engine_ran_with(method: str, tmp_path) -> None:
    panel, orbit = tj.Panel.paper(), tj.Orbit.leo()
    kw = {"vary": {"damping": ("uniform", 0.5, 2.0)}, "n": 2, "seed": 3, "progress": False}
    frame = tj.monte_carlo(panel, orbit, method=method, solver=ASKED, **kw)
    assert tj.montecarlo.solver_of(frame) == ASKED
    assert frame.attrs["solver"] == ASKED.as_dict()  # plain data: the frame writes to Parquet
    assert frame.attrs["settings"]["run"]["solver"] == ASKED.as_dict()  # the request, as before
    plain = tj.monte_carlo(panel, orbit, method=method, **kw)
    assert frame.attrs["solver"] != plain.attrs["solver"]
    assert plain.attrs["solver"] == dict(_core.SOLVER_DEFAULTS)
    # a study read whole from its checkpoint reports the same
    for _ in range(2):
        read = tj.monte_carlo(
            panel, orbit, method=method, solver=ASKED, checkpoint=tmp_path / "mc", **kw
        )
        assert tj.montecarlo.solver_of(read) == ASKED
