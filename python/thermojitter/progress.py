"""Progress bars and Ctrl-C for the long calls (long runs, Monte Carlo, sweeps, maps, commands).

One home for how a long call looks while it runs and how it stops:

- :func:`progress_bar` is a ``tqdm.auto`` bar on stderr (a widget in Jupyter, text elsewhere,
  also when stderr is not a terminal) with the remaining time estimated from the rate so far.
- :class:`Interruptible` runs engine calls in a worker thread with a cancellation token, so that
  Ctrl-C reaches the waiting thread at once, the engine stops within one integration step, and
  the caller keeps what finished.
- :func:`interruptible` does the same for one engine call (a run, a map block): every long call
  of the package goes through it, so that Ctrl-C stops it with a plain ``KeyboardInterrupt``.
- :class:`DeferredInterrupt` holds Ctrl-C back while a write that must not be cut runs (a
  checkpoint chunk), and raises it once the write is whole.
- :func:`report_interrupted` is the one line a stopped call prints: what was kept and how to go on.
"""

from __future__ import annotations

import concurrent.futures as cf
import contextlib
import os
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator
from typing import Any, TypeVar

from thermojitter import _core

T = TypeVar("T")

BAR_FORMAT = "{desc}: {percentage:3.0f}%|{bar}| {n_fmt}/{total_fmt} {unit} [{elapsed}<{remaining}]"
"""Done, total and the remaining time (tqdm's estimate from the rate so far)."""


def progress_bar(
    total: int,
    *,
    unit: str,
    initial: int = 0,
    desc: str = "thermojitter",
    enabled: bool | None = True,
    delay: float = 0.0,
) -> Any:
    """A tqdm bar on stderr, or None when ``enabled`` is false or tqdm is not installed.

    ``enabled=None`` means "when stderr is a terminal". Outside a terminal (a log file, a pipe, a
    notebook's captured stderr) the bar is redrawn at most every few seconds. ``delay``: seconds
    before the bar first appears (short calls then show nothing)."""
    if enabled is None:
        enabled = sys.stderr.isatty()
    if not enabled:
        return None
    try:
        from tqdm.auto import tqdm
    except ImportError:
        return None
    interactive = sys.stderr.isatty()
    return tqdm(
        total=total,
        initial=initial,
        unit=unit,
        desc=desc,
        file=sys.stderr,
        leave=False,
        delay=delay,
        mininterval=0.1 if interactive else 2.0,
        bar_format=BAR_FORMAT,
        dynamic_ncols=interactive,
    )


def report_interrupted(kept: str, resume: str) -> None:
    """The one line a call stopped by Ctrl-C prints on stderr: what it kept, how to go on."""
    print(f"thermojitter: interrupted; {kept}; {resume}", file=sys.stderr, flush=True)


SHORT_CALL = 2e-3
"""Seconds: an engine call that follows one shorter than this runs in the calling thread
(:attr:`Interruptible.runs_here`), where handing it to the worker and back (~0.1 ms on a
2-core machine) would cost about what the call does (a hybrid GEO orbit: ~0.2 ms)."""


def _timed(fn: Callable[..., T], /, *args: Any, **kwargs: Any) -> tuple[T, float]:
    """``fn(*args, **kwargs)`` and the seconds it took."""
    start = time.perf_counter()
    out = fn(*args, **kwargs)
    return out, time.perf_counter() - start


class Interruptible:
    """Runs engine calls in one worker thread, each given ``cancel=`` a shared token.

    The calling thread waits on the result, which Ctrl-C interrupts at once (a thread inside the
    engine, with the GIL released, would only notice at the end of the call). On Ctrl-C the token
    is cancelled, the engine stops within one integration step, and :meth:`call` re-raises
    ``KeyboardInterrupt`` once the worker is idle again. Use as a context manager.

    A call that follows a short one (``SHORT_CALL``) runs in the calling thread instead
    (:attr:`runs_here` says so before it): Ctrl-C then comes at its end, so the caller holds it
    back over the call and the keeping of its result (nothing finished is lost)."""

    def __init__(self) -> None:
        self.token = _core.CancelToken()
        self._executor = cf.ThreadPoolExecutor(max_workers=1, thread_name_prefix="thermojitter")
        self.runs_here = False

    def call(self, fn: Callable[..., T], /, *args: Any, **kwargs: Any) -> T:
        # The call's own duration decides, timed where it runs: the worker's start (its thread
        # is made at the first call) and the handoff are not the call's.
        if self.runs_here:
            out, spent = _timed(fn, *args, cancel=self.token, **kwargs)
        else:
            future = self._executor.submit(_timed, fn, *args, cancel=self.token, **kwargs)
            try:
                out, spent = future.result()
            except KeyboardInterrupt:
                self.token.cancel()
                cf.wait([future])
                raise
        self.runs_here = spent < SHORT_CALL
        return out

    def __enter__(self) -> Interruptible:
        return self

    def __exit__(self, *exc: object) -> None:
        self.token.cancel()  # whatever is still running stops; nothing new starts
        self._executor.shutdown(wait=True)


