"""The Earth's heat and the attitude on the models beyond the two-layer plate: the N-node laminate
(two nodes against the two-layer model, N nodes against the reference's N-node plate), the
distributed panel (its hinge limit, its element loads) and the flutter analysis about the forcing
averaged over an orbit's sunlit arc (against a quasi-steady balance solved here)."""

from __future__ import annotations

import math

import hypothesis.strategies as st
import numpy as np
import pytest
from hypothesis import given, settings
from test_earth_heating import ATTITUDES, PANELS, orbits

import thermojitter as tj
from conftest import wing_layup
from thermojitter import reference as ref

SIGMA = ref.STEFAN_BOLTZMANN

# Runs tight enough that two integrations of the same equations agree far below the physics.
TIGHT = {"rtol": 1e-11, "atol": 1e-12, "max_step": 0.5}


@settings(max_examples=6)
@given(data=st.data(), attitude=ATTITUDES, panel=PANELS, coupled=st.booleans())
def test_two_nodes_under_the_earths_heat_are_the_two_layer_model(
    data: st.DataObject, attitude: tj.Attitude, panel: tj.Panel, coupled: bool
) -> None:
    orbit = data.draw(orbits())
    span = (0.0, 300.0)
    t_eval = np.linspace(*span, 31)
    # Drawn panels may bend beyond the hinge model's range: the two runs are compared all the same.
    run = {
        "attitude": attitude,
        "coupled": coupled,
        "t_eval": t_eval,
        "on_limit": "ignore",
        **TIGHT,
    }
    two = tj.simulate(panel, orbit, span, **run)  # type: ignore[arg-type]
    nodes = tj.simulate(panel, orbit, span, layers=2, **run)  # type: ignore[arg-type]
    # The same start (the two-layer model's steady state under the loads at t = 0) to the bit.
    assert (nodes.T_front[0], nodes.T_back[0]) == (two.T_front[0], two.T_back[0])
    assert nodes.theta[0] == two.theta[0]
    # The same equations: only the two integrations' rounding (and the fused multiply-adds of
    # the two-layer kernel) part them.
    np.testing.assert_allclose(nodes.T_front, two.T_front, rtol=1e-10)
    np.testing.assert_allclose(nodes.T_back, two.T_back, rtol=1e-10)
    scale = max(float(np.max(np.abs(two.theta))), 1e-6)
    np.testing.assert_allclose(nodes.theta, two.theta, rtol=0, atol=1e-7 * scale)
    assert nodes.flux_front is not None and two.flux_front is not None
    assert nodes.flux_back is not None and two.flux_back is not None
    np.testing.assert_array_equal(nodes.flux_front, two.flux_front)
    np.testing.assert_array_equal(nodes.flux_back, two.flux_back)


@settings(max_examples=6)
@given(data=st.data(), attitude=ATTITUDES, panel=PANELS, coupled=st.booleans())
def test_two_nodes_analyse_the_same_flutter_under_the_earths_heat(
    data: st.DataObject, attitude: tj.Attitude, panel: tj.Panel, coupled: bool
) -> None:
    orbit = data.draw(orbits())
    t = data.draw(st.floats(0.0, orbit.period))
    average = data.draw(st.booleans())
    run = {"orbit": orbit, "t": t, "attitude": attitude, "coupled": coupled}
    two = tj.flutter(panel, orbit_average=average, **run)  # type: ignore[arg-type]
    nodes = tj.flutter(panel, layers=2, orbit_average=average, **run)  # type: ignore[arg-type]
    assert nodes.equilibrium.T_front == two.equilibrium.T_front
    assert nodes.equilibrium.T_back == two.equilibrium.T_back
    assert nodes.equilibrium.theta == two.equilibrium.theta
    assert nodes.flux == two.flux
    # The two-layer Jacobian is by differences, the nodal one analytic.
    scale = float(np.max(np.abs(two.eigenvalues)))
    assert nodes.growth_rate == pytest.approx(two.growth_rate, rel=1e-5, abs=1e-8 * scale)
    # A growth rate off by ε moves c_d* by 2 I_B ε: the differences' 1e-8 of the spectrum is
    # 2e-8 of the hinge's critical damping sqrt(K_el I_B) (frozen, undamped: growth 0 exactly).
    inertia = panel.mass_per_length * (panel.length / 4) ** 3 * 2 / 3
    hinge_scale = math.sqrt(panel.hinge_stiffness * inertia)
    assert nodes.critical_damping == pytest.approx(
        two.critical_damping, rel=1e-4, abs=2e-8 * hinge_scale
    )


