"""Monte Carlo, sweeps and sensitivity: determinism across threads, chunks and backends,
kill-and-resume, refusal of bad inputs, and metrics checked against single runs."""

from __future__ import annotations

import json
import math
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest
from scipy import stats

import thermojitter as tj
from conftest import PAPER
from thermojitter import montecarlo
from thermojitter.montecarlo_cli import mc_command

# A low orbit and loose tolerances keep these tests fast: ~1.6 h period, ~35 min eclipse.
LOW = tj.Orbit(radius=7.0e6, period=5828.5)
FAST: dict[str, Any] = {"rtol": 1e-6, "atol": 1e-8, "progress": False}
VARY = {"damping": ("uniform", 1.0, 4.0), "emissivity_back": ("normal", 0.3, 0.03)}


def run(**kwargs: Any) -> pd.DataFrame:
    args: dict[str, Any] = {"vary": VARY, "n": 12, "seed": 7, **FAST, **kwargs}
    return tj.monte_carlo(PAPER, LOW, **args)


def test_same_frame_for_any_threads_and_chunking() -> None:
    one = run(threads=1)
    two = run(threads=2, chunk_size=5)
    single = run(threads=2, chunk_size=1)
    pd.testing.assert_frame_equal(one, two, check_exact=True)
    pd.testing.assert_frame_equal(one, single, check_exact=True)
    assert list(one.columns[:2]) == ["damping", "emissivity_back"]
    assert one["error"].isna().all()
    # Another seed draws other panels; the same seed the same ones.
    assert not np.array_equal(run(seed=8)["damping"], one["damping"])
    # With the random sampler a sample depends on (seed, index) only, not on n.
    pd.testing.assert_frame_equal(run(n=5), one.iloc[:5], check_exact=True)


def test_lockstep_lanes_give_the_frame_of_one_sample_at_a_time(
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    # The engine runs four samples per core at once in SIMD lanes; one at a time (the scalar
    # path) must give the same frame, bit for bit: sweeps and Monte Carlo, a sample stopped at
    # its threshold, a linear model, a frozen coupling and an invalid panel among them.
    def both(study: Any, **kwargs: Any) -> tuple[pd.DataFrame, pd.DataFrame]:
        frames = []
        for lockstep in (True, False):
            monkeypatch.setattr(montecarlo.backends, "_LOCKSTEP", lockstep)
            frames.append(study(PAPER, LOW, **FAST, threads=2, **kwargs))
        return frames[0], frames[1]

    lanes, scalar = both(
        tj.monte_carlo, vary=VARY, n=11, seed=3, threshold=0.15, stop_at_threshold=True
    )
    pd.testing.assert_frame_equal(lanes, scalar, check_exact=True)
    assert (lanes["t_reached"] < LOW.period).any() and (lanes["t_reached"] == LOW.period).any()
    grid = {"damping": [0.0, 1.5, 3.0], "conductance": [15.0, 25.0, 40.0]}
    for kwargs in ({}, {"model": "linear"}, {"coupled": False, "horizon": 2}):
        lanes, scalar = both(tj.sweep, grid=grid, **kwargs)
        pd.testing.assert_frame_equal(lanes, scalar, check_exact=True)
        assert lanes["error"].isna().all()


def test_same_frame_on_a_dask_cluster() -> None:
    distributed = pytest.importorskip("distributed")
    local = run(threads=2, chunk_size=3)
    cluster = distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=False, dashboard_address=None
    )
    try:
        with distributed.Client(cluster) as client:
            on_dask = run(backend=client, chunk_size=3)
            workers = client.scheduler_info()["workers"]
        by_address = run(backend=cluster.scheduler_address, chunk_size=4)
    finally:
        cluster.close()
    assert {w["nthreads"] for w in workers.values()} == {1}
    # The chunks ran on the workers, each on a rayon pool of the worker's one thread.
    used = [key for key in montecarlo.backends._WORKER_POOLS if key[0] in workers]
    assert used and all(montecarlo.backends._WORKER_POOLS[key].threads == 1 for key in used)
    pd.testing.assert_frame_equal(local, on_dask, check_exact=True)
    pd.testing.assert_frame_equal(local, by_address, check_exact=True)


