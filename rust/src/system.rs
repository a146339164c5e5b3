//! The right-hand sides: the thermal models alone, the coupled thermo-structural system, and the
//! hinge driven by a prescribed moment. Each implements [`OdeSystem`] on a fixed-size state.

use crate::dynamics::{hinge_acceleration, sin_cos, HingeModel};
use crate::integrate::OdeSystem;
use crate::orbit::{Orbit, Shadow};
use crate::params::Panel;
use crate::thermal::{one_node_rate, two_layer_rates};
use crate::STEFAN_BOLTZMANN;
use nalgebra::{SVector, Vector1, Vector2, Vector4, U1, U2, U4};

/// How the hinge angle feeds back on the heating (paper Sec. 4).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Coupling {
    /// Absorbed flux ∝ cos θ: the projected area follows the hinge angle (two-way coupling).
    ProjectedArea,
    /// Projected area frozen (cos θ → 1): one-way coupling, paper Fig. 18.
    Frozen,
}

/// Illumination bookkeeping shared by every orbit-driven system: the segment being integrated
/// decides s, so a step that ends on a shadow boundary sees the segment's own side.
#[derive(Debug, Clone, Copy)]
struct Sunlight {
    orbit: Orbit,
    segment: (f64, f64),
    /// s over the current segment when it cannot change there: every segment of a cylindrical
    /// shadow, and the full-Sun and umbra segments of a penumbral one (the breakpoints include
    /// every contact). None inside a penumbra, where s(t) is evaluated at each call.
    constant_s: Option<f64>,
}

impl Sunlight {
    fn new(orbit: Orbit) -> Self {
        Sunlight {
            orbit,
            segment: (0.0, 0.0),
            constant_s: None,
        }
    }

    fn enter(&mut self, a: f64, b: f64) {
        self.segment = (a, b);
        let mid = self.orbit.illumination_on(0.5 * (a + b), a, b);
        let varies = matches!(self.orbit.shadow, Shadow::Penumbra) && mid > 0.0 && mid < 1.0;
        self.constant_s = if varies { None } else { Some(mid) };
    }

    #[inline]
    fn flux(&self, t: f64) -> f64 {
        let s = match self.constant_s {
            Some(s) => s,
            None => {
                let (a, b) = self.segment;
                self.orbit.illumination_on(t, a, b)
            }
        };
        s * self.orbit.flux_scale(t)
    }
}

/// Isothermal plate, state (T).
#[derive(Debug, Clone, Copy)]
pub struct OneNode {
    pub panel: Panel,
    sun: Sunlight,
}

impl OneNode {
    pub fn new(panel: Panel, orbit: Orbit) -> Self {
        OneNode {
            panel,
            sun: Sunlight::new(orbit),
        }
    }
}

impl OdeSystem<U1> for OneNode {
    #[inline]
    fn rhs(&self, t: f64, y: &Vector1<f64>) -> Vector1<f64> {
        Vector1::new(one_node_rate(&self.panel, self.sun.flux(t), y[0]))
    }
    fn breakpoints(&self, t0: f64, t1: f64) -> Vec<f64> {
        self.sun.orbit.breakpoints(t0, t1)
    }
    fn enter_segment(&mut self, a: f64, b: f64) {
        self.sun.enter(a, b);
    }
}

/// Two-layer plate without structure (θ = 0), state (T_f, T_b).
#[derive(Debug, Clone, Copy)]
pub struct TwoLayer {
    pub panel: Panel,
    sun: Sunlight,
}

impl TwoLayer {
    pub fn new(panel: Panel, orbit: Orbit) -> Self {
        TwoLayer {
            panel,
            sun: Sunlight::new(orbit),
        }
    }
}

