"""The boom (thin-walled tube lit on one side) against the closed forms of the classical problem,
derived here from the equations, and against the independent reference."""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from scipy.optimize import minimize_scalar

import thermojitter as tj
from thermojitter import cli
from thermojitter import reference as ref
from thermojitter.scenario import load_scenario

SIGMA = 5.670374419e-8
GEO = tj.Orbit.geo_equinox()
ENTRY = GEO.period / 2 - GEO.eclipse_duration / 2


def bare_becu(**changes: float) -> tj.Boom:
    """A 30 m beryllium–copper STEM tube, 12.7 mm across, 51 µm wall, bare (α 0.5, ε 0.05)."""
    values = {"length": 30.0, "radius": 6.35e-3, "wall": 5.1e-5, **changes}
    return tj.Boom(**values)  # type: ignore[arg-type]


def closed_form_steady(b: tj.Boom) -> tuple[float, float, float]:
    """Frozen incidence: the mean balance α C sin ψ/π = ε σ T̄⁴ (the lit half's projected width
    2r over the circumference 2πr), the first harmonic's α C sin ψ/2 = (k h/r² + 4 σ T̄³ ε) T_m
    (the cos φ mode's conduction eigenvalue −1/r²), and the tip deflection of the uniform
    curvature a T_m/r, w(L) = a T_m L²/(2r)."""
    q = b.absorptivity * b.solar_constant * math.sin(b.solar_inclination)
    mean = (q / (math.pi * b.emissivity * SIGMA)) ** 0.25
    relax = b.conductivity * b.wall / b.radius**2 + 4 * SIGMA * mean**3 * b.emissivity
    circ = q / 2 / relax
    return mean, circ, b.expansion_coeff * circ / b.radius * b.length**2 / 2


@pytest.mark.parametrize("psi", [0.4, math.pi / 2, 2.5])
def test_steady_sunlit_state_is_the_closed_form(psi: float) -> None:
    b = bare_becu(solar_inclination=psi, tip_mass=0.3)
    eq = tj.steady_state(b, coupled=False)
    mean, circ, tip = closed_form_steady(b)
    assert eq.T_mean == pytest.approx(mean, rel=1e-12)
    assert eq.T_circ == pytest.approx(circ, rel=1e-12)
    assert eq.tip_deflection == pytest.approx(tip, rel=1e-9)
    # The thermal curvature a T_m / r bends the bare 30 m boom by a metre or so (the
    # gravity-gradient booms of the 1960s bent by feet), less as the Sun grazes it.
    assert 0.1 < tip < 5.0


def test_the_coupled_steady_state_solves_the_incidence() -> None:
    # Coupled, θ is the fixed point θ = θ_frozen · sin(ψ + θ)/sin ψ (T_m ∝ the absorbed flux).
    b = bare_becu(solar_inclination=0.3, length=60.0)
    frozen = tj.steady_state(b, coupled=False).theta
    theta = tj.steady_state(b).theta
    assert theta == pytest.approx(frozen * math.sin(0.3 + theta) / math.sin(0.3), rel=1e-9)
    assert theta > frozen  # leaning toward the Sun, bending away raises the heating


def boley_ratio(B: float) -> float:
    """Peak over static deflection of x'' + ω² x = ω² x_s (1 − e^{−t/τ}), x(0) = x'(0) = 0:
    x/x_s = 1 − (B² e^{−t/τ} + cos ωt + B sin ωt)/(1 + B²), B = ωτ (time in 1/ω units)."""

    def x(s: float) -> float:
        return 1 - (B**2 * math.exp(-s / B) + math.cos(s) + B * math.sin(s)) / (1 + B**2)

    grid = np.linspace(0.0, 12 * math.pi + 10 * B, 200_001)
    values = np.array([x(s) for s in grid])
    i = int(np.argmax(values))
    best = minimize_scalar(
        lambda s: -x(s), bounds=(grid[max(i - 1, 0)], grid[min(i + 1, grid.size - 1)]),
        method="bounded", options={"xatol": 1e-12},
    )  # fmt: skip
    return -float(best.fun)


def test_boley_ratio_limits() -> None:
    assert boley_ratio(1e-4) == pytest.approx(2.0, abs=1e-3)
    assert boley_ratio(1e3) == pytest.approx(1.0, abs=2e-3)


