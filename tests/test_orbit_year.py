"""Orbit options: penumbra, the Sun over the year, the Sun–Earth distance, a low orbit."""

from __future__ import annotations

import datetime as dt
import math

import hypothesis.strategies as st
import numpy as np
import pytest
from hypothesis import given, settings
from scipy.integrate import solve_ivp

import thermojitter as tj
from conftest import GEO, PAPER
from thermojitter import reference as ref
from thermojitter.scenario import parse_scenario

R_SUN = 6.957e8
AU = 1.495978707e11
YEAR = 365.2422
DAY = 86400.0

PEN = tj.Orbit(shadow="penumbra")  # GEO, Sun fixed in the orbit plane at 1 au


def geo_angles() -> tuple[float, float, float]:
    """Earth's and Sun's angular radii seen from GEO and the phase rate (rad, rad, rad/s)."""
    rho_e = math.asin(GEO.earth_radius / GEO.radius)
    rho_s = math.asin(R_SUN / AU)
    return rho_e, rho_s, 2 * math.pi / GEO.period


def test_penumbra_durations_match_the_geometry():
    """Contacts where the Sun's and the Earth's disks touch, seen from the satellite: their
    separation is ρ_E ± ρ_S. Seen from the Earth's centre the phase from the anti-Sun point is
    larger by the Sun's parallax, (r/AU) sin(ρ_E ± ρ_S) ≈ 4e-5 rad (0.6 s per contact), and the
    Sun, r cos ψ farther than 1 au, looks smaller by that fraction."""
    rho_e, rho_s, w = geo_angles()
    par = GEO.radius / AU
    rho_s *= 1 - par * math.cos(rho_e)
    e = PEN.eclipses(0.0, PEN.period)
    assert e.shape == (1, 5)
    centre, first, last, u_in, u_out = e[0]
    assert centre == pytest.approx(0.5 * PEN.period, abs=0.01)
    total, umbra = last - first, u_out - u_in
    outer = rho_e + rho_s + par * math.sin(rho_e + rho_s)
    inner = rho_e - rho_s + par * math.sin(rho_e - rho_s)
    assert total == pytest.approx(2 * outer / w, abs=0.005)
    assert umbra == pytest.approx(2 * inner / w, abs=0.005)
    crossing = (outer - inner) / w
    assert u_in - first == pytest.approx(crossing, abs=0.01)
    assert last - u_out == pytest.approx(crossing, abs=0.01)
    assert 120 < crossing < 135  # sunrise takes about two minutes at GEO
    # the cylinder's eclipse lies between the umbra and the penumbra, mid-way
    assert umbra < GEO.eclipse_duration < total
    assert (umbra + total) / 2 == pytest.approx(GEO.eclipse_duration, abs=1.5)
    print(
        f"GEO equinox: total {total:.2f} s (analytic {2 * outer / w:.2f}), "
        f"umbra {umbra:.2f} s (analytic {2 * inner / w:.2f}), "
        f"penumbra crossing {u_in - first:.2f} s / {last - u_out:.2f} s (analytic {crossing:.2f})"
    )
    assert PEN.shadow_intervals(0.0, PEN.period) == [(first, last)]
    assert PEN.umbra_intervals(0.0, PEN.period) == [(u_in, u_out)]
    assert PEN.breakpoints(0.0, PEN.period) == [first, u_in, u_out, last]
    assert np.allclose(PEN.eclipse_durations(0.0, PEN.period), [total])


def test_penumbra_illumination_is_continuous_and_bounded():
    e = PEN.eclipses(0.0, PEN.period)[0]
    t = np.linspace(e[1] - 60.0, e[2] + 60.0, 200_001)  # 0.04 s apart
    s = PEN.illumination(t)
    assert np.all((s >= 0.0) & (s <= 1.0))
    assert np.max(np.abs(np.diff(s))) < 1e-3  # no jump (the steepest slope is about 1%/s)
    assert np.all(s[t <= e[1]] == 1.0) and np.all(s[t >= e[2]] == 1.0)
    assert np.all(s[(t >= e[3]) & (t <= e[4])] == 0.0)
    # ingress falls monotonically, egress rises monotonically
    ingress = s[(t > e[1]) & (t < e[3])]
    egress = s[(t > e[4]) & (t < e[2])]
    assert np.all(np.diff(ingress) <= 0) and np.all(np.diff(egress) >= 0)
    # half the Sun is hidden when its centre is on the Earth's limb (limb nearly straight)
    mid = 0.5 * (e[1] + e[3])
    assert PEN.illumination(mid)[0] == pytest.approx(0.5, abs=0.02)


