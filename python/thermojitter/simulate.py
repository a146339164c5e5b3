"""Running the models: the coupled system, the thermal models alone, the hinge alone."""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
from numpy.typing import ArrayLike

from thermojitter import _core
from thermojitter import errors as checks

# What every run shares (its home before _runs.py), exported here as before.
from thermojitter._runs import DEFAULT_DT_OUT as DEFAULT_DT_OUT
from thermojitter._runs import DEFAULT_THETA_LIMIT as DEFAULT_THETA_LIMIT
from thermojitter._runs import ON_LIMIT as ON_LIMIT
from thermojitter._runs import limit_args as limit_args
from thermojitter._runs import limit_record as limit_record
from thermojitter._runs import run_record as run_record
from thermojitter._runs import run_settings as run_settings
from thermojitter._runs import solver_args as solver_args
from thermojitter._runs import start_state as start_state
from thermojitter._runs import time_span as time_span
from thermojitter._runs import warn_crossing as warn_crossing
from thermojitter.attitude import Attitude, engine_orbit
from thermojitter.boom import Boom, boom_steady_state, check_attitude, simulate_boom
from thermojitter.errors import ParameterError
from thermojitter.orbit import Orbit
from thermojitter.panel import Equilibrium, Panel
from thermojitter.panel import steady_state as panel_steady_state
from thermojitter.progress import interruptible
from thermojitter.results import HingeSolution, Solution, ThermalSolution
from thermojitter.solver import ATOL, MAX_STEP, MAX_STEPS, RTOL, SolverSettings

if TYPE_CHECKING:
    from thermojitter._core import _Grid, _Orbits

Model = Literal["nonlinear", "linear"]
Method = Literal["rk45", "rk4"]
OnLimit = Literal["flag", "stop", "ignore"]


_MODELS = ("nonlinear", "linear")
_METHODS = ("rk45", "rk4")


def _hinge_columns(raw: Mapping[str, Any]) -> dict[str, Any]:
    """The columns of a coupled run beside its temperatures, and its limit."""
    columns = ("theta", "theta_dot", "thermal_moment", "sunlit", "y_end")
    return {**{name: raw[name] for name in columns}, **limit_record(raw)}


def solver_settings(
    method: str, rtol: float, atol: float, dt: float | None, max_step: float, max_steps: int
) -> dict[str, Any]:
    """The integrator settings as the engine takes them, checked (see :class:`SolverSettings`);
    ``dt`` is the fixed step of rk4, ``max_step`` caps rk45's step (s)."""
    return SolverSettings(method, rtol, atol, dt, max_step, max_steps).as_dict()  # type: ignore[arg-type]


_NO_ORBIT: Any = object()


def check_inputs(panel: Panel, orbit: Orbit = _NO_ORBIT) -> None:
    """TypeError unless ``panel`` is a Panel (and ``orbit``, when the call takes one, an Orbit:
    None is not an orbit)."""
    checks.instance("panel", panel, Panel, "a thermojitter.Panel")
    if orbit is not _NO_ORBIT:
        checks.instance("orbit", orbit, Orbit, "a thermojitter.Orbit")


def check_layers(layers: Any) -> int:
    """``layers`` as a node count through the thickness: an int in [2, MAX_NODES] (the engine
    checks it against the layup)."""
    return checks.integer("layers", layers, 2, _core.MAX_NODES)


def layup_dict(panel: Panel) -> dict[str, Any] | None:
    """The panel's layup as the engine takes it (None: one homogeneous layer)."""
    return None if panel.layup is None else panel.layup.as_dict()


def grid_args(panel: Panel, nodes: int) -> _Grid:
    """The engine's ``grid`` mapping of the N-node model (``Grid`` in rust/src/bindings/convert.rs):
    the panel's layup and ``nodes`` (checked by :func:`check_layers`)."""
    return {"layup": layup_dict(panel), "nodes": nodes}


