"""Inclined circular orbits (issue 30, first piece): β, the J2 nodal drift and the eclipses,
against closed forms and the pure-Python reference; inclination 0 keeps the presets' results."""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import thermojitter as tj
from thermojitter import reference as ref
from thermojitter.checkpoint import CheckpointError
from thermojitter.errors import ParameterError
from thermojitter.orbit import (
    DAY,
    EARTH_RADIUS,
    EQUINOX_DAY,
    GEO_RADIUS,
    J2,
    MU_EARTH,
    SIDEREAL_DAY,
    YEAR_DAYS,
)

GEO_ALTITUDE = GEO_RADIUS - EARTH_RADIUS
YEAR = YEAR_DAYS * DAY

altitudes = st.floats(300e3, 40_000e3)
inclinations = st.floats(0.01, math.pi - 0.01)
raans = st.floats(-math.pi, math.pi)


def mean_motion(radius: float) -> float:
    """Keplerian mean motion, rad/s."""
    return math.sqrt(MU_EARTH / radius**3)


def cylinder_eclipse(radius: float, beta: float) -> float:
    """Time in the cylindrical shadow per orbit with the Sun and the plane fixed, s: the half arc
    has cos = sqrt(1 − (R/r)²)/cos β (no eclipse when that exceeds 1)."""
    c = math.sqrt(1.0 - (EARTH_RADIUS / radius) ** 2) / math.cos(beta)
    return 2.0 * math.acos(c) / mean_motion(radius) if c < 1.0 else 0.0


def frozen(orbit: tj.Orbit) -> tj.Orbit:
    """The orbit with the Sun fixed at the March equinox direction, at 1 au, and no drift: β is
    then asin(sin Ω sin i) for ever, and the closed forms are exact."""
    return orbit.replace(season=False, eccentric_sun=False, j2=False)


def test_geo_equinox_longest_eclipse_is_69_4_minutes() -> None:
    closed = 2.0 * math.asin(EARTH_RADIUS / GEO_RADIUS) / mean_motion(GEO_RADIUS)
    assert abs(closed / 60.0 - 69.4) < 0.05
    for inclination in (0.0, 0.05):
        orbit = tj.Orbit.circular(
            GEO_ALTITUDE, inclination, epoch=EQUINOX_DAY - 3.0, shadow="cylindrical"
        )
        longest = orbit.eclipse_durations(0.0, 7.0 * DAY).max()
        # With the Sun moving the shadow is crossed at n − 2π/year, 0.27 % slower (11 s); the
        # eclipse nearest the equinox has |β| < 0.3°: ~1 s shorter than at β = 0.
        moving = (
            2.0
            * math.asin(EARTH_RADIUS / GEO_RADIUS)
            / (mean_motion(GEO_RADIUS) - 2.0 * math.pi / YEAR)
        )
        assert abs(longest - moving) < 3.0, (inclination, longest, moving)
        fixed = frozen(orbit).eclipse_durations(0.0, 3.0 * DAY)
        np.testing.assert_allclose(fixed, closed, rtol=0, atol=1e-4)


@pytest.mark.parametrize("inclination, raan", [(0.0, 0.0), (0.2, 1.0)])
def test_no_geo_eclipse_when_beta_is_beyond_8_7_degrees(inclination: float, raan: float) -> None:
    orbit = tj.Orbit.circular(
        GEO_ALTITUDE, inclination, raan, epoch="2026-01-01", shadow="cylindrical"
    )
    limit = math.asin(EARTH_RADIUS / GEO_RADIUS)
    assert abs(math.degrees(limit) - 8.7) < 0.01
    e = orbit.eclipses(0.0, YEAR)
    assert 60 < len(e) < 200
    assert np.all(np.abs(orbit.beta(e[:, 0])) < limit)
    # One passage a synodic day; those with |β| clearly beyond the limit have no eclipse, those
    # clearly within it have one.
    midnights = np.arange(0.5, YEAR / orbit.synodic_period) * orbit.synodic_period
    b = np.abs(orbit.beta(midnights))
    clear = np.abs(b - limit) > 0.01
    near = np.abs(midnights[:, None] - e[None, :, 0]).min(axis=1) < 0.2 * orbit.period
    np.testing.assert_array_equal(near[clear], b[clear] < limit)


