//! Observers that keep what the caller asked for.

use super::{DenseStep, Observer, State};
use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim};
use std::ops::ControlFlow;

/// Times every `dt` from t0 to t1, both included (the last interval may be shorter).
pub fn every(t0: f64, t1: f64, dt: f64) -> Vec<f64> {
    let n = ((t1 - t0) / dt).floor() as usize;
    let mut times: Vec<f64> = (0..=n).map(|i| t0 + i as f64 * dt).collect();
    if let Some(&last) = times.last() {
        if t1 - last > 1e-9 * dt {
            times.push(t1);
        }
    }
    times
}

/// Records the state at requested times (sorted), interpolated with the step's dense output.
/// (The Monte Carlo design's "sampler" is another thing: how panels are drawn.)
#[derive(Debug, Clone)]
pub struct Recorder<D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    times: Vec<f64>,
    next: usize,
    pub t: Vec<f64>,
    pub y: Vec<State<D>>,
}

impl<D: Dim> Recorder<D>
where
    DefaultAllocator: Allocator<D>,
{
    /// `times` must be sorted; times outside the integrated span are never reached.
    pub fn new(times: Vec<f64>) -> Self {
        let n = times.len();
        Recorder {
            times,
            next: 0,
            t: Vec::with_capacity(n),
            y: Vec::with_capacity(n),
        }
    }

    /// Samples every `dt` from t0 to t1, both included (the last interval may be shorter).
    pub fn every(t0: f64, t1: f64, dt: f64) -> Self {
        Self::new(every(t0, t1, dt))
    }

    /// Skips requested times before `t` (used when the first step starts later than them).
    fn skip_before(&mut self, t: f64) {
        while self.next < self.times.len() && self.times[self.next] < t {
            self.next += 1;
        }
    }

    /// Keeps the requested times inside `step` (the slow path, out of the step loop).
    #[inline(never)]
    fn sample(&mut self, step: &DenseStep<D>) {
        self.sample_through(step, step.t1);
    }

    /// Keeps the requested times of `step` up to `t_last` (<= its end): a run that stops inside
    /// a step keeps no sample beyond where it stopped.
    pub fn sample_through(&mut self, step: &DenseStep<D>, t_last: f64) {
        self.skip_before(step.t0);
        while self.next < self.times.len() && self.times[self.next] <= t_last {
            let t = self.times[self.next];
            self.t.push(t);
            self.y.push(if t == step.t0 {
                step.y0.clone()
            } else {
                step.eval(t)
            });
            self.next += 1;
        }
    }
}

impl<D: Dim> Observer<D> for Recorder<D>
where
    DefaultAllocator: Allocator<D>,
{
    /// Most steps hold no requested time: that test is inlined into the step loop, and only a
    /// step that holds one builds its interpolant.
    #[inline]
    fn on_step(&mut self, step: &DenseStep<D>) -> ControlFlow<()> {
        if self.times.get(self.next).is_some_and(|&t| t <= step.t1) {
            self.sample(step);
        }
        ControlFlow::Continue(())
    }
}

/// Keeps nothing; only lets the integration run (for benchmarks and final-state queries).
#[derive(Debug, Clone, Copy, Default)]
pub struct StepCounter {
    pub steps: u64,
}

impl<D: Dim> Observer<D> for StepCounter
where
    DefaultAllocator: Allocator<D>,
{
    fn on_step(&mut self, _step: &DenseStep<D>) -> ControlFlow<()> {
        self.steps += 1;
        ControlFlow::Continue(())
    }
}

/// Keeps every step end (t1, y1), plus the very first point: for tests and short diagnostics.
#[derive(Debug, Clone)]
pub struct EveryStep<D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    pub t: Vec<f64>,
    pub y: Vec<State<D>>,
}

impl<D: Dim> Default for EveryStep<D>
where
    DefaultAllocator: Allocator<D>,
{
    fn default() -> Self {
        EveryStep {
            t: Vec::new(),
            y: Vec::new(),
        }
    }
}

impl<D: Dim> Observer<D> for EveryStep<D>
where
    DefaultAllocator: Allocator<D>,
{
    fn on_step(&mut self, step: &DenseStep<D>) -> ControlFlow<()> {
        if self.t.is_empty() {
            self.t.push(step.t0);
            self.y.push(step.y0.clone());
        }
        self.t.push(step.t1);
        self.y.push(step.y1.clone());
        ControlFlow::Continue(())
    }
}
