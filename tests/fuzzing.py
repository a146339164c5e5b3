"""A fuzz harness over the public API and the scenario parser, shared by tests/test_fuzz.py (a
short run in CI) and benches/fuzz.py (a long run that prints the count of each outcome).

Each example is a known-good call of one entry point with one to three of its arguments replaced
by a hostile value (NaN, ±inf, 0, negatives, 1e±300, integers too large for a float, bools, None,
strings, wrong shapes, reversed spans), or the bytes of a scenario file or of a long run's
checkpoint, damaged (truncated, bit-flipped, a line dropped or repeated, a piece replaced). It
runs in a worker process under a watchdog, so that a crash (the process dies) or a hang (no
answer within the CPU-time limit, see ``Runner``) is counted, not fatal.

Outcomes:

Besides hostile values, an example may be *known invalid* (``Example.invalid``): one argument
replaced by a value its kind (``SPECS``, ``INVALID``) never accepts — out of range, non-finite, a
bool for a number, a string for a bool, an integer too large, an empty path, an unphysical start
state. Such a call must be refused, naming that argument.

- ``ok``: a result whose every number is finite (NaN only where documented: no eclipse, no umbra,
  a failed Monte Carlo sample with its error; +inf only for ``max_step``, "no cap");
- ``refused_named``: ValueError/TypeError naming the parameter (a ``ParameterError``'s
  ``.parameter``, or the argument's name in the message); ``refused_unnamed`` otherwise;
- ``runtime_error``: IntegrationError or ConvergenceError (a clear error from the engine);
- failures: ``accepted_invalid`` (a known-invalid example answered, not refused),
  ``wrong_name`` (a known-invalid example refused naming another parameter), ``silent_nan`` (a
  non-finite number returned), ``wrong_result`` (a run resumed
  from a damaged checkpoint that differs from the run itself), ``internal_error`` (a panic caught at
  the boundary), ``panic`` (a BaseException from the engine), ``other_exception`` (any other
  type), ``abort`` (the worker died), ``hang`` (past the time limit).
"""

from __future__ import annotations

import math
import multiprocessing as mp
import os
import time
import traceback
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import hypothesis.strategies as st
import numpy as np

FAILURES = (
    "accepted_invalid", "wrong_name", "silent_nan", "wrong_result", "internal_error", "panic",
    "other_exception", "abort", "hang",
)  # fmt: skip
OUTCOMES = ("ok", "refused_named", "refused_unnamed", "runtime_error", *FAILURES)

# Hostile values, and values that are fine, to mix into good calls.
HOSTILE: list[Any] = [
    math.nan,
    math.inf,
    -math.inf,
    0.0,
    -0.0,
    -1.0,
    1e300,
    -1e300,
    1e-300,
    5e-324,
    1.7976931348623157e308,
    10**400,
    -(10**400),
    2**63,
    2**64 + 1,
    True,
    False,
    None,
    "1.0",
    "abc",
    "",
    [1.0, 2.0],
    [],
    [[1.0, 2.0], [3.0, 4.0]],
    {"a": 1},
    (math.nan, 1.0),
    (1.0, 0.0),
    (0.0,),
    object(),
    np.float64(math.nan),
    np.array([1.0, math.inf]),
    np.zeros((2, 2)),
    np.int64(-5),
    complex(1.0, 1.0),
    540.0,  # km for m
    20.0,  # degrees for rad
    4.89,
    1e12,
    -600.0,
]


def hostile_values() -> st.SearchStrategy[Any]:
    return st.one_of(
        st.sampled_from(HOSTILE),
        st.floats(allow_nan=True, allow_infinity=True),
        st.integers(min_value=-(2**70), max_value=2**70),
        st.text(max_size=4),
    )


