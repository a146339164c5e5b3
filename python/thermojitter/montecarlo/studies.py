"""The three studies over panel (or boom) parameters and orbit inputs: Monte Carlo,
full-factorial sweeps and Sobol sensitivity."""

from __future__ import annotations

import itertools
import math
import os
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray

from thermojitter import errors as checks
from thermojitter.attitude import Attitude
from thermojitter.boom import Boom
from thermojitter.errors import ParameterError
from thermojitter.montecarlo.design import (
    MAX_SAMPLES,
    Sampler,
    check_n,
    check_seed,
    check_table,
    check_vary,
    checked_orbit_inputs,
    describe,
    panel_matrix,
    refuse_invalid,
    sampled,
    truncation_hint,
    unit_design,
)
from thermojitter.montecarlo.driver import run_design, run_options, with_layers
from thermojitter.montecarlo.metrics import (
    FLOAT_METRICS,
)
from thermojitter.orbit import Orbit
from thermojitter.panel import Panel
from thermojitter.simulate import check_inputs
from thermojitter.solver import ATOL, MAX_STEPS, RTOL, SolverSettings


def monte_carlo(
    panel: Panel | Boom,
    orbit: Orbit,
    *,
    vary: Mapping[str, Any],
    n: int,
    horizon: int = 1,
    seed: int | None = None,
    sampler: Sampler = "random",
    truncate: bool = False,
    threshold: float | None = None,
    stop_at_threshold: bool = False,
    threads: int | None = None,
    backend: Any = None,
    checkpoint: str | os.PathLike[str] | None = None,
    chunk_size: int | None = None,
    progress: bool = True,
    model: Literal["nonlinear", "linear", "distributed"] = "nonlinear",
    coupled: bool = True,
    method: Literal["rk45", "rk4", "hybrid"] | None = None,
    rtol: float = RTOL,
    atol: float = ATOL,
    dt: float | None = None,
    window: float = 600.0,
    max_steps: int = MAX_STEPS,
    solver: SolverSettings | None = None,
    layers: int | None = None,
    attitude: Attitude | None = None,
    elements: int | None = None,
    modes: int | None = None,
    support: Literal["free-free", "cantilever"] = "free-free",
    damping_ratio: float | None = None,
) -> Any:
    """Runs ``n`` panels drawn around ``panel`` and returns a pandas DataFrame, one row a sample:
    the sampled parameters, then the metrics (see ``METRICS``).

    - ``vary``: panel parameter name (or orbit input: ``albedo``, ``earth_ir``,
      ``inclination``, ``raan``, named as the parameters of :meth:`Orbit.circular`; each sample
      then runs on ``orbit`` with its own values) → frozen scipy.stats distribution or shorthand
      (``("uniform", lo, hi)``, ``("normal", mean, sd)``, ``("lognormal", median, sigma)``,
      ``("loguniform", lo, hi)``, ``("truncnorm", mean, sd, lo, hi)``,
      ``("triangular", lo, mode, hi)``). A design with a sample outside a parameter's valid range
      (e.g. an emissivity above 1) is refused before anything runs, unless ``truncate=True``:
      then each distribution is truncated to the valid range.
    - ``sampler``: ``"random"`` (NumPy generator; sample i depends on the seed and i only, so a
      larger n extends a study), ``"lhs"`` (Latin hypercube) or ``"sobol"``
      (scrambled; best with n a power of 2), all seeded by ``seed`` (None: a fresh seed, kept in
      ``frame.attrs["seed"]``; required with ``checkpoint``).
    - ``horizon``: whole orbits integrated from t = 0, starting at the sunlit equilibrium
      (``amplitude_slope``, a slope over the orbits, needs 2 or more: NaN on the default 1).
    - ``method``: ``"hybrid"`` (exact linear arcs in sunlight, the non-linear model through the
      shadows; see ``simulate_orbits``), ``"rk45"`` (hinge-resolved) or ``"rk4"``; None: hybrid
      for horizons of a month or more, rk45 below.
    - ``threshold`` (rad): time the first abs(θ) above it (``t_threshold``); with
      ``stop_at_threshold`` a sample stops there.
    - ``max_steps``: the study's step budget, every sample together (each sample also stops at
      it). A design whose least cost, known up front for rk45 with its step cap and rk4, exceeds
      it is refused before it starts, naming ``horizon`` or ``n``.
    - ``threads``: rayon threads on this machine (default: one per core, at most
      ``MAX_THREADS``). ``backend``: None (this
      machine), ``"dask"`` (a new LocalCluster), a scheduler address or a ``distributed.Client``;
      each worker then runs chunks on as many rayon threads as it has threads.
    - ``checkpoint``: a directory; finished chunks (``chunk_size`` samples, default depending on n
      only; a resumed run keeps the size it started with) are written there as Parquet as they
      complete, and a run with the same settings resumes from them. Settings that differ are
      refused, naming them.

    - ``solver``: a :class:`thermojitter.SolverSettings` in place of ``rtol``, ``atol``, ``dt``
      and ``max_steps`` (with ``method="hybrid"``, those of its rk45 fallback); those the engine
      ran with are :func:`thermojitter.montecarlo.solver_of` (``frame.attrs["solver"]``).
    - ``layers``: N runs every sample with the N-node through-thickness model (as
      ``simulate_orbits(..., layers=N)``): on the layup of a panel made by
      :meth:`Panel.from_laminate` (whose layup-decided fields cannot be varied then), or on each
      sample's panel as one homogeneous layer. The N-node model is integrated in full (rk45 in
      place of the hybrid propagator). A sample is the single run of its panel.

    A sample that fails (its integration cannot finish, e.g. it runs into ``max_steps``) keeps
    its row: the reason in ``error``, ``stable`` and ``n_steps`` missing (NA), its numbers NaN.
    The study then warns (:class:`thermojitter.SampleFailureWarning`, naming how many failed and
    the first reason) and counts them in ``frame.attrs["n_failed"]``; when every sample fails it
    raises :class:`AllSamplesFailedError` (an ``IntegrationError``; the frame is its
    ``.samples``).

    - ``attitude``: where the front face points (:class:`thermojitter.Attitude`, default
      Sun-pointing), as in ``simulate_orbits``. With it, or with the Earth's loads on the orbit or
      drawn (``albedo``, ``earth_ir``), a sample's ``theta_eq``, ``growth_rate``,
      ``frequency_hz`` and ``critical_damping`` are those of its equilibrium in full sunlight
      under every load at t = 0 (``tj.flutter(panel, orbit=..., t=0, attitude=...)``), and its run
      starts there, as ``simulate_orbits`` does; the hybrid propagator runs such samples on slow
      time (see ``simulate_orbits``; ``t_nonlinear`` counts the time it integrated in full).
      Each sample equals the single ``simulate_orbits`` run of its panel on its orbit.
    - A :class:`thermojitter.Boom` in place of the panel: ``vary`` names boom parameters (and
      ``inclination``, ``raan``; a boom takes no Earth heating nor attitude); each sample is the
      tube's flutter analysis at full Sun (``critical_damping`` is then the first mode's
      critical damping ratio ζ, as ``tj.flutter(boom)``'s) and its ``simulate_orbits`` run,
      integrated in full (the tube has no hybrid form).

    The frame is identical, bit for bit, for any ``threads``, ``chunk_size`` and backend.

    ``model="distributed"`` runs the distributed panel (``elements``, ``modes``, ``support``,
    ``damping_ratio``, ``layers`` as in ``simulate_orbits``): ``vary`` names panel parameters,
    each sample is its own ``simulate_orbits(..., model="distributed")`` run over ``horizon``
    orbits (``method``, ``window``, ``solver``, ``attitude`` passed on; ``method=None`` as above)
    with its row read off the run's summaries
    (:data:`thermojitter.montecarlo.distributed.DISTRIBUTED_METRICS`), the samples one per thread
    (``threads``). ``threshold``, ``backend``, ``checkpoint`` and ``chunk_size`` are the hinge
    studies' only.
    """
    if model == "distributed":
        from thermojitter.montecarlo.distributed import distributed_study
        from thermojitter.montecarlo.driver import default_method

        check_structure(panel, orbit)
        for name, value in (
            ("threshold", threshold), ("backend", backend), ("checkpoint", checkpoint),
            ("chunk_size", chunk_size),
        ):  # fmt: skip
            if value is not None:
                raise ParameterError(name, value, "is not a setting of model='distributed'")
        n = check_n(n)
        seed = check_seed(seed, None)
        sampler = checks.choice("sampler", sampler, ("random", "lhs", "sobol"))  # type: ignore[assignment]
        run = {
            "n_orbits": horizon,
            "coupled": coupled,
            "method": default_method(method, orbit, horizon),
            "window": window,
            "rtol": rtol,
            "atol": atol,
            "dt": dt,
            "max_steps": max_steps,
            "solver": solver,
            "attitude": attitude,
        }
        settings = {
            "elements": elements, "modes": modes, "support": support,
            "damping_ratio": damping_ratio, "layers": layers,
        }  # fmt: skip
        vary = check_vary(vary, False)
        return distributed_study(
            panel, orbit, vary, n, seed, sampler, checks.flag("truncate", truncate), threads,
            run, settings,
        )  # fmt: skip
    from thermojitter.longrun import refuse_distributed_only

    refuse_distributed_only(
        str(model),
        {"elements": elements, "modes": modes, "support": support, "damping_ratio": damping_ratio},
    )
    check_structure(panel, orbit)
    vary = check_vary(vary, isinstance(panel, Boom))
    n = check_n(n)
    seed = check_seed(seed, checkpoint)
    sampler = checks.choice("sampler", sampler, ("random", "lhs", "sobol"))  # type: ignore[assignment]
    truncate = checks.flag("truncate", truncate)
    options = run_options(
        orbit, horizon, model, coupled, method, solver, rtol, atol, dt, max_steps, window,
        threshold, stop_at_threshold, attitude, panel,
    )  # fmt: skip
    options = with_layers(options, panel, layers, list(vary))
    u = unit_design(sampler, n, len(vary), seed)
    frame = _run_drawn(
        "monte_carlo", panel, vary, u, n, seed, {"sampler": sampler}, truncate, options,
        threads=threads, backend=backend, checkpoint=checkpoint, chunk_size=chunk_size,
        progress=progress,
    )  # fmt: skip
    frame.attrs["seed"] = seed
    return frame


