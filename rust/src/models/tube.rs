//! The thin-walled tube lit on one side: its thermal model (the mean temperature and the
//! circumferential perturbation T_m cos φ) and its structure (the cantilever's equivalent hinge,
//! `inputs::boom`), which couple through the thermal moment and the Sun's incidence on the
//! deflected tube.
//!
//! # The thermal model
//!
//! The wall, radius r, thickness h ≪ r, at angle φ around the section from the line facing the
//! Sun, conducts around the circumference (k), stores ρ c h per unit area and radiates from its
//! outer surface (ε). The Sun, at angle ψ to the boom's axis, gives the wall its component
//! normal to the axis, C sin ψ; a wall element whose normal makes φ with it absorbs
//!
//! ```text
//! q(φ) = α C sin ψ · max(cos φ, 0).
//! ```
//!
//! Its Fourier series, q = q₀ + q₁ cos φ + …, has
//! q₀ = (1/2π) ∫_{−π/2}^{π/2} α C sin ψ cos φ dφ = α C sin ψ / π (the lit half-circle's
//! projected width 2r over the circumference 2π r) and
//! q₁ = (1/π) ∫_{−π/2}^{π/2} α C sin ψ cos² φ dφ = α C sin ψ / 2. With T(φ, t) = T̄ + T_m cos φ,
//! the wall's balance ρ c h ∂T/∂t = (k h / r²) ∂²T/∂φ² + q(φ) − ε σ T⁴ projected on 1 and on
//! cos φ, with T⁴ linearised in T_m about T̄ (T_m ≪ T̄), gives the two equations here:
//!
//! ```text
//! ρ c h dT̄/dt  = α C sin ψ · f / π − ε σ T̄⁴
//! ρ c h dT_m/dt = α C sin ψ · f / 2 − (η k h / r² + 4 σ T̄*³ ε_eff) T_m
//! ```
//!
//! (f the flux factor: illumination × the incidence factor below), the second relaxed by the
//! circumferential conduction (the cos φ mode is an eigenfunction of ∂²/∂φ² with eigenvalue −1;
//! η the open section's share of it) and by the radiation, linearised about the sunlit mean
//! temperature T̄* = (α C sin ψ/(π ε σ))^(1/4), constant (the classical model's time constant τ,
//! so that T_m's equation is linear and the single-mode stability is that of a cubic).
//!
//! Radiation across the tube (inner emissivity ε_i, a grey enclosure): the view factor between
//! two strips of a circle's inside is ¼ |sin((φ − φ′)/2)| dφ′, whose cos φ component is
//! ∫₀^{2π} ¼ sin(u/2) cos u du = −1/3 (and its mean 1: closure). The radiosity of the cos φ mode
//! is then J₁ = ε_i E₁ + (1 − ε_i)(−1/3) J₁ and its net loss (1 + 1/3) J₁ = 4 ε_i E₁/(4 − ε_i),
//! E₁ = 4 σ T̄³ T_m; the mean mode exchanges nothing. So ε_eff = ε + 4 ε_i/(4 − ε_i).
//!
//! The stresses a E T_m cos φ over the ring bend it by M = ∫ E a T_m cos φ · r cos φ · h r dφ =
//! π E a h r² T_m about the axis normal to the Sun's plane; with I = π r³ h the curvature is
//! a T_m / r, the lit side convex: the tube bends away from the Sun when a > 0.
//!
//! # The incidence
//!
//! The boom lies along its axis from root to tip; the Sun makes ψ with it. Bent by θ (the
//! equivalent hinge's angle, the tip deflection over the length, positive away from the Sun),
//! the tube's axis makes ψ + θ with the Sun, so its normal component is C sin(ψ + θ): the
//! incidence factor sin(ψ + θ)/sin ψ multiplies the absorbed flux (both harmonics). At ψ = π/2
//! it is cos θ, the plate's projected area. Its slope at rest, cot ψ, is the coupling's sign:
//! for a tube bending away from the Sun (a > 0) whose tip leans toward the Sun (ψ < π/2) the
//! deflection raises the heating (the lagged feedback then damps the motion); leaning away
//! (ψ > π/2) it lowers it, and the thermal lag pumps the oscillation: thermal flutter when the
//! structure's own damping is too small (`analysis::tube`).

use crate::error::{Error, Result};
use crate::inputs::boom::Boom;
use crate::inputs::orbit::Orbit;
use crate::models::coupled::{Coupled, Coupling};
use crate::models::hinge::{check_angle_and_rate, generalised_moment, StructuralModel};
use crate::models::thermal::{ThermalModel, STEFAN_BOLTZMANN};
use nalgebra::{DimName, U4};
use std::f64::consts::PI;

