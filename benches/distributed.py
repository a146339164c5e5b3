"""The coupled distributed panel, in one run:

1. one GEO orbit (default, converged settings) beside the hinge model: wall time, steps,
   right-hand-side evaluations, and how far apart θ and θ_f end up;
2. the distributed long run (``simulate_orbits(..., model="distributed")``) over one GEO orbit
   (``Orbit.geo_equinox()``, its cylindrical shadow), linear arcs (``method="hybrid"``) against
   the full integration (``method="rk45"``): wall time, ratio, and the largest error of each
   summary column against the gate of benches/longrun.py (2 %, or 1e-6 where the full run's value
   is below 5e-5);
3. a year on ``Orbit.geo_year`` (``--start``): the fast run's wall time and split, against the
   full integration of the same year when ``--full-year`` (about an hour here) or a reference
   saved by it (``--reference FILE.npz``; ``--save-reference FILE.npz`` writes one);
4. the cost's growth with the number of elements (``--elements-sweep``, one equinox orbit, fast
   and full);
5. optionally (``--convergence``) the convergence tables of θ_f through the eclipse.

    python benches/distributed.py [--repeat 3] [--elements 40] [--modes 4] [--years 1]
                                  [--full-year | --reference FILE.npz] [--convergence]

Timings are medians over ``--repeat`` alternating runs (the machine is shared; read the ratio).
"""

from __future__ import annotations

import argparse
import statistics
import time
from typing import Any

import longrun  # benches/longrun.py
import machine  # benches/machine.py
import numpy as np

import thermojitter as tj
from thermojitter.distributed import distributed_convergence

COLUMNS = (
    "theta_eq", "theta_max", "theta_min", "amplitude", "jitter_rms", "jitter_peak",
    "entry_theta_min", "exit_theta_max", "entry_peak", "exit_peak", "tip_max", "tip_min",
)  # fmt: skip


def timed(run: Any) -> tuple[float, Any]:
    start = time.perf_counter()
    result = run()
    return time.perf_counter() - start, result


def gate(full: dict[str, np.ndarray], fast: dict[str, np.ndarray]) -> int:
    """benches/longrun.py's gate over this bench's columns (θ_f and the tip's)."""
    return longrun.gate(full, fast, COLUMNS)