@settings(max_examples=6)
@given(
    data=st.data(),
    attitude=ATTITUDES,
    panel=PANELS,
    coupled=st.booleans(),
    nodes=st.integers(3, 4),
)
def test_n_nodes_under_the_earths_heat_are_the_references(
    data: st.DataObject, attitude: tj.Attitude, panel: tj.Panel, coupled: bool, nodes: int
) -> None:
    orbit = data.draw(orbits(shadow="none"))
    span = (0.0, 300.0)
    t_eval = np.linspace(*span, 31)
    sol = tj.simulate(
        panel, orbit, span, layers=nodes, attitude=attitude, coupled=coupled, t_eval=t_eval,
        on_limit="ignore", **TIGHT,  # type: ignore[arg-type]
    )  # fmt: skip
    want = ref.simulate_nodes(
        panel, orbit, span, nodes=nodes, attitude=attitude, coupled=coupled, t_eval=t_eval,
        **TIGHT,
    )  # fmt: skip
    assert sol.T_nodes is not None
    # The default starts: the equilibria under the loads at t = 0, solved apart.
    np.testing.assert_allclose(sol.T_nodes[0], want.y[:nodes, 0], rtol=1e-10)
    assert sol.theta[0] == pytest.approx(want.y[nodes, 0], rel=1e-8, abs=1e-12)
    np.testing.assert_allclose(sol.T_nodes, want.y[:nodes].T, rtol=1e-9)
    scale = max(float(np.max(np.abs(want.y[nodes]))), 1e-6)
    np.testing.assert_allclose(sol.theta, want.y[nodes], rtol=0, atol=1e-7 * scale)
    # The fluxes reaching each face are the reference's.
    fluxes = ref.face_fluxes(orbit, attitude, sol.t, sol.sunlit, panel.solar_constant)
    assert sol.flux_front is not None and sol.flux_back is not None
    front = fluxes["sun_front"] + fluxes["albedo_front"] + fluxes["ir_front"]
    back = fluxes["sun_back"] + fluxes["albedo_back"] + fluxes["ir_back"]
    np.testing.assert_allclose(sol.flux_front, front, rtol=1e-12, atol=1e-9)
    np.testing.assert_allclose(sol.flux_back, back, rtol=1e-12, atol=1e-9)


def test_n_nodes_flutter_at_a_point_of_the_orbit_is_the_references() -> None:
    panel = tj.Panel.paper().replace(damping=0.0)
    orbit = tj.Orbit.circular(540e3, math.radians(28.5), 0.0, "2026-06-01")
    attitude = tj.Attitude.sun_tracking(0.2)
    t, nodes = 300.0, 4
    fl = tj.flutter(panel, orbit=orbit, t=t, attitude=attitude, layers=nodes)
    loads = ref.absorbed_loads(panel, orbit, attitude, t, 1.0)
    eq = ref.steady_state_nodes_loaded(panel, nodes, loads)
    assert fl.equilibrium.T_front == pytest.approx(eq[0], rel=1e-11)
    assert fl.equilibrium.T_back == pytest.approx(eq[nodes - 1], rel=1e-11)
    assert fl.equilibrium.theta == pytest.approx(eq[nodes], rel=1e-9)
    y = np.append(eq, 0.0)
    jac = np.zeros((nodes + 2, nodes + 2))
    for j in range(nodes + 2):
        h = 1e-6 * max(abs(y[j]), 1e-3)
        up, down = y.copy(), y.copy()
        up[j] += h
        down[j] -= h
        jac[:, j] = (
            ref.rhs_nodes_loaded(up, panel, nodes, loads)
            - ref.rhs_nodes_loaded(down, panel, nodes, loads)
        ) / (2 * h)
    eigenvalues = np.linalg.eigvals(jac)
    scale = float(np.max(np.abs(eigenvalues)))
    assert fl.growth_rate == pytest.approx(
        float(np.max(eigenvalues.real)), rel=1e-5, abs=1e-8 * scale
    )


