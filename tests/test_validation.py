"""Bad input is refused at the boundary with an error that names the parameter."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import thermojitter as tj
from conftest import GEO, PAPER

BAD_POSITIVE = [math.nan, math.inf, -math.inf, 0.0, -1.0]


@pytest.mark.parametrize("name", tj.Panel.field_names())
@pytest.mark.parametrize("value", BAD_POSITIVE)
def test_panel_refuses_bad_values_naming_them(name: str, value: float) -> None:
    if name == "damping" and value == 0.0:
        assert PAPER.replace(damping=0.0).damping == 0.0
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
    if name == "damping" and value == 0.0:
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