def _base_calls() -> dict[str, tuple[Callable[..., Any], dict[str, Any]]]:
    """Each entry point with arguments that run cheaply (a short span, a low orbit, a small
    design, the step budget of the fuzz): the fuzz replaces some of them."""
    import thermojitter as tj
    from thermojitter.scenario import parse_scenario

    low = tj.Orbit(radius=7.0e6, period=5828.5)
    panel = tj.Panel.paper()
    geo = tj.Orbit.geo_equinox()
    budget = {"max_steps": 200_000}
    fast = {"rtol": 1e-6, "atol": 1e-8}

    def orbit_call(method: str) -> Callable[..., Any]:
        def call(_self: Any = geo, **kw: Any) -> Any:
            return getattr(_self, method)(**kw)

        return call

    def scenario(**tables: Any) -> Any:
        return parse_scenario({k: v for k, v in tables.items() if v is not None}, "fuzz.toml")

    series = _series()
    sandwich = _sandwich()
    beam = tj.FreeFreeBeam(panel, n_elements=20)

    return {
        "Panel": (tj.Panel, {"length": 50.0, "damping": 3.0, "specific_heat": 900.0}),
        "Panel.replace": (
            lambda _self, **kw: _self.replace(**kw),
            {"_self": panel, "conductance": 25.0, "youngs_modulus": 70e9},
        ),
        "Orbit": (tj.Orbit, {"radius": 42_164e3, "period": 86_164.0, "phase0": 0.0}),
        "Orbit.leo": (tj.Orbit.leo, {"altitude": 540e3}),
        "Orbit.geo_year": (tj.Orbit.geo_year, {"start_date": "2026-03-01"}),
        "Orbit.circular": (
            tj.Orbit.circular,
            {
                "altitude": 540e3,
                "inclination": 0.5,
                "raan": 1.0,
                "epoch": "2026-06-01",
                "j2": True,
                "shadow": "conical",
            },
        ),  # fmt: skip
        "beta": (orbit_call("beta"), {"_self": tj.Orbit.circular(700e3, 1.7), "t": [0.0, 1e6]}),
        "shadow_intervals": (orbit_call("shadow_intervals"), {"t0": 0.0, "t1": 1e5}),
        "eclipses": (orbit_call("eclipses"), {"_self": tj.Orbit.geo_year(), "t0": 0.0, "t1": 1e6}),
        "umbra_intervals": (orbit_call("umbra_intervals"), {"t0": 0.0, "t1": 1e5}),
        "breakpoints": (orbit_call("breakpoints"), {"t0": 0.0, "t1": 1e5}),
        "illumination": (orbit_call("illumination"), {"t": [0.0, 4.3e4]}),
        "flux_scale": (orbit_call("flux_scale"), {"_self": tj.Orbit.geo_year(), "t": 1e6}),
        "eclipse_durations": (orbit_call("eclipse_durations"), {"t0": 0.0, "t1": 2e5}),
        "steady_state": (tj.steady_state, {"panel": panel, "coupled": True, "flux": 1.0}),
        "simulate": (
            tj.simulate,
            {
                "panel": panel,
                "orbit": geo,
                "t_span": (0.0, 60.0),
                "model": "nonlinear",
                "coupled": True,
                "method": "rk45",
                "dt_out": 1.0,
                "y0": None,
                **fast,
                **budget,
            },
        ),
        "simulate rk4": (
            tj.simulate,
            {
                "panel": panel,
                "orbit": geo,
                "t_span": (0.0, 30.0),
                "method": "rk4",
                "dt": 0.05,
                "t_eval": [0.0, 10.0, 30.0],
            },
        ),
        "simulate_thermal": (
            tj.simulate_thermal,
            {"panel": panel, "orbit": geo, "t_span": (0.0, 600.0), "layers": 2, **budget},
        ),
        "simulate_hinge": (
            tj.simulate_hinge,
            {"panel": panel, "moment": 400.0, "t_span": (0.0, 30.0), "y0": (0.0, 0.0), **budget},
        ),
        "hinge_energy": (
            tj.hinge_energy,
            {"panel": panel, "theta": [0.0, 0.1], "theta_dot": [0.0, 0.01], "moment": 400.0},
        ),
        "hinge_stiffness": (tj.hinge_stiffness, {"panel": panel, "criterion": "frequency"}),
        "natural_frequency": (tj.natural_frequency, {"panel": panel}),
        "beam_frequency": (tj.beam_frequency, {"panel": panel}),
        "flutter": (tj.flutter, {"panel": panel, "coupled": True, "flux": 1.0}),
        "stability_map": (
            tj.stability_map,
            {
                "panel": panel,
                "x": ("damping", [0.0, 3.0]),
                "y": ("conductance", [10.0, 25.0]),
                "flux": 1.0,
                "progress": False,
            },
        ),
        "linear_thermal_response": (
            tj.linear_thermal_response,
            {"panel": panel, "omega": None, "T_star": None, "flux": 1.0},
        ),
        "simulate_orbits": (
            tj.simulate_orbits,
            {
                "panel": panel,
                "orbit": low,
                "n_orbits": 1,
                "theta_limit": 0.3,
                "window": 600.0,
                "steps_per_period": 10.0,
                "progress": False,
                **fast,
                **budget,
            },
        ),
        "monte_carlo": (
            tj.monte_carlo,
            {
                "panel": panel,
                "orbit": low,
                "vary": {"damping": ("uniform", 1.0, 4.0)},
                "n": 2,
                "seed": 1,
                "horizon": 1,
                "threads": 1,
                "progress": False,
                **fast,
                **budget,
            },
        ),
        "sweep": (
            tj.sweep,
            {
                "panel": panel,
                "orbit": low,
                "grid": {"damping": [1.0, 3.0]},
                "threads": 1,
                "progress": False,
                **fast,
                **budget,
            },
        ),
        "scenario": (
            scenario,
            {
                "panel": {"damping": 3.0},
                "orbit": {"preset": "leo", "altitude": 540e3},
                "simulation": {"t_end": 600.0, "rtol": 1e-8},
                "output": {"format": "csv"},
            },
        ),
        "sensitivity": (
            tj.sensitivity,
            {
                "panel": panel,
                "orbit": low,
                "vary": {"damping": ("uniform", 1.0, 4.0)},
                "n": 2,
                "seed": 1,
                "horizon": 1,
                "threads": 1,
                "progress": False,
                **fast,
                **budget,
            },
        ),
        "calibrate": (
            tj.calibrate,
            {
                "t": series[0],
                "theta": series[1],
                "panel": panel,
                "orbit": geo,
                "fit": ("damping",),
                "initial": {"damping": 2.5},
                "y0": None,
                "model": "nonlinear",
                "coupled": True,
                "diff_step": 1e-3,
                **fast,
            },
        ),
        "calibrate_from_csv": (
            _calibrate_csv,
            {"path": CSV, "degrees": False, "fit": ("damping",), "diff_step": 1e-3, **fast},
        ),
        "FreeFreeBeam": (tj.FreeFreeBeam, {"panel": panel, "n_elements": 20}),
        "FreeFreeBeam.natural_frequencies": (
            lambda _self, **kw: _self.natural_frequencies(**kw),
            {"_self": beam, "n": 2},
        ),
        "FreeFreeBeam.static_tip_deflection": (
            lambda _self, **kw: _self.static_tip_deflection(**kw),
            {"_self": beam, "moment": 400.0},
        ),
        "FreeFreeBeam.response": (
            lambda _self, **kw: _self.response(**kw),
            {
                "_self": beam,
                "times": [0.0, 10.0, 20.0],
                "moments": [400.0, 350.0, 300.0],
                "damping_ratio": 0.01,
                "residual": True,
                **fast,
            },
        ),
        "compare_with_beam": (
            tj.compare_with_beam,
            {
                "panel": panel,
                "orbit": geo,
                "t_span": (0.0, 30.0),
                "dt_out": 1.0,
                "n_elements": 10,
                "model": "nonlinear",
                "coupled": True,
                **fast,
            },
        ),
        "distributed_defaults": (tj.distributed_defaults, {"panel": panel}),
        "distributed_frequencies": (
            tj.distributed_frequencies,
            {"panel": panel, "support": "free-free", "elements": 8, "modes": 2},
        ),
        "distributed_flutter": (
            tj.distributed_flutter,
            {"panel": panel, "elements": 8, "modes": 2, "flux": 1.0, "sun_angle": 0.0},
        ),
        "simulate_distributed": (
            tj.simulate_distributed,
            {
                "panel": panel,
                "orbit": geo,
                "t_span": (0.0, 10.0),
                "elements": 4,
                "modes": 2,
                "coupled": True,
                "dt_out": 1.0,
                **fast,
                **budget,
            },
        ),
        "Layer": (
            tj.Layer,
            {
                "thickness": 5e-4,
                "conductivity": 100.0,
                "density": 1650.0,
                "specific_heat": 900.0,
                "youngs_modulus": 1e11,
                "expansion_coeff": -1e-6,
                "name": "skin",
            },
        ),
        "Laminate": (
            tj.Laminate,
            {
                "layers": sandwich.layers,
                "emissivity_front": 0.8,
                "emissivity_back": 0.3,
                "absorptivity": 0.8,
                "reference_temperature": 293.15,
            },
        ),
        "Panel.from_laminate": (
            tj.Panel.from_laminate,
            {"laminate": sandwich, "length": 20.0, "criterion": "frequency", "damping": 1.0},
        ),
        "materials.get": (tj.materials.get, {"key": "kapton"}),
        "Material.layer": (
            lambda _self, **kw: _self.layer(**kw),
            {"_self": tj.materials.CFRP_M55J_QI, "thickness": 5e-4},
        ),
        "SolverSettings": (
            tj.SolverSettings,
            {"method": "rk45", "rtol": 1e-8, "atol": 1e-10, "max_steps": 1000},
        ),
        # Damaged files: the bytes of a good one, mutated (see ``damaged``).
        "scenario file": (_scenario_file, {"text": SCENARIO_TEXT}),
        "checkpoint": (_resume, {"text": b""}),
    }


