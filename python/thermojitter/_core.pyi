"""Typed stub of the native engine module (built from rust/src/py by maturin)."""

from typing import Any, TypedDict, final

import numpy as np
from numpy.typing import NDArray
from typing_extensions import NotRequired

_F = NDArray[np.float64]

__all__ = [
    "least_steps",
    "SLOW_ORBIT",
    "SLOW_RING_LIMIT",
    "SLOW_PIECE_ORBITS",
    "leo_orbit",
    "eclipse_duration",
    "SIDEREAL_DAY",
    "PERIHELION_DAY",
    "MU_EARTH",
    "GEO_RADIUS",
    "LEO_ALTITUDE",
    "MAX_LEO_ALTITUDE",
    "MIN_LEO_ALTITUDE",
    "GEO_EQUINOX_ORBIT",
    "EQUINOX_DAY",
    "EARTH_RADIUS",
    "CASE_A_PANEL",
    "CancelToken",
    "ConvergenceError",
    "EnsemblePool",
    "MonteCarloPool",
    "IntegrationError",
    "LAYER_FIELDS",
    "MAX_THREADS",
    "LINEAR_FIELDS",
    "MAX_TIME",
    "MAX_NODES",
    "MAX_SAMPLES",
    "BEAM_MAX_ELEMENTS",
    "PANEL_FIELDS",
    "BOOM_FIELDS",
    "BOOM_RANGES",
    "BOOM_EXAMPLE",
    "boom_derived",
    "boom_steady_state",
    "boom_start_state",
    "simulate_boom",
    "run_boom_orbits",
    "boom_flutter",
    "boom_stability_map",
    "PANEL_RANGES",
    "PAPER_PANEL",
    "ENSEMBLE_LANES",
    "ENSEMBLE_RUNS_PER_CORE",
    "KERNEL_CHOICES",
    "KERNEL_VARIABLE",
    "REFERENCE_TEMPERATURE",
    "SOLVER_DEFAULTS",
    "VALIDITY_LIMIT",
    "ARCSEC_PER_RADIAN",
    "STEFAN_BOLTZMANN",
    "beam_modes",
    "beam_response",
    "beam_static",
    "check_panels",
    "check_orbits",
    "ORBIT_INPUTS",
    "ORBIT_INPUT_RANGES",
    "check_solver",
    "conduction_grid",
    "cpu_info",
    "declination",
    "beta",
    "nodal_rate",
    "J2",
    "EARTH_ALBEDO",
    "EARTH_IR",
    "OBLIQUITY",
    "YEAR_DAYS",
    "DAY",
    "derived",
    "distributed_defaults",
    "distributed_flutter",
    "distributed_start_state",
    "run_distributed_orbits",
    "summary_metrics",
    "distributed_info",
    "eclipses",
    "energy",
    "flutter",
    "flutter_at",
    "flux_scale",
    "hinge_points",
    "hinge_equivalent_damping_ratio",
    "illumination",
    "laminate_properties",
    "linear_delta_t",
    "linear_thermal",
    "layered_flutter",
    "layered_flutter_at",
    "layered_steady_state",
    "materials",
    "moment",
    "orbit_breakpoints",
    "run_orbits",
    "shadow_intervals",
    "simulate",
    "simulate_distributed",
    "simulate_hinge",
    "simulate_spacecraft",
    "simulate_layers",
    "simulate_thermal",
    "stability_map",
    "start_state",
    "steady_state",
    "stiffness",
    "synodic_period",
    "umbra_intervals",
    "validate_laminate",
    "validate_layer",
    "validate_orbit",
    "validate_panel",
]