def test_metrics_agree_with_a_sampled_single_run() -> None:
    frame = run(n=3, threshold=0.12, rtol=1e-8, atol=1e-10)
    row = frame.iloc[1]
    panel = PAPER.replace(damping=row["damping"], emissivity_back=row["emissivity_back"])
    sol = tj.simulate(panel, LOW, (0.0, LOW.period), dt_out=0.05)
    assert row["theta_abs_max"] == pytest.approx(np.abs(sol.theta).max(), abs=1e-6)
    dynamic = sol.theta - sol.thermal_moment / panel.hinge_stiffness
    assert row["jitter_rms"] == pytest.approx(np.sqrt(np.mean(dynamic**2)), rel=1e-2)
    above = sol.t[np.abs(sol.theta) > 0.12]
    assert above.size and row["t_threshold"] == pytest.approx(above[0], abs=0.05)
    entry, exit_ = LOW.shadow_intervals(0.0, LOW.period)[0]
    eq = tj.steady_state(panel).theta
    # The window opens at the exit itself, where θ is still at its lowest: sample it from there.
    window = tj.simulate(
        panel, LOW, (0.0, LOW.period), t_eval=np.linspace(exit_, exit_ + 600, 30001)
    )
    assert row["exit_peak"] == pytest.approx(np.abs(window.theta - eq).max(), abs=1e-6)
    assert row["theta_eq"] == pytest.approx(eq, rel=1e-9)
    assert row["t_reached"] == LOW.period


def test_stop_at_threshold_cuts_the_run_at_the_crossing() -> None:
    flagged = run(n=4, threshold=0.12)
    stopped = run(n=4, threshold=0.12, stop_at_threshold=True)
    crossed = flagged["t_threshold"].notna().to_numpy()
    assert crossed.any()
    np.testing.assert_array_equal(stopped["t_threshold"], flagged["t_threshold"])
    assert (stopped["t_reached"][crossed] < LOW.period).all()
    assert (stopped["t_reached"][~crossed] == LOW.period).all()
    assert (stopped["n_steps"][crossed] < flagged["n_steps"][crossed]).all()


def test_stability_agrees_with_the_critical_damping() -> None:
    # Two computations: the eigenvalues at the sampled damping, and the damping that zeroes them.
    frame = run(n=24, horizon=1, sampler="lhs")
    margin = frame["damping"] - frame["critical_damping"]
    assert (frame["stable"] == (margin > 0)).all()
    assert frame["stable"].any() and (~frame["stable"]).any()
    panel = PAPER.replace(
        damping=frame["damping"].iloc[0], emissivity_back=frame["emissivity_back"].iloc[0]
    )
    assert frame["growth_rate"].iloc[0] == pytest.approx(tj.flutter(panel).growth_rate, rel=1e-12)


def test_latin_hypercube_fills_every_stratum() -> None:
    n = 16
    frame = run(n=n, sampler="lhs", vary={"damping": ("uniform", 1.0, 5.0)}, horizon=1)
    strata = np.floor((frame["damping"].to_numpy() - 1.0) / 4.0 * n).astype(int)
    assert sorted(strata) == list(range(n))
    sobol = run(n=n, sampler="sobol", vary={"damping": ("uniform", 1.0, 5.0)})
    strata = np.floor((sobol["damping"].to_numpy() - 1.0) / 4.0 * n).astype(int)
    assert sorted(strata) == list(range(n))  # a scrambled Sobol' set of 2^k points does too


def test_truncation_draws_from_the_truncated_distribution() -> None:
    vary = {"emissivity_front": ("normal", 0.9, 0.1)}
    with pytest.raises(ValueError, match=r"emissivity_front.*truncate=True"):
        run(vary=vary, n=200)
    frame = run(vary=vary, n=200, truncate=True, rtol=1e-4, atol=1e-6)
    x = frame["emissivity_front"].to_numpy()
    assert x.max() <= 1.0 and x.min() > 0.0
    truth = stats.truncnorm(-9.0, 1.0, loc=0.9, scale=0.1)
    assert stats.kstest(x, truth.cdf).pvalue > 1e-3


