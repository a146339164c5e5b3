"""``thermojitter paper --out DIR``: the paper reproduced on its Table 1 panel."""

from __future__ import annotations

import argparse
import time
from typing import Any

from thermojitter.cli.common import STOP, add_writing_command, out_dir, positive


def add_parser(sub: Any) -> None:
    paper = add_writing_command(
        sub,
        "paper",
        help="reproduce the paper on its Table 1 panel",
        description=(
            "Reproduce the paper on its Table 1 panel in GEO at equinox: writes the figures "
            "(fig02 … fig24 PNG), summary.json (the key numbers, solver settings and step "
            "counts) and report.md (the numbers set beside what the paper states) into --out."
        ),
        epilog="Example: thermojitter paper --out out/",
    )
    paper.add_argument(
        "--flutter-hours",
        type=positive,
        default=None,
        metavar="H",
        help="length of the undamped runs of Figs. 17-18, hours from just before the first "
        "eclipse (default 14; the growth leaves the small-angle range after about 12 h)",
    )
    paper.add_argument(
        "--dt-out",
        type=positive,
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
    paper.set_defaults(handler=run, stop_flag=True)


def run(args: argparse.Namespace) -> int:
    from thermojitter.reports.paper import PaperOptions, run_paper

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
    summary = run_paper(
        out_dir(args.out, args.overwrite), options, progress=not args.no_progress, stop=STOP
    )
    elapsed = time.perf_counter() - started
    print(
        f"wrote {len(summary['figures'])} figures, summary.json and report.md to {args.out} "
        f"in {elapsed:.1f} s: θ = {summary['theta_steady_deg']:.2f}°, eclipse "
        f"{summary['eclipse_duration_min']:.1f} min, jitter {summary['jitter_frequency_hz']:.4f}"
        f" Hz (beam f_n {summary['beam_frequency_hz']:.4f} Hz)"
    )
    return 0
