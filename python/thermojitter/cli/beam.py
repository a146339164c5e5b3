"""``thermojitter beam --out DIR``: the hinge model against a finite-element beam (Sec. 4.3)."""

from __future__ import annotations

import argparse
from typing import Any

from thermojitter.cli.common import add_writing_command, out_dir


def add_parser(sub: Any) -> None:
    beam = add_writing_command(
        sub,
        "beam",
        help="compare the hinge model with a finite-element beam (paper Sec. 4.3)",
        description=(
            "Drive a free-free finite-element beam with the hinge run's thermal moment through "
            "an eclipse and compare its equivalent angle with the hinge model's, for K_el by the "
            "deflection and the frequency criteria (paper Figs. 22-24); then compare the hinge "
            "model with the two-way coupled distributed panel (theta vs theta_f, critical "
            "damping at 1 au, perihelion and aphelion, the cantilever's stability). Writes the "
            "figures, beam_summary.json and beam_report.md into --out."
        ),
        epilog="Example: thermojitter beam --out out/beam",
    )
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
    beam.add_argument(
        "--no-distributed",
        action="store_true",
        help="skip the comparison with the coupled distributed panel",
    )
    beam.set_defaults(handler=run, stop_flag=False)


def run(args: argparse.Namespace) -> int:
    from thermojitter.reports.beam import write_beam_comparison

    return write_beam_comparison(
        out_dir(args.out, args.overwrite),
        args.elements,
        not args.no_calibrate,
        not args.no_distributed,
    )
