"""The figures of thermojitter, in one style (matplotlib, Agg): ``thermojitter paper``, ``run``,
``flutter``, ``beam`` and ``mc`` all draw with these helpers.

The style:

- a title on every figure; figures of the paper carry the paper's number ("Fig. 22 — ...");
- SI units or degrees on every axis, in brackets ("time from shadow entry [min]"); one unit per
  axis, never a time offset written into the label;
- Earth's shadow shaded grey (umbra darker, penumbra lighter), each with a legend entry;
- legends below the axes (:func:`legend`), never over the data;
- tick labels in scientific notation with a common factor (×10⁻⁴), not "−0.00010";
- nothing below the solver's resolution drawn as if it were signal (:data:`NOISE_FLOOR_DEG`);
- long records reduced to their per-pixel minimum and maximum before drawing, so an oscillation
  of millions of samples keeps its envelope and draws fast.
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from thermojitter.checkpoint import write_atomic
from thermojitter.panel import PANEL_UNITS

Array = NDArray[np.float64]

MAX_POINTS = 6000
"""Above this many samples a curve is drawn from its min/max per bin (2 points per bin)."""

NOISE_FLOOR_DEG = 1e-6
"""Angles below this (deg, about 2e-8 rad, a hundred times the default atol on θ) are the
integrator's resolution, not a physical oscillation: they are not drawn as data."""

UMBRA_COLOR = "0.80"
PENUMBRA_COLOR = "0.92"
DPI = 110


def pyplot() -> Any:
    """matplotlib.pyplot on the non-interactive Agg backend (raises ImportError with a hint)."""
    try:
        import matplotlib
    except ImportError as exc:  # pragma: no cover - depends on the environment
        raise ImportError("plots need matplotlib: pip install 'thermojitter[cli]'") from exc
    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    return plt


# --------------------------------------------------------------------------------------------
# building blocks


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
    color: str = UMBRA_COLOR,
) -> None:
    """Grey bands over the eclipses; times (s) are mapped to (t - offset)/scale on the axis."""
    for i, (a, b) in enumerate(intervals):
        ax.axvspan(
            (a - offset) / scale,
            (b - offset) / scale,
            color=color,
            lw=0,
            zorder=0,
            label=label if i == 0 else None,
        )


def shade_eclipses(
    ax: Any,
    orbit: Any,
    t0: float,
    t1: float,
    *,
    scale: float = 1.0,
    offset: float = 0.0,
    labels: bool = True,
) -> None:
    """Earth's shadow over [t0, t1] of ``orbit``: the umbra (s = 0) darker, the penumbra
    (0 < s < 1) lighter, each with a legend entry when present (``labels``)."""
    whole = orbit.shadow_intervals(t0, t1)
    umbra = orbit.umbra_intervals(t0, t1)
    has_penumbra = any(
        abs(a - c) > 1e-6 or abs(b - d) > 1e-6 for (a, b), (c, d) in zip(whole, umbra, strict=False)
    ) or len(whole) != len(umbra)
    if has_penumbra:
        shade_shadow(
            ax,
            whole,
            scale=scale,
            offset=offset,
            label="penumbra" if labels else None,
            color=PENUMBRA_COLOR,
        )
    shade_shadow(
        ax,
        umbra,
        scale=scale,
        offset=offset,
        label=("umbra" if has_penumbra else "Earth shadow") if labels else None,
    )


def mark(ax: Any, x: float, text: str, **kwargs: Any) -> None:
    """A dashed vertical line with a small label inside the top of the axes."""
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


def legend(fig: Any, *, ncols: int | None = None) -> Any:
    """One legend for the whole figure, below the axes (clear of the data), with each label once
    (the shadow bands of several panels appear once)."""
    seen: dict[str, Any] = {}
    for ax in fig.axes:
        for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
            if label and not label.startswith("_") and label not in seen:
                seen[label] = handle
    if not seen:
        return None
    if ncols is None:
        # As many columns as fit the figure's width (about 11 characters per inch at 8 pt).
        room = 11.0 * fig.get_figwidth()
        ncols = min(len(seen), 4)
        while ncols > 1 and max(len(label) + 6 for label in seen) * ncols > room:
            ncols -= 1
    return fig.legend(
        list(seen.values()),
        list(seen),
        loc="outside lower center",
        ncols=ncols,
        fontsize=8,
        frameon=False,
    )


def tidy_ticks(ax: Any) -> None:
    """Scientific notation with a common factor on linear axes whose numbers are very small or
    large (×10⁻⁴ at the axis end instead of tick labels like −0.00010)."""
    for axis in ("x", "y"):
        try:
            ax.ticklabel_format(axis=axis, style="sci", scilimits=(-3, 4), useMathText=True)
        except AttributeError:  # a log or categorical axis: its own formatter is fine
            pass