_SERIES: list[Any] = []


def _series() -> tuple[np.ndarray, np.ndarray]:
    """A short angle series to calibrate against (21 samples over 60 s of the paper panel on
    GEO, from a kick off its equilibrium), made once per process."""
    if not _SERIES:
        import thermojitter as tj

        panel = tj.Panel.paper()
        eq = tj.steady_state(panel)
        t = np.linspace(0.0, 60.0, 21)
        y0 = (eq.T_front, eq.T_back, eq.theta + 1e-3, 0.0)
        sol = tj.simulate(panel, tj.Orbit.geo_equinox(), (0.0, 60.0), t_eval=t, y0=y0)
        _SERIES.extend([t, np.asarray(sol.theta)])
    return _SERIES[0], _SERIES[1]


def _sandwich() -> Any:
    """CFRP skins on an aluminium honeycomb core, from the package's materials: a real layup
    whose expansion coefficient is negative."""
    import thermojitter as tj
    from thermojitter import materials

    skin, core = materials.CFRP_M55J_QI, materials.ALUMINIUM_HONEYCOMB
    layers = (skin.layer(5e-4, "front"), core.layer(0.02, "core"), skin.layer(5e-4, "back"))
    return tj.Laminate(layers, emissivity_front=0.8, emissivity_back=0.3, absorptivity=0.8)


CSV: Any = type("CsvFile", (), {"__repr__": lambda self: "<the series as a CSV file>"})()
"""Stands for the path of a CSV file of the series, written for the call (``_calibrate_csv``)."""


def _calibrate_csv(path: Any, **kwargs: Any) -> Any:
    import tempfile
    from pathlib import Path

    import thermojitter as tj

    t, theta = _series()
    with tempfile.TemporaryDirectory() as folder:
        file = Path(folder) / "series.csv"
        rows = "\n".join(f"{a:.17g},{b:.17g}" for a, b in zip(t, theta, strict=True))
        file.write_text("t,theta\n" + rows + "\n")
        return tj.calibrate_from_csv(file if path is CSV else path, **kwargs)


# --- known-invalid arguments ----------------------------------------------------------------

# Values no argument of the kind accepts. A scalar real number: not a bool, a string, a
# sequence, a complex, None (where it is not optional), nor non-finite or beyond a float.
_NOT_REAL: list[Any] = [True, False, "1.0", "abc", [1.0, 2.0], complex(1.0, 1.0), object()]
_HUGE: list[Any] = [10**400, -(10**400)]
_REAL = [*_NOT_REAL, *_HUGE, math.nan, math.inf, -math.inf, np.float64(math.nan)]
_POSITIVE = [*_REAL, 0.0, -0.0, -1.0, -1e-300, np.int64(-5)]
_CAP = [*_NOT_REAL, math.nan, 10**400, 0.0, -1.0]  # > 0, +inf allowed ("no cap")
_COUNT = [True, False, 1.5, "2", math.nan, 0, -1, 10**400, -(10**400), np.float64(3.0)]
_FLAG = ["False", "true", "", 0, 1, 1.0, np.float64(1.0), [True]]
_CHOICE = ["bogus", "", 1, True, 2.5]
_PATH = ["", 1.5, True, b"run"]
_SPAN = [(math.nan, 1.0), (True, 60.0), (0.0, -1.0), (0.0, 0.0), (0.0,), "ab", (0.0, math.inf),
         (0.0, 10**400), (0.0, 1.0, 2.0)]  # fmt: skip
