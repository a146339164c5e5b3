"""Monte Carlo throughput: 200 panels around Table 1, one GEO orbit each (rk45, rtol 1e-8,
atol 1e-10), on 1 and 2 rayon threads, along both of the engine's paths in the same run: the
lockstep lanes (several samples per core at once, the default) and one sample at a time per core
(the scalar path); and the cost of a sample against one ``tj.simulate`` call of the same orbit for
the same panels (the sample adds the flutter analysis, the critical damping and the per-orbit
summary). The paths alternate, so a change of load touches both alike; run it on a quiet
machine anyway (the header prints the load average).

Where the processor has FMA both paths run the fused kernel; a third row runs the scalar path in a
child process with ``THERMOJITTER_KERNEL=portable``, the arithmetic without FMA (its frame is not
the same bits: the kernels agree within the integration's accuracy).

    python benches/montecarlo.py [--n 200] [--threads 1 2] [--repeat 1] [--simulate 50]
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time
from typing import Any

import machine  # benches/machine.py

import thermojitter as tj
import thermojitter.montecarlo.backends as mc

RTOL, ATOL = 1e-8, 1e-10
VARY = {
    "damping": ("uniform", 2.0, 4.0),
    "emissivity_back": ("normal", 0.3, 0.03),
    "conductance": ("normal", 25.0, 2.5),
}
PATHS = {"lockstep": True, "scalar": False}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--n", type=int, default=200, help="samples")
    parser.add_argument("--threads", type=int, nargs="+", default=[1, 2])
    parser.add_argument("--repeat", type=int, default=1, help="runs per thread count (best)")
    parser.add_argument("--simulate", type=int, default=50, help="panels run with tj.simulate")
    parser.add_argument("--scalar-only", action="store_true", help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.n < 1 or args.simulate < 1 or args.repeat < 1 or min(args.threads) < 1:
        parser.error("--n, --simulate, --repeat and --threads must be at least 1")

    panel, orbit = tj.Panel.paper(), tj.Orbit.geo_equinox()
    if args.scalar_only:
        # The child: one scalar batch on the kernel its environment picks; (wall, cores busy).
        cpu, start = time.process_time(), time.perf_counter()
        mc._LOCKSTEP = False
        tj.monte_carlo(
            panel, orbit, vary=VARY, n=args.n, seed=1, threads=args.threads[0], rtol=RTOL,
            atol=ATOL, progress=False,
        )  # fmt: skip
        wall = time.perf_counter() - start
        print(json.dumps([wall, (time.process_time() - cpu) / wall]))
        return
    print(machine.describe())
    print(f"{args.n} samples x 1 GEO orbit, rtol={RTOL:g}, atol={ATOL:g}, vary={list(VARY)}")

    def portable_scalar(threads: int) -> tuple[float, float]:
        """The scalar batch in a child process on the portable kernel: (wall s, cores busy)."""
        env = {**os.environ, tj._core.KERNEL_VARIABLE: "portable"}
        argv = [sys.executable, __file__, "--scalar-only", "--n", str(args.n), "--threads"]
        done = subprocess.run(
            [*argv, str(threads)], env=env, capture_output=True, text=True, check=True
        )
        wall, busy = json.loads(done.stdout)
        return float(wall), float(busy)

    def batch(threads: int, lockstep: bool) -> Any:
        mc._LOCKSTEP = lockstep
        try:
            return tj.monte_carlo(
                panel, orbit, vary=VARY, n=args.n, seed=1, threads=threads, rtol=RTOL, atol=ATOL,
                progress=False,
            )  # fmt: skip
        finally:
            mc._LOCKSTEP = True

    runs: dict[tuple[int, str], list[tuple[float, float]]] = {}
    frames = {}
    for threads in args.threads:
        for _ in range(args.repeat):
            for path, lockstep in PATHS.items():
                cpu, start = time.process_time(), time.perf_counter()
                frames[threads, path] = batch(threads, lockstep)
                wall = time.perf_counter() - start
                busy = (time.process_time() - cpu) / wall
                runs.setdefault((threads, path), []).append((wall, busy))
            runs.setdefault((threads, "portable"), []).append(portable_scalar(threads))
    best = {key: min(v) for key, v in runs.items()}
    frame = frames[args.threads[0], "lockstep"]
    steps = int(frame["n_steps"].sum())
    # "cores busy": process CPU time over wall time (below `threads` when others hold cores).
    # "per core": samples per second per core busy, the throughput that does not depend on how
    # much of the machine the others left.
    print(
        f"{'threads':>8}{'path':>10}{'wall s':>10}{'samples/s':>11}{'cores busy':>12}"
        f"{'per core':>10}{'ns/step':>9}{'x scalar':>10}{'x portable':>12}"
    )
    for threads in args.threads:
        paths = ("portable", "scalar", "lockstep")
        rate = {p: args.n / best[threads, p][0] / max(best[threads, p][1], 1e-9) for p in paths}
        for path in paths:
            wall, busy = best[threads, path]
            print(
                f"{threads:>8}{path:>10}{wall:>10.2f}{args.n / wall:>11.1f}{busy:>12.2f}"
                f"{rate[path]:>10.1f}{1e9 * wall * busy / steps:>9.0f}"
                f"{rate[path] / rate['scalar']:>10.2f}"
                f"{rate[path] / rate['portable']:>12.2f}"
            )
    print("(portable: the scalar path without FMA, in a child process; its ns/step uses the")
    print(" lockstep frame's step count, which differs from its own by a few rejections)")
    same = all(f.equals(frame) for f in frames.values())
    print(f"identical frames across paths and thread counts: {same}")
    # CPU seconds per sample (wall x cores busy): less sensitive to other work than wall time.
    cpu_per = {key: wall * busy / args.n for key, (wall, busy) in best.items()}

    if 1 not in args.threads:
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
    start = time.process_time()
    for p in panels:
        cap = 1.0 / (40.0 * tj.natural_frequency(p))
        tj.simulate(
            p, orbit, (0.0, orbit.period), rtol=RTOL, atol=ATOL, t_eval=[orbit.period], max_step=cap
        )
    per_sim = (time.process_time() - start) / k
    start = time.process_time()
    for p in panels:
        tj.simulate_orbits(p, orbit, 1, rtol=RTOL, atol=ATOL, progress=False)
    per_orbits = (time.process_time() - start) / k
    per_sample = cpu_per[1, "lockstep"]
    per_scalar = cpu_per[1, "scalar"]
    mc_steps = int(frame["n_steps"].iloc[:k].sum())
    print(f"CPU time per sample, same {k} panels ({mc_steps // k} steps each), one thread:")
    for name, t in (
        ("tj.simulate (end state, same cap)", per_sim),
        ("tj.simulate_orbits (summary)", per_orbits),
        ("tj.monte_carlo, scalar path", per_scalar),
        ("tj.monte_carlo, lockstep", per_sample),
    ):
        print(f"  {name:<34}{1e3 * t:8.1f} ms {t / per_sim:8.2f} x tj.simulate")


if __name__ == "__main__":
    main()
