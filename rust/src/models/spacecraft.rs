//! A spacecraft: a rigid bus turning about one axis, carrying N hinged appendages, each the
//! paper's panel (two layers, eq. 2, on the linear hinge, eq. 28), coupled to the bus's attitude.
//!
//! # Model and assumptions
//!
//! - **Planar.** The bus turns about one axis z (its attitude φ, rad); every hinge axis is
//!   parallel to it, with a sense s_i = ±1 (the hinge model's θ_i turns appendage i about +z by
//!   u_i = s_i θ_i). The Sun lies in the plane normal to z; at φ = θ_i = 0 every panel's front
//!   faces it (the paper's Sun-pointing plate), so the incidence of panel i is its absolute
//!   attitude φ + u_i, and its absorbed flux is scaled by max(cos(φ + u_i), 0) (the front alone
//!   is heated: beyond 90° it is in its own shade).
//! - **The bus's centre O is fixed** in inertial space: O is taken as the system's centre of
//!   mass, and the bus's translation in reaction to the appendages' swing is neglected (it
//!   changes the attitude at second order in the appendages' mass over the spacecraft's).
//!   The pin at O then carries no moment about z, so the angular momentum about O is exchanged
//!   between the bus and the appendages only.
//! - **An appendage is rigid on its hinge**, its mass m_i = (mass per length) L (the panel's mass
//!   as the hinge model counts it) lumped at its radius of gyration about the hinge,
//!   ρ_i = sqrt(I_B/m_i) (= l/√6 for the uniform panel), on the line from the bus axis through
//!   the hinge (radially outward), so that its inertia about the hinge is the hinge model's own
//!   I_B = 2 m l³/3. Its hinge is at distance r_i from the bus axis, with the hinge model's spring
//!   K_el and damper c_d and the thermal moment M_T = χ a E I (T_f − T_b)/d between the bus and
//!   the appendage. The hinge is the linear model (eq. 28); its non-linear factor 1 + 3 sin²θ
//!   (eq. 20) is of second order in θ and left out, like the bus's translation.
//!
//! # Equations (from the kinetic energy)
//!
//! The lumped mass of appendage i is at p_i = R(φ)(r_i + ρ_i R(u_i) e_i), e_i = r_i/|r_i|:
//!
//! ```text
//! T = ½ J₀ φ̇² + Σ_i ½ m_i [ r_i² φ̇² + ρ_i² (φ̇ + u̇_i)² + 2 r_i ρ_i cos u_i φ̇ (φ̇ + u̇_i) ]
//! V = Σ_i ½ K_el,i θ_i²,        generalised forces: τ on φ, s_i (M_T,i − c_d,i θ̇_i) on u_i
//! ```
//!
//! With h_i = m_i ρ_i r_i (the hinge offset's coupling) and I_B,i = m_i ρ_i², the mass matrix of
//! (φ, u_1 … u_N) is an arrowhead:
//!
//! ```text
//! M_φφ  = J₀ + Σ_i (m_i r_i² + I_B,i + 2 h_i cos u_i)     (the inertia about the bus axis)
//! M_φu_i = I_B,i + h_i cos u_i,      M_u_i u_i = I_B,i
//! ```
//!
//! and Lagrange's equations are
//!
//! ```text
//! M_φφ φ̈ + Σ_i M_φu_i ü_i = τ + Σ_i h_i sin u_i u̇_i (2 φ̇ + u̇_i)
//! M_φu_i φ̈ + I_B,i ü_i    = s_i (M_T,i − c_d,i θ̇_i − K_el,i θ_i) − h_i sin u_i φ̇²
//! ```
//!
//! φ is cyclic, so with τ = 0 the angular momentum about O, H = M_φφ φ̇ + Σ_i M_φu_i u̇_i, is
//! conserved. The arrowhead is solved in O(N) by its Schur complement,
//! D = M_φφ − Σ M_φu_i²/I_B,i = J₀ + Σ m_i r_i² sin² u_i (written in this form, which has no
//! cancellation). With the bus infinitely heavy (J₀ = ∞) φ̈ = 0 exactly and each hinge's θ̈ is
//! the paper model's (eq. 28) to the bit.
//!
//! The reaction torque of appendage i on the bus is −dH_i/dt, H_i its angular momentum about O:
//! J₀ φ̈ = τ + Σ_i τ_i.
//!
//! The attitude controller (optional) is a PD on φ: τ = τ_d − K_p φ − K_d φ̇ with K_p = J ω_c²,
//! K_d = 2 ζ ω_c J for a bandwidth ω_c (rad/s) and damping ratio ζ, J = M_φφ at rest (u = 0);
//! τ_d is a constant disturbance torque. Against τ_d alone the bus settles at φ = τ_d / K_p.

