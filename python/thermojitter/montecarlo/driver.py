"""The driver of a study: the run options every chunk shares, the chunking, the checkpoint, the
backend, progress and Ctrl-C, and the frame it returns."""

from __future__ import annotations

import contextlib
import hashlib
import math
import os
import warnings
from collections.abc import Generator, Mapping, Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from thermojitter import _core
from thermojitter import checkpoint as checkpoints
from thermojitter import errors as checks
from thermojitter.attitude import Attitude, engine_orbit
from thermojitter.boom import Boom, check_attitude
from thermojitter.errors import HybridFallbackWarning, ParameterError
from thermojitter.longrun import (
    DEFAULT_THETA_LIMIT,
    HYBRID_FALLBACK,
    on_slow_time,
    orbit_count,
    refuse_beyond_budget,
)
from thermojitter.montecarlo.backends import dask_chunks, dask_client, local_chunks
from thermojitter.montecarlo.metrics import (
    report_failures,
    samples_frame,
)
from thermojitter.montecarlo.store import (
    FORMAT_VERSION,
    open_checkpoint,
    read_chunk,
    write_chunk,
)
from thermojitter.orbit import Orbit
from thermojitter.panel import LAYUP_FIELDS, Panel
from thermojitter.progress import DeferredInterrupt, progress_bar, report_interrupted
from thermojitter.simulate import check_layers, grid_args, layup_dict
from thermojitter.solver import SolverSettings


