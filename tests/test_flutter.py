"""Flutter analysis: Jacobian, growth rate against integration, critical damping, stability map,
and the closed-form linear analysis of paper Sec. 4.2."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import solve_ivp

import thermojitter as tj
from conftest import PAPER
from thermojitter import reference as ref

SUNLIT = tj.Orbit.sunlit()


def measured_growth(
    panel: tj.Panel, model: str, t_end: float, kick: float = 1e-7, t_skip: float = 600.0
) -> tuple[float, float]:
    """Growth rate (1/s) and frequency (Hz) of θ − θ_eq measured by integrating in permanent
    sunlight from the equilibrium with a small kick: a line through log(peak) against time."""
    eq = tj.steady_state(panel)
    sol = tj.simulate(
        panel,
        SUNLIT,
        (0.0, t_end),
        model=model,
        y0=(eq.T_front, eq.T_back, eq.theta + kick, 0.0),
        dt_out=0.2,
        rtol=1e-10,
        atol=1e-13,
    )
    x = sol.theta - eq.theta
    inner = (x[1:-1] > x[:-2]) & (x[1:-1] >= x[2:]) & (x[1:-1] > 0)
    idx = np.nonzero(inner)[0] + 1
    # refine each peak with a parabola through the three samples around it
    a, b, c = x[idx - 1], x[idx], x[idx + 1]
    shift = 0.5 * (a - c) / (a - 2 * b + c)
    t_peak = sol.t[idx] + shift * 0.2
    peak = b - 0.25 * (a - c) * shift
    keep = t_peak > t_skip
    rate, _ = np.polyfit(t_peak[keep], np.log(peak[keep]), 1)
    freq = 1.0 / np.mean(np.diff(t_peak[keep]))
    return float(rate), float(freq)


@pytest.mark.parametrize("model", ["nonlinear", "linear"])
@pytest.mark.parametrize("coupled", [True, False])
@pytest.mark.parametrize("flux", [1.0, 1.034])
def test_jacobian_matches_reference_finite_differences(model: str, coupled: bool, flux: float):
    r = tj.flutter(PAPER, model, coupled=coupled, flux=flux)
    eq = r.equilibrium
    y = np.array([eq.T_front, eq.T_back, eq.theta, 0.0])
    fd = np.empty((4, 4))
    for j in range(4):
        h = 1e-6 * max(abs(y[j]), 1e-3)
        yp, ym = y.copy(), y.copy()
        yp[j] += h
        ym[j] -= h
        fd[:, j] = (
            ref.rhs_coupled(0.0, yp, PAPER, flux, model, coupled)
            - ref.rhs_coupled(0.0, ym, PAPER, flux, model, coupled)
        ) / (2 * h)
    # the equilibrium is a fixed point of the oracle's right-hand side
    assert np.max(np.abs(ref.rhs_coupled(0.0, y, PAPER, flux, model, coupled)[:2])) < 1e-9
    scale = np.max(np.abs(fd), axis=0)
    assert np.all(np.abs(fd - r.jacobian) <= 1e-6 * scale + 1e-14)
    assert np.allclose(np.sort_complex(np.linalg.eigvals(fd)), np.sort_complex(r.eigenvalues))


def test_growth_rate_at_zero_damping_matches_sunlit_integration():
    p = PAPER.replace(damping=0.0)
    r = tj.flutter(p)
    assert r.growth_rate > 0 and not r.stable
    t_end = 11.0 / r.growth_rate + 600.0  # more than 10 e-foldings after the thermal transient
    rate, freq = measured_growth(p, "nonlinear", t_end)
    print(f"growth rate: eigen {r.growth_rate:.6e} 1/s, integrated {rate:.6e} 1/s")
    assert rate == pytest.approx(r.growth_rate, rel=0.01)
    assert freq == pytest.approx(r.frequency_hz, rel=0.002)


def test_critical_damping_separates_decay_from_growth():
    r = tj.flutter(PAPER)
    cd = r.critical_damping
    assert 1.0 < cd < PAPER.damping  # the paper's c_d = 3 is stable
    t_end = 3.0 * 86400.0
    rates = {}
    for factor in (0.95, 1.05):
        p = PAPER.replace(damping=factor * cd)
        rates[factor], _ = measured_growth(p, "nonlinear", t_end, kick=1e-5)
        predicted = tj.flutter(p).growth_rate
        # over three days the amplitude changes by e^(±1.9): clearly growing or decaying
        assert rates[factor] * t_end == pytest.approx(predicted * t_end, abs=0.05)
    assert rates[0.95] > 0 > rates[1.05]


def test_linear_and_nonlinear_analyses_agree():
    p = PAPER.replace(damping=0.0)
    nl, lin = tj.flutter(p, "nonlinear"), tj.flutter(p, "linear")
    assert nl.equilibrium == lin.equilibrium
    assert lin.growth_rate == pytest.approx(nl.growth_rate, rel=0.01)
    # the non-linear inertia 1 + 3 sin²θ* lowers the frequency by about 1.1 % at θ* ≈ 5°
    ratio = nl.frequency_hz / lin.frequency_hz
    assert ratio == pytest.approx(
        1.0 / math.sqrt(1.0 + 3.0 * math.sin(nl.equilibrium.theta) ** 2), rel=2e-3
    )
    assert lin.critical_damping == pytest.approx(nl.critical_damping, rel=0.03)
    # linear hinge: the oscillatory pair sits near ±i ω_n
    assert lin.frequency_hz == pytest.approx(tj.natural_frequency(p), rel=0.01)
    # frozen projected area: no pumping, undamped neutral oscillation
    frozen = tj.flutter(p, coupled=False)
    assert abs(frozen.growth_rate) < 1e-12 and frozen.critical_damping == 0.0


def test_growth_rate_of_linear_model_matches_integration():
    p = PAPER.replace(damping=0.0)
    r = tj.flutter(p, "linear")
    rate, _ = measured_growth(p, "linear", 11.0 / r.growth_rate + 600.0)
    assert rate == pytest.approx(r.growth_rate, rel=0.01)


def test_flux_over_the_year_moves_the_critical_damping():
    year = tj.Orbit.geo_year("2026-01-01")
    days = np.arange(0.0, 366.0)
    flux = year.flux_scale(days * 86400.0)
    peri, aph = float(flux.max()), float(flux.min())
    c_peri = tj.flutter(PAPER, flux=peri).critical_damping
    c_aph = tj.flutter(PAPER, flux=aph).critical_damping
    c_mean = tj.flutter(PAPER).critical_damping
    # more sunlight: a larger equilibrium angle, more pumping
    assert c_aph < c_mean < c_peri
    # the pumping is ∝ p sin θ* ∝ flux² to first order: ±6.7 % for ±3.3 % flux
    assert c_peri / c_aph == pytest.approx((peri / aph) ** 2, rel=0.02)
    with pytest.raises(ValueError, match="flux"):
        tj.flutter(PAPER, flux=0.0)
    # the flux for a date, through the orbit
    july = tj.flutter(PAPER, orbit=tj.Orbit.geo_year("2026-07-05T12:00"))
    assert july.flux == pytest.approx(aph, rel=1e-5)
    assert july.critical_damping == pytest.approx(c_aph, rel=1e-4)
    # a damping between the two: stable around aphelion, flutter around perihelion
    mid = PAPER.replace(damping=0.5 * (c_aph + c_peri))
    assert tj.flutter(mid, orbit=year, t=185 * 86400.0).stable
    assert not tj.flutter(mid, orbit=year, t=3 * 86400.0).stable
    with pytest.raises(ValueError, match="not both"):
        tj.flutter(PAPER, flux=1.0, orbit=year)


# ----------------------------------------------------------------------------- stability map


def test_stability_map_matches_point_by_point_analysis():
    xs, ys = [0.0, 1.5, 2.2, 4.0], [10.0, 25.0, 40.0]
    m = tj.stability_map(PAPER, x=("damping", xs), y=("conductance", ys), model="linear")
    assert m.growth_rate.shape == (3, 4)
    for i, k in enumerate(ys):
        for j, cd in enumerate(xs):
            r = tj.flutter(PAPER.replace(damping=cd, conductance=k), "linear")
            assert m.growth_rate[i, j] == r.growth_rate
            assert m.frequency_hz[i, j] == r.frequency_hz
    assert np.array_equal(m.stable, m.growth_rate < 0)
    again = tj.stability_map(PAPER, x=("damping", xs), y=("conductance", ys), model="linear")
    assert np.array_equal(again.growth_rate, m.growth_rate)


def test_stability_map_any_two_fields_and_bad_names():
    m = tj.stability_map(PAPER, x=("length", [40.0, 50.0]), y=("absorptivity", [0.5, 0.8]))
    r = tj.flutter(PAPER.replace(length=40.0, absorptivity=0.8))
    assert m.growth_rate[1, 0] == r.growth_rate
    with pytest.raises(ValueError, match="lenght"):
        tj.stability_map(PAPER, x=("lenght", [1.0]), y=("damping", [1.0]))
    with pytest.raises(ValueError, match="dampin"):
        tj.stability_map(PAPER, x=("length", [1.0]), y=("dampin", [1.0]))
    with pytest.raises(ValueError, match="differ"):
        tj.stability_map(PAPER, x=("damping", [1.0]), y=("damping", [2.0]))
    with pytest.raises(ValueError, match="conductance"):
        tj.stability_map(PAPER, x=("damping", [1.0]), y=("conductance", [-5.0]))
    with pytest.raises(ValueError, match="finite"):
        tj.stability_map(PAPER, x=("damping", [np.nan]), y=("conductance", [5.0]))


# ------------------------------------------------------------ closed-form linear analysis (4.2)

EQUAL = PAPER.replace(emissivity_front=0.55, emissivity_back=0.55)


def fit_cos(t: np.ndarray, x: np.ndarray, omega: float) -> tuple[float, float, float]:
    """Least-squares x ≈ c + A cos(ω t − lag): returns (c, A, lag)."""
    basis = np.column_stack([np.ones_like(t), np.cos(omega * t), np.sin(omega * t)])
    c, a, b = np.linalg.lstsq(basis, x, rcond=None)[0]
    return float(c), float(math.hypot(a, b)), float(math.atan2(b, a))


@pytest.mark.parametrize("omega_factor", [1.0, 0.05])
def test_closed_form_response_matches_scalar_integration(omega_factor: float):
    lr = tj.linear_thermal_response(EQUAL)
    omega = omega_factor * lr.omega_n
    lr = tj.linear_thermal_response(EQUAL, omega=omega)
    phi = 0.3
    sol = solve_ivp(
        lambda t, y: [lr.p * math.cos(omega * t + phi) - lr.q * y[0]],
        (0.0, 1200.0),
        [2.0],
        rtol=1e-11,
        atol=1e-12,
        dense_output=True,
    )
    t = np.linspace(0.0, 1200.0, 6001)
    assert np.allclose(sol.sol(t)[0], lr.delta_T(t, phi=phi, delta_T0=2.0), atol=1e-8)
    late = t > 900.0
    _, amp, lag = fit_cos(t[late], sol.sol(t[late])[0], omega)
    assert amp == pytest.approx(lr.p / math.hypot(lr.q, omega), rel=1e-6)
    assert lag + phi == pytest.approx(lr.phase_lag, abs=1e-6)
    assert lr.resonant == (omega_factor == 1.0)


def test_closed_form_response_matches_the_two_layer_model():
    """The paper's linearisation against the non-linear two-layer equations (eq. 2) with equal
    emissivities, under a small sinusoidal modulation of the absorbed flux at ω_n."""
    lr = tj.linear_thermal_response(EQUAL)
    eq = tj.steady_state(EQUAL, coupled=False)
    delta = 1e-3
    omega = lr.omega_n

    def rhs(t: float, y: np.ndarray) -> list[float]:
        return list(ref.rhs_two_layer(t, y, EQUAL, 1.0 + delta * math.cos(omega * t), 1.0))

    sol = solve_ivp(
        rhs,
        (0.0, 500.0),
        [eq.T_front, eq.T_back],
        rtol=1e-11,
        atol=1e-10,
        dense_output=True,
        max_step=0.5,
    )
    t = np.linspace(300.0, 500.0, 4001)
    tf, tb = sol.sol(t)
    mean, amp, lag = fit_cos(t, tf - tb, omega)
    assert mean == pytest.approx(eq.T_front - eq.T_back, rel=1e-4)
    assert amp == pytest.approx(delta * lr.amplitude, rel=5e-3)
    assert lag == pytest.approx(lr.phase_lag, abs=5e-3)
    # the steady gradient of the linear equation, p/q, is the two-layer one
    assert lr.p / lr.q == pytest.approx(eq.T_front - eq.T_back, rel=0.02)


def test_lag_pumping_estimate_matches_eigen_analysis():
    """Sec. 4.2's resonance argument made quantitative: the lag of ΔT behind the swing acts as a
    negative damping s p sin θ*/(q² + ω_n²); it predicts the eigen-analysis' critical damping."""
    for panel in (EQUAL, PAPER):
        lr = tj.linear_thermal_response(panel)
        lin = tj.flutter(panel, "linear")
        assert lr.critical_damping_estimate == pytest.approx(lin.critical_damping, rel=0.02)
        zero = panel.replace(damping=0.0)
        assert tj.linear_thermal_response(zero).growth_rate_estimate == pytest.approx(
            tj.flutter(zero, "linear").growth_rate, rel=0.02
        )
    assert "resonant" in tj.linear_thermal_response(PAPER).describe()
    with pytest.raises(ValueError, match="T_star"):
        tj.linear_thermal_response(PAPER, T_star=-1.0)
    with pytest.raises(ValueError, match="omega"):
        tj.linear_thermal_response(PAPER, omega=math.nan)