use crate::error::{require_finite, require_non_negative, require_positive, Error, Result};
use crate::inputs::orbit::Orbit;
use crate::inputs::panel::Panel;
use crate::models::coupled::Sunlight;
use crate::models::hinge::{check_start_state, sin_cos, Hinge, HingeModel, StructuralModel};
use crate::models::thermal::{ThermalModel, TwoLayer};
use crate::numerics::integrate::{OdeSystem, State};
use nalgebra::{Dyn, U1};

/// Arcseconds in a radian, 648000/π: the unit an attitude engineer reads pointing in.
pub const ARCSEC_PER_RADIAN: f64 = 648_000.0 / std::f64::consts::PI;

/// States of the bus (φ, φ̇) at the head of the state vector.
pub const BUS_STATES: usize = 2;

/// States of each appendage after the bus's: (T_f, T_b, θ, θ̇).
pub const APPENDAGE_STATES: usize = 4;

/// One hinged appendage: a panel, its hinge's distance from the bus axis and its sense.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Appendage {
    pub panel: Panel,
    /// r, distance of the hinge from the bus axis, m (>= 0).
    pub offset: f64,
    /// s: +1 when the hinge turns the appendage about the bus axis, −1 about its opposite.
    pub sense: f64,
}

impl Appendage {
    /// m = (mass per length) L, kg: the panel's mass as the hinge model counts it.
    pub fn mass(&self) -> f64 {
        self.panel.mass_per_length * self.panel.length
    }

    /// ρ = sqrt(I_B/m), m: where the appendage's mass is lumped, from its hinge.
    pub fn gyration_radius(&self) -> f64 {
        (self.panel.hinge_inertia() / self.mass()).sqrt()
    }

    /// h = m ρ r, kg m²: the coupling of the hinge's offset.
    pub fn offset_coupling(&self) -> f64 {
        self.mass() * self.gyration_radius() * self.offset
    }

    /// m (r + ρ)², kg m²: the appendage's inertia about the bus axis at rest (θ = 0).
    pub fn inertia_about_bus_axis(&self) -> f64 {
        let arm = self.offset + self.gyration_radius();
        self.mass() * arm * arm
    }

    /// Checks the panel, the offset (finite, >= 0) and the sense (±1); names carry the index.
    pub fn validate(&self, index: usize) -> Result<()> {
        self.panel.validate().map_err(|e| match e {
            Error::InvalidParameter {
                name,
                value,
                reason,
            } => Error::InvalidParameter {
                name: format!("appendages[{index}].panel.{name}"),
                value,
                reason,
            },
            other => other,
        })?;
        require_non_negative(&format!("appendages[{index}].offset"), self.offset)?;
        if self.sense != 1.0 && self.sense != -1.0 {
            return Err(Error::invalid(
                &format!("appendages[{index}].sense"),
                self.sense,
                "must be +1 or -1 (the hinge axis along the bus axis or against it)",
            ));
        }
        Ok(())
    }
}

/// A proportional-derivative attitude controller by its closed-loop bandwidth ω_c (rad/s) and
/// damping ratio ζ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pd {
    pub bandwidth: f64,
    pub damping: f64,
}

impl Pd {
    pub fn validate(&self) -> Result<()> {
        require_positive("controller.bandwidth", self.bandwidth)?;
        require_non_negative("controller.damping", self.damping)
    }

    /// (K_p, K_d) = (J ω_c², 2 ζ ω_c J) for the inertia J, N m/rad and N m s/rad.
    pub fn gains(&self, inertia: f64) -> (f64, f64) {
        let w = self.bandwidth;
        (inertia * w * w, 2.0 * self.damping * w * inertia)
    }
}

/// The bus, its appendages and its controller.
#[derive(Debug, Clone, PartialEq)]
pub struct Spacecraft {
    /// J₀, the bus's inertia about its axis, kg m² (> 0; ∞ for a bus that does not turn).
    pub bus_inertia: f64,
    pub appendages: Vec<Appendage>,
    pub controller: Option<Pd>,
}

