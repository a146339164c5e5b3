"""The design of a study: distributions of panel (or boom) parameters and orbit inputs,
unit-cube samplers, and the rows of panels and the orbit inputs they map to, each checked
against the engine's ranges before anything runs."""

from __future__ import annotations

import math
import warnings
from collections.abc import Mapping, Sequence
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray
from scipy import stats
from scipy.stats import qmc

from thermojitter import _core
from thermojitter import errors as checks
from thermojitter.boom import Boom
from thermojitter.errors import ParameterError, ParameterTypeError
from thermojitter.panel import Panel

Sampler = Literal["random", "lhs", "sobol"]

ORBIT_INPUTS: tuple[str, ...] = tuple(_core.ORBIT_INPUTS)
"""The orbit inputs a study may vary beside the panel's parameters, named as the parameters of
:meth:`thermojitter.Orbit.circular`: each sample runs on the study's orbit with its own values."""

ORBIT_INPUT_RANGES: Mapping[str, tuple[float, float, bool]] = {
    name: (float(lo), float(hi), bool(open_))
    for name, (lo, hi, open_) in _core.ORBIT_INPUT_RANGES.items()
}
"""The valid range of each orbit input, as the engine checks it: (low, high, low end open)."""

BOOM_REFUSED_INPUTS = ("albedo", "earth_ir")
"""Orbit inputs a boom cannot vary: its model takes the Sun alone on its lit side."""


def _numbers(name: str, spec: Sequence[Any], count: int, usage: str) -> list[float]:
    args = list(spec[1:])
    if len(args) != count:
        raise ParameterError(
            f"vary.{name}", spec, message=f"vary[{name!r}] = {spec!r} is invalid: expected {usage}"
        )
    out = []
    for a in args:
        if isinstance(a, bool) or not isinstance(a, (int, float, np.floating, np.integer)):
            raise ParameterTypeError(
                f"vary.{name}",
                spec,
                "numbers",
                f"vary[{name!r}] = {spec!r} is invalid: {a!r} is not a number",
            )
        if not math.isfinite(float(a)):
            raise ParameterError(
                f"vary.{name}",
                spec,
                message=f"vary[{name!r}] = {spec!r} is invalid: {a!r} is not finite",
            )
        out.append(float(a))
    return out


def _shorthand(name: str, spec: Sequence[Any]) -> Any:
    kind = spec[0]

    def bad(reason: str) -> ParameterError:
        message = f"vary[{name!r}] = {tuple(spec)!r} is invalid: {reason}"
        return ParameterError(f"vary.{name}", spec, message=message)

    if kind == "uniform":
        lo, hi = _numbers(name, spec, 2, "('uniform', lo, hi)")
        if not hi > lo:
            raise bad("needs lo < hi")
        return stats.uniform(loc=lo, scale=hi - lo)
    if kind == "normal":
        mean, sd = _numbers(name, spec, 2, "('normal', mean, sd)")
        if not sd > 0:
            raise bad("needs sd > 0")
        return stats.norm(loc=mean, scale=sd)
    if kind == "lognormal":
        median, sigma = _numbers(name, spec, 2, "('lognormal', median, sigma of the log)")
        if not (median > 0 and sigma > 0):
            raise bad("needs median > 0 and sigma > 0")
        return stats.lognorm(s=sigma, scale=median)
    if kind == "loguniform":
        lo, hi = _numbers(name, spec, 2, "('loguniform', lo, hi)")
        if not 0 < lo < hi:
            raise bad("needs 0 < lo < hi")
        return stats.loguniform(lo, hi)
    if kind == "truncnorm":
        mean, sd, lo, hi = _numbers(name, spec, 4, "('truncnorm', mean, sd, lo, hi)")
        if not sd > 0:
            raise bad("needs sd > 0")
        if not hi > lo:
            raise bad("needs lo < hi")
        return stats.truncnorm((lo - mean) / sd, (hi - mean) / sd, loc=mean, scale=sd)
    if kind == "triangular":
        lo, mode, hi = _numbers(name, spec, 3, "('triangular', lo, mode, hi)")
        if not (hi > lo and lo <= mode <= hi):
            raise bad("needs lo <= mode <= hi and lo < hi")
        return stats.triang(c=(mode - lo) / (hi - lo), loc=lo, scale=hi - lo)
    raise bad(
        f"unknown distribution {kind!r}: use 'uniform', 'normal', 'lognormal', 'loguniform', "
        "'truncnorm', 'triangular' or a frozen scipy.stats distribution"
    )


