"""The distributed panel against closed forms, the beam comparator and its own linearisation."""

from __future__ import annotations

import math

import numpy as np
import pytest

import thermojitter as tj
from conftest import ENTRY, GEO, PAPER
from thermojitter.distributed import distributed_convergence

EI = PAPER.youngs_modulus * PAPER.bending_inertia
L = PAPER.length
M = PAPER.mass_per_length

# Roots of cos x cosh x = 1 (free–free) and cos x cosh x = −1 (cantilever), to 16 digits: the
# 4-digit values 4.7300 and 1.8751 are themselves 1.7e-5 and 4e-5 off in (βL)².
BETA_FREE = 4.730040744862704
BETA_CANTILEVER = 1.875104068711961


def closed_form_hz(beta_l: float) -> float:
    return beta_l**2 * math.sqrt(EI / (M * L**4)) / (2 * math.pi)


@pytest.mark.parametrize(
    ("support", "beta_l"), [("free-free", BETA_FREE), ("cantilever", BETA_CANTILEVER)]
)
def test_first_frequency_matches_the_continuous_beam(support: str, beta_l: float) -> None:
    f1 = tj.distributed_frequencies(PAPER, support=support)[0]  # type: ignore[arg-type]
    assert f1 == pytest.approx(closed_form_hz(beta_l), rel=1e-6)
    assert f1 == pytest.approx(
        closed_form_hz(4.7300 if support == "free-free" else 1.8751), rel=1e-4
    )


@pytest.mark.parametrize("support", ["free-free", "cantilever"])
def test_uniform_gradient_bends_to_constant_curvature(support: str) -> None:
    # Frozen coupling, Sun on the normal: every element has the same ΔT, hence the same M_T,
    # and the run starts at rest in the static shape: w'' = M_T/EI everywhere.
    sol = tj.simulate_distributed(
        PAPER,
        GEO,
        (0.0, 1.0),
        support=support,
        coupled=False,
        t_eval=[0.0],  # type: ignore[arg-type]
    )
    moment = sol.thermal_moment[0]
    assert np.ptp(moment) == 0.0
    kappa = moment[0] / EI
    w, slope, x = sol.deflection[0], sol.slope[0], sol.x_node
    if support == "free-free":
        centre = len(x) // 2
        rise = 0.5 * (w[0] + w[-1]) - w[centre]
        assert rise == pytest.approx(moment[0] * L**2 / (8 * EI), rel=1e-9)
        assert np.allclose(slope, kappa * (x - L / 2), rtol=0, atol=1e-9 * kappa * L)
        assert sol.theta_f[0] == pytest.approx(math.asin(2 * rise / L), rel=1e-12)
    else:
        assert w[0] == 0.0 and slope[0] == 0.0
        assert w[-1] == pytest.approx(moment[0] * L**2 / (2 * EI), rel=1e-9)
        assert np.allclose(slope, kappa * x, rtol=0, atol=1e-9 * kappa * L)
        assert sol.theta_f[0] == pytest.approx(math.asin(w[-1] / L), rel=1e-12)


def test_frozen_uniform_panel_follows_the_beam_comparator() -> None:
    # Same M_T(t) on the comparator (40 elements): every element identical, θ_f equal up to the
    # dynamics of the symmetric modes the default reduction keeps quasi-static (engine test
    # frozen_uniform_panel_is_the_beam_comparator keeps them all and holds 1e-6 rad over the
    # whole passage): here the binding's side of it, across the shadow entry.
    span = (ENTRY - 300.0, ENTRY + 900.0)
    times = np.unique(np.append(np.arange(span[0], span[1], 0.1), ENTRY))
    sol = tj.simulate_distributed(
        PAPER, GEO, span, coupled=False, modes=16, t_eval=times, rtol=1e-10, atol=1e-12
    )
    assert np.all(np.ptp(sol.T_front, axis=1) == 0.0)
    assert np.all(np.ptp(sol.T_back, axis=1) == 0.0)
    beam = tj.beam.FreeFreeBeam(PAPER, 40)
    resp = beam.response(sol.t, sol.thermal_moment[:, 0], rtol=1e-10, atol=1e-12)
    assert np.max(np.abs(sol.theta_f - resp.theta_f)) < 1e-6
    assert np.max(np.abs(sol.theta_f)) > 0.08


def test_result_shapes_and_xarray() -> None:
    sol = tj.simulate_distributed(PAPER, GEO, (ENTRY - 10.0, ENTRY + 10.0), elements=8, dt_out=1.0)
    nt = sol.t.size
    assert sol.T_front.shape == sol.T_back.shape == sol.thermal_moment.shape == (nt, 8)
    assert sol.deflection.shape == sol.slope.shape == (nt, 9)
    assert sol.sunlit[0] == 1.0 and sol.sunlit[-1] == 0.0
    ds = sol.to_xarray()
    assert ds["T_front"].dims == ("time", "x")
    assert ds["deflection"].dims == ("time", "x_node")
    assert ds["theta_f"].dims == ("time",)
    assert np.allclose(ds["x"].values, (np.arange(8) + 0.5) * L / 8)


