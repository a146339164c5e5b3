"""Short orbits of a linear hinge: the hybrid propagator runs whole orbits by the exponential
integrator (its steps read in closed form) instead of resolving the ringing that every eclipse
starts. Held to the accuracy gate of tests/test_hybrid.py against rk45 at tight tolerances on
drawn panels and low orbits (altitude, inclination, node, date, both shadow models), on every
orbit and every gated column.

The default tier is sized for CI; THERMOJITTER_SLOW=1 draws more cases over longer spans. The
cost of a LEO decade is measured by benches/longrun.py, not here.
"""

from __future__ import annotations

import math
import os

import hypothesis.strategies as st
import numpy as np
import pytest
from hypothesis import given, note
from test_hybrid import assert_gate
from test_hybrid_properties import Case, assert_case_gate, case_settings, drawn_panel

import thermojitter as tj
from conftest import PAPER

SLOW = bool(os.environ.get("THERMOJITTER_SLOW"))

REFERENCE = {"rtol": 1e-9, "atol": 1e-12}
"""rk45 well inside its default tolerances: the reference the gate is held to."""


@st.composite
def low_orbits(draw: st.DrawFn) -> tuple[str, tj.Orbit]:
    altitude = draw(st.floats(300e3, 2000e3))
    shadow = draw(st.sampled_from(["cylindrical", "conical"]))
    if draw(st.booleans()):
        return f"leo({altitude!r}, shadow={shadow!r})", tj.Orbit.leo(altitude, shadow=shadow)
    inclination = draw(st.floats(0.0, math.radians(98.0)))
    raan = draw(st.floats(0.0, 2.0 * math.pi))
    epoch = draw(st.floats(1.0, 365.0))
    name = (
        f"circular({altitude!r}, inclination={inclination!r}, raan={raan!r}, epoch={epoch!r}, "
        f"shadow={shadow!r}, albedo=0, earth_ir=0)"
    )
    orbit = tj.Orbit.circular(
        altitude, inclination, raan, epoch, shadow=shadow, albedo=0.0, earth_ir=0.0
    )
    return name, orbit


@st.composite
def cases(draw: st.DrawFn) -> Case:
    kind = draw(st.sampled_from(["paper", "paper", "metal", "cfrp", "sandwich"]))
    panel = drawn_panel(draw, kind)
    orbit_name, orbit = draw(low_orbits())
    # rk45 resolves the hinge: a stiff, light metal hinge costs ten times Table 1's.
    if SLOW:
        n = 8 if kind == "metal" else 30
    else:
        n = 2 if kind == "metal" else 6
    return Case(kind, panel, orbit_name, orbit, n)


@case_settings(6, 40)
@given(case=cases())
def test_whole_orbits_hold_the_gate_of_a_tight_rk45_run(case: Case) -> None:
    note(case.describe())
    kw = {"orbits_per_call": case.n, "progress": False, "model": "linear"}
    full = tj.simulate_orbits(case.panel, case.orbit, case.n, method="rk45", **REFERENCE, **kw)  # type: ignore[arg-type]
    hybrid = tj.simulate_orbits(case.panel, case.orbit, case.n, method="hybrid", **kw)  # type: ignore[arg-type]
    m = None
    if full.limit_crossing is None and hybrid.limit_crossing is None:
        # A run whose end falls a rounding past an orbit's edge also returns a stub of the next
        # orbit (rk45 as the hybrid; a defect of how a run ends, not of the propagator): the
        # orbits asked for are compared.
        assert len(full) == len(hybrid) in (case.n, case.n + 1), (len(full), len(hybrid))
        m = case.n
    assert_case_gate(case, full, hybrid, m)


@pytest.mark.parametrize("shadow", ["cylindrical", "conical"])
def test_table_1_at_540_km_runs_whole_orbits_within_the_gate(shadow: str) -> None:
    """Thirty orbits of Table 1 (linear hinge) at 540 km: every orbit within the gate of a tight
    rk45 run, the time integrated by exponential steps but for the partial shadows and the hinge
    periods after them (resolved), and far fewer steps than the resolved run."""
    n = 30
    orbit = tj.Orbit.leo(540e3, shadow=shadow)  # type: ignore[arg-type]
    kw = {"orbits_per_call": n, "progress": False, "model": "linear"}
    full = tj.simulate_orbits(PAPER, orbit, n, method="rk45", **REFERENCE, **kw)  # type: ignore[arg-type]
    hybrid = tj.simulate_orbits(PAPER, orbit, n, method="hybrid", **kw)  # type: ignore[arg-type]
    assert_gate(full, hybrid)
    p = hybrid.propagation
    span = n * orbit.period
    penumbra = sum(b - a for a, b in orbit.shadow_intervals(0.0, span)) - sum(
        b - a for a, b in orbit.umbra_intervals(0.0, span)
    )
    # Two contacts per orbit end a partial shadow, each followed by two resolved hinge periods.
    after = n * 2 * 2.0 / tj.natural_frequency(PAPER)
    assert p["t_linear"] == 0.0
    assert p["t_fallback"] <= penumbra + after * (1.0 + 1e-9)
    assert p["t_exponential"] + p["t_fallback"] == pytest.approx(span, rel=1e-12)
    assert hybrid.n_steps * 20 < full.n_steps


def test_geo_keeps_its_linear_arcs() -> None:
    """GEO (a day's orbit) keeps the linear arcs, with the linear hinge as with the other."""
    hybrid = tj.simulate_orbits(
        PAPER, tj.Orbit.geo_equinox(), 2, model="linear", progress=False, orbits_per_call=2
    )
    assert hybrid.propagation["t_linear"] > tj.Orbit.geo_equinox().period


def test_the_nonlinear_hinge_on_a_low_orbit_keeps_the_other_path() -> None:
    """The non-linear hinge's ringing changes its frequency with its amplitude, which a step of
    many periods does not hold: its low orbits stay on the path of linear arcs and fallback."""
    orbit = tj.Orbit.leo(540e3)
    hybrid = tj.simulate_orbits(PAPER, orbit, 2, progress=False, orbits_per_call=2)
    full = tj.simulate_orbits(PAPER, orbit, 2, method="rk45", progress=False, orbits_per_call=2)
    assert_gate(full, hybrid)
    assert hybrid.propagation["t_fallback"] > 0.5 * 2 * orbit.period
    assert np.isfinite(hybrid.t_entry).all()
