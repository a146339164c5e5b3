"""``thermojitter run SCENARIO.toml --out DIR``: one simulation from a scenario file, as a time
series (``keep = "samples"``) or as one summary per orbit (``keep = "orbits"``, resumable)."""

from __future__ import annotations

import argparse
import json
import math
import textwrap
import time
import warnings
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from thermojitter.attitude import has_face_loads
from thermojitter.cli.common import STOP, Interrupted, UserError, add_out, out_dir, write_output
from thermojitter.errors import ParameterError, ValidityLimitWarning
from thermojitter.progress import progress_bar, report_interrupted
from thermojitter.scenario import (
    ATTITUDE_KEYS,
    BOOM_KEYS,
    LAMINATE_KEYS,
    LAMINATE_PANEL_KEYS,
    LAYER_KEYS,
    Scenario,
    ScenarioError,
    load_scenario,
)

MAX_ROWS = 20_000_000
"""Largest time series ``run`` will keep (rows); more asks for a larger dt_out."""

MAX_ORBITS = 100_000
"""Longest run ``run`` accepts, in orbits (about 270 years of GEO)."""

COLUMNS = ("T_front", "T_back", "theta", "theta_dot", "thermal_moment", "sunlit")
SERIES_UNITS = {
    "t": "s", "T_front": "K", "T_back": "K", "theta": "rad", "theta_dot": "rad/s",
    "thermal_moment": "N m", "sunlit": "-", "flux_front": "W/m²", "flux_back": "W/m²",
}  # fmt: skip
"""The unit of each column of the time series: in the CSV header (``t [s]``), and in the
Parquet file's ``attrs["units"]``; a node's temperature (``T_node07 (core)``) is in K.
``flux_front`` and ``flux_back`` (the flux reaching each face) are kept when the orbit heats the
panel from the Earth or the attitude is not Sun-pointing."""
FLUX_COLUMNS = ("flux_front", "flux_back")


def series_units(names: Sequence[str]) -> dict[str, str]:
    """The unit of each of the time series' columns ``names``."""
    return {name: SERIES_UNITS.get(name, "K" if name.startswith("T_") else "-") for name in names}


def scenario_keys_help() -> str:
    """Every key of the tables of a scenario, for ``run --help`` (the names come from the
    code, so none is missing)."""
    from dataclasses import fields

    from thermojitter import _core
    from thermojitter.orbit import Orbit
    from thermojitter.scenario import SimulationSettings

    def table(name: str, keys: list[str], note: str) -> str:
        body = textwrap.fill(", ".join(keys) + "; " + note, width=86, break_on_hyphens=False)
        return f"[{name}]\n" + textwrap.indent(body, "  ")

    return "\n".join(
        [
            table("panel", list(_core.PANEL_FIELDS), "SI units, Table 1 for the rest"),
            table(
                "laminate",
                [*LAMINATE_KEYS, "layers"],
                "a layup in place of a plain panel ([panel] then gives only "
                + ", ".join(LAMINATE_PANEL_KEYS)
                + "); each [[laminate.layers]], front first, has "
                + ", ".join(LAYER_KEYS)
                + " (material = a tj.materials key, or every property)",
            ),
            table(
                "boom",
                list(BOOM_KEYS),
                "a thin-walled tube in place of [panel] (length, radius, wall required; "
                "material = a tj.materials key; SI units, angles in rad or _deg)",
            ),
            table(
                "orbit",
                ["preset", "start_date", "altitude", *(f.name for f in fields(Orbit))],
                'preset = "geo_equinox" | "geo_year" (start_date = YYYY-MM-DD) | "leo" '
                '(altitude, m) | "circular" (altitude, start_date; Earth heating on) | '
                '"sunlit"; shadow = "none" | "cylindrical" | "penumbra" (or "conical")',
            ),
            table(
                "simulation",
                [f.name for f in fields(SimulationSettings)],
                "the span is one of t_end (s), orbits, years; model = nonlinear | linear; "
                "method = rk45 | rk4 (dt = step, s) | hybrid (keep = orbits; its default); "
                'dt_out = output interval, s; keep = "samples" | "orbits" (one summary row per '
                'orbit, resumable, with theta_limit_deg and on_limit = "stop" | "flag"); '
                "layers = nodes through "
                "the thickness (the N-node model); max_steps = the run's step budget",
            ),
            table(
                "attitude",
                list(ATTITUDE_KEYS),
                'kind = "sun_pointing" | "sun_tracking" (offset, rad) | "nadir" | "inertial" '
                "(normal = [x, y, z], the equatorial frame)",
            ),
            table("output", ["format", "plots"], 'format = "csv" | "parquet"; plots = true'),
        ]
    )


