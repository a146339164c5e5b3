"""Thermal flutter without integration: linear stability of the sunlit equilibrium."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, ClassVar, Literal

import numpy as np
from numpy.typing import ArrayLike, NDArray

from thermojitter import _core
from thermojitter import boom as boom_module
from thermojitter import errors as checks
from thermojitter.attitude import Attitude, engine_orbit, has_face_loads
from thermojitter.boom import Boom
from thermojitter.boom import _equilibrium as _boom_equilibrium
from thermojitter.orbit import Orbit
from thermojitter.panel import Panel
from thermojitter.persist import Persistent
from thermojitter.progress import interruptible, progress_bar
from thermojitter.results import Equilibrium
from thermojitter.simulate import check_layers, grid_args

if TYPE_CHECKING:
    from thermojitter._core import _FlutterPoint

MAP_BLOCK = 20_000
"""Grid points per engine call of :func:`stability_map` (about 40 ms each)."""


@dataclass(frozen=True)
class FlutterResult(Persistent):
    """Eigen-analysis of the coupled system linearised at the sunlit equilibrium.

    ``growth_rate`` (1/s) is the largest real part of the eigenvalues: positive means the
    oscillation grows (thermal flutter), e-folding in 1/growth_rate seconds. ``critical_damping``
    (N m s/rad) is the hinge damping c_d at which it crosses zero.
    """

    equilibrium: Equilibrium
    jacobian: NDArray[np.float64]
    eigenvalues: NDArray[np.complex128]
    growth_rate: float
    frequency_hz: float
    critical_damping: float
    model: str
    coupled: bool
    flux: float
    panel: Panel | None = field(default=None, repr=False, compare=False)
    """The panel analysed (saved with the result)."""
    orbit: Orbit | None = field(default=None, repr=False, compare=False)
    """The orbit whose flux at ``t`` was taken (None: ``flux`` given)."""

    xarray_dims: ClassVar[dict[str, tuple[str, ...]]] = {
        "jacobian": ("row", "column"),
        "eigenvalues": ("eigenvalue",),
    }

    @property
    def stable(self) -> bool:
        return self.growth_rate < 0.0

    @property
    def e_folding_time(self) -> float:
        """1/|growth_rate|, s (time to grow, or decay, by a factor e)."""
        return math.inf if self.growth_rate == 0.0 else 1.0 / abs(self.growth_rate)


def flutter(
    panel: Panel,
    model: Literal["nonlinear", "linear"] = "nonlinear",
    *,
    coupled: bool = True,
    flux: float | None = None,
    orbit: Orbit | None = None,
    t: float = 0.0,
    layers: int | None = None,
    attitude: Attitude | None = None,
    orbit_average: bool = False,
) -> FlutterResult:
    """Linear stability of the sunlit equilibrium of ``panel``.

    ``flux`` scales the solar constant (default 1, the Sun at 1 au; the Sun–Earth distance changes
    it by about ±3.3 % over the year); the equilibrium, and with it the critical damping, depend
    on it. Or give ``orbit`` and a time ``t`` (s) instead: the flux is then
    ``orbit.flux_scale(t)``, e.g. ``flutter(panel, orbit=Orbit.geo_year("2026-07-05"))`` near
    aphelion.

    ``layers=N`` analyses the N-node through-thickness model on the panel's layup (or one
    homogeneous layer for a plain panel); ``jacobian`` is then over (node temperatures…, θ, θ̇).

    With an ``orbit`` that heats the panel from the Earth (``orbit.albedo``, ``orbit.earth_ir``)
    or an ``attitude`` other than Sun-pointing, the equilibrium is the one in full sunlight under
    every load at the point ``t`` of the orbit (the Earth's infrared and albedo and the
    incidence there), and the critical damping is that equilibrium's; the N-node model
    (``layers=N``) takes them on its outer nodes.

    ``orbit_average=True`` (with ``orbit``) analyses instead the equilibrium under the forcing
    averaged over the sunlit arc of the orbit that begins at ``t``: every load (the front's
    sunlight at the Sun's distance and the attitude's incidence, the Earth's infrared and albedo,
    sunlight on the back) is averaged over the times the Sun is at least partly visible (the
    penumbra's partial Sun included), and the panel's quasi-steady state under that constant mean
    is the equilibrium the Jacobian, the growth rate and the critical damping are about. ``flux``
    is then the mean of the front's solar flux factor over the arc. Along an inclined LEO orbit the
    incidence and the Earth's loads change over the arc; this is the operating point about which
    the panel oscillates on average, where ``t`` alone gives one point of the arc.

    A :class:`thermojitter.Boom` in place of the panel: the tube's analysis, ``jacobian`` over
    (T_mean, T_circ, θ, θ̇), ``equilibrium`` a :class:`thermojitter.BoomEquilibrium`, and
    ``critical_damping`` the first mode's damping ratio ζ at which the growth rate crosses zero
    (not a c_d); ``model`` is ``"tube"``.
    """
    average = checks.flag("orbit_average", orbit_average)
    if average and orbit is None:
        raise checks.ParameterError("orbit_average", orbit_average, "needs an orbit (and t)")
    if isinstance(panel, Boom):
        if average:
            raise checks.ParameterError(
                "orbit_average", orbit_average, "is for a panel: a Boom takes the flux at t"
            )
        boom_module.check_attitude(attitude)
        return _boom_flutter(panel, model, coupled, flux, orbit, t)
    checks.instance("panel", panel, Panel, "a thermojitter.Panel")
    flux = _flux(flux, orbit, t)
    if attitude is not None and orbit is None:
        raise checks.ParameterError("attitude", attitude, "needs an orbit (and t)")
    coupled = checks.flag("coupled", coupled)
    checks.choice("model", model, ("nonlinear", "linear"))
    point: _FlutterPoint = {"model": model, "coupled": coupled, "flux": flux}
    # On an orbit with more than the front's sunlight, or averaged over its sunlit arc: the
    # engine takes the orbit's loads itself.
    on_orbit = orbit is not None and (average or has_face_loads(orbit, attitude))
    at_point: _core._OrbitPoint = {"t": t, "model": model, "coupled": coupled, "average": average}
    pd = panel.as_dict()
    nodes = None if layers is None else check_layers(layers)
    at = engine_orbit(orbit, attitude) if on_orbit and orbit is not None else None
    if nodes is not None:
        grid = grid_args(panel, nodes)
        if at is not None:
            raw = _core.layered_flutter_at(pd, grid, at, at_point)
        else:
            raw = _core.layered_flutter(pd, grid, point)
    elif at is not None:
        raw = _core.flutter_at(pd, at, at_point)
    else:
        raw = _core.flutter(pd, point)
    if average:  # the mean of the front's flux factor over the arc
        point["flux"] = float(raw["loads"][0])
    if nodes is not None:
        result = _layered_result(raw, point)
    else:
        tf, tb, th = raw["equilibrium"]
        moment = float(_core.moment(pd, np.array([tf]), np.array([tb]))[0])
        equilibrium = Equilibrium(T_front=tf, T_back=tb, theta=th, thermal_moment=moment)
        result = _result(raw, equilibrium, point)
    return dataclasses.replace(result, panel=panel, orbit=orbit)


def _flux(flux: float | None, orbit: Orbit | None, t: float) -> float:
    """The flux factor of an analysis: ``flux``, or ``orbit.flux_scale(t)``, or 1."""
    # t is checked even without an orbit: a t of the wrong type is a mistake either way.
    t = checks.finite("t", t)
    if orbit is not None:
        checks.instance("orbit", orbit, Orbit, "a thermojitter.Orbit")
        if flux is not None:
            raise checks.ParameterError("flux", flux, "give flux or orbit (with t), not both")
        flux = float(orbit.flux_scale(t)[0])
    return checks.real("flux", 1.0 if flux is None else flux)


def _boom_flutter(
    boom: Boom, model: str, coupled: bool, flux: float | None, orbit: Orbit | None, t: float
) -> FlutterResult:
    """The tube's flutter analysis (see :func:`flutter`)."""
    checks.choice("model", model, ("nonlinear", "linear"))
    flux = _flux(flux, orbit, t)
    if orbit is not None and has_face_loads(orbit, None):
        # As the boom's runs do: its analysis knows the Sun on its lit side only.
        raise checks.ParameterError(
            "orbit", orbit, "with Earth heating, a boom takes the Sun alone on its lit side"
        )
    coupled = checks.flag("coupled", coupled)
    raw = _core.boom_flutter(boom.as_dict(), coupled, flux)
    equilibrium = _boom_equilibrium(boom, raw["equilibrium"])
    point: _FlutterPoint = {"model": "tube", "coupled": coupled, "flux": flux}  # type: ignore[typeddict-item]
    return _result(raw, equilibrium, point)  # type: ignore[arg-type]


def _layered_result(raw: dict[str, Any], point: _FlutterPoint) -> FlutterResult:
    """The N-node model's flutter analysis: the Jacobian over (node temperatures…, θ, θ̇)."""
    temps = raw["temperatures"]
    equilibrium = Equilibrium(
        T_front=float(temps[0]),
        T_back=float(temps[-1]),
        theta=float(raw["theta"]),
        thermal_moment=float(raw["thermal_moment"]),
    )
    return _result(raw, equilibrium, point)


def _result(raw: dict[str, Any], equilibrium: Equilibrium, point: _FlutterPoint) -> FlutterResult:
    """The result from the engine's analysis (two-layer or N-node alike) about ``equilibrium``."""
    return FlutterResult(
        equilibrium=equilibrium,
        jacobian=np.asarray(raw["jacobian"]),
        eigenvalues=np.array([complex(re, im) for re, im in raw["eigenvalues"]]),
        growth_rate=float(raw["growth_rate"]),
        frequency_hz=float(raw["frequency_hz"]),
        critical_damping=float(raw["critical_damping"]),
        model=point["model"],
        coupled=point["coupled"],
        flux=float(point["flux"]),
    )


# ----------------------------------------------------------------------------- stability map

Axis = tuple[str, ArrayLike]

DEFAULT_X: tuple[str, NDArray[np.float64]] = ("damping", np.linspace(0.0, 5.0, 51))
"""Default x axis of :func:`stability_map`: hinge damping c_d, N m s/rad."""
MAX_GRID_POINTS = 4_000_000
"""Most points of a :func:`stability_map` grid (one eigen-analysis each, ~ a microsecond)."""
DEFAULT_Y: tuple[str, NDArray[np.float64]] = ("conductance", np.linspace(5.0, 60.0, 56))
"""Default y axis of :func:`stability_map`: through-thickness conductance K, W/(m² K)."""


@dataclass(frozen=True)
class StabilityMap(Persistent):
    """Flutter growth rate over a grid of two panel parameters.

    ``growth_rate[i, j]`` and ``frequency_hz[i, j]`` belong to ``y[i]`` and ``x[j]`` (rows follow
    y, as for ``matplotlib.pyplot.contourf(x, y, growth_rate)``).
    """

    x_name: str
    x: NDArray[np.float64]
    y_name: str
    y: NDArray[np.float64]
    growth_rate: NDArray[np.float64]
    frequency_hz: NDArray[np.float64]
    model: str
    coupled: bool
    flux: float
    panel: Panel | None = field(default=None, repr=False, compare=False)
    """The panel whose other fields the grid kept (saved with the result)."""

    xarray_dims: ClassVar[dict[str, tuple[str, ...]]] = {
        "x": ("x",),
        "y": ("y",),
        "growth_rate": ("y", "x"),
        "frequency_hz": ("y", "x"),
    }

    @property
    def stable(self) -> NDArray[np.bool_]:
        """True where the sunlit equilibrium is stable (growth rate < 0)."""
        return np.asarray(self.growth_rate < 0.0)


def _axis(which: str, axis: object) -> tuple[str, NDArray[np.float64]]:
    if not (isinstance(axis, tuple) and len(axis) == 2 and isinstance(axis[0], str)):
        raise checks.wrong_type(
            which,
            axis,
            "a (parameter name, values) tuple",
            f"{which} must be a (parameter name, values) tuple",
        )
    name, raw = axis
    if name not in _core.PANEL_FIELDS:
        raise checks.ParameterError(
            which, name, "not a panel parameter; one of " + ", ".join(_core.PANEL_FIELDS)
        )
    values = checks.real_array(f"{which}[{name!r}]", raw)
    if values.size == 0:
        raise checks.ParameterError(f"{which}[{name!r}]", raw, "must hold at least one value")
    return name, values


def stability_map(
    panel: Panel,
    x: Axis = DEFAULT_X,
    y: Axis = DEFAULT_Y,
    model: Literal["nonlinear", "linear"] = "nonlinear",
    *,
    coupled: bool = True,
    flux: float = 1.0,
    progress: bool = True,
) -> StabilityMap:
    """Growth rate of the sunlit equilibrium with two panel parameters swept over a grid.

    ``x`` and ``y`` are ``(name, values)`` with ``name`` any :class:`Panel` field; the other
    fields keep the values of ``panel``. The grid is analysed in parallel by the engine (one
    eigen-analysis per point, the same as :func:`flutter`); the result does not depend on the
    number of threads. A grid that takes more than a second shows a progress bar (``progress``);
    Ctrl-C stops it within a grid point and raises ``KeyboardInterrupt``.
    """
    checks.instance("panel", panel, Panel, "a thermojitter.Panel")
    x_name, xs = _axis("x", x)
    y_name, ys = _axis("y", y)
    if x_name == y_name:
        raise checks.ParameterError("y", y_name, "must differ from the x parameter")
    if xs.size * ys.size > MAX_GRID_POINTS:
        raise checks.ParameterError(
            "x",
            xs.size * ys.size,
            message=f"x = {xs.size} x {ys.size} points is invalid: the grid may hold at most "
            f"{MAX_GRID_POINTS}",
        )
    coupled = checks.flag("coupled", coupled)
    flux = checks.real("flux", flux)
    checks.choice("model", model, ("nonlinear", "linear"))
    # Blocks of rows of about MAP_BLOCK points: each a parallel engine call, with progress and
    # Ctrl-C between them.
    rows_per_block = max(1, MAP_BLOCK // xs.size)
    growth, frequency = [], []
    checks.flag("progress", progress)
    bar = progress_bar(ys.size, unit="row", desc="stability map", enabled=progress, delay=1.0)
    try:
        for start in range(0, ys.size, rows_per_block):
            block = ys[start : start + rows_per_block]
            raw = interruptible(
                _core.stability_map,
                panel.as_dict(),
                x_name,
                xs.tolist(),
                y_name,
                block.tolist(),
                model,
                coupled,
                flux,
            )
            growth.append(np.asarray(raw["growth_rate"], dtype=float).reshape(block.size, -1))
            frequency.append(np.asarray(raw["frequency_hz"], dtype=float).reshape(block.size, -1))
            if bar is not None:
                bar.update(block.size)
    finally:
        if bar is not None:
            bar.close()
    return StabilityMap(
        x_name=x_name,
        x=xs,
        y_name=y_name,
        y=ys,
        growth_rate=np.concatenate(growth),
        frequency_hz=np.concatenate(frequency),
        model=model,
        coupled=coupled,
        flux=float(flux),
        panel=panel,
    )


# ------------------------------------------------------------ closed-form linear analysis (4.2)


@dataclass(frozen=True)
class LinearThermalResponse(Persistent):
    """The linear analysis of paper Sec. 4.2.

    With ε_f = ε_b = ε and T⁴ linearised about a common T*, the gradient ΔT = T_f − T_b obeys

        dΔT/dt + q ΔT = p cos θ,     p = 2 α C flux/(m c),   q = (4 K + 8 σ ε T*³)/(m c)

    and the linear hinge θ̈ + r θ̇ + ω_n² θ = s ΔT, r = c_d/I_B, s = χ a E I/(I_B d). Under a
    forcing p cos(ω t + φ) the steady response is

        ΔT(t) = p/√(q² + ω²) · cos(ω t + φ − lag),   lag = atan2(ω, q),

    (the paper's p q²/(q² + ω²) [cos/q + ω sin/q²], rewritten). The projected area varies at the
    hinge frequency, so the forcing of the hinge by s ΔT has the hinge's own frequency: the system
    is resonant, and the lag puts part of the moment in phase with θ̇. For a swing θ = θ* + A cos
    ω_n t that part acts as a negative damping
    ``thermal_damping = s p sin θ* /(q² + ω_n²)`` (1/s); the oscillation grows when it exceeds r,
    at about (thermal_damping − r)/2, so the critical damping is about
    ``I_B · thermal_damping`` — which the eigen-analysis of :func:`flutter` gives exactly.
    """

    p: float
    """Forcing of the gradient, K/s."""
    q: float
    """Relaxation rate of the gradient, 1/s."""
    r: float
    """Hinge damping rate c_d/I_B, 1/s."""
    s: float
    """Hinge acceleration per kelvin of gradient, rad/(K s²)."""
    omega: float
    """Forcing angular frequency, rad/s."""
    omega_n: float
    """Natural angular frequency of the linear hinge, rad/s."""
    T_star: float
    """Linearisation temperature, K."""
    emissivity: float
    """Common emissivity ε used in q, the mean of ε_f and ε_b."""
    theta_star: float
    """Sunlit equilibrium hinge angle, rad."""
    hinge_inertia: float
    """I_B, kg m²."""
    amplitude: float
    """Steady amplitude of ΔT under p cos(ω t + φ), K: p/√(q² + ω²)."""
    phase_lag: float
    """Lag of ΔT behind the forcing, rad: atan2(ω, q), in [0, π/2)."""
    time_constant: float
    """1/q, s: how fast the gradient forgets its initial value."""
    resonant: bool
    """True when the forcing is at the hinge's natural frequency (within 1 %)."""
    thermal_damping: float
    """Negative damping rate from the lag, 1/s: s p sin θ* /(q² + ω_n²)."""
    critical_damping_estimate: float
    """c_d at which the lag's pumping is balanced, N m s/rad: I_B · thermal_damping."""
    growth_rate_estimate: float
    """Growth rate of the swing, 1/s: (thermal_damping − r)/2."""
    panel: Panel | None = field(default=None, repr=False, compare=False)
    """The panel analysed (saved with the result)."""

    def delta_T(
        self, t: ArrayLike, *, phi: float = 0.0, delta_T0: float | None = None
    ) -> NDArray[np.float64]:
        """Closed-form ΔT(t) for dΔT/dt + q ΔT = p cos(ω t + φ), K.

        ``delta_T0``: the gradient at t = 0 (its transient decays as e^(−q t)); ``None`` gives the
        steady (long-period) solution alone."""
        times = np.asarray(t, dtype=float)
        fields = {name: getattr(self, name) for name in _core.LINEAR_FIELDS}
        values = _core.linear_delta_t(
            fields,
            np.ascontiguousarray(times.ravel()),
            float(phi),
            None if delta_T0 is None else float(delta_T0),
        )
        return np.asarray(values).reshape(times.shape)

    def describe(self) -> str:
        """A short statement of the analysis, with numbers."""
        return (
            f"p = {self.p:.4g} K/s, q = {self.q:.4g} 1/s (1/q = {self.time_constant:.1f} s), "
            f"omega = {self.omega:.4g} rad/s: dT amplitude {self.amplitude:.4g} K per unit "
            f"cos forcing, lag {math.degrees(self.phase_lag):.1f} deg. "
            + (
                "The forcing is at the hinge's natural frequency: the system is resonant. "
                if self.resonant
                else ""
            )
            + f"Thermal pumping {self.thermal_damping:.4g} 1/s vs damping r = {self.r:.4g} 1/s: "
            f"critical c_d ~ {self.critical_damping_estimate:.4g} N m s/rad."
        )


def linear_thermal_response(
    panel: Panel,
    omega: float | None = None,
    T_star: float | None = None,
    *,
    flux: float = 1.0,
) -> LinearThermalResponse:
    """The closed-form linear analysis of paper Sec. 4.2 for ``panel``.

    ``omega``: forcing angular frequency, rad/s (default ω_n, the hinge's natural frequency, as in
    the paper). ``T_star``: linearisation temperature, K (default the mean of the two layers at the
    sunlit equilibrium under ``flux``). The paper assumes ε_f = ε_b; for other panels ε is taken
    as their mean, an approximation.
    """
    checks.instance("panel", panel, Panel, "a thermojitter.Panel")
    raw = _core.linear_thermal(
        panel.as_dict(),
        checks.positive("flux", flux),
        None if omega is None else checks.real("omega", omega),
        None if T_star is None else checks.real("T_star", T_star),
    )
    return LinearThermalResponse(**raw, panel=panel)
