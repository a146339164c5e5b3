"""``thermojitter flutter [SCENARIO.toml] --out DIR``: the flutter analysis of a scenario.

Prints the sunlit equilibrium, the growth rate, frequency and critical damping for the
non-linear and the linear hinge, the closed-form estimate of paper Sec. 4.2, and the critical
damping at perihelion and aphelion flux; writes ``stability_map.png`` (growth rate over two panel
parameters with its zero contour) and ``flutter.json`` into DIR.

The scenario is a TOML file. Its ``[panel]`` table sets any :class:`~thermojitter.Panel` field
(Table 1 for the rest); an optional ``[orbit]`` table (``preset`` = "geo_equinox" | "geo_year" |
"leo" | "sunlit", ``start_date``, ``altitude``, or :class:`~thermojitter.Orbit` fields) gives the
flux at the point ``t`` of the orbit (0 by default); an optional ``[flutter]`` table sets
``model``, ``coupled``, ``flux``, ``t``, ``x`` and ``y`` (as on the command line). Other tables
are ignored, so the scenario files of ``thermojitter run`` work here too.

With Earth heating on the orbit (``albedo``, ``earth_ir``) or an ``[attitude]`` other than
Sun-pointing, the analysis is :func:`thermojitter.flutter` with that orbit, ``t`` and attitude:
the equilibrium in full sunlight under every load at ``t``. The closed form, the year's two
critical dampings and the map take the Sun alone (their functions know no other load), and say
so. A ``[boom]`` scenario is the tube's analysis (:func:`thermojitter.flutter` of the
:class:`~thermojitter.Boom`): growth rate and the critical damping ratio, and
``boom_stability.png``, the growth rate over the solar inclination at the boom's own ratio B of
the thermal to the structural response time (:func:`thermojitter.boom_stability_map`).
"""

from __future__ import annotations

import argparse
import json
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal, cast

import numpy as np

from thermojitter import _core
from thermojitter.attitude import Attitude, has_face_loads
from thermojitter.boom import Boom, BoomEquilibrium, boom_stability_map
from thermojitter.cli.common import Command, UserError, add_out, out_dir, write_output
from thermojitter.flutter import (
    FlutterResult,
    flutter,
    linear_thermal_response,
    stability_map,
)
from thermojitter.orbit import Orbit
from thermojitter.panel import Panel
from thermojitter.scenario import Scenario, ScenarioError, load_scenario

DEFAULT_X = "damping:0:5:51"
DEFAULT_Y = "conductance:5:60:56"
ModelName = Literal["nonlinear", "linear"]
MODELS: tuple[ModelName, ...] = ("nonlinear", "linear")
FLUTTER_KEYS = ("model", "coupled", "flux", "t", "x", "y")
"""Keys of the [flutter] table."""


def parse_axis(text: str, which: str) -> tuple[str, np.ndarray]:
    """``NAME:START:STOP:N`` → (name, N values from START to STOP)."""
    parts = str(text).split(":")
    if len(parts) != 4:
        raise UserError(f"{which} = {text!r}: expected NAME:START:STOP:N")
    name = parts[0]
    if name not in _core.PANEL_FIELDS:
        raise UserError(
            f"{which} = {text!r}: {name!r} is not a panel parameter; one of "
            + ", ".join(_core.PANEL_FIELDS)
        )
    try:
        start, stop, n = float(parts[1]), float(parts[2]), int(parts[3])
    except ValueError:
        raise UserError(f"{which} = {text!r}: START, STOP must be numbers, N an integer") from None
    if not (math.isfinite(start) and math.isfinite(stop)) or n < 1 or n > 2000:
        raise UserError(f"{which} = {text!r}: need finite bounds and 1 <= N <= 2000")
    return name, np.linspace(start, stop, n)


def _number(path: Path, key: str, value: Any) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise UserError(f"{path}: {key} must be a number, not {type(value).__name__}")
    return float(value)


def _analysis_record(r: FlutterResult) -> dict[str, Any]:
    return {
        "growth_rate_per_s": r.growth_rate,
        "e_folding_time_s": r.e_folding_time,
        "frequency_hz": r.frequency_hz,
        "critical_damping_N_m_s_per_rad": r.critical_damping,
        "stable": r.stable,
        "eigenvalues": [[z.real, z.imag] for z in r.eigenvalues],
    }


