"""The ``thermojitter`` command.

    thermojitter paper --out DIR             reproduce the paper (figures, summary.json, report.md)
    thermojitter run SCENARIO.toml --out DIR one simulation from a scenario file

User errors (bad files, values, folders) are one line on stderr and exit code 2; Ctrl-C stops
with exit code 130 and keeps the files already written.
"""

from __future__ import annotations

import argparse
import json
import math
import signal
import sys
import threading
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, NoReturn

import numpy as np

from thermojitter import __version__
from thermojitter._core import ConvergenceError, IntegrationError
from thermojitter.scenario import Scenario, ScenarioError, load_scenario

EXIT_USER_ERROR = 2
EXIT_INTERRUPTED = 130
MAX_ROWS = 20_000_000
"""Largest time series ``run`` will keep (rows); more asks for a larger dt_out."""

MAX_ORBITS = 100_000
"""Longest run ``run`` accepts, in orbits (about 270 years of GEO)."""

COLUMNS = ("T_front", "T_back", "theta", "theta_dot", "thermal_moment", "sunlit")


class UserError(Exception):
    """A problem with what the user asked for: reported in one line, exit code 2."""


class _Interrupt:
    """Ctrl-C as a flag polled between orbits and figures, so the stop happens at a clean point
    (never inside matplotlib or a callback); a second Ctrl-C stops at once."""

    def __init__(self) -> None:
        self.requested = False
        self._previous: Any = None

    def __call__(self) -> bool:
        return self.requested

    def _handle(self, signum: int, frame: Any) -> None:
        if self.requested:
            raise KeyboardInterrupt
        self.requested = True

    def __enter__(self) -> _Interrupt:
        if threading.current_thread() is threading.main_thread():
            self._previous = signal.signal(signal.SIGINT, self._handle)
        return self

    def __exit__(self, *exc: object) -> None:
        if self._previous is not None:
            signal.signal(signal.SIGINT, self._previous)


_STOP = _Interrupt()


# --------------------------------------------------------------------------------------------
# paper


def _paper(args: argparse.Namespace) -> int:
    from thermojitter.paper import PaperOptions, run_paper

    base = (
        PaperOptions(dt_out=1.0, thermal_dt_out=5.0, flutter_hours=6.0)
        if args.quick
        else (PaperOptions())
    )
    options = PaperOptions(
        rtol=base.rtol,
        atol=base.atol,
        dt_out=args.dt_out if args.dt_out is not None else base.dt_out,
        thermal_dt_out=base.thermal_dt_out,
        flutter_hours=args.flutter_hours if args.flutter_hours is not None else base.flutter_hours,
    )
    started = time.perf_counter()
    summary = run_paper(_out_dir(args.out), options, progress=not args.no_progress, stop=_STOP)
    elapsed = time.perf_counter() - started
    print(
        f"wrote {len(summary['figures'])} figures, summary.json and report.md to {args.out} "
        f"in {elapsed:.1f} s: θ = {summary['theta_steady_deg']:.2f}°, eclipse "
        f"{summary['eclipse_duration_min']:.1f} min, jitter {summary['jitter_frequency_hz']:.4f}"
        f" Hz (beam f_n {summary['beam_frequency_hz']:.4f} Hz)"
    )
    return 0


# --------------------------------------------------------------------------------------------
# run


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
    y0: Any = None
    interrupted = False
    bar: Any = None
    if progress and len(chunks) > 1:
        from tqdm.auto import tqdm

        bar = tqdm(total=len(chunks), unit="orbit", desc="run", delay=2.0, leave=False)
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
                method=sim.method,  # type: ignore[arg-type]
                rtol=sim.rtol,
                atol=sim.atol,
                dt=sim.dt,
                t_eval=t_eval,
                y0=y0,
            )
            # the sample at b starts the next orbit's piece; only the last piece keeps its end
            keep = slice(None) if last else slice(0, len(inside))
            pieces.append({"t": sol.t[keep], **{c: getattr(sol, c)[keep] for c in COLUMNS}})
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
    names = ("t", *COLUMNS)
    columns = {
        name: np.concatenate([p[name] for p in pieces]) if pieces else np.empty(0) for name in names
    }
    return columns, counters, interrupted