def run_options(
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
    attitude: Attitude | None = None,
    panel: Panel | Boom | None = None,
) -> dict[str, Any]:
    """The keyword arguments of MonteCarloPool.run shared by every chunk (plain data), from the
    study's own arguments (those monte_carlo, sweep and sensitivity share). The orbit carries
    the study's ``attitude`` (as single runs take it); a ``panel`` that is a boom runs the
    tube's model (``"boom"``)."""
    boom = isinstance(panel, Boom)
    if boom:
        check_attitude(attitude)
    chosen = default_method(method, orbit, horizon)
    # The method as given (None: the solver's or the default); "hybrid" is no solver method.
    full = SolverSettings.of(
        solver, method=None if method == "hybrid" else method, rtol=rtol, atol=atol, dt=dt,
        max_steps=max_steps,
    )  # fmt: skip
    horizon = orbit_count("horizon", horizon, orbit)
    threshold = checks.optional_positive("threshold", threshold)
    window = checks.positive("window", window)
    hybrid = chosen == "hybrid"
    record = orbit.as_record()
    # The attitude is kept only when not Sun-pointing, so that a study without it keeps its
    # settings (and its checkpoint's fingerprint).
    if "attitude" in (with_attitude := engine_orbit(orbit, attitude)):
        record["attitude"] = with_attitude["attitude"]
    options: dict[str, Any] = {
        "orbit": record,
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
    if boom:
        options["boom"] = True
    if face_loads(options, {}):
        # The samples start at, and are analysed about, the equilibrium under every load of the
        # orbit at t = 0 (before, at the Sun's alone): a checkpoint of a study on such an orbit
        # written before that is not resumed with rows computed otherwise.
        options["start"] = "loaded_equilibrium"
    return options


def face_loads(options: Mapping[str, Any], inputs: Mapping[str, Any]) -> bool:
    """Whether some sample of a study heats more than the front's sunlight: the Earth's loads on
    the study's orbit or drawn for a sample, or an attitude other than Sun-pointing."""
    orbit = options["orbit"]
    drawn = [np.asarray(inputs[k]) for k in ("albedo", "earth_ir") if k in inputs]
    return bool(
        orbit.get("albedo", 0.0) != 0.0
        or orbit.get("earth_ir", 0.0) != 0.0
        or "attitude" in orbit
        or any((v != 0.0).any() for v in drawn)
    )


def warn_hybrid_fallback(options: Mapping[str, Any], inputs: Mapping[str, Any]) -> None:
    """Says, once, that the hybrid propagator integrates in full the samples with the Earth's
    loads or another attitude on an orbit of 6 h or more (each then has ``t_nonlinear`` equal to
    ``t_reached``); shorter orbits run on slow time."""
    if (
        options["hybrid"] is not None
        and not options.get("boom")
        and not on_slow_time(options["orbit"]["period"])
        and face_loads(options, inputs)
    ):
        warnings.warn(
            f"{HYBRID_FALLBACK} for the samples with them (their t_nonlinear is the whole run)",
            HybridFallbackWarning,
            stacklevel=4,
        )


def with_layers(
    options: dict[str, Any], panel: Panel | Boom, layers: Any, names: Sequence[str]
) -> dict[str, Any]:
    """The run options with the N-node through-thickness model (``layers`` nodes) on the
    panel's layup, or on each sample's panel as one homogeneous layer for a plain panel.

    The hybrid propagator, when asked, runs the N-node model too. On a laminate panel the fields
    its layup decides cannot be varied (the N-node model takes them from the layers)."""
    if layers is None:
        return options
    if isinstance(panel, Boom):
        raise ParameterError("layers", layers, "a Boom has its own thermal model")
    nodes = check_layers(layers)
    if face_loads(options, {}) or any(name in ("albedo", "earth_ir") for name in names):
        raise ParameterError(
            "layers",
            layers,
            "takes the front's sunlight only: no Earth heating (albedo, earth_ir, drawn or on "
            "the orbit) or attitude",
        )
    # Run-wide: a node count the layup cannot take is refused here, not by every sample.
    _core.conduction_grid(panel.as_dict(), grid_args(panel, nodes))
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


def default_method(method: str | None, orbit: Orbit, horizon: Any) -> str:
    """``None``: the hybrid propagator over a month or more, the hinge-resolved rk45 below."""
    if method is not None:
        return method
    # horizon is compared, not multiplied: an int too large for a float is refused later.
    long = isinstance(horizon, (int, np.integer)) and horizon >= 30 * 86400.0 / orbit.period
    return "hybrid" if long else "rk45"


# Rows come from the engine's lockstep lanes (several samples per core at once); False runs one
# sample at a time per core, which gives the same rows bit for bit (benches/montecarlo.py times
# both, tests/test_montecarlo.py compares them).


def default_chunk_size(n: int) -> int:
    """Depends on n only, so that a default run cuts the same chunks on any machine: about a
    sixteenth of the run, at most 64, and a multiple of what two cores run at once in the
    engine's lockstep lanes, so that on two cores or more a chunk keeps their lanes full (the
    engine gives each thread a share of a chunk, at most a core's worth)."""
    two_cores = 2 * _core.ENSEMBLE_RUNS_PER_CORE
    return min(max(64 // two_cores, 1) * two_cores, two_cores * math.ceil(n / (16 * two_cores)))


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
    span = options["n_orbits"] * period
    least = _core.least_steps(matrix, solver, span, boom=bool(options.get("boom")))
    budget = int(solver["max_steps"])
    horizon = options["n_orbits"]
    per = f"{least.max() / horizon:.3g} per orbit of the slowest sample"
    refuse_beyond_budget("horizon", horizon, float(least.max()), budget, per)
    size = "grid" if settings["study"] == "sweep" else "n"
    what = f"{len(matrix)} samples of {horizon} orbits, {per}"
    value = settings.get(size, len(matrix)) if size == "n" else len(matrix)  # panels of the grid
    refuse_beyond_budget(size, value, float(least.sum()), budget, what)


def run_design(
    names: Sequence[str],
    values: NDArray[np.float64],
    matrix: NDArray[np.float64],
    options: dict[str, Any],
    settings: dict[str, Any],
    inputs: dict[str, Any],
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
    warn_hybrid_fallback(options, inputs)
    if chunk_size is None:
        chunk_size = default_chunk_size(n)
    else:
        chunk_size = checks.integer("chunk_size", chunk_size, 1)
    design = hashlib.sha256(np.ascontiguousarray(matrix).tobytes())
    for name in sorted(inputs):  # each sample's orbit inputs (none: the digest of the panels)
        design.update(name.encode() + b"\0" + np.ascontiguousarray(inputs[name]).tobytes())
    settings = {
        **settings,
        "format": FORMAT_VERSION,
        "run": options,
        "design_sha256": design.hexdigest(),
    }
    directory = checks.path("checkpoint", checkpoint) if checkpoint is not None else None
    request = checkpoints.digest(settings)
    if directory is not None:
        chunk_size = open_checkpoint(directory, settings, n, chunk_size)
    bounds = [(k, a, min(n, a + chunk_size)) for k, a in enumerate(range(0, n, chunk_size))]
    done: dict[int, dict[str, Any]] = {}
    if directory is not None:
        for k, a, b in bounds:
            chunk = read_chunk(directory, k, a, b, request)
            if chunk is not None:
                done[k] = chunk
    todo = [c for c in bounds if c[0] not in done]

    bar = progress_bar(
        n, initial=sum(b - a for k, a, b in bounds if k in done), unit="sample", enabled=progress
    )
    client, owned = (None, False) if backend is None else dask_client(backend)
    interrupted = False
    try:
        if todo:
            stream: Generator[tuple[int, dict[str, Any]], None, None] = (
                local_chunks(matrix, inputs, todo, options, threads)
                if client is None
                else dask_chunks(client, matrix, inputs, todo, options)
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
                                failed_write = not write_chunk(
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
                                write_chunk(directory, k, bounds[k][1], done[k], request)
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
    frame = samples_frame(names, values, [done[k] for k, _, _ in finished], rows.astype(np.int64))
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
    report_failures(frame)
    return frame
