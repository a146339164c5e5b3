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
            let (s, c) = sin_cos(theta);
            let forced = generalised / panel.hinge_inertia() - 3.0 * theta_dot * theta_dot * s * c;
            forced / (1.0 + 3.0 * s * s)
        }
    }
}

/// (sin θ, cos θ), the right-hand side's only transcendental functions.
///
/// For |θ| ≤ π/4, where the hinge lives, the minimax polynomials of fdlibm's sine and cosine
/// kernels (degrees 13 and 14, within an ulp or so of the library), evaluated with short
/// dependency chains; further out the library's `sin_cos`. Inline arithmetic keeps the hot path
/// free of calls into libm, which make every caller spill its registers.
#[inline]
pub fn sin_cos(theta: f64) -> (f64, f64) {
    if theta.abs() > std::f64::consts::FRAC_PI_4 {
        return theta.sin_cos();
    }
    sin_cos_kernel(theta)
}

/// The polynomials of [`sin_cos`] alone, for |θ| ≤ π/4 (no branch, so that a loop over SIMD
/// lanes vectorises; the caller handles the lanes beyond π/4).
#[inline(always)]
pub(crate) fn sin_cos_kernel(theta: f64) -> (f64, f64) {
    const S: [f64; 6] = [
        -0.16666666666666632,
        0.00833333333332249,
        -0.0001984126982985795,
        2.7557313707070068e-06,
        -2.5050760253406863e-08,
        1.58969099521155e-10,
    ];
    const C: [f64; 6] = [
        0.0416666666666666,
        -0.001388888888887411,
        2.480158728947673e-05,
        -2.7557314351390663e-07,
        2.087572321298175e-09,
        -1.1359647557788195e-11,
    ];
    let z = theta * theta;
    let w = z * z;
    let w2 = w * w;
    // Estrin's scheme: three independent pairs, then two levels.
    let ps = (S[0] + z * S[1]) + w * (S[2] + z * S[3]) + w2 * (S[4] + z * S[5]);
    let pc = (C[0] + z * C[1]) + w * (C[2] + z * C[3]) + w2 * (C[4] + z * C[5]);
    (theta + theta * z * ps, 1.0 - (0.5 * z - w * pc))
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

    /// Units in the last place between a and b.
    fn ulps(a: f64, b: f64) -> f64 {
        (a - b).abs() / (f64::EPSILON * b.abs().max(f64::MIN_POSITIVE))
    }

    #[test]
    fn sin_cos_agrees_with_the_library_to_an_ulp() {
        let n = 200_001;
        let mut worst: f64 = 0.0;
        for i in 0..n {
            // 1.2·[−π/4, π/4] also crosses into the library branch on both sides.
            let x = (2.0 * i as f64 / (n - 1) as f64 - 1.0) * 1.2 * std::f64::consts::FRAC_PI_4;
            let (s, c) = sin_cos(x);
            if x != 0.0 {
                worst = worst.max(ulps(s, x.sin()));
            } else {
                assert_eq!(s, 0.0);
            }
            worst = worst.max(ulps(c, x.cos()));
        }
        for x in [
            1e-300,
            -1e-8,
            1e-3,
            0.085,
            0.5,
            -std::f64::consts::FRAC_PI_4,
            3.0,
            -40.0,
        ] {
            let (s, c) = sin_cos(x);
            worst = worst.max(ulps(s, x.sin())).max(ulps(c, x.cos()));
        }
        assert!(worst <= 1.0, "worst difference {worst} ulp");
    }

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
