"""The boom: a thin-walled circular tube cantilevered from the spacecraft, lit on one side.

Its thermal model is the classical thin-walled one (the mean temperature T̄ and the
circumferential perturbation T_m cos φ), its structure the cantilever's first mode as an
equivalent hinge (with the tip mass), coupled through the thermal moment π E a h r² T_m and the
Sun's incidence on the deflected tube. Every equation is the engine's (``models/tube.rs``,
``inputs/boom.rs``); this module validates, converts and presents.

A :class:`Boom` goes where a :class:`thermojitter.Panel` goes: :func:`thermojitter.simulate`,
:func:`thermojitter.flutter`, :func:`thermojitter.simulate_orbits`,
:func:`thermojitter.steady_state`, scenario files (a ``[boom]`` table) and the command line.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from dataclasses import InitVar, dataclass, fields
from functools import cached_property
from types import MappingProxyType
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike

from thermojitter import _core, _runs, materials
from thermojitter import errors as checks
from thermojitter.attitude import Attitude
from thermojitter.orbit import Orbit
from thermojitter.progress import interruptible
from thermojitter.results import Array, LimitCrossing, _Run
from thermojitter.solver import SolverSettings

_EXAMPLE: dict[str, float] = dict(_core.BOOM_EXAMPLE)
"""The engine's example boom (a 1963-22A-like beryllium–copper tube), whose values are the
defaults of the optical and support parameters."""

MATERIAL_FIELDS = ("density", "youngs_modulus", "expansion_coeff", "conductivity", "specific_heat")
"""The fields a boom takes from its ``material`` unless given."""


def check_attitude(attitude: Any) -> None:
    """Refuses an attitude other than Sun-pointing for a boom, naming ``attitude``: its model
    takes the Sun alone on its lit side (the engine refuses an orbit with Earth heating)."""
    if attitude is not None and Attitude.of(attitude).kind != "sun_pointing":
        raise checks.ParameterError(
            "attitude", attitude, "a boom takes the Sun alone on its lit side (not an attitude)"
        )


DEFAULT_MATERIAL = "beryllium_copper"
"""The material of a boom given none: beryllium copper, the STEM booms' classical alloy."""

BOOM_RANGES: Mapping[str, tuple[float, float, bool]] = MappingProxyType(
    {
        name: (float(lo), float(hi), bool(open_))
        for name, (lo, hi, open_) in _core.BOOM_RANGES.items()
    }
)
"""Every boom parameter's range as the engine checks it: (low, high, low end open)."""


def _from_material() -> Any:
    """A material field: NaN until ``__post_init__`` fills it from the material."""
    return dataclasses.field(default=math.nan)


def _parameter(name: str) -> Any:
    return dataclasses.field(default=_EXAMPLE[name])


