"""Monte Carlo studies, full-factorial sweeps and Sobol sensitivity over panel parameters.

A study is a design — one row of panel parameters per sample, drawn in Python from the seed up
front — and a batch run of it in the Rust engine on a rayon pool with the GIL released. Each
sample depends only on its own row, so the results are the same, bit for bit, whatever the
number of threads, the chunking or the backend (local threads or Dask workers).

The design is cut into chunks of rows. With ``checkpoint=DIR`` every finished chunk is written to
``DIR/chunk-NNNNN.parquet`` as soon as it completes, beside ``DIR/manifest.json`` (the settings and
their fingerprint); a run started again with the same settings reads the finished chunks and
computes only the others.
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import hashlib
import itertools
import math
import os
import threading
import warnings
from collections.abc import Generator, Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np
from numpy.typing import NDArray
from scipy import stats
from scipy.stats import qmc

from thermojitter import _core
from thermojitter import checkpoint as checkpoints
from thermojitter import errors as checks
from thermojitter.errors import ParameterError, SampleFailureWarning
from thermojitter.longrun import DEFAULT_THETA_LIMIT, orbit_count, refuse_beyond_budget
from thermojitter.orbit import Orbit
from thermojitter.panel import LAYUP_FIELDS, Panel
from thermojitter.progress import DeferredInterrupt, progress_bar, report_interrupted
from thermojitter.simulate import check_inputs, check_layers, layup_dict
from thermojitter.solver import ATOL, MAX_STEPS, RTOL, SolverSettings

Sampler = Literal["random", "lhs", "sobol"]

METRICS = (
    "theta_eq", "growth_rate", "frequency_hz", "stable", "critical_damping", "theta_abs_max",
    "amplitude", "entry_peak", "exit_peak", "jitter_rms", "jitter_peak", "t_threshold",
    "orbit_threshold", "orbit_limit", "amplitude_slope", "t_nonlinear", "t_reached", "n_steps",
    "error",
)  # fmt: skip
"""Columns of the metrics, after the sampled parameters (angles rad, times s, rates 1/s):

- ``theta_eq``: sunlit equilibrium angle at full Sun;
- ``growth_rate``, ``frequency_hz``, ``stable``: linear stability of that equilibrium
  (``tj.flutter``); ``stable`` is a nullable boolean (pandas ``"boolean"``), missing (NA) for a
  sample that failed, so that ``(~frame.stable).mean()`` is the share of the finished samples
  that flutter; ``critical_damping``: c_d at which the growth rate crosses zero, N m s/rad;
- ``theta_abs_max``: max abs(θ) over the horizon; ``amplitude``: max abs(θ − θ_eq);
- ``entry_peak``/``exit_peak``: max abs(θ − θ_eq) within ``window`` s after a shadow entry / exit;
- ``jitter_rms``/``jitter_peak``: of θ − M_T/K_el (the oscillation about the quasi-static
  deflection) over the horizon;
- ``t_threshold``/``orbit_threshold``: first time (s) and orbit at which abs(θ) passed
  ``threshold`` (NaN: never, or no threshold);
- ``orbit_limit``: first orbit whose abs(θ) passed the validity limit (20°; NaN: none);
- ``amplitude_slope``: growth (> 0) or decay of the per-orbit amplitude over the run, the
  least-squares slope of ln(amplitude) against the orbit index, 1/orbit;
- ``t_nonlinear``: simulated time integrated with the full non-linear model, s (the whole run
  unless ``method="hybrid"``);
- ``t_reached``: where the integration ended (the horizon, unless stopped at the threshold);
- ``n_steps``: accepted integrator steps (nullable ``"Int64"``, NA for a failed sample);
  ``error``: why a sample failed (None when it did not; its numbers are then NaN, its ``stable``
  and ``n_steps`` NA).

