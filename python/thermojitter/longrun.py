"""Long runs over months and years: one summary per orbit, resumable from a checkpoint.

The run is integrated in chunks of whole orbits. Between chunks, Python shows progress, notices
Ctrl-C and writes the checkpoint. Each chunk restarts the integrator at an orbit boundary, so a
run resumed from a checkpoint gives the very same summaries as one that was never interrupted.
"""

from __future__ import annotations

import contextlib
import os
import time
import warnings
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar, Literal

import numpy as np
from numpy.typing import NDArray

from thermojitter import _core
from thermojitter import boom as boom_module
from thermojitter import checkpoint as checkpoints
from thermojitter import errors as checks
from thermojitter._runs import DISTRIBUTED_LIMIT
from thermojitter.attitude import Attitude, engine_orbit, has_face_loads
from thermojitter.boom import Boom
from thermojitter.errors import HybridFallbackWarning
from thermojitter.orbit import Orbit
from thermojitter.panel import Panel
from thermojitter.persist import Persistent
from thermojitter.progress import (
    DeferredInterrupt,
    Interruptible,
    progress_bar,
    report_interrupted,
)
from thermojitter.results import LimitCrossing
from thermojitter.simulate import (
    DEFAULT_THETA_LIMIT,
    check_inputs,
    check_layers,
    grid_args,
    layup_dict,
    orbits_args,
    start_state,
    warn_crossing,
)
from thermojitter.solver import ATOL, MAX_STEPS, RTOL, HybridSettings, SolverSettings

HYBRID_FALLBACK = (
    "Earth heating or an attitude other than Sun-pointing vary the sunlit forcing, which the "
    "hybrid propagator takes as constant between eclipses on orbits of 6 h or more and in the "
    "N-node model: every orbit was integrated in full with rk45 (the hybrid's fallback)"
)
"""Why a hybrid run with the Earth's loads or another attitude is integrated in full: on a long
orbit, or with the N-node model (short orbits of the two-layer model run on slow time)."""

SLOW_REFUSED = (
    "{n} orbit(s) of this hybrid run were integrated in full with rk45 (the hybrid's fallback), "
    "given back by slow time's guards: {reasons}"
)
"""What a hybrid run says when its slow-time guards gave orbits back to the full integration."""

SLOW_GUARDS = {
    "n_refused_gate": "a summary too near 0 for the accuracy slow time vouches for",
    "n_refused_separation": "thermal rates not slow against the hinge",
    "n_refused_ringing": "a ringing past {ring} rad",
    "n_refused_split": "a split of the state that did not converge",
    "n_refused_limit": "|theta| near the run's limit",
    "n_refused_growth": "a ringing that grows over the orbit (flutter)",
}
"""Each slow-time guard's counter in ``propagation`` and what it says."""


def slow_refused(counters: Mapping[str, Any]) -> str:
    """The warning for a run whose slow-time guards gave orbits back, each guard with its count
    (a run resumed from an older checkpoint may lack them: then all are named)."""
    ring = _core.SLOW_RING_LIMIT
    named = [
        f"{text.format(ring=ring)} ({counters[key]})"
        for key, text in SLOW_GUARDS.items()
        if counters.get(key, 0) > 0
    ]
    if not named:
        named = [text.format(ring=ring) for text in SLOW_GUARDS.values()]
    return SLOW_REFUSED.format(n=counters["n_refused_orbits"], reasons="; ".join(named))


def on_slow_time(period: float) -> bool:
    """Whether the hybrid runs the two-layer model on an orbit of this period (s) on slow time
    (the engine's rule: shorter than ``_core.SLOW_ORBIT``), the Earth's loads included."""
    return period < _core.SLOW_ORBIT


SUMMARY_FIELDS = (
    "index", "t_start", "t_end", "theta_eq", "theta_max", "theta_min", "amplitude", "jitter_rms",
    "jitter_peak", "t_entry", "t_exit", "entry_theta_min", "exit_theta_max", "entry_peak",
    "exit_peak",
)  # fmt: skip
"""Columns of the per-orbit summaries (angles rad, times s; NaN where an orbit has no eclipse)."""

TIP_FIELDS = ("tip_max", "tip_min")
"""Columns a run of the distributed panel adds: the largest and smallest tip deflection of each
orbit, m (positive away from the Sun)."""

DISTRIBUTED_ONLY = ("elements", "modes", "support", "damping_ratio")
"""Settings of ``simulate_orbits`` that only ``model="distributed"`` takes."""