def figure(
    rows: int = 1, *, height: float = 4.0, sharex: bool = True, width: float = 8.0
) -> tuple[Any, Any]:
    """A figure of ``rows`` axes stacked, with room for :func:`legend` below them."""
    plt = pyplot()
    fig, axes = plt.subplots(
        rows, 1, figsize=(width, height), sharex=sharex, squeeze=False, layout="constrained"
    )
    return fig, [ax for ax in axes[:, 0]]


def save(fig: Any, path: Path) -> Path:
    """Writes the PNG and closes the figure."""
    if fig.get_layout_engine() is None:
        fig.tight_layout()
    try:
        # Atomic: a failed write (a full disk) leaves no partial image.
        write_atomic(path, lambda fh: fig.savefig(fh, dpi=DPI, format="png"))
    finally:
        pyplot().close(fig)
    return path


def time_axis(span: float) -> tuple[float, str]:
    """A readable time unit for a span of ``span`` s: (seconds per unit, unit name)."""
    if span <= 600.0:
        return 1.0, "s"
    if span <= 6.0 * 3600.0:
        return 60.0, "min"
    if span <= 10.0 * 86400.0:
        return 3600.0, "h"
    return 86400.0, "days"


def above_noise(values_deg: Array) -> Array:
    """Angles (deg) with those below :data:`NOISE_FLOOR_DEG` replaced by NaN (not drawn)."""
    v = np.asarray(values_deg, dtype=float)
    return np.where(np.abs(v) >= NOISE_FLOOR_DEG, v, np.nan)


# --------------------------------------------------------------------------------------------
# thermojitter run


def run_figures(
    out: Path,
    t: Array,
    columns: dict[str, Array],
    orbit: Any,
    *,
    title: str,
) -> list[Path]:
    """The plots of ``thermojitter run``: temperatures and ΔT, then θ and θ̇ (if present)."""
    t0, t1 = float(t[0]), float(t[-1])
    scale, unit = time_axis(t1 - t0 if len(t) > 1 else 1.0)
    x = (t - t0) / scale
    xlabel = f"time from t = {t0:g} s [{unit}]" if t0 != 0.0 else f"time [{unit}]"
    written = []
    if "T_front" in columns:
        fig, (ax1, ax2) = figure(2, height=6.0)
        line(ax1, x, columns["T_front"], lw=0.9, label="front layer $T_f$")
        line(ax1, x, columns["T_back"], lw=0.9, label="back layer $T_b$")
        ax1.set_ylabel("temperature [K]")
        line(ax2, x, columns["T_front"] - columns["T_back"], lw=0.9, color="C2")
        ax2.set_ylabel(r"$\Delta T = T_f - T_b$ [K]")
        for i, ax in enumerate((ax1, ax2)):
            shade_eclipses(ax, orbit, t0, t1, scale=scale, offset=t0, labels=i == 0)
            ax.grid(alpha=0.3)
        ax2.set_xlabel(xlabel)
        ax1.set_title(f"{title}: layer temperatures and their difference")
        legend(fig)
        written.append(save(fig, out / "temperatures.png"))
    if "theta" in columns:
        fig, (ax1, ax2) = figure(2, height=6.0)
        line(ax1, x, np.degrees(columns["theta"]), lw=0.7, label=r"hinge angle $\theta$")
        ax1.set_ylabel(r"$\theta$ [deg]")
        line(ax2, x, np.degrees(columns["theta_dot"]), lw=0.7, color="C1", label=r"$\dot\theta$")
        ax2.set_ylabel(r"$\dot\theta$ [deg/s]")
        for i, ax in enumerate((ax1, ax2)):
            shade_eclipses(ax, orbit, t0, t1, scale=scale, offset=t0, labels=i == 0)
            ax.grid(alpha=0.3)
            tidy_ticks(ax)
        ax2.set_xlabel(xlabel)
        ax1.set_title(f"{title}: hinge angle and rate")
        legend(fig)
        written.append(save(fig, out / "theta.png"))
    return written


YEAR = 365.25 * 86400.0
"""A Julian year, s: the default span of :func:`orbit_year_figure`."""

BETA_SAMPLES = 2000
"""Points of the β curve of :func:`orbit_year_figure`."""


