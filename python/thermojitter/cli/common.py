"""What every subcommand of ``thermojitter`` shares: the user-error type, exit codes, the output
folder, number options and the Ctrl-C flag."""

from __future__ import annotations

import argparse
import math
import signal
import threading
from pathlib import Path
from typing import Any, NoReturn

EXIT_USER_ERROR = 2
EXIT_INTERRUPTED = 130


class UserError(Exception):
    """A problem with what the user asked for: reported in one line, exit code 2."""


class Interrupted(KeyboardInterrupt):
    """Ctrl-C after the command has already said, in one line, what it kept (exit code 130)."""


class StopFlag:
    """Ctrl-C as a flag polled between orbits and figures, so the stop happens at a clean point
    (never inside matplotlib or a callback); a second Ctrl-C stops at once. Commands whose work
    stops by itself on KeyboardInterrupt (Monte Carlo) run without it."""

    def __init__(self) -> None:
        self.requested = False
        self._previous: Any = None

    def __call__(self) -> bool:
        return self.requested

    def _handle(self, signum: int, frame: Any) -> None:
        if self.requested:
            raise KeyboardInterrupt
        self.requested = True

    def __enter__(self) -> StopFlag:
        self.requested = False
        if threading.current_thread() is threading.main_thread():
            self._previous = signal.signal(signal.SIGINT, self._handle)
        return self

    def __exit__(self, *exc: object) -> None:
        if self._previous is not None:
            signal.signal(signal.SIGINT, self._previous)
            self._previous = None


STOP = StopFlag()
"""The flag of the running command (polled by long runs and ``paper``)."""


def out_dir(path: str | Path) -> Path:
    """The output folder, created; a UserError when it cannot be."""
    folder = Path(path)
    if folder.exists() and not folder.is_dir():
        raise UserError(f"--out {path}: exists and is not a folder")
    try:
        folder.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise UserError(f"--out {path}: cannot create the folder ({exc.strerror})") from None
    return folder


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
