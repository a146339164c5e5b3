"""Long runs: per-orbit summaries, the validity limit, checkpoint/resume, Ctrl-C."""

from __future__ import annotations

import json
import math
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import thermojitter as tj
from conftest import EXIT, GEO, PAPER

# A low orbit keeps these tests fast: ~1.6 h period, ~35 min eclipse.
LOW = tj.Orbit(radius=7.0e6, period=5828.5)


def test_summaries_agree_with_the_sampled_solution() -> None:
    runs = tj.simulate_orbits(PAPER, GEO, 1)
    sol = tj.simulate(PAPER, GEO, (0.0, GEO.period), dt_out=0.05)
    window = (sol.t >= EXIT) & (sol.t <= EXIT + 600.0)
    assert runs.exit_theta_max[0] == pytest.approx(sol.theta[window].max(), abs=1e-6)
    assert runs.theta_min[0] == pytest.approx(sol.theta.min(), abs=1e-6)
    assert runs.t_exit[0] == pytest.approx(EXIT)
    dynamic = sol.theta - sol.thermal_moment / PAPER.hinge_stiffness
    assert runs.jitter_rms[0] == pytest.approx(np.sqrt(np.mean(dynamic**2)), rel=1e-2)


@settings(max_examples=4, deadline=None)
@given(
    window=st.floats(60.0, 900.0),
    absorptivity=st.floats(0.6, 0.95),
    altitude=st.floats(300e3, 800e3),
    inclination=st.floats(0.0, 1.2),
    into_eclipse=st.floats(0.0, 1.0),
)
def test_every_orbit_is_read_to_its_edges(
    window: float, absorptivity: float, altitude: float, inclination: float, into_eclipse: float
) -> None:
    # θ still moves where a window ends: the full integration reads its extreme at the edge, not
    # at the last step's middle or end before it (up to half a step early: 1.2e-5 rad on
    # Table 1's low orbit at a 150 s window). Starting inside an eclipse, every orbit opens in
    # one carried over: its window starts with the orbit, θ at its start included (the orbit
    # after the first read it 2.5e-4 rad off on the heated 540 km orbit).
    panel = PAPER.replace(absorptivity=absorptivity)
    orbit = tj.Orbit.circular(altitude, inclination)
    first = tj.simulate_orbits(panel, orbit, 1, method="rk45", progress=False)
    t_start = first.t_entry[0] + into_eclipse * (first.t_exit[0] - first.t_entry[0])
    if not np.isfinite(t_start):
        t_start = into_eclipse * orbit.period  # no eclipse on this orbit
    kick = tj.steady_state(panel)
    y0 = (kick.T_front, kick.T_back, kick.theta, 0.0)
    n = 2
    runs = tj.simulate_orbits(
        panel, orbit, n, t_start=t_start, window=window, method="rk45", y0=y0, progress=False
    )
    t_end = t_start + n * orbit.period
    # Every 0.01 s, and every orbit's and window's edge exactly.
    starts, ends = runs.columns["t_start"], runs.columns["t_end"]
    edges = [starts, runs.t_entry, runs.t_entry + window, runs.t_exit, runs.t_exit + window]
    times = np.concatenate([np.arange(t_start, t_end, 0.01), [t_end], *edges])
    times = np.unique(times[np.isfinite(times) & (times <= t_end)])
    fine = tj.simulate(panel, orbit, (t_start, t_end), t_eval=times, y0=y0, rtol=1e-11, atol=1e-13)
    for k in range(n):
        t0, t1 = starts[k], ends[k]

        def over(a: float, b: float) -> np.ndarray:
            return np.asarray(fine.theta[(fine.t >= a - 1e-9) & (fine.t <= b + 1e-9)])

        want = {"theta_max": over(t0, t1).max(), "theta_min": over(t0, t1).min()}
        if np.isfinite(runs.t_entry[k]):
            want["entry_theta_min"] = over(runs.t_entry[k], min(runs.t_entry[k] + window, t1)).min()
        if np.isfinite(runs.t_exit[k]):
            want["exit_theta_max"] = over(runs.t_exit[k], min(runs.t_exit[k] + window, t1)).max()
        # Within the accuracy gate's 1e-6 rad (the integration's own error at an interior turn
        # reaches 3e-7; sampling every 0.01 s misses ~2e-8 there), where the reads that missed
        # an edge were 4e-6 to 2.5e-4 off.
        for name, value in want.items():
            assert getattr(runs, name)[k] == pytest.approx(value, abs=1e-6), (k, name)


def test_undamped_panel_is_stopped_at_the_validity_limit() -> None:
    limit = math.radians(15.0)
    with pytest.warns(tj.ValidityLimitWarning, match="stopped there"):
        runs = tj.simulate_orbits(PAPER.replace(damping=0.0), GEO, 5, theta_limit=limit)
    assert runs.limit_crossing is not None
    t, orbit, theta = runs.limit_crossing
    assert abs(theta) > limit and orbit == runs.index[-1]
    assert len(runs) < 5  # stopped, not integrated on to nonsense
    flagged = tj.simulate_orbits(
        PAPER.replace(damping=0.0), LOW, 3, theta_limit=limit, on_limit="flag"
    )
    assert len(flagged) == 3


def test_damping_above_and_below_critical() -> None:
    crit = tj.flutter(PAPER).critical_damping
    kick = tj.steady_state(PAPER)
    y0 = (kick.T_front, kick.T_back, kick.theta + 0.02, 0.0)
    above = tj.simulate_orbits(PAPER.replace(damping=1.3 * crit), LOW, 8, y0=y0)
    below = tj.simulate_orbits(PAPER.replace(damping=0.7 * crit), LOW, 8, y0=y0)
    # Compare the jitter left at the end of each orbit's sunlit arc: it decays or grows.
    assert above.jitter_peak[-1] < above.jitter_peak[1]
    assert below.jitter_peak[-1] > below.jitter_peak[1]


