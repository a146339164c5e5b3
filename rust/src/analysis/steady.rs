//! Steady states under constant sunlight: every temperature's heat flow zero and the structure
//! at rest under the thermal moment, for any thermal model and structural model, by Newton's
//! method with a finite-difference Jacobian.

use crate::error::{Error, Result};
use crate::inputs::heating::Loads;
use crate::inputs::panel::Panel;
use crate::models::coupled::{Coupled, Coupling};
use crate::models::hinge::{Hinge, HingeModel, StructuralModel};
use crate::models::thermal::{ThermalModel, TwoLayer};
use crate::numerics::integrate::State;
use crate::numerics::newton::newton;
use nalgebra::allocator::Allocator;
use nalgebra::{DMatrix, DVector, DefaultAllocator, Dim};

/// The steady state of the paper's model under constant flux factor `flux` (1: full Sun at the
/// nominal constant).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Equilibrium {
    pub t_front: f64,
    pub t_back: f64,
    pub theta: f64,
}

impl Equilibrium {
    /// The state (T_f, T_b, θ, θ̇ = 0).
    pub fn state(&self) -> nalgebra::Vector4<f64> {
        nalgebra::Vector4::new(self.t_front, self.t_back, self.theta, 0.0)
    }
}

/// Residual of the steady equations at x = (temperatures, positions): the heat flows (W/m²) and
/// the structure's static balance, each in balanced units so that Newton's test is too.
fn residual<T, S>(
    thermal: &T,
    structure: &S,
    coupling: Coupling,
    loads: Loads,
    x: &[f64],
) -> DVector<f64>
where
    T: ThermalModel + ?Sized,
    S: StructuralModel,
{
    let n = thermal.size();
    let (temps, positions) = x.split_at(n);
    let area = match coupling {
        Coupling::ProjectedArea => structure.area_factor(&rest_state(structure, positions)),
        Coupling::Frozen => 1.0,
    };
    let mut r = DVector::zeros(x.len());
    let (flows, statics) = r.as_mut_slice().split_at_mut(n);
    // The rates dT/dt (heat flow over capacity), scaled back to W/m² by the capacity.
    thermal.heat_flows(loads.sun * area, temps, flows);
    if loads.has_face_loads() {
        thermal.add_face_flows(loads.front * area, loads.back * area, flows);
    }
    for (i, f) in flows.iter_mut().enumerate() {
        let capacity = thermal.capacity(i);
        *f = *f / capacity * capacity;
    }
    structure.static_residual(thermal.moment(temps), positions, statics);
    r
}

/// The structure's state at rest in `positions` (velocities zero).
fn rest_state<S: StructuralModel>(structure: &S, positions: &[f64]) -> Vec<f64> {
    let mut q = vec![0.0; structure.size()];
    q[..positions.len()].copy_from_slice(positions);
    q
}

/// Flux factors a steady state is sought for: from far beyond the planets (1e-6, at 1000 au) to
/// 100 (0.1 au, well inside Mercury's orbit). Beyond them a panel's temperatures underflow or
/// soar to thousands of kelvin, and Newton fails without saying why.
pub const FLUX_RANGE: (f64, f64) = (1e-6, 100.0);

/// The steady state of `thermal` coupled to `structure` under constant flux factor `flux`:
/// (temperatures, positions), velocities being zero. Newton from the isothermal plate's
/// temperature and the unloaded shape, with a forward-difference Jacobian.
pub fn steady<T, S>(
    thermal: &T,
    structure: &S,
    coupling: Coupling,
    flux: f64,
) -> Result<DVector<f64>>
where
    T: ThermalModel + ?Sized,
    S: StructuralModel,
{
    steady_loaded(thermal, structure, coupling, Loads::sun(flux), flux)
}