def test_penumbra_and_year_orbit_run() -> None:
    orbit = tj.Orbit.geo_year("2026-03-20")
    enter, leave = orbit.shadow_intervals(0.0, orbit.period)[0]
    sol = tj.simulate_distributed(PAPER, orbit, (enter - 60.0, leave + 60.0), dt_out=5.0)
    assert np.any((sol.sunlit > 0.0) & (sol.sunlit < 1.0))  # inside the penumbra
    assert np.all(np.isfinite(sol.theta_f))


@pytest.mark.parametrize(
    ("setting", "value"),
    [("elements", 1), ("elements", 0), ("elements", -3), ("modes", 0), ("modes", 9)],
)
def test_bad_counts_name_the_setting(setting: str, value: int) -> None:
    kw = {"elements": 4, setting: value}
    with pytest.raises(ValueError, match=setting):
        tj.distributed_flutter(PAPER, **kw)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match=setting):
        tj.simulate_distributed(PAPER, GEO, (0.0, 1.0), **kw)  # type: ignore[arg-type]


def test_bad_support_and_types() -> None:
    with pytest.raises(ValueError, match="support"):
        tj.distributed_flutter(PAPER, support="pinned")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="sun_angle"):
        tj.distributed_flutter(PAPER, support="cantilever", sun_angle=2.0)
    with pytest.raises(TypeError, match="elements"):
        tj.distributed_flutter(PAPER, elements=4.0)  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="coupled"):
        tj.simulate_distributed(PAPER, GEO, (0.0, 1.0), coupled=1)  # type: ignore[arg-type]
    # layers >= 3 is the N-node conduction model per element (thermal::model); 0 is refused.
    with pytest.raises(ValueError, match="layers"):
        tj.distributed_flutter(PAPER, elements=4, layers=0)
    with pytest.raises(ValueError, match="y0"):
        tj.simulate_distributed(PAPER, GEO, (0.0, 1.0), elements=4, y0=np.ones(3))


def test_critical_damping_separates_growth_from_decay() -> None:
    fl = tj.distributed_flutter(PAPER)
    zeta = fl.critical_damping_ratio
    assert zeta > 0.0
    # The hinge-equivalent c_d maps ζ back with the same 2 I_B ω₁ as the default ratio.
    defaults = tj.distributed_defaults(PAPER)
    assert fl.critical_damping / PAPER.damping == pytest.approx(zeta / defaults["damping_ratio"])
    above = tj.distributed_flutter(PAPER, damping_ratio=1.01 * zeta)
    below = tj.distributed_flutter(PAPER, damping_ratio=0.99 * zeta)
    assert above.stable and not below.stable
    first = below.oscillatory_modes[0]
    assert first.structural_mode == 0
    assert first.frequency_hz == pytest.approx(closed_form_hz(BETA_FREE), rel=1e-3)


def test_eclipse_response_converges_with_the_mesh() -> None:
    rows, order = distributed_convergence(
        PAPER, GEO, vary="elements", values=(10, 20, 40), t_span=(ENTRY - 300, ENTRY + 900)
    )
    assert rows[0].max_change > rows[1].max_change > 0.0
    assert order > 2.5


def test_report_tables_are_consistent() -> None:
    from thermojitter.distributed_report import cantilever_table, critical_damping_table

    rows = critical_damping_table(PAPER)
    by = {r["where"]: r for r in rows}
    # More sunlight, a larger gradient and a stronger pump: c_d* grows with the flux, in every
    # model, and the flux scale is the orbit model's 1/r² at perihelion and aphelion.
    assert by["perihelion"]["flux"] == pytest.approx(1 / (1 - 0.0167) ** 2, rel=1e-4)
    assert by["aphelion"]["flux"] == pytest.approx(1 / (1 + 0.0167) ** 2, rel=1e-4)
    for key in ("hinge_deflection", "hinge_frequency", "distributed"):
        assert by["aphelion"][key] < by["1 au"][key] < by["perihelion"][key]
    zeta = tj.distributed_defaults(PAPER)["damping_ratio"]
    for r in cantilever_table(PAPER, (-30.0, 0.0, 30.0)):
        assert r["stable"] == (r["critical_damping_ratio"] < zeta)
        assert r["stable"] == (r["growth_rate"] < 0.0)


@pytest.mark.parametrize(
    "orbit",
    [tj.Orbit.leo(), tj.Orbit.leo(shadow="penumbra"), tj.Orbit.sunlit()],
    ids=["leo", "leo-penumbra", "sunlit"],
)
def test_every_orbit_runs(orbit: tj.Orbit) -> None:
    # One orbit of each kind on a coarse mesh: finite fields, and in permanent sunlight the
    # panel stays at its equilibrium (θ_f constant to integration accuracy).
    sol = tj.simulate_distributed(
        PAPER, orbit, (0.0, min(orbit.period, 6000.0)), elements=6, dt_out=10.0
    )
    assert np.all(np.isfinite(sol.theta_f)) and np.all(np.isfinite(sol.T_front))
    if not orbit.shadow_intervals(0.0, orbit.period):
        assert np.ptp(sol.theta_f) < 1e-9
    else:
        assert sol.sunlit.min() == 0.0 and np.ptp(sol.theta_f) > 1e-3