A study counts its failed samples in ``frame.attrs["n_failed"]`` and warns with a
:class:`thermojitter.SampleFailureWarning` naming the first; a study whose every sample failed
raises :class:`AllSamplesFailedError`.
"""

_FLOAT_METRICS = tuple(m for m in METRICS if m not in ("stable", "n_steps", "error"))

FORMAT_VERSION = 1


class AllSamplesFailedError(_core.IntegrationError):
    """Every sample of a study failed: there is no result to give. An ``IntegrationError``, so
    that code catching a failed run catches this too.

    ``n``: the samples run; ``first_sample`` and ``first_error``: the first failed sample's number
    and its reason; ``samples``: the study's frame, every row with its ``error``.
    """

    def __init__(self, n: int, first_sample: int, first_error: str, samples: Any = None) -> None:
        self.n = n
        self.first_sample = first_sample
        self.first_error = first_error
        self.samples = samples
        every = "the only sample" if n == 1 else f"all {n} samples"
        super().__init__(
            f"{every} of the study failed, nothing was computed (sample {first_sample}: "
            f"{first_error}); every reason is in the 'error' column of the exception's .samples"
        )

    def __reduce__(self) -> tuple[Any, ...]:
        # Crosses process boundaries with its numbers; the frame stays behind.
        return (type(self), (self.n, self.first_sample, self.first_error))


# --- distributions --------------------------------------------------------------------------


def _valid_range(name: str) -> tuple[float, float, bool, bool]:
    """(lo, hi, lo open, hi open) of a panel parameter: the engine's range, which Panel
    validation checks (its high end is closed)."""
    lo, hi, lo_open = _core.PANEL_RANGES[name]
    return lo, hi, lo_open, False


def _numbers(name: str, spec: Sequence[Any], count: int, usage: str) -> list[float]:
    args = list(spec[1:])
    if len(args) != count:
        raise ValueError(f"vary[{name!r}] = {spec!r} is invalid: expected {usage}")
    out = []
    for a in args:
        if isinstance(a, bool) or not isinstance(a, (int, float, np.floating, np.integer)):
            raise ValueError(f"vary[{name!r}] = {spec!r} is invalid: {a!r} is not a number")
        if not math.isfinite(float(a)):
            raise ValueError(f"vary[{name!r}] = {spec!r} is invalid: {a!r} is not finite")
        out.append(float(a))
    return out


def _shorthand(name: str, spec: Sequence[Any]) -> Any:
    kind = spec[0]

    def bad(reason: str) -> ValueError:
        return ValueError(f"vary[{name!r}] = {tuple(spec)!r} is invalid: {reason}")

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
            raise ValueError(
                f"vary[{name!r}] = {spec!r} is invalid: not a proper univariate distribution "
                "(its median is not a finite number; check its parameters)"
            )
        return spec
    raise ValueError(
        f"vary[{name!r}] = {spec!r} is invalid: give a frozen scipy.stats distribution or a "
        "shorthand such as ('uniform', lo, hi) or ('normal', mean, sd)"
    )


def _describe(spec: Any) -> Any:
    """A JSON form of a distribution spec, for the settings fingerprint."""
    if isinstance(spec, (tuple, list)):
        return [v if isinstance(v, str) else float(v) for v in spec]
    dist = getattr(spec, "dist", None)
    return {
        "dist": getattr(dist, "name", type(spec).__name__),
        "args": [float(a) for a in getattr(spec, "args", ())],
        "kwds": {k: float(v) for k, v in sorted(getattr(spec, "kwds", {}).items())},
    }


def _check_names(names: Sequence[Any], what: str) -> None:
    fields = Panel.field_names()
    for name in names:
        if not isinstance(name, str) or name not in fields:
            raise ValueError(
                f"{what}: {name!r} is not a panel parameter; choose from {', '.join(fields)}"
            )


# --- designs --------------------------------------------------------------------------------


def _unit_design(sampler: str, n: int, d: int, seed: int) -> NDArray[np.float64]:
    """n points of the unit cube [0, 1)^d, deterministic in (sampler, n, d, seed)."""
    rng = np.random.default_rng(seed)
    if sampler == "random":
        return rng.random((n, d))
    if sampler == "lhs":
        engine: qmc.QMCEngine = _qmc(qmc.LatinHypercube, d, rng)
    elif sampler == "sobol":
        engine = _qmc(qmc.Sobol, d, rng, scramble=True)
    else:
        raise ValueError(f"sampler = {sampler!r} is invalid: must be 'random', 'lhs' or 'sobol'")
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


def _quantiles(name: str, dist: Any, u: NDArray[np.float64], truncate: bool) -> NDArray[np.float64]:
    """Maps unit points through the distribution's ppf; with ``truncate``, through the ppf
    restricted to the parameter's valid range."""
    u = _open_unit(u)
    if not truncate:
        with np.errstate(all="ignore"):
            return np.asarray(dist.ppf(u), dtype=float)
    lo, hi, lo_open, hi_open = _valid_range(name)
    with np.errstate(all="ignore"):
        a, b = float(dist.cdf(lo)), float(dist.cdf(hi))
    if not b - a > 0:
        raise ValueError(
            f"vary[{name!r}]: the distribution has no probability inside the valid range of "
            f"{name} ({lo:g}, {hi:g}); truncation is impossible"
        )
    with np.errstate(all="ignore"):
        x = np.asarray(dist.ppf(a + u * (b - a)), dtype=float)
    # Rounding at the ends of the interval must not step outside the range.
    low = np.nextafter(lo, math.inf) if lo_open else lo
    high = np.nextafter(hi, -math.inf) if hi_open else hi
    return np.clip(x, low, high)


def _panel_matrix(panel: Panel, names: Sequence[str], values: NDArray[np.float64]) -> Any:
    """Rows of every panel field (PANEL_FIELDS order): the base panel with ``names`` replaced."""
    fields = list(_core.PANEL_FIELDS)
    base = panel.as_dict()
    rows = np.tile(np.array([base[f] for f in fields], dtype=float), (len(values), 1))
    for j, name in enumerate(names):
        rows[:, fields.index(name)] = values[:, j]
    return np.ascontiguousarray(rows)


