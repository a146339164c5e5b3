"""Errors as data: ParameterError carries the parameter, the value and the allowed range, from
the engine and from Python alike, so that no caller reads them out of a message."""

from __future__ import annotations

import pickle
from pathlib import Path

import pytest

import thermojitter as tj
from thermojitter.scenario import ScenarioError, parse_scenario


def test_parameter_error_is_a_value_error_with_attributes() -> None:
    assert issubclass(tj.ParameterError, ValueError)
    assert issubclass(tj.InternalError, RuntimeError)
    with pytest.raises(tj.ParameterError) as info:
        tj.Panel(length=-2.0)  # refused by the engine
    err = info.value
    assert err.parameter == "length"
    assert err.value == -2.0
    assert err.allowed is not None and "must be in [0.1, 10000]" in err.allowed
    assert "length" in str(err)


def test_engine_errors_keep_their_attributes_across_processes() -> None:
    with pytest.raises(tj.ParameterError) as info:
        tj.Panel(emissivity_front=1.5)
    copy = pickle.loads(pickle.dumps(info.value))
    assert type(copy) is tj.ParameterError
    assert (copy.parameter, copy.value, copy.allowed) == (
        info.value.parameter,
        info.value.value,
        info.value.allowed,
    )
    assert str(copy) == str(info.value)


def test_binding_refusals_are_parameter_errors() -> None:
    panel, orbit = tj.Panel.paper(), tj.Orbit.geo_equinox()
    with pytest.raises(tj.ParameterError) as info:
        tj.simulate(panel, orbit, (0.0, 10.0), model="quadratic")  # type: ignore[arg-type]
    assert info.value.parameter == "model"
    with pytest.raises(tj.ParameterError) as info:
        tj.simulate(panel, orbit, (0.0, 10.0), y0=(300.0, 290.0, 0.0))
    assert info.value.parameter == "y0"


def test_scenario_names_the_key_from_the_attribute() -> None:
    with pytest.raises(ScenarioError) as info:
        parse_scenario({"panel": {"thickness": -0.04}}, Path("s.toml"))
    assert info.value.key == "panel.thickness"
    assert str(info.value).startswith("s.toml: panel.thickness = -0.04 is invalid")


def test_monte_carlo_refusal_names_the_parameter() -> None:
    with pytest.raises(tj.ParameterError) as info:
        tj.monte_carlo(
            tj.Panel.paper(),
            tj.Orbit.geo_equinox(),
            vary={"emissivity_back": ("uniform", 0.5, 3.0)},
            n=8,
            seed=1,
            truncate=False,
            progress=False,
        )
    assert info.value.parameter == "emissivity_back"
    assert info.value.value > 1.0


def test_wrong_types_are_parameter_type_errors() -> None:
    """A wrong type is a TypeError (what callers catch) and a ParameterError (the argument, the
    value given and the type expected as attributes), and crosses processes as one."""
    assert issubclass(tj.ParameterTypeError, TypeError)
    assert issubclass(tj.ParameterTypeError, tj.ParameterError)
    cases = [
        (lambda: tj.Panel(length="2"), "length", "2"),  # type: ignore[arg-type]
        (lambda: tj.simulate("panel", tj.Orbit.sunlit(), (0, 1)), "panel", "panel"),  # type: ignore[arg-type]
        (lambda: tj.steady_state(tj.Panel.paper(), coupled=None), "coupled", None),  # type: ignore[arg-type]
        (lambda: tj.materials.get(3), "key", 3),  # type: ignore[arg-type]
    ]
    for call, parameter, value in cases:
        with pytest.raises(tj.ParameterTypeError) as info:
            call()
        assert (info.value.parameter, info.value.value) == (parameter, value)
        copy = pickle.loads(pickle.dumps(info.value))
        assert type(copy) is tj.ParameterTypeError and copy.parameter == parameter


def test_no_plain_value_or_type_error_is_raised_in_the_package() -> None:
    """Every refusal goes through errors.py (the test oracle, reference.py, aside)."""
    import re

    package = Path(tj.__file__).parent
    plain = re.compile(r"raise (ValueError|TypeError)\b|return (ValueError|TypeError)\(")
    found = [
        f"{path.relative_to(package)}:{number}"
        for path in sorted(package.rglob("*.py"))
        if path.name not in ("errors.py", "reference.py")
        for number, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
        if plain.search(line)
    ]
    assert found == []


def test_numbers_stay_numbers() -> None:
    with pytest.raises(tj.ParameterError) as info:
        tj.sweep(
            tj.Panel.paper(), tj.Orbit.sunlit(), {"damping": [1.0] * 4000, "length": [8.0] * 4000}
        )
    assert info.value.parameter == "grid" and info.value.value == 16_000_000
