"""Pure NumPy/SciPy reference implementation of the thermo-mechanical jitter model.

This module is the test oracle: it restates the equations of ``MODEL.md`` (Parisse &
Angeletti 2024, eqs. 1, 2, 20, 28) independently of the Rust engine. All quantities are SI;
angles are in radians. Inputs are duck-typed: ``panel`` carries the Table 1 attributes,
``orbit`` carries ``radius``, ``earth_radius`` and ``period``.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from itertools import pairwise
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray
from scipy.integrate import solve_ivp
from scipy.optimize import fsolve

STEFAN_BOLTZMANN = 5.670374419e-8  # W/(m^2 K^4)

FloatArray = NDArray[np.float64]
StateFun = Callable[[float, FloatArray, float], FloatArray]


# --------------------------------------------------------------------------- orbit / shadow


def _check_orbit(orbit: Any) -> None:
    """The oracle knows only the paper's orbit: cylindrical shadow, Sun fixed at 1 au."""
    if (
        getattr(orbit, "shadow", "cylindrical") != "cylindrical"
        or getattr(orbit, "season", False)
        or getattr(orbit, "eccentric_sun", False)
    ):
        raise NotImplementedError("reference: only the cylindrical shadow at equinox (1 au)")


def _shadow_half_angle(orbit: Any) -> float:
    """Half-width of the cylindrical-shadow arc in orbit phase [rad]."""
    return math.asin(orbit.earth_radius / orbit.radius)


def shadow_intervals(orbit: Any, t0: float, t1: float) -> list[tuple[float, float]]:
    """Eclipses (t_enter, t_exit) [s] overlapping [t0, t1], clipped to it, in time order."""
    _check_orbit(orbit)
    period = float(orbit.period)
    half = _shadow_half_angle(orbit) * period / (2.0 * math.pi)  # half eclipse duration [s]
    # Eclipse k is centred at (k + 1/2) * period (phase beta = pi).
    k_first = math.floor((t0 + half) / period - 0.5)
    k_last = math.ceil((t1 - half) / period - 0.5)
    intervals = []
    for k in range(k_first, k_last + 1):
        centre = (k + 0.5) * period
        enter, leave = max(centre - half, t0), min(centre + half, t1)
        if enter < leave:
            intervals.append((enter, leave))
    return intervals


def illumination(orbit: Any, t: float) -> float:
    """Illuminated fraction s(t): 0.0 in the cylindrical shadow, 1.0 in sunlight."""
    _check_orbit(orbit)
    beta = (2.0 * math.pi * t / orbit.period) % (2.0 * math.pi)
    return 0.0 if abs(beta - math.pi) < _shadow_half_angle(orbit) else 1.0


# --------------------------------------------------------------------------- inclined orbits
#
# The geometry of a circular orbit of any inclination, written as rotations of vectors (the engine
# works with the orbit's basis vectors and angles). Constants come from the engine, once.


def _rot_x(angle: float) -> FloatArray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def _rot_z(angle: float) -> FloatArray:
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def sun_vector(orbit: Any, t: ArrayLike) -> FloatArray:
    """Unit vectors to the Sun in the equatorial frame, shape (len(t), 3): the ecliptic direction
    of longitude λ (from the March equinox, uniform over the year) turned by the obliquity."""
    from thermojitter.orbit import DAY, EQUINOX_DAY, OBLIQUITY, YEAR_DAYS

    t = np.atleast_1d(np.asarray(t, dtype=float))
    if getattr(orbit, "season", False):
        lon = 2.0 * np.pi * (orbit.epoch_day + t / DAY - EQUINOX_DAY) / YEAR_DAYS
    else:
        lon = np.zeros_like(t)
    ecliptic = np.stack([np.cos(lon), np.sin(lon), np.zeros_like(lon)], axis=1)
    return np.asarray(ecliptic @ _rot_x(OBLIQUITY).T)


def node_rate(orbit: Any) -> float:
    """J2 drift of the ascending node, rad/s (0 without ``j2``)."""
    from thermojitter.orbit import EARTH_RADIUS, J2

    if not getattr(orbit, "j2", False):
        return 0.0
    n = 2.0 * math.pi / orbit.period
    return -1.5 * J2 * (EARTH_RADIUS / orbit.radius) ** 2 * n * math.cos(orbit.inclination)


def _plane(orbit: Any, t: float) -> FloatArray:
    """Rotation from the orbit frame (x: ascending node, z: orbit normal) to the equatorial."""
    node = orbit.raan + node_rate(orbit) * t
    return np.asarray(_rot_z(node) @ _rot_x(orbit.inclination))


def orbit_normals(orbit: Any, t: ArrayLike) -> FloatArray:
    """Unit normals of the orbit plane, shape (len(t), 3)."""
    t = np.atleast_1d(np.asarray(t, dtype=float))
    return np.array([_plane(orbit, x)[:, 2] for x in t])


def beta(orbit: Any, t: ArrayLike) -> FloatArray:
    """The Sun's angle to the orbit plane, rad (positive on the side of the normal)."""
    dots = np.einsum("ij,ij->i", sun_vector(orbit, t), orbit_normals(orbit, t))
    return np.asarray(np.arcsin(np.clip(dots, -1.0, 1.0)))


