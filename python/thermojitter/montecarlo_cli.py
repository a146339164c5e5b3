"""``thermojitter mc SCENARIO.toml --n 1000 --out DIR``: a Monte Carlo study from a scenario file.

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

from thermojitter.montecarlo import monte_carlo
from thermojitter.panel import PANEL_UNITS
from thermojitter.scenario import ScenarioError, load_scenario

HISTOGRAMS = (
    "theta_eq", "growth_rate", "critical_damping", "theta_abs_max", "entry_peak", "exit_peak",
    "jitter_rms", "jitter_peak", "t_threshold",
)  # fmt: skip
SCATTER_METRICS = ("exit_peak", "jitter_rms", "growth_rate")
_RUN_KEYS = ("horizon", "threshold", "rtol", "atol", "model", "coupled", "window")


def read_scenario(path: str | Path) -> dict[str, Any]:
    """The panel, orbit, vary and montecarlo tables of a scenario file, checked (the panel and
    orbit by the shared scenario parser, so every scenario file of ``run`` works here)."""
    scenario = load_scenario(path, extra_sections=("vary", "montecarlo"))
    vary = scenario.extra["vary"]
    if not vary:
        raise ScenarioError(path, "vary", "a [vary] table is required (parameter = [dist, ...])")
    settings = dict(scenario.extra["montecarlo"])
    allowed = {"n", "seed", "sampler", "truncate", *_RUN_KEYS}
    extra = sorted(set(settings) - allowed)
    if extra:
        raise ScenarioError(path, f"montecarlo.{extra[0]}", "unknown key")
    return {"panel": scenario.panel, "orbit": scenario.orbit, "vary": vary, "settings": settings}


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(
        prog="thermojitter mc", description="Monte Carlo study of a scenario file."
    )
    p.add_argument("scenario", help="scenario TOML with [panel], [orbit], [vary] tables")
    p.add_argument("--out", required=True, help="output directory")
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
    p.add_argument("--no-progress", action="store_true")
    p.add_argument("--no-plots", action="store_true")
    return p


# Plot labels: angles are shown in degrees (the tables keep radians), other metrics in SI.
_ANGLES = {"theta_eq", "theta_abs_max", "entry_peak", "exit_peak", "jitter_rms", "jitter_peak"}
_UNITS = {"growth_rate": "1/s", "critical_damping": "N m s/rad", "t_threshold": "s"}


def _shown(frame: Any, name: str) -> tuple[np.ndarray, str]:
    """A metric or parameter column as plotted, with its axis label."""
    values = frame[name].to_numpy(float)
    if name in _ANGLES:
        return np.degrees(values), f"{name} [deg]"
    unit = _UNITS.get(name) or PANEL_UNITS.get(name)
    return values, f"{name} [{unit}]" if unit else name


def plot(frame: Any, names: Sequence[str], out: Path) -> list[Path]:
    """Histograms of the metrics and scatter plots of the metrics against the parameters."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    written = []
    metrics = [m for m in HISTOGRAMS if np.isfinite(frame[m].to_numpy(float)).any()]
    cols = 3
    rows = max(1, -(-len(metrics) // cols))
    fig, axes = plt.subplots(rows, cols, figsize=(4 * cols, 3 * rows), squeeze=False)
    for ax, m in zip(axes.flat, metrics, strict=False):
        values, label = _shown(frame, m)
        ax.hist(values[np.isfinite(values)], bins=40, color="tab:blue")
        ax.set_xlabel(label)
        ax.set_ylabel("samples")
    for ax in list(axes.flat)[len(metrics) :]:
        ax.set_visible(False)
    fig.suptitle(f"{len(frame)} samples")
    fig.tight_layout()
    path = out / "histograms.png"
    fig.savefig(path, dpi=100)
    plt.close(fig)
    written.append(path)

    fig, axes = plt.subplots(
        len(names),
        len(SCATTER_METRICS),
        figsize=(4 * len(SCATTER_METRICS), 3 * len(names)),
        squeeze=False,
    )
    stable = frame["stable"].to_numpy(bool)
    for i, name in enumerate(names):
        for j, m in enumerate(SCATTER_METRICS):
            ax = axes[i, j]
            (x, xlabel), (y, ylabel) = _shown(frame, name), _shown(frame, m)
            ax.scatter(x[stable], y[stable], s=6, label="stable", color="tab:blue")
            ax.scatter(x[~stable], y[~stable], s=6, label="flutter", color="tab:red")
            ax.set_xlabel(xlabel)
            ax.set_ylabel(ylabel)
    axes[0, 0].legend(fontsize="small")
    fig.tight_layout()
    path = out / "scatter.png"
    fig.savefig(path, dpi=100)
    plt.close(fig)
    written.append(path)
    return written


def mc_command(argv: Sequence[str] | None = None) -> int:
    """Entry point of ``thermojitter mc``; returns the exit status."""
    args = _parser().parse_args(argv)
    scenario = read_scenario(args.scenario)
    s = scenario["settings"]
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    run = {k: s[k] for k in _RUN_KEYS if k in s}
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
    frame.to_parquet(out / "samples.parquet")
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
        for path in plot(frame, names, out):
            print(f"wrote {path}")
    return 0


if __name__ == "__main__":
    sys.exit(mc_command())