def check_structure(panel: Any, orbit: Any) -> None:
    """TypeError unless ``panel`` is a Panel or a Boom and ``orbit`` an Orbit; a boom refuses an
    orbit with the Earth's loads (its model takes the Sun alone), naming ``orbit``."""
    if not isinstance(panel, Boom):
        check_inputs(panel, orbit)
        return
    checks.instance("orbit", orbit, Orbit, "a thermojitter.Orbit")
    if orbit.albedo != 0.0 or orbit.earth_ir != 0.0:
        raise ParameterError(
            "orbit",
            orbit,
            message="orbit: a boom takes the Sun alone on its lit side: give an orbit with "
            "albedo = earth_ir = 0",
        )


def _settings(study: str, panel: Panel | Boom) -> dict[str, Any]:
    """The settings every study records first: its name and the base panel (or boom)."""
    out: dict[str, Any] = {"study": study, "panel": panel.as_dict()}
    if isinstance(panel, Boom):
        out["structure"] = "boom"
    return out


def _run_drawn(
    study: str,
    panel: Panel | Boom,
    vary: Mapping[str, Any],
    u: NDArray[np.float64],
    n: int,
    seed: int,
    sampler: dict[str, Any],
    truncate: bool,
    options: dict[str, Any],
    **run: Any,
) -> Any:
    """Runs the panels of the unit design ``u`` mapped through the distributions of ``vary``
    (``monte_carlo`` and ``sensitivity``): the study's settings are its name, the panel, the
    distributions, ``n``, ``seed``, ``sampler`` (how ``u`` was drawn) and ``truncate``; ``run``
    goes to ``run_design``."""
    names, values, matrix = sampled(panel, vary, u, truncate)
    inputs = checked_orbit_inputs(options["orbit"], names, values, truncation_hint(truncate))
    settings = {
        **_settings(study, panel),
        "vary": {name: describe(vary[name]) for name in names},
        "n": n,
        "seed": seed,
        **sampler,
        "truncate": truncate,
    }
    return run_design(names, values, matrix, options, settings, inputs, **run)


