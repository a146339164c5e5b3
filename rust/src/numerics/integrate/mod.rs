//! Explicit Runge–Kutta integrators generic over a small ODE trait and over the state's dimension:
//! `Const<N>` for a size known at compile time (the hinge model's four states, on the stack, as
//! fast as hand-written code) or `Dyn` for one chosen at run time (many layers, many elements).
//!
//! The span is cut at the system's breakpoints (shadow entries and exits) and every segment is
//! integrated on its own, so no step straddles a discontinuity of the right-hand side. Results are
//! delivered to an [`Observer`] one accepted step at a time, with an interpolant over the step, so
//! callers keep only what they need (samples, per-orbit summaries) and never every step.

pub mod dop853;
pub mod dopri5;
pub mod output;
pub mod rk4;

use crate::error::{require_positive, Error, Result};
use crate::numerics::cpu::ScalarKernel;
use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim, OVector};
use std::cell::OnceCell;
use std::ops::ControlFlow;

pub use nalgebra::{Const, Dyn};
pub use output::{Recorder, StepCounter};

/// A state vector of dimension `D`: `Const<N>` (N known at compile time) or `Dyn`.
pub type State<D> = OVector<f64, D>;

/// An ODE y' = f(t, y) whose state has dimension `D`.
pub trait OdeSystem<D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    /// f(t, y), of the same dimension as y.
    fn rhs(&self, t: f64, y: &State<D>) -> State<D>;

    /// f(t, y) with the multiply-adds fused where the system has a fused form (the paper's
    /// model: [`crate::models::coupled::Coupled`] of two layers on the hinge), else [`OdeSystem::rhs`].
    /// Only the loop compiled for FMA calls it ([`ScalarKernel::Fma`]).
    #[inline(always)]
    fn rhs_fused(&self, t: f64, y: &State<D>) -> State<D> {
        self.rhs(t, y)
    }

    /// Times in (t0, t1) where the right-hand side is discontinuous, sorted.
    fn breakpoints(&self, _t0: f64, _t1: f64) -> Vec<f64> {
        Vec::new()
    }

    /// Refuses a span whose breakpoints could not be listed at a bounded cost (called before
    /// [`OdeSystem::breakpoints`]); by default only the checks of [`check_span`].
    fn check_span(&self, t0: f64, t1: f64) -> Result<()> {
        check_span(t0, t1)
    }

    /// Called before integrating the segment [a, b] between two breakpoints.
    fn enter_segment(&mut self, _a: f64, _b: f64) {}
}

/// `system` over a span whose breakpoints its caller knows already (an orbit's, from a table of
/// its eclipses): `cuts`, sorted, instead of the system's own search for them.
pub struct WithCuts<'a, S> {
    pub system: &'a mut S,
    pub cuts: &'a [f64],
}

impl<D: Dim, S: OdeSystem<D>> OdeSystem<D> for WithCuts<'_, S>
where
    DefaultAllocator: Allocator<D>,
{
    #[inline(always)]
    fn rhs(&self, t: f64, y: &State<D>) -> State<D> {
        self.system.rhs(t, y)
    }

    #[inline(always)]
    fn rhs_fused(&self, t: f64, y: &State<D>) -> State<D> {
        self.system.rhs_fused(t, y)
    }

    fn breakpoints(&self, t0: f64, t1: f64) -> Vec<f64> {
        self.cuts
            .iter()
            .copied()
            .filter(|&c| c > t0 && c < t1)
            .collect()
    }

    fn check_span(&self, t0: f64, t1: f64) -> Result<()> {
        self.system.check_span(t0, t1)
    }

    fn enter_segment(&mut self, a: f64, b: f64) {
        self.system.enter_segment(a, b);
    }
}

