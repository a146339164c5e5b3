//! High-level runs: integrate a system over a span and keep its state at the requested times.

use crate::error::{Error, Result};
use crate::integrate::{check_span, output, solve, Method, OdeSystem, Recorder, State, Stats};
use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim};

/// Where to report the solution.
#[derive(Debug, Clone, PartialEq)]
pub enum Output {
    /// At these times (sorted, inside the span).
    Times(Vec<f64>),
    /// Every `dt` from t0, and at t1.
    Every(f64),
}

/// Sampled solution of one run.
#[derive(Debug, Clone)]
pub struct Trajectory<D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    pub t: Vec<f64>,
    pub y: Vec<State<D>>,
    pub stats: Stats,
    /// State at `stats.t_end`.
    pub y_end: State<D>,
    /// The integrator and the settings the run used.
    pub method: Method,
}

impl<D: Dim> Trajectory<D>
where
    DefaultAllocator: Allocator<D>,
{
    /// Component `i` of every sample.
    pub fn column(&self, i: usize) -> Vec<f64> {
        self.y.iter().map(|y| y[i]).collect()
    }
}

/// Largest number of samples a single run may keep (about 160 MB for the coupled state).
pub const MAX_SAMPLES: usize = 5_000_000;

impl Output {
    /// Checks the request against the span and turns it into sample times.
    pub fn sample_times(&self, t0: f64, t1: f64) -> Result<Vec<f64>> {
        match self {
            Output::Every(dt) => {
                crate::error::require_positive("dt_out", *dt)?;
                let n = (t1 - t0) / dt;
                if n > MAX_SAMPLES as f64 {
                    return Err(Error::invalid(
                        "dt_out",
                        dt,
                        &format!("would keep {n:.0} samples (more than {MAX_SAMPLES}); use a larger dt_out or per-orbit summaries"),
                    ));
                }
                Ok(output::every(t0, t1, *dt))
            }
            Output::Times(ts) => {
                if ts.len() > MAX_SAMPLES {
                    return Err(Error::invalid("t_eval", ts.len(), "holds too many times"));
                }
                if let Some(&bad) = ts.iter().find(|v| !v.is_finite() || **v < t0 || **v > t1) {
                    return Err(Error::invalid(
                        "t_eval",
                        bad,
                        "times must be finite and inside t_span",
                    ));
                }
                if let Some(w) = ts.windows(2).find(|w| w[1] < w[0]) {
                    return Err(Error::invalid(
                        "t_eval",
                        w[1],
                        "times must be sorted increasing",
                    ));
                }
                Ok(ts.clone())
            }
        }
    }
}

/// Integrates `system` over [t0, t1] from y0 and samples it as `output` asks.
pub fn run<D: Dim, S: OdeSystem<D>>(
    system: &mut S,
    method: &Method,
    t_span: (f64, f64),
    y0: State<D>,
    output: &Output,
) -> Result<Trajectory<D>>
where
    DefaultAllocator: Allocator<D>,
{
    let (t0, t1) = t_span;
    check_span(t0, t1)?;
    let mut recorder = Recorder::new(output.sample_times(t0, t1)?);
    let (stats, y_end) = solve(system, method, t0, y0, t1, &mut recorder)?;
    Ok(Trajectory {
        t: recorder.t,
        y: recorder.y,
        stats,
        y_end,
        method: *method,
    })
}
