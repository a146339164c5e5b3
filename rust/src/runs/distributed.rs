//! The distributed panel on an orbit: the coupled system on a run-time-sized state, integrated by
//! the generic integrators through eclipses and penumbrae, and its sampled fields.

use crate::cancel::Cancel;
use crate::error::{Error, Result};
use crate::inputs::heating::Optics;
use crate::inputs::orbit::Orbit;
use crate::models::coupled::Sunlight;
use crate::models::distributed::{DistributedPanel, ElementHeat};
use crate::numerics::integrate::Stats;
use crate::numerics::integrate::{Dyn, OdeSystem, State};
use crate::runs::orbits::LimitCrossing;
use crate::runs::simulate::{run_watched, Limit, OnLimit, TransientSettings};
use nalgebra::DVector;

/// The distributed panel driven by an orbit's sunlight, and by its Earth heating and attitude
/// when it has them; state (T_f[n], T_b[n], q[k], q̇[k]).
#[derive(Debug, Clone)]
pub struct DistributedSystem {
    pub model: DistributedPanel,
    sun: Sunlight,
}

impl DistributedSystem {
    pub fn new(model: DistributedPanel, orbit: Orbit) -> Self {
        let optics = Optics::of(&model.panel);
        DistributedSystem {
            model,
            sun: Sunlight::with_optics(orbit, optics),
        }
    }

    /// The orbit's heat on the elements at time t inside the current segment.
    fn heat(&self, t: f64) -> ElementHeat {
        let optics = self
            .sun
            .optics()
            .expect("the system is built with the panel's optics");
        ElementHeat::at(&self.sun.orbit, t, self.sun.illumination(t), optics)
    }
}

impl OdeSystem<Dyn> for DistributedSystem {
    fn rhs(&self, t: f64, y: &State<Dyn>) -> State<Dyn> {
        let mut dy = DVector::zeros(y.len());
        if self.sun.face_loads {
            self.model
                .rhs_loaded(&self.heat(t), y.as_slice(), dy.as_mut_slice());
        } else {
            self.model
                .rhs_at_flux(self.sun.flux(t), y.as_slice(), dy.as_mut_slice());
        }
        dy
    }
    fn breakpoints(&self, t0: f64, t1: f64) -> Vec<f64> {
        self.sun.orbit.breakpoints(t0, t1)
    }
    fn enter_segment(&mut self, a: f64, b: f64) {
        self.sun.enter(a, b);
    }
    fn check_span(&self, t0: f64, t1: f64) -> crate::error::Result<()> {
        self.model.check_orbit(&self.sun.orbit)?;
        crate::numerics::integrate::check_span(t0, t1)
    }
}

/// The sampled fields of a distributed run; per-sample rows.
#[derive(Debug, Clone)]
pub struct DistributedRun {
    pub t: Vec<f64>,
    /// Names of an element's temperatures ("T_front", "T_back" for two layers).
    pub names: Vec<String>,
    /// Per sample, per name, the temperature of every element, K.
    pub temperatures: Vec<Vec<Vec<f64>>>,
    /// Thermal moment per element, N m.
    pub moment: Vec<Vec<f64>>,
    /// Deflection (m) and slope per node.
    pub deflection: Vec<Vec<f64>>,
    pub slope: Vec<Vec<f64>>,
    /// θ_f, rad.
    pub theta_f: Vec<f64>,
    /// s(t), the illuminated fraction.
    pub sunlit: Vec<f64>,
    /// The flux reaching the flat panel's front and back face at each sample, W/m² (sunlight,
    /// albedo and Earth infrared in its attitude, the deflection not applied).
    pub fluxes: (Vec<f64>, Vec<f64>),
    pub stats: Stats,
    pub y_end: Vec<f64>,
    /// Where |θ_f| first passed the validity limit, when one was watched.
    pub crossing: Option<LimitCrossing>,
}

