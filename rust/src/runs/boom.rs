//! Runs of the boom (`models::tube`): a transient, and whole orbits summarised orbit by orbit,
//! on the same integrators, observers and summaries as the panel's.

use crate::cancel::Cancel;
use crate::error::Result;
use crate::inputs::boom::Boom;
use crate::inputs::orbit::Orbit;
use crate::models::coupled::Coupling;
use crate::models::hinge::HingeModel;
use crate::models::thermal::ThermalModel;
use crate::models::tube::{boom_system, TubeSystem};
use crate::numerics::integrate::Method;
use crate::runs::layered::LayeredSummaries;
use crate::runs::orbits::{run_summarised, OrbitRunSpec, SummaryOptions, SummaryView};
use crate::runs::request::{coupled_run, CoupledRun};
use crate::runs::simulate::{state_from, TransientSettings};
use nalgebra::U4;

/// One transient of the boom as `settings` say, from their `y0` (default: its steady state at the
/// start's flux): columns T_mean, T_circ, theta, theta_dot, the thermal moment and the
/// illumination.
pub fn simulate(
    boom: &Boom,
    orbit: Orbit,
    coupling: Coupling,
    settings: TransientSettings,
    cancel: &Cancel,
) -> Result<CoupledRun> {
    let sys = boom_system(boom, orbit, coupling)?;
    coupled_run(sys, settings, cancel)
}

/// How the orbit summaries read the boom's state (T̄, T_m, θ, θ̇).
struct TubeView {
    system: TubeSystem,
    stiffness: f64,
}

impl SummaryView for TubeView {
    fn theta_eq(&self, flux: f64) -> Result<f64> {
        Ok(self.system.steady_state(flux)?[2])
    }
    #[inline]
    fn angles(&self, _t: f64, y: &[f64]) -> (f64, f64) {
        let moment = self.system.thermal().moment_per_kelvin() * y[1];
        (y[2], moment / self.stiffness)
    }
    #[inline]
    fn rate(&self, y: &[f64]) -> f64 {
        y[3]
    }
}

/// Whole orbits of the boom, `first_index .. first_index + n_orbits` from `y0` at `t_start`,
/// summarised as the panel's (`runs::orbits`), the step capped by the equivalent hinge's
/// period.
#[allow(clippy::too_many_arguments)]
pub fn run_orbits(
    boom: &Boom,
    orbit: Orbit,
    coupling: Coupling,
    method: &Method,
    span: (f64, u64, u64),
    y0: &[f64],
    options: SummaryOptions,
    cancel: &Cancel,
) -> Result<LayeredSummaries> {
    options.check()?;
    let mut system = boom_system(boom, orbit, coupling)?;
    let y0 = state_from(y0, U4)?;
    system.check_start(&y0)?;
    let view = TubeView {
        system,
        stiffness: boom.hinge_stiffness(),
    };
    let (t_start, first_index, n_orbits) = span;
    let spec = OrbitRunSpec {
        // The panel of the same hinge: its period caps the step, its rates bound the start.
        panel: boom.hinge_panel(),
        orbit,
        // The rigid link has one equation of motion (no 1 + 3 sin²θ).
        model: HingeModel::Linear,
        coupling,
        method: *method,
        t_start,
        first_index,
        n_orbits,
        options,
    };
    let run = run_summarised(&mut system, view, &spec, y0, 2, cancel)?;
    Ok(run.into())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::integrate::Tolerances;

    #[test]
    fn a_boom_runs_an_orbit_and_swings_at_its_terminators() {
        let boom = Boom {
            damping: 0.01,
            ..Boom::example()
        };
        let orbit = Orbit::geo_equinox();
        let sys = boom_system(&boom, orbit, Coupling::ProjectedArea).unwrap();
        let y0 = sys.steady_state(1.0).unwrap();
        let options = SummaryOptions {
            window: 3600.0,
            theta_limit: 0.3,
            stop_at_limit: false,
            steps_per_period: 40.0,
        };
        let method = Method::Dopri5(Tolerances::default());
        let out = run_orbits(
            &boom,
            orbit,
            Coupling::ProjectedArea,
            &method,
            (0.0, 0, 1),
            y0.as_slice(),
            options,
            &Cancel::new(),
        )
        .unwrap();
        let s = out.summaries[0];
        assert!((s.theta_eq / y0[2] - 1.0).abs() < 1e-9);
        assert!(s.theta_max > 0.0 && s.theta_min < s.theta_max);
        assert!(s.jitter_peak > 0.0 && s.jitter_peak.is_finite());
    }
}
