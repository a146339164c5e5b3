"""A fuzz harness over the public API and the scenario parser, shared by tests/test_fuzz.py (a
short run in CI) and benches/fuzz.py (a long run that prints the count of each outcome).

Each example is a known-good call of one entry point with one to three of its arguments replaced
by a hostile value (NaN, ±inf, 0, negatives, 1e±300, integers too large for a float, bools, None,
strings, wrong shapes, reversed spans), or the bytes of a scenario file or of a long run's
checkpoint, damaged (truncated, bit-flipped, a line dropped or repeated, a piece replaced). It
runs in a worker process under a watchdog, so that a crash (the process dies) or a hang (no
answer within the CPU-time limit, see ``Runner``) is counted, not fatal.

Outcomes:

- ``ok``: a result whose every number is finite (NaN only where documented: no eclipse, no umbra,
  a failed Monte Carlo sample with its error; +inf only for ``max_step``, "no cap");
- ``refused_named``: ValueError/TypeError naming the parameter (a ``ParameterError``'s
  ``.parameter``, or the argument's name in the message); ``refused_unnamed`` otherwise;
- ``runtime_error``: IntegrationError or ConvergenceError (a clear error from the engine);
- failures: ``silent_nan`` (a non-finite number returned), ``wrong_result`` (a run resumed
  from a damaged checkpoint that differs from the run itself), ``internal_error`` (a panic caught at
  the boundary), ``panic`` (a BaseException from the engine), ``other_exception`` (any other
  type), ``abort`` (the worker died), ``hang`` (past the time limit).
"""

from __future__ import annotations

import math
import multiprocessing as mp
import os
import time
import traceback
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import hypothesis.strategies as st
import numpy as np

FAILURES = (
    "silent_nan", "wrong_result", "internal_error", "panic", "other_exception", "abort", "hang",
)  # fmt: skip
OUTCOMES = ("ok", "refused_named", "refused_unnamed", "runtime_error", *FAILURES)

# Hostile values, and values that are fine, to mix into good calls.
HOSTILE: list[Any] = [
    math.nan,
    math.inf,
    -math.inf,
    0.0,
    -0.0,
    -1.0,
    1e300,
    -1e300,
    1e-300,
    5e-324,
    1.7976931348623157e308,
    10**400,
    -(10**400),
    2**63,
    2**64 + 1,
    True,
    False,
    None,
    "1.0",
    "abc",
    "",
    [1.0, 2.0],
    [],
    [[1.0, 2.0], [3.0, 4.0]],
    {"a": 1},
    (math.nan, 1.0),
    (1.0, 0.0),
    (0.0,),
    object(),
    np.float64(math.nan),
    np.array([1.0, math.inf]),
    np.zeros((2, 2)),
    np.int64(-5),
    complex(1.0, 1.0),
    540.0,  # km for m
    20.0,  # degrees for rad
    4.89,
    1e12,
    -600.0,
]


def hostile_values() -> st.SearchStrategy[Any]:
    return st.one_of(
        st.sampled_from(HOSTILE),
        st.floats(allow_nan=True, allow_infinity=True),
        st.integers(min_value=-(2**70), max_value=2**70),
        st.text(max_size=4),
    )