def test_leo_at_beta_zero_longest_eclipse_is_35_6_minutes() -> None:
    radius = EARTH_RADIUS + 540e3
    closed = 2.0 * math.asin(EARTH_RADIUS / radius) / mean_motion(radius)
    assert abs(closed / 60.0 - 35.6) < 0.05
    orbit = frozen(tj.Orbit.circular(540e3, math.radians(28.5), 0.0, shadow="cylindrical"))
    assert np.all(np.abs(orbit.beta([0.0, 1e4])) < 1e-15)
    durations = orbit.eclipse_durations(0.0, 5.0 * orbit.period)
    assert len(durations) == 5
    np.testing.assert_allclose(durations, closed, rtol=0, atol=1e-4)


@settings(max_examples=40, deadline=None)
@given(altitude=altitudes, inclination=inclinations, raan=raans)
def test_cylinder_eclipse_length_follows_beta(
    altitude: float, inclination: float, raan: float
) -> None:
    orbit = frozen(tj.Orbit.circular(altitude, inclination, raan, shadow="cylindrical", j2=False))
    beta = math.asin(math.sin(raan) * math.sin(inclination))
    assert orbit.beta(1234.5)[0] == pytest.approx(beta, abs=1e-12)
    want = cylinder_eclipse(orbit.radius, beta)
    got = orbit.eclipse_durations(0.0, 3.0 * orbit.period)
    limit = math.asin(EARTH_RADIUS / orbit.radius)
    if abs(abs(beta) - limit) < 1e-6:
        return  # grazing: the length is infinitely sensitive to β
    if want == 0.0:
        assert len(got) == 0
    else:
        assert len(got) == 3
        np.testing.assert_allclose(got, want, rtol=0, atol=1e-4)


def test_hubble_node_drifts_minus_6_59_degrees_a_day() -> None:
    radius, inclination = EARTH_RADIUS + 540e3, math.radians(28.5)
    closed = -1.5 * J2 * (EARTH_RADIUS / radius) ** 2 * mean_motion(radius) * math.cos(inclination)
    assert abs(math.degrees(closed * DAY) + 6.59) < 0.005
    orbit = tj.Orbit.circular(540e3, inclination, 0.0).replace(season=False)
    assert orbit.nodal_rate == pytest.approx(closed, rel=1e-9)
    # Measured from the geometry: with the Sun at the equinox direction, sin β = sin Ω sin i.
    node = math.asin(math.sin(orbit.beta(DAY)[0]) / math.sin(inclination))
    assert abs(math.degrees(node) + 6.59) < 0.005
    assert tj.Orbit.circular(540e3, inclination, j2=False).nodal_rate == 0.0


@settings(max_examples=40, deadline=None)
@given(
    altitude=altitudes,
    inclination=st.floats(0.0, math.pi),
    raan=raans,
    epoch=st.floats(0.0, 365.0),
    j2=st.booleans(),
)
def test_beta_matches_the_vector_computation_over_a_year(
    altitude: float, inclination: float, raan: float, epoch: float, j2: bool
) -> None:
    orbit = tj.Orbit.circular(altitude, inclination, raan, epoch, j2=j2)
    t = np.linspace(0.0, YEAR, 97)
    np.testing.assert_allclose(orbit.beta(t), ref.beta(orbit, t), rtol=0, atol=1e-9)


@settings(max_examples=25, deadline=None)
@given(
    altitude=st.floats(300e3, 2000e3),
    inclination=inclinations,
    raan=raans,
    epoch=st.floats(0.0, 365.0),
    phase0=st.floats(-math.pi, math.pi),
)
def test_cylinder_shadow_matches_the_reference(
    altitude: float, inclination: float, raan: float, epoch: float, phase0: float
) -> None:
    orbit = tj.Orbit.circular(altitude, inclination, raan, epoch, shadow="cylindrical").replace(
        phase0=phase0
    )
    t = np.linspace(0.0, 3.0 * orbit.period, 1001)
    edges = np.array(orbit.breakpoints(0.0, 3.0 * orbit.period) or [np.inf])
    away = np.abs(t[:, None] - edges[None, :]).min(axis=1) > 0.01
    engine = orbit.illumination(t)[away] == 1.0
    np.testing.assert_array_equal(engine, ref.cylinder_sunlit(orbit, t[away]))