impl OdeSystem<U2> for TwoLayer {
    #[inline]
    fn rhs(&self, t: f64, y: &Vector2<f64>) -> Vector2<f64> {
        let (df, db) = two_layer_rates(&self.panel, self.sun.flux(t), y[0], y[1]);
        Vector2::new(df, db)
    }
    fn breakpoints(&self, t0: f64, t1: f64) -> Vec<f64> {
        self.sun.orbit.breakpoints(t0, t1)
    }
    fn enter_segment(&mut self, a: f64, b: f64) {
        self.sun.enter(a, b);
    }
}

/// The coupled thermo-structural system, state (T_f, T_b, θ, θ̇) (paper eqs. 20 and 28).
///
/// The panel's coefficients are folded into per-second rates once, in [`Coupled::new`]; the
/// system keeps only those.
#[derive(Debug, Clone, Copy)]
pub struct Coupled {
    model: HingeModel,
    coupling: Coupling,
    sun: Sunlight,
    rates: Rates,
}

/// The coupled right-hand side's coefficients, each divided by the capacity or inertia it is
/// divided by in eqs. 2, 20 and 28, so that the hot path holds no division but the inertia factor.
#[derive(Debug, Clone, Copy)]
struct Rates {
    /// α C / (m c / 2), K/s per unit flux factor.
    heating: f64,
    /// K / (m c / 2), 1/s.
    conduction: f64,
    /// σ ε_f / (m c / 2) and σ ε_b / (m c / 2), 1/(s K³).
    radiation_front: f64,
    radiation_back: f64,
    /// (χ a E I / d) / I_B, 1/(s² K).
    moment: f64,
    /// c_d / I_B, 1/s.
    damping: f64,
    /// K_el / I_B, 1/s².
    stiffness: f64,
}

impl Rates {
    fn new(panel: &Panel) -> Self {
        let half_capacity = 0.5 * panel.heat_capacity();
        let inertia = panel.hinge_inertia();
        Rates {
            heating: panel.absorptivity * panel.solar_constant / half_capacity,
            conduction: panel.conductance / half_capacity,
            radiation_front: STEFAN_BOLTZMANN * panel.emissivity_front / half_capacity,
            radiation_back: STEFAN_BOLTZMANN * panel.emissivity_back / half_capacity,
            moment: panel.moment_per_kelvin() / inertia,
            damping: panel.damping / inertia,
            stiffness: panel.hinge_stiffness / inertia,
        }
    }
}

impl Coupled {
    pub fn new(panel: Panel, orbit: Orbit, model: HingeModel, coupling: Coupling) -> Self {
        Coupled {
            model,
            coupling,
            sun: Sunlight::new(orbit),
            rates: Rates::new(&panel),
        }
    }

    /// Projected-area factor of the absorbed flux.
    #[inline]
    pub fn area_factor(coupling: Coupling, theta: f64) -> f64 {
        match coupling {
            Coupling::ProjectedArea => theta.cos(),
            Coupling::Frozen => 1.0,
        }
    }

    /// The right-hand side at a given illumination factor (used by the equilibrium solver too).
    ///
    /// The same equations as [`two_layer_rates`], [`crate::dynamics::thermal_moment`] and
    /// [`hinge_acceleration`],
    /// with sin θ and cos θ computed once and the coefficients taken from [`Rates`].
    #[inline(always)]
    pub fn rhs_at_flux(&self, flux: f64, y: &Vector4<f64>) -> Vector4<f64> {
        let (sin, cos) = match (self.coupling, self.model) {
            (Coupling::Frozen, HingeModel::Linear) => (0.0, 1.0),
            _ => sin_cos(y[2]),
        };
        let r = &self.rates;
        let c = [
            r.heating,
            r.conduction,
            r.radiation_front,
            r.radiation_back,
            r.moment,
            r.damping,
            r.stiffness,
        ];
        let [dtf, dtb, om, acc] = coupled_rates(
            self.model,
            self.coupling,
            &c,
            flux,
            &[y[0], y[1], y[2], y[3]],
            sin,
            cos,
        );
        Vector4::new(dtf, dtb, om, acc)
    }

