"""thermojitter against its peers on the same problem, in one run.

The problem: the paper's coupled model (two-layer heat balance + non-linear hinge, two-way
coupling, Table 1 panel) over one GEO orbit at equinox (and a 10-orbit variant), started from the
sunlit equilibrium, integrated at rtol 1e-8 / atol 1e-10 and split at the shadow entry and exit
times so that no solver steps across the jump of the illumination.

Solvers: thermojitter rk45 (Rust Dormand-Prince 5(4)), scipy ``solve_ivp`` RK45 and DOP853 with
a plain-Python right-hand side, CyRK ``nbsolve_ivp`` (Numba) with a Numba-compiled right-hand side,
CyRK ``pysolve_ivp`` (C++ loop calling a Python right-hand side), and thermojitter rk4 at the
fixed step that gives the same final error as rk45. Every peer gets the same equations with the
same coefficients, the same initial state and the same segments.

Per solver: wall time (median of the repeats shown), accepted steps, ns per step, the final-state
error against a tight reference, and the time ratio to thermojitter rk45. The reference is
independent of thermojitter: CyRK's DOP853 at rtol 1e-13 / atol 1e-15 on the Numba right-hand side
(it agrees with scipy's DOP853 at the same tolerances to ~3e-11), or without CyRK scipy's DOP853 at
rtol 1e-12 / atol 1e-14.

scipy is run twice over: with the plain right-hand side below, written for speed (coefficients
folded, math.sin, one small array per call), and with thermojitter.reference's right-hand side
(the project's readable oracle, one function per equation), which is about 1.4x slower. The
ratio targets are checked against the faster one. Error is shown as the
largest component of |y - y_ref| / (atol + rtol |y_ref|) (1 = one tolerance unit) and as |dθ|.
The rk4 step is the largest whose final error is no larger than rk45's in every component.

    pip install -e ".[bench]"
    python benches/peers.py                 # one orbit and ten orbits
    python benches/peers.py --orbits 1      # one orbit only

Slow solvers (scipy, pysolve_ivp) take fewer repeats; the table says how many.
"""

from __future__ import annotations

import argparse
import math
import os
import statistics
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

# One BLAS thread: the solvers here never need more, and idle OpenBLAS workers spinning on the
# second of two cores would tax whichever solver runs next. Set before NumPy loads.
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import machine  # noqa: E402  (benches/machine.py)
import numpy as np  # noqa: E402
from scipy.integrate import solve_ivp  # noqa: E402

import thermojitter as tj  # noqa: E402
from thermojitter import reference as ref  # noqa: E402

RTOL, ATOL = 1e-8, 1e-10
STEFAN_BOLTZMANN = 5.670374419e-8

try:
    import CyRK
    import numba
except ImportError:  # the optional peers: pip install -e ".[bench]"
    CyRK = None
    numba = None


# ----------------------------------------------------------------------------- the problem


def coefficients(panel: tj.Panel) -> tuple[float, ...]:
    """The right-hand side's coefficients (paper eqs. 2 and 20), in per-second units.

    (heating, conduction, radiation_front, radiation_back, moment, damping, stiffness): each the
    panel's coefficient divided by the half heat capacity m c / 2 or by I_B = 2 m l^3 / 3.
    """
    half_capacity = 0.5 * panel.mass_per_length * panel.specific_heat
    arm = panel.length / 4.0
    inertia = 2.0 * panel.mass_per_length * arm**3 / 3.0
    moment_per_kelvin = (
        panel.moment_scale
        * panel.expansion_coeff
        * panel.youngs_modulus
        * panel.bending_inertia
        / panel.thickness
    )
    return (
        panel.absorptivity * panel.solar_constant / half_capacity,
        panel.conductance / half_capacity,
        STEFAN_BOLTZMANN * panel.emissivity_front / half_capacity,
        STEFAN_BOLTZMANN * panel.emissivity_back / half_capacity,
        moment_per_kelvin / inertia,
        panel.damping / inertia,
        panel.hinge_stiffness / inertia,
    )


def rates(
    y: Any,
    s: float,
    heating: float,
    conduction: float,
    rad_f: float,
    rad_b: float,
    moment: float,
    damping: float,
    stiffness: float,
) -> tuple[float, float, float, float]:
    """dy/dt of y = (T_f, T_b, θ, θ̇) under illumination s: eq. 2 with the flux ∝ cos θ, eq. 20."""
    t_f, t_b, theta, omega = y[0], y[1], y[2], y[3]
    sin, cos = math.sin(theta), math.cos(theta)
    conducted = conduction * (t_f - t_b)
    d_f = heating * s * cos - conducted - rad_f * t_f**4
    d_b = conducted - rad_b * t_b**4
    forced = moment * (t_f - t_b) - damping * omega - stiffness * theta
    accel = (forced - 3.0 * omega * omega * sin * cos) / (1.0 + 3.0 * sin * sin)
    return d_f, d_b, omega, accel