def test_the_laminate_takes_the_earths_heat_on_its_outer_nodes() -> None:
    """A 20-node laminate (its fast conduction modes quasi-static): the run starts at rest in the
    steady state under the loads, where every node's rate is zero; the back node is warmer with
    the Earth under it, and the orbit summaries run."""
    panel = tj.Panel.from_laminate(wing_layup(), length=20.0)
    orbit = tj.Orbit.circular(540e3, math.radians(28.5), 0.0, "2026-06-01", shadow="cylindrical")
    bare = orbit.replace(albedo=0.0, earth_ir=0.0)
    nadir = tj.Attitude.nadir()
    heated = tj.simulate(panel, orbit, (0.0, 120.0), layers=20, dt_out=10.0, attitude=nadir)
    alone = tj.simulate(panel, bare, (0.0, 120.0), layers=20, dt_out=10.0, attitude=nadir)
    assert heated.T_nodes is not None and alone.T_nodes is not None
    # At the start (noon) the front faces the lit Earth; the back faces the Sun.
    assert heated.T_nodes[0, 0] > alone.T_nodes[0, 0] + 1.0
    # At rest in the steady state: the first samples barely move.
    assert np.max(np.abs(heated.T_nodes[1] - heated.T_nodes[0])) < 0.05
    assert heated.flux_front is not None and heated.flux_front[0] > 200.0
    runs = tj.simulate_orbits(
        panel, orbit, 1, layers=20, method="rk45", attitude=nadir, progress=False
    )
    assert np.isfinite(runs.theta_eq).all()


def element_normals(
    orbit: tj.Orbit, attitude: tj.Attitude, t: float, slopes: np.ndarray
) -> np.ndarray:
    """Each element's front normal (n + ρ x̂)/√(1 + ρ²), from the reference's attitude normal n
    and the panel's length x̂ in the plane of n and the orbit normal."""
    n = ref.front_normals(orbit, attitude, [t])[0]
    h = ref.orbit_normals(orbit, [t])[0]
    along = h - (h @ n) * n
    along /= np.linalg.norm(along)
    tilted = n[None, :] + slopes[:, None] * along[None, :]
    return tilted / np.sqrt(1.0 + slopes**2)[:, None]


def two_node_balance(panel: tj.Panel, loads: tuple[float, float]) -> tuple[float, float]:
    """The faces of one element (eq. 2) at rest under absorbed loads (front, back), W/m²."""
    from scipy.optimize import fsolve

    def residual(x: np.ndarray) -> list[float]:
        tf, tb = x
        conducted = panel.conductance * (tf - tb)
        return [
            loads[0] - conducted - SIGMA * panel.emissivity_front * tf**4,
            loads[1] + conducted - SIGMA * panel.emissivity_back * tb**4,
        ]

    total = (loads[0] + loads[1]) / (SIGMA * (panel.emissivity_front + panel.emissivity_back))
    tf, tb = fsolve(residual, [total**0.25] * 2, xtol=1e-14)
    return float(tf), float(tb)


LEO_ATTITUDES = st.sampled_from(
    [tj.Attitude.nadir(), tj.Attitude.sun_tracking(0.3), tj.Attitude.inertial((0.3, -0.5, 0.8))]
)


@settings(max_examples=4)
@given(data=st.data(), attitude=LEO_ATTITUDES, panel=PANELS)
def test_every_element_of_the_distributed_panel_takes_the_loads_at_its_own_slope(
    data: st.DataObject, attitude: tj.Attitude, panel: tj.Panel
) -> None:
    """At the start (the equilibrium under the loads at t = 0) every element's faces are the
    two-node balance under the reference's loads on the element's own normal, turned from the
    attitude's by its chord slope: the two-way coupling, element by element."""
    from types import SimpleNamespace

    orbit = data.draw(orbits(shadow="none"))
    # Soft enough for the slopes to matter (a few degrees), within the model's range.
    panel = panel.replace(youngs_modulus=2e10)
    sol = tj.simulate_distributed(
        panel, orbit, (0.0, 1.0), attitude=attitude, elements=12, t_eval=[0.0], on_limit="ignore"
    )  # type: ignore[arg-type]
    w, x = sol.deflection[0], sol.x_node
    slopes = np.diff(w) / np.diff(x)
    assert np.ptp(slopes) > 1e-3
    for e, normal in enumerate(element_normals(orbit, attitude, 0.0, slopes)):
        element = SimpleNamespace(kind="inertial", normal=normal)
        loads = ref.absorbed_loads(panel, orbit, element, 0.0, 1.0)
        tf, tb = two_node_balance(panel, loads)
        assert sol.T_front[0, e] == pytest.approx(tf, rel=1e-9)
        assert sol.T_back[0, e] == pytest.approx(tb, rel=1e-9)
    fluxes = ref.face_fluxes(orbit, attitude, sol.t, sol.sunlit, panel.solar_constant)
    assert sol.flux_back is not None
    back = fluxes["sun_back"] + fluxes["albedo_back"] + fluxes["ir_back"]
    np.testing.assert_allclose(sol.flux_back, back, rtol=1e-12, atol=1e-9)


