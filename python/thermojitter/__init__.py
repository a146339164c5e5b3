"""thermojitter: thermally induced vibration ("thermal jitter") and thermal flutter of long, thin
spacecraft appendages — a two-layer thermal model of a Sun-pointing plate in orbit, two-way
coupled to a one-degree-of-freedom hinge model of its first bending mode, with a Rust engine.

    import thermojitter as tj
    sol = tj.simulate(tj.Panel.paper(), tj.Orbit.geo_equinox(), (0, 86164.0905))
"""

from thermojitter._core import ConvergenceError, IntegrationError
from thermojitter.flutter import FlutterResult, flutter
from thermojitter.longrun import OrbitSummaries, simulate_orbits
from thermojitter.montecarlo import SensitivityResult, monte_carlo, sensitivity, sweep
from thermojitter.orbit import Orbit
from thermojitter.panel import Panel, beam_frequency, hinge_stiffness, natural_frequency
from thermojitter.results import Equilibrium, HingeSolution, Solution, ThermalSolution
from thermojitter.simulate import (
    hinge_energy,
    simulate,
    simulate_hinge,
    simulate_thermal,
    steady_state,
)

__version__ = "0.1.0"

__all__ = [
    "ConvergenceError",
    "Equilibrium",
    "FlutterResult",
    "HingeSolution",
    "IntegrationError",
    "Orbit",
    "OrbitSummaries",
    "Panel",
    "SensitivityResult",
    "Solution",
    "ThermalSolution",
    "beam_frequency",
    "flutter",
    "hinge_energy",
    "hinge_stiffness",
    "monte_carlo",
    "natural_frequency",
    "sensitivity",
    "simulate",
    "simulate_hinge",
    "simulate_orbits",
    "simulate_thermal",
    "steady_state",
    "sweep",
]
