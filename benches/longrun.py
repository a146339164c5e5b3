"""Long runs of the Table 1 panel, full integration against the hybrid propagator, in one run:

1. one year (``--years``) on ``geo_year``: wall time of each, their ratio, and the largest error
   of the hybrid's per-orbit summaries against the hinge-resolved rk45 (the accuracy gate: 2 %,
   or 1e-6 rad where the value is below 5e-5 rad);
2. the hybrid alone on ten years (``--long-years``), with peak memory;
3. a multi-year Monte Carlo with the hybrid: samples per second (``--mc-samples`` samples of
   ``--mc-years`` years, c_d varied);
4. low orbits at ``--leo-altitude`` (540 km): ``Orbit.leo`` (equatorial, the Sun alone) and
   ``Orbit.circular`` at 28.5 deg with the Earth's heat, J2 and the seasons, for each hinge model
   of ``--leo-models``: the hybrid (on slow time: orbits shorter than 6 h) against rk45 over
   ``--leo-years`` side by side with the gate, then the hybrid alone over ``--leo-long-years``
   on both (``--leo-long-models`` picks the models of the long run; ``--leo-years 0`` skips
   part 4).

    python benches/longrun.py [--years 1] [--long-years 10] [--mc-samples 20] [--mc-years 10]
                              [--skip-full] [--damping C_D] [--start 2026-01-01]
                              [--leo-years 1] [--leo-long-years 10] [--leo-altitude 540e3]
                              [--leo-models linear,nonlinear] [--leo-long-models linear]

The machine may be shared: the load average is printed before and after.
"""

from __future__ import annotations

import argparse
import resource
import time
from collections.abc import Mapping, Sequence

import machine  # benches/machine.py
import numpy as np

import thermojitter as tj
from thermojitter.longrun import SUMMARY_FIELDS

METRICS = tuple(
    c
    for c in SUMMARY_FIELDS
    if c not in ("index", "t_start", "t_end", "theta_eq", "t_entry", "t_exit")
)
"""Every summary column of θ: the gate holds on each (tests/test_hybrid.py)."""


def peak_rss_mb() -> float:
    # ru_maxrss is in KiB on Linux.
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def gate(
    full: Mapping[str, np.ndarray],
    fast: Mapping[str, np.ndarray],
    columns: Sequence[str] = METRICS,
) -> int:
    """Prints, per column of two runs' summaries, the largest relative error (values >= 5e-5),
    the largest absolute error (values below) and the orbits outside the gate; returns how many
    are (benches/distributed.py reads its columns with it too)."""
    outside = 0
    for name in columns:
        a, b = np.asarray(full[name]), np.asarray(fast[name])
        both = np.isfinite(a) & np.isfinite(b)
        mismatch = int(np.sum(np.isfinite(a) != np.isfinite(b)))
        big = both & (np.abs(a) >= 5e-5)
        small = both & (np.abs(a) < 5e-5)
        rel = np.abs(b[big] - a[big]) / np.abs(a[big])
        err = np.abs(b[small] - a[small])
        bad = int(np.sum(rel > 0.02) + np.sum(err > 1e-6)) + mismatch
        outside += bad
        print(
            f"  {name:15s} max rel err {rel.max() if rel.size else 0.0:.2e} ({big.sum()} orbits)"
            f"  max abs err {err.max() if err.size else 0.0:.2e} ({small.sum()} orbits)"
            f"  outside the gate: {bad}"
        )
    return outside


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--years", type=float, default=1.0)
    parser.add_argument("--long-years", type=float, default=10.0)
    parser.add_argument("--mc-samples", type=int, default=20)
    parser.add_argument("--mc-years", type=float, default=10.0)
    parser.add_argument("--skip-full", action="store_true")
    parser.add_argument("--damping", type=float, default=None, help="override c_d, N m s/rad")
    parser.add_argument("--start", default="2026-01-01", help="start date of geo_year")
    parser.add_argument("--leo-years", type=float, default=1.0)
    parser.add_argument("--leo-long-years", type=float, default=10.0)
    parser.add_argument("--leo-altitude", type=float, default=540e3, help="m")
    parser.add_argument("--leo-models", default="linear,nonlinear")
    parser.add_argument("--leo-long-models", default="linear")
    args = parser.parse_args()
    print(machine.describe())

    panel = tj.Panel.paper()
    if args.damping is not None:
        panel = panel.replace(damping=args.damping)
    orbit = tj.Orbit.geo_year(args.start)
    per_year = 365.25 * 86400.0 / orbit.period
    print(f"panel: Table 1, c_d = {panel.damping:g} N m s/rad; orbit: geo_year from {args.start}")

    n = int(round(args.years * per_year))
    kw = {"on_limit": "flag", "progress": False, "orbits_per_call": n}
    start = time.perf_counter()
    hybrid = tj.simulate_orbits(panel, orbit, n, method="hybrid", **kw)  # type: ignore[arg-type]
    t_hybrid = time.perf_counter() - start
    p = hybrid.propagation
    print(f"\n1. {n} orbits ({args.years:g} years), {int(np.isfinite(hybrid.t_entry).sum())} "
          "with an eclipse")  # fmt: skip
    print(f"  hybrid: {t_hybrid:.3f} s; linear arcs {p['n_arcs']}, exponential steps "
          f"{p['n_exp_steps']}, fallback steps {p['n_fallback_steps']}; non-linear model on "
          f"{100 * hybrid.nonlinear_fraction:.2f} % of the simulated time "
          f"(exponential {p['t_exponential']:.0f} s, "
          f"fallback {p['t_fallback']:.0f} s)")  # fmt: skip
    if not args.skip_full:
        start = time.perf_counter()
        full = tj.simulate_orbits(panel, orbit, n, method="rk45", **kw)  # type: ignore[arg-type]
        t_full = time.perf_counter() - start
        print(f"  full (rk45, step <= T_n/40): {t_full:.1f} s, {full.n_steps} steps")
        print(f"  ratio full / hybrid: {t_full / t_hybrid:.0f}x")
        gate(full.columns, hybrid.columns)

    n_long = int(round(args.long_years * per_year))
    start = time.perf_counter()
    long = tj.simulate_orbits(panel, orbit, n_long, on_limit="flag", progress=False,
                              orbits_per_call=n_long)  # fmt: skip
    t_long = time.perf_counter() - start
    print(f"\n2. hybrid on {n_long} orbits ({args.long_years:g} years): {t_long:.2f} s; "
          f"non-linear model on {100 * long.nonlinear_fraction:.2f} % of the time; "
          f"peak RSS {peak_rss_mb():.0f} MB")  # fmt: skip
    largest = np.degrees(np.max(np.abs([long.theta_max, long.theta_min])))
    print(f"  largest |theta| {largest:.3f} deg; limit crossing: {long.limit_crossing}")

    if args.mc_samples > 0:
        horizon = int(round(args.mc_years * per_year))
        vary = {"damping": ("uniform", 2.5, 4.0)}
        start = time.perf_counter()
        frame = tj.monte_carlo(panel, orbit, vary=vary, n=args.mc_samples, horizon=horizon,
                               seed=1, method="hybrid", progress=False)  # fmt: skip
        t_mc = time.perf_counter() - start
        failed = int(frame["error"].notna().sum())
        rate = args.mc_samples / t_mc
        print(f"\n3. Monte Carlo, {args.mc_samples} samples x {horizon} orbits "
              f"({args.mc_years:g} years), hybrid: {t_mc:.1f} s, {rate:.2f} samples/s "
              f"({failed} failed); 1000 samples: about {1000 / rate / 60:.1f} min")  # fmt: skip
    if args.leo_years > 0:
        leo(panel, args)
    print(f"\nload average after: {machine.load()}")