def _write_series(path: Path, columns: dict[str, np.ndarray], fmt: str) -> Path:
    try:
        import pandas as pd
    except ImportError:
        raise UserError(
            "writing time series needs pandas: pip install 'thermojitter[cli]'"
        ) from None
    frame = pd.DataFrame(columns)
    if fmt == "parquet":
        target = path.with_suffix(".parquet")
        try:
            frame.to_parquet(target, index=False)
        except ImportError:
            raise UserError("Parquet output needs pyarrow: pip install pyarrow") from None
    else:
        target = path.with_suffix(".csv")
        frame.to_csv(target, index=False)  # shortest round-trip representation
    return target


def _run_orbits(args: argparse.Namespace, scenario: Scenario, out: Path) -> int:
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
    fmt = args.format or scenario.output.format
    started = time.perf_counter()
    runs = simulate_orbits(
        scenario.panel,
        scenario.orbit,
        n_orbits,
        t_start=sim.t_start,
        model=sim.model,  # type: ignore[arg-type]
        coupled=sim.coupled,
        method=sim.method,  # type: ignore[arg-type]
        rtol=sim.rtol,
        atol=sim.atol,
        dt=sim.dt,
        theta_limit=math.radians(sim.theta_limit_deg),
        on_limit=sim.on_limit,  # type: ignore[arg-type]
        checkpoint=out / "checkpoint.json",
        progress=not args.no_progress,
        stop=_STOP,
    )
    written = [_write_series(out / "orbits", dict(runs.columns), fmt).name]
    if scenario.output.plots and not args.no_plots and len(runs) > 1:
        from thermojitter.plots import orbit_summary_figure

        written.append(orbit_summary_figure(out, runs.columns, Path(scenario.source).stem).name)
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
        "settings": runs.settings,
        "columns": "angles in rad, times in s; see thermojitter.OrbitSummaries",
        "files": files,
        "wall_time_s": round(time.perf_counter() - started, 2),
    }
    (out / "run.json").write_text(json.dumps(meta, indent=2) + "\n")
    if runs.interrupted:
        print(f"interrupted after {len(runs)} orbits; run again to resume", file=sys.stderr)
        raise KeyboardInterrupt
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


def _run(args: argparse.Namespace) -> int:
    scenario = load_scenario(args.scenario)
    out = _out_dir(args.out)
    if scenario.simulation.keep == "orbits":
        return _run_orbits(args, scenario, out)
    fmt = args.format or scenario.output.format
    make_plots = scenario.output.plots and not args.no_plots
    started = time.perf_counter()
    columns, counters, interrupted = simulate_scenario(
        scenario, progress=not args.no_progress, stop=_STOP
    )
    t = columns["t"]
    written = []
    if len(t):
        written.append(_write_series(out / "timeseries", columns, fmt).name)
    intervals = scenario.orbit.shadow_intervals(float(t[0]), float(t[-1])) if len(t) else []
    if make_plots and len(t) > 1 and not interrupted:
        from thermojitter.plots import run_figures

        title = Path(scenario.source).stem
        written += [p.name for p in run_figures(out, t, columns, intervals, title=title)]
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
            **counters,
        },
        "shadow_intervals_s": [list(iv) for iv in intervals],
        "columns": {
            "t": "s",
            "T_front": "K",
            "T_back": "K",
            "theta": "rad",
            "theta_dot": "rad/s",
            "thermal_moment": "N m",
            "sunlit": "illuminated fraction",
        },
        "theta_min_deg": float(np.degrees(columns["theta"].min())) if len(t) else None,
        "theta_max_deg": float(np.degrees(columns["theta"].max())) if len(t) else None,
        "files": files,
        "wall_time_s": round(time.perf_counter() - started, 2),
    }
    (out / "run.json").write_text(json.dumps(meta, indent=2) + "\n")
    if interrupted:
        print(
            f"interrupted: kept {len(t)} samples up to t = {t[-1] if len(t) else 0:.0f} s",
            file=sys.stderr,
        )
        raise KeyboardInterrupt
    print(
        f"wrote {', '.join(files)} to {args.out} ({len(t)} samples, "
        f"{counters['n_steps']} steps, {meta['wall_time_s']} s)"
    )
    return 0