def rhs_python(t: float, y: np.ndarray, s: float, *c: float) -> np.ndarray:
    """The right-hand side for scipy: a new array per call, as solve_ivp expects."""
    return np.array(rates(y, s, *c))


def rhs_python_inplace(dy: np.ndarray, t: float, y: np.ndarray, s: float, *c: float) -> None:
    """The right-hand side for CyRK pysolve_ivp (pass_dy_as_arg=True): writes into dy."""
    dy[0], dy[1], dy[2], dy[3] = rates(y, s, *c)


if numba is not None:
    _rates_nb = numba.njit(cache=True)(rates)

    @numba.njit(cache=True)
    def rhs_numba(
        t: float,
        y: np.ndarray,
        s: float,
        heating: float,
        conduction: float,
        rad_f: float,
        rad_b: float,
        moment: float,
        damping: float,
        stiffness: float,
    ) -> np.ndarray:
        """The right-hand side compiled by Numba, for CyRK nbsolve_ivp."""
        d_f, d_b, omega, accel = _rates_nb(
            y, s, heating, conduction, rad_f, rad_b, moment, damping, stiffness
        )
        out = np.empty(4)
        out[0], out[1], out[2], out[3] = d_f, d_b, omega, accel
        return out


@dataclass
class Problem:
    panel: tj.Panel
    orbit: tj.Orbit
    t_end: float
    y0: np.ndarray
    segments: list[tuple[float, float, float]]  # (a, b, s)
    coef: tuple[float, ...]


def problem(orbits: int) -> Problem:
    panel, orbit = tj.Panel.paper(), tj.Orbit.geo_equinox()
    t_end = orbits * orbit.period
    eq = tj.steady_state(panel)
    y0 = np.array([eq.T_front, eq.T_back, eq.theta, 0.0])
    cuts = sorted({0.0, t_end, *(t for iv in orbit.shadow_intervals(0.0, t_end) for t in iv)})
    segments = []
    for a, b in zip(cuts[:-1], cuts[1:], strict=True):
        s = float(orbit.illumination(0.5 * (a + b))[0])
        segments.append((a, b, s))
    return Problem(panel, orbit, t_end, y0, segments, coefficients(panel))


# ----------------------------------------------------------------------------- the solvers

Run = tuple[np.ndarray, int]  # (final state, accepted steps)


def run_thermojitter(p: Problem, method: str = "rk45", dt: float | None = None) -> Run:
    sol = tj.simulate(
        p.panel,
        p.orbit,
        (0.0, p.t_end),
        method=method,  # type: ignore[arg-type]
        rtol=RTOL,
        atol=ATOL,
        dt=dt,
        t_eval=[p.t_end],
        y0=p.y0,
    )
    return np.asarray(sol.y_end), int(sol.n_steps)


def run_scipy(
    p: Problem,
    method: str,
    rhs: Callable[..., np.ndarray] = rhs_python,
    rtol: float = RTOL,
    atol: float = ATOL,
) -> Run:
    y, steps = p.y0, 0
    for a, b, s in p.segments:
        sol = solve_ivp(rhs, (a, b), y, method=method, rtol=rtol, atol=atol, args=(s, *p.coef))
        if not sol.success:
            raise RuntimeError(sol.message)
        y, steps = sol.y[:, -1], steps + len(sol.t) - 1
    return y, steps


def run_scipy_reference(p: Problem) -> Run:
    sol = ref.simulate(
        p.panel, p.orbit, (0.0, p.t_end), rtol=RTOL, atol=ATOL, method="RK45", y0=p.y0
    )
    return sol.y[:, -1], sol.n_steps


def run_nbsolve(p: Problem, rk_method: int = 1, rtol: float = RTOL, atol: float = ATOL) -> Run:
    y, steps = p.y0, 0
    for a, b, s in p.segments:
        res = CyRK.nbsolve_ivp(
            rhs_numba,
            (a, b),
            y,
            args=(s, *p.coef),
            rtol=rtol,
            atol=atol,
            rk_method=rk_method,
            warnings=False,
        )
        if not res.success:
            raise RuntimeError(res.message)
        y, steps = np.ascontiguousarray(res.y[:, -1]), steps + res.size - 1
    return y, steps


