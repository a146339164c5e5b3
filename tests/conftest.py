"""Shared fixtures and hypothesis strategies: physically valid panels around Table 1."""

from __future__ import annotations

import os

import hypothesis.strategies as st
from hypothesis import settings

import thermojitter as tj

settings.register_profile("ci", deadline=None, print_blob=True, derandomize=True)
settings.register_profile("dev", deadline=None)
settings.load_profile(os.environ.get("HYPOTHESIS_PROFILE", "dev"))

PAPER = tj.Panel.paper()
GEO = tj.Orbit.geo_equinox()
ENTRY, EXIT = GEO.shadow_intervals(0.0, GEO.period)[0]


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
