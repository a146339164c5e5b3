"""One GEO orbit of the coupled model, rk45 at rtol 1e-8 / atol 1e-10: thermojitter against
scipy's solve_ivp RK45 on the same equations (thermojitter.reference), split at the same shadow
times, in the same run. Prints wall time, steps, ns per step and the speed ratio.

    python benches/orbit_vs_scipy.py [--repeat N]
"""

from __future__ import annotations

import argparse
import statistics
import time

import machine  # benches/machine.py
import numpy as np

import thermojitter as tj
from thermojitter import reference as ref

RTOL, ATOL = 1e-8, 1e-10


def timed(fn, repeat: int):  # type: ignore[no-untyped-def]
    times, result = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - start)
    return statistics.median(times), result


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeat", type=int, default=5, help="runs of thermojitter (median)")
    parser.add_argument("--repeat-scipy", type=int, default=1, help="runs of scipy (median)")
    args = parser.parse_args()
    print(machine.describe())

    panel, orbit = tj.Panel.paper(), tj.Orbit.geo_equinox()
    span = (0.0, orbit.period)
    t_end = np.array([orbit.period])

    def engine() -> tj.Solution:
        return tj.simulate(panel, orbit, span, rtol=RTOL, atol=ATOL, t_eval=t_end)

    def scipy_rk45() -> ref.ReferenceSolution:
        return ref.simulate(panel, orbit, span, rtol=RTOL, atol=ATOL, method="RK45")

    t_tj, sol = timed(engine, args.repeat)
    t_sp, peer = timed(scipy_rk45, args.repeat_scipy)
    truth = ref.simulate(panel, orbit, span, rtol=1e-12, atol=1e-14, method="DOP853", t_eval=t_end)

    rows = [
        ("thermojitter rk45", t_tj, sol.n_steps, sol.n_rhs, sol.y[:, -1]),
        ("scipy solve_ivp RK45", t_sp, peer.n_steps, peer.nfev, peer.y[:, -1]),
    ]
    print(f"one GEO orbit ({orbit.period:.1f} s), rtol={RTOL:g}, atol={ATOL:g}")
    print(
        f"{'solver':<24}{'wall s':>10}{'steps':>10}{'rhs':>10}{'ns/step':>10}{'|dθ_end| rad':>14}"
    )
    for name, wall, steps, nrhs, y_end in rows:
        err = abs(y_end[2] - truth.y[2, -1])
        print(
            f"{name:<24}{wall:>10.4f}{steps:>10d}{nrhs:>10d}{wall / steps * 1e9:>10.0f}{err:>14.2e}"
        )
    print(f"speed ratio scipy/thermojitter: {t_sp / t_tj:.0f}x")
    print(f"step-count ratio thermojitter/scipy: {sol.n_steps / peer.n_steps:.4f}")


if __name__ == "__main__":
    main()
