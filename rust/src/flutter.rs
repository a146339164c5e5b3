//! Thermal flutter without integration: the Jacobian of the coupled system at the sunlit
//! equilibrium, its eigenvalues, the growth rate of the oscillatory mode and the critical damping.
//!
//! With the two-way coupling the absorbed flux depends on cos θ, so a swing of the panel modulates
//! the heating; the temperature gradient answers with a lag, and that lag can feed energy into the
//! oscillation (the paper's "thermal pumping"). Linear stability of the equilibrium decides it.

use crate::dynamics::HingeModel;
use crate::error::{require_non_negative, Error, Result};
use crate::params::Panel;
use crate::steady::{equilibrium, Equilibrium};
use crate::system::Coupling;
use crate::STEFAN_BOLTZMANN;
use nalgebra::{Complex, Matrix4, Vector4};

/// Linear stability of the sunlit equilibrium.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FlutterAnalysis {
    pub equilibrium: Equilibrium,
    /// ∂f/∂y at the equilibrium, state (T_f, T_b, θ, θ̇).
    pub jacobian: Matrix4<f64>,
    /// Eigenvalues of the Jacobian, 1/s, sorted by decreasing real part.
    pub eigenvalues: [Complex<f64>; 4],
    /// Largest real part of the eigenvalues, 1/s: positive means the equilibrium is unstable
    /// (with the thermal modes strongly damped, this is the oscillatory mode's growth rate).
    pub growth_rate: f64,
    /// Frequency of the oscillatory pair, Hz (0 when the hinge is overdamped).
    pub frequency_hz: f64,
}

impl FlutterAnalysis {
    pub fn stable(&self) -> bool {
        self.growth_rate < 0.0
    }
}

/// The analytic Jacobian of the coupled right-hand side at a steady state (θ̇ = 0, M_T = K_el θ).
pub fn jacobian(
    panel: &Panel,
    model: HingeModel,
    coupling: Coupling,
    flux: f64,
    eq: &Equilibrium,
) -> Matrix4<f64> {
    let h = 0.5 * panel.heat_capacity();
    let k = panel.conductance;
    let absorbed = panel.absorptivity * panel.solar_constant * flux;
    let s = eq.theta.sin();
    // d(absorbed · cos θ)/dθ; zero when the projected area is frozen.
    let d_heating = match coupling {
        Coupling::ProjectedArea => -absorbed * s,
        Coupling::Frozen => 0.0,
    };
    let rad_f = 4.0 * STEFAN_BOLTZMANN * panel.emissivity_front * eq.t_front.powi(3);
    let rad_b = 4.0 * STEFAN_BOLTZMANN * panel.emissivity_back * eq.t_back.powi(3);
    // Non-linear inertia factor 1 + 3 sin²θ; its derivative multiplies the static residual,
    // which is zero at the equilibrium, and the θ̇² term vanishes with θ̇.
    let inertia = panel.hinge_inertia()
        * match model {
            HingeModel::Nonlinear => 1.0 + 3.0 * s * s,
            HingeModel::Linear => 1.0,
        };
    let mu = panel.moment_per_kelvin();
    Matrix4::new(
        (-k - rad_f) / h,
        k / h,
        d_heating / h,
        0.0,
        k / h,
        (-k - rad_b) / h,
        0.0,
        0.0,
        0.0,
        0.0,
        0.0,
        1.0,
        mu / inertia,
        -mu / inertia,
        -panel.hinge_stiffness / inertia,
        -panel.damping / inertia,
    )
}

/// Eigen-analysis of the coupled system at the sunlit equilibrium under flux factor `flux`.
pub fn analyse(
    panel: &Panel,
    model: HingeModel,
    coupling: Coupling,
    flux: f64,
) -> Result<FlutterAnalysis> {
    let eq = equilibrium(panel, coupling, flux)?;
    let jac = jacobian(panel, model, coupling, flux, &eq);
    // Balance the scales (kelvin rows against radian rows) before the eigen-solve;
    // a diagonal similarity leaves the eigenvalues unchanged.
    let scale = Vector4::new(
        1.0,
        1.0,
        1.0 / eq.t_front.max(1.0),
        panel.natural_angular_frequency() / eq.t_front.max(1.0),
    );
    let balanced = Matrix4::from_fn(|i, j| jac[(i, j)] * scale[j] / scale[i]);
    let ev = balanced.complex_eigenvalues();
    if ev.iter().any(|z| !z.re.is_finite() || !z.im.is_finite()) {
        return Err(Error::NoConvergence {
            what: "eigenvalues".into(),
            reason: "non-finite result".into(),
        });
    }
    let mut eigenvalues = [ev[0], ev[1], ev[2], ev[3]];
    eigenvalues.sort_by(|a, b| b.re.total_cmp(&a.re).then(b.im.total_cmp(&a.im)));
    let growth_rate = eigenvalues[0].re;
    let omega = eigenvalues.iter().map(|z| z.im.abs()).fold(0.0, f64::max);
    Ok(FlutterAnalysis {
        equilibrium: eq,
        jacobian: jac,
        eigenvalues,
        growth_rate,
        frequency_hz: omega / (2.0 * std::f64::consts::PI),
    })
}

