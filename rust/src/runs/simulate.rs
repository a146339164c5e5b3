//! High-level runs: integrate a system over a span and keep its state at the requested times.

use crate::cancel::Cancel;
use crate::error::{Error, Result};
use crate::numerics::integrate::{
    check_span, output, solve, DenseStep, Method, Observer, OdeSystem, Recorder, State, Stats,
};
use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim, U1};
use std::ops::ControlFlow;

/// A start state of dimension `dim` (`U4`, or `Dyn(n)` for a size known at run time).
pub fn state_from<D: Dim>(v: &[f64], dim: D) -> Result<State<D>>
where
    DefaultAllocator: Allocator<D>,
{
    let n = dim.value();
    if v.len() != n {
        return Err(Error::invalid(
            "y0",
            format!("{v:?}"),
            &format!("must have {n} components, not {}", v.len()),
        ));
    }
    if let Some(x) = v.iter().find(|x| !x.is_finite()) {
        return Err(Error::invalid(
            "y0",
            format!("{v:?}"),
            &format!("component {x} is not finite"),
        ));
    }
    Ok(State::from_column_slice_generic(dim, U1, v))
}

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
    /// Where the watched angle first passed its [`Limit`] (t, the state there), if it did.
    pub crossing: Option<(f64, State<D>)>,
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
    run_watched(system, method, t_span, y0, output, None, &Cancel::new())
}

/// Sub-steps of a step scanned for the first point beyond a [`Limit`] when its bound does not
/// exclude one: the interpolant between them is then bisected.
const LIMIT_SCANS: usize = 16;

/// Bisections of the interval holding the first crossing: the crossing's time to 2⁻⁴⁸ of a
/// sixteenth of the step, far below the interpolant's own error.
const LIMIT_BISECTIONS: usize = 48;

/// The range of validity a run is watched for: the angle passes it where |a·y + b| > `bound`.
/// The watched value is affine in the state: the hinge's θ is one component; the distributed
/// panel's tip rise (θ_f = asin(rise/arm)) is a sum over the modes and the element moments.
#[derive(Debug, Clone, PartialEq)]
pub struct Limit {
    /// (component, weight) of the value's linear part a.
    pub weights: Vec<(usize, f64)>,
    /// Its constant part b.
    pub offset: f64,
    /// |value| beyond which the model is not trusted.
    pub bound: f64,
    /// End the run at the first crossing (else record it and go on).
    pub stop: bool,
}

impl Limit {
    fn linear(&self, y: &[f64]) -> f64 {
        self.weights.iter().map(|&(i, w)| w * y[i]).sum()
    }

    /// The watched value of a state.
    pub fn value(&self, y: &[f64]) -> f64 {
        self.linear(y) + self.offset
    }

    fn beyond<D: Dim>(&self, y: &State<D>) -> bool
    where
        DefaultAllocator: Allocator<D>,
    {
        // NaN is never beyond: the integrator refuses a NaN state itself.
        self.value(y.as_slice()).abs() > self.bound
    }

    /// The first time in `step` where the value is beyond the bound, if any.
    ///
    /// Most steps are excluded at the cost of four reads: the cubic Hermite interpolant through
    /// the step's ends and slopes stays within max(|v0|, |v1|) + 4/27 h (|v0'| + |v1'|); the
    /// bound taken here doubles that last term to cover Dormand–Prince's quartic extension.
    /// Other steps are scanned on the interpolant, so that a crossing between two samples, or
    /// inside a step, is found where it happens.
    fn first_crossing<D: Dim>(&self, step: &DenseStep<D>) -> Option<f64>
    where
        DefaultAllocator: Allocator<D>,
    {
        if self.beyond(&step.y0) {
            return Some(step.t0);
        }
        let h = step.t1 - step.t0;
        if let (Some(f0), Some(f1)) = (step.start_slope(), step.end_slope()) {
            let ends = self
                .value(step.y0.as_slice())
                .abs()
                .max(self.value(step.y1.as_slice()).abs());
            let swing = self.linear(f0.as_slice()).abs() + self.linear(f1.as_slice()).abs();
            if ends + 8.0 / 27.0 * h * swing <= self.bound {
                return None;
            }
        }
        let mut inside = step.t0;
        for k in 1..=LIMIT_SCANS {
            let t = if k == LIMIT_SCANS {
                step.t1
            } else {
                step.t0 + k as f64 * (h / LIMIT_SCANS as f64)
            };
            if self.beyond(&step.eval(t)) {
                // Inside at `inside`, beyond at `past`: bisect to the first point past.
                let mut past = t;
                for _ in 0..LIMIT_BISECTIONS {
                    let mid = inside + 0.5 * (past - inside);
                    if mid <= inside || mid >= past {
                        break;
                    }
                    if self.beyond(&step.eval(mid)) {
                        past = mid;
                    } else {
                        inside = mid;
                    }
                }
                return Some(past);
            }
            inside = t;
        }
        None
    }
}