/// Most appendages a spacecraft may carry.
pub const MAX_APPENDAGES: usize = 64;

impl Spacecraft {
    pub fn validate(&self) -> Result<()> {
        if self.bus_inertia.is_nan() || self.bus_inertia <= 0.0 {
            return Err(Error::invalid(
                "bus_inertia",
                self.bus_inertia,
                "must be > 0 kg m² (inf for a bus that does not turn)",
            ));
        }
        if self.appendages.len() > MAX_APPENDAGES {
            return Err(Error::invalid(
                "appendages",
                self.appendages.len(),
                &format!("must hold at most {MAX_APPENDAGES} appendages"),
            ));
        }
        for (i, a) in self.appendages.iter().enumerate() {
            a.validate(i)?;
        }
        if let Some(pd) = &self.controller {
            pd.validate()?;
            if self.bus_inertia.is_infinite() {
                return Err(Error::invalid(
                    "controller",
                    "PD",
                    "cannot act on a bus of infinite inertia (it does not turn)",
                ));
            }
        }
        Ok(())
    }

    /// J = J₀ + Σ m_i (r_i + ρ_i)², the inertia about the bus axis at rest, kg m².
    pub fn inertia_at_rest(&self) -> f64 {
        self.bus_inertia
            + self
                .appendages
                .iter()
                .map(Appendage::inertia_about_bus_axis)
                .sum::<f64>()
    }

    /// (K_p, K_d) of the controller, if any ([`Pd::gains`] with [`Spacecraft::inertia_at_rest`]).
    pub fn gains(&self) -> Option<(f64, f64)> {
        self.controller.map(|pd| pd.gains(self.inertia_at_rest()))
    }

    /// Checks a value that acts on the bus (a torque, a rate): finite, and 0 on a bus of
    /// infinite inertia, which does not turn.
    pub fn check_bus_value(&self, name: &str, value: f64) -> Result<()> {
        require_finite(name, value)?;
        if value != 0.0 && self.bus_inertia.is_infinite() {
            return Err(Error::invalid(
                name,
                value,
                "must be 0 on a bus of infinite inertia",
            ));
        }
        Ok(())
    }

    /// The state's size: 2 + 4 N.
    pub fn size(&self) -> usize {
        BUS_STATES + APPENDAGE_STATES * self.appendages.len()
    }
}

/// What the right-hand side uses of one appendage, its coefficients folded once.
#[derive(Debug, Clone, Copy)]
struct Member {
    thermal: TwoLayer,
    hinge: Hinge,
    /// M_T per kelvin over I_B.
    load_per_kelvin: f64,
    sense: f64,
    /// m r², I_B, h, h / I_B.
    mr2: f64,
    inertia: f64,
    coupling: f64,
    coupling_rate: f64,
}

/// The bus's and the hinges' accelerations in a state, with what the reaction torques need.
#[derive(Debug, Clone, PartialEq)]
pub struct Accelerations {
    /// φ̈, rad/s².
    pub bus: f64,
    /// θ̈ of each hinge, rad/s².
    pub hinges: Vec<f64>,
}

/// The spacecraft driven by the orbit's Sun: state (φ, φ̇, then (T_f, T_b, θ, θ̇) per appendage).
#[derive(Debug, Clone)]
pub struct SpacecraftSystem {
    bus_inertia: f64,
    members: Vec<Member>,
    gains: Option<(f64, f64)>,
    /// τ_d, N m.
    disturbance: f64,
    sun: Sunlight,
}

impl SpacecraftSystem {
    /// The system of `craft` under a constant disturbance torque `disturbance` (N m) on the bus.
    pub fn new(craft: &Spacecraft, orbit: Orbit, disturbance: f64) -> Result<Self> {
        craft.validate()?;
        craft.check_bus_value("disturbance", disturbance)?;
        let members = craft
            .appendages
            .iter()
            .map(|a| {
                let thermal = TwoLayer::new(&a.panel);
                let hinge = Hinge::new(&a.panel, HingeModel::Linear);
                let inertia = a.panel.hinge_inertia();
                let coupling = a.offset_coupling();
                Member {
                    load_per_kelvin: thermal.moment_per_kelvin() / hinge.inertia(),
                    thermal,
                    hinge,
                    sense: a.sense,
                    mr2: a.mass() * a.offset * a.offset,
                    inertia,
                    coupling,
                    coupling_rate: coupling / inertia,
                }
            })
            .collect();
        Ok(SpacecraftSystem {
            bus_inertia: craft.bus_inertia,
            members,
            gains: craft.gains(),
            disturbance,
            sun: Sunlight::new(orbit),
        })
    }