def satellite_vector(orbit: Any, t: ArrayLike) -> FloatArray:
    """Unit vectors to the satellite, shape (len(t), 3): argument of latitude u0 + n t, u0 putting
    it ``phase0`` past the orbit's point nearest the Sun (the Sun seen in the orbit frame) at 0."""
    t = np.atleast_1d(np.asarray(t, dtype=float))
    in_orbit = _plane(orbit, 0.0).T @ sun_vector(orbit, 0.0)[0]
    u0 = math.atan2(in_orbit[1], in_orbit[0]) + orbit.phase0
    u = u0 + 2.0 * np.pi * t / orbit.period
    return np.array(
        [_plane(orbit, x) @ [math.cos(a), math.sin(a), 0.0] for x, a in zip(t, u, strict=True)]
    )


def cylinder_sunlit(orbit: Any, t: ArrayLike) -> NDArray[np.bool_]:
    """Outside the cylindrical shadow: on the Sun's side of the Earth, or farther from the shadow's
    axis than the Earth's radius."""
    sat = orbit.radius * satellite_vector(orbit, t)
    sun = sun_vector(orbit, t)
    along = np.einsum("ij,ij->i", sat, sun)
    off_axis = np.linalg.norm(sat - along[:, None] * sun, axis=1)
    return np.asarray((along > 0.0) | (off_axis >= orbit.earth_radius))


# --------------------------------------------------------------------------- Earth heating
#
# The loads of an attitude and of the Earth, in the angles of the Earth's disk seen from the panel
# (the engine writes the view factor in H = r/R_E and the attitude through its basis vectors).


def earth_view_factor(lam: ArrayLike, height_ratio: float) -> FloatArray:
    """View factor of a flat face to the Earth, λ the angle of its normal to the Earth's centre
    (rad), ``height_ratio`` = r/R_E. With ρ = asin(R_E/r) the Earth's angular radius: cos λ sin²ρ
    while the whole disk is in front of the face (λ <= π/2 − ρ), 0 once all of it is behind
    (λ >= π/2 + ρ), and in between
    1/2 − asin(cos ρ / sin λ)/π + [sin²ρ cos λ acos(−cot ρ cot λ) − cos ρ sqrt(sin²ρ − cos²λ)]/π."""
    lam = np.atleast_1d(np.asarray(lam, dtype=float))
    rho = math.asin(1.0 / height_ratio)
    out = np.zeros_like(lam)
    full = lam <= 0.5 * math.pi - rho
    out[full] = np.cos(lam[full]) * math.sin(rho) ** 2
    part = (~full) & (lam < 0.5 * math.pi + rho)
    lp = lam[part]
    cl, sl = np.cos(lp), np.sin(lp)
    cot_rho = math.cos(rho) / math.sin(rho)
    first = 0.5 - np.arcsin(np.clip(math.cos(rho) / sl, -1.0, 1.0)) / math.pi
    wedge = math.sin(rho) ** 2 * cl * np.arccos(np.clip(-cot_rho * cl / sl, -1.0, 1.0))
    root = math.cos(rho) * np.sqrt(np.maximum(math.sin(rho) ** 2 - cl**2, 0.0))
    out[part] = np.maximum(first + (wedge - root) / math.pi, 0.0)
    return out


def sun_distance_scale(orbit: Any, t: ArrayLike) -> FloatArray:
    """The solar flux over its value at 1 au, 1/r² (1 without ``eccentric_sun``)."""
    from thermojitter.orbit import DAY, PERIHELION_DAY, YEAR_DAYS

    t = np.atleast_1d(np.asarray(t, dtype=float))
    if not getattr(orbit, "eccentric_sun", False):
        return np.ones_like(t)
    anomaly = 2.0 * np.pi * (orbit.epoch_day + t / DAY - PERIHELION_DAY) / YEAR_DAYS
    return np.asarray(1.0 / (1.0 - 0.0167 * np.cos(anomaly)) ** 2)


def front_normals(orbit: Any, attitude: Any, t: ArrayLike) -> FloatArray:
    """The front face's unit normal, shape (len(t), 3), for an inclined orbit: ``attitude.kind``
    "sun_pointing" (on the Sun), "nadir" (on the Earth's centre), "inertial" (``attitude.normal``)
    or "sun_tracking" (in the plane of the orbit normal h and the Sun, ``attitude.offset`` from the
    orbit plane: the Sun's angle to it is β − offset)."""
    t = np.atleast_1d(np.asarray(t, dtype=float))
    kind = getattr(attitude, "kind", "sun_pointing")
    sun = sun_vector(orbit, t)
    if kind == "sun_pointing":
        return sun
    if kind == "nadir":
        return -satellite_vector(orbit, t)
    if kind == "inertial":
        n = np.asarray(attitude.normal, dtype=float)
        return np.tile(n / np.linalg.norm(n), (len(t), 1))
    if kind == "sun_tracking":
        h = orbit_normals(orbit, t)
        b = beta(orbit, t)
        in_plane = (sun - np.sin(b)[:, None] * h) / np.cos(b)[:, None]
        return np.asarray(math.cos(attitude.offset) * in_plane + math.sin(attitude.offset) * h)
    raise ValueError(f"unknown attitude {kind!r}")