def test_sweep_is_full_factorial_in_order() -> None:
    grid = {"damping": [1.0, 3.0], "conductance": [20.0, 25.0, 30.0]}
    frame = tj.sweep(PAPER, LOW, grid, **FAST)
    assert len(frame) == 6
    assert frame["damping"].tolist() == [1.0, 1.0, 1.0, 3.0, 3.0, 3.0]
    assert frame["conductance"].tolist() == [20.0, 25.0, 30.0] * 2
    for _, row in frame.iterrows():
        panel = PAPER.replace(damping=row["damping"], conductance=row["conductance"])
        assert row["theta_eq"] == pytest.approx(tj.steady_state(panel).theta, rel=1e-9)
    # Damping leaves the equilibrium alone; conductance changes it.
    eq = frame["theta_eq"].to_numpy().reshape(2, 3)
    np.testing.assert_allclose(eq[0], eq[1], rtol=1e-12)
    assert np.all(np.diff(eq[0]) < 0)
    with pytest.raises(ValueError, match="damping"):
        tj.sweep(PAPER, LOW, {"damping": [1.0, -1.0]}, **FAST)


# Samples that fail for real: the hybrid propagator's cost is not known up front (an rk45 design
# beyond its budget is refused before it starts), so each sample runs into max_steps by itself.
# Its steps are those of the shadow, where the step follows the hinge period: about 9,700 at
# K_el = 1000 N m/rad and 42,000 at 20,000, so a budget of 12,000 stops the stiff panels only.
# Damping 100 makes the soft panel stable (c_d* ~ 52), damping 3 lets it flutter.
BUDGET = 12_000
FAILING: dict[str, Any] = {"method": "hybrid", "max_steps": BUDGET, **FAST}
GRID = {"hinge_stiffness": [1000.0, 20000.0], "damping": [3.0, 100.0]}


def test_failed_samples_are_missing_not_flutter() -> None:
    free = tj.sweep(PAPER, LOW, GRID, method="hybrid", **FAST)  # the default budget: all finish
    expected_failed = (free["n_steps"] > BUDGET).to_numpy()
    assert free["error"].isna().all() and free["stable"].all() == False  # noqa: E712
    assert 0 < expected_failed.sum() < len(free)
    with pytest.warns(tj.SampleFailureWarning) as record:
        frame = tj.sweep(PAPER, LOW, GRID, **FAILING)
    assert len(record) == 1
    failed = frame["error"].notna().to_numpy()
    np.testing.assert_array_equal(failed, expected_failed)
    first = int(np.flatnonzero(failed)[0])
    message = str(record[0].message)
    assert message.startswith(f"{failed.sum()} of {len(frame)} samples failed")
    assert f"sample {first}: {frame['error'].iloc[first]}" in message
    assert frame["error"][failed].str.contains(f"max_steps = {BUDGET} reached").all()
    # Failed: stable and n_steps missing, numbers NaN; finished: the budget-free run's values.
    assert frame["stable"].dtype == "boolean" and frame["n_steps"].dtype == "Int64"
    assert frame["stable"][failed].isna().all() and frame["n_steps"][failed].isna().all()
    assert frame.loc[failed, ["theta_eq", "growth_rate", "exit_peak"]].isna().all().all()
    done = ~failed
    np.testing.assert_array_equal(frame["stable"][done], free["stable"][done])
    np.testing.assert_array_equal(frame["n_steps"][done], free["n_steps"][done])
    assert frame.attrs["n_failed"] == failed.sum()
    json.dumps(frame.attrs)  # attrs stay JSON, for Parquet
    # The README's flutter share counts the finished samples only: NA is skipped.
    assert (~frame["stable"]).mean() == pytest.approx((~free["stable"][done]).mean())
    assert (~frame["stable"]).mean() != pytest.approx((~frame["stable"].fillna(False)).mean())


def test_a_monte_carlo_study_counts_its_failures() -> None:
    vary = {"hinge_stiffness": ("loguniform", 500.0, 20000.0)}
    free = tj.monte_carlo(PAPER, LOW, vary=vary, n=8, seed=5, method="hybrid", **FAST)
    expected_failed = (free["n_steps"] > BUDGET).to_numpy()
    assert 0 < expected_failed.sum() < len(free)
    with pytest.warns(tj.SampleFailureWarning, match=f"{expected_failed.sum()} of 8 samples"):
        frame = tj.monte_carlo(PAPER, LOW, vary=vary, n=8, seed=5, **FAILING)
    np.testing.assert_array_equal(frame["stable"].isna().to_numpy(), expected_failed)
    assert frame.attrs["n_failed"] == expected_failed.sum()