HYBRID_COUNTERS = (
    "t_linear", "t_exponential", "t_fallback", "n_arcs", "n_exp_steps", "n_fallback_steps",
    "n_reread_steps", "t_slow", "n_slow_steps", "n_refused_orbits", "n_refused_separation",
    "n_refused_ringing", "n_refused_split", "n_refused_limit", "n_refused_gate",
    "n_refused_growth", "n_refused_windows", "n_pieces", "n_warmup_orbits", "n_pieces_rerun",
)  # fmt: skip
"""How a hybrid run split its simulated time (s) and work between linear arcs, the exponential
integrator of the non-linear model, slow time (short orbits and varying loads) and the
hinge-resolved fallback; ``n_refused_orbits`` of slow time's orbits given back to the full
integration, and by which guard (``n_refused_separation``, ``_ringing``, ``_split``, ``_limit``,
``_gate``, ``_growth``) and the orbits that ran only a window in full, from their start, because
slow time could not vouch for that window's summaries alone (``n_refused_windows``, slow time
after it); ``n_pieces`` into which a call's long slow-time run was cut to run on
several cores (summed over calls), the orbits their warm-ups ran (``n_warmup_orbits``, not
summarised) and the pieces run again in order because their warmed-up start missed
(``n_pieces_rerun``)."""


@dataclass
class OrbitSummaries(Persistent):
    """Per-orbit summaries of a long run, with how it ended.

    Columns (one value per orbit): ``index``, ``t_start``, ``t_end``, ``theta_eq`` (sunlit
    equilibrium at that orbit's flux), ``theta_max``, ``theta_min``, ``amplitude``
    (max abs(θ − θ_eq)), ``jitter_rms`` and ``jitter_peak`` (of θ − M_T/K_el, the oscillation about
    the quasi-static deflection), ``t_entry``/``t_exit`` (umbra), ``entry_theta_min`` and
    ``exit_theta_max`` (in the window after entry and exit), ``entry_peak``/``exit_peak``
    (max abs(θ − θ_eq) in those windows). A run of the distributed panel
    (``model="distributed"``) reads θ as its hinge-equivalent angle θ_f, the quasi-static part as
    θ_f of the static state with the same temperatures (the kept modes at rest in equilibrium
    with the element moments), and adds ``tip_max`` and ``tip_min`` (the tip deflection's
    extremes in the orbit, m, positive away from the Sun).
    """

    columns: dict[str, NDArray[Any]]
    y_end: NDArray[np.float64]
    t_end: float
    n_steps: int = 0
    n_rhs: int = 0
    limit_crossing: LimitCrossing | None = None
    """(t s, orbit index, θ rad) where abs(θ) first passed theta_limit, or None (always with
    ``on_limit="ignore"``): a :class:`thermojitter.results.LimitCrossing`, a named tuple."""
    interrupted: bool = False
    """True when Ctrl-C ended the run early; the columns hold the finished orbits."""
    settings: dict[str, Any] = field(default_factory=dict)
    propagation: dict[str, float] = field(default_factory=dict)
    """Hybrid runs: simulated time (s) by linear arcs (``t_linear``), by the non-linear model
    (``t_exponential`` with the exponential integrator — the distributed panel's umbra, its
    temperatures integrated alone and its modes exactly —, ``t_fallback`` with the
    hinge-resolved full integration), and the work (``n_arcs``, ``n_exp_steps``,
    ``n_fallback_steps``, and ``n_reread_steps``: exponential steps whose band of θ failed its
    check and were read again)."""
    fallback: str | None = None
    """Why a run asked for ``method="hybrid"`` ran the full integration instead (a boom), or
    None."""
    solver: SolverSettings | None = None
    """The integrator settings the engine ran with, as it reports them (with ``method="hybrid"``,
    those of its rk45 fallback); rk45's step is further capped at T_n/``steps_per_period``.
    ``settings`` holds the request as given (the checkpoint's identity)."""
    panel: Panel | None = field(default=None, repr=False, compare=False)
    """The panel the run was made with (saved with the result)."""
    orbit: Orbit | None = field(default=None, repr=False, compare=False)
    """The orbit the run was made on."""

    xarray_dims: ClassVar[dict[str, tuple[str, ...]]] = {
        "columns": ("orbit",),
        "y_end": ("state",),
    }

    @property
    def nonlinear_fraction(self) -> float:
        """Share of the simulated time integrated with the full non-linear model (1: not hybrid)."""
        p = self.propagation
        if not p:
            return 1.0
        total = p["t_linear"] + p["t_exponential"] + p["t_fallback"] + p.get("t_slow", 0.0)
        return (p["t_exponential"] + p["t_fallback"]) / total if total > 0 else 0.0

    def __getattr__(self, name: str) -> NDArray[Any]:
        columns = self.__dict__.get("columns", {})
        if name in columns:
            return columns[name]
        raise AttributeError(name)

    def __len__(self) -> int:
        return len(self.columns["index"])

    @property
    def completed_orbits(self) -> int:
        return len(self)

    def to_pandas(self) -> Any:
        import pandas as pd

        return pd.DataFrame(self.columns).set_index("index")


