"""The spacecraft bus and its pointing error: a rigid bus turning about one axis, carrying hinged
panels whose thermal moments turn it.

    import thermojitter as tj
    wing = tj.Panel.paper()
    craft = tj.Spacecraft(7.7e4, appendages=[(wing, (0.0, 2.0), +1), (wing, (0.0, -2.0), +1)],
                          controller=tj.PD(bandwidth=0.1, damping=0.7))
    sol = tj.simulate_spacecraft(craft, tj.Orbit.geo_equinox(), (t0, t1), budget=0.007)
    sol.pointing_error          # arcsec
    sol.after_crossings()       # peak and rms after each terminator crossing

The model (its equations and assumptions are the engine's, ``models/spacecraft.rs``): the bus's
attitude φ about its axis z, each appendage's hinge angle θ_i (the paper's linear hinge, eq. 28)
about an axis parallel to z, coupled through the appendages' inertia about the bus axis and the
hinges' offsets (the mass matrix from the kinetic energy). Each appendage's mass (mass per length
× length) is lumped at its radius of gyration about the hinge, so that its inertia there is the
hinge model's I_B; the bus's centre is taken as fixed (the system's centre of mass). Each panel's
incidence is its absolute attitude φ + θ_i (two-way coupling); with no controller and no
disturbance the angular momentum about the bus axis is conserved.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import Any, NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from thermojitter import _core
from thermojitter import errors as checks
from thermojitter.errors import ParameterError
from thermojitter.orbit import Orbit
from thermojitter.panel import Panel
from thermojitter.progress import interruptible
from thermojitter.signals import power_spectral_density, window
from thermojitter.simulate import run_record, run_settings, start_state, time_span
from thermojitter.solver import SolverSettings

Array = NDArray[np.float64]

ARCSEC_PER_RADIAN: float = _core.ARCSEC_PER_RADIAN
"""Arcseconds in a radian (648000/π)."""

_COLUMNS = (
    "phi", "phi_dot", "theta", "theta_dot", "T_front", "T_back", "thermal_moment",
    "reaction_torque", "bus_torque", "angular_momentum",
)  # fmt: skip
"""The engine's columns a :class:`SpacecraftSolution` holds as they come."""

_AXIS_TOLERANCE = 1e-9
"""How far (relative) a hinge axis given as a vector may lean off the bus axis."""


@dataclass(frozen=True)
class PD:
    """A proportional-derivative attitude controller on the bus's attitude φ: torque
    −K_p φ − K_d φ̇ with K_p = J ω_c², K_d = 2 ζ ω_c J, J the spacecraft's inertia about the bus
    axis at rest (bus and appendages). ``bandwidth`` ω_c, rad/s (> 0); ``damping`` ζ (>= 0)."""

    bandwidth: float
    damping: float = 0.7

    def __post_init__(self) -> None:
        object.__setattr__(self, "bandwidth", checks.positive("bandwidth", self.bandwidth))
        damping = checks.finite("damping", self.damping)
        if damping < 0.0:
            raise ParameterError("damping", self.damping, "must be >= 0")
        object.__setattr__(self, "damping", damping)


class Appendage(NamedTuple):
    """One hinged appendage as the spacecraft holds it: its panel, its hinge's position (x, y, z)
    in the bus frame (m; z along the bus axis), the hinge axis's sense (+1 along the bus axis,
    −1 against it) and its distance from the bus axis, hypot(x, y) (m)."""

    panel: Panel
    position: tuple[float, float, float]
    sense: int
    offset: float


def _position(name: str, value: Any) -> tuple[float, float, float]:
    arr = checks.real_array(name, value)
    if arr.size not in (2, 3):
        raise ParameterError(name, value, "must be (x, y) or (x, y, z) in m, the bus frame")
    xyz = [float(v) for v in arr] + [0.0] * (3 - arr.size)
    return xyz[0], xyz[1], xyz[2]


def _sense(name: str, value: Any) -> int:
    """+1 or −1 from a sign or from an axis vector parallel to the bus axis z."""
    if isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool):
        if value in (1, -1):
            return int(value)
        raise ParameterError(name, value, "must be +1 or -1, or a vector along the bus axis")
    arr = checks.real_array(name, value)
    if arr.size != 3 or arr[2] == 0.0:
        raise ParameterError(name, value, "must be +1, -1 or a 3-vector along the bus axis z")
    if math.hypot(arr[0], arr[1]) > _AXIS_TOLERANCE * abs(arr[2]):
        raise ParameterError(
            name, value, "must be parallel to the bus axis z (the model is planar)"
        )
    return 1 if arr[2] > 0 else -1


def _appendage(i: int, item: Any) -> Appendage:
    name = f"appendages[{i}]"
    if isinstance(item, Appendage):
        item = (item.panel, item.position, item.sense)
    if not isinstance(item, (tuple, list)) or len(item) != 3:
        raise checks.wrong_type(name, item, "a (panel, hinge position, axis) tuple")
    panel, position, axis = item
    checks.instance(f"{name}.panel", panel, Panel, "a thermojitter.Panel")
    xyz = _position(f"{name}.position", position)
    return Appendage(panel, xyz, _sense(f"{name}.axis", axis), math.hypot(xyz[0], xyz[1]))