def run_pysolve(p: Problem) -> Run:
    y, steps = p.y0, 0
    for a, b, s in p.segments:
        res = CyRK.pysolve_ivp(
            rhs_python_inplace,
            (a, b),
            y,
            method="RK45",
            args=(s, *p.coef),
            rtol=RTOL,
            atol=ATOL,
            pass_dy_as_arg=True,
        )
        if not res.success:
            raise RuntimeError(res.message)
        y, steps = np.ascontiguousarray(res.y[:, -1]), steps + res.size - 1
    return y, steps


# ----------------------------------------------------------------------------- measuring


def timed(fn: Callable[[], Run], repeat: int) -> tuple[float, Run]:
    times, result = [], None
    for _ in range(repeat):
        start = time.perf_counter()
        result = fn()
        times.append(time.perf_counter() - start)
    assert result is not None
    return statistics.median(times), result


def error(y: np.ndarray, truth: np.ndarray) -> float:
    """Largest component of |y − truth| in tolerance units atol + rtol |truth| (in practice θ̇,
    whose final value is small)."""
    return float(np.max(np.abs(y - truth) / (ATOL + RTOL * np.abs(truth))))


def rk4_step_for(p: Problem, target: np.ndarray, truth: np.ndarray) -> float:
    """The largest RK4 step (s) whose final error is no larger than `target` in every component
    (T_f, T_b, θ, θ̇): a geometric sweep down from 2 s, then bisection between the last step that
    missed and the first that met it."""

    def meets(dt: float) -> bool:
        return bool(np.all(np.abs(run_thermojitter(p, "rk4", dt)[0] - truth) <= target))

    miss, hit = None, 2.0
    while not meets(hit):
        miss, hit = hit, hit * 0.7
        if hit < 1e-3:
            raise RuntimeError("rk4 does not reach the rk45 error")
    if miss is None:
        return hit
    for _ in range(10):
        mid = math.sqrt(miss * hit)
        if meets(mid):
            hit = mid
        else:
            miss = mid
    return hit


def reference_state(p: Problem) -> tuple[np.ndarray, str]:
    """The final state from a tight, independent integration, and how it was obtained."""
    if CyRK is not None:
        return run_nbsolve(p, 2, 1e-13, 1e-15)[0], "CyRK DOP853, rtol 1e-13"
    return run_scipy(p, "DOP853", rtol=1e-12, atol=1e-14)[0], "scipy DOP853, rtol 1e-12"


def bench(orbits: int, repeat: int, repeat_slow: int, reference_rhs: bool) -> dict[str, float]:
    p = problem(orbits)
    truth, truth_name = reference_state(p)

    rows: list[tuple[str, float, int, Run]] = []

    def add(name: str, fn: Callable[[], Run], n: int) -> None:
        wall, result = timed(fn, n)
        rows.append((name, wall, n, result))

    add("thermojitter rk45", lambda: run_thermojitter(p), repeat)
    if CyRK is not None:
        run_nbsolve(p)  # compile (and warm) before timing
        add("CyRK nbsolve_ivp RK45", lambda: run_nbsolve(p), repeat)
        add("CyRK pysolve_ivp RK45", lambda: run_pysolve(p), repeat_slow)
    add("scipy solve_ivp RK45", lambda: run_scipy(p, "RK45"), repeat_slow)
    if reference_rhs:
        add("scipy RK45, reference rhs", lambda: run_scipy_reference(p), repeat_slow)
    add("scipy solve_ivp DOP853", lambda: run_scipy(p, "DOP853"), repeat_slow)
    dt = rk4_step_for(p, np.abs(rows[0][3][0] - truth), truth)
    add(f"thermojitter rk4 dt={dt:.3g}s", lambda: run_thermojitter(p, "rk4", dt), repeat)

    t_ref, steps_ref = rows[0][1], rows[0][3][1]
    print(
        f"\n{orbits} GEO orbit(s) ({p.t_end:.0f} s, {len(p.segments)} segments), coupled "
        f"non-linear model, rtol={RTOL:g}, atol={ATOL:g}; error against {truth_name}"
    )
    widths = (30, 9, 4, 8, 8, 9, 8, 9)
    names = ("solver", "wall s", "runs", "steps", "ns/step", "err (tol)", "dθ rad", "x tj rk45")
    print(
        "| "
        + " | ".join(
            f"{n:<{w}}" if i == 0 else f"{n:>{w}}"
            for i, (n, w) in enumerate(zip(names, widths, strict=True))
        )
        + " |"
    )
    print("|" + "|".join("-" * (w + 2) for w in widths) + "|")
    out: dict[str, float] = {}
    for name, wall, n, (y_end, steps) in rows:
        err = error(y_end, truth)
        dtheta = abs(y_end[2] - truth[2])
        ratio = wall / t_ref
        print(
            f"| {name:<30} | {wall:>9.4f} | {n:>4d} | {steps:>8d} | {wall / steps * 1e9:>8.0f} "
            f"| {err:>9.3f} | {dtheta:>8.1e} | {ratio:>9.1f} |"
        )
        out[f"{name} ratio"] = ratio
        out[f"{name} err"] = err
        out[f"{name} steps"] = steps
    out["tj ns/step"] = t_ref / steps_ref * 1e9
    return out