@settings(max_examples=3)
@given(data=st.data(), attitude=ATTITUDES)
def test_the_frozen_uniform_distributed_panel_under_the_earths_heat_is_the_flat_plate(
    data: st.DataObject, attitude: tj.Attitude
) -> None:
    """The limit of the beam comparator: with the coupling frozen every element takes the flat
    panel's loads, so each is the two-layer plate held flat under them (tj.simulate_thermal), and
    the panel bends as the free–free beam under their moment."""
    from conftest import PAPER

    orbit = data.draw(orbits())
    span = (0.0, 200.0)
    times = np.arange(span[0], span[1] + 0.05, 0.1)
    sol = tj.simulate_distributed(
        PAPER, orbit, span, coupled=False, modes=16, t_eval=times, rtol=1e-10, atol=1e-12,
        attitude=attitude,
    )  # fmt: skip
    assert np.all(np.ptp(sol.T_front, axis=1) == 0.0)
    assert np.all(np.ptp(sol.T_back, axis=1) == 0.0)
    plate = tj.simulate_thermal(
        PAPER, orbit, span, t_eval=times, rtol=1e-11, atol=1e-12, attitude=attitude
    )
    np.testing.assert_allclose(sol.T_front[:, 0], plate.T_front, rtol=1e-8)
    np.testing.assert_allclose(sol.T_back[:, 0], plate.T_back, rtol=1e-8)
    beam = tj.beam.FreeFreeBeam(PAPER, 40)
    resp = beam.response(sol.t, sol.thermal_moment[:, 0], rtol=1e-10, atol=1e-12)
    assert np.max(np.abs(sol.theta_f - resp.theta_f)) < 1e-6


def test_the_distributed_panel_refuses_a_sun_angle_with_an_attitude() -> None:
    orbit = tj.Orbit.leo(540e3)
    with pytest.raises(tj.ParameterError) as err:
        tj.simulate_distributed(
            tj.Panel.paper(), orbit, (0.0, 10.0), sun_angle=0.1, attitude=tj.Attitude.nadir()
        )
    assert err.value.parameter == "sun_angle"
    with pytest.raises(tj.ParameterError) as err:
        tj.simulate_distributed(
            tj.Panel.paper(), orbit.replace(earth_ir=237.0), (0.0, 10.0), sun_angle=0.1
        )
    assert err.value.parameter == "sun_angle"


def sunlit_arcs(orbit: tj.Orbit, t0: float) -> list[tuple[float, float]]:
    """The sunlit arcs of the orbit [t0, t0 + period] outside the reference's cylindrical shadow,
    each shadow boundary found where the satellite's distance from the shadow's axis is R_E."""
    from scipy.optimize import brentq

    t1 = t0 + orbit.period
    grid = np.linspace(t0, t1, 4001)
    lit = ref.cylinder_sunlit(orbit, grid)

    def off_axis(t: float) -> float:
        sat = orbit.radius * ref.satellite_vector(orbit, [t])[0]
        sun = ref.sun_vector(orbit, [t])[0]
        return float(np.linalg.norm(sat - (sat @ sun) * sun)) - orbit.earth_radius

    edges = [t0]
    for i in np.flatnonzero(lit[1:] != lit[:-1]):
        edges.append(brentq(off_axis, grid[i], grid[i + 1], xtol=1e-12, rtol=1e-15))
    edges.append(t1)
    return [
        (a, b) for a, b in zip(edges[:-1], edges[1:], strict=True)
        if ref.cylinder_sunlit(orbit, [0.5 * (a + b)])[0]
    ]  # fmt: skip