def _refuse_invalid(matrix: NDArray[np.float64], hint: str) -> None:
    """Runs the panel validation on every row; refuses the design naming the parameter."""
    bad = _core.check_panels(matrix)
    if not bad:
        return
    by_name: dict[str, list[tuple[int, str]]] = {}
    for row, name, message in bad:
        by_name.setdefault(name, []).append((row, message))
    name, rows = next(iter(by_name.items()))
    row, message = rows[0]
    value = matrix[row, list(_core.PANEL_FIELDS).index(name)]
    raise ParameterError(
        name,
        float(value),
        message=f"{name}: {len(rows)} of {len(matrix)} samples are outside its valid range "
        f"(sample {row}: {message}){hint}",
    )


# --- running chunks ---------------------------------------------------------------------------


def _options(
    orbit: Orbit,
    horizon: int,
    model: str,
    coupled: bool,
    method: str | None,
    solver: SolverSettings | None,
    rtol: float,
    atol: float,
    dt: float | None,
    max_steps: int,
    window: float,
    threshold: float | None,
    stop_at_threshold: bool,
) -> dict[str, Any]:
    """The keyword arguments of MonteCarloPool.run shared by every chunk (plain data), from the
    study's own arguments (those monte_carlo, sweep and sensitivity share)."""
    chosen = _default_method(method, orbit, horizon)
    # The method as given (None: the solver's or the default); "hybrid" is no solver method.
    full = SolverSettings.of(
        solver, method=None if method == "hybrid" else method, rtol=rtol, atol=atol, dt=dt,
        max_steps=max_steps,
    )  # fmt: skip
    horizon = orbit_count("horizon", horizon, orbit)
    threshold = checks.optional_positive("threshold", threshold)
    window = checks.positive("window", window)
    hybrid = chosen == "hybrid"
    return {
        "orbit": orbit.as_dict(),
        "model": checks.choice("model", model, ("nonlinear", "linear")),
        "coupled": checks.flag("coupled", coupled),
        # The hybrid propagator falls back on the hinge-resolved rk45 where it must.
        "solver": (full.replace(method="rk45") if hybrid else full).as_dict(),
        "n_orbits": int(horizon),
        "window": float(window),
        "threshold": None if threshold is None else float(threshold),
        "stop_at_threshold": checks.flag("stop_at_threshold", stop_at_threshold),
        "validity_limit": DEFAULT_THETA_LIMIT,
        "hybrid": {} if hybrid else None,
    }


def _with_layers(
    options: dict[str, Any], panel: Panel, layers: Any, names: Sequence[str]
) -> dict[str, Any]:
    """The run options with the N-node through-thickness model (``layers`` nodes) on the
    panel's layup, or on each sample's panel as one homogeneous layer for a plain panel.

    The hybrid propagator, when asked, runs the N-node model too. On a laminate panel the fields
    its layup decides cannot be varied (the N-node model takes them from the layers)."""
    if layers is None:
        return options
    nodes = check_layers(layers)
    # Run-wide: a node count the layup cannot take is refused here, not by every sample.
    _core.conduction_grid(panel.as_dict(), layup_dict(panel), nodes)
    if panel.layup is not None:
        fixed = [name for name in names if name in LAYUP_FIELDS]
        if fixed:
            raise ParameterError(
                f"vary.{fixed[0]}",
                fixed[0],
                message=(
                    f"{fixed[0]} of a laminate panel follows from its layup, which layers={nodes} "
                    "integrates layer by layer: vary a plain panel, or run one study per laminate"
                ),
            )
    return {**options, "nodes": nodes, "layup": layup_dict(panel)}


def _default_method(method: str | None, orbit: Orbit, horizon: Any) -> str:
    """``None``: the hybrid propagator over a month or more, the hinge-resolved rk45 below."""
    if method is not None:
        return method
    # horizon is compared, not multiplied: an int too large for a float is refused later.
    long = isinstance(horizon, (int, np.integer)) and horizon >= 30 * 86400.0 / orbit.period
    return "hybrid" if long else "rk45"


# Rows come from the engine's lockstep lanes (several samples per core at once); False runs one
# sample at a time per core, which gives the same rows bit for bit (benches/montecarlo.py times
# both, tests/test_montecarlo.py compares them).
_LOCKSTEP = True


def _run_chunk(
    pool: Any, panels: NDArray[np.float64], options: dict[str, Any], cancel: Any = None
) -> dict[str, Any]:
    opts = dict(options)
    orbit = opts.pop("orbit")
    raw = pool.run(panels, orbit, cancel=cancel, lockstep=_LOCKSTEP, **opts)
    out: dict[str, Any] = {m: np.asarray(raw[m], dtype=float) for m in _FLOAT_METRICS}
    out["stable"] = np.asarray(raw["stable"], dtype=bool)
    out["n_steps"] = np.asarray(raw["n_steps"], dtype=np.int64)
    out["error"] = list(raw["error"])
    out["solver"] = dict(raw["solver"])  # the settings the engine reports it ran with
    return out


_WORKER_POOLS: dict[tuple[str, int], Any] = {}
_WORKER_POOLS_LOCK = threading.Lock()