def orbits_args(options: Mapping[str, Any], n_orbits: int) -> _Orbits:
    """The engine's ``orbits`` mapping of a run of ``n_orbits`` whole orbits (``OrbitsRun`` in
    rust/src/bindings/convert.rs), for the long run and the Monte Carlo batches alike, from run
    options naming ``model``, ``coupled``, ``solver``, ``window`` and optionally ``hybrid`` (its
    settings) and the N-node model's ``nodes`` and ``layup``."""
    nodes = options.get("nodes")
    return {
        "model": options["model"],
        "coupled": options["coupled"],
        "solver": options["solver"],
        "n_orbits": n_orbits,
        "window": options["window"],
        "hybrid": options.get("hybrid"),
        "grid": None if nodes is None else {"layup": options.get("layup"), "nodes": nodes},
    }


def steady_state(panel: Panel, *, coupled: bool = True, flux: float = 1.0) -> Equilibrium:
    """The sunlit equilibrium of the coupled system (θ̇ = 0, all rates zero).

    ``coupled=False`` freezes the projected area (cos θ → 1). ``flux`` scales the solar constant
    (1: nominal; e.g. 1.033 at perihelion). A :class:`thermojitter.Boom` gives its
    :class:`thermojitter.BoomEquilibrium` (:func:`thermojitter.boom_steady_state`).
    """
    if isinstance(panel, Boom):
        return boom_steady_state(panel, coupled=coupled, flux=flux)  # type: ignore[return-value]
    return panel_steady_state(panel, coupled=coupled, flux=flux)


