//! A run of the spacecraft ([`crate::models::spacecraft`]): the bus's attitude and rate, each
//! appendage's temperatures, hinge angle, thermal moment and reaction torque on the bus.

use crate::analysis::steady::equilibrium;
use crate::cancel::Cancel;
use crate::error::Result;
use crate::inputs::orbit::Orbit;
use crate::models::coupled::Coupling;
use crate::models::spacecraft::{Spacecraft, SpacecraftSystem, APPENDAGE_STATES, BUS_STATES};
use crate::numerics::integrate::{Method, State, Stats};
use crate::runs::simulate::{run_watched, state_from, Output};
use nalgebra::Dyn;

/// The sampled columns of one appendage.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct AppendageColumns {
    pub t_front: Vec<f64>,
    pub t_back: Vec<f64>,
    /// θ, rad, in the hinge model's own sense.
    pub theta: Vec<f64>,
    pub theta_dot: Vec<f64>,
    /// M_T, N m.
    pub thermal_moment: Vec<f64>,
    /// The torque of the appendage on the bus about its axis, N m.
    pub reaction_torque: Vec<f64>,
}

/// The sampled solution of a spacecraft run.
#[derive(Debug, Clone)]
pub struct SpacecraftRun {
    pub t: Vec<f64>,
    /// φ, rad: the bus's attitude error (its reference is 0).
    pub phi: Vec<f64>,
    /// φ̇, rad/s.
    pub phi_dot: Vec<f64>,
    /// The external torque on the bus (controller and disturbance), N m.
    pub bus_torque: Vec<f64>,
    /// H about the bus axis, kg m²/s; None for a bus of infinite inertia.
    pub angular_momentum: Option<Vec<f64>>,
    pub appendages: Vec<AppendageColumns>,
    /// (K_p, K_d) of the controller, if any.
    pub gains: Option<(f64, f64)>,
    /// J₀ + Σ m_i (r_i + ρ_i)², kg m².
    pub inertia_at_rest: f64,
    pub stats: Stats,
    pub y_end: Vec<f64>,
    pub method: Method,
}

/// The default start at `t0`: φ = 0, φ̇ = `bus_rate`, each panel at its sunlit equilibrium at
/// that time's solar flux, at rest (with φ = 0 the incidence is θ_i's alone, as in the paper's
/// model, whose default start this is).
pub fn default_start(
    craft: &Spacecraft,
    orbit: &Orbit,
    t0: f64,
    bus_rate: f64,
) -> Result<Vec<f64>> {
    craft.check_bus_value("bus_rate", bus_rate)?;
    let flux = orbit.flux_scale(t0);
    let mut y = vec![0.0, bus_rate];
    for a in &craft.appendages {
        let eq = equilibrium(&a.panel, Coupling::ProjectedArea, flux)?;
        y.extend([eq.t_front, eq.t_back, eq.theta, 0.0]);
    }
    Ok(y)
}

/// What a spacecraft run is asked.
#[derive(Debug, Clone)]
pub struct SpacecraftRequest {
    pub craft: Spacecraft,
    pub orbit: Orbit,
    /// τ_d, a constant torque on the bus, N m.
    pub disturbance: f64,
    pub method: Method,
    pub span: (f64, f64),
    /// The start state; None for [`default_start`] with `bus_rate`.
    pub y0: Option<Vec<f64>>,
    /// φ̇ of the default start, rad/s.
    pub bus_rate: f64,
    pub output: Output,
}

