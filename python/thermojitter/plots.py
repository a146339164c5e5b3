"""Plot helpers shared by ``thermojitter paper`` and ``thermojitter run`` (matplotlib, Agg).

Angles are shown in degrees, times in the unit named on the axis; every figure gets a title
saying what is shown. Long records are reduced to their per-pixel minimum and maximum before
drawing, so an oscillation of millions of samples keeps its envelope and draws fast.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]

MAX_POINTS = 6000
"""Above this many samples a curve is drawn from its min/max per bin (2 points per bin)."""


def pyplot() -> Any:
    """matplotlib.pyplot on the non-interactive Agg backend (raises ImportError with a hint)."""
    try:
        import matplotlib
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError("plots need matplotlib: pip install 'thermojitter[cli]'") from exc
    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    return plt


def envelope(x: Array, y: Array, max_points: int = MAX_POINTS) -> tuple[Array, Array]:
    """(x, y) reduced to the minimum and maximum of y in each of max_points/2 bins, in order.

    Below max_points samples the data is returned unchanged."""
    n = len(x)
    if n <= max_points:
        return x, y
    bins = max_points // 2
    edges = np.linspace(0, n, bins + 1).astype(int)
    xs = np.empty(2 * bins)
    ys = np.empty(2 * bins)
    for i in range(bins):
        a, b = edges[i], edges[i + 1]
        seg = y[a:b]
        lo, hi = int(np.argmin(seg)), int(np.argmax(seg))
        first, second = (lo, hi) if lo <= hi else (hi, lo)
        xs[2 * i], ys[2 * i] = x[a + first], seg[first]
        xs[2 * i + 1], ys[2 * i + 1] = x[a + second], seg[second]
    return xs, ys


def line(ax: Any, x: Array, y: Array, **kwargs: Any) -> Any:
    """ax.plot of a possibly very long record (see :func:`envelope`)."""
    xs, ys = envelope(np.asarray(x, dtype=float), np.asarray(y, dtype=float))
    return ax.plot(xs, ys, **kwargs)


def shade_shadow(
    ax: Any,
    intervals: Iterable[tuple[float, float]],
    *,
    scale: float = 1.0,
    offset: float = 0.0,
    label: str | None = "Earth shadow",
) -> None:
    """Grey bands over the eclipses; times (s) are mapped to (t - offset)/scale on the axis."""
    for i, (a, b) in enumerate(intervals):
        ax.axvspan(
            (a - offset) / scale,
            (b - offset) / scale,
            color="0.85",
            zorder=0,
            label=label if i == 0 else None,
        )


def mark(ax: Any, x: float, text: str, **kwargs: Any) -> None:
    """A dashed vertical line with a small label at the top of the axes."""
    ax.axvline(x, color="0.3", lw=0.8, ls="--", zorder=1)
    ax.annotate(
        text,
        xy=(x, 1.0),
        xycoords=("data", "axes fraction"),
        xytext=(3, -12),
        textcoords="offset points",
        fontsize=8,
        color="0.3",
        **kwargs,
    )


def figure(rows: int = 1, *, height: float = 4.0, sharex: bool = True) -> tuple[Any, Any]:
    plt = pyplot()
    fig, axes = plt.subplots(rows, 1, figsize=(8.0, height), sharex=sharex, squeeze=False)
    return fig, [ax for ax in axes[:, 0]]


def save(fig: Any, path: Path) -> Path:
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    pyplot().close(fig)
    return path


def time_axis(span: float) -> tuple[float, str]:
    """A readable time unit for a span of ``span`` s: (seconds per unit, axis label)."""
    if span <= 600.0:
        return 1.0, "time [s]"
    if span <= 6.0 * 3600.0:
        return 60.0, "time [min]"
    return 3600.0, "time [h]"


def run_figures(
    out: Path,
    t: Array,
    columns: dict[str, Array],
    intervals: Sequence[tuple[float, float]],
    *,
    title: str,
) -> list[Path]:
    """The plots of ``thermojitter run``: temperatures and ΔT, then θ and θ̇ (if present)."""
    scale, label = time_axis(float(t[-1] - t[0]) if len(t) > 1 else 1.0)
    x = t / scale
    written = []
    if "T_front" in columns:
        fig, (ax1, ax2) = figure(2, height=6.0)
        line(ax1, x, columns["T_front"], lw=0.9, label="front layer $T_f$")
        line(ax1, x, columns["T_back"], lw=0.9, label="back layer $T_b$")
        ax1.set_ylabel("temperature [K]")
        line(ax2, x, columns["T_front"] - columns["T_back"], lw=0.9, color="C2")
        ax2.set_ylabel(r"$\Delta T = T_f - T_b$ [K]")
        for ax in (ax1, ax2):
            shade_shadow(ax, intervals, scale=scale)
            ax.grid(alpha=0.3)
        ax1.legend(loc="best", fontsize=8)
        ax2.set_xlabel(label)
        ax1.set_title(f"{title}: layer temperatures and their difference")
        written.append(save(fig, out / "temperatures.png"))
    if "theta" in columns:
        fig, (ax1, ax2) = figure(2, height=6.0)
        line(ax1, x, np.degrees(columns["theta"]), lw=0.7)
        ax1.set_ylabel(r"hinge angle $\theta$ [deg]")
        line(ax2, x, np.degrees(columns["theta_dot"]), lw=0.7, color="C1")
        ax2.set_ylabel(r"$\dot\theta$ [deg/s]")
        for ax in (ax1, ax2):
            shade_shadow(ax, intervals, scale=scale)
            ax.grid(alpha=0.3)
        ax2.set_xlabel(label)
        ax1.set_title(f"{title}: hinge angle and rate")
        written.append(save(fig, out / "theta.png"))
    return written


def orbit_summary_figure(out: Path, columns: dict[str, Array], title: str) -> Path:
    """Per-orbit summaries of a long run: amplitude, transient peaks and jitter RMS against time
    (days), on a log scale so that growth (flutter) shows as a straight line."""
    fig, (top, bottom) = figure(2, height=4.2)
    days = np.asarray(columns["t_start"]) / 86400.0
    for key, label in (
        ("amplitude", "max |θ − θ_eq| over the orbit"),
        ("exit_peak", "peak after shadow exit"),
        ("entry_peak", "peak after shadow entry"),
    ):
        values = np.degrees(np.asarray(columns[key], dtype=float))
        top.semilogy(days, np.where(values > 0, values, np.nan), lw=0.8, label=label)
    top.set_ylabel("angle [deg]")
    top.set_title(f"{title}: per-orbit summaries")
    top.legend(loc="best", fontsize=8)
    top.grid(alpha=0.3, which="both")
    rms = np.degrees(np.asarray(columns["jitter_rms"], dtype=float))
    bottom.semilogy(days, np.where(rms > 0, rms, np.nan), lw=0.8, color="C3")
    bottom.set_ylabel("RMS jitter [deg]")
    bottom.set_title(
        "RMS over each orbit of θ − M_T/K_el (the oscillation about the static angle)", fontsize=9
    )
    bottom.set_xlabel("time from the start [days]")
    bottom.grid(alpha=0.3, which="both")
    return save(fig, out / "orbits.png")
