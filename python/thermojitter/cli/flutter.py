"""``thermojitter flutter [SCENARIO.toml] --out DIR``: the flutter analysis of a scenario.

Prints the sunlit equilibrium, the growth rate, frequency and critical damping for the
non-linear and the linear hinge, the closed-form estimate of paper Sec. 4.2, and the critical
damping at perihelion and aphelion flux; writes ``stability_map.png`` (growth rate over two panel
parameters with its zero contour) and ``flutter.json`` into DIR.

The scenario is a TOML file. Its ``[panel]`` table sets any :class:`~thermojitter.Panel` field
(Table 1 for the rest); an optional ``[orbit]`` table (``preset`` = "geo_equinox" | "geo_year" |
"leo" | "sunlit", ``start_date``, ``altitude``, or :class:`~thermojitter.Orbit` fields) gives the
flux at t = 0; an optional ``[flutter]`` table sets ``model``, ``coupled``, ``flux``, ``x`` and
``y`` (as on the command line). Other tables are ignored, so the scenario files of
``thermojitter run`` work here too.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path
from typing import Any, Literal, cast

import numpy as np

from thermojitter import _core
from thermojitter.cli.common import Command, UserError, add_out, out_dir, write_output
from thermojitter.flutter import (
    FlutterResult,
    flutter,
    linear_thermal_response,
    stability_map,
)
from thermojitter.orbit import Orbit
from thermojitter.panel import Panel
from thermojitter.scenario import ScenarioError, load_scenario

DEFAULT_X = "damping:0:5:51"
DEFAULT_Y = "conductance:5:60:56"
ModelName = Literal["nonlinear", "linear"]
MODELS: tuple[ModelName, ...] = ("nonlinear", "linear")
FLUTTER_KEYS = ("model", "coupled", "flux", "x", "y")
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
        "--uncoupled", action="store_true", help="freeze the projected area (no pumping)"
    )
    parser.add_argument("--no-plot", action="store_true", help="skip the PNG")


def run(args: argparse.Namespace) -> int:
    panel, orbit, options = Panel.paper(), Orbit.geo_equinox(), {}
    source = "Table 1 (paper), GEO equinox"
    if args.scenario is not None:
        path = Path(args.scenario)
        try:
            scenario = load_scenario(path, extra_sections=("flutter",))
        except ScenarioError as e:
            raise UserError(str(e)) from None
        if not isinstance(scenario.panel, Panel):
            raise UserError(
                f"{path}: boom: the flutter command maps a [panel]; a boom's analysis is "
                "tj.flutter(boom) and tj.boom_stability_map"
            )
        panel, orbit, options = scenario.panel, scenario.orbit, scenario.extra["flutter"]
        unknown = set(options) - set(FLUTTER_KEYS)
        if unknown:
            raise UserError(f"{path}: flutter.{sorted(unknown)[0]}: unknown key")
        source = str(path)
    raw_model = args.model or options.get("model", "nonlinear")
    if raw_model not in MODELS:
        raise UserError(f"model = {raw_model!r}: must be 'nonlinear' or 'linear'")
    model = cast(ModelName, raw_model)
    coupled = not args.uncoupled and options.get("coupled", True) is not False
    if args.flux is not None:
        flux = float(args.flux)
    elif "flux" in options:
        flux = _number(Path(source), "flutter.flux", options["flux"])
    else:
        flux = float(orbit.flux_scale(0.0)[0])
    if not (math.isfinite(flux) and flux > 0.0):
        raise UserError(f"flux = {flux}: must be finite and > 0")
    x = parse_axis(args.x or options.get("x", DEFAULT_X), "x")
    y = parse_axis(args.y or options.get("y", DEFAULT_Y), "y")
    if x[0] == y[0]:
        raise UserError(f"x and y are both {x[0]!r}: choose two different parameters")
    # The folder is checked before any work: a non-empty one is refused at once, not after the
    # whole analysis is printed.
    out = out_dir(args.out, args.overwrite)

    try:
        results = {m: flutter(panel, m, coupled=coupled, flux=flux) for m in MODELS}
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
    lines = [
        f"thermal flutter analysis: {source}",
        f"  writing to {out}/"
        + (" (the default; --out DIR to choose)" if args.out == DEFAULT_OUT else ""),
        f"  flux factor {flux:.4f}, projected area {'coupled' if coupled else 'frozen'}, "
        f"c_d = {panel.damping:g} N m s/rad",
        f"  sunlit equilibrium: T_front {eq.T_front:.2f} K, T_back {eq.T_back:.2f} K, "
        f"theta {math.degrees(eq.theta):.3f} deg",
    ]
    for m, r in results.items():
        lines.append(
            f"  {m:9s}: growth rate {r.growth_rate:+.4e} 1/s ("
            + ("stable" if r.stable else f"flutter, e-folding {r.e_folding_time / 3600:.2f} h")
            + f"), frequency {r.frequency_hz:.5f} Hz, critical damping "
            f"{r.critical_damping:.4f} N m s/rad"
        )
    lines.append(
        f"  Sec. 4.2 closed form: q = {closed.q:.4g} 1/s, lag {math.degrees(closed.phase_lag):.1f}"
        f" deg at omega_n; critical damping ~ {closed.critical_damping_estimate:.4f} N m s/rad"
    )
    for m in MODELS:
        lines.append(
            f"  over the year ({m}): critical damping {seasonal[m]['perihelion']:.4f} at "
            f"perihelion (flux {peri:.4f}), {seasonal[m]['aphelion']:.4f} at aphelion "
            f"(flux {aph:.4f})"
        )
    print("\n".join(lines))

    png = out / "stability_map.png"
    if not args.no_plot:
        from thermojitter.reports.plots import stability_map_figure

        stability_map_figure(smap, panel, png)
    record = {
        "scenario": source,
        "panel": panel.as_dict(),
        "flux": flux,
        "coupled": coupled,
        "equilibrium": {
            "T_front_K": eq.T_front,
            "T_back_K": eq.T_back,
            "theta_deg": math.degrees(eq.theta),
        },
        "models": {m: _analysis_record(r) for m, r in results.items()},
        "closed_form": {
            "p_K_per_s": closed.p,
            "q_per_s": closed.q,
            "phase_lag_rad": closed.phase_lag,
            "amplitude_K": closed.amplitude,
            "thermal_damping_per_s": closed.thermal_damping,
            "critical_damping_estimate": closed.critical_damping_estimate,
        },
        "year": {
            "perihelion_flux": peri,
            "aphelion_flux": aph,
            "critical_damping": seasonal,
        },
        "map": {
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