@pytest.mark.parametrize("B", [0.1, 0.3, 1.0, 3.0, 10.0, 20.0])
def test_boley_suddenly_heated_boom(B: float) -> None:
    """The engine's boom, undamped with its incidence frozen, lit suddenly from T_m = 0 at the
    steady mean temperature: T_m = T_s (1 − e^{−t/τ}) drives the hinge; its peak deflection over
    the static one is Boley's ratio."""
    base = bare_becu(length=10.0, absorptivity=0.05)  # a few degrees at most
    omega = base.derived["first_angular_frequency"]
    tau = B / omega
    # τ = ρ c h / (k h/r² + 4 σ T̄³ ε): the conductivity that gives it.
    mean, _, _ = closed_form_steady(base)
    radiative = 4 * SIGMA * mean**3 * base.emissivity
    k = (
        (base.density * base.specific_heat * base.wall / tau - radiative)
        * base.radius**2
        / base.wall
    )
    b = base.replace(conductivity=k)
    assert b.response_time_ratio == pytest.approx(B, rel=1e-9)
    static = closed_form_steady(b)[2] / b.length
    span = 12 * math.pi / omega + 10 * tau
    t = np.linspace(0.0, span, 40_001)
    sol = tj.simulate(
        b, GEO, (0.0, span), coupled=False, y0=(mean, 0.0, 0.0, 0.0), t_eval=t,
        rtol=1e-11, atol=1e-14, max_step=2 * math.pi / omega / 200,
    )  # fmt: skip
    assert np.all(sol.sunlit == 1.0)
    ratio = float(np.max(sol.theta)) / static
    assert ratio == pytest.approx(boley_ratio(B), abs=1e-3)


def routh_hurwitz_critical_ratio(jac: np.ndarray) -> float:
    """The damping ratio at the flutter boundary of the single-mode model, from its own
    linearisation's entries. State (T̄, T_m, θ, θ̇): T̄ feeds nothing back, so (T_m, θ, θ̇) is
    closed, with T_m' = −a T_m + g₁ θ and θ'' = g₂ T_m − ω² θ − r θ'. Its characteristic cubic
    λ³ + (a + r) λ² + (ω² + a r) λ + (a ω² − g₁ g₂) is Hurwitz iff every coefficient is positive
    and (a + r)(ω² + a r) > a ω² − g₁ g₂, i.e. a r² + (ω² + a²) r + g₁ g₂ > 0: the boundary is
    that quadratic's positive root, and ζ = r / (2ω)."""
    assert np.all(jac[0, 1:] == 0.0) or True  # T̄'s row may depend on θ: it is not fed back
    assert jac[1, 0] == 0.0 and jac[3, 0] == 0.0 and jac[2, 0] == 0.0
    a, g1 = -jac[1, 1], jac[1, 2]
    w2, g2 = -jac[3, 2], jac[3, 1]
    qa, qb, qc = a, w2 + a * a, g1 * g2
    r = (-qb + math.sqrt(qb * qb - 4 * qa * qc)) / (2 * qa)
    return r / (2 * math.sqrt(w2))


@pytest.mark.parametrize("psi", [1.8, 2.2, 2.7])
@pytest.mark.parametrize("length", [15.0, 30.0])
def test_flutter_boundary_is_the_routh_hurwitz_boundary(psi: float, length: float) -> None:
    b = bare_becu(solar_inclination=psi, length=length)
    res = tj.flutter(b)
    assert res.growth_rate > 0.0
    want = routh_hurwitz_critical_ratio(res.jacobian)
    assert res.critical_damping == pytest.approx(want, rel=1e-6)
    # Just above the boundary the boom is stable, just below it flutters.
    assert tj.flutter(b.replace(damping=want * 1.001)).growth_rate < 0.0
    assert tj.flutter(b.replace(damping=want * 0.999)).growth_rate > 0.0


def test_yu_orientation() -> None:
    """Undamped, the boom whose deflection lowers its heating flutters; the one whose
    deflection raises it does not. With the hot side convex (a > 0) the tube bends away from
    the Sun: leaning away from the Sun (ψ > 90°) that turns it toward grazing incidence, leaning
    toward the Sun (ψ < 90°) toward normal incidence. A negative expansion (CFRP) bends the other
    way and swaps them."""
    for psi, flutters in [(0.5, False), (1.2, False), (1.9, True), (2.6, True)]:
        assert (tj.flutter(bare_becu(solar_inclination=psi)).growth_rate > 0) == flutters
        shrinking = bare_becu(solar_inclination=psi, expansion_coeff=-1e-6)
        assert (tj.flutter(shrinking).growth_rate > 0) == (not flutters)
    # In time: from the same small kick, the amplitude grows in one and decays in the other.
    for psi, grows in [(1.2, False), (1.9, True)]:
        b = bare_becu(solar_inclination=psi, length=15.0)
        eq = tj.steady_state(b)
        period = 1 / b.first_frequency
        y0 = (eq.T_mean, eq.T_circ, eq.theta + 1e-4, 0.0)
        sol = tj.simulate(
            b, GEO, (0.0, 40 * period), y0=y0, dt_out=period / 50, rtol=1e-10, atol=1e-14
        )
        swing = np.abs(sol.theta - eq.theta)
        first, last = swing[: 5 * 50].max(), swing[-5 * 50 :].max()
        assert (last > first) == grows, (psi, first, last)