def _base_calls() -> dict[str, tuple[Callable[..., Any], dict[str, Any]]]:
    """Each entry point with arguments that run cheaply (a short span, a low orbit, a small
    design, the step budget of the fuzz): the fuzz replaces some of them."""
    import thermojitter as tj
    from thermojitter.scenario import parse_scenario

    low = tj.Orbit(radius=7.0e6, period=5828.5)
    panel = tj.Panel.paper()
    geo = tj.Orbit.geo_equinox()
    budget = {"max_steps": 200_000}
    fast = {"rtol": 1e-6, "atol": 1e-8}

    def orbit_call(method: str) -> Callable[..., Any]:
        def call(_self: Any = geo, **kw: Any) -> Any:
            return getattr(_self, method)(**kw)

        return call

    def scenario(**tables: Any) -> Any:
        return parse_scenario({k: v for k, v in tables.items() if v is not None}, "fuzz.toml")

    return {
        "Panel": (tj.Panel, {"length": 50.0, "damping": 3.0, "specific_heat": 900.0}),
        "Panel.replace": (
            lambda _self, **kw: _self.replace(**kw),
            {"_self": panel, "conductance": 25.0, "youngs_modulus": 70e9},
        ),
        "Orbit": (tj.Orbit, {"radius": 42_164e3, "period": 86_164.0, "phase0": 0.0}),
        "Orbit.leo": (tj.Orbit.leo, {"altitude": 540e3}),
        "Orbit.geo_year": (tj.Orbit.geo_year, {"start_date": "2026-03-01"}),
        "shadow_intervals": (orbit_call("shadow_intervals"), {"t0": 0.0, "t1": 1e5}),
        "eclipses": (orbit_call("eclipses"), {"_self": tj.Orbit.geo_year(), "t0": 0.0, "t1": 1e6}),
        "umbra_intervals": (orbit_call("umbra_intervals"), {"t0": 0.0, "t1": 1e5}),
        "breakpoints": (orbit_call("breakpoints"), {"t0": 0.0, "t1": 1e5}),
        "illumination": (orbit_call("illumination"), {"t": [0.0, 4.3e4]}),
        "flux_scale": (orbit_call("flux_scale"), {"_self": tj.Orbit.geo_year(), "t": 1e6}),
        "eclipse_durations": (orbit_call("eclipse_durations"), {"t0": 0.0, "t1": 2e5}),
        "steady_state": (tj.steady_state, {"panel": panel, "coupled": True, "flux": 1.0}),
        "simulate": (
            tj.simulate,
            {
                "panel": panel,
                "orbit": geo,
                "t_span": (0.0, 60.0),
                "model": "nonlinear",
                "coupled": True,
                "method": "rk45",
                "dt_out": 1.0,
                "y0": None,
                **fast,
                **budget,
            },
        ),
        "simulate rk4": (
            tj.simulate,
            {
                "panel": panel,
                "orbit": geo,
                "t_span": (0.0, 30.0),
                "method": "rk4",
                "dt": 0.05,
                "t_eval": [0.0, 10.0, 30.0],
            },
        ),
        "simulate_thermal": (
            tj.simulate_thermal,
            {"panel": panel, "orbit": geo, "t_span": (0.0, 600.0), "layers": 2, **budget},
        ),
        "simulate_hinge": (
            tj.simulate_hinge,
            {"panel": panel, "moment": 400.0, "t_span": (0.0, 30.0), "y0": (0.0, 0.0), **budget},
        ),
        "hinge_energy": (
            tj.hinge_energy,
            {"panel": panel, "theta": [0.0, 0.1], "theta_dot": [0.0, 0.01], "moment": 400.0},
        ),
        "hinge_stiffness": (tj.hinge_stiffness, {"panel": panel, "criterion": "frequency"}),
        "natural_frequency": (tj.natural_frequency, {"panel": panel}),
        "beam_frequency": (tj.beam_frequency, {"panel": panel}),
        "flutter": (tj.flutter, {"panel": panel, "coupled": True, "flux": 1.0}),
        "stability_map": (
            tj.stability_map,
            {
                "panel": panel,
                "x": ("damping", [0.0, 3.0]),
                "y": ("conductance", [10.0, 25.0]),
                "flux": 1.0,
                "progress": False,
            },
        ),
        "linear_thermal_response": (
            tj.linear_thermal_response,
            {"panel": panel, "omega": None, "T_star": None, "flux": 1.0},
        ),
        "simulate_orbits": (
            tj.simulate_orbits,
            {
                "panel": panel,
                "orbit": low,
                "n_orbits": 1,
                "theta_limit": 0.3,
                "window": 600.0,
                "steps_per_period": 10.0,
                "progress": False,
                **fast,
                **budget,
            },
        ),
        "monte_carlo": (
            tj.monte_carlo,
            {
                "panel": panel,
                "orbit": low,
                "vary": {"damping": ("uniform", 1.0, 4.0)},
                "n": 2,
                "seed": 1,
                "horizon": 1,
                "threads": 1,
                "progress": False,
                **fast,
                **budget,
            },
        ),
        "sweep": (
            tj.sweep,
            {
                "panel": panel,
                "orbit": low,
                "grid": {"damping": [1.0, 3.0]},
                "threads": 1,
                "progress": False,
                **fast,
                **budget,
            },
        ),
        "scenario": (
            scenario,
            {
                "panel": {"damping": 3.0},
                "orbit": {"preset": "leo", "altitude": 540e3},
                "simulation": {"t_end": 600.0, "rtol": 1e-8},
                "output": {"format": "csv"},
            },
        ),
        # Damaged files: the bytes of a good one, mutated (see ``damaged``).
        "scenario file": (_scenario_file, {"text": SCENARIO_TEXT}),
        "checkpoint": (_resume, {"text": b""}),
    }


SCENARIO_TEXT = b"""# a scenario file
[panel]
damping = 3.0
length = 50.0

[orbit]
preset = "leo"
altitude = 540e3

[simulation]
t_end = 600.0
rtol = 1e-8
keep = "samples"

[output]
format = "csv"
plots = false
"""