def per_call_us(fn: Callable[[], object], calls: int = 2000, batches: int = 5) -> float:
    """Best over batches of the mean time per call, µs."""
    fn()
    best = math.inf
    for _ in range(batches):
        start = time.perf_counter()
        for _ in range(calls):
            fn()
        best = min(best, (time.perf_counter() - start) / calls)
    return best * 1e6


def call_overhead() -> None:
    """Cost of one short call (1 s of the coupled model, a handful of steps): what a sweep of many
    short runs pays per call on top of the integration."""
    p = problem(1)
    span, t_eval = (0.0, 1.0), [1.0]
    rows = [
        (
            "thermojitter simulate",
            lambda: tj.simulate(p.panel, p.orbit, span, rtol=RTOL, atol=ATOL, t_eval=t_eval),
        ),
        (
            "thermojitter simulate, y0 given",
            lambda: tj.simulate(
                p.panel, p.orbit, span, rtol=RTOL, atol=ATOL, t_eval=t_eval, y0=p.y0
            ),
        ),
        (
            "scipy solve_ivp RK45",
            lambda: solve_ivp(
                rhs_python,
                span,
                p.y0,
                rtol=RTOL,
                atol=ATOL,
                t_eval=t_eval,
                args=(p.segments[0][2], *p.coef),
            ),
        ),
    ]
    if CyRK is not None:
        rows.append(
            (
                "CyRK nbsolve_ivp RK45",
                lambda: CyRK.nbsolve_ivp(
                    rhs_numba,
                    span,
                    p.y0,
                    args=(p.segments[0][2], *p.coef),
                    rtol=RTOL,
                    atol=ATOL,
                    t_eval=np.asarray(t_eval),
                    warnings=False,
                ),
            )
        )
    print("\nper-call cost of a 1 s run (coupled model, a few steps), best of 5 x 2000 calls")
    print(f"| {'call':<34} | {'us/call':>8} |")
    print(f"|{'-' * 36}|{'-' * 10}|")
    for name, fn in rows:
        print(f"| {name:<34} | {per_call_us(fn):>8.1f} |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--orbits", type=int, nargs="+", default=[1, 10])
    parser.add_argument("--repeat", type=int, default=11, help="runs of the fast solvers")
    parser.add_argument("--repeat-slow", type=int, default=3, help="runs of scipy and pysolve")
    args = parser.parse_args()

    print(machine.describe())
    print(f"thermojitter {tj.__version__}", end="")
    if CyRK is not None:
        print(f", CyRK {CyRK.__version__}, numba {numba.__version__}", end="")
    import scipy

    print(
        f", scipy {scipy.__version__}, numpy {np.__version__}; {os.cpu_count()} CPUs, "
        f"load average {machine.load()}"
    )
    if CyRK is None:
        print("CyRK is not installed (pip install -e '.[bench]'): its rows are left out")
    call_overhead()
    for orbits in args.orbits:
        slow = args.repeat_slow if orbits == 1 else 1
        r = bench(orbits, args.repeat, slow, reference_rhs=orbits == 1)
        if orbits != 1:
            continue
        tj_name, sp_name, nb_name = (
            "thermojitter rk45",
            "scipy solve_ivp RK45",
            "CyRK nbsolve_ivp RK45",
        )
        print("\nchecks (one orbit):")
        print(
            f"  scipy RK45 / thermojitter rk45 = {r[f'{sp_name} ratio']:.0f}x (target >= 300x); "
            f"with the reference rhs {r['scipy RK45, reference rhs ratio']:.0f}x"
        )
        if CyRK is not None:
            print(
                f"  CyRK nbsolve_ivp / thermojitter rk45 = {r[f'{nb_name} ratio']:.1f}x "
                "(target >= 3x)"
            )
        print(f"  thermojitter rk45: {r['tj ns/step']:.0f} ns/step (target <= 250)")
        steps = r[f"{tj_name} steps"] / r[f"{sp_name} steps"]
        print(f"  steps thermojitter / scipy RK45 = {steps:.5f} (target within 2%)")
        peers = [sp_name] + ([nb_name] if CyRK is not None else [])
        worst = max(r[f"{name} err"] for name in peers)
        print(
            f"  final error: thermojitter {r[f'{tj_name} err']:.3f}, RK45 peers up to "
            f"{worst:.3f} tolerance units"
        )


if __name__ == "__main__":
    main()
