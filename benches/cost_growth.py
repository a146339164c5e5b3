"""How the cost of a run grows with its horizon, with the nodes through the thickness and with the
elements of the distributed panel, side by side in one run, with a log-log figure.

1. Horizon: wall time of ``tj.simulate_orbits`` on Table 1 (``tj.Panel()``) for a geometric
   series of orbit counts, ``method="hybrid"`` and ``"rk45"``, on
   - GEO over a year, ``Orbit.geo_year(--start)`` (default 1 March, in the spring eclipse
     season, so that the short spans have an eclipse in every orbit: from 1 January the first
     fifty-odd orbits have none, which would flatter the hybrid);
   - LEO, ``Orbit.leo(540e3)`` (equatorial, cylindrical shadow, the Sun alone);
   - LEO inclined, ``Orbit.circular(540e3, inclination=28.5 deg)`` (conical shadow, Earth's
     albedo and infrared): the hybrid takes the sunlit forcing as constant, which the Earth's
     loads are not, so there it runs rk45 and says so (the warning is recorded in the table,
     not printed).
2. Nodes through the thickness: ``layers=N`` on the examples' CFRP/honeycomb wing
   (``examples/laminates.py``: four layers, so N >= 5), a fixed number of GEO orbits, hybrid
   and rk45.
3. Elements: ``tj.simulate_distributed`` (full integration, modes at the default) over a fixed
   span through the GEO equinox eclipse, for a series of element counts. A long run of the
   distributed panel through ``simulate_orbits(..., model="distributed")`` is timed too when the
   installed package accepts it (detected; skipped otherwise).

Each time is the median of repeated runs (repeated until about a second has been spent, at most
``--repeat`` times); each series gets the slope of log(time) against log(size), over all its
points and over its last three (the growth once fixed costs are paid). Times are wall seconds,
with this process's CPU seconds beside them: every run here uses one thread, and on a shared
machine the CPU time is the steadier of the two. The load average is printed before and after
each part.

    python benches/cost_growth.py [--quick] [--big] [--no-figure] [--figure PATH]
        [--repeat 5] [--start 2026-03-01] [--layer-orbits 3] [--element-span 0.1]
        [--parts horizon,layers,elements] [--elements 5,10,20,40,80] [--leo-orbits 1,10,100] ...
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, NamedTuple

import numpy as np

import thermojitter as tj
from thermojitter.errors import HybridFallbackWarning

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "examples"))
sys.path.insert(0, str(Path(__file__).resolve().parent))
import machine  # noqa: E402  (benches/machine.py)
from laminates import wing  # noqa: E402  (examples/laminates.py)

HERE = Path(__file__).resolve().parent


class Timing(NamedTuple):
    wall: float
    """Median wall seconds."""
    cpu: float
    """Median CPU seconds of this process: less sensitive than the wall time to other work on a
    shared machine (the runs timed here use one thread)."""


@dataclass
class Series:
    """One line of the figure: wall and CPU time against a size."""

    axis: str  # "orbits", "layers" or "elements"
    label: str
    sizes: list[int] = field(default_factory=list)
    times: list[float] = field(default_factory=list)
    cpu: list[float] = field(default_factory=list)
    steps: list[int] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    def add(self, size: int, timing: Timing, steps: int, note: str = "") -> None:
        self.sizes.append(size)
        self.times.append(timing.wall)
        self.cpu.append(timing.cpu)
        self.steps.append(steps)
        self.notes.append(note)

    def slopes(self) -> tuple[float, float, float]:
        """The slope of log(wall time) against log(size) over every point and over the last
        three, and that of log(CPU time) over every point."""
        return (
            slope(self.sizes, self.times),
            slope(self.sizes[-3:], self.times[-3:]),
            slope(self.sizes, self.cpu),
        )


def slope(sizes: Sequence[int], times: Sequence[float]) -> float:
    if len(sizes) < 2:
        return math.nan
    return float(np.polyfit(np.log(sizes), np.log(times), 1)[0])


def median_time(run: Callable[[], Any], repeat: int, budget: float = 1.0) -> tuple[Timing, Any]:
    """The median wall and CPU times of ``run`` over at most ``repeat`` calls, stopping once
    ``budget`` wall seconds have been spent (a long run is timed once), and the last result."""
    walls: list[float] = []
    cpus: list[float] = []
    result = None
    while len(walls) < max(1, repeat) and (not walls or sum(walls) < budget):
        start, start_cpu = time.perf_counter(), time.process_time()
        result = run()
        walls.append(time.perf_counter() - start)
        cpus.append(time.process_time() - start_cpu)
    return Timing(statistics.median(walls), statistics.median(cpus)), result


def orbits_run(
    panel: tj.Panel, orbit: tj.Orbit, n: int, method: str, **kw: Any
) -> tj.OrbitSummaries:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", HybridFallbackWarning)
        return tj.simulate_orbits(
            panel,
            orbit,
            n,
            method=method,  # type: ignore[arg-type]
            on_limit="flag",
            progress=False,
            orbits_per_call=n,
            max_steps=10**11,
            **kw,
        )


def time_orbits(
    series: Series,
    size: int,
    repeat: int,
    panel: tj.Panel,
    orbit: tj.Orbit,
    n_orbits: int,
    method: str,
    **kw: Any,
) -> None:
    """Times ``n_orbits`` of ``simulate_orbits`` and adds the row at ``size`` to ``series``."""
    timing, runs = median_time(lambda: orbits_run(panel, orbit, n_orbits, method, **kw), repeat)
    series.add(size, timing, runs.n_steps, how(runs))


def how(runs: tj.OrbitSummaries) -> str:
    """What a hybrid run did: its share on the non-linear model, or that it ran rk45."""
    if runs.settings.get("hybrid_fallback") or runs.fallback:
        return "ran rk45 (the hybrid's fallback)"
    if runs.propagation:
        return f"non-linear model on {100 * runs.nonlinear_fraction:.1f} % of the time"
    return ""


def table(series: Sequence[Series], size_name: str) -> None:
    """The measured rows (wall and CPU time, per unit of the size and per integrator step), then
    the slopes."""
    unit = size_name[:-1]
    print(
        f"| series | {size_name} | wall s | CPU s | wall ms per {unit} | steps | CPU ns per step "
        "| note |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for s in series:
        rows = zip(s.sizes, s.times, s.cpu, s.steps, s.notes, strict=True)
        for size, wall, cpu, steps, note in rows:
            per_step = f"{1e9 * cpu / steps:.0f}" if steps else "-"
            print(
                f"| {s.label} | {size} | {wall:.4f} | {cpu:.4f} | {1e3 * wall / size:.3f} | "
                f"{steps} | {per_step} | {note} |"
            )
    print()
    print("| series | slope (wall), all points | slope (wall), last three | slope (CPU), all |")
    print("|---|---|---|---|")
    for s in series:
        whole, tail, cpu = s.slopes()
        print(f"| {s.label} | {whole:.2f} | {tail:.2f} | {cpu:.2f} |")


def part(title: str) -> None:
    print(f"\n## {title}\n\nload average before: {machine.load()}\n")


def horizon(args: argparse.Namespace) -> list[Series]:
    """Part 1: Table 1 on GEO over a year and on two low orbits, hybrid and rk45."""
    panel = tj.Panel()
    alt = 540e3
    orbits = {
        "GEO geo_year": tj.Orbit.geo_year(args.start),
        "LEO leo(540 km)": tj.Orbit.leo(alt),
        "LEO 28.5 deg + Earth": tj.Orbit.circular(alt, inclination=math.radians(28.5)),
    }
    counts = {
        ("GEO", "hybrid"): args.geo_hybrid_orbits,
        ("GEO", "rk45"): args.geo_rk45_orbits,
        ("LEO", "hybrid"): args.leo_orbits,
        ("LEO", "rk45"): args.leo_orbits,
    }
    orbits_run(panel, tj.Orbit.geo_year(args.start), 1, "hybrid")  # warm-up, not timed
    part(
        f"1. Horizon: Table 1, simulate_orbits against the number of orbits (GEO: geo_year "
        f"from {args.start}; LEO 28.5 deg + Earth: Orbit.circular(540e3, inclination 28.5 deg), "
        "conical shadow, albedo and Earth infrared)"
    )
    out = []
    for name, orbit in orbits.items():
        for method in ("hybrid", "rk45"):
            s = Series("orbits", f"{name} {method}")
            for n in counts[(name[:3], method)]:
                time_orbits(s, n, args.repeat, panel, orbit, n, method)
            out.append(s)
    table(out, "orbits")
    print(f"\nload average after: {machine.load()}")
    return out


def layers(args: argparse.Namespace) -> list[Series]:
    """Part 2: the N-node model of the CFRP wing over a fixed number of GEO orbits."""
    panel = wing()
    assert panel.layup is not None
    if args.layer_orbit == "geo":
        orbit, name = tj.Orbit.geo_year(args.start), f"geo_year({args.start})"
    else:
        orbit, name = tj.Orbit.leo(540e3), "leo(540 km)"
    part(
        f"2. Nodes through the thickness: the CFRP wing ({len(panel.layup.layers)} layers), "
        f"{args.layer_orbits} orbits of {name}"
    )
    out = []
    for method in ("hybrid", "rk45"):
        s = Series("layers", f"wing {method}")
        for nodes in args.layers:
            try:
                time_orbits(s, nodes, args.repeat, panel, orbit, args.layer_orbits, method,
                            layers=nodes)  # fmt: skip
            except tj.ParameterError as error:
                print(f"{method}, {nodes} nodes refused: {error}")
        out.append(s)
    table(out, "nodes")
    print(f"\nload average after: {machine.load()}")
    return out


def elements(args: argparse.Namespace) -> list[Series]:
    """Part 3: the distributed panel's full integration over a fixed span through the eclipse,
    then its long run where the package has one."""
    panel, orbit = tj.Panel(), tj.Orbit.geo_equinox()
    half = 0.5 * args.element_span * orbit.period
    span = (0.5 * orbit.period - half, 0.5 * orbit.period + half)
    modes = tj.distributed_defaults(panel)["modes"]
    part(
        f"3. Elements: simulate_distributed, Table 1, geo_equinox, t in [{span[0]:.0f}, "
        f"{span[1]:.0f}] s ({args.element_span:g} orbit through the eclipse), {modes} modes"
    )
    full = Series("elements", "simulate_distributed (full)")
    for n in args.elements:

        def run(n: int = n) -> tj.DistributedSolution:
            return tj.simulate_distributed(panel, orbit, span, elements=n, t_eval=[span[1]])

        timing, sol = median_time(run, args.repeat)
        full.add(n, timing, sol.n_steps, f"{sol.y_end.size} states")
    out = [full]
    long = distributed_long_run(panel, orbit, args)
    if long is not None:
        out.append(long)
    table(out, "elements")
    print(f"\nload average after: {machine.load()}")
    return out


# --- The distributed panel's long run --------------------------------------------------------
# Rows for simulate_orbits(..., model="distributed") (issue 32's reduced distributed long run):
# timed here as soon as the installed package accepts that model, left out (one line says so)
# while it refuses it. Nothing else needs to change for them to appear in the table and figure.


def distributed_long_run(
    panel: tj.Panel, orbit: tj.Orbit, args: argparse.Namespace
) -> Series | None:
    """The distributed panel's long run, ``simulate_orbits(..., model="distributed")``, over
    ``--distributed-orbits`` orbits for each element count, when the package accepts that model
    (a ParameterError naming ``model`` otherwise: the rows are then left out, said in one line).
    The element count is passed as ``elements=`` when the call takes it."""
    try:
        orbits_run(panel, orbit, 1, "hybrid", model="distributed")
    except tj.ParameterError as error:
        if error.parameter != "model":
            raise
        print('simulate_orbits(..., model="distributed") is not available here: rows left out\n')
        return None
    s = Series(
        "elements", f'simulate_orbits(model="distributed"), {args.distributed_orbits} orbits'
    )
    n_orbits = args.distributed_orbits
    for n in args.elements:
        try:
            time_orbits(s, n, args.repeat, panel, orbit, n_orbits, "hybrid", model="distributed",
                        elements=n)  # fmt: skip
        except TypeError as error:  # no elements= keyword: the default mesh only
            if isinstance(error, tj.ParameterError):  # a ParameterTypeError is a TypeError too
                raise
            default = tj.distributed_defaults(panel)["elements"]
            time_orbits(s, default, args.repeat, panel, orbit, n_orbits, "hybrid",
                        model="distributed")  # fmt: skip
            break
    return s


def figure(parts: Sequence[Sequence[Series]], path: Path, dpi: int = 90) -> None:
    """One log-log panel per axis of growth: wall time (solid) and CPU time (dashed, same
    colour) of each series, and a dotted line of slope 1 for scale."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib.ticker import FuncFormatter, NullFormatter

    plain = FuncFormatter(lambda v, _: f"{v:g}")
    titles = ("horizon (Table 1)", "nodes through the thickness (CFRP wing)", "distributed panel")
    xlabels = ("orbits", "nodes N", "elements")
    fig, axes = plt.subplots(1, 3, figsize=(13, 5.2))
    for ax, series, title, xlabel in zip(axes, parts, titles, xlabels, strict=True):
        drawn = [s for s in series if s.sizes]
        for s in drawn:
            whole = s.slopes()[0]
            (line,) = ax.loglog(
                s.sizes, s.times, "o-", ms=3, label=f"{s.label} (slope {whole:.2f})"
            )
            ax.loglog(s.sizes, s.cpu, "--", lw=0.8, color=line.get_color())
        if drawn:
            x = np.array([min(min(s.sizes) for s in drawn), max(max(s.sizes) for s in drawn)])
            ax.loglog(x, drawn[0].times[0] * x / x[0], ":", color="grey", label="slope 1")
        ax.set_title(title, fontsize=10)
        ax.set_xlabel(xlabel)
        ax.grid(True, which="both", alpha=0.3)
        ax.xaxis.set_major_formatter(plain)
        ax.xaxis.set_minor_formatter(NullFormatter())
        ax.yaxis.set_major_formatter(plain)
        if drawn and len(drawn[0].sizes) > 1 and max(drawn[0].sizes) / min(drawn[0].sizes) < 20:
            ax.set_xticks(sorted({n for s in drawn for n in s.sizes}))
        low, high = ax.get_ylim()
        if high / low < 20:  # less than about a decade: label the minor ticks too
            ax.yaxis.set_minor_formatter(plain)
        ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.14), frameon=False)
    axes[0].set_ylabel("time, s")
    fig.suptitle(
        "cost growth of a run (log-log): wall time, solid; CPU time, dashed; slopes of the wall "
        "time",
        fontsize=10,
    )
    fig.tight_layout()
    fig.savefig(path, dpi=dpi, pil_kwargs={"optimize": True})
    plt.close(fig)
    print(f"\nfigure: {path} ({path.stat().st_size / 1024:.0f} KB)")


