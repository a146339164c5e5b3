"""What a study reports: the metrics of each sample, the samples' frame, and its failed samples."""

from __future__ import annotations

import warnings
from collections.abc import Sequence
from typing import Any

import numpy as np
from numpy.typing import NDArray

from thermojitter import _core
from thermojitter.errors import SampleFailureWarning
from thermojitter.solver import SolverSettings

METRICS = (
    "theta_eq", "growth_rate", "frequency_hz", "stable", "critical_damping", "theta_abs_max",
    "amplitude", "entry_peak", "exit_peak", "jitter_rms", "jitter_peak", "t_threshold",
    "orbit_threshold", "orbit_limit", "amplitude_slope", "t_nonlinear", "t_reached", "n_steps",
    "error",
)  # fmt: skip
"""Columns of the metrics, after the sampled parameters (angles rad, times s, rates 1/s):

- ``theta_eq``: sunlit equilibrium angle at full Sun (for a boom, its tip deflection over its
  length);
- ``growth_rate``, ``frequency_hz``, ``stable``: linear stability of that equilibrium
  (``tj.flutter``); ``stable`` is a nullable boolean (pandas ``"boolean"``), missing (NA) for a
  sample that failed, so that ``(~frame.stable).mean()`` is the share of the finished samples
  that flutter; ``critical_damping``: c_d at which the growth rate crosses zero, N m s/rad (for
  a boom, the first mode's damping ratio ζ at which it does); with the Earth's loads or an
  attitude other than Sun-pointing, these four are of the equilibrium in full sunlight under
  every load at t = 0;
- ``theta_abs_max``: max abs(θ) over the horizon; ``amplitude``: max abs(θ − θ_eq);
- ``entry_peak``/``exit_peak``: max abs(θ − θ_eq) within ``window`` s after a shadow entry / exit;
- ``jitter_rms``/``jitter_peak``: of θ − M_T/K_el (the oscillation about the quasi-static
  deflection) over the horizon;
- ``t_threshold``/``orbit_threshold``: first time (s) and orbit at which abs(θ) passed
  ``threshold`` (NaN: never, or no threshold);
- ``orbit_limit``: first orbit whose abs(θ) passed the validity limit (20°; NaN: none);
- ``amplitude_slope``: growth (> 0) or decay of the per-orbit amplitude over the run, the
  least-squares slope of ln(amplitude) against the orbit index, 1/orbit; it needs two orbits or
  more, so it is NaN on the default one-orbit horizon (``horizon=1``: pass ``horizon >= 2``);
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

FLOAT_METRICS = tuple(m for m in METRICS if m not in ("stable", "n_steps", "error"))


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


def samples_frame(
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


def report_failures(frame: Any) -> None:
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
        stacklevel=4,  # report_failures < run_design < the study < its caller
    )


def solver_of(frame: Any) -> SolverSettings:
    """The integrator settings the engine ran a study's samples with (``frame.attrs["solver"]``
    of a :func:`monte_carlo`, :func:`sweep` or :func:`sensitivity` frame) as a
    :class:`thermojitter.SolverSettings`; with ``method="hybrid"``, those of its rk45 fallback.
    Each sample's rk45 step is further capped at its hinge period / 40, as long runs cap it."""
    return SolverSettings(**frame.attrs["solver"])