_TIMES = [[0.0, math.nan], [True, False], "abc", [[0.0, 1.0], [2.0, 3.0]], [math.inf]]
_REALS = [[math.nan], "abc", [True, False], [[1.0, 2.0], [3.0, 4.0]], None, [10**400]]
_PANEL = [{"damping": 1.0}, "paper", 1.0, True]
_ORBIT = ["GEO", 1.0, True, {"radius": 7e6}]

INVALID: dict[str, list[Any]] = {
    "real": [*_REAL, None],
    "real?": _REAL,
    "positive": [*_POSITIVE, None],
    "positive?": _POSITIVE,
    "nonneg": [*_REAL, None, -1.0, -1e-300],
    "nonneg?": [*_REAL, -1.0],
    "unit": [*_POSITIVE, None, 1.5],
    "expansion": [*_REAL, None, 0.01, -0.01],  # any sign, |a| <= 1e-3 1/K
    "angle": [*_POSITIVE, 2.0, 20.0],  # a limit in (0, π/2] rad
    "sun_angle": [*_REAL, None, 2.0, -1.6],  # |ψ| < π/2
    "inclination": [*_REAL, None, -0.1, 3.2, 28.5],  # in [0, π] rad (28.5: degrees)
    "cap": [*_CAP, None],
    "count": [*_COUNT, None],
    "count?": _COUNT,
    # A count with no upper bound (beyond the need it does no harm: one chunk, one call).
    "many": [v for v in _COUNT if v is not _COUNT[7]],  # all but 10**400
    "seed": [True, 1.5, "2", math.nan, -1, np.float64(3.0)],
    "nodes?": [*_COUNT, 1, 10**7],
    "layers12": [*_COUNT, None, 3],
    "flag": [*_FLAG, None],
    "flag?": _FLAG,
    "choice": [*_CHOICE, None],
    "choice?": _CHOICE,
    "path?": _PATH,
    "span": [*_SPAN, None],
    "span?": _SPAN,
    "times?": _TIMES,
    "reals": _REALS,
    "panel": [*_PANEL, None],
    "panel?": _PANEL,
    "orbit": [*_ORBIT, None],
    "orbit?": _ORBIT,
    # Unphysical or malformed start states.
    "y0_4?": [(-10.0, 290.0, 0.0, 0.0), (0.0, 290.0, 0.0, 0.0), (300.0, 0.0, 0.0, 0.0),
              (300.0, 290.0, 0.0, 1e6), (300.0, 290.0, 0.0, -50.0), (300.0, 290.0, 4.89, 0.0),
              (300.0, math.nan, 0.0, 0.0), (300.0, 290.0, 0.0), "abcd", (True, 290.0, 0.0, 0.0)],
    "y0_2": [(0.0, 1e6), (0.0, -3.0), (4.89, 0.0), (math.nan, 0.0), (0.0,), "ab", None],
    "y0_T2?": [(-10.0, 290.0), (0.0, 290.0), (300.0, -1.0), (math.nan, 290.0), (300.0,)],
    "y0_dist?": [[-10.0] * 8 + [0.0] * 4, [0.0] * 12, [300.0] * 3, "abc", [math.nan] * 12],
    "grid": [{"damping": [True, False]}, {"damping": []}, {"damping": [math.nan]},
             {"damping": "abc"}, {"colour": [1.0]}, {}, None, "damping"],
    "vary": [{}, None, "damping", {"colour": ("uniform", 1.0, 2.0)},
             {"damping": ("uniform", True, 2.0)}, {"damping": ("bogus", 1.0, 2.0)}],
    "axis": ["damping", ("damping",), ("colour", [1.0]), ("damping", [True, False]),
             ("damping", []), None, ("damping", [math.nan])],
    "fit": ["damping", None, (), ("colour",), 1.0, ("damping", "damping")],
    "initial": [{"damping": True}, {"damping": "3"}, "damping", {"colour": 1.0},
                {"damping": math.nan}, 1.0],
    "material": ["nope", 1, None, True],
    "name": [1, None, True],
    "name?": [1, True, 2.5],
    "date": ["2026-13-01", "", True, None, math.nan],  # a number is a day of the year
    "laminate": ["x", None, 1.0],
    "layers": ["x", None, [], [1.0], 1.0],
    "support": [*_CHOICE, None],
}  # fmt: skip

_SOLVER = {"rtol": "positive", "atol": "positive", "max_steps": "count"}
_STUDY = {
    "horizon": "count", "threads": "count?", "progress": "flag", "coupled": "flag",
    "model": "choice", "method": "choice?", "window": "positive", "threshold": "positive?",
    "stop_at_threshold": "flag", "layers": "nodes?", "checkpoint": "path?",
    "chunk_size": "many", "panel": "panel", "orbit": "orbit", **_SOLVER,
}  # fmt: skip
_ORBIT_SPAN = {"t0": "real", "t1": "real"}

