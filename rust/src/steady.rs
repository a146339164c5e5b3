//! The sunlit equilibrium of the coupled system: θ̇ = 0 and every rate zero under full Sun.

use crate::dynamics::thermal_moment;
use crate::error::{Error, Result};
use crate::params::Panel;
use crate::system::Coupling;
use crate::thermal::{one_node_equilibrium, two_layer_rates};
use nalgebra::{Matrix3, Vector3};

/// The steady state under constant flux factor `flux` (1: full Sun at the nominal constant).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Equilibrium {
    pub t_front: f64,
    pub t_back: f64,
    pub theta: f64,
}

/// Residual of the steady equations: two heat balances and the static hinge, M_T − K_el θ = 0
/// (the same for the linear and the non-linear hinge, whose static terms coincide).
fn residual(panel: &Panel, coupling: Coupling, flux: f64, x: &Vector3<f64>) -> Vector3<f64> {
    let (tf, tb, th) = (x[0], x[1], x[2]);
    let area = match coupling {
        Coupling::ProjectedArea => th.cos(),
        Coupling::Frozen => 1.0,
    };
    let (df, db) = two_layer_rates(panel, flux * area, tf, tb);
    let hc = 0.5 * panel.heat_capacity();
    // Scaled to W/m² and N m so that Newton's test is dimensionally balanced.
    Vector3::new(
        df * hc,
        db * hc,
        (thermal_moment(panel, tf, tb) - panel.hinge_stiffness * th) / panel.hinge_stiffness,
    )
}

/// Newton's method on the 3×3 steady system with a finite-difference Jacobian, from the
/// one-node temperature and the uncoupled angle.
pub fn equilibrium(panel: &Panel, coupling: Coupling, flux: f64) -> Result<Equilibrium> {
    panel.validate()?;
    if !(flux.is_finite() && flux > 0.0) {
        return Err(Error::invalid("flux", flux, "must be finite and > 0"));
    }
    let t0 = one_node_equilibrium(panel, flux);
    let mut x = Vector3::new(t0, t0, 0.0);
    for _ in 0..100 {
        let f = residual(panel, coupling, flux, &x);
        let mut jac = Matrix3::zeros();
        for j in 0..3 {
            let h = 1e-7 * x[j].abs().max(1e-3);
            let mut xp = x;
            xp[j] += h;
            jac.set_column(j, &((residual(panel, coupling, flux, &xp) - f) / h));
        }
        let dx = jac.lu().solve(&(-f)).ok_or_else(|| Error::NoConvergence {
            what: "steady state".into(),
            reason: "singular Jacobian".into(),
        })?;
        // Damped update keeps the temperatures positive on wild parameter sets.
        let mut lambda = 1.0;
        while x[0] + lambda * dx[0] <= 0.0 || x[1] + lambda * dx[1] <= 0.0 {
            lambda *= 0.5;
        }
        x += dx * lambda;
        if dx[0].abs() < 1e-12 * x[0] && dx[1].abs() < 1e-12 * x[1] && dx[2].abs() < 1e-14 {
            let eq = Equilibrium {
                t_front: x[0],
                t_back: x[1],
                theta: x[2],
            };
            if eq.theta.abs() >= std::f64::consts::FRAC_PI_2 {
                return Err(Error::NoConvergence {
                    what: "steady state".into(),
                    reason: format!(
                        "hinge angle {} rad is beyond 90°: the panel is far too soft",
                        eq.theta
                    ),
                });
            }
            return Ok(eq);
        }
    }
    Err(Error::NoConvergence {
        what: "steady state".into(),
        reason: "Newton did not converge in 100 iterations".into(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dynamics::HingeModel;
    use crate::orbit::Orbit;
    use crate::system::Coupled;

    #[test]
    fn paper_angle_is_about_five_degrees_and_a_fixed_point() {
        let p = Panel::paper();
        let eq = equilibrium(&p, Coupling::ProjectedArea, 1.0).unwrap();
        let deg = eq.theta.to_degrees();
        assert!(deg > 4.5 && deg < 5.5, "{deg}");
        assert!(eq.t_front > eq.t_back);
        let sys = Coupled::new(
            p,
            Orbit::geo_equinox(),
            HingeModel::Nonlinear,
            Coupling::ProjectedArea,
        );
        let rate = sys.rhs_at_flux(
            1.0,
            &nalgebra::Vector4::new(eq.t_front, eq.t_back, eq.theta, 0.0),
        );
        assert!(rate.amax() < 1e-9, "{rate}");
        let frozen = equilibrium(&p, Coupling::Frozen, 1.0).unwrap();
        assert!(frozen.theta > eq.theta, "cos θ lowers the absorbed flux");
    }
}