def test_failed_samples_survive_the_checkpoint_and_dask(tmp_path: Path) -> None:
    with pytest.warns(tj.SampleFailureWarning):
        straight = tj.sweep(PAPER, LOW, GRID, **FAILING)
    with pytest.warns(tj.SampleFailureWarning):
        tj.sweep(PAPER, LOW, GRID, checkpoint=tmp_path, chunk_size=1, **FAILING)
    # The second call reads every chunk back from Parquet and runs nothing.
    with pytest.warns(tj.SampleFailureWarning):
        resumed = tj.sweep(PAPER, LOW, GRID, checkpoint=tmp_path, chunk_size=1, **FAILING)
    assert len(list(tmp_path.glob("chunk-*.parquet"))) == len(straight)
    pd.testing.assert_frame_equal(resumed, straight, check_exact=True)
    assert resumed.attrs["n_failed"] == straight.attrs["n_failed"] > 0
    distributed = pytest.importorskip("distributed")
    cluster = distributed.LocalCluster(
        n_workers=1, threads_per_worker=1, processes=False, dashboard_address=None
    )
    try:
        with distributed.Client(cluster) as client, pytest.warns(tj.SampleFailureWarning):
            on_dask = tj.sweep(PAPER, LOW, GRID, backend=client, chunk_size=2, **FAILING)
    finally:
        cluster.close()
    pd.testing.assert_frame_equal(on_dask, straight, check_exact=True)


def test_a_study_whose_every_sample_failed_raises() -> None:
    # A stiff hinge on a panel of little heat capacity: its thermal rates are not slow against
    # the hinge, so the hybrid's slow time gives the orbit back to the full integration, which
    # costs far more than the budget's steps.
    stiff = {"hinge_stiffness": [20000.0, 40000.0]}
    light = PAPER.replace(specific_heat=50.0)
    with pytest.raises(tj.AllSamplesFailedError) as caught:
        tj.sweep(light, LOW, stiff, **FAILING)
    exc = caught.value
    assert isinstance(exc, tj.IntegrationError)  # caught by code that catches a failed run
    assert exc.n == 2 and exc.first_sample == 0
    assert f"max_steps = {BUDGET} reached" in exc.first_error and exc.first_error in str(exc)
    assert exc.samples["stable"].isna().all() and exc.samples.attrs["n_failed"] == 2
    with pytest.raises(tj.AllSamplesFailedError, match="all 3 samples"):
        run(n=3, max_steps=10, method="hybrid")


def test_sensitivity_of_stability_refuses_failed_samples() -> None:
    pytest.importorskip("SALib")
    # Stiffness on both sides of the budget's limit (~1,500 N m/rad): some of the 16 fail. Their
    # stable must not enter the indices as flutter (0).
    vary = {"hinge_stiffness": ("loguniform", 500.0, 5000.0), "damping": ("uniform", 1, 4)}
    with (
        pytest.warns(tj.SampleFailureWarning),
        pytest.raises(ValueError, match=r"stable is not defined for \d+ of 16 samples.*max_steps"),
    ):
        tj.sensitivity(PAPER, LOW, vary, metric="stable", n=4, **FAILING)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"vary": {"colour": ("uniform", 0, 1)}}, "'colour' is not a panel parameter"),
        ({"vary": {"damping": ("uniform", 2.0, 1.0)}}, r"damping.*lo < hi"),
        ({"vary": {"damping": ("uniform", 1.0)}}, r"damping.*expected \('uniform', lo, hi\)"),
        ({"vary": {"conductance": ("normal", 25.0, 0.0)}}, r"conductance.*sd > 0"),
        ({"vary": {"conductance": ("normal", 25.0, math.nan)}}, r"conductance.*not finite"),
        ({"vary": {"conductance": ("gamma", 2.0, 1.0)}}, "unknown distribution 'gamma'"),
        ({"vary": {"conductance": stats.norm(25.0, -1.0)}}, r"conductance.*not a proper"),
        ({"vary": {"conductance": 25.0}}, r"conductance.*frozen scipy.stats"),
        ({"vary": {}}, "non-empty"),
        ({"vary": {"damping": ("normal", 0.5, 2.0)}, "n": 50}, r"damping: \d+ of 50 samples"),
        ({"vary": {"absorptivity": ("uniform", 0.9, 1.2)}}, r"absorptivity.*must be in \(0, 1\]"),
        ({"n": 0}, "n = 0"),
        ({"horizon": 0}, "horizon"),
        ({"threads": 0}, "threads"),
        ({"seed": -1}, "seed"),
        ({"sampler": "halton"}, "sampler"),
        ({"threshold": -0.1}, "threshold"),
        ({"chunk_size": 0}, "chunk_size"),
        ({"backend": 42}, "backend"),
        ({"rtol": -1.0}, "rtol"),
    ],
)
def test_bad_inputs_are_refused_by_name(kwargs: dict[str, Any], match: str) -> None:
    with pytest.raises(ValueError, match=match):
        run(**kwargs)