def orbit_year_figure(
    orbit: Any, t0: float = 0.0, span: float = YEAR, *, title: str = "orbit"
) -> Any:
    """The Sun's angle β to the orbit plane and the length of every eclipse over
    [t0, t0 + span] (a year by default), against days from t0: β from ``orbit.beta`` at
    :data:`BETA_SAMPLES` evenly spaced times, each eclipse's length from first to last contact
    (``orbit.eclipse_durations``) at its deepest point (``orbit.eclipses``), and its umbra when
    the orbit has a penumbra. Eclipses exist only while abs(β) is small enough; their seasons are
    the gaps. Returns the figure (top axes: β [deg]; bottom: eclipse length [min])."""
    t1 = t0 + span
    t = np.linspace(t0, t1, BETA_SAMPLES)
    fig, (top, bottom) = figure(2, height=5.6)
    top.plot((t - t0) / 86400.0, np.degrees(orbit.beta(t)), lw=1.0, color="C0", label=r"$\beta$")
    top.axhline(0.0, color="k", lw=0.6)
    top.set_ylabel(r"$\beta$, Sun to orbit plane [deg]")
    top.set_title(f"{title}: the Sun's angle to the orbit plane and the eclipses")
    rows = orbit.eclipses(t0, t1)
    rows = rows[(rows[:, 0] >= t0) & (rows[:, 0] < t1)]
    days = (rows[:, 0] - t0) / 86400.0
    total = orbit.eclipse_durations(t0, t1) / 60.0
    bottom.plot(days, total, ".", ms=2.5, color="C3", label="eclipse, first to last contact")
    if orbit.shadow == "penumbra":
        umbra = orbit.eclipse_durations(t0, t1, kind="umbra") / 60.0
        bottom.plot(days, umbra, ".", ms=1.5, color="C1", label="umbra")
    if not len(days):
        bottom.text(0.5, 0.5, "no eclipse", transform=bottom.transAxes, ha="center")
    bottom.set_ylim(bottom=0.0)
    bottom.set_ylabel("eclipse length [min]")
    bottom.set_xlabel(f"time from t = {t0:g} s [days]" if t0 else "time [days]")
    for ax in (top, bottom):
        ax.grid(alpha=0.3)
    legend(fig)
    return fig


def cd_year_figure(data: Any, *, title: str = "Table 1 on GEO") -> Any:
    """The critical damping c_d* of the hinge model and of the distributed panel over a year, on
    one axes (``data``: a :class:`thermojitter.CriticalDampingYear`), with
    the solar flux scale beneath. Lines in the order hinge, distributed (top axes)."""
    fig, (top, bottom) = figure(2, height=5.6)
    days = data.days
    top.plot(days, data.hinge, "o-", ms=3, lw=1.0, color="C0", label="hinge model, c_d*")
    top.plot(
        days, data.distributed, "s-", ms=3, lw=1.0, color="C3",
        label="distributed panel, c_d* (hinge-equivalent 2 I_B ω₁ ζ*)",
    )  # fmt: skip
    top.set_ylabel("critical damping c_d* [N m s/rad]")
    top.set_title(f"{title}: critical damping over the year")
    bottom.plot(days, data.flux, lw=1.0, color="C1", label="solar flux scale")
    bottom.set_ylabel("flux / 1 au")
    bottom.set_xlabel("time [days]")
    for ax in (top, bottom):
        ax.grid(alpha=0.3)
    legend(fig)
    return fig


def face_flux_figure(
    t: Array, flux_front: Array, flux_back: Array, orbit: Any, *, title: str = "run"
) -> Any:
    """The flux reaching each face over a run (``sol.flux_front``, ``sol.flux_back``, W/m²:
    sunlight, albedo and Earth infrared on the flat panel in its attitude), with the Earth's
    shadow shaded. Returns the figure (one axes: the front's line, then the back's)."""
    t = np.asarray(t, dtype=float)
    t0, t1 = float(t[0]), float(t[-1])
    scale, unit = time_axis(t1 - t0 if len(t) > 1 else 1.0)
    x = (t - t0) / scale
    fig, (ax,) = figure(1, height=4.2)
    line(ax, x, flux_front, lw=0.9, color="C3", label="front face")
    line(ax, x, flux_back, lw=0.9, color="C0", label="back face")
    shade_eclipses(ax, orbit, t0, t1, scale=scale, offset=t0)
    ax.set_ylabel("flux reaching the face [W/m²]")
    ax.set_xlabel(f"time from t = {t0:g} s [{unit}]" if t0 != 0.0 else f"time [{unit}]")
    ax.set_title(f"{title}: sunlight, albedo and Earth infrared on each face")
    ax.grid(alpha=0.3)
    legend(fig)
    return fig


