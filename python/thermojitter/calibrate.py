"""Calibration of the hinge model against a measured or simulated angle series θ(t).

The hinge parameters K_el (``hinge_stiffness``), c_d (``damping``) and optionally χ
(``moment_scale``) are fitted by non-linear least squares (``scipy.optimize.least_squares``)
with the engine doing every forward run: the coupled model (:func:`thermojitter.simulate`) over
the series' time span, from the sunlit equilibrium of the trial panel (or a given ``y0``),
sampled at the series' times. Standard errors come from the Jacobian at the solution,
cov = s² (JᵀJ)⁻¹ with s² = Σr²/(n − p).

    fit = tj.calibrate(t, theta, panel=tj.Panel.paper(), orbit=tj.Orbit.geo_equinox())
    fit.parameters["hinge_stiffness"], fit.standard_errors["hinge_stiffness"], fit.residual_rms

The validity limit (``theta_limit``, ``on_limit``) concerns the answer, the fitted model: the
trial runs of the fit are not checked (a trial panel on the way may well swing beyond it); the
fitted panel's run over the series is, once the fit is done.
"""

from __future__ import annotations

import csv
import math
import re
import warnings
from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.optimize import least_squares

from thermojitter import errors as checks
from thermojitter.errors import ValidityLimitWarning
from thermojitter.orbit import Orbit
from thermojitter.panel import Panel
from thermojitter.persist import Persistent
from thermojitter.results import LimitCrossing
from thermojitter.simulate import (
    DEFAULT_THETA_LIMIT,
    Model,
    OnLimit,
    check_inputs,
    limit_args,
    simulate,
    warn_crossing,
)

Array = NDArray[np.float64]

FITTABLE = ("hinge_stiffness", "damping", "moment_scale")
"""Panel parameters calibrate() can fit."""
MIN_POINTS = 20
"""Fewest samples a series may hold."""


@dataclass(frozen=True)
class CalibrationResult(Persistent):
    """Fitted hinge parameters with standard errors (same units as the panel fields), the RMS of
    the residual θ_model − θ_data (rad), and the model's θ at the series' times."""

    parameters: dict[str, float]
    standard_errors: dict[str, float]
    residual_rms: float
    covariance: Array
    panel: Panel
    t: Array
    theta_model: Array
    n_points: int
    success: bool
    message: str
    nfev: int
    settings: dict[str, Any] = field(default_factory=dict, repr=False)
    limit_crossing: LimitCrossing | None = None
    """Where the fitted model's θ first passed ``theta_limit`` over the series, or None."""

    xarray_dims: ClassVar[dict[str, tuple[str, ...]]] = {
        "t": ("t",),
        "theta_model": ("t",),
        "covariance": ("parameter", "parameter_"),
    }

    @property
    def residual_rms_deg(self) -> float:
        return math.degrees(self.residual_rms)

    def summary(self) -> dict[str, Any]:
        """JSON-ready numbers."""
        return {
            "parameters": dict(self.parameters),
            "standard_errors": dict(self.standard_errors),
            "residual_rms_deg": self.residual_rms_deg,
            "n_points": self.n_points,
            "success": self.success,
            "nfev": self.nfev,
        }


def _series(t: ArrayLike, theta: ArrayLike) -> tuple[Array, Array]:
    # Real numbers, one-dimensional and finite (a bool or a string is refused, not converted).
    ts = checks.real_array("t", t)
    th = checks.real_array("theta", theta)
    if th.shape != ts.shape:
        raise checks.ParameterError(
            "theta", theta, message=f"theta has shape {th.shape}; must match t's {ts.shape}"
        )
    if ts.size < MIN_POINTS:
        raise checks.ParameterError(
            "t",
            t,
            message=f"t holds {ts.size} samples: the series is too short (need {MIN_POINTS})",
        )
    if np.any(np.diff(ts) <= 0):
        i = int(np.argmax(np.diff(ts) <= 0)) + 1
        raise checks.ParameterError(
            f"t[{i}]",
            float(ts[i]),
            message=f"t must be strictly increasing (t[{i}] = {ts[i]} does not increase)",
        )
    return ts, th