/// Integrates `model` on `orbit` as `settings` say: over their span from their `y0` (default: the
/// sunlit equilibrium at the start's flux scale), sampled as their `output` asks, watching θ_f
/// against their `limit` (see
/// [`crate::runs::simulate::run_watched`]) and stopping within a step of `cancel`.
pub fn simulate(
    model: &DistributedPanel,
    orbit: Orbit,
    settings: TransientSettings,
    cancel: &Cancel,
) -> Result<DistributedRun> {
    let t_span = settings.span;
    orbit.validate()?;
    model.check_orbit(&orbit)?;
    let (t0, _) = t_span;
    crate::numerics::integrate::check_span(t_span.0, t_span.1)?;
    let start = match settings.y0 {
        Some(v) => {
            check_state(model, &v)?;
            v
        }
        None => start_state(model, &orbit, t0)?,
    };
    let mut system = DistributedSystem::new(model.clone(), orbit);
    let watch = settings.limit.map(|on| model.limit(on));
    let traj = run_watched(
        &mut system,
        &settings.method,
        t_span,
        DVector::from_vec(start),
        &settings.output,
        watch.as_ref(),
        cancel,
    )?;
    let crossing = match &traj.crossing {
        Some((t, y)) => {
            let theta = model.theta_f(y.as_slice(), *t)?;
            Some(LimitCrossing::in_run(&orbit, t0, *t, theta))
        }
        None => None,
    };
    let mut out = DistributedRun {
        t: traj.t.clone(),
        names: model.temperature_names(),
        temperatures: Vec::with_capacity(traj.t.len()),
        moment: Vec::with_capacity(traj.t.len()),
        deflection: Vec::with_capacity(traj.t.len()),
        slope: Vec::with_capacity(traj.t.len()),
        theta_f: Vec::with_capacity(traj.t.len()),
        sunlit: Vec::with_capacity(traj.t.len()),
        fluxes: orbit.face_flux_samples(&traj.t, model.panel.solar_constant),
        stats: traj.stats,
        y_end: traj.y_end.as_slice().to_vec(),
        crossing,
    };
    for (t, y) in traj.t.iter().zip(&traj.y) {
        let y = y.as_slice();
        out.temperatures.push(model.temperature_rows(y));
        out.moment.push(model.moments(y));
        let (w, s) = model.nodal(y);
        out.deflection.push(w);
        out.slope.push(s);
        out.theta_f.push(model.theta_f(y, *t)?);
        out.sunlit.push(orbit.illumination(*t));
    }
    Ok(out)
}

/// Refuses a start state that is not `model`'s: its size, and its temperatures as every start
/// state's (the modal amplitudes have no such range).
pub(crate) fn check_state(model: &DistributedPanel, v: &[f64]) -> Result<()> {
    if v.len() != model.state_size() {
        return Err(Error::invalid(
            "y0",
            format!("{} components", v.len()),
            &format!(
                "must hold {} (the {} temperatures of each of {} elements, then q and q̇ of {} modes)",
                model.state_size(),
                model.layers(),
                model.n(),
                model.k()
            ),
        ));
    }
    crate::models::hinge::check_start_state(v, model.layers() * model.n(), None)
}

/// The default start of a run of `model` on `orbit` at t0: the sunlit equilibrium at rest under
/// the Sun's distance at t0, and under the Earth's loads and the attitude there when the orbit
/// has them.
pub fn start_state(model: &DistributedPanel, orbit: &Orbit, t0: f64) -> Result<Vec<f64>> {
    Orbit::check_time(t0)?;
    if orbit.has_face_loads() {
        let optics = Optics::of(&model.panel);
        return model.equilibrium_loaded(&ElementHeat::at(orbit, t0, 1.0, optics));
    }
    model.equilibrium(orbit.flux_scale(t0))
}

impl DistributedPanel {
    /// Refuses an orbit whose attitude would be set twice: with the Earth's heat or an attitude
    /// other than Sun-pointing the attitude sets the incidence, and ψ must be 0.
    pub fn check_orbit(&self, orbit: &Orbit) -> Result<()> {
        if orbit.has_face_loads() && self.settings.sun_angle != 0.0 {
            return Err(Error::invalid(
                "sun_angle",
                self.settings.sun_angle,
                "must be 0 with the orbit's Earth heating or an attitude: the attitude sets the \
                 Sun's incidence on the panel",
            ));
        }
        Ok(())
    }

    /// The validity limit on θ_f as the integrators watch it: |tip rise| <= arm · sin(θ_limit),
    /// the rise an affine function of the state (the modes' share, and the element moments',
    /// which are linear in the temperatures: read off unit temperatures).
    pub fn limit(&self, on: OnLimit) -> Limit {
        let s = self.layers();
        let r = &self.reduction;
        let zero = vec![0.0; s];
        let m0 = self.thermal.moment(&zero);
        let mut weights = Vec::with_capacity(self.state_size());
        let mut unit = zero.clone();
        for e in 0..self.n() {
            for i in 0..s {
                unit[i] = 1.0;
                weights.push((
                    e * s + i,
                    r.rise_residual[e] * (self.thermal.moment(&unit) - m0),
                ));
                unit[i] = 0.0;
            }
        }
        for j in 0..self.k() {
            weights.push((self.temps() + j, r.rise_modal[j]));
        }
        Limit {
            weights,
            offset: r.rise_residual.sum() * m0,
            bound: r.mesh.arm() * on.theta_limit.sin(),
            stop: on.stop,
        }
    }
}
