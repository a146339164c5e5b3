"""A Hubble-like solar array over a year: 540 km, 28.5°, a one-axis Sun-tracking wing, with and
without the Earth's heat; and GEO, where the Earth's heat is negligible.

    python examples/hubble_year.py [--days 24] [--orbits 3] [--out DIR]

A year of a 95-minute orbit is about 5,500 orbits; the example samples ``--days`` days spread
evenly over the year (24 by default) and runs ``--orbits`` orbits from each (the first orbit
leaves the start's steady state; the last is reported). For each sampled day it prints:

- β, the Sun's angle to the orbit plane (``orbit.beta``), which the node's J2 drift
  (−6.6°/day) and the Sun's motion swing within about ±52°, a full swing every seven weeks or so;
- the eclipse's length from first to last contact (``orbit.eclipse_durations``);
- θ_eq, the sunlit equilibrium at the orbit's noon, Sun alone and with the Earth's albedo
  (0.30) and infrared (237 W/m²);
- the post-eclipse jitter: the largest |θ − θ_eq| after the shadow exit over the last orbit
  (the ``exit_peak`` of :func:`thermojitter.simulate_orbits`), both ways;
- c_d*, the critical hinge damping of the sunlit equilibrium at the orbit's noon
  (:func:`thermojitter.flutter` with the orbit, the point t and the attitude), both ways.

Then the same for GEO at the equinox, where switching the Earth's heat on moves the mean angle
over the sunlit arc by about 0.5 % (2 to 3 % at the noon, where the back face sees the lit
Earth). With ``--out DIR`` it also draws β and the eclipses over
the year (``orbit_year.png``) and the flux on each face over one orbit (``fluxes.png``). The
default run takes about half a minute.
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import numpy as np

import thermojitter as tj

YEAR = 365.25 * 86400.0
PANEL = tj.Panel.paper()
"""The paper's Table 1 panel, as a stand-in for one wing of the array."""
TRACKING = tj.Attitude.sun_tracking(0.0)
"""The wing turns about the orbit normal to face the Sun: the incidence is β."""


def hubble(earth: bool) -> tj.Orbit:
    """540 km, 28.5°, from 1 January 2026, with or without the Earth's albedo and infrared."""
    orbit = tj.Orbit.circular(540e3, math.radians(28.5), 0.0, "2026-01-01")
    return orbit if earth else orbit.replace(albedo=0.0, earth_ir=0.0)


def noon_after(orbit: tj.Orbit, t: float) -> float:
    """The orbit's noon after t: half a period past the deepest point of the next eclipse."""
    deepest = orbit.eclipses(t, t + orbit.period)[0, 0]
    return float(deepest + 0.5 * orbit.period)


def sampled_day(orbit: tj.Orbit, day: float, n_orbits: int) -> dict[str, float]:
    """β, the eclipse, the post-eclipse jitter of the last of ``n_orbits`` orbits and c_d* on
    ``day``, with the Earth's heat as ``orbit`` has it. The runs start at the orbit's noon, so
    each orbit's ``theta_eq`` (the sunlit equilibrium under the loads at its start) is the
    noon's, the reference of its ``exit_peak``."""
    noon = noon_after(orbit, day * 86400.0)
    runs = tj.simulate_orbits(
        PANEL, orbit, n_orbits, t_start=noon, method="rk45", attitude=TRACKING, progress=False
    )
    last = runs.to_pandas().iloc[-1]
    point = tj.flutter(PANEL, orbit=orbit, t=noon, attitude=TRACKING)
    return {
        "beta_deg": math.degrees(float(orbit.beta(noon)[0])),
        "eclipse_min": float(orbit.eclipse_durations(noon, noon + orbit.period)[0]) / 60.0,
        "theta_eq_deg": math.degrees(point.equilibrium.theta),
        "exit_peak_deg": math.degrees(float(last["exit_peak"])),
        "jitter_peak_deg": math.degrees(float(last["jitter_peak"])),
        "cd_star": point.critical_damping,
    }