def calibrate(
    t: ArrayLike,
    theta: ArrayLike,
    *,
    panel: Panel | None = None,
    orbit: Orbit | None = None,
    fit: Sequence[str] = ("hinge_stiffness", "damping"),
    initial: Mapping[str, float] | None = None,
    y0: Sequence[float] | None = None,
    model: Model = "nonlinear",
    coupled: bool = True,
    rtol: float = 1e-10,
    atol: float = 1e-12,
    diff_step: float = 1e-6,
    theta_limit: float = DEFAULT_THETA_LIMIT,
    on_limit: OnLimit = "flag",
) -> CalibrationResult:
    """Fits the hinge parameters named in ``fit`` to the angle series ``theta`` (rad) at times
    ``t`` (s, strictly increasing, at least :data:`MIN_POINTS` samples, no NaN).

    ``panel`` holds every other parameter and the starting values (default Table 1); ``initial``
    overrides starting values. ``orbit`` defaults to GEO at equinox, and the times are on its
    clock (t = 0 at the subsolar point). ``y0`` = (T_f, T_b, θ, θ̇) at ``t[0]``; default the
    sunlit equilibrium of each trial panel. The forward runs use ``rtol``/``atol``, tight enough
    for the finite-difference Jacobian (relative step ``diff_step``).

    ``theta_limit`` (rad) and ``on_limit`` check the fitted model, not the trials of the fit: its
    run over the series is watched as :func:`thermojitter.simulate` watches one. ``"flag"``
    (default): ``limit_crossing`` says where its θ first passed the limit and a
    :class:`thermojitter.errors.ValidityLimitWarning` says so; ``"stop"``: the same, and
    ``theta_model`` is NaN after the crossing (the fitted model means nothing there);
    ``"ignore"``: no check.

    Ctrl-C stops the fit within one integration step of the run under way
    (``KeyboardInterrupt``).
    """
    limits = limit_args(theta_limit, on_limit)
    ts, th = _series(t, theta)
    base = Panel.paper() if panel is None else panel
    orb = Orbit.geo_equinox() if orbit is None else orbit
    check_inputs(base, orb)
    checks.choice("model", model, ("nonlinear", "linear"))
    checks.flag("coupled", coupled)
    diff_step = checks.positive("diff_step", diff_step)
    if isinstance(fit, str) or not isinstance(fit, Iterable):
        raise checks.wrong_type("fit", fit, "a sequence of parameter names")
    if initial is not None and not isinstance(initial, Mapping):
        raise checks.wrong_type("initial", initial, "a mapping of names to values")
    names = list(fit)
    # Names only: an array's rows or other unhashable items are refused before the set is built.
    if (
        not names
        or not all(isinstance(n, str) for n in names)
        or len(set(names)) != len(names)
        or any(n not in FITTABLE for n in names)
    ):
        raise checks.ParameterError("fit", fit, f"a non-empty set of {', '.join(FITTABLE)}")
    if ts.size <= len(names):
        raise checks.ParameterError(
            "t", t, message=f"t holds {ts.size} samples: too short to fit {len(names)} parameters"
        )
    start = {n: float(getattr(base, n)) for n in names}
    for key, value in (initial or {}).items():
        if key not in names:
            raise checks.ParameterError(
                f"initial.{key}",
                value,
                message=f"initial names {key!r}, which is not fitted (fit = {names})",
            )
        start[key] = checks.finite(f"initial.{key}", value)
    trial0 = base.replace(**start)  # validates the starting values
    x0 = np.array([start[n] for n in names])
    scale = np.array([max(abs(v), 1e-3) for v in x0])
    lower = np.array(
        [0.0 if n == "damping" else 1e-9 * s for n, s in zip(names, scale, strict=True)]
    )

    # The forward runs' settings, written once: the result records them.
    trial_settings: dict[str, Any] = {"model": model, "coupled": coupled, "rtol": rtol}
    trial_settings.update(atol=atol, theta_limit=limits["theta_limit"])
    span = (ts[0], ts[-1])

    def run(x: Array, on_limit: OnLimit) -> Any:
        trial = trial0.replace(**dict(zip(names, (float(v) for v in x), strict=True)))
        with warnings.catch_warnings():
            # The fit warns once, itself, of a crossing of the fitted run.
            warnings.simplefilter("ignore", ValidityLimitWarning)
            return simulate(trial, orb, span, t_eval=ts, y0=y0, on_limit=on_limit, **trial_settings)

    def forward(x: Array) -> Array:
        return np.asarray(run(x, "ignore").theta)

    def residual(x: Array) -> Array:
        return forward(x) - th

    res = least_squares(
        residual,
        x0,
        x_scale="jac",
        bounds=(lower, np.full_like(x0, np.inf)),
        diff_step=diff_step,
        method="trf",
    )
    n, p = ts.size, len(names)
    s2 = float(np.sum(res.fun**2)) / (n - p)
    # cov = s² (JᵀJ)⁻¹ through the SVD of J (column-scaled for conditioning)
    jac = np.asarray(res.jac) * scale
    _, sv, vt = np.linalg.svd(jac, full_matrices=False)
    if sv[-1] <= sv[0] * 1e-12:
        cov_scaled = np.full((p, p), np.inf)
    else:
        cov_scaled = (vt.T / sv**2) @ vt * s2
    cov = cov_scaled * np.outer(scale, scale)
    params = {nm: float(v) for nm, v in zip(names, res.x, strict=True)}
    errors = {nm: float(math.sqrt(cov[i, i])) for i, nm in enumerate(names)}
    _warn_unidentified(names, errors, sv, vt)
    theta_model = res.fun + th
    crossing = None
    if on_limit != "ignore":
        crossing = run(res.x, on_limit).limit_crossing
        if crossing is not None and on_limit == "stop":
            theta_model = np.where(ts > crossing.t, np.nan, theta_model)
        warn_crossing(crossing, limits["theta_limit"], on_limit)
    return CalibrationResult(
        parameters=params,
        standard_errors=errors,
        residual_rms=float(np.sqrt(np.mean(res.fun**2))),
        covariance=cov,
        panel=trial0.replace(**params),
        t=ts,
        theta_model=theta_model,
        n_points=n,
        success=bool(res.success),
        message=str(res.message),
        nfev=int(res.nfev),
        settings={**trial_settings, "fit": names, "on_limit": on_limit},
        limit_crossing=crossing,
    )


