//! ∂f/∂y of the coupled right-hand side at any state, and ∂f/∂(flux): the exponential integrator
//! linearises about the current state, not only about the sunlit equilibrium
//! ([`crate::analysis::flutter::jacobian`] is this matrix's value there).

use crate::inputs::heating::Loads;
use crate::inputs::panel::Panel;
use crate::models::coupled::{jacobian_from_rows, Coupling};
use crate::models::hinge::{generalised_moment, HingeModel};
use crate::models::thermal::STEFAN_BOLTZMANN;
use nalgebra::{Matrix4, Vector4};

/// The coupled system's coefficients, each per unit capacity or inertia (eqs. 2, 20, 28).
#[derive(Debug, Clone, Copy)]
pub struct Linearisation {
    model: HingeModel,
    coupling: Coupling,
    /// α C / (m c / 2), K/s per unit flux factor.
    heating: f64,
    /// K / (m c / 2), 1/s.
    conduction: f64,
    /// 1 / (m c / 2): a load absorbed on a face (W/m²) to its layer's rate, K/s.
    per_capacity: f64,
    /// σ ε / (m c / 2) of the front and back faces, 1/(s K³).
    radiation_front: f64,
    radiation_back: f64,
    /// M_T per kelvin over I_B, c_d / I_B and K_el / I_B.
    moment: f64,
    damping: f64,
    stiffness: f64,
}

impl Linearisation {
    pub fn new(panel: &Panel, model: HingeModel, coupling: Coupling) -> Self {
        let half_capacity = 0.5 * panel.heat_capacity();
        let inertia = panel.hinge_inertia();
        Linearisation {
            model,
            coupling,
            heating: panel.absorptivity * panel.solar_constant / half_capacity,
            conduction: panel.conductance / half_capacity,
            per_capacity: 1.0 / half_capacity,
            radiation_front: STEFAN_BOLTZMANN * panel.emissivity_front / half_capacity,
            radiation_back: STEFAN_BOLTZMANN * panel.emissivity_back / half_capacity,
            moment: panel.moment_per_kelvin() / inertia,
            damping: panel.damping_rate(),
            stiffness: panel.stiffness_rate(),
        }
    }

    /// ∂f/∂y at state y under flux factor `flux`.
    pub fn jacobian(&self, flux: f64, y: &Vector4<f64>) -> Matrix4<f64> {
        let (tf, tb, th, om) = (y[0], y[1], y[2], y[3]);
        let (sin, cos) = match (self.coupling, self.model) {
            (Coupling::Frozen, HingeModel::Linear) => (0.0, 1.0),
            _ => th.sin_cos(),
        };
        let d_heating = match self.coupling {
            Coupling::ProjectedArea => -self.heating * flux * sin,
            Coupling::Frozen => 0.0,
        };
        let rad_f = 4.0 * self.radiation_front * tf * tf * tf;
        let rad_b = 4.0 * self.radiation_back * tb * tb * tb;
        let (a_tf, a_tb, a_th, a_om) = match self.model {
            HingeModel::Linear => (self.moment, -self.moment, -self.stiffness, -self.damping),
            HingeModel::Nonlinear => {
                // θ̈ = N / D with N = forced − 3 θ̇² s c and D = 1 + 3 s² (eq. 20).
                let inertia = HingeModel::Nonlinear.inertia_factor(sin);
                let forced = generalised_moment(
                    self.moment * (tf - tb),
                    self.damping,
                    self.stiffness,
                    th,
                    om,
                );
                let n = forced - 3.0 * om * om * sin * cos;
                let cos2 = cos * cos - sin * sin;
                let dn_dth = -self.stiffness - 3.0 * om * om * cos2;
                let dd_dth = 6.0 * sin * cos;
                (
                    self.moment / inertia,
                    -self.moment / inertia,
                    (dn_dth * inertia - n * dd_dth) / (inertia * inertia),
                    (-self.damping - 6.0 * om * sin * cos) / inertia,
                )
            }
        };
        let c = self.conduction;
        jacobian_from_rows(
            [-c - rad_f, c, d_heating],
            [c, -c - rad_b],
            [a_tf, a_tb, a_th, a_om],
        )
    }

    /// ∂f/∂y at state y under `loads`: sunlight on the front and loads on each face (the
    /// Earth's, an attitude's), all on the projected area.
    pub fn jacobian_at_loads(&self, loads: Loads, y: &Vector4<f64>) -> Matrix4<f64> {
        let mut j = self.jacobian(loads.sun, y);
        if loads.has_face_loads() && self.coupling == Coupling::ProjectedArea {
            let sin = y[2].sin();
            j[(0, 2)] -= self.per_capacity * loads.front * sin;
            j[(1, 2)] -= self.per_capacity * loads.back * sin;
        }
        j
    }

    /// ∂f/∂(flux) at state y: the absorbed flux enters the front layer's balance only.
    pub fn flux_sensitivity(&self, y: &Vector4<f64>) -> Vector4<f64> {
        let area = match self.coupling {
            Coupling::ProjectedArea => y[2].cos(),
            Coupling::Frozen => 1.0,
        };
        Vector4::new(self.heating * area, 0.0, 0.0, 0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::inputs::orbit::Orbit;
    use crate::models::coupled::Coupled;
    use crate::numerics::testing::assert_jacobian;

    /// Away from any equilibrium (swinging, hot, cold) against central differences of the
    /// system's own right-hand side.
    #[test]
    fn jacobian_matches_finite_differences_anywhere() {
        let panel = Panel::paper();
        let states = [
            Vector4::new(380.0, 368.0, 0.085, 0.0),
            Vector4::new(250.0, 262.0, -0.3, 0.02),
            Vector4::new(120.0, 119.0, 0.6, -0.7),
        ];
        for model in [HingeModel::Nonlinear, HingeModel::Linear] {
            for coupling in [Coupling::ProjectedArea, Coupling::Frozen] {
                let sys = Coupled::new(panel, Orbit::geo_equinox(), model, coupling);
                let lin = Linearisation::new(&panel, model, coupling);
                for y in &states {
                    let f = |y: &Vector4<f64>| sys.rhs_at_flux(0.9, y);
                    let case = format!("{model:?} {coupling:?} {y}");
                    assert_jacobian(&lin.jacobian(0.9, y), f, y, 1e-9, &case);
                    let dflux =
                        (sys.rhs_at_flux(0.9 + 1e-6, y) - sys.rhs_at_flux(0.9 - 1e-6, y)) / 2e-6;
                    assert!((dflux - lin.flux_sensitivity(y)).amax() < 1e-6 * dflux.amax());
                    // With loads on both faces (W/m²).
                    let loads = Loads {
                        sun: 0.9,
                        front: 180.0,
                        back: 95.0,
                    };
                    let f = |y: &Vector4<f64>| sys.rhs_at_loads(loads, y);
                    assert_jacobian(&lin.jacobian_at_loads(loads, y), f, y, 1e-9, &case);
                }
            }
        }
    }
}