def year_table(days: int, n_orbits: int) -> None:
    print(
        f"Hubble-like array, 540 km, 28.5 deg, Sun-tracking: {days} days sampled over 2026, "
        f"{n_orbits} orbits each (the last one reported)"
    )
    print(
        "  day   beta  eclipse | theta_eq [deg] | exit peak [deg] | jitter peak [deg] |"
        "  c_d* [N m s/rad]\n"
        "        [deg]   [min] |  Sun   +Earth  |  Sun    +Earth  |   Sun     +Earth  |"
        "   Sun    +Earth"
    )
    for day in np.linspace(0.0, 365.0, days, endpoint=False):
        bare = sampled_day(hubble(False), float(day), n_orbits)
        heated = sampled_day(hubble(True), float(day), n_orbits)
        print(
            f"  {day:5.1f} {bare['beta_deg']:+6.1f}  {bare['eclipse_min']:5.1f}  | "
            f"{bare['theta_eq_deg']:5.2f}  {heated['theta_eq_deg']:5.2f}  | "
            f"{bare['exit_peak_deg']:5.2f}   {heated['exit_peak_deg']:5.2f}   | "
            f"{bare['jitter_peak_deg']:7.4f}  {heated['jitter_peak_deg']:7.4f}  | "
            f"{bare['cd_star']:6.3f}  {heated['cd_star']:6.3f}"
        )


def geo_table() -> None:
    """GEO at the equinox, Sun-pointing as in the paper, with and without the Earth's heat."""
    geo = tj.Orbit.geo_equinox()
    heated = geo.replace(albedo=0.30, earth_ir=237.0)
    print("GEO at the equinox, Sun-pointing (the paper's case), Sun alone vs with the Earth:")
    rows = []
    for orbit in (geo, heated):
        point = tj.flutter(PANEL, orbit=orbit, t=0.0)
        sol = tj.simulate(PANEL, orbit, (0.0, orbit.period), dt_out=60.0)
        runs = tj.simulate_orbits(PANEL, orbit, 2, method="rk45", progress=False)
        rows.append(
            (
                math.degrees(point.equilibrium.theta),
                math.degrees(float(sol.theta[sol.sunlit == 1.0].mean())),
                math.degrees(float(runs.to_pandas()["exit_peak"].iloc[-1])),
                point.critical_damping,
            )
        )
    names = (
        "theta_eq at noon [deg]",
        "mean theta over the sunlit arc [deg]",
        "post-eclipse peak [deg]",
        "c_d* at noon [N m s/rad]",
    )
    for k, name in enumerate(names):
        bare, warm = rows[0][k], rows[1][k]
        print(f"  {name:37s} {bare:8.4f}  {warm:8.4f}  ({100 * (warm / bare - 1):+.2f} %)")


def figures(out: Path) -> None:
    from thermojitter.reports.plots import face_flux_figure, orbit_year_figure, save

    out.mkdir(parents=True, exist_ok=True)
    orbit = hubble(True)
    save(orbit_year_figure(orbit, title="Hubble-like orbit, 2026"), out / "orbit_year.png")
    sol = tj.simulate(PANEL, orbit, (0.0, orbit.period), dt_out=20.0, attitude=TRACKING)
    assert sol.flux_front is not None and sol.flux_back is not None
    fig = face_flux_figure(sol.t, sol.flux_front, sol.flux_back, orbit, title="1 January")
    save(fig, out / "fluxes.png")
    print(f"wrote {out / 'orbit_year.png'} and {out / 'fluxes.png'}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--days", type=int, default=24, help="days sampled over the year")
    parser.add_argument("--orbits", type=int, default=3, help="orbits run from each day")
    parser.add_argument("--out", type=Path, default=None, help="folder for the two figures")
    args = parser.parse_args()
    started = time.perf_counter()
    # Every orbit is integrated in full (method="rk45"): the loads vary along the sunlit arc,
    # which the hybrid propagator's closed form does not take.
    year_table(args.days, args.orbits)
    geo_table()
    if args.out is not None:
        figures(args.out)
    print(f"({time.perf_counter() - started:.1f} s)")


if __name__ == "__main__":
    main()
