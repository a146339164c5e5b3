"""What can differ between the source tree and an installed wheel: every module imports, the
packaged files are there, the console script runs, and each public module does one small piece of
real work through the engine. CI runs this file (and only this) against the release wheel in a
clean virtualenv; here it runs against whatever ``import thermojitter`` finds."""

from __future__ import annotations

import importlib
import pkgutil
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import thermojitter as tj

PACKAGE = Path(tj.__file__).parent
PAPER = tj.Panel.paper()
EXAMPLES = Path(__file__).resolve().parent.parent / "examples"


def test_every_module_imports() -> None:
    names = [m.name for m in pkgutil.walk_packages(tj.__path__, "thermojitter.")]
    assert {
        "thermojitter._core",
        "thermojitter.montecarlo.studies",
        "thermojitter.reports.paper",
    } <= set(names)
    names.remove("thermojitter.__main__")  # runs the command: the entry point test runs it
    for name in names:
        importlib.import_module(name)
    for name in tj.__all__:
        assert getattr(tj, name) is not None, name


def test_packaged_files() -> None:
    """The typed stub and marker beside the native module, which is the engine's build."""
    assert (PACKAGE / "py.typed").is_file()
    assert (PACKAGE / "_core.pyi").is_file()
    assert Path(tj._core.__file__).parent == PACKAGE
    # The release build chooses its kernels at run time among those it was built with.
    info = tj._core.cpu_info()
    assert info["scalar_kernel"] and info["ensemble_kernel"] and "kernel" in info["summary"]


def test_console_script_and_module_entry_point() -> None:
    script = shutil.which("thermojitter", path=str(Path(sys.executable).parent))
    assert script is not None, "the thermojitter console script is not installed"
    for command in ([script], [sys.executable, "-m", "thermojitter"]):
        done = subprocess.run([*command, "--version"], capture_output=True, text=True, timeout=60)
        assert done.returncode == 0, done.stderr
        assert tj.__version__ in done.stdout + done.stderr


def test_panel_orbit_and_a_run() -> None:
    eq = tj.steady_state(PAPER)
    assert 0.0 < eq.theta < 0.2 and eq.T_front > eq.T_back
    orbit = tj.Orbit.geo_equinox()
    (enter, leave), *_ = orbit.shadow_intervals(0.0, orbit.period)
    sol = tj.simulate(PAPER, orbit, (enter - 60.0, enter + 240.0))
    assert sol.n_steps > 0 and np.all(np.isfinite(sol.theta))
    assert abs(sol.theta[-1] - sol.theta[0]) > 1e-4  # the shadow moves the panel
    omega = np.sqrt(PAPER.hinge_stiffness / PAPER.hinge_inertia)
    assert tj.natural_frequency(PAPER) == pytest.approx(omega / (2 * np.pi), rel=1e-12)


def test_long_runs_flutter_and_the_beam() -> None:
    summaries = tj.simulate_orbits(PAPER, tj.Orbit.sunlit(), 1, progress=False)
    assert len(summaries.columns["amplitude"]) == 1
    assert tj.flutter(PAPER).stable
    assert tj.beam.FreeFreeBeam(PAPER, 8).natural_frequencies(1)[0] > 0.0
    assert set(tj.distributed_defaults(PAPER)) >= {"elements", "modes"}


def test_laminates_materials_and_scenarios() -> None:
    from thermojitter.scenario import load_scenario

    layup = tj.Laminate(
        [tj.materials.get("cfrp_m55j_qi").layer(1e-3)],
        emissivity_front=0.8,
        emissivity_back=0.8,
        absorptivity=0.9,
    )
    assert tj.Panel.from_laminate(layup).layup is layup
    if EXAMPLES.is_dir():
        assert load_scenario(EXAMPLES / "paper.toml").panel == PAPER


def test_a_small_study_and_a_figure(tmp_path: Path) -> None:
    frame = tj.sweep(PAPER, tj.Orbit.sunlit(), {"damping": [1.0, 2.0]}, progress=False)
    assert len(frame) == 2 and frame.attrs["n_failed"] == 0
    from thermojitter.reports.plots import figure, pyplot, save

    fig, (ax,) = figure(1)
    ax.plot([0.0, 1.0], [0.0, 1.0])
    assert save(fig, tmp_path / "f.png").stat().st_size > 0
    pyplot().close(fig)


def test_the_build_gives_the_recorded_bits() -> None:
    """What most differs between builds is the compiler's work on the engine (the release
    profile's optimisation, link-time inlining): one orbit of each recorded case, with the
    portable kernel, to the bit (the records of tests/test_recorded.py)."""
    from test_recorded import COLUMNS, RECORDED, run_cases

    got = run_cases("portable")
    assert got["kernel"] == "portable"
    for name, want in RECORDED.items():
        assert (got[name]["n_steps"], got[name]["n_rhs"]) == (want["n_steps"], want["n_rhs"])
        for column in COLUMNS:
            assert got[name][column] == want[column], (name, column)
