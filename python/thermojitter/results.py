"""Result objects: NumPy arrays in small frozen containers, with table exports."""

from __future__ import annotations

import importlib
import math
from dataclasses import dataclass, field
from typing import Any, NamedTuple, Protocol

import numpy as np
from numpy.typing import NDArray

from thermojitter.orbit import Orbit
from thermojitter.panel import Equilibrium as Equilibrium  # the panel's steady state
from thermojitter.panel import Panel
from thermojitter.persist import Persistent, field_type
from thermojitter.solver import SolverSettings

Array = NDArray[np.float64]


@field_type
class LimitCrossing(NamedTuple):
    """Where a run's angle first passed its ``theta_limit``: the time ``t`` (s), the ``orbit``
    it falls in (whole orbits since the run's start, as :func:`thermojitter.simulate_orbits`
    numbers them) and the angle ``theta`` there (rad: θ, or θ_f of the distributed panel)."""

    t: float
    orbit: int
    theta: float

    @property
    def theta_deg(self) -> float:
        return math.degrees(self.theta)

    @classmethod
    def of(cls, raw: Any) -> LimitCrossing | None:
        """The engine's (t, orbit, θ), or None."""
        return None if raw is None else cls(float(raw[0]), int(raw[1]), float(raw[2]))


def _dataframes_module(name: str, method: str) -> Any:
    """The optional module ``name`` (pandas or xarray) that the export ``method`` needs; an
    ImportError saying how to install it when it is missing."""
    try:
        return importlib.import_module(name)
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError(f"{method} needs {name}: pip install 'thermojitter[dataframes]'") from exc


class _Faces(Protocol):
    @property
    def T_front(self) -> Array: ...
    @property
    def T_back(self) -> Array: ...


class _FaceDifference:
    """``delta_T`` of a run result holding both faces' temperatures."""

    @property
    def delta_T(self: _Faces) -> Array:
        """T_front − T_back, K (over time; over time × element for the distributed panel)."""
        return self.T_front - self.T_back


@dataclass(frozen=True)
class _Run(Persistent):
    """Counters common to every run (names as in scipy's solve_ivp where they exist)."""

    t: Array
    n_steps: int
    n_rejected: int
    n_rhs: int
    method: str
    settings: dict[str, Any] = field(default_factory=dict, repr=False)
    panel: Panel | None = field(default=None, repr=False, compare=False)
    """The panel the run was made with (saved with the result)."""
    orbit: Orbit | None = field(default=None, repr=False, compare=False)
    """The orbit the run was made on (None for a run without one, such as the hinge alone)."""

    @property
    def solver(self) -> SolverSettings | None:
        """The integrator settings the engine used (None where the run does not report them)."""
        used = self.settings.get("solver")
        return None if used is None else SolverSettings(**used)

    @property
    def nfev(self) -> int:
        """Right-hand-side evaluations (alias of n_rhs)."""
        return self.n_rhs

    def _columns(self) -> dict[str, Array]:
        raise NotImplementedError

    def to_pandas(self) -> Any:
        """A pandas DataFrame indexed by time (s); needs pandas."""
        pd = _dataframes_module("pandas", "to_pandas()")
        frame = pd.DataFrame(self._columns(), index=pd.Index(self.t, name="t"))
        return frame

    def _dataset(self) -> Any:
        """An xarray Dataset over the time coordinate t (s); needs xarray."""
        xr = _dataframes_module("xarray", "to_xarray()")
        return xr.Dataset(
            {name: ("t", values) for name, values in self._columns().items()},
            coords={"t": self.t},
            attrs={"method": self.method, **{k: str(v) for k, v in self.settings.items()}},
        )


Run = _Run
"""The counters and exports every run result shares (the base of the result classes of other
modules, such as :class:`thermojitter.distributed.DistributedSolution`)."""