boom_params = st.fixed_dictionaries(
    {
        "length": st.floats(2.0, 40.0),
        "radius": st.floats(3e-3, 3e-2),
        "wall_ratio": st.floats(0.003, 0.05),
        "material": st.sampled_from(["beryllium_copper", "stainless_301", "cfrp_m55j_qi"]),
        "absorptivity": st.floats(0.05, 0.95),
        "emissivity": st.floats(0.03, 0.9),
        "emissivity_inner": st.floats(0.0, 1.0),
        "damping": st.floats(0.0, 0.05),
        "tip_mass": st.floats(0.0, 2.0),
        "solar_inclination": st.floats(0.3, 2.8),
        "conduction_scale": st.floats(0.2, 1.0),
    }
)


@settings(max_examples=10, deadline=None)
@given(params=boom_params, coupled=st.booleans())
@example(  # a 2 m CFRP tube: rings at nano-radians, where the absolute tolerance rules
    params={
        "length": 2.0, "radius": 0.0234375, "wall_ratio": 0.03125, "material": "cfrp_m55j_qi",
        "absorptivity": 0.5, "emissivity": 0.5, "emissivity_inner": 0.0, "damping": 0.0,
        "tip_mass": 0.0, "solar_inclination": 1.0, "conduction_scale": 1.0,
    },
    coupled=False,
)  # fmt: skip
def test_engine_transient_matches_the_reference(params: dict[str, object], coupled: bool) -> None:
    p = dict(params)
    p["wall"] = float(p.pop("wall_ratio")) * float(p["radius"])  # type: ignore[arg-type]
    b = tj.Boom(**p)  # type: ignore[arg-type]
    # Through the shadow entry from the sunlit steady state: the cooling transient, over at
    # most 20 periods of the boom after it (both integrators' phase errors grow with them).
    span = (
        ENTRY - min(300.0, 5.0 / b.first_frequency),
        ENTRY + min(900.0, 20.0 / b.first_frequency),
    )
    t = np.linspace(*span, 121)
    y0 = ref.tube_steady_state(b, coupled)
    got = tj.simulate(b, GEO, span, coupled=coupled, t_eval=t, y0=y0, rtol=1e-11, atol=1e-13)
    want = ref.simulate_tube(
        b, GEO, span, coupled=coupled, t_eval=t, y0=y0, rtol=1e-11, atol=1e-13,
        max_step=0.05 / b.first_frequency,
    )  # fmt: skip
    # Relative to each row's scale, plus the absolute tolerance both runs were given (atol per step,
    # over about a hundred steps): a stiff short tube rings at nano-radians, where atol dominates.
    for name, row in zip(want.names, want.y, strict=True):
        scale = float(np.max(np.abs(row)))
        assert np.max(np.abs(getattr(got, name) - row)) <= 1e-6 * scale + 100 * 1e-13, name


def test_reference_steady_state_agrees_with_the_engine() -> None:
    b = bare_becu(solar_inclination=1.0, tip_mass=1.5, emissivity_inner=0.5, damping=0.01)
    eng = tj.steady_state(b)
    want = ref.tube_steady_state(b, True)
    assert [eng.T_mean, eng.T_circ, eng.theta] == pytest.approx(list(want[:3]), rel=1e-9)
    hinge = ref.tube_hinge(b)
    assert b.derived["hinge_inertia"] == pytest.approx(hinge["inertia"], rel=1e-10)
    assert b.derived["hinge_stiffness"] == pytest.approx(hinge["stiffness"], rel=1e-10)


def test_a_boom_is_refused_by_name() -> None:
    with pytest.raises(tj.ParameterError) as e:
        bare_becu(wall=2e-3)
    assert e.value.parameter == "wall"
    with pytest.raises(tj.ParameterError) as e:
        bare_becu(solar_inclination=-0.1)
    assert e.value.parameter == "solar_inclination"
    with pytest.raises(tj.ParameterError):
        tj.Boom(30.0, 6e-3, 5e-5, material="unobtainium")
    with pytest.raises(tj.ParameterError) as e:
        tj.simulate(bare_becu(), GEO, (0.0, 10.0), layers=3)
    assert e.value.parameter == "layers"


EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
HISTORICAL = sorted(EXAMPLES.glob("boom_*.toml"))


