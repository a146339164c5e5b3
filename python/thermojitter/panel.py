"""The panel (paper Table 1) and the hinge parameters derived from it."""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping
from dataclasses import dataclass, fields
from functools import cached_property
from types import MappingProxyType
from typing import Any, ClassVar, Literal, NamedTuple

import numpy as np

from thermojitter import _core
from thermojitter import errors as checks
from thermojitter.laminate import Laminate
from thermojitter.persist import Persistent, field_type

StiffnessCriterion = Literal["deflection", "deflection_small_angle", "frequency"]

LAYUP_FIELDS = (
    "specific_heat",
    "mass_per_length",
    "expansion_coeff",
    "youngs_modulus",
    "thickness",
    "width",
    "conductance",
    "bending_inertia",
)
"""The fields of a panel made by :meth:`Panel.from_laminate` that its layup decides."""


_TABLE_1: dict[str, float] = dict(_core.PAPER_PANEL)
"""The paper's Table 1 (Case B), C = 1361 W/m², χ = 1: defined once, in the engine."""


class PanelRange(NamedTuple):
    """The valid range of a panel parameter, the engine's: ``low`` to ``high`` (SI), ``high``
    included, ``low`` included unless ``low_open``."""

    low: float
    high: float
    low_open: bool

    def contains(self, value: float) -> bool:
        above = value > self.low if self.low_open else value >= self.low
        return above and value <= self.high


RANGES: Mapping[str, PanelRange] = MappingProxyType(
    {name: PanelRange(*bounds) for name, bounds in _core.PANEL_RANGES.items()}
)
"""Every panel parameter's valid range, as the engine checks it (``Panel.RANGES`` too)."""


def _parameter(name: str, unit: str) -> Any:
    """A Panel field: its default from Table 1 (the engine's), its SI unit in the metadata. The
    field's name, default, unit and range are then each written once (range and default in the
    engine); adding a parameter adds one line here."""
    return dataclasses.field(default=_TABLE_1[name], metadata={"unit": unit})


