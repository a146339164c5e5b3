"""Laminate layups in scenario files: [laminate] with [[laminate.layers]], and layers = N."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

import thermojitter as tj
from thermojitter import materials as mat
from thermojitter.scenario import ScenarioError, load_scenario

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "examples"))

GOOD = """
[panel]
length = 20.0
damping = 0.5

[laminate]
emissivity_front = 0.8
emissivity_back = 0.7
absorptivity = 0.9

[[laminate.layers]]
material = "kapton"
thickness = 50e-6

[[laminate.layers]]
material = "cfrp_m55j_qi"
thickness = 0.3e-3

[[laminate.layers]]
name = "core"
thickness = 20e-3
conductivity = 2.5
density = 50.0
specific_heat = 900.0
youngs_modulus = 0.0
expansion_coeff = 2.4e-5

[[laminate.layers]]
material = "cfrp_m55j_qi"
thickness = 0.3e-3
conductivity = 1.0          # overrides the library's

[simulation]
orbits = 1
layers = 12
"""


def write(tmp_path: Path, text: str, name: str = "wing.toml") -> Path:
    path = tmp_path / name
    path.write_text(text)
    return path


def test_a_layup_in_a_scenario_is_the_laminate_panel(tmp_path: Path) -> None:
    s = load_scenario(write(tmp_path, GOOD))
    core = tj.Layer(20e-3, 2.5, 50.0, 900.0, 0.0, 2.4e-5, name="core")
    back = mat.CFRP_M55J_QI.layer(0.3e-3)
    want = tj.Laminate(
        [
            mat.KAPTON.layer(50e-6),
            mat.CFRP_M55J_QI.layer(0.3e-3),
            core,
            tj.Layer(**{**back.as_dict(), "conductivity": 1.0}),
        ],
        emissivity_front=0.8,
        emissivity_back=0.7,
        absorptivity=0.9,
    )
    assert s.panel.layup == want
    assert s.panel == tj.Panel.from_laminate(want, length=20.0, damping=0.5)
    assert s.simulation.layers == 12


def test_the_example_wing_scenario_is_the_example_wing() -> None:
    from laminates import wing

    s = load_scenario(REPO / "examples" / "laminate_wing.toml")
    assert s.panel.layup == wing().layup
    assert s.panel.hinge_stiffness == wing().hinge_stiffness
    assert s.panel.damping == pytest.approx(wing().damping, rel=1e-3)
    assert s.simulation.layers == 20


def test_run_writes_a_column_per_node(tmp_path: Path) -> None:
    pd = pytest.importorskip("pandas")
    from thermojitter.cli import main

    text = GOOD.replace("orbits = 1", "t_end = 600.0\ndt_out = 60.0")
    path = write(tmp_path, text)
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--no-plots"]) == 0
    frame = pd.read_csv(next((tmp_path / "out").glob("*.csv")))
    nodes = [c for c in frame.columns if c.startswith("T_node")]
    assert len(nodes) == 12
    # Each node's temperature in K, named as Solution.node_columns names it.
    assert all(n.endswith(" [K]") for n in nodes)
    nodes = [n.removesuffix(" [K]") for n in nodes]
    frame = frame.rename(columns=lambda c: c.removesuffix(" [K]"))
    assert nodes[0] == "T_node00 (front, kapton)" and nodes[-1] == "T_node11 (back, cfrp_m55j_qi)"
    assert sum(n.endswith(" (cfrp_m55j_qi|core)") for n in nodes) == 1
    assert np.array_equal(frame[nodes[0]], frame["T_front"])


@pytest.mark.parametrize(
    ("change", "key", "reason"),
    [
        (("thickness = 20e-3", "thickness = -20e-3"), "laminate.layers[2] ('core').thickness",
         "is invalid: must be finite and > 0"),
        (("density = 50.0", "density = \"light\""), "laminate.layers[2] ('core').density",
         "must be a number"),
        (("conductivity = 2.5\n", ""), "laminate.layers[2] ('core').conductivity",
         "is required"),
        (('material = "kapton"', 'material = "unobtainium"'),
         "laminate.layers[0] ('unobtainium').material", "must be one of 'aluminium_6061'"),
        (('material = "kapton"', 'material = "kapton"\ncolour = "gold"'),
         "laminate.layers[0] ('kapton').colour", "unknown key"),
        (("emissivity_back = 0.7", "emissivity_back = 1.7"), "laminate.emissivity_back",
         "is invalid: must be in (0, 1]"),
        (("absorptivity = 0.9\n", ""), "laminate.absorptivity", "is required"),
        (("length = 20.0", "length = 20.0\nconductance = 5.0"), "panel.conductance",
         "follows from [laminate]"),
        (("layers = 12", "layers = 4"), None, None),  # fewer nodes than the layup needs: at run
        (("layers = 12", "layers = 1"), "simulation.layers", "must be an integer >= 2"),
    ],
)  # fmt: skip
def test_bad_layups_name_file_key_and_layer(
    tmp_path: Path, change: tuple[str, str], key: str | None, reason: str | None
) -> None:
    text = GOOD.replace(*change, 1)
    assert text != GOOD
    path = write(tmp_path, text)
    if key is None:
        s = load_scenario(path)
        with pytest.raises(ValueError, match="layers = 4 is invalid: must be between 5"):
            tj.simulate(s.panel, s.orbit, (0.0, 60.0), layers=s.simulation.layers)
        return
    with pytest.raises(ScenarioError) as err:
        load_scenario(path)
    assert err.value.key == key, str(err.value)
    assert reason in str(err.value)
    assert str(err.value).startswith(f"{path}: {key}")


def test_a_laminate_needs_layers(tmp_path: Path) -> None:
    text = "[laminate]\nemissivity_front = 0.8\nemissivity_back = 0.8\nabsorptivity = 0.9\n"
    with pytest.raises(ScenarioError, match="laminate.layers: at least one"):
        load_scenario(write(tmp_path, text))
    text += '[[laminate.layers]]\nmaterial = "aluminium_honeycomb"\nthickness = 0.02\n'
    with pytest.raises(ScenarioError, match="laminate.layers .*carry bending stress"):
        load_scenario(write(tmp_path, text))


def test_mc_scenario_takes_layers(tmp_path: Path) -> None:
    from thermojitter.cli.mc import read_scenario

    text = GOOD + '\n[vary]\ndamping = ["uniform", 0.1, 1.0]\n[montecarlo]\nn = 2\nlayers = 6\n'
    assert read_scenario(write(tmp_path, text))["settings"]["layers"] == 6
    with pytest.raises(ScenarioError, match="montecarlo.layers: must be an integer >= 2"):
        read_scenario(write(tmp_path, text.replace("layers = 6", "layers = 1.5")))