def test_inclination_zero_is_the_presets() -> None:
    # GEO: the preset's fields but the period (sidereal day against Keplerian), the node and J2.
    date = "2026-03-01"
    year = tj.Orbit.geo_year(date)
    same = tj.Orbit.circular(GEO_ALTITUDE, 0.0, 1.3, date).replace(period=SIDEREAL_DAY)
    assert same.replace(raan=0.0, j2=False, albedo=0.0, earth_ir=0.0) == year
    span = (0.0, 30.0 * DAY)
    np.testing.assert_array_equal(same.eclipses(*span), year.eclipses(*span))
    t = np.linspace(*span, 10_001)
    np.testing.assert_array_equal(same.illumination(t), year.illumination(t))
    np.testing.assert_array_equal(same.beta(t), year.declination(t))
    # LEO: the preset fixes the Sun in the orbit plane; so does the circular orbit, frozen.
    leo = tj.Orbit.leo(540e3)
    flat = frozen(tj.Orbit.circular(540e3, 0.0, 2.0, shadow="cylindrical"))
    t = np.linspace(0.0, 10.0 * leo.period, 10_001)
    np.testing.assert_array_equal(flat.illumination(t), leo.illumination(t))
    assert flat.shadow_intervals(0.0, 1e5) == leo.shadow_intervals(0.0, 1e5)


def test_the_hybrid_keeps_its_gate_on_an_inclined_low_orbit() -> None:
    from test_hybrid import assert_gate, both

    # The geometry alone (the Earth's heat runs in full: tests/test_earth_heating.py).
    orbit = tj.Orbit.circular(540e3, math.radians(51.6), 0.3, "2026-06-01", albedo=0, earth_ir=0)
    assert 0.1 < abs(orbit.beta(0.0)[0]) < 1.0  # an eclipse shorter than at β = 0
    full, hybrid = both(orbit, 6)
    assert_gate(full, hybrid)


def test_bad_orbits_are_named() -> None:
    with pytest.raises(ParameterError, match="inclination.*degrees"):
        tj.Orbit.circular(540e3, 28.5)
    with pytest.raises(ParameterError, match="inclination"):
        tj.Orbit.circular(540e3, -0.1)
    with pytest.raises(ParameterError, match="raan"):
        tj.Orbit.circular(540e3, 0.5, float("nan"))
    with pytest.raises(ParameterError, match="540 km"):
        tj.Orbit.circular(540)
    with pytest.raises(ParameterError, match="epoch"):
        tj.Orbit.circular(540e3, epoch="March")
    assert tj.Orbit.circular(540e3).shadow == "penumbra"
    assert tj.Orbit(shadow="conical") == tj.Orbit(shadow="penumbra")


PRE_INCLINATION_ORBIT_KEYS = {
    "radius", "earth_radius", "period", "phase0", "shadow", "season", "eccentric_sun", "epoch_day"
}  # fmt: skip
"""The orbit fields a checkpoint recorded before inclined orbits existed."""


def test_checkpoints_of_equatorial_orbits_keep_their_identity(tmp_path: Path) -> None:
    """A checkpoint's request records the orbit plane only where it is set: a long run of an
    equatorial orbit written before inclined orbits existed still resumes (its request is the
    same), and an inclined orbit's checkpoint names its plane."""
    import json

    kw: dict[str, Any] = {"progress": False, "orbits_per_call": 1}
    flat = tmp_path / "flat.json"
    tj.simulate_orbits(tj.Panel.paper(), tj.Orbit.leo(), 1, checkpoint=flat, **kw)
    assert set(json.loads(flat.read_text())["request"]["orbit"]) == PRE_INCLINATION_ORBIT_KEYS
    tilted = tmp_path / "tilted.json"
    orbit = tj.Orbit.circular(540e3, math.radians(28.5), shadow="cylindrical")
    tj.simulate_orbits(tj.Panel.paper(), orbit, 1, checkpoint=tilted, **kw)
    recorded = json.loads(tilted.read_text())["request"]["orbit"]
    assert recorded["inclination"] == orbit.inclination and recorded["j2"] is True
    with pytest.raises(CheckpointError):
        tj.simulate_orbits(tj.Panel.paper(), orbit.replace(raan=0.5), 1, checkpoint=tilted, **kw)
