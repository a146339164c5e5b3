"""The command line on real orbits, attitudes and booms: ``thermojitter flutter`` and ``run`` on
scenarios with Earth heating, an ``[attitude]``, the point ``t`` of the orbit, and a ``[boom]``;
every number the commands write is the API's on the same inputs. And the figures of the orbit's
environment (β and eclipses over a year, the flux on each face): their plotted data are the API's
values."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

import thermojitter as tj
from thermojitter import cli
from thermojitter.cli.flutter import BOOM_INCLINATIONS_DEG
from thermojitter.reports.plots import boom_stability_figure, face_flux_figure, orbit_year_figure

INCLINATION = 0.4974  # rad, about 28.5 deg
HUBBLE_ORBIT = f"""
[orbit]
preset = "circular"
altitude = 540e3
inclination = {INCLINATION}
start_date = 2026-06-01
"""
TRACKING = '\n[attitude]\nkind = "sun_tracking"\noffset = 0.1\n'


def hubble() -> tj.Orbit:
    """The orbit of HUBBLE_ORBIT, built through the API."""
    return tj.Orbit.circular(540e3, INCLINATION, 0.0, "2026-06-01")


def flutter_json(tmp_path: Path, text: str, *args: str) -> dict:
    scenario = tmp_path / "s.toml"
    scenario.write_text(text)
    out = tmp_path / "out"
    assert cli.main(["flutter", str(scenario), "--out", str(out), *args]) == 0
    return json.loads((out / "flutter.json").read_text())  # type: ignore[no-any-return]


def test_flutter_takes_earth_heating_the_attitude_and_the_point_of_the_orbit(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    text = "[panel]\ndamping = 1.5\n" + HUBBLE_ORBIT + TRACKING + "\n[flutter]\nt = 1500.0\n"
    axes = ("--x", "damping:0:3:4", "--y", "conductance:5:20:3")
    data = flutter_json(tmp_path, text, "--no-plot", *axes)
    panel, orbit = tj.Panel.paper().replace(damping=1.5), hubble()
    attitude = tj.Attitude.sun_tracking(0.1)
    for model in ("nonlinear", "linear"):
        api = tj.flutter(panel, model, orbit=orbit, t=1500.0, attitude=attitude)
        got = data["models"][model]
        assert got["growth_rate_per_s"] == api.growth_rate
        assert got["critical_damping_N_m_s_per_rad"] == api.critical_damping
        assert got["frequency_hz"] == api.frequency_hz
    api = tj.flutter(panel, orbit=orbit, t=1500.0, attitude=attitude)
    assert data["equilibrium"]["T_back_K"] == api.equilibrium.T_back
    # The Earth heats the back face: the equilibrium differs from the Sun alone at that flux.
    sun_alone = tj.flutter(panel, flux=float(orbit.flux_scale(1500.0)[0]))
    assert data["equilibrium"]["T_back_K"] != sun_alone.equilibrium.T_back
    assert data["t_s"] == 1500.0 and data["earth_heating"] is True
    assert data["attitude"] == {"kind": "sun_tracking", "offset": 0.1}
    assert data["map"]["sun_only"] is True and data["year"]["sun_only"] is True
    text_out = capsys.readouterr().out
    assert "Earth heating" in text_out and "the Sun alone" in text_out


def test_flutter_t_moves_the_flux_along_the_year(tmp_path: Path) -> None:
    text = '[orbit]\npreset = "geo_year"\nstart_date = "2026-01-04"\n'
    t = 182.0 * 86400.0  # near aphelion
    data = flutter_json(tmp_path, text, "--no-plot", "--t", str(t))
    orbit = tj.Orbit.geo_year("2026-01-04")
    api = tj.flutter(tj.Panel.paper(), orbit=orbit, t=t)
    assert data["flux"] == float(orbit.flux_scale(t)[0]) == api.flux
    assert data["models"]["nonlinear"]["critical_damping_N_m_s_per_rad"] == api.critical_damping
    assert data["earth_heating"] is False


BOOM = """
[boom]
length = 15.0
radius = 6.35e-3
wall = 5.1e-5
absorptivity = 0.5
emissivity = 0.05
damping = 0.001
solar_inclination_deg = 120.0
"""


def the_boom() -> tj.Boom:
    """The boom of BOOM, built through the API."""
    return tj.Boom(
        15.0,
        6.35e-3,
        5.1e-5,
        absorptivity=0.5,
        emissivity=0.05,
        damping=0.001,
        solar_inclination=math.radians(120.0),
    )


def test_flutter_of_a_boom_is_the_tubes_analysis(tmp_path: Path) -> None:
    data = flutter_json(tmp_path, BOOM + '\n[orbit]\npreset = "geo_year"\n')
    boom = the_boom()
    orbit = tj.Orbit.geo_year()
    api = tj.flutter(boom, orbit=orbit, t=0.0)
    assert data["tube"]["growth_rate_per_s"] == api.growth_rate
    assert data["tube"]["critical_damping_ratio"] == api.critical_damping
    assert data["equilibrium"]["tip_deflection_m"] == api.equilibrium.tip_deflection
    assert data["flux"] == float(orbit.flux_scale(0.0)[0])
    sweep = tj.boom_stability_map(
        boom, np.radians(BOOM_INCLINATIONS_DEG), [boom.response_time_ratio], flux=data["flux"]
    )
    assert data["sweep"]["growth_rate_per_s"] == sweep.growth_rate[:, 0].tolist()
    assert data["sweep"]["critical_damping_ratio"] == sweep.critical_damping[:, 0].tolist()
    assert (tmp_path / "out" / "boom_stability.png").stat().st_size > 10_000


@pytest.mark.parametrize(
    ("text", "args", "message"),
    [
        (BOOM + '\n[attitude]\nkind = "nadir"\n', [], "attitude.kind"),
        (BOOM + HUBBLE_ORBIT, [], "orbit.albedo"),
        (BOOM, ["--x", "damping:0:1:3"], "boom"),
        (HUBBLE_ORBIT, ["--flux", "1.0"], "give t, not flux"),
        ('[flutter]\nt = "noon"\n', [], "flutter.t"),
    ],
)
def test_flutter_refuses_what_it_cannot_analyse_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], text: str, args: list[str], message: str
) -> None:
    scenario = tmp_path / "s.toml"
    scenario.write_text(text)
    assert cli.main(["flutter", str(scenario), "--out", str(tmp_path / "o"), *args]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and "\n" not in err


def test_run_with_earth_heating_and_an_attitude_keeps_each_faces_flux(tmp_path: Path) -> None:
    scenario = tmp_path / "s.toml"
    scenario.write_text(HUBBLE_ORBIT + TRACKING + "\n[simulation]\nt_end = 1200.0\ndt_out = 60.0\n")
    out = tmp_path / "out"
    assert cli.main(["run", str(scenario), "--out", str(out), "--no-progress"]) == 0
    series = pd.read_csv(out / "timeseries.csv")
    orbit, attitude = hubble(), tj.Attitude.sun_tracking(0.1)
    sol = tj.simulate(tj.Panel.paper(), orbit, (0.0, 1200.0), dt_out=60.0, attitude=attitude)
    np.testing.assert_array_equal(series["t [s]"], sol.t)
    np.testing.assert_array_equal(series["theta [rad]"], sol.theta)
    assert sol.flux_front is not None and sol.flux_back is not None
    np.testing.assert_array_equal(series["flux_front [W/m²]"], sol.flux_front)
    np.testing.assert_array_equal(series["flux_back [W/m²]"], sol.flux_back)
    meta = json.loads((out / "run.json").read_text())
    assert {"fluxes.png", "orbit_year.png"} <= set(meta["files"])
    assert meta["columns"]["flux_back"] == "W/m²"


def test_run_of_a_boom_writes_the_tubes_columns(tmp_path: Path) -> None:
    scenario = tmp_path / "s.toml"
    scenario.write_text(BOOM + '\n[orbit]\npreset = "leo"\n\n[simulation]\nt_end = 600.0\n')
    out = tmp_path / "out"
    assert cli.main(["run", str(scenario), "--out", str(out), "--no-progress", "--no-plots"]) == 0
    series = pd.read_csv(out / "timeseries.csv")
    boom = the_boom()
    sol = tj.simulate(boom, tj.Orbit.leo(), (0.0, 600.0), dt_out=0.5)
    np.testing.assert_array_equal(series["T_circ [K]"], sol.T_circ)
    np.testing.assert_array_equal(series["theta [rad]"], sol.theta)
    meta = json.loads((out / "run.json").read_text())
    assert meta["columns"]["T_mean"] == "K" and "T_front" not in meta["columns"]


def test_the_year_figure_plots_the_apis_beta_and_eclipses() -> None:
    orbit = hubble()
    span = 20.0 * 86400.0
    fig = orbit_year_figure(orbit, 1000.0, span, title="hubble")
    try:
        top, bottom = fig.axes[:2]
        beta = top.lines[0].get_xydata()
        t = 1000.0 + beta[:, 0] * 86400.0
        np.testing.assert_allclose(beta[:, 1], np.degrees(orbit.beta(t)), rtol=0, atol=1e-9)
        assert beta[0, 0] == 0.0 and beta[-1, 0] == pytest.approx(20.0)
        total = bottom.lines[0].get_xydata()
        np.testing.assert_array_equal(
            total[:, 1], orbit.eclipse_durations(1000.0, 1000.0 + span) / 60.0
        )
        rows = orbit.eclipses(1000.0, 1000.0 + span)
        deepest = rows[(rows[:, 0] >= 1000.0) & (rows[:, 0] < 1000.0 + span), 0]
        np.testing.assert_array_equal(total[:, 0], (deepest - 1000.0) / 86400.0)
        assert len(total) == pytest.approx(span / orbit.synodic_period, abs=1.0)
        umbra = bottom.lines[1].get_xydata()
        kind = "umbra"
        np.testing.assert_array_equal(
            umbra[:, 1], orbit.eclipse_durations(1000.0, 1000.0 + span, kind=kind) / 60.0
        )
    finally:
        import matplotlib.pyplot as plt

        plt.close(fig)


def test_the_year_figure_of_geo_shows_two_eclipse_seasons() -> None:
    orbit = tj.Orbit.geo_year("2026-01-01")
    fig = orbit_year_figure(orbit)
    try:
        days = fig.axes[1].lines[0].get_xdata()
        # Eclipses only around the equinoxes (days ~79 and ~266), none at the solstices.
        assert days.min() > 79 - 30 and days.max() < 266 + 30
        assert not np.any((days > 120) & (days < 220))
        assert len(days) == len(orbit.eclipse_durations(0.0, 365.25 * 86400.0))
    finally:
        import matplotlib.pyplot as plt

        plt.close(fig)


def test_the_flux_figure_plots_each_faces_flux() -> None:
    orbit = hubble()
    sol = tj.simulate(
        tj.Panel.paper(),
        orbit,
        (0.0, orbit.period),
        dt_out=30.0,
        attitude=tj.Attitude.nadir(),
    )
    assert sol.flux_front is not None and sol.flux_back is not None
    fig = face_flux_figure(sol.t, sol.flux_front, sol.flux_back, orbit, title="nadir")
    try:
        (ax,) = fig.axes
        front, back = ax.lines[:2]
        np.testing.assert_array_equal(front.get_ydata(), sol.flux_front)
        np.testing.assert_array_equal(back.get_ydata(), sol.flux_back)
        np.testing.assert_array_equal(front.get_xdata(), sol.t / 60.0)
        # Nadir: the front faces the Earth, so it keeps the Earth's infrared in the shadow.
        dark = sol.sunlit == 0.0
        assert dark.any() and np.all(sol.flux_front[dark] > 0.0)
    finally:
        import matplotlib.pyplot as plt

        plt.close(fig)


def test_the_boom_figure_plots_the_sweep() -> None:
    boom = tj.Boom(15.0, 6.35e-3, 5.1e-5, absorptivity=0.5, emissivity=0.05, damping=0.0)
    psi = np.radians([60.0, 90.0, 120.0])
    sweep = tj.boom_stability_map(boom, psi, [boom.response_time_ratio])
    fig = boom_stability_figure(sweep, boom)
    try:
        top, bottom = fig.axes[:2]
        np.testing.assert_array_equal(top.lines[0].get_xdata(), np.degrees(psi))
        np.testing.assert_array_equal(top.lines[0].get_ydata(), sweep.growth_rate[:, 0])
        np.testing.assert_array_equal(bottom.lines[0].get_ydata(), sweep.critical_damping[:, 0])
    finally:
        import matplotlib.pyplot as plt

        plt.close(fig)


def test_the_hubble_year_example_runs(tmp_path: Path) -> None:
    """examples/hubble_year.py on one day (its default samples 24, about half a minute)."""
    import subprocess
    import sys

    script = Path(__file__).resolve().parents[1] / "examples" / "hubble_year.py"
    done = subprocess.run(
        [sys.executable, str(script), "--days", "1", "--orbits", "2", "--out", str(tmp_path)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    assert "Warning" not in done.stderr
    lines = done.stdout.splitlines()
    day0 = next(line for line in lines if line.strip().startswith("0.0"))
    beta = float(day0.split()[1])
    orbit = tj.Orbit.circular(540e3, math.radians(28.5), 0.0, "2026-01-01")
    deepest = orbit.eclipses(0.0, orbit.period)[0, 0]
    assert beta == pytest.approx(math.degrees(orbit.beta(deepest + orbit.period / 2)[0]), abs=0.05)
    assert any("c_d* at noon" in line for line in lines)
    assert (tmp_path / "orbit_year.png").exists() and (tmp_path / "fluxes.png").exists()


HISTORICAL = ("boom_1963_22a_bare", "boom_1963_22a_silver", "boom_hst_bistem", "boom_cfrp")


@pytest.mark.parametrize("name", HISTORICAL)
def test_each_historical_scenario_runs_through_the_command_in_under_a_minute(
    name: str, tmp_path: Path
) -> None:
    """Issue 31's bound, through ``thermojitter run`` as a user runs it (plots included)."""
    import time

    scenario = Path(__file__).resolve().parents[1] / "examples" / f"{name}.toml"
    started = time.perf_counter()
    assert cli.main(["run", str(scenario), "--out", str(tmp_path), "--no-progress"]) == 0
    elapsed = time.perf_counter() - started
    assert elapsed < 60.0, elapsed
    meta = json.loads((tmp_path / "run.json").read_text())
    assert not meta["interrupted"] and "theta.png" in meta["files"]


@pytest.mark.parametrize(
    ("text", "key"),
    [
        ('[orbit]\npreset = "circular"\naltitude = 540\n', "orbit.altitude"),
        ('[orbit]\npreset = "circular"\nstart_date = "noon"\n', "orbit.start_date"),
        ('[orbit]\npreset = "circular"\ninclination = 28.5\n', "orbit.inclination"),
        ('[orbit]\npreset = "leo"\nstart_date = 2026-01-01\n', "orbit.start_date"),
    ],
)
def test_the_circular_preset_names_a_bad_key(tmp_path: Path, text: str, key: str) -> None:
    from thermojitter.scenario import ScenarioError, load_scenario

    scenario = tmp_path / "s.toml"
    scenario.write_text(text)
    with pytest.raises(ScenarioError) as caught:
        load_scenario(scenario)
    assert caught.value.key == key, caught.value


def test_the_circular_preset_is_orbit_circular(tmp_path: Path) -> None:
    from thermojitter.scenario import load_scenario

    scenario = tmp_path / "s.toml"
    scenario.write_text(HUBBLE_ORBIT + "albedo = 0.0\n")
    assert load_scenario(scenario).orbit == hubble().replace(albedo=0.0)