def orbit_count(name: str, value: Any, orbit: Orbit, t_start: float = 0.0) -> int:
    """A whole number of orbits >= 1 that a run starting at ``t_start`` can reach (|t| at most
    the engine's MAX_TIME), checked before any product that would overflow a float."""
    n = checks.integer(name, value, 1)
    most = (_core.MAX_TIME - abs(t_start)) / orbit.period
    if most < 1.0:  # not one orbit fits after the start: the start is what is wrong
        raise checks.ParameterError(
            "t_start",
            t_start,
            f"must leave room for one orbit ({orbit.period:g} s) before |t| = "
            f"{_core.MAX_TIME:g} s, the longest time a run may reach",
        )
    if n > most:  # exact for any int, even 10**400
        raise checks.ParameterError(
            name,
            value,
            f"must be <= {most:.4g}: a run may reach at most t = {_core.MAX_TIME:g} s "
            f"(about {_core.MAX_TIME / 3.15576e7:.0f} years)",
        )
    return n


def refuse_beyond_budget(name: str, value: Any, least: float, max_steps: int, what: str) -> None:
    """A ParameterError naming ``name`` when a request needs, at the least, more integrator steps
    than its budget ``max_steps``: known before any work, rather than found minutes into it.
    ``what`` says where the steps come from."""
    if least > max_steps:
        raise checks.ParameterError(
            name,
            value,
            f"needs at least {least:.3g} integrator steps ({what}), more than max_steps = "
            f"{max_steps}: use method='hybrid' (sunlit arcs without steps), a shorter span, "
            "or a larger max_steps",
        )


def _empty_columns(fields: tuple[str, ...] = SUMMARY_FIELDS) -> dict[str, list[Any]]:
    return {name: [] for name in fields}


def _save_checkpoint(
    path: Path,
    request: dict[str, Any],
    n_orbits: int,
    columns: dict[str, list[Any]],
    y: list[float],
    next_index: int,
    counters: dict[str, int],
    crossing: LimitCrossing | None,
) -> bool:
    """Writes the checkpoint atomically; on failure (a full disk, a read-only folder) warns and
    returns False, leaving the previous checkpoint and no partial file: the run and its result
    go on."""
    content = {
        "n_orbits": n_orbits,
        "next_index": next_index,
        "y": [float(v) for v in y],
        "counters": counters,
        "crossing": None if crossing is None else list(crossing),
        "columns": {
            k: [float(v) if k != "index" else int(v) for v in vals] for k, vals in columns.items()
        },
    }
    try:
        checkpoints.save(path, request, content)
    except OSError as exc:
        warnings.warn(
            f"checkpoint {path} could not be written ({exc.strerror or exc}); the orbits "
            "computed so far are kept in memory and returned",
            RuntimeWarning,
            stacklevel=3,
        )
        return False
    return True


def _check_extension(
    path: Path, content: dict[str, Any], n_orbits: int, orbits_per_call: int, done: int
) -> None:
    """A checkpoint of the same settings answers a call for as many orbits, or extends to more
    when the saved run finished and its chunks end where a fresh run's would (so the result is
    the same to the bit). A checkpoint of more orbits than asked is refused: its rows and end
    state are not those of the shorter run."""
    saved = content.get("n_orbits")
    if saved == n_orbits:
        return
    if not isinstance(saved, int):
        raise checkpoints.CheckpointError("checkpoint", path, "is missing fields")
    if saved > n_orbits:
        raise checkpoints.CheckpointError(
            "checkpoint",
            path,
            f"holds a run of n_orbits = {saved}, more than the {n_orbits} asked",
        )
    if done < saved or saved % orbits_per_call != 0:
        raise checkpoints.CheckpointError(
            "checkpoint",
            path,
            f"was written for n_orbits = {saved} and cannot be extended to {n_orbits} "
            f"(unfinished, or its last chunk is not a whole orbits_per_call = {orbits_per_call})",
        )


def _restore(
    path: Path,
    content: dict[str, Any],
    fields: tuple[str, ...] = SUMMARY_FIELDS,
    size: int = 4,
) -> tuple[Any, ...]:
    """The state of a checked checkpoint (``fields`` its columns, ``size`` its state's); refuses
    one whose rows do not run 0..next_index−1 (a file the checksum vouches for was written by
    this code, so this guards its logic)."""
    try:
        columns = {k: list(content["columns"][k]) for k in fields}
        next_index = int(content["next_index"])
        y = [float(v) for v in content["y"]]
        counters = dict(content["counters"])
        counters["n_steps"], counters["n_rhs"] = int(counters["n_steps"]), int(counters["n_rhs"])
        crossing = content["crossing"]
    except (KeyError, TypeError, ValueError):
        raise checkpoints.CheckpointError("checkpoint", path, "is missing fields") from None
    rows = columns["index"]
    if rows != list(range(next_index)):
        raise checkpoints.CheckpointError(
            "checkpoint", path, f"holds rows {rows[:1]}..{rows[-1:]} for next_index {next_index}"
        )
    if len(y) != size or any(len(v) != len(rows) for v in columns.values()):
        raise checkpoints.CheckpointError("checkpoint", path, "has columns of unequal length")
    return columns, y, next_index, counters, LimitCrossing.of(crossing)