/// What a caller asks of a run's validity limit: |θ| <= `theta_limit` (rad), and whether the run
/// ends at the first crossing (else it is recorded and the run goes on).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct OnLimit {
    pub theta_limit: f64,
    pub stop: bool,
}

impl OnLimit {
    /// The limit checked (> 0, within the hinge model's range ±π/2).
    pub fn new(theta_limit: f64, stop: bool) -> Result<Self> {
        check_theta_limit(theta_limit)?;
        Ok(OnLimit { theta_limit, stop })
    }

    /// The limit on state component `index`, the hinge angle θ itself.
    pub fn on_component(self, index: usize) -> Limit {
        Limit {
            weights: vec![(index, 1.0)],
            offset: 0.0,
            bound: self.theta_limit,
            stop: self.stop,
        }
    }
}

/// How one transient runs, whatever its system: the integrator, the span (t0, t1), where to
/// report, the start (None: the system's steady state at t0's flux) and the validity limit to
/// watch.
#[derive(Debug, Clone)]
pub struct TransientSettings {
    pub method: Method,
    pub span: (f64, f64),
    pub output: Output,
    pub y0: Option<Vec<f64>>,
    pub limit: Option<OnLimit>,
}

/// Checks a validity limit on the hinge angle: > 0 and within the hinge model's range ±π/2.
pub fn check_theta_limit(theta_limit: f64) -> Result<()> {
    crate::models::hinge::check_hinge_angle("theta_limit", theta_limit)?;
    crate::error::require_positive("theta_limit", theta_limit)
}

/// The recorder of a run, with its watch for Ctrl-C (`cancel`, polled once a step) and for the
/// validity limit.
struct Watched<'a, D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    recorder: Recorder<D>,
    limit: Option<&'a Limit>,
    cancel: &'a Cancel,
    crossing: Option<(f64, State<D>)>,
    cancelled: bool,
}

impl<D: Dim> Observer<D> for Watched<'_, D>
where
    DefaultAllocator: Allocator<D>,
{
    #[inline]
    fn on_step(&mut self, step: &DenseStep<D>) -> ControlFlow<()> {
        if self.cancel.is_cancelled() {
            self.cancelled = true;
            return ControlFlow::Break(());
        }
        if let Some(limit) = self.limit.filter(|_| self.crossing.is_none()) {
            if let Some(t) = limit.first_crossing(step) {
                self.crossing = Some((t, step.eval(t)));
                if limit.stop {
                    self.recorder.sample_through(step, t);
                    return ControlFlow::Break(());
                }
            }
        }
        self.recorder.on_step(step)
    }
}