/// The damping c_d (N m s/rad) at which the growth rate crosses zero, by bracketing and bisection.
/// Returns 0 when the panel is stable even without damping.
pub fn critical_damping(
    panel: &Panel,
    model: HingeModel,
    coupling: Coupling,
    flux: f64,
) -> Result<f64> {
    let growth = |cd: f64| -> Result<f64> {
        let p = Panel {
            damping: cd,
            ..*panel
        };
        Ok(analyse(&p, model, coupling, flux)?.growth_rate)
    };
    if growth(0.0)? < 0.0 {
        return Ok(0.0);
    }
    // The equilibrium does not depend on c_d; only the hinge row of the Jacobian does.
    let mut hi = panel
        .damping
        .max(1e-3 * (panel.hinge_stiffness * panel.hinge_inertia()).sqrt());
    let mut n = 0;
    while growth(hi)? >= 0.0 {
        hi *= 2.0;
        n += 1;
        if n > 200 {
            return Err(Error::NoConvergence {
                what: "critical damping".into(),
                reason: "no stabilising damping found".into(),
            });
        }
    }
    let mut lo = 0.0;
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if growth(mid)? >= 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= 1e-12 * hi {
            break;
        }
    }
    Ok(0.5 * (lo + hi))
}

/// Checks a flux factor argument.
pub fn check_flux(flux: f64) -> Result<()> {
    require_non_negative("flux", flux)?;
    if flux == 0.0 {
        return Err(Error::invalid(
            "flux",
            flux,
            "must be > 0 (the analysis is about the sunlit equilibrium)",
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::orbit::Orbit;
    use crate::system::Coupled;

    #[test]
    fn analytic_jacobian_matches_finite_differences() {
        for model in [HingeModel::Nonlinear, HingeModel::Linear] {
            for coupling in [Coupling::ProjectedArea, Coupling::Frozen] {
                let p = Panel::paper();
                let eq = equilibrium(&p, coupling, 1.0).unwrap();
                let jac = jacobian(&p, model, coupling, 1.0, &eq);
                let sys = Coupled::new(p, Orbit::geo_equinox(), model, coupling);
                let y = Vector4::new(eq.t_front, eq.t_back, eq.theta, 0.0);
                for j in 0..4 {
                    let h = 1e-6 * y[j].abs().max(1e-3);
                    let mut yp = y;
                    let mut ym = y;
                    yp[j] += h;
                    ym[j] -= h;
                    let col = (sys.rhs_at_flux(1.0, &yp) - sys.rhs_at_flux(1.0, &ym)) / (2.0 * h);
                    for i in 0..4 {
                        let tol = 1e-6 * jac.column(j).amax().max(1e-12);
                        assert!(
                            (col[i] - jac[(i, j)]).abs() < tol,
                            "{model:?} {coupling:?} ({i},{j}): {} vs {}",
                            col[i],
                            jac[(i, j)]
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn frozen_area_cannot_flutter() {
        // Without the cos θ feedback the mechanical mode only sees its own damping.
        let p = Panel {
            damping: 0.0,
            ..Panel::paper()
        };
        let a = analyse(&p, HingeModel::Linear, Coupling::Frozen, 1.0).unwrap();
        assert!(a.growth_rate.abs() < 1e-12, "{}", a.growth_rate);
        assert_eq!(
            critical_damping(&p, HingeModel::Linear, Coupling::Frozen, 1.0).unwrap(),
            0.0
        );
    }

    #[test]
    fn undamped_coupled_panel_flutters_and_damping_cures_it() {
        let p = Panel {
            damping: 0.0,
            ..Panel::paper()
        };
        let a = analyse(&p, HingeModel::Nonlinear, Coupling::ProjectedArea, 1.0).unwrap();
        assert!(a.growth_rate > 0.0);
        let f_lin = p.natural_angular_frequency() / (2.0 * std::f64::consts::PI);
        assert!((a.frequency_hz / f_lin - 1.0).abs() < 0.05);
        let cd = critical_damping(&p, HingeModel::Nonlinear, Coupling::ProjectedArea, 1.0).unwrap();
        assert!(cd > 0.0);
        let above = analyse(
            &Panel {
                damping: cd * 1.01,
                ..p
            },
            HingeModel::Nonlinear,
            Coupling::ProjectedArea,
            1.0,
        )
        .unwrap();
        let below = analyse(
            &Panel {
                damping: cd * 0.99,
                ..p
            },
            HingeModel::Nonlinear,
            Coupling::ProjectedArea,
            1.0,
        )
        .unwrap();
        assert!(above.stable() && !below.stable());
    }
}
