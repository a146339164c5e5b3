"""Monte Carlo over orbit inputs (albedo, Earth infrared, inclination, RAAN), attitudes and booms:
each sample equals the single run of its own panel (or boom) on its own orbit, the frames do not
depend on threads, chunks or the lanes, bad names and ranges are refused by name, the checkpoint
tells the new inputs apart, and the ``mc`` command takes scenarios with them."""

from __future__ import annotations

import math
import textwrap
import warnings
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import thermojitter as tj
from conftest import PAPER
from thermojitter import montecarlo
from thermojitter.checkpoint import CheckpointError
from thermojitter.montecarlo_cli import mc_command

# A 700 km orbit, its Sun by date: ~99 min period, ~35 min eclipse; loose tolerances keep the
# runs short (one orbit each).
LEO = tj.Orbit.circular(700e3, inclination=0.5, raan=0.3, albedo=0.3, earth_ir=237.0)
LOW = tj.Orbit(radius=7.0e6, period=5828.5)
FAST: dict[str, Any] = {"rtol": 1e-6, "atol": 1e-8, "progress": False}
ATTITUDES = [None, tj.Attitude.nadir(), tj.Attitude.sun_tracking(0.2)]


def single_run(panel: Any, orbit: tj.Orbit, attitude: Any = None) -> Any:
    """The one simulate_orbits run a sample stands for: one orbit, rk45 with the study's
    tolerances, its step capped as the study caps it, nothing stopped."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", tj.errors.ValidityLimitWarning)
        return tj.simulate_orbits(
            panel, orbit, 1, method="rk45", rtol=1e-6, atol=1e-8, on_limit="ignore",
            progress=False, attitude=attitude,
        )  # fmt: skip


def assert_sample_is_its_single_run(row: Any, run: Any, flutter: Any) -> None:
    c = run.columns
    assert row["theta_abs_max"] == max(abs(c["theta_max"][0]), abs(c["theta_min"][0]))
    assert row["amplitude"] == c["amplitude"][0]
    assert row["jitter_peak"] == c["jitter_peak"][0]
    assert row["jitter_rms"] == pytest.approx(c["jitter_rms"][0], rel=1e-12)
    for peak in ("entry_peak", "exit_peak"):
        assert row[peak] == c[peak][0] or (math.isnan(row[peak]) and math.isnan(c[peak][0]))
    assert row["n_steps"] == run.n_steps
    assert row["t_reached"] == run.t_end
    assert row["growth_rate"] == flutter.growth_rate
    assert row["critical_damping"] == flutter.critical_damping
    assert row["theta_eq"] == flutter.equilibrium.theta


@settings(max_examples=4, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    attitude=st.sampled_from(ATTITUDES),
    seed=st.integers(0, 2**32 - 1),
    albedo_hi=st.floats(0.05, 0.6),
)
def test_each_sample_is_the_single_run_of_its_orbit(
    attitude: Any, seed: int, albedo_hi: float
) -> None:
    vary = {
        "damping": ("uniform", 1.0, 4.0),
        "albedo": ("uniform", 0.0, albedo_hi),
        "earth_ir": ("uniform", 150.0, 260.0),
        "inclination": ("uniform", 0.0, 1.7),
        "raan": ("uniform", -math.pi, math.pi),
    }
    frame = tj.monte_carlo(PAPER, LEO, vary=vary, n=3, seed=seed, attitude=attitude, **FAST)
    assert frame["error"].isna().all()
    for _, row in frame.iterrows():
        orbit = LEO.replace(**{k: float(row[k]) for k in vary if k != "damping"})
        panel = PAPER.replace(damping=float(row["damping"]))
        flutter = tj.flutter(panel, orbit=orbit, t=0.0, attitude=attitude)
        assert_sample_is_its_single_run(row, single_run(panel, orbit, attitude), flutter)


def test_the_earths_loads_and_the_orbit_plane_change_the_samples() -> None:
    # The same panels with and without the Earth's loads, and on two inclinations.
    grid = {"albedo": [0.0, 0.35], "inclination": [0.2, 1.2], "damping": [2.0]}
    frame = tj.sweep(PAPER, LEO.replace(earth_ir=0.0), grid, **FAST)
    by = frame.set_index(["albedo", "inclination"])
    assert by.loc[(0.35, 0.2), "theta_eq"] != by.loc[(0.0, 0.2), "theta_eq"]
    assert by.loc[(0.0, 1.2), "exit_peak"] != by.loc[(0.0, 0.2), "exit_peak"]
    # Without Earth heating and Sun-pointing: the flutter analysis at full Sun, as tj.flutter.
    assert by.loc[(0.0, 0.2), "growth_rate"] == tj.flutter(PAPER.replace(damping=2.0)).growth_rate


def test_frames_with_orbit_inputs_do_not_depend_on_threads_chunks_or_lanes(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # Samples with and without the Earth's loads in one study: the lanes take those without,
    # the others run one at a time; every way gives the same frame, bit for bit.
    grid = {
        "albedo": [0.0, 0.3],
        "earth_ir": [0.0, 220.0],
        "raan": [0.0, 1.0],
        "damping": [1.0, 3.0],
    }
    orbit = LEO.replace(albedo=0.0, earth_ir=0.0)
    frames = []
    for lockstep, threads, chunk in ((True, 2, None), (True, 1, 5), (False, 2, 1)):
        monkeypatch.setattr(montecarlo.backends, "_LOCKSTEP", lockstep)
        frames.append(tj.sweep(PAPER, orbit, grid, threads=threads, chunk_size=chunk, **FAST))
    for other in frames[1:]:
        pd.testing.assert_frame_equal(frames[0], other, check_exact=True)
    vary = {"inclination": ("uniform", 0.0, 1.0), "earth_ir": ("normal", 230.0, 10.0)}
    one = tj.monte_carlo(PAPER, LEO, vary=vary, n=6, seed=4, threads=1, **FAST)
    two = tj.monte_carlo(PAPER, LEO, vary=vary, n=6, seed=4, threads=2, chunk_size=4, **FAST)
    pd.testing.assert_frame_equal(one, two, check_exact=True)
    assert list(one.columns[:2]) == ["inclination", "earth_ir"]


def test_a_hybrid_study_with_the_earths_loads_runs_each_sample_as_its_single_run() -> None:
    # On slow time, as a single hybrid run: each sample equals its own simulate_orbits, and
    # only its penumbrae are counted as integrated in full.
    vary = {"albedo": ("uniform", 0.2, 0.4)}
    n_orbits = 2
    with warnings.catch_warnings():
        warnings.simplefilter("error", tj.errors.HybridFallbackWarning)
        frame = tj.monte_carlo(
            PAPER, LEO, vary=vary, n=2, seed=1, method="hybrid", horizon=n_orbits, **FAST
        )
    for _, row in frame.iterrows():
        orbit = LEO.replace(albedo=float(row["albedo"]))
        single = tj.simulate_orbits(PAPER, orbit, n_orbits, method="hybrid", **FAST)
        assert row["jitter_peak"] == single.jitter_peak.max()
        assert row["amplitude"] == single.amplitude.max()
        p = single.propagation
        assert p["t_slow"] > 0.9 * n_orbits * orbit.period
        assert row["t_nonlinear"] == pytest.approx(p["t_fallback"] + p["t_exponential"], rel=1e-12)
        assert row["t_nonlinear"] < 0.1 * row["t_reached"]


def boom(**changes: float) -> tj.Boom:
    """A 30 m beryllium–copper STEM tube, lightly damped."""
    values = {"length": 30.0, "radius": 6.35e-3, "wall": 5.1e-5, "damping": 0.01, **changes}
    return tj.Boom(**values)  # type: ignore[arg-type]


def test_each_boom_sample_is_the_single_run_of_its_boom() -> None:
    vary = {
        "damping": ("uniform", 0.0, 0.02),
        "solar_inclination": ("uniform", 0.8, 2.3),
        "inclination": ("uniform", 0.0, 0.5),
    }
    base = boom()
    frame = tj.monte_carlo(base, LOW, vary=vary, n=3, seed=5, **FAST)
    assert frame["error"].isna().all() and list(frame.columns[:3]) == list(vary)
    for _, row in frame.iterrows():
        b = base.replace(damping=row["damping"], solar_inclination=row["solar_inclination"])
        orbit = LOW.replace(inclination=float(row["inclination"]))
        assert_sample_is_its_single_run(row, single_run(b, orbit), tj.flutter(b))
    # Threads and chunks change nothing; the damping ratio decides the stability.
    two = tj.monte_carlo(base, LOW, vary=vary, n=3, seed=5, threads=2, chunk_size=1, **FAST)
    pd.testing.assert_frame_equal(frame, two, check_exact=True)
    assert (frame["stable"] == (frame["damping"] > frame["critical_damping"])).all()


def test_a_boom_sweep_and_its_hybrid_run_the_tube_in_full() -> None:
    grid = {"emissivity": [0.05, 0.3], "tip_mass": [0.0, 0.5]}
    frame = tj.sweep(boom(), LOW, grid, method="hybrid", **FAST)
    assert frame["error"].isna().all() and len(frame) == 4
    np.testing.assert_array_equal(frame["t_nonlinear"], frame["t_reached"])
    first = boom(emissivity=0.05, tip_mass=0.0)
    assert frame["theta_eq"].iloc[0] == tj.flutter(first).equilibrium.theta


@pytest.mark.parametrize(
    ("panel", "kwargs", "name"),
    [
        (PAPER, {"vary": {"albedo": ("uniform", 0.5, 1.5)}}, "albedo"),
        (PAPER, {"vary": {"inclination": ("uniform", 10.0, 30.0)}}, "inclination"),
        (PAPER, {"vary": {"earth_ir": ("normal", 200.0, 500.0)}, "n": 40}, "earth_ir"),
        (PAPER, {"vary": {"albedos": ("uniform", 0.1, 0.2)}}, "vary"),
        (PAPER, {"vary": {"albedo": ("uniform", 0.1, 0.2)}, "layers": 3}, "layers"),
        (PAPER, {"attitude": "nadir"}, "attitude"),
        (boom(), {"vary": {"earth_ir": ("uniform", 100.0, 200.0)}}, "vary.earth_ir"),
        (boom(), {"vary": {"conductance": ("uniform", 10.0, 20.0)}}, "vary"),
        (boom(), {"attitude": tj.Attitude.nadir()}, "attitude"),
        (boom(), {"vary": {"wall": ("uniform", 1e-4, 5e-3)}}, "wall"),
        (boom(), {"layers": 3}, "layers"),
    ],
)
def test_bad_names_and_ranges_are_refused_naming_the_parameter(
    panel: Any, kwargs: dict[str, Any], name: str
) -> None:
    args: dict[str, Any] = {"vary": {"damping": ("uniform", 0.0, 0.01)}, "n": 4, "seed": 1}
    with pytest.raises(tj.ParameterError) as info:
        tj.monte_carlo(panel, LOW, **{**args, **kwargs}, **FAST)
    assert info.value.parameter == name, info.value


def test_a_boom_refuses_an_orbit_with_earth_heating() -> None:
    with pytest.raises(tj.ParameterError) as info:
        tj.monte_carlo(boom(), LEO, vary={"damping": ("uniform", 0.0, 0.01)}, n=2, **FAST)
    assert info.value.parameter == "orbit"


def test_truncation_keeps_orbit_inputs_in_their_range() -> None:
    vary = {"albedo": ("normal", 0.9, 0.3), "inclination": ("normal", 3.0, 0.5)}
    frame = tj.monte_carlo(PAPER, LEO, vary=vary, n=8, seed=2, truncate=True, **FAST)
    assert frame["albedo"].between(0.0, 1.0).all()
    assert frame["inclination"].between(0.0, math.pi).all()
    assert (frame["albedo"] > 0.6).any()


def test_the_checkpoint_tells_attitudes_and_orbit_inputs_apart(tmp_path: Path) -> None:
    vary: dict[str, Any] = {"raan": ("uniform", 0.0, 1.0)}
    args: dict[str, Any] = {"n": 2, "seed": 3, "checkpoint": tmp_path / "c", **FAST}
    first = tj.monte_carlo(PAPER, LEO, vary=vary, **args)
    again = tj.monte_carlo(PAPER, LEO, vary=vary, **args)
    pd.testing.assert_frame_equal(first, again, check_exact=True)
    for changed in (
        {"vary": vary, "attitude": tj.Attitude.nadir()},
        {"vary": {"raan": ("uniform", 0.0, 2.0)}},
        {"vary": {"inclination": ("uniform", 0.0, 1.0)}},
    ):
        with pytest.raises(CheckpointError):
            tj.monte_carlo(PAPER, LEO, **changed, **args)
    # The design's digest covers the orbit inputs: the same panels on other orbits differ.
    s = first.attrs["settings"]
    # Where the samples start on an orbit with the Earth's loads is part of the request.
    assert s["run"]["start"] == "loaded_equilibrium"
    other = tj.monte_carlo(PAPER, LEO, vary={"raan": ("uniform", 0.0, 2.0)}, n=2, seed=3, **FAST)
    assert other.attrs["settings"]["design_sha256"] != s["design_sha256"]


def test_mc_command_takes_orbit_inputs_an_attitude_and_a_boom(tmp_path: Path) -> None:
    scenario = tmp_path / "leo.toml"
    scenario.write_text(
        textwrap.dedent(f"""
            [orbit]
            radius = {LEO.radius!r}
            period = {LEO.period!r}
            shadow = "penumbra"
            season = true
            eccentric_sun = true
            epoch_day = {LEO.epoch_day!r}
            inclination = 0.5
            raan = 0.3
            j2 = true
            albedo = 0.3
            earth_ir = 237.0
            [attitude]
            kind = "nadir"
            [vary]
            albedo = ["uniform", 0.2, 0.4]
            inclination = ["uniform", 0.3, 0.9]
            [montecarlo]
            rtol = 1e-6
            atol = 1e-8
        """)
    )
    base = ["--n", "3", "--no-progress", "--no-plots", "--seed", "6"]
    assert mc_command([str(scenario), *base, "--out", str(tmp_path / "leo")]) == 0
    frame = pd.read_parquet(tmp_path / "leo" / "samples.parquet")
    expected = tj.monte_carlo(
        PAPER, LEO, attitude=tj.Attitude.nadir(), n=3, seed=6,
        vary={"albedo": ("uniform", 0.2, 0.4), "inclination": ("uniform", 0.3, 0.9)}, **FAST,
    )  # fmt: skip
    np.testing.assert_array_equal(frame["exit_peak"], expected["exit_peak"])
    np.testing.assert_array_equal(frame["albedo"], expected["albedo"])

    tube = tmp_path / "boom.toml"
    tube.write_text(
        "[boom]\nlength = 30.0\nradius = 6.35e-3\nwall = 5.1e-5\ndamping = 0.01\n"
        "[orbit]\nradius = 7.0e6\nperiod = 5828.5\n"
        '[vary]\nsolar_inclination = ["uniform", 0.8, 2.3]\nraan = ["uniform", 0.0, 1.0]\n'
        "[montecarlo]\nrtol = 1e-6\natol = 1e-8\n"
    )
    assert mc_command([str(tube), *base, "--out", str(tmp_path / "boom")]) == 0
    frame = pd.read_parquet(tmp_path / "boom" / "samples.parquet")
    expected = tj.monte_carlo(
        boom(), LOW, n=3, seed=6,
        vary={"solar_inclination": ("uniform", 0.8, 2.3), "raan": ("uniform", 0.0, 1.0)}, **FAST,
    )  # fmt: skip
    np.testing.assert_array_equal(frame["jitter_rms"], expected["jitter_rms"])


def test_mc_command_refuses_a_bad_orbit_input_in_one_line(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scenario = tmp_path / "bad.toml"
    scenario.write_text(
        '[orbit]\nradius = 7.0e6\nperiod = 5828.5\n[vary]\nalbedo = ["uniform", 0.5, 1.5]\n'
    )
    code = mc_command([str(scenario), "--n", "4", "--out", str(tmp_path / "x"), "--no-progress"])
    err = capsys.readouterr().err
    assert code == 2 and "albedo" in err and err.count("\n") == 1


def test_sensitivity_takes_orbit_inputs_and_an_attitude() -> None:
    pytest.importorskip("SALib")
    vary = {"albedo": ("uniform", 0.0, 0.6), "raan": ("uniform", 0.0, 1.0)}
    res = tj.sensitivity(
        PAPER, LEO, vary, metric="theta_eq", n=4, attitude=tj.Attitude.nadir(), **FAST
    )
    assert list(res.indices.index) == ["albedo", "raan"]
    assert len(res.samples) == 4 * 4 and res.samples["albedo"].between(0.0, 0.6).all()
    # Each sample's equilibrium is its own orbit's at t = 0 (as the Monte Carlo's are).
    row = res.samples.iloc[5]
    orbit = LEO.replace(albedo=float(row["albedo"]), raan=float(row["raan"]))
    eq = tj.flutter(PAPER, orbit=orbit, t=0.0, attitude=tj.Attitude.nadir()).equilibrium
    assert row["theta_eq"] == eq.theta
