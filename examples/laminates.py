"""Laminate panels: a CFRP/honeycomb solar-array wing and an aluminium boom, each run with the
two-layer model and with the N-node through-thickness model on the same panel.

    python examples/laminates.py [--nodes 20]

prints, for each panel, the sunlit equilibrium, the jitter over one GEO orbit (per-orbit
summaries) and the critical damping c_d* from the flutter analysis, two-layer vs N nodes.
"""

from __future__ import annotations

import argparse
import math

import thermojitter as tj
from thermojitter import materials as mat

DAMPING_RATIO = 0.005
"""Hinge damping of the examples, as a fraction of critical (2 sqrt(K_el I_B))."""


def with_damping(panel: tj.Panel) -> tj.Panel:
    return panel.replace(
        damping=DAMPING_RATIO * 2.0 * math.sqrt(panel.hinge_stiffness * panel.hinge_inertia)
    )


def wing() -> tj.Panel:
    """A 20 m solar-array wing: Kapton on the cell side, 0.3 mm CFRP M55J face sheets on a
    20 mm aluminium honeycomb core; cells on the front (α 0.9, ε 0.8), black back (ε 0.8)."""
    layup = tj.Laminate(
        [
            mat.KAPTON.layer(50e-6),
            mat.CFRP_M55J_QI.layer(0.3e-3),
            mat.ALUMINIUM_HONEYCOMB.layer(20e-3),
            mat.CFRP_M55J_QI.layer(0.3e-3),
        ],
        emissivity_front=0.8,
        emissivity_back=0.8,
        absorptivity=0.9,
    )
    return with_damping(tj.Panel.from_laminate(layup, length=20.0))


def boom() -> tj.Panel:
    """A 2 m strip of 1 mm aluminium 6061, painted (α 0.4, ε 0.8 on both sides)."""
    layup = tj.Laminate(
        [mat.ALUMINIUM_6061.layer(1e-3)],
        emissivity_front=0.8,
        emissivity_back=0.8,
        absorptivity=0.4,
    )
    return with_damping(tj.Panel.from_laminate(layup, length=2.0))


def compare(name: str, panel: tj.Panel, nodes: int) -> None:
    orbit = tj.Orbit.geo_equinox()
    print(
        f"## {name}: {len(panel.layup.layers) if panel.layup else 1} layer(s), "
        f"f_n = {tj.natural_frequency(panel):.3f} Hz, c_d = {panel.damping:.3g} N m s/rad"
    )
    print()
    print(
        "| model | T_front K | T_back K | θ_eq rad | exit peak rad | jitter peak rad "
        "| jitter RMS rad | c_d* N m s/rad |"
    )
    print("|---|---|---|---|---|---|---|---|")
    for layers in (None, nodes):
        eq = tj.flutter(panel, layers=layers)
        run = tj.simulate_orbits(panel, orbit, 1, layers=layers, progress=False, method="rk45")
        label = "two-layer" if layers is None else f"{layers} nodes"
        print(
            f"| {label} | {eq.equilibrium.T_front:.2f} | {eq.equilibrium.T_back:.2f} |"
            f" {eq.equilibrium.theta:.3e} | {run.exit_peak[0]:.3e} | {run.jitter_peak[0]:.3e} |"
            f" {run.jitter_rms[0]:.3e} | {eq.critical_damping:.3e} |"
        )
    print()


def main() -> None:
    parser = argparse.ArgumentParser(description="two-layer vs N-node laminate panels")
    parser.add_argument("--nodes", type=int, default=20)
    args = parser.parse_args()
    compare("CFRP/honeycomb solar-array wing", wing(), args.nodes)
    compare("aluminium boom", boom(), args.nodes)


if __name__ == "__main__":
    main()