def _chunks(t0: float, t1: float, period: float) -> list[tuple[float, float]]:
    """[t0, t1] cut at every whole orbit after t0 (one progress step per orbit)."""
    n = max(1, math.ceil((t1 - t0) / period - 1e-9))
    edges = [t0 + k * period for k in range(n)] + [t1]
    return [(a, b) for a, b in zip(edges[:-1], edges[1:], strict=True) if b > a]


def simulate_scenario(
    scenario: Scenario, *, progress: bool = True, stop: Any = None
) -> tuple[dict[str, Any], dict[str, Any], bool]:
    """Runs a scenario orbit by orbit (each continuing from the last state).

    Returns (columns with "t", counters, interrupted). On Ctrl-C (or when ``stop()`` turns
    True, polled after each orbit) the orbits finished so far are returned with
    interrupted = True."""
    from thermojitter.simulate import simulate

    sim = scenario.simulation
    t0, t1 = sim.span(scenario.orbit)
    n_rows = (t1 - t0) / sim.dt_out + 1
    if n_rows > MAX_ROWS:
        raise ScenarioError(
            scenario.source,
            "simulation.dt_out",
            f"{sim.dt_out} s over {t1 - t0:.6g} s gives {n_rows:.3g} rows, more than "
            f"{MAX_ROWS:.0e}: choose a larger dt_out",
        )
    n_orbits = (t1 - t0) / scenario.orbit.period
    if n_orbits > MAX_ORBITS:
        raise ScenarioError(
            scenario.source,
            "simulation",
            f"the span covers {n_orbits:.3g} orbits, more than {MAX_ORBITS:.0e}: shorten it",
        )
    grid = t0 + sim.dt_out * np.arange(int(math.floor((t1 - t0) / sim.dt_out)) + 1)
    if grid[-1] < t1:
        grid = np.append(grid, t1)
    pieces: list[dict[str, np.ndarray]] = []
    counters = {"n_steps": 0, "n_rejected": 0, "n_rhs": 0}
    chunks = _chunks(t0, t1, scenario.orbit.period)
    loaded = has_face_loads(scenario.orbit, scenario.attitude)
    node_names: tuple[str, ...] = ()
    y0: Any = None
    interrupted = False
    bar: Any = None
    if len(chunks) > 1:
        bar = progress_bar(len(chunks), unit="orbit", desc="run", enabled=progress, delay=2.0)
    try:
        for i, (a, b) in enumerate(chunks):
            last = i == len(chunks) - 1
            inside = grid[(grid >= a) & (grid < b)]
            t_eval = np.append(inside, b)
            sol = simulate(
                scenario.panel,
                scenario.orbit,
                (a, b),
                model=sim.model,  # type: ignore[arg-type]
                coupled=sim.coupled,
                solver=sim.solver,
                t_eval=t_eval,
                y0=y0,
                layers=sim.layers,
                attitude=scenario.attitude,
            )
            # the sample at b starts the next orbit's piece; only the last piece keeps its end
            keep = slice(None) if last else slice(0, len(inside))
            # A boom's columns are its own (T_mean, T_circ in place of T_front, T_back).
            names_of = sol._columns() if not hasattr(sol, "T_front") else COLUMNS
            piece = {"t": sol.t[keep], **{c: getattr(sol, c)[keep] for c in names_of}}
            # With layers = N: a column per node, named as in Solution.to_pandas().
            if loaded:
                piece.update({c: getattr(sol, c)[keep] for c in FLUX_COLUMNS})
            node_names = getattr(sol, "node_columns", ())
            nodes = getattr(sol, "T_nodes", None)
            if nodes is not None:
                piece.update({n: nodes[keep, k] for k, n in enumerate(node_names)})
            pieces.append(piece)
            for key in counters:
                counters[key] += int(getattr(sol, key))
            y0 = [float(v) for v in sol.y_end]
            if bar is not None:
                bar.update(1)
            if stop is not None and stop() and not last:
                raise KeyboardInterrupt
    except KeyboardInterrupt:
        interrupted = True
    finally:
        if bar is not None:
            bar.close()
    names = tuple(pieces[0]) if pieces else ("t", *COLUMNS)
    columns = {
        name: np.concatenate([p[name] for p in pieces]) if pieces else np.empty(0) for name in names
    }
    return columns, counters, interrupted


