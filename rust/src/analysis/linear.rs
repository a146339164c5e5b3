//! The closed-form linear analysis of paper Sec. 4.2.
//!
//! With ε_f = ε_b = ε and T⁴ linearised about a common T*:
//!
//! ```text
//! d(ΔT)/dt + q ΔT = p cos θ,   p = 2 α C/(m c),   q = (4 K + 8 σ ε T*³)/(m c)
//! θ̈ + r θ̇ + ω_n² θ = s ΔT,   r = c_d / I_B,     s = χ a E I/(I_B d)
//! ```
//!
//! A swing δθ about the sunlit tilt θ* modulates the forcing by −p sin θ* δθ; the gradient answers
//! through 1/(q + iω), a lag that feeds the swing a negative damping s p sin θ*/(q² + ω_n²)
//! ("thermal pumping"). The eigen-analysis of [`crate::analysis::flutter`] gives the exact value.

use crate::analysis::steady::equilibrium;
use crate::error::{require_positive, Error, Result};
use crate::inputs::panel::Panel;
use crate::models::coupled::Coupling;
use crate::models::thermal::MAX_TEMPERATURE;
use crate::models::thermal::STEFAN_BOLTZMANN;

/// The coefficients of Sec. 4.2 for one panel and forcing frequency, with what follows from them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LinearThermal {
    /// Forcing of the gradient, K/s.
    pub p: f64,
    /// Relaxation rate of the gradient, 1/s.
    pub q: f64,
    /// Hinge damping rate c_d/I_B, 1/s.
    pub r: f64,
    /// Hinge acceleration per kelvin of gradient, rad/(K s²).
    pub s: f64,
    /// Forcing angular frequency, rad/s.
    pub omega: f64,
    /// Natural angular frequency of the linear hinge, rad/s.
    pub omega_n: f64,
    /// Linearisation temperature, K.
    pub t_star: f64,
    /// The common ε in q: the mean of ε_f and ε_b (the paper assumes them equal).
    pub emissivity: f64,
    /// Sunlit equilibrium hinge angle, rad.
    pub theta_star: f64,
    /// I_B, kg m².
    pub hinge_inertia: f64,
}

impl LinearThermal {
    /// The coefficients' names, in the order of [`LinearThermal::values`] (`T_star` is
    /// `t_star`, named as in the paper).
    pub const FIELDS: [&'static str; 10] = [
        "p",
        "q",
        "r",
        "s",
        "omega",
        "omega_n",
        "T_star",
        "emissivity",
        "theta_star",
        "hinge_inertia",
    ];

    /// The coefficients in the order of [`LinearThermal::FIELDS`].
    pub fn values(&self) -> [f64; 10] {
        [
            self.p,
            self.q,
            self.r,
            self.s,
            self.omega,
            self.omega_n,
            self.t_star,
            self.emissivity,
            self.theta_star,
            self.hinge_inertia,
        ]
    }

    /// The analysis from its coefficients in the order of [`LinearThermal::FIELDS`].
    pub fn from_values(v: [f64; 10]) -> Self {
        let [p, q, r, s, omega, omega_n, t_star, emissivity, theta_star, hinge_inertia] = v;
        LinearThermal {
            p,
            q,
            r,
            s,
            omega,
            omega_n,
            t_star,
            emissivity,
            theta_star,
            hinge_inertia,
        }
    }

    /// The analysis of `panel` under flux factor `flux`; `omega` defaults to ω_n (as in the
    /// paper), `t_star` to the mean layer temperature at the sunlit equilibrium.
    pub fn new(panel: &Panel, flux: f64, omega: Option<f64>, t_star: Option<f64>) -> Result<Self> {
        require_positive("flux", flux)?;
        let eq = equilibrium(panel, Coupling::ProjectedArea, flux)?;
        let inertia = panel.hinge_inertia();
        let omega_n = panel.natural_angular_frequency();
        let omega = omega.unwrap_or(omega_n);
        if !(omega.is_finite() && omega >= 0.0) {
            return Err(Error::invalid("omega", omega, "must be finite and >= 0"));
        }
        let t_star = t_star.unwrap_or(0.5 * (eq.t_front + eq.t_back));
        if !(t_star > 0.0 && t_star <= MAX_TEMPERATURE) {
            return Err(Error::invalid(
                "T_star",
                t_star,
                &format!("must be in (0, {MAX_TEMPERATURE:e}] K"),
            ));
        }
        let mc = panel.heat_capacity();
        let eps = 0.5 * (panel.emissivity_front + panel.emissivity_back);
        Ok(LinearThermal {
            p: 2.0 * panel.absorptivity * panel.solar_constant * flux / mc,
            q: (4.0 * panel.conductance + 8.0 * STEFAN_BOLTZMANN * eps * t_star.powi(3)) / mc,
            r: panel.damping_rate(),
            s: panel.moment_per_kelvin() / inertia,
            omega,
            omega_n,
            t_star,
            emissivity: eps,
            theta_star: eq.theta,
            hinge_inertia: inertia,
        })
    }