    /// The hinge model, the coupling and the folded coefficients (heating, conduction,
    /// radiation front and back, moment, damping, stiffness), for kernels that evaluate
    /// [`Coupled::rhs_at_flux`] for several panels at once with the same arithmetic.
    pub(crate) fn lane_form(&self) -> (HingeModel, Coupling, [f64; 7]) {
        let r = &self.rates;
        let c = [
            r.heating,
            r.conduction,
            r.radiation_front,
            r.radiation_back,
            r.moment,
            r.damping,
            r.stiffness,
        ];
        (self.model, self.coupling, c)
    }

    /// Illumination factor (s × flux scale) inside the current segment at time t.
    pub fn flux_at(&self, t: f64) -> f64 {
        self.sun.flux(t)
    }
}

impl OdeSystem<U4> for Coupled {
    #[inline(always)]
    fn rhs(&self, t: f64, y: &Vector4<f64>) -> Vector4<f64> {
        self.rhs_at_flux(self.sun.flux(t), y)
    }
    fn breakpoints(&self, t0: f64, t1: f64) -> Vec<f64> {
        self.sun.orbit.breakpoints(t0, t1)
    }
    fn enter_segment(&mut self, a: f64, b: f64) {
        self.sun.enter(a, b);
    }
}

/// The coupled right-hand side (T_f', T_b', θ', θ̇') at state `y` and illumination `flux`, from
/// the coefficients of [`Rates`] in field order (heating, conduction, radiation front and back,
/// moment, damping, stiffness) and sin θ, cos θ (0 and 1 when unused). Its arithmetic lives
/// here once, for [`Coupled::rhs_at_flux`] and for the ensemble's lockstep kernel, which must
/// give the same bits.
#[inline(always)]
pub(crate) fn coupled_rates(
    model: HingeModel,
    coupling: Coupling,
    c: &[f64; 7],
    flux: f64,
    y: &[f64; 4],
    sin: f64,
    cos: f64,
) -> [f64; 4] {
    let [heating, conduction, radiation_front, radiation_back, moment, damping, stiffness] = *c;
    let [tf, tb, th, om] = *y;
    let area = match coupling {
        Coupling::ProjectedArea => cos,
        Coupling::Frozen => 1.0,
    };
    let gradient = tf - tb;
    let conducted = conduction * gradient;
    let tf4 = (tf * tf) * (tf * tf);
    let tb4 = (tb * tb) * (tb * tb);
    let dtf = heating * (flux * area) - conducted - radiation_front * tf4;
    let dtb = conducted - radiation_back * tb4;
    // Generalised moment over I_B: M_T − c_d θ̇ − K_el θ.
    let forced = moment * gradient - damping * om - stiffness * th;
    let acc = match model {
        HingeModel::Linear => forced,
        // eq. 20 with 3/(2 m l³) = 1/I_B factored out
        HingeModel::Nonlinear => (forced - 3.0 * om * om * sin * cos) / (1.0 + 3.0 * sin * sin),
    };
    [dtf, dtb, om, acc]
}

/// A thermal-moment history M(t), N m: constant, or linear between samples (held at the ends).
#[derive(Debug, Clone, PartialEq)]
pub enum MomentHistory {
    Constant(f64),
    Samples { t: Vec<f64>, moment: Vec<f64> },
}

impl MomentHistory {
    #[inline]
    pub fn at(&self, t: f64) -> f64 {
        match self {
            MomentHistory::Constant(m) => *m,
            MomentHistory::Samples { t: ts, moment } => {
                let n = ts.len();
                if t <= ts[0] {
                    return moment[0];
                }
                if t >= ts[n - 1] {
                    return moment[n - 1];
                }
                let i = ts.partition_point(|&x| x <= t) - 1;
                let w = (t - ts[i]) / (ts[i + 1] - ts[i]);
                moment[i] + w * (moment[i + 1] - moment[i])
            }
        }
    }

