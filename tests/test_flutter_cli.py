"""End-to-end checks of ``thermojitter flutter`` (the function the command calls)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

import thermojitter as tj
from conftest import PAPER
from thermojitter.cli.flutter import flutter_command


def test_default_run_prints_the_analysis_and_writes_map_and_json(tmp_path: Path, capsys):
    code = flutter_command(
        ["--out", str(tmp_path), "--x", "damping:0:4:9", "--y", "conductance:10:40:7"]
    )
    assert code == 0
    text = capsys.readouterr().out
    assert "critical damping" in text and "perihelion" in text
    png = tmp_path / "stability_map.png"
    assert png.stat().st_size > 10_000 and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    data = json.loads((tmp_path / "flutter.json").read_text())
    nl = tj.flutter(PAPER)
    assert data["models"]["nonlinear"]["critical_damping_N_m_s_per_rad"] == nl.critical_damping
    assert data["models"]["linear"]["growth_rate_per_s"] == tj.flutter(PAPER, "linear").growth_rate
    year = data["year"]
    assert year["perihelion_flux"] == pytest.approx(1.0343, abs=2e-4)
    assert year["aphelion_flux"] == pytest.approx(0.9674, abs=2e-4)
    cd = year["critical_damping"]["nonlinear"]
    assert cd["aphelion"] < nl.critical_damping < cd["perihelion"]
    grid = data["map"]
    assert (grid["x_name"], grid["y_name"]) == ("damping", "conductance")
    assert len(grid["growth_rate"]) == 7 and len(grid["growth_rate"][0]) == 9
    # the map's point at (c_d = 3, K = 25) is the scenario's own analysis
    assert grid["growth_rate"][3][6] == nl.growth_rate


def test_scenario_file_sets_panel_orbit_and_map(tmp_path: Path, capsys):
    scenario = tmp_path / "s.toml"
    scenario.write_text(
        '[panel]\ndamping = 1.0\n\n[orbit]\npreset = "geo_year"\nstart_date = "2026-01-04"\n\n'
        "[simulation]\norbits = 3\n\n"
        '[flutter]\nmodel = "linear"\nx = "length:40:60:3"\ny = "damping:0:3:4"\n'
    )
    out = tmp_path / "out"
    assert flutter_command([str(scenario), "--out", str(out), "--no-plot"]) == 0
    data = json.loads((out / "flutter.json").read_text())
    assert data["panel"]["damping"] == 1.0
    assert data["flux"] == pytest.approx(1 / (1 - 0.0167) ** 2, rel=1e-4)  # perihelion
    assert data["map"]["model"] == "linear" and data["map"]["x_name"] == "length"
    assert not (out / "stability_map.png").exists()
    assert data["models"]["nonlinear"]["stable"] is False  # c_d = 1 < critical
    capsys.readouterr()


@pytest.mark.parametrize(
    ("content", "args", "message"),
    [
        ("[panel]\nmass = 3.0\n", [], "panel.mass"),
        ("[panel]\nmass_per_length = -3.0\n", [], "mass_per_length"),
        ('[panel]\ndamping = "big"\n', [], "panel.damping"),
        ("[panel\n", [], "TOML"),
        ("", ["--x", "dampng:0:1:3"], "dampng"),
        ("", ["--y", "damping:0:1:3"], "different"),
        ('[orbit]\npreset = "moon"\n', [], "orbit.preset"),
        ("[flutter]\nspeed = 1\n", [], "flutter.speed"),
    ],
)
def test_bad_input_gives_one_line_and_exit_code_2(tmp_path: Path, capsys, content, args, message):
    scenario = tmp_path / "bad.toml"
    scenario.write_text(content)
    assert flutter_command([str(scenario), "--out", str(tmp_path), "--no-plot", *args]) == 2
    err = capsys.readouterr().err.strip()
    assert message in err and "\n" not in err


def test_missing_file(tmp_path: Path, capsys):
    assert flutter_command([str(tmp_path / "nope.toml"), "--out", str(tmp_path)]) == 2
    assert "no such file" in capsys.readouterr().err


def test_it_says_where_it_writes_and_checks_the_folder_first(
    tmp_path: Path, capsys, monkeypatch
) -> None:
    monkeypatch.chdir(tmp_path)
    small = ["--x", "damping:0:4:3", "--y", "conductance:10:40:3", "--no-plot"]
    assert flutter_command(small) == 0
    first = capsys.readouterr().out
    assert "writing to out/flutter/ (the default; --out DIR to choose)" in first
    assert (tmp_path / "out" / "flutter" / "flutter.json").is_file()
    # A second run refuses the non-empty folder before any analysis is printed.
    assert flutter_command(small) == 2
    second = capsys.readouterr()
    assert second.out == ""
    assert "out/flutter: the folder is not empty" in second.err
