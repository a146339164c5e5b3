//! The boom: a thin-walled circular tube cantilevered from the spacecraft with a tip mass, lit by
//! the Sun on one side (the classical problem of Boley, Yu 1969, Frisch, Thornton & Kim 1993).
//! Validation returns errors; nothing here panics.
//!
//! # The equivalent hinge (one degree of freedom)
//!
//! The cantilever of length L, bending stiffness E I, mass m per length and tip mass M_t is
//! reduced to its first bending mode φ(x) (clamped at x = 0; at the tip free of moment, the tip
//! mass a point mass), scaled so that φ(L) = 1. The state is the hinge angle θ = w(L)/L of a
//! rigid link of length L about the root: the tip deflection over the length, which for the
//! uniform thermal curvature κ of a boom lit along its whole length (w = κ x²/2) is also the
//! mean slope of the boom, w(L)/L = κ L/2 = (1/L) ∫ w' dx. Then
//!
//! - inertia I_B = L² (m ∫₀ᴸ φ² dx + M_t): the mode's kinetic energy ½ I_B θ̇²;
//! - stiffness K_el = ω₁² I_B, ω₁ = (β₁L)² √(E I/(m L⁴)) the first cantilever frequency with the
//!   tip mass (β₁L the first root of 1 + cos β cosh β + μ β (cos β sinh β − sin β cosh β) = 0,
//!   μ = M_t/(m L); 1.8751 without tip mass): the hinge oscillates at the boom's frequency;
//! - moment scale χ = K_el L / (2 E I): under a steady thermal moment M_T the hinge settles at
//!   θ = χ M_T / K_el = M_T L / (2 E I), the exact tip deflection of the uniformly curved
//!   cantilever (κ = M_T / E I, w(L) = κ L²/2) over L. Without tip mass K_el ≈ 3.0 E I/L and
//!   χ ≈ 1.5 (the paper's χ ≈ 1.3 matches the free–free panel the same way);
//! - damping c_d = 2 ζ ω₁ I_B from the mode's damping ratio ζ (the boom's `damping`).
//!
//! The rigid link turns about the root, so its equation of motion is I_B θ̈ + c_d θ̇ + K_el θ =
//! χ M_T with no kinematic term (the free–free panel's (1 + 3 sin²θ) does not arise).

use crate::error::{Error, Result};
use crate::inputs::panel::{check_in_range, Panel, MAX_EXPANSION};
use crate::models::thermal::STEFAN_BOLTZMANN;
use std::f64::consts::PI;

/// The boom's parameters, one row each: name, example value, range `(low, high, low end open)`
/// (the high end closed). The example is a 1963-22A-like beryllium–copper gravity-gradient boom
/// (see `Boom::example`).
pub const BOOM_TABLE: [(&str, f64, (f64, f64, bool)); 17] = [
    ("length", 30.0, (0.1, 1e4, false)),
    ("radius", 6.35e-3, (1e-4, 10.0, false)),
    ("wall", 5.1e-5, (1e-6, 0.1, false)),
    ("density", 8250.0, (1.0, 3e4, false)),
    ("youngs_modulus", 128e9, (1e6, 1e13, false)),
    (
        "expansion_coeff",
        1.7e-5,
        (-MAX_EXPANSION, MAX_EXPANSION, false),
    ),
    ("conductivity", 105.0, (0.0, 1e4, false)),
    ("specific_heat", 420.0, (10.0, 1e5, false)),
    ("absorptivity", 0.5, (0.0, 1.0, true)),
    ("emissivity", 0.05, (0.0, 1.0, true)),
    ("emissivity_inner", 0.0, (0.0, 1.0, false)),
    ("conduction_scale", 1.0, (0.0, 1.0, true)),
    ("damping", 0.0, (0.0, 10.0, false)),
    ("tip_mass", 0.0, (0.0, 1e4, false)),
    ("solar_constant", 1361.0, (0.0, 1e5, true)),
    ("solar_inclination", PI / 2.0, (0.0, PI, true)),
    ("moment_scale", 1.0, (0.0, 100.0, true)),
];

