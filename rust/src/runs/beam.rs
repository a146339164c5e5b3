//! The free–free beam's modal transient under end moments ±M(t) (the model: models/beam.rs).

use crate::cancel::Cancel;
use crate::error::{require_non_negative, Error, Result};
use crate::models::beam::{FreeFreeBeam, ModalBeam, BEAM_STATE};
use crate::models::coupled::MomentHistory;
use crate::numerics::integrate::{Const, Method, State, Stats};
use crate::runs::simulate::{run_watched, Output};

/// The beam's response to end moments ±M(t).
#[derive(Debug, Clone)]
pub struct BeamResponse {
    pub t: Vec<f64>,
    /// η, tip deflection relative to the centre node, m.
    pub eta: Vec<f64>,
    /// θ_f = asin(2η/L), the equivalent hinge angle, rad.
    pub theta_f: Vec<f64>,
    pub stats: Stats,
}

/// Largest modal damping ratio a transient accepts. An overdamped mode's fast rate grows as
/// 2ζω, so the explicit integrator's steps shrink as 1/ζ (20 s of the 20-element Table 1 beam:
/// 2.1e3 steps at ζ = 0.01, 1.2e4 at 10, 1.2e6 at 1000; 2e5 ran for minutes).
pub const MAX_DAMPING_RATIO: f64 = 10.0;

/// Modal transient response of `beam` to end moments ±`moment`(t), starting at rest in the
/// static deflection under M(t0). `residual` adds the quasi-static part of the modes not kept.
#[allow(clippy::too_many_arguments)]
pub fn respond(
    beam: &FreeFreeBeam,
    moment: MomentHistory,
    damping_ratio: f64,
    residual: bool,
    method: &Method,
    t_span: (f64, f64),
    output: &Output,
    cancel: &Cancel,
) -> Result<BeamResponse> {
    require_non_negative("damping_ratio", damping_ratio)?;
    if damping_ratio > MAX_DAMPING_RATIO {
        return Err(Error::invalid(
            "damping_ratio",
            damping_ratio,
            &format!(
                "must be at most {MAX_DAMPING_RATIO} (times critical): beyond it every mode only \
                 creeps to its static deflection, at a cost that grows with the ratio"
            ),
        ));
    }
    moment.validate()?;
    let (t0, t1) = t_span;
    crate::numerics::integrate::check_span(t0, t1)?;
    output.sample_times(t0, t1)?;
    let modes = beam.end_moment_modes()?;
    let mut system = ModalBeam::new(&modes, damping_ratio, moment);
    let y0: State<Const<BEAM_STATE>> = system.static_state(system.moment.at(t0));
    let recorder = run_watched(&mut system, method, t_span, y0, output, None, cancel)?;
    let stats = recorder.stats;
    let residual_flex = if residual {
        modes.residual_flexibility
    } else {
        0.0
    };
    let mut eta = Vec::with_capacity(recorder.t.len());
    let mut theta_f = Vec::with_capacity(recorder.t.len());
    for (t, y) in recorder.t.iter().zip(&recorder.y) {
        let mut e = residual_flex * system.moment.at(*t);
        for (i, (_, _, h)) in modes.kept.iter().enumerate() {
            e += h * y[i];
        }
        let s = 2.0 * e / beam.length;
        if s.is_nan() || s.abs() > 1.0 {
            return Err(Error::Integration {
                t: *t,
                reason: format!("tip deflection η = {e} m exceeds L/2: θ_f is undefined"),
            });
        }
        eta.push(e);
        theta_f.push(s.asin());
    }
    Ok(BeamResponse {
        t: recorder.t,
        eta,
        theta_f,
        stats,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::inputs::panel::Panel;
    use crate::numerics::integrate::Tolerances;

    fn paper_beam(n: usize) -> FreeFreeBeam {
        FreeFreeBeam::new(&Panel::paper(), n).unwrap()
    }

    #[test]
    fn transient_settles_on_the_static_deflection() {
        let b = paper_beam(40);
        let method = Method::Dopri5(Tolerances::default());
        // A moment ramped from 0 to 100 N m over 10 s, then held; heavy damping to settle.
        let history = MomentHistory::Samples {
            t: vec![0.0, 10.0],
            moment: vec![0.0, 100.0],
        };
        let out = Output::Times(vec![0.0, 200.0]);
        let r = respond(
            &b,
            history,
            0.3,
            true,
            &method,
            (0.0, 200.0),
            &out,
            &Cancel::new(),
        )
        .unwrap();
        let exact = 100.0 * 50.0 * 50.0 / (8.0 * b.flexural_rigidity);
        assert_eq!(r.eta[0], 0.0);
        assert!((r.eta[1] - exact).abs() < 1e-6 * exact, "{}", r.eta[1]);
        assert!((r.theta_f[1] - (2.0 * r.eta[1] / 50.0).asin()).abs() < 1e-15);
    }

    #[test]
    fn undamped_step_oscillates_at_the_first_frequency() {
        // Static start at M = 0, then a step: η(t) = Σ hᵢ gᵢ M (1 − cos ωᵢ t)/ωᵢ² + residual.
        let b = paper_beam(40);
        let modes = b.end_moment_modes().unwrap();
        let method = Method::Dopri5(Tolerances {
            rtol: 1e-10,
            atol: 1e-12,
            ..Tolerances::default()
        });
        let history = MomentHistory::Samples {
            t: vec![0.0, 1e-9],
            moment: vec![0.0, 10.0],
        };
        let ts: Vec<f64> = (1..20).map(|i| i as f64 * 1.7).collect();
        let r = respond(
            &b,
            history,
            0.0,
            false,
            &method,
            (0.0, 40.0),
            &Output::Times(ts.clone()),
            &Cancel::new(),
        )
        .unwrap();
        for (k, t) in ts.iter().enumerate() {
            let exact: f64 = modes
                .kept
                .iter()
                .map(|(w, g, h)| h * g * 10.0 * (1.0 - (w * t).cos()) / (w * w))
                .sum();
            assert!(
                (r.eta[k] - exact).abs() < 1e-6 * exact.abs().max(1e-3),
                "t = {t}"
            );
        }
    }
}