# Byte strings spliced into a file: TOML and JSON syntax, hostile numbers, bad encodings.
TOKENS = [
    b"", b"nan", b"inf", b"-inf", b"-1", b"0", b"1e400", b"9" * 400, b'"x"', b"[]", b"{}",
    b"true", b"null", b"=", b"[panel]", b"[[orbit]]", b"\n", b"\x00", b"\xff\xfe", b'"', b",",
    b"}", b"]", b"damping = ", b'"content"', b'"checksum": "0"', b"1.0000000000000002",
]  # fmt: skip


def damaged(base: bytes) -> st.SearchStrategy[bytes]:
    """``base`` truncated, with a bit flipped, a line removed or repeated, or a piece replaced
    by a token."""
    n = len(base)
    lines = base.split(b"\n")

    def flip(i: int, bit: int) -> bytes:
        return base[:i] + bytes([base[i] ^ (1 << bit)]) + base[i + 1 :]

    def splice(i: int, width: int, token: bytes) -> bytes:
        return base[:i] + token + base[i + width :]

    def line(j: int, repeat: bool) -> bytes:
        kept = lines[: j + 1] + lines[j:] if repeat else lines[:j] + lines[j + 1 :]
        return b"\n".join(kept)

    return st.one_of(
        st.integers(0, n - 1).map(lambda k: base[:k]),
        st.builds(flip, st.integers(0, n - 1), st.integers(0, 7)),
        st.builds(splice, st.integers(0, n), st.integers(0, 24), st.sampled_from(TOKENS)),
        st.builds(line, st.integers(0, len(lines) - 1), st.booleans()),
    )


def _scenario_file(text: bytes) -> Any:
    import tempfile
    from pathlib import Path

    from thermojitter.scenario import load_scenario

    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "fuzz.toml"
        path.write_bytes(text)
        return load_scenario(path)


_RESUME: dict[str, Any] = {}


def _resume_call() -> tuple[Any, dict[str, Any]]:
    """The long run whose checkpoint the fuzz damages: two orbits of the low orbit."""
    import thermojitter as tj

    low = tj.Orbit(radius=7.0e6, period=5828.5)
    args = {"rtol": 1e-6, "atol": 1e-8, "progress": False, "window": 600.0}
    return lambda **kw: tj.simulate_orbits(tj.Panel.paper(), low, 2, **args, **kw), args


def checkpoint_reference() -> tuple[bytes, Any]:
    """(the bytes of an intact checkpoint, the run it answers), made once per process."""
    if not _RESUME:
        import tempfile
        from pathlib import Path

        run, _ = _resume_call()
        with tempfile.TemporaryDirectory() as folder:
            path = Path(folder) / "run.json"
            result = run(checkpoint=path)
            _RESUME["bytes"], _RESUME["result"] = path.read_bytes(), result
    return _RESUME["bytes"], _RESUME["result"]


def _resume(text: bytes) -> Any:
    """Resumes the reference run from a damaged copy of its checkpoint."""
    import tempfile
    from pathlib import Path

    run, _ = _resume_call()
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "run.json"
        path.write_bytes(text)
        return run(checkpoint=path)


@dataclass
class Example:
    """One call: the entry point, the names of the replaced arguments and their values."""

    target: str
    changes: dict[str, Any] = field(default_factory=dict)


@st.composite
def examples(draw: st.DrawFn, targets: list[str] | None = None) -> Example:
    calls = _base_calls()
    name = draw(st.sampled_from(sorted(targets or calls)))
    base = calls[name][1]
    # The receiver of a method ("_self") is not an argument a user passes: it stays valid.
    keys = sorted(k for k in base if not k.startswith("_"))
    if name == "scenario file":
        return Example(name, {"text": draw(damaged(SCENARIO_TEXT))})
    if name == "checkpoint":
        return Example(name, {"text": draw(damaged(checkpoint_reference()[0]))})
    if name == "scenario":
        # Replace a key of one table (or the table itself) in the scenario data.
        table = draw(st.sampled_from(keys))
        fields = {
            "panel": ["damping", "youngs_modulus", "length", "mass_per_length"],
            "orbit": ["preset", "altitude", "radius", "period", "phase0", "shadow", "season"],
            "simulation": ["t_end", "orbits", "years", "rtol", "atol", "dt", "dt_out", "keep",
                           "method", "coupled", "theta_limit_deg"],
            "output": ["format", "plots"],
        }[table]  # fmt: skip
        key = draw(st.sampled_from([*fields, None]))
        value = draw(hostile_values())
        return Example(name, {f"{table}.{key}" if key else table: value})
    count = draw(st.integers(1, min(3, len(keys))))
    chosen = draw(st.lists(st.sampled_from(keys), min_size=count, max_size=count, unique=True))
    return Example(name, {k: draw(_value_for(base[k])) for k in chosen})


