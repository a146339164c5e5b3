"""Bad input is refused at the boundary with an error that names the parameter."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import thermojitter as tj
from conftest import GEO, PAPER, wing_layup

BAD_POSITIVE = [math.nan, math.inf, -math.inf, 0.0, -1.0]


@pytest.mark.parametrize("name", tj.Panel.field_names())
@pytest.mark.parametrize("value", BAD_POSITIVE)
def test_panel_refuses_bad_values_naming_them(name: str, value: float) -> None:
    if name == "damping" and value == 0.0:
        assert PAPER.replace(damping=0.0).damping == 0.0
        return
    if name == "expansion_coeff" and value == 0.0:
        # A panel that does not expand is physical (see tests/test_laminate.py); -1 1/K is not.
        assert PAPER.replace(expansion_coeff=0.0).expansion_coeff == 0.0
        return
    with pytest.raises(ValueError, match=name):
        PAPER.replace(**{name: value})


@pytest.mark.parametrize("name", ["emissivity_front", "emissivity_back", "absorptivity"])
def test_optical_properties_are_fractions(name: str) -> None:
    with pytest.raises(ValueError, match=name):
        PAPER.replace(**{name: 1.01})
    assert getattr(PAPER.replace(**{name: 1.0}), name) == 1.0


def test_panel_is_immutable_and_typed() -> None:
    with pytest.raises(AttributeError):
        PAPER.damping = 1.0  # type: ignore[misc]
    with pytest.raises(TypeError, match="damping"):
        tj.Panel(damping="3")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="colour"):
        PAPER.replace(colour=1.0)
    assert PAPER.replace(damping=2).damping == 2.0


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"radius": 1e6}, "earth_radius"),
        ({"period": -1.0}, "period"),
        ({"period": math.nan}, "period"),
        ({"radius": math.inf}, "radius"),
        ({"phase0": math.nan}, "phase0"),
    ],
)
def test_orbit_refuses_bad_values(kwargs: dict[str, float], name: str) -> None:
    with pytest.raises(ValueError, match=name):
        tj.Orbit(**kwargs)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"rtol": 0.0}, "rtol"),
        ({"rtol": -1e-6}, "rtol"),
        ({"rtol": math.nan}, "rtol"),
        ({"atol": 0.0}, "atol"),
        ({"atol": math.inf}, "atol"),
        ({"method": "rk4"}, "dt"),
        ({"method": "rk4", "dt": 0.0}, "dt"),
        ({"method": "rk4", "dt": -0.1}, "dt"),
        ({"method": "euler"}, "method"),
        ({"model": "quadratic"}, "model"),
        ({"dt_out": 0.0}, "dt_out"),
        ({"dt_out": math.nan}, "dt_out"),
        ({"dt_out": 1e-6}, "dt_out"),
        ({"t_eval": [0.0, math.nan]}, "t_eval"),
        ({"t_eval": [5.0, 1.0]}, "t_eval"),
        ({"t_eval": [-1.0]}, "t_eval"),
        ({"t_eval": [1.0], "dt_out": 1.0}, "t_eval"),
        ({"y0": (300.0, 300.0, 0.0)}, "y0"),
        ({"y0": (300.0, math.nan, 0.0, 0.0)}, "y0"),
        ({"max_steps": 0}, "max_steps"),
        ({"max_step": 0.0}, "max_step"),
    ],
)
def test_simulate_refuses_bad_settings(kwargs: dict[str, object], name: str) -> None:
    with pytest.raises(ValueError, match=name):
        tj.simulate(PAPER, GEO, (0.0, 100.0), **kwargs)  # type: ignore[arg-type]


@pytest.mark.parametrize(
    "span", [(100.0, 0.0), (0.0, 0.0), (math.nan, 1.0), (0.0, math.inf), (0.0,), "ab"]
)
def test_simulate_refuses_bad_spans(span: object) -> None:
    # A string is the wrong type (TypeError), the rest wrong values (ValueError).
    with pytest.raises(TypeError if isinstance(span, str) else ValueError, match="t_span"):
        tj.simulate(PAPER, GEO, span)  # type: ignore[arg-type]


def test_wrong_types_are_type_errors() -> None:
    with pytest.raises(TypeError, match="panel"):
        tj.simulate({"damping": 1.0}, GEO, (0, 1))  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="orbit"):
        tj.simulate(PAPER, "GEO", (0, 1))  # type: ignore[arg-type]


def test_step_guard_is_an_integration_error() -> None:
    with pytest.raises(tj.IntegrationError, match="max_steps"):
        tj.simulate(PAPER, GEO, (0.0, GEO.period), max_steps=100)


def test_runaway_state_is_an_error_not_nan() -> None:
    # An absurd start (temperature 1e7 K) makes T⁴ overflow: an error, never a NaN result.
    with pytest.raises(tj.IntegrationError):
        tj.simulate(PAPER, GEO, (0.0, 100.0), y0=(1e80, 300.0, 0.0, 0.0), method="rk4", dt=1.0)


def test_hinge_inputs() -> None:
    with pytest.raises(ValueError, match="moment"):
        tj.simulate_hinge(PAPER, math.nan, (0.0, 1.0))
    with pytest.raises(ValueError, match="moment_t"):
        tj.simulate_hinge(PAPER, [1.0, 2.0], (0.0, 1.0), moment_t=[1.0, 0.0])
    with pytest.raises(ValueError, match="layers"):
        tj.simulate_thermal(PAPER, GEO, (0.0, 1.0), layers=3)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="criterion"):
        tj.hinge_stiffness(PAPER, "stiff")  # type: ignore[arg-type]


BAD = st.sampled_from([math.nan, math.inf, -math.inf, 0.0, -1.0, -1e300])


@settings(max_examples=200)
@given(
    name=st.sampled_from(list(tj.Panel.field_names())),
    value=BAD,
    target=st.sampled_from(["simulate", "steady", "thermal", "stiffness", "frequency"]),
)
def test_no_bad_value_crashes_anything(name: str, value: float, target: str) -> None:
    """Any bad parameter through any public entry point: a ValueError naming it, never a crash."""
    if name in ("damping", "expansion_coeff") and value == 0.0:
        return
    with pytest.raises(ValueError, match=name):
        panel = PAPER.replace(**{name: value})
        if target == "simulate":
            tj.simulate(panel, GEO, (0.0, 10.0))
        elif target == "steady":
            tj.steady_state(panel)
        elif target == "thermal":
            tj.simulate_thermal(panel, GEO, (0.0, 10.0))
        elif target == "stiffness":
            tj.hinge_stiffness(panel, "frequency")
        else:
            tj.natural_frequency(panel)


@settings(max_examples=100)
@given(
    rtol=st.one_of(BAD, st.floats(1e-12, 1e-3)),
    atol=st.one_of(BAD, st.floats(1e-14, 1e-3)),
    t1=st.one_of(BAD, st.floats(1.0, 500.0)),
)
def test_solver_settings_fuzz(rtol: float, atol: float, t1: float) -> None:
    ok = all(math.isfinite(v) and v > 0 for v in (rtol, atol, t1))
    if ok:
        sol = tj.simulate(PAPER, GEO, (0.0, t1), rtol=rtol, atol=atol, dt_out=50.0)
        assert np.all(np.isfinite(sol.y))
    else:
        with pytest.raises(ValueError):
            tj.simulate(PAPER, GEO, (0.0, t1), rtol=rtol, atol=atol, dt_out=50.0)


# --- start states: one check in the engine, shared by every function that takes y0 -----------

LOW = tj.Orbit(radius=7.0e6, period=5828.5)
_EQ = tj.steady_state(PAPER)
# The documented bound on a start's |θ̇|: (π/2) max(ω_n, c_d/I_B).
MAX_RATE = (
    0.5
    * math.pi
    * max(2.0 * math.pi * tj.natural_frequency(PAPER), PAPER.damping / PAPER.hinge_inertia)
)


def _runs_from(y0: tuple[float, ...]) -> list[object]:
    """Every public run that takes a two-layer start state (T_f, T_b, θ, θ̇), as callables."""
    return [
        lambda: tj.simulate(PAPER, GEO, (0.0, 10.0), y0=y0),
        lambda: tj.simulate(PAPER, GEO, (0.0, 10.0), y0=y0, method="rk4", dt=0.1),
        lambda: tj.simulate_orbits(PAPER, LOW, 1, y0=y0, progress=False),
        lambda: tj.simulate_orbits(PAPER, LOW, 1, y0=y0, method="rk45", progress=False),
    ]


@pytest.mark.parametrize(
    ("y0", "name"),
    [
        ((-10.0, _EQ.T_back, 0.0, 0.0), "y0[0]"),
        ((0.0, _EQ.T_back, 0.0, 0.0), "y0[0]"),
        ((_EQ.T_front, 0.0, 0.0, 0.0), "y0[1]"),
        ((_EQ.T_front, -5.0, 0.0, 0.0), "y0[1]"),
        ((_EQ.T_front, _EQ.T_back, 0.0, 1e6), "y0[3]"),
        ((_EQ.T_front, _EQ.T_back, 0.0, -1.01 * MAX_RATE), "y0[3]"),
    ],
)
def test_unphysical_start_states_are_refused_naming_the_component(
    y0: tuple[float, ...], name: str
) -> None:
    for run in _runs_from(y0):
        with pytest.raises(tj.ParameterError) as info:
            run()  # type: ignore[operator]
        assert info.value.parameter == name, str(info.value)


def test_every_function_taking_a_start_state_refuses_an_unphysical_one() -> None:
    cold = (-10.0, 290.0)
    checks = [
        (lambda: tj.simulate_thermal(PAPER, GEO, (0.0, 10.0), y0=cold), "y0[0]"),
        (lambda: tj.simulate_thermal(PAPER, GEO, (0.0, 10.0), layers=1, y0=(0.0,)), "y0[0]"),
        (lambda: tj.simulate_hinge(PAPER, 0.0, (0.0, 10.0), y0=(0.0, 1e6)), "y0[1]"),
        (lambda: tj.simulate(PAPER, GEO, (0.0, 10.0), layers=4, y0=(300.0,) * 3 + (0.0,) * 3),
         "y0[3]"),
        (lambda: tj.simulate(PAPER, GEO, (0.0, 10.0), layers=4,
                             y0=(300.0,) * 4 + (0.0, 1e6)), "y0[5]"),
        (lambda: tj.simulate_orbits(PAPER, LOW, 1, layers=4, method="rk45", progress=False,
                                    y0=(300.0,) * 4 + (0.0, 1e6)), "y0[5]"),
        (lambda: tj.simulate_distributed(PAPER, GEO, (0.0, 10.0), elements=4, modes=2,
                                         y0=[-1.0] * 8 + [0.0] * 4), "y0[0]"),
        (lambda: tj.calibrate(np.linspace(0.0, 60.0, 21), np.zeros(21), fit=("damping",),
                              y0=(0.0, 290.0, 0.0, 0.0)), "y0[0]"),
    ]  # fmt: skip
    for run, name in checks:
        with pytest.raises(tj.ParameterError) as info:
            run()
        assert info.value.parameter == name, str(info.value)


def test_a_start_rate_up_to_the_bound_runs() -> None:
    tj.simulate_hinge(PAPER, 0.0, (0.0, 1.0), y0=(0.0, 0.99 * MAX_RATE))
    with pytest.raises(tj.ParameterError, match=r"y0\[1\]"):
        tj.simulate_hinge(PAPER, 0.0, (0.0, 1.0), y0=(0.0, 1.01 * MAX_RATE))


# --- types: a bool is not a number, a string not a bool --------------------------------------


def test_strings_for_bools_and_bools_for_numbers_are_type_errors() -> None:
    fast = {"n": 2, "seed": 1, "progress": False, "threads": 1, "rtol": 1e-6, "atol": 1e-8}
    vary = {"damping": ("uniform", 1.0, 4.0)}
    cases = [
        ("coupled", lambda: tj.simulate(PAPER, GEO, (0.0, 10.0), layers=4, coupled="False")),
        ("coupled", lambda: tj.monte_carlo(PAPER, LOW, vary=vary, coupled="False", **fast)),
        ("window", lambda: tj.monte_carlo(PAPER, LOW, vary=vary, window=True, **fast)),
        ("threshold", lambda: tj.monte_carlo(PAPER, LOW, vary=vary, threshold=True, **fast)),
        ("truncate", lambda: tj.monte_carlo(PAPER, LOW, vary=vary, truncate="no", **fast)),
        ("grid.damping", lambda: tj.sweep(PAPER, LOW, {"damping": [True, False]}, threads=1,
                                          progress=False)),
        ("diff_step", lambda: tj.calibrate(np.linspace(0.0, 60.0, 21), np.zeros(21),
                                           diff_step=False)),
        ("y0[0]", lambda: tj.simulate(PAPER, GEO, (0.0, 10.0), y0=[True, 290.0, 0.0, 0.0])),
        ("t", lambda: tj.flutter(PAPER, t="noon")),
    ]  # fmt: skip
    for name, run in cases:
        with pytest.raises(TypeError, match=re.escape(name)):
            run()  # type: ignore[no-untyped-call]


# --- run-wide settings, paths, huge integers, blame -------------------------------------------


@pytest.mark.parametrize("layers", [10**7, 1, 10**400])
def test_study_wide_settings_are_refused_before_any_sample_runs(layers: int) -> None:
    vary = {"damping": ("uniform", 1.0, 4.0)}
    for run in (
        lambda: tj.monte_carlo(PAPER, LOW, vary=vary, n=2, seed=1, layers=layers, progress=False),
        lambda: tj.sweep(PAPER, LOW, {"damping": [1.0, 2.0]}, layers=layers, progress=False),
    ):
        with pytest.raises(tj.ParameterError) as info:
            run()
        assert info.value.parameter == "layers"


def test_a_laminate_study_with_too_few_nodes_for_its_layup_is_refused_up_front() -> None:
    panel = tj.Panel.from_laminate(wing_layup())  # four layers need five nodes
    with pytest.raises(tj.ParameterError) as info:
        tj.sweep(panel, LOW, {"damping": [1.0, 2.0]}, layers=3, progress=False)
    assert info.value.parameter == "layers"


def test_an_empty_checkpoint_path_is_refused(tmp_path: object) -> None:
    vary = {"damping": ("uniform", 1.0, 4.0)}
    for run in (
        lambda: tj.simulate_orbits(PAPER, LOW, 1, checkpoint="", progress=False),
        lambda: tj.monte_carlo(PAPER, LOW, vary=vary, n=2, seed=1, checkpoint="", progress=False),
    ):
        with pytest.raises(tj.ParameterError) as info:
            run()
        assert info.value.parameter == "checkpoint"
    with pytest.raises(TypeError, match="path"):
        tj.calibrate_from_csv(12)  # type: ignore[arg-type]


def test_huge_integers_are_parameter_errors_naming_them() -> None:
    for name, run in [
        ("n_elements", lambda: tj.FreeFreeBeam(PAPER, n_elements=10**400)),
        ("layers", lambda: tj.simulate(PAPER, GEO, (0.0, 10.0), layers=10**400)),
        ("layers", lambda: tj.flutter(PAPER, layers=2**64 + 1)),
    ]:
        with pytest.raises(tj.ParameterError) as info:
            run()
        assert info.value.parameter == name


def test_a_start_beyond_the_time_range_is_blamed_on_t_start() -> None:
    with pytest.raises(tj.ParameterError) as info:
        tj.simulate_orbits(PAPER, LOW, 1, t_start=1e12, progress=False)
    assert info.value.parameter == "t_start"


def test_orbit_methods_name_their_own_times() -> None:
    for name, run in [
        ("t0", lambda: GEO.shadow_intervals(math.nan, 1e5)),
        ("t1", lambda: GEO.eclipses(0.0, math.inf)),
        ("t1", lambda: GEO.breakpoints(0.0, 1e12)),
    ]:
        with pytest.raises(tj.ParameterError) as info:
            run()
        assert info.value.parameter == name


def test_values_the_run_would_ignore_are_still_checked() -> None:
    with pytest.raises(tj.ParameterError, match="dt"):
        tj.SolverSettings(method="rk45", dt=math.nan)
    with pytest.raises(tj.ParameterError, match="dt"):
        tj.simulate(PAPER, GEO, (0.0, 10.0), dt=-1.0)
    with pytest.raises(tj.ParameterError) as info:
        tj.materials.get("unobtainium")
    assert info.value.parameter == "key"


def test_calibrate_warns_when_the_series_does_not_determine_a_parameter() -> None:
    # A panel that does not expand never bends: θ(t) = 0 whatever K_el is.
    flat = PAPER.replace(expansion_coeff=0.0)
    t = np.linspace(0.0, 60.0, 21)
    with pytest.warns(RuntimeWarning, match="hinge_stiffness"):
        fit = tj.calibrate(t, np.zeros_like(t), panel=flat, fit=("hinge_stiffness",),
                           rtol=1e-6, atol=1e-9)  # fmt: skip
    assert not math.isfinite(fit.standard_errors["hinge_stiffness"])