def test_a_horizon_that_is_not_a_whole_number_is_a_type_error() -> None:
    # Types are checked, not coerced: 1.5 orbits is not rounded.
    with pytest.raises(TypeError, match="horizon must be an integer"):
        run(horizon=1.5)


def test_truncation_needs_probability_in_the_valid_range() -> None:
    with pytest.raises(ValueError, match=r"emissivity_back.*no probability"):
        run(vary={"emissivity_back": ("uniform", 1.5, 2.0)}, truncate=True)


def _child(path: Path) -> str:
    return textwrap.dedent(f"""
        import thermojitter as tj
        low = tj.Orbit(radius=7.0e6, period=5828.5)
        vary = {{"damping": ("uniform", 1.0, 4.0), "emissivity_back": ("normal", 0.3, 0.03)}}
        tj.monte_carlo(tj.Panel.paper(), low, vary=vary, n=60, seed=3, horizon=3, threads=1,
                       chunk_size=2, checkpoint={str(path)!r}, progress=False)
    """)


def test_killed_run_resumes_to_the_same_frame(tmp_path: Path) -> None:
    path = tmp_path / "ckpt"
    proc = subprocess.Popen([sys.executable, "-c", _child(path)])
    deadline = time.monotonic() + 120
    while len(list(path.glob("chunk-*.parquet"))) < 3:
        if proc.poll() is not None:
            pytest.fail("child finished before it could be killed")
        if time.monotonic() > deadline:
            pytest.fail("no chunk written")
        time.sleep(0.01)
    proc.send_signal(signal.SIGKILL)  # no chance to clean up
    proc.wait()
    written = {p: p.stat().st_mtime_ns for p in path.glob("chunk-*.parquet")}
    assert 3 <= len(written) < 30
    vary = {"damping": ("uniform", 1.0, 4.0), "emissivity_back": ("normal", 0.3, 0.03)}
    common: dict[str, Any] = {"vary": vary, "n": 60, "seed": 3, "horizon": 3, "progress": False}
    resumed = tj.monte_carlo(PAPER, LOW, checkpoint=path, threads=2, **common)
    assert len(list(path.glob("chunk-*.parquet"))) == 30
    for p, mtime in written.items():
        assert p.stat().st_mtime_ns == mtime, f"{p.name} was computed again"
    straight = tj.monte_carlo(PAPER, LOW, threads=2, chunk_size=7, **common)
    pd.testing.assert_frame_equal(resumed, straight, check_exact=True)
    # A run with other settings is refused, naming what differs.
    with pytest.raises(ValueError, match=r"differs in: .*seed"):
        tj.monte_carlo(PAPER, LOW, checkpoint=path, **{**common, "seed": 4})
    with pytest.raises(ValueError, match=r"differs in: .*vary\.damping"):
        tj.monte_carlo(
            PAPER,
            LOW,
            checkpoint=path,
            **{**common, "vary": {**vary, "damping": ("uniform", 1, 5)}},
        )
    with pytest.raises(ValueError, match="seed is required"):
        tj.monte_carlo(PAPER, LOW, checkpoint=path, **{**common, "seed": None})