def face_fluxes(
    orbit: Any, attitude: Any, t: ArrayLike, s: ArrayLike, solar_constant: float
) -> dict[str, FloatArray]:
    """Incident fluxes on each face, W/m², by source (``sun_``, ``albedo_``, ``ir_`` +
    ``front``/``back``), for the illuminated fraction ``s`` of the Sun: sunlight on the face the
    Sun is in front of, Earth infrared ``orbit.earth_ir`` times the view factor, and albedo
    ``orbit.albedo`` times the sunlight at the sub-satellite point times the view factor."""
    t = np.atleast_1d(np.asarray(t, dtype=float))
    n = front_normals(orbit, attitude, t)
    sun, sat = sun_vector(orbit, t), satellite_vector(orbit, t)
    sunlight = solar_constant * sun_distance_scale(orbit, t)
    incidence = np.einsum("ij,ij->i", n, sun)
    if getattr(attitude, "kind", "sun_pointing") == "sun_pointing":
        incidence = np.ones_like(t)
    direct = sunlight * np.asarray(s, dtype=float)
    # The angle of each face's normal to the direction of the Earth's centre, −sat.
    to_earth = np.arccos(np.clip(-np.einsum("ij,ij->i", n, sat), -1.0, 1.0))
    ratio = orbit.radius / orbit.earth_radius
    view_front = earth_view_factor(to_earth, ratio)
    view_back = earth_view_factor(np.pi - to_earth, ratio)
    zenith = np.maximum(np.einsum("ij,ij->i", sat, sun), 0.0)
    reflected = orbit.albedo * sunlight * zenith
    return {
        "sun_front": direct * np.maximum(incidence, 0.0),
        "sun_back": direct * np.maximum(-incidence, 0.0),
        "albedo_front": reflected * view_front,
        "albedo_back": reflected * view_back,
        "ir_front": orbit.earth_ir * view_front,
        "ir_back": orbit.earth_ir * view_back,
    }


def absorbed_loads(
    panel: Any, orbit: Any, attitude: Any, t: float, s: float
) -> tuple[float, float]:
    """(front, back) absorbed W/m² at time t, before the structure's area factor: sunlight and
    albedo with each face's solar absorptivity, Earth infrared with its emissivity."""
    f = {
        k: float(v[0])
        for k, v in face_fluxes(orbit, attitude, [t], [s], panel.solar_constant).items()
    }
    back_alpha = getattr(panel, "absorptivity_back", panel.absorptivity)
    front = panel.absorptivity * (f["sun_front"] + f["albedo_front"])
    front += panel.emissivity_front * f["ir_front"]
    back = back_alpha * (f["sun_back"] + f["albedo_back"]) + panel.emissivity_back * f["ir_back"]
    return front, back


def rhs_loaded(
    y: Sequence[float] | FloatArray,
    panel: Any,
    loads: tuple[float, float],
    model: str = "nonlinear",
    coupled: bool = True,
) -> FloatArray:
    """Eq. 2 with absorbed loads (front, back) W/m² on the two faces, both scaled by cos θ (the
    two halves' mean projected area), on the hinge: y = [T_f, T_b, θ, θ̇]."""
    T_f, T_b, theta, theta_dot = (float(v) for v in y)
    area = math.cos(theta) if coupled else 1.0
    half_cap = 0.5 * panel.mass_per_length * panel.specific_heat
    conduction = panel.conductance * (T_f - T_b)
    q_f = area * loads[0] - conduction - STEFAN_BOLTZMANN * panel.emissivity_front * T_f**4
    q_b = area * loads[1] + conduction - STEFAN_BOLTZMANN * panel.emissivity_back * T_b**4
    moment = float(thermal_moment(panel, T_f, T_b))
    accel = _hinge_accel(panel, theta, theta_dot, moment, model)
    return np.array([q_f / half_cap, q_b / half_cap, theta_dot, accel])


def steady_state_loaded(
    panel: Any, loads: tuple[float, float], coupled: bool = True
) -> tuple[float, float, float]:
    """The equilibrium (T_f, T_b, θ) under constant absorbed loads (front, back), W/m²."""
    total = loads[0] + loads[1]
    eps = panel.emissivity_front + panel.emissivity_back
    T0 = (total / (STEFAN_BOLTZMANN * eps)) ** 0.25

    def residual(x: FloatArray) -> FloatArray:
        rates = rhs_loaded((x[0], x[1], x[2], 0.0), panel, loads, "linear", coupled)
        half_cap = 0.5 * panel.mass_per_length * panel.specific_heat
        static = float(thermal_moment(panel, x[0], x[1])) - panel.hinge_stiffness * x[2]
        return np.array([rates[0] * half_cap, rates[1] * half_cap, static])

    sol, _, ier, msg = fsolve(residual, [T0, T0, 0.0], xtol=1e-14, full_output=True)
    if ier != 1 and np.max(np.abs(residual(sol))) > 1e-8:
        raise RuntimeError(f"steady_state_loaded did not converge: {msg}")
    return float(sol[0]), float(sol[1]), float(sol[2])


def _simulate_loaded(
    panel: Any, orbit: Any, attitude: Any, t_span: tuple[float, float], options: dict[str, Any]
) -> ReferenceSolution:
    """:func:`simulate` under the attitude's and the Earth's loads, in permanent sunlight (the
    orbit's shadow is not modelled here: an orbit with ``shadow="none"``). Default start: the
    equilibrium under the loads at t_span[0]."""
    if getattr(orbit, "shadow", "none") != "none":
        raise NotImplementedError("reference: Earth heating in permanent sunlight only")
    model, coupled = options["model"], options["coupled"]
    y0 = options["y0"]
    if y0 is None:
        start = absorbed_loads(panel, orbit, attitude, t_span[0], 1.0)
        y0 = (*steady_state_loaded(panel, start, coupled), 0.0)

    def fun(t: float, y: FloatArray, s: float) -> FloatArray:
        return rhs_loaded(y, panel, absorbed_loads(panel, orbit, attitude, t, s), model, coupled)

    names = ("T_front", "T_back", "theta", "theta_dot")
    return _integrate_segments(
        fun, y0, t_span, None, options["rtol"], options["atol"], options["t_eval"],
        options["method"], names, options["max_step"],
    )  # fmt: skip


