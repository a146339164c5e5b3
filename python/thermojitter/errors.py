"""The exceptions thermojitter raises, and the checks that name a bad argument.

- :class:`ParameterError` (a ``ValueError``): a value outside its allowed range. It carries the
  parameter's name, the value and the allowed range as attributes, so that callers (the scenario
  parser, Monte Carlo) never read them out of the message.
- :class:`ParameterTypeError` (a ``ParameterError`` and a ``TypeError``): a value of the wrong
  type, with the same attributes. Types are checked, not coerced: a bool is not a number, None is
  not False, a string is not a number. ``except TypeError`` and ``except ParameterError`` both
  catch it.

Every refusal of the package is one of these two, raised here or through the helpers below (the
test oracle ``reference.py`` aside): ``parameter`` is the argument's name as the caller wrote it,
``value`` the value itself (a number stays a number).
- :class:`IntegrationError`, :class:`ConvergenceError` (``RuntimeError``, from the engine): a run
  that could not finish, a solve that did not converge.
- :class:`InternalError` (``RuntimeError``): a defect caught at the engine's boundary (a panic);
  the call's result is lost but the process lives on.
- :class:`SampleFailureWarning` (a ``RuntimeWarning``): some samples of a study (Monte Carlo,
  sweep, sensitivity) failed; their rows are kept with the reason and no numbers.
  ``thermojitter.montecarlo.AllSamplesFailedError`` (an ``IntegrationError``, defined beside the
  studies because this module does not import the engine): every sample of a study failed.
- :class:`ValidityLimitWarning` (a warning, not an error): a run's angle passed ``theta_limit``,
  beyond which the hinge model means nothing; the result says where (``limit_crossing``).
- :class:`HybridFallbackWarning` (a warning): a run asked of the hybrid propagator was
  integrated in full instead, its sunlit forcing varying (Earth heating, another attitude).

This module imports nothing from the engine: the engine's binding layer builds its
``ParameterError`` from here.
"""

from __future__ import annotations

import dataclasses
import math
import numbers
import os
from collections.abc import Collection, Mapping
from pathlib import Path
from typing import Any

import numpy as np


class ParameterError(ValueError):
    """A value outside its allowed range.

    ``parameter``: the argument's name (dotted for nested ones, e.g. ``"vary.damping"``);
    ``value``: the value given; ``allowed``: the allowed range or choices in words, or None.
    """

    def __init__(
        self, parameter: str, value: Any, allowed: str | None = None, message: str | None = None
    ) -> None:
        self.parameter = parameter
        self.value = value
        self.allowed = allowed
        if message is None:
            message = f"{parameter} = {_shown(value)} is invalid"
            if allowed:
                message += f": {allowed}"
        super().__init__(message)

    def __reduce__(self) -> tuple[Any, ...]:
        # Crosses process boundaries (Monte Carlo workers) with its attributes.
        return (type(self), (self.parameter, self.value, self.allowed, str(self)))


class ParameterTypeError(ParameterError, TypeError):
    """A value of the wrong type (a string for a number, None for a flag, a dict for a panel).

    A :class:`ParameterError` (``parameter``, ``value``, ``allowed``: here the type expected, in
    words) and a ``TypeError``, so that ``except TypeError`` keeps catching it."""


def wrong_type(
    name: str, value: Any, expected: str, message: str | None = None
) -> ParameterTypeError:
    """The refusal of ``value`` for ``name``, which must be ``expected`` (words: "a real number",
    "a thermojitter.Panel"); the message says what was given."""
    if message is None:
        message = f"{name} must be {expected}, not {type_name(value)}"
    return ParameterTypeError(name, value, expected, message)


def _shown(value: Any) -> str:
    """``value`` as a message shows it: a repr of hundreds of characters (an integer of 400
    digits) is cut, saying how long it was."""
    text = repr(value)
    return text if len(text) <= 60 else f"{text[:24]}… ({len(text)} characters)"


class InternalError(RuntimeError):
    """A defect in thermojitter caught at the engine's boundary (a Rust panic). Please report it
    with the call that raised it."""


class SampleFailureWarning(RuntimeWarning):
    """Some samples of a study could not be computed. The study goes on: each failed sample keeps
    its row, with the reason in its ``error`` column, ``stable`` missing (pandas NA) and its numbers
    NaN; ``frame.attrs["n_failed"]`` counts them."""


class ValidityLimitWarning(UserWarning):
    """A run's hinge angle (θ, or θ_f of the distributed panel) passed ``theta_limit``: the hinge
    model is not trusted beyond it (its rigid halves and cos θ coupling are meant for modest
    angles). Issued once per call; the result's ``limit_crossing`` says when and where. Silence
    it with ``on_limit="ignore"`` or :mod:`warnings` filters."""


class HybridFallbackWarning(UserWarning):
    """A run asked of the hybrid propagator was integrated in full (hinge resolved) instead: its
    sunlit forcing varies (Earth heating, an attitude other than Sun-pointing), which the
    hybrid's arcs take as constant. The result is the full integration's; its settings say so
    under ``"hybrid_fallback"``."""


def type_name(value: Any) -> str:
    return type(value).__name__


