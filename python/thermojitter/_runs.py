"""What every run function shares: its span, its start state, the engine's ``run`` mapping of
its integrator and reporting times, the validity limit it watches, and the fields its result
takes from the engine's answer. Below the run functions of every structure (the panel's in
``simulate``, the boom's in ``boom``), so each builds its engine call here, once."""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from thermojitter import _core
from thermojitter import errors as checks
from thermojitter.errors import ParameterError, ValidityLimitWarning
from thermojitter.results import LimitCrossing
from thermojitter.solver import SolverSettings

DEFAULT_THETA_LIMIT: float = _core.VALIDITY_LIMIT
"""abs(θ) beyond which the hinge model is not trusted, rad (20°; its rigid halves and cos θ
coupling are meant for modest angles): the engine's ``dynamics::VALIDITY_LIMIT``."""

ON_LIMIT = ("flag", "stop", "ignore")
"""What a run does when its angle passes ``theta_limit``: record the first crossing and warn
(``"flag"``), also end the run there (``"stop"``), or nothing (``"ignore"``)."""

DEFAULT_DT_OUT = 0.5
"""Default reporting interval, s: 16 samples per period of the paper panel's ~8 s jitter."""


def time_span(t_span: Sequence[float]) -> tuple[float, float]:
    if isinstance(t_span, (str, bytes)) or not isinstance(t_span, (Sequence, np.ndarray)):
        raise checks.wrong_type("t_span", t_span, "a pair of numbers (t0, t1) in s")
    if len(t_span) != 2:
        raise ParameterError("t_span", t_span, "must be two numbers (t0, t1) in s")
    # Finite and within the engine's reach, checked before any arithmetic on them.
    reach = (-_core.MAX_TIME, _core.MAX_TIME)
    return checks.in_range("t_span[0]", t_span[0], *reach, "s"), checks.in_range(
        "t_span[1]", t_span[1], *reach, "s"
    )


def _times(t_eval: ArrayLike | None) -> np.ndarray | None:
    if t_eval is None:
        return None
    return checks.real_array("t_eval", t_eval)


def start_state(y0: Any, size: int | None) -> list[float] | None:
    """A start state of ``size`` real numbers (None: any size, the engine knows it); the engine
    checks their values (temperatures > 0 K, θ and θ̇ in the hinge's range)."""
    if y0 is None:
        return None
    arr = checks.real_array("y0", y0, finite_only=False)
    if size is not None and arr.size != size:
        raise ParameterError("y0", y0, f"must hold {size} numbers")
    return [float(v) for v in arr]


def solver_args(
    solver: SolverSettings,
    span: tuple[float, float],
    t_eval: ArrayLike | None,
    dt_out: float | None,
) -> dict[str, Any]:
    """The engine's ``run`` mapping (``RunOptions`` in rust/src/bindings/convert.rs) for the
    integrator, the span and the reporting times; a run adds its ``y0`` and, when it watches the
    validity limit, its ``limit`` (:func:`limit_args`)."""
    if t_eval is None and dt_out is None:
        dt_out = DEFAULT_DT_OUT
    return {
        "span": span,
        "solver": solver.as_dict(),
        "t_eval": _times(t_eval),
        "dt_out": None if dt_out is None else checks.real("dt_out", dt_out),
    }


def run_settings(
    solver: SolverSettings | None,
    span: tuple[float, float],
    t_eval: ArrayLike | None,
    dt_out: float | None,
    **keywords: Any,
) -> tuple[SolverSettings, dict[str, Any]]:
    """The integrator settings of one run over ``span`` (``solver``, or the run function's
    ``keywords``: see :meth:`SolverSettings.of`) and the engine's ``run`` mapping for them and the
    reporting times (:func:`solver_args`): every run function builds its engine call's options
    here, once."""
    used = SolverSettings.of(solver, **keywords)
    return used, solver_args(used, span, t_eval, dt_out)


def run_record(raw: Mapping[str, Any], used: SolverSettings) -> dict[str, Any]:
    """The fields every run's result takes from the engine's answer: the times, the step and
    right-hand-side counts, and the method."""
    return {
        "t": raw["t"],
        "n_steps": int(raw["n_steps"]),
        "n_rejected": int(raw["n_rejected"]),
        "n_rhs": int(raw["n_rhs"]),
        "method": used.method,
    }


def limit_record(raw: Mapping[str, Any]) -> dict[str, Any]:
    """The validity limit's fields of a run's result: where it was first crossed, and whether
    the run stopped there."""
    return {
        "limit_crossing": LimitCrossing.of(raw["crossing"]),
        "stopped_at_limit": bool(raw["stopped"]),
    }


def limit_args(theta_limit: Any, on_limit: Any) -> dict[str, Any]:
    """The engine's keyword arguments of the validity limit, their types checked (the engine
    checks theta_limit's range, 0 < theta_limit <= π/2, whatever on_limit)."""
    return {
        "theta_limit": checks.real("theta_limit", theta_limit),
        "on_limit": checks.choice("on_limit", on_limit, ON_LIMIT),
    }


DISTRIBUTED_LIMIT = ("θ_f", "the distributed panel")
"""The angle a distributed run's limit is read on, and the model whose validity it bounds."""


def warn_crossing(
    crossing: LimitCrossing | None,
    theta_limit: float,
    on_limit: str,
    angle: str = "θ",
    *,
    stacklevel: int = 3,
    model: str = "the hinge model",
) -> None:
    """The one :class:`ValidityLimitWarning` of a call whose run passed ``theta_limit``
    (``angle`` as the model names it, ``model`` whose range of validity it left)."""
    if crossing is None:
        return
    then = "the run stopped there" if on_limit == "stop" else "the result beyond means nothing"
    warnings.warn(
        f"{angle} passed theta_limit = {math.degrees(theta_limit):.4g}° at "
        f"t = {crossing.t:.6g} s (orbit {crossing.orbit}): {angle} = "
        f"{crossing.theta_deg:.4g}°, beyond {model}'s range of validity; {then} "
        "(result.limit_crossing; on_limit='ignore' silences this)",
        ValidityLimitWarning,
        stacklevel=stacklevel,
    )
