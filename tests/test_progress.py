"""Progress bars and Ctrl-C of the long calls, seen as a user sees them: a child process whose
stderr is a pipe (not a terminal, as in a notebook or a log), interrupted by SIGINT."""

from __future__ import annotations

import math
import os
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
from thermojitter.progress import DeferredInterrupt, Interruptible
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
        """Sends SIGINT; returns (CPU seconds the child spent from then until it exited, its
        stdout). CPU time, not the clock: on a loaded machine the child may wait long for a core,
        but the work it does after Ctrl-C (finish the step, keep what is done, say so, exit) is
        what must be small; a child that went on computing would spend seconds of CPU."""
        before = cpu_seconds(self.proc.pid)
        self.proc.send_signal(signal.SIGINT)
        deadline = time.monotonic() + 120.0
        while True:
            # wait4 reaps the child and gives its whole CPU time (every thread).
            pid, status, usage = os.wait4(self.proc.pid, os.WNOHANG)
            if pid:
                break
            if time.monotonic() > deadline:
                self.proc.kill()
                pytest.fail("the child did not stop within 120 s of Ctrl-C")
            time.sleep(0.01)
        self.proc.returncode = os.waitstatus_to_exitcode(status)
        spent = usage.ru_utime + usage.ru_stime - before
        self._reader.join(timeout=5)
        assert self.proc.stdout is not None
        return spent, self.proc.stdout.read()

    def note(self) -> str:
        """The child's stderr without its progress bars: what a user reads after the stop."""
        lines = [ln.strip() for ln in self.err.replace("\r", "\n").splitlines()]
        return "\n".join(ln for ln in lines if ln and "|" not in ln)


def cpu_seconds(pid: int) -> float:
    """CPU time (user + system, every thread) the live process ``pid`` has used so far, s."""
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


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
    cpu, out = child.interrupt()
    assert cpu < 2.0
    assert child.proc.returncode == 0
    done, interrupted = out.split()
    assert interrupted == "True" and 0 < int(done) < 366
    note = child.note()
    assert "Traceback" not in child.err
    assert note == (
        f"thermojitter: interrupted; kept {done} of 366 orbits (returned, interrupted=True); "
        "pass checkpoint=FILE to make a run resumable"
    )


def test_monte_carlo_stops_on_ctrl_c_within_two_cpu_seconds(tmp_path: Path) -> None:
    ckpt = tmp_path / "mc"
    child = Child(
        python(f"""
            import thermojitter as tj
            vary = {{"damping": ("uniform", 1.0, 4.0)}}
            df = tj.monte_carlo(tj.Panel.paper(), tj.Orbit.geo_equinox(), vary=vary, n=8,
                                horizon=100, seed=1, chunk_size=1, method="rk45",
                                checkpoint={str(ckpt)!r})
            print(len(df), df.attrs["interrupted"])
        """)
    )
    child.wait_for(r"0/8 sample \[")
    time.sleep(1.0)  # inside the engine: each sample is minutes of work
    cpu, out = child.interrupt()
    assert cpu < 2.0
    assert child.proc.returncode == 0 and out.split() == ["0", "True"]
    assert "Traceback" not in child.err
    assert child.note() == (
        "thermojitter: interrupted; kept 0 of 8 samples (frame.attrs['interrupted'] is True); "
        f"finished chunks are in {ckpt}; run the same call again to resume"
    )


def test_the_command_stops_on_ctrl_c_in_one_line(tmp_path: Path) -> None:
    out = tmp_path / "run"
    # A year integrated in full (the example's hybrid propagator would finish at once; ten years
    # in full are beyond the default step budget).
    example = Path("examples/ten_years.toml").read_text()
    scenario = tmp_path / "long.toml"
    changed = example.replace('method = "hybrid"', 'method = "rk45"')
    scenario.write_text(changed.replace("years = 10", "years = 1"))
    assert 'method = "rk45"' in scenario.read_text() and "years = 1\n" in scenario.read_text()
    child = Child([sys.executable, "-m", "thermojitter", "run", str(scenario), "--out", str(out)])
    child.wait_for(r"[1-9]\d*/\d+ orbit \[")
    cpu, _ = child.interrupt()
    assert cpu < 2.0
    assert child.proc.returncode == 130
    assert "Traceback" not in child.err
    note = child.note().splitlines()
    assert len(note) == 1 and note[0].startswith("thermojitter: interrupted; kept ")
    assert "run the same command again to resume" in note[0]
    assert (out / "checkpoint.json").exists()