def simulate(
    panel: Panel | Boom,
    orbit: Orbit,
    t_span: Sequence[float],
    *,
    model: Model = "nonlinear",
    coupled: bool = True,
    method: Method = "rk45",
    rtol: float = RTOL,
    atol: float = ATOL,
    dt: float | None = None,
    t_eval: ArrayLike | None = None,
    dt_out: float | None = None,
    y0: Sequence[float] | None = None,
    max_step: float = MAX_STEP,
    max_steps: int = MAX_STEPS,
    layers: int | None = None,
    solver: SolverSettings | None = None,
    theta_limit: float = DEFAULT_THETA_LIMIT,
    on_limit: OnLimit = "flag",
    attitude: Attitude | None = None,
) -> Solution:
    """Integrates the coupled thermo-structural model over ``t_span`` (s).

    - ``model``: ``"nonlinear"`` hinge (paper eq. 20) or ``"linear"`` (eq. 28).
    - ``coupled``: absorbed flux ∝ cos θ (two-way coupling); ``False`` freezes the projected area
      (paper Fig. 18).
    - ``method``: ``"rk45"`` (Dormand–Prince 5(4), error control by ``rtol``/``atol``) or ``"rk4"``
      (classical, fixed step ``dt`` in s).
    - Reporting: at ``t_eval`` (sorted times inside the span, from the dense output), or every
      ``dt_out`` s (default 0.5 s). Every step is never kept.
    - ``y0``: (T_front K, T_back K, θ rad, θ̇ rad/s); default the sunlit equilibrium.

    Steps stop exactly at every shadow entry and exit. Error control alone (as here by default,
    like scipy's RK45) lets the step grow once the oscillation is small against ``atol``, and
    the method's own dissipation can then hide a weak flutter near the critical damping: for
    growth studies pass ``max_step`` ≈ T_n/40 (T_n = 1/natural_frequency), or use
    :func:`thermojitter.simulate_orbits`, which does so by default.

    ``layers=N`` runs the N-node through-thickness model (nodes on both faces, on every layer
    interface and inside the layers) on the panel's layup (:meth:`Panel.from_laminate`), or on
    one homogeneous layer for a plain panel, where ``layers=2`` is the two-layer model itself.
    The solution then carries ``T_nodes`` (time × node, K) and ``depth`` (m below the front
    face); ``y0`` is (node temperatures…, θ, θ̇).

    ``solver``: a :class:`thermojitter.SolverSettings` in place of ``method``, ``rtol``, ``atol``,
    ``dt``, ``max_step`` and ``max_steps``; ``sol.solver`` is what the engine used.

    ``theta_limit`` (rad, in (0, π/2]; default 20°): the hinge model's range of validity, checked
    by the engine on every step (on the interpolant, so a crossing between two samples is found
    where it happens). When abs(θ) passes it, ``on_limit="flag"`` (default) records the first
    crossing in ``sol.limit_crossing`` (t, orbit, θ) and issues one
    :class:`thermojitter.errors.ValidityLimitWarning`; ``"stop"`` does so and ends the run there
    (``sol.stopped_at_limit``: no sample after the crossing, ``y_end`` the state at it);
    ``"ignore"`` checks nothing.

    ``attitude``: where the front face points (:class:`thermojitter.Attitude`; default
    Sun-pointing, the paper's plate). With it, and with the orbit's Earth heating
    (``orbit.albedo``, ``orbit.earth_ir``), each face absorbs sunlight, albedo and Earth
    infrared through its own incidence and view factor (docs/howto/earth-heating.md);
    ``sol.flux_front`` and ``sol.flux_back`` are the fluxes reaching each face, W/m². The N-node
    model (``layers=N``) takes them on its outer nodes, the front's loads on the front node and the
    back's on the back node.

    Ctrl-C stops the run within one integration step (``KeyboardInterrupt``).

    Raises ``ValueError`` naming a bad input, ``IntegrationError`` if the integrator cannot
    finish.

    A :class:`thermojitter.Boom` in place of the panel runs the tube
    (:func:`thermojitter.boom.simulate_boom`: a :class:`thermojitter.BoomSolution`, ``y0`` =
    (T_mean, T_circ, θ, θ̇); its rigid link has one equation of motion, whatever ``model``).
    """
    if isinstance(panel, Boom):
        checks.choice("model", model, _MODELS)
        if layers is not None:
            raise ParameterError("layers", layers, "a Boom has its own thermal model")
        check_attitude(attitude)
        return simulate_boom(  # type: ignore[return-value]
            panel, orbit, t_span, coupled=coupled, method=method, rtol=rtol, atol=atol, dt=dt,
            t_eval=t_eval, dt_out=dt_out, y0=y0, max_step=max_step, max_steps=max_steps,
            solver=solver, theta_limit=theta_limit, on_limit=on_limit,
        )  # fmt: skip
    check_inputs(panel, orbit)
    engine_orbit_args = engine_orbit(orbit, attitude)
    used, run = run_settings(
        solver, time_span(t_span), t_eval, dt_out, method=method, rtol=rtol, atol=atol, dt=dt,
        max_step=max_step, max_steps=max_steps,
    )  # fmt: skip
    run["limit"] = limit_args(theta_limit, on_limit)
    settings: dict[str, Any] = {"rtol": used.rtol, "atol": used.atol, "dt": used.dt}
    settings.update(model=model, coupled=coupled)
    settings.update(run["limit"])
    if "attitude" in engine_orbit_args:
        settings["attitude"] = engine_orbit_args["attitude"]
    nodes = None if layers is None else check_layers(layers)
    hinge = {
        "model": checks.choice("model", model, _MODELS),
        "coupled": checks.flag("coupled", coupled),
    }
    run["y0"] = start_state(y0, 4 if nodes is None else None)
    if nodes is not None:
        raw = interruptible(
            _core.simulate_layers,
            panel.as_dict(),
            grid_args(panel, nodes),
            engine_orbit_args,
            run,
            **hinge,
        )
        temps = np.asarray(raw["T_nodes"])
        sol = Solution(
            **run_record(raw, used),
            settings={**settings, "layers": nodes, "solver": dict(raw["solver"])},
            panel=panel,
            orbit=orbit,
            T_front=temps[:, 0],
            T_back=temps[:, -1],
            **_hinge_columns(raw),
            T_nodes=temps,
            depth=raw["depth"],
            node_labels=tuple(raw["node_labels"]),
            flux_front=raw.get("flux_front"),
            flux_back=raw.get("flux_back"),
        )
        warn_crossing(sol.limit_crossing, theta_limit, on_limit)
        return sol
    raw = interruptible(_core.simulate, panel.as_dict(), engine_orbit_args, run, **hinge)
    sol = Solution(
        **run_record(raw, used),
        settings={**settings, "solver": dict(raw["solver"])},
        panel=panel,
        orbit=orbit,
        T_front=raw["T_front"],
        T_back=raw["T_back"],
        **_hinge_columns(raw),
        flux_front=raw.get("flux_front"),
        flux_back=raw.get("flux_back"),
    )
    warn_crossing(sol.limit_crossing, theta_limit, on_limit)
    return sol


