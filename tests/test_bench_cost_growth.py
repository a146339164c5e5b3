"""A smoke run of ``benches/cost_growth.py --quick``: the bench runs end to end and reports what
each run did. Its timings are not checked (speed is measured in benches/, never asserted here)."""

from __future__ import annotations

import math
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
    # --quick: two sizes in each of the six orbit series, the two layer series and the full
    # distributed run (a distributed long run, once simulate_orbits has one, may add a series).
    known = list(QUICK_SIZES)
    for label in known:
        assert [size for size, _ in by_series.get(label, [])] == QUICK_SIZES[label], label
    # Low orbits run on the hybrid's slow time, with or without the Earth's loads: no fallback.
    assert all("fallback" not in note for _, note in by_series["LEO 28.5 deg + Earth hybrid"])
    assert all("fallback" not in note for _, note in by_series["LEO leo(540 km) hybrid"])
    assert "HybridFallbackWarning" not in done.stderr
    # A slope for every series, finite for those of two sizes.
    slopes = dict(
        re.findall(r"^\| (.+?) \| (-?[0-9.]+|nan) \| (?:-?[0-9.]+|nan) \| \S+ \|$", out, re.M)
    )
    assert set(slopes) == set(by_series)
    assert all(math.isfinite(float(slopes[label])) for label in known)


QUICK_SIZES = {
    **{f"GEO geo_year {m}": s for m, s in (("hybrid", [1, 3]), ("rk45", [1, 2]))},
    **{
        f"{orbit} {m}": [1, 3]
        for orbit in ("LEO leo(540 km)", "LEO 28.5 deg + Earth")
        for m in ("hybrid", "rk45")
    },
    "wing hybrid": [5, 6],
    "wing rk45": [5, 6],
    "simulate_distributed (full)": [5, 10],
}
"""The sizes of ``--quick`` (benches/cost_growth.py, PRESETS["quick"])."""