def orbit_summary_figure(out: Path, columns: dict[str, Array], title: str) -> Path:
    """Per-orbit summaries of a long run: amplitude, transient peaks and jitter RMS against time
    (days), on a log scale so that growth (flutter) shows as a straight line. Values below the
    integrator's resolution (orbits without an eclipse) are left out, and said so."""
    fig, (top, bottom) = figure(2, height=5.6)
    days = np.asarray(columns["t_start"]) / 86400.0
    hidden = 0
    for key, label, style in (
        # The amplitude often equals one of the peaks: drawn wide and light beneath them.
        ("amplitude", "max |θ − θ_eq| over the orbit", {"lw": 2.8, "alpha": 0.45}),
        ("exit_peak", "peak after shadow exit", {"lw": 0.9}),
        ("entry_peak", "peak after shadow entry", {"lw": 0.9, "ls": "--"}),
    ):
        values = above_noise(np.degrees(np.asarray(columns[key], dtype=float)))
        top.semilogy(days, values, label=label, **style)
    top.set_ylabel("angle [deg]")
    top.set_title(f"{title}: per-orbit summaries")
    top.grid(alpha=0.3, which="both")
    raw = np.degrees(np.asarray(columns["jitter_rms"], dtype=float))
    rms = above_noise(raw)
    hidden = int(np.sum(np.isfinite(raw) & ~np.isfinite(rms)))
    bottom.semilogy(days, rms, lw=0.8, color="C3", label="RMS jitter (θ − M_T/K_el)")
    bottom.set_ylabel("RMS jitter [deg]")
    bottom.set_title(
        "RMS over each orbit of θ − M_T/K_el (the oscillation about the static angle)",
        fontsize=9,
    )
    if hidden:
        bottom.text(
            0.01,
            0.04,
            f"{hidden} orbits without eclipse: RMS below {NOISE_FLOOR_DEG:g}° "
            "(solver resolution), not drawn",
            transform=bottom.transAxes,
            fontsize=8,
            color="0.3",
        )
    bottom.set_xlabel("time from the start [days]")
    bottom.grid(alpha=0.3, which="both")
    legend(fig)
    return save(fig, out / "orbits.png")


# --------------------------------------------------------------------------------------------
# thermojitter flutter


def stability_map_figure(m: Any, panel: Any, path: Path) -> Path:
    """Growth-rate colour map over two panel parameters with its zero contour (the flutter
    boundary) and the scenario's panel marked."""
    from matplotlib.colors import TwoSlopeNorm
    from matplotlib.lines import Line2D

    g = m.growth_rate
    lo, hi = float(np.nanmin(g)), float(np.nanmax(g))
    fig, (ax,) = figure(1, height=5.4, width=7.2)
    norm: Any = TwoSlopeNorm(vcenter=0.0, vmin=lo, vmax=hi) if lo < 0.0 < hi else None
    handles = []
    if m.x.size > 1 and m.y.size > 1:
        filled: Any = ax.contourf(m.x, m.y, g, levels=40, cmap="RdBu_r", norm=norm)
        if lo < 0.0 < hi:
            ax.contour(m.x, m.y, g, levels=[0.0], colors="k", linewidths=1.5)
            handles.append(Line2D([], [], color="k", lw=1.5, label="growth rate = 0 (boundary)"))
    else:
        filled = ax.scatter(
            np.repeat(m.x[None, :], m.y.size, 0), np.repeat(m.y[:, None], m.x.size, 1), c=g
        )
    bar = fig.colorbar(filled, ax=ax, label="growth rate [1/s]; > 0: flutter")
    bar.formatter.set_powerlimits((-3, 4))
    bar.formatter.set_useMathText(True)
    bar.update_ticks()
    (star,) = ax.plot(
        getattr(panel, m.x_name), getattr(panel, m.y_name), "k*", markersize=12, label="scenario"
    )
    ax.set_xlabel(f"{m.x_name} [{PANEL_UNITS.get(m.x_name, '-')}]")
    ax.set_ylabel(f"{m.y_name} [{PANEL_UNITS.get(m.y_name, '-')}]")
    ax.set_title(f"Thermal flutter of the sunlit equilibrium ({m.model} hinge, flux ×{m.flux:.3f})")
    tidy_ticks(ax)
    fig.legend(
        [*handles, star],
        [h.get_label() for h in [*handles, star]],
        loc="outside lower center",
        ncols=2,
        fontsize=8,
        frameon=False,
    )
    return save(fig, path)


def boom_stability_figure(sweep: Any, boom: Any) -> Any:
    """A boom's flutter over its solar inclination ψ at one response-time ratio B (a
    :class:`thermojitter.BoomStabilityMap` of one column): the growth rate at the boom's own
    damping (top axes), and the damping ratio that suppresses flutter (bottom), with the boom's
    own ψ marked. Returns the figure."""
    psi = np.degrees(np.asarray(sweep.inclination, dtype=float))
    fig, (top, bottom) = figure(2, height=5.6)
    top.plot(psi, sweep.growth_rate[:, 0], "o-", ms=3, lw=1.0, color="C3", label="growth rate")
    top.axhline(0.0, color="k", lw=0.8)
    top.set_ylabel("growth rate [1/s]; > 0: flutter")
    bottom.plot(
        psi, sweep.critical_damping[:, 0], "o-", ms=3, lw=1.0, color="C0",
        label="damping ratio that suppresses flutter",
    )  # fmt: skip
    bottom.set_ylabel(r"critical damping ratio $\zeta$ [-]")
    bottom.set_xlabel(r"solar inclination $\psi$, Sun to the axis from root to tip [deg]")
    for ax in (top, bottom):
        ax.axvline(
            np.degrees(boom.solar_inclination), color="0.4", ls="--", lw=0.9, label="scenario"
        )
        ax.grid(alpha=0.3)
        tidy_ticks(ax)
    ratio = float(np.asarray(sweep.ratio, dtype=float)[0])
    top.set_title(
        f"Thermal flutter of the boom over its solar inclination (B = $\\omega_1\\tau$ = "
        f"{ratio:.3g}, $\\zeta$ = {boom.damping:g})"
    )
    legend(fig)
    return fig