def check_writer(fmt: str) -> None:
    """Imports what writing ``fmt`` needs before a run starts: a missing package is said at once,
    not after hours, and the write after Ctrl-C does not pay for the import."""
    try:
        import pandas  # noqa: F401
    except ImportError:
        raise UserError(
            "writing time series needs pandas: pip install 'thermojitter[cli]'"
        ) from None
    if fmt == "parquet":
        try:
            import pyarrow  # noqa: F401
        except ImportError:
            raise UserError("Parquet output needs pyarrow: pip install pyarrow") from None


def write_series(
    path: Path, columns: dict[str, np.ndarray], fmt: str, units: dict[str, str] | None = None
) -> Path:
    """Writes the table ``columns`` as ``path``.csv or .parquet; ``units`` (by column) go in the
    CSV header as ``name [unit]`` and in the Parquet file's ``attrs["units"]``."""
    check_writer(fmt)
    import pandas as pd

    frame = pd.DataFrame(columns)
    if units:
        frame.attrs["units"] = dict(units)
    if fmt == "parquet":
        try:
            import pyarrow  # noqa: F401
        except ImportError:
            raise UserError("Parquet output needs pyarrow: pip install pyarrow") from None
        target = path.with_suffix(".parquet")
        return write_output(target, lambda fh: frame.to_parquet(fh, index=False))
    target = path.with_suffix(".csv")
    if units:
        frame.columns = [f"{c} [{units[c]}]" if c in units else c for c in frame.columns]
    # Shortest round-trip representation of each float.
    return write_output(target, lambda fh: fh.write(frame.to_csv(index=False).encode()))


def orbit_figures(
    out: Path,
    scenario: Scenario,
    t: np.ndarray | None = None,
    columns: dict[str, np.ndarray] | None = None,
) -> list[Path]:
    """The figures of the orbit's environment: ``orbit_year.png`` (β and the eclipses over a
    year from the run's start) when the Sun follows the year (``season``), and ``fluxes.png``
    (the flux on each face over the time series) when the run keeps the fluxes."""
    from thermojitter.reports.plots import face_flux_figure, orbit_year_figure, save

    title = Path(scenario.source).stem
    written = []
    if scenario.orbit.season:
        t0 = scenario.simulation.t_start
        fig = orbit_year_figure(scenario.orbit, t0, title=title)
        written.append(save(fig, out / "orbit_year.png"))
    if t is not None and columns is not None and "flux_front" in columns:
        fig = face_flux_figure(
            t, columns["flux_front"], columns["flux_back"], scenario.orbit, title=title
        )
        written.append(save(fig, out / "fluxes.png"))
    return written


