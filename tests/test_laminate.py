"""Laminate layups and the N-node through-thickness model, through the public API.

The physics is checked against independent truth in the engine's own tests (the exact steady
profile, Carslaw & Jaeger's series, a E I ΔT/d, Timoshenko's bimetal); here: the contract of the
Python names, and that ``layers=2`` on a plain panel is the two-layer model.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import thermojitter as tj
from conftest import ENTRY, wing_layup
from thermojitter import materials as mat

GEO = tj.Orbit.geo_equinox()


def test_layer_errors_name_the_layer_and_field() -> None:
    with pytest.raises(ValueError, match="layer 'core': density"):
        tj.Layer(20e-3, 2.5, -50.0, 880.0, 0.0, 2.4e-5, name="core")
    with pytest.raises(TypeError, match="layer 'skin': thickness"):
        tj.Layer("thin", 1.0, 1600.0, 800.0, 1e11, 0.0, name="skin")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="emissivity_back"):
        tj.Laminate([mat.KAPTON.layer(1e-4)], 0.8, 1.5, 0.5)
    with pytest.raises(TypeError, match=r"layers\[1\]"):
        tj.Laminate([mat.KAPTON.layer(1e-4), "glue"], 0.8, 0.8, 0.5)  # type: ignore[list-item]
    # A core alone carries no bending stress: not a panel.
    with pytest.raises(ValueError, match="youngs_modulus"):
        tj.Laminate([mat.ALUMINIUM_HONEYCOMB.layer(0.02)], 0.8, 0.8, 0.5)


def test_every_material_names_its_source() -> None:
    assert len(mat.LIBRARY) >= 5
    for m in mat.LIBRARY.values():
        assert len(m.source) > 40, m.key
        assert m.key.upper() in (mat.__doc__ or "")
        assert m.layer(1e-3).name == m.key
    with pytest.raises(ValueError, match="not in the library"):
        mat.get("unobtainium")


def test_lamination_theory_of_a_sandwich() -> None:
    # Thin equal faces on a core without modulus: D = E t (c + t)²/2 + 2 E t³/12 (parallel axes).
    face, core = mat.CFRP_M55J_QI, mat.ALUMINIUM_HONEYCOMB
    t, c = 0.3e-3, 20e-3
    lam = tj.Laminate([face.layer(t), core.layer(c), face.layer(t)], 0.8, 0.8, 0.9)
    e = face.youngs_modulus
    assert lam.bending_stiffness == pytest.approx(
        e * t * (c + t) ** 2 / 2 + e * t**3 / 6, rel=1e-12
    )
    assert lam.neutral_axis == pytest.approx(c / 2 + t, rel=1e-12)
    rho_h = 2 * face.density * t + core.density * c
    assert lam.mass_per_area == pytest.approx(rho_h, rel=1e-12)
    assert lam.thermal_resistance == pytest.approx(
        2 * t / face.conductivity + c / core.conductivity
    )


def test_from_laminate_gives_the_layup_its_panel() -> None:
    lam = wing_layup()
    p = tj.Panel.from_laminate(lam, length=20.0)
    assert p.layup is lam
    assert p.youngs_modulus * p.bending_inertia == pytest.approx(lam.bending_stiffness, rel=1e-12)
    assert p.mass_per_length * p.specific_heat == pytest.approx(lam.heat_capacity, rel=1e-12)
    assert p.conductance == pytest.approx(1.0 / lam.thermal_resistance, rel=1e-12)
    assert p.hinge_stiffness == pytest.approx(4 * lam.bending_stiffness / 20.0, rel=1e-12)
    # Fields the layup decides cannot drift from it; the others can, and the layup stays.
    with pytest.raises(ValueError, match="conductance"):
        p.replace(conductance=10.0)
    assert p.replace(damping=0.5).layup is lam
    assert tj.Panel.paper().layup is None


def test_two_layers_on_a_plain_panel_are_the_two_layer_model() -> None:
    p = tj.Panel.paper()
    a = tj.simulate(p, GEO, (0.0, GEO.period), dt_out=60.0)
    b = tj.simulate(p, GEO, (0.0, GEO.period), dt_out=60.0, layers=2)
    # On the portable kernel the two do eq. 2's arithmetic alike and take the same steps. The
    # fused kernel rounds the two-layer model's multiply-adds once and not the nodal model's,
    # so their adaptive steps part and θ, θ̇ differ by about the integration's own error
    # (measured 1.1e-6 and 3.7e-5 of their largest values; the portable case is checked to the
    # bit by rust/src/layered.rs on every processor).
    fused = tj._core.cpu_info()["scalar_kernel"] == "fma"
    bounds = {"theta": 1e-5, "theta_dot": 5e-4} if fused else {}
    for name in ("T_front", "T_back", "theta", "theta_dot", "thermal_moment"):
        x, y = getattr(a, name), getattr(b, name)
        bound = bounds.get(name, 1e-9 if fused else 1e-10)
        assert np.max(np.abs(x - y)) <= bound * np.max(np.abs(x)), name
    assert b.T_nodes is not None and b.T_nodes.shape == (a.t.size, 2)
    fa, fb = tj.flutter(p.replace(damping=0.0)), tj.flutter(p.replace(damping=0.0), layers=2)
    assert fb.critical_damping == pytest.approx(fa.critical_damping, rel=1e-10)
    assert fb.growth_rate == pytest.approx(fa.growth_rate, rel=1e-10)
    sa = tj.simulate_orbits(p, GEO, 1, progress=False, method="rk45")
    sb = tj.simulate_orbits(p, GEO, 1, progress=False, layers=2, method="rk45")
    if fused:
        np.testing.assert_allclose(sb.exit_peak, sa.exit_peak, rtol=1e-6)
    else:
        assert np.array_equal(sa.exit_peak, sb.exit_peak)


def test_node_temperatures_over_time_and_depth() -> None:
    xr = pytest.importorskip("xarray")
    p = tj.Panel.from_laminate(wing_layup(), length=20.0)
    t0 = GEO.shadow_intervals(0.0, GEO.period)[0][1] - 100.0
    sol = tj.simulate(p, GEO, (t0, t0 + 400.0), layers=20, dt_out=5.0)
    assert sol.T_nodes is not None and sol.depth is not None
    assert sol.T_nodes.shape == (sol.t.size, 20)
    assert sol.depth[0] == 0.0 and sol.depth[-1] == pytest.approx(wing_layup().thickness)
    # Sunrise warms the front face first.
    after = sol.t > t0 + 100.0
    assert np.all(np.diff(sol.T_nodes[after, 0]) > 0.0)
    assert np.all(sol.T_front == sol.T_nodes[:, 0]) and np.all(sol.T_back == sol.T_nodes[:, -1])
    ds = sol.to_xarray()
    assert isinstance(ds, xr.Dataset)
    assert ds["T_nodes"].dims == ("t", "node") and ds["depth"].size == 20
    # Restart from the end state: same continuation.
    again = tj.simulate(p, GEO, (t0 + 400.0, t0 + 500.0), layers=20, y0=sol.y_end, dt_out=50.0)
    assert again.T_nodes is not None and again.T_nodes[0] == pytest.approx(
        sol.T_nodes[-1], rel=1e-12
    )


def test_node_temperatures_in_pandas_name_node_and_layer() -> None:
    pd = pytest.importorskip("pandas")
    p = tj.Panel.from_laminate(wing_layup(), length=20.0)
    sol = tj.simulate(p, GEO, (0.0, 600.0), layers=12, dt_out=60.0)
    frame = sol.to_pandas()
    assert isinstance(frame, pd.DataFrame)
    names = [c for c in frame.columns if c.startswith("T_node")]
    assert names == list(sol.node_columns) and len(names) == 12
    # Faces, interfaces and interior nodes each say where they are.
    assert names[0] == "T_node00 (front, kapton)"
    assert names[-1] == "T_node11 (back, cfrp_m55j_qi)"
    interfaces = [n for n in names if "|" in n]
    assert [n.split(" ", 1)[1] for n in interfaces] == [
        "(kapton|cfrp_m55j_qi)",
        "(cfrp_m55j_qi|aluminium_honeycomb)",
        "(aluminium_honeycomb|cfrp_m55j_qi)",
    ]
    assert sol.T_nodes is not None and sol.depth is not None
    for k, name in enumerate(names):
        assert np.array_equal(frame[name].to_numpy(), sol.T_nodes[:, k])
    assert frame.attrs["depth"] == pytest.approx(list(sol.depth), abs=0.0)
    # The interface nodes sit at the layers' boundaries.
    bounds = np.cumsum([layer.thickness for layer in wing_layup().layers])[:-1]
    at = [sol.depth[k] for k, n in enumerate(names) if "|" in n]
    assert at == pytest.approx(list(bounds), rel=1e-12)
    # Without layers=N: the plain columns only.
    plain = tj.simulate(p, GEO, (0.0, 600.0), dt_out=60.0).to_pandas()
    assert not [c for c in plain.columns if c.startswith("T_node")]


def test_layers_is_checked() -> None:
    p = tj.Panel.from_laminate(wing_layup(), length=20.0)
    with pytest.raises(ValueError, match="layers"):
        tj.simulate(p, GEO, (0.0, 10.0), layers=3)  # fewer nodes than the layup needs
    with pytest.raises(ValueError, match="layers"):
        tj.flutter(p, layers=1)
    with pytest.raises(TypeError, match="layers"):
        tj.simulate(p, GEO, (0.0, 10.0), layers=True)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="y0"):
        tj.simulate(p, GEO, (0.0, 10.0), layers=8, y0=[300.0] * 4)


def test_the_laminate_bends_with_a_uniform_temperature_like_a_bimetal() -> None:
    # Kapton on one side only: the sunlit equilibrium angle of the N-node model includes the
    # moment of the mean temperature above T_ref, which the two-layer equivalent leaves out.
    p = tj.Panel.from_laminate(wing_layup(), length=20.0)
    eq2 = tj.flutter(p).equilibrium
    eqn = tj.flutter(p, layers=20).equilibrium
    assert eqn.thermal_moment > eq2.thermal_moment > 0.0
    assert math.isclose(eqn.theta, eqn.thermal_moment / p.hinge_stiffness, rel_tol=1e-3)


def _sandwich() -> tj.Laminate:
    """CFRP face sheets on an aluminium honeycomb core, every value from the package's own
    materials: a layup whose net expansion coefficient is negative (the CFRP's)."""
    skin, core = mat.CFRP_M55J_QI, mat.ALUMINIUM_HONEYCOMB
    return tj.Laminate(
        [skin.layer(0.5e-3, "front"), core.layer(20e-3, "core"), skin.layer(0.5e-3, "back")],
        emissivity_front=0.8,
        emissivity_back=0.3,
        absorptivity=0.8,
    )


def test_cfrp_honeycomb_sandwich_from_the_library_runs() -> None:
    # Refused before: its equivalent expansion coefficient (−2.4e-8 1/K) is negative.
    panel = tj.Panel.from_laminate(_sandwich(), length=20.0)
    assert panel.expansion_coeff < 0.0
    sol = tj.simulate(panel, GEO, (0.0, 120.0), dt_out=10.0)
    assert np.all(np.isfinite(sol.theta)) and np.all(sol.theta < 0.0)  # bends towards the Sun
    nodes = tj.simulate(panel, GEO, (0.0, 120.0), dt_out=10.0, layers=8)
    assert np.all(np.isfinite(nodes.theta))
    result = tj.flutter(panel)
    assert math.isfinite(result.growth_rate) and result.critical_damping >= 0.0
    assert math.isfinite(tj.flutter(panel, layers=8).critical_damping)


@pytest.mark.parametrize("a", [-1e-6, -2.5e-5, -1e-3, 0.0, 1e-3])
def test_expansion_of_either_sign_is_accepted(a: float) -> None:
    assert tj.Panel.paper().replace(expansion_coeff=a).expansion_coeff == a
    assert tj.Layer(1e-3, 1.0, 1600.0, 800.0, 1e11, a).expansion_coeff == a


@pytest.mark.parametrize("a", [1.01e-3, -1.01e-3])
def test_expansion_beyond_any_solid_is_refused(a: float) -> None:
    with pytest.raises(tj.ParameterError, match="expansion_coeff") as info:
        tj.Panel.paper().replace(expansion_coeff=a)
    assert info.value.parameter == "expansion_coeff"


def test_a_panel_that_does_not_expand_bends_by_nothing() -> None:
    flat = tj.Panel.paper().replace(expansion_coeff=0.0)
    eq = tj.steady_state(flat)
    assert eq.theta == 0.0 and eq.thermal_moment == 0.0
    sol = tj.simulate(flat, GEO, (ENTRY - 60.0, ENTRY + 240.0), dt_out=10.0)
    assert np.all(sol.theta == 0.0) and np.all(sol.thermal_moment == 0.0)
    assert np.all(tj.simulate(flat, GEO, (0.0, 60.0), layers=6, dt_out=10.0).theta == 0.0)
    # The deflection criterion has no moment to match: its small-angle limit 4 E I / L, no 0/0.
    assert tj.hinge_stiffness(flat, "deflection") == tj.hinge_stiffness(
        flat, "deflection_small_angle"
    )
    # Nothing drives the hinge: no damping is needed against flutter.
    assert abs(tj.flutter(flat).critical_damping) < 1e-9


def test_a_symmetric_layup_of_zero_net_moment_bends_by_nothing() -> None:
    # Invar-like skins (a = 0) on a core: the layup decides a = 0, so θ stays at rest.
    skin = tj.Layer(0.5e-3, 10.0, 8000.0, 500.0, 1.4e11, 0.0, name="skin")
    core = mat.ALUMINIUM_HONEYCOMB.layer(20e-3, "core")
    lam = tj.Laminate([skin, core, skin], 0.8, 0.3, 0.8)
    panel = tj.Panel.from_laminate(lam, length=20.0)
    assert panel.expansion_coeff == 0.0
    assert tj.steady_state(panel).theta == 0.0
    assert np.all(tj.simulate(panel, GEO, (0.0, 60.0), dt_out=10.0, layers=7).theta == 0.0)


def test_negative_expansion_bends_the_other_way() -> None:
    # Steady static angle, closed form: θ = a E I (T_f − T_b) / (d K_el) with χ = 1. With the
    # area frozen (coupled=False) the temperatures do not depend on a; coupled, cos θ is even in
    # θ, so the mirrored state is the equilibrium too.
    warm = tj.Panel.paper()
    cold = warm.replace(expansion_coeff=-warm.expansion_coeff)
    for coupled in (False, True):
        up, down = tj.steady_state(warm, coupled=coupled), tj.steady_state(cold, coupled=coupled)
        assert up.theta > 0.0 > down.theta
        assert down.theta == pytest.approx(-up.theta, rel=1e-12)
        assert (down.T_front, down.T_back) == pytest.approx((up.T_front, up.T_back), rel=1e-12)
        p = cold
        closed = (
            p.expansion_coeff * p.youngs_modulus * p.bending_inertia
            * (down.T_front - down.T_back) / (p.thickness * p.hinge_stiffness)
        )  # fmt: skip
        assert down.theta == pytest.approx(closed, rel=1e-9)
    sol = tj.simulate(cold, GEO, (0.0, 60.0), dt_out=10.0)
    assert np.all(sol.theta < 0.0)
