"""The figure style: legends clear of the data, round-off not drawn as signal, the shadow
shaded with a legend entry, readable tick labels."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import thermojitter as tj

pytest.importorskip("matplotlib")
from thermojitter import plots  # noqa: E402


def _legend_clear_of_axes(fig: object) -> None:
    fig.canvas.draw()  # type: ignore[attr-defined]
    renderer = fig.canvas.get_renderer()  # type: ignore[attr-defined]
    (leg,) = fig.legends  # type: ignore[attr-defined]
    box = leg.get_window_extent(renderer)
    for ax in fig.axes:  # type: ignore[attr-defined]
        assert not box.overlaps(ax.get_window_extent(renderer)), "legend over the data"


def test_legend_below_the_axes_with_each_label_once() -> None:
    fig, (a, b) = plots.figure(2)
    orbit = tj.Orbit.geo_equinox()
    t = np.linspace(0.0, orbit.period, 500)
    for ax in (a, b):
        ax.plot(t / 3600.0, np.sin(t / 3000.0), label="signal")
        plots.shade_eclipses(ax, orbit, 0.0, orbit.period, scale=3600.0)
    leg = plots.legend(fig)
    assert [x.get_text() for x in leg.get_texts()] == ["signal", "Earth shadow"]
    _legend_clear_of_axes(fig)
    plots.pyplot().close(fig)


def test_penumbra_has_its_own_legend_entry() -> None:
    fig, (ax,) = plots.figure(1)
    year = tj.Orbit.geo_year("2026-03-20")
    plots.shade_eclipses(ax, year, 0.0, year.period)
    labels = ax.get_legend_handles_labels()[1]
    assert labels == ["penumbra", "umbra"]
    plots.pyplot().close(fig)


def test_round_off_is_not_drawn(tmp_path: Path) -> None:
    n = 6
    rms = np.array([1e-14, 3e-15, 2e-5, 3e-5, 1e-16, 4e-5])  # rad: three orbits of round-off
    columns = {
        "t_start": np.arange(n) * 86164.0,
        "amplitude": np.full(n, 1e-3),
        "exit_peak": np.full(n, 1e-3),
        "entry_peak": np.full(n, 1e-3),
        "jitter_rms": rms,
    }
    plt = plots.pyplot()
    drawn: list[np.ndarray] = []
    real_save = plots.save

    def keep_lines(fig: object, path: Path) -> Path:
        drawn.extend(np.asarray(line.get_ydata()) for line in fig.axes[1].get_lines())  # type: ignore[attr-defined]
        return real_save(fig, path)

    plots.save = keep_lines  # type: ignore[assignment]
    try:
        plots.orbit_summary_figure(tmp_path, columns, "test")
    finally:
        plots.save = real_save  # type: ignore[assignment]
    (ys,) = drawn
    np.testing.assert_array_equal(np.isnan(ys), np.degrees(rms) < plots.NOISE_FLOOR_DEG)
    assert (tmp_path / "orbits.png").exists()
    plt.close("all")


def test_small_numbers_get_a_common_factor() -> None:
    fig, (ax,) = plots.figure(1)
    ax.plot([-1e-4, 1e-4], [0.0, 1.0])
    plots.tidy_ticks(ax)
    fig.canvas.draw()
    labels = [t.get_text() for t in ax.get_xticklabels()]
    assert not any("0.000" in s for s in labels), labels
    assert ax.xaxis.get_offset_text().get_text()  # the ×10⁻⁴ at the axis end
    plots.pyplot().close(fig)