    pub fn orbit(&self) -> &Orbit {
        &self.sun.orbit
    }

    /// Whether the bus has infinite inertia (it does not turn).
    pub fn bus_is_fixed(&self) -> bool {
        self.bus_inertia.is_infinite()
    }

    pub fn size(&self) -> usize {
        BUS_STATES + APPENDAGE_STATES * self.members.len()
    }

    /// Names of the state's components.
    pub fn names(&self) -> Vec<String> {
        let mut names = vec!["phi".to_string(), "phi_dot".to_string()];
        for i in 0..self.members.len() {
            for n in ["T_front", "T_back", "theta", "theta_dot"] {
                names.push(format!("{n}[{i}]"));
            }
        }
        names
    }

    /// The external torque on the bus, τ = τ_d − K_p φ − K_d φ̇, N m.
    pub fn bus_torque(&self, phi: f64, phi_dot: f64) -> f64 {
        match self.gains {
            Some((kp, kd)) => self.disturbance - kp * phi - kd * phi_dot,
            None => self.disturbance,
        }
    }

    /// Refuses a start state of the wrong size, a temperature not above 0 K, a hinge out of its
    /// range, or a bus that cannot turn given a rate.
    pub fn check_start(&self, y: &[f64]) -> Result<()> {
        if y.len() != self.size() {
            return Err(Error::invalid(
                "y0",
                format!("{} components", y.len()),
                &format!(
                    "must have {} (φ, φ̇, then T_f, T_b, θ, θ̇ per appendage)",
                    self.size()
                ),
            ));
        }
        if self.bus_inertia.is_infinite() && (y[0] != 0.0 || y[1] != 0.0) {
            return Err(Error::invalid(
                "y0[1]",
                y[1],
                "φ and φ̇ must be 0 on a bus of infinite inertia",
            ));
        }
        for (i, m) in self.members.iter().enumerate() {
            let base = BUS_STATES + APPENDAGE_STATES * i;
            check_start_state(&y[base..base + APPENDAGE_STATES], 2, Some(&m.hinge)).map_err(
                |e| match e {
                    Error::InvalidParameter {
                        name,
                        value,
                        reason,
                    } => Error::InvalidParameter {
                        name: shifted(&name, base),
                        value,
                        reason,
                    },
                    other => other,
                },
            )?;
        }
        Ok(())
    }

    /// Thermal moment of each appendage in state `y`, N m.
    pub fn moments(&self, y: &[f64]) -> Vec<f64> {
        self.members
            .iter()
            .enumerate()
            .map(|(i, m)| {
                let base = BUS_STATES + APPENDAGE_STATES * i;
                m.thermal.moment(&y[base..base + 2])
            })
            .collect()
    }

    /// φ̈ and every θ̈ in state `y` (they do not depend on the Sun).
    pub fn accelerations(&self, y: &[f64]) -> Accelerations {
        let mut hinge_rates = vec![0.0; self.members.len()];
        for (i, m) in self.members.iter().enumerate() {
            let base = BUS_STATES + APPENDAGE_STATES * i;
            let load = m.load_per_kelvin * m.thermal.gradient(&y[base..base + 2]);
            let mut out = [0.0; 2];
            m.hinge.rates(load, &y[base + 2..base + 4], &mut out);
            hinge_rates[i] = out[1];
        }
        let bus = self.bus_acceleration(y, &hinge_rates);
        for (i, m) in self.members.iter().enumerate() {
            let base = BUS_STATES + APPENDAGE_STATES * i;
            hinge_rates[i] = self.hinge_acceleration(m, y, base, hinge_rates[i], bus);
        }
        Accelerations {
            bus,
            hinges: hinge_rates,
        }
    }