def run_orbits_command(args: argparse.Namespace, scenario: Scenario, out: Path) -> int:
    """`run` with keep = "orbits": one summary row per orbit, resumable from out/checkpoint.json."""
    from thermojitter.longrun import simulate_orbits

    sim = scenario.simulation
    n = sim.n_orbits(scenario.orbit)
    n_orbits = max(1, int(round(n)))
    # A span in years is rounded to whole orbits; an explicit one must already be whole.
    if sim.years is None and abs(n - n_orbits) > 1e-6 * max(n, 1.0):
        raise ScenarioError(
            scenario.source, "simulation", f"keep = 'orbits' needs whole orbits; the span is {n:g}"
        )
    span_key = "simulation." + next(
        (k for k in ("years", "orbits", "t_end") if getattr(sim, k) is not None), "orbits"
    )
    if n_orbits > MAX_ORBITS:
        raise ScenarioError(
            scenario.source,
            span_key,
            f"the span covers {n:.3g} orbits, more than {MAX_ORBITS:.0e}: shorten it",
        )
    fmt = args.format or scenario.output.format
    check_writer(fmt)
    started = time.perf_counter()
    try:
        with warnings.catch_warnings():
            # The command says where |θ| passed the limit in its own last line.
            warnings.simplefilter("ignore", ValidityLimitWarning)
            runs = simulate_orbits(
                scenario.panel,
                scenario.orbit,
                n_orbits,
                t_start=sim.t_start,
                model=sim.model,  # type: ignore[arg-type]
                coupled=sim.coupled,
                method=sim.method,  # type: ignore[arg-type]
                solver=sim.solver,
                theta_limit=math.radians(sim.theta_limit_deg),
                on_limit=sim.on_limit,  # type: ignore[arg-type]
                layers=sim.layers,
                checkpoint=out / "checkpoint.json",
                progress=not args.no_progress,
                stop=STOP,
                attitude=scenario.attitude,
            )
    except ParameterError as exc:
        if exc.parameter != "n_orbits":
            raise
        # The span is the scenario's key (a budget refusal, said in its own words).
        raise ScenarioError(scenario.source, span_key, f"{n_orbits} orbits {exc.allowed}") from None
    written = [write_series(out / "orbits", dict(runs.columns), fmt).name]
    if scenario.output.plots and not args.no_plots and len(runs) > 1 and not runs.interrupted:
        from thermojitter.reports.plots import orbit_summary_figure

        written.append(orbit_summary_figure(out, runs.columns, Path(scenario.source).stem).name)
        written += [p.name for p in orbit_figures(out, scenario)]
    crossing = runs.limit_crossing
    files = [*written, "run.json", "checkpoint.json"]
    meta: dict[str, Any] = {
        "scenario": scenario.source,
        "keep": "orbits",
        "orbits_requested": n_orbits,
        "orbits_done": len(runs),
        "interrupted": runs.interrupted,
        "limit_crossing": None
        if crossing is None
        else {"t_s": crossing[0], "orbit": crossing[1], "theta_deg": math.degrees(crossing[2])},
        "n_steps": runs.n_steps,
        "n_rhs": runs.n_rhs,
        "propagation": runs.propagation,
        "settings": runs.settings,
        "columns": "angles in rad, times in s; see thermojitter.OrbitSummaries",
        "files": files,
        "wall_time_s": round(time.perf_counter() - started, 2),
    }
    write_output(
        out / "run.json", lambda fh: fh.write((json.dumps(meta, indent=2) + "\n").encode())
    )
    if runs.interrupted:
        report_interrupted(
            f"kept {len(runs)} of {n_orbits} orbits in {out / 'checkpoint.json'}",
            "run the same command again to resume",
        )
        raise Interrupted
    note = ""
    if crossing is not None:
        note = (
            f"; |θ| passed {sim.theta_limit_deg:g}° at t = {crossing[0]:.0f} s "
            f"(orbit {crossing[1]})"
        )
    print(
        f"wrote {', '.join(meta['files'])} to {args.out} ({len(runs)} orbits, "
        f"{runs.n_steps} steps, {meta['wall_time_s']} s{note})"
    )
    return 0


