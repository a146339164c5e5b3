"""Property test of the hybrid propagator: drawn panels (thin metal, CFRP, a CFRP/honeycomb
sandwich, Table 1 varied) on drawn orbits (GEO at equinox, GEO on a date in or out of the spring
eclipse season, LEO), hybrid against the hinge-resolved rk45 run, held to the accuracy gate of
tests/test_hybrid.py on every orbit and every gated column.

The default tier is sized for CI (a few short spans); THERMOJITTER_SLOW=1 draws many more cases
over longer spans.
"""

from __future__ import annotations

import datetime as dt
import math
import os
from dataclasses import dataclass

import hypothesis.strategies as st
import numpy as np
import pytest
from hypothesis import HealthCheck, Phase, given, note, reject, settings
from test_hybrid import METRICS

import thermojitter as tj
from conftest import panels
from thermojitter import materials as mat
from thermojitter.laminate import Layer

SLOW = bool(os.environ.get("THERMOJITTER_SLOW"))

STEEL_304 = Layer(
    thickness=1e-3,
    conductivity=16.2,
    density=8000.0,
    specific_heat=500.0,
    youngs_modulus=193e9,
    expansion_coeff=17.3e-6,
    name="steel_304",
)
"""A stainless-steel-like layer (the library has no steel); thickness replaced when drawn."""

SPRING_SEASON = (dt.date(2026, 2, 28), dt.date(2026, 4, 10))
"""Dates well inside the spring eclipse season of GEO (eclipses every orbit)."""
NO_ECLIPSES = (dt.date(2026, 5, 1), dt.date(2026, 8, 15))
"""Dates between the seasons: GEO sees no eclipse."""


@dataclass(frozen=True)
class Case:
    kind: str
    panel: tj.Panel
    orbit_name: str
    orbit: tj.Orbit
    n: int

    def describe(self) -> str:
        fields = {k: v for k, v in self.panel.as_dict().items() if k != "layup"}
        layers = (
            [(layer.name, layer.thickness) for layer in self.panel.layup.layers]
            if self.panel.layup is not None
            else None
        )
        return f"{self.kind} panel {fields}, layers {layers}, on {self.orbit_name}, {self.n} orbits"


def metal_layer(draw: st.DrawFn) -> Layer:
    thickness = draw(st.floats(0.5e-3, 3e-3))
    choice = draw(st.sampled_from(["aluminium_6061", "titanium_6al4v", "steel_304"]))
    if choice == "steel_304":
        return Layer(**{**STEEL_304.as_dict(), "thickness": thickness})
    return mat.get(choice).layer(thickness)


def cfrp_layer(draw: st.DrawFn, thickness: float) -> Layer:
    """A quasi-isotropic CFRP layer: the library's CFRP M55J QI (a = -2.4e-8 1/K: the panel bends
    the other way, and barely), or its properties with a drawn expansion coefficient from
    slightly negative to that of T300-class laminates."""
    if draw(st.booleans()):
        return mat.CFRP_M55J_QI.layer(thickness)
    cte = draw(st.floats(-1e-6, 2e-6))
    fields = {**mat.CFRP_M55J_QI.layer(thickness).as_dict(), "expansion_coeff": cte}
    return Layer(**{**fields, "name": "cfrp_qi"})


def optics(draw: st.DrawFn) -> dict[str, float]:
    return {
        "emissivity_front": draw(st.floats(0.2, 0.9)),
        "emissivity_back": draw(st.floats(0.2, 0.9)),
        "absorptivity": draw(st.floats(0.2, 0.95)),
    }


def with_drawn_damping(draw: st.DrawFn, panel: tj.Panel) -> tj.Panel:
    """Damping a multiple 0.2–5 of the flutter analysis' critical damping c_d*; where c_d* is ~0
    or undefined (a panel that does not flutter), a fraction 0.2–5 % of critical 2 sqrt(K I)."""
    ref = 2.0 * math.sqrt(panel.hinge_stiffness * panel.hinge_inertia)
    critical = tj.flutter(panel).critical_damping
    if math.isfinite(critical) and critical > 1e-6 * ref:
        return panel.replace(damping=draw(st.floats(0.2, 5.0)) * critical)
    return panel.replace(damping=draw(st.floats(0.002, 0.05)) * ref)