    /// φ̈ from the state and each hinge's θ̈ on a clamped bus, `clamped` (the Schur complement
    /// of the arrowhead mass matrix).
    #[inline]
    fn bus_acceleration(&self, y: &[f64], clamped: &[f64]) -> f64 {
        let (phi, phi_dot) = (y[0], y[1]);
        let mut force = self.bus_torque(phi, phi_dot);
        let mut schur = self.bus_inertia;
        for (i, m) in self.members.iter().enumerate() {
            let base = BUS_STATES + APPENDAGE_STATES * i;
            let u = m.sense * y[base + 2];
            let u_dot = m.sense * y[base + 3];
            let (sn, cs) = sin_cos(u);
            let coupling = m.inertia + m.coupling * cs;
            // f_u / I_B = s θ̈_clamped − (h/I_B) sin u φ̇².
            let per_inertia = m.sense * clamped[i] - m.coupling_rate * sn * phi_dot * phi_dot;
            force += m.coupling * sn * u_dot * (2.0 * phi_dot + u_dot) - coupling * per_inertia;
            schur += m.mr2 * sn * sn;
        }
        force / schur
    }

    /// θ̈ of one hinge on the turning bus: θ̈_clamped − s (M_φu φ̈ + h sin u φ̇²)/I_B.
    #[inline]
    fn hinge_acceleration(
        &self,
        m: &Member,
        y: &[f64],
        base: usize,
        clamped: f64,
        bus: f64,
    ) -> f64 {
        let phi_dot = y[1];
        let (sn, cs) = sin_cos(m.sense * y[base + 2]);
        let coupling = m.inertia + m.coupling * cs;
        let bus_term = coupling * bus / m.inertia + m.coupling_rate * sn * phi_dot * phi_dot;
        clamped - m.sense * bus_term
    }

    /// The reaction torque of each appendage on the bus, −dH_i/dt, N m.
    pub fn reaction_torques(&self, y: &[f64], acc: &Accelerations) -> Vec<f64> {
        let (phi_dot, phi_dd) = (y[1], acc.bus);
        self.members
            .iter()
            .enumerate()
            .map(|(i, m)| {
                let base = BUS_STATES + APPENDAGE_STATES * i;
                let (u, u_dot, u_dd) = (
                    m.sense * y[base + 2],
                    m.sense * y[base + 3],
                    m.sense * acc.hinges[i],
                );
                let (sn, cs) = sin_cos(u);
                let own = m.mr2 + m.inertia + 2.0 * m.coupling * cs;
                let coupling = m.inertia + m.coupling * cs;
                let rates = m.coupling * sn * u_dot * (2.0 * phi_dot + u_dot);
                -(own * phi_dd + coupling * u_dd - rates)
            })
            .collect()
    }

    /// H = M_φφ φ̇ + Σ M_φu_i u̇_i, the angular momentum about the bus axis, kg m²/s; None for a
    /// bus of infinite inertia.
    pub fn angular_momentum(&self, y: &[f64]) -> Option<f64> {
        if self.bus_inertia.is_infinite() {
            return None;
        }
        let phi_dot = y[1];
        let mut h = self.bus_inertia * phi_dot;
        for (i, m) in self.members.iter().enumerate() {
            let base = BUS_STATES + APPENDAGE_STATES * i;
            let (u_dot, (_, cs)) = (m.sense * y[base + 3], sin_cos(m.sense * y[base + 2]));
            h += (m.mr2 + m.inertia + 2.0 * m.coupling * cs) * phi_dot
                + (m.inertia + m.coupling * cs) * u_dot;
        }
        Some(h)
    }

    /// The right-hand side at illumination `flux`, with the fused rates when `FUSED`.
    #[inline(always)]
    fn rhs_as<const FUSED: bool>(&self, flux: f64, y: &State<Dyn>) -> State<Dyn> {
        let n = self.size();
        let mut out = State::<Dyn>::zeros_generic(Dyn(n), U1);
        let ys = y.as_slice();
        let phi = ys[0];
        let o = out.as_mut_slice();
        let mut clamped = [0.0; MAX_APPENDAGES];
        for (i, m) in self.members.iter().enumerate() {
            let base = BUS_STATES + APPENDAGE_STATES * i;
            let (temps, q) = ys[base..base + APPENDAGE_STATES].split_at(2);
            let (temp_rates, q_rates) = o[base..base + APPENDAGE_STATES].split_at_mut(2);
            let load = m.load_per_kelvin * m.thermal.gradient(temps);
            if FUSED {
                m.hinge.rates_fused(load, q, q_rates);
            } else {
                m.hinge.rates(load, q, q_rates);
            }
            clamped[i] = q_rates[1];
            // The incidence is the absolute attitude φ + s θ (φ + s θ = ±θ exactly at φ = 0).
            let area = sin_cos(phi + m.sense * q[0]).1.max(0.0);
            if FUSED {
                m.thermal.rates_fused(flux * area, temps, temp_rates);
            } else {
                m.thermal.rates(flux * area, temps, temp_rates);
            }
        }
        let bus = self.bus_acceleration(ys, &clamped[..self.members.len()]);
        o[0] = ys[1];
        o[1] = bus;
        for (i, m) in self.members.iter().enumerate() {
            let base = BUS_STATES + APPENDAGE_STATES * i;
            o[base + 3] = self.hinge_acceleration(m, ys, base, clamped[i], bus);
        }
        out
    }

