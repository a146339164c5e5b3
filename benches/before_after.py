"""Two builds of thermojitter timed side by side in one sitting: the same public calls under two
Python interpreters (each with its own build installed), every timing of one followed by the
same timing of the other, so that both see the same load. Prints each build's machine lines, a
table of median wall and CPU times with the ratios after/before, and the load average of each
case's timings.

    python benches/before_after.py --before /path/to/venv-a/bin/python \\
                                   --after /path/to/venv-b/bin/python [--repeat 5] [--cases ...]

The calls are those both builds have (the public API as it stood before the hybrid's speed-up):

- ``geo10-hybrid``: ten GEO years of Table 1 (``Orbit.geo_year("2026-01-01")``, 3663 orbits),
  ``simulate_orbits(method="hybrid")``;
- ``geo-rk45``: three orbits of the same year in its spring eclipse season (penumbra), rk45
  with the hinge-resolving step cap;
- ``leo-hybrid`` and ``leo-rk45``: 300 orbits of ``Orbit.leo(540e3)``;
- ``montecarlo``: eight samples of one GEO orbit (c_d uniform in [2.5, 4]) on one thread;
- ``simulate``: ``tj.simulate`` of the paper's orbit (GEO at equinox) over one orbit.

Each worker runs one untimed call of a case before its timings. CPU time is the process's
(``time.process_time``), which on a shared machine is the steadier figure.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import time
import warnings
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

CASES = ("geo10-hybrid", "geo-rk45", "leo-hybrid", "leo-rk45", "montecarlo", "simulate")


def orbits(orbit: Any, n: int, method: str) -> Callable[[], str]:
    import thermojitter as tj

    def run() -> str:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            runs = tj.simulate_orbits(tj.Panel.paper(), orbit, n, method=method, progress=False)
        return f"{len(runs)} orbits, {runs.n_steps} steps"

    return run


def case(name: str) -> Callable[[], str]:
    """The call a case times; it returns a line saying what it did (the same for both builds
    unless their results differ)."""
    import thermojitter as tj

    if name == "geo10-hybrid":
        return orbits(tj.Orbit.geo_year("2026-01-01"), 3663, "hybrid")
    if name == "geo-rk45":
        return orbits(tj.Orbit.geo_year("2026-03-10"), 3, "rk45")
    if name in ("leo-hybrid", "leo-rk45"):
        return orbits(tj.Orbit.leo(540e3), 300, name.split("-")[1])
    if name == "montecarlo":

        def mc() -> str:
            frame = tj.monte_carlo(
                tj.Panel.paper(),
                tj.Orbit.geo_equinox(),
                vary={"damping": ("uniform", 2.5, 4.0)},
                n=8,
                seed=1,
                threads=1,
                progress=False,
            )
            return f"{len(frame)} samples"

        return mc
    if name == "simulate":
        orbit = tj.Orbit.geo_equinox()

        def sim() -> str:
            sol = tj.simulate(tj.Panel.paper(), orbit, (0.0, orbit.period))
            return f"{len(sol.t)} samples"

        return sim
    raise SystemExit(f"unknown case {name!r}; known: {', '.join(CASES)}")


def worker() -> None:
    """Reads case names on stdin, answers each with one JSON line: wall and CPU seconds of one
    call (after one untimed call the first time a case is asked), the load, what it did."""
    import machine  # benches/machine.py

    import thermojitter as tj

    hello = {"describe": machine.describe(), "version": tj.__version__, "path": tj.__file__}
    print(json.dumps(hello), flush=True)
    calls: dict[str, Callable[[], str]] = {}
    for line in sys.stdin:
        name = line.strip()
        if not name:
            continue
        if name not in calls:
            calls[name] = case(name)
            calls[name]()
        start, start_cpu = time.perf_counter(), time.process_time()
        what = calls[name]()
        wall, cpu = time.perf_counter() - start, time.process_time() - start_cpu
        load = os.getloadavg()[0] if hasattr(os, "getloadavg") else float("nan")
        print(json.dumps({"wall": wall, "cpu": cpu, "load": load, "what": what}), flush=True)


class Worker:
    def __init__(self, python: str) -> None:
        self.proc = subprocess.Popen(
            [python, str(Path(__file__).resolve()), "--worker"],
            stdin=subprocess.PIPE,
            stdout=subprocess.PIPE,
            text=True,
            cwd=Path(__file__).resolve().parent,
        )
        self.hello = self.answer()

    def answer(self) -> dict[str, Any]:
        assert self.proc.stdout is not None
        line = self.proc.stdout.readline()
        if not line:
            raise SystemExit(f"worker {self.proc.args[0]} ended early")
        result: dict[str, Any] = json.loads(line)
        return result

    def time(self, name: str) -> dict[str, Any]:
        assert self.proc.stdin is not None
        self.proc.stdin.write(name + "\n")
        self.proc.stdin.flush()
        return self.answer()

    def close(self) -> None:
        assert self.proc.stdin is not None
        self.proc.stdin.close()
        self.proc.wait()


def parse(argv: Sequence[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--before", default=sys.executable, help="interpreter of the old build")
    parser.add_argument("--after", default=sys.executable, help="interpreter of the new build")
    parser.add_argument("--repeat", type=int, default=5, help="timings of each case and build")
    parser.add_argument("--cases", nargs="+", default=list(CASES), choices=CASES)
    return parser.parse_args(argv)


def main(argv: Sequence[str] | None = None) -> None:
    args = parse(argv)
    if args.worker:
        worker()
        return
    builds = {"before": Worker(args.before), "after": Worker(args.after)}
    for label, w in builds.items():
        print(f"{label}: {args.before if label == 'before' else args.after}")
        print(f"  thermojitter {w.hello['version']} from {w.hello['path']}")
        print("  " + w.hello["describe"].replace("\n", "\n  "))
    print(f"\nmedian of {args.repeat} timings per case and build, taken in turn\n")
    head = (
        f"| {'case':13s} | {'before wall':>11s} | {'after wall':>10s} | {'ratio':>5s} "
        f"| {'before CPU':>10s} | {'after CPU':>9s} | {'ratio':>5s} | {'load':>9s} |"
    )
    print(head)
    print("|" + "|".join("-" * (len(c)) for c in head.split("|")[1:-1]) + "|")
    notes = []
    for name in args.cases:
        got: dict[str, list[dict[str, Any]]] = {label: [] for label in builds}
        for _ in range(args.repeat):
            for label, w in builds.items():
                got[label].append(w.time(name))

        def median(label: str, key: str, runs: dict[str, list[dict[str, Any]]] = got) -> float:
            return statistics.median(r[key] for r in runs[label])

        bw, aw = median("before", "wall"), median("after", "wall")
        bc, ac = median("before", "cpu"), median("after", "cpu")
        loads = [r["load"] for label in builds for r in got[label]]
        print(
            f"| {name:13s} | {bw:9.3f} s | {aw:8.3f} s | {aw / bw:5.2f} "
            f"| {bc:8.3f} s | {ac:7.3f} s | {ac / bc:5.2f} | {min(loads):.1f}-{max(loads):.1f} |",
            flush=True,
        )
        for label in builds:
            notes.append(f"  {name} {label}: {got[label][-1]['what']}")
    for w in builds.values():
        w.close()
    print("\nwhat each run did (the last timing):")
    print("\n".join(notes))
    load = " ".join(f"{x:.2f}" for x in os.getloadavg()) if hasattr(os, "getloadavg") else "n/a"
    print(f"\nload average at the end: {load}")


if __name__ == "__main__":
    main()