PRESETS: dict[str, dict[str, Any]] = {
    "default": {
        "geo_hybrid_orbits": [1, 3, 10, 30, 100, 300, 1000, 3653],
        "geo_rk45_orbits": [1, 3, 10, 30, 100],
        "leo_orbits": [1, 3, 10, 30, 100, 300, 1000],
        "layers": [5, 6, 8, 12, 20, 40],
        "layer_orbits": 3,
        "layer_orbit": "geo",
        "elements": [5, 10, 20, 40],
        "element_span": 0.1,
        "distributed_orbits": 3,
        "repeat": 5,
    },
    "big": {
        "geo_hybrid_orbits": [1, 3, 10, 30, 100, 300, 1000, 3653, 10000],
        "geo_rk45_orbits": [1, 3, 10, 30, 100, 300],
        "leo_orbits": [1, 3, 10, 30, 100, 300, 1000, 3000],
        "layers": [5, 6, 8, 12, 20, 40, 80],
        "layer_orbits": 10,
        "layer_orbit": "geo",
        "elements": [5, 10, 20, 40, 80],
        "element_span": 0.1,
        "distributed_orbits": 10,
        "repeat": 5,
    },
    "quick": {
        "geo_hybrid_orbits": [1, 3],
        "geo_rk45_orbits": [1, 2],
        "leo_orbits": [1, 3],
        "layers": [5, 6],
        "layer_orbits": 1,
        "layer_orbit": "leo",
        "elements": [5, 10],
        "element_span": 0.005,
        "distributed_orbits": 1,
        "repeat": 1,
    },
}
"""The sizes of each run (``--quick``: a smoke run of a few seconds; ``--big``: tens of
minutes); a flag given on the command line overrides its preset."""


