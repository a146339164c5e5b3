"""Settings in one home: the panel's ranges are the engine's (Panel.RANGES), the hybrid
propagator's settings an object beside SolverSettings (HybridSettings), a dict still taken."""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import thermojitter as tj
from thermojitter import _core
from thermojitter.panel import PANEL_UNITS, PanelRange

PAPER = tj.Panel.paper()


def test_ranges_are_the_engines_and_name_every_parameter() -> None:
    assert list(tj.Panel.RANGES) == list(tj.Panel.field_names()) == list(_core.PANEL_FIELDS)
    assert list(PANEL_UNITS) == list(tj.Panel.field_names())
    for name, bounds in _core.PANEL_RANGES.items():
        assert tuple(tj.Panel.RANGES[name]) == tuple(bounds)
    with pytest.raises(TypeError):
        tj.Panel.RANGES["damping"] = PanelRange(0.0, 1.0, False)  # type: ignore[index]


@pytest.mark.parametrize("name", list(tj.Panel.field_names()))
def test_ranges_agree_with_the_panels_validation(name: str) -> None:
    """The ends of each range are where Panel refuses: inside accepted, outside refused."""
    r = tj.Panel.RANGES[name]
    inside = [math.nextafter(r.low, math.inf) if r.low_open else r.low, r.high]
    outside = [r.low if r.low_open else math.nextafter(r.low, -math.inf)]
    outside.append(math.nextafter(r.high, math.inf))
    for value in inside:
        assert r.contains(value)
        try:
            PAPER.replace(**{name: value})
        except tj.ParameterError as exc:
            # In its range, refused only by a rule on a combination (a hinge frequency or a
            # damping rate beyond the engine's reach with Table 1's other values).
            assert "with the other parameters" in str(exc), str(exc)
    for value in outside:
        assert not r.contains(value)
        with pytest.raises(tj.ParameterError) as info:
            PAPER.replace(**{name: value})
        assert info.value.parameter == name


def test_monte_carlo_truncation_reads_the_ranges() -> None:
    """Truncated to the engine's range: an emissivity drawn around 1 never passes it."""
    from thermojitter.montecarlo.design import sampled

    u = np.linspace(0.0, 1.0, 64)[:, None]
    names, values, _ = sampled(PAPER, {"emissivity_front": ("normal", 0.99, 0.2)}, u, True)
    r = tj.Panel.RANGES["emissivity_front"]
    assert names == ["emissivity_front"]
    assert values.max() <= r.high and values.min() > r.low
    assert values.max() == r.high  # the top of the unit interval maps onto the range's end


def test_hybrid_settings_are_checked_and_keep_the_engines_defaults() -> None:
    assert tj.HybridSettings().as_dict() == {}
    s = tj.HybridSettings(rtol=1e-5, linear_tolerance=1e-8)
    assert s.as_dict() == {"rtol": 1e-5, "linear_tolerance": 1e-8}
    assert tj.HybridSettings.of({"rtol": 1e-5, "linear_tolerance": 1e-8}) == s
    assert tj.HybridSettings.of(s) is s and tj.HybridSettings.of(None) == tj.HybridSettings()
    with pytest.raises(dataclasses.FrozenInstanceError):
        s.rtol = 1.0  # type: ignore[misc]
    with pytest.raises(tj.ParameterTypeError) as info:
        tj.HybridSettings(rtol="tight")  # type: ignore[arg-type]
    assert info.value.parameter == "hybrid.rtol"
    with pytest.raises(tj.ParameterError) as unknown:
        tj.HybridSettings.of({"warp": 9.0})
    assert unknown.value.parameter == "hybrid.warp" and unknown.value.value == 9.0
    with pytest.raises(tj.ParameterTypeError) as wrong:
        tj.HybridSettings.of([("rtol", 1e-5)])  # type: ignore[arg-type]
    assert wrong.value.parameter == "hybrid"


def test_simulate_orbits_takes_hybrid_settings_as_the_dict() -> None:
    """The object and the dict of the same settings give the same run, bit for bit; the engine
    checks the values, naming the setting."""
    kw = {"method": "hybrid", "progress": False}
    orbit = tj.Orbit.sunlit()
    as_dict = tj.simulate_orbits(PAPER, orbit, 1, hybrid={"linear_tolerance": 1e-8}, **kw)  # type: ignore[arg-type]
    as_object = tj.simulate_orbits(
        PAPER,
        orbit,
        1,
        hybrid=tj.HybridSettings(linear_tolerance=1e-8),
        **kw,  # type: ignore[arg-type]
    )
    for name, column in as_dict.columns.items():
        np.testing.assert_array_equal(as_object.columns[name], column, err_msg=name)
    with pytest.raises(tj.ParameterError) as info:
        tj.simulate_orbits(PAPER, orbit, 1, hybrid=tj.HybridSettings(linear_amplitude=-1.0), **kw)  # type: ignore[arg-type]
    assert info.value.parameter == "hybrid.linear_amplitude"
    with pytest.raises(tj.ParameterError) as unknown:
        tj.simulate_orbits(PAPER, orbit, 1, hybrid={"warp": 9.0}, **kw)  # type: ignore[arg-type]
    assert unknown.value.parameter == "hybrid.warp"
