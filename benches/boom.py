"""One GEO orbit of a boom (the thin-walled tube, ``tj.Boom``) against the paper's plate.

Both run one whole orbit through ``tj.simulate_orbits(method="rk45")``, whose step is capped at
the hinge's period over 40: the cost follows the hinge frequency, so the boom is the 1963-22A-like
beryllium–copper tube of ``examples/boom_1963_22a_bare.toml`` shortened until its first
frequency is the paper panel's (found by bisection on the length, the engine's frequency). Timed
alternately; the median of the repeats is reported with the ratio of the wall times and of the
time per right-hand side. Target: the boom's orbit costs no more than 1.5x the plate's.

Then each historical scenario (``examples/boom_*.toml``) through the ``run`` command, as a user
runs it, wall time from the command line to its written outputs. Target: under a minute each.

    python benches/boom.py [--repeats 7]
"""

from __future__ import annotations

import argparse
import statistics
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

import thermojitter as tj
from thermojitter.scenario import load_scenario

sys.path.insert(0, str(Path(__file__).resolve().parent))
from machine import describe, load  # noqa: E402

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def timed(
    runs: dict[str, Callable[[], tj.OrbitSummaries]], repeats: int
) -> dict[str, tuple[float, int, int]]:
    """Each run's median wall time over `repeats` calls made alternately (so that a change of
    the machine's load falls on both), and the steps and right-hand sides of one call."""
    times: dict[str, list[float]] = {name: [] for name in runs}
    counts: dict[str, tuple[int, int]] = {}
    for _ in range(repeats):
        for name, run in runs.items():
            start = time.perf_counter()
            out = run()
            times[name].append(time.perf_counter() - start)
            counts[name] = (out.n_steps, out.n_rhs)
    return {name: (statistics.median(times[name]), *counts[name]) for name in runs}


def matching_boom(frequency: float) -> tj.Boom:
    """The example boom with the length that puts its first mode at `frequency` (Hz)."""
    boom = load_scenario(EXAMPLES / "boom_1963_22a_bare.toml").panel
    assert isinstance(boom, tj.Boom)
    lo, hi = 0.5, boom.length
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        if boom.replace(length=mid).first_frequency > frequency:
            lo = mid
        else:
            hi = mid
    return boom.replace(length=0.5 * (lo + hi), damping=0.01)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    args = parser.parse_args()
    print(describe())
    plate = tj.Panel.paper()
    boom = matching_boom(tj.natural_frequency(plate))
    orbit = tj.Orbit.geo_equinox()
    print(
        f"plate: the paper's panel, hinge {tj.natural_frequency(plate):.4f} Hz; boom: "
        f"L = {boom.length:.3f} m, f1 = {boom.first_frequency:.4f} Hz, tau = "
        f"{boom.time_constant:.1f} s"
    )

    def run_plate() -> tj.OrbitSummaries:
        return tj.simulate_orbits(plate, orbit, 1, method="rk45", progress=False)

    def run_boom() -> tj.OrbitSummaries:
        return tj.simulate_orbits(boom, orbit, 1, method="rk45", progress=False)

    run_plate(), run_boom()  # warm up
    results = timed({"plate": run_plate, "boom": run_boom}, args.repeats)
    for name, (wall, steps, rhs) in results.items():
        print(f"{name:>5}: {wall * 1e3:8.2f} ms per orbit, {steps} steps, {rhs} rhs, "
              f"{wall / rhs * 1e9:6.1f} ns per rhs")  # fmt: skip
    (wp, _, rp), (wb, _, rb) = results["plate"], results["boom"]
    print(
        f"boom / plate: {wb / wp:.2f}x per orbit (target <= 1.5x), "
        f"{(wb / rb) / (wp / rp):.2f}x per rhs"
    )
    for path in sorted(EXAMPLES.glob("boom_*.toml")):
        with tempfile.TemporaryDirectory() as out:
            start = time.perf_counter()
            subprocess.run(
                [sys.executable, "-m", "thermojitter", "run", str(path), "--out", out,
                 "--no-progress"],
                check=True, capture_output=True,
            )  # fmt: skip
            wall = time.perf_counter() - start
        print(f"{path.name}: {wall:5.1f} s through `thermojitter run` (target < 60 s)")
    print(f"load average at the end: {load()}")


if __name__ == "__main__":
    main()
