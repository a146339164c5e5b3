//! The N-node laminate as the hybrid propagator's model, and its runs of many orbits.

use crate::analysis::layered::equilibrium;
use crate::error::{Error, Result};
use crate::inputs::heating::Loads;
use crate::inputs::panel::Panel;
use crate::models::coupled::Coupling;
use crate::models::hinge::HingeModel;
use crate::numerics::integrate::{OdeSystem, State};
use crate::runs::hybrid::model::{equilibrium_at_rest, HybridModel};
use crate::runs::layered::{
    check_start, LayeredOrbit, LayeredRunRequest, LayeredSummaries, LayeredView,
};
use nalgebra::{Const, DVector, SMatrix, SVector};

/// The N-node system as the hybrid propagator's model, on a state of S components (the slow
/// thermal coordinates, θ, θ̇): the same right-hand side as the full run, its derivatives by
/// central differences (the slow-mode model's faces are solved by Newton's method, so it has no
/// closed-form Jacobian; S is small, so 2S evaluations a Jacobian are cheap).
#[derive(Debug, Clone)]
struct HybridLayered<const S: usize> {
    orbit: LayeredOrbit,
    panel: Panel,
    coupling: Coupling,
}

/// Relative step of the central differences, and the magnitudes below which each kind of
/// component is stepped absolutely: K, rad, rad/s. Larger than the cube root of the rounding
/// unit (6e-6) because the faces are solved by Newton's method, whose tolerance is noise in
/// the right-hand side. The 20-node wing's growth rate in the hybrid run against the 20-node
/// eigenvalue, at steps 6e-6, 6e-5, 2e-4, 6e-4: −1.45e-10, +3.0e-11, +6.6e-11, +6.9e-11 /s;
/// the last two are the slow-mode cut's own +5.5e-3 of the rate (docs/laminates.md).
const DIFFERENCE_STEP: f64 = 2e-4;
const DIFFERENCE_FLOOR: [f64; 3] = [1.0, 1e-3, 1e-3];

impl<const S: usize> HybridLayered<S> {
    fn step(&self, y: &SVector<f64, S>, j: usize) -> f64 {
        let floor = DIFFERENCE_FLOOR[match S - j {
            2 => 1,
            1 => 2,
            _ => 0,
        }];
        DIFFERENCE_STEP * y[j].abs().max(floor)
    }

    /// ∂g/∂y_j of a function of the state by central differences, for every j.
    fn gradient<R>(
        &self,
        y: &SVector<f64, S>,
        g: impl Fn(&SVector<f64, S>) -> R,
        mut column: impl FnMut(usize, R, R, f64),
    ) {
        for j in 0..S {
            let h = self.step(y, j);
            let (mut plus, mut minus) = (*y, *y);
            plus[j] += h;
            minus[j] -= h;
            // The step actually taken, so that rounding of y ± h does not bias the quotient.
            column(j, g(&plus), g(&minus), plus[j] - minus[j]);
        }
    }

    fn angle(&self, flux: f64, y: &SVector<f64, S>) -> f64 {
        self.orbit.system.moment_of(Loads::sun(flux), y.as_slice()) / self.panel.hinge_stiffness
    }
}

impl<const S: usize> OdeSystem<Const<S>> for HybridLayered<S> {
    #[inline]
    fn rhs(&self, t: f64, y: &State<Const<S>>) -> State<Const<S>> {
        HybridModel::rhs_at_flux(self, self.orbit.sun.flux(t), y)
    }
    fn breakpoints(&self, t0: f64, t1: f64) -> Vec<f64> {
        self.orbit.breakpoints(t0, t1)
    }
    fn enter_segment(&mut self, a: f64, b: f64) {
        self.orbit.enter_segment(a, b);
    }
}

impl<const S: usize> HybridModel<S> for HybridLayered<S> {
    type View = LayeredView;