def sweep(
    panel: Panel | Boom,
    orbit: Orbit,
    grid: Mapping[str, Sequence[float]],
    *,
    horizon: int = 1,
    threshold: float | None = None,
    stop_at_threshold: bool = False,
    threads: int | None = None,
    backend: Any = None,
    checkpoint: str | os.PathLike[str] | None = None,
    chunk_size: int | None = None,
    progress: bool = True,
    model: Literal["nonlinear", "linear"] = "nonlinear",
    coupled: bool = True,
    method: Literal["rk45", "rk4", "hybrid"] | None = None,
    rtol: float = RTOL,
    atol: float = ATOL,
    dt: float | None = None,
    window: float = 600.0,
    max_steps: int = MAX_STEPS,
    solver: SolverSettings | None = None,
    layers: int | None = None,
    attitude: Attitude | None = None,
) -> Any:
    """Full-factorial study: every combination of the ``grid`` values (parameter name → values),
    the first parameter varying slowest. Returns a DataFrame like ``monte_carlo``'s; the other
    arguments (``layers``, ``attitude`` and a boom too; the grid may name orbit inputs) are the
    same, and so is the handling of failed samples (a warning and ``frame.attrs["n_failed"]``;
    :class:`AllSamplesFailedError` when all failed)."""
    check_structure(panel, orbit)
    check_table(grid, "grid", "values", isinstance(panel, Boom))
    axes: list[list[float]] = []
    for name, vals in grid.items():
        arr = checks.real_array(f"grid.{name}", vals)  # numbers: not bools, not strings
        if arr.size == 0:
            raise ParameterError(f"grid.{name}", vals, "must hold at least one value")
        axes.append(arr.tolist())
    options = run_options(
        orbit, horizon, model, coupled, method, solver, rtol, atol, dt, max_steps, window,
        threshold, stop_at_threshold, attitude, panel,
    )  # fmt: skip
    names = list(grid)
    size = math.prod(len(a) for a in axes)
    if size > MAX_SAMPLES:
        raise ParameterError(
            "grid",
            size,
            message=f"grid = {size} panels is invalid: must hold at most {MAX_SAMPLES} panels",
        )
    options = with_layers(options, panel, layers, names)
    values = np.array(list(itertools.product(*axes)), dtype=float).reshape(-1, len(names))
    matrix = panel_matrix(panel, names, values)
    refuse_invalid(matrix, "", isinstance(panel, Boom))
    inputs = checked_orbit_inputs(options["orbit"], names, values, "")
    settings = {**_settings("sweep", panel), "grid": dict(zip(names, axes, strict=True))}
    return run_design(
        names, values, matrix, options, settings, inputs, threads=threads, backend=backend,
        checkpoint=checkpoint, chunk_size=chunk_size, progress=progress,
    )  # fmt: skip