# ------------------------------------------------------------- N nodes through the thickness


def node_model(panel: Any, nodes: int) -> tuple[FloatArray, float, FloatArray]:
    """A plain panel's one homogeneous layer on ``nodes`` equally spaced nodes, front (ξ = 0) to
    back (ξ = 1), the temperature linear between them: (heat capacity lumped at each node,
    J/(m² K): the node's share of the layer, half a spacing at the faces; conductance of each
    spacing, W/(m² K), the panel's K over the spacing's fraction of the thickness; thermal moment
    per kelvin at each node, N m/K: M_T = χ a E b ∫ z T dz with z = d (1/2 − ξ) from the middle
    plane, b = 12 I/d³, integrated exactly over the node's hat function)."""
    if nodes < 2:
        raise ValueError("nodes must be >= 2")
    h = 1.0 / (nodes - 1)
    heat_capacity = panel.mass_per_length * panel.specific_heat
    capacity = np.full(nodes, heat_capacity * h)
    capacity[[0, -1]] *= 0.5
    xi = np.linspace(0.0, 1.0, nodes)
    # ∫ φ_i(ξ) (1/2 − ξ) dξ over the hat of node i: the interior's two halves, the faces' one.
    weight = h * (0.5 - xi)
    weight[0] = h / 4.0 - h * h / 6.0
    weight[-1] = -weight[0]
    chi = getattr(panel, "moment_scale", 1.0)
    # χ a E b d² ∫ ... dξ with b d³ = 12 I.
    gain = chi * panel.expansion_coeff * panel.youngs_modulus * 12.0 * panel.bending_inertia
    return capacity, panel.conductance / h, gain / panel.thickness * weight


def rhs_nodes_loaded(
    y: Sequence[float] | FloatArray,
    panel: Any,
    nodes: int,
    loads: tuple[float, float],
    model: str = "nonlinear",
    coupled: bool = True,
) -> FloatArray:
    """The N-node plate with absorbed loads (front, back) W/m² on its face nodes, both scaled by
    cos θ, on the hinge: y = [T_0 … T_{N−1}, θ, θ̇]."""
    y = np.asarray(y, dtype=float)
    temps, theta, theta_dot = y[:nodes], float(y[nodes]), float(y[nodes + 1])
    capacity, conductance, weight = node_model(panel, nodes)
    area = math.cos(theta) if coupled else 1.0
    flow = np.zeros(nodes)
    through = conductance * np.diff(temps)  # into node i from node i + 1
    flow[:-1] += through
    flow[1:] -= through
    flow[0] += area * loads[0] - STEFAN_BOLTZMANN * panel.emissivity_front * temps[0] ** 4
    flow[-1] += area * loads[1] - STEFAN_BOLTZMANN * panel.emissivity_back * temps[-1] ** 4
    moment = float(weight @ temps)
    accel = _hinge_accel(panel, theta, theta_dot, moment, model)
    return np.concatenate([flow / capacity, [theta_dot, accel]])


def steady_state_nodes_loaded(
    panel: Any, nodes: int, loads: tuple[float, float], coupled: bool = True
) -> FloatArray:
    """The N-node plate's equilibrium (T_0 … T_{N−1}, θ) under constant loads (front, back)."""
    capacity, _, weight = node_model(panel, nodes)
    two = steady_state_loaded(panel, loads, coupled)
    # From the two-node balance's faces, linear between them.
    x0 = np.concatenate([np.linspace(two[0], two[1], nodes), [two[2]]])

    def residual(x: FloatArray) -> FloatArray:
        rates = rhs_nodes_loaded(np.append(x, 0.0), panel, nodes, loads, "linear", coupled)
        static = float(weight @ x[:nodes]) - panel.hinge_stiffness * x[nodes]
        return np.append(rates[:nodes] * capacity, static)

    sol, _, ier, msg = fsolve(residual, x0, xtol=1e-14, full_output=True)
    if ier != 1 and np.max(np.abs(residual(sol))) > 1e-8:
        raise RuntimeError(f"steady_state_nodes_loaded did not converge: {msg}")
    return np.asarray(sol, dtype=float)


def simulate_nodes(
    panel: Any,
    orbit: Any,
    t_span: tuple[float, float],
    *,
    nodes: int,
    attitude: Any = None,
    model: str = "nonlinear",
    coupled: bool = True,
    rtol: float = 1e-10,
    atol: float = 1e-12,
    t_eval: ArrayLike | None = None,
    max_step: float = np.inf,
) -> ReferenceSolution:
    """The N-node plate on the hinge under every load of the orbit and attitude
    (:func:`absorbed_loads`), in permanent sunlight (an orbit with ``shadow="none"``), from the
    equilibrium under the loads at t_span[0]; rows T_0 … T_{N−1}, θ, θ̇."""
    if getattr(orbit, "shadow", "none") != "none":
        raise NotImplementedError("reference: the N-node plate in permanent sunlight only")
    start = absorbed_loads(panel, orbit, attitude, t_span[0], 1.0)
    y0 = np.append(steady_state_nodes_loaded(panel, nodes, start, coupled), 0.0)

    def fun(t: float, y: FloatArray, s: float) -> FloatArray:
        loads = absorbed_loads(panel, orbit, attitude, t, s)
        return rhs_nodes_loaded(y, panel, nodes, loads, model, coupled)

    names = (*(f"T_{i}" for i in range(nodes)), "theta", "theta_dot")
    return _integrate_segments(fun, y0, t_span, None, rtol, atol, t_eval, "RK45", names, max_step)


