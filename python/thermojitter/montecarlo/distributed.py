"""Monte Carlo studies of the distributed panel (``monte_carlo(..., model="distributed")``).

Each sample is one ``simulate_orbits(..., model="distributed")`` run of its panel, and its row is
read off that run's per-orbit summaries; the samples run one per thread (the engine releases the
GIL), in a pool of ``threads``, so the rows are the same whatever the number of threads.
"""

from __future__ import annotations

import concurrent.futures as cf
import math
import os
from collections.abc import Mapping
from typing import Any

import numpy as np

from thermojitter import _core
from thermojitter.errors import ParameterError
from thermojitter.longrun import OrbitSummaries, simulate_orbits
from thermojitter.montecarlo.design import ORBIT_INPUTS, sampled, unit_design
from thermojitter.orbit import Orbit
from thermojitter.panel import Panel

DISTRIBUTED_METRICS = (
    "theta_eq", "growth_rate", "frequency_hz", "stable", "critical_damping", "theta_abs_max",
    "amplitude", "entry_peak", "exit_peak", "jitter_rms", "jitter_peak", "tip_max", "tip_min",
    "orbit_limit", "amplitude_slope", "t_nonlinear", "t_reached", "n_steps", "error",
)  # fmt: skip
"""Columns of a distributed study's metrics, after the sampled parameters: those of ``METRICS``
read on θ_f (the hinge-equivalent angle), the stability columns from
:func:`thermojitter.distributed_flutter` at the flux of t = 0 (``critical_damping`` as a hinge
damping, N m s/rad), ``tip_max``/``tip_min`` the tip deflection's extremes over the horizon (m),
``t_nonlinear`` the time integrated in full (s)."""


def row_of(run: OrbitSummaries) -> dict[str, Any]:
    """The metrics a run's summaries give (all but the stability columns), read by the engine
    as the hinge studies read theirs, and the tip's extremes."""
    c = run.columns
    crossing = run.limit_crossing
    p = run.propagation
    return {
        "theta_eq": float(c["theta_eq"][0]),
        **dict(_core.summary_metrics({k: v.tolist() for k, v in c.items()}, run.t_end)),
        "tip_max": float(np.max(c["tip_max"])),
        "tip_min": float(np.min(c["tip_min"])),
        "orbit_limit": math.nan if crossing is None else float(crossing.orbit),
        "t_nonlinear": float(p["t_fallback"]) if p else run.t_end - float(c["t_start"][0]),
        "t_reached": run.t_end,
        "n_steps": run.n_steps,
        "error": None,
    }


def distributed_study(
    panel: Panel | Any,
    orbit: Orbit,
    vary: Mapping[str, Any],
    n: int,
    seed: int,
    sampler: str,
    truncate: bool,
    threads: int | None,
    run: dict[str, Any],
    model: dict[str, Any],
) -> Any:
    """The frame of ``n`` panels drawn around ``panel`` (``vary``: panel parameters only), each
    run as ``simulate_orbits(panel_i, orbit, **run, model="distributed", **model)`` and analysed
    by ``distributed_flutter`` with ``model``'s settings."""
    import pandas as pd

    from thermojitter.distributed import distributed_flutter

    if not isinstance(panel, Panel):
        raise ParameterError("model", "distributed", "takes a thermojitter.Panel")
    inputs = [name for name in vary if name in ORBIT_INPUTS]
    if inputs:
        raise ParameterError(
            f"vary.{inputs[0]}", vary[inputs[0]], "model='distributed' varies panel parameters"
        )
    if threads is not None and (
        isinstance(threads, bool) or not isinstance(threads, int) or threads < 1
    ):
        raise ParameterError("threads", threads, "must be a positive integer")
    u = unit_design(sampler, n, len(vary), seed)
    names, values, _ = sampled(panel, vary, u, truncate)
    flux = float(np.asarray(orbit.flux_scale([0.0]))[0])
    analysis = {k: model[k] for k in ("elements", "modes", "support", "damping_ratio")}
    layers = model.get("layers")

    def one(i: int) -> dict[str, Any]:
        sample = panel.replace(**{k: float(v) for k, v in zip(names, values[i], strict=True)})
        try:
            result = simulate_orbits(
                sample, orbit, model="distributed", progress=False, layers=layers,
                **analysis, **run,
            )  # fmt: skip
            row = row_of(result)
            fl = distributed_flutter(sample, flux=flux, layers=layers or 2, **analysis)
            row.update(
                growth_rate=fl.growth_rate,
                frequency_hz=fl.frequency_hz,
                stable=fl.stable,
                critical_damping=fl.critical_damping,
            )
            return row
        except (_core.IntegrationError, _core.ConvergenceError) as exc:
            row = {m: math.nan for m in DISTRIBUTED_METRICS}
            row.update(stable=None, n_steps=None, error=str(exc))
            return row

    workers = threads or os.cpu_count() or 1
    with cf.ThreadPoolExecutor(max_workers=workers) as pool:
        rows = list(pool.map(one, range(n)))
    frame = pd.DataFrame({name: values[:, j] for j, name in enumerate(names)})
    for m in DISTRIBUTED_METRICS:
        frame[m] = [r[m] for r in rows]
    frame["stable"] = frame["stable"].astype("boolean")
    frame["n_steps"] = frame["n_steps"].astype("Int64")
    frame.attrs["seed"] = seed
    frame.attrs["model"] = "distributed"
    frame.attrs["n_failed"] = int(sum(r["error"] is not None for r in rows))
    return frame