PANEL_FIELDS: list[str]
PANEL_RANGES: dict[str, tuple[float, float, bool]]  # name: (low, high, low end open); high closed
MAX_NODES: int  # most nodes of the N-node through-thickness model
BEAM_MAX_ELEMENTS: int  # most elements of the free-free beam
MAX_SAMPLES: int  # most samples one run may keep
LINEAR_FIELDS: list[str]
PAPER_PANEL: dict[str, float]
ENSEMBLE_LANES: int  # SIMD lanes of one lockstep group
ENSEMBLE_RUNS_PER_CORE: int  # samples one core runs at once (its groups' lanes)
SLOW_RING_LIMIT: float  # largest ringing (rad) the hybrid carries on slow time
SLOW_ORBIT: float  # orbits shorter than this (s) run on slow time under the hybrid
SLOW_PIECE_ORBITS: int  # a call of twice this many slow-time orbits runs in pieces at once
KERNEL_VARIABLE: str  # environment variable: "portable" forces the kernels without FMA
KERNEL_CHOICES: list[str]  # its values ("auto", "portable")
SOLVER_DEFAULTS: dict[str, Any]
GEO_RADIUS: float
LEO_ALTITUDE: float
MIN_LEO_ALTITUDE: float
MAX_LEO_ALTITUDE: float
EARTH_RADIUS: float
SIDEREAL_DAY: float
MU_EARTH: float
EQUINOX_DAY: float
PERIHELION_DAY: float
J2: float
EARTH_ALBEDO: float
EARTH_IR: float
OBLIQUITY: float
YEAR_DAYS: float
DAY: float
GEO_EQUINOX_ORBIT: dict[str, Any]
CASE_A_PANEL: dict[str, float]
STEFAN_BOLTZMANN: float
MAX_THREADS: int
MAX_TIME: float
VALIDITY_LIMIT: float
ARCSEC_PER_RADIAN: float  # 648000/π

class _Limit(TypedDict):
    """The validity limit a run watches (``thermojitter.simulate.limit_args``)."""

    theta_limit: float
    on_limit: str

class _Run(TypedDict):
    """How one transient is run: every transient run function takes this one mapping (``RunOptions``
    in rust/src/bindings/convert.rs; built by ``thermojitter.simulate.run_settings``)."""

    span: tuple[float, float]
    solver: dict[str, Any]
    t_eval: _F | None
    dt_out: float | None
    y0: NotRequired[list[float] | None]
    limit: NotRequired[_Limit | None]

class _Grid(TypedDict):
    """The N-node model's grid: every function of that model takes this one mapping (``Grid`` in
    rust/src/bindings/convert.rs; built by ``thermojitter.simulate.grid_args``)."""

    layup: dict[str, Any] | None
    nodes: int

class _Orbits(TypedDict):
    """One run over whole orbits: ``run_orbits`` and ``MonteCarloPool.run`` take this one
    mapping (``OrbitsRun`` in rust/src/bindings/convert.rs; built by ``simulate.orbits_args``)."""

    model: str
    coupled: bool
    solver: dict[str, Any]
    n_orbits: int
    window: float
    hybrid: NotRequired[dict[str, float] | None]
    grid: NotRequired[_Grid | None]

class _FlutterPoint(TypedDict):
    """The point a flutter analysis linearises about: both flutter analyses take this one
    mapping (``FlutterPoint`` in rust/src/bindings/convert.rs; built by ``tj.flutter``)."""

    model: str
    coupled: bool
    flux: float

class _OrbitPoint(TypedDict):
    """A flutter analysis on an orbit: at time t, or averaged over the sunlit arc from t."""

    t: float
    model: str
    coupled: bool
    average: bool

class IntegrationError(RuntimeError): ...

@final
class CancelToken:
    def __new__(cls) -> CancelToken: ...
    def cancel(self) -> None: ...
    @property
    def cancelled(self) -> bool: ...

class ConvergenceError(RuntimeError): ...

def check_solver(solver: dict[str, Any]) -> dict[str, Any]: ...
def validate_panel(panel: dict[str, float]) -> None: ...
def validate_orbit(orbit: dict[str, Any]) -> None: ...
def steady_state(
    panel: dict[str, float], coupled: bool = True, flux: float = 1.0
) -> tuple[float, float, float]: ...
def start_state(
    panel: dict[str, float],
    orbit: dict[str, Any],
    t0: float,
    coupled: bool,
    grid: _Grid | None = None,
) -> list[float]: ...
def stiffness(panel: dict[str, float], criterion: str, moment: float = 0.0) -> float: ...
def derived(panel: dict[str, float]) -> dict[str, float]: ...
def shadow_intervals(orbit: dict[str, Any], t0: float, t1: float) -> list[tuple[float, float]]: ...
def illumination(orbit: dict[str, Any], t: _F) -> _F: ...
def moment(panel: dict[str, float], t_front: _F, t_back: _F) -> _F: ...
def energy(panel: dict[str, float], model: str, theta: _F, theta_dot: _F, moment: float) -> _F: ...
def hinge_points(panel: dict[str, float], zeta: float, theta: _F) -> tuple[_F, _F]: ...
def simulate(
    panel: dict[str, float],
    orbit: dict[str, Any],
    run: _Run,
    *,
    model: str,
    coupled: bool,
    layers: int = 2,
    cancel: CancelToken | None = None,
) -> dict[str, Any]: ...
def simulate_thermal(
    panel: dict[str, float],
    orbit: dict[str, Any],
    run: _Run,
    *,
    layers: int,
    cancel: CancelToken | None = None,
) -> dict[str, Any]: ...
def simulate_hinge(
    panel: dict[str, float],
    run: _Run,
    *,
    model: str,
    moment: _F,
    moment_t: _F | None,
    cancel: CancelToken | None = None,
) -> dict[str, Any]: ...