/// Integrates the spacecraft over the span and samples it.
pub fn simulate_spacecraft(req: &SpacecraftRequest, cancel: &Cancel) -> Result<SpacecraftRun> {
    let mut sys = SpacecraftSystem::new(&req.craft, req.orbit, req.disturbance)?;
    crate::Orbit::check_time(req.span.0)?;
    let y0 = match &req.y0 {
        Some(v) => v.clone(),
        None => default_start(&req.craft, &req.orbit, req.span.0, req.bus_rate)?,
    };
    let y_start: State<Dyn> = state_from(&y0, Dyn(sys.size()))?;
    sys.check_start(y_start.as_slice())?;
    let traj = run_watched(
        &mut sys,
        &req.method,
        req.span,
        y_start,
        &req.output,
        None,
        cancel,
    )?;
    let n = req.craft.appendages.len();
    let mut appendages = vec![AppendageColumns::default(); n];
    let mut bus_torque = Vec::with_capacity(traj.t.len());
    let mut momentum = Vec::with_capacity(traj.t.len());
    for y in &traj.y {
        let ys = y.as_slice();
        let acc = sys.accelerations(ys);
        let torques = sys.reaction_torques(ys, &acc);
        let moments = sys.moments(ys);
        bus_torque.push(sys.bus_torque(ys[0], ys[1]));
        momentum.extend(sys.angular_momentum(ys));
        for (i, cols) in appendages.iter_mut().enumerate() {
            let base = BUS_STATES + APPENDAGE_STATES * i;
            cols.t_front.push(ys[base]);
            cols.t_back.push(ys[base + 1]);
            cols.theta.push(ys[base + 2]);
            cols.theta_dot.push(ys[base + 3]);
            cols.thermal_moment.push(moments[i]);
            cols.reaction_torque.push(torques[i]);
        }
    }
    Ok(SpacecraftRun {
        phi: traj.column(0),
        phi_dot: traj.column(1),
        t: traj.t,
        bus_torque,
        angular_momentum: (!sys.bus_is_fixed()).then_some(momentum),
        appendages,
        gains: req.craft.gains(),
        inertia_at_rest: req.craft.inertia_at_rest(),
        stats: traj.stats,
        y_end: traj.y_end.as_slice().to_vec(),
        method: traj.method,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::inputs::panel::Panel;
    use crate::models::spacecraft::{Appendage, Pd};
    use crate::numerics::integrate::Tolerances;

    fn request(
        craft: Spacecraft,
        disturbance: f64,
        span: (f64, f64),
        rtol: f64,
    ) -> SpacecraftRequest {
        SpacecraftRequest {
            craft,
            orbit: Orbit::geo_equinox(),
            disturbance,
            method: Method::Dopri5(Tolerances {
                rtol,
                atol: rtol * 1e-3,
                ..Default::default()
            }),
            span,
            y0: None,
            bus_rate: 1e-6,
            output: Output::Every(50.0),
        }
    }

    #[test]
    fn momentum_is_conserved_through_an_eclipse_without_a_controller() {
        let p = Panel::paper();
        let craft = Spacecraft {
            bus_inertia: 7.7e4,
            appendages: vec![
                Appendage {
                    panel: p,
                    offset: 2.0,
                    sense: 1.0,
                },
                Appendage {
                    panel: Panel { length: 30.0, ..p },
                    offset: 1.0,
                    sense: -1.0,
                },
            ],
            controller: None,
        };
        let o = Orbit::geo_equinox();
        let (a, _) = o.shadow_intervals(0.0, o.period)[0];
        let run = simulate_spacecraft(
            &request(craft, 0.0, (a - 600.0, a + 3000.0), 1e-11),
            &Cancel::new(),
        )
        .unwrap();
        let h = run.angular_momentum.unwrap();
        let scale = h.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        let drift = h.iter().fold(0.0f64, |m, v| m.max((v - h[0]).abs()));
        assert!(drift <= 1e-9 * scale, "{drift} of {scale}");
        // The eclipse did move the bus: the exchange is not trivially zero.
        let swing = run.appendages[0]
            .reaction_torque
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs()));
        assert!(swing > 0.0);
    }

    #[test]
    fn the_controller_holds_a_constant_disturbance_at_its_closed_form_offset() {
        let craft = Spacecraft {
            bus_inertia: 1e4,
            appendages: vec![],
            controller: Some(Pd {
                bandwidth: 0.05,
                damping: 0.7,
            }),
        };
        let tau = 0.02;
        let mut req = request(craft, tau, (0.0, 2000.0), 1e-10);
        req.bus_rate = 0.0;
        let run = simulate_spacecraft(&req, &Cancel::new()).unwrap();
        let want = tau / (1e4 * 0.05 * 0.05);
        let end = *run.phi.last().unwrap();
        assert!((end - want).abs() < 1e-8 * want, "{end} vs {want}");
    }
}