SPECS: dict[str, dict[str, str]] = {
    "Panel": {
        "length": "positive",
        "damping": "nonneg",
        "specific_heat": "positive",
        "expansion_coeff": "expansion",
        "emissivity_front": "unit",
        "moment_scale": "positive",
        "width": "positive",
    },
    "Panel.replace": {
        "conductance": "positive",
        "youngs_modulus": "positive",
        "absorptivity": "unit",
        "colour": "real",
    },
    "Orbit": {
        "radius": "positive",
        "period": "positive",
        "phase0": "real",
        "shadow": "choice",
        "season": "flag",
        "eccentric_sun": "flag",
        "epoch_day": "real",
    },
    "Orbit.leo": {"altitude": "positive"},
    "Orbit.geo_year": {"start_date": "date"},
    "Orbit.circular": {
        "altitude": "positive",
        "inclination": "inclination",
        "raan": "real",
        "epoch": "date",
        "j2": "flag",
        "shadow": "choice",
    },
    "beta": {"t": "reals"},
    "shadow_intervals": _ORBIT_SPAN,
    "umbra_intervals": _ORBIT_SPAN,
    "breakpoints": _ORBIT_SPAN,
    "eclipse_durations": _ORBIT_SPAN,
    "eclipses": _ORBIT_SPAN,
    "illumination": {"t": "reals"},
    "flux_scale": {"t": "reals"},
    "steady_state": {"panel": "panel", "coupled": "flag", "flux": "real"},
    "simulate": {
        "panel": "panel",
        "orbit": "orbit",
        "t_span": "span",
        "model": "choice",
        "coupled": "flag",
        "method": "choice?",
        "dt_out": "positive?",
        "y0": "y0_4?",
        "max_step": "cap",
        "layers": "nodes?",
        **_SOLVER,
    },
    "simulate rk4": {"dt": "positive", "t_eval": "times?", "y0": "y0_4?"},
    "simulate_thermal": {"t_span": "span", "layers": "layers12", "y0": "y0_T2?", **_SOLVER},
    "simulate_hinge": {
        "panel": "panel",
        "moment": "reals",
        "t_span": "span",
        "y0": "y0_2",
        "model": "choice",
        **_SOLVER,
    },
    "hinge_energy": {"theta": "reals", "theta_dot": "reals", "moment": "real", "model": "choice"},
    "hinge_stiffness": {"panel": "panel", "criterion": "choice"},
    "natural_frequency": {"panel": "panel"},
    "beam_frequency": {"panel": "panel"},
    "flutter": {
        "panel": "panel",
        "coupled": "flag",
        "flux": "real?",
        "model": "choice",
        "layers": "nodes?",
        "orbit": "orbit?",
        "t": "real",
    },
    "stability_map": {
        "x": "axis",
        "y": "axis",
        "flux": "real",
        "progress": "flag",
        "coupled": "flag",
        "model": "choice",
    },
    "linear_thermal_response": {"omega": "real?", "T_star": "positive?", "flux": "real"},
    "simulate_orbits": {
        "panel": "panel",
        "orbit": "orbit",
        "n_orbits": "count",
        "t_start": "real",
        "window": "positive",
        "theta_limit": "angle",
        "coupled": "flag",
        "model": "choice",
        "method": "choice",
        "checkpoint": "path?",
        "checkpoint_every": "real",
        "orbits_per_call": "many",
        "progress": "flag?",
        "y0": "y0_4?",
        "layers": "nodes?",
        "steps_per_period": "real",
        **_SOLVER,
    },
    "monte_carlo": {
        **_STUDY,
        "vary": "vary",
        "n": "count",
        "seed": "seed",
        "sampler": "choice",
        "truncate": "flag",
    },
    "sweep": {**_STUDY, "grid": "grid"},
    "sensitivity": {
        **_STUDY,
        "vary": "vary",
        "n": "count",
        "seed": "seed",
        "metric": "choice",
        "second_order": "flag",
        "truncate": "flag",
    },
    "calibrate": {
        "t": "reals",
        "theta": "reals",
        "panel": "panel?",
        "orbit": "orbit?",
        "fit": "fit",
        "initial": "initial",
        "y0": "y0_4?",
        "model": "choice",
        "coupled": "flag",
        "diff_step": "positive",
        **_SOLVER,
    },
    "calibrate_from_csv": {"path": "path?", "degrees": "flag", "diff_step": "positive"},
    "FreeFreeBeam": {"panel": "panel", "n_elements": "count"},
    "FreeFreeBeam.natural_frequencies": {"n": "count"},
    "FreeFreeBeam.static_tip_deflection": {"moment": "real"},
    "FreeFreeBeam.response": {
        "times": "reals",
        "moments": "reals",
        "damping_ratio": "nonneg?",
        "residual": "flag",
        **_SOLVER,
    },
    "compare_with_beam": {
        "panel": "panel",
        "orbit": "orbit",
        "t_span": "span?",
        "dt_out": "positive",
        "n_elements": "count",
        "model": "choice",
        "coupled": "flag",
        "scale_moment": "flag",
        "criterion": "choice?",
        "damping_ratio": "nonneg?",
        "f_min": "positive",
        **_SOLVER,
    },
    "distributed_defaults": {"panel": "panel?"},
    "distributed_frequencies": {
        "panel": "panel",
        "support": "support",
        "elements": "count?",
        "modes": "count?",
    },
    "distributed_flutter": {
        "panel": "panel",
        "support": "support",
        "elements": "count?",
        "modes": "count?",
        "flux": "real",
        "sun_angle": "sun_angle",
        "damping_ratio": "nonneg?",
        "layers": "count",
    },
    "simulate_distributed": {
        "panel": "panel",
        "orbit": "orbit",
        "t_span": "span",
        "coupled": "flag",
        "y0": "y0_dist?",
        "sun_angle": "sun_angle",
        "elements": "count?",
        "modes": "count?",
        "dt_out": "positive?",
        "layers": "count",
        **_SOLVER,
    },
    "Layer": {
        "thickness": "positive",
        "conductivity": "positive",
        "density": "positive",
        "specific_heat": "positive",
        "youngs_modulus": "nonneg",
        "expansion_coeff": "expansion",
        "name": "name",
    },
    "Laminate": {
        "layers": "layers",
        "emissivity_front": "unit",
        "emissivity_back": "unit",
        "absorptivity": "unit",
        "reference_temperature": "positive",
    },
    "Panel.from_laminate": {
        "laminate": "laminate",
        "length": "positive",
        "criterion": "choice",
        "damping": "nonneg",
        "hinge_stiffness": "positive?",
        "width": "positive",
    },
    "materials.get": {"key": "material"},
    "Material.layer": {"thickness": "positive", "name": "name?"},
    "SolverSettings": {"method": "choice", "dt": "positive?", "max_step": "cap", **_SOLVER},
    # Keys of a scenario file's tables (dotted), as the parser receives them.
    "scenario": {
        "simulation.coupled": "flag",
        "simulation.t_end": "positive",
        "simulation.rtol": "positive",
        "simulation.dt_out": "positive",
        "simulation.method": "choice",
        "panel.damping": "nonneg",
        "panel.length": "positive",
        "orbit.altitude": "positive",
        "output.plots": "flag",
        "output.format": "choice",
    },
}
"""The kind of each argument (see ``INVALID``) that the invalid-input fuzz replaces."""


