"""thermojitter: thermally induced vibration ("thermal jitter") and thermal flutter of long, thin
spacecraft appendages — a two-layer thermal model of a Sun-pointing plate in orbit, two-way
coupled to a one-degree-of-freedom hinge model of its first bending mode, with a Rust engine.

    import thermojitter as tj
    sol = tj.simulate(tj.Panel.paper(), tj.Orbit.geo_equinox(), (0, 86164.0905))
"""

from thermojitter import _core, beam, materials, nastran
from thermojitter._core import ConvergenceError, IntegrationError
from thermojitter.attitude import Attitude
from thermojitter.beam import BeamComparison, FreeFreeBeam, compare_with_beam
from thermojitter.boom import (
    Boom,
    BoomEquilibrium,
    BoomSolution,
    BoomStabilityMap,
    boom_stability_map,
    boom_steady_state,
)
from thermojitter.calibrate import CalibrationResult, calibrate, calibrate_from_csv
from thermojitter.checkpoint import CheckpointError
from thermojitter.distributed import (
    CriticalDampingYear,
    DistributedFlutterResult,
    DistributedSolution,
    critical_damping_year,
    distributed_defaults,
    distributed_flutter,
    distributed_frequencies,
    simulate_distributed,
)
from thermojitter.errors import (
    HybridFallbackWarning,
    InternalError,
    ParameterError,
    ParameterTypeError,
    SampleFailureWarning,
    ValidityLimitWarning,
)
from thermojitter.flutter import (
    FlutterResult,
    LinearThermalResponse,
    StabilityMap,
    flutter,
    linear_thermal_response,
    stability_map,
)
from thermojitter.laminate import Laminate, Layer
from thermojitter.longrun import OrbitSummaries, simulate_orbits
from thermojitter.montecarlo import (
    AllSamplesFailedError,
    SensitivityResult,
    monte_carlo,
    sensitivity,
    sweep,
)
from thermojitter.nastran import NastranBeam, from_nastran, to_nastran
from thermojitter.orbit import Orbit
from thermojitter.panel import Panel, beam_frequency, hinge_stiffness, natural_frequency
from thermojitter.persist import ResultFileError, load, save
from thermojitter.results import (
    Equilibrium,
    HingeSolution,
    LimitCrossing,
    Solution,
    ThermalSolution,
)
from thermojitter.simulate import (
    hinge_energy,
    simulate,
    simulate_hinge,
    simulate_thermal,
    steady_state,
)
from thermojitter.solver import HybridSettings, SolverSettings
from thermojitter.spacecraft import PD, Spacecraft, SpacecraftSolution, simulate_spacecraft

__version__ = "0.1.0"


def _check_kernel_variable() -> None:
    """Refuses a value of THERMOJITTER_KERNEL the engine would not understand (it reads the
    variable at its first run: ``portable`` forces the kernels without FMA, whose bits are the
    same on every processor; ``auto`` or unset, the best the processor has)."""
    import os

    value = os.environ.get(_core.KERNEL_VARIABLE)
    if value is not None and value.strip().lower() not in ("", *_core.KERNEL_CHOICES):
        raise ParameterError(
            _core.KERNEL_VARIABLE,
            value,
            f"the environment variable must be one of {', '.join(_core.KERNEL_CHOICES)}",
        )


_check_kernel_variable()

__all__ = [
    "AllSamplesFailedError",
    "BeamComparison",
    "Boom",
    "BoomEquilibrium",
    "BoomSolution",
    "BoomStabilityMap",
    "CalibrationResult",
    "CheckpointError",
    "ConvergenceError",
    "CriticalDampingYear",
    "DistributedFlutterResult",
    "DistributedSolution",
    "Equilibrium",
    "FlutterResult",
    "FreeFreeBeam",
    "HingeSolution",
    "HybridSettings",
    "IntegrationError",
    "Laminate",
    "Layer",
    "InternalError",
    "LimitCrossing",
    "LinearThermalResponse",
    "NastranBeam",
    "Orbit",
    "Attitude",
    "HybridFallbackWarning",
    "PD",
    "OrbitSummaries",
    "Panel",
    "ParameterError",
    "ParameterTypeError",
    "ResultFileError",
    "SampleFailureWarning",
    "SensitivityResult",
    "Solution",
    "SolverSettings",
    "Spacecraft",
    "SpacecraftSolution",
    "StabilityMap",
    "ThermalSolution",
    "ValidityLimitWarning",
    "beam",
    "beam_frequency",
    "boom_stability_map",
    "boom_steady_state",
    "flutter",
    "calibrate",
    "calibrate_from_csv",
    "compare_with_beam",
    "critical_damping_year",
    "distributed_defaults",
    "distributed_flutter",
    "distributed_frequencies",
    "from_nastran",
    "hinge_energy",
    "hinge_stiffness",
    "linear_thermal_response",
    "load",
    "materials",
    "monte_carlo",
    "nastran",
    "natural_frequency",
    "save",
    "sensitivity",
    "simulate",
    "simulate_distributed",
    "simulate_hinge",
    "simulate_orbits",
    "simulate_spacecraft",
    "simulate_thermal",
    "stability_map",
    "steady_state",
    "sweep",
    "to_nastran",
]