# --- the spacecraft bus --------------------------------------------------------------------------
def simulate_spacecraft(
    bus_inertia: float,
    panels: list[dict[str, float]],
    offsets: list[float],
    senses: list[float],
    controller: tuple[float, float] | None,
    orbit: dict[str, Any],
    run: _Run,
    *,
    disturbance: float = 0.0,
    bus_rate: float = 0.0,
    cancel: CancelToken | None = None,
) -> dict[str, Any]: ...

# --- flutter analysis ---------------------------------------------------------------------------
def flutter(panel: dict[str, float], point: _FlutterPoint) -> dict[str, Any]: ...
def flutter_at(
    panel: dict[str, float], orbit: dict[str, Any], point: _OrbitPoint, with_critical: bool = True
) -> dict[str, Any]: ...

# --- long runs ----------------------------------------------------------------------------------
def run_orbits(
    panel: dict[str, float],
    orbit: dict[str, Any],
    orbits: _Orbits,
    *,
    t_start: float,
    first_index: int,
    y0: list[float],
    theta_limit: float,
    stop_at_limit: bool,
    steps_per_period: float,
    cancel: CancelToken | None = None,
) -> dict[str, Any]: ...

# --- the boom (rust/src/bindings/boom.rs) --------------------------------------------------------
BOOM_FIELDS: list[str]
BOOM_RANGES: dict[str, tuple[float, float, bool]]  # name: (low, high, low end open); high closed
BOOM_EXAMPLE: dict[str, float]

def boom_derived(boom: dict[str, float]) -> dict[str, Any]: ...
def boom_steady_state(
    boom: dict[str, float], coupled: bool = True, flux: float = 1.0
) -> list[float]: ...
def boom_start_state(
    boom: dict[str, float], orbit: dict[str, Any], t0: float, coupled: bool
) -> list[float]: ...
def simulate_boom(
    boom: dict[str, float],
    orbit: dict[str, Any],
    run: _Run,
    *,
    coupled: bool,
    cancel: CancelToken | None = None,
) -> dict[str, Any]: ...
def run_boom_orbits(
    boom: dict[str, float],
    orbit: dict[str, Any],
    spec: dict[str, Any],
    y0: list[float],
    *,
    hybrid: dict[str, float] | None = None,
    cancel: CancelToken | None = None,
) -> dict[str, Any]: ...
def boom_flutter(
    boom: dict[str, float], coupled: bool, flux: float, with_critical: bool = True
) -> dict[str, Any]: ...
def boom_stability_map(
    boom: dict[str, float],
    inclinations: list[float],
    ratios: list[float],
    coupled: bool,
    flux: float,
    *,
    cancel: CancelToken | None = None,
) -> dict[str, Any]: ...

# --- finite-element beam comparator (rust/src/py/beam.rs) ---

def beam_modes(panel: dict[str, float], n_elements: int, n_modes: int) -> dict[str, Any]: ...
def beam_static(panel: dict[str, float], n_elements: int, moment: float) -> float: ...
def beam_response(
    panel: dict[str, float],
    n_elements: int,
    moment_t: _F,
    moment: _F,
    run: _Run,
    *,
    damping_ratio: float,
    residual: bool,
    cancel: CancelToken | None = None,
) -> dict[str, Any]: ...

# --- distributed panel (rust/src/py/distributed.rs) ---

def distributed_defaults(panel: dict[str, float]) -> dict[str, Any]: ...
def hinge_equivalent_damping_ratio(panel: dict[str, float]) -> float: ...
def distributed_info(panel: dict[str, float], settings: dict[str, Any]) -> dict[str, Any]: ...
def distributed_flutter(
    panel: dict[str, float], settings: dict[str, Any], flux: float
) -> dict[str, Any]: ...
def simulate_distributed(
    panel: dict[str, float],
    orbit: dict[str, Any],
    settings: dict[str, Any],
    run: _Run,
    *,
    cancel: CancelToken | None = None,
) -> dict[str, Any]: ...
def distributed_start_state(
    panel: dict[str, float], settings: dict[str, Any], orbit: dict[str, Any], t0: float
) -> list[float]: ...
def summary_metrics(columns: dict[str, Any], t_end: float) -> list[tuple[str, float]]: ...
def run_distributed_orbits(
    panel: dict[str, float],
    orbit: dict[str, Any],
    settings: dict[str, Any],
    orbits: _Orbits,
    chunk: dict[str, Any],
    *,
    cancel: CancelToken | None = None,
) -> dict[str, Any]: ...