def ints(text: str) -> list[int]:
    return [int(x) for x in text.split(",") if x]


def parse(argv: Sequence[str] | None) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="a smoke run of a few seconds")
    parser.add_argument("--big", action="store_true", help="longer series (ten minutes or more)")
    parser.add_argument("--no-figure", action="store_true")
    parser.add_argument(
        "--parts", default="horizon,layers,elements", help="which parts to run, comma-separated"
    )
    parser.add_argument("--figure", type=Path, default=HERE / "cost_growth.png")
    parser.add_argument("--repeat", type=int, default=None, help="at most (default 5)")
    parser.add_argument("--start", default="2026-03-01", help="start date of geo_year")
    parser.add_argument("--geo-hybrid-orbits", type=ints, default=None)
    parser.add_argument("--geo-rk45-orbits", type=ints, default=None)
    parser.add_argument("--leo-orbits", type=ints, default=None)
    parser.add_argument("--layers", type=ints, default=None, help="node counts, e.g. 5,6,8")
    parser.add_argument("--layer-orbits", type=int, default=None)
    parser.add_argument("--layer-orbit", choices=("geo", "leo"), default=None)
    parser.add_argument("--elements", type=ints, default=None)
    parser.add_argument("--element-span", type=float, default=None, help="in orbits")
    parser.add_argument("--distributed-orbits", type=int, default=None)
    args = parser.parse_args(argv)
    preset = "quick" if args.quick else "big" if args.big else "default"
    for name, value in PRESETS[preset].items():
        if getattr(args, name) is None:
            setattr(args, name, value)
    return args


def main(argv: Sequence[str] | None = None) -> None:
    args = parse(argv)
    print(machine.describe())
    start = time.perf_counter()
    chosen = set(args.parts.split(","))
    parts = [
        run(args) if name in chosen else []
        for name, run in (("horizon", horizon), ("layers", layers), ("elements", elements))
    ]
    print(f"\ntotal {time.perf_counter() - start:.0f} s; load average at the end: {machine.load()}")
    if not args.no_figure:
        figure(parts, args.figure)


if __name__ == "__main__":
    main()