# --------------------------------------------------------------------------- model equations


def _arm(panel: Any) -> float:
    """Half-length of one rigid half, l = L/4 [m]."""
    return panel.length / 4.0


def hinge_inertia(panel: Any) -> float:
    """Linearised hinge inertia I_B = 2 m l^3 / 3 [kg m^2] (per unit width)."""
    return 2.0 * panel.mass_per_length * _arm(panel) ** 3 / 3.0


def thermal_moment(panel: Any, T_front: ArrayLike, T_back: ArrayLike) -> Any:
    """Thermal bending moment M_T = chi a E I (T_f - T_b) / d [N m]; works on arrays."""
    chi = getattr(panel, "moment_scale", 1.0)
    gain = chi * panel.expansion_coeff * panel.youngs_modulus * panel.bending_inertia
    return gain * (np.asarray(T_front) - np.asarray(T_back)) / panel.thickness


def rhs_one_node(t: float, y: Sequence[float] | FloatArray, panel: Any, s: float) -> FloatArray:
    """Eq. 1: dT/dt [K/s] of the isothermal plate, y = [T]."""
    (T,) = y
    eps = panel.emissivity_front + panel.emissivity_back
    net = panel.absorptivity * panel.solar_constant * s - STEFAN_BOLTZMANN * eps * T**4
    return np.array([net / (panel.mass_per_length * panel.specific_heat)])


def rhs_two_layer(
    t: float, y: Sequence[float] | FloatArray, panel: Any, s: float, cos_theta: float = 1.0
) -> FloatArray:
    """Eq. 2: [dT_f/dt, dT_b/dt] [K/s], each layer holding half the heat capacity."""
    T_f, T_b = y[0], y[1]
    half_cap = 0.5 * panel.mass_per_length * panel.specific_heat
    conduction = panel.conductance * (T_f - T_b)
    absorbed = panel.absorptivity * panel.solar_constant * s * cos_theta
    q_f = absorbed - conduction - STEFAN_BOLTZMANN * panel.emissivity_front * T_f**4
    q_b = conduction - STEFAN_BOLTZMANN * panel.emissivity_back * T_b**4
    return np.array([q_f / half_cap, q_b / half_cap])


def _hinge_accel(panel: Any, theta: float, theta_dot: float, moment: float, model: str) -> float:
    """Hinge angular acceleration [rad/s^2]: eq. 20 ("nonlinear") or eq. 28 ("linear")."""
    if model == "linear":
        torque = moment - panel.damping * theta_dot - panel.hinge_stiffness * theta
        return torque / hinge_inertia(panel)
    if model == "nonlinear":
        ml3 = panel.mass_per_length * _arm(panel) ** 3
        sin_t, cos_t = math.sin(theta), math.cos(theta)
        torque = moment - panel.damping * theta_dot - panel.hinge_stiffness * theta
        num = 1.5 * torque / ml3 - 3.0 * theta_dot**2 * sin_t * cos_t
        return num / (1.0 + 3.0 * sin_t**2)
    raise ValueError(f"unknown hinge model {model!r} (use 'nonlinear' or 'linear')")


def rhs_coupled(
    t: float,
    y: Sequence[float] | FloatArray,
    panel: Any,
    s: float,
    model: str = "nonlinear",
    coupled: bool = True,
) -> FloatArray:
    """Derivative of y = [T_f, T_b, theta, theta_dot] [K/s, K/s, rad/s, rad/s^2]."""
    T_f, T_b, theta, theta_dot = (float(v) for v in y)
    # coupled=False freezes the projected area (cos theta -> 1), paper Fig. 18.
    cos_theta = math.cos(theta) if coupled else 1.0
    dT_f, dT_b = rhs_two_layer(t, (T_f, T_b), panel, s, cos_theta)
    moment = float(thermal_moment(panel, T_f, T_b))
    accel = _hinge_accel(panel, theta, theta_dot, moment, model)
    return np.array([dT_f, dT_b, theta_dot, accel])


def hinge_energy(
    panel: Any, theta: ArrayLike, theta_dot: ArrayLike, moment: float, model: str = "nonlinear"
) -> Any:
    """Hinge energy [J] (kinetic + spring - work of constant M), conserved if c_d = 0."""
    th, thd = np.asarray(theta), np.asarray(theta_dot)
    if model == "nonlinear":
        ml3 = panel.mass_per_length * _arm(panel) ** 3
        kinetic = ml3 / 3.0 * thd**2 * (1.0 + 3.0 * np.sin(th) ** 2)
    elif model == "linear":
        kinetic = 0.5 * hinge_inertia(panel) * thd**2
    else:
        raise ValueError(f"unknown hinge model {model!r} (use 'nonlinear' or 'linear')")
    return kinetic + 0.5 * panel.hinge_stiffness * th**2 - moment * th


# --------------------------------------------------------------------------- equilibria