    /// Steady amplitude of ΔT under p cos(ω t + φ), K: p/√(q² + ω²).
    pub fn amplitude(&self) -> f64 {
        self.p / self.q.hypot(self.omega)
    }

    /// Lag of ΔT behind the forcing, rad: atan2(ω, q), in [0, π/2).
    pub fn phase_lag(&self) -> f64 {
        self.omega.atan2(self.q)
    }

    /// 1/q, s: how fast the gradient forgets its initial value.
    pub fn time_constant(&self) -> f64 {
        1.0 / self.q
    }

    /// The forcing is at the hinge's natural frequency (within 1 %).
    pub fn resonant(&self) -> bool {
        (self.omega - self.omega_n).abs() <= 0.01 * self.omega_n
    }

    /// Negative damping rate from the lag, 1/s: s p sin θ* /(q² + ω_n²).
    pub fn thermal_damping(&self) -> f64 {
        self.s * self.p * self.theta_star.sin() / (self.q * self.q + self.omega_n * self.omega_n)
    }

    /// c_d at which the pumping is balanced, N m s/rad: I_B · thermal_damping.
    pub fn critical_damping_estimate(&self) -> f64 {
        self.hinge_inertia * self.thermal_damping()
    }

    /// Growth rate of the swing, 1/s: (thermal_damping − r)/2.
    pub fn growth_rate_estimate(&self) -> f64 {
        0.5 * (self.thermal_damping() - self.r)
    }

    /// ΔT(t) for dΔT/dt + q ΔT = p cos(ω t + φ), K: the steady solution, plus the decaying
    /// transient from ΔT(0) = `delta_t0` when given.
    pub fn delta_t(&self, t: f64, phi: f64, delta_t0: Option<f64>) -> f64 {
        let (a, lag) = (self.amplitude(), self.phase_lag());
        let steady = a * (self.omega * t + phi - lag).cos();
        match delta_t0 {
            None => steady,
            Some(d0) => steady + (d0 - a * (phi - lag).cos()) * (-self.q * t).exp(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn equal_emissivities() -> Panel {
        Panel {
            emissivity_front: 0.55,
            emissivity_back: 0.55,
            ..Panel::paper()
        }
    }

    #[test]
    fn delta_t_solves_its_equation() {
        let lt = LinearThermal::new(&equal_emissivities(), 1.0, Some(0.3), None).unwrap();
        let (phi, d0) = (0.4, 2.0);
        assert!((lt.delta_t(0.0, phi, Some(d0)) - d0).abs() < 1e-12);
        for t in [0.0, 3.0, 40.0, 900.0] {
            let h = 1e-4;
            let rate =
                (lt.delta_t(t + h, phi, Some(d0)) - lt.delta_t(t - h, phi, Some(d0))) / (2.0 * h);
            let rhs = lt.p * (lt.omega * t + phi).cos() - lt.q * lt.delta_t(t, phi, Some(d0));
            assert!((rate - rhs).abs() < 1e-7 * lt.p, "t = {t}: {rate} vs {rhs}");
        }
    }

    #[test]
    fn pumping_estimate_is_close_to_the_eigen_analysis() {
        use crate::models::hinge::HingeModel;
        let p = equal_emissivities();
        let lt = LinearThermal::new(&p, 1.0, None, None).unwrap();
        let exact = crate::analysis::flutter::critical_damping(
            &p,
            HingeModel::Linear,
            Coupling::ProjectedArea,
            1.0,
        )
        .unwrap();
        assert!((lt.critical_damping_estimate() / exact - 1.0).abs() < 0.02);
        assert!(lt.resonant());
    }

    #[test]
    fn bad_arguments_are_named() {
        let p = Panel::paper();
        let e = LinearThermal::new(&p, 1.0, None, Some(-1.0)).unwrap_err();
        assert!(e.to_string().starts_with("T_star"));
        let e = LinearThermal::new(&p, 1.0, Some(f64::NAN), None).unwrap_err();
        assert!(e.to_string().starts_with("omega"));
    }
}