def test_the_historical_booms_are_shipped() -> None:
    names = {p.stem for p in HISTORICAL}
    assert {"boom_1963_22a_bare", "boom_1963_22a_silver", "boom_hst_bistem", "boom_cfrp"} <= names
    for path in HISTORICAL:
        text = path.read_text()
        # Every scenario says where its values come from.
        assert "estimate" in text or "data sheet" in text, path.name
        assert isinstance(load_scenario(path).panel, tj.Boom)


@pytest.mark.parametrize("path", HISTORICAL, ids=[p.stem for p in HISTORICAL])
def test_a_historical_boom_runs_in_under_a_minute(path: Path, tmp_path: Path) -> None:
    started = time.perf_counter()
    out = tmp_path / "out"
    assert cli.main(["run", str(path), "--out", str(out), "--no-progress", "--no-plots"]) == 0
    assert time.perf_counter() - started < 60.0
    frame = pd.read_csv(out / "timeseries.csv")
    names = [c.split(" [")[0] for c in frame.columns]  # headers carry their units
    assert names[:3] == ["t", "T_mean", "T_circ"]
    assert np.all(np.isfinite(frame[frame.columns[names.index("theta")]]))


def test_silver_plating_cures_the_gravity_gradient_boom() -> None:
    """1963-22A's fix: the silver-plated boom absorbs less, so its sunlit bending and its
    terminator jitter are several times smaller than the bare boom's."""
    bare = load_scenario(EXAMPLES / "boom_1963_22a_bare.toml")
    silver = load_scenario(EXAMPLES / "boom_1963_22a_silver.toml")
    runs = [
        tj.simulate_orbits(s.panel, s.orbit, 2, method="rk45", progress=False)
        for s in (bare, silver)
    ]
    assert runs[1].theta_eq[0] < 0.3 * runs[0].theta_eq[0]
    assert runs[1].jitter_peak[1] < 0.3 * runs[0].jitter_peak[1]


def test_a_boom_runs_whole_orbits_and_the_hybrid_says_it_fell_back() -> None:
    b = bare_becu(length=15.0, damping=0.01)
    orbit = tj.Orbit.leo()
    rk45 = tj.simulate_orbits(b, orbit, 2, method="rk45", progress=False)
    hybrid = tj.simulate_orbits(b, orbit, 2, method="hybrid", progress=False)
    assert rk45.fallback is None and hybrid.fallback is not None
    assert hybrid.propagation["t_linear"] == 0.0
    assert hybrid.propagation["t_fallback"] == pytest.approx(2 * orbit.period)
    for name in ("theta_max", "jitter_peak", "jitter_rms"):
        assert np.array_equal(getattr(rk45, name), getattr(hybrid, name)), name
    # The summaries agree with a sampled transient of the same orbits.
    sol = tj.simulate(
        b, orbit, (0.0, 2 * orbit.period), dt_out=0.5, max_step=1 / b.first_frequency / 40
    )
    assert rk45.theta_max.max() == pytest.approx(sol.theta.max(), rel=1e-4)


def test_the_stability_map_is_the_flutter_analysis_point_by_point() -> None:
    # Weakly absorbing: the steady deflection stays small, so that ψ + θ stays on ψ's side of
    # 90° (a boom bent past normal incidence changes the feedback's sign).
    b = bare_becu(length=15.0, absorptivity=0.05)
    psi = np.radians([60.0, 120.0, 150.0])
    ratios = [0.5, 2.0, 8.0]
    m = tj.boom_stability_map(b, psi, ratios)
    assert m.growth_rate.shape == (3, 3) == m.critical_damping.shape
    # Leaning toward the Sun needs no damping; leaning away it does, at every ratio.
    assert np.all(m.critical_damping[0] == 0.0) and np.all(m.critical_damping[1:] > 0.0)
    assert np.all(m.stable[0]) and not np.any(m.stable[1:])
    # Each point is the boom with the conductivity that gives B = ω₁ τ.
    for i, j in [(1, 0), (2, 2)]:
        mean, _, _ = closed_form_steady(b.replace(solar_inclination=psi[i]))
        tau = ratios[j] / b.derived["first_angular_frequency"]
        radiative = 4 * SIGMA * mean**3 * b.emissivity
        k = (b.density * b.specific_heat * b.wall / tau - radiative) * b.radius**2 / b.wall
        point = b.replace(solar_inclination=psi[i], conductivity=k)
        res = tj.flutter(point)
        assert m.growth_rate[i, j] == pytest.approx(res.growth_rate, rel=1e-9)
        assert m.critical_damping[i, j] == pytest.approx(res.critical_damping, rel=1e-9)
    with pytest.raises(tj.ParameterError) as e:
        tj.boom_stability_map(b, psi, [1e6])
    assert e.value.parameter == "ratio"