def _warn_unidentified(names: list[str], errors: dict[str, float], sv: Array, vt: Array) -> None:
    """Warns when a standard error is not finite: the series does not determine the fit (the
    Jacobian is singular, e.g. a panel that does not bend, or two parameters that trade off).
    The fit is still returned (its residual is meaningful); the warning names the parameters
    along the undetermined directions, those of the right singular vectors whose singular value
    is negligible."""
    if all(math.isfinite(v) for v in errors.values()):
        return
    flat = vt[sv <= sv[0] * 1e-12] if sv[0] > 0 else vt
    weight = np.max(np.abs(flat), axis=0) if len(flat) else np.zeros(len(names))
    blamed = [nm for nm, w in zip(names, weight, strict=True) if w > 0.1]
    blamed = blamed or [nm for nm, v in errors.items() if not math.isfinite(v)]
    warnings.warn(
        f"calibrate: the series does not determine {', '.join(blamed)} (singular Jacobian): "
        "their standard errors are infinite; fit fewer parameters or a series that excites them",
        RuntimeWarning,
        stacklevel=3,
    )


def calibrate_from_csv(
    path: str | Path,
    *,
    time_column: str = "t",
    angle_column: str = "theta",
    degrees: bool = False,
    **kwargs: Any,
) -> CalibrationResult:
    """:func:`calibrate` on telemetry from a CSV file with a header row: ``time_column`` (s) and
    ``angle_column`` (rad, or degrees with ``degrees=True``). A header may give a column's unit
    after its name, as ``thermojitter run`` writes ``timeseries.csv`` (``t [s]``, ``theta
    [rad]``): the name alone finds it. Other keywords go to calibrate."""
    p = checks.path("path", path)
    degrees = checks.flag("degrees", degrees)
    if not p.is_file():
        raise checks.ParameterError(
            "path", path, message=f"path = {str(p)!r} is invalid: no such file"
        )
    with p.open(encoding="utf-8", newline="") as fh:
        header = [h.strip() for h in next(csv.reader(fh), [])]
    bare = [re.sub(r"\s*\[[^\]]*\]$", "", h) for h in header]
    found = []
    for name, col in (("time_column", time_column), ("angle_column", angle_column)):
        where = [i for i, (h, b) in enumerate(zip(header, bare, strict=True)) if col in (h, b)]
        if not where:
            raise checks.ParameterError(name, col, f"the file's columns are {tuple(header)}")
        found.append(where[0])
    data = np.genfromtxt(
        p, delimiter=",", skip_header=1, usecols=found, dtype=float, encoding="utf-8", ndmin=2
    )
    theta = data[:, 1].astype(float)
    if degrees:
        theta = np.radians(theta)
    return calibrate(data[:, 0].astype(float), theta, **kwargs)