@field_type
@dataclass(frozen=True)
class Panel:
    """A long, thin, Sun-pointing plate of unit width; every value SI.

    Immutable and validated on construction: a bad value raises ``ParameterError`` naming it.
    Defaults are the paper's Table 1 (Case B), with C = 1361 W/m² and χ = 1; the valid range of
    each parameter is ``Panel.RANGES[name]`` (the engine's, a :class:`PanelRange`).
    """

    RANGES: ClassVar[Mapping[str, PanelRange]] = RANGES
    """The engine's range of each parameter, by name (read-only)."""

    emissivity_front: float = _parameter("emissivity_front", "-")
    """ε_f, emissivity of the Sun-facing side, in (0, 1]."""
    emissivity_back: float = _parameter("emissivity_back", "-")
    """ε_b, emissivity of the back side, in (0, 1]."""
    absorptivity: float = _parameter("absorptivity", "-")
    """α, solar absorptivity of the front side, in (0, 1]."""
    specific_heat: float = _parameter("specific_heat", "J/(kg K)")
    """c, J/(kg K)."""
    mass_per_length: float = _parameter("mass_per_length", "kg/m")
    """m, kg/m (unit width, so also kg/m²)."""
    expansion_coeff: float = _parameter("expansion_coeff", "1/K")
    """a, coefficient of thermal expansion, 1/K."""
    length: float = _parameter("length", "m")
    """L, m; the hinge model's half-arm is l = L/4."""
    youngs_modulus: float = _parameter("youngs_modulus", "Pa")
    """E, Pa."""
    thickness: float = _parameter("thickness", "m")
    """d, m."""
    width: float = _parameter("width", "m")
    """w, m."""
    conductance: float = _parameter("conductance", "W/(m² K)")
    """K, conductance through the thickness per unit area, W/(m² K)."""
    hinge_stiffness: float = _parameter("hinge_stiffness", "N m/rad")
    """K_el, N m/rad."""
    bending_inertia: float = _parameter("bending_inertia", "m⁴")
    """I, second moment of area, m⁴."""
    damping: float = _parameter("damping", "N m s/rad")
    """c_d, N m s/rad (>= 0)."""
    solar_constant: float = _parameter("solar_constant", "W/m²")
    """C, solar flux at 1 au, W/m²."""
    moment_scale: float = _parameter("moment_scale", "-")
    """χ, scale of the flexural rigidity in the thermal moment (paper Sec. 4.3)."""
    absorptivity_back: float = dataclasses.field(default=None, metadata={"unit": "-"})  # type: ignore[assignment]
    """α_b, solar absorptivity of the back side, in (0, 1]: what it absorbs of sunlight and of
    the Earth's albedo when they reach it. Default: equal to ``absorptivity``."""

    def __post_init__(self) -> None:
        if self.absorptivity_back is None:
            object.__setattr__(self, "absorptivity_back", self.absorptivity)
        checks.check_fields(self)
        _core.validate_panel(self.as_dict())

    @classmethod
    def paper(cls) -> Panel:
        """The paper's Table 1 panel (Case B: ε_f = 0.8, ε_b = 0.3)."""
        return cls()

    @classmethod
    def case_a(cls) -> Panel:
        """The paper's Case A: Table 1 with the emissivities swapped (ε_f = 0.3, ε_b = 0.8)."""
        return cls(**_core.CASE_A_PANEL)

    @classmethod
    def from_dict(cls, values: dict[str, Any]) -> Panel:
        """A panel from a mapping of parameter names (missing ones take Table 1 values)."""
        if not isinstance(values, dict):
            raise checks.wrong_type("values", values, "a dict")
        unknown = sorted(set(values) - set(cls.field_names()))
        if unknown:
            raise checks.ParameterError(
                str(unknown[0]), values[unknown[0]], "is not a panel parameter"
            )
        return cls(**values)

    @staticmethod
    def field_names() -> tuple[str, ...]:
        return tuple(f.name for f in fields(Panel))

    def replace(self, **changes: float) -> Panel:
        """A validated copy with some parameters changed.

        A panel made by :meth:`from_laminate` keeps its layup; the fields the layup decides
        (:data:`LAYUP_FIELDS`) cannot be changed on it (change the laminate instead)."""
        unknown = sorted(set(changes) - set(self.field_names()))
        if unknown:
            raise checks.ParameterError(unknown[0], changes[unknown[0]], "is not a panel parameter")
        if self.layup is not None:
            fixed = sorted(set(changes) & set(LAYUP_FIELDS))
            if fixed:
                raise checks.ParameterError(
                    fixed[0],
                    changes[fixed[0]],
                    message=f"{', '.join(fixed)} of a laminate panel follow from its layup: change "
                    "the Laminate and call Panel.from_laminate again",
                )
        copy = dataclasses.replace(self, **changes)
        object.__setattr__(copy, "_layup", self.layup)
        return copy

    @classmethod
    def from_laminate(
        cls,
        laminate: Laminate,
        *,
        length: float = _TABLE_1["length"],
        width: float = _TABLE_1["width"],
        hinge_stiffness: float | None = None,
        criterion: StiffnessCriterion = "deflection_small_angle",
        damping: float = _TABLE_1["damping"],
        solar_constant: float = _TABLE_1["solar_constant"],
        moment_scale: float = _TABLE_1["moment_scale"],
    ) -> Panel:
        """The panel of a laminate, carrying its layup (``panel.layup``).

        The engine derives, by classical lamination theory: the mass per area Σρh (times the
        width) and the specific heat that gives the heat capacity Σρch; E = Σ E h / d and
        I = w D / E, D the bending stiffness about the neutral axis (the modulus-weighted
        centroid); the two-layer conductance K = 1/Σ(h/k) between the two faces; and the
        expansion coefficient that gives a linear profile's thermal moment in a E I ΔT / d.
        The existing models run on these fields; ``layers=N`` runs the N-node model on the
        layup itself. ``hinge_stiffness`` defaults to K_el by ``criterion``.
        """
        checks.instance("laminate", laminate, Laminate, "a thermojitter.Laminate")
        base = cls(
            length=length,
            width=width,
            damping=damping,
            solar_constant=solar_constant,
            moment_scale=moment_scale,
            hinge_stiffness=1.0 if hinge_stiffness is None else hinge_stiffness,
        )
        properties = _core.laminate_properties(laminate.as_dict(), base.as_dict())
        fields_ = dict(properties["equivalent_panel"])
        panel = cls(**fields_)
        if hinge_stiffness is None:
            k_el = _hinge_stiffness(panel, criterion)
            panel = cls(**{**fields_, "hinge_stiffness": k_el})
        object.__setattr__(panel, "_layup", laminate)
        return panel

    @property
    def layup(self) -> Laminate | None:
        """The laminate this panel was made from (:meth:`from_laminate`), or None for a plain
        panel (one homogeneous layer to the N-node model)."""
        return self.__dict__.get("_layup")

    @cached_property
    def _values(self) -> dict[str, float]:
        """The parameters by name, built once: the panel is immutable, and every call into the
        engine passes them."""
        return {f.name: getattr(self, f.name) for f in fields(self)}

    def as_dict(self) -> dict[str, float]:
        return dict(self._values)

    @property
    def half_arm(self) -> float:
        """l = L/4, m."""
        return float(_core.derived(self.as_dict())["half_arm"])

    @property
    def hinge_inertia(self) -> float:
        """I_B = 2 m l³/3, kg m²."""
        return float(_core.derived(self.as_dict())["hinge_inertia"])