@dataclass(frozen=True)
class Boom:
    """A thin-walled circular tube of ``length`` L (m), mean ``radius`` r (m) and ``wall`` h (m,
    at most r/5), cantilevered from the spacecraft with a ``tip_mass`` (kg); every value SI,
    angles in rad.

    ``material``: a :class:`thermojitter.materials.Material` or its key (default beryllium
    copper) giving ``density``, ``youngs_modulus``, ``expansion_coeff``, ``conductivity`` and
    ``specific_heat``; any of them given here wins over the material's.

    ``absorptivity`` α and ``emissivity`` ε of the outer surface (the silver plating of the
    gravity-gradient booms lowered α), ``emissivity_inner`` ε_i (radiation across the tube; 0:
    none), ``conduction_scale`` η (the share of the closed tube's circumferential conduction an
    open or overlapped section has), ``damping`` ζ (the first mode's damping ratio),
    ``solar_constant`` C (W/m²), ``solar_inclination`` ψ (the Sun's angle to the boom's axis
    from root to tip, in (0, π): below π/2 the tip leans toward the Sun, above it away; π/2
    lights it square on) and ``moment_scale`` (an extra scale of the thermal moment, 1: none).

    The equivalent hinge: θ is the tip deflection over L (positive away from the Sun), with the
    first mode's inertia, the cantilever's first frequency and the static tip deflection of the
    uniform thermal curvature a T_m / r (the engine's ``inputs/boom.rs`` states the
    equivalence); :attr:`derived` holds it.
    """

    length: float
    radius: float
    wall: float
    material: InitVar[materials.Material | str | None] = None
    density: float = _from_material()
    """ρ, kg/m³."""
    youngs_modulus: float = _from_material()
    """E, Pa."""
    expansion_coeff: float = _from_material()
    """a, 1/K (either sign: CFRP booms shrink when heated)."""
    conductivity: float = _from_material()
    """k, W/(m K)."""
    specific_heat: float = _from_material()
    """c, J/(kg K)."""
    absorptivity: float = _parameter("absorptivity")
    """α, solar absorptivity of the outer surface, in (0, 1]."""
    emissivity: float = _parameter("emissivity")
    """ε, infrared emissivity of the outer surface, in (0, 1]."""
    emissivity_inner: float = _parameter("emissivity_inner")
    """ε_i, emissivity of the inner surface (radiation across the tube), in [0, 1]."""
    conduction_scale: float = _parameter("conduction_scale")
    """η, share of the closed tube's circumferential conduction, in (0, 1]."""
    damping: float = _parameter("damping")
    """ζ, damping ratio of the first bending mode."""
    tip_mass: float = _parameter("tip_mass")
    """M_t, kg."""
    solar_constant: float = _parameter("solar_constant")
    """C, W/m² at 1 au."""
    solar_inclination: float = _parameter("solar_inclination")
    """ψ, rad, in (0, π)."""
    moment_scale: float = _parameter("moment_scale")
    """Extra scale of the thermal moment (1: none)."""

    RANGES: ClassVar[Mapping[str, tuple[float, float, bool]]] = BOOM_RANGES

    def __post_init__(self, material: materials.Material | str | None) -> None:
        if material is None:
            material = DEFAULT_MATERIAL
        if isinstance(material, str):
            material = materials.get(material)
        checks.instance("material", material, materials.Material, "a material or its key")
        for name in MATERIAL_FIELDS:
            value = getattr(self, name)
            if isinstance(value, float) and math.isnan(value):
                object.__setattr__(self, name, getattr(material, name))
        checks.check_fields(self)
        _core.boom_derived(self.as_dict())

    @staticmethod
    def field_names() -> tuple[str, ...]:
        return tuple(f.name for f in fields(Boom))

    @classmethod
    def from_dict(cls, values: Mapping[str, Any]) -> Boom:
        """A boom from a mapping of its parameters (and optionally ``material``)."""
        if not isinstance(values, Mapping):
            raise checks.wrong_type("values", values, "a mapping")
        unknown = sorted(set(values) - set(cls.field_names()) - {"material"})
        if unknown:
            raise checks.ParameterError(unknown[0], values[unknown[0]], "is not a boom parameter")
        for name in ("length", "radius", "wall"):
            if name not in values:
                raise checks.ParameterError(name, None, "is required")
        return cls(**values)

    def replace(self, **changes: float) -> Boom:
        """A validated copy with some parameters changed."""
        unknown = sorted(set(changes) - set(self.field_names()))
        if unknown:
            raise checks.ParameterError(unknown[0], changes[unknown[0]], "is not a boom parameter")
        return dataclasses.replace(self, **changes)  # type: ignore[arg-type]

    def as_dict(self) -> dict[str, float]:
        return {f.name: getattr(self, f.name) for f in fields(self)}

    @cached_property
    def derived(self) -> dict[str, Any]:
        """What the engine derives: ``mass_per_length`` (kg/m), ``bending_inertia`` (m⁴),
        ``heat_capacity`` (ρ c h, J/(m² K)), ``time_constant`` τ of T_m (s),
        ``sunlit_mean_temperature`` (K), ``first_angular_frequency`` ω₁ (rad/s), ``beta1_l``,
        and the equivalent hinge: ``hinge_inertia`` (kg m²), ``hinge_stiffness`` (N m/rad),
        ``hinge_damping`` (N m s/rad), ``hinge_moment_scale`` χ, ``moment_per_kelvin`` (N m/K
        of T_m)."""
        return dict(_core.boom_derived(self.as_dict()))

    @property
    def first_frequency(self) -> float:
        """f₁, the cantilever's first bending frequency with its tip mass, Hz."""
        return float(self.derived["first_angular_frequency"]) / (2.0 * math.pi)

    @property
    def time_constant(self) -> float:
        """τ, the thermal time constant of T_m, s."""
        return float(self.derived["time_constant"])

    @property
    def response_time_ratio(self) -> float:
        """B = ω₁ τ, the ratio of the thermal to the structural response time (Boley's)."""
        return float(self.derived["first_angular_frequency"]) * self.time_constant