def distribution(name: str, spec: Any) -> Any:
    """A frozen scipy.stats distribution from ``spec``: a frozen distribution itself, or a
    shorthand ``("uniform", lo, hi)``, ``("normal", mean, sd)``, ``("lognormal", median, sigma)``
    (sigma of the natural log), ``("loguniform", lo, hi)``, ``("truncnorm", mean, sd, lo, hi)``
    or ``("triangular", lo, mode, hi)``."""
    if isinstance(spec, (tuple, list)) and spec and isinstance(spec[0], str):
        return _shorthand(name, spec)
    if callable(getattr(spec, "ppf", None)) and callable(getattr(spec, "cdf", None)):
        with np.errstate(all="ignore"):
            mid = np.asarray(spec.ppf(0.5), dtype=float)
        if mid.shape != () or not np.isfinite(mid):
            raise ParameterError(
                f"vary.{name}",
                spec,
                message=f"vary[{name!r}] = {spec!r} is invalid: not a proper univariate "
                "distribution (its median is not a finite number; check its parameters)",
            )
        return spec
    raise ParameterError(
        f"vary.{name}",
        spec,
        message=f"vary[{name!r}] = {spec!r} is invalid: give a frozen scipy.stats distribution "
        "or a shorthand such as ('uniform', lo, hi) or ('normal', mean, sd)",
    )


def describe(spec: Any) -> Any:
    """A JSON form of a distribution spec, for the settings fingerprint."""
    if isinstance(spec, (tuple, list)):
        return [v if isinstance(v, str) else float(v) for v in spec]
    dist = getattr(spec, "dist", None)
    return {
        "dist": getattr(dist, "name", type(spec).__name__),
        "args": [float(a) for a in getattr(spec, "args", ())],
        "kwds": {k: float(v) for k, v in sorted(getattr(spec, "kwds", {}).items())},
    }


def check_names(names: Sequence[Any], what: str, boom: bool = False) -> None:
    """Each name a parameter of the panel (of the boom with ``boom``) or an orbit input."""
    kind = "boom" if boom else "panel"
    fields = (*(Boom if boom else Panel).field_names(), *ORBIT_INPUTS)
    for name in names:
        if not isinstance(name, str) or name not in fields:
            raise ParameterError(
                what,
                name,
                message=f"{what}: {name!r} is not a {kind} parameter or an orbit input; "
                f"choose from {', '.join(fields)}",
            )
        if boom and name in BOOM_REFUSED_INPUTS:
            raise ParameterError(
                f"{what}.{name}",
                name,
                message=f"{what}: {name!r} cannot be varied for a boom: its model takes the Sun "
                "alone on its lit side (no Earth heating)",
            )


def value_range(name: str, boom: bool = False) -> tuple[float, float, bool]:
    """The valid range of a varied parameter or orbit input: (low, high, low end open)."""
    if name in ORBIT_INPUT_RANGES:
        return ORBIT_INPUT_RANGES[name]
    lo, hi, lo_open = (Boom if boom else Panel).RANGES[name]
    return float(lo), float(hi), bool(lo_open)