    /// The right-hand side at a given illumination factor.
    pub fn rhs_at_flux(&self, flux: f64, y: &State<Dyn>) -> State<Dyn> {
        self.rhs_as::<false>(flux, y)
    }
}

/// `y0[k]` of an appendage's own start state, renamed to its index in the whole state.
fn shifted(name: &str, base: usize) -> String {
    name.strip_prefix("y0[")
        .and_then(|rest| rest.strip_suffix(']'))
        .and_then(|k| k.parse::<usize>().ok())
        .map_or_else(|| name.to_string(), |k| format!("y0[{}]", base + k))
}

impl OdeSystem<Dyn> for SpacecraftSystem {
    #[inline(always)]
    fn rhs(&self, t: f64, y: &State<Dyn>) -> State<Dyn> {
        self.rhs_as::<false>(self.sun.flux(t), y)
    }
    #[inline(always)]
    fn rhs_fused(&self, t: f64, y: &State<Dyn>) -> State<Dyn> {
        self.rhs_as::<true>(self.sun.flux(t), y)
    }
    fn breakpoints(&self, t0: f64, t1: f64) -> Vec<f64> {
        self.sun.orbit.breakpoints(t0, t1)
    }
    fn check_span(&self, t0: f64, t1: f64) -> Result<()> {
        self.sun.orbit.check_span(t0, t1)
    }
    fn enter_segment(&mut self, a: f64, b: f64) {
        self.sun.enter(a, b);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::models::coupled::{Coupled, Coupling};
    use nalgebra::{DMatrix, DVector, Vector4};

    fn wing(offset: f64, sense: f64, length: f64) -> Appendage {
        Appendage {
            panel: Panel {
                length,
                ..Panel::paper()
            },
            offset,
            sense,
        }
    }

    fn craft(bus_inertia: f64) -> Spacecraft {
        Spacecraft {
            bus_inertia,
            appendages: vec![wing(2.0, 1.0, 50.0), wing(1.5, -1.0, 30.0)],
            controller: None,
        }
    }

    /// A state away from rest: both hinges deflected and moving, the bus turning.
    fn busy_state() -> Vec<f64> {
        vec![
            0.01, 2e-4, 370.0, 352.0, 0.09, 0.004, 340.0, 338.0, -0.05, -0.01,
        ]
    }

    #[test]
    fn the_schur_solve_is_the_full_mass_matrix_solve() {
        let sc = craft(5e4);
        let sys = SpacecraftSystem::new(&sc, Orbit::geo_equinox(), 3.0).unwrap();
        let y = busy_state();
        let acc = sys.accelerations(&y);
        // The (N+1)×(N+1) mass matrix and forces in (φ, u_i), written out from the Lagrangian.
        let n = sc.appendages.len();
        let mut mass = DMatrix::<f64>::zeros(n + 1, n + 1);
        let mut force = DVector::<f64>::zeros(n + 1);
        mass[(0, 0)] = sc.bus_inertia;
        force[0] = 3.0;
        let phi_dot = y[1];
        for (i, a) in sc.appendages.iter().enumerate() {
            let base = 2 + 4 * i;
            let (m, r, rho) = (a.mass(), a.offset, a.gyration_radius());
            let (u, u_dot) = (a.sense * y[base + 2], a.sense * y[base + 3]);
            mass[(0, 0)] += m * (r * r + rho * rho + 2.0 * r * rho * u.cos());
            mass[(0, i + 1)] = m * (rho * rho + r * rho * u.cos());
            mass[(i + 1, 0)] = mass[(0, i + 1)];
            mass[(i + 1, i + 1)] = m * rho * rho;
            let p = a.panel;
            let mt = p.moment_per_kelvin() * (y[base] - y[base + 1]);
            let q = mt - p.damping * y[base + 3] - p.hinge_stiffness * y[base + 2];
            force[0] += m * r * rho * u.sin() * u_dot * (2.0 * phi_dot + u_dot);
            force[i + 1] = a.sense * q - m * r * rho * u.sin() * phi_dot * phi_dot;
        }
        let qdd = mass.lu().solve(&force).unwrap();
        assert!(
            (acc.bus - qdd[0]).abs() < 1e-12 * qdd[0].abs(),
            "{} {}",
            acc.bus,
            qdd[0]
        );
        for (i, a) in sc.appendages.iter().enumerate() {
            let want = a.sense * qdd[i + 1];
            assert!((acc.hinges[i] - want).abs() < 1e-11 * want.abs(), "{i}");
        }
        // The bus's balance: J₀ φ̈ = τ + Σ reaction torques.
        let torques = sys.reaction_torques(&y, &acc);
        let sum: f64 = torques.iter().sum::<f64>() + 3.0;
        assert!((sc.bus_inertia * acc.bus - sum).abs() < 1e-10 * sum.abs().max(1.0));
    }

    #[test]
    fn the_angular_momentum_rate_is_the_external_torque() {
        // dH/dt = ∂H/∂y · ẏ, by central differences along the motion, must be τ.
        let sc = craft(5e4);
        let sys = SpacecraftSystem::new(&sc, Orbit::geo_equinox(), 2.5).unwrap();
        let y = DVector::from_vec(busy_state());
        let f = sys.rhs_at_flux(1.0, &y);
        let eps = 1e-4;
        let h = |s: f64| sys.angular_momentum((&y + s * &f).as_slice()).unwrap();
        let rate = (h(eps) - h(-eps)) / (2.0 * eps);
        assert!((rate - 2.5).abs() < 1e-6, "{rate}");
    }

    #[test]
    fn an_infinitely_heavy_bus_gives_the_paper_model_to_the_bit() {
        let p = Panel::paper();
        let o = Orbit::geo_equinox();
        for sense in [1.0, -1.0] {
            let sc = Spacecraft {
                bus_inertia: f64::INFINITY,
                appendages: vec![Appendage {
                    panel: p,
                    offset: 3.0,
                    sense,
                }],
                controller: None,
            };
            let sys = SpacecraftSystem::new(&sc, o, 0.0).unwrap();
            let paper = Coupled::new(p, o, HingeModel::Linear, Coupling::ProjectedArea);
            for y in [
                Vector4::new(380.0, 368.0, 0.085, 0.0),
                Vector4::new(250.0, 262.0, -0.3, 0.02),
            ] {
                for flux in [0.0, 1.0] {
                    let want = paper.rhs_at_flux(flux, &y);
                    let full = DVector::from_vec(vec![0.0, 0.0, y[0], y[1], y[2], y[3]]);
                    let got = sys.rhs_at_flux(flux, &full);
                    assert_eq!(&got.as_slice()[2..], want.as_slice());
                    assert_eq!(&got.as_slice()[..2], &[0.0, 0.0]);
                }
            }
        }
    }

    #[test]
    fn bad_spacecraft_are_refused_by_name() {
        let name = |sc: Spacecraft| match SpacecraftSystem::new(&sc, Orbit::geo_equinox(), 0.0) {
            Err(Error::InvalidParameter { name, .. }) => name,
            other => panic!("{other:?}"),
        };
        assert_eq!(name(craft(0.0)), "bus_inertia");
        assert_eq!(name(craft(f64::NAN)), "bus_inertia");
        let mut sc = craft(1e4);
        sc.appendages[1].sense = 0.5;
        assert_eq!(name(sc), "appendages[1].sense");
        let mut sc = craft(1e4);
        sc.appendages[0].offset = -1.0;
        assert_eq!(name(sc), "appendages[0].offset");
        let mut sc = craft(1e4);
        sc.appendages[0].panel.length = -1.0;
        assert_eq!(name(sc), "appendages[0].panel.length");
        let mut sc = craft(f64::INFINITY);
        sc.controller = Some(Pd {
            bandwidth: 0.1,
            damping: 0.7,
        });
        assert_eq!(name(sc), "controller");
    }
}