def hinge_beside(panel: tj.Panel, orbit: tj.Orbit, elements: int, modes: int, repeat: int) -> None:
    span = (0.0, orbit.period)
    print(
        f"\n1. one GEO orbit ({orbit.period:.0f} s), rk45 rtol 1e-8 atol 1e-10, output every 10 s; "
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
    for _ in range(repeat):
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


def long_run(
    panel: tj.Panel, orbit: tj.Orbit, n: int, method: str, **kw: Any
) -> tuple[float, tj.OrbitSummaries]:
    return timed(
        lambda: tj.simulate_orbits(
            panel, orbit, n, model="distributed", method=method, progress=False, **kw
        )
    )


def split(run: tj.OrbitSummaries) -> str:
    p = run.propagation
    return (
        f"linear arcs {p['t_linear'] / 86400:.2f} d in {p['n_arcs']} arcs, umbra (temperatures "
        f"alone, modes exact) {p['t_exponential'] / 3600:.2f} h in {p['n_exp_steps']} steps, "
        f"full integration {p['t_fallback'] / 3600:.2f} h ({p['n_fallback_steps']} steps), "
        f"arcs refused by their checks {p['n_refused_arcs']}"
    )


def one_orbit(panel: tj.Panel, repeat: int, **kw: Any) -> None:
    orbit = tj.Orbit.geo_equinox()
    print(
        "\n2. the distributed long run over one GEO orbit (geo_equinox, cylindrical shadow): "
        "linear arcs vs the full integration"
    )
    times: dict[str, list[float]] = {"hybrid": [], "rk45": []}
    runs: dict[str, tj.OrbitSummaries] = {}
    for _ in range(repeat):
        for method in times:
            wall, runs[method] = long_run(panel, orbit, 1, method, **kw)
            times[method].append(wall)
    fast, full = statistics.median(times["hybrid"]), statistics.median(times["rk45"])
    print(f"  fast (hybrid) {fast:.2f} s, full (rk45) {full:.2f} s: {full / fast:.1f}x")
    print(f"  fast: {split(runs['hybrid'])}")
    gate(runs["rk45"].columns, runs["hybrid"].columns)


def one_year(panel: tj.Panel, args: argparse.Namespace, **kw: Any) -> None:
    orbit = tj.Orbit.geo_year(args.start)
    n = int(round(args.years * 365.25 * 86400.0 / orbit.period))
    wall, fast = long_run(panel, orbit, n, "hybrid", **kw)
    eclipses = int(np.isfinite(fast.t_entry).sum())
    print(
        f"\n3. {n} orbits ({args.years:g} years) of geo_year from {args.start}, {eclipses} eclipses"
    )
    print(f"  fast (hybrid) {wall:.1f} s; {split(fast)}")
    reference: dict[str, np.ndarray] | None = None
    if args.full_year:
        wall_full, full = long_run(panel, orbit, n, "rk45", **kw)
        print(f"  full (rk45) {wall_full:.1f} s: {wall_full / wall:.1f}x")
        reference = {name: full.columns[name] for name in COLUMNS}
        if args.save_reference:
            np.savez(args.save_reference, wall=wall_full, **reference)
    elif args.reference:
        saved = np.load(args.reference)
        reference = {name: saved[name] for name in COLUMNS}
        print(f"  full (rk45, from {args.reference}): {float(saved['wall']):.1f} s when measured")
    if reference is None:
        print("  (no full year: pass --full-year, about an hour here, or --reference FILE.npz)")
        return
    gate(reference, fast.columns)


def elements_sweep(panel: tj.Panel, values: list[int], modes: int | None) -> None:
    orbit = tj.Orbit.geo_equinox()
    print("\n4. the cost's growth with the number of elements (one geo_equinox orbit)")
    print(f"  {'elements':>8s} {'fast (s)':>9s} {'full (s)':>9s} {'ratio':>6s} {'outside':>8s}")
    for e in values:
        wall_fast, fast = long_run(panel, orbit, 1, "hybrid", elements=e, modes=modes)
        wall_full, full = long_run(panel, orbit, 1, "rk45", elements=e, modes=modes)
        outside = 0
        for name in COLUMNS:
            a, b = full.columns[name][0], fast.columns[name][0]
            if np.isnan(a) != np.isnan(b):
                outside += 1
            elif np.isfinite(a):
                outside += abs(b - a) > (1e-6 if abs(a) < 5e-5 else 0.02 * abs(a))
        print(
            f"  {e:8d} {wall_fast:9.2f} {wall_full:9.2f} {wall_full / wall_fast:6.1f} {outside:8d}"
        )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--elements", type=int, default=None)
    parser.add_argument("--modes", type=int, default=None)
    parser.add_argument("--years", type=float, default=1.0)
    parser.add_argument("--start", default="2026-01-01", help="start date of geo_year")
    parser.add_argument("--full-year", action="store_true", help="also the full year (~1 h)")
    parser.add_argument("--reference", default=None, help="a saved full year (.npz)")
    parser.add_argument("--save-reference", default=None, help="write the full year (.npz)")
    parser.add_argument(
        "--elements-sweep", type=int, nargs="*", default=[10, 20, 40, 80], help="elements"
    )
    parser.add_argument("--convergence", action="store_true", help="also the convergence tables")
    args = parser.parse_args()

    panel = tj.Panel.paper()
    defaults = tj.distributed_defaults(panel)
    elements = args.elements or defaults["elements"]
    modes = args.modes or defaults["modes"]
    print(machine.describe())
    hinge_beside(panel, tj.Orbit.geo_equinox(), elements, modes, args.repeat)
    kw = {"elements": elements, "modes": modes}
    one_orbit(panel, args.repeat, **kw)
    one_year(panel, args, **kw)
    if args.elements_sweep:
        elements_sweep(panel, args.elements_sweep, args.modes)

    if args.convergence:
        orbit = tj.Orbit.geo_equinox()
        for vary, values in (("elements", (10, 20, 40, 80)), ("modes", (1, 2, 4, 8, 16))):
            rows, order = distributed_convergence(panel, orbit, vary=vary, values=values)  # type: ignore[arg-type]
            print(f"\nθ_f through the eclipse against {vary} (rtol 1e-10):")
            print(f"{vary:>8s} {'max change (rad)':>18s} {'max error (rad)':>16s} {'steps':>8s}")
            for r in rows:
                print(
                    f"{getattr(r, vary):8d} {r.max_change:18.3e} {r.max_error:16.3e} {r.n_steps:8d}"
                )
            print(f"observed order: {order:.2f}")
    print(f"load average at the end: {machine.load()}")


if __name__ == "__main__":
    main()