/// [`run`] that stops with [`Error::Cancelled`] within one step of `cancel` being cancelled and
/// watches `limit`: the first crossing is reported in [`Trajectory::crossing`]; with
/// [`Limit::stop`] the run ends there (no sample after it, `y_end` and `stats.t_end` at the
/// crossing, `stats.stopped` set).
pub fn run_watched<D: Dim, S: OdeSystem<D>>(
    system: &mut S,
    method: &Method,
    t_span: (f64, f64),
    y0: State<D>,
    output: &Output,
    limit: Option<&Limit>,
    cancel: &Cancel,
) -> Result<Trajectory<D>>
where
    DefaultAllocator: Allocator<D>,
{
    let (t0, t1) = t_span;
    check_span(t0, t1)?;
    cancel.check()?;
    let mut watched = Watched {
        recorder: Recorder::new(output.sample_times(t0, t1)?),
        limit,
        cancel,
        crossing: None,
        cancelled: false,
    };
    let (mut stats, mut y_end) = solve(system, method, t0, y0, t1, &mut watched)?;
    if watched.cancelled {
        return Err(Error::Cancelled);
    }
    if let (Some((t, y)), Some(true)) = (&watched.crossing, limit.map(|l| l.stop)) {
        stats.t_end = *t;
        y_end = y.clone();
    }
    Ok(Trajectory {
        t: watched.recorder.t,
        y: watched.recorder.y,
        stats,
        y_end,
        method: *method,
        crossing: watched.crossing,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::inputs::panel::Panel;
    use crate::models::coupled::{DrivenHinge, MomentHistory};
    use crate::models::hinge::HingeModel;
    use crate::numerics::integrate::Tolerances;
    use nalgebra::Vector2;

    /// The undamped linear hinge released at rest under a constant moment: θ = θs (1 − cos ωt),
    /// θs = M/K_el = 0.15 rad, so it first passes 0.2 rad at cos ωt = −1/3.
    fn released() -> (DrivenHinge, f64, f64) {
        let panel = Panel {
            damping: 0.0,
            ..Panel::paper()
        };
        let moment = 0.15 * panel.hinge_stiffness;
        let w = panel.natural_angular_frequency();
        let system = DrivenHinge {
            panel,
            model: HingeModel::Linear,
            moment: MomentHistory::Constant(moment),
        };
        (system, w, (-1.0f64 / 3.0).acos() / w)
    }

    fn method() -> Method {
        Method::Dopri5(Tolerances {
            rtol: 1e-10,
            atol: 1e-12,
            ..Tolerances::default()
        })
    }

    #[test]
    fn a_crossing_between_samples_is_found_where_it_happens() {
        let (mut sys, w, exact) = released();
        let span = (0.0, 4.0 * std::f64::consts::PI / w);
        // Samples only at both ends: the crossing is between them, inside a step.
        let out = Output::Every(span.1);
        for stop in [false, true] {
            let limit = OnLimit::new(0.2, stop).unwrap().on_component(0);
            let y0 = Vector2::zeros();
            let traj = run_watched(
                &mut sys,
                &method(),
                span,
                y0,
                &out,
                Some(&limit),
                &Cancel::new(),
            )
            .unwrap();
            let (t, y) = traj.crossing.unwrap();
            assert!((t - exact).abs() < 1e-6 * exact, "{t} vs {exact}");
            assert!(y[0] > 0.2 && y[0] < 0.2 + 1e-9, "{}", y[0]);
            if stop {
                assert_eq!(traj.t, vec![0.0]);
                assert!(traj.stats.stopped);
                assert_eq!((traj.stats.t_end, traj.y_end[0]), (t, y[0]));
            } else {
                assert_eq!(traj.t, vec![0.0, span.1]);
                assert_eq!(traj.stats.t_end, span.1);
            }
        }
        // Below the peak 2 θs = 0.3 rad nothing is passed; the samples are those of a plain run.
        let limit = OnLimit::new(0.31, true).unwrap().on_component(0);
        let out = Output::Every(0.5);
        let plain = run(&mut sys, &method(), span, Vector2::zeros(), &out).unwrap();
        let cancel = Cancel::new();
        let watched = run_watched(
            &mut sys,
            &method(),
            span,
            Vector2::zeros(),
            &out,
            Some(&limit),
            &cancel,
        )
        .unwrap();
        assert!(watched.crossing.is_none());
        assert_eq!(plain.y, watched.y);
    }

    #[test]
    fn a_cancelled_run_stops() {
        let (mut sys, _, _) = released();
        let cancel = Cancel::new();
        cancel.cancel();
        let out = Output::Every(1.0);
        let r = run_watched(
            &mut sys,
            &method(),
            (0.0, 1e4),
            Vector2::zeros(),
            &out,
            None,
            &cancel,
        );
        assert_eq!(r.unwrap_err(), Error::Cancelled);
    }

    #[test]
    fn theta_limit_is_checked_by_name() {
        for bad in [0.0, -0.1, 2.0, f64::NAN, f64::INFINITY] {
            let e = OnLimit::new(bad, false).unwrap_err().to_string();
            assert!(e.starts_with("theta_limit"), "{e}");
        }
    }
}