@dataclass(frozen=True)
class BoomEquilibrium:
    """The boom's steady state: ``T_mean`` T̄ and ``T_circ`` T_m (K), θ (rad, the tip
    deflection over the length), the thermal moment (N m) and the tip deflection (m)."""

    T_mean: float
    T_circ: float
    theta: float
    thermal_moment: float
    tip_deflection: float


def boom_steady_state(boom: Boom, *, coupled: bool = True, flux: float = 1.0) -> BoomEquilibrium:
    """The boom's steady state under the flux factor ``flux`` (1: the Sun at 1 au, unshadowed)."""
    checks.instance("boom", boom, Boom, "a thermojitter.Boom")
    y = _core.boom_steady_state(
        boom.as_dict(), checks.flag("coupled", coupled), checks.real("flux", flux)
    )
    return _equilibrium(boom, y)


def _equilibrium(boom: Boom, y: Sequence[float]) -> BoomEquilibrium:
    return BoomEquilibrium(
        T_mean=float(y[0]),
        T_circ=float(y[1]),
        theta=float(y[2]),
        thermal_moment=float(y[1]) * float(boom.derived["moment_per_kelvin"]),
        tip_deflection=boom.length * float(y[2]),
    )


@dataclass(frozen=True)
class BoomSolution(_Run):
    """A boom's transient: ``T_mean`` T̄ and ``T_circ`` T_m (K), θ (rad: tip deflection over
    the length, positive away from the Sun), θ̇ (rad/s), the thermal moment on the hinge (N m),
    ``sunlit`` s(t), and the limit's crossing as :class:`thermojitter.Solution` has it."""

    length: float = 0.0
    T_mean: Array = dataclasses.field(default_factory=lambda: np.empty(0))
    T_circ: Array = dataclasses.field(default_factory=lambda: np.empty(0))
    theta: Array = dataclasses.field(default_factory=lambda: np.empty(0))
    theta_dot: Array = dataclasses.field(default_factory=lambda: np.empty(0))
    thermal_moment: Array = dataclasses.field(default_factory=lambda: np.empty(0))
    sunlit: Array = dataclasses.field(default_factory=lambda: np.empty(0))
    y_end: Array = dataclasses.field(default_factory=lambda: np.empty(0))
    limit_crossing: LimitCrossing | None = None
    stopped_at_limit: bool = False

    @property
    def tip_deflection(self) -> Array:
        """L θ, the tip's deflection away from the Sun, m."""
        return self.length * self.theta

    @property
    def y(self) -> Array:
        """The state (T_mean, T_circ, theta, theta_dot) as a (4, n) array."""
        return np.vstack([self.T_mean, self.T_circ, self.theta, self.theta_dot])

    COLUMNS: ClassVar[tuple[str, ...]] = (
        "T_mean", "T_circ", "theta", "theta_dot", "thermal_moment", "sunlit",
    )  # fmt: skip
    """The run's columns, in the engine's order."""

    def _columns(self) -> dict[str, Array]:
        return {name: getattr(self, name) for name in self.COLUMNS}