def real(name: str, value: Any) -> float:
    """``value`` as a float if it is a real number (int, float, NumPy scalar; not bool, not a
    string, not None); a TypeError naming ``name`` otherwise, a ParameterError for an integer
    too large for a float."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Real):
        raise wrong_type(
            name,
            value,
            "a real number",
            f"{name} must be a real number, not {type_name(value)} {value!r:.60}",
        )
    try:
        return float(value)
    except OverflowError:
        raise ParameterError(name, value, "too large for a float (|x| < 1.8e308)") from None


def finite(name: str, value: Any) -> float:
    """A finite real number."""
    x = real(name, value)
    if not math.isfinite(x):
        raise ParameterError(name, value, "must be finite")
    return x


def positive(name: str, value: Any) -> float:
    """A finite real number > 0."""
    x = real(name, value)
    if not (math.isfinite(x) and x > 0.0):
        raise ParameterError(name, value, "must be finite and > 0")
    return x


def in_range(name: str, value: Any, low: float, high: float, unit: str = "") -> float:
    """A real number in [low, high]."""
    x = real(name, value)
    if not (low <= x <= high):
        suffix = f" {unit}" if unit else ""
        raise ParameterError(name, value, f"must be in [{low:g}, {high:g}]{suffix}")
    return x


def instance(name: str, value: Any, cls: type | tuple[type, ...], expected: str) -> Any:
    """``value`` if it is an instance of ``cls``; a :class:`ParameterTypeError` naming ``name``
    otherwise (``expected`` in words: "a thermojitter.Panel")."""
    if not isinstance(value, cls):
        raise wrong_type(name, value, expected)
    return value


def optional_positive(name: str, value: Any) -> float | None:
    return None if value is None else positive(name, value)


def integer(name: str, value: Any, minimum: int = 1, maximum: int | None = None) -> int:
    """An int (Python or NumPy, not bool) in [minimum, maximum]."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
        raise wrong_type(
            name,
            value,
            "an integer",
            f"{name} must be an integer, not {type_name(value)} {value!r:.60}",
        )
    n = int(value)
    if n < minimum or (maximum is not None and n > maximum):
        allowed = f"must be an integer >= {minimum}"
        if maximum is not None:
            allowed = f"must be an integer in [{minimum}, {maximum}]"
        raise ParameterError(name, value, allowed)
    return n


def flag(name: str, value: Any) -> bool:
    """A bool (or NumPy bool): None, 0/1 and strings are refused, not read as truth values."""
    if not isinstance(value, (bool, np.bool_)):
        raise wrong_type(
            name,
            value,
            "True or False",
            f"{name} must be True or False, not {type_name(value)} {value!r:.60}",
        )
    return bool(value)


def choice(name: str, value: Any, allowed: tuple[str, ...]) -> str:
    """One of the strings ``allowed``."""
    if not isinstance(value, str):
        raise wrong_type(
            name,
            value,
            "a string",
            f"{name} must be a string, not {type_name(value)} {value!r:.60}",
        )
    if value not in allowed:
        raise ParameterError(name, value, "must be " + " or ".join(repr(a) for a in allowed))
    return value


def path(name: str, value: Any) -> Path:
    """A file or directory path (a string or an ``os.PathLike``). An empty string is refused:
    ``Path("")`` is the current directory, where a run would silently write its files."""
    if not isinstance(value, (str, os.PathLike)):
        raise wrong_type(name, value, "a path (str or os.PathLike)")
    text = os.fspath(value)
    if isinstance(text, bytes) or not text.strip():
        raise ParameterError(name, value, "must be a non-empty path (str or os.PathLike)")
    return Path(text)


def real_array(name: str, value: Any, *, finite_only: bool = True) -> np.ndarray:
    """A 1-D contiguous float array from a number or a sequence of real numbers."""
    if isinstance(value, (str, bytes)) or value is None:
        raise wrong_type(name, value, "numbers")
    if isinstance(value, (list, tuple)):
        # NumPy would read [True, 290.0] as [1.0, 290.0]: a bool in a sequence is no number.
        for i, v in enumerate(value):
            if isinstance(v, (bool, np.bool_, str, bytes)):
                raise wrong_type(
                    f"{name}[{i}]",
                    v,
                    "a real number",
                    f"{name}[{i}] must be a real number, not {type_name(v)} {v!r:.60}",
                )
    try:
        arr = np.asarray(value)
    except (TypeError, ValueError) as exc:
        raise wrong_type(name, value, "numbers", f"{name} must be numbers: {exc}") from None
    if arr.dtype == np.bool_ or not (
        np.issubdtype(arr.dtype, np.integer) or np.issubdtype(arr.dtype, np.floating)
    ):
        raise wrong_type(
            name, value, "real numbers", f"{name} must be real numbers, not an array of {arr.dtype}"
        )
    if arr.ndim > 1:
        raise ParameterError(
            name,
            value,
            "must be one-dimensional",
            f"{name} = an array of shape {arr.shape} is invalid: must be one-dimensional",
        )
    with np.errstate(over="ignore"):
        out = np.ascontiguousarray(np.atleast_1d(arr).astype(float))
    if finite_only and not np.all(np.isfinite(out)):
        bad = out[~np.isfinite(out)][0]
        raise ParameterError(name, float(bad), "every value must be finite")
    return out


def check_fields(
    obj: Any,
    *,
    flags: Collection[str] = (),
    choices: Mapping[str, tuple[str, ...]] | None = None,
) -> None:
    """Checks the type of every field of the frozen dataclass ``obj`` and keeps the plain value:
    a bool for the names in ``flags``, one of ``choices[name]`` for those, a real number for
    the others (the engine then checks the ranges)."""
    choices = choices or {}
    for f in dataclasses.fields(obj):
        value = getattr(obj, f.name)
        if f.name in flags:
            value = flag(f.name, value)
        elif f.name in choices:
            value = choice(f.name, value, choices[f.name])
        else:
            value = real(f.name, value)
        object.__setattr__(obj, f.name, value)
