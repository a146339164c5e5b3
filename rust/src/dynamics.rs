//! Thermal bending moment and the one-degree-of-freedom hinge model (paper Sec. 3, eqs. 20, 28).

use crate::params::Panel;

/// Structural model of the hinge.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum HingeModel {
    /// Eq. 20: the exact kinematics of two rigid halves, with the (1 + 3 sin²θ) inertia.
    Nonlinear,
    /// Eq. 28: I_B θ̈ + c_d θ̇ + K_el θ = M_T.
    Linear,
}

/// M_T = χ a E I (T_f − T_b) / d, N m.
#[inline]
pub fn thermal_moment(panel: &Panel, t_front: f64, t_back: f64) -> f64 {
    panel.moment_per_kelvin() * (t_front - t_back)
}

/// θ̈ of the hinge under the thermal moment `moment`, rad/s².
#[inline]
pub fn hinge_acceleration(
    panel: &Panel,
    model: HingeModel,
    moment: f64,
    theta: f64,
    theta_dot: f64,
) -> f64 {
    let generalised = moment - panel.damping * theta_dot - panel.hinge_stiffness * theta;
    match model {
        HingeModel::Linear => generalised / panel.hinge_inertia(),
        HingeModel::Nonlinear => {
            // eq. 20 with 3/(2 m l³) = 1/I_B factored out
            let (s, c) = theta.sin_cos();
            let forced = generalised / panel.hinge_inertia() - 3.0 * theta_dot * theta_dot * s * c;
            forced / (1.0 + 3.0 * s * s)
        }
    }
}

/// Mechanical energy of the hinge in a constant moment field, J: kinetic + spring − work of M.
/// Conserved when c_d = 0 and M constant.
pub fn hinge_energy(
    panel: &Panel,
    model: HingeModel,
    theta: f64,
    theta_dot: f64,
    moment: f64,
) -> f64 {
    let kinetic = match model {
        HingeModel::Linear => 0.5 * panel.hinge_inertia() * theta_dot * theta_dot,
        HingeModel::Nonlinear => {
            let l = panel.half_arm();
            let s = theta.sin();
            panel.mass_per_length * l * l * l / 3.0 * theta_dot * theta_dot * (1.0 + 3.0 * s * s)
        }
    };
    kinetic + 0.5 * panel.hinge_stiffness * theta * theta - moment * theta
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn models_agree_for_small_angles() {
        let p = Panel::paper();
        let a = hinge_acceleration(&p, HingeModel::Nonlinear, 10.0, 1e-6, 1e-6);
        let b = hinge_acceleration(&p, HingeModel::Linear, 10.0, 1e-6, 1e-6);
        assert!((a - b).abs() < 1e-9 * b.abs());
    }

    #[test]
    fn static_equilibrium_is_moment_over_stiffness() {
        let p = Panel::paper();
        for model in [HingeModel::Nonlinear, HingeModel::Linear] {
            let th = 400.0 / p.hinge_stiffness;
            assert!(hinge_acceleration(&p, model, 400.0, th, 0.0).abs() < 1e-15);
        }
    }

    #[test]
    fn energy_rate_is_zero_along_undamped_motion() {
        // dE/dt = ∂E/∂θ θ̇ + ∂E/∂θ̇ θ̈ must vanish for c_d = 0 (checks eq. 20 against its Lagrangian).
        let p = Panel {
            damping: 0.0,
            ..Panel::paper()
        };
        for model in [HingeModel::Nonlinear, HingeModel::Linear] {
            let (th, om, m) = (0.4, 0.3, 250.0);
            let acc = hinge_acceleration(&p, model, m, th, om);
            let eps = 1e-6;
            let de_dth = (hinge_energy(&p, model, th + eps, om, m)
                - hinge_energy(&p, model, th - eps, om, m))
                / (2.0 * eps);
            let de_dom = (hinge_energy(&p, model, th, om + eps, m)
                - hinge_energy(&p, model, th, om - eps, m))
                / (2.0 * eps);
            let rate = de_dth * om + de_dom * acc;
            assert!(rate.abs() < 1e-5 * (de_dth * om).abs(), "{model:?}: {rate}");
        }
    }
}
