"""The integrator's settings: one object, its defaults written once (in the engine).

:class:`SolverSettings` holds what every run function's ``method``, ``rtol``, ``atol``, ``dt``,
``max_step`` and ``max_steps`` keywords say. Its defaults are the engine's
(``Tolerances::default`` in ``rust/src/integrate/mod.rs``, exported as ``_core.SOLVER_DEFAULTS``),
and it is validated on construction: the types here (a bool or a string is not a number), the
values by the engine's own check, the one every run goes through. A run function takes either the
keywords or ``solver=SolverSettings(...)``, and its result reports the settings the engine used.
"""

from __future__ import annotations

import dataclasses
import functools
from collections.abc import Mapping
from typing import Any, Literal

from thermojitter import _core
from thermojitter import errors as checks
from thermojitter.persist import field_type

DEFAULTS: dict[str, Any] = dict(_core.SOLVER_DEFAULTS)
"""method "rk45", rtol, atol, max_step (s), max_steps."""
RTOL: float = DEFAULTS["rtol"]
ATOL: float = DEFAULTS["atol"]
MAX_STEP: float = DEFAULTS["max_step"]
MAX_STEPS: int = DEFAULTS["max_steps"]
METHODS = ("rk45", "rk4")


@field_type
@dataclasses.dataclass(frozen=True)
class SolverSettings:
    """How a run integrates: ``method`` ``"rk45"`` (Dormand–Prince 5(4), error control by
    ``rtol``/``atol``, step at most ``max_step`` s) or ``"rk4"`` (classical, fixed step ``dt`` s);
    at most ``max_steps`` steps (accepted + rejected). Immutable; a bad value raises
    :class:`thermojitter.ParameterError` naming it when the object is made. Every run function
    takes it as ``solver=``, e.g. ``tj.simulate(panel, orbit, span, solver=fine)`` with
    ``fine = tj.SolverSettings(rtol=1e-10, atol=1e-12)``.
    """

    method: Literal["rk45", "rk4"] = DEFAULTS["method"]
    rtol: float = RTOL
    atol: float = ATOL
    dt: float | None = None
    max_step: float = MAX_STEP
    max_steps: int = MAX_STEPS

    def __post_init__(self) -> None:
        checked = {
            "method": checks.choice("method", self.method, METHODS),
            "rtol": checks.real("rtol", self.rtol),
            "atol": checks.real("atol", self.atol),
            "dt": None if self.dt is None else checks.real("dt", self.dt),
            "max_step": checks.real("max_step", self.max_step),
            "max_steps": checks.integer("max_steps", self.max_steps, 1),
        }
        for name, value in checked.items():
            object.__setattr__(self, name, value)
        # Kept as made (the object is immutable): every run passes them to the engine.
        object.__setattr__(self, "_items", tuple(checked.items()))
        _core.check_solver(self.as_dict())

    def as_dict(self) -> dict[str, Any]:
        """The settings as the engine takes them (a plain mapping)."""
        return dict(self._items)  # type: ignore[attr-defined]

    def replace(self, **changes: Any) -> SolverSettings:
        """A validated copy with ``changes``."""
        return dataclasses.replace(self, **changes)

    @classmethod
    def of(cls, solver: SolverSettings | None, **keywords: Any) -> SolverSettings:
        """The settings of one run: ``solver`` when given, else those of the ``keywords``
        (``method``, ``rtol``, …; ``method=None`` leaves the method at its default). Given both,
        a keyword set away from its default and from ``solver``'s value is refused rather than
        silently ignored."""
        given = {k: v for k, v in keywords.items() if not (k == "method" and v is None)}
        if solver is None:
            # Runs repeat the same few settings: each distinct set is checked once. The key holds
            # each value's type, so True is not taken for 1.
            key = tuple((k, type(v), v) for k, v in given.items())
            try:
                return _checked(key)
            except TypeError as exc:
                if "unhashable" not in str(exc):
                    raise
                return cls(**given)
        if not isinstance(solver, SolverSettings):
            raise checks.wrong_type("solver", solver, "a thermojitter.SolverSettings")
        default = cls.__dataclass_fields__
        clash = [k for k, v in given.items() if v != default[k].default and v != getattr(solver, k)]
        if clash:
            raise checks.ParameterError(
                "solver", solver, f"give solver= or {', '.join(clash)}, not both"
            )
        return solver


@functools.lru_cache(maxsize=64)
def _checked(key: tuple[tuple[str, type, Any], ...]) -> SolverSettings:
    """The settings of ``key`` ((name, type, value) triples), checked once (a refused set is not
    cached: its error is raised again on every call)."""
    return SolverSettings(**{name: value for name, _, value in key})


@field_type
@dataclasses.dataclass(frozen=True)
class HybridSettings:
    """How ``method="hybrid"`` propagates (see :func:`thermojitter.simulate_orbits`): every
    field None keeps the engine's own default (``HybridSettings::default`` in the engine, the
    one home of those numbers).

    - ``rtol``, ``atol_temperature`` (K), ``atol_angle`` (rad), ``max_step`` (s): error control
      of the exponential integrator through the shadows;
    - ``linear_tolerance`` (rad): largest non-linear remainder, as a static angle error, at which
      the state is handed back to the exact linear arcs;
    - ``linear_amplitude`` (rad): largest oscillation about the equilibrium propagated linearly;
    - ``resolved_amplitude`` (rad): largest oscillation left to the exponential integrator.

    Immutable; the types are checked here (a real number or None), the values by the engine
    (each > 0) when a run starts, naming ``hybrid.<field>``. ``simulate_orbits`` takes it as
    ``hybrid=``, or the same keys as a dict.
    """

    rtol: float | None = None
    atol_temperature: float | None = None
    atol_angle: float | None = None
    max_step: float | None = None
    linear_tolerance: float | None = None
    linear_amplitude: float | None = None
    resolved_amplitude: float | None = None

    def __post_init__(self) -> None:
        for f in dataclasses.fields(self):
            value = getattr(self, f.name)
            if value is not None:
                object.__setattr__(self, f.name, checks.real(f"hybrid.{f.name}", value))

    def as_dict(self) -> dict[str, float]:
        """The settings given (None left out: the engine's default), as the engine takes them."""
        return {
            f.name: getattr(self, f.name)
            for f in dataclasses.fields(self)
            if getattr(self, f.name) is not None
        }

    def replace(self, **changes: Any) -> HybridSettings:
        """A checked copy with ``changes``."""
        return dataclasses.replace(self, **changes)

    @classmethod
    def of(cls, hybrid: HybridSettings | Mapping[str, Any] | None) -> HybridSettings:
        """``hybrid`` as settings: a HybridSettings as it is, None as the engine's defaults, a
        mapping by its keys (a key that is no setting is refused, naming it)."""
        if hybrid is None:
            return cls()
        if isinstance(hybrid, HybridSettings):
            return hybrid
        if not isinstance(hybrid, Mapping):
            raise checks.wrong_type(
                "hybrid", hybrid, "a thermojitter.HybridSettings or a dict of its fields"
            )
        known = [f.name for f in dataclasses.fields(cls)]
        for key, value in hybrid.items():
            if key not in known:
                raise checks.ParameterError(
                    f"hybrid.{key}",
                    value,
                    message=f"hybrid = {{{key!r}: ...}} is invalid: not a hybrid setting; "
                    f"the settings are {', '.join(known)}",
                )
        return cls(**hybrid)