@dataclass(frozen=True)
class Solution(_FaceDifference, _Run):
    """The coupled thermo-structural solution at the reported times.

    Temperatures in K, angles in rad, θ̇ in rad/s, the thermal moment in N m, ``sunlit`` the
    illuminated fraction s(t).
    """

    T_front: Array = field(default_factory=lambda: np.empty(0))
    T_back: Array = field(default_factory=lambda: np.empty(0))
    theta: Array = field(default_factory=lambda: np.empty(0))
    theta_dot: Array = field(default_factory=lambda: np.empty(0))
    thermal_moment: Array = field(default_factory=lambda: np.empty(0))
    sunlit: Array = field(default_factory=lambda: np.empty(0))
    y_end: Array = field(default_factory=lambda: np.empty(0))
    T_nodes: Array | None = None
    """With ``layers=N``: the temperature of every node (time × node), K."""
    limit_crossing: LimitCrossing | None = None
    """Where abs(θ) first passed ``theta_limit`` (None: it did not, or ``on_limit="ignore"``)."""
    stopped_at_limit: bool = False
    """True when ``on_limit="stop"`` ended the run at the crossing: no sample after it, and
    ``y_end`` is the state there."""
    depth: Array | None = None
    """With ``layers=N``: each node's depth below the front face, m."""
    flux_front: Array | None = None
    """The flux reaching the front face at each sample, W/m²: sunlight, albedo and Earth
    infrared on the flat panel in its attitude (the deflection's cos θ not applied)."""
    flux_back: Array | None = None
    """The flux reaching the back face at each sample, W/m² (as ``flux_front``)."""
    node_labels: tuple[str, ...] | None = None
    """With ``layers=N``: where each node sits: ``"front, L"``/``"back, L"`` on the faces of
    layers L, ``"L|M"`` on the interface of layers L and M, ``"L"`` inside layer L (a plain
    panel's one layer is ``"panel"``)."""

    @property
    def node_columns(self) -> tuple[str, ...]:
        """The ``to_pandas()`` column of each node's temperature: ``"T_node07 (honeycomb)"``
        (node index, front first, and where it sits, see ``node_labels``); empty without
        ``layers=N``."""
        if self.T_nodes is None or self.node_labels is None:
            return ()
        width = len(str(len(self.node_labels) - 1))
        return tuple(f"T_node{i:0{width}d} ({label})" for i, label in enumerate(self.node_labels))

    def to_pandas(self) -> Any:
        """A pandas DataFrame indexed by time (s); needs pandas. With ``layers=N`` it has a
        column per node after the others (``node_columns``), and ``frame.attrs["depth"]`` gives
        each node's depth below the front face, m."""
        frame = super().to_pandas()
        names = self.node_columns
        if names and self.T_nodes is not None:
            import pandas as pd

            nodes = pd.DataFrame(np.asarray(self.T_nodes), index=frame.index, columns=list(names))
            frame = pd.concat([frame, nodes], axis=1)
            frame.attrs["depth"] = [float(v) for v in np.asarray(self.depth)]
        return frame

    def _dataset(self) -> Any:
        """An xarray Dataset over t (s); with ``layers=N`` also ``T_nodes`` over (t, node),
        with the node depth (m) and label (``node_labels``) as coordinates."""
        ds = super()._dataset()
        if self.T_nodes is not None and self.depth is not None:
            ds = ds.assign_coords(depth=("node", np.asarray(self.depth)))
            if self.node_labels is not None:
                ds = ds.assign_coords(label=("node", list(self.node_labels)))
            ds["T_nodes"] = (("t", "node"), np.asarray(self.T_nodes))
        return ds

    @property
    def y(self) -> Array:
        """The state (T_front, T_back, theta, theta_dot) as a (4, n) array."""
        return np.vstack([self.T_front, self.T_back, self.theta, self.theta_dot])

    def _columns(self) -> dict[str, Array]:
        return {
            "T_front": self.T_front,
            "T_back": self.T_back,
            "theta": self.theta,
            "theta_dot": self.theta_dot,
            "thermal_moment": self.thermal_moment,
            "sunlit": self.sunlit,
        }


@dataclass(frozen=True)
class ThermalSolution(_Run):
    """A thermal model alone: ``T`` for one node, ``T_front``/``T_back`` for two layers (K)."""

    layers: int = 2
    T: Array | None = None
    T_front: Array | None = None
    T_back: Array | None = None

    @property
    def delta_T(self) -> Array:
        if self.T_front is None or self.T_back is None:
            raise AttributeError("delta_T needs the two-layer model (layers=2)")
        return self.T_front - self.T_back

    def _columns(self) -> dict[str, Array]:
        if self.T is not None:
            return {"T": self.T}
        assert self.T_front is not None and self.T_back is not None
        return {"T_front": self.T_front, "T_back": self.T_back}


@dataclass(frozen=True)
class HingeSolution(_Run):
    """The hinge alone under a prescribed moment: θ (rad) and θ̇ (rad/s)."""

    theta: Array = field(default_factory=lambda: np.empty(0))
    theta_dot: Array = field(default_factory=lambda: np.empty(0))

    def _columns(self) -> dict[str, Array]:
        return {"theta": self.theta, "theta_dot": self.theta_dot}