/// A thin-walled circular tube on a cantilever (all quantities SI, angles in rad).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Boom {
    /// L, length from the root to the tip, m.
    pub length: f64,
    /// r, mean radius of the wall, m.
    pub radius: f64,
    /// h, wall thickness, m (thin: h <= r/5).
    pub wall: f64,
    /// ρ, density of the wall, kg/m³.
    pub density: f64,
    /// E, Young's modulus, Pa.
    pub youngs_modulus: f64,
    /// a, coefficient of thermal expansion, 1/K (either sign).
    pub expansion_coeff: f64,
    /// k, thermal conductivity of the wall, W/(m K).
    pub conductivity: f64,
    /// c, specific heat, J/(kg K).
    pub specific_heat: f64,
    /// α, solar absorptivity of the outer surface.
    pub absorptivity: f64,
    /// ε, infrared emissivity of the outer surface.
    pub emissivity: f64,
    /// ε_i, emissivity of the inner surface: radiation across the tube (0: none).
    pub emissivity_inner: f64,
    /// η, the share of the closed tube's circumferential conduction the section has, in (0, 1]
    /// (1: closed; an open or overlapped STEM section conducts less across its seam).
    pub conduction_scale: f64,
    /// ζ, damping ratio of the first bending mode.
    pub damping: f64,
    /// M_t, tip mass, kg.
    pub tip_mass: f64,
    /// C, solar flux at 1 au, W/m².
    pub solar_constant: f64,
    /// ψ, the Sun's angle to the boom's axis (root to tip), rad, in (0, π): below π/2 the tip
    /// leans toward the Sun, above it away; π/2 lights the boom square on.
    pub solar_inclination: f64,
    /// An extra scale of the thermal moment on top of the hinge equivalence's χ (1: none).
    pub moment_scale: f64,
}

/// The fastest rate a boom's model may have, 1/s (as [`Panel::MAX_RATE`]).
const MAX_RATE: f64 = Panel::MAX_RATE;

impl Boom {
    /// The field names, in the table's order.
    pub const FIELDS: [&'static str; 17] = {
        let mut names = [""; 17];
        let mut i = 0;
        while i < 17 {
            names[i] = BOOM_TABLE[i].0;
            i += 1;
        }
        names
    };

    /// The table's example: a 30 m beryllium–copper STEM-like tube, 12.7 mm across, 51 µm wall,
    /// bare metal (α = 0.5, ε = 0.05), lit square on, undamped, without tip mass.
    pub fn example() -> Self {
        let mut b = Boom {
            length: 0.0,
            radius: 0.0,
            wall: 0.0,
            density: 0.0,
            youngs_modulus: 0.0,
            expansion_coeff: 0.0,
            conductivity: 0.0,
            specific_heat: 0.0,
            absorptivity: 0.0,
            emissivity: 0.0,
            emissivity_inner: 0.0,
            conduction_scale: 0.0,
            damping: 0.0,
            tip_mass: 0.0,
            solar_constant: 0.0,
            solar_inclination: 0.0,
            moment_scale: 0.0,
        };
        for (name, value, _) in BOOM_TABLE {
            b.set(name, value).expect("the table's names are fields");
        }
        b
    }

    /// Sets a field by name.
    pub fn set(&mut self, name: &str, value: f64) -> Result<()> {
        *self.field(name)? = value;
        Ok(())
    }

    /// Reads a field by name.
    pub fn get(&self, name: &str) -> Result<f64> {
        let mut copy = *self;
        Ok(*copy.field(name)?)
    }

    fn field(&mut self, name: &str) -> Result<&mut f64> {
        Ok(match name {
            "length" => &mut self.length,
            "radius" => &mut self.radius,
            "wall" => &mut self.wall,
            "density" => &mut self.density,
            "youngs_modulus" => &mut self.youngs_modulus,
            "expansion_coeff" => &mut self.expansion_coeff,
            "conductivity" => &mut self.conductivity,
            "specific_heat" => &mut self.specific_heat,
            "absorptivity" => &mut self.absorptivity,
            "emissivity" => &mut self.emissivity,
            "emissivity_inner" => &mut self.emissivity_inner,
            "conduction_scale" => &mut self.conduction_scale,
            "damping" => &mut self.damping,
            "tip_mass" => &mut self.tip_mass,
            "solar_constant" => &mut self.solar_constant,
            "solar_inclination" => &mut self.solar_inclination,
            "moment_scale" => &mut self.moment_scale,
            _ => return Err(Error::invalid("parameter", name, "is not a boom parameter")),
        })
    }