def names_parameter(exc: BaseException, name: str) -> bool:
    """Whether the refusal ``exc`` names the argument ``name``: its ``.parameter`` (or a scenario
    error's ``.key``) is the argument or a part of it (``y0[2]``, ``grid.damping``, ``layer
    'core': density``), or, for an error that carries none, its message says the name."""
    import re

    named = getattr(exc, "parameter", None) or getattr(exc, "key", None)
    if named:
        p = str(named)
        return p == name or p.startswith((f"{name}[", f"{name}.")) or p.endswith(f": {name}")
    return re.search(rf"(?<![\w.]){re.escape(name)}(?!\w)", str(exc)) is not None


SCENARIO_TEXT = b"""# a scenario file
[panel]
damping = 3.0
length = 50.0

[orbit]
preset = "leo"
altitude = 540e3

[simulation]
t_end = 600.0
rtol = 1e-8
keep = "samples"

[output]
format = "csv"
plots = false
"""

# Byte strings spliced into a file: TOML and JSON syntax, hostile numbers, bad encodings.
TOKENS = [
    b"", b"nan", b"inf", b"-inf", b"-1", b"0", b"1e400", b"9" * 400, b'"x"', b"[]", b"{}",
    b"true", b"null", b"=", b"[panel]", b"[[orbit]]", b"\n", b"\x00", b"\xff\xfe", b'"', b",",
    b"}", b"]", b"damping = ", b'"content"', b'"checksum": "0"', b"1.0000000000000002",
]  # fmt: skip


def damaged(base: bytes) -> st.SearchStrategy[bytes]:
    """``base`` truncated, with a bit flipped, a line removed or repeated, or a piece replaced
    by a token."""
    n = len(base)
    lines = base.split(b"\n")

    def flip(i: int, bit: int) -> bytes:
        return base[:i] + bytes([base[i] ^ (1 << bit)]) + base[i + 1 :]

    def splice(i: int, width: int, token: bytes) -> bytes:
        return base[:i] + token + base[i + width :]

    def line(j: int, repeat: bool) -> bytes:
        kept = lines[: j + 1] + lines[j:] if repeat else lines[:j] + lines[j + 1 :]
        return b"\n".join(kept)

    return st.one_of(
        st.integers(0, n - 1).map(lambda k: base[:k]),
        st.builds(flip, st.integers(0, n - 1), st.integers(0, 7)),
        st.builds(splice, st.integers(0, n), st.integers(0, 24), st.sampled_from(TOKENS)),
        st.builds(line, st.integers(0, len(lines) - 1), st.booleans()),
    )


def _scenario_file(text: bytes) -> Any:
    import tempfile
    from pathlib import Path

    from thermojitter.scenario import load_scenario

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "fuzz.toml"
        path.write_bytes(text)
        return load_scenario(path)


_RESUME: dict[str, Any] = {}


def _resume_call() -> tuple[Any, dict[str, Any]]:
    """The long run whose checkpoint the fuzz damages: two orbits of the low orbit."""
    import thermojitter as tj

    low = tj.Orbit(radius=7.0e6, period=5828.5)
    args = {"rtol": 1e-6, "atol": 1e-8, "progress": False, "window": 600.0}
    return lambda **kw: tj.simulate_orbits(tj.Panel.paper(), low, 2, **args, **kw), args


def checkpoint_reference() -> tuple[bytes, Any]:
    """(the bytes of an intact checkpoint, the run it answers), made once per process."""
    if not _RESUME:
        import tempfile
        from pathlib import Path

        run, _ = _resume_call()
        with tempfile.TemporaryDirectory() as folder:
            path = Path(folder) / "run.json"
            result = run(checkpoint=path)
            _RESUME["bytes"], _RESUME["result"] = path.read_bytes(), result
    return _RESUME["bytes"], _RESUME["result"]


def _resume(text: bytes) -> Any:
    """Resumes the reference run from a damaged copy of its checkpoint."""
    import tempfile
    from pathlib import Path

    run, _ = _resume_call()
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "run.json"
        path.write_bytes(text)
        return run(checkpoint=path)


@dataclass
class Example:
    """One call: the entry point, the names of the replaced arguments and their values."""

    target: str
    changes: dict[str, Any] = field(default_factory=dict)
    invalid: bool = False
    """The one change is known invalid (see ``SPECS``): it must be refused, naming it."""


