"""``thermojitter mc SCENARIO.toml --n 1000 --out DIR``: a Monte Carlo study of a scenario file.

The scenario format of ``thermojitter run`` with two more tables:

    [panel]            # Panel fields overriding Table 1 (optional; or a [boom] table)
    damping = 3.0
    [orbit]            # a preset and/or Orbit fields (optional; default GEO at equinox)
    radius = 7.0e6
    period = 5828.5
    [attitude]         # optional: where the front face points (as for ``run``)
    [vary]             # parameter = [distribution, numbers...] (see tj.monte_carlo): panel
                       # (or boom) parameters and the orbit inputs albedo, earth_ir,
                       # inclination, raan
    damping = ["uniform", 1.0, 4.0]
    emissivity_back = ["normal", 0.3, 0.03]
    [montecarlo]       # optional defaults: n, seed, sampler, horizon, threshold, truncate,
                       # rtol, atol, model, coupled, window

Writes DIR/samples.parquet (one row a sample), DIR/checkpoint/ (finished chunks: run the same
command again to resume a killed run), DIR/histograms.png and DIR/scatter.png.

A sample that fails keeps its row (the reason in ``error``, ``stable`` empty); the summary counts
the failed samples and the flutter share is of those that finished. Exit code 3 when samples
failed, unless ``--allow-failures``; always 3 (with samples.parquet and no plots) when every
sample failed.
"""

from __future__ import annotations

import argparse
import warnings
from pathlib import Path
from typing import Any

import numpy as np

from thermojitter.cli.common import (
    EXIT_SAMPLES_FAILED,
    Command,
    Interrupted,
    SamplesFailed,
    add_out,
    out_dir,
    write_output,
)
from thermojitter.errors import SampleFailureWarning
from thermojitter.montecarlo import AllSamplesFailedError, monte_carlo
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
    """The panel (or boom), orbit, attitude, vary and montecarlo tables of a scenario file,
    checked (the panel, orbit and attitude by the shared scenario parser, so every scenario file
    of ``run`` works here)."""
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
    return {
        "panel": scenario.panel,
        "orbit": scenario.orbit,
        "attitude": scenario.attitude,
        "vary": vary,
        "settings": settings,
    }


def options(p: argparse.ArgumentParser) -> None:
    p.add_argument(
        "scenario", help="scenario TOML with [panel] or [boom], [orbit], [attitude], [vary] tables"
    )
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
    p.add_argument(
        "--allow-failures",
        action="store_true",
        help="exit 0 when some samples failed (they are counted in the summary and kept in "
        f"samples.parquet with their error); without it the exit code is {EXIT_SAMPLES_FAILED}. "
        f"A study whose every sample failed exits {EXIT_SAMPLES_FAILED} all the same",
    )


def run(args: argparse.Namespace) -> int:
    scenario = read_scenario(args.scenario)
    s = scenario["settings"]
    out = out_dir(args.out, args.overwrite)
    run = {k: s[k] for k in RUN_KEYS if k in s}
    for key in ("horizon", "threshold"):
        if getattr(args, key) is not None:
            run[key] = getattr(args, key)
    samples = out / "samples.parquet"
    try:
        with warnings.catch_warnings():
            # The summary below counts the failed samples; the warning would say it again.
            warnings.simplefilter("ignore", SampleFailureWarning)
            frame = monte_carlo(
                scenario["panel"],
                scenario["orbit"],
                attitude=scenario["attitude"],
                vary={
                    k: tuple(v) if isinstance(v, list) else v for k, v in scenario["vary"].items()
                },
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
    except AllSamplesFailedError as exc:
        failed_frame = exc.samples  # the study's frame, every row with its error
        if failed_frame.attrs["interrupted"]:
            raise Interrupted from None  # monte_carlo said what it kept and how to resume
        write_output(samples, lambda fh: failed_frame.to_parquet(fh))
        every_sample = "the only sample" if exc.n == 1 else f"all {exc.n} samples"
        raise SamplesFailed(
            f"{every_sample} failed (sample {exc.first_sample}: {exc.first_error}); "
            f"every error is in {samples}"
        ) from None
    if frame.attrs["interrupted"]:
        raise Interrupted  # monte_carlo said what it kept and how to resume
    write_output(samples, lambda fh: frame.to_parquet(fh))
    names = list(scenario["vary"])
    failed = int(frame.attrs["n_failed"])
    finished = len(frame) - failed
    # stable is NA for a failed sample, and the sum skips NA: flutter among the finished ones.
    flutter = int((~frame["stable"]).sum())
    print(f"{len(frame)} samples -> {samples}")
    first = ""
    if failed:
        k = int(np.flatnonzero(frame["error"].notna().to_numpy())[0])
        first = f"sample {frame.index[k]}: {frame['error'].iloc[k]}"
    print(f"failed: {failed} of {len(frame)} samples" + (f" ({first})" if failed else ""))
    print(
        f"unstable equilibrium (flutter): {flutter} of {finished} finished samples "
        f"({100.0 * flutter / finished:.1f} %)"
    )
    for m in ("exit_peak", "jitter_rms", "theta_abs_max"):
        q = np.nanpercentile(frame[m].to_numpy(float), [5, 50, 95])
        print(f"{m:>14}: 5% {q[0]:.4g}  median {q[1]:.4g}  95% {q[2]:.4g} rad")
    horizon = int(run.get("horizon", 1))
    if horizon < 2:
        print(
            f"note: amplitude_slope is NaN for every sample: it is the slope over the orbits of "
            f"the run and needs 2 or more (the horizon is {horizon}; --horizon N or horizon = N "
            "in [montecarlo])"
        )
    if not args.no_plots:
        from thermojitter.reports.plots import monte_carlo_figures

        for path in monte_carlo_figures(frame, names, out):
            print(f"wrote {path}")
    if failed and not args.allow_failures:
        raise SamplesFailed(
            f"{failed} of {len(frame)} samples failed ({first}); the summary above is of the "
            f"{finished} that finished, every error is in {samples}; pass --allow-failures to "
            "accept a study with failed samples"
        )
    return 0


COMMAND = Command(
    "mc",
    options,
    run,
    # No stop flag: Ctrl-C reaches monte_carlo, which stops at once and keeps finished chunks.
    stop_flag=False,
    help="Monte Carlo study of a scenario with a [vary] table (Parquet, histograms)",
    description="Monte Carlo study of a scenario file: panels drawn from the [vary] "
    "distributions, each run over whole orbits; writes samples.parquet, histograms.png and "
    "scatter.png, and resumes a killed run from DIR/checkpoint/.",
    epilog="Example: thermojitter mc examples/montecarlo.toml --n 200 --out out/mc. "
    f"Exit codes: 0 done, 2 bad input, {EXIT_SAMPLES_FAILED} samples failed (see "
    "--allow-failures), 130 Ctrl-C.",
)
add_parser = COMMAND.add_parser
mc_command = COMMAND.main