def simulate_thermal(
    panel: Panel,
    orbit: Orbit,
    t_span: Sequence[float],
    *,
    layers: Literal[1, 2] = 2,
    method: Method = "rk45",
    rtol: float = RTOL,
    atol: float = ATOL,
    dt: float | None = None,
    t_eval: ArrayLike | None = None,
    dt_out: float | None = None,
    y0: Sequence[float] | None = None,
    max_step: float = MAX_STEP,
    max_steps: int = MAX_STEPS,
    solver: SolverSettings | None = None,
    attitude: Attitude | None = None,
) -> ThermalSolution:
    """The thermal models alone (paper Figs. 2–6): one isothermal node (eq. 1) or two layers
    (eq. 2 with θ = 0). ``y0`` defaults to the sunlit equilibrium of that model. ``attitude``
    and the orbit's Earth heating as in :func:`simulate` (the isothermal node absorbs both
    faces' loads)."""
    check_inputs(panel, orbit)
    layers = checks.integer("layers", layers, 1, 2)  # type: ignore[assignment]
    used, run = run_settings(
        solver, time_span(t_span), t_eval, dt_out, method=method, rtol=rtol, atol=atol, dt=dt,
        max_step=max_step, max_steps=max_steps,
    )  # fmt: skip
    run["y0"] = start_state(y0, int(layers))
    raw = interruptible(
        _core.simulate_thermal,
        panel.as_dict(),
        engine_orbit(orbit, attitude),
        run,
        layers=int(layers),
    )
    return ThermalSolution(
        **run_record(raw, used),
        settings={"solver": dict(raw["solver"])},
        panel=panel,
        orbit=orbit,
        layers=int(layers),
        T=raw.get("T"),
        T_front=raw.get("T_front"),
        T_back=raw.get("T_back"),
    )


def simulate_hinge(
    panel: Panel,
    moment: float | ArrayLike,
    t_span: Sequence[float],
    *,
    moment_t: ArrayLike | None = None,
    model: Model = "nonlinear",
    y0: Sequence[float] = (0.0, 0.0),
    method: Method = "rk45",
    rtol: float = RTOL,
    atol: float = ATOL,
    dt: float | None = None,
    t_eval: ArrayLike | None = None,
    dt_out: float | None = None,
    max_step: float = MAX_STEP,
    max_steps: int = MAX_STEPS,
    solver: SolverSettings | None = None,
) -> HingeSolution:
    """The hinge alone under a prescribed thermal moment (N m): a constant, or samples
    ``moment`` at times ``moment_t`` (linear in between, held beyond the ends).
    ``y0`` = (θ rad, θ̇ rad/s)."""
    check_inputs(panel)
    used, run = run_settings(
        solver, time_span(t_span), t_eval, dt_out, method=method, rtol=rtol, atol=atol, dt=dt,
        max_step=max_step, max_steps=max_steps,
    )  # fmt: skip
    m = checks.real_array("moment", moment)
    mt = None if moment_t is None else checks.real_array("moment_t", moment_t)
    hinge = checks.choice("model", model, _MODELS)
    run["y0"] = start_state(y0, 2) or []
    raw = interruptible(
        _core.simulate_hinge, panel.as_dict(), run, model=hinge, moment=m, moment_t=mt
    )
    return HingeSolution(
        **run_record(raw, used),
        settings={"solver": dict(raw["solver"])},
        panel=panel,
        theta=raw["theta"],
        theta_dot=raw["theta_dot"],
    )


def hinge_energy(
    panel: Panel,
    theta: ArrayLike,
    theta_dot: ArrayLike,
    moment: float,
    *,
    model: Model = "nonlinear",
) -> np.ndarray:
    """Energy of the hinge in a constant moment field (kinetic + spring − M θ), J.
    Conserved when c_d = 0."""
    check_inputs(panel)
    th = checks.real_array("theta", theta)
    om = checks.real_array("theta_dot", theta_dot)
    if th.shape != om.shape:
        raise ParameterError("theta_dot", theta_dot, f"must have theta's shape {th.shape}")
    m = checks.finite("moment", moment)
    return np.asarray(_core.energy(panel.as_dict(), model, th, om, m))