def _value_for(good: Any) -> st.SearchStrategy[Any]:
    """A hostile value, or (one time in three) a fair change of a good number, so that many
    calls get past the checks and run."""
    if isinstance(good, float) and not isinstance(good, bool):
        fair = st.floats(0.25, 4.0).map(lambda f: good * f if good else f - 1.0)
        return st.one_of(hostile_values(), hostile_values(), fair)
    return hostile_values()


def arguments(example: Example) -> tuple[Callable[..., Any], dict[str, Any]]:
    call, base = _base_calls()[example.target]
    kwargs = {k: (dict(v) if isinstance(v, dict) else v) for k, v in base.items()}
    for key, value in example.changes.items():
        if example.target == "scenario" and "." in key:
            table, sub = key.split(".", 1)
            kwargs[table] = {**kwargs[table], sub: value}
        else:
            kwargs[key] = value
    return call, kwargs


# Result fields where NaN is documented (no eclipse in an orbit, no umbra, a sample that failed).
NAN_ALLOWED = {
    "t_entry", "t_exit", "entry_theta_min", "exit_theta_max", "entry_peak", "exit_peak",
    "t_threshold", "eclipses", "critical_damping", "orbit_threshold", "orbit_limit",
    "amplitude_slope",
}  # fmt: skip


# Settings echoed in a result where +inf is the documented value "no cap" (max_step).
INF_ALLOWED = {"max_step"}


def _non_finite(value: Any, name: str = "") -> str | None:
    """The name of a non-finite number in a result, or None."""
    if name in NAN_ALLOWED:
        return None
    if isinstance(value, (bool, np.bool_, str, bytes)) or value is None:
        return None
    if isinstance(value, (float, int, np.number)):
        if name in INF_ALLOWED and value == math.inf:
            return None
        return None if np.isfinite(value) else name or "value"
    if isinstance(value, np.ndarray):
        if value.dtype.kind in "fc" and not np.all(np.isfinite(value)):
            return name or "array"
        return None
    if hasattr(value, "to_numpy") and hasattr(value, "columns"):  # a DataFrame
        failed = value["error"].notna() if "error" in value.columns else None
        for col in value.columns:
            if col in NAN_ALLOWED or value[col].dtype.kind not in "fc":
                continue
            bad = ~np.isfinite(value[col].to_numpy(float))
            if failed is not None:
                bad &= ~failed.to_numpy()
            if bad.any():
                return str(col)
        return None
    if isinstance(value, dict):
        for k, v in value.items():
            found = _non_finite(v, str(k))
            if found:
                return found
        return None
    if isinstance(value, (list, tuple)):
        if name == "" and value and all(isinstance(v, tuple) and len(v) == 5 for v in value):
            return None
        for v in value:
            found = _non_finite(v, name)
            if found:
                return found
        return None
    if hasattr(value, "__dict__"):
        return _non_finite({k: v for k, v in vars(value).items() if not k.startswith("_")}, name)
    return None


def _eclipse_rows(rows: Any) -> str | None:
    """``Orbit.eclipses`` rows (deepest point, first contact, last contact, umbra entry, umbra
    exit): the first three finite; the umbra pair NaN together (documented: a penumbral eclipse
    has no umbra) or finite inside the contacts."""
    rows = np.asarray(rows, dtype=float)
    if rows.ndim != 2 or rows.shape[1] != 5:
        return f"eclipses of shape {rows.shape}"
    if not np.all(np.isfinite(rows[:, :3])):
        return "eclipses[:, :3]"
    umbra = rows[:, 3:]
    none = np.isnan(umbra).all(axis=1)
    inside = np.isfinite(umbra).all(axis=1)
    inside &= (
        (rows[:, 1] <= umbra[:, 0]) & (umbra[:, 0] <= umbra[:, 1]) & (umbra[:, 1] <= rows[:, 2])
    )
    if not np.all(none | inside):
        return "eclipses[:, 3:]"
    return None