def unit_design(sampler: str, n: int, d: int, seed: int) -> NDArray[np.float64]:
    """n points of the unit cube [0, 1)^d, deterministic in (sampler, n, d, seed)."""
    rng = np.random.default_rng(seed)
    if sampler == "random":
        return rng.random((n, d))
    if sampler == "lhs":
        engine: qmc.QMCEngine = _qmc(qmc.LatinHypercube, d, rng)
    elif sampler == "sobol":
        engine = _qmc(qmc.Sobol, d, rng, scramble=True)
    else:
        raise ParameterError("sampler", sampler, "must be 'random', 'lhs' or 'sobol'")
    with warnings.catch_warnings():
        # Sobol prefers powers of 2; other sizes are still valid designs.
        warnings.simplefilter("ignore", UserWarning)
        return np.asarray(engine.random(n), dtype=float)


def _qmc(cls: Any, d: int, rng: np.random.Generator, **kwargs: Any) -> qmc.QMCEngine:
    try:
        return cls(d, rng=rng, **kwargs)  # type: ignore[no-any-return]
    except TypeError:  # scipy < 1.15 names it seed
        return cls(d, seed=rng, **kwargs)  # type: ignore[no-any-return]


def _open_unit(u: NDArray[np.float64]) -> NDArray[np.float64]:
    """Keeps points off 0 and 1, where unbounded distributions have infinite quantiles."""
    return np.clip(u, np.finfo(float).tiny, np.nextafter(1.0, 0.0))


def quantiles(
    name: str, dist: Any, u: NDArray[np.float64], truncate: bool, boom: bool = False
) -> NDArray[np.float64]:
    """Maps unit points through the distribution's ppf; with ``truncate``, through the ppf
    restricted to the parameter's valid range."""
    u = _open_unit(u)
    if not truncate:
        with np.errstate(all="ignore"):
            return np.asarray(dist.ppf(u), dtype=float)
    lo, hi, lo_open = value_range(name, boom)  # the engine's range, high end closed
    with np.errstate(all="ignore"):
        a, b = float(dist.cdf(lo)), float(dist.cdf(hi))
    if not b - a > 0:
        raise ParameterError(
            f"vary.{name}",
            dist,
            message=f"vary[{name!r}]: the distribution has no probability inside the valid range "
            f"of {name} ({lo:g}, {hi:g}); truncation is impossible",
        )
    with np.errstate(all="ignore"):
        x = np.asarray(dist.ppf(a + u * (b - a)), dtype=float)
    # Rounding at the ends of the interval must not step outside the range.
    low = np.nextafter(lo, math.inf) if lo_open else lo
    return np.clip(x, low, hi)


def structure_fields(panel: Panel | Boom) -> list[str]:
    """The columns of a design's rows: PANEL_FIELDS, or BOOM_FIELDS for a boom."""
    return list(_core.BOOM_FIELDS if isinstance(panel, Boom) else _core.PANEL_FIELDS)


def panel_matrix(panel: Panel | Boom, names: Sequence[str], values: NDArray[np.float64]) -> Any:
    """Rows of every panel field (PANEL_FIELDS order; BOOM_FIELDS for a boom): the base panel
    with its parameters among ``names`` replaced (the orbit inputs are the orbit's)."""
    fields = structure_fields(panel)
    base = panel.as_dict()
    rows = np.tile(np.array([base[f] for f in fields], dtype=float), (len(values), 1))
    for j, name in enumerate(names):
        if name not in ORBIT_INPUTS:
            rows[:, fields.index(name)] = values[:, j]
    return np.ascontiguousarray(rows)


def orbit_inputs(names: Sequence[str], values: NDArray[np.float64]) -> dict[str, Any]:
    """The varied orbit inputs among ``names``: name → one value a sample (empty: none)."""
    return {
        name: np.ascontiguousarray(values[:, j], dtype=float)
        for j, name in enumerate(names)
        if name in ORBIT_INPUTS
    }


def _refuse(bad: Sequence[tuple[int, str, str]], n: int, value: Any, hint: str) -> None:
    """Refuses a design with rows the engine's validation refused, naming the first parameter;
    ``value(row, name)`` is that parameter's value in the row."""
    if not bad:
        return
    by_name: dict[str, list[tuple[int, str]]] = {}
    for row, name, message in bad:
        by_name.setdefault(name, []).append((row, message))
    name, rows = next(iter(by_name.items()))
    row, message = rows[0]
    raise ParameterError(
        name,
        float(value(row, name)),
        message=f"{name}: {len(rows)} of {n} samples are outside its valid range "
        f"(sample {row}: {message}){hint}",
    )


