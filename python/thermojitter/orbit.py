"""Orbits: phase, Earth shadow (none, cylindrical, penumbra), illumination, the Sun over the year.

The orbit is circular and the plate points at the Sun. At inclination 0 (the presets) the orbit
is in the Earth's equatorial plane and its phase is measured from the Sun's meridian: 0 at the
subsolar point (t = 0 by default), the shadow centred on π.

Inclined orbits (:meth:`Orbit.circular`): inclination i, right ascension of the ascending node
Ω(t) = raan + Ω̇ t with the J2 nodal drift Ω̇ = −(3/2) J2 (R_E/a)² n cos i (``j2=True``; the
along-track J2 terms are left out, the period stays Keplerian), the satellite at argument of
latitude u(t) = u₀ + n t, ``phase0`` past the orbit's noon (its point nearest the Sun) at t = 0.
The Sun is the unit vector of ecliptic longitude λ = 2π (d − 78.5)/365.2422 (declination
asin(sin ε sin λ), right ascension atan2(cos ε sin λ, cos λ)); β(t), the Sun's angle to the orbit
plane, is :meth:`Orbit.beta`. Eclipses exist only while |β| < asin(R_E/r) (plus the penumbra's
width) and shorten as |β| grows. At inclination 0 the presets' path is kept bit for bit: the
equator has no node (``raan`` and ``j2`` do nothing) and the Sun's right ascension is the mean
one, λ itself (at most 2.5° off the true one, building up over months from t = 0).

Shadow models (``shadow``):

- ``"none"``: permanent sunlight, s = 1 (for flutter growth measurements).
- ``"cylindrical"``: the paper's model, a cylinder of radius R_E behind the Earth; s jumps
  between 1 and 0.
- ``"penumbra"`` (also ``"conical"``, stored as ``"penumbra"``): the Sun is a disk (angular
  radius asin(R_sun / distance), about 0.267° at 1 au) partly hidden by the Earth's disk
  (angular radius asin(R_E / r)); s is the visible fraction of the solar disk, continuous in
  [0, 1], from the overlap area of the two disks (planar geometry in angles; the atmosphere is
  ignored). At GEO sunrise and sunset take about two minutes.

The year (``season=True``): the Sun's declination is δ = asin(sin 23.44° · sin(2π (d − 78.5) /
365.2422)), d the day of the year (days since 1 January 00:00 UTC; 78.5 is a mean March
equinox, about 20 March 12:00), and the Sun moves eastwards by 360°/365.2422 per day, so
eclipses recur once per synodic period (86400 s at GEO). At GEO eclipses happen only within about
±23 days of the equinoxes, growing from 0 to about 72 min (first to last contact) and back.
``eccentric_sun=True``: the Sun–Earth distance is r = 1 − 0.0167 cos(2π (d − 3) / 365.2422) au
(perihelion about 4 January) and the flux scales as 1/r², ±3.3 %. Dates are mean values, good to
about a day; the equation of time is ignored.
"""

from __future__ import annotations

import datetime as _dt
from dataclasses import dataclass, fields
from typing import Any, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from thermojitter import _core
from thermojitter import errors as checks
from thermojitter.persist import field_type

# The constants live in the engine (rust/src/orbit.rs); these are their Python names.
GEO_RADIUS: float = _core.GEO_RADIUS
"""GEO orbit radius, m."""
EARTH_RADIUS: float = _core.EARTH_RADIUS
"""Equatorial Earth radius, m."""
SIDEREAL_DAY: float = _core.SIDEREAL_DAY
"""One sidereal day, s."""
MU_EARTH: float = _core.MU_EARTH
"""Earth's gravitational parameter, m³/s²."""
EQUINOX_DAY: float = _core.EQUINOX_DAY
"""Mean March equinox, days since 1 January 00:00 UTC."""
PERIHELION_DAY: float = _core.PERIHELION_DAY
"""Mean perihelion, days since 1 January 00:00 UTC."""
_GEO_EQUINOX: dict[str, Any] = dict(_core.GEO_EQUINOX_ORBIT)