/// The tube's two temperatures (T̄, T_m), per unit area of wall.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TubeThermal {
    /// α C sin ψ / π and α C sin ψ / 2, W/m² per unit flux factor.
    mean_heating: f64,
    harmonic_heating: f64,
    /// ε σ, W/(m² K⁴).
    radiation: f64,
    /// η k h/r² + 4 σ T̄*³ ε_eff, W/(m² K).
    relaxation: f64,
    /// ρ c h, J/(m² K).
    capacity: f64,
    /// The same coefficients over the capacity (per second), for the integrator.
    rate_mean_heating: f64,
    rate_harmonic_heating: f64,
    rate_radiation: f64,
    rate_relaxation: f64,
    /// χ π E a h r², N m/K.
    moment_per_kelvin: f64,
}

impl TubeThermal {
    pub fn new(boom: &Boom) -> Self {
        let absorbed = boom.normal_absorbed();
        let capacity = boom.heat_capacity();
        let (mean_heating, harmonic_heating) = (absorbed / PI, 0.5 * absorbed);
        let radiation = STEFAN_BOLTZMANN * boom.emissivity;
        let relaxation = boom.conduction_relaxation() + boom.radiation_relaxation();
        TubeThermal {
            mean_heating,
            harmonic_heating,
            radiation,
            relaxation,
            capacity,
            rate_mean_heating: mean_heating / capacity,
            rate_harmonic_heating: harmonic_heating / capacity,
            rate_radiation: radiation / capacity,
            rate_relaxation: relaxation / capacity,
            moment_per_kelvin: boom.moment_per_kelvin(),
        }
    }

    /// (T̄, T_m) at rest under the flux factor `flux`.
    pub fn equilibrium(&self, flux: f64) -> (f64, f64) {
        (
            (self.mean_heating * flux / self.radiation).powf(0.25),
            self.harmonic_heating * flux / self.relaxation,
        )
    }
}

impl ThermalModel for TubeThermal {
    fn size(&self) -> usize {
        2
    }
    fn names(&self) -> Vec<String> {
        vec!["T_mean".into(), "T_circ".into()]
    }
    fn heat_flows(&self, flux: f64, t: &[f64], out: &mut [f64]) {
        let t2 = t[0] * t[0];
        out[0] = self.mean_heating * flux - self.radiation * (t2 * t2);
        out[1] = self.harmonic_heating * flux - self.relaxation * t[1];
    }
    fn capacity(&self, _i: usize) -> f64 {
        self.capacity
    }
    #[inline(always)]
    fn rates(&self, flux: f64, t: &[f64], out: &mut [f64]) {
        let t2 = t[0] * t[0];
        out[0] = self.rate_mean_heating * flux - self.rate_radiation * (t2 * t2);
        out[1] = self.rate_harmonic_heating * flux - self.rate_relaxation * t[1];
    }
    #[inline(always)]
    fn gradient(&self, t: &[f64]) -> f64 {
        t[1]
    }
    fn moment_per_kelvin(&self) -> f64 {
        self.moment_per_kelvin
    }
    /// T̄ is an absolute temperature (> 0 K), T_m a perturbation about it (any sign, finite).
    fn check_start(&self, temps: &[f64]) -> Result<()> {
        crate::models::hinge::check_start_state(&temps[..1], 1, None)?;
        if !temps[1].is_finite() {
            return Err(Error::invalid("y0[1]", temps[1], "T_circ must be finite"));
        }
        Ok(())
    }
    fn initial_guess(&self, flux: f64, out: &mut [f64]) {
        let (mean, circ) = self.equilibrium(flux);
        out[0] = mean;
        out[1] = circ;
    }
}

/// The cantilever's equivalent hinge: a rigid link about the root, states (θ, θ̇), the incidence
/// factor sin(ψ + θ)/sin ψ. Its coefficients are divided by I_B once, here.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TubeHinge {
    /// I_B, kg m².
    inertia: f64,
    /// c_d / I_B, 1/s, and K_el / I_B, 1/s².
    damping: f64,
    stiffness: f64,
    /// K_el, N m/rad.
    hinge_stiffness: f64,
    /// ψ and 1/sin ψ.
    inclination: f64,
    inv_sin: f64,
}

impl TubeHinge {
    pub fn new(boom: &Boom) -> Self {
        let inertia = boom.hinge_inertia();
        TubeHinge {
            inertia,
            damping: boom.hinge_damping() / inertia,
            stiffness: boom.hinge_stiffness() / inertia,
            hinge_stiffness: boom.hinge_stiffness(),
            inclination: boom.solar_inclination,
            inv_sin: 1.0 / boom.solar_inclination.sin(),
        }
    }

