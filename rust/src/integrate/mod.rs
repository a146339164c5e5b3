//! Explicit Runge–Kutta integrators generic over a small ODE trait on nalgebra fixed-size vectors.
//!
//! The span is cut at the system's breakpoints (shadow entries and exits) and every segment is
//! integrated on its own, so no step straddles a discontinuity of the right-hand side. Results are
//! delivered to an [`Observer`] one accepted step at a time, with an interpolant over the step, so
//! callers keep only what they need (samples, per-orbit summaries) and never every step.

pub mod dopri5;
pub mod output;
pub mod rk4;

use crate::error::{require_positive, Error, Result};
use nalgebra::SVector;
use std::cell::OnceCell;
use std::ops::ControlFlow;

pub use output::{Sampler, StepCounter};

/// An ODE y' = f(t, y) with a state of N components.
pub trait OdeSystem<const N: usize> {
    fn rhs(&self, t: f64, y: &SVector<f64, N>) -> SVector<f64, N>;

    /// Times in (t0, t1) where the right-hand side is discontinuous, sorted.
    fn breakpoints(&self, _t0: f64, _t1: f64) -> Vec<f64> {
        Vec::new()
    }

    /// Called before integrating the segment [a, b] between two breakpoints.
    fn enter_segment(&mut self, _a: f64, _b: f64) {}
}

/// One accepted step [t0, t1] and its continuous extension.
///
/// The interpolant is y(t0 + θh) = r1 + θ(r2 + (1−θ)(r3 + θ(r4 + (1−θ) r5))): Dormand–Prince's
/// fourth-order dense output, or (with r5 = 0) the cubic Hermite interpolant for RK4. The step
/// keeps the stage slopes and builds r1..r5 on the first call of [`DenseStep::eval`], so steps
/// that no observer samples cost nothing more.
#[derive(Debug, Clone)]
pub struct DenseStep<const N: usize> {
    pub t0: f64,
    pub t1: f64,
    pub y0: SVector<f64, N>,
    pub y1: SVector<f64, N>,
    /// (f0, f1) for Hermite; (k1, k3, k4, k5, k6, k7) for Dormand–Prince.
    slopes: [SVector<f64, N>; 6],
    kind: Interpolant,
    r: OnceCell<[SVector<f64, N>; 5]>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Interpolant {
    Hermite,
    Dopri5,
}

impl<const N: usize> DenseStep<N> {
    /// The cubic Hermite interpolant from values and slopes at both ends.
    pub fn hermite(
        t0: f64,
        t1: f64,
        y0: SVector<f64, N>,
        y1: SVector<f64, N>,
        f0: &SVector<f64, N>,
        f1: &SVector<f64, N>,
    ) -> Self {
        let zero = SVector::zeros();
        DenseStep {
            t0,
            t1,
            y0,
            y1,
            slopes: [*f0, *f1, zero, zero, zero, zero],
            kind: Interpolant::Hermite,
            r: OnceCell::new(),
        }
    }

    /// Dormand–Prince's continuous extension from the slopes k1, k3, k4, k5, k6, k7.
    pub(crate) fn dopri5(
        t0: f64,
        t1: f64,
        y0: SVector<f64, N>,
        y1: SVector<f64, N>,
        slopes: [SVector<f64, N>; 6],
    ) -> Self {
        DenseStep {
            t0,
            t1,
            y0,
            y1,
            slopes,
            kind: Interpolant::Dopri5,
            r: OnceCell::new(),
        }
    }

    /// The interpolant's coefficients r1..r5.
    fn coefficients(&self) -> [SVector<f64, N>; 5] {
        let h = self.t1 - self.t0;
        let diff = self.y1 - self.y0;
        match self.kind {
            Interpolant::Hermite => {
                let [f0, f1, ..] = &self.slopes;
                let r3 = f0 * h - diff;
                let r4 = diff - f1 * h - r3;
                [self.y0, diff, r3, r4, SVector::zeros()]
            }
            Interpolant::Dopri5 => dopri5::dense_coefficients(h, &self.y0, &diff, &self.slopes),
        }
    }