    /// Checks every parameter against [`BOOM_TABLE`], the wall against the radius (thin-walled:
    /// h <= r/5), ψ below π, and the model's rates against the fastest an explicit integrator
    /// follows.
    pub fn validate(&self) -> Result<()> {
        for (name, _, range) in BOOM_TABLE {
            check_in_range(name, self.get(name)?, range)?;
        }
        if self.solar_inclination >= PI {
            return Err(Error::invalid(
                "solar_inclination",
                self.solar_inclination,
                "must be in (0, π) rad: the Sun's angle to the boom's axis",
            ));
        }
        if self.wall > 0.2 * self.radius {
            return Err(Error::invalid(
                "wall",
                self.wall,
                &format!(
                    "must be at most radius/5 = {:e} m: the model is the thin-walled tube's",
                    0.2 * self.radius
                ),
            ));
        }
        let omega = self.first_angular_frequency();
        let rates = [
            ("youngs_modulus", self.youngs_modulus, omega, "ω₁"),
            (
                "damping",
                self.damping,
                2.0 * self.damping * omega,
                "2 ζ ω₁",
            ),
            (
                "conductivity",
                self.conductivity,
                1.0 / self.time_constant(),
                "the thermal rate 1/τ",
            ),
        ];
        for (name, value, rate, what) in rates {
            if !rate.is_finite() || rate > MAX_RATE {
                return Err(Error::invalid(
                    name,
                    value,
                    &format!(
                        "gives {what} = {rate:.3e} 1/s with the other parameters; at most \
                         {MAX_RATE:e} 1/s"
                    ),
                ));
            }
        }
        Ok(())
    }

    /// m = ρ 2π r h, mass per length of the tube, kg/m.
    pub fn mass_per_length(&self) -> f64 {
        self.density * 2.0 * PI * self.radius * self.wall
    }

    /// I = π r³ h, second moment of area of the thin ring, m⁴.
    pub fn bending_inertia(&self) -> f64 {
        PI * self.radius.powi(3) * self.wall
    }

    /// ρ c h, heat capacity per unit area of wall, J/(m² K).
    pub fn heat_capacity(&self) -> f64 {
        self.density * self.specific_heat * self.wall
    }

    /// η k h / r², the circumferential conduction's relaxation of T_m cos φ per unit area of
    /// wall, W/(m² K).
    pub fn conduction_relaxation(&self) -> f64 {
        self.conduction_scale * self.conductivity * self.wall / (self.radius * self.radius)
    }

    /// α C sin ψ, the absorbed flux on the part of the wall facing the Sun square on, W/m².
    pub fn normal_absorbed(&self) -> f64 {
        self.absorptivity * self.solar_constant * self.solar_inclination.sin()
    }

    /// T̄*, the sunlit mean temperature at 1 au: (α C sin ψ / (π ε σ))^(1/4), K.
    pub fn sunlit_mean_temperature(&self) -> f64 {
        (self.normal_absorbed() / (PI * self.emissivity * STEFAN_BOLTZMANN)).powf(0.25)
    }

    /// The linearised radiation's relaxation of T_m cos φ per unit area of wall at T̄*, W/(m² K):
    /// 4 σ T̄*³ (ε + 4 ε_i/(4 − ε_i)), the outer surface's and the exchange across the tube's
    /// (see `models::tube`).
    pub fn radiation_relaxation(&self) -> f64 {
        let ei = self.emissivity_inner;
        let t = self.sunlit_mean_temperature();
        4.0 * STEFAN_BOLTZMANN * t * t * t * (self.emissivity + 4.0 * ei / (4.0 - ei))
    }

    /// τ = ρ c h / (η k h/r² + radiation), the thermal time constant of T_m, s.
    pub fn time_constant(&self) -> f64 {
        self.heat_capacity() / (self.conduction_relaxation() + self.radiation_relaxation())
    }

    /// π E a h r², the thermal moment per kelvin of T_m (curvature a T_m / r), N m/K.
    pub fn physical_moment_per_kelvin(&self) -> f64 {
        PI * self.youngs_modulus * self.expansion_coeff * self.wall * self.radius * self.radius
    }