def _boom_orbits(
    boom: dict[str, float],
    orbit: dict[str, Any],
    orbits: Mapping[str, Any],
    *,
    y0: list[float],
    cancel: Any = None,
    **watch: Any,
) -> dict[str, Any]:
    """``_core.run_boom_orbits`` called as ``_core.run_orbits`` is: the run's mapping and its
    watch keys (start, index, limit) in the tube's one spec mapping."""
    spec = {k: v for k, v in orbits.items() if k != "hybrid"} | watch
    return _core.run_boom_orbits(boom, orbit, spec, y0, hybrid=orbits.get("hybrid"), cancel=cancel)


def _distributed_call(settings: dict[str, Any]) -> Callable[..., dict[str, Any]]:
    """``_core.run_distributed_orbits`` with the distributed model's ``settings``, called as
    ``_core.run_orbits`` is."""

    def call(
        panel: dict[str, float],
        orbit: dict[str, Any],
        orbits: Any,
        *,
        cancel: Any = None,
        **kw: Any,
    ) -> Any:
        return _core.run_distributed_orbits(panel, orbit, settings, orbits, kw, cancel=cancel)

    return call


def distributed_request(
    panel: Any,
    orbit: Orbit,
    layers: int | None,
    coupled: bool,
    given: dict[str, Any],
) -> dict[str, Any]:
    """The distributed model's settings of a long run (``given``: elements, modes, support,
    damping_ratio as passed), checked: a Panel, Sun-pointing through the orbit's attitude."""
    from thermojitter.distributed import distributed_settings

    if not isinstance(panel, Panel):
        raise checks.ParameterError(
            "model", "distributed", "takes a thermojitter.Panel (the distributed panel's mesh)"
        )
    check_inputs(panel, orbit)
    return distributed_settings(
        panel,
        support=given["support"],
        elements=given["elements"],
        modes=given["modes"],
        damping_ratio=given["damping_ratio"],
        coupled=coupled,
        layers=2 if layers is None else layers,
    )


def refuse_distributed_only(model: str, given: dict[str, Any]) -> None:
    """A ParameterError naming the first distributed-only setting given to another model."""
    if model == "distributed":
        return
    defaults = {"support": "free-free"}
    for name in DISTRIBUTED_ONLY:
        if given[name] is not None and given[name] != defaults.get(name):
            raise checks.ParameterError(
                name, given[name], "is a setting of model='distributed' only"
            )


