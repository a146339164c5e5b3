"""What every subcommand of ``thermojitter`` shares: the user-error type, exit codes and the one
error path that gives them, the output folder, number options and the Ctrl-C flag."""

from __future__ import annotations

import argparse
import contextlib
import math
import sys
import warnings
from collections.abc import Callable, Iterator, Sequence
from pathlib import Path
from typing import Any, BinaryIO, NoReturn

from thermojitter._core import ConvergenceError, IntegrationError
from thermojitter.checkpoint import write_atomic
from thermojitter.progress import SigintHandler
from thermojitter.scenario import ScenarioError

EXIT_USER_ERROR = 2
EXIT_SAMPLES_FAILED = 3
EXIT_INTERRUPTED = 130


class UserError(Exception):
    """A problem with what the user asked for: reported in one line, exit code 2."""


class SamplesFailed(Exception):
    """Samples of a study failed (``thermojitter mc``): reported in one line, exit code 3, after
    what finished was written and summarised."""


class Interrupted(KeyboardInterrupt):
    """Ctrl-C after the command has already said, in one line, what it kept (exit code 130)."""


class StopFlag(SigintHandler):
    """Ctrl-C as a flag polled between orbits and figures, so the stop happens at a clean point
    (never inside matplotlib or a callback); a second Ctrl-C stops at once. Commands whose work
    stops by itself on KeyboardInterrupt (Monte Carlo) run without it."""

    def __init__(self) -> None:
        super().__init__()
        self.requested = False

    def __call__(self) -> bool:
        return self.requested

    def _handle(self, signum: int, frame: Any) -> None:
        if self.requested:
            raise KeyboardInterrupt
        self.requested = True

    def __enter__(self) -> StopFlag:
        self.requested = False
        return super().__enter__()


STOP = StopFlag()
"""The flag of the running command (polled by long runs and ``paper``)."""


def out_dir(path: str | Path, overwrite: bool = False) -> Path:
    """The output folder, created; a UserError when it cannot be, or when it already holds files
    and ``overwrite`` (--overwrite) is not given, so that earlier results are never replaced
    silently."""
    folder = Path(path)
    if folder.exists() and not folder.is_dir():
        raise UserError(f"--out {path}: exists and is not a folder")
    if folder.is_dir() and not overwrite and any(folder.iterdir()):
        raise UserError(
            f"--out {path}: the folder is not empty; pass --overwrite to replace its files "
            "(and to resume a run from the checkpoint there), or choose another folder"
        )
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise UserError(f"--out {path}: cannot create the folder ({exc.strerror})") from None
    return folder


def add_out(parser: argparse.ArgumentParser, **kwargs: Any) -> None:
    """--out DIR and --overwrite, the same for every subcommand."""
    parser.add_argument("--out", metavar="DIR", **kwargs)
    parser.add_argument(
        "--overwrite",
        action="store_true",
        help="write into a non-empty --out, replacing its files (a run resumes from the "
        "checkpoint there)",
    )


def add_writing_command(sub: Any, name: str, **kwargs: Any) -> argparse.ArgumentParser:
    """The subcommand ``name`` (``kwargs``: help, description, epilog...) with its required
    --out DIR and --overwrite."""
    parser: argparse.ArgumentParser = sub.add_parser(name, **kwargs)
    add_out(parser, required=True, help="output folder (created)")
    return parser


def write_output(path: Path, write: Callable[[BinaryIO], object]) -> Path:
    """Writes one output file atomically (a temporary file renamed over it): a failure, such as
    a full disk, leaves no partial file and is reported in one line naming the file."""
    try:
        write_atomic(path, write)
    except OSError as exc:
        raise UserError(
            f"{path}: cannot be written ({exc.strerror or exc}); no partial file was left"
        ) from None
    return path


def positive(text: str) -> float:
    """argparse type: a finite number > 0."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number") from None
    if not math.isfinite(value) or value <= 0:
        raise argparse.ArgumentTypeError(f"{text!r} must be a finite number > 0")
    return value


class Parser(argparse.ArgumentParser):
    """argparse with one-line errors (exit code 2) pointing at --help."""

    def error(self, message: str) -> NoReturn:
        self.exit(EXIT_USER_ERROR, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def _fail(message: str, code: int = EXIT_USER_ERROR) -> int:
    print(f"thermojitter: error: {message}", file=sys.stderr)
    return code


def one_line_warning(
    message: Warning | str,
    category: type[Warning],
    filename: str,
    lineno: int,
    line: str | None = None,
) -> str:
    """A warning as the command shows it: one line, like its errors, without the Python file,
    line and source a warning shows by default."""
    text = " ".join(str(message).split())
    return f"thermojitter: warning: {text} ({category.__name__})\n"


@contextlib.contextmanager
def command_warnings() -> Iterator[None]:
    """Warnings shown in the command's one-line format while a command runs (then as before);
    which are shown, and code recording them, are unchanged."""
    before = warnings.formatwarning
    warnings.formatwarning = one_line_warning
    try:
        yield
    finally:
        warnings.formatwarning = before


def run_parsed(parser: argparse.ArgumentParser, args: argparse.Namespace) -> int:
    """Runs the subcommand ``parser`` parsed into ``args``, through the command's one error path
    (the module's docstring of ``thermojitter.cli``); returns the exit code."""
    if getattr(args, "handler", None) is None:
        parser.print_help(sys.stderr)
        return EXIT_USER_ERROR
    with command_warnings():
        return _run_handler(args)


def _run_handler(args: argparse.Namespace) -> int:
    """The subcommand's handler through the one error path."""
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


def run_command(add_parser: Callable[[Any], None], argv: Sequence[str]) -> int:
    """``thermojitter ARGV`` with only the subcommand that ``add_parser`` adds (the scripts that
    predate the subcommands: ``python -m thermojitter.montecarlo_cli``): the same parser, error
    path and exit codes as the whole command."""
    parser = Parser(prog="thermojitter")
    add_parser(parser.add_subparsers(dest="command", metavar="COMMAND"))
    return run_parsed(parser, parser.parse_args(argv))