class Spacecraft:
    """A rigid bus of inertia ``bus_inertia`` (kg m², about its axis z; ``math.inf`` for a bus
    that does not turn, the paper's clamped panel) carrying ``appendages``, each
    ``(panel, hinge position, axis)``: a :class:`thermojitter.Panel`, the hinge's position
    (x, y) or (x, y, z) in m in the bus frame from the bus's centre (z along the bus axis: it does
    not change the inertia about z), and the hinge axis, +1 or −1 (along the bus axis or against
    it), or a 3-vector parallel to z. The hinge angle θ_i (positive as the thermal moment drives
    it) turns the appendage about z by ±θ_i. ``controller``: None, or a :class:`PD`.
    """

    def __init__(
        self,
        bus_inertia: float,
        appendages: Sequence[Any] = (),
        controller: PD | None = None,
    ) -> None:
        j = checks.real("bus_inertia", bus_inertia)
        if not (j > 0.0):
            raise ParameterError("bus_inertia", bus_inertia, "must be > 0 kg m² (inf: fixed)")
        if isinstance(appendages, (str, bytes)) or not isinstance(appendages, Sequence):
            raise checks.wrong_type("appendages", appendages, "a sequence of appendages")
        if controller is not None:
            checks.instance("controller", controller, PD, "None or a thermojitter.PD")
            if math.isinf(j):
                raise ParameterError(
                    "controller", controller, "cannot act on a bus of infinite inertia"
                )
        self.bus_inertia = j
        self.appendages = tuple(_appendage(i, a) for i, a in enumerate(appendages))
        self.controller = controller

    def __repr__(self) -> str:
        return (
            f"Spacecraft(bus_inertia={self.bus_inertia!r}, "
            f"appendages={len(self.appendages)}, controller={self.controller!r})"
        )

    def simulate(self, orbit: Orbit, t_span: Sequence[float], **options: Any) -> SpacecraftSolution:
        """:func:`simulate_spacecraft` of this spacecraft."""
        return simulate_spacecraft(self, orbit, t_span, **options)


class CrossingPointing(NamedTuple):
    """The pointing error after one terminator crossing, over ``[t, t + duration]``: its change
    since the crossing, φ(t') − φ(t), peak (largest magnitude) and rms, in arcsec. ``kind``:
    ``"entry"`` (into the shadow) or ``"exit"``."""

    t: float
    kind: str
    duration: float
    peak: float
    rms: float


@dataclass
class SpacecraftSolution:
    """A spacecraft run. Angles are in rad, the pointing error in arcsec; the per-appendage
    columns are (time × appendage) arrays."""

    t: Array
    phi: Array
    """The bus's attitude error φ, rad (its reference is 0)."""
    phi_dot: Array
    theta: Array
    theta_dot: Array
    T_front: Array
    T_back: Array
    thermal_moment: Array
    reaction_torque: Array
    """The torque of each appendage on the bus about its axis, N m."""
    bus_torque: Array
    """The external torque on the bus (controller and disturbance), N m."""
    angular_momentum: Array | None
    """About the bus axis, kg m²/s (None for a bus of infinite inertia)."""
    gains: tuple[float, float] | None
    inertia_at_rest: float
    crossings: list[tuple[float, str]]
    """The terminator crossings inside the run: (time, ``"entry"`` or ``"exit"``)."""
    y_end: Array
    n_steps: int
    n_rejected: int
    n_rhs: int
    method: str
    settings: dict[str, Any] = field(default_factory=dict)
    budget: float | None = None
    """The rms budget (arcsec) the run was checked against, if any."""

    @property
    def pointing_error(self) -> Array:
        """φ in arcsec."""
        return self.phi * ARCSEC_PER_RADIAN

    @property
    def pointing_rate(self) -> Array:
        """φ̇ in arcsec/s."""
        return self.phi_dot * ARCSEC_PER_RADIAN

    @property
    def pointing_rms(self) -> float:
        """The rms of the pointing error over the run, arcsec."""
        return float(np.sqrt(np.mean(self.pointing_error**2)))

    @property
    def pointing_peak(self) -> float:
        """The largest magnitude of the pointing error over the run, arcsec."""
        return float(np.max(np.abs(self.pointing_error)))

    def psd(self, t0: float | None = None, t1: float | None = None) -> tuple[Array, Array]:
        """Power spectral density of the pointing error (arcsec²/Hz) over [t0, t1] (default the
        whole run): frequencies (Hz) and densities
        (:func:`thermojitter.signals.power_spectral_density`; uniform samples, ``dt_out``)."""
        lo = float(self.t[0]) if t0 is None else checks.finite("t0", t0)
        hi = float(self.t[-1]) if t1 is None else checks.finite("t1", t1)
        ts, xs = window(self.t, self.pointing_error, lo, hi)
        return power_spectral_density(ts, xs)

    def after_crossings(self, duration: float | None = None) -> list[CrossingPointing]:
        """Peak and rms of the pointing error's change after each terminator crossing, over
        ``duration`` s (default: until the next crossing or the end of the run)."""
        span = None if duration is None else checks.positive("duration", duration)
        out = []
        ends = [t for t, _ in self.crossings[1:]] + [float(self.t[-1])]
        for (tc, kind), nxt in zip(self.crossings, ends, strict=True):
            t1 = nxt if span is None else min(tc + span, float(self.t[-1]))
            mask = (self.t >= tc) & (self.t <= t1)
            if not mask.any():
                continue
            start = float(np.interp(tc, self.t, self.pointing_error))
            change = self.pointing_error[mask] - start
            out.append(
                CrossingPointing(
                    tc,
                    kind,
                    t1 - tc,
                    float(np.max(np.abs(change))),
                    float(np.sqrt(np.mean(change**2))),
                )
            )
        return out

    def meets(self, budget: float, duration: float | None = None) -> bool:
        """Whether the rms pointing error after every terminator crossing (see
        :meth:`after_crossings`) is within ``budget`` arcsec; with no crossing in the run, the
        rms over the whole run."""
        limit = checks.positive("budget", budget)
        after = self.after_crossings(duration)
        if not after:
            return self.pointing_rms <= limit
        return all(c.rms <= limit for c in after)

    @property
    def passed(self) -> bool | None:
        """:meth:`meets` of the run's ``budget`` (None when none was given)."""
        return None if self.budget is None else self.meets(self.budget)