def test_critical_damping_decides_the_jitter_between_eclipses_on_the_paper_orbit():
    """On the paper's orbit the eclipse kicks the panel; between shadow exit and the next entry
    the swing dies out just above the critical damping and grows just below it, at the rate of
    the eigen-analysis once the panel has warmed back up (the first hour or so after exit the
    temperatures are still recovering and the swing decays faster)."""
    geo = tj.Orbit.geo_equinox()
    cd = tj.flutter(PAPER).critical_damping
    (_, exit_), (entry, _) = geo.shadow_intervals(0.0, 2 * geo.period)
    early = np.arange(exit_ + 6000.0, exit_ + 6100.0, 0.1)
    late = np.arange(entry - 100.0, entry, 0.1)
    ratios = {}
    for factor in (0.95, 1.05):
        p = PAPER.replace(damping=factor * cd)
        sol = tj.simulate(p, geo, (0.0, entry), t_eval=np.concatenate([early, late]))
        # peak-to-peak swing in each window (free of any slow drift of the mean angle)
        a, b = sol.theta[: early.size], sol.theta[early.size :]
        ratios[factor] = float(np.ptp(b) / np.ptp(a))
        predicted = math.exp(tj.flutter(p).growth_rate * (late[-1] - early[-1]))
        assert ratios[factor] == pytest.approx(predicted, rel=0.02)
    assert ratios[0.95] > 1.3 and ratios[1.05] < 0.77