_worker: cf.ThreadPoolExecutor | None = None
"""The thread that runs the main thread's engine calls (made at the first call)."""


def _forget_worker() -> None:
    # A forked child has no copy of the worker thread: it makes its own.
    global _worker
    _worker = None


os.register_at_fork(after_in_child=_forget_worker)


def interruptible(fn: Callable[..., T], /, *args: Any, **kwargs: Any) -> T:
    """``fn(*args, cancel=token, **kwargs)``, an engine call, stopped by Ctrl-C.

    Python runs its SIGINT handler only in the main thread and only between bytecodes, so a call
    that holds the main thread inside the engine would notice Ctrl-C at its end. Called from the
    main thread, the engine call runs in one shared worker thread while the main thread waits:
    Ctrl-C interrupts the wait at once, cancels the token, the engine stops within one step (or
    one grid point), and ``KeyboardInterrupt`` is raised once the worker is idle again. From
    another thread (which Ctrl-C never reaches) the call runs in place."""
    token = _core.CancelToken()
    if threading.current_thread() is not threading.main_thread():
        return fn(*args, cancel=token, **kwargs)
    global _worker
    if _worker is None:
        _worker = cf.ThreadPoolExecutor(max_workers=1, thread_name_prefix="thermojitter-engine")
    future = _worker.submit(fn, *args, cancel=token, **kwargs)
    try:
        return future.result()
    except KeyboardInterrupt:
        token.cancel()
        cf.wait([future])
        raise


H = TypeVar("H", bound="SigintHandler")


class SigintHandler:
    """A SIGINT handler (the subclass's ``_handle``) for the length of a ``with`` block, the
    previous one put back after. Installed only in the main thread (the only one that can), and,
    with ``keep_own``, only over Python's default handler, so that a program's own stays."""

    keep_own = False

    def __init__(self) -> None:
        self._previous: Any = None

    def __enter__(self: H) -> H:
        if threading.current_thread() is threading.main_thread() and (
            not self.keep_own or signal.getsignal(signal.SIGINT) is signal.default_int_handler
        ):
            self._previous = signal.signal(signal.SIGINT, self._handle)
        return self

    def __exit__(self, *exc: object) -> None:
        if self._previous is not None:
            signal.signal(signal.SIGINT, self._previous)
            self._previous = None

    def _handle(self, signum: int, frame: Any) -> None:
        raise NotImplementedError


class DeferredInterrupt(SigintHandler):
    """Ctrl-C that waits for the end of :meth:`hold` sections (checkpoint writes).

    Outside a held section Ctrl-C raises ``KeyboardInterrupt`` at once, as Python's own handler
    does; inside one it is remembered and raised when the section ends, so that a write is never
    cut in the middle, and never lost in a finalizer that ran then (Python ignores an exception
    raised in ``__del__``, and with it the Ctrl-C). A program with its own SIGINT handler keeps
    it."""

    keep_own = True

    def __init__(self) -> None:
        super().__init__()
        self._depth = 0
        self._pending = False

    def _handle(self, signum: int, frame: Any) -> None:
        if self._depth:
            self._pending = True
        else:
            raise KeyboardInterrupt

    @contextlib.contextmanager
    def hold(self, *, then_raise: bool = True) -> Iterator[None]:
        """Runs the block with Ctrl-C held back; one that came meanwhile is raised at its end
        (``then_raise``), or dropped when the caller is already stopping."""
        self._depth += 1
        try:
            yield
        finally:
            self._depth -= 1
            pending = self._depth == 0 and self._pending
            if pending:
                self._pending = False
        if pending and then_raise:
            raise KeyboardInterrupt
