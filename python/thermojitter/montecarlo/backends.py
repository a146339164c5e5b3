"""Where the chunks of a study run: a rayon pool on this machine, or Dask workers (each with its
own pool). Each takes and gives plain data, so that a chunk's rows are the same wherever it ran."""

from __future__ import annotations

import concurrent.futures as cf
import threading
from collections.abc import Generator
from typing import Any

import numpy as np
from numpy.typing import NDArray

from thermojitter import _core
from thermojitter.errors import ParameterError
from thermojitter.montecarlo.metrics import (
    FLOAT_METRICS,
)
from thermojitter.simulate import orbits_args

_LOCKSTEP = True


def run_chunk(
    pool: Any,
    panels: NDArray[np.float64],
    options: dict[str, Any],
    cancel: Any = None,
    inputs: dict[str, Any] | None = None,
) -> dict[str, Any]:
    """Runs the rows of ``panels`` (booms with ``options["boom"]``), each sample's orbit the
    study's with its ``inputs`` (orbit input name → one value a row)."""
    raw = pool.run(
        panels,
        options["orbit"],
        orbits_args(options, options["n_orbits"]),
        threshold=options["threshold"],
        stop_at_threshold=options["stop_at_threshold"],
        validity_limit=options["validity_limit"],
        cancel=cancel,
        lockstep=_LOCKSTEP,
        orbit_inputs=inputs or None,
        boom=bool(options.get("boom", False)),
    )
    out: dict[str, Any] = {m: np.asarray(raw[m], dtype=float) for m in FLOAT_METRICS}
    out["stable"] = np.asarray(raw["stable"], dtype=bool)
    out["n_steps"] = np.asarray(raw["n_steps"], dtype=np.int64)
    out["error"] = list(raw["error"])
    out["solver"] = dict(raw["solver"])  # the settings the engine reports it ran with
    return out


_WORKER_POOLS: dict[tuple[str, int], Any] = {}
_WORKER_POOLS_LOCK = threading.Lock()


def dask_chunk(
    panels: NDArray[np.float64], options: dict[str, Any], inputs: dict[str, Any] | None = None
) -> dict[str, Any]:
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
    return run_chunk(pool, panels, options, inputs=inputs)


def rows(inputs: dict[str, Any], a: int, b: int) -> dict[str, Any]:
    """The orbit inputs of samples a..b."""
    return {name: values[a:b] for name, values in inputs.items()}


def local_chunks(
    matrix: NDArray[np.float64],
    inputs: dict[str, Any],
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
        futures = {
            ex.submit(run_chunk, pool, matrix[a:b], options, token, rows(inputs, a, b)): k
            for k, a, b in todo
        }
        try:
            for fut in cf.as_completed(futures):
                yield futures[fut], fut.result()
        finally:
            token.cancel()
            for fut in futures:
                fut.cancel()


def dask_client(backend: Any) -> tuple[Any, bool]:
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
    raise ParameterError(
        "backend",
        backend,
        "must be None, 'dask', a scheduler address ('tcp://host:8786') or a "
        "dask.distributed Client",
    )


def dask_chunks(
    client: Any,
    matrix: NDArray[np.float64],
    inputs: dict[str, Any],
    todo: list[tuple[int, int, int]],
    options: dict[str, Any],
) -> Generator[tuple[int, dict[str, Any]], None, None]:
    from distributed import as_completed

    futures = {
        client.submit(dask_chunk, matrix[a:b], options, rows(inputs, a, b), pure=False): k
        for k, a, b in todo
    }
    try:
        for fut in as_completed(list(futures)):
            yield futures[fut], fut.result()
    finally:
        client.cancel([f for f in futures if not f.done()])