@st.composite
def examples(draw: st.DrawFn, targets: list[str] | None = None) -> Example:
    calls = _base_calls()
    name = draw(st.sampled_from(sorted(targets or calls)))
    base = calls[name][1]
    if name in SPECS and draw(st.integers(0, 2)) == 0:
        # One argument replaced by a value its kind never accepts: it must be refused.
        arg = draw(st.sampled_from(sorted(SPECS[name])))
        value = draw(st.sampled_from(INVALID[SPECS[name][arg]]))
        return Example(name, {arg: value}, invalid=True)
    # The receiver of a method ("_self") is not an argument a user passes: it stays valid.
    keys = sorted(k for k in base if not k.startswith("_"))
    if name == "scenario file":
        return Example(name, {"text": draw(damaged(SCENARIO_TEXT))})
    if name == "checkpoint":
        return Example(name, {"text": draw(damaged(checkpoint_reference()[0]))})
    if name == "scenario":
        # Replace a key of one table (or the table itself) in the scenario data.
        table = draw(st.sampled_from(keys))
        fields = {
            "panel": ["damping", "youngs_modulus", "length", "mass_per_length"],
            "orbit": ["preset", "altitude", "radius", "period", "phase0", "shadow", "season"],
            "simulation": ["t_end", "orbits", "years", "rtol", "atol", "dt", "dt_out", "keep",
                           "method", "coupled", "theta_limit_deg"],
            "output": ["format", "plots"],
        }[table]  # fmt: skip
        key = draw(st.sampled_from([*fields, None]))
        value = draw(hostile_values())
        return Example(name, {f"{table}.{key}" if key else table: value})
    count = draw(st.integers(1, min(3, len(keys))))
    chosen = draw(st.lists(st.sampled_from(keys), min_size=count, max_size=count, unique=True))
    return Example(name, {k: draw(_value_for(base[k])) for k in chosen})


def _value_for(good: Any) -> st.SearchStrategy[Any]:
    """A hostile value, or (one time in three) a fair change of a good number, so that many
    calls get past the checks and run."""
    if isinstance(good, float) and not isinstance(good, bool):
        fair = st.floats(0.25, 4.0).map(lambda f: good * f if good else f - 1.0)
        return st.one_of(hostile_values(), hostile_values(), fair)
    return hostile_values()


def arguments(example: Example) -> tuple[Callable[..., Any], dict[str, Any]]:
    call, base = _base_calls()[example.target]
    kwargs = {k: (dict(v) if isinstance(v, dict) else v) for k, v in base.items()}
    for key, value in example.changes.items():
        if example.target == "scenario" and "." in key:
            table, sub = key.split(".", 1)
            kwargs[table] = {**kwargs[table], sub: value}
        else:
            kwargs[key] = value
    return call, kwargs


# Result fields where NaN is documented (no eclipse in an orbit, no umbra, a sample that failed).
NAN_ALLOWED = {
    "t_entry", "t_exit", "entry_theta_min", "exit_theta_max", "entry_peak", "exit_peak",
    "t_threshold", "eclipses", "critical_damping", "orbit_threshold", "orbit_limit",
    "amplitude_slope",
}  # fmt: skip


# Settings echoed in a result where +inf is the documented value "no cap" (max_step).
INF_ALLOWED = {"max_step"}


def _non_finite(value: Any, name: str = "") -> str | None:
    """The name of a non-finite number in a result, or None."""
    if name in NAN_ALLOWED:
        return None
    if isinstance(value, (bool, np.bool_, str, bytes)) or value is None:
        return None
    if isinstance(value, (float, int, np.number)):
        if name in INF_ALLOWED and value == math.inf:
            return None
        return None if np.isfinite(value) else name or "value"
    if isinstance(value, np.ndarray):
        if value.dtype.kind in "fc" and not np.all(np.isfinite(value)):
            return name or "array"
        return None
    if hasattr(value, "to_numpy") and hasattr(value, "columns"):  # a DataFrame
        failed = value["error"].notna() if "error" in value.columns else None
        for col in value.columns:
            if col in NAN_ALLOWED or value[col].dtype.kind not in "fc":
                continue
            bad = ~np.isfinite(value[col].to_numpy(float))
            if failed is not None:
                bad &= ~failed.to_numpy()
            if bad.any():
                return str(col)
        return None
    if isinstance(value, dict):
        for k, v in value.items():
            found = _non_finite(v, str(k))
            if found:
                return found
        return None
    if isinstance(value, (list, tuple)):
        if name == "" and value and all(isinstance(v, tuple) and len(v) == 5 for v in value):
            return None
        for v in value:
            found = _non_finite(v, name)
            if found:
                return found
        return None
    if hasattr(value, "__dict__"):
        return _non_finite({k: v for k, v in vars(value).items() if not k.startswith("_")}, name)
    return None


def _eclipse_rows(rows: Any) -> str | None:
    """``Orbit.eclipses`` rows (deepest point, first contact, last contact, umbra entry, umbra
    exit): the first three finite; the umbra pair NaN together (documented: a penumbral eclipse
    has no umbra) or finite inside the contacts."""
    rows = np.asarray(rows, dtype=float)
    if rows.ndim != 2 or rows.shape[1] != 5:
        return f"eclipses of shape {rows.shape}"
    if not np.all(np.isfinite(rows[:, :3])):
        return "eclipses[:, :3]"
    umbra = rows[:, 3:]
    none = np.isnan(umbra).all(axis=1)
    inside = np.isfinite(umbra).all(axis=1)
    inside &= (
        (rows[:, 1] <= umbra[:, 0]) & (umbra[:, 0] <= umbra[:, 1]) & (umbra[:, 1] <= rows[:, 2])
    )
    if not np.all(none | inside):
        return "eclipses[:, 3:]"
    return None


