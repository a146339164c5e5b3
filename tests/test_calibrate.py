"""Calibration of the hinge model: recovery of known parameters, validation, the beam fit."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

import thermojitter as tj
from conftest import ENTRY, GEO, PAPER

EI_L = PAPER.youngs_modulus * PAPER.bending_inertia / PAPER.length
T = np.arange(ENTRY - 60.0, ENTRY + 900.0, 1.0)


def synthetic(panel: tj.Panel, sigma_deg: float, seed: int) -> np.ndarray:
    """θ of a forward run at the times T plus Gaussian noise of sigma_deg degrees."""
    sol = tj.simulate(panel, GEO, (T[0], T[-1]), t_eval=T, rtol=1e-10, atol=1e-12)
    rng = np.random.default_rng(seed)
    return np.asarray(sol.theta) + math.radians(sigma_deg) * rng.standard_normal(T.size)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_recovers_stiffness_and_damping_within_their_errors(seed: int) -> None:
    sigma = 0.02
    theta = synthetic(PAPER, sigma, seed)
    start = PAPER.replace(hinge_stiffness=4000.0, damping=6.0)
    fit = tj.calibrate(T, theta, panel=start, orbit=GEO)
    assert fit.success
    for name, true in (("hinge_stiffness", 4438.0), ("damping", 3.0)):
        se = fit.standard_errors[name]
        assert abs(fit.parameters[name] - true) < 3.0 * se, (name, fit.parameters[name], se)
        assert se < 0.1 * true  # the data do constrain the parameter
    assert fit.residual_rms_deg == pytest.approx(sigma, rel=0.1)
    assert fit.panel.hinge_stiffness == fit.parameters["hinge_stiffness"]


def test_recovers_moment_scale() -> None:
    truth = PAPER.replace(hinge_stiffness=5840.0, moment_scale=1.3)
    theta = synthetic(truth, 0.02, 7)
    fit = tj.calibrate(
        T,
        theta,
        panel=PAPER,
        orbit=GEO,
        fit=("hinge_stiffness", "damping", "moment_scale"),
        initial={"hinge_stiffness": 5500.0, "moment_scale": 1.2},
    )
    for name, true in (("hinge_stiffness", 5840.0), ("damping", 3.0), ("moment_scale", 1.3)):
        assert abs(fit.parameters[name] - true) < 3.0 * fit.standard_errors[name], name


def test_reads_telemetry_from_csv(tmp_path: Path) -> None:
    theta = synthetic(PAPER, 0.02, 4)
    path = tmp_path / "telemetry.csv"
    np.savetxt(
        path,
        np.column_stack([T, np.degrees(theta)]),
        delimiter=",",
        header="time,angle",
        comments="",
    )
    fit = tj.calibrate_from_csv(
        path, time_column="time", angle_column="angle", degrees=True, panel=PAPER, orbit=GEO
    )
    assert (
        abs(fit.parameters["hinge_stiffness"] - 4438.0)
        < 3.0 * fit.standard_errors["hinge_stiffness"]
    )
    with pytest.raises(ValueError, match="angle_column"):
        tj.calibrate_from_csv(path, time_column="time", angle_column="theta")
    with pytest.raises(ValueError, match="path"):
        tj.calibrate_from_csv(tmp_path / "missing.csv")


def test_reads_the_time_series_of_the_run_command_with_its_units(tmp_path: Path) -> None:
    """timeseries.csv says its units in its header (t [s], theta [rad]); the column names alone
    find them."""
    from thermojitter.cli import main

    scenario = tmp_path / "s.toml"
    span = f"t_start = {ENTRY - 60.0!r}\nt_end = {ENTRY + 600.0!r}\ndt_out = 2.0\n"
    scenario.write_text(f"[simulation]\n{span}[output]\nplots = false\n")
    assert main(["run", str(scenario), "--out", str(tmp_path / "out"), "--no-progress"]) == 0
    series = tmp_path / "out" / "timeseries.csv"
    assert series.read_text().splitlines()[0].startswith("t [s],T_front [K],T_back [K],theta [rad]")
    start = PAPER.replace(hinge_stiffness=4000.0)
    fit = tj.calibrate_from_csv(series, panel=start, orbit=GEO, fit=("hinge_stiffness",))
    table = np.loadtxt(series, delimiter=",", skiprows=1)
    same = tj.calibrate(table[:, 0], table[:, 3], panel=start, orbit=GEO, fit=("hinge_stiffness",))
    assert fit.parameters == same.parameters
    assert fit.theta_model.tobytes() == same.theta_model.tobytes()


def test_refuses_bad_series() -> None:
    theta = np.zeros(T.size)
    with pytest.raises(ValueError, match="too short"):
        tj.calibrate(T[:5], theta[:5])
    backwards = T.copy()
    backwards[10] = backwards[9]
    with pytest.raises(ValueError, match="t must be strictly increasing"):
        tj.calibrate(backwards, theta)
    holed = theta.copy()
    holed[3] = np.nan
    with pytest.raises(tj.ParameterError, match="theta = nan .* must be finite"):
        tj.calibrate(T, holed)
    t_nan = T.copy()
    t_nan[0] = np.nan
    with pytest.raises(tj.ParameterError, match="t = nan .* must be finite"):
        tj.calibrate(t_nan, theta)
    with pytest.raises(TypeError, match="theta"):  # a bool is not an angle
        tj.calibrate(T, [False] * T.size)
    with pytest.raises(ValueError, match="theta has shape"):
        tj.calibrate(T, theta[:-1])
    with pytest.raises(ValueError, match="fit"):
        tj.calibrate(T, theta, fit=("length",))
    with pytest.raises(ValueError, match="initial"):
        tj.calibrate(T, theta, initial={"moment_scale": 1.3})


def test_fit_to_the_beam_lands_on_the_criteria() -> None:
    """The hinge fitted to the beam's θ_f: with χ free, K_el near the frequency criterion and χ
    near 5.21/4; with K_el and c_d alone, K_el near the deflection criterion 4EI/L."""
    cmp = tj.compare_with_beam(PAPER, GEO)
    m = (cmp.t >= ENTRY - 60.0) & (cmp.t <= ENTRY + 600.0)
    freq = tj.hinge_stiffness(PAPER, "frequency")
    full = tj.calibrate(
        cmp.t[m],
        cmp.theta_f[m],
        panel=PAPER,
        orbit=GEO,
        fit=("hinge_stiffness", "damping", "moment_scale"),
        initial={"hinge_stiffness": freq, "moment_scale": freq / (4 * EI_L)},
    )
    assert full.parameters["hinge_stiffness"] == pytest.approx(freq, rel=0.02)
    assert full.parameters["moment_scale"] == pytest.approx(5.21 / 4, rel=0.02)
    assert full.residual_rms_deg < 0.02
    two = tj.calibrate(cmp.t[m], cmp.theta_f[m], panel=PAPER, orbit=GEO)
    assert two.parameters["hinge_stiffness"] == pytest.approx(4 * EI_L, rel=0.02)