DEFAULT_OUT = "out/flutter"
"""Where ``thermojitter flutter`` writes without --out (relative to the working folder)."""


def options(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("scenario", nargs="?", help="TOML scenario (default: Table 1 at GEO)")
    add_out(parser, default=DEFAULT_OUT, help=f"output folder (created; default {DEFAULT_OUT})")
    parser.add_argument("--x", default=None, help=f"map x axis NAME:START:STOP:N ({DEFAULT_X})")
    parser.add_argument("--y", default=None, help=f"map y axis NAME:START:STOP:N ({DEFAULT_Y})")
    parser.add_argument("--model", choices=MODELS, default=None, help="hinge model of the map")
    parser.add_argument("--flux", type=float, default=None, help="solar flux factor (1 = 1 au)")
    parser.add_argument(
        "--t",
        type=float,
        default=None,
        help="the point of the orbit analysed, s (default 0): its flux, Earth heating, attitude",
    )
    parser.add_argument(
        "--uncoupled", action="store_true", help="freeze the projected area (no pumping)"
    )
    parser.add_argument("--no-plot", action="store_true", help="skip the PNG")


@dataclass(frozen=True)
class Inputs:
    """What the command analyses: the scenario's structure, orbit and attitude, the point ``t``
    of the orbit, and the flux factor (given, or the orbit's at ``t``)."""

    panel: Panel | Boom
    orbit: Orbit
    attitude: Attitude
    options: dict[str, Any]
    source: str
    t: float
    flux: float
    flux_given: bool
    coupled: bool

    @property
    def loaded(self) -> bool:
        """Whether more than the front's sunlight heats the panel (Earth heating, an attitude)."""
        return has_face_loads(self.orbit, self.attitude)

    def analyse(self, model: ModelName) -> FlutterResult:
        """:func:`thermojitter.flutter` on these inputs: at the given flux, or at ``t`` of the
        orbit (with its Earth heating and the attitude)."""
        if self.flux_given:
            return flutter(self.panel, model, coupled=self.coupled, flux=self.flux)  # type: ignore[arg-type]
        attitude = None if isinstance(self.panel, Boom) else self.attitude
        return flutter(
            self.panel,  # type: ignore[arg-type]
            model,
            coupled=self.coupled,
            orbit=self.orbit,
            t=self.t,
            attitude=attitude,
        )


def _inputs(args: argparse.Namespace) -> Inputs:
    """The scenario, the [flutter] table and the options, checked."""
    scenario = Scenario(source="Table 1 (paper), GEO equinox")
    options: dict[str, Any] = {}
    if args.scenario is not None:
        path = Path(args.scenario)
        try:
            scenario = load_scenario(path, extra_sections=("flutter",))
        except ScenarioError as e:
            raise UserError(str(e)) from None
        options = scenario.extra["flutter"]
        unknown = set(options) - set(FLUTTER_KEYS)
        if unknown:
            raise UserError(f"{path}: flutter.{sorted(unknown)[0]}: unknown key")
    source = scenario.source
    orbit, attitude = scenario.orbit, scenario.attitude
    if args.t is not None:
        t = float(args.t)
    elif "t" in options:
        t = _number(Path(source), "flutter.t", options["t"])
    else:
        t = 0.0
    if not math.isfinite(t):
        raise UserError(f"t = {t}: must be finite")
    coupled = not args.uncoupled and options.get("coupled", True) is not False
    flux_given = args.flux is not None or "flux" in options
    if args.flux is not None:
        flux = float(args.flux)
    elif "flux" in options:
        flux = _number(Path(source), "flutter.flux", options["flux"])
    else:
        try:
            flux = float(orbit.flux_scale(t)[0])
        except ValueError as e:
            raise UserError(f"t = {t:g}: {e}") from None
    if not (math.isfinite(flux) and flux > 0.0):
        raise UserError(f"flux = {flux}: must be finite and > 0")
    boom = isinstance(scenario.panel, Boom)
    if boom and attitude.kind != "sun_pointing":
        raise UserError(f"{source}: attitude.kind: a boom takes the Sun alone on its lit side")
    if boom and (orbit.albedo != 0.0 or orbit.earth_ir != 0.0):
        key = "albedo" if orbit.albedo != 0.0 else "earth_ir"
        raise UserError(
            f"{source}: orbit.{key}: a boom takes the Sun alone on its lit side (no Earth heating)"
        )
    if flux_given and has_face_loads(orbit, attitude):
        raise UserError(
            f"{source}: flux: the scenario's Earth heating or attitude sets the loads at the "
            "point t of the orbit; give t, not flux"
        )
    return Inputs(scenario.panel, orbit, attitude, options, source, t, flux, flux_given, coupled)


def _loads_line(inputs: Inputs) -> str:
    """What heats the panel at ``t``, in one line."""
    orbit = inputs.orbit
    parts = [f"at t = {inputs.t:g} s of the orbit"]
    if orbit.albedo != 0.0 or orbit.earth_ir != 0.0:
        parts.append(f"Earth heating (albedo {orbit.albedo:g}, infrared {orbit.earth_ir:g} W/m2)")
    if inputs.attitude.kind != "sun_pointing":
        parts.append(f"attitude {inputs.attitude.kind}")
    parts.append(f"beta {math.degrees(float(orbit.beta(inputs.t)[0])):.2f} deg")
    return "  loads " + ", ".join(parts)


def run(args: argparse.Namespace) -> int:
    inputs = _inputs(args)
    if isinstance(inputs.panel, Boom):
        out = out_dir(args.out, args.overwrite)
        return _boom_run(args, inputs, out)
    panel, flux, coupled, options = inputs.panel, inputs.flux, inputs.coupled, inputs.options
    raw_model = args.model or options.get("model", "nonlinear")
    if raw_model not in MODELS:
        raise UserError(f"model = {raw_model!r}: must be 'nonlinear' or 'linear'")
    model = cast(ModelName, raw_model)
    x = parse_axis(args.x or options.get("x", DEFAULT_X), "x")
    y = parse_axis(args.y or options.get("y", DEFAULT_Y), "y")
    if x[0] == y[0]:
        raise UserError(f"x and y are both {x[0]!r}: choose two different parameters")
    # The folder is checked before any work: a non-empty one is refused at once, not after the
    # whole analysis is printed.
    out = out_dir(args.out, args.overwrite)

    try:
        results = {m: inputs.analyse(m) for m in MODELS}
        closed = linear_thermal_response(panel, flux=flux)
        year = Orbit.geo_year("2026-01-01").flux_scale(np.arange(0.0, 366.0) * 86400.0)
        peri, aph = float(year.max()), float(year.min())
        seasonal = {
            m: {
                "perihelion": flutter(panel, m, coupled=coupled, flux=peri).critical_damping,
                "aphelion": flutter(panel, m, coupled=coupled, flux=aph).critical_damping,
            }
            for m in MODELS
        }
        smap = stability_map(panel, x=x, y=y, model=model, coupled=coupled, flux=flux)
    except ValueError as e:
        raise UserError(str(e)) from None

    eq = results["nonlinear"].equilibrium
    sun_only = " (the Sun alone)" if inputs.loaded else ""
    lines = [
        f"thermal flutter analysis: {inputs.source}",
        f"  writing to {out}/"
        + (" (the default; --out DIR to choose)" if args.out == DEFAULT_OUT else ""),
        f"  flux factor {flux:.4f}, projected area {'coupled' if coupled else 'frozen'}, "
        f"c_d = {panel.damping:g} N m s/rad",
    ]
    if inputs.loaded:
        lines.append(_loads_line(inputs))
    lines.append(
        f"  sunlit equilibrium: T_front {eq.T_front:.2f} K, T_back {eq.T_back:.2f} K, "
        f"theta {math.degrees(eq.theta):.3f} deg"
    )
    for m, r in results.items():
        lines.append(
            f"  {m:9s}: growth rate {r.growth_rate:+.4e} 1/s ("
            + ("stable" if r.stable else f"flutter, e-folding {r.e_folding_time / 3600:.2f} h")
            + f"), frequency {r.frequency_hz:.5f} Hz, critical damping "
            f"{r.critical_damping:.4f} N m s/rad"
        )
    lines.append(
        f"  Sec. 4.2 closed form{sun_only}: q = {closed.q:.4g} 1/s, lag "
        f"{math.degrees(closed.phase_lag):.1f} deg at omega_n; critical damping ~ "
        f"{closed.critical_damping_estimate:.4f} N m s/rad"
    )
    for m in MODELS:
        lines.append(
            f"  over the year ({m}{', the Sun alone' if inputs.loaded else ''}): critical "
            f"damping {seasonal[m]['perihelion']:.4f} at perihelion (flux {peri:.4f}), "
            f"{seasonal[m]['aphelion']:.4f} at aphelion (flux {aph:.4f})"
        )
    if inputs.loaded:
        lines.append(f"  stability map: the Sun alone at flux {flux:.4f}")
    print("\n".join(lines))

    png = out / "stability_map.png"
    if not args.no_plot:
        from thermojitter.reports.plots import stability_map_figure

        stability_map_figure(smap, panel, png)
    record = {
        **_point_record(inputs),
        "panel": panel.as_dict(),
        "equilibrium": {
            "T_front_K": eq.T_front,
            "T_back_K": eq.T_back,
            "theta_deg": math.degrees(eq.theta),
        },
        "models": {m: _analysis_record(r) for m, r in results.items()},
        "closed_form": {
            "sun_only": inputs.loaded,
            "p_K_per_s": closed.p,
            "q_per_s": closed.q,
            "phase_lag_rad": closed.phase_lag,
            "amplitude_K": closed.amplitude,
            "thermal_damping_per_s": closed.thermal_damping,
            "critical_damping_estimate": closed.critical_damping_estimate,
        },
        "year": {
            "sun_only": inputs.loaded,
            "perihelion_flux": peri,
            "aphelion_flux": aph,
            "critical_damping": seasonal,
        },
        "map": {
            "sun_only": inputs.loaded,
            "model": smap.model,
            "x_name": smap.x_name,
            "x": smap.x.tolist(),
            "y_name": smap.y_name,
            "y": smap.y.tolist(),
            "growth_rate": smap.growth_rate.tolist(),
            "frequency_hz": smap.frequency_hz.tolist(),
            "png": None if args.no_plot else png.name,
        },
    }
    write_output(out / "flutter.json", lambda fh: fh.write(json.dumps(record, indent=2).encode()))
    print(f"  wrote {out / 'flutter.json'}" + ("" if args.no_plot else f" and {png}"))
    return 0


def _point_record(inputs: Inputs) -> dict[str, Any]:
    """The analysed point in flutter.json: the scenario, the flux and what set it."""
    return {
        "scenario": inputs.source,
        "flux": inputs.flux,
        "coupled": inputs.coupled,
        "t_s": None if inputs.flux_given else inputs.t,
        "orbit": None if inputs.flux_given else inputs.orbit.as_dict(),
        "attitude": inputs.attitude.as_dict(),
        "earth_heating": inputs.orbit.albedo != 0.0 or inputs.orbit.earth_ir != 0.0,
    }


BOOM_INCLINATIONS_DEG = np.linspace(5.0, 175.0, 35)
"""The solar inclinations ψ of a boom's stability sweep, deg."""


def _boom_run(args: argparse.Namespace, inputs: Inputs, out: Path) -> int:
    """The tube's analysis: growth rate, frequency and critical damping ratio at the scenario's
    point, the same at perihelion and aphelion flux, and the sweep over ψ at the boom's own B."""
    boom = cast(Boom, inputs.panel)
    if args.x or args.y or args.model or any(k in inputs.options for k in ("x", "y", "model")):
        raise UserError(
            f"{inputs.source}: x, y and model map a panel; a boom's sweep is over its solar "
            "inclination at its own response-time ratio"
        )
    try:
        result = inputs.analyse("nonlinear")
        year = Orbit.geo_year("2026-01-01").flux_scale(np.arange(0.0, 366.0) * 86400.0)
        peri, aph = float(year.max()), float(year.min())
        seasonal = {
            "perihelion": flutter(boom, coupled=inputs.coupled, flux=peri).critical_damping,  # type: ignore[arg-type]
            "aphelion": flutter(boom, coupled=inputs.coupled, flux=aph).critical_damping,  # type: ignore[arg-type]
        }
        sweep = boom_stability_map(
            boom,
            np.radians(BOOM_INCLINATIONS_DEG),
            [boom.response_time_ratio],
            coupled=inputs.coupled,
            flux=inputs.flux,
        )
    except ValueError as e:
        raise UserError(str(e)) from None
    eq = cast(BoomEquilibrium, result.equilibrium)
    verdict = (
        "stable" if result.stable else f"flutter, e-folding {result.e_folding_time / 3600:.2f} h"
    )
    print(
        "\n".join(
            [
                f"thermal flutter analysis of a boom: {inputs.source}",
                f"  writing to {out}/"
                + (" (the default; --out DIR to choose)" if args.out == DEFAULT_OUT else ""),
                f"  flux factor {inputs.flux:.4f}, incidence "
                f"{'coupled' if inputs.coupled else 'frozen'}, solar inclination "
                f"{math.degrees(boom.solar_inclination):.1f} deg, damping ratio {boom.damping:g}",
                f"  f1 {boom.first_frequency:.5f} Hz, tau {boom.time_constant:.4g} s, "
                f"B = omega1 tau {boom.response_time_ratio:.4g}",
                f"  sunlit equilibrium: T_mean {eq.T_mean:.2f} K, T_circ {eq.T_circ:.3f} K, "
                f"tip deflection {eq.tip_deflection:.4g} m",
                f"  tube: growth rate {result.growth_rate:+.4e} 1/s ({verdict}), frequency "
                f"{result.frequency_hz:.5f} Hz, critical damping ratio "
                f"{result.critical_damping:.4g}",
                f"  over the year: critical damping ratio {seasonal['perihelion']:.4g} at "
                f"perihelion (flux {peri:.4f}), {seasonal['aphelion']:.4g} at aphelion "
                f"(flux {aph:.4f})",
            ]
        )
    )
    png = out / "boom_stability.png"
    if not args.no_plot:
        from thermojitter.reports.plots import boom_stability_figure, save

        save(boom_stability_figure(sweep, boom), png)
    record = {
        **_point_record(inputs),
        "boom": boom.as_dict(),
        "equilibrium": {
            "T_mean_K": eq.T_mean,
            "T_circ_K": eq.T_circ,
            "theta_rad": eq.theta,
            "tip_deflection_m": eq.tip_deflection,
        },
        "tube": {
            "growth_rate_per_s": result.growth_rate,
            "e_folding_time_s": result.e_folding_time,
            "frequency_hz": result.frequency_hz,
            "critical_damping_ratio": result.critical_damping,
            "stable": result.stable,
            "eigenvalues": [[z.real, z.imag] for z in result.eigenvalues],
        },
        "year": {"perihelion_flux": peri, "aphelion_flux": aph, "critical_damping_ratio": seasonal},
        "sweep": {
            "ratio": boom.response_time_ratio,
            "solar_inclination_deg": BOOM_INCLINATIONS_DEG.tolist(),
            "growth_rate_per_s": sweep.growth_rate[:, 0].tolist(),
            "critical_damping_ratio": sweep.critical_damping[:, 0].tolist(),
            "png": None if args.no_plot else png.name,
        },
    }
    write_output(out / "flutter.json", lambda fh: fh.write(json.dumps(record, indent=2).encode()))
    print(f"  wrote {out / 'flutter.json'}" + ("" if args.no_plot else f" and {png}"))
    return 0


COMMAND = Command(
    "flutter",
    options,
    run,
    stop_flag=False,
    help="flutter analysis without integration: growth rate, critical damping, stability map",
    description="Flutter analysis of a scenario without integration: growth rate, "
    "frequency and critical damping at the sunlit equilibrium, and a stability map "
    "(stability_map.png, flutter.json).",
    epilog="Example: thermojitter flutter examples/paper.toml --out out/flutter",
)
add_parser = COMMAND.add_parser
flutter_command = COMMAND.main