def classify(example: Example) -> tuple[str, str]:
    """Runs one example here and returns (outcome, detail)."""
    import thermojitter as tj

    call, kwargs = arguments(example)
    try:
        result = call(**kwargs)
    except tj.InternalError as exc:
        return "internal_error", str(exc)[:200]
    except (tj.IntegrationError, tj.ConvergenceError) as exc:
        return "runtime_error", str(exc)[:200]
    except (ValueError, TypeError) as exc:
        message = str(exc)
        named = getattr(exc, "parameter", None) or getattr(exc, "key", None)
        if not named and example.target == "scenario file":
            named = getattr(exc, "path", None)  # the file itself is what is wrong
        if not named:
            names = [k.split(".")[-1] for k in example.changes]
            named = next((n for n in names if n and n in message), None)
        return ("refused_named" if named else "refused_unnamed"), message[:200]
    except Exception as exc:
        return "other_exception", f"{type(exc).__name__}: {exc}"[:200] + traceback.format_exc(
            limit=-2
        )[-300:]
    except BaseException as exc:  # PanicException derives from BaseException
        if type(exc).__name__ == "PanicException":
            return "panic", str(exc)[:200]
        raise
    bad = _eclipse_rows(result) if example.target == "eclipses" else _non_finite(result)
    if bad:
        return "silent_nan", f"{bad} is not finite"
    if example.target == "checkpoint":
        # A damaged checkpoint is refused or recomputed; what it returns is the run itself.
        reference = checkpoint_reference()[1]
        for name, column in reference.columns.items():
            if not np.array_equal(column, result.columns[name], equal_nan=True):
                return "wrong_result", f"{name} differs from the run's own"
    return "ok", ""


def _worker(conn: Any) -> None:
    import warnings

    warnings.simplefilter("ignore")
    while True:
        example = conn.recv()
        if example is None:
            return
        conn.send(classify(example))


def _cpu_seconds(pid: int) -> float | None:
    """CPU time (user + system, every thread) the process ``pid`` has used, s; None where /proc
    cannot tell."""
    try:
        fields = open(f"/proc/{pid}/stat").read().rsplit(")", 1)[1].split()  # noqa: SIM115
        return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")
    except (OSError, IndexError, ValueError):
        return None


class Runner:
    """Runs examples in a worker process, one at a time, with a watchdog: a worker that dies
    (abort) or does not answer (hang) is counted and replaced.

    A hang is judged by the CPU time the worker spends on the call (every thread), not by the
    clock: other jobs share the machine, and a call that waits for a core is not hanging. A call
    is a hang once it has used ``limit`` s of CPU, or (a worker stuck without computing, or where
    the CPU time is unknown) ``wall_factor`` × ``limit`` s of wall time. ``last_cpu`` and
    ``last_wall`` hold the last call's figures.
    """

    def __init__(self, limit: float = 20.0, wall_factor: float = 6.0) -> None:
        self.limit = limit
        self.wall_limit = wall_factor * limit
        self.ctx = mp.get_context("spawn")
        self.proc: Any = None
        self.conn: Any = None
        self.last_cpu = 0.0
        self.last_wall = 0.0

    def _start(self) -> None:
        parent, child = self.ctx.Pipe()
        self.proc = self.ctx.Process(target=_worker, args=(child,), daemon=True)
        self.proc.start()
        self.conn = parent

    def run(self, example: Example) -> tuple[str, str]:
        if self.proc is None or not self.proc.is_alive():
            self._start()
        try:
            self.conn.send(example)
        except (BrokenPipeError, OSError):
            self._start()
            self.conn.send(example)
        cpu0 = _cpu_seconds(self.proc.pid) or 0.0
        start = time.monotonic()
        answered = False
        while True:
            if self.conn.poll(0.05):
                answered = True
                break
            cpu = _cpu_seconds(self.proc.pid)
            self.last_cpu = (cpu - cpu0) if cpu is not None else 0.0
            self.last_wall = time.monotonic() - start
            if not self.proc.is_alive() or self.last_cpu > self.limit:
                break
            if self.last_wall > self.wall_limit or (cpu is None and self.last_wall > self.limit):
                break
        cpu = _cpu_seconds(self.proc.pid)
        if cpu is not None:
            self.last_cpu = cpu - cpu0
        self.last_wall = time.monotonic() - start
        if answered:
            try:
                return self.conn.recv()  # type: ignore[no-any-return]
            except (EOFError, OSError):  # the worker died while answering
                pass
        if self.proc.is_alive():
            self.proc.kill()
            self.proc.join()
            self.proc = None
            return "hang", (
                f"no answer after {self.last_cpu:.1f} s of CPU ({self.last_wall:.1f} s wall); "
                f"limits {self.limit:g} s CPU, {self.wall_limit:g} s wall"
            )
        code = self.proc.exitcode
        self.proc = None
        return "abort", f"worker died (exit code {code})"

    def close(self) -> None:
        if self.proc is not None and self.proc.is_alive():
            self.conn.send(None)
            self.proc.join(5)
            if self.proc.is_alive():
                self.proc.kill()