/// One accepted step [t0, t1] and its continuous extension.
///
/// The interpolant is y(t0 + θh) = r1 + θ(r2 + (1−θ)(r3 + θ(r4 + (1−θ) r5))): Dormand–Prince's
/// fourth-order dense output, or (with r5 = 0) the cubic Hermite interpolant for RK4. The step
/// keeps the stage slopes and builds r1..r5 on the first call of [`DenseStep::eval`], so steps
/// that no observer samples cost nothing more.
#[derive(Debug, Clone)]
pub struct DenseStep<D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    pub t0: f64,
    pub t1: f64,
    pub y0: State<D>,
    pub y1: State<D>,
    slopes: Slopes<D>,
    r: OnceCell<[State<D>; 5]>,
    /// The interpolant at [`DenseStep::midpoint`]'s time, when the integrator computed it with
    /// the step (the lockstep lanes do, four steps at once).
    mid: Option<State<D>>,
}

/// The slopes an interpolant is built from.
#[derive(Debug, Clone)]
enum Slopes<D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    /// (f0, f1): the cubic Hermite interpolant.
    Hermite([State<D>; 2]),
    /// (k1, k3, k4, k5, k6, k7): Dormand–Prince's continuous extension.
    Dopri5([State<D>; 6]),
    /// None: the coefficients were given on construction.
    Given,
}

impl<D: Dim> DenseStep<D>
where
    DefaultAllocator: Allocator<D>,
{
    /// The cubic Hermite interpolant from values and slopes at both ends.
    pub fn hermite(
        t0: f64,
        t1: f64,
        y0: State<D>,
        y1: State<D>,
        f0: State<D>,
        f1: State<D>,
    ) -> Self {
        Self::from_slopes(t0, t1, y0, y1, Slopes::Hermite([f0, f1]))
    }

    /// Dormand–Prince's continuous extension from the slopes k1, k3, k4, k5, k6, k7.
    pub(crate) fn dopri5(
        t0: f64,
        t1: f64,
        y0: State<D>,
        y1: State<D>,
        slopes: [State<D>; 6],
    ) -> Self {
        Self::from_slopes(t0, t1, y0, y1, Slopes::Dopri5(slopes))
    }

    /// A step whose interpolant's coefficients r1..r5 and value `mid` at [`DenseStep::midpoint`]
    /// the caller has built (with `dopri5::dense_coefficients`' and [`DenseStep::eval`]'s
    /// arithmetic: the lockstep lanes build them for several steps at once).
    pub(crate) fn with_coefficients(
        t0: f64,
        t1: f64,
        y0: State<D>,
        y1: State<D>,
        r: [State<D>; 5],
        mid: State<D>,
    ) -> Self {
        let mut step = Self::from_slopes(t0, t1, y0, y1, Slopes::Given);
        step.r = OnceCell::from(r);
        step.mid = Some(mid);
        step
    }

    /// A step over [t0, t1] from y0 to y1 whose interpolant `slopes` gives, its coefficients
    /// and midpoint not built yet.
    fn from_slopes(t0: f64, t1: f64, y0: State<D>, y1: State<D>, slopes: Slopes<D>) -> Self {
        DenseStep {
            t0,
            t1,
            y0,
            y1,
            slopes,
            r: OnceCell::new(),
            mid: None,
        }
    }

    /// The interpolant's coefficients r1..r5.
    fn coefficients(&self) -> [State<D>; 5] {
        let h = self.t1 - self.t0;
        let diff = &self.y1 - &self.y0;
        match &self.slopes {
            Slopes::Hermite([f0, f1]) => {
                let r3 = f0 * h - &diff;
                let r4 = &diff - f1 * h - &r3;
                let zero = r4.map(|_| 0.0);
                [self.y0.clone(), diff, r3, r4, zero]
            }
            Slopes::Dopri5(k) => dopri5::dense_coefficients(h, &self.y0, diff, k),
            Slopes::Given => unreachable!("the coefficients were given on construction"),
        }
    }

    /// The middle of the step, t0 + h/2, and the interpolant there (the same bits as
    /// [`DenseStep::eval`] at that time).
    #[inline]
    pub fn midpoint(&self) -> (f64, State<D>) {
        let t = self.t0 + 0.5 * (self.t1 - self.t0);
        match &self.mid {
            Some(y) => (t, y.clone()),
            None => (t, self.eval(t)),
        }
    }

    /// f(t1, y1), the slope at the step's end, when the integrator evaluated it (Dormand–Prince's
    /// k7, the Hermite step's f1); None for a step built from given coefficients.
    #[inline]
    pub fn end_slope(&self) -> Option<&State<D>> {
        match &self.slopes {
            Slopes::Hermite([_, f1]) => Some(f1),
            Slopes::Dopri5(k) => Some(&k[5]),
            Slopes::Given => None,
        }
    }

    /// f(t0, y0), the slope at the step's start, when the integrator evaluated it
    /// (Dormand–Prince's k1, the Hermite step's f0); None for a step built from given
    /// coefficients.
    #[inline]
    pub fn start_slope(&self) -> Option<&State<D>> {
        match &self.slopes {
            Slopes::Hermite([f0, _]) => Some(f0),
            Slopes::Dopri5(k) => Some(&k[0]),
            Slopes::Given => None,
        }
    }

    /// The interpolant's coefficients r1..r5 along the weights `w` (each w·r_i): the
    /// interpolant of the scalar w·y, of the same form in θ.
    pub(crate) fn coefficients_along(&self, w: &[f64]) -> [f64; 5] {
        let r = self.r.get_or_init(|| self.coefficients());
        std::array::from_fn(|i| r[i].iter().zip(w).map(|(a, b)| a * b).sum())
    }

    /// Value of the interpolant at t in [t0, t1].
    pub fn eval(&self, t: f64) -> State<D> {
        if t == self.t1 {
            return self.y1.clone();
        }
        let th = (t - self.t0) / (self.t1 - self.t0);
        let th1 = 1.0 - th;
        let [r1, r2, r3, r4, r5] = self.r.get_or_init(|| self.coefficients());
        r1 + (r2 + (r3 + (r4 + r5 * th1) * th) * th1) * th
    }

    /// The interpolant's time derivative at t in [t0, t1]: an estimate of f(t, y(t)) without
    /// evaluating the system. At the middle it is the cubic Hermite's slope (the quartic term
    /// of Dormand–Prince's extension has none there), 3/2 (y1 − y0)/h − (f0 + f1)/4, whose error
    /// is h⁴ y⁽⁵⁾/1920: a relative (ωh)⁴/1920 of an oscillation at ω.
    pub fn slope(&self, t: f64) -> State<D> {
        let h = self.t1 - self.t0;
        let th = (t - self.t0) / h;
        let th1 = 1.0 - th;
        let [_, r2, r3, r4, r5] = self.r.get_or_init(|| self.coefficients());
        // y = r1 + θ P, P = r2 + (1 − θ) Q, Q = r3 + θ R, R = r4 + (1 − θ) r5.
        let rr = r4 + r5 * th1;
        let q = r3 + &rr * th;
        let p = r2 + &q * th1;
        let dq = rr - r5 * th;
        let dp = dq * th1 - &q;
        (p + dp * th) / h
    }
}

