"""Monte Carlo studies, full-factorial sweeps and Sobol sensitivity over panel (or boom)
parameters and orbit inputs.

A study is a design — one row of panel parameters per sample, with the sample's orbit inputs
(``ORBIT_INPUTS``: the study's orbit with its own albedo, Earth infrared, inclination, RAAN),
drawn in Python from the seed up front (:mod:`.design`) — and a batch run of it in the Rust
engine on a rayon pool with the GIL released (:mod:`.backends`). Each sample depends only on its
own row, so the results are the same, bit for bit, whatever the number of threads, the chunking
or the backend (local threads or Dask workers).

The design is cut into chunks of rows (:mod:`.driver`). With ``checkpoint=DIR`` every finished
chunk is written to ``DIR/chunk-NNNNN.parquet`` as soon as it completes, beside
``DIR/manifest.json`` (the settings and their fingerprint); a run started again with the same
settings reads the finished chunks and computes only the others (:mod:`.store`). The studies
themselves are in :mod:`.studies`, what they report in :mod:`.metrics`.
"""

from thermojitter.montecarlo.backends import dask_chunk
from thermojitter.montecarlo.design import (
    MAX_SAMPLES,
    ORBIT_INPUT_RANGES,
    ORBIT_INPUTS,
    Sampler,
    distribution,
)
from thermojitter.montecarlo.metrics import METRICS, AllSamplesFailedError, solver_of
from thermojitter.montecarlo.store import FORMAT_VERSION
from thermojitter.montecarlo.studies import SensitivityResult, monte_carlo, sensitivity, sweep

__all__ = [
    "FORMAT_VERSION",
    "MAX_SAMPLES",
    "METRICS",
    "ORBIT_INPUTS",
    "ORBIT_INPUT_RANGES",
    "AllSamplesFailedError",
    "Sampler",
    "SensitivityResult",
    "dask_chunk",
    "distribution",
    "monte_carlo",
    "sensitivity",
    "solver_of",
    "sweep",
]