# --------------------------------------------------------------------------------------------
# thermojitter mc

HISTOGRAMS = (
    "theta_eq", "growth_rate", "critical_damping", "theta_abs_max", "entry_peak", "exit_peak",
    "jitter_rms", "jitter_peak", "t_threshold",
)  # fmt: skip
"""Metrics drawn as histograms by :func:`monte_carlo_figures`."""

SCATTER_METRICS = ("exit_peak", "jitter_rms", "growth_rate")
"""Metrics drawn against each varied parameter by :func:`monte_carlo_figures`."""

# Angles are shown in degrees (the tables keep radians), other metrics in SI.
ANGLE_METRICS = {
    "theta_eq",
    "theta_abs_max",
    "entry_peak",
    "exit_peak",
    "jitter_rms",
    "jitter_peak",
}
METRIC_UNITS = {"growth_rate": "1/s", "critical_damping": "N m s/rad", "t_threshold": "s"}


def shown(frame: Any, name: str) -> tuple[Array, str]:
    """A Monte Carlo metric or parameter column as plotted, with its axis label."""
    values = frame[name].to_numpy(float)
    if name in ANGLE_METRICS:
        return np.degrees(values), f"{name} [deg]"
    unit = METRIC_UNITS.get(name) or PANEL_UNITS.get(name)
    return values, f"{name} [{unit}]" if unit else name


def _counted(frame: Any) -> str:
    """The count in a Monte Carlo figure's title: '200 samples', or '200 samples, 3 failed (not
    shown)' (a failed sample has no metric to plot)."""
    failed = int(frame["error"].notna().sum())
    text = f"{len(frame)} samples"
    return f"{text}, {failed} failed (not shown)" if failed else text