    fn view(&self) -> LayeredView {
        LayeredView::new(
            self.orbit.system.clone(),
            self.panel,
            self.orbit.sun.orbit,
            self.coupling,
        )
    }
    fn panel(&self) -> &Panel {
        &self.panel
    }
    fn hinge(&self) -> HingeModel {
        self.orbit.system.model
    }
    fn rhs_at_flux(&self, flux: f64, y: &SVector<f64, S>) -> SVector<f64, S> {
        let mut dy = SVector::<f64, S>::zeros();
        self.orbit
            .system
            .rhs_at_flux(flux, y.as_slice(), dy.as_mut_slice());
        dy
    }
    fn flux_at(&self, t: f64) -> f64 {
        self.orbit.sun.flux(t)
    }
    fn jacobian(&self, flux: f64, y: &SVector<f64, S>) -> SMatrix<f64, S, S> {
        let mut jac = SMatrix::<f64, S, S>::zeros();
        self.gradient(
            y,
            |x| HybridModel::rhs_at_flux(self, flux, x),
            |j, plus, minus, h| jac.set_column(j, &((plus - minus) / h)),
        );
        jac
    }
    fn flux_sensitivity(&self, flux: f64, y: &SVector<f64, S>) -> SVector<f64, S> {
        let h = 1e-6;
        (self.rhs_at_flux(flux + h, y) - self.rhs_at_flux(flux - h, y)) / (2.0 * h)
    }
    fn equilibrium(&self, flux: f64, from: Option<&SVector<f64, S>>) -> Result<SVector<f64, S>> {
        let start = match from {
            Some(y) => *y,
            None => {
                let c = &self.orbit.system.conduction;
                let eq = equilibrium(&self.panel, c, self.coupling, flux)?;
                let y = self
                    .orbit
                    .system
                    .state_from_nodes(&eq.temperatures, eq.theta, 0.0);
                SVector::from_column_slice(&y)
            }
        };
        // Refined on this model's own right-hand side (the slow-mode model's steady state in its
        // coordinates).
        let settled = |x: &DVector<f64>, dx: &DVector<f64>| {
            (0..S - 2).all(|i| dx[i].abs() < 1e-12 * x[i].abs().max(1.0)) && dx[S - 2].abs() < 1e-14
        };
        equilibrium_at_rest(self, flux, &start, 0, settled)
    }
    fn static_angle(&self, flux: f64, y: &SVector<f64, S>, f: &SVector<f64, S>) -> (f64, f64) {
        // The rate along the flow by a central difference over 10 ms.
        let dt = 1e-2;
        let rate = (self.angle(flux, &(y + f * dt)) - self.angle(flux, &(y - f * dt))) / (2.0 * dt);
        (self.angle(flux, y), rate)
    }
    fn quasi_static(&self, flux: f64, y: &SVector<f64, S>) -> f64 {
        self.angle(flux, y)
    }
    fn dynamic_weights(&self, flux: f64, y_ref: &SVector<f64, S>) -> (SVector<f64, S>, f64) {
        // M_T/K_el ≈ m(y_ref) + ∇m·(y − y_ref): affine in the slow-mode coordinates, so
        // θ − M_T/K_el ≈ w·y + c with w = e_θ − ∇m and c = ∇m·y_ref − m(y_ref).
        let mut grad = SVector::<f64, S>::zeros();
        self.gradient(
            y_ref,
            |x| self.angle(flux, x),
            |j, plus, minus, h| grad[j] = (plus - minus) / h,
        );
        let offset = grad.dot(y_ref) - self.angle(flux, y_ref);
        let mut w = -grad;
        w[S - 2] += 1.0;
        (w, offset)
    }
}

/// A hybrid run of the N-node system: the summaries (end state as node temperatures, θ, θ̇)
/// and how the time was split.
pub struct LayeredHybrid {
    pub run: LayeredSummaries,
    pub split: crate::runs::hybrid::HybridRun,
}

/// The largest state (slow thermal coordinates, θ, θ̇) the hybrid propagator is built for.
pub const HYBRID_MAX_STATE: usize = 24;

/// Per-orbit summaries of the N-node system by the hybrid propagator (as
/// [`crate::runs::hybrid::run_orbits_hybrid`]); `req.spec.method` is the full integration of its fallback.
pub fn run_orbits_hybrid(
    req: &LayeredRunRequest,
    settings: &crate::runs::hybrid::HybridSettings,
    cancel: &crate::cancel::Cancel,
) -> Result<LayeredHybrid> {
    let (y0, n, spec) = (&req.y0, req.conduction.nodes(), &req.spec);
    check_start(&spec.panel, y0, n)?;
    crate::runs::hybrid::check_request(spec, y0, settings, cancel)?;
    if req.conduction.two_layer {
        // Two nodes on a plain panel are eq. 2: the two-layer hybrid run, to the bit.
        let out = crate::runs::hybrid::run_orbits_hybrid(&req.two_layer(), settings, cancel)?;
        let run = out.run.clone().into();
        return Ok(LayeredHybrid { run, split: out });
    }
    if req.spec.orbit.has_face_loads() {
        // As the two-layer hybrid: the Earth's loads and an attitude vary the forcing along
        // every arc, so the orbits run in full, all of their time counted as the fallback's.
        let run = crate::runs::layered::run_orbits(req, cancel)?;
        let split = crate::runs::hybrid::counted_as_fallback(&run.summaries, run.stats.n_steps);
        return Ok(LayeredHybrid { run, split });
    }
    let (system, start) = req.system()?;
    let args = HybridArgs {
        spec,
        settings,
        cancel,
    };
    macro_rules! sizes {
        ($($s:literal)*) => {
            match start.len() {
                $($s => hybrid_run::<$s>(
                    HybridLayered {
                        orbit: LayeredOrbit::new(system.clone(), &spec.panel, spec.orbit),
                        panel: spec.panel,
                        coupling: spec.coupling,
                    },
                    &start,
                    &args,
                ),)*
                other => Err(Error::invalid(
                    "layers",
                    other,
                    &format!(
                        "gives a state of {other} components; the hybrid propagator takes 3 to \
                         {HYBRID_MAX_STATE} (use method = \"rk45\")"
                    ),
                )),
            }
        };
    }
    let (mut run, split) = sizes!(3 4 5 6 7 8 9 10 11 12 13 14 15 16 17 18 19 20 21 22 23 24)?;
    run.y_end = req.nodal(&system, run.stats.t_end, &run.y_end);
    Ok(LayeredHybrid { run, split })
}

/// What a hybrid run is asked, passed through the size dispatch.
struct HybridArgs<'a> {
    spec: &'a crate::runs::orbits::OrbitRunSpec,
    settings: &'a crate::runs::hybrid::HybridSettings,
    cancel: &'a crate::cancel::Cancel,
}

fn hybrid_run<const S: usize>(
    model: HybridLayered<S>,
    y0: &[f64],
    a: &HybridArgs<'_>,
) -> Result<(LayeredSummaries, crate::runs::hybrid::HybridRun)> {
    let y0 = SVector::from_column_slice(y0);
    let done = crate::runs::hybrid::propagate(model, a.spec, y0, a.settings, a.cancel)?;
    Ok((done.run.into(), done.split))
}
