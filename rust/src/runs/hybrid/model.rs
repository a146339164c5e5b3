//! What the hybrid propagator needs of a coupled model whose state (thermal coordinates…, θ, θ̇)
//! has N components: its right-hand side, Jacobian and flux sensitivity at any state, its
//! sunlit equilibrium, the quasi-static deflection M_T/K_el, and the summaries' view. The
//! two-layer model ([`TwoLayerModel`]) implements it with its analytic derivatives; the N-node
//! laminate implements it in `crate::models::layered`.

use super::jacobian::Linearisation;
use crate::analysis::steady::equilibrium;
use crate::error::Result;
use crate::inputs::panel::Panel;
use crate::models::coupled::{Coupled, Coupling};
use crate::models::hinge::{thermal_moment, HingeModel};
use crate::numerics::integrate::{OdeSystem, State};
use crate::numerics::newton::newton;
use crate::runs::orbits::{SummaryView, TwoLayerView};
use nalgebra::{Const, DMatrix, DVector, SMatrix, SVector, Vector4, U4};

/// A coupled model the hybrid propagator can run; θ and θ̇ are the last two components.
pub(crate) trait HybridModel<const N: usize>: OdeSystem<Const<N>> + Clone {
    type View: SummaryView;

    /// The summaries' view of the state.
    fn view(&self) -> Self::View;
    fn panel(&self) -> &Panel;
    fn hinge(&self) -> HingeModel;
    /// dy/dt under the illumination factor `flux` (before the projected area).
    fn rhs_at_flux(&self, flux: f64, y: &SVector<f64, N>) -> SVector<f64, N>;
    /// The illumination factor inside the current segment at t.
    fn flux_at(&self, t: f64) -> f64;
    /// ∂f/∂y at any state.
    fn jacobian(&self, flux: f64, y: &SVector<f64, N>) -> SMatrix<f64, N, N>;
    /// ∂f/∂(flux) at state y.
    fn flux_sensitivity(&self, flux: f64, y: &SVector<f64, N>) -> SVector<f64, N>;
    /// The sunlit equilibrium under `flux`, at rest; `from` is the last one found (at a flux
    /// that has barely changed), a start for Newton's method.
    fn equilibrium(&self, flux: f64, from: Option<&SVector<f64, N>>) -> Result<SVector<f64, N>>;
    /// The quasi-static deflection M_T/K_el of state y and its rate along f = dy/dt (rad,
    /// rad/s): the oscillation is measured about it.
    fn static_angle(&self, flux: f64, y: &SVector<f64, N>, f: &SVector<f64, N>) -> (f64, f64);
    /// M_T/K_el as the summaries read it (rad).
    fn quasi_static(&self, flux: f64, y: &SVector<f64, N>) -> f64;
    /// (w, c) with w·y + c the dynamic part θ − M_T/K_el linearised about `y_ref`: c is zero
    /// when M_T is linear in the state, and not when it is affine (a reduced model's
    /// coordinates, a reference temperature).
    fn dynamic_weights(&self, flux: f64, y_ref: &SVector<f64, N>) -> (SVector<f64, N>, f64);
}

/// The paper's two-layer model (T_f, T_b, θ, θ̇).
#[derive(Debug, Clone, Copy)]
pub(crate) struct TwoLayerModel {
    pub(crate) system: Coupled,
    pub(crate) lin: Linearisation,
    panel: Panel,
    model: HingeModel,
    coupling: Coupling,
    /// Static θ per kelvin of gradient, rad/K.
    theta_per_kelvin: f64,
}

impl TwoLayerModel {
    pub(crate) fn new(
        panel: &Panel,
        orbit: &crate::inputs::orbit::Orbit,
        model: HingeModel,
        coupling: Coupling,
    ) -> Self {
        TwoLayerModel {
            system: Coupled::new(*panel, *orbit, model, coupling),
            lin: Linearisation::new(panel, model, coupling),
            panel: *panel,
            model,
            coupling,
            theta_per_kelvin: panel.moment_per_kelvin() / panel.hinge_stiffness,
        }
    }

    /// The equilibrium under `flux` by Newton's method from the state `start` at rest
    /// ([`equilibrium_at_rest`]): the unknowns (T_f, T_b, θ), the equations dT_f/dt = dT_b/dt =
    /// θ̈ = 0, with the analytic Jacobian.
    fn equilibrium_from(&self, flux: f64, start: &Vector4<f64>) -> Result<Vector4<f64>> {
        // As steady::steady: temperatures to 1e-12 relative, the angle to 1e-14 rad.
        let settled = |x: &DVector<f64>, dx: &DVector<f64>| {
            dx[0].abs() < 1e-12 * x[0] && dx[1].abs() < 1e-12 * x[1] && dx[2].abs() < 1e-14
        };
        equilibrium_at_rest(self, flux, start, 2, settled)
    }
}

