//! The panel: every parameter of the paper's Table 1, plus the solar constant and the χ scaling of
//! the thermal moment. Validation returns errors; nothing here panics.

use crate::error::{short, Error, Result};

/// The panel's parameters, one row each: its doc, name, Table 1 value and valid range
/// `(low, high, low end open)` (the high end is closed). The struct, [`Panel::paper`],
/// [`Panel::FIELDS`], [`Panel::get`], [`Panel::set`] and [`Panel::RANGES`] are all made from this
/// one table, so a new parameter is one row here (and one line in the Python `Panel`).
macro_rules! panel_parameters {
    ($( $(#[$doc:meta])* $name:ident = $paper:expr, in ($low:expr, $high:expr, $open:expr); )*) => {
        /// How many parameters a panel has.
        const PANEL_PARAMETERS: usize = [$( stringify!($name), )*].len();

        /// A long, thin, Sun-pointing plate of unit width (all quantities SI).
        ///
        /// The thermal equations are per unit area; the hinge model uses `mass_per_length`,
        /// `bending_inertia` and `hinge_stiffness` of the whole panel, as in the paper (width 1 m).
        #[derive(Debug, Clone, Copy, PartialEq)]
        pub struct Panel {
            $( $(#[$doc])* pub $name: f64, )*
        }

        impl Panel {
            /// The paper's Table 1 panel (Case B: ε_f = 0.8 > ε_b = 0.3), C = 1361 W/m².
            pub fn paper() -> Self {
                Panel { $( $name: $paper, )* }
            }

            /// The field names, in declaration order (the Python layer and scenario files use
            /// them).
            pub const FIELDS: [&'static str; PANEL_PARAMETERS] = [$( stringify!($name), )*];

            /// Sets a field by name (used by bindings and parameter sweeps).
            pub fn set(&mut self, name: &str, value: f64) -> Result<()> {
                match name {
                    $( stringify!($name) => self.$name = value, )*
                    _ => return Err(not_a_parameter(name)),
                }
                Ok(())
            }

            /// Reads a field by name.
            pub fn get(&self, name: &str) -> Result<f64> {
                match name {
                    $( stringify!($name) => Ok(self.$name), )*
                    _ => Err(not_a_parameter(name)),
                }
            }

            /// The physical range of each parameter: (name, low, high, low end open); the high
            /// end is closed. The ranges are wide (a thin film to a truss boom, polymers to
            /// steel) but finite: values outside them are unit slips or typing errors, and would
            /// make the model meaningless or the integration endless.
            pub const RANGES: [(&'static str, f64, f64, bool); PANEL_PARAMETERS] =
                [$( (stringify!($name), $low, $high, $open), )*];
        }
    };
}

/// Refuses `v` outside `(low, high, low end open)` (the high end closed), naming `name`: the
/// one range check of the panel's and the boom's parameter tables.
pub(crate) fn check_in_range(name: &str, v: f64, range: (f64, f64, bool)) -> Result<()> {
    let (low, high, open) = range;
    let above_low = if open { v > low } else { v >= low };
    if v.is_finite() && above_low && v <= high {
        return Ok(());
    }
    let (low, high) = (short(low), short(high));
    let range = if open {
        format!("must be in ({low}, {high}]")
    } else {
        format!("must be in [{low}, {high}]")
    };
    Err(Error::invalid(name, v, &range))
}

fn not_a_parameter(name: &str) -> Error {
    Error::invalid("parameter", name, "is not a panel parameter")
}

panel_parameters! {
    /// ε_f, emissivity of the Sun-facing side, in (0, 1].
    emissivity_front = 0.8, in (0.0, 1.0, true);
    /// ε_b, emissivity of the back side, in (0, 1].
    emissivity_back = 0.3, in (0.0, 1.0, true);
    /// α, solar absorptivity of the front side, in (0, 1].
    absorptivity = 0.8, in (0.0, 1.0, true);
    /// c, specific heat, J/(kg K).
    specific_heat = 900.0, in (10.0, 1e5, false);
    /// m, mass per unit length (unit width, so also per unit area), kg/m.
    mass_per_length = 5.51, in (1e-3, 1e4, false);
    /// a, coefficient of thermal expansion, 1/K: any sign within ±[`MAX_EXPANSION`] (carbon
    /// fibre shrinks when heated, and CFRP booms are designed around a ≈ −1e-6 1/K; 0 bends by
    /// nothing).
    expansion_coeff = 2.5e-5, in (-MAX_EXPANSION, MAX_EXPANSION, false);
    /// L, panel length, m (hinge half-arm l = L/4).
    length = 50.0, in (0.1, 1e4, false);
    /// E, Young's modulus, Pa.
    youngs_modulus = 70e9, in (1e6, 1e13, false);
    /// d, thickness, m.
    thickness = 0.04, in (1e-5, 10.0, false);
    /// w, width, m.
    width = 1.0, in (1e-3, 1e3, false);
    /// K, conductance through the thickness per unit area, W/(m² K).
    conductance = 25.0, in (0.0, 1e6, true);
    /// K_el, rotational stiffness of the hinge, N m/rad.
    hinge_stiffness = 4438.0, in (0.0, 1e12, true);
    /// I, second moment of area of the cross-section, m⁴.
    bending_inertia = 8e-7, in (0.0, 1e3, true);
    /// c_d, rotational damping of the hinge, N m s/rad (>= 0).
    damping = 3.0, in (0.0, 1e9, false);
    /// C, solar flux at 1 au, W/m².
    solar_constant = 1361.0, in (0.0, 1e5, true);
    /// χ, scale of the flexural rigidity in the thermal moment (paper Sec. 4.3); 1 by default.
    moment_scale = 1.0, in (0.0, 100.0, true);
    /// α_b, solar absorptivity of the back side, in (0, 1]: what it absorbs of sunlight and of
    /// the Earth's albedo when they reach it (Table 1 has one absorptivity: the same value).
    absorptivity_back = 0.8, in (0.0, 1.0, true);
}

impl Panel {
    /// The paper's Case A: Table 1 with the emissivities swapped (ε_f = 0.3, ε_b = 0.8).
    pub fn case_a() -> Self {
        let b = Panel::paper();
        Panel {
            emissivity_front: b.emissivity_back,
            emissivity_back: b.emissivity_front,
            ..b
        }
    }

    /// The fastest rate the model may have, 1/s: the hinge's natural angular frequency, its
    /// damping rate c_d/I_B and the thermal rate 2K/(m c) are each at most this. Beyond it an
    /// explicit integrator needs more than ~10⁸ steps per orbit (the paper's panel: 0.8 rad/s).
    pub const MAX_RATE: f64 = 1e3;

    /// Checks every parameter against [`Panel::RANGES`], then the rates against
    /// [`Panel::MAX_RATE`]; the first offending parameter is named in the error.
    pub fn validate(&self) -> Result<()> {
        for (name, low, high, open) in Self::RANGES {
            check_in_range(name, self.get(name)?, (low, high, open))?;
        }
        let rates = [
            (
                "hinge_stiffness",
                self.hinge_stiffness,
                self.natural_angular_frequency(),
                "the hinge's natural angular frequency sqrt(K_el/I_B)",
            ),
            (
                "damping",
                self.damping,
                self.damping_rate(),
                "the damping rate c_d/I_B",
            ),
            (
                "conductance",
                self.conductance,
                2.0 * self.conductance / self.heat_capacity(),
                "the conduction rate 2K/(m c)",
            ),
        ];
        for (name, value, rate, what) in rates {
            if rate.is_nan() || rate > Self::MAX_RATE {
                return Err(Error::invalid(
                    name,
                    value,
                    &format!(
                        "gives {what} = {rate:.3e} 1/s with the other parameters; at most {:e} 1/s",
                        Self::MAX_RATE
                    ),
                ));
            }
        }
        Ok(())
    }

    /// l = L/4, half the length of one rigid half of the hinge model, m.
    pub fn half_arm(&self) -> f64 {
        self.length / 4.0
    }

    /// I_B = 2 m l³ / 3, inertia of the hinge model about its hinge, kg m².
    pub fn hinge_inertia(&self) -> f64 {
        let l = self.half_arm();
        2.0 * self.mass_per_length * l * l * l / 3.0
    }

    /// Thermal moment per kelvin of gradient, χ a E I / d, N m/K.
    pub fn moment_per_kelvin(&self) -> f64 {
        self.moment_scale * self.expansion_coeff * self.youngs_modulus * self.bending_inertia
            / self.thickness
    }

    /// Heat capacity per unit area, m c, J/(m² K).
    pub fn heat_capacity(&self) -> f64 {
        self.mass_per_length * self.specific_heat
    }

    /// E I / L, N m/rad: the unit in which the paper states hinge stiffnesses (K_el ≈ 5.21 E I / L
    /// by the frequency criterion).
    pub fn rigidity_per_length(&self) -> f64 {
        self.youngs_modulus * self.bending_inertia / self.length
    }

    /// 4 E I / L, N m/rad: the small-angle deflection criterion's K_el, the hinge stiffness of
    /// the continuous panel's bending under end moments. (The factor 4 is a power of two: the
    /// product is the same to the bit as 4 E I / L written out.)
    pub fn flexural_stiffness(&self) -> f64 {
        4.0 * self.rigidity_per_length()
    }

    /// χ = K_el / (4 E I / L): the scale of the flexural rigidity in the thermal moment that
    /// gives the hinge, with its own K_el, the continuous panel's static deflection (paper
    /// Sec. 4.3, χ ≈ 1.3 with the frequency criterion's K_el).
    pub fn matching_moment_scale(&self) -> f64 {
        self.hinge_stiffness / self.flexural_stiffness()
    }

    /// c_d / I_B, the hinge's damping rate, 1/s: the one place it is computed.
    pub fn damping_rate(&self) -> f64 {
        self.damping / self.hinge_inertia()
    }

    /// K_el / I_B = ω_n², the hinge's stiffness rate, 1/s².
    pub fn stiffness_rate(&self) -> f64 {
        self.hinge_stiffness / self.hinge_inertia()
    }

    /// Natural angular frequency of the linearised hinge, sqrt(K_el / I_B), rad/s.
    pub fn natural_angular_frequency(&self) -> f64 {
        self.stiffness_rate().sqrt()
    }
}

/// |a| of a panel or a laminate layer at most, 1/K: ten times that of any solid (the largest,
/// of rubbers, are ~2e-4); beyond it the value is a percentage or a unit slip.
pub const MAX_EXPANSION: f64 = 1e-3;

/// How K_el is chosen (paper Sec. 4 and 4.3; MODEL.md "Choosing K_el").
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StiffnessCriterion {
    /// Equal mid-span deflection under the steady thermal moment: K_el = M_T / asin(M_T L/(4EI)).
    Deflection,
    /// Small-angle limit of the deflection criterion: K_el = 4 E I / L.
    DeflectionSmallAngle,
    /// Equal first free–free bending frequency: K_el = (β₁L)⁴ E I I_B / (m L⁴) ≈ 5.21 E I / L.
    Frequency,
}

/// β₁L of the first free–free bending mode of a uniform beam (root of cos x cosh x = 1).
pub const BETA1_L: f64 = 4.730_040_744_862_704;

/// First free–free bending angular frequency of the continuous panel, rad/s.
pub fn beam_first_angular_frequency(panel: &Panel) -> f64 {
    let ei = panel.youngs_modulus * panel.bending_inertia;
    let l4 = panel.length.powi(4);
    BETA1_L * BETA1_L * (ei / (panel.mass_per_length * l4)).sqrt()
}

/// K_el by `criterion`. The deflection criterion needs the thermal moment it is matched at
/// (`moment`, N m); use the steady sunlit moment for the paper's choice.
pub fn hinge_stiffness(panel: &Panel, criterion: StiffnessCriterion, moment: f64) -> Result<f64> {
    panel.validate()?;
    let ei = panel.youngs_modulus * panel.bending_inertia;
    match criterion {
        StiffnessCriterion::DeflectionSmallAngle => Ok(panel.flexural_stiffness()),
        StiffnessCriterion::Frequency => {
            let w1 = beam_first_angular_frequency(panel);
            Ok(w1 * w1 * panel.hinge_inertia())
        }
        StiffnessCriterion::Deflection => {
            let x = moment.abs() * panel.length / (4.0 * ei);
            if !moment.is_finite() || x >= 1.0 {
                return Err(Error::invalid(
                    "moment",
                    moment,
                    "is too large for the deflection criterion (M_T L / 4EI must be < 1)",
                ));
            }
            if x < 1e-12 {
                Ok(panel.flexural_stiffness())
            } else {
                Ok(moment.abs() / x.asin())
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paper_panel_is_valid() {
        Panel::paper().validate().unwrap();
    }

    #[test]
    fn expansion_of_either_sign_is_physical() {
        for a in [-MAX_EXPANSION, -2.4e-8, 0.0, MAX_EXPANSION] {
            let p = Panel {
                expansion_coeff: a,
                ..Panel::paper()
            };
            p.validate().unwrap();
            // The deflection criterion divides by no moment: none gives 4 E I / L.
            let k = hinge_stiffness(&p, StiffnessCriterion::Deflection, 0.0).unwrap();
            assert_eq!(k, p.flexural_stiffness());
        }
        for a in [-1.01 * MAX_EXPANSION, 1.01 * MAX_EXPANSION] {
            let p = Panel {
                expansion_coeff: a,
                ..Panel::paper()
            };
            assert!(p.validate().is_err());
        }
    }

    #[test]
    fn table_1_rigidity_per_length_is_1120() {
        // E I / L = 70e9 Pa · 8e-7 m⁴ / 50 m = 1120 N m/rad, by hand from Table 1; 4 E I / L is
        // the 4480 N m/rad of the small-angle deflection criterion.
        let p = Panel::paper();
        assert!((p.rigidity_per_length() - 1120.0).abs() <= 1e-12 * 1120.0);
        assert!((p.flexural_stiffness() - 4480.0).abs() <= 1e-12 * 4480.0);
    }

    #[test]
    fn every_field_round_trips_and_is_checked() {
        for name in Panel::FIELDS {
            let mut p = Panel::paper();
            p.set(name, 0.5).unwrap();
            assert_eq!(p.get(name).unwrap(), 0.5);
            for bad in [f64::NAN, f64::INFINITY, -1.0] {
                let mut p = Panel::paper();
                p.set(name, bad).unwrap();
                let err = p.validate().unwrap_err();
                assert!(err.to_string().starts_with(name), "{err}");
            }
        }
        let mut p = Panel::paper();
        p.set("emissivity_back", 1.5).unwrap();
        assert!(p.validate().is_err());
        let mut p = Panel::paper();
        p.set("damping", 0.0).unwrap();
        assert!(p.validate().is_ok());
        assert!(Panel::paper().set("colour", 1.0).is_err());
    }

    #[test]
    fn stiffness_criteria_match_model_sheet() {
        let p = Panel::paper();
        let ei = 70e9 * 8e-7;
        let small = hinge_stiffness(&p, StiffnessCriterion::DeflectionSmallAngle, 0.0).unwrap();
        assert!((small - 4.0 * ei / 50.0).abs() < 1e-9);
        let freq = hinge_stiffness(&p, StiffnessCriterion::Frequency, 0.0).unwrap();
        assert!(
            (freq / (ei / 50.0) - 5.21).abs() < 0.01,
            "{}",
            freq / (ei / 50.0)
        );
        // The exact deflection criterion softens the spring as the moment grows.
        let exact = hinge_stiffness(&p, StiffnessCriterion::Deflection, 400.0).unwrap();
        assert!(exact < small && exact > 0.99 * small);
    }

    #[test]
    fn beam_frequency_is_the_papers() {
        let f = beam_first_angular_frequency(&Panel::paper()) / (2.0 * std::f64::consts::PI);
        assert!((f - 0.144).abs() < 0.0005, "{f}");
    }
}
