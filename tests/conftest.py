"""Shared fixtures and hypothesis strategies: physically valid panels around Table 1."""

from __future__ import annotations

import os

import hypothesis.strategies as st
import pytest
from hypothesis import settings

import thermojitter as tj
from thermojitter import materials as mat

settings.register_profile("ci", deadline=None, print_blob=True, derandomize=True)
settings.register_profile("dev", deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "dev"))

SLOW = bool(os.environ.get("THERMOJITTER_SLOW"))
"""The slow tier: cases of minutes (``@pytest.mark.slow``) run only with THERMOJITTER_SLOW=1; the
default tier checks the same things on shorter spans."""


def pynastran_imports() -> bool:
    """Whether pyNastran (the extra thermojitter[nastran]) imports here: pyNastran 1.4 pins
    numpy < 2 and fails to import under a newer numpy, so its tests skip rather than fail."""
    try:
        from pyNastran.bdf import bdf  # noqa: F401
    except Exception:
        return False
    return True


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    if SLOW:
        return
    skip = pytest.mark.skip(reason="minutes-long case: set THERMOJITTER_SLOW=1 to run it")
    for item in items:
        if "slow" in item.keywords:
            item.add_marker(skip)


PAPER = tj.Panel.paper()
GEO = tj.Orbit.geo_equinox()
ENTRY, EXIT = GEO.shadow_intervals(0.0, GEO.period)[0]


def wing_layup() -> tj.Laminate:
    """The solar-array wing's layup of examples/laminates.py (the example keeps its own copy, so
    that it reads on its own): Kapton, 0.3 mm CFRP face sheets on a 20 mm honeycomb core."""
    return tj.Laminate(
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


@st.composite
def panels(draw: st.DrawFn, spread: float = 0.3) -> tj.Panel:
    """A Table 1 panel with every dimensional parameter scaled by up to ±spread and the optical
    properties drawn over a wide range of real coatings."""
    factor = st.floats(1.0 - spread, 1.0 + spread)
    changes = {
        name: getattr(PAPER, name) * draw(factor)
        for name in (
            "specific_heat",
            "mass_per_length",
            "expansion_coeff",
            "length",
            "youngs_modulus",
            "thickness",
            "conductance",
            "hinge_stiffness",
            "bending_inertia",
            "damping",
            "solar_constant",
        )
    }
    changes["emissivity_front"] = draw(st.floats(0.1, 0.95))
    changes["emissivity_back"] = draw(st.floats(0.1, 0.95))
    changes["absorptivity"] = draw(st.floats(0.2, 0.95))
    return PAPER.replace(**changes)
