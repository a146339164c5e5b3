"""Results that persist: every result type saved and loaded back to the bit, with its inputs,
settings and the package's version; files of another kind refused by name."""

from __future__ import annotations

import dataclasses
import json
import math
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd
import pytest
import xarray as xr

import thermojitter as tj
from conftest import ENTRY, GEO, PAPER, wing_layup
from thermojitter.persist import from_xarray

LOW = tj.Orbit(radius=7.0e6, period=5828.5)


def _same_bits(a: np.ndarray, b: Any) -> bool:
    return (
        isinstance(b, np.ndarray)
        and a.dtype == b.dtype
        and a.shape == b.shape
        and a.tobytes() == b.tobytes()
    )


def _equal(a: Any, b: Any) -> bool:
    """Equal to the bit for arrays (NaN included), of the same type for everything else."""
    if isinstance(a, np.ndarray):
        return _same_bits(a, b)
    if type(a) is not type(b):
        return False
    if isinstance(a, float):
        return a == b or (math.isnan(a) and math.isnan(b))
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(_equal(a[k], b[k]) for k in a)
    if isinstance(a, (tuple, list)):
        return len(a) == len(b) and all(_equal(x, y) for x, y in zip(a, b, strict=True))
    return bool(a == b)


def _assert_round_trip(result: Any, path: Path) -> Any:
    assert result.save(path) == path
    loaded = tj.load(path)
    assert type(loaded) is type(result)
    for f in dataclasses.fields(result):
        mine, theirs = getattr(result, f.name), getattr(loaded, f.name)
        assert _equal(mine, theirs), f"{type(result).__name__}.{f.name} differs after loading"
    # The inputs compare as inputs (a laminate panel with its layup).
    for name in ("panel", "orbit"):
        if getattr(result, name, None) is not None:
            assert getattr(loaded, name) == getattr(result, name)
    if getattr(result, "panel", None) is not None:
        assert loaded.panel.layup == result.panel.layup
    # The file says what it is and which version wrote it, to any NetCDF reader.
    with xr.open_dataset(path, engine="h5netcdf") as ds:
        assert ds.attrs["thermojitter_kind"] == type(result).__name__
        assert ds.attrs["thermojitter_version"] == tj.__version__
    return loaded


def _results() -> dict[str, Any]:
    wing = tj.Panel.from_laminate(wing_layup(), length=20.0)
    return {
        "solution": lambda: tj.simulate(PAPER, GEO, (0.0, 60.0)),
        "layered solution": lambda: tj.simulate(
            wing, GEO, (0.0, 20.0), layers=6, on_limit="ignore"
        ),
        "thermal solution": lambda: tj.simulate_thermal(PAPER, GEO, (0.0, 30.0), layers=1),
        "hinge solution": lambda: tj.simulate_hinge(PAPER, 0.01, (0.0, 30.0)),
        "distributed solution": lambda: tj.simulate_distributed(PAPER, GEO, (0.0, 20.0)),
        "orbit summaries": lambda: tj.simulate_orbits(PAPER, LOW, 2, progress=False),
        "flutter": lambda: tj.flutter(PAPER, orbit=GEO, t=100.0),
        "layered flutter": lambda: tj.flutter(wing, layers=6),
        "stability map": lambda: tj.stability_map(
            PAPER, ("damping", [0.0, 1.0, 2.0]), ("conductance", [5.0, 30.0]), progress=False
        ),
        "linear thermal response": lambda: tj.linear_thermal_response(PAPER),
        "distributed flutter": lambda: tj.distributed_flutter(PAPER, elements=10, modes=3),
        "equilibrium": lambda: tj.steady_state(PAPER),
        "beam comparison": lambda: tj.compare_with_beam(
            PAPER, GEO, t_span=(ENTRY - 30.0, ENTRY + 60.0), n_elements=10
        ),
        "calibration": _calibration,
    }


def _calibration() -> Any:
    t = np.arange(ENTRY - 30.0, ENTRY + 120.0, 1.0)
    theta = tj.simulate(PAPER, GEO, (t[0], t[-1]), t_eval=t).theta
    start = PAPER.replace(hinge_stiffness=4000.0)
    return tj.calibrate(t, theta, panel=start, orbit=GEO, fit=("hinge_stiffness",))


@pytest.mark.parametrize("name", list(_results()))
def test_every_result_round_trips_to_the_bit(name: str, tmp_path: Path) -> None:
    result = _results()[name]()
    _assert_round_trip(result, tmp_path / "result.nc")


def test_a_run_keeps_its_inputs_and_a_loaded_run_carries_them(tmp_path: Path) -> None:
    orbit = GEO.replace(phase0=0.3)
    panel = PAPER.replace(damping=2.5)
    sol = tj.simulate(panel, orbit, (0.0, 10.0))
    assert sol.panel is panel and sol.orbit is orbit
    loaded = _assert_round_trip(sol, tmp_path / "run.nc")
    # The loaded inputs run again to the same bits.
    again = tj.simulate(loaded.panel, loaded.orbit, (0.0, 10.0))
    assert again.theta.tobytes() == sol.theta.tobytes()