def test_ctrl_c_stops_the_run_and_keeps_the_finished_chunks(tmp_path: Path) -> None:
    path = tmp_path / "ckpt"
    script = _child(path).replace("tj.monte_carlo(", "df = tj.monte_carlo(", 1)
    script = script.replace(
        "\n                       chunk_size", "\n                            chunk_size"
    )
    script += "print('interrupted' if df.attrs['interrupted'] else 'finished', len(df))\n"
    proc = subprocess.Popen([sys.executable, "-c", script], stdout=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while len(list(path.glob("chunk-*.parquet"))) < 2:
        if proc.poll() is not None or time.monotonic() > deadline:
            pytest.fail("child finished before it could be interrupted")
        time.sleep(0.01)
    proc.send_signal(signal.SIGINT)
    out, _ = proc.communicate(timeout=60)
    word, kept = out.split()
    assert proc.returncode == 0 and word == "interrupted"
    finished = sorted(path.glob("chunk-*.parquet"))
    assert 2 <= len(finished) < 30
    assert int(kept) == 2 * len(finished)  # the frame returned holds the finished chunks
    assert not list(path.glob("*.tmp"))
    for chunk in finished:  # each one whole
        assert pd.read_parquet(chunk)["sample"].size == 2


def test_sobol_indices_find_the_parameter_that_matters() -> None:
    pytest.importorskip("SALib")
    vary = {"emissivity_back": ("uniform", 0.2, 0.4), "damping": ("uniform", 1.0, 4.0)}
    res = tj.sensitivity(PAPER, LOW, vary, metric="theta_eq", n=32, **FAST)
    s = res.indices
    # The sunlit equilibrium does not depend on damping at all: its indices vanish exactly.
    assert s.loc["damping", "ST"] == 0.0 and s.loc["damping", "S1"] == 0.0
    assert s.loc["emissivity_back", "ST"] == pytest.approx(1.0, abs=0.05)
    assert len(res.samples) == 32 * 4
    with pytest.raises(ValueError, match="metric"):
        tj.sensitivity(PAPER, LOW, vary, metric="error", n=4, **FAST)


def test_mc_command_writes_samples_and_plots(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    scenario = tmp_path / "s.toml"
    scenario.write_text(
        textwrap.dedent("""
            [panel]
            conductance = 24.0
            [orbit]
            radius = 7.0e6
            period = 5828.5
            [vary]
            damping = ["uniform", 1.0, 4.0]
            [montecarlo]
            rtol = 1e-6
            atol = 1e-8
        """)
    )
    out = tmp_path / "out"
    argv = [str(scenario), "--n", "6", "--out", str(out), "--no-progress", "--seed", "2"]
    assert mc_command(argv) == 0
    frame = pd.read_parquet(out / "samples.parquet")
    assert len(frame) == 6 and frame["damping"].between(1.0, 4.0).all()
    assert (out / "histograms.png").stat().st_size > 0 and (out / "scatter.png").exists()
    expected = tj.monte_carlo(
        PAPER.replace(conductance=24.0),
        LOW,
        vary={"damping": ("uniform", 1.0, 4.0)},
        n=6,
        seed=2,
        **FAST,
    )
    np.testing.assert_array_equal(frame["exit_peak"], expected["exit_peak"])
    scenario.write_text("[vary]\ncolour = ['uniform', 0, 1]\n")
    # Bad input: one line naming the key, exit code 2 (the command's one error path).
    code = mc_command([str(scenario), "--n", "2", "--out", str(out / "x"), "--no-progress"])
    err = capsys.readouterr().err
    assert code == 2 and "colour" in err and err.count("\n") == 1


def test_amplitude_slope_is_nan_on_one_orbit_and_the_summary_says_so(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    one = run(n=2)
    assert one["amplitude_slope"].isna().all()  # one orbit: no slope, by definition
    two = run(n=2, horizon=2)
    assert np.isfinite(two["amplitude_slope"]).all()
    # Its documentation says so, where the metrics are described.
    described = " ".join(Path(montecarlo.metrics.__file__).read_text().split())
    assert "NaN on the default one-orbit horizon" in described
    scenario = tmp_path / "s.toml"
    scenario.write_text(
        "[orbit]\nradius = 7.0e6\nperiod = 5828.5\n[vary]\n"
        'damping = ["uniform", 1.0, 4.0]\n[montecarlo]\nrtol = 1e-6\natol = 1e-8\n'
    )
    base = [str(scenario), "--n", "2", "--no-progress", "--no-plots", "--seed", "2"]
    assert mc_command([*base, "--out", str(tmp_path / "one")]) == 0
    assert "note: amplitude_slope is NaN for every sample" in capsys.readouterr().out
    assert mc_command([*base, "--out", str(tmp_path / "two"), "--horizon", "2"]) == 0
    assert "note: amplitude_slope" not in capsys.readouterr().out