    /// Value of the interpolant at t in [t0, t1].
    pub fn eval(&self, t: f64) -> SVector<f64, N> {
        if t == self.t1 {
            return self.y1;
        }
        let th = (t - self.t0) / (self.t1 - self.t0);
        let th1 = 1.0 - th;
        let [r1, r2, r3, r4, r5] = self.r.get_or_init(|| self.coefficients());
        r1 + (r2 + (r3 + (r4 + r5 * th1) * th) * th1) * th
    }
}

/// What the observer is told after each accepted step.
pub trait Observer<const N: usize> {
    /// Return `ControlFlow::Break(())` to stop the integration after this step.
    fn on_step(&mut self, step: &DenseStep<N>) -> ControlFlow<()>;
}

/// Which integrator, with its settings.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Method {
    /// Classical fourth-order Runge–Kutta with fixed step `dt` (shortened so that every segment
    /// holds a whole number of equal steps).
    Rk4 { dt: f64 },
    /// Dormand–Prince 5(4) with error control.
    Dopri5(Tolerances),
}

/// Error-control settings of the adaptive integrator.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerances {
    pub rtol: f64,
    pub atol: f64,
    /// Largest step, s.
    pub max_step: f64,
    /// Guard against runaway integrations: at most this many steps (accepted + rejected).
    pub max_steps: u64,
}

impl Default for Tolerances {
    fn default() -> Self {
        Tolerances {
            rtol: 1e-8,
            atol: 1e-10,
            max_step: f64::INFINITY,
            max_steps: 500_000_000,
        }
    }
}

impl Method {
    pub fn validate(&self) -> Result<()> {
        match self {
            Method::Rk4 { dt } => require_positive("dt", *dt),
            Method::Dopri5(tol) => {
                require_positive("rtol", tol.rtol)?;
                require_positive("atol", tol.atol)?;
                if tol.rtol < 1e-14 {
                    return Err(Error::invalid(
                        "rtol",
                        tol.rtol,
                        "must be >= 1e-14 (double precision)",
                    ));
                }
                if tol.max_step.is_nan() || tol.max_step <= 0.0 {
                    return Err(Error::invalid("max_step", tol.max_step, "must be > 0"));
                }
                if tol.max_steps == 0 {
                    return Err(Error::invalid("max_steps", 0, "must be >= 1"));
                }
                Ok(())
            }
        }
    }
}

/// Work counters and how the integration ended.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Stats {
    pub n_steps: u64,
    pub n_rejected: u64,
    pub n_rhs: u64,
    /// Time reached (t1, or earlier when the observer stopped the run).
    pub t_end: f64,
    /// True when the observer asked to stop before t1.
    pub stopped: bool,
}

/// Integrates `system` from (t0, y0) to t1 with `method`, cutting at the system's breakpoints.
/// Returns the counters and the state at `stats.t_end`.
pub fn solve<const N: usize, S: OdeSystem<N>, O: Observer<N>>(
    system: &mut S,
    method: &Method,
    t0: f64,
    y0: SVector<f64, N>,
    t1: f64,
    observer: &mut O,
) -> Result<(Stats, SVector<f64, N>)> {
    method.validate()?;
    check_span(t0, t1)?;
    if let Some(i) = y0.iter().position(|v| !v.is_finite()) {
        return Err(Error::invalid(
            "y0",
            y0[i],
            "every component must be finite",
        ));
    }
    let mut cuts = vec![t0];
    cuts.extend(system.breakpoints(t0, t1));
    cuts.push(t1);
    let mut stats = Stats {
        t_end: t0,
        ..Stats::default()
    };
    let mut y = y0;
    for w in cuts.windows(2) {
        let (a, b) = (w[0], w[1]);
        if b <= a {
            continue;
        }
        system.enter_segment(a, b);
        let flow = match method {
            Method::Rk4 { dt } => rk4::segment(system, a, b, &mut y, *dt, &mut stats, observer)?,
            Method::Dopri5(tol) => {
                dopri5::segment(system, a, b, &mut y, tol, &mut stats, observer)?
            }
        };
        if flow.is_break() {
            stats.stopped = stats.t_end < t1;
            break;
        }
    }
    Ok((stats, y))
}

/// Checks an integration span: finite ends, t1 > t0.
pub fn check_span(t0: f64, t1: f64) -> Result<()> {
    crate::error::require_finite("t_span[0]", t0)?;
    crate::error::require_finite("t_span[1]", t1)?;
    if t1 <= t0 {
        return Err(Error::invalid(
            "t_span",
            format!("({t0}, {t1})"),
            "must be increasing (t1 > t0)",
        ));
    }
    Ok(())
}

/// RMS norm of x / scale, as used by the error controller.
#[inline]
pub(crate) fn rms_scaled<const N: usize>(x: &SVector<f64, N>, scale: &SVector<f64, N>) -> f64 {
    let mut acc = 0.0;
    for i in 0..N {
        let r = x[i] / scale[i];
        acc += r * r;
    }
    (acc / N as f64).sqrt()
}

#[cfg(test)]
mod tests;