def refuse_invalid(matrix: NDArray[np.float64], hint: str, boom: bool = False) -> None:
    """Runs the panel (or boom) validation on every row; refuses the design naming the
    parameter."""
    fields = list(_core.BOOM_FIELDS if boom else _core.PANEL_FIELDS)
    bad = _core.check_panels(matrix, boom=boom)
    _refuse(bad, len(matrix), lambda row, name: matrix[row, fields.index(name)], hint)


def refuse_invalid_orbits(orbit: dict[str, Any], inputs: dict[str, Any], hint: str) -> None:
    """Runs the orbit validation on every sample's orbit (``orbit`` with the sample's
    ``inputs``); refuses the design naming the input."""
    if not inputs:
        return
    n = len(next(iter(inputs.values())))
    bad = _core.check_orbits(orbit, inputs, n)
    _refuse(bad, n, lambda row, name: inputs[name][row] if name in inputs else math.nan, hint)


def check_seed(seed: Any, checkpoint: Any) -> int:
    if seed is None:
        if checkpoint is not None:
            raise ParameterError(
                "seed",
                seed,
                message="seed is required with checkpoint (a resumed run must redraw it)",
            )
        return int(np.random.SeedSequence().entropy % (2**63))  # type: ignore[operator]
    return checks.integer("seed", seed, 0)


MAX_SAMPLES = 10**7
"""Most samples of one study: its design is held in memory (about 140 bytes a sample, over a
gigabyte at the limit), and so many runs of even one orbit take CPU-days."""


def check_n(n: Any, least: int = 1) -> int:
    return checks.integer("n", n, least, MAX_SAMPLES)


def sampled(
    panel: Panel | Boom,
    vary: Mapping[str, Any],
    u: NDArray[np.float64],
    truncate: bool,
) -> tuple[list[str], NDArray[np.float64], NDArray[np.float64]]:
    """(names, sampled values, full panel rows) of unit points ``u`` mapped through ``vary``,
    the rows checked by the engine's validation (the orbit inputs are checked by
    :func:`checked_orbit_inputs`)."""
    names = list(vary)
    boom = isinstance(panel, Boom)
    dists = [distribution(name, vary[name]) for name in names]
    values = np.column_stack(
        [
            quantiles(name, dist, u[:, j], truncate, boom)
            for j, (name, dist) in enumerate(zip(names, dists, strict=True))
        ]
    )
    matrix = panel_matrix(panel, names, values)
    refuse_invalid(matrix, truncation_hint(truncate), boom)
    return names, values, matrix


def truncation_hint(truncate: bool) -> str:
    """What a refusal of a drawn design suggests."""
    return "" if truncate else "; narrow the distribution or pass truncate=True"


def checked_orbit_inputs(
    orbit: dict[str, Any], names: Sequence[str], values: NDArray[np.float64], hint: str
) -> dict[str, Any]:
    """The orbit inputs of a design (name → one value a sample), each sample's orbit (``orbit``
    with its inputs) checked by the engine's validation: a design with any sample outside a valid
    range is refused, naming the input."""
    inputs = orbit_inputs(names, values)
    refuse_invalid_orbits(orbit, inputs, hint)
    return inputs


def check_table(table: Any, what: str, of: str, boom: bool = False) -> Mapping[str, Any]:
    """``table`` (the argument ``what``: ``vary``, ``grid``) as a non-empty mapping of panel
    (or boom) parameter names and orbit inputs to ``of``."""
    if not isinstance(table, Mapping) or not table:
        raise ParameterError(
            what,
            table,
            message=f"{what} must be a non-empty mapping of panel parameter names to {of}",
        )
    check_names(list(table), what, boom)
    return table


def check_vary(vary: Any, boom: bool = False) -> Mapping[str, Any]:
    return check_table(vary, "vary", "distributions", boom)