def test_a_run_that_crossed_the_limit_keeps_the_crossing(tmp_path: Path) -> None:
    with pytest.warns(tj.ValidityLimitWarning):
        sol = tj.simulate(
            PAPER, GEO, (0.0, 30.0), y0=(300.0, 290.0, 0.0, 0.1), theta_limit=0.01, on_limit="stop"
        )
    assert sol.limit_crossing is not None and sol.stopped_at_limit
    loaded = _assert_round_trip(sol, tmp_path / "stopped.nc")
    assert isinstance(loaded.limit_crossing, tj.LimitCrossing)


def test_to_xarray_holds_what_the_file_holds() -> None:
    summaries = tj.simulate_orbits(PAPER, LOW, 2, progress=False)
    ds = summaries.to_xarray()  # was an AttributeError
    assert ds.sizes["orbit"] == 2
    np.testing.assert_array_equal(ds["amplitude"].values, summaries.amplitude)
    fields = json.loads(ds.attrs["thermojitter_fields"])
    assert fields["settings"]["__dict__"]["window"] == 600.0
    again = from_xarray(ds)
    assert _equal(again.columns, summaries.columns)


def test_a_study_frame_round_trips_through_parquet(tmp_path: Path) -> None:
    budget = 12_000  # some samples fail: their error strings, NA and NaN must come back
    grid = {"hinge_stiffness": [1000.0, 20000.0], "damping": [3.0, 100.0]}
    with pytest.warns(tj.SampleFailureWarning):
        frame = tj.sweep(PAPER, LOW, grid, method="hybrid", max_steps=budget, progress=False)
    assert frame["error"].notna().any() and frame["error"].isna().any()
    path = tj.save(frame, tmp_path / "study.parquet")
    loaded = tj.load(path)
    pd.testing.assert_frame_equal(loaded, frame, check_exact=True)
    assert loaded.attrs == frame.attrs
    assert loaded["error"].dtype == object
    assert [e is None for e in loaded["error"]] == [e is None for e in frame["error"]]
    # Plain pandas reads it too, attrs and all.
    assert pd.read_parquet(path).attrs == frame.attrs


def test_a_file_of_another_kind_is_refused_by_name(tmp_path: Path) -> None:
    path = tj.flutter(PAPER).save(tmp_path / "flutter.nc")
    with pytest.raises(tj.ResultFileError, match="holds a FlutterResult, not the Solution"):
        tj.Solution.load(path)
    with pytest.raises(tj.ResultFileError, match="holds a FlutterResult, not the Solution"):
        tj.load(path, kind=tj.Solution)
    assert isinstance(tj.FlutterResult.load(path), tj.FlutterResult)


def test_an_unknown_kind_a_later_format_and_a_foreign_file_are_refused(tmp_path: Path) -> None:
    ds = tj.steady_state(PAPER).to_xarray()
    unknown = ds.assign_attrs(thermojitter_kind="Spacecraft")
    unknown.to_netcdf(tmp_path / "unknown.nc", engine="h5netcdf")
    with pytest.raises(tj.ResultFileError, match="kind 'Spacecraft', which this version"):
        tj.load(tmp_path / "unknown.nc")
    later = ds.assign_attrs(thermojitter_format=99)
    later.to_netcdf(tmp_path / "later.nc", engine="h5netcdf")
    with pytest.raises(tj.ResultFileError, match="file format 99"):
        tj.load(tmp_path / "later.nc")
    damaged = ds.assign_attrs(thermojitter_fields='{"T_front": {"__type__": "Spacecraft"}}')
    damaged.to_netcdf(tmp_path / "damaged.nc", engine="h5netcdf")
    with pytest.raises(tj.ResultFileError, match="is damaged"):
        tj.load(tmp_path / "damaged.nc")
    xr.Dataset({"a": ("t", [1.0])}).to_netcdf(tmp_path / "foreign.nc", engine="h5netcdf")
    with pytest.raises(tj.ResultFileError, match="not a saved thermojitter result"):
        tj.load(tmp_path / "foreign.nc")
    (tmp_path / "notes.txt").write_text("hello")
    with pytest.raises(tj.ResultFileError, match="neither NetCDF-4 nor Parquet"):
        tj.load(tmp_path / "notes.txt")
    pd.DataFrame({"a": [1.0]}).to_parquet(tmp_path / "plain.parquet")
    with pytest.raises(tj.ResultFileError, match="not a saved thermojitter frame"):
        tj.load(tmp_path / "plain.parquet")
    with pytest.raises(tj.ResultFileError, match="does not exist"):
        tj.load(tmp_path / "missing.nc")
    with pytest.raises(tj.ParameterError, match="result"):
        tj.save({"a": 1}, tmp_path / "dict.nc")
    # A ResultFileError is a ParameterError naming the file.
    with pytest.raises(tj.ParameterError) as info:
        tj.load(tmp_path / "notes.txt")
    assert info.value.parameter == "path"
