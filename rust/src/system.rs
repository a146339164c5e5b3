//! The right-hand sides: the thermal models alone, the coupled thermo-structural system, and the
//! hinge driven by a prescribed moment. Each implements [`OdeSystem`] on a fixed-size state.

use crate::dynamics::{hinge_acceleration, thermal_moment, HingeModel};
use crate::integrate::OdeSystem;
use crate::orbit::{Orbit, Shadow};
use crate::params::Panel;
use crate::thermal::{one_node_rate, two_layer_rates};
use nalgebra::{SVector, Vector1, Vector2, Vector4};

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
        if self.orbit.eccentric_sun {
            s * self.orbit.flux_scale(t)
        } else {
            s
        }
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

impl OdeSystem<1> for OneNode {
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

impl OdeSystem<2> for TwoLayer {
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
#[derive(Debug, Clone, Copy)]
pub struct Coupled {
    pub panel: Panel,
    pub model: HingeModel,
    pub coupling: Coupling,
    sun: Sunlight,
}

impl Coupled {
    pub fn new(panel: Panel, orbit: Orbit, model: HingeModel, coupling: Coupling) -> Self {
        Coupled {
            panel,
            model,
            coupling,
            sun: Sunlight::new(orbit),
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
    #[inline]
    pub fn rhs_at_flux(&self, flux: f64, y: &Vector4<f64>) -> Vector4<f64> {
        let (tf, tb, th, om) = (y[0], y[1], y[2], y[3]);
        let absorbed = flux * Self::area_factor(self.coupling, th);
        let (dtf, dtb) = two_layer_rates(&self.panel, absorbed, tf, tb);
        let moment = thermal_moment(&self.panel, tf, tb);
        let acc = hinge_acceleration(&self.panel, self.model, moment, th, om);
        Vector4::new(dtf, dtb, om, acc)
    }

    /// Illumination factor (s × flux scale) inside the current segment at time t.
    pub fn flux_at(&self, t: f64) -> f64 {
        self.sun.flux(t)
    }
}

impl OdeSystem<4> for Coupled {
    #[inline]
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

impl OdeSystem<2> for DrivenHinge {
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
