"""A multi-year run of the Table 1 panel with per-orbit summaries: wall time, steps and peak
memory (resident set size of this process).

    python benches/longrun.py --years 10 [--orbit geo_year|geo_equinox] [--checkpoint FILE]
"""

from __future__ import annotations

import argparse
import resource
import sys
import time

import machine  # benches/machine.py
import numpy as np

import thermojitter as tj


def peak_rss_mb() -> float:
    # ru_maxrss is in KiB on Linux.
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--years", type=float, default=10.0)
    parser.add_argument("--orbit", default="geo_year", help="an Orbit preset (classmethod name)")
    parser.add_argument("--damping", type=float, default=None, help="override c_d, N m s/rad")
    parser.add_argument("--checkpoint", default=None)
    args = parser.parse_args()
    print(machine.describe())

    panel = tj.Panel.paper()
    if args.damping is not None:
        panel = panel.replace(damping=args.damping)
    preset = getattr(tj.Orbit, args.orbit, None)
    if preset is None:
        sys.exit(f"no orbit preset {args.orbit!r}")
    orbit = preset()
    n_orbits = int(round(args.years * 365.25 * 86400.0 / orbit.period))
    before = peak_rss_mb()
    start = time.perf_counter()
    runs = tj.simulate_orbits(panel, orbit, n_orbits, checkpoint=args.checkpoint, on_limit="flag")
    wall = time.perf_counter() - start
    print(
        f"orbit preset: {args.orbit}; {n_orbits} orbits ({args.years:g} years); c_d = "
        f"{panel.damping:g} N m s/rad"
    )
    print(f"wall time: {wall:.1f} s; steps: {runs.n_steps}; rhs evaluations: {runs.n_rhs}")
    print(f"ns per step (whole run): {wall / max(runs.n_steps, 1) * 1e9:.0f}")
    print(f"peak RSS: {peak_rss_mb():.1f} MB (after imports, before the run: {before:.1f} MB)")
    eclipsing = np.isfinite(runs.t_entry)
    print(f"orbits with an eclipse: {int(eclipsing.sum())} of {len(runs)}")
    largest = np.degrees(np.max(np.abs([runs.theta_max, runs.theta_min])))
    overshoot = np.degrees(np.nanmax(runs.exit_theta_max))
    print(f"largest exit overshoot: {overshoot:.3f} deg; largest |theta|: {largest:.3f} deg")
    print(f"limit crossing: {runs.limit_crossing}; interrupted: {runs.interrupted}")


if __name__ == "__main__":
    main()
