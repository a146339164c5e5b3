"""One GEO orbit of the coupled distributed panel (default, converged settings) beside the hinge
model, in one run: wall time, steps, right-hand-side evaluations, and how far apart θ and θ_f
end up; optionally the convergence tables of θ_f through the eclipse.

    python benches/distributed.py [--repeat 3] [--elements 40] [--modes 4] [--convergence]

Timings are medians over ``--repeat`` alternating runs (the machine is shared; read the ratio).
"""

from __future__ import annotations

import argparse
import statistics
import time
from typing import Any

import machine  # benches/machine.py
import numpy as np

import thermojitter as tj
from thermojitter.distributed import distributed_convergence


def timed(run: Any) -> tuple[float, Any]:
    start = time.perf_counter()
    result = run()
    return time.perf_counter() - start, result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--elements", type=int, default=None)
    parser.add_argument("--modes", type=int, default=None)
    parser.add_argument("--convergence", action="store_true", help="also the convergence tables")
    args = parser.parse_args()

    panel, orbit = tj.Panel.paper(), tj.Orbit.geo_equinox()
    span = (0.0, orbit.period)
    defaults = tj.distributed_defaults(panel)
    elements = args.elements or defaults["elements"]
    modes = args.modes or defaults["modes"]
    print(machine.describe())
    print(
        f"one GEO orbit ({orbit.period:.0f} s), rk45 rtol 1e-8 atol 1e-10, output every 10 s; "
        f"distributed: {elements} elements, {modes} modes"
    )

    def hinge() -> tj.Solution:
        return tj.simulate(panel, orbit, span, dt_out=10.0)

    def distributed() -> tj.DistributedSolution:
        return tj.simulate_distributed(
            panel, orbit, span, elements=elements, modes=modes, dt_out=10.0
        )

    times: dict[str, list[float]] = {"hinge": [], "distributed": []}
    results: dict[str, Any] = {}
    for _ in range(args.repeat):
        for name, run in (("hinge", hinge), ("distributed", distributed)):
            wall, results[name] = timed(run)
            times[name].append(wall)
    h, d = results["hinge"], results["distributed"]
    print(
        f"{'model':12s} {'wall (s)':>10s} {'steps':>10s} {'rhs':>10s} {'us/step':>9s} {'state':>6s}"
    )
    for name, sol, size in (("hinge", h, 4), ("distributed", d, d.y_end.size)):
        wall = statistics.median(times[name])
        print(
            f"{name:12s} {wall:10.3f} {sol.n_steps:10d} {sol.n_rhs:10d} "
            f"{wall / sol.n_steps * 1e6:9.2f} {size:6d}"
        )
    ratio = statistics.median(times["distributed"]) / statistics.median(times["hinge"])
    print(f"distributed / hinge wall time: {ratio:.1f}x")
    diff = np.degrees(np.sqrt(np.mean((h.theta - d.theta_f) ** 2)))
    print(f"RMSE theta - theta_f over the orbit (Table 1 K_el): {diff:.3f} deg")

    if args.convergence:
        for vary, values in (("elements", (10, 20, 40, 80)), ("modes", (1, 2, 4, 8, 16))):
            rows, order = distributed_convergence(panel, orbit, vary=vary, values=values)  # type: ignore[arg-type]
            print(f"\nθ_f through the eclipse against {vary} (rtol 1e-10):")
            print(f"{vary:>8s} {'max change (rad)':>18s} {'max error (rad)':>16s} {'steps':>8s}")
            for r in rows:
                print(
                    f"{getattr(r, vary):8d} {r.max_change:18.3e} {r.max_error:16.3e} {r.n_steps:8d}"
                )
            print(f"observed order: {order:.2f}")


if __name__ == "__main__":
    main()