LEO_ALTITUDE: float = _core.LEO_ALTITUDE
"""Default altitude of :meth:`Orbit.leo` (a Hubble-like low orbit), m."""
MIN_LEO_ALTITUDE: float = _core.MIN_LEO_ALTITUDE
"""Lowest altitude of :meth:`Orbit.leo`, m (the Kármán line; lower, the atmosphere ends an orbit
within hours)."""
MAX_LEO_ALTITUDE: float = _core.MAX_LEO_ALTITUDE
"""Highest altitude of :meth:`Orbit.leo`, m (beyond the Moon)."""
J2: float = _core.J2
"""The Earth's second zonal harmonic, for the nodal drift."""
EARTH_ALBEDO: float = _core.EARTH_ALBEDO
"""The Earth's mean albedo, the default of :meth:`Orbit.circular`."""
EARTH_IR: float = _core.EARTH_IR
"""The Earth's mean infrared flux at its surface, W/m², the default of :meth:`Orbit.circular`."""
OBLIQUITY: float = _core.OBLIQUITY
"""Obliquity of the ecliptic, rad."""
YEAR_DAYS: float = _core.YEAR_DAYS
"""Tropical year, days."""
DAY: float = _core.DAY
"""Mean solar day, s."""

ShadowModel = Literal["none", "cylindrical", "conical", "penumbra"]
_SHADOWS = ("none", "cylindrical", "conical", "penumbra")
_BOOLS = ("season", "eccentric_sun", "j2")
_EQUATORIAL: dict[str, Any] = {
    k: _GEO_EQUINOX[k] for k in ("inclination", "raan", "j2", "albedo", "earth_ir")
}
"""The orbit plane's and the Earth's heat fields at their defaults: an equatorial orbit without
Earth heating, as before they existed."""
_UNSET = object()

DateLike = str | _dt.date | float | int


def _time(name: str, value: Any) -> float:
    """A time on the orbit's clock, s, within the engine's reach (|t| <= MAX_TIME), checked here
    so that the error names the method's own argument."""
    return checks.in_range(name, value, -_core.MAX_TIME, _core.MAX_TIME, "s")


def day_of_year(date: DateLike, name: str = "start_date") -> float:
    """Days since 1 January 00:00 UTC of the date's year, fractional.

    ``date``: an ISO date or date-time string ("2026-03-20", "2026-03-20T14:46"), a
    ``datetime.date``/``datetime.datetime`` (aware ones are converted to UTC), or a number taken
    as the day of the year already.
    """
    if isinstance(date, bool):
        raise checks.wrong_type(
            name,
            date,
            "a date, an ISO date string or a day of the year",
            f"{name} must be a date, an ISO date string or a day of the year",
        )
    if isinstance(date, (int, float, np.integer, np.floating)):
        return checks.finite(name, date)
    if isinstance(date, str):
        try:
            parsed: _dt.date = _dt.datetime.fromisoformat(date)
        except ValueError:
            raise checks.ParameterError(
                name, date, "not an ISO date (YYYY-MM-DD[THH:MM[:SS]])"
            ) from None
        date = parsed
    if isinstance(date, _dt.datetime):
        if date.tzinfo is not None:
            date = date.astimezone(_dt.timezone.utc).replace(tzinfo=None)
        start = _dt.datetime(date.year, 1, 1)
        return (date - start).total_seconds() / 86400.0
    if isinstance(date, _dt.date):
        return float((date - _dt.date(date.year, 1, 1)).days)
    raise checks.wrong_type(name, date, "a date, an ISO date string or a day of the year")


