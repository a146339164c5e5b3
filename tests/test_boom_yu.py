"""Yu's orientation result (Y.-Y. Yu, "Thermally induced vibration and flutter of a flexible
boom", 1969, doi:10.2514/3.29725: "stable if the boom is pointed away from the sun
and unstable if it is pointed towards the sun", undamped) stated in the convention under which
this model agrees with it (docs/booms.md, "Orientation and flutter").

The model measures ψ from the boom's root-to-tip axis to the direction of the Sun. Yu's statement
holds when "the direction the boom points" is measured against the rays' direction of travel
(from the Sun), i.e. Yu's angle is φ = π − ψ and "pointed towards the sun" is φ < 90°: the rays
run along the boom from its root toward its tip, the tip in the lee.

Why, from the equations (independent of any convention): linearised about the sunlit steady
state, T_m and θ obey u̇ = −u/τ + g x and ẍ + 2ζω ẋ + ω² x = k u (x = θ − θ*, u = T_m − T_m*;
g = ∂(heating of T_m)/∂θ ∝ cos(ψ + θ*), k the moment per kelvin over I_B, > 0 for a > 0). The
characteristic cubic is (s² + 2ζω s + ω²)(s + 1/τ) − k g = 0; undamped (ζ = 0) its Routh–Hurwitz
condition a₂a₁ > a₀ reads ω²/τ > ω²/τ − k g, i.e. k g > 0. The undamped boom flutters exactly
when the deflection lowers its heating (k g < 0)."""

from __future__ import annotations

import math

import pytest

import thermojitter as tj


def yu_boom(phi_deg: float, **changes: float) -> tj.Boom:
    """An undamped 15 m beryllium-copper tube whose root-to-tip axis makes ``phi_deg`` with the
    rays' direction of travel (Yu's angle as read here): ψ = 180° − φ."""
    boom = tj.Boom(15.0, 6.35e-3, 5.1e-5, absorptivity=0.5, emissivity=0.05, damping=0.0)
    return boom.replace(solar_inclination=math.radians(180.0 - phi_deg), **changes)


@pytest.mark.parametrize("phi_deg", [20.0, 45.0, 70.0, 80.0])
def test_pointed_towards_the_sun_in_yus_convention_flutters(phi_deg: float) -> None:
    result = tj.flutter(yu_boom(phi_deg))
    assert result.growth_rate > 0.0
    assert result.frequency_hz == pytest.approx(yu_boom(phi_deg).first_frequency, rel=0.05)


@pytest.mark.parametrize("phi_deg", [100.0, 110.0, 135.0, 160.0])
def test_pointed_away_from_the_sun_in_yus_convention_is_stable(phi_deg: float) -> None:
    assert tj.flutter(yu_boom(phi_deg)).growth_rate < 0.0


@pytest.mark.parametrize("phi_deg", [20.0, 70.0, 110.0, 160.0])
def test_the_sign_is_the_routh_hurwitz_one_of_the_single_mode_cubic(phi_deg: float) -> None:
    """Undamped, the boom flutters iff k g < 0, k g read off the linearisation's own coefficients
    (the Jacobian over T̄, T_m, θ, θ̇: g = ∂Ṫ_m/∂θ, k = ∂θ̈/∂T_m); and g has the sign of
    cos(ψ + θ*), the slope of the incidence factor sin(ψ + θ)/sin ψ at the steady state."""
    boom = yu_boom(phi_deg)
    result = tj.flutter(boom)
    jac = result.jacobian
    g, k = jac[1, 2], jac[3, 1]
    assert k > 0.0  # a > 0: T_m > 0 bends the tube away from the Sun, θ > 0
    incidence_slope = math.cos(boom.solar_inclination + result.equilibrium.theta)
    assert math.copysign(1.0, g) == math.copysign(1.0, incidence_slope)
    assert (result.growth_rate > 0.0) == (k * g < 0.0)


def test_a_negative_expansion_swaps_yus_result() -> None:
    """A CFRP-like tube (a < 0) bends toward the Sun: k < 0, and the orientations swap."""
    for phi_deg, flutters in ((45.0, False), (135.0, True)):
        boom = yu_boom(phi_deg, expansion_coeff=-1e-6)
        assert (tj.flutter(boom).growth_rate > 0.0) == flutters


def test_the_plain_reading_is_the_opposite() -> None:
    """Read as "the tip leans toward the Sun" (ψ < 90° in the model's own angle), Yu's words
    would predict flutter where the model finds stability: the mapping above is needed."""
    tip_toward_sun = yu_boom(180.0 - 60.0)  # ψ = 60°
    tip_away = yu_boom(180.0 - 120.0)  # ψ = 120°
    assert math.degrees(tip_toward_sun.solar_inclination) == pytest.approx(60.0)
    assert tj.flutter(tip_toward_sun).growth_rate < 0.0 < tj.flutter(tip_away).growth_rate