def dask_chunk(panels: NDArray[np.float64], options: dict[str, Any]) -> dict[str, Any]:
    """Runs one chunk on a Dask worker, on a rayon pool of as many threads as the worker has.

    Tasks that run at once on one worker share its pool, so the worker's cores are not
    oversubscribed. Takes and returns plain data (a NumPy array, dicts, lists).
    """
    try:
        from distributed import get_worker

        worker = get_worker()
        key = (str(worker.address), int(worker.state.nthreads))
    except (ImportError, ValueError):  # called outside a worker
        key = ("local", 0)
    with _WORKER_POOLS_LOCK:
        pool = _WORKER_POOLS.get(key)
        if pool is None:
            pool = _core.MonteCarloPool(key[1] or None)
            _WORKER_POOLS[key] = pool
    return _run_chunk(pool, panels, options)


def _local_chunks(
    matrix: NDArray[np.float64],
    todo: list[tuple[int, int, int]],
    options: dict[str, Any],
    threads: int | None,
) -> Generator[tuple[int, dict[str, Any]], None, None]:
    """Yields (chunk, metrics) as chunks finish. Two chunks are in flight at once on one rayon
    pool, so the pool's threads stay busy while a chunk finishes its last samples. Leaving early
    (Ctrl-C in the consumer) cancels the engine's token: the running chunks stop within one
    integration step and are dropped."""
    pool = _core.MonteCarloPool(threads)
    token = _core.CancelToken()
    with cf.ThreadPoolExecutor(max_workers=2, thread_name_prefix="thermojitter") as ex:
        futures = {ex.submit(_run_chunk, pool, matrix[a:b], options, token): k for k, a, b in todo}
        try:
            for fut in cf.as_completed(futures):
                yield futures[fut], fut.result()
        finally:
            token.cancel()
            for fut in futures:
                fut.cancel()


def _dask_client(backend: Any) -> tuple[Any, bool]:
    """(client, owned): a Client given, one connected to an address, or a new LocalCluster."""
    if callable(getattr(backend, "submit", None)) and hasattr(backend, "scheduler_info"):
        return backend, False
    try:
        from distributed import Client, LocalCluster
    except ImportError as exc:
        raise ImportError(
            "backend='dask' needs dask.distributed: pip install 'thermojitter[dask]'"
        ) from exc
    if backend == "dask":
        return Client(LocalCluster(dashboard_address=":0")), True  # any free port
    if isinstance(backend, str):
        return Client(backend), True
    raise ValueError(
        f"backend = {backend!r} is invalid: must be None, 'dask', a scheduler address "
        "('tcp://host:8786') or a dask.distributed Client"
    )


def _dask_chunks(
    client: Any,
    matrix: NDArray[np.float64],
    todo: list[tuple[int, int, int]],
    options: dict[str, Any],
) -> Generator[tuple[int, dict[str, Any]], None, None]:
    from distributed import as_completed

    futures = {client.submit(dask_chunk, matrix[a:b], options, pure=False): k for k, a, b in todo}
    try:
        for fut in as_completed(list(futures)):
            yield futures[fut], fut.result()
    finally:
        client.cancel([f for f in futures if not f.done()])


# --- checkpoints ----------------------------------------------------------------------------


def _chunk_path(directory: Path, k: int) -> Path:
    return directory / f"chunk-{k:05d}.parquet"


_CHUNK_REQUEST = b"thermojitter.request"
_CHUNK_CHECKSUM = b"thermojitter.checksum"


def _chunk_digest(columns: dict[str, Any]) -> str:
    """SHA-256 over a chunk's columns (names, values to the bit, error strings)."""
    h = hashlib.sha256()
    for name in sorted(columns):
        h.update(name.encode() + b"\0")
        value = columns[name]
        if name == "error":
            h.update(checkpoints.canonical(list(value)))
        else:
            h.update(np.ascontiguousarray(np.asarray(value, dtype=float)).tobytes())
    return h.hexdigest()


def _write_chunk(
    directory: Path, k: int, start: int, metrics: dict[str, Any], request: str
) -> bool:
    """Writes chunk ``k`` atomically, with the request's fingerprint and a checksum of its
    content in the Parquet metadata. On failure (a full disk, say) warns and returns False: the
    chunk stays in memory and in the result, and no partial file is left."""
    import pyarrow as pa
    import pyarrow.parquet as pq

    n = len(metrics["error"])
    columns: dict[str, Any] = {"sample": np.arange(start, start + n, dtype=np.int64)}
    for m in METRICS:
        columns[m] = metrics[m]
    meta = {_CHUNK_REQUEST: request.encode(), _CHUNK_CHECKSUM: _chunk_digest(columns).encode()}
    columns["error"] = pa.array(metrics["error"], type=pa.string())
    table = pa.table(columns).replace_schema_metadata(meta)
    path = _chunk_path(directory, k)
    try:
        checkpoints.write_atomic(path, lambda fh: pq.write_table(table, fh))
    except OSError as exc:
        warnings.warn(
            f"checkpoint chunk {path} could not be written ({exc.strerror or exc}); its samples "
            "are kept in memory and returned",
            RuntimeWarning,
            stacklevel=2,
        )
        return False
    return True