def test_geo_eclipse_seasons_over_a_year():
    year = tj.Orbit.geo_year("2026-01-01")
    e = year.eclipses(0.0, YEAR * DAY)
    day = year.epoch_day + e[:, 0] / DAY
    total = (e[:, 2] - e[:, 1]) / 60.0
    spring, autumn = 78.5, 78.5 + YEAR / 2
    # eclipses exist while the Sun's declination is within ρ_E + ρ_S of the equator
    rho_e, rho_s, _ = geo_angles()
    half_season = (
        math.asin(math.sin(rho_e + rho_s) / math.sin(math.radians(23.44))) / (2 * math.pi) * YEAR
    )
    assert 22.5 < half_season < 24.0
    near = np.minimum(np.abs(day - spring), np.abs(day - autumn))
    assert np.all(near < half_season + 0.6)
    for eq in (spring, autumn):
        season = np.abs(day - eq) < 40
        assert season.sum() == pytest.approx(2 * half_season, abs=2)
        longest = np.argmax(np.where(season, total, 0))
        assert abs(day[longest] - eq) < 1.0
        assert 69.0 < total[longest] < 72.0
        assert total[season].min() < 20.0  # grazing eclipses at the edges of the season
    # none in between
    assert not np.any((day > spring + 30) & (day < autumn - 30))
    assert year.umbra_intervals(150 * DAY, 160 * DAY) == []
    assert np.all(year.illumination(np.linspace(150 * DAY, 152 * DAY, 5000)) == 1.0)
    # eclipses happen at local midnight, once per solar day
    assert year.synodic_period == pytest.approx(DAY, abs=0.01)
    season = np.abs(day - spring) < 20
    assert np.allclose(np.diff(e[season, 0]), DAY, atol=2.0)


def test_declination_and_flux_over_the_year():
    year = tj.Orbit.geo_year("2026-01-01")
    t = np.arange(0.0, 366.0) * DAY
    dec = np.degrees(year.declination(t))
    assert dec.max() == pytest.approx(23.44, abs=0.01) and dec.min() == pytest.approx(
        -23.44, abs=0.01
    )
    assert 170 <= np.argmax(dec) <= 173  # June solstice, day 171 ≈ 21 June
    flux = year.flux_scale(t)
    assert flux.max() == pytest.approx(1 / (1 - 0.0167) ** 2, rel=1e-4)  # +3.4 %
    assert flux.min() == pytest.approx(1 / (1 + 0.0167) ** 2, rel=1e-4)  # −3.3 %
    assert 2 <= np.argmax(flux) <= 4  # perihelion in early January
    assert 184 <= np.argmin(flux) <= 187  # aphelion in early July
    assert np.all(GEO.flux_scale(t) == 1.0)


def test_start_dates_place_the_year():
    a = tj.Orbit.geo_year("2026-03-20")
    b = tj.Orbit.geo_year(dt.date(2026, 3, 20))
    c = tj.Orbit.geo_year(dt.datetime(2026, 3, 20, 1, 0, tzinfo=dt.timezone(dt.timedelta(hours=1))))
    assert a.epoch_day == b.epoch_day == c.epoch_day == 78.0
    assert tj.Orbit.geo_year(78.0) == a
    assert tj.Orbit.geo_year("2024-12-31").epoch_day == 365.0  # leap year
    with pytest.raises(ValueError, match="start_date"):
        tj.Orbit.geo_year("20 March")
    with pytest.raises(TypeError, match="start_date"):
        tj.Orbit.geo_year([1, 2])  # type: ignore[arg-type]


def test_leo_preset():
    leo = tj.Orbit.leo()
    r = 6378.137e3 + 540e3
    assert leo.period == pytest.approx(2 * math.pi * math.sqrt(r**3 / 3.986004418e14), rel=1e-12)
    assert leo.period / 60 == pytest.approx(95.4, abs=0.2)
    iv = leo.shadow_intervals(0.0, 10 * leo.period)
    assert len(iv) == 10
    assert all(
        b - a == pytest.approx(leo.period * math.asin(6378.137e3 / r) / math.pi) for a, b in iv
    )
    assert np.allclose(iv, ref.shadow_intervals(leo, 0.0, 10 * leo.period), rtol=0, atol=1e-6)
    with pytest.raises(ValueError, match="altitude"):
        tj.Orbit.leo(-1.0)
    # one default (the engine's), for the method and for a scenario's preset
    assert tj.orbit.LEO_ALTITUDE == 540e3
    assert parse_scenario({"orbit": {"preset": "leo"}}).orbit == leo
    assert parse_scenario({"orbit": {"preset": "leo", "altitude": 600e3}}).orbit != leo


