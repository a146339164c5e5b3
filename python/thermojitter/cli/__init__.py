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
from thermojitter._core import ConvergenceError, IntegrationError
from thermojitter.cli import beam, flutter, mc, paper, run
from thermojitter.cli.common import (
    EXIT_INTERRUPTED,
    EXIT_SAMPLES_FAILED,
    EXIT_USER_ERROR,
    STOP,
    Interrupted,
    Parser,
    SamplesFailed,
    UserError,
)
from thermojitter.cli.run import MAX_ORBITS, MAX_ROWS, simulate_scenario
from thermojitter.scenario import ScenarioError

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


def _fail(message: str, code: int = EXIT_USER_ERROR) -> int:
    print(f"thermojitter: error: {message}", file=sys.stderr)
    return code


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``thermojitter`` command; returns the exit code."""
    parser = build_parser()
    args = parser.parse_args(argv)
    if getattr(args, "handler", None) is None:
        parser.print_help(sys.stderr)
        return EXIT_USER_ERROR
    try:
        if args.stop_flag:
            with STOP:
                return int(args.handler(args))
        return int(args.handler(args))
    except Interrupted:
        return EXIT_INTERRUPTED  # what was kept is already said
    except KeyboardInterrupt:
        print(
            "thermojitter: interrupted; the files already written are kept; run the command "
            "again to redo the rest",
            file=sys.stderr,
        )
        return EXIT_INTERRUPTED
    except (ScenarioError, UserError) as exc:
        return _fail(str(exc))
    except SamplesFailed as exc:
        return _fail(" ".join(str(exc).split()), EXIT_SAMPLES_FAILED)
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