@field_type
@dataclass(frozen=True)
class Equilibrium(Persistent):
    """The sunlit steady state: temperatures (K), hinge angle (rad) and thermal moment (N m)."""

    T_front: float
    T_back: float
    theta: float
    thermal_moment: float

    @property
    def delta_T(self) -> float:
        """T_front − T_back, K."""
        return self.T_front - self.T_back

    @property
    def theta_deg(self) -> float:
        return math.degrees(self.theta)


PANEL_UNITS: dict[str, str] = {f.name: f.metadata["unit"] for f in fields(Panel)}
"""SI unit of each Panel field, for axis labels and tables."""


def _check_panel(panel: Any) -> None:
    checks.instance("panel", panel, Panel, "a thermojitter.Panel")


def steady_state(panel: Panel, *, coupled: bool = True, flux: float = 1.0) -> Equilibrium:
    """The panel's sunlit equilibrium (θ̇ = 0, all rates zero): ``coupled`` and ``flux`` as
    :func:`thermojitter.steady_state` takes them (which takes a :class:`thermojitter.Boom`
    too)."""
    _check_panel(panel)
    pd = panel.as_dict()
    tf, tb, th = _core.steady_state(pd, checks.flag("coupled", coupled), checks.real("flux", flux))
    moment = float(_core.moment(pd, np.array([tf]), np.array([tb]))[0])
    return Equilibrium(T_front=tf, T_back=tb, theta=th, thermal_moment=moment)


def natural_frequency(panel: Panel) -> float:
    """Natural frequency of the linearised hinge, sqrt(K_el/I_B)/2π, Hz."""
    _check_panel(panel)
    return float(_core.derived(panel.as_dict())["natural_frequency_hz"])


def beam_frequency(panel: Panel) -> float:
    """First free–free bending frequency of the continuous panel, (β₁L)² sqrt(EI/(mL⁴))/2π, Hz."""
    _check_panel(panel)
    return float(_core.derived(panel.as_dict())["beam_frequency_hz"])


def hinge_stiffness(panel: Panel, criterion: StiffnessCriterion = "deflection") -> float:
    """K_el (N m/rad) by one of the paper's criteria.

    - ``"deflection"``: equal mid-span deflection under the panel's steady sunlit thermal moment,
      K_el = M_T / asin(M_T L / 4EI).
    - ``"deflection_small_angle"``: its small-angle limit, 4EI/L.
    - ``"frequency"``: equal first free–free frequency, (β₁L)⁴ EI I_B/(m L⁴) ≈ 5.21 EI/L.
    """
    _check_panel(panel)
    checks.choice("criterion", criterion, ("deflection", "deflection_small_angle", "frequency"))
    moment = 0.0
    if criterion == "deflection":
        moment = steady_state(panel).thermal_moment
    return float(_core.stiffness(panel.as_dict(), criterion, moment))


_hinge_stiffness = hinge_stiffness  # for Panel.from_laminate, whose keyword shadows the name