def test_defaults_and_validation():
    assert GEO == tj.Orbit.geo_equinox() == tj.Orbit()
    assert (GEO.shadow, GEO.season, GEO.eccentric_sun) == ("cylindrical", False, False)
    assert np.allclose(
        GEO.shadow_intervals(0.0, 3 * GEO.period), ref.shadow_intervals(GEO, 0.0, 3 * GEO.period)
    )
    assert GEO.umbra_intervals(0.0, GEO.period) == GEO.shadow_intervals(0.0, GEO.period)
    assert tj.Orbit.sunlit().shadow_intervals(0.0, 1e6) == []
    assert np.all(tj.Orbit.sunlit().illumination([0.0, 0.5 * GEO.period]) == 1.0)
    with pytest.raises(ValueError, match="shadow"):
        tj.Orbit(shadow="umbra")  # type: ignore[arg-type]
    with pytest.raises(TypeError, match="season"):
        tj.Orbit(season=1)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="epoch_day"):
        tj.Orbit(epoch_day=math.inf)
    with pytest.raises(ValueError, match="period"):
        tj.Orbit(period=400 * DAY, season=True)
    with pytest.raises(ValueError, match="eclipse"):
        PEN.eclipse_durations(0.0, 1.0, kind="eclipse")  # type: ignore[arg-type]
    assert GEO.replace(shadow="penumbra") == PEN
    with pytest.raises(NotImplementedError):
        ref.shadow_intervals(PEN, 0.0, 1.0)  # the oracle knows only the paper's cylinder


def test_integrator_follows_the_penumbra():
    """One-node plate through a penumbral eclipse: the engine (which stops at every contact and
    umbra boundary) against scipy with s(t) from the same orbit, split at the same breakpoints."""
    orbit = tj.Orbit.geo_year("2026-09-23")
    e = orbit.eclipses(0.0, DAY)[0]
    t0, t1 = e[1] - 600.0, e[2] + 1800.0
    t_eval = np.linspace(t0, t1, 400)
    T0 = ref.one_node_equilibrium(PAPER, float(orbit.flux_scale(t0)[0]))
    sol = tj.simulate_thermal(
        PAPER, orbit, (t0, t1), layers=1, t_eval=t_eval, rtol=1e-10, atol=1e-8, y0=(T0,)
    )
    assert sol.T is not None

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        s = float(orbit.illumination(t)[0] * orbit.flux_scale(t)[0])
        return ref.rhs_one_node(t, y, PAPER, s)

    cuts = [t0, *orbit.breakpoints(t0, t1), t1]
    assert len(cuts) == 6  # first contact, umbra entry and exit, last contact
    y = np.array([T0])
    expected = np.empty_like(t_eval)
    for a, b in zip(cuts[:-1], cuts[1:], strict=True):
        seg = solve_ivp(rhs, (a, b), y, rtol=1e-10, atol=1e-8, dense_output=True)
        inside = (t_eval >= a) & (t_eval <= b)
        expected[inside] = seg.sol(t_eval[inside])[0]
        y = seg.y[:, -1]
    assert np.allclose(sol.T, expected, rtol=1e-6)
    assert sol.T.min() < T0 - 100.0  # it did go through the eclipse


@settings(max_examples=25)
@given(
    altitude=st.floats(300e3, 40_000e3),
    epoch_day=st.floats(0.0, 365.0),
    phase0=st.floats(-math.pi, math.pi),
)
def test_penumbra_contacts_hold_for_any_orbit_and_date(
    altitude: float, epoch_day: float, phase0: float
):
    """Random circular orbits and dates: s stays in [0, 1], is 1 at the contacts and 0 at the
    umbra boundaries, falls monotonically through ingress and rises through egress."""
    r = 6378.137e3 + altitude
    orbit = tj.Orbit(
        radius=r,
        period=2 * math.pi * math.sqrt(r**3 / 3.986004418e14),
        phase0=phase0,
        shadow="penumbra",
        season=True,
        eccentric_sun=True,
        epoch_day=epoch_day,
    )
    span = 2.0 * orbit.synodic_period
    bps = orbit.breakpoints(0.0, span)
    assert bps == sorted(bps)
    for centre, first, last, u_in, u_out in orbit.eclipses(0.0, span):
        assert first < centre < last
        assert orbit.illumination([first, last]) == pytest.approx([1.0, 1.0], abs=1e-6)
        if not math.isnan(u_in):
            assert first < u_in <= centre <= u_out < last
            assert orbit.illumination([u_in, u_out]) == pytest.approx([0.0, 0.0], abs=1e-6)
            ingress = orbit.illumination(np.linspace(first, u_in, 200))
            egress = orbit.illumination(np.linspace(u_out, last, 200))
            assert np.all(np.diff(ingress) <= 1e-12) and np.all(np.diff(egress) >= -1e-12)
        s = orbit.illumination(np.linspace(first - 60.0, last + 60.0, 2000))
        assert np.all((s >= 0.0) & (s <= 1.0))
