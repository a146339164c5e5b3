"""One GEO orbit of a 20-node laminate against the two-layer model on the same panel.

The panels are the examples' CFRP/honeycomb solar-array wing and aluminium boom
(``examples/laminates.py``); the two-layer model runs on the panel ``Panel.from_laminate`` makes
of each (the same mass, heat capacity, E I, face-to-face conductance). Both are timed through the
public API, alternately, and the median of the repeats is reported with the ratio. Target: the
20-node run costs no more than 3x the two-layer run.

Then the long runs of the 20-node wing: ten orbits and one year of ``geo_year`` (eclipse seasons,
penumbra, eccentric Sun), the hybrid propagator against the full rk45 run in the same process,
with the largest relative difference of the per-orbit summaries (``--no-year`` skips the year,
whose full run takes minutes).

    python benches/laminate.py [--repeats 5] [--nodes 20] [--no-year] [--no-orbit]
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

import thermojitter as tj

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))
sys.path.insert(0, str(Path(__file__).resolve().parent))
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
    parser.add_argument("--no-year", action="store_true", help="skip the one-year long run")
    parser.add_argument("--no-orbit", action="store_true", help="skip the one-orbit costs")
    args = parser.parse_args()
    print(describe())
    if not args.no_orbit:
        one_orbit(args)
    long_runs(args.nodes, year=not args.no_year)


def long_runs(nodes: int, *, year: bool) -> None:
    """The wing's hybrid run against its full rk45 run over ten orbits and a year."""
    panel = wing()
    orbit = tj.Orbit.geo_year("2026-01-01")
    spans = [10] + ([orbit_count_of_year(orbit)] if year else [])
    print()
    print(f"CFRP wing, {nodes} nodes, geo_year from 2026-01-01: hybrid against full rk45")
    print()
    print(
        "| orbits | full s | full steps | hybrid s | hybrid steps | speed-up | worst summary diff |"
    )
    print("|---|---|---|---|---|---|---|")
    for n in spans:
        t0 = time.process_time()
        full = tj.simulate_orbits(
            panel, orbit, n, layers=nodes, method="rk45", max_steps=10**10, orbits_per_call=64
        )
        t_full = time.process_time() - t0
        t0 = time.process_time()
        hybrid = tj.simulate_orbits(panel, orbit, n, layers=nodes, method="hybrid")
        t_hybrid = time.process_time() - t0
        worst = worst_difference(full, hybrid)
        print(
            f"| {n} | {t_full:.2f} | {full.n_steps} | {t_hybrid:.3f} | {hybrid.n_steps} |"
            f" {t_full / t_hybrid:.0f}x | {worst} |"
        )
    print("(CPU seconds of this process, the two runs one after the other)")


def orbit_count_of_year(orbit: tj.Orbit) -> int:
    return round(365.25 * 86400.0 / orbit.period)


def worst_difference(full: tj.OrbitSummaries, hybrid: tj.OrbitSummaries) -> str:
    """The largest difference of each metric, relative where the full run's value is at least
    5e-5 rad, absolute below (the accuracy gate: 2 %, 1e-6 rad)."""
    out = []
    for name in ("amplitude", "exit_peak", "entry_peak", "jitter_rms", "theta_max", "theta_min"):
        a, b = np.asarray(full.columns[name]), np.asarray(hybrid.columns[name])
        ok = ~np.isnan(a)
        small = np.abs(a[ok]) < 5e-5
        err = np.abs(b[ok] - a[ok])
        rel = np.where(small, 0.0, err / np.where(small, 1.0, np.abs(a[ok])))
        absolute = np.where(small, err, 0.0)
        out.append(f"{name} {rel.max(initial=0.0):.1e} rel / {absolute.max(initial=0.0):.1e} rad")
    return "; ".join(out)


def one_orbit(args: argparse.Namespace) -> None:
    orbit = tj.Orbit.geo_equinox()
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