def one_node_equilibrium(panel: Any, s: float = 1.0) -> float:
    """Equilibrium temperature [K] of eq. 1 under illumination s."""
    eps = panel.emissivity_front + panel.emissivity_back
    return (panel.absorptivity * panel.solar_constant * s / (STEFAN_BOLTZMANN * eps)) ** 0.25


def steady_state(panel: Any, coupled: bool = True) -> tuple[float, float, float]:
    """Sunlit equilibrium (T_f [K], T_b [K], theta [rad]) with theta_dot = 0, s = 1."""
    T0 = one_node_equilibrium(panel)
    # Initial split: the back face re-radiates what conducts through, K dT = sigma eps_b T^4.
    split = STEFAN_BOLTZMANN * panel.emissivity_back * T0**4 / panel.conductance
    T_f0, T_b0 = T0 + 0.5 * split, T0 - 0.5 * split
    theta0 = float(thermal_moment(panel, T_f0, T_b0)) / panel.hinge_stiffness
    half_cap = 0.5 * panel.mass_per_length * panel.specific_heat

    def residual(x: FloatArray) -> FloatArray:
        # Heat balances in W/m^2, hinge balance in N m (static for both models).
        cos_theta = math.cos(x[2]) if coupled else 1.0
        dT = rhs_two_layer(0.0, x[:2], panel, 1.0, cos_theta)
        static = float(thermal_moment(panel, x[0], x[1])) - panel.hinge_stiffness * x[2]
        return np.array([dT[0] * half_cap, dT[1] * half_cap, static])

    x0 = [T_f0, T_b0, theta0]
    sol, _, ier, msg = fsolve(residual, x0, xtol=1e-14, full_output=True)
    if ier != 1 and np.max(np.abs(residual(sol))) > 1e-8:
        raise RuntimeError(f"steady_state did not converge: {msg}")
    return float(sol[0]), float(sol[1]), float(sol[2])


# --------------------------------------------------------------------------- integration


@dataclass
class ReferenceSolution:
    """Time history: t [s] (n,), y (k, n) whose rows are named by ``names``."""

    t: FloatArray
    y: FloatArray
    nfev: int
    n_steps: int  # accepted steps; -1 when t_eval was given (not observable then)
    names: tuple[str, ...] = ("T_front", "T_back", "theta", "theta_dot")

    def _row(self, name: str) -> FloatArray:
        if name in self.names:
            return self.y[self.names.index(name)]
        if name in ("T_front", "T_back") and "T" in self.names:
            return self.y[self.names.index("T")]  # isothermal plate: both faces at T
        raise AttributeError(f"solution has no component {name!r} (has {self.names})")

    @property
    def T_front(self) -> FloatArray:
        """Front-face temperature [K]."""
        return self._row("T_front")

    @property
    def T_back(self) -> FloatArray:
        """Back-face temperature [K]."""
        return self._row("T_back")

    @property
    def theta(self) -> FloatArray:
        """Hinge angle [rad]."""
        return self._row("theta")

    @property
    def theta_dot(self) -> FloatArray:
        """Hinge angular rate [rad/s]."""
        return self._row("theta_dot")


def _integrate_segments(
    fun: StateFun,
    y0: ArrayLike,
    t_span: tuple[float, float],
    orbit: Any | None,
    rtol: float,
    atol: float,
    t_eval: ArrayLike | None,
    method: str,
    names: tuple[str, ...],
    max_step: float = np.inf,
) -> ReferenceSolution:
    """Integrate fun(t, y, s) with one solve_ivp call per shadow-free segment."""
    t0, t1 = float(t_span[0]), float(t_span[1])
    if not t1 > t0:
        raise ValueError("t_span must satisfy t_span[0] < t_span[1]")
    cuts = [t0, t1]
    if orbit is not None:
        for enter, leave in shadow_intervals(orbit, t0, t1):
            cuts += [enter, leave]
    edges = sorted({c for c in cuts if t0 <= c <= t1})

    requested = None
    if t_eval is not None:
        requested = np.asarray(t_eval, dtype=float)
        if requested.size and (requested[0] < t0 or requested[-1] > t1):
            raise ValueError("t_eval must lie inside t_span")
        if np.any(np.diff(requested) < 0):
            raise ValueError("t_eval must be sorted")

    y = np.asarray(y0, dtype=float)
    ts, ys = [], []
    nfev, n_steps = 0, 0
    for i, (a, b) in enumerate(pairwise(edges)):
        s = illumination(orbit, 0.5 * (a + b)) if orbit is not None else 1.0
        seg_eval = None
        if requested is not None:
            # A boundary time belongs to the segment ending there (t_span[0] to the first).
            lo = 0 if i == 0 else np.searchsorted(requested, a, side="right")
            hi = np.searchsorted(requested, b, side="right")
            mine = requested[lo:hi]
            # solve_ivp needs strictly increasing times; b is always included because its
            # state starts the next segment.
            seg_eval = np.union1d(mine, [b])
        sol = solve_ivp(
            fun,
            (a, b),
            y,
            method=method,
            t_eval=seg_eval,
            args=(s,),
            rtol=rtol,
            atol=atol,
            max_step=max_step,
        )
        if not sol.success:
            raise RuntimeError(f"solve_ivp failed on [{a}, {b}]: {sol.message}")
        nfev += int(sol.nfev)
        y = sol.y[:, -1]
        if requested is None:
            n_steps += len(sol.t) - 1
            skip = 0 if i == 0 else 1  # the boundary point is already stored
            ts.append(sol.t[skip:])
            ys.append(sol.y[:, skip:])
        else:
            ts.append(mine)
            assert seg_eval is not None
            ys.append(sol.y[:, np.searchsorted(seg_eval, mine)])
    return ReferenceSolution(
        t=np.concatenate(ts),
        y=np.concatenate(ys, axis=1),
        nfev=nfev,
        n_steps=n_steps if requested is None else -1,
        names=names,
    )