@dataclass(frozen=True)
class SensitivityResult:
    """Sobol indices of ``metric``: ``indices`` is a DataFrame indexed by parameter with columns
    ``S1``, ``S1_conf``, ``ST``, ``ST_conf``; ``samples`` is the frame of every sample run."""

    indices: Any
    metric: str
    samples: Any
    interrupted: bool = False
    """True when Ctrl-C stopped the run: ``samples`` holds the finished ones, ``indices`` NaN."""


def sensitivity(
    panel: Panel | Boom,
    orbit: Orbit,
    vary: Mapping[str, Any],
    *,
    metric: str = "exit_peak",
    n: int = 256,
    seed: int = 0,
    second_order: bool = False,
    truncate: bool = False,
    horizon: int = 1,
    threshold: float | None = None,
    stop_at_threshold: bool = False,
    threads: int | None = None,
    backend: Any = None,
    checkpoint: str | os.PathLike[str] | None = None,
    chunk_size: int | None = None,
    progress: bool = True,
    model: Literal["nonlinear", "linear"] = "nonlinear",
    coupled: bool = True,
    method: Literal["rk45", "rk4", "hybrid"] | None = None,
    rtol: float = RTOL,
    atol: float = ATOL,
    dt: float | None = None,
    window: float = 600.0,
    max_steps: int = MAX_STEPS,
    solver: SolverSettings | None = None,
    layers: int | None = None,
    attitude: Attitude | None = None,
) -> SensitivityResult:
    """Sobol sensitivity indices of one metric to the parameters in ``vary`` (needs SALib:
    ``pip install 'thermojitter[sensitivity]'``).

    Runs n·(d + 2) samples (n·(2d + 2) with ``second_order``) of Saltelli's design (best with n
    a power of 2), mapped through the distributions of ``vary`` like ``monte_carlo``, whose other
    arguments (``layers``, ``attitude``, orbit inputs in ``vary`` and a boom too) these are.
    ``indices`` holds ``S1``, ``S1_conf``, ``ST``, ``ST_conf`` per parameter (first-order and
    total indices, 95 % confidence half-widths).

    The indices need the metric of every sample: a study in which some sample failed (or whose
    metric is NaN somewhere) is refused with a ValueError naming the first, after the warning
    every study gives of its failed samples; one in which all failed raises
    :class:`AllSamplesFailedError`. With ``metric="stable"`` the indices are those of the
    0/1 indicator of stability.
    """
    try:
        from SALib.analyze import sobol as sobol_analyze
        from SALib.sample import sobol as sobol_sample
    except ImportError as exc:
        raise ImportError(
            "sensitivity needs SALib: pip install 'thermojitter[sensitivity]'"
        ) from exc
    import pandas as pd

    check_structure(panel, orbit)
    vary = check_vary(vary, isinstance(panel, Boom))
    n = check_n(n, 2)
    seed = check_seed(seed, None)
    second_order = checks.flag("second_order", second_order)
    truncate = checks.flag("truncate", truncate)
    checks.instance("metric", metric, str, "a string")
    if metric not in FLOAT_METRICS and metric != "stable":
        choices = ", ".join((*FLOAT_METRICS, "stable"))
        raise ParameterError("metric", metric, f"choose from {choices}")
    options = run_options(
        orbit, horizon, model, coupled, method, solver, rtol, atol, dt, max_steps, window,
        threshold, stop_at_threshold, attitude, panel,
    )  # fmt: skip
    names = list(vary)
    options = with_layers(options, panel, layers, names)
    problem = {"num_vars": len(names), "names": names, "bounds": [[0.0, 1.0]] * len(names)}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # n not a power of 2
        u = np.asarray(
            sobol_sample.sample(problem, n, calc_second_order=second_order, seed=seed), dtype=float
        )
    samples = _run_drawn(
        "sensitivity", panel, vary, u, n, seed, {"second_order": second_order}, truncate,
        options, threads=threads, backend=backend, checkpoint=checkpoint, chunk_size=chunk_size,
        progress=progress,
    )  # fmt: skip
    if samples.attrs["interrupted"]:
        nan = np.full(len(names), np.nan)
        indices = pd.DataFrame(
            {k: nan for k in ("S1", "S1_conf", "ST", "ST_conf")},
            index=pd.Index(names, name="parameter"),
        )
        return SensitivityResult(indices=indices, metric=metric, samples=samples, interrupted=True)
    # A failed sample's stable is NA: NaN here, refused below like a missing number.
    y = samples[metric].to_numpy(dtype=float, na_value=np.nan)
    missing = np.flatnonzero(~np.isfinite(y))
    if missing.size:
        k = int(missing[0])
        why = samples["error"].iloc[k] or "no value"
        raise ParameterError(
            "metric",
            metric,
            message=f"{metric} is not defined for {missing.size} of {len(y)} samples (sample {k}: "
            f"{why}); Sobol indices need a value for every sample",
        )
    res = sobol_analyze.analyze(problem, y, calc_second_order=second_order, seed=seed)
    indices = pd.DataFrame(
        {k: np.asarray(res[k], dtype=float) for k in ("S1", "S1_conf", "ST", "ST_conf")},
        index=pd.Index(names, name="parameter"),
    )
    return SensitivityResult(indices=indices, metric=metric, samples=samples)