def monte_carlo_figures(frame: Any, names: Sequence[str], out: Path) -> list[Path]:
    """``histograms.png`` (each metric over the samples) and ``scatter.png`` (metrics against
    the varied parameters, stable and fluttering samples apart)."""
    plt = pyplot()
    written = []
    metrics = [m for m in HISTOGRAMS if np.isfinite(frame[m].to_numpy(float)).any()]
    cols = 3
    rows = max(1, -(-len(metrics) // cols))
    fig, axes = plt.subplots(
        rows, cols, figsize=(4.2 * cols, 3.0 * rows), squeeze=False, layout="constrained"
    )
    for ax, m in zip(axes.flat, metrics, strict=False):
        values, label = shown(frame, m)
        ax.hist(values[np.isfinite(values)], bins=40, color="tab:blue")
        ax.set_xlabel(label)
        ax.set_ylabel("samples")
        tidy_ticks(ax)
        ax.tick_params(axis="x", labelsize=8)
    for ax in list(axes.flat)[len(metrics) :]:
        ax.set_visible(False)
    fig.suptitle(f"Monte Carlo: {_counted(frame)}")
    written.append(save(fig, out / "histograms.png"))

    fig, axes = plt.subplots(
        len(names),
        len(SCATTER_METRICS),
        figsize=(4.2 * len(SCATTER_METRICS), 3.0 * len(names) + 0.4),
        squeeze=False,
        layout="constrained",
    )
    # A failed sample's stable is missing (NA): it is neither stable nor flutter, and it has no
    # metric to plot. astype reads a frame saved before stable could be NA too.
    verdict = frame["stable"].astype("boolean")
    stable = verdict.fillna(False).to_numpy(bool)
    flutter = (~verdict).fillna(False).to_numpy(bool)
    for i, name in enumerate(names):
        for j, m in enumerate(SCATTER_METRICS):
            ax = axes[i, j]
            (x, xlabel), (y, ylabel) = shown(frame, name), shown(frame, m)
            ax.scatter(x[stable], y[stable], s=6, label="stable", color="tab:blue")
            ax.scatter(x[flutter], y[flutter], s=6, label="flutter", color="tab:red")
            ax.set_xlabel(xlabel)
            ax.set_ylabel(ylabel)
            tidy_ticks(ax)
            ax.tick_params(labelsize=8)
    fig.suptitle(f"Monte Carlo: metrics against the varied parameters ({_counted(frame)})")
    legend(fig)
    written.append(save(fig, out / "scatter.png"))
    return written


# --------------------------------------------------------------------------------------------
# hinge model against the finite-element beam (paper Figs. 22-24)

BEAM_NUMBERS = {
    "fig22": "Fig. 22",
    "fig22b": "Fig. 22b (not in the paper)",
    "fig23": "Fig. 23",
    "fig24": "Fig. 24",
}
"""The paper's number of each beam comparison figure (file names: thermojitter.beam.FIGURES)."""


def _k_label(case: Any) -> str:
    return f"K_el = {case.hinge_stiffness:.0f} N m/rad ({case.criterion_label})"


def beam_time_figure(case: Any, orbit: Any, number: str, path: Path) -> Path:
    """θ of the hinge model and θ_f of the beam through the eclipse, shadow shaded; below, the
    first minutes after shadow entry, where the ~8 s jitter of each can be told apart."""
    entry = orbit.shadow_intervals(float(case.t[0]), float(case.t[-1]))[0][0]
    fig, (whole, zoom) = figure(2, height=6.4, sharex=False)
    minutes = (case.t - entry) / 60.0
    near = (minutes >= -0.5) & (minutes <= 3.0)
    for ax, keep in ((whole, slice(None)), (zoom, near)):
        # The beam below, thicker and lighter; the hinge model on top, thin and dark.
        ax.plot(
            minutes[keep], case.theta_f_deg[keep], lw=1.8, color="C1", alpha=0.75,
            label="beam θ_f (finite elements)",
        )  # fmt: skip
        ax.plot(
            minutes[keep], case.theta_deg[keep], lw=0.7, color="C0", zorder=3,
            label="hinge model θ",
        )  # fmt: skip
        ax.set_ylabel("angle [deg]")
        ax.grid(alpha=0.3)
    shade_eclipses(whole, orbit, float(case.t[0]), float(case.t[-1]), scale=60.0, offset=entry)
    shade_eclipses(zoom, orbit, entry - 30.0, entry + 180.0, scale=60.0, offset=entry, labels=False)
    zoom.set_xlim(-0.5, 3.0)
    whole.set_xlabel("time from shadow entry [min]")
    zoom.set_xlabel("time from shadow entry [min] (zoom on the jitter)")
    whole.set_title(
        f"{number} — hinge model vs beam, {_k_label(case)}; RMSE {case.rmse_deg:.2f}°",
        fontsize=10,
    )
    legend(fig)
    return save(fig, path)


def beam_spectrum_figure(case: Any, number: str, path: Path) -> Path:
    """Spectra of θ and θ_f with the beam's first frequency f_n marked."""
    from thermojitter.signals import spectrum

    fig, (ax,) = figure(1, height=4.2)
    for values, label, style in (
        (case.theta_f_deg, "θ_f (beam)", {"lw": 1.6, "color": "C1", "alpha": 0.7}),
        (case.theta_deg, "θ (hinge model)", {"lw": 0.8, "color": "C0", "zorder": 3}),
    ):
        f, a = spectrum(case.t, values)
        keep = (f > 0.0) & (f <= 0.5)
        ax.semilogy(f[keep], a[keep], label=label, **style)
    ax.axvline(case.natural_frequency, color="k", ls="--", lw=0.8, label="beam f_n")
    ax.annotate(
        f"f_n = {case.natural_frequency:.3f} Hz",
        xy=(case.natural_frequency, 1.0),
        xycoords=("data", "axes fraction"),
        xytext=(4, -12),
        textcoords="offset points",
        fontsize=8,
    )
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("amplitude [deg]")
    ax.set_title(
        f"{number} — spectra of θ and θ_f, {_k_label(case)}\n"
        f"θ peaks at {case.hinge_frequency:.4f} Hz, {100 * case.frequency_mismatch:+.2f}% from f_n",
        fontsize=10,
    )
    ax.grid(alpha=0.3, which="both")
    legend(fig)
    return save(fig, path)


# --- the paper's figures (``thermojitter paper``) -------------------------------------------
# Each takes the records and returns the figure; paper.py computes, saves and reports.

_HOUR = 3600.0


def _finish(fig: Any, axes: Sequence[Any]) -> Any:
    legend(fig)
    for ax in axes:
        ax.grid(alpha=0.3)
    return fig


def one_node_figure(t: Array, T: Array, shadows: Sequence[tuple[float, float]]) -> Any:
    """Fig. 2: the isothermal plate over one orbit."""
    fig, (ax,) = figure(1, height=3.8)
    line(ax, t / _HOUR, T, lw=1.2, color="C3")
    shade_shadow(ax, shadows, scale=_HOUR)
    ax.set_xlabel("time from the subsolar point [h]")
    ax.set_ylabel("plate temperature $T$ [K]")
    ax.set_title("Fig. 2 — one-node (isothermal) plate temperature over one GEO orbit (Case B)")
    return _finish(fig, [ax])


def layer_temperatures_figure(
    t: Array, T_front: Array, T_back: Array, shadows: Sequence[tuple[float, float]], title: str
) -> Any:
    """Figs. 3–4: the two layers over one orbit."""
    fig, (ax,) = figure(1, height=3.8)
    line(ax, t / _HOUR, T_front, lw=1.2, label="front (Sun side) $T_f$")
    line(ax, t / _HOUR, T_back, lw=1.2, ls="--", label="back $T_b$")
    shade_shadow(ax, shadows, scale=_HOUR)
    ax.set_xlabel("time from the subsolar point [h]")
    ax.set_ylabel("layer temperature [K]")
    ax.set_title(title)
    return _finish(fig, [ax])


def delta_t_figure(
    t: Array, delta_T: Array, shadows: Sequence[tuple[float, float]], entry: float, title: str
) -> Any:
    """Figs. 5–6: ΔT = T_f − T_b around the eclipse, time from shadow entry."""
    fig, (ax,) = figure(1, height=3.8)
    ax.plot((t - entry) / 60.0, delta_T, lw=1.2, color="C2")
    ax.axhline(0.0, color="k", lw=0.6)
    shade_shadow(ax, shadows, scale=60.0, offset=entry)
    ax.set_xlabel("time from shadow entry [min]")
    ax.set_ylabel(r"$\Delta T = T_f - T_b$ [K]")
    ax.set_title(title)
    return _finish(fig, [ax])


def kinematics_figure(
    paths: Sequence[tuple[Array, Array]],
    panel_at: tuple[Array, Array],
    theta_eq: float,
    theta: Array,
    theta_dot: Array,
) -> Any:
    """Fig. 12: the paths (x, y) of points of the hinge model's halves (both halves drawn, y and
    −y), the panel at the sunlit angle ``theta_eq`` (rad); beside it the θ–θ̇ phase plane of the
    simulated orbit (rad, rad/s)."""
    fig, (ax1, ax2) = pyplot().subplots(1, 2, figsize=(10.0, 5.4), layout="constrained")
    for x, y in paths:
        for sign in (1.0, -1.0):
            ax1.plot(x, sign * y, lw=0.8, color="C0")
    for sign in (1.0, -1.0):
        ax1.plot(
            panel_at[0],
            sign * panel_at[1],
            lw=2.5,
            color="k",
            label=f"panel at θ = {np.degrees(theta_eq):.1f}° (sunlit)" if sign > 0 else None,
        )
    ax1.set_aspect("equal")
    ax1.set_xlabel("x, normal to the panel [m]")
    ax1.set_ylabel("y, along the panel [m]")
    ax1.set_title(
        "Fig. 12 — paths of points Q, −90° ≤ θ ≤ 90°,\nζ = 0 … 2l every 2.5 m", fontsize=10
    )
    ax2.plot(np.degrees(theta), np.degrees(theta_dot), lw=0.3, color="C1")
    ax2.plot([np.degrees(theta_eq)], [0.0], "ko", ms=4, label="sunlit equilibrium")
    ax2.set_xlabel(r"$\theta$ [deg]")
    ax2.set_ylabel(r"$\dot\theta$ [deg/s]")
    ax2.set_title(
        "(added) phase plane θ–θ̇, shadow entry to 1 h after exit\n(Table 1, non-linear, coupled)",
        fontsize=10,
    )
    return _finish(fig, [ax1, ax2])


def theta_orbit_figure(t: Array, theta_deg: Array, shadows: Sequence[tuple[float, float]]) -> Any:
    """Fig. 14: θ over one orbit."""
    fig, (ax,) = figure(1, height=3.8)
    line(ax, t / _HOUR, theta_deg, lw=0.7)
    shade_shadow(ax, shadows, scale=_HOUR)
    ax.axhline(0.0, color="k", lw=0.5)
    ax.set_xlabel("time from the subsolar point [h]")
    ax.set_ylabel(r"hinge angle $\theta$ [deg]")
    ax.set_title("Fig. 14 — thermal shock: hinge angle θ over one orbit (non-linear, coupled)")
    return _finish(fig, [ax])


def shadow_event_figure(
    t: Array,
    theta_deg: Array,
    moment: Array,
    shadows: Sequence[tuple[float, float]],
    t_event: float,
    name: str,
    number: int,
) -> Any:
    """Figs. 15–16: θ and the thermal moment (N m) from shadow ``name`` ("entry" or "exit")."""
    fig, (ax1, ax2) = figure(2, height=5.5)
    ax1.plot((t - t_event) / 60.0, theta_deg, lw=0.8)
    ax1.set_ylabel(r"$\theta$ [deg]")
    ax2.plot((t - t_event) / 60.0, moment, lw=1.0, color="C3")
    ax2.set_ylabel("thermal moment $M_T$ [N m]")
    for ax in (ax1, ax2):
        shade_shadow(ax, shadows, scale=60.0, offset=t_event)
        ax.axhline(0.0, color="k", lw=0.5)
    ax2.set_xlabel(f"time from shadow {name} [min]")
    where = "entering" if name == "entry" else "leaving"
    ax1.set_title(f"Fig. {number} — zoom: {where} the shadow, hinge angle and thermal moment")
    return _finish(fig, [ax1, ax2])


def flutter_figure(
    t: Array,
    theta_deg: Array,
    centres: Array,
    amplitudes: Array,
    fit: tuple[Array, Array, float] | None,
    shadows: Sequence[tuple[float, float]],
    entry: float,
    coupled: bool,
) -> Any:
    """Figs. 17–18: θ (deg) with c_d = 0, and its amplitude per 10 min on a log scale; ``fit``:
    (times s, fitted amplitudes deg, growth rate 1/s) of the exponential fit, or None."""
    fig, (ax1, ax2) = figure(2, height=6.0)
    line(ax1, (t - entry) / _HOUR, theta_deg, lw=0.5)
    ax1.set_ylabel(r"$\theta$ [deg]")
    ax2.semilogy(
        (centres - entry) / _HOUR,
        np.maximum(amplitudes, 1e-6),
        "o-",
        ms=2.5,
        lw=0.8,
        color="C1",
        label="half peak-to-peak of θ per 10 min (with the thermal drift)",
    )
    if fit is not None:
        times, fitted, rate = fit
        ax2.semilogy(
            (times - entry) / _HOUR,
            fitted,
            "k--",
            lw=1.0,
            label=f"fit: e-folding {1 / rate / 3600:.2f} h",
        )
    ax2.axhline(20.0, color="C3", lw=0.8, ls=":", label="20°: beyond modest angles")
    ax2.set_ylim(bottom=0.01)
    ax2.set_ylabel("oscillation amplitude [deg]")
    ax2.set_xlabel("time from the first shadow entry [h]")
    for ax in (ax1, ax2):
        shade_shadow(ax, shadows, scale=_HOUR, offset=entry)
    if coupled:
        title = "Fig. 17 — thermal flutter, c_d = 0, projected area ∝ cos θ: θ grows"
    else:
        title = "Fig. 18 — c_d = 0, projected area frozen (cos θ → 1): no growth"
    ax1.set_title(title, fontsize=10)
    return _finish(fig, [ax1, ax2])


def linearity_figure(
    t: Array,
    nonlinear_deg: Array,
    linear_deg: Array,
    shadows: Sequence[tuple[float, float]],
    t_event: float,
    name: str,
    number: int,
) -> Any:
    """Figs. 19–20: the non-linear and the linearised hinge from shadow ``name``, and their
    difference."""
    x = t - t_event
    fig, (ax1, ax2) = figure(2, height=5.5)
    ax1.plot(x, nonlinear_deg, lw=1.6, label="non-linear (eq. 20)")
    ax1.plot(x, linear_deg, lw=1.0, ls="--", color="C3", label="linearised (eq. 28)")
    ax1.set_ylabel(r"$\theta$ [deg]")
    ax2.plot(x, nonlinear_deg - linear_deg, lw=0.8, color="k")
    ax2.set_ylabel(r"$\theta_{nl} - \theta_{lin}$ [deg]")
    ax2.set_xlabel(f"time from shadow {name} [s]")
    for ax in (ax1, ax2):
        shade_shadow(ax, shadows, offset=t_event, label=None)
    where = "entering" if name == "entry" else "leaving"
    ax1.set_title(f"Fig. {number} — {where} the shadow: linearised vs non-linear hinge")
    return _finish(fig, [ax1, ax2])


def hinge_vs_distributed_figure(cases: Sequence[Any], path: Path) -> Path:
    """θ of the hinge model and θ_f of the distributed panel through the eclipse, one axis per
    hinge stiffness (``cases``: records with ``t``, ``theta``, ``theta_f`` in rad, s)."""
    fig, axes = figure(len(cases), height=6.0)
    start = float(cases[0].t[0])
    for ax, case in zip(axes, cases, strict=True):
        minutes = (case.t - start) / 60.0
        ax.plot(minutes, np.degrees(case.theta), lw=0.6, label="hinge model θ")
        ax.plot(minutes, np.degrees(case.theta_f), lw=0.6, label="distributed panel θ_f")
        ax.set_ylabel("angle [deg]")
        ax.set_title(
            f"K_el = {case.hinge_stiffness:.0f} N m/rad ({case.criterion}); "
            f"RMSE {case.rmse_deg:.3f}°",
            fontsize=9,
        )
        ax.grid(alpha=0.3)
    axes[-1].set_xlabel(f"time from t = {start:.0f} s [min]")
    legend(fig, ncols=2)
    return save(fig, path)
