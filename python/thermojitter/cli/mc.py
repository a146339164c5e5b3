"""``thermojitter mc SCENARIO.toml --n 1000 --out DIR``: a Monte Carlo study of a scenario file.

The scenario format of ``thermojitter run`` with two more tables:

    [panel]            # Panel fields overriding Table 1 (optional)
    damping = 3.0
    [orbit]            # a preset and/or Orbit fields (optional; default GEO at equinox)
    radius = 7.0e6
    period = 5828.5
    [vary]             # parameter = [distribution, numbers...] (see tj.monte_carlo)
    damping = ["uniform", 1.0, 4.0]
    emissivity_back = ["normal", 0.3, 0.03]
    [montecarlo]       # optional defaults: n, seed, sampler, horizon, threshold, truncate,
                       # rtol, atol, model, coupled, window

Writes DIR/samples.parquet (one row a sample), DIR/checkpoint/ (finished chunks: run the same
command again to resume a killed run), DIR/histograms.png and DIR/scatter.png.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from thermojitter.cli.common import Interrupted, add_out, out_dir, write_output
from thermojitter.montecarlo import monte_carlo
from thermojitter.scenario import ScenarioError, load_scenario

SETTING_KEYS = ("n", "seed", "sampler", "truncate")
"""Keys of [montecarlo] that set the design."""
RUN_KEYS = (
    "horizon",
    "threshold",
    "rtol",
    "atol",
    "model",
    "coupled",
    "window",
    "max_steps",
    "layers",
)


def read_scenario(path: str | Path) -> dict[str, Any]:
    """The panel, orbit, vary and montecarlo tables of a scenario file, checked (the panel and
    orbit by the shared scenario parser, so every scenario file of ``run`` works here)."""
    scenario = load_scenario(path, extra_sections=("vary", "montecarlo"))
    vary = scenario.extra["vary"]
    if not vary:
        raise ScenarioError(path, "vary", "a [vary] table is required (parameter = [dist, ...])")
    settings = dict(scenario.extra["montecarlo"])
    allowed = {*SETTING_KEYS, *RUN_KEYS}
    extra = sorted(set(settings) - allowed)
    if extra:
        raise ScenarioError(path, f"montecarlo.{extra[0]}", "unknown key")
    layers = settings.get("layers")
    if layers is not None and (
        isinstance(layers, bool) or not isinstance(layers, int) or layers < 2
    ):
        raise ScenarioError(
            path,
            "montecarlo.layers",
            f"must be an integer >= 2 (nodes through the thickness), not {layers!r}",
        )
    return {"panel": scenario.panel, "orbit": scenario.orbit, "vary": vary, "settings": settings}


def mc_command(argv: Sequence[str] | None = None) -> int:
    """``thermojitter mc ARGS``; returns the exit status."""
    from thermojitter.cli import main

    return main(["mc", *(sys.argv[1:] if argv is None else argv)])


def add_parser(sub: Any) -> None:
    p = sub.add_parser(
        "mc",
        help="Monte Carlo study of a scenario with a [vary] table (Parquet, histograms)",
        description="Monte Carlo study of a scenario file: panels drawn from the [vary] "
        "distributions, each run over whole orbits; writes samples.parquet, histograms.png and "
        "scatter.png, and resumes a killed run from DIR/checkpoint/.",
        epilog="Example: thermojitter mc examples/montecarlo.toml --n 200 --out out/mc",
    )
    p.add_argument("scenario", help="scenario TOML with [panel], [orbit], [vary] tables")
    add_out(p, required=True, help="output folder (created)")
    p.add_argument("--n", type=int, help="number of samples (default 1000)")
    p.add_argument("--seed", type=int, help="seed of the design (default 0)")
    p.add_argument("--sampler", choices=("random", "lhs", "sobol"))
    p.add_argument("--horizon", type=int, help="whole orbits per sample (default 1)")
    p.add_argument("--threshold", type=float, help="time the first |θ| above this, rad")
    p.add_argument("--threads", type=int, help="rayon threads (default: one per core)")
    p.add_argument(
        "--dask",
        nargs="?",
        const="dask",
        metavar="ADDRESS",
        help="run on Dask: a new LocalCluster, or the scheduler at ADDRESS",
    )
    p.add_argument("--truncate", action="store_true", help="truncate to the valid ranges")
    p.add_argument("--no-progress", action="store_true", help="no progress bar")
    p.add_argument("--no-plots", action="store_true", help="write no plots")
    # No stop flag: Ctrl-C reaches monte_carlo, which stops at once and keeps finished chunks.
    p.set_defaults(handler=run, stop_flag=False)


def run(args: argparse.Namespace) -> int:
    scenario = read_scenario(args.scenario)
    s = scenario["settings"]
    out = out_dir(args.out, args.overwrite)
    run = {k: s[k] for k in RUN_KEYS if k in s}
    for key in ("horizon", "threshold"):
        if getattr(args, key) is not None:
            run[key] = getattr(args, key)
    frame = monte_carlo(
        scenario["panel"],
        scenario["orbit"],
        vary={k: tuple(v) if isinstance(v, list) else v for k, v in scenario["vary"].items()},
        n=args.n if args.n is not None else int(s.get("n", 1000)),
        seed=args.seed if args.seed is not None else int(s.get("seed", 0)),
        sampler=args.sampler or s.get("sampler", "random"),
        truncate=args.truncate or bool(s.get("truncate", False)),
        threads=args.threads,
        backend=args.dask,
        checkpoint=out / "checkpoint",
        progress=not args.no_progress,
        **run,
    )
    if frame.attrs["interrupted"]:
        raise Interrupted  # monte_carlo said what it kept and how to resume
    write_output(out / "samples.parquet", lambda fh: frame.to_parquet(fh))
    names = list(scenario["vary"])
    flutter = int((~frame["stable"]).sum())
    failed = int(frame["error"].notna().sum())
    print(f"{len(frame)} samples -> {out / 'samples.parquet'}")
    print(f"unstable equilibrium (flutter): {flutter} ({100.0 * flutter / len(frame):.1f} %)")
    if failed:
        print(f"failed samples: {failed} (see the 'error' column)")
    for m in ("exit_peak", "jitter_rms", "theta_abs_max"):
        q = np.nanpercentile(frame[m].to_numpy(float), [5, 50, 95])
        print(f"{m:>14}: 5% {q[0]:.4g}  median {q[1]:.4g}  95% {q[2]:.4g} rad")
    if not args.no_plots:
        from thermojitter.plots import monte_carlo_figures

        for path in monte_carlo_figures(frame, names, out):
            print(f"wrote {path}")
    return 0