def simulate_orbits(
    panel: Panel | Boom,
    orbit: Orbit,
    n_orbits: int,
    *,
    t_start: float = 0.0,
    model: Literal["nonlinear", "linear", "distributed"] = "nonlinear",
    coupled: bool = True,
    method: Literal["hybrid", "rk45", "rk4"] = "hybrid",
    rtol: float = RTOL,
    atol: float = ATOL,
    dt: float | None = None,
    y0: tuple[float, ...] | None = None,
    window: float = 600.0,
    theta_limit: float = DEFAULT_THETA_LIMIT,
    on_limit: Literal["stop", "flag", "ignore"] = "stop",
    checkpoint: str | os.PathLike[str] | None = None,
    checkpoint_every: float = 10.0,
    orbits_per_call: int = 1,
    progress: bool | None = True,
    max_steps: int = MAX_STEPS,
    stop: Callable[[], bool] | None = None,
    steps_per_period: float = 40.0,
    hybrid: HybridSettings | dict[str, float] | None = None,
    layers: int | None = None,
    solver: SolverSettings | None = None,
    attitude: Attitude | None = None,
    elements: int | None = None,
    modes: int | None = None,
    support: Literal["free-free", "cantilever"] = "free-free",
    damping_ratio: float | None = None,
) -> OrbitSummaries:
    """Integrates ``n_orbits`` whole orbits of the coupled system, keeping one summary per orbit.

    Memory grows with the number of orbits, not of steps (a 10-year GEO run keeps ~3650 rows).

    - ``theta_limit`` (rad): the hinge model's range of validity; when abs(θ) passes it the run
      stops (``on_limit="stop"``) or records the first crossing and goes on (``"flag"``), and
      either way says so in ``limit_crossing`` and one
      :class:`thermojitter.errors.ValidityLimitWarning`; ``"ignore"`` reports nothing.
    - ``checkpoint``: a file written every ``checkpoint_every`` s of wall time, at Ctrl-C and at
      the end; if it exists (same settings) the run resumes from it and gives identical results.
    - Ctrl-C stops within one integration step and returns the finished orbits with
      ``interrupted=True``, saying so in one line on stderr. So does ``stop()`` turning True
      (polled between chunks, for callers that handle SIGINT and report it themselves), silently.
    - ``progress``: a tqdm bar on stderr with the remaining time (in Jupyter a widget; also when
      stderr is not a terminal); ``None``: only when stderr is a terminal; ``False``: none.
    - ``max_steps``: the step budget of the whole run, every orbit together. A run whose least
      cost (known up front for rk45 with its step cap, and rk4) exceeds it is refused before it
      starts, naming ``n_orbits``; one that reaches it raises ``IntegrationError``.
    - ``method``: ``"hybrid"`` (default) propagates the sunlit arcs exactly in the linearised
      system's modal form and integrates only the shadow crossings and their thermal recovery
      with the full non-linear model (an exponential integrator), falling back on the
      hinge-resolved rk45 where the oscillation is too large for either; the per-orbit
      summaries agree with rk45's within 2 % and it is hundreds of times faster on GEO.
      ``result.propagation`` says how the simulated time was split. ``"rk45"``/``"rk4"``
      integrate everything (rk45 resolves the hinge period, see ``steps_per_period``).
      ``hybrid``: a :class:`thermojitter.HybridSettings`, or a dict of its fields (``rtol``,
      ``atol_temperature``, ``atol_angle``, ``max_step``, ``linear_tolerance``,
      ``linear_amplitude``, ``resolved_amplitude``); unset ones keep the engine's defaults.
    - ``steps_per_period``: rk45's step is capped at T_n/steps_per_period, T_n the hinge's natural
      period (0: error control alone). Without the cap the step grows, once the oscillation is
      small against ``atol``, to where the method's own dissipation exceeds a weak flutter's
      growth rate, and flutter near the critical damping goes unseen. With 40 the measured growth
      is within 1 % of the eigen-analysis; it costs about twice the steps of error control alone.
    - ``layers=N``: the N-node through-thickness model on the panel's layup (see
      :func:`thermojitter.simulate`); ``y0`` and ``y_end`` are then (node temperatures…, θ, θ̇).
    - ``solver``: a :class:`thermojitter.SolverSettings` in place of ``rtol``, ``atol``, ``dt``
      and ``max_steps`` (with ``method="hybrid"``, those of its rk45 fallback);
      ``result.solver`` is what the engine ran with.
    - ``attitude``: where the front face points (:class:`thermojitter.Attitude`, default
      Sun-pointing); with it or with the orbit's Earth heating each face takes its own loads (see
      :func:`thermojitter.simulate`), and each orbit's ``theta_eq`` is the sunlit equilibrium
      under the loads at the orbit's start. On an orbit shorter than 6 h the hybrid runs them on
      slow time (below); elsewhere, and in the N-node model (``layers=N``), it takes the sunlit
      forcing as constant between eclipses, which these loads are not, and integrates such a run
      in full with rk45 (``result.propagation`` counts all of it as the fallback's), said in
      ``result.settings["hybrid_fallback"]`` and by one
      :class:`thermojitter.errors.HybridFallbackWarning`.
    - Slow time (``method="hybrid"`` on an orbit shorter than 6 h, with or without the Earth's
      loads and an attitude; the two-layer model): the temperatures are integrated on their own
      time scale with the hinge on its slow manifold, the ringing carried in closed form as a
      complex amplitude along the hinge mode (the thermal coupling, hence flutter, in its
      eigenvalue; the non-linear hinge's frequency shift with amplitude from its conservative
      period), the penumbrae integrated in full. An orbit where the ringing passes 0.03 rad,
      the thermal rates are not slow against the hinge, or a summary lies too near 0 for the
      closed form's accuracy (0.3 % of the ringing's amplitude) is integrated again in full
      with rk45 from its start (``propagation["n_refused_orbits"]``, and a
      :class:`thermojitter.errors.HybridFallbackWarning`); where only the summaries of the window
      after entry or exit lie too near 0, the orbit runs in full from its start to that
      window's end and on slow time after it (``propagation["n_refused_windows"]``, no warning:
      those summaries are rk45's); ``propagation["t_slow"]`` is the time carried on slow time.

    A :class:`thermojitter.Boom` in place of the panel runs the tube: ``y0`` and ``y_end`` are
    (T_mean, T_circ, θ, θ̇), the summaries read θ (the tip deflection over the length) and its
    quasi-static part as the panel's. ``method="hybrid"`` runs it with the full integration
    (the hybrid's linear arcs are the plate's modal form) and says so: ``result.fallback`` gives
    the reason and ``propagation`` puts all the time in ``t_fallback``.

    ``model="distributed"`` runs the distributed panel (:func:`thermojitter.simulate_distributed`:
    ``elements`` two-layer elements, ``modes`` elastic modes, ``support``, ``damping_ratio``, and
    ``layers`` the elements' through-thickness model, default 2; defaults
    :func:`thermojitter.distributed_defaults`), two-way coupled unless ``coupled=False``. The
    summaries read θ as its hinge-equivalent angle θ_f and add ``tip_max``/``tip_min``; ``y0`` and
    ``y_end`` are its state (the temperatures of each element, then q and q̇), the default start
    its sunlit equilibrium. ``method="rk45"`` integrates it in full (the step capped at
    T₁/``steps_per_period``, T₁ the first kept mode's period; every step read at eight points);
    ``"hybrid"`` (default) propagates the sunlit arcs near the equilibrium exactly in the
    linearised system's modal form (the structural pairs in closed form, the thermal part by the
    matrix exponential); in the umbra, where the elements' heat balances do not depend on the
    structure, it integrates the temperatures alone with rk45 (steps of the thermal time scales)
    and propagates the modes exactly over each step; the penumbra and the recovery after the
    exit are integrated in full with rk45. An arc is taken only where its checks hold (the
    non-linear remainder at its start below ``hybrid.linear_tolerance`` as a static θ_f error,
    the oscillation below ``hybrid.linear_amplitude``, the drift of the dropped non-linear terms
    within half the accuracy gate, the reads' interpolation error); elsewhere the run goes on in
    full. The split is in ``result.propagation`` (``t_linear``, ``t_exponential`` the umbra and
    ``n_exp_steps`` its steps, ``t_fallback`` the full integration, ``n_arcs``,
    ``n_refused_arcs``).
    """
    given = {
        "elements": elements,
        "modes": modes,
        "support": support,
        "damping_ratio": damping_ratio,
    }
    model = checks.choice("model", model, ("nonlinear", "linear", "distributed"))  # type: ignore[assignment]
    refuse_distributed_only(model, given)
    distributed = model == "distributed"
    dsettings = distributed_request(panel, orbit, layers, coupled, given) if distributed else None
    boom = isinstance(panel, Boom)
    if isinstance(panel, Boom):
        checks.instance("orbit", orbit, Orbit, "a thermojitter.Orbit")
        if layers is not None:
            raise checks.ParameterError("layers", layers, "a Boom has its own thermal model")
        boom_module.check_attitude(attitude)
    else:
        check_inputs(panel, orbit)
    engine_orbit_args = engine_orbit(orbit, attitude)
    n_orbits = checks.integer("n_orbits", n_orbits, 1)
    orbits_per_call = checks.integer("orbits_per_call", orbits_per_call, 1)
    on_limit = checks.choice("on_limit", on_limit, ("stop", "flag", "ignore"))  # type: ignore[assignment]
    coupled = checks.flag("coupled", coupled)
    t_start = checks.finite("t_start", t_start)
    window = checks.positive("window", window)
    theta_limit = checks.real("theta_limit", theta_limit)
    checkpoint_every = checks.finite("checkpoint_every", checkpoint_every)
    steps_per_period = checks.in_range("steps_per_period", steps_per_period, 0.0, 1e4)
    if progress is not None:
        checks.flag("progress", progress)
    if stop is not None and not callable(stop):
        raise checks.wrong_type("stop", stop, "callable")
    # Each chunk is checked by the engine; the whole run is checked here, before any work.
    n_orbits = orbit_count("n_orbits", n_orbits, orbit, t_start)
    method = checks.choice("method", method, ("hybrid", "rk45", "rk4"))  # type: ignore[assignment]
    nodes = None if layers is None or distributed else check_layers(layers)
    # The N-node model's layup (layers is refused for a boom).
    layup = None if isinstance(panel, Boom) or nodes is None else layup_dict(panel)
    used = SolverSettings.of(
        solver,
        method=None if method == "hybrid" else method,
        rtol=rtol,
        atol=atol,
        dt=dt,
        max_steps=max_steps,
    )
    if method == "hybrid":
        # The hybrid propagator falls back on the hinge-resolved rk45 where it must.
        used = used.replace(method="rk45")
    full = used.as_dict()
    if y0 is not None:
        y0 = start_state(y0, len(y0) if hasattr(y0, "__len__") else 4)  # type: ignore[assignment]
    if y0 is None and dsettings is not None:
        y0 = tuple(
            _core.distributed_start_state(panel.as_dict(), dsettings, engine_orbit_args, t_start)
        )
    elif y0 is None and boom:
        y0 = tuple(_core.boom_start_state(panel.as_dict(), orbit.as_dict(), t_start, coupled))
    elif y0 is None:
        # The engine's default start: the sunlit equilibrium at the start date's solar flux.
        # (layers is refused for a boom)
        grid = grid_args(panel, nodes) if nodes is not None and isinstance(panel, Panel) else None
        y0 = tuple(_core.start_state(panel.as_dict(), engine_orbit_args, t_start, coupled, grid))
    settings: dict[str, Any] = {
        "panel": panel.as_dict(),
        "orbit": orbit.as_record(),
        "t_start": t_start,
        "model": model,
        "coupled": coupled,
        "method": method,
        "rtol": full["rtol"],
        "atol": full["atol"],
        "dt": full["dt"],
        "y0": [float(v) for v in y0],
        "window": window,
        "theta_limit": theta_limit,
        "on_limit": on_limit,
        "orbits_per_call": orbits_per_call,
        "steps_per_period": steps_per_period,
        "max_steps": full["max_steps"],
    }
    if nodes is not None:
        settings["layers"] = nodes
        settings["layup"] = layup
    if dsettings is not None:
        settings["distributed"] = dsettings
    hybrid_settings = HybridSettings.of(hybrid).as_dict()
    if method == "hybrid":
        settings["hybrid"] = hybrid_settings
    if "attitude" in engine_orbit_args:
        settings["attitude"] = engine_orbit_args["attitude"]
    slow = on_slow_time(orbit.period) and nodes is None and not distributed
    if method == "hybrid" and not slow and has_face_loads(orbit, attitude):
        settings["hybrid_fallback"] = HYBRID_FALLBACK
        warnings.warn(HYBRID_FALLBACK, HybridFallbackWarning, stacklevel=2)
    # The distributed model's engine call takes the hinge model's mapping (its `model` unused).
    engine_model = "nonlinear" if distributed else model
    run: dict[str, Any] = {
        "model": engine_model,
        "coupled": coupled,
        "solver": full,
        "window": window,
    }
    if nodes is not None and isinstance(panel, Panel):
        run.update(layup=layup_dict(panel), nodes=nodes)
    if method == "hybrid":
        run["hybrid"] = hybrid_settings
    watch = {
        "theta_limit": theta_limit,
        "stop_at_limit": on_limit == "stop",
        "steps_per_period": steps_per_period,
    }

    budget = int(full["max_steps"])  # for the whole run, every orbit together
    if method != "hybrid" and dsettings is not None:
        f1 = float(_core.distributed_info(panel.as_dict(), dsettings)["frequencies_hz"][0])
        per_orbit = orbit.period * f1 * steps_per_period if method == "rk45" else 0.0
        if method == "rk4":
            per_orbit = orbit.period / float(full["dt"])
        cap = (
            "a fixed step dt" if method == "rk4" else f"the step capped at T₁/{steps_per_period:g}"
        )
        least = per_orbit * n_orbits
        refuse_beyond_budget(
            "n_orbits", n_orbits, least, budget, f"{per_orbit:.3g} per orbit with {cap}"
        )
    elif method != "hybrid":
        # A boom's step is capped by its equivalent hinge's period, the panel's of the same hinge.
        hinge = panel.derived["hinge_panel"] if isinstance(panel, Boom) else panel.as_dict()
        row = np.array([[hinge[f] for f in _core.PANEL_FIELDS]])
        least = float(_core.least_steps(row, full, orbit.period, steps_per_period)[0])
        cap = (
            "a fixed step dt" if method == "rk4" else f"the step capped at T_n/{steps_per_period:g}"
        )
        refuse_beyond_budget(
            "n_orbits", n_orbits, least * n_orbits, budget, f"{least:.3g} per orbit with {cap}"
        )

    fields = SUMMARY_FIELDS + TIP_FIELDS if distributed else SUMMARY_FIELDS
    columns = _empty_columns(fields)
    y = [float(v) for v in y0]
    next_index = 0
    counters: dict[str, Any] = {"n_steps": 0, "n_rhs": 0}
    if method == "hybrid":
        counters.update({name: 0 for name in HYBRID_COUNTERS})
        if distributed:
            counters["n_refused_arcs"] = 0
    crossing: LimitCrossing | None = None
    path = checks.path("checkpoint", checkpoint) if checkpoint is not None else None
    if path is not None:
        saved = checkpoints.load(path, settings)
        if saved is not None:
            columns, y, next_index, counters, crossing = _restore(
                path, saved, fields, len(settings["y0"])
            )
            _check_extension(path, saved, n_orbits, orbits_per_call, next_index)

    ran_with: dict[str, Any] | None = None  # the settings the engine reports it ran with
    fallback: str | None = None
    bar = progress_bar(n_orbits, initial=next_index, unit="orbit", enabled=progress)
    interrupted = report = False
    stopped = crossing is not None and on_limit == "stop"
    last_save = time.monotonic()
    engine = Interruptible()
    # Ctrl-C waits for the bookkeeping of a finished call and for checkpoint writes.
    with DeferredInterrupt() as ctrl_c:
        try:
            while next_index < n_orbits and not stopped:
                # Chunks start at multiples of orbits_per_call, so resumed runs cut in the same
                # places.
                count = min(orbits_per_call - next_index % orbits_per_call, n_orbits - next_index)
                t0 = float(t_start) + next_index * orbit.period
                call: Callable[..., Any] = (
                    _distributed_call(dsettings)
                    if dsettings is not None
                    else _boom_orbits
                    if boom
                    else _core.run_orbits
                )
                # A call in this thread holds Ctrl-C until its chunk is kept (Interruptible).
                here = ctrl_c.hold() if engine.runs_here else contextlib.nullcontext()
                with here:
                    raw = engine.call(
                        call,
                        panel.as_dict(),
                        engine_orbit_args,
                        orbits_args(run, count),
                        t_start=t0,
                        first_index=next_index,
                        y0=y,
                        **watch,
                    )
                    with ctrl_c.hold():
                        for name in fields:
                            columns[name].extend(np.asarray(raw[name]).tolist())
                        y = list(raw["y_end"])
                        ran_with = raw["solver"]
                        fallback = raw.get("fallback", fallback)
                        counters["n_steps"] += int(raw["n_steps"])
                        counters["n_rhs"] += int(raw["n_rhs"])
                        for name in HYBRID_COUNTERS if method == "hybrid" else ():
                            counters[name] = counters.get(name, 0) + raw[name]
                        if "n_refused_arcs" in counters:
                            counters["n_refused_arcs"] += raw["n_refused_arcs"]
                        if crossing is None and on_limit != "ignore":
                            crossing = LimitCrossing.of(raw["crossing"])
                        if raw["stopped"]:
                            stopped = True
                            next_index = int(columns["index"][-1]) + 1
                        else:
                            next_index += count
                        if counters["n_steps"] >= budget and next_index < n_orbits and not stopped:
                            raise _core.IntegrationError(
                                f"max_steps = {budget} reached after {next_index} of "
                                f"{n_orbits} orbits ({counters['n_steps']} steps; the budget "
                                "holds for the whole run): pass a larger max_steps or fewer "
                                "orbits"
                            )
                        if bar is not None:
                            bar.update(count)
                        if path is not None and time.monotonic() - last_save > checkpoint_every:
                            _save_checkpoint(
                                path, settings, n_orbits, columns, y, next_index, counters, crossing
                            )
                            last_save = time.monotonic()
                if stop is not None and stop() and next_index < n_orbits and not stopped:
                    interrupted = True  # the caller asked, and reports it
                    break
        except KeyboardInterrupt:
            interrupted = report = True
        finally:
            engine.__exit__()
            if bar is not None:
                bar.close()
            if path is not None:
                with ctrl_c.hold(then_raise=False):
                    _save_checkpoint(
                        path, settings, n_orbits, columns, y, next_index, counters, crossing
                    )
    angle, validity = DISTRIBUTED_LIMIT if model == "distributed" else ("θ", "the hinge model")
    warn_crossing(crossing, theta_limit, on_limit, angle, model=validity)
    if counters.get("n_refused_orbits", 0) > 0:
        warnings.warn(slow_refused(counters), HybridFallbackWarning, stacklevel=2)
    if report:
        kept = f"kept {len(columns['index'])} of {n_orbits} orbits"
        if path is not None:
            report_interrupted(
                f"{kept} (checkpoint {path})", "run it again with the same checkpoint to resume"
            )
        else:
            report_interrupted(
                f"{kept} (returned, interrupted=True)",
                "pass checkpoint=FILE to make a run resumable",
            )

    return OrbitSummaries(
        columns={
            k: np.asarray(v, dtype=np.int64 if k == "index" else float) for k, v in columns.items()
        },
        y_end=np.asarray(y, dtype=float),
        t_end=float(columns["t_end"][-1]) if columns["t_end"] else float(t_start),
        n_steps=counters["n_steps"],
        n_rhs=counters["n_rhs"],
        propagation={k: counters[k] for k in (*HYBRID_COUNTERS, "n_refused_arcs") if k in counters},
        limit_crossing=crossing,
        interrupted=interrupted,
        settings=settings,
        fallback=fallback,
        # A run all read from its checkpoint made no engine call: the engine's reading of the
        # same settings (the check every run makes of them) stands for it.
        solver=SolverSettings(**(_core.check_solver(full) if ran_with is None else ran_with)),
        # A boom's runs are not saved with their input (persist knows panels).
        panel=panel if isinstance(panel, Panel) else None,
        orbit=orbit,
    )