def _altitude(altitude: Any) -> float:
    """An orbit's altitude, m, in [MIN_LEO_ALTITUDE, MAX_LEO_ALTITUDE], saying so when km were
    probably meant."""
    height = checks.real("altitude", altitude)
    if 0.0 < height < MIN_LEO_ALTITUDE:
        # Below 100 km nothing stays in orbit: the number was almost surely given in km.
        raise checks.ParameterError(
            "altitude",
            altitude,
            f"must be in [{MIN_LEO_ALTITUDE:g}, {MAX_LEO_ALTITUDE:g}] m; below 100 km nothing "
            f"orbits: if km were meant, {height:g} km = {height * 1e3:g} m",
        )
    if not (MIN_LEO_ALTITUDE <= height <= MAX_LEO_ALTITUDE):
        raise checks.ParameterError(
            "altitude", altitude, f"must be in [{MIN_LEO_ALTITUDE:g}, {MAX_LEO_ALTITUDE:g}] m"
        )
    return height


@field_type
@dataclass(frozen=True)
class Orbit:
    """A circular orbit, its Earth shadow and the Sun over the year.

    Equatorial (the presets, inclination 0): phase 2π t/period + phase0 relative to a fixed Sun
    (``season=False``), or advancing at 2π/period − 2π/year when the Sun moves over the year; 0 at
    the subsolar point, the shadow centred on π. Inclined: see the module's notes and
    :meth:`circular`; ``phase0`` is then measured from the orbit's noon. Immutable and
    validated on construction. The defaults are the paper's scenario (GEO at equinox, cylindrical
    shadow, Sun at 1 au).
    """

    radius: float = _GEO_EQUINOX["radius"]
    """Orbit radius, m."""
    earth_radius: float = _GEO_EQUINOX["earth_radius"]
    """Radius of the shadowing body, m."""
    period: float = _GEO_EQUINOX["period"]
    """Orbit period (inertial), s."""
    phase0: float = _GEO_EQUINOX["phase0"]
    """Phase at t = 0, rad."""
    shadow: ShadowModel = _GEO_EQUINOX["shadow"]
    """Shadow model: "none", "cylindrical" or "penumbra" ("conical" is taken as "penumbra")."""
    season: bool = _GEO_EQUINOX["season"]
    """The Sun's declination and right ascension follow the year from ``epoch_day``."""
    eccentric_sun: bool = _GEO_EQUINOX["eccentric_sun"]
    """The flux (∝ 1/r²) and the Sun's size follow the Sun–Earth distance r."""
    epoch_day: float = _GEO_EQUINOX["epoch_day"]
    """Day of the year at t = 0 (days since 1 January 00:00 UTC)."""
    inclination: float = _GEO_EQUINOX["inclination"]
    """Inclination of the orbit plane to the equator, rad in [0, π] (0: equatorial)."""
    raan: float = _GEO_EQUINOX["raan"]
    """Right ascension of the ascending node at t = 0, rad (no effect at inclination 0)."""
    j2: bool = _GEO_EQUINOX["j2"]
    """The node drifts under the Earth's oblateness (no effect at inclination 0)."""
    albedo: float = _GEO_EQUINOX["albedo"]
    """The Earth's albedo, in [0, 1]: the fraction of sunlight it reflects onto the panel's faces
    (0 on the presets, :data:`EARTH_ALBEDO` on :meth:`circular`)."""
    earth_ir: float = _GEO_EQUINOX["earth_ir"]
    """The Earth's infrared flux at its surface, W/m² (0 on the presets, :data:`EARTH_IR` on
    :meth:`circular`)."""

    def __post_init__(self) -> None:
        checks.check_fields(self, flags=_BOOLS, choices={"shadow": _SHADOWS})
        if self.shadow == "conical":
            # One stored name per model, so that equal orbits compare equal.
            object.__setattr__(self, "shadow", "penumbra")
        _core.validate_orbit(self.as_dict())

    @classmethod
    def geo_equinox(cls) -> Orbit:
        """The paper's scenario: GEO at equinox, cylindrical shadow, t = 0 at the subsolar point."""
        return cls()

    @classmethod
    def geo_year(
        cls,
        start_date: DateLike = "2026-01-01",
        *,
        shadow: ShadowModel = "penumbra",
        eccentric_sun: bool = True,
    ) -> Orbit:
        """GEO over a realistic year from ``start_date`` (t = 0 at the subsolar point that day):
        the Sun's declination (eclipse seasons around the equinoxes), its distance (flux ±3.3 %)
        and a penumbra."""
        return cls(
            shadow=shadow,
            season=True,
            eccentric_sun=eccentric_sun,
            epoch_day=day_of_year(start_date),
        )

    @classmethod
    def leo(cls, altitude: float = LEO_ALTITUDE, *, shadow: ShadowModel = "cylindrical") -> Orbit:
        """A Hubble-like circular low orbit at ``altitude`` (m): Keplerian period (about 95 min at
        540 km), the Sun in the orbit plane (the longest eclipses, about 36 min)."""
        leo = _core.leo_orbit(_altitude(altitude))
        return cls(radius=leo["radius"], period=leo["period"], shadow=shadow)

    @classmethod
    def circular(
        cls,
        altitude: float,
        inclination: float = 0.0,
        raan: float = 0.0,
        epoch: DateLike = EQUINOX_DAY,
        *,
        j2: bool = True,
        shadow: ShadowModel = "conical",
        albedo: float = EARTH_ALBEDO,
        earth_ir: float = EARTH_IR,
    ) -> Orbit:
        """Any circular Earth orbit: ``altitude`` (m), ``inclination`` and ``raan`` (rad; the node
        at ``epoch``), the Sun by date from ``epoch`` (as ``geo_year``'s ``start_date``; default
        the March equinox) with its distance, the node's J2 drift (``j2``), and ``shadow``
        ("conical" with penumbra, "cylindrical" or "none"). t = 0 at the orbit's noon (its
        point nearest the Sun). Keplerian period. At inclination 0 this is the presets'
        equatorial orbit, where ``raan`` and ``j2`` do nothing.

        The Earth heats the panel: ``albedo`` (the fraction of sunlight it reflects) and
        ``earth_ir`` (its infrared flux at the surface, W/m²) reach each face through its view
        factor to the Earth (docs/howto/earth-heating.md); 0 for both leaves the Sun alone, as
        on the presets."""
        leo = _core.leo_orbit(_altitude(altitude))
        return cls(
            radius=leo["radius"],
            period=leo["period"],
            shadow=shadow,
            season=True,
            eccentric_sun=True,
            epoch_day=day_of_year(epoch, "epoch"),
            inclination=inclination,
            raan=raan,
            j2=j2,
            albedo=albedo,
            earth_ir=earth_ir,
        )

    @classmethod
    def sunlit(cls) -> Orbit:
        """GEO in permanent sunlight (``shadow="none"``)."""
        return cls(shadow="none")

    def replace(self, **changes: Any) -> Orbit:
        """A validated copy with some fields changed."""
        return type(self)(**{**self.as_dict(), **changes})

    def as_dict(self) -> dict[str, Any]:
        return {f.name: getattr(self, f.name) for f in fields(self)}

    def as_record(self) -> dict[str, Any]:
        """The orbit as run settings and checkpoints record it: :meth:`as_dict` without the
        orbit plane's fields where they hold their equatorial defaults, so that a checkpoint
        written before inclined orbits existed still answers the same run."""
        return {k: v for k, v in self.as_dict().items() if _EQUATORIAL.get(k, _UNSET) != v}

    @property
    def eclipse_duration(self) -> float:
        """Time in the cylindrical shadow per orbit with the Sun in the orbit plane, s:
        period · asin(R_E/r)/π. For the other models see :meth:`eclipse_durations`."""
        return float(_core.eclipse_duration(self.as_dict()))

    @property
    def synodic_period(self) -> float:
        """Time between two eclipses, s (the period relative to the Sun)."""
        return float(_core.synodic_period(self.as_dict()))

    def shadow_intervals(self, t0: float, t1: float) -> list[tuple[float, float]]:
        """Every eclipse (t_enter, t_exit), s, overlapping [t0, t1], clipped to it, in order.

        Cylinder: shadow entry and exit. Penumbra: first and last contact, where s starts to fall
        below 1 and where it is back to 1 (see :meth:`umbra_intervals` for s = 0)."""
        return list(_core.shadow_intervals(self.as_dict(), _time("t0", t0), _time("t1", t1)))

    def umbra_intervals(self, t0: float, t1: float) -> list[tuple[float, float]]:
        """Intervals where s = 0, s, clipped to [t0, t1] (the shadow intervals for the cylinder)."""
        return list(_core.umbra_intervals(self.as_dict(), _time("t0", t0), _time("t1", t1)))

    def breakpoints(self, t0: float, t1: float) -> list[float]:
        """Times in (t0, t1) where s jumps (cylinder) or has a kink (penumbra contacts and umbra
        boundaries); the integrators stop on each."""
        return list(_core.orbit_breakpoints(self.as_dict(), _time("t0", t0), _time("t1", t1)))

    def eclipses(self, t0: float, t1: float) -> NDArray[np.float64]:
        """Eclipses overlapping [t0, t1], unclipped, one row each: (deepest point, first contact,
        last contact, umbra entry, umbra exit), s; NaN where there is no umbra."""
        rows = _core.eclipses(self.as_dict(), _time("t0", t0), _time("t1", t1))
        return np.asarray(rows, dtype=float).reshape(-1, 5)

    def eclipse_durations(
        self, t0: float, t1: float, *, kind: Literal["total", "umbra"] = "total"
    ) -> NDArray[np.float64]:
        """Duration, s, of each eclipse whose deepest point is in [t0, t1): ``kind="total"`` from
        first to last contact (s < 1), ``"umbra"`` with s = 0."""
        checks.choice("kind", kind, ("total", "umbra"))
        e = self.eclipses(t0, t1)
        e = e[(e[:, 0] >= t0) & (e[:, 0] < t1)]
        if kind == "total":
            return e[:, 2] - e[:, 1]
        umbra = e[:, 4] - e[:, 3]
        return np.where(np.isnan(umbra), 0.0, umbra)

    def illumination(self, t: ArrayLike) -> NDArray[np.float64]:
        """Illuminated fraction of the Sun s(t): 1 in sunlight, 0 in umbra, between in penumbra."""
        return np.asarray(_core.illumination(self.as_dict(), checks.real_array("t", t)))

    def flux_scale(self, t: ArrayLike) -> NDArray[np.float64]:
        """Solar flux at time t relative to the solar constant at 1 au: 1/r², r in au (1 unless
        ``eccentric_sun``). Pass it to :func:`thermojitter.flutter` as ``flux``."""
        return np.asarray(_core.flux_scale(self.as_dict(), checks.real_array("t", t)))

    def beta(self, t: ArrayLike) -> NDArray[np.float64]:
        """The Sun's angle to the orbit plane at time t, rad in [−π/2, π/2], positive on the
        side of the orbit normal (for an equatorial orbit, the declination)."""
        return np.asarray(_core.beta(self.as_dict(), checks.real_array("t", t)))

    @property
    def nodal_rate(self) -> float:
        """Rate of the ascending node, rad/s: −(3/2) J2 (R_E/a)² n cos i with ``j2``, else 0."""
        return float(_core.nodal_rate(self.as_dict()))

    def declination(self, t: ArrayLike) -> NDArray[np.float64]:
        """The Sun's declination at time t, rad (0 unless ``season``)."""
        return np.asarray(_core.declination(self.as_dict(), checks.real_array("t", t)))

    def time_of(self, date: DateLike) -> float:
        """Seconds from t = 0 (``epoch_day``) to ``date`` within the same year's day count."""
        return (day_of_year(date) - self.epoch_day) * 86400.0


ECLIPSE_MARGIN = 1200.0
"""Sunlight either side of the first eclipse in :func:`eclipse_window`, s."""


def eclipse_window(orbit: Orbit, margin: float = ECLIPSE_MARGIN) -> tuple[float, float]:
    """The first eclipse of the orbit with ``margin`` seconds of sunlight on each side, s."""
    intervals = orbit.shadow_intervals(0.0, orbit.period)
    if not intervals:
        raise checks.ParameterError(
            "orbit", orbit, message="orbit has no eclipse in its first period: give t_span"
        )
    enter, leave = intervals[0]
    return max(0.0, enter - margin), leave + margin
