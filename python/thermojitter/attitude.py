"""Where the panel's front face points along its orbit: the ``attitude=`` of the runs.

The engine computes the front normal at every time from the attitude and the orbit (the Sun's
direction, the satellite's position, the orbit normal), and from it the incidence of sunlight on
each face and each face's view of the Earth (docs/howto/earth-heating.md). The structure's
deflection still scales the loads by its projected-area factor (cos θ for the hinge) about what
the attitude sets.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Literal

from thermojitter import errors as checks

AttitudeKind = Literal["sun_pointing", "sun_tracking", "nadir", "inertial"]
_KINDS = ("sun_pointing", "sun_tracking", "nadir", "inertial")


@dataclass(frozen=True)
class Attitude:
    """The pointing of the panel's front face. Build it with a class method:

    - :meth:`sun_pointing`: the front normal on the Sun (the paper's plate, the default);
    - :meth:`sun_tracking`: a one-axis tracking array turning about the orbit normal: the
      incidence of sunlight is β − ``offset`` (β the Sun's angle to the orbit plane);
    - :meth:`nadir`: the front normal on the Earth's centre (a boom or antenna held towards it);
    - :meth:`inertial`: a fixed front normal in the equatorial frame (x towards the March
      equinox, z the north pole).
    """

    kind: AttitudeKind = "sun_pointing"
    offset: float = 0.0
    """Sun tracking: the normal's tilt from the orbit plane towards the orbit normal, rad in
    [−π/2, π/2]."""
    normal: tuple[float, float, float] | None = None
    """Inertial: the front normal (any non-zero length; the engine normalises it)."""

    def __post_init__(self) -> None:
        checks.choice("kind", self.kind, _KINDS)
        object.__setattr__(self, "offset", checks.real("offset", self.offset))
        if self.kind == "inertial":
            if self.normal is None:
                raise checks.ParameterError("normal", None, "is required for an inertial attitude")
            values = checks.real_array("normal", self.normal)
            if values.shape != (3,):
                raise checks.ParameterError("normal", self.normal, "must hold three numbers")
            length = math.sqrt(float(sum(v * v for v in values)))
            if not (math.isfinite(length) and length > 0.0):
                raise checks.ParameterError("normal", self.normal, "must be a non-zero vector")
            object.__setattr__(self, "normal", tuple(float(v) for v in values))
        elif self.normal is not None:
            raise checks.ParameterError("normal", self.normal, "is for an inertial attitude only")

    @classmethod
    def sun_pointing(cls) -> Attitude:
        """The front normal on the Sun: the incidence is 0 at all times (the paper's plate)."""
        return cls("sun_pointing")

    @classmethod
    def sun_tracking(cls, offset: float = 0.0) -> Attitude:
        """A one-axis tracking array turning about the orbit normal, its normal tilted
        ``offset`` (rad) from the orbit plane: the incidence of sunlight is β − offset."""
        return cls("sun_tracking", offset=offset)

    @classmethod
    def nadir(cls) -> Attitude:
        """The front normal on the Earth's centre."""
        return cls("nadir")

    @classmethod
    def inertial(cls, normal: Any) -> Attitude:
        """A fixed front normal in the equatorial frame (x: March equinox, z: north pole)."""
        return cls("inertial", normal=tuple(normal))

    @classmethod
    def of(cls, attitude: Attitude | None) -> Attitude:
        """``attitude`` checked, or Sun-pointing for None."""
        if attitude is None:
            return cls.sun_pointing()
        return checks.instance("attitude", attitude, cls, "a thermojitter.Attitude")

    def as_dict(self) -> dict[str, Any]:
        """The attitude as the engine takes it."""
        out: dict[str, Any] = {"kind": self.kind}
        if self.kind == "sun_tracking":
            out["offset"] = self.offset
        if self.normal is not None:
            out["normal"] = list(self.normal)
        return out


def engine_orbit(orbit: Any, attitude: Attitude | None) -> dict[str, Any]:
    """The orbit as the engine takes it, with the run's attitude (left out when Sun-pointing,
    the engine's default)."""
    out: dict[str, Any] = orbit.as_dict()
    used = Attitude.of(attitude)
    if used.kind != "sun_pointing":
        out["attitude"] = used.as_dict()
    return out


def has_face_loads(orbit: Any, attitude: Attitude | None) -> bool:
    """Whether a run heats more than the front's sunlight: Earth heating on the orbit, or an
    attitude other than Sun-pointing (the engine's own test, on the same fields)."""
    kind = Attitude.of(attitude).kind
    return bool(orbit.albedo != 0.0 or orbit.earth_ir != 0.0 or kind != "sun_pointing")