def _child_script(path: Path, n: int) -> str:
    return textwrap.dedent(f"""
        import json, sys, thermojitter as tj
        orbit = tj.Orbit(radius=7.0e6, period=5828.5)
        r = tj.simulate_orbits(tj.Panel.paper(), orbit, {n}, checkpoint={str(path)!r},
                               checkpoint_every=0.0, progress=False)
        print(json.dumps({{"interrupted": r.interrupted, "done": len(r)}}))
    """)


def _wait_for_progress(path: Path, proc: subprocess.Popen[str], at_least: int) -> None:
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline:
        if path.exists():
            try:
                if json.loads(path.read_text())["content"]["next_index"] >= at_least:
                    return
            except (json.JSONDecodeError, KeyError):
                pass  # caught mid-replace; try again
        if proc.poll() is not None:
            pytest.fail("child finished before it could be interrupted")
        time.sleep(0.02)
    pytest.fail("no checkpoint progress")


def test_killed_run_resumes_to_identical_summaries(tmp_path: Path) -> None:
    n = 30
    path = tmp_path / "run.ckpt"
    proc = subprocess.Popen(
        [sys.executable, "-c", _child_script(path, n)], text=True, stdout=subprocess.PIPE
    )
    _wait_for_progress(path, proc, 3)
    proc.kill()  # SIGKILL: no chance to clean up
    proc.wait()
    done_before = json.loads(path.read_text())["content"]["next_index"]
    assert 0 < done_before < n
    resumed = tj.simulate_orbits(PAPER, LOW, n, checkpoint=path, progress=False)
    straight = tj.simulate_orbits(PAPER, LOW, n, progress=False)
    assert len(resumed) == len(straight) == n
    for name, column in straight.columns.items():
        np.testing.assert_array_equal(resumed.columns[name], column, err_msg=name)
    np.testing.assert_array_equal(resumed.y_end, straight.y_end)


def test_ctrl_c_returns_the_finished_orbits(tmp_path: Path) -> None:
    path = tmp_path / "run.ckpt"
    proc = subprocess.Popen(
        [sys.executable, "-c", _child_script(path, 100_000)], text=True, stdout=subprocess.PIPE
    )
    _wait_for_progress(path, proc, 2)
    proc.send_signal(signal.SIGINT)
    out, _ = proc.communicate(timeout=60)
    result = json.loads(out.strip().splitlines()[-1])
    assert proc.returncode == 0
    assert result["interrupted"] is True and result["done"] >= 2
    assert json.loads(path.read_text())["content"]["next_index"] == result["done"]


def test_checkpoint_with_other_settings_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "run.ckpt"
    tj.simulate_orbits(PAPER, LOW, 2, checkpoint=path)
    with pytest.raises(ValueError, match="damping"):
        tj.simulate_orbits(PAPER.replace(damping=1.0), LOW, 2, checkpoint=path)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"n_orbits": 0}, "n_orbits"),
        ({"theta_limit": -1.0}, "theta_limit"),
        ({"window": math.nan}, "window"),
        ({"on_limit": "warn"}, "on_limit"),
        ({"orbits_per_call": 0}, "orbits_per_call"),
    ],
)
def test_bad_long_run_settings(kwargs: dict[str, object], name: str) -> None:
    args: dict[str, object] = {"n_orbits": 1, **kwargs}
    with pytest.raises(ValueError, match=name):
        tj.simulate_orbits(PAPER, LOW, **args)  # type: ignore[arg-type]


def test_weak_flutter_grows_at_the_predicted_rate() -> None:
    """Just below the critical damping the growth is slow (e-folding over a day or more); the
    long run must neither hide it in numerical dissipation nor invent it."""
    base = PAPER.replace(solar_constant=1361.0 * 1.034)  # perihelion flux
    crit = tj.flutter(base).critical_damping
    sunlit = tj.Orbit.sunlit()
    eq = tj.steady_state(base)
    y0 = (eq.T_front, eq.T_back, eq.theta + 1e-6, 0.0)  # a kick far below atol-relevant sizes
    for damping in (crit - 0.1, crit + 0.1):
        panel = base.replace(damping=damping)
        predicted = tj.flutter(panel).growth_rate
        runs = tj.simulate_orbits(panel, sunlit, 4, y0=y0)
        measured = math.log(runs.amplitude[3] / runs.amplitude[1]) / (2 * sunlit.period)
        assert measured == pytest.approx(predicted, rel=0.03), damping


def test_one_panel_is_stable_in_one_season_and_flutters_in_another() -> None:
    """c_d between the aphelion and perihelion critical dampings (about 2.03 and 2.31)."""
    panel = PAPER.replace(damping=2.20)
    for start, grows in (("2026-07-01", False), ("2026-11-20", True)):  # no eclipses in either
        orbit = tj.Orbit.geo_year(start)
        flux = float(orbit.flux_scale(0.0)[0])
        assert (tj.flutter(panel, flux=flux).growth_rate > 0) == grows
        eq = tj.steady_state(panel, flux=flux)
        runs = tj.simulate_orbits(panel, orbit, 12, y0=(eq.T_front, eq.T_back, eq.theta + 1e-4, 0))
        assert not np.isfinite(runs.t_entry).any()
        ratio = runs.jitter_peak[-1] / runs.jitter_peak[1]
        assert ratio > 5.0 if grows else ratio < 0.2, (start, ratio)