def test_short_orbits_stop_on_ctrl_c_and_keep_every_finished_one() -> None:
    """A hybrid GEO orbit is a call of ~0.2 ms, which runs in the calling thread
    (Interruptible.runs_here): Ctrl-C comes at a call's end, and every orbit finished before it
    is kept, each the same as in a run that was not interrupted."""
    child = Child(
        python("""
            import numpy as np
            import thermojitter as tj
            orbit = tj.Orbit.geo_year("2026-01-01")
            runs = tj.simulate_orbits(tj.Panel.paper(), orbit, 200_000, method="hybrid")
            print(len(runs), runs.interrupted, flush=True)
            again = tj.simulate_orbits(tj.Panel.paper(), orbit, len(runs), method="hybrid",
                                       progress=False)
            same = all(np.array_equal(runs.columns[k], again.columns[k], equal_nan=True)
                       for k in again.columns)
            print(same)
        """)
    )
    child.wait_for(r"[1-9]\d{3,}/200000 orbit")
    cpu, out = child.interrupt()
    assert child.proc.returncode == 0, child.err[-500:]
    assert "Traceback" not in child.err
    done, interrupted, same = out.split()
    assert interrupted == "True" and 1000 <= int(done) < 200_000
    assert same == "True"
    # Stopping took no more than the run of the kept orbits again (~0.2 ms each) and its start.
    assert cpu < 2.0 + 1e-3 * int(done)


def test_a_call_after_a_short_one_runs_in_the_calling_thread() -> None:
    seen: list[int] = []

    def short(*, cancel: object) -> int:
        seen.append(threading.get_ident())
        return len(seen)

    def long(*, cancel: object) -> int:
        time.sleep(0.05)  # longer than SHORT_CALL
        return short(cancel=cancel)

    with Interruptible() as engine:
        assert not engine.runs_here
        assert engine.call(short) == 1  # the first in the worker
        assert engine.runs_here
        assert engine.call(short) == 2  # then here
        assert engine.call(long) == 3  # here too; a long call sends the next to the worker
        assert not engine.runs_here
        assert engine.call(short) == 4
    main = threading.get_ident()
    assert seen[0] != main and seen[1] == main and seen[2] == main and seen[3] != main


def test_interruptible_cancels_the_engine_call() -> None:
    """The token handed to the engine stops a long batch from another thread."""
    pool = _core.MonteCarloPool(1)
    assert _core.EnsemblePool is _core.MonteCarloPool  # the name before, kept
    panel = tj.Panel.paper()
    row = np.array([[getattr(panel, f) for f in _core.PANEL_FIELDS]])
    with Interruptible() as engine:
        threading.Timer(0.3, engine.token.cancel).start()
        # CPU time of this process, not the clock: under load the engine may wait for a core.
        started = time.process_time()
        with pytest.raises(KeyboardInterrupt):
            engine.call(
                pool.run,
                row,
                tj.Orbit.geo_equinox().as_dict(),
                {
                    "model": "nonlinear",
                    "coupled": True,
                    "solver": solver_settings("rk45", 1e-8, 1e-10, None, math.inf, 500_000_000),
                    "n_orbits": 100_000,
                    "window": 600.0,
                },
                threshold=None,
                stop_at_threshold=False,
            )
        assert time.process_time() - started < 5.0