def classify(example: Example) -> tuple[str, str]:
    """Runs one example here and returns (outcome, detail)."""
    import thermojitter as tj

    call, kwargs = arguments(example)
    try:
        result = call(**kwargs)
    except tj.InternalError as exc:
        return "internal_error", str(exc)[:200]
    except (tj.IntegrationError, tj.ConvergenceError) as exc:
        if example.invalid:  # a run began: the boundary let the value through
            return "accepted_invalid", f"ran, then {type(exc).__name__}: {exc}"[:200]
        return "runtime_error", str(exc)[:200]
    except (ValueError, TypeError) as exc:
        message = str(exc)
        if example.invalid:
            (arg,) = example.changes
            if names_parameter(exc, arg):
                return "refused_named", message[:200]
            named = getattr(exc, "parameter", None)
            return "wrong_name", f"{type(exc).__name__} naming {named!r}: {message}"[:200]
        named = getattr(exc, "parameter", None) or getattr(exc, "key", None)
        if not named and example.target == "scenario file":
            named = getattr(exc, "path", None)  # the file itself is what is wrong
        if not named:
            names = [k.split(".")[-1] for k in example.changes]
            named = next((n for n in names if n and n in message), None)
        return ("refused_named" if named else "refused_unnamed"), message[:200]
    except Exception as exc:
        return "other_exception", f"{type(exc).__name__}: {exc}"[:200] + traceback.format_exc(
            limit=-2
        )[-300:]
    except BaseException as exc:  # PanicException derives from BaseException
        if type(exc).__name__ == "PanicException":
            return "panic", str(exc)[:200]
        raise
    if example.invalid:
        return "accepted_invalid", f"returned {type(result).__name__}"
    bad = _eclipse_rows(result) if example.target == "eclipses" else _non_finite(result)
    if bad:
        return "silent_nan", f"{bad} is not finite"
    if example.target == "checkpoint":
        # A damaged checkpoint is refused or recomputed; what it returns is the run itself.
        reference = checkpoint_reference()[1]
        for name, column in reference.columns.items():
            if not np.array_equal(column, result.columns[name], equal_nan=True):
                return "wrong_result", f"{name} differs from the run's own"
    return "ok", ""


def _worker(conn: Any) -> None:
    import warnings

    warnings.simplefilter("ignore")
    while True:
        example = conn.recv()
        if example is None:
            return
        conn.send(classify(example))


def _cpu_seconds(pid: int) -> float | None:
    """CPU time (user + system, every thread) the process ``pid`` has used, s; None where /proc
    cannot tell."""
    try:
        fields = open(f"/proc/{pid}/stat").read().rsplit(")", 1)[1].split()  # noqa: SIM115
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    except (OSError, IndexError, ValueError):
        return None


class Runner:
    """Runs examples in a worker process, one at a time, with a watchdog: a worker that dies
    (abort) or does not answer (hang) is counted and replaced.

    A hang is judged by the CPU time the worker spends on the call (every thread), not by the
    clock: other jobs share the machine, and a call that waits for a core is not hanging. A call
    is a hang once it has used ``limit`` s of CPU, or (a worker stuck without computing, or where
    the CPU time is unknown) ``wall_factor`` × ``limit`` s of wall time. ``last_cpu`` and
    ``last_wall`` hold the last call's figures.
    """

    def __init__(self, limit: float = 20.0, wall_factor: float = 6.0) -> None:
        self.limit = limit
        self.wall_limit = wall_factor * limit
        self.ctx = mp.get_context("spawn")
        self.proc: Any = None
        self.conn: Any = None
        self.last_cpu = 0.0
        self.last_wall = 0.0

    def _start(self) -> None:
        parent, child = self.ctx.Pipe()
        self.proc = self.ctx.Process(target=_worker, args=(child,), daemon=True)
        self.proc.start()
        self.conn = parent

    def run(self, example: Example) -> tuple[str, str]:
        if self.proc is None or not self.proc.is_alive():
            self._start()
        try:
            self.conn.send(example)
        except (BrokenPipeError, OSError):
            self._start()
            self.conn.send(example)
        cpu0 = _cpu_seconds(self.proc.pid) or 0.0
        start = time.monotonic()
        answered = False
        while True:
            if self.conn.poll(0.05):
                answered = True
                break
            cpu = _cpu_seconds(self.proc.pid)
            self.last_cpu = (cpu - cpu0) if cpu is not None else 0.0
            self.last_wall = time.monotonic() - start
            if not self.proc.is_alive() or self.last_cpu > self.limit:
                break
            if self.last_wall > self.wall_limit or (cpu is None and self.last_wall > self.limit):
                break
        cpu = _cpu_seconds(self.proc.pid)
        if cpu is not None:
            self.last_cpu = cpu - cpu0
        self.last_wall = time.monotonic() - start
        if answered:
            try:
                return self.conn.recv()  # type: ignore[no-any-return]
            except (EOFError, OSError):  # the worker died while answering
                pass
        if self.proc.is_alive():
            self.proc.kill()
            self.proc.join()
            self.proc = None
            return "hang", (
                f"no answer after {self.last_cpu:.1f} s of CPU ({self.last_wall:.1f} s wall); "
                f"limits {self.limit:g} s CPU, {self.wall_limit:g} s wall"
            )
        code = self.proc.exitcode
        self.proc = None
        return "abort", f"worker died (exit code {code})"

    def close(self) -> None:
        if self.proc is not None and self.proc.is_alive():
            self.conn.send(None)
            self.proc.join(5)
            if self.proc.is_alive():
                self.proc.kill()
