"""Heat from the Earth (infrared and albedo) and the panel's attitude: the view factor against a
quadrature of its integral, the engine's fluxes and transients against the reference's loads
(written independently), the quasi-steady two-node balance at the sub-solar point, the night side,
GEO's small share, and the hybrid propagator's handling of a varying sunlit forcing."""

from __future__ import annotations

import math
import warnings
from typing import Any

import hypothesis.strategies as st
import numpy as np
import pytest
from hypothesis import given, settings
from scipy.integrate import dblquad
from scipy.optimize import fsolve

import thermojitter as tj
from thermojitter import reference as ref
from thermojitter.orbit import EARTH_RADIUS

SIGMA = ref.STEFAN_BOLTZMANN


def view_factor_by_quadrature(lam: float, ratio: float) -> float:
    """F = (1/π) ∫ max(cos, 0) dΩ over the Earth's disk of directions (half-angle asin(1/H))."""
    rho = math.asin(1.0 / ratio)

    def integrand(azimuth: float, polar: float) -> float:
        # A direction `polar` from the nadir; the normal tilted λ from the nadir.
        c = math.sin(polar) * math.cos(azimuth) * math.sin(lam) + math.cos(polar) * math.cos(lam)
        return max(c, 0.0) * math.sin(polar)

    value, _ = dblquad(integrand, 0.0, rho, 0.0, 2.0 * math.pi, epsabs=1e-13, epsrel=1e-11)
    return value / math.pi


@pytest.mark.parametrize("ratio", [1.05, 1.0847, 2.0, 6.6107])
def test_view_factor_is_its_integral_in_full_and_partial_view(ratio: float) -> None:
    rho = math.asin(1.0 / ratio)
    angles = [0.0, 0.5 * math.pi - rho - 0.2, 0.5 * math.pi - 0.3 * rho, 0.5 * math.pi]
    angles += [0.5 * math.pi + 0.7 * rho, 0.5 * math.pi + rho + 0.1, math.pi]
    for lam in angles:
        got = float(ref.earth_view_factor(lam, ratio)[0])
        assert got == pytest.approx(view_factor_by_quadrature(lam, ratio), abs=1e-10), lam
    # Full view: cos λ / H².
    assert (
        float(ref.earth_view_factor(0.3, ratio)[0])
        == pytest.approx(math.cos(0.3) / ratio**2, rel=1e-14)
        or 0.3 > 0.5 * math.pi - rho
    )


ATTITUDES = st.one_of(
    st.just(tj.Attitude.sun_pointing()),
    st.just(tj.Attitude.nadir()),
    st.floats(-1.5, 1.5).map(tj.Attitude.sun_tracking),
    st.tuples(*[st.floats(-1.0, 1.0)] * 3)
    .filter(lambda v: sum(c * c for c in v) > 0.01)
    .map(tj.Attitude.inertial),
)


def drawn_orbit(draw: st.DrawFn, shadow: str) -> tj.Orbit:
    return tj.Orbit.circular(
        draw(st.floats(300e3, 36_000e3)),
        draw(st.floats(0.05, math.pi - 0.05)),
        draw(st.floats(-math.pi, math.pi)),
        draw(st.floats(0.0, 365.0)),
        shadow=shadow,  # type: ignore[arg-type]
        albedo=draw(st.floats(0.0, 1.0)),
        earth_ir=draw(st.floats(0.0, 400.0)),
    ).replace(phase0=draw(st.floats(-math.pi, math.pi)))


@st.composite
def orbits(draw: st.DrawFn, shadow: str = "conical") -> tj.Orbit:
    return drawn_orbit(draw, shadow)


PANELS = st.builds(
    tj.Panel,
    emissivity_front=st.floats(0.2, 0.95),
    emissivity_back=st.floats(0.2, 0.95),
    absorptivity=st.floats(0.2, 0.95),
    absorptivity_back=st.floats(0.2, 0.95),
    conductance=st.floats(5.0, 80.0),
)


