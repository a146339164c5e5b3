"""The ``thermojitter`` command: one parser, one module per subcommand.

    thermojitter paper --out DIR              reproduce the paper (figures, summary.json, report.md)
    thermojitter run SCENARIO.toml --out DIR  one simulation from a scenario file
    thermojitter flutter [SCENARIO.toml]      growth rate, critical damping, stability map
    thermojitter beam --out DIR               hinge model against a finite-element beam
    thermojitter mc SCENARIO.toml --out DIR   Monte Carlo study of a scenario's [vary] table

One error path: user errors (bad files, values, folders) are one line on stderr and exit code 2;
a Monte Carlo study with failed samples is one line on stderr and exit code 3 (``mc
--allow-failures`` accepts some failed samples, never all); Ctrl-C stops within about a second
with exit code 130, keeps what finished and says in one line what was kept and how to resume.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence

from thermojitter import __version__
from thermojitter.cli import beam, flutter, mc, paper, run
from thermojitter.cli.common import (
    EXIT_INTERRUPTED,
    EXIT_SAMPLES_FAILED,
    EXIT_USER_ERROR,
    Parser,
    UserError,
    run_parsed,
)
from thermojitter.cli.run import MAX_ORBITS, MAX_ROWS, simulate_scenario

__all__ = [
    "EXIT_INTERRUPTED",
    "EXIT_SAMPLES_FAILED",
    "EXIT_USER_ERROR",
    "MAX_ORBITS",
    "MAX_ROWS",
    "UserError",
    "build_parser",
    "main",
    "simulate_scenario",
]


def build_parser() -> argparse.ArgumentParser:
    parser = Parser(
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
    for command in (paper, run, flutter, beam, mc):
        command.add_parser(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``thermojitter`` command; returns the exit code."""
    parser = build_parser()
    return run_parsed(parser, parser.parse_args(argv))


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