/// A model's equilibrium at rest under `flux`, by Newton's method on its own right-hand side and
/// Jacobian from `start`: the unknowns every component but θ̇ (the last), the equations every
/// rate but θ' = θ̇ (the one before last). The first `n_temps` unknowns are kept positive;
/// `settled(x, dx)` ends it.
pub(crate) fn equilibrium_at_rest<const N: usize, M: HybridModel<N>>(
    model: &M,
    flux: f64,
    start: &SVector<f64, N>,
    n_temps: usize,
    settled: impl Fn(&DVector<f64>, &DVector<f64>) -> bool,
) -> Result<SVector<f64, N>> {
    let rows: Vec<usize> = (0..N).filter(|&i| i != N - 2).collect();
    let state = |x: &DVector<f64>| {
        let mut y = SVector::<f64, N>::zeros();
        y.as_mut_slice()[..N - 1].copy_from_slice(x.as_slice());
        y
    };
    let system = |x: &DVector<f64>| {
        let y = state(x);
        let (f, jac) = (model.rhs_at_flux(flux, &y), model.jacobian(flux, &y));
        (
            DVector::from_fn(N - 1, |i, _| f[rows[i]]),
            DMatrix::from_fn(N - 1, N - 1, |i, j| jac[(rows[i], j)]),
        )
    };
    let x0 = DVector::from_column_slice(&start.as_slice()[..N - 1]);
    Ok(state(&newton(
        "sunlit equilibrium",
        x0,
        n_temps,
        system,
        settled,
    )?))
}

impl OdeSystem<U4> for TwoLayerModel {
    #[inline(always)]
    fn rhs(&self, t: f64, y: &State<U4>) -> State<U4> {
        self.system.rhs(t, y)
    }
    fn breakpoints(&self, t0: f64, t1: f64) -> Vec<f64> {
        self.system.breakpoints(t0, t1)
    }
    fn check_span(&self, t0: f64, t1: f64) -> Result<()> {
        self.system.check_span(t0, t1)
    }
    fn enter_segment(&mut self, a: f64, b: f64) {
        self.system.enter_segment(a, b)
    }
}

impl HybridModel<4> for TwoLayerModel {
    type View = TwoLayerView;

    fn view(&self) -> TwoLayerView {
        TwoLayerView {
            panel: self.panel,
            coupling: self.coupling,
        }
    }
    fn panel(&self) -> &Panel {
        &self.panel
    }
    fn hinge(&self) -> HingeModel {
        self.model
    }
    // Inlined into the integrators' loops (the resolved stretches' RK4 steps call it four
    // times a step, one after the other).
    #[inline(always)]
    fn rhs_at_flux(&self, flux: f64, y: &Vector4<f64>) -> Vector4<f64> {
        self.system.rhs_at_flux(flux, y)
    }
    fn flux_at(&self, t: f64) -> f64 {
        self.system.flux_at(t)
    }
    fn jacobian(&self, flux: f64, y: &Vector4<f64>) -> nalgebra::Matrix4<f64> {
        self.lin.jacobian(flux, y)
    }
    fn flux_sensitivity(&self, _flux: f64, y: &Vector4<f64>) -> Vector4<f64> {
        self.lin.flux_sensitivity(y)
    }
    fn equilibrium(&self, flux: f64, from: Option<&Vector4<f64>>) -> Result<Vector4<f64>> {
        match from {
            Some(y) => self.equilibrium_from(flux, y),
            None => Ok(equilibrium(&self.panel, self.coupling, flux)?.state()),
        }
    }
    fn static_angle(&self, _flux: f64, y: &Vector4<f64>, f: &Vector4<f64>) -> (f64, f64) {
        let k = self.theta_per_kelvin;
        (k * (y[0] - y[1]), k * (f[0] - f[1]))
    }
    fn quasi_static(&self, _flux: f64, y: &Vector4<f64>) -> f64 {
        thermal_moment(&self.panel, y[0], y[1]) / self.panel.hinge_stiffness
    }
    fn dynamic_weights(&self, _flux: f64, _y_ref: &Vector4<f64>) -> (Vector4<f64>, f64) {
        // M_T/K_el = k (T_f − T_b): linear, no offset.
        let k = self.theta_per_kelvin;
        (Vector4::new(-k, k, 1.0, 0.0), 0.0)
    }
}