@st.composite
def cases(draw: st.DrawFn) -> Case:
    kind = draw(st.sampled_from(["metal", "cfrp", "sandwich", "paper"]))
    if kind == "paper":
        panel = draw(panels(spread=0.2))
    else:
        if kind == "metal":
            layers = [metal_layer(draw)]
            length = draw(st.floats(1.0, 5.0))
        elif kind == "cfrp":
            layers = [cfrp_layer(draw, draw(st.floats(0.5e-3, 3e-3)))]
            length = draw(st.floats(1.0, 5.0))
        else:
            face = cfrp_layer(draw, draw(st.floats(0.1e-3, 0.5e-3)))
            layers = [face, mat.ALUMINIUM_HONEYCOMB.layer(draw(st.floats(5e-3, 25e-3))), face]
            length = draw(st.floats(2.0, 8.0))
        panel = tj.Panel.from_laminate(tj.Laminate(layers, **optics(draw)), length=length)
    panel = with_drawn_damping(draw, panel)

    orbits = ["geo_equinox", "geo_spring", "geo_no_eclipse", "leo"]
    # rk45 on a sandwich through GEO eclipses took up to 260 s for 2 orbits (measured on
    # 22f48cb): only the slow tier takes sandwiches to GEO.
    which = draw(st.sampled_from(orbits if SLOW or kind != "sandwich" else ["leo"]))
    if which == "geo_equinox":
        orbit_name, orbit = "geo_equinox()", tj.Orbit.geo_equinox()
    elif which == "leo":
        orbit_name, orbit = "leo()", tj.Orbit.leo()
    else:
        first, last = SPRING_SEASON if which == "geo_spring" else NO_ECLIPSES
        date = first + dt.timedelta(days=draw(st.integers(0, (last - first).days)))
        orbit_name, orbit = f'geo_year("{date.isoformat()}")', tj.Orbit.geo_year(date.isoformat())

    # rk45 resolves the hinge: thin metal (a stiff, light hinge) costs ~4 s per GEO orbit.
    leo = which == "leo"
    if SLOW:
        n = (15 if kind == "metal" else 30) if leo else (2 if kind == "metal" else 4)
    else:
        n = {"metal": 5, "sandwich": 3}.get(kind, 10) if leo else (1 if kind == "metal" else 2)
    return Case(kind, panel, orbit_name, orbit, n)


def gate_failures(full: tj.OrbitSummaries, hybrid: tj.OrbitSummaries, m: int) -> list[str]:
    """Every (column, orbit) of the first m orbits outside the gate, worst first."""
    found: list[tuple[float, str]] = []
    for name in METRICS:
        a, b = full.columns[name][:m], hybrid.columns[name][:m]
        for i in np.flatnonzero(np.isnan(a) != np.isnan(b)):
            found.append((math.inf, f"{name} orbit {i}: rk45 {a[i]!r} vs hybrid {b[i]!r} (NaN)"))
        defined = ~np.isnan(a) & ~np.isnan(b)
        tol = np.where(np.abs(a) < 5e-5, 1e-6, 0.02 * np.abs(a))
        excess = np.where(defined, np.abs(b - a) / tol, 0.0)
        for i in np.flatnonzero(excess > 1.0):
            found.append(
                (
                    float(excess[i]),
                    f"{name} orbit {i}: rk45 {a[i]:.6e} vs hybrid {b[i]:.6e} "
                    f"({excess[i]:.2f} x the gate)",
                )
            )
    return [text for _, text in sorted(found, key=lambda f: -f[0])]