def _read_chunk(
    directory: Path, k: int, start: int, stop: int, request: str
) -> dict[str, Any] | None:
    """Chunk ``k`` if it is intact and was written for ``request``; None if absent. A damaged,
    edited or foreign chunk is refused naming the file."""
    import pyarrow.parquet as pq

    path = _chunk_path(directory, k)
    if not path.exists():
        return None
    try:
        table = pq.read_table(path)
        meta = table.schema.metadata or {}
        columns: dict[str, Any] = {"sample": table.column("sample").to_numpy()}
        for m in METRICS:
            if m == "error":
                columns[m] = table.column(m).to_pylist()
            else:
                columns[m] = table.column(m).to_numpy()
    except Exception:  # pyarrow raises several kinds on a damaged file
        raise checkpoints.CheckpointError(
            "checkpoint", path, "is damaged (not a readable chunk)"
        ) from None
    if meta.get(_CHUNK_REQUEST) != request.encode():
        raise checkpoints.CheckpointError(
            "checkpoint", path, "was written for another request (seed, n, design or settings)"
        )
    if meta.get(_CHUNK_CHECKSUM) != _chunk_digest(columns).encode():
        raise checkpoints.CheckpointError(
            "checkpoint", path, "is damaged or was edited (its checksum does not match)"
        )
    if not np.array_equal(columns["sample"], np.arange(start, stop)):
        raise checkpoints.CheckpointError(
            "checkpoint", path, f"does not hold samples {start}..{stop - 1}"
        )
    del columns["sample"]
    return columns


def _open_checkpoint(directory: Path, settings: dict[str, Any], n: int, chunk_size: int) -> int:
    """Creates or checks the manifest; returns the chunk size the directory was started with.
    Without a manifest, chunks already in the folder are still checked one by one against the
    request's fingerprint when they are read."""
    try:
        directory.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise checkpoints.CheckpointError(
            "checkpoint", directory, f"cannot be created ({exc.strerror or exc})"
        ) from None
    manifest = directory / "manifest.json"
    saved = checkpoints.load(manifest, settings)
    if saved is not None:
        size = saved.get("chunk_size")
        if not isinstance(size, int) or size < 1:
            raise checkpoints.CheckpointError("checkpoint", manifest, "has no valid chunk_size")
        return size
    try:
        checkpoints.save(manifest, settings, {"n": n, "chunk_size": chunk_size})
    except OSError as exc:
        warnings.warn(
            f"checkpoint {manifest} could not be written ({exc.strerror or exc}); the run goes "
            "on and returns its result",
            RuntimeWarning,
            stacklevel=3,
        )
    return chunk_size


# --- the driver -------------------------------------------------------------------------------