/// [`steady`] under loads on both faces; `flux` is the front's solar flux factor that heats the
/// plate as much (where Newton starts, and what is checked against [`FLUX_RANGE`]).
pub fn steady_loaded<T, S>(
    thermal: &T,
    structure: &S,
    coupling: Coupling,
    loads: Loads,
    flux: f64,
) -> Result<DVector<f64>>
where
    T: ThermalModel + ?Sized,
    S: StructuralModel,
{
    let (low, high) = FLUX_RANGE;
    if !(low..=high).contains(&flux) {
        return Err(Error::invalid(
            "flux",
            flux,
            &format!("must be in [{low:e}, {high}] (the solar flux over its value at 1 au)"),
        ));
    }
    let n = thermal.size();
    let m = n + structure.positions();
    let mut x = DVector::zeros(m);
    thermal.initial_guess(flux, &mut x.as_mut_slice()[..n]);
    let f_of = |x: &DVector<f64>| residual(thermal, structure, coupling, loads, x.as_slice());
    let residual_and_jacobian = |x: &DVector<f64>| {
        let f = f_of(x);
        let mut jac = DMatrix::zeros(m, m);
        for j in 0..m {
            let h = 1e-7 * x[j].abs().max(1e-3);
            let mut xp = x.clone();
            xp[j] += h;
            jac.set_column(j, &((f_of(&xp) - &f) / h));
        }
        (f, jac)
    };
    let settled = |x: &DVector<f64>, dx: &DVector<f64>| {
        let temperatures_settled = (0..n).all(|i| dx[i].abs() < 1e-12 * x[i]);
        let shape_settled = (n..m).all(|i| dx[i].abs() < 1e-14);
        temperatures_settled && shape_settled
    };
    let x = newton("steady state", x, n, residual_and_jacobian, settled)?;
    structure.check_static(&x.as_slice()[n..])?;
    Ok(x)
}

/// The full state at rest of a system of dimension `dim` from a steady (temperatures,
/// positions): the velocities zero.
pub fn rest<D: Dim>(x: &DVector<f64>, dim: D) -> State<D>
where
    DefaultAllocator: Allocator<D>,
{
    let mut y = State::<D>::zeros_generic(dim, nalgebra::U1);
    y.as_mut_slice()[..x.len()].copy_from_slice(x.as_slice());
    y
}

impl<T: ThermalModel, S: StructuralModel, D: Dim> Coupled<T, S, D>
where
    DefaultAllocator: Allocator<D>,
{
    /// The steady state under constant flux factor `flux`, velocities zero: the default start
    /// of a run.
    pub fn steady_state(&self, flux: f64) -> Result<State<D>> {
        let x = steady(self.thermal(), self.structure(), self.coupling(), flux)?;
        Ok(rest(&x, self.dim()))
    }

    /// The steady state under constant `loads` on both faces (`flux`: the front's solar flux
    /// factor heating as much, see [`steady_loaded`]), velocities zero.
    pub fn steady_state_loaded(&self, loads: Loads, flux: f64) -> Result<State<D>> {
        let x = steady_loaded(
            self.thermal(),
            self.structure(),
            self.coupling(),
            loads,
            flux,
        )?;
        Ok(rest(&x, self.dim()))
    }
}

/// The paper model's steady state: two layers and the hinge (whose static balance does not
/// depend on the linear or non-linear form).
pub fn equilibrium(panel: &Panel, coupling: Coupling, flux: f64) -> Result<Equilibrium> {
    panel.validate()?;
    let x = steady(
        &TwoLayer::new(panel),
        &Hinge::new(panel, HingeModel::Nonlinear),
        coupling,
        flux,
    )?;
    Ok(Equilibrium {
        t_front: x[0],
        t_back: x[1],
        theta: x[2],
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::inputs::orbit::Orbit;
    use crate::models::coupled::Coupled;

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
        let rate = sys.rhs_at_flux(1.0, &eq.state());
        assert!(rate.amax() < 1e-9, "{rate}");
        let frozen = equilibrium(&p, Coupling::Frozen, 1.0).unwrap();
        assert!(frozen.theta > eq.theta, "cos θ lowers the absorbed flux");
    }

    #[test]
    fn thermal_steady_state_is_the_isothermal_closed_form_for_one_node() {
        let p = Panel::paper();
        for flux in [1.0, 0.97] {
            let one = crate::models::thermal::OneNode::new(&p);
            let exact = one.equilibrium(flux);
            let orbit = crate::inputs::orbit::Orbit::geo_equinox();
            let y = crate::models::coupled::Coupled::thermal_only(one, orbit)
                .steady_state(flux)
                .unwrap();
            assert!((y[0] - exact).abs() <= 1e-13 * exact, "{} vs {exact}", y[0]);
        }
    }

    #[test]
    fn flux_factors_outside_the_range_are_named() {
        let p = Panel::paper();
        for flux in [0.0, 5e-324, 0.9e-6, 100.1, 1e12, f64::NAN, f64::INFINITY] {
            match equilibrium(&p, Coupling::ProjectedArea, flux) {
                Err(crate::error::Error::InvalidParameter { name, .. }) => assert_eq!(name, "flux"),
                other => panic!("flux {flux}: {other:?}"),
            }
        }
        for flux in [FLUX_RANGE.0, 0.0111, 1.0, 10.6] {
            assert!(
                equilibrium(&p, Coupling::ProjectedArea, flux).is_ok(),
                "flux {flux}"
            );
        }
    }
}