def compared_orbits(full: tj.OrbitSummaries, hybrid: tj.OrbitSummaries, n: int) -> int:
    """How many leading orbits both runs finished. A run that flutters stops at theta_limit in
    an orbit it does not finish; both must stop in the same orbit ±1 (or, for one that stops
    in the last orbit or the one before, the other may still be short of the limit)."""
    fc, hc = full.limit_crossing, hybrid.limit_crossing
    if fc is None and hc is None:
        assert len(full) == len(hybrid) == n, (len(full), len(hybrid), n)
        return n
    if fc is not None and hc is not None:
        assert abs(fc[1] - hc[1]) <= 1, f"limit crossed in orbit {fc} (rk45) vs {hc} (hybrid)"
        m = min(fc[1], hc[1])
    else:
        crossing = fc if fc is not None else hc
        assert crossing is not None
        who = "rk45" if fc is not None else "hybrid"
        assert crossing[1] >= n - 2, f"only {who} crossed the limit, at {crossing} of {n} orbits"
        m = crossing[1]
    return min(m, len(full), len(hybrid))


# Shrinking re-runs rk45 dozens of times (minutes for thin metal on GEO): the default tier
# reports the drawn case as it failed (the message names every field), the slow tier shrinks.
@settings(
    max_examples=60 if SLOW else 8,
    deadline=None,
    phases=list(Phase) if SLOW else [p for p in Phase if p is not Phase.shrink],
    suppress_health_check=[HealthCheck.too_slow],
)
@given(case=cases())
def test_hybrid_holds_the_gate_of_the_full_run(case: Case) -> None:
    note(case.describe())
    kw = {"orbits_per_call": case.n, "progress": False}
    try:
        full = tj.simulate_orbits(case.panel, case.orbit, case.n, method="rk45", **kw)  # type: ignore[arg-type]
    except tj.ParameterError as e:
        # A drawn case whose full integration is beyond the run's step budget (a stiff sandwich
        # on GEO) has nothing to compare with: the refusal names the span.
        assert e.parameter == "n_orbits" and "max_steps" in str(e), e
        reject()
    hybrid = tj.simulate_orbits(case.panel, case.orbit, case.n, method="hybrid", **kw)  # type: ignore[arg-type]
    m = compared_orbits(full, hybrid, case.n)
    failures = gate_failures(full, hybrid, m)
    assert not failures, (
        f"{case.describe()}: {len(failures)} outside the gate in {m} compared orbits; "
        + "; ".join(failures[:5])
    )


@pytest.mark.xfail(
    strict=True,
    reason="known defect of the hybrid on GEO: a fluttering non-linear hinge (front emissivity "
    "0.15, θ_eq 15°) reads orbit 0's jitter_peak and jitter_rms 4 % high, 1.97 x the gate, "
    "uncaught. The exponential steps through the eclipse hold θ to rtol 1e-4 of itself (2.7e-5 "
    "rad here), not the small oscillation riding on it (~1e-4 rad), and the flutter carries that "
    "fraction into the ringing it grows to: the error falls to 0.4 % with atol_angle 1e-9 and "
    "rtol 1e-7, to 2e-4 with the stretch left to the full integration. Handing growing "
    "oscillations to the full integration mends it but sent Table 1's GEO decade 18.8 M steps "
    "to the full integration instead of 1.0 M",
)
def test_the_known_fluttering_case_on_geo_holds_the_gate() -> None:
    # Drawn by the property test above (dev profile).
    panel = tj.Panel.paper().replace(
        emissivity_front=0.15132300635607948,
        emissivity_back=0.95,
        absorptivity=0.7066896092458339,
        specific_heat=827.0431581700932,
        mass_per_length=5.881868280083421,
        expansion_coeff=2.2619963073516082e-05,
        length=57.630225184976425,
        youngs_modulus=58310644833.52782,
        conductance=24.831180402000104,
        hinge_stiffness=3818.0692800791876,
        bending_inertia=8.323818110026694e-07,
        damping=9.502121727292856,
        solar_constant=1633.2,
    )
    orbit = tj.Orbit.geo_year("2026-03-03")
    full = tj.simulate_orbits(panel, orbit, 1, method="rk45", progress=False)
    hybrid = tj.simulate_orbits(panel, orbit, 1, method="hybrid", progress=False)
    assert not gate_failures(full, hybrid, 1)
