"""A smoke run of ``benches/cost_growth.py --quick``: the bench runs end to end and reports what
each run did. Its timings are not checked (speed is measured in benches/, never asserted here)."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

BENCH = Path(__file__).resolve().parent.parent / "benches" / "cost_growth.py"


def test_quick_run_reports_every_series() -> None:
    done = subprocess.run(
        [sys.executable, str(BENCH), "--quick", "--no-figure"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 0, done.stderr
    out = done.stdout
    for title in ("## 1. Horizon", "## 2. Nodes through the thickness", "## 3. Elements"):
        assert title in out
    number = r"[0-9.]+"
    row = rf"^\| (.+?) \| (\d+) \| {number} \| {number} \| {number} \| (\d+) \| (\d+|-) \| (.*) \|$"
    by_series: dict[str, list[tuple[int, str]]] = {}
    for label, size, steps, _, note in re.findall(row, out, re.M):
        assert int(steps) > 0, (label, size)
        by_series.setdefault(label, []).append((int(size), note))
    # --quick: two sizes in every series, six orbit series, two layer series, one distributed.
    assert len(by_series) >= 9, sorted(by_series)
    assert all(len(v) == 2 for v in by_series.values()), by_series
    # With the Earth's loads the hybrid runs rk45, and the table says so (not a warning).
    inclined = [k for k in by_series if k.startswith("LEO 28.5 deg") and k.endswith("hybrid")]
    assert inclined and all("fallback" in note for _, note in by_series[inclined[0]])
    assert all("fallback" not in note for _, note in by_series["LEO leo(540 km) hybrid"])
    assert "HybridFallbackWarning" not in done.stderr
    # A slope per series, finite where there are two sizes.
    slope = r"-?[0-9.]+"
    slopes = re.findall(rf"^\| (.+?) \| {slope} \| {slope} \| {slope} \|$", out, re.M)
    assert set(slopes) == set(by_series)