@settings(max_examples=25)
@given(orbit=orbits(), attitude=ATTITUDES)
def test_fluxes_on_each_face_are_the_references(orbit: tj.Orbit, attitude: tj.Attitude) -> None:
    panel = tj.Panel.paper()
    span = (0.0, 0.6 * orbit.period)
    sol = tj.simulate(
        panel, orbit, span, attitude=attitude, dt_out=span[1] / 40, coupled=False, rtol=1e-4
    )
    want = ref.face_fluxes(orbit, attitude, sol.t, sol.sunlit, panel.solar_constant)
    front = want["sun_front"] + want["albedo_front"] + want["ir_front"]
    back = want["sun_back"] + want["albedo_back"] + want["ir_back"]
    assert sol.flux_front is not None and sol.flux_back is not None
    np.testing.assert_allclose(sol.flux_front, front, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(sol.flux_back, back, rtol=1e-12, atol=1e-9)


@settings(max_examples=6)
@given(
    data=st.data(),
    attitude=ATTITUDES,
    panel=PANELS,
    coupled=st.booleans(),
)
def test_transients_under_earth_heating_are_the_references(
    data: st.DataObject, attitude: tj.Attitude, panel: tj.Panel, coupled: bool
) -> None:
    orbit = data.draw(orbits(shadow="none"))
    span = (0.0, 400.0)
    t_eval = np.linspace(*span, 41)
    sol = tj.simulate(
        panel, orbit, span, attitude=attitude, coupled=coupled, t_eval=t_eval, rtol=1e-11,
        atol=1e-12, max_step=0.5,
    )  # fmt: skip
    want = ref.simulate(
        panel, orbit, span, attitude=attitude, coupled=coupled, t_eval=t_eval, rtol=1e-11,
        atol=1e-12, max_step=0.5,
    )  # fmt: skip
    # The default starts: the equilibria under the loads at t = 0, solved apart.
    np.testing.assert_allclose([sol.T_front[0], sol.T_back[0]], want.y[:2, 0], rtol=1e-10)
    assert sol.theta[0] == pytest.approx(want.theta[0], rel=1e-7, abs=1e-11)
    np.testing.assert_allclose(sol.T_front, want.T_front, rtol=1e-10)
    np.testing.assert_allclose(sol.T_back, want.T_back, rtol=1e-10)
    np.testing.assert_allclose(sol.theta, want.theta, rtol=1e-8, atol=1e-11)


def test_quasi_steady_faces_at_the_sub_solar_point_are_the_two_node_balance() -> None:
    """Sunlit, β = 0, at the sub-solar point, projected area frozen: the front faces the Sun and
    nothing of the Earth, the back faces the nadir with view factor 1/H²."""
    panel = tj.Panel.paper().replace(absorptivity_back=0.6, emissivity_back=0.5)
    orbit = tj.Orbit.circular(540e3, 0.0, 0.0, shadow="cylindrical").replace(
        season=False, eccentric_sun=False
    )
    assert orbit.beta(0.0)[0] == 0.0
    sol = tj.simulate(panel, orbit, (0.0, 10.0), coupled=False, dt_out=10.0)
    view = (EARTH_RADIUS / orbit.radius) ** 2
    c, a = panel.solar_constant, orbit.albedo
    front = panel.absorptivity * c
    back = panel.absorptivity_back * a * c * view + panel.emissivity_back * orbit.earth_ir * view

    def balance(x: np.ndarray) -> list[float]:
        tf, tb = x
        conducted = panel.conductance * (tf - tb)
        return [
            front - conducted - SIGMA * panel.emissivity_front * tf**4,
            back + conducted - SIGMA * panel.emissivity_back * tb**4,
        ]

    tf, tb = fsolve(balance, [350.0, 340.0], xtol=1e-13)
    assert sol.T_front[0] == pytest.approx(tf, rel=1e-12)
    assert sol.T_back[0] == pytest.approx(tb, rel=1e-12)
    assert sol.flux_back is not None
    assert sol.flux_back[0] == pytest.approx((a * c + orbit.earth_ir) * view, rel=1e-12)
    # The Earth's loads lower the gradient against the Sun alone.
    alone = tj.simulate(
        panel, orbit.replace(albedo=0.0, earth_ir=0.0), (0.0, 10.0), coupled=False, dt_out=10.0
    )
    assert sol.T_back[0] - alone.T_back[0] > 10.0


def test_the_face_over_the_night_side_takes_infrared_and_no_albedo() -> None:
    orbit = tj.Orbit.circular(540e3, 0.0, 0.0, shadow="cylindrical").replace(
        season=False, eccentric_sun=False
    )
    view = (EARTH_RADIUS / orbit.radius) ** 2
    midnight = 0.5 * orbit.period
    t = np.array([0.0, midnight])
    for attitude in (tj.Attitude.sun_pointing(), tj.Attitude.nadir()):
        sol = tj.simulate(tj.Panel.paper(), orbit, (0.0, orbit.period), t_eval=t, attitude=attitude)
        assert sol.flux_front is not None and sol.flux_back is not None
        assert sol.sunlit[1] == 0.0
        # At midnight the Earth-facing face is the front for both: the anti-Sun is the nadir.
        assert sol.flux_front[1] == pytest.approx(orbit.earth_ir * view, rel=1e-12)
        assert sol.flux_back[1] == 0.0
    # The same face at noon over the lit Earth takes the albedo too.
    assert sol.flux_front[0] == pytest.approx(
        (orbit.albedo * 1361.0 + orbit.earth_ir) * view, rel=1e-12
    )


def test_at_geo_the_earth_changes_the_equilibrium_angle_by_less_than_a_percent() -> None:
    """Over the sunlit arcs of a GEO orbit the mean angle moves by about 0.5 %; the most is at
    the sub-solar point, where the back faces the lit Earth (view factor 1/H² = 0.023, 15 W/m²
    reaching it): about 2.3 % there with the albedo of the sub-satellite point."""
    geo = tj.Orbit.geo_equinox()
    heated = geo.replace(albedo=tj.orbit.EARTH_ALBEDO, earth_ir=tj.orbit.EARTH_IR)
    panel = tj.Panel.paper()
    bare = tj.simulate(panel, geo, (0.0, geo.period), dt_out=60.0)
    warm = tj.simulate(panel, heated, (0.0, geo.period), dt_out=60.0)
    lit = bare.sunlit == 1.0
    np.testing.assert_array_equal(lit, warm.sunlit == 1.0)
    mean_change = abs(warm.theta[lit].mean() - bare.theta[lit].mean()) / bare.theta[lit].mean()
    assert 1e-3 < mean_change < 0.01, mean_change
    noon_change = abs(warm.theta[0] - bare.theta[0]) / bare.theta[0]
    assert mean_change < noon_change < 0.03, noon_change
    # At LEO it is no longer small.
    leo = tj.Orbit.leo(540e3)
    low = tj.simulate(panel, leo.replace(albedo=0.3, earth_ir=237.0), (0.0, 1.0), dt_out=1.0)
    alone = tj.simulate(panel, leo, (0.0, 1.0), dt_out=1.0)
    assert abs(low.theta[0] - alone.theta[0]) > 0.5 * abs(alone.theta[0])


def test_the_hybrid_runs_earth_heating_on_a_low_orbit_on_slow_time_within_the_gate() -> None:
    from test_hybrid import assert_gate

    orbit = tj.Orbit.circular(540e3, math.radians(28.5), 0.4, "2026-06-01")
    n = 3
    full = tj.simulate_orbits(tj.Panel.paper(), orbit, n, method="rk45", orbits_per_call=n)
    with warnings.catch_warnings():
        warnings.simplefilter("error", tj.HybridFallbackWarning)
        hybrid = tj.simulate_orbits(tj.Panel.paper(), orbit, n, method="hybrid", orbits_per_call=n)
    assert "hybrid_fallback" not in hybrid.settings
    assert_gate(full, hybrid)
    p = hybrid.propagation
    assert p["t_linear"] == p["t_exponential"] == 0.0
    assert p["n_refused_orbits"] == 0
    # Slow time but for the penumbrae, integrated in full.
    assert p["t_slow"] + p["t_fallback"] == pytest.approx(n * orbit.period, rel=1e-12)
    assert 0.0 < p["t_fallback"] < 0.01 * n * orbit.period


def test_the_hybrid_runs_earth_heating_on_geo_in_full_and_says_so() -> None:
    from test_hybrid import assert_gate

    orbit = tj.Orbit.geo_year("2026-03-08").replace(albedo=0.3, earth_ir=237.0)
    n = 3
    full = tj.simulate_orbits(tj.Panel.paper(), orbit, n, method="rk45", orbits_per_call=n)
    with pytest.warns(tj.HybridFallbackWarning):
        hybrid = tj.simulate_orbits(tj.Panel.paper(), orbit, n, method="hybrid", orbits_per_call=n)
    assert "hybrid_fallback" in hybrid.settings
    assert_gate(full, hybrid)
    p = hybrid.propagation
    assert p["t_linear"] == p["t_exponential"] == p["t_slow"] == 0.0
    assert p["t_fallback"] == pytest.approx(n * orbit.period, rel=1e-12)
    # Without the Earth's heat the hybrid propagates by its linear arcs as before, with no
    # warning.
    with warnings.catch_warnings():
        warnings.simplefilter("error", tj.HybridFallbackWarning)
        bare = orbit.replace(albedo=0.0, earth_ir=0.0)
        plain = tj.simulate_orbits(tj.Panel.paper(), bare, 1, method="hybrid")
    assert plain.propagation["t_linear"] > 0.0


def test_models_that_take_the_front_sunlight_only_refuse_the_earths_heat() -> None:
    orbit = tj.Orbit.leo(540e3).replace(earth_ir=237.0)
    boom = tj.Boom(length=30.0, radius=6.35e-3, wall=5.1e-5)
    with pytest.raises(tj.ParameterError) as err:
        tj.simulate(boom, orbit, (0.0, 100.0))
    assert err.value.parameter == "orbit"
    with pytest.raises(tj.ParameterError) as err:
        tj.simulate(boom, tj.Orbit.leo(540e3), (0.0, 100.0), attitude=tj.Attitude.nadir())
    assert err.value.parameter == "attitude"


def test_the_n_node_hybrid_runs_earth_heating_in_full_and_says_so() -> None:
    # Its propagator takes the sunlit forcing as constant between eclipses: under the Earth's
    # loads it runs the orbits in full, the very run method="rk45" gives, and says so.
    orbit = tj.Orbit.leo(540e3).replace(earth_ir=237.0, albedo=0.3)
    kw: dict[str, Any] = {"layers": 4, "progress": False, "orbits_per_call": 2}
    full = tj.simulate_orbits(tj.Panel.paper(), orbit, 2, method="rk45", **kw)
    with pytest.warns(tj.HybridFallbackWarning):
        hybrid = tj.simulate_orbits(tj.Panel.paper(), orbit, 2, method="hybrid", **kw)
    assert "hybrid_fallback" in hybrid.settings
    for name, column in full.columns.items():
        np.testing.assert_array_equal(hybrid.columns[name], column, err_msg=name)
    p = hybrid.propagation
    assert p["t_linear"] == p["t_exponential"] == 0.0
    assert p["t_fallback"] == pytest.approx(2 * orbit.period, rel=1e-12)
    assert p["n_fallback_steps"] == full.n_steps


def test_attitudes_and_heat_loads_are_checked() -> None:
    with pytest.raises(tj.ParameterError):
        tj.Attitude.inertial((0.0, 0.0, 0.0))
    with pytest.raises(tj.ParameterError):
        tj.Attitude.inertial((1.0, 0.0))
    with pytest.raises(tj.ParameterError) as err:
        tj.simulate(
            tj.Panel.paper(), tj.Orbit.leo(), (0, 10), attitude=tj.Attitude.sun_tracking(28.5)
        )
    assert err.value.parameter == "attitude.offset"
    with pytest.raises(tj.ParameterError) as err:
        tj.Orbit.leo().replace(albedo=1.5)
    assert err.value.parameter == "albedo"
    with pytest.raises(tj.ParameterError) as err:
        tj.Orbit.leo().replace(earth_ir=-1.0)
    assert err.value.parameter == "earth_ir"
    with pytest.raises(tj.ParameterTypeError):
        tj.simulate(tj.Panel.paper(), tj.Orbit.leo(), (0, 10), attitude="nadir")  # type: ignore[arg-type]
    # The back's absorptivity follows the front's unless given.
    assert tj.Panel(absorptivity=0.4).absorptivity_back == 0.4
    assert tj.Panel(absorptivity=0.4, absorptivity_back=0.9).absorptivity_back == 0.9


def test_a_scenario_sets_the_earths_heat_and_the_attitude() -> None:
    from thermojitter.scenario import ScenarioError, parse_scenario

    data = {
        "orbit": {"preset": "leo", "albedo": 0.3, "earth_ir": 237.0, "inclination": 0.5},
        "attitude": {"kind": "sun_tracking", "offset": 0.2},
    }
    scenario = parse_scenario(data)
    assert scenario.attitude == tj.Attitude.sun_tracking(0.2)
    assert (scenario.orbit.albedo, scenario.orbit.earth_ir) == (0.3, 237.0)
    assert parse_scenario({}).attitude == tj.Attitude.sun_pointing()
    inertial = parse_scenario({"attitude": {"kind": "inertial", "normal": [0, 0, 2]}})
    assert inertial.attitude.normal == (0.0, 0.0, 2.0)
    for bad, key in [
        ({"kind": "nadir", "offset": 0.1}, "attitude.offset"),
        ({"kind": "inertial", "normal": [1, 0]}, "attitude.normal"),
        ({"kind": "sideways"}, "attitude.kind"),
        ({"roll": 0.1}, "roll"),
    ]:
        with pytest.raises(ScenarioError, match=key.replace(".", r"\.")):
            parse_scenario({"attitude": bad})


@pytest.mark.parametrize(
    "attitude", [None, tj.Attitude.sun_tracking(0.1), tj.Attitude.nadir()], ids=str
)
def test_flutter_at_a_point_of_the_orbit_takes_the_earths_loads(
    attitude: tj.Attitude | None,
) -> None:
    panel = tj.Panel.paper()
    orbit = tj.Orbit.circular(540e3, math.radians(28.5), 0.0, "2026-06-01")
    t = 100.0
    fl = tj.flutter(panel, orbit=orbit, t=t, attitude=attitude)
    used = attitude or tj.Attitude.sun_pointing()
    loads = ref.absorbed_loads(panel, orbit, used, t, 1.0)
    eq = ref.steady_state_loaded(panel, loads)
    assert fl.equilibrium.T_front == pytest.approx(eq[0], rel=1e-12)
    assert fl.equilibrium.T_back == pytest.approx(eq[1], rel=1e-12)
    assert fl.equilibrium.theta == pytest.approx(eq[2], rel=1e-9, abs=1e-14)
    # The Jacobian of the reference's equations, by central differences, and its spectrum.
    y = np.array([*eq, 0.0])
    jac = np.zeros((4, 4))
    for j in range(4):
        h = 1e-6 * max(abs(y[j]), 1e-3)
        up, down = y.copy(), y.copy()
        up[j] += h
        down[j] -= h
        jac[:, j] = (ref.rhs_loaded(up, panel, loads) - ref.rhs_loaded(down, panel, loads)) / (
            2 * h
        )
    eigenvalues = np.linalg.eigvals(jac)
    growth = float(np.max(eigenvalues.real))
    # Both Jacobians are finite differences: the real part is compared on the spectrum's scale
    # (a nadir panel's growth rate is 2e-5 of its eigenvalues' size).
    scale = float(np.max(np.abs(eigenvalues)))
    assert fl.growth_rate == pytest.approx(growth, rel=1e-5, abs=1e-8 * scale)
    # The Earth's heat on the back face lowers the gradient, and with it the critical damping.
    bare = tj.flutter(panel, orbit=orbit.replace(albedo=0.0, earth_ir=0.0), t=t, attitude=attitude)
    if used.kind != "nadir":
        assert fl.critical_damping < bare.critical_damping
