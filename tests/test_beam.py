"""The finite-element beam against closed forms, and the hinge model against the beam."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings

import thermojitter as tj
from conftest import GEO, PAPER, panels
from thermojitter import cli
from thermojitter.beam import FIGURES, dominant_frequency

EI = PAPER.youngs_modulus * PAPER.bending_inertia
L = PAPER.length
M = PAPER.mass_per_length


def continuous_frequency(beta_l: float, panel: tj.Panel = PAPER) -> float:
    """(β L)² sqrt(EI/(m L⁴))/2π of the continuous free–free beam, Hz."""
    ei = panel.youngs_modulus * panel.bending_inertia
    return beta_l**2 * math.sqrt(ei / (panel.mass_per_length * panel.length**4)) / (2 * math.pi)


@pytest.fixture(scope="module")
def beam() -> tj.FreeFreeBeam:
    return tj.beam.FreeFreeBeam(PAPER)


def test_first_frequency_is_the_papers(beam: tj.FreeFreeBeam) -> None:
    f1 = beam.natural_frequencies(1)[0]
    assert f1 == pytest.approx(0.144, abs=5e-4)  # paper Sec. 4.3
    assert f1 == pytest.approx(continuous_frequency(4.7300), rel=1e-3)


def test_first_frequency_converges_at_fourth_order() -> None:
    exact = continuous_frequency(4.730040745)
    errors = [
        tj.beam.FreeFreeBeam(PAPER, n).natural_frequencies(1)[0] / exact - 1.0 for n in (4, 8, 16)
    ]
    # Hermite cubics with consistent mass converge from above, error ∝ h⁴.
    assert all(e > 0 for e in errors)
    for coarse, fine in zip(errors, errors[1:], strict=False):
        assert math.log2(coarse / fine) > 3.5
    assert errors[1] < 1e-3


def test_higher_frequencies_match_the_continuous_beam(beam: tj.FreeFreeBeam) -> None:
    f = beam.natural_frequencies(3)
    for fi, beta_l in zip(f, (4.7300, 7.8532, 10.9956), strict=True):
        assert fi == pytest.approx(continuous_frequency(beta_l), rel=1e-4)


def test_rigid_modes_have_zero_frequency_and_mass_is_whole(beam: tj.FreeFreeBeam) -> None:
    w1_sq = (2 * math.pi * beam.natural_frequencies(1)[0]) ** 2
    assert np.all(np.abs(beam.rigid_eigenvalues) < 1e-6 * w1_sq)
    assert beam.total_mass == pytest.approx(M * L, rel=1e-12)


def test_mode_shapes_are_the_free_free_shapes(beam: tj.FreeFreeBeam) -> None:
    x, shapes = beam.mode_shapes(2)
    assert shapes.shape == (101, 2)
    # first mode symmetric with two nodes near x = 0.224 L and 0.776 L; second antisymmetric
    first, second = shapes[:, 0], shapes[:, 1]
    np.testing.assert_allclose(first, first[::-1], atol=1e-8 * np.abs(first).max())
    np.testing.assert_allclose(second, -second[::-1], atol=1e-8 * np.abs(second).max())
    j = np.nonzero(np.diff(np.sign(first)) != 0)[0]
    crossings = (x[j] - first[j] * (x[j + 1] - x[j]) / (first[j + 1] - first[j])) / L
    assert crossings == pytest.approx([0.2242, 0.7758], abs=2e-4)
    # mass normalisation: ∫ m φ² dx ≈ 1 (the slope terms of the consistent mass are small)
    assert np.trapezoid(M * first**2, x) == pytest.approx(1.0, rel=2e-3)


@settings(max_examples=10)
@given(panels())
def test_static_end_moments_give_uniform_curvature(panel: tj.Panel) -> None:
    ei = panel.youngs_modulus * panel.bending_inertia
    moment = 0.1 * ei / panel.length
    eta = tj.beam.FreeFreeBeam(panel, 20).static_tip_deflection(moment)
    # tips above the centre for a positive moment, η = M L²/(8EI)
    assert eta == pytest.approx(moment * panel.length**2 / (8 * ei), rel=1e-7)
    assert tj.beam.FreeFreeBeam(panel, 20).static_tip_deflection(-moment) < 0


def test_constant_moment_keeps_the_beam_at_rest(beam: tj.FreeFreeBeam) -> None:
    t = np.array([0.0, 100.0])
    r = beam.response(t, [400.0, 400.0], dt_out=1.0)
    exact = math.asin(2 * 400.0 * L**2 / (8 * EI) / L)
    np.testing.assert_allclose(r.theta_f, exact, rtol=1e-6)
    assert r.theta_f.size == 101


def test_step_moment_rings_at_the_first_frequency(beam: tj.FreeFreeBeam) -> None:
    t = np.array([0.0, 1.0, 1.001, 600.0])
    m = np.array([0.0, 0.0, 100.0, 100.0])
    r = beam.response(t, m, dt_out=0.25, damping_ratio=0.0)
    assert dominant_frequency(r.t, r.theta_f) == pytest.approx(
        continuous_frequency(4.730040745), abs=1.0 / 600.0
    )
    # undamped: the oscillation is about the static deflection
    assert r.eta.mean() == pytest.approx(100.0 * L**2 / (8 * EI), rel=0.01)


def test_damping_ratio_sets_the_decay(beam: tj.FreeFreeBeam) -> None:
    zeta = 0.01
    t = np.array([0.0, 0.001, 300.0])
    r = beam.response(t, [0.0, 100.0, 100.0], dt_out=0.05, damping_ratio=zeta)
    w1 = 2 * math.pi * beam.natural_frequencies(1)[0]
    static = 100.0 * L**2 / (8 * EI)
    dev = np.abs(r.eta - static)
    early = dev[(r.t > 20) & (r.t < 30)].max()
    late = dev[(r.t > 220) & (r.t < 230)].max()
    assert late / early == pytest.approx(math.exp(-zeta * w1 * 200.0), rel=0.05)


def test_bad_input_is_refused(beam: tj.FreeFreeBeam) -> None:
    for n in (0, 3, 101, 2000):
        with pytest.raises(ValueError, match="n_elements"):
            tj.beam.FreeFreeBeam(PAPER, n)
    with pytest.raises(TypeError, match="n_elements"):
        tj.beam.FreeFreeBeam(PAPER, True)
    with pytest.raises(ValueError, match="moment_t"):
        beam.response([0.0, 2.0, 1.0], [1.0, 2.0, 3.0])
    with pytest.raises(ValueError, match="moment"):
        beam.response([0.0, 1.0, 2.0], [1.0, math.nan, 3.0])
    with pytest.raises(ValueError, match="times/moments"):
        beam.response([0.0, 1.0], [1.0])
    with pytest.raises(ValueError, match="damping_ratio"):
        beam.response([0.0, 1.0], [1.0, 1.0], damping_ratio=-0.1)
    with pytest.raises(ValueError, match="n = 0"):
        beam.natural_frequencies(0)
    with pytest.raises(ValueError, match="dt_out"):
        tj.compare_with_beam(PAPER, GEO, dt_out=0.0)


@pytest.fixture(scope="module")
def comparisons() -> dict[str, tj.BeamComparison]:
    return {
        "table1": tj.compare_with_beam(PAPER, GEO),
        "frequency": tj.compare_with_beam(PAPER, GEO, criterion="frequency"),
        "scaled": tj.compare_with_beam(PAPER, GEO, criterion="frequency", scale_moment=True),
    }


def test_deflection_criterion_matches_angle_but_not_frequency(
    comparisons: dict[str, tj.BeamComparison],
) -> None:
    c = comparisons["table1"]
    assert c.hinge_stiffness == 4438.0
    assert c.rmse_deg < 0.3
    # paper: the jitter frequency is about 12% off f_n with the deflection criterion
    assert -0.15 < c.frequency_mismatch < -0.10
    assert c.beam_frequency == pytest.approx(c.natural_frequency, rel=2e-3)
    assert c.hinge_frequency == pytest.approx(c.hinge_natural_frequency, rel=1e-2)


def test_frequency_criterion_matches_frequency_but_not_angle(
    comparisons: dict[str, tj.BeamComparison],
) -> None:
    c = comparisons["frequency"]
    assert c.hinge_stiffness == pytest.approx(5.21 * EI / L, rel=2e-3)
    assert abs(c.frequency_mismatch) < 0.01
    assert c.rmse_deg == pytest.approx(0.93, abs=0.15)  # paper: 0.93° RMSE
    s = comparisons["scaled"]
    assert s.moment_scale == pytest.approx(5.21 / 4, rel=2e-3)
    assert abs(s.frequency_mismatch) < 0.01 and s.rmse_deg < 0.3


def test_beam_command_writes_figures_and_summary(tmp_path: object) -> None:
    out = str(tmp_path)
    assert cli.main(["beam", "--out", out, "--no-calibrate"]) == 0
    with open(f"{out}/beam_summary.json") as fh:
        summary = json.load(fh)
    for name in FIGURES.values():
        with open(f"{out}/{name}", "rb") as fh:
            assert fh.read(8) == b"\x89PNG\r\n\x1a\n"
    assert set(summary["cases"]) == {"deflection", "frequency", "frequency_scaled"}
    assert summary["beam"]["convergence"][-1]["relative_error"] < 1e-3
    with open(f"{out}/beam_report.md") as fh:
        report = fh.read()
    assert "0.93°" in report and "about 12%" in report
    # The distributed-panel section: its numbers, table rows and figure.
    assert "## Hinge model vs coupled distributed panel" in report
    dist = summary["distributed"]
    assert [r["where"] for r in dist["critical_damping"]] == ["1 au", "perihelion", "aphelion"]
    with open(dist["figure"], "rb") as fh:
        assert fh.read(8) == b"\x89PNG\r\n\x1a\n"


def test_default_damping_matches_the_hinge_decay_rate() -> None:
    # ζ ω₁ = c_d/(2 I_B): equal to the hinge's ζ with the frequency-criterion K_el
    k_freq = tj.hinge_stiffness(PAPER, "frequency")
    expected = PAPER.damping / (2 * math.sqrt(k_freq * PAPER.hinge_inertia))
    assert tj.beam.default_damping_ratio(PAPER) == pytest.approx(expected, rel=1e-9)
    assert tj.beam.default_damping_ratio(PAPER.replace(damping=0.0)) == 0.0


def test_report_functions_live_in_reports_only() -> None:
    """The report half of the beam comparison lives in thermojitter.reports.beam; the API module
    thermojitter.beam neither offers those names nor imports the reports."""
    import thermojitter.beam as beam
    from thermojitter.reports import beam as reports

    for name in (
        "beam_comparison_figures",
        "beam_report_markdown",
        "calibration_note",
        "frequency_convergence",
        "write_beam_comparison",
    ):
        assert callable(getattr(reports, name))
        assert not hasattr(beam, name)
    source = Path(beam.__file__).read_text(encoding="utf-8")
    assert "thermojitter.reports" not in source
