"""Orbits: phase, Earth shadow, illumination."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

import numpy as np
from numpy.typing import ArrayLike, NDArray

from thermojitter import _core

GEO_RADIUS = 42_164.17e3
"""GEO orbit radius, m."""
EARTH_RADIUS = 6_378.137e3
"""Equatorial Earth radius, m."""
SIDEREAL_DAY = 86_164.0905
"""One sidereal day, s."""


@dataclass(frozen=True)
class Orbit:
    """A circular orbit with a cylindrical Earth shadow and the Sun in the orbit plane.

    Phase β = 2π t/period + phase0, with β = 0 at the subsolar point; the shadow is centred on
    β = π. Immutable and validated on construction.
    """

    radius: float = GEO_RADIUS
    """Orbit radius, m."""
    earth_radius: float = EARTH_RADIUS
    """Radius of the shadowing body, m."""
    period: float = SIDEREAL_DAY
    """Orbit period, s."""
    phase0: float = 0.0
    """Phase at t = 0, rad."""

    def __post_init__(self) -> None:
        for f in fields(self):
            value = getattr(self, f.name)
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                raise TypeError(f"{f.name} must be a real number, not {type(value).__name__}")
            object.__setattr__(self, f.name, float(value))
        _core.validate_orbit(self.as_dict())

    @classmethod
    def geo_equinox(cls) -> Orbit:
        """The paper's scenario: GEO at equinox, cylindrical shadow, t = 0 at the subsolar point."""
        return cls()

    def as_dict(self) -> dict[str, float]:
        return {f.name: getattr(self, f.name) for f in fields(self)}

    @property
    def eclipse_duration(self) -> float:
        """Time in shadow per orbit, s: period · asin(R_E/r)/π."""
        return self.period * math.asin(self.earth_radius / self.radius) / math.pi

    def shadow_intervals(self, t0: float, t1: float) -> list[tuple[float, float]]:
        """Every eclipse (t_enter, t_exit), s, overlapping [t0, t1], clipped to it, in order."""
        return list(_core.shadow_intervals(self.as_dict(), float(t0), float(t1)))

    def illumination(self, t: ArrayLike) -> NDArray[np.float64]:
        """Illuminated fraction of the Sun s(t): 1 in sunlight, 0 in shadow."""
        times = np.atleast_1d(np.asarray(t, dtype=float))
        return np.asarray(_core.illumination(self.as_dict(), np.ascontiguousarray(times)))