def _crossings(orbit: Orbit, t0: float, t1: float) -> list[tuple[float, str]]:
    found = []
    for a, b in orbit.shadow_intervals(t0, t1):
        if a > t0:
            found.append((float(a), "entry"))
        if b < t1:
            found.append((float(b), "exit"))
    return sorted(found)


def simulate_spacecraft(
    spacecraft: Spacecraft,
    orbit: Orbit,
    t_span: Sequence[float],
    *,
    disturbance: float = 0.0,
    bus_rate: float = 0.0,
    budget: float | None = None,
    y0: Sequence[float] | None = None,
    solver: SolverSettings | None = None,
    t_eval: ArrayLike | None = None,
    dt_out: float | None = None,
) -> SpacecraftSolution:
    """Integrates a :class:`Spacecraft` over ``t_span`` (s) in ``orbit``.

    - ``disturbance``: a constant external torque on the bus, N m (with a :class:`PD` the bus
      settles at φ = disturbance / K_p).
    - ``bus_rate``: the bus's rate at the start, rad/s (the default start: φ = 0, each panel at
      its sunlit equilibrium at rest, as :func:`thermojitter.simulate`'s).
    - ``y0``: the whole start state instead, (φ, φ̇, then T_front, T_back, θ, θ̇ per appendage).
    - ``budget``: an rms pointing budget in arcsec (Hubble's was 0.007″); ``sol.passed`` says
      whether the rms after every terminator crossing is within it.
    - ``solver``: a :class:`thermojitter.SolverSettings` (default: :func:`thermojitter.simulate`'s
      rk45 settings); reporting at ``t_eval`` or every ``dt_out`` s (default 0.5 s).

    Raises :class:`thermojitter.ParameterError` naming a bad input, ``IntegrationError`` if the
    integrator cannot finish.
    """
    checks.instance("spacecraft", spacecraft, Spacecraft, "a thermojitter.Spacecraft")
    checks.instance("orbit", orbit, Orbit, "a thermojitter.Orbit")
    t0, t1 = time_span(t_span)
    torque = checks.finite("disturbance", disturbance)
    rate = checks.finite("bus_rate", bus_rate)
    limit = None if budget is None else checks.positive("budget", budget)
    used, run = run_settings(solver, (t0, t1), t_eval, dt_out)
    run["y0"] = start_state(y0, 2 + 4 * len(spacecraft.appendages))
    parts = spacecraft.appendages
    pd = spacecraft.controller
    raw = interruptible(
        _core.simulate_spacecraft,
        spacecraft.bus_inertia,
        [a.panel.as_dict() for a in parts],
        [a.offset for a in parts],
        [float(a.sense) for a in parts],
        None if pd is None else (pd.bandwidth, pd.damping),
        orbit.as_dict(),
        run,
        disturbance=torque,
        bus_rate=rate,
    )
    gains = raw["gains"]
    return SpacecraftSolution(
        **run_record(raw, used),
        **{name: raw[name] for name in _COLUMNS},
        gains=None if gains is None else (float(gains[0]), float(gains[1])),
        inertia_at_rest=float(raw["inertia_at_rest"]),
        crossings=_crossings(orbit, t0, t1),
        y_end=raw["y_end"],
        settings={"disturbance": torque, "bus_rate": rate, "solver": dict(raw["solver"])},
        budget=limit,
    )
