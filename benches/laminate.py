"""One GEO orbit of a 20-node laminate against the two-layer model on the same panel.

The panels are the examples' CFRP/honeycomb solar-array wing and aluminium boom
(``examples/laminates.py``); the two-layer model runs on the panel ``Panel.from_laminate`` makes
of each (the same mass, heat capacity, E I, face-to-face conductance). Both are timed through the
public API, alternately, and the median of the repeats is reported with the ratio. Target: the
20-node run costs no more than 3x the two-layer run.

    python benches/laminate.py [--repeats 5] [--nodes 20]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

import thermojitter as tj

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))
from laminates import boom, wing  # noqa: E402
from machine import describe  # noqa: E402


def timed(run: Callable[[], int], repeats: int) -> tuple[float, int]:
    """Median wall time of `repeats` calls, and the steps of one."""
    times, steps = [], 0
    for _ in range(repeats):
        start = time.perf_counter()
        steps = run()
        times.append(time.perf_counter() - start)
    return statistics.median(times), steps


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    parser.add_argument("--nodes", type=int, default=20)
    args = parser.parse_args()
    orbit = tj.Orbit.geo_equinox()
    print(describe())
    print(f"one GEO orbit ({orbit.period:.0f} s), rk45 rtol 1e-8, atol 1e-10")
    print()
    print("| panel | run | model | wall s | steps | ns/step | x two-layer |")
    print("|---|---|---|---|---|---|---|")
    worst = 0.0
    for name, panel in (("CFRP wing", wing()), ("Al boom", boom())):
        runs: dict[str, Callable[[int | None], int]] = {
            "simulate": lambda layers, p=panel: (
                tj.simulate(
                    p, orbit, (0.0, orbit.period), layers=layers, t_eval=[orbit.period]
                ).n_steps
            ),
            "simulate_orbits": lambda layers, p=panel: (
                tj.simulate_orbits(
                    p, orbit, 1, layers=layers, progress=False, method="rk45"
                ).n_steps
            ),
        }
        for run_name, run in runs.items():
            results = {}
            # Alternate the two models so that a change of load hits both alike.
            for _ in range(args.repeats):
                for layers in (None, args.nodes):
                    t, steps = timed(lambda r=run, n=layers: r(n), 1)
                    results.setdefault(layers, ([], steps))[0].append(t)
            base = statistics.median(results[None][0])
            for layers, (times, steps) in results.items():
                wall = statistics.median(times)
                ratio = wall / base
                if layers is not None:
                    worst = max(worst, ratio)
                label = "two-layer" if layers is None else f"{layers} nodes"
                print(
                    f"| {name} | {run_name} | {label} | {wall:.3f} | {steps} |"
                    f" {wall / steps * 1e9:.0f} | {ratio:.2f} |"
                )
    print()
    print(f"largest ratio: {worst:.2f} (target <= 3)")
    # The load at the end too: a change of load during the run shows here.
    print(describe().splitlines()[1])


if __name__ == "__main__":
    main()
