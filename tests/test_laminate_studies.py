"""Studies (``monte_carlo``, ``sweep``) with the N-node through-thickness model: a sample is the
single run of its panel, on plain and laminate panels alike."""

from __future__ import annotations

import math

import pytest

import thermojitter as tj
from conftest import wing_layup

LEO = tj.Orbit.leo()


def wing() -> tj.Panel:
    panel = tj.Panel.from_laminate(wing_layup(), length=20.0)
    return panel.replace(damping=0.01 * math.sqrt(panel.hinge_stiffness * panel.hinge_inertia))


def single_run(panel: tj.Panel, nodes: int) -> dict[str, float]:
    """The metrics of one sample, computed by the single-run functions."""
    run = tj.simulate_orbits(panel, LEO, 1, layers=nodes, progress=False, method="rk45")
    analysis = tj.flutter(panel, layers=nodes)
    return {
        "theta_eq": analysis.equilibrium.theta,
        "growth_rate": analysis.growth_rate,
        "critical_damping": analysis.critical_damping,
        "exit_peak": float(run.exit_peak[0]),
        "entry_peak": float(run.entry_peak[0]),
        "jitter_rms": float(run.jitter_rms[0]),
        "n_steps": run.n_steps,
    }


@pytest.mark.parametrize(
    ("panel", "nodes", "name", "spread"),
    [
        (tj.Panel(), 5, "damping", (1.0, 3.0)),
        (wing(), 12, "emissivity_back", (0.7, 0.9)),
    ],
    ids=["plain", "laminate"],
)
def test_a_sample_is_the_single_run_of_its_panel(
    panel: tj.Panel, nodes: int, name: str, spread: tuple[float, float]
) -> None:
    frame = tj.monte_carlo(
        panel, LEO, vary={name: ("uniform", *spread)}, n=2, seed=3, layers=nodes, progress=False
    )
    for k in range(2):
        row = frame.iloc[k]
        want = single_run(panel.replace(**{name: float(row[name])}), nodes)
        for metric, value in want.items():
            # The same computation on the same inputs: equal to the bit.
            assert row[metric] == value, (k, metric, row[metric], value)
        assert row["error"] is None


def test_sweep_points_are_single_runs_and_two_nodes_are_the_two_layer_model() -> None:
    panel = tj.Panel()
    grid = {"damping": [1.5, 2.5]}
    nodal = tj.sweep(panel, LEO, grid, layers=2, progress=False)
    plain = tj.sweep(panel, LEO, grid, progress=False)
    assert nodal.iloc[1]["exit_peak"] == single_run(panel.replace(damping=2.5), 2)["exit_peak"]
    # Two nodes on a plain panel are eq. 2: the runs agree to rounding, the flutter analyses
    # (eigenvalues of differently assembled Jacobians) to 1e-9.
    for metric in ("exit_peak", "entry_peak", "jitter_rms", "theta_abs_max"):
        a, b = nodal[metric].to_numpy(), plain[metric].to_numpy()
        assert max(abs(a / b - 1.0)) < 1e-10, metric
    for metric in ("theta_eq", "growth_rate", "critical_damping"):
        a, b = nodal[metric].to_numpy(), plain[metric].to_numpy()
        assert max(abs(a / b - 1.0)) < 1e-9, metric


def test_layup_fields_of_a_laminate_cannot_be_varied_with_layers() -> None:
    with pytest.raises(tj.ParameterError, match="conductance of a laminate panel") as err:
        tj.monte_carlo(
            wing(), LEO, vary={"conductance": ("uniform", 1.0, 2.0)}, n=2, seed=0, layers=8,
            progress=False,
        )  # fmt: skip
    assert err.value.parameter == "vary.conductance"
    with pytest.raises(ValueError, match="layers = 1 is invalid"):
        tj.sweep(tj.Panel(), LEO, {"damping": [1.0]}, layers=1, progress=False)
