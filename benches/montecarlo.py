"""Monte Carlo throughput: 200 panels around Table 1, one GEO orbit each (rk45, rtol 1e-8,
atol 1e-10), on 1 and 2 rayon threads; and the cost of a sample against one ``tj.simulate`` call
of the same orbit for the same panels (the sample adds the flutter analysis, the critical damping
and the per-orbit summary). Run it on a quiet machine (check ``uptime``).

    python benches/montecarlo.py [--n 200] [--threads 1 2] [--repeat 1] [--simulate 50]
"""

from __future__ import annotations

import argparse
import os
import time
from typing import Any

import thermojitter as tj

RTOL, ATOL = 1e-8, 1e-10
VARY = {
    "damping": ("uniform", 2.0, 4.0),
    "emissivity_back": ("normal", 0.3, 0.03),
    "conductance": ("normal", 25.0, 2.5),
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--n", type=int, default=200, help="samples")
    parser.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--repeat", type=int, default=1, help="runs per thread count (best)")
    parser.add_argument("--simulate", type=int, default=50, help="panels run with tj.simulate")
    args = parser.parse_args()

    panel, orbit = tj.Panel.paper(), tj.Orbit.geo_equinox()
    print(
        f"load average: {' '.join(f'{x:.2f}' for x in os.getloadavg())} on {os.cpu_count()} cores"
    )
    print(f"{args.n} samples x 1 GEO orbit, rtol={RTOL:g}, atol={ATOL:g}, vary={list(VARY)}")

    def batch(threads: int) -> Any:
        return tj.monte_carlo(
            panel, orbit, vary=VARY, n=args.n, seed=1, threads=threads, rtol=RTOL, atol=ATOL,
            progress=False,
        )  # fmt: skip

    walls: dict[int, float] = {}
    cores: dict[int, float] = {}
    frames = {}
    for threads in args.threads:
        runs = []
        for _ in range(args.repeat):
            cpu, start = time.process_time(), time.perf_counter()
            frames[threads] = batch(threads)
            wall = time.perf_counter() - start
            runs.append((wall, (time.process_time() - cpu) / wall))
        walls[threads], cores[threads] = min(runs)
    frame = frames[args.threads[0]]
    steps = int(frame["n_steps"].sum())
    base = walls[args.threads[0]]
    # "cores busy": process CPU time over wall time (below `threads` when others hold cores).
    print(
        f"{'threads':>8}{'wall s':>10}{'samples/s':>12}{'speed-up':>10}{'cores busy':>12}"
        f"{'ns/step':>10}"
    )
    for threads, wall in walls.items():
        print(
            f"{threads:>8}{wall:>10.2f}{args.n / wall:>12.1f}{base / wall:>10.2f}"
            f"{cores[threads]:>12.2f}{1e9 * wall * threads / steps:>10.0f}"
        )
    same = all(frames[t].equals(frame) for t in frames)
    print(f"identical frames across thread counts: {same}")

    if 1 not in walls:
        return
    # The same panels, one call each on this thread: tj.simulate (end state only) and
    # tj.simulate_orbits (the per-orbit summary a sample is reduced from).
    k = min(args.simulate, args.n)
    panels = [
        panel.replace(**{name: float(row[name]) for name in VARY})
        for _, row in frame.iloc[:k].iterrows()
    ]
    # Samples resolve the hinge period (step <= T_n/40, as tj.simulate_orbits does); the same
    # cap here makes both integrate the same steps, so the difference is the sample's own cost.
    start = time.perf_counter()
    for p in panels:
        cap = 1.0 / (40.0 * tj.natural_frequency(p))
        tj.simulate(
            p, orbit, (0.0, orbit.period), rtol=RTOL, atol=ATOL, t_eval=[orbit.period], max_step=cap
        )
    per_sim = (time.perf_counter() - start) / k
    start = time.perf_counter()
    for p in panels:
        tj.simulate_orbits(p, orbit, 1, rtol=RTOL, atol=ATOL, progress=False)
    per_orbits = (time.perf_counter() - start) / k
    per_sample = walls[1] / args.n
    mc_steps = int(frame["n_steps"].iloc[:k].sum())
    print(f"per sample, same {k} panels ({mc_steps // k} steps each):")
    for name, t in (
        ("tj.simulate (end state, same cap)", per_sim),
        ("tj.simulate_orbits (summary)", per_orbits),
        ("tj.monte_carlo, 1 thread", per_sample),
    ):
        print(f"  {name:<30}{1e3 * t:8.1f} ms {100.0 * (t / per_sim - 1.0):+8.1f} %")
    print(f"overhead of a sample over one tj.simulate call: {1e3 * (per_sample - per_sim):+.1f} ms")


if __name__ == "__main__":
    main()