    /// The largest |θ̇| of a start state, rad/s: (π/2) max(ω₁, c_d/I_B), as the panel's hinge.
    pub fn max_start_rate(&self) -> f64 {
        std::f64::consts::FRAC_PI_2 * self.stiffness.sqrt().max(self.damping)
    }
}

impl StructuralModel for TubeHinge {
    /// sin(ψ + θ) / sin ψ.
    #[inline(always)]
    fn area_factor(&self, q: &[f64]) -> f64 {
        (self.inclination + q[0]).sin() * self.inv_sin
    }
    fn inertia(&self) -> f64 {
        self.inertia
    }
    /// θ (the tip deflection over the length) and θ̇, as the panel's hinge names them.
    fn names(&self) -> Vec<String> {
        vec!["theta".into(), "theta_dot".into()]
    }
    fn size(&self) -> usize {
        2
    }
    #[inline(always)]
    fn rates(&self, load: f64, q: &[f64], out: &mut [f64]) -> f64 {
        out[0] = q[1];
        out[1] = generalised_moment(load, self.damping, self.stiffness, q[0], q[1]);
        self.area_factor(q)
    }
    fn positions(&self) -> usize {
        1
    }
    fn static_residual(&self, moment: f64, positions: &[f64], out: &mut [f64]) {
        out[0] = (moment - self.hinge_stiffness * positions[0]) / self.hinge_stiffness;
    }
    fn check_static(&self, positions: &[f64]) -> Result<()> {
        let theta = positions[0];
        if theta.abs() >= std::f64::consts::FRAC_PI_2 {
            return Err(Error::NoConvergence {
                what: "steady state".into(),
                reason: format!("boom angle {theta} rad is beyond 90°: the boom is far too soft"),
            });
        }
        Ok(())
    }
    fn check_start(&self, offset: usize, states: &[f64]) -> Result<()> {
        check_angle_and_rate(offset, states, self.max_start_rate())
    }
}

/// The boom's coupled system, state (T̄, T_m, θ, θ̇).
pub type TubeSystem = Coupled<TubeThermal, TubeHinge, U4>;

/// The boom in its orbit, validated.
pub fn boom_system(boom: &Boom, orbit: Orbit, coupling: Coupling) -> Result<TubeSystem> {
    boom.validate()?;
    if orbit.has_face_loads() {
        return Err(Error::invalid(
            "orbit",
            "with Earth heating or an attitude",
            "a boom takes the Sun alone on its lit side (albedo, earth_ir and the attitude are \
             the plate's)",
        ));
    }
    Coupled::compose(
        TubeThermal::new(boom),
        TubeHinge::new(boom),
        orbit,
        coupling,
        U4::name(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_steady_state_is_the_closed_form() {
        // Frozen incidence: T̄⁴ = α C sin ψ/(π ε σ); T_m = (α C sin ψ/2)/(k h/r² + 4σT̄³ε);
        // θ = χ π E a h r² T_m / K_el = (a T_m / r) L / 2, the tip deflection of the uniform
        // curvature a T_m/r over L.
        let boom = Boom {
            solar_inclination: 1.1,
            ..Boom::example()
        };
        let sys = boom_system(&boom, Orbit::geo_equinox(), Coupling::Frozen).unwrap();
        let y = sys.steady_state(1.0).unwrap();
        let sigma = 5.670374419e-8;
        let q = boom.absorptivity * boom.solar_constant * 1.1f64.sin();
        let mean = (q / (PI * boom.emissivity * sigma)).powf(0.25);
        let k = boom.conductivity * boom.wall / boom.radius.powi(2);
        let circ = 0.5 * q / (k + 4.0 * sigma * mean.powi(3) * boom.emissivity);
        let theta = boom.expansion_coeff * circ / boom.radius * boom.length / 2.0;
        assert!((y[0] / mean - 1.0).abs() < 1e-12, "{} {mean}", y[0]);
        assert!((y[1] / circ - 1.0).abs() < 1e-12, "{} {circ}", y[1]);
        assert!((y[2] / theta - 1.0).abs() < 1e-9, "{} {theta}", y[2]);
        assert_eq!(y[3], 0.0);
    }

    #[test]
    fn energy_is_conserved_by_the_mean_equation() {
        // Absorbed per unit length 2 r α C sin ψ (the projected width); the mean equation's
        // absorbed share times the circumference 2π r is the same.
        let boom = Boom::example();
        let th = TubeThermal::new(&boom);
        let mut out = [0.0; 2];
        th.heat_flows(1.0, &[1e-9, 0.0], &mut out);
        let per_length = out[0] * 2.0 * PI * boom.radius;
        let want = 2.0 * boom.radius * boom.normal_absorbed();
        assert!((per_length / want - 1.0).abs() < 1e-14);
    }
}