# --- orbit options (issue 4)
def eclipses(
    orbit: dict[str, Any], t0: float, t1: float
) -> list[tuple[float, float, float, float, float]]: ...
def umbra_intervals(orbit: dict[str, Any], t0: float, t1: float) -> list[tuple[float, float]]: ...
def orbit_breakpoints(orbit: dict[str, Any], t0: float, t1: float) -> list[float]: ...
def flux_scale(orbit: dict[str, Any], t: _F) -> _F: ...
def declination(orbit: dict[str, Any], t: _F) -> _F: ...
def beta(orbit: dict[str, Any], t: _F) -> _F: ...
def nodal_rate(orbit: dict[str, Any]) -> float: ...
def eclipse_duration(orbit: dict[str, Any]) -> float: ...
def leo_orbit(altitude: float) -> dict[str, Any]: ...
def synodic_period(orbit: dict[str, Any]) -> float: ...

# --- stability map (issue 4)
def linear_thermal(
    panel: dict[str, float],
    flux: float = 1.0,
    omega: float | None = None,
    t_star: float | None = None,
) -> dict[str, Any]: ...
def linear_delta_t(fields: dict[str, float], t: _F, phi: float, delta_t0: float | None) -> _F: ...
def stability_map(
    panel: dict[str, float],
    x_name: str,
    x_values: list[float],
    y_name: str,
    y_values: list[float],
    model: str,
    coupled: bool,
    flux: float,
    *,
    cancel: CancelToken | None = None,
) -> dict[str, Any]: ...

# --- ensembles (Monte Carlo, sweeps) -----------------------------------------------------------
def check_panels(panels: _F, *, boom: bool = False) -> list[tuple[int, str, str]]: ...
def check_orbits(
    orbit: dict[str, Any], orbit_inputs: dict[str, Any], n: int
) -> list[tuple[int, str, str]]: ...
def least_steps(
    panels: _F,
    solver: dict[str, Any],
    span: float,
    steps_per_period: float | None = None,
    *,
    boom: bool = False,
) -> _F: ...

ORBIT_INPUTS: list[str]
ORBIT_INPUT_RANGES: dict[str, tuple[float, float, bool]]

@final
class MonteCarloPool:
    def __new__(cls, threads: int | None = None) -> MonteCarloPool: ...
    @property
    def threads(self) -> int: ...
    def run(
        self,
        panels: _F,
        orbit: dict[str, Any],
        orbits: _Orbits,
        *,
        threshold: float | None,
        stop_at_threshold: bool,
        validity_limit: float = ...,
        cancel: CancelToken | None = None,
        lockstep: bool = True,
        orbit_inputs: dict[str, Any] | None = None,
        boom: bool = False,
    ) -> dict[str, Any]: ...

EnsemblePool = MonteCarloPool
"""The name before :class:`MonteCarloPool` (the same class)."""

# --- laminates and the N-node model -------------------------------------------------------------
LAYER_FIELDS: list[str]
REFERENCE_TEMPERATURE: float

def validate_layer(layer: dict[str, Any]) -> None: ...
def validate_laminate(laminate: dict[str, Any]) -> None: ...
def laminate_properties(
    laminate: dict[str, Any], panel: dict[str, float] | None = None
) -> dict[str, Any]: ...
def materials() -> list[dict[str, Any]]: ...
def conduction_grid(panel: dict[str, float], grid: _Grid) -> dict[str, Any]: ...
def layered_steady_state(
    panel: dict[str, float],
    grid: _Grid,
    coupled: bool = True,
    flux: float = 1.0,
) -> dict[str, Any]: ...
def layered_flutter(
    panel: dict[str, float], grid: _Grid, point: _FlutterPoint
) -> dict[str, Any]: ...
def layered_flutter_at(
    panel: dict[str, float], grid: _Grid, orbit: dict[str, Any], point: _OrbitPoint
) -> dict[str, Any]: ...
def simulate_layers(
    panel: dict[str, float],
    grid: _Grid,
    orbit: dict[str, Any],
    run: _Run,
    *,
    model: str,
    coupled: bool,
    cancel: CancelToken | None = None,
) -> dict[str, Any]: ...
def cpu_info() -> dict[str, Any]: ...