    /// μ = M_t / (m L), the tip mass over the boom's mass.
    pub fn tip_mass_ratio(&self) -> f64 {
        self.tip_mass / (self.mass_per_length() * self.length)
    }

    /// β₁L, the first root of the cantilever-with-tip-mass frequency equation.
    pub fn beta1_l(&self) -> f64 {
        cantilever_beta1(self.tip_mass_ratio())
    }

    /// ω₁, the first bending angular frequency of the cantilever with its tip mass, rad/s.
    pub fn first_angular_frequency(&self) -> f64 {
        let b = self.beta1_l();
        let ei = self.youngs_modulus * self.bending_inertia();
        b * b * (ei / (self.mass_per_length() * self.length.powi(4))).sqrt()
    }

    /// I_B = L² (m ∫φ² + M_t), φ(L) = 1: the equivalent hinge's inertia, kg m².
    pub fn hinge_inertia(&self) -> f64 {
        let l = self.length;
        let modal = cantilever_modal_mass(self.beta1_l());
        l * l * (self.mass_per_length() * l * modal + self.tip_mass)
    }

    /// K_el = ω₁² I_B, N m/rad.
    pub fn hinge_stiffness(&self) -> f64 {
        self.first_angular_frequency().powi(2) * self.hinge_inertia()
    }

    /// c_d = 2 ζ ω₁ I_B, N m s/rad.
    pub fn hinge_damping(&self) -> f64 {
        2.0 * self.damping * self.first_angular_frequency() * self.hinge_inertia()
    }

    /// χ = K_el L / (2 E I) times `moment_scale`: the static angle is the exact tip deflection.
    pub fn hinge_moment_scale(&self) -> f64 {
        let ei = self.youngs_modulus * self.bending_inertia();
        self.moment_scale * self.hinge_stiffness() * self.length / (2.0 * ei)
    }

    /// The thermal moment on the hinge per kelvin of T_m, χ π E a h r², N m/K.
    pub fn moment_per_kelvin(&self) -> f64 {
        self.hinge_moment_scale() * self.physical_moment_per_kelvin()
    }

    /// This boom with the conductivity that gives B = ω₁ τ = `ratio` (Boley's ratio of the
    /// thermal to the structural response time): k = (ρ c h/τ − radiation) r² / (η h) with
    /// τ = ratio/ω₁. Refused beyond the radiation's own time constant (k would be negative).
    pub fn with_response_time_ratio(&self, ratio: f64) -> Result<Boom> {
        let tau = ratio / self.first_angular_frequency();
        let conduction = self.heat_capacity() / tau - self.radiation_relaxation();
        let most =
            self.first_angular_frequency() * self.heat_capacity() / self.radiation_relaxation();
        if !(ratio.is_finite() && ratio > 0.0 && conduction >= 0.0) {
            return Err(Error::invalid(
                "ratio",
                ratio,
                &format!(
                    "must be in (0, {most:.6e}]: beyond it the radiation alone relaxes T_m \
                     faster (no conductivity gives it)"
                ),
            ));
        }
        let b = Boom {
            conductivity: conduction * self.radius * self.radius
                / (self.conduction_scale * self.wall),
            ..*self
        };
        b.validate()?;
        Ok(b)
    }

    /// A panel with the boom's hinge (inertia, stiffness and damping): what the runs of whole
    /// orbits read of a panel (the hinge's period, which caps the step, and its fastest start).
    pub fn hinge_panel(&self) -> Panel {
        let arm = self.length / 4.0;
        Panel {
            length: self.length,
            // 2 m l³/3 = I_B.
            mass_per_length: 1.5 * self.hinge_inertia() / (arm * arm * arm),
            hinge_stiffness: self.hinge_stiffness(),
            damping: self.hinge_damping(),
            ..Panel::paper()
        }
    }
}

/// The cantilever's frequency function 1 + cos β cosh β + μ β (cos β sinh β − sin β cosh β).
fn frequency_function(beta: f64, mu: f64) -> f64 {
    let (s, c) = beta.sin_cos();
    let (sh, ch) = (beta.sinh(), beta.cosh());
    1.0 + c * ch + mu * beta * (c * sh - s * ch)
}