def timed_orbits(
    panel: tj.Panel, orbit: tj.Orbit, n: int, **kw: object
) -> tuple[float, tj.OrbitSummaries]:
    start = time.perf_counter()
    runs = tj.simulate_orbits(panel, orbit, n, on_limit="flag", progress=False,  # type: ignore[arg-type]
                              orbits_per_call=n, **kw)  # fmt: skip
    return time.perf_counter() - start, runs


def leo(panel: tj.Panel, args: argparse.Namespace) -> None:
    """Part 4: low orbits, the hybrid (slow time) against rk45 over a span with the gate, then
    the hybrid's long run."""
    equatorial = tj.Orbit.leo(args.leo_altitude)
    heated = tj.Orbit.circular(args.leo_altitude, np.radians(28.5))
    per_year = 365.25 * 86400.0 / equatorial.period
    n = int(round(args.leo_years * per_year))
    orbits = (
        ("Orbit.leo (equatorial, Sun only)", equatorial),
        ("Orbit.circular 28.5 deg, Earth's heat, J2, seasons", heated),
    )
    print(f"\n4. Low orbits at {args.leo_altitude:g} m, period {equatorial.period:.0f} s: {n} "
          f"orbits ({args.leo_years:g} years)")  # fmt: skip
    for name, orbit in orbits:
        for model in args.leo_models.split(","):
            t_hybrid, hybrid = timed_orbits(panel, orbit, n, model=model, method="hybrid")
            p = hybrid.propagation
            print(f"  {name}, {model} hinge, hybrid: {t_hybrid:.2f} s "
                  f"({1e3 * t_hybrid / n:.3f} ms/orbit); slow-time steps {p['n_slow_steps']} "
                  f"({p['t_slow']:.0f} s), full steps {p['n_fallback_steps']} "
                  f"({p['t_fallback']:.0f} s: penumbrae and {p['n_refused_orbits']} orbits "
                  f"given back)")  # fmt: skip
            if not args.skip_full:
                t_full, full = timed_orbits(panel, orbit, n, model=model, method="rk45")
                ratio = t_full / t_hybrid
                print(f"  {name}, {model} hinge, rk45:   {t_full:.2f} s "
                      f"({1e3 * t_full / n:.3f} ms/orbit), {full.n_steps} steps; "
                      f"ratio rk45 / hybrid {ratio:.1f}x")  # fmt: skip
                gate(full.columns, hybrid.columns)
    n_long = int(round(args.leo_long_years * per_year))
    for model in args.leo_long_models.split(",") if n_long > 0 else []:
        for name, o in orbits:
            t_long, long = timed_orbits(panel, o, n_long, model=model, method="hybrid")
            p = long.propagation
            print(f"  {model} hinge, hybrid, {n_long} orbits ({args.leo_long_years:g} years), "
                  f"{name}: {t_long:.1f} s; {p['n_refused_orbits']} orbits given back to rk45; "
                  f"peak RSS {peak_rss_mb():.0f} MB")  # fmt: skip


if __name__ == "__main__":
    main()