def _default_chunk_size(n: int) -> int:
    """Depends on n only, so that a default run cuts the same chunks on any machine: about a
    sixteenth of the run, at most 64, and a multiple of what two cores run at once in the
    engine's lockstep lanes, so that on two cores or more a chunk keeps their lanes full (the
    engine gives each thread a share of a chunk, at most a core's worth)."""
    two_cores = 2 * _core.ENSEMBLE_RUNS_PER_CORE
    return min(max(64 // two_cores, 1) * two_cores, two_cores * math.ceil(n / (16 * two_cores)))


def _frame(
    names: Sequence[str],
    values: NDArray[np.float64],
    chunks: list[dict[str, Any]],
    rows: NDArray[np.int64] | None = None,
) -> Any:
    """The samples' frame; ``rows``: the sample numbers the chunks hold (default: all)."""
    import pandas as pd

    if rows is None:
        rows = np.arange(len(values))
    data: dict[str, Any] = {name: values[rows, j] for j, name in enumerate(names)}
    errors = [e for c in chunks for e in c["error"]]
    for m in METRICS:
        if m == "error":
            data[m] = pd.Series(errors, dtype=object)
        else:
            data[m] = np.concatenate([np.asarray(c[m]) for c in chunks] or [np.empty(0)])
    # The engine (and the chunks stored from it) gives a failed sample stable = False and no
    # steps; both would read as answers (flutter, a run of 0 steps), so they are missing here.
    failed = np.array([e is not None for e in errors], dtype=bool)
    data["stable"] = pd.arrays.BooleanArray(np.asarray(data["stable"], dtype=bool), failed)
    data["n_steps"] = pd.arrays.IntegerArray(np.asarray(data["n_steps"], dtype=np.int64), failed)
    frame = pd.DataFrame(data)
    frame.index = (
        pd.RangeIndex(len(values), name="sample")
        if len(rows) == len(values)
        else pd.Index(rows, name="sample")
    )
    return frame


def _refuse_beyond_budget(
    matrix: NDArray[np.float64], options: dict[str, Any], settings: dict[str, Any]
) -> None:
    """Refuses, before any work, a design whose samples together need more integrator steps than
    ``max_steps`` (the study's budget; each sample also stops at it): a sample that needs more
    names ``horizon``, a design that does names its size. The hybrid's least cost is not known
    up front (its sunlit arcs take no step); each of its samples stops at the budget."""
    if options["hybrid"] is not None:
        return
    solver = options["solver"]
    period = float(options["orbit"]["period"])
    least = _core.least_steps(matrix, solver, options["n_orbits"] * period)
    budget = int(solver["max_steps"])
    horizon = options["n_orbits"]
    per = f"{least.max() / horizon:.3g} per orbit of the slowest sample"
    refuse_beyond_budget("horizon", horizon, float(least.max()), budget, per)
    size = "grid" if settings["study"] == "sweep" else "n"
    what = f"{len(matrix)} samples of {horizon} orbits, {per}"
    value = settings.get(size, len(matrix)) if size == "n" else f"{len(matrix)} panels"
    refuse_beyond_budget(size, value, float(least.sum()), budget, what)


def _run_design(
    names: Sequence[str],
    values: NDArray[np.float64],
    matrix: NDArray[np.float64],
    options: dict[str, Any],
    settings: dict[str, Any],
    *,
    threads: int | None,
    backend: Any,
    checkpoint: str | os.PathLike[str] | None,
    chunk_size: int | None,
    progress: bool,
) -> Any:
    n = len(matrix)
    checks.flag("progress", progress)
    if threads is not None:
        threads = checks.integer("threads", threads, 1, _core.MAX_THREADS)
    _refuse_beyond_budget(matrix, options, settings)
    if chunk_size is None:
        chunk_size = _default_chunk_size(n)
    else:
        chunk_size = checks.integer("chunk_size", chunk_size, 1)
    settings = {
        **settings,
        "format": FORMAT_VERSION,
        "run": options,
        "design_sha256": hashlib.sha256(np.ascontiguousarray(matrix).tobytes()).hexdigest(),
    }
    directory = checks.path("checkpoint", checkpoint) if checkpoint is not None else None
    request = checkpoints.digest(settings)
    if directory is not None:
        chunk_size = _open_checkpoint(directory, settings, n, chunk_size)
    bounds = [(k, a, min(n, a + chunk_size)) for k, a in enumerate(range(0, n, chunk_size))]
    done: dict[int, dict[str, Any]] = {}
    if directory is not None:
        for k, a, b in bounds:
            chunk = _read_chunk(directory, k, a, b, request)
            if chunk is not None:
                done[k] = chunk
    todo = [c for c in bounds if c[0] not in done]

    bar = progress_bar(
        n, initial=sum(b - a for k, a, b in bounds if k in done), unit="sample", enabled=progress
    )
    client, owned = (None, False) if backend is None else _dask_client(backend)
    interrupted = False
    try:
        if todo:
            stream: Generator[tuple[int, dict[str, Any]], None, None] = (
                _local_chunks(matrix, todo, options, threads)
                if client is None
                else _dask_chunks(client, matrix, todo, options)
            )
            written = set(done)
            failed_write = False  # after one failed write, the rest are kept in memory only
            # closing: on any error (Ctrl-C included) the pending chunks are cancelled at once;
            # Ctrl-C during a chunk's write is raised when the write is whole.
            with DeferredInterrupt() as ctrl_c, contextlib.closing(stream):
                try:
                    for k, metrics in stream:
                        done[k] = metrics
                        start, stop = bounds[k][1], bounds[k][2]
                        if directory is not None and not failed_write:
                            with ctrl_c.hold():
                                failed_write = not _write_chunk(
                                    directory, k, start, metrics, request
                                )
                                written.add(k)
                        if bar is not None:
                            bar.update(stop - start)
                except BaseException as exc:
                    # A finished chunk not yet written is written before leaving.
                    if directory is not None and not failed_write:
                        with ctrl_c.hold(then_raise=False):
                            for k in sorted(set(done) - written):
                                _write_chunk(directory, k, bounds[k][1], done[k], request)
                    if not isinstance(exc, KeyboardInterrupt):
                        raise
                    interrupted = True
    finally:
        if bar is not None:
            bar.close()
        if owned and client is not None:
            cluster = getattr(client, "cluster", None)
            client.close()
            if cluster is not None:
                cluster.close()
    finished = [(k, a, b) for k, a, b in bounds if k in done]
    rows = np.concatenate([np.arange(a, b) for _, a, b in finished] or [np.empty(0, np.int64)])
    frame = _frame(names, values, [done[k] for k, _, _ in finished], rows.astype(np.int64))
    frame.attrs["settings"] = settings
    # The solver settings the engine reports it ran the samples with (a plain mapping, so that
    # the frame's attrs stay JSON for Parquet; solver_of(frame) gives the SolverSettings). When
    # every chunk was read from the checkpoint no engine ran: its reading of the same settings
    # (the check every run makes of them) stands for it.
    echoes = [done[k]["solver"] for k, _, _ in finished if "solver" in done[k]]
    frame.attrs["solver"] = dict(echoes[0] if echoes else _core.check_solver(options["solver"]))
    frame.attrs["interrupted"] = interrupted
    if interrupted:
        kept = f"kept {len(frame)} of {n} samples (frame.attrs['interrupted'] is True)"
        if directory is not None:
            report_interrupted(
                f"{kept}; finished chunks are in {directory}",
                "run the same call again to resume",
            )
        else:
            report_interrupted(kept, "pass checkpoint=DIR to make a run resumable")
    _report_failures(frame)
    return frame


def _report_failures(frame: Any) -> None:
    """Counts the failed samples in ``frame.attrs["n_failed"]``; warns once when some failed
    (stacklevel: the caller of the study), raises AllSamplesFailedError when all did."""
    failed = frame["error"].notna().to_numpy()
    n_failed = int(failed.sum())
    frame.attrs["n_failed"] = n_failed
    if n_failed == 0:
        return
    first = int(np.flatnonzero(failed)[0])
    first_sample, first_error = int(frame.index[first]), str(frame["error"].iloc[first])
    if n_failed == len(frame):
        raise AllSamplesFailedError(len(frame), first_sample, first_error, frame)
    warnings.warn(
        f"{n_failed} of {len(frame)} samples failed (sample {first_sample}: {first_error}); "
        "their rows have stable = NA and NaN numbers, the 'error' column says why, "
        "frame.attrs['n_failed'] counts them",
        SampleFailureWarning,
        stacklevel=4,  # _report_failures < _run_design < the study < its caller
    )


def solver_of(frame: Any) -> SolverSettings:
    """The integrator settings the engine ran a study's samples with (``frame.attrs["solver"]``
    of a :func:`monte_carlo`, :func:`sweep` or :func:`sensitivity` frame) as a
    :class:`thermojitter.SolverSettings`; with ``method="hybrid"``, those of its rk45 fallback.
    Each sample's rk45 step is further capped at its hinge period / 40, as long runs cap it."""
    return SolverSettings(**frame.attrs["solver"])


def _check_seed(seed: Any, checkpoint: Any) -> int:
    if seed is None:
        if checkpoint is not None:
            raise ValueError("seed is required with checkpoint (a resumed run must redraw it)")
        return int(np.random.SeedSequence().entropy % (2**63))  # type: ignore[operator]
    return checks.integer("seed", seed, 0)


MAX_SAMPLES = 10**7
"""Most samples of one study: its design is held in memory (about 140 bytes a sample, over a
gigabyte at the limit), and so many runs of even one orbit take CPU-days."""


def _check_n(n: Any, least: int = 1) -> int:
    return checks.integer("n", n, least, MAX_SAMPLES)


def _sampled(
    panel: Panel,
    vary: Mapping[str, Any],
    u: NDArray[np.float64],
    truncate: bool,
) -> tuple[list[str], NDArray[np.float64], NDArray[np.float64]]:
    """(names, sampled values, full panel rows) of unit points ``u`` mapped through ``vary``."""
    names = list(vary)
    dists = [distribution(name, vary[name]) for name in names]
    values = np.column_stack(
        [
            _quantiles(name, dist, u[:, j], truncate)
            for j, (name, dist) in enumerate(zip(names, dists, strict=True))
        ]
    )
    matrix = _panel_matrix(panel, names, values)
    hint = "" if truncate else "; narrow the distribution or pass truncate=True"
    _refuse_invalid(matrix, hint)
    return names, values, matrix


def _check_vary(vary: Any) -> Mapping[str, Any]:
    if not isinstance(vary, Mapping) or not vary:
        raise ValueError(
            "vary must be a non-empty mapping of panel parameter names to distributions"
        )
    _check_names(list(vary), "vary")
    return vary


def monte_carlo(
    panel: Panel,
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
) -> Any:
    """Runs ``n`` panels drawn around ``panel`` and returns a pandas DataFrame, one row a sample:
    the sampled parameters, then the metrics (see ``METRICS``).

    - ``vary``: panel parameter name → frozen scipy.stats distribution or shorthand
      (``("uniform", lo, hi)``, ``("normal", mean, sd)``, ``("lognormal", median, sigma)``,
      ``("loguniform", lo, hi)``, ``("truncnorm", mean, sd, lo, hi)``,
      ``("triangular", lo, mode, hi)``). A design with a sample outside a parameter's valid range
      (e.g. an emissivity above 1) is refused before anything runs, unless ``truncate=True``:
      then each distribution is truncated to the valid range.
    - ``sampler``: ``"random"`` (NumPy generator; sample i depends on the seed and i only, so a
      larger n extends a study), ``"lhs"`` (Latin hypercube) or ``"sobol"``
      (scrambled; best with n a power of 2), all seeded by ``seed`` (None: a fresh seed, kept in
      ``frame.attrs["seed"]``; required with ``checkpoint``).
    - ``horizon``: whole orbits integrated from t = 0, starting at the sunlit equilibrium.
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

    The frame is identical, bit for bit, for any ``threads``, ``chunk_size`` and backend.
    """
    check_inputs(panel, orbit)
    vary = _check_vary(vary)
    n = _check_n(n)
    seed = _check_seed(seed, checkpoint)
    sampler = checks.choice("sampler", sampler, ("random", "lhs", "sobol"))  # type: ignore[assignment]
    truncate = checks.flag("truncate", truncate)
    options = _options(
        orbit, horizon, model, coupled, method, solver, rtol, atol, dt, max_steps, window,
        threshold, stop_at_threshold,
    )  # fmt: skip
    options = _with_layers(options, panel, layers, list(vary))
    u = _unit_design(sampler, n, len(vary), seed)
    names, values, matrix = _sampled(panel, vary, u, bool(truncate))
    settings = {
        "study": "monte_carlo",
        "panel": panel.as_dict(),
        "vary": {name: _describe(vary[name]) for name in names},
        "n": n,
        "seed": seed,
        "sampler": sampler,
        "truncate": bool(truncate),
    }
    frame = _run_design(
        names, values, matrix, options, settings, threads=threads, backend=backend,
        checkpoint=checkpoint, chunk_size=chunk_size, progress=progress,
    )  # fmt: skip
    frame.attrs["seed"] = seed
    return frame


def sweep(
    panel: Panel,
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
) -> Any:
    """Full-factorial study: every combination of the ``grid`` values (parameter name → values),
    the first parameter varying slowest. Returns a DataFrame like ``monte_carlo``'s; the other
    arguments (``layers`` too) are the same, and so is the handling of failed samples (a
    warning and ``frame.attrs["n_failed"]``; :class:`AllSamplesFailedError` when all failed)."""
    check_inputs(panel, orbit)
    if not isinstance(grid, Mapping) or not grid:
        raise ValueError("grid must be a non-empty mapping of panel parameter names to values")
    _check_names(list(grid), "grid")
    axes: list[list[float]] = []
    for name, vals in grid.items():
        arr = checks.real_array(f"grid.{name}", vals)  # numbers: not bools, not strings
        if arr.size == 0:
            raise ParameterError(f"grid.{name}", vals, "must hold at least one value")
        axes.append(arr.tolist())
    options = _options(
        orbit, horizon, model, coupled, method, solver, rtol, atol, dt, max_steps, window,
        threshold, stop_at_threshold,
    )  # fmt: skip
    names = list(grid)
    size = math.prod(len(a) for a in axes)
    if size > MAX_SAMPLES:
        raise ParameterError("grid", f"{size} panels", f"must hold at most {MAX_SAMPLES} panels")
    options = _with_layers(options, panel, layers, names)
    values = np.array(list(itertools.product(*axes)), dtype=float).reshape(-1, len(names))
    matrix = _panel_matrix(panel, names, values)
    _refuse_invalid(matrix, "")
    settings = {
        "study": "sweep",
        "panel": panel.as_dict(),
        "grid": dict(zip(names, axes, strict=True)),
    }
    return _run_design(
        names, values, matrix, options, settings, threads=threads, backend=backend,
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
    panel: Panel,
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
) -> SensitivityResult:
    """Sobol sensitivity indices of one metric to the parameters in ``vary`` (needs SALib:
    ``pip install 'thermojitter[sensitivity]'``).

    Runs n·(d + 2) samples (n·(2d + 2) with ``second_order``) of Saltelli's design (best with n
    a power of 2), mapped through the distributions of ``vary`` like ``monte_carlo``, whose other
    arguments (``layers`` too) these are. ``indices`` holds ``S1``, ``S1_conf``, ``ST``,
    ``ST_conf`` per parameter (first-order and total indices, 95 % confidence half-widths).

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

    check_inputs(panel, orbit)
    vary = _check_vary(vary)
    n = _check_n(n, 2)
    seed = _check_seed(seed, None)
    second_order = checks.flag("second_order", second_order)
    truncate = checks.flag("truncate", truncate)
    if not isinstance(metric, str):
        raise TypeError(f"metric must be a string, not {type(metric).__name__}")
    if metric not in _FLOAT_METRICS and metric != "stable":
        choices = ", ".join((*_FLOAT_METRICS, "stable"))
        raise ValueError(f"metric = {metric!r} is invalid: choose from {choices}")
    options = _options(
        orbit, horizon, model, coupled, method, solver, rtol, atol, dt, max_steps, window,
        threshold, stop_at_threshold,
    )  # fmt: skip
    names = list(vary)
    options = _with_layers(options, panel, layers, names)
    problem = {"num_vars": len(names), "names": names, "bounds": [[0.0, 1.0]] * len(names)}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)  # n not a power of 2
        u = np.asarray(
            sobol_sample.sample(problem, n, calc_second_order=second_order, seed=seed), dtype=float
        )
    names, values, matrix = _sampled(panel, vary, u, bool(truncate))
    settings = {
        "study": "sensitivity",
        "panel": panel.as_dict(),
        "vary": {name: _describe(vary[name]) for name in names},
        "n": n,
        "seed": seed,
        "second_order": bool(second_order),
        "truncate": bool(truncate),
    }
    samples = _run_design(
        names, values, matrix, options, settings, threads=threads, backend=backend,
        checkpoint=checkpoint, chunk_size=chunk_size, progress=progress,
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
        raise ValueError(
            f"{metric} is not defined for {missing.size} of {len(y)} samples (sample {k}: "
            f"{why}); Sobol indices need a value for every sample"
        )
    res = sobol_analyze.analyze(problem, y, calc_second_order=second_order, seed=seed)
    indices = pd.DataFrame(
        {k: np.asarray(res[k], dtype=float) for k in ("S1", "S1_conf", "ST", "ST_conf")},
        index=pd.Index(names, name="parameter"),
    )
    return SensitivityResult(indices=indices, metric=metric, samples=samples)