def simulate_boom(
    boom: Boom,
    orbit: Orbit,
    t_span: Sequence[float],
    *,
    coupled: bool = True,
    t_eval: ArrayLike | None = None,
    dt_out: float | None = None,
    y0: Sequence[float] | None = None,
    solver: SolverSettings | None = None,
    theta_limit: float | None = None,
    on_limit: str = "flag",
    **integrator: Any,
) -> BoomSolution:
    """Integrates the boom over ``t_span`` (s), as :func:`thermojitter.simulate` a panel (which
    calls this for a :class:`Boom`): ``y0`` is (T_mean K, T_circ K, θ rad, θ̇ rad/s), default
    the steady state at the start's flux; ``coupled=False`` freezes the incidence;
    ``integrator``: ``method``, ``rtol``, ``atol``, ``dt``, ``max_step``, ``max_steps`` as
    :func:`thermojitter.simulate` takes them (or ``solver``)."""
    checks.instance("boom", boom, Boom, "a thermojitter.Boom")
    checks.instance("orbit", orbit, Orbit, "a thermojitter.Orbit")
    used, options = _runs.run_settings(
        solver, _runs.time_span(t_span), t_eval, dt_out, **integrator
    )
    limit = _runs.DEFAULT_THETA_LIMIT if theta_limit is None else theta_limit
    options["limit"] = _runs.limit_args(limit, on_limit)
    options["y0"] = _runs.start_state(y0, 4)
    raw = interruptible(
        _core.simulate_boom,
        boom.as_dict(),
        orbit.as_dict(),
        options,
        coupled=checks.flag("coupled", coupled),
    )
    settings = {"rtol": used.rtol, "atol": used.atol, "dt": used.dt, "coupled": coupled}
    sol = BoomSolution(
        **_runs.run_record(raw, used),
        settings={**settings, "boom": boom.as_dict(), "solver": dict(raw["solver"])},
        length=boom.length,
        **{name: raw[name] for name in (*BoomSolution.COLUMNS, "y_end")},
        **_runs.limit_record(raw),
    )
    _runs.warn_crossing(sol.limit_crossing, limit, on_limit, stacklevel=4)
    return sol


@dataclass(frozen=True)
class BoomStabilityMap:
    """A boom's thermal flutter over the solar inclination ψ (rows, rad) and the ratio
    B = ω₁ τ of the thermal to the structural response time (columns; each point's
    conductivity set to give it): ``growth_rate`` (1/s, at the boom's own damping) and
    ``critical_damping`` (the damping ratio ζ that suppresses flutter; 0 where the undamped
    boom is stable)."""

    inclination: Array
    ratio: Array
    growth_rate: Array
    critical_damping: Array

    @property
    def stable(self) -> Any:
        return self.growth_rate < 0.0


def boom_stability_map(
    boom: Boom,
    inclinations: ArrayLike,
    ratios: ArrayLike,
    *,
    coupled: bool = True,
    flux: float = 1.0,
) -> BoomStabilityMap:
    """:class:`BoomStabilityMap` of ``boom`` over ``inclinations`` (ψ, rad, in (0, π)) and
    ``ratios`` (B = ω₁ τ > 0, up to the radiation's own time constant; a ratio beyond it is
    refused naming ``ratio``)."""
    checks.instance("boom", boom, Boom, "a thermojitter.Boom")
    psi = checks.real_array("inclinations", inclinations)
    b = checks.real_array("ratios", ratios)
    raw = interruptible(
        _core.boom_stability_map,
        boom.as_dict(),
        [float(v) for v in psi],
        [float(v) for v in b],
        checks.flag("coupled", coupled),
        checks.real("flux", flux),
    )
    shape = (psi.size, b.size)
    return BoomStabilityMap(
        inclination=psi,
        ratio=b,
        growth_rate=np.asarray(raw["growth_rate"], dtype=float).reshape(shape),
        critical_damping=np.asarray(raw["critical_damping"], dtype=float).reshape(shape),
    )