def simulate(
    panel: Any,
    orbit: Any,
    t_span: tuple[float, float],
    *,
    model: str = "nonlinear",
    coupled: bool = True,
    rtol: float = 1e-10,
    atol: float = 1e-12,
    t_eval: ArrayLike | None = None,
    y0: ArrayLike | None = None,
    method: str = "RK45",
    max_step: float = np.inf,
    attitude: Any = None,
) -> ReferenceSolution:
    """Coupled thermo-mechanical run, y = [T_f, T_b, theta, theta_dot], split at eclipses.

    ``max_step`` (s) caps solve_ivp's step; near an equilibrium its steps can otherwise span
    several hinge periods, and its interpolant between them does not resolve the oscillation.

    With an ``attitude`` (``kind``, ``offset``, ``normal``) or an orbit heated by the Earth
    (``albedo``, ``earth_ir``), each face takes its loads (:func:`absorbed_loads`), in permanent
    sunlight only.
    """
    earth = float(getattr(orbit, "albedo", 0.0)) + float(getattr(orbit, "earth_ir", 0.0))
    if attitude is not None or earth > 0.0:
        options = {
            "model": model, "coupled": coupled, "rtol": rtol, "atol": atol, "t_eval": t_eval,
            "y0": y0, "method": method, "max_step": max_step,
        }  # fmt: skip
        return _simulate_loaded(panel, orbit, attitude, t_span, options)
    if y0 is None:
        y0 = (*steady_state(panel, coupled), 0.0)

    def fun(t: float, y: FloatArray, s: float) -> FloatArray:
        return rhs_coupled(t, y, panel, s, model, coupled)

    names = ("T_front", "T_back", "theta", "theta_dot")
    return _integrate_segments(fun, y0, t_span, orbit, rtol, atol, t_eval, method, names, max_step)


def simulate_thermal(
    panel: Any,
    orbit: Any,
    t_span: tuple[float, float],
    *,
    layers: int = 2,
    rtol: float = 1e-10,
    atol: float = 1e-12,
    t_eval: ArrayLike | None = None,
    y0: ArrayLike | None = None,
    method: str = "RK45",
) -> ReferenceSolution:
    """Thermal model alone: layers=1 is eq. 1 (y = [T]), layers=2 is eq. 2 with cos theta = 1."""
    if layers == 1:
        y0 = (one_node_equilibrium(panel),) if y0 is None else y0

        def fun(t: float, y: FloatArray, s: float) -> FloatArray:
            return rhs_one_node(t, y, panel, s)

        names: tuple[str, ...] = ("T",)
    elif layers == 2:
        y0 = steady_state(panel, coupled=False)[:2] if y0 is None else y0

        def fun(t: float, y: FloatArray, s: float) -> FloatArray:
            return rhs_two_layer(t, y, panel, s, 1.0)

        names = ("T_front", "T_back")
    else:
        raise ValueError("layers must be 1 or 2")
    return _integrate_segments(fun, y0, t_span, orbit, rtol, atol, t_eval, method, names)


def simulate_hinge(
    panel: Any,
    moment: float,
    t_span: tuple[float, float],
    *,
    y0: ArrayLike = (0.0, 0.0),
    model: str = "nonlinear",
    rtol: float = 1e-10,
    atol: float = 1e-12,
    t_eval: ArrayLike | None = None,
    method: str = "RK45",
) -> ReferenceSolution:
    """Hinge alone, y = [theta, theta_dot], driven by a constant moment [N m]."""

    def fun(t: float, y: FloatArray, s: float) -> FloatArray:
        return np.array([y[1], _hinge_accel(panel, float(y[0]), float(y[1]), moment, model)])

    names = ("theta", "theta_dot")
    return _integrate_segments(fun, y0, t_span, None, rtol, atol, t_eval, method, names)


# --------------------------------------------------------------------------- thin-walled tube


def tube_cantilever_beta(mu: float) -> float:
    """First root β of 1 + cos β cosh β + μ β (cos β sinh β − sin β cosh β) = 0: the clamped
    beam with a point tip mass μ m L (moment-free tip, shear balanced by the mass's inertia)."""
    from scipy.optimize import brentq

    def f(b: float) -> float:
        return (
            1
            + math.cos(b) * math.cosh(b)
            + mu * b * (math.cos(b) * math.sinh(b) - math.sin(b) * math.cosh(b))
        )

    return float(brentq(f, 1e-4, 1.8751040687119611 + 1e-9, xtol=1e-15, rtol=1e-15))