/// What the observer is told after each accepted step.
pub trait Observer<D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    /// Return `ControlFlow::Break(())` to stop the integration after this step.
    fn on_step(&mut self, step: &DenseStep<D>) -> ControlFlow<()>;
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
    /// The fewest steps this method can take over `span` s, known before any work: the fixed
    /// step's count, or the span over the adaptive step's cap (error control may take more,
    /// never fewer; 0 without a cap).
    pub fn least_steps(&self, span: f64) -> f64 {
        match self {
            Method::Rk4 { dt } => (span / dt).ceil(),
            Method::Dopri5(tol) => span / tol.max_step,
        }
    }

    /// The most steps (accepted + rejected) a run may take.
    pub fn max_steps(&self) -> u64 {
        match self {
            Method::Rk4 { .. } => MAX_FIXED_STEPS as u64,
            Method::Dopri5(tol) => tol.max_steps,
        }
    }

    pub fn validate(&self) -> Result<()> {
        match self {
            Method::Rk4 { dt } => require_positive("dt", *dt),
            Method::Dopri5(tol) => {
                // Tolerances looser than these let the error control accept steps past the
                // stability limit: the run then wanders off to θ of thousands of radians, or
                // stalls rejecting steps, instead of failing.
                if !(1e-14..=MAX_RTOL).contains(&tol.rtol) {
                    return Err(Error::invalid(
                        "rtol",
                        tol.rtol,
                        &format!("must be in [1e-14, {MAX_RTOL:e}] (double precision to 1 %)"),
                    ));
                }
                if !(tol.atol > 0.0 && tol.atol <= MAX_ATOL) {
                    return Err(Error::invalid(
                        "atol",
                        tol.atol,
                        &format!("must be in (0, {MAX_ATOL:e}] (K, rad, rad/s)"),
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

/// The problem of one integration: from (t0, y0) to t1.
#[derive(Debug, Clone, PartialEq)]
pub struct Span<D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    pub t0: f64,
    pub y0: State<D>,
    pub t1: f64,
}

/// Integrates `system` from (t0, y0) to t1 with `method`, cutting at the system's breakpoints.
/// Returns the counters and the state at `stats.t_end`. Runs on [`ScalarKernel::detect`].
pub fn solve<D: Dim, S: OdeSystem<D>, O: Observer<D>>(
    system: &mut S,
    method: &Method,
    t0: f64,
    y0: State<D>,
    t1: f64,
    observer: &mut O,
) -> Result<(Stats, State<D>)>
where
    DefaultAllocator: Allocator<D>,
{
    let span = Span { t0, y0, t1 };
    solve_on(ScalarKernel::detect(), system, method, span, observer)
}

/// [`solve`] of `span` on a given compilation of its loop (the portable one when the processor
/// lacks the kernel's instruction set).
pub fn solve_on<D: Dim, S: OdeSystem<D>, O: Observer<D>>(
    kernel: ScalarKernel,
    system: &mut S,
    method: &Method,
    span: Span<D>,
    observer: &mut O,
) -> Result<(Stats, State<D>)>
where
    DefaultAllocator: Allocator<D>,
{
    let Span { t0, y0, t1 } = span;
    method.validate()?;
    system.check_span(t0, t1)?;
    if let Method::Rk4 { dt } = method {
        // A fixed step's cost is known up front.
        let n = (t1 - t0) / dt;
        if n > MAX_FIXED_STEPS {
            return Err(Error::invalid(
                "dt",
                dt,
                &format!(
                    "would take {n:.3e} steps over the span; at most {MAX_FIXED_STEPS:e} (use a larger dt)"
                ),
            ));
        }
    }
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
    let run = Integration {
        method,
        cuts,
        y: y0,
        stats: Stats {
            t_end: t0,
            ..Stats::default()
        },
        observer,
    };
    match kernel {
        #[cfg(target_arch = "x86_64")]
        ScalarKernel::Fma if kernel.runs_here() => {
            // SAFETY: the processor has AVX and FMA (checked just above).
            unsafe { integrate_fma(system, run) }
        }
        _ => integrate::<false, D, S, O>(system, run),
    }
}

/// An integration under way: the method, the span's cuts (its ends and the system's
/// breakpoints), the state reached, the work counters and the observer, carried from segment to
/// segment and through each stepper.
pub(super) struct Integration<'r, D: Dim, O>
where
    DefaultAllocator: Allocator<D>,
{
    method: &'r Method,
    cuts: Vec<f64>,
    pub(super) y: State<D>,
    pub(super) stats: Stats,
    pub(super) observer: &'r mut O,
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx,fma")]
unsafe fn integrate_fma<D: Dim, S: OdeSystem<D>, O: Observer<D>>(
    system: &mut S,
    run: Integration<'_, D, O>,
) -> Result<(Stats, State<D>)>
where
    DefaultAllocator: Allocator<D>,
{
    integrate::<true, D, S, O>(system, run)
}

/// `system` seen through its fused right-hand side ([`OdeSystem::rhs_fused`]), for the steppers.
pub struct FusedRhs<'a, S>(pub &'a S);

impl<D: Dim, S: OdeSystem<D>> OdeSystem<D> for FusedRhs<'_, S>
where
    DefaultAllocator: Allocator<D>,
{
    #[inline(always)]
    fn rhs(&self, t: f64, y: &State<D>) -> State<D> {
        self.0.rhs_fused(t, y)
    }
}

/// A local on a cache line of its own. Its alignment makes the compiler align the frame that
/// holds it to 64 bytes, so the step loop's 32-byte vectors, which it spills and reloads at every
/// step, sit at the same place in a cache line whatever the caller's stack depth. Unaligned,
/// they could straddle two lines at one depth only: the paper's orbit took 9 % longer called
/// from the engine's worker thread than from any other thread.
#[repr(align(64))]
struct LineAligned(#[expect(dead_code, reason = "only its alignment is used")] u8);

/// The segments between successive cuts, one after another, on the fused right-hand side when
/// `FUSED`. Always inlined, with the steppers and the right-hand side, into each compilation.
#[inline(always)]
fn integrate<const FUSED: bool, D: Dim, S: OdeSystem<D>, O: Observer<D>>(
    system: &mut S,
    mut run: Integration<'_, D, O>,
) -> Result<(Stats, State<D>)>
where
    DefaultAllocator: Allocator<D>,
{
    // Aligns this frame to a cache line (see LineAligned).
    let anchor = LineAligned(0);
    std::hint::black_box(&anchor);
    let cuts = std::mem::take(&mut run.cuts);
    let t1 = cuts[cuts.len() - 1];
    for w in cuts.windows(2) {
        let (a, b) = (w[0], w[1]);
        if b <= a {
            continue;
        }
        system.enter_segment(a, b);
        let flow = if FUSED {
            run.segment(&FusedRhs(&*system), (a, b))?
        } else {
            run.segment(&*system, (a, b))?
        };
        if flow.is_break() {
            run.stats.stopped = run.stats.t_end < t1;
            break;
        }
    }
    Ok((run.stats, run.y))
}

impl<D: Dim, O: Observer<D>> Integration<'_, D, O>
where
    DefaultAllocator: Allocator<D>,
{
    /// One segment [a, b] by the run's method.
    #[inline(always)]
    fn segment<S: OdeSystem<D>>(&mut self, system: &S, ab: (f64, f64)) -> Result<ControlFlow<()>> {
        match self.method {
            Method::Rk4 { dt } => rk4::segment(system, ab, *dt, self),
            Method::Dopri5(tol) => dopri5::segment(system, ab, tol, self),
        }
    }
}

/// Loosest relative tolerance accepted.
pub const MAX_RTOL: f64 = 1e-2;
/// Loosest absolute tolerance accepted (the state is in K, rad and rad/s; θ is ~0.1 rad).
pub const MAX_ATOL: f64 = 1e-3;

/// Most steps a fixed-step run may take (the adaptive one stops at `max_steps`).
pub const MAX_FIXED_STEPS: f64 = 5e8;

/// Largest |t| of a span, s (about 3,000 years): beyond it a step of a second is lost in the
/// rounding of t, and the orbit's phase means nothing.
pub const MAX_TIME: f64 = 1e11;

/// Checks an integration span: finite ends within ±[`MAX_TIME`], t1 > t0.
pub fn check_span(t0: f64, t1: f64) -> Result<()> {
    for (name, t) in [("t_span[0]", t0), ("t_span[1]", t1)] {
        if t.is_nan() || t.abs() > MAX_TIME {
            return Err(Error::invalid(
                name,
                t,
                &format!("must be finite and in [-{MAX_TIME:e}, {MAX_TIME:e}] s"),
            ));
        }
    }
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
pub(crate) fn rms_scaled<D: Dim>(x: &State<D>, scale: &State<D>) -> f64
where
    DefaultAllocator: Allocator<D>,
{
    let mut acc = 0.0;
    for i in 0..x.len() {
        let r = x[i] / scale[i];
        acc += r * r;
    }
    (acc / x.len() as f64).sqrt()
}

#[cfg(test)]
mod tests;