/// β₁L of a cantilever whose tip carries μ times the beam's mass: the first root of
/// [`frequency_function`], by bisection (positive near 0, not positive at 1.8751, the root
/// without tip mass, which the tip mass only lowers).
pub fn cantilever_beta1(mu: f64) -> f64 {
    let (mut lo, mut hi) = (1e-4, 1.875_104_068_711_961);
    if mu == 0.0 {
        return hi;
    }
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if frequency_function(mid, mu) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= 1e-15 * hi {
            break;
        }
    }
    0.5 * (lo + hi)
}

/// ∫₀¹ φ² dξ of the first cantilever mode at β = `beta` scaled to φ(1) = 1 (moment-free tip:
/// φ = cosh βξ − cos βξ − σ (sinh βξ − sin βξ), σ = (cosh β + cos β)/(sinh β + sin β)), by
/// Simpson's rule on 2048 intervals (relative error ~1e-13).
pub fn cantilever_modal_mass(beta: f64) -> f64 {
    let sigma = (beta.cosh() + beta.cos()) / (beta.sinh() + beta.sin());
    let phi = |x: f64| {
        let b = beta * x;
        b.cosh() - b.cos() - sigma * (b.sinh() - b.sin())
    };
    let n = 2048;
    let h = 1.0 / n as f64;
    let mut sum = phi(0.0).powi(2) + phi(1.0).powi(2);
    for i in 1..n {
        let w = if i % 2 == 1 { 4.0 } else { 2.0 };
        sum += w * phi(i as f64 * h).powi(2);
    }
    sum * h / 3.0 / phi(1.0).powi(2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_example_is_valid_and_round_trips() {
        let b = Boom::example();
        b.validate().unwrap();
        for name in Boom::FIELDS {
            let mut c = b;
            c.set(name, 0.125).unwrap();
            assert_eq!(c.get(name).unwrap(), 0.125);
            let mut c = b;
            c.set(name, f64::NAN).unwrap();
            assert!(c.validate().unwrap_err().to_string().starts_with(name));
        }
        assert!(b.get("colour").is_err());
    }

    #[test]
    fn a_thick_wall_and_a_sun_behind_are_refused() {
        let b = Boom {
            wall: 0.3 * Boom::example().radius,
            ..Boom::example()
        };
        assert!(b.validate().unwrap_err().to_string().starts_with("wall"));
        let b = Boom {
            solar_inclination: PI,
            ..Boom::example()
        };
        assert!(b.validate().is_err());
    }

    #[test]
    fn the_cantilever_without_tip_mass_is_the_textbooks() {
        // β₁L = 1.87510407 (root of 1 + cos β cosh β = 0); every clamped–free mode has
        // ∫₀¹ φ² dξ = φ(1)²/4, so the modal mass at the tip is m L / 4 and K_el = ω₁² I_B =
        // (β₁L)⁴/4 · E I/L = 3.09 E I/L, the static tip stiffness 3 E I/L³ times L² to 3 % (the
        // single mode's own static error).
        let b = cantilever_beta1(0.0);
        assert!((1.0 + b.cos() * b.cosh()).abs() < 1e-12);
        let modal = cantilever_modal_mass(b);
        assert!((modal - 0.25).abs() < 1e-10, "{modal}");
        let boom = Boom::example();
        let k =
            boom.hinge_stiffness() / (boom.youngs_modulus * boom.bending_inertia() / boom.length);
        assert!((k - 3.0).abs() < 0.1, "{k}");
    }

    #[test]
    fn a_heavy_tip_mass_gives_the_spring_mass_frequency() {
        // μ ≫ 1: the tip mass on the beam's static stiffness 3 E I / L³ (the beam's own mass
        // adds 33/140 of it to the tip mass).
        let mut boom = Boom::example();
        boom.tip_mass = 1000.0 * boom.mass_per_length() * boom.length;
        let ei = boom.youngs_modulus * boom.bending_inertia();
        let k = 3.0 * ei / boom.length.powi(3);
        let m = boom.tip_mass + 33.0 / 140.0 * boom.mass_per_length() * boom.length;
        let w = (k / m).sqrt();
        assert!((boom.first_angular_frequency() / w - 1.0).abs() < 1e-5);
    }
}