# --------------------------------------------------------------------------------------------
# parser and entry point


def _out_dir(path: str) -> Path:
    folder = Path(path)
    if folder.exists() and not folder.is_dir():
        raise UserError(f"--out {path}: exists and is not a folder")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise UserError(f"--out {path}: cannot create the folder ({exc.strerror})") from None
    return folder


def _positive(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not math.isfinite(value) or value <= 0:
        raise argparse.ArgumentTypeError(f"{text!r} must be a finite number > 0")
    return value


class _Parser(argparse.ArgumentParser):
    """argparse with one-line errors (exit code 2) pointing at --help."""

    def error(self, message: str) -> NoReturn:
        self.exit(EXIT_USER_ERROR, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="thermojitter",
        description=(
            "Thermal jitter and thermal flutter of long, thin spacecraft appendages "
            "(Parisse & Angeletti 2024): a two-layer thermal model of a Sun-pointing plate in "
            "orbit coupled to a one-hinge model of its first bending mode."
        ),
        epilog="Run 'thermojitter COMMAND --help' for the options of a command.",
    )
    parser.add_argument("--version", action="version", version=f"thermojitter {__version__}")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")

    paper = sub.add_parser(
        "paper",
        help="reproduce the paper on its Table 1 panel",
        description=(
            "Reproduce the paper on its Table 1 panel in GEO at equinox: writes the figures "
            "(fig02 … fig24 PNG), summary.json (the key numbers, solver settings and step "
            "counts) and report.md (the numbers set beside what the paper states) into --out."
        ),
        epilog="Example: thermojitter paper --out out/",
    )
    paper.add_argument("--out", required=True, metavar="DIR", help="output folder (created)")
    paper.add_argument(
        "--flutter-hours",
        type=_positive,
        default=None,
        metavar="H",
        help="length of the undamped runs of Figs. 17-18, hours from just before the first "
        "eclipse (default 14; the growth leaves the small-angle range after about 12 h)",
    )
    paper.add_argument(
        "--dt-out",
        type=_positive,
        default=None,
        metavar="S",
        help="reporting interval of the coupled runs, s (default 0.5; the jitter period is ~8 s)",
    )
    paper.add_argument(
        "--quick",
        action="store_true",
        help="reduced horizon for a fast check: 6 h flutter runs, 1 s output (explicit "
        "--flutter-hours / --dt-out still win)",
    )
    paper.add_argument("--no-progress", action="store_true", help="no progress bar")
    paper.set_defaults(handler=_paper)

    run = sub.add_parser(
        "run",
        help="run one simulation from a TOML scenario file",
        description=(
            "Run one simulation from a TOML scenario file and write the time series "
            "(timeseries.csv or .parquet: t [s], T_front, T_back [K], theta [rad], "
            "theta_dot [rad/s], thermal_moment [N m], sunlit), run.json (settings, step counts) "
            "and plots (temperatures.png, theta.png) into --out. Tables: [panel] any Panel "
            'field; [orbit] preset = "geo_equinox" and/or radius, earth_radius, period, '
            "phase0; [simulation] t_start, t_end or orbits, model (nonlinear|linear), coupled, "
            "method (rk45|rk4), rtol, atol, dt, dt_out; [output] format (csv|parquet), plots."
        ),
        epilog="Example: thermojitter run examples/paper.toml --out out/run",
    )
    run.add_argument("scenario", metavar="SCENARIO.toml", help="the scenario file")
    run.add_argument("--out", required=True, metavar="DIR", help="output folder (created)")
    run.add_argument(
        "--format", choices=("csv", "parquet"), help="override [output] format of the file"
    )
    run.add_argument("--no-plots", action="store_true", help="write no plots")
    run.add_argument("--no-progress", action="store_true", help="no progress bar")
    run.set_defaults(handler=_run)

    beam = sub.add_parser(
        "beam",
        help="compare the hinge model with a finite-element beam (paper Sec. 4.3)",
        description=(
            "Drive a free-free finite-element beam with the hinge run's thermal moment through "
            "an eclipse and compare its equivalent angle with the hinge model's, for K_el by the "
            "deflection and the frequency criteria (paper Figs. 22-24). Writes the figures, "
            "beam_summary.json and beam_report.md into --out."
        ),
        epilog="Example: thermojitter beam --out out/beam",
    )
    beam.add_argument("--out", required=True, metavar="DIR", help="output folder (created)")
    beam.add_argument(
        "--elements",
        type=int,
        default=100,
        metavar="N",
        help="beam elements, even (default 100: 101 nodes as in the paper)",
    )
    beam.add_argument(
        "--no-calibrate",
        action="store_true",
        help="skip fitting the hinge parameters to the beam run",
    )
    beam.set_defaults(handler=_beam)

    flutter = sub.add_parser(
        "flutter",
        help="flutter analysis without integration: growth rate, critical damping, stability map",
        description="Run 'thermojitter flutter --help' for its options.",
        add_help=False,
    )
    flutter.set_defaults(handler=_flutter)

    mc = sub.add_parser(
        "mc",
        help="Monte Carlo study of a scenario with a [vary] table (Parquet, histograms)",
        description="Run 'thermojitter mc --help' for its options.",
        add_help=False,
    )
    mc.set_defaults(handler=_mc)
    return parser


def _flutter(argv: Sequence[str]) -> int:
    from thermojitter.flutter_cli import flutter_command

    return flutter_command(list(argv))


def _mc(argv: Sequence[str]) -> int:
    from thermojitter.montecarlo_cli import mc_command

    return mc_command(list(argv))


# Commands with parsers of their own: main() hands them the rest of the command line.
FORWARDED: dict[str, Callable[[Sequence[str]], int]] = {"flutter": _flutter, "mc": _mc}


def _beam(args: argparse.Namespace) -> int:
    from thermojitter.beam import write_beam_comparison

    return write_beam_comparison(_out_dir(args.out), args.elements, not args.no_calibrate)


def _fail(message: str) -> int:
    print(f"thermojitter: error: {message}", file=sys.stderr)
    return EXIT_USER_ERROR


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``thermojitter`` command; returns the exit code."""
    args_list = sys.argv[1:] if argv is None else list(argv)
    if args_list and args_list[0] in FORWARDED:
        try:
            return FORWARDED[args_list[0]](args_list[1:])
        except KeyboardInterrupt:
            print("thermojitter: interrupted (files already written are kept)", file=sys.stderr)
            return EXIT_INTERRUPTED
        except (ValueError, TypeError, IntegrationError, ConvergenceError) as exc:
            return _fail(" ".join(str(exc).split()))
        except ImportError as exc:
            return _fail(f"{exc} (pip install 'thermojitter[cli]')")
    parser = build_parser()
    args = parser.parse_args(argv)
    if getattr(args, "handler", None) is None:
        parser.print_help(sys.stderr)
        return EXIT_USER_ERROR
    try:
        with _STOP:
            _STOP.requested = False
            return int(args.handler(args))
    except KeyboardInterrupt:
        print("thermojitter: interrupted (files already written are kept)", file=sys.stderr)
        return EXIT_INTERRUPTED
    except (ScenarioError, UserError) as exc:
        return _fail(str(exc))
    except (ValueError, TypeError, IntegrationError, ConvergenceError) as exc:
        return _fail(" ".join(str(exc).split()))
    except ImportError as exc:
        return _fail(f"{exc} (pip install 'thermojitter[cli]')")
    except OSError as exc:
        if exc.filename:
            return _fail(f"{exc.filename}: {exc.strerror or exc}")
        return _fail(str(exc))


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
