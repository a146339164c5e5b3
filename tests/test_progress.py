"""Progress bars and Ctrl-C of the long calls, seen as a user sees them: a child process whose
stderr is a pipe (not a terminal, as in a notebook or a log), interrupted by SIGINT."""

from __future__ import annotations

import math
import re
import signal
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import thermojitter as tj
from thermojitter import _core
from thermojitter.progress import Interruptible
from thermojitter.simulate import solver_settings

REPO = Path(__file__).resolve().parent.parent


class Child:
    """A Python child with SIGINT at its default (Python's KeyboardInterrupt), its stderr read
    as it comes."""

    def __init__(self, args: list[str]) -> None:
        self.proc = subprocess.Popen(
            args,
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            cwd=REPO,
            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
        )
        self.err = ""
        self._reader = threading.Thread(target=self._read, daemon=True)
        self._reader.start()

    def _read(self) -> None:
        assert self.proc.stderr is not None
        while chunk := self.proc.stderr.read(1):
            self.err += chunk

    def wait_for(self, pattern: str, timeout: float = 120.0) -> None:
        """Waits until stderr matches the regular expression ``pattern``."""
        deadline = time.monotonic() + timeout
        while not re.search(pattern, self.err):
            if self.proc.poll() is not None:
                pytest.fail(f"child ended before showing {pattern!r}: {self.err[-500:]}")
            if time.monotonic() > deadline:
                pytest.fail(f"no {pattern!r} on stderr within {timeout} s: {self.err[-500:]}")
            time.sleep(0.05)

    def interrupt(self) -> tuple[float, str]:
        """Sends SIGINT; returns (seconds until the child exited, its stdout)."""
        self.proc.send_signal(signal.SIGINT)
        sent = time.monotonic()
        try:
            self.proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            self.proc.kill()
            pytest.fail("the child did not stop within 30 s of Ctrl-C")
        elapsed = time.monotonic() - sent
        self._reader.join(timeout=5)
        assert self.proc.stdout is not None
        return elapsed, self.proc.stdout.read()

    def note(self) -> str:
        """The child's stderr without its progress bars: what a user reads after the stop."""
        lines = [ln.strip() for ln in self.err.replace("\r", "\n").splitlines()]
        return "\n".join(ln for ln in lines if ln and "|" not in ln)


def python(code: str) -> list[str]:
    return [sys.executable, "-c", textwrap.dedent(code)]


def test_a_year_of_orbits_shows_progress_and_stops_on_ctrl_c() -> None:
    child = Child(
        python("""
            import thermojitter as tj
            runs = tj.simulate_orbits(tj.Panel.paper(), tj.Orbit.geo_year("2026-01-01"), 366,
                                      method="rk45")  # the hybrid would finish at once
            print(len(runs), runs.interrupted)
        """)
    )
    # A bar with counts and the remaining time, though stderr is a pipe.
    child.wait_for(r"[1-9]\d*/366 orbit \[\d\d:\d\d<\d\d:\d\d\]")
    elapsed, out = child.interrupt()
    assert elapsed < 2.0
    assert child.proc.returncode == 0
    done, interrupted = out.split()
    assert interrupted == "True" and 0 < int(done) < 366
    note = child.note()
    assert "Traceback" not in child.err
    assert note == (
        f"thermojitter: interrupted; kept {done} of 366 orbits (returned, interrupted=True); "
        "pass checkpoint=FILE to make a run resumable"
    )


def test_monte_carlo_stops_on_ctrl_c_within_two_seconds(tmp_path: Path) -> None:
    ckpt = tmp_path / "mc"
    child = Child(
        python(f"""
            import thermojitter as tj
            vary = {{"damping": ("uniform", 1.0, 4.0)}}
            df = tj.monte_carlo(tj.Panel.paper(), tj.Orbit.geo_equinox(), vary=vary, n=8,
                                horizon=200, seed=1, chunk_size=1, checkpoint={str(ckpt)!r})
            print(len(df), df.attrs["interrupted"])
        """)
    )
    child.wait_for(r"0/8 sample \[")
    time.sleep(1.0)  # inside the engine: each sample is minutes of work
    elapsed, out = child.interrupt()
    assert elapsed < 2.0
    assert child.proc.returncode == 0 and out.split() == ["0", "True"]
    assert "Traceback" not in child.err
    assert child.note() == (
        "thermojitter: interrupted; kept 0 of 8 samples (frame.attrs['interrupted'] is True); "
        f"finished chunks are in {ckpt}; run the same call again to resume"
    )


def test_the_command_stops_on_ctrl_c_in_one_line(tmp_path: Path) -> None:
    out = tmp_path / "run"
    # Ten years integrated in full (the example's hybrid propagator would finish at once).
    example = Path("examples/ten_years.toml").read_text()
    scenario = tmp_path / "long.toml"
    scenario.write_text(example.replace('method = "hybrid"', 'method = "rk45"'))
    assert scenario.read_text() != example
    child = Child([sys.executable, "-m", "thermojitter", "run", str(scenario), "--out", str(out)])
    child.wait_for(r"[1-9]\d*/\d+ orbit \[")
    elapsed, _ = child.interrupt()
    assert elapsed < 2.0
    assert child.proc.returncode == 130
    assert "Traceback" not in child.err
    note = child.note().splitlines()
    assert len(note) == 1 and note[0].startswith("thermojitter: interrupted; kept ")
    assert "run the same command again to resume" in note[0]
    assert (out / "checkpoint.json").exists()


def test_interruptible_cancels_the_engine_call() -> None:
    """The token handed to the engine stops a long batch from another thread."""
    pool = _core.EnsemblePool(1)
    panel = tj.Panel.paper()
    row = np.array([[getattr(panel, f) for f in _core.PANEL_FIELDS]])
    with Interruptible() as engine:
        threading.Timer(0.3, engine.token.cancel).start()
        started = time.monotonic()
        with pytest.raises(KeyboardInterrupt):
            engine.call(
                pool.run,
                row,
                tj.Orbit.geo_equinox().as_dict(),
                model="nonlinear",
                coupled=True,
                solver=solver_settings("rk45", 1e-8, 1e-10, None, math.inf, 500_000_000),
                n_orbits=100_000,
                window=600.0,
                threshold=None,
                stop_at_threshold=False,
            )
        assert time.monotonic() - started < 5.0