def test_ctrl_c_in_a_held_section_is_raised_when_it_ends_not_lost() -> None:
    finished = []

    class Finalised:
        def __del__(self) -> None:
            # Python ignores an exception raised here: Ctrl-C raised in a finalizer is lost.
            signal.raise_signal(signal.SIGINT)
            finished.append("finaliser")

    with DeferredInterrupt() as ctrl_c:
        with pytest.raises(KeyboardInterrupt):
            with ctrl_c.hold():
                Finalised()  # dropped at once: its __del__ runs inside the held section
                finished.append("write")
        assert finished == ["finaliser", "write"]
        with pytest.raises(KeyboardInterrupt):  # outside a held section: at once
            signal.raise_signal(signal.SIGINT)
        with ctrl_c.hold(then_raise=False):
            signal.raise_signal(signal.SIGINT)
        # dropped, and not carried into the next section
        with ctrl_c.hold():
            pass
    assert signal.getsignal(signal.SIGINT) is signal.default_int_handler


def test_a_programs_own_sigint_handler_is_kept() -> None:
    seen = []

    def own(signum: int, frame: object) -> None:
        seen.append(signum)

    previous = signal.signal(signal.SIGINT, own)
    try:
        with DeferredInterrupt() as ctrl_c, ctrl_c.hold():
            assert signal.getsignal(signal.SIGINT) is own
            signal.raise_signal(signal.SIGINT)
        assert seen == [signal.SIGINT]
    finally:
        signal.signal(signal.SIGINT, previous)


# Ctrl-C of every long engine call: each runs for several seconds of CPU in a child, is sent
# SIGINT half a second in, and must end at once with a plain KeyboardInterrupt (before, the run
# went on to its end and the first one of a process ended in an InternalError from NumPy).

LONG_CALLS = {
    "simulate": "tj.simulate(P, O, (0, 10 * O.period), max_step=0.05, dt_out=100.0)",
    "simulate_rk4": "tj.simulate(P, O, (0, 10 * O.period), method='rk4', dt=0.02, dt_out=100.0)",
    "simulate_layers": (
        "tj.simulate(P.replace(damping=10.0), O, (0, 60 * O.period), layers=8, dt_out=100.0)"
    ),
    "simulate_thermal": (
        "tj.simulate_thermal(P, O, (0, 100 * O.period), max_step=0.01, dt_out=100.0)"
    ),
    "simulate_distributed": "tj.simulate_distributed(P, O, (0, O.period), dt_out=100.0)",
    "stability_map": (
        "tj.stability_map(P, ('damping', np.linspace(0.5, 5.0, 1_000_000)),"
        " ('conductance', [20.0]), progress=False)"
    ),
    "calibrate": (
        "tj.calibrate(np.linspace(0, 10 * O.period, 100), np.zeros(100), panel=P, orbit=O)"
    ),
    "beam_response": (
        "tj.FreeFreeBeam(P, 100).response(np.linspace(0, 2e4, 2001),"
        " 5 * np.sin(np.linspace(0, 400, 2001)), max_step=0.002)"
    ),
    "compare_with_beam": "tj.compare_with_beam(P, O, t_span=(0, 30 * O.period), dt_out=5.0)",
}


@pytest.mark.parametrize("call", sorted(LONG_CALLS))
def test_ctrl_c_stops_every_long_engine_call_with_a_plain_keyboard_interrupt(call: str) -> None:
    child = Child(
        python(f"""
            import sys
            import numpy as np
            import thermojitter as tj
            P, O = tj.Panel.paper(), tj.Orbit.geo_equinox()
            print("running", file=sys.stderr, flush=True)
            try:
                {LONG_CALLS[call]}
            except BaseException as exc:
                print(type(exc).__module__, type(exc).__name__)
            else:
                print("finished")
        """)
    )
    child.wait_for("running")
    time.sleep(0.5)  # inside the engine
    cpu, out = child.interrupt()
    assert out.split() == ["builtins", "KeyboardInterrupt"], (out, child.err[-800:])
    assert cpu < 1.5
    assert "panicked" not in child.err and "Traceback" not in child.err