def run_command(args: argparse.Namespace) -> int:
    scenario = load_scenario(args.scenario)
    out = out_dir(args.out, args.overwrite)
    if scenario.simulation.keep == "orbits":
        return run_orbits_command(args, scenario, out)
    fmt = args.format or scenario.output.format
    check_writer(fmt)
    make_plots = scenario.output.plots and not args.no_plots
    started = time.perf_counter()
    columns, counters, interrupted = simulate_scenario(
        scenario, progress=not args.no_progress, stop=STOP
    )
    t = columns["t"]
    written = []
    if len(t):
        units = series_units(list(columns))
        written.append(write_series(out / "timeseries", columns, fmt, units).name)
    intervals = scenario.orbit.shadow_intervals(float(t[0]), float(t[-1])) if len(t) else []
    if make_plots and len(t) > 1 and not interrupted:
        from thermojitter.reports.plots import run_figures

        title = Path(scenario.source).stem
        written += [p.name for p in run_figures(out, t, columns, scenario.orbit, title=title)]
        written += [p.name for p in orbit_figures(out, scenario, t, columns)]
    sim = scenario.simulation
    files = [*written, "run.json"]
    meta = {
        "scenario": scenario.source,
        "interrupted": interrupted,
        "panel": scenario.panel.as_dict(),
        "orbit": scenario.orbit.as_dict(),
        "simulation": {
            "t_span_s": list(sim.span(scenario.orbit)),
            "model": sim.model,
            "coupled": sim.coupled,
            "method": sim.method,
            "rtol": sim.rtol,
            "atol": sim.atol,
            "dt": sim.dt,
            "dt_out": sim.dt_out,
            "layers": sim.layers,
            **counters,
        },
        "shadow_intervals_s": [list(iv) for iv in intervals],
        # The unit of each column (a boom's are T_mean, T_circ in place of T_front, T_back).
        "columns": {**series_units(list(columns)), "sunlit": "illuminated fraction"},
        "theta_min_deg": float(np.degrees(columns["theta"].min())) if len(t) else None,
        "theta_max_deg": float(np.degrees(columns["theta"].max())) if len(t) else None,
        "files": files,
        "wall_time_s": round(time.perf_counter() - started, 2),
    }
    write_output(
        out / "run.json", lambda fh: fh.write((json.dumps(meta, indent=2) + "\n").encode())
    )
    if interrupted:
        report_interrupted(
            f"kept {len(t)} samples up to t = {t[-1] if len(t) else 0:.0f} s in {args.out}",
            "run the command again for the whole span",
        )
        raise Interrupted
    print(
        f"wrote {', '.join(files)} to {args.out} ({len(t)} samples, "
        f"{counters['n_steps']} steps, {meta['wall_time_s']} s)"
    )
    return 0


def add_parser(sub: Any) -> None:
    run = sub.add_parser(
        "run",
        help="run one simulation from a TOML scenario file",
        description=(
            "Run one simulation from a TOML scenario file and write the time series "
            "(timeseries.csv or .parquet: t [s], T_front, T_back [K], theta [rad], "
            "theta_dot [rad/s], thermal_moment [N m], sunlit [-]; the CSV header says the "
            "units, the Parquet file's attrs['units']), run.json (settings, step counts) "
            'and plots (temperatures.png, theta.png) into --out; with keep = "orbits", one '
            "summary row per orbit (orbits.csv, orbits.png), resumable from checkpoint.json. "
            "With Earth heating or an [attitude], the flux reaching each face (flux_front, "
            "flux_back [W/m2], fluxes.png); with the Sun following the year (season), "
            "orbit_year.png (beta and every eclipse's length over a year from the start)."
        ),
        epilog="Scenario keys (every table and key optional):\n"
        + scenario_keys_help()
        + "\n\nExample: thermojitter run examples/paper.toml --out out/run",
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    run.add_argument("scenario", metavar="SCENARIO.toml", help="the scenario file")
    add_out(run, required=True, help="output folder (created)")
    run.add_argument(
        "--format", choices=("csv", "parquet"), help="override [output] format of the file"
    )
    run.add_argument("--no-plots", action="store_true", help="write no plots")
    run.add_argument("--no-progress", action="store_true", help="no progress bar")
    run.set_defaults(handler=run_command, stop_flag=True)