    /// Checks sample times increasing and values finite.
    pub fn validate(&self) -> crate::Result<()> {
        use crate::Error;
        match self {
            MomentHistory::Constant(m) => crate::error::require_finite("moment", *m),
            MomentHistory::Samples { t, moment } => {
                if t.len() < 2 || t.len() != moment.len() {
                    return Err(Error::invalid(
                        "moment",
                        format!("{} times, {} values", t.len(), moment.len()),
                        "needs at least two (time, moment) samples of equal length",
                    ));
                }
                if let Some(i) = t
                    .windows(2)
                    .position(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater))
                {
                    return Err(Error::invalid(
                        "moment_t",
                        t[i + 1],
                        "times must be finite and increasing",
                    ));
                }
                if let Some(v) = t.iter().chain(moment).find(|v| !v.is_finite()) {
                    return Err(Error::invalid("moment", v, "samples must be finite"));
                }
                Ok(())
            }
        }
    }
}

/// The hinge alone, driven by a prescribed thermal moment; state (θ, θ̇).
#[derive(Debug, Clone)]
pub struct DrivenHinge {
    pub panel: Panel,
    pub model: HingeModel,
    pub moment: MomentHistory,
}

impl OdeSystem<U2> for DrivenHinge {
    #[inline]
    fn rhs(&self, t: f64, y: &Vector2<f64>) -> Vector2<f64> {
        let m = self.moment.at(t);
        Vector2::new(
            y[1],
            hinge_acceleration(&self.panel, self.model, m, y[0], y[1]),
        )
    }
    fn breakpoints(&self, t0: f64, t1: f64) -> Vec<f64> {
        // Kinks of the piecewise-linear history would cost accuracy if straddled.
        match &self.moment {
            MomentHistory::Constant(_) => Vec::new(),
            MomentHistory::Samples { t, .. } => {
                t.iter().copied().filter(|&x| x > t0 && x < t1).collect()
            }
        }
    }
}

/// Convenience: a state vector from its four components.
pub fn state(t_front: f64, t_back: f64, theta: f64, theta_dot: f64) -> SVector<f64, 4> {
    Vector4::new(t_front, t_back, theta, theta_dot)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::thermal_moment;

    /// The folded coefficients give the rates of the textbook form of the equations.
    #[test]
    fn coupled_rhs_matches_the_equations_term_by_term() {
        let panel = Panel {
            damping: 2.0,
            ..Panel::paper()
        };
        let states = [
            Vector4::new(380.0, 368.0, 0.085, 0.0),
            Vector4::new(250.0, 262.0, -0.3, 0.02),
            Vector4::new(120.0, 119.0, 1.2, -0.7),
        ];
        for model in [HingeModel::Nonlinear, HingeModel::Linear] {
            for coupling in [Coupling::ProjectedArea, Coupling::Frozen] {
                let sys = Coupled::new(panel, Orbit::geo_equinox(), model, coupling);
                for y in &states {
                    for flux in [0.0, 1.0, 0.97] {
                        let got = sys.rhs_at_flux(flux, y);
                        let area = Coupled::area_factor(coupling, y[2]);
                        let (dtf, dtb) = two_layer_rates(&panel, flux * area, y[0], y[1]);
                        let m = thermal_moment(&panel, y[0], y[1]);
                        let acc = hinge_acceleration(&panel, model, m, y[2], y[3]);
                        let want = Vector4::new(dtf, dtb, y[3], acc);
                        for i in 0..4 {
                            let tol = 1e-13 * want[i].abs().max(1e-3);
                            assert!(
                                (got[i] - want[i]).abs() <= tol,
                                "{model:?} {coupling:?} {y} flux {flux}: component {i} {} vs {}",
                                got[i],
                                want[i]
                            );
                        }
                    }
                }
            }
        }
    }
}
