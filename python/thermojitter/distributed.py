"""The distributed panel: finite elements, each with its own temperatures and its own sunlight.

The hinge model lumps the panel into two rigid halves; the beam comparator loads a free–free beam
with the hinge model's moment, one way. Here the panel is a chain of Euler–Bernoulli elements,
two-way coupled: every element carries its own two-layer heat balance, absorbs sunlight at its own
incidence — the Sun's angle to the element's deformed normal, rigid attitude ``sun_angle`` plus
the elastic rotation of its chord — and bends under its own thermal moment. The structure is
reduced to its first ``modes`` elastic modes (the rest quasi-static), so the step size follows the
physics, not the mesh.

Supports: ``"free-free"`` (the paper's panel, attitude held by the spacecraft; θ_f = asin(2η/L),
η the tip rise over the centre, as the beam comparator defines it) and ``"cantilever"`` (clamped
at x = 0 to a rigid bus; θ_f = asin(w(L)/L), the angle of a rigid arm hinged at the root with the
same tip deflection).

    sol = tj.simulate_distributed(panel, orbit, (t0, t1))
    sol.theta_f, sol.T_front  # (time,), (time, element)
    fl = tj.distributed_flutter(panel)
    fl.growth_rate, fl.critical_damping_ratio, fl.critical_damping

The equations, the mesh and the modal reduction live in the engine (``rust/src/distributed``);
this module checks types, converts and presents.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, ClassVar, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from thermojitter import _core
from thermojitter._runs import DISTRIBUTED_LIMIT
from thermojitter.attitude import Attitude, engine_orbit
from thermojitter.errors import ParameterError, flag, real, wrong_type
from thermojitter.orbit import Orbit, eclipse_window
from thermojitter.panel import Panel
from thermojitter.persist import Persistent, field_type
from thermojitter.progress import interruptible
from thermojitter.results import LimitCrossing, Run, _dataframes_module, _FaceDifference
from thermojitter.simulate import (
    DEFAULT_THETA_LIMIT,
    Method,
    OnLimit,
    check_inputs,
    limit_args,
    limit_record,
    run_record,
    run_settings,
    start_state,
    time_span,
    warn_crossing,
)
from thermojitter.solver import ATOL, MAX_STEP, MAX_STEPS, RTOL, SolverSettings

Array = NDArray[np.float64]
Support = Literal["free-free", "cantilever"]


def _count(name: str, value: Any) -> int:
    """An integer setting (its range is the engine's to check)."""
    if isinstance(value, (bool, np.bool_)) or not isinstance(value, numbers.Integral):
        raise wrong_type(name, value, "an integer")
    return int(value)


def distributed_settings(
    panel: Panel,
    *,
    support: Support = "free-free",
    elements: int | None = None,
    modes: int | None = None,
    damping_ratio: float | None = None,
    sun_angle: float = 0.0,
    coupled: bool = True,
    layers: int = 2,
) -> dict[str, Any]:
    """The model settings as the engine takes them; ``None`` picks the engine's default (see
    :func:`distributed_defaults`). The engine checks the values and names any bad one."""
    check_inputs(panel)
    if not isinstance(support, str):
        raise wrong_type("support", support, "a string")
    defaults = _core.distributed_defaults(panel.as_dict())
    counts = {}
    for name, value in (("elements", elements), ("modes", modes)):
        if value is None:
            value = defaults[name]
        counts[name] = _count(name, value)
    return {
        "support": support,
        "elements": counts["elements"],
        "modes": counts["modes"],
        "damping_ratio": None if damping_ratio is None else real("damping_ratio", damping_ratio),
        "sun_angle": real("sun_angle", sun_angle),
        "coupled": flag("coupled", coupled),
        "layers": _count("layers", layers),
    }


def distributed_defaults(panel: Panel | None = None) -> dict[str, Any]:
    """The engine's default settings: support, elements, modes, damping_ratio (the
    hinge-equivalent ζ = c_d/(2 I_B ω₁) of ``panel``, default Table 1) and sun_angle (rad)."""
    panel = Panel.paper() if panel is None else panel
    check_inputs(panel)
    return dict(_core.distributed_defaults(panel.as_dict()))


class _FaceTemperatures:
    """The face temperatures by name, from ``temperatures`` (element fields, K)."""

    temperatures: dict[str, Array]

    @property
    def T_front(self) -> Array:
        """Front-face temperature per element, K (over time × element for a run)."""
        return self.temperatures["T_front"]

    @property
    def T_back(self) -> Array:
        """Back-face temperature per element, K (over time × element for a run)."""
        return self.temperatures["T_back"]


@dataclass(frozen=True)
class DistributedSolution(_FaceTemperatures, _FaceDifference, Run):
    """The distributed panel at the reported times.

    ``x``: element centres (m), ``x_node``: nodes (m). ``temperatures`` maps each name of the
    elements' thermal model ("T_front", "T_back" for two layers; also attributes) to a (time,
    element) array in K; ``thermal_moment`` (N m) has shape (time, element); ``deflection`` (m,
    positive away from the Sun) and ``slope`` (rad) have shape (time, node); ``theta_f`` (rad) is
    the hinge-equivalent angle; ``sunlit`` the illuminated fraction s(t).
    """

    x: Array = field(default_factory=lambda: np.empty(0))
    x_node: Array = field(default_factory=lambda: np.empty(0))
    temperatures: dict[str, Array] = field(default_factory=dict)
    thermal_moment: Array = field(default_factory=lambda: np.empty((0, 0)))
    deflection: Array = field(default_factory=lambda: np.empty((0, 0)))
    slope: Array = field(default_factory=lambda: np.empty((0, 0)))
    theta_f: Array = field(default_factory=lambda: np.empty(0))
    sunlit: Array = field(default_factory=lambda: np.empty(0))
    y_end: Array = field(default_factory=lambda: np.empty(0))
    support: str = "free-free"
    frequencies_hz: Array = field(default_factory=lambda: np.empty(0))
    """The kept elastic modes' frequencies, Hz."""
    damping_ratio: float = 0.0
    limit_crossing: LimitCrossing | None = None
    """Where abs(θ_f) first passed ``theta_limit`` (its ``theta`` is θ_f, rad), or None."""
    stopped_at_limit: bool = False
    """True when ``on_limit="stop"`` ended the run at the crossing."""
    flux_front: Array | None = None
    """The flux reaching the flat panel's front face at each sample, W/m²: sunlight, albedo and
    Earth infrared in its attitude (each element's own orientation not applied)."""
    flux_back: Array | None = None
    """The flux reaching the flat panel's back face at each sample, W/m² (as ``flux_front``)."""

    @property
    def theta_f_deg(self) -> Array:
        return np.degrees(self.theta_f)

    def _columns(self) -> dict[str, Array]:
        return {
            "theta_f": self.theta_f,
            "tip_deflection": self.deflection[:, -1],
            "sunlit": self.sunlit,
        }

    def _dataset(self) -> Any:
        """An xarray Dataset: element fields over (time, x), nodal fields over (time, x_node),
        θ_f and s over time; needs xarray."""
        xr = _dataframes_module("xarray", "to_xarray()")
        return xr.Dataset(
            {
                **{
                    name: (("time", "x"), values, {"units": "K"})
                    for name, values in self.temperatures.items()
                },
                "thermal_moment": (("time", "x"), self.thermal_moment, {"units": "N m"}),
                "deflection": (("time", "x_node"), self.deflection, {"units": "m"}),
                "slope": (("time", "x_node"), self.slope, {"units": "rad"}),
                "theta_f": ("time", self.theta_f, {"units": "rad"}),
                "sunlit": ("time", self.sunlit),
            },
            coords={
                "time": ("time", self.t, {"units": "s"}),
                "x": ("x", self.x, {"units": "m", "long_name": "element centre"}),
                "x_node": ("x_node", self.x_node, {"units": "m", "long_name": "node"}),
            },
            attrs={
                "method": self.method,
                "support": self.support,
                **{k: str(v) for k, v in self.settings.items()},
            },
        )


def simulate_distributed(
    panel: Panel,
    orbit: Orbit,
    t_span: Sequence[float],
    *,
    support: Support = "free-free",
    elements: int | None = None,
    modes: int | None = None,
    coupled: bool = True,
    damping_ratio: float | None = None,
    sun_angle: float = 0.0,
    layers: int = 2,
    method: Method = "rk45",
    rtol: float = RTOL,
    atol: float = ATOL,
    dt: float | None = None,
    max_step: float = MAX_STEP,
    max_steps: int = MAX_STEPS,
    t_eval: ArrayLike | None = None,
    dt_out: float | None = None,
    y0: ArrayLike | None = None,
    solver: SolverSettings | None = None,
    theta_limit: float = DEFAULT_THETA_LIMIT,
    on_limit: OnLimit = "flag",
    attitude: Attitude | None = None,
) -> DistributedSolution:
    """Integrates the distributed panel over ``t_span`` (s) on ``orbit``, through its eclipses
    and penumbrae.

    - ``support``: ``"free-free"`` or ``"cantilever"``; ``sun_angle`` ψ (rad): the Sun's angle to
      the undeformed front normal (0: Sun-pointing; |ψ| < π/2). With ψ > 0 the Sun lies on the
      side where thermal bending (away from the Sun) turns the elements further from it.
    - ``elements``, ``modes``: the mesh and the number of elastic modes integrated (default
      :func:`distributed_defaults`; the others follow quasi-statically).
    - ``coupled=False`` freezes every element's absorbing area at cos ψ (one-way coupling).
    - ``damping_ratio`` ζ of every kept mode; default the hinge-equivalent c_d/(2 I_B ω₁).
    - ``layers``: every element's through-thickness thermal model (2: the paper's eq. 2).
    - Integrator and output as :func:`thermojitter.simulate`; ``y0`` the state (the
      temperatures of element 0, of element 1, ..., then q[k] and q̇[k]), default the sunlit
      equilibrium at the start's flux.
    - ``theta_limit``, ``on_limit``: the validity limit on abs(θ_f), as
      :func:`thermojitter.simulate` watches θ (checked on every step; ``"flag"`` records the
      first crossing in ``sol.limit_crossing`` and warns, ``"stop"`` also ends the run there,
      ``"ignore"`` checks nothing).
    - ``attitude`` (:class:`thermojitter.Attitude`; default Sun-pointing) and the orbit's Earth
      heating (``orbit.albedo``, ``orbit.earth_ir``): every element absorbs sunlight on either
      face, albedo and Earth infrared (docs/howto/earth-heating.md) at its own orientation — the
      attitude's front normal turned by the element's slope about the panel's width, the panel's
      length lying in the plane of the normal and the orbit normal (a Sun-tracking wing along its
      drive axis) — so the deflection still feeds back on every load; ``sun_angle`` must then be
      0 (the attitude sets the incidence). ``sol.flux_front`` and ``sol.flux_back`` are the fluxes
      reaching the flat panel's faces, W/m².

    Ctrl-C stops the run within one integration step (``KeyboardInterrupt``).
    """
    check_inputs(panel, orbit)
    engine_orbit_args = engine_orbit(orbit, attitude)
    t0, t1 = time_span(t_span)
    settings = distributed_settings(
        panel,
        support=support,
        elements=elements,
        modes=modes,
        damping_ratio=damping_ratio,
        sun_angle=sun_angle,
        coupled=coupled,
        layers=layers,
    )
    used, run = run_settings(
        solver, (t0, t1), t_eval, dt_out, method=method, rtol=rtol, atol=atol, dt=dt,
        max_step=max_step, max_steps=max_steps,
    )  # fmt: skip
    run["limit"] = limit_args(theta_limit, on_limit)
    run["y0"] = start_state(y0, None)  # numbers (the engine checks the size and the temperatures)
    raw = interruptible(
        _core.simulate_distributed, panel.as_dict(), engine_orbit_args, settings, run
    )
    limit = limit_record(raw)
    angle, validity = DISTRIBUTED_LIMIT
    warn_crossing(
        limit["limit_crossing"], run["limit"]["theta_limit"], on_limit, angle, model=validity
    )
    return DistributedSolution(
        **run_record(raw, used),
        settings={
            **settings,
            "damping_ratio": float(raw["damping_ratio"]),
            "rtol": used.rtol,
            "atol": used.atol,
            "dt": used.dt,
            "solver": used.as_dict(),
            **run["limit"],
            **(
                {"attitude": engine_orbit_args["attitude"]}
                if "attitude" in engine_orbit_args
                else {}
            ),
        },
        x=raw["x"],
        x_node=raw["x_node"],
        temperatures=dict(raw["temperatures"]),
        thermal_moment=raw["thermal_moment"],
        deflection=raw["deflection"],
        slope=raw["slope"],
        theta_f=raw["theta_f"],
        sunlit=raw["sunlit"],
        y_end=raw["y_end"],
        panel=panel,
        orbit=orbit,
        support=support,
        frequencies_hz=raw["frequencies_hz"],
        damping_ratio=float(raw["damping_ratio"]),
        flux_front=raw["flux_front"],
        flux_back=raw["flux_back"],
        **limit,
    )


@field_type
@dataclass(frozen=True)
class OscillatoryMode:
    """One oscillatory eigen-pair of the linearised distributed panel: growth rate Re λ (1/s),
    frequency Im λ/2π (Hz), and the kept structural mode nearest in frequency (0: the first)."""

    growth_rate: float
    frequency_hz: float
    structural_mode: int


@dataclass(frozen=True)
class DistributedFlutterResult(_FaceTemperatures, Persistent):
    """Linear stability of the distributed panel's sunlit equilibrium.

    ``growth_rate`` (1/s) is the largest real part of all eigenvalues; ``oscillatory_modes`` lists
    each oscillatory pair by ascending frequency. ``critical_damping_ratio`` is the modal ζ (every
    kept mode) at which the growth rate crosses zero, ``critical_damping`` the same as a hinge
    damping c_d = 2 I_B ω₁ ζ (N m s/rad), comparable with :func:`thermojitter.flutter`'s.
    The equilibrium: ``temperatures`` by name per element (K; ``T_front``/``T_back``),
    ``deflection``/``slope`` per node, ``theta_f`` (rad).
    """

    eigenvalues: NDArray[np.complex128]
    growth_rate: float
    oscillatory_modes: tuple[OscillatoryMode, ...]
    critical_damping_ratio: float
    critical_damping: float
    damping_ratio: float
    theta_f: float
    x: Array
    x_node: Array
    temperatures: dict[str, Array]
    deflection: Array
    slope: Array
    support: str
    elements: int
    modes: int
    flux: float
    sun_angle: float
    panel: Panel | None = field(default=None, repr=False, compare=False)
    """The panel analysed (saved with the result)."""

    xarray_dims: ClassVar[dict[str, tuple[str, ...]]] = {
        "x": ("x",),
        "x_node": ("x_node",),
        "temperatures": ("x",),
        "deflection": ("x_node",),
        "slope": ("x_node",),
        "eigenvalues": ("eigenvalue",),
    }

    @property
    def stable(self) -> bool:
        return self.growth_rate < 0.0

    @property
    def frequency_hz(self) -> float:
        """Frequency of the least stable oscillatory pair, Hz (0 if none)."""
        if not self.oscillatory_modes:
            return 0.0
        return max(self.oscillatory_modes, key=lambda m: m.growth_rate).frequency_hz

    @property
    def theta_f_deg(self) -> float:
        return math.degrees(self.theta_f)


def distributed_flutter(
    panel: Panel,
    *,
    support: Support = "free-free",
    elements: int | None = None,
    modes: int | None = None,
    flux: float = 1.0,
    damping_ratio: float | None = None,
    sun_angle: float = 0.0,
    layers: int = 2,
) -> DistributedFlutterResult:
    """Eigen-analysis of the two-way coupled distributed panel linearised at its sunlit
    equilibrium under ``flux`` (the solar constant's scale: 1 at 1 au, about 1.0343 at
    perihelion, 0.9674 at aphelion), and its critical damping. Settings as
    :func:`simulate_distributed`."""
    settings = distributed_settings(
        panel,
        support=support,
        elements=elements,
        modes=modes,
        damping_ratio=damping_ratio,
        sun_angle=sun_angle,
        coupled=True,
        layers=layers,
    )
    flux = real("flux", flux)
    pd = panel.as_dict()
    raw = _core.distributed_flutter(pd, settings, float(flux))
    info = _core.distributed_info(pd, settings)
    return DistributedFlutterResult(
        eigenvalues=np.array([complex(re, im) for re, im in raw["eigenvalues"]]),
        growth_rate=float(raw["growth_rate"]),
        oscillatory_modes=tuple(OscillatoryMode(g, f, int(i)) for g, f, i in raw["modes"]),
        critical_damping_ratio=float(raw["critical_damping_ratio"]),
        critical_damping=float(raw["critical_damping"]),
        damping_ratio=float(raw["damping_ratio"]),
        theta_f=float(raw["theta_f"]),
        x=np.asarray(info["x"]),
        x_node=np.asarray(info["x_node"]),
        temperatures={k: np.asarray(v) for k, v in raw["temperatures"].items()},
        deflection=np.asarray(raw["deflection"]),
        slope=np.asarray(raw["slope"]),
        support=support,
        elements=settings["elements"],
        modes=settings["modes"],
        flux=float(flux),
        sun_angle=float(sun_angle),
        panel=panel,
    )


def distributed_frequencies(
    panel: Panel,
    *,
    support: Support = "free-free",
    elements: int | None = None,
    modes: int | None = None,
) -> Array:
    """The kept elastic modes' frequencies of the mesh, Hz (the first is the panel's first
    bending frequency on its support)."""
    settings = distributed_settings(panel, support=support, elements=elements, modes=modes)
    return np.asarray(_core.distributed_info(panel.as_dict(), settings)["frequencies_hz"])


@dataclass(frozen=True)
class ConvergenceRow:
    """One run of a convergence study: its setting, the largest difference of θ_f (rad) from
    the next finer run and from the finest run, and its cost."""

    elements: int
    modes: int
    max_change: float
    max_error: float
    n_steps: int


def distributed_convergence(
    panel: Panel,
    orbit: Orbit,
    *,
    vary: Literal["elements", "modes"] = "elements",
    values: Sequence[int] = (10, 20, 40, 80),
    support: Support = "free-free",
    elements: int | None = None,
    modes: int | None = None,
    t_span: Sequence[float] | None = None,
    dt_out: float = 0.5,
    rtol: float = 1e-10,
    atol: float = 1e-12,
) -> tuple[list[ConvergenceRow], float]:
    """θ_f through the eclipse as ``vary`` takes ``values`` (ascending), the other setting fixed
    (default the engine's). Returns the rows and the observed order p from the last three runs,
    p = log(|Δ₁| / |Δ₂|) / log(r), Δ the largest change between successive runs and r the ratio
    of successive values (constant). ``t_span`` defaults to the first eclipse with 1200 s of
    sunlight either side."""
    values = [int(v) for v in values]
    if len(values) < 3 or any(b <= a for a, b in zip(values, values[1:], strict=False)):
        raise ParameterError("values", values, "need three or more, ascending")
    span = eclipse_window(orbit) if t_span is None else time_span(t_span)
    runs = []
    for v in values:
        kw: dict[str, Any] = {"elements": elements, "modes": modes, vary: v}
        runs.append(
            simulate_distributed(
                panel, orbit, span, support=support, dt_out=dt_out, rtol=rtol, atol=atol, **kw
            )
        )
    finest = runs[-1].theta_f
    rows = []
    for i, run in enumerate(runs):
        nxt = runs[i + 1].theta_f if i + 1 < len(runs) else run.theta_f
        rows.append(
            ConvergenceRow(
                elements=int(run.settings["elements"]),
                modes=int(run.settings["modes"]),
                max_change=float(np.max(np.abs(nxt - run.theta_f))),
                max_error=float(np.max(np.abs(finest - run.theta_f))),
                n_steps=run.n_steps,
            )
        )
    d1, d2 = rows[-3].max_change, rows[-2].max_change
    ratio = values[-1] / values[-2]
    order = math.log(d1 / d2) / math.log(ratio) if d1 > 0 and d2 > 0 else math.inf
    return rows, order


@dataclass(frozen=True)
class CriticalDampingYear:
    """The critical damping c_d* of the hinge model and of the distributed panel (as the
    hinge-equivalent c_d = 2 I_B ω₁ ζ*) over a year, N m s/rad, at the sampled times ``t`` (s)
    and their solar flux scale ``flux``."""

    t: Array
    flux: Array
    hinge: Array
    distributed: Array
    settings: dict[str, Any]

    @property
    def days(self) -> Array:
        return (self.t - self.t[0]) / 86400.0


def critical_damping_year(
    panel: Panel | None = None,
    orbit: Orbit | None = None,
    *,
    samples: int = 25,
    span: float = 365.25 * 86400.0,
    elements: int | None = None,
    modes: int | None = None,
    support: Literal["free-free", "cantilever"] = "free-free",
) -> CriticalDampingYear:
    """c_d* of the hinge model (:func:`thermojitter.flutter` on ``orbit`` at each sampled time:
    the flux of that day) and of the distributed panel (:func:`thermojitter.distributed_flutter`
    at the same flux) at ``samples`` evenly spaced times over ``span`` s from t = 0. Defaults:
    Table 1 on ``Orbit.geo_year("2026-01-01")``, the distributed model's default mesh."""
    from thermojitter import errors as checks
    from thermojitter.flutter import flutter

    panel = Panel.paper() if panel is None else panel
    orbit = Orbit.geo_year("2026-01-01") if orbit is None else orbit
    samples = checks.integer("samples", samples, 2)
    span = checks.positive("span", span)
    t = np.linspace(0.0, span, samples)
    flux = np.asarray(orbit.flux_scale(t), dtype=float)
    hinge = np.array([flutter(panel, orbit=orbit, t=float(ti)).critical_damping for ti in t])
    distributed = np.array(
        [
            distributed_flutter(
                panel, flux=float(f), elements=elements, modes=modes, support=support
            ).critical_damping
            for f in flux
        ]
    )
    return CriticalDampingYear(
        t=t,
        flux=flux,
        hinge=hinge,
        distributed=distributed,
        settings={"elements": elements, "modes": modes, "support": support},
    )