def averaged_loads(
    panel: tj.Panel, orbit: tj.Orbit, attitude: tj.Attitude, t0: float
) -> tuple[float, float]:
    """The reference's absorbed loads (front, back) averaged over the sunlit arcs: the trapezoid
    rule on 200,001 points an arc (its error, h² f''/12 and at a kink of the loads h² |Δf'|, is
    below 1e-10 of the mean)."""
    total = np.zeros(2)
    arcs = sunlit_arcs(orbit, t0)
    back_alpha = panel.absorptivity_back
    for a, b in arcs:
        t = np.linspace(a, b, 200_001)
        f = ref.face_fluxes(orbit, attitude, t, np.ones_like(t), panel.solar_constant)
        front = panel.absorptivity * (f["sun_front"] + f["albedo_front"])
        front += panel.emissivity_front * f["ir_front"]
        back = (
            back_alpha * (f["sun_back"] + f["albedo_back"]) + panel.emissivity_back * f["ir_back"]
        )
        total += [np.trapezoid(front, t), np.trapezoid(back, t)]
    duration = sum(b - a for a, b in arcs)
    return float(total[0] / duration), float(total[1] / duration)


@settings(max_examples=5)
@given(data=st.data(), attitude=ATTITUDES, panel=PANELS, layers=st.sampled_from([None, 3]))
def test_the_orbit_averaged_flutter_is_about_the_quasi_steady_balance_of_the_mean_forcing(
    data: st.DataObject, attitude: tj.Attitude, panel: tj.Panel, layers: int | None
) -> None:
    orbit = data.draw(orbits(shadow="cylindrical"))
    t = data.draw(st.floats(0.0, 2.0 * orbit.period))
    fl = tj.flutter(panel, orbit=orbit, t=t, attitude=attitude, orbit_average=True, layers=layers)
    loads = averaged_loads(panel, orbit, attitude, t)
    if layers is None:
        tf, tb, theta = ref.steady_state_loaded(panel, loads)
    else:
        eq = ref.steady_state_nodes_loaded(panel, layers, loads)
        tf, tb, theta = eq[0], eq[layers - 1], eq[layers]
    assert fl.equilibrium.T_front == pytest.approx(tf, rel=1e-8)
    assert fl.equilibrium.T_back == pytest.approx(tb, rel=1e-8)
    assert fl.equilibrium.theta == pytest.approx(theta, rel=1e-6, abs=1e-10)
    # It is not the equilibrium at the point t (unless the loads do not change along the arc).
    point = tj.flutter(panel, orbit=orbit, t=t, attitude=attitude, layers=layers)
    assert math.isfinite(point.growth_rate) and math.isfinite(fl.critical_damping)


def test_the_orbit_average_without_the_earths_heat_is_the_mean_sunlight() -> None:
    """A Sun-pointing plate in LEO without the Earth's heat: the mean of the Sun's distance
    scale over the sunlit arc, and the analysis at that flux; over one orbit it moves by less
    than 2e-4 (its 1/r² changes by that much a day)."""
    panel = tj.Panel.paper()
    orbit = tj.Orbit.circular(
        540e3, math.radians(28.5), 0.0, "2026-03-10", shadow="cylindrical", albedo=0.0,
        earth_ir=0.0,
    )  # fmt: skip
    t = 3.0 * orbit.period
    fl = tj.flutter(panel, orbit=orbit, t=t, orbit_average=True)
    arcs = sunlit_arcs(orbit, t)
    assert sum(b - a for a, b in arcs) < 0.7 * orbit.period
    mean = sum(
        float(np.trapezoid(ref.sun_distance_scale(orbit, g := np.linspace(a, b, 20001)), g))
        for a, b in arcs
    ) / sum(b - a for a, b in arcs)
    assert fl.flux == pytest.approx(mean, rel=1e-9)
    at_flux = tj.flutter(panel, flux=fl.flux)
    assert fl.equilibrium.theta == pytest.approx(at_flux.equilibrium.theta, rel=1e-12)
    # The analysis on an orbit differentiates numerically, the one at a flux analytically.
    assert fl.critical_damping == pytest.approx(at_flux.critical_damping, rel=1e-6)
    assert abs(fl.flux / float(orbit.flux_scale(t)[0]) - 1.0) < 2e-4
    with pytest.raises(tj.ParameterError) as err:
        tj.flutter(panel, orbit_average=True)
    assert err.value.parameter == "orbit_average"