def tube_hinge(boom: Any) -> dict[str, float]:
    """The cantilever's first mode as a hinge of angle θ = w(L)/L: I_B = L² (m ∫φ² + M_t) with
    φ(L) = 1, K = ω₁² I_B, χ = K L/(2 E I) (static θ = the uniform curvature's tip deflection
    over L), c = 2 ζ ω₁ I_B."""
    from scipy.integrate import quad

    r, h, L = boom.radius, boom.wall, boom.length
    m = boom.density * 2 * math.pi * r * h
    ei = boom.youngs_modulus * math.pi * r**3 * h
    b = tube_cantilever_beta(boom.tip_mass / (m * L))
    sigma = (math.cosh(b) + math.cos(b)) / (math.sinh(b) + math.sin(b))

    def phi(x: float) -> float:
        return math.cosh(b * x) - math.cos(b * x) - sigma * (math.sinh(b * x) - math.sin(b * x))

    integral = quad(lambda x: phi(x) ** 2, 0.0, 1.0, epsabs=0, epsrel=1e-13)[0] / phi(1.0) ** 2
    inertia = L**2 * (m * L * integral + boom.tip_mass)
    omega = b**2 * math.sqrt(ei / (m * L**4))
    stiffness = omega**2 * inertia
    return {
        "inertia": inertia,
        "stiffness": stiffness,
        "omega": omega,
        "damping": 2 * boom.damping * omega * inertia,
        "chi": boom.moment_scale * stiffness * L / (2 * ei),
    }


def tube_coefficients(boom: Any) -> dict[str, float]:
    """The thin-walled tube's heat balance per unit area of wall (see ``tube_rhs``)."""
    psi = boom.solar_inclination
    q = boom.absorptivity * boom.solar_constant * math.sin(psi)
    mean_t = (q / (math.pi * boom.emissivity * STEFAN_BOLTZMANN)) ** 0.25
    ei = boom.emissivity_inner
    eps = boom.emissivity + 4 * ei / (4 - ei)
    conduction = boom.conduction_scale * boom.conductivity * boom.wall / boom.radius**2
    return {
        "mean": q / math.pi,
        "harmonic": q / 2,
        "capacity": boom.density * boom.specific_heat * boom.wall,
        "radiation": boom.emissivity * STEFAN_BOLTZMANN,
        "relaxation": conduction + 4 * STEFAN_BOLTZMANN * mean_t**3 * eps,
        "moment": math.pi * boom.youngs_modulus * boom.expansion_coeff * boom.wall * boom.radius**2,
    }


def tube_rhs(
    y: FloatArray,
    boom: Any,
    s: float,
    coupled: bool,
    parts: tuple[dict[str, float], dict[str, float]] | None = None,
) -> FloatArray:
    """(T̄, T_m, θ, θ̇)' of the tube lit on one side under illumination s: the absorbed flux
    α C sin ψ max(cos φ, 0) has mean α C sin ψ/π and first harmonic α C sin ψ/2; incidence
    sin(ψ + θ)/sin ψ; thermal moment χ π E a h r² T_m on the hinge. ``parts``: the
    (``tube_coefficients``, ``tube_hinge``) of ``boom``, computed once by the caller."""
    c, hinge = parts if parts is not None else (tube_coefficients(boom), tube_hinge(boom))
    mean_t, circ, theta, rate = y
    psi = boom.solar_inclination
    f = s * (math.sin(psi + theta) / math.sin(psi) if coupled else 1.0)
    return np.array(
        [
            (c["mean"] * f - c["radiation"] * mean_t**4) / c["capacity"],
            (c["harmonic"] * f - c["relaxation"] * circ) / c["capacity"],
            rate,
            (
                hinge["chi"] * c["moment"] * circ
                - hinge["damping"] * rate
                - hinge["stiffness"] * theta
            )
            / hinge["inertia"],
        ]
    )


def tube_steady_state(boom: Any, coupled: bool = True, s: float = 1.0) -> FloatArray:
    """(T̄, T_m, θ, 0) at rest under illumination s."""
    c, hinge = tube_coefficients(boom), tube_hinge(boom)
    mean_t = (c["mean"] * s / c["radiation"]) ** 0.25
    circ = c["harmonic"] * s / c["relaxation"]
    theta = hinge["chi"] * c["moment"] * circ / hinge["stiffness"]
    guess = np.array([mean_t, circ, theta, 0.0])
    if not coupled:
        return guess
    x = fsolve(lambda z: tube_rhs(z, boom, s, True, (c, hinge)), guess, xtol=1e-12)
    return np.asarray(x, dtype=float)


def simulate_tube(
    boom: Any,
    orbit: Any,
    t_span: tuple[float, float],
    *,
    coupled: bool = True,
    y0: ArrayLike | None = None,
    **options: Any,
) -> ReferenceSolution:
    """The tube's transient, y = [T_mean, T_circ, theta, theta_dot], split at eclipses (from
    the steady state at t_span[0]'s illumination unless ``y0`` is given). ``options``: ``rtol``
    (1e-10), ``atol`` (1e-12), ``t_eval``, ``method`` ("RK45") and ``max_step`` as
    :func:`simulate` takes them."""
    o: dict[str, Any] = {"rtol": 1e-10, "atol": 1e-12, "t_eval": None, "method": "RK45"}
    o["max_step"] = np.inf
    o.update(options)
    parts = (tube_coefficients(boom), tube_hinge(boom))
    start = tube_steady_state(boom, coupled, illumination(orbit, float(t_span[0])))
    return _integrate_segments(
        lambda t, y, s: tube_rhs(y, boom, s, coupled, parts),
        start if y0 is None else y0,
        t_span, orbit, o["rtol"], o["atol"], o["t_eval"], o["method"],
        ("T_mean", "T_circ", "theta", "theta_dot"), o["max_step"],
    )  # fmt: skip
