//! Several independent runs of the coupled system advanced together, one run per SIMD lane.
//!
//! One panel's Dormand–Prince step is a chain of dependent operations (each stage waits for the
//! one before, each step for the step size of the one before), which leaves most of a core's
//! arithmetic units idle. Ensembles integrate many panels over the same span: running [`LANES`]
//! of them side by side fills those units, and the stage arithmetic maps onto vector
//! instructions (for the eight lanes: four SSE2, two AVX2 or one AVX-512 operation). Each
//! lane's y0, k1 and constant illumination stay in the vectors from step to step; only its
//! step size, times and reads pass through scalars.
//!
//! Every lane has its own step size, accept/reject decision, segments (shadow crossings),
//! counters and observer: lanes share only the instruction stream. A lane performs for its run
//! exactly the floating-point operations of [`crate::numerics::integrate::solve`] with [`crate::numerics::integrate::dopri5`], in the same
//! order, with the multiply-adds of the right-hand side fused exactly where the scalar kernel
//! the lane kernel matches fuses them ([`Kernel::scalar`]; Rust never contracts on its own), so
//! a run gives the same bits in any lane as alone, whatever the other lanes hold
//! (`tests::lanes_equal_single_runs`). A lane whose run ends takes the next job; a lane without
//! one computes on zeros and is ignored.
//!
//! The kernel is compiled three times: for the build's baseline, for AVX2 with FMA and for
//! AVX-512F with FMA, the newest the processor has picked at run time ([`Kernel::detect`]).
//! The two FMA kernels give the same bits, those of [`ScalarKernel::Fma`]; the portable one
//! those of [`ScalarKernel::Portable`].

use crate::error::{Error, Result};
use crate::models::coupled::{Coupled, Coupling, LaneForm};
use crate::models::hinge::quasi_static;
use crate::models::hinge::{angular_acceleration, generalised_moment, sin_cos_kernel, HingeModel};
use crate::models::thermal::Balance;
use crate::numerics::cpu::{Kernel, ScalarKernel};
use crate::numerics::integrate::dopri5::{
    self, A21, A3, A4, A5, A6, B, B_HAT, C, DENSE, ERROR_EXPONENT,
};
use crate::numerics::integrate::{
    check_span, solve_on, DenseStep, FusedRhs, Method, Observer, OdeSystem, Span, Stats, Tolerances,
};
#[cfg(target_arch = "x86_64")]
use crate::numerics::simd::{Avx, Avx512};
use crate::numerics::simd::{Lanes, Portable};
use nalgebra::Vector4;
use std::f64::consts::FRAC_PI_4;

/// Runs advanced together on one core.
pub const LANES: usize = crate::numerics::simd::LANES;

/// One run for a lane: integrate `system` from (`t0`, `y0`) to `t1` with Dormand–Prince at `tol`,
/// telling `observer` of every accepted step.
pub struct Job<O> {
    pub system: Coupled,
    pub tol: Tolerances,
    pub t0: f64,
    pub t1: f64,
    pub y0: Vector4<f64>,
    pub observer: O,
}

/// What a lane's run tells its observer. For every accepted step the lanes compute the reads the
/// per-orbit summary takes of it ([`StepReads`]); an observer that can take the step from them
/// spares the lane building the step's dense output.
pub trait LaneObserver: Observer<nalgebra::U4> {
    /// (M_T per kelvin, K_el) of the run's panel, for the dynamic part θ − M_T/K_el of
    /// [`StepReads`] (`models::hinge::quasi_static`); None: the observer takes dense steps only.
    fn dynamic_form(&self) -> Option<(f64, f64)> {
        None
    }
    /// Takes an accepted step from its reads; None: it needs the dense output, and
    /// [`Observer::on_step`] is called with it.
    fn on_reads(&mut self, _reads: &StepReads) -> Option<std::ops::ControlFlow<()>> {
        None
    }
}

/// An accepted step as the lanes read it: its start, middle ([`DenseStep::midpoint`]) and end,
/// with θ, the dynamic part θ − M_T/K_el at the middle and end, and whether θ̇ > 0 at the start,
/// middle and end. The same bits as reading the dense step.
#[derive(Debug, Clone, Copy)]
pub struct StepReads {
    pub t0: f64,
    pub t_mid: f64,
    pub t1: f64,
    /// θ at the middle and at the end.
    pub theta: [f64; 2],
    /// θ − M_T/K_el at the middle and at the end.
    pub dynamic: [f64; 2],
    /// θ̇ > 0 at the start, the middle and the end.
    pub rising: [bool; 3],
}

/// Runs every job `next` hands out, [`LANES`] at a time, and hands each observer back to `done`
/// with the run's outcome (as [`crate::numerics::integrate::solve`] returns it) as soon as its run ends. Jobs whose model or
/// coupling differs from the first job's run alone, through [`crate::numerics::integrate::solve`].
pub fn solve_lockstep<O, N, F>(kernel: Kernel, next: N, done: F)
where
    O: LaneObserver,
    N: FnMut() -> Option<Job<O>>,
    F: FnMut(O, Result<(Stats, Vector4<f64>)>),
{
    match kernel {
        #[cfg(target_arch = "x86_64")]
        Kernel::Avx2 if kernel.runs_here() => {
            // SAFETY: the processor has AVX2 and FMA (checked just above).
            unsafe { drive_avx2(next, done) }
        }
        #[cfg(target_arch = "x86_64")]
        Kernel::Avx512 if kernel.runs_here() => {
            // SAFETY: the processor has AVX-512F and FMA (checked just above).
            unsafe { drive_avx512(next, done) }
        }
        _ => drive::<Portable, O, N, F>(next, done),
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn drive_avx2<O, N, F>(next: N, done: F)
where
    O: LaneObserver,
    N: FnMut() -> Option<Job<O>>,
    F: FnMut(O, Result<(Stats, Vector4<f64>)>),
{
    drive::<Avx, O, N, F>(next, done)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,fma")]
unsafe fn drive_avx512<O, N, F>(next: N, done: F)
where
    O: LaneObserver,
    N: FnMut() -> Option<Job<O>>,
    F: FnMut(O, Result<(Stats, Vector4<f64>)>),
{
    drive::<Avx512, O, N, F>(next, done)
}

/// The lanes' inputs to one trial step, lane by lane in each value.
#[derive(Clone, Copy)]
struct Pack<V> {
    t: V,
    h: V,
    /// The step's end as the lane's run has it (t + h, bit for bit).
    t_new: V,
    y0: [V; 4],
    k1: [V; 4],
    /// Each lane's coefficients (see [`Coupled::lane_form`]).
    balance: Balance<V>,
    load_per_kelvin: V,
    damping: V,
    stiffness: V,
    atol: V,
    rtol: V,
    /// Illumination at the stage times t + c_i h (i = 2..5) and at t + h (stages 6 and 7).
    flux: [V; 5],
    /// M_T per kelvin and K_el, for the dynamic part of [`StepReads`].
    moment_per_kelvin: V,
    hinge_stiffness: V,
}

/// The lanes' results of one trial step.
struct Trial<V> {
    y_new: [V; 4],
    /// The continuous extension's coefficients r2..r5 (r1 is y0) of each component.
    dense: [[V; 4]; 4],
    /// k7 = f(t + h, y_new), the next step's k1.
    k7: [V; 4],
    /// The interpolant at the middle of the step ([`DenseStep::midpoint`]).
    mid: [V; 4],
    /// The error norm squared (mean square of the weighted error).
    mean_square: V,
    /// The middle of the step, and the dynamic part θ − M_T/K_el there and at its end.
    t_mid: V,
    dynamic: [V; 2],
}

impl<V: Lanes> Trial<V> {
    /// A trial of nothing, the starting value of a group's last trial.
    fn zeros() -> Self {
        let zero = V::from(0.0);
        Trial {
            y_new: [zero; 4],
            dense: [[zero; 4]; 4],
            k7: [zero; 4],
            mid: [zero; 4],
            mean_square: zero,
            t_mid: zero,
            dynamic: [zero; 2],
        }
    }
}

impl<V: Lanes> Pack<V> {
    fn zeros() -> Self {
        let zero = V::from(0.0);
        Pack {
            t: zero,
            h: zero,
            t_new: zero,
            y0: [zero; 4],
            k1: [zero; 4],
            balance: Balance {
                heating: zero,
                conduction: zero,
                radiation_front: zero,
                radiation_back: zero,
            },
            load_per_kelvin: zero,
            damping: zero,
            stiffness: zero,
            atol: zero,
            rtol: zero,
            flux: [zero; 5],
            moment_per_kelvin: zero,
            hinge_stiffness: V::from(1.0),
        }
    }

    /// Empties lane `l`: zeros keep its arithmetic finite and cheap.
    fn clear(&mut self, l: usize) {
        let mut empty = Pack::zeros();
        // A zero step would divide by zero in the midpoint: keep it finite.
        empty.h = 1.0.into();
        empty.t_new = 1.0.into();
        self.set_lane(l, &empty);
    }

    /// Copies lane `l` of `from` into lane `l`.
    fn set_lane(&mut self, l: usize, from: &Pack<V>) {
        let put = |to: &mut V, from: &V| to.lanes_mut()[l] = from.lanes()[l];
        put(&mut self.t, &from.t);
        put(&mut self.h, &from.h);
        put(&mut self.t_new, &from.t_new);
        for i in 0..4 {
            put(&mut self.y0[i], &from.y0[i]);
            put(&mut self.k1[i], &from.k1[i]);
        }
        put(&mut self.balance.heating, &from.balance.heating);
        put(&mut self.balance.conduction, &from.balance.conduction);
        put(
            &mut self.balance.radiation_front,
            &from.balance.radiation_front,
        );
        put(
            &mut self.balance.radiation_back,
            &from.balance.radiation_back,
        );
        put(&mut self.load_per_kelvin, &from.load_per_kelvin);
        put(&mut self.damping, &from.damping);
        put(&mut self.stiffness, &from.stiffness);
        put(&mut self.atol, &from.atol);
        put(&mut self.rtol, &from.rtol);
        for j in 0..5 {
            put(&mut self.flux[j], &from.flux[j]);
        }
        put(&mut self.moment_per_kelvin, &from.moment_per_kelvin);
        put(&mut self.hinge_stiffness, &from.hinge_stiffness);
    }
}

/// The coupled right-hand side in every lane: [`Coupled::rhs_at_flux`]'s arithmetic.
#[inline(always)]
fn rhs_lanes<V: Lanes>(
    model: HingeModel,
    coupling: Coupling,
    p: &Pack<V>,
    flux: V,
    y: &[V; 4],
) -> [V; 4] {
    // One body per (model, coupling), each with its constants folded, so that it holds no
    // branch.
    use {Coupling::*, HingeModel::*};
    match (model, coupling) {
        (Nonlinear, ProjectedArea) => rhs_lanes_of::<V, true, true>(p, flux, y),
        (Nonlinear, Frozen) => rhs_lanes_of::<V, true, false>(p, flux, y),
        (Linear, ProjectedArea) => rhs_lanes_of::<V, false, true>(p, flux, y),
        (Linear, Frozen) => rhs_lanes_of::<V, false, false>(p, flux, y),
    }
}

/// [`rhs_lanes`] of the model and coupling fixed by the type: the non-linear hinge when
/// `NONLINEAR`, the projected area when `PROJECTED`.
#[inline(always)]
fn rhs_lanes_of<V: Lanes, const NONLINEAR: bool, const PROJECTED: bool>(
    p: &Pack<V>,
    flux: V,
    y: &[V; 4],
) -> [V; 4] {
    let model = if NONLINEAR {
        HingeModel::Nonlinear
    } else {
        HingeModel::Linear
    };
    let coupling = if PROJECTED {
        Coupling::ProjectedArea
    } else {
        Coupling::Frozen
    };
    let [tf, tb, th, om] = *y;
    let (mut sin, mut cos) = (V::from(0.0), V::from(1.0));
    if !matches!((coupling, model), (Coupling::Frozen, HingeModel::Linear)) {
        // `sin_cos`: the polynomials in every lane, the library for a lane beyond π/4.
        (sin, cos) = sin_cos_kernel(th);
        if th.any_abs_above(FRAC_PI_4) {
            for l in 0..LANES {
                if th.lanes()[l].abs() > FRAC_PI_4 {
                    (sin.lanes_mut()[l], cos.lanes_mut()[l]) = th.lanes()[l].sin_cos();
                }
            }
        }
    }
    // `Coupled::rhs_at_flux` of the two-layer plate on the hinge.
    let load = p.load_per_kelvin * (tf - tb);
    let forced = generalised_moment(load, p.damping, p.stiffness, th, om);
    let acc = angular_acceleration(model, forced, om, sin, cos);
    let area = match coupling {
        Coupling::ProjectedArea => cos,
        Coupling::Frozen => V::from(1.0),
    };
    let (front, back) = p.balance.flows(flux * area, tf, tb);
    [front, back, om, acc]
}

/// y0 + Σ k_j (a_j h), summed in the order given (as nalgebra sums `y0 + k1 * x + k2 * y`).
#[inline(always)]
fn stage<V: Lanes, const M: usize>(y0: &[V; 4], h: V, terms: [(&[V; 4], f64); M]) -> [V; 4] {
    let mut out = *y0;
    for (k, a) in terms {
        let ah = V::from(a) * h;
        for i in 0..4 {
            out[i] = out[i] + k[i] * ah;
        }
    }
    out
}

/// One Dormand–Prince trial step in every lane: [`dopri5::step`] and the error norm of
/// [`dopri5`]'s segment loop, operation for operation.
#[inline(always)]
fn step_lanes<V: Lanes>(model: HingeModel, coupling: Coupling, p: &Pack<V>) -> Trial<V> {
    let (y0, k1, h) = (&p.y0, &p.k1, p.h);
    let f = |flux: V, y: &[V; 4]| rhs_lanes(model, coupling, p, flux, y);
    let k2 = f(p.flux[0], &stage(y0, h, [(k1, A21)]));
    let k3 = f(p.flux[1], &stage(y0, h, [(k1, A3[0]), (&k2, A3[1])]));
    let k4 = f(
        p.flux[2],
        &stage(y0, h, [(k1, A4[0]), (&k2, A4[1]), (&k3, A4[2])]),
    );
    let k5 = f(
        p.flux[3],
        &stage(
            y0,
            h,
            [(k1, A5[0]), (&k2, A5[1]), (&k3, A5[2]), (&k4, A5[3])],
        ),
    );
    let k6 = f(
        p.flux[4],
        &stage(
            y0,
            h,
            [
                (k1, A6[0]),
                (&k2, A6[1]),
                (&k3, A6[2]),
                (&k4, A6[3]),
                (&k5, A6[4]),
            ],
        ),
    );
    let y_new = stage(
        y0,
        h,
        [
            (k1, B[0]),
            (&k3, B[2]),
            (&k4, B[3]),
            (&k5, B[4]),
            (&k6, B[5]),
        ],
    );
    let k7 = f(p.flux[4], &y_new);
    // err = Σ k_j ((b_j − b̂_j) h), starting from the first product (no y0 term).
    let weights = [
        (&k3, B[2] - B_HAT[2]),
        (&k4, B[3] - B_HAT[3]),
        (&k5, B[4] - B_HAT[4]),
        (&k6, B[5] - B_HAT[5]),
        (&k7, B[6] - B_HAT[6]),
    ];
    let first = V::from(B[0] - B_HAT[0]) * h;
    let mut err = k1.map(|k| k * first);
    for (k, w) in weights {
        let wh = V::from(w) * h;
        for i in 0..4 {
            err[i] = err[i] + k[i] * wh;
        }
    }
    // The scaled error e_i = err_i / (atol + rtol max(|y0_i|, |y_new_i|)), and its mean square
    // summed as nalgebra's norm_squared sums a 4-vector: (e0² + e2²) + (e1² + e3²).
    // Arrays are built whole (`from_fn`), not zeroed and filled: the filling is not always
    // seen through, and zeroing a kilobyte per step costs.
    let e: [V; 4] = std::array::from_fn(|i| {
        let weight = V::from(1.0) / (p.atol + y0[i].abs().max(y_new[i].abs()) * p.rtol);
        err[i] * weight
    });
    let a = e[0] * e[0] + e[2] * e[2];
    let b = e[1] * e[1] + e[3] * e[3];
    let mean_square = (a + b) / V::from(4.0);
    // `dopri5::dense_coefficients`, computed for every lane (most trials are accepted and the
    // summary reads every step).
    let dense: [[V; 4]; 4] = std::array::from_fn(|i| {
        let diff = y_new[i] - y0[i];
        let bspl = k1[i] * h - diff;
        let r4 = diff - k7[i] * h - bspl;
        let r5 = (k1[i] * V::from(DENSE[0])
            + k3[i] * V::from(DENSE[2])
            + k4[i] * V::from(DENSE[3])
            + k5[i] * V::from(DENSE[4])
            + k6[i] * V::from(DENSE[5])
            + k7[i] * V::from(DENSE[6]))
            * h;
        [diff, bspl, r4, r5]
    });
    // `DenseStep::midpoint`: the interpolant at t + h/2 as `DenseStep::eval` evaluates it
    // (the summaries read every step there), or y_new where that time rounds onto the end.
    let t_mid = p.t + V::from(0.5) * h;
    let th = (t_mid - p.t) / h;
    let th1 = V::from(1.0) - th;
    let at_end: [bool; LANES] = std::array::from_fn(|l| t_mid.lanes()[l] == p.t_new.lanes()[l]);
    let mid: [V; 4] = std::array::from_fn(|i| {
        let [r2, r3, r4, r5] = dense[i];
        let y = y0[i] + (r2 + (r3 + (r4 + r5 * th1) * th) * th1) * th;
        y.or_where(at_end, y_new[i])
    });
    // The summary's dynamic part at the middle and the end (`Collector::point`).
    let dynamic = [&mid, &y_new].map(|[tf, tb, th, _]| {
        *th - quasi_static(p.moment_per_kelvin, p.hinge_stiffness, *tf, *tb)
    });
    Trial {
        y_new,
        dense,
        k7,
        mid,
        mean_square,
        t_mid,
        dynamic,
    }
}

/// A run in a lane: [`crate::numerics::integrate::solve`]'s loop over segments and `dopri5::segment`'s loop over
/// steps, unrolled into states so that each trial step is taken with the other lanes'.
struct Lane<O> {
    system: Coupled,
    tol: Tolerances,
    observer: O,
    cuts: Vec<f64>,
    /// Index in `cuts` of the end of the current segment.
    seg: usize,
    t: f64,
    b: f64,
    t1: f64,
    h_abs: f64,
    min_step: f64,
    /// The trial under way follows a rejection.
    rejected: bool,
    t_new: f64,
    stats: Stats,
    y: Vector4<f64>,
    /// The first stage of the next trial, when the lane's pack holds another (`stale`).
    k1: Vector4<f64>,
    /// The illumination when it is the same over the whole segment.
    constant_flux: Option<f64>,
    /// The pack's y0, k1 and constant illumination in this lane are not the run's: the run has
    /// just started or entered a segment. Otherwise the pack keeps them from step to step (the
    /// lanes that accept take y_new and k7 together, [`drive`]).
    stale: bool,
    /// The scalar kernel whose arithmetic the lanes have: the run's scalar parts (its first
    /// stage at each segment, its first step's estimate) take its right-hand side too.
    kernel: ScalarKernel,
}

/// A segment's first stage f(a, y) and first step's estimate on `system`: the prologue of
/// `dopri5::segment`.
fn first_step<S: OdeSystem<nalgebra::U4>>(
    system: &S,
    a: f64,
    b: f64,
    y: &Vector4<f64>,
    tol: &Tolerances,
    stats: &mut Stats,
) -> (Vector4<f64>, f64) {
    let k1 = system.rhs(a, y);
    let h0 = dopri5::initial_step(4, system, a, y, &k1, b - a, tol, stats);
    (k1, h0)
}

/// How a run left its lane.
type Outcome = Result<(Stats, Vector4<f64>)>;

impl<O: LaneObserver> Lane<O> {
    /// Sets up a run (the checks of [`crate::numerics::integrate::solve`]); `Err` hands the job back with its outcome
    /// when it ends before its first step.
    fn start(job: Job<O>, kernel: ScalarKernel) -> std::result::Result<Self, (O, Outcome)> {
        let Job {
            system,
            tol,
            t0,
            t1,
            y0,
            observer,
        } = job;
        let checked = Method::Dopri5(tol)
            .validate()
            .and_then(|()| check_span(t0, t1))
            .and_then(|()| match y0.iter().position(|v| !v.is_finite()) {
                Some(i) => Err(Error::invalid(
                    "y0",
                    y0[i],
                    "every component must be finite",
                )),
                None => Ok(()),
            });
        if let Err(e) = checked {
            return Err((observer, Err(e)));
        }
        let mut cuts = vec![t0];
        cuts.extend(system.breakpoints(t0, t1));
        cuts.push(t1);
        let mut lane = Lane {
            system,
            tol,
            observer,
            cuts,
            seg: 0,
            t: t0,
            b: t0,
            t1,
            h_abs: 0.0,
            min_step: 0.0,
            rejected: false,
            t_new: t0,
            stats: Stats {
                t_end: t0,
                ..Stats::default()
            },
            y: y0,
            k1: y0,
            constant_flux: None,
            stale: true,
            kernel,
        };
        if lane.enter_segment() {
            Ok(lane)
        } else {
            let (stats, y) = (lane.stats, lane.y);
            Err((lane.observer, Ok((stats, y))))
        }
    }

    /// Enters the next non-empty segment (false: none is left): the prologue of
    /// `dopri5::segment`.
    fn enter_segment(&mut self) -> bool {
        while self.seg + 1 < self.cuts.len() {
            let (a, b) = (self.cuts[self.seg], self.cuts[self.seg + 1]);
            self.seg += 1;
            if b <= a {
                continue;
            }
            self.system.enter_segment(a, b);
            self.constant_flux = self.system.constant_flux();
            self.t = a;
            self.b = b;
            let (y, tol, stats) = (&self.y, &self.tol, &mut self.stats);
            let (k1, h0) = if self.kernel.fused() {
                first_step(&FusedRhs(&self.system), a, b, y, tol, stats)
            } else {
                first_step(&self.system, a, b, y, tol, stats)
            };
            self.k1 = k1;
            self.stats.n_rhs += 1;
            self.stale = true;
            self.h_abs = h0.min(self.tol.max_step);
            self.rejected = false;
            return true;
        }
        false
    }

    /// Chooses the trial step and loads the lane's inputs into `p`.
    fn begin_trial<V: Lanes>(&mut self, p: &mut Pack<V>, l: usize) -> Result<()> {
        let t = self.t;
        if !self.rejected {
            self.min_step = 10.0 * (dopri5::next_up(t) - t);
            if self.h_abs < self.min_step {
                self.h_abs = self.min_step;
            }
        }
        if self.stats.n_steps + self.stats.n_rejected >= self.tol.max_steps {
            return Err(Error::Integration {
                t,
                reason: format!("max_steps = {} reached", self.tol.max_steps),
            });
        }
        let t_new = if t + self.h_abs >= self.b {
            self.b
        } else {
            t + self.h_abs
        };
        self.t_new = t_new;
        let h = t_new - t;
        p.t.lanes_mut()[l] = t;
        p.h.lanes_mut()[l] = h;
        p.t_new.lanes_mut()[l] = t_new;
        if self.stale {
            for i in 0..4 {
                p.y0[i].lanes_mut()[l] = self.y[i];
                p.k1[i].lanes_mut()[l] = self.k1[i];
            }
            if let Some(flux) = self.constant_flux {
                for f in &mut p.flux {
                    f.lanes_mut()[l] = flux;
                }
            }
            self.stale = false;
        }
        if self.constant_flux.is_none() {
            for (j, c) in C[1..5].iter().enumerate() {
                p.flux[j].lanes_mut()[l] = self.system.flux_at(t + c * h);
            }
            p.flux[4].lanes_mut()[l] = self.system.flux_at(t_new);
        }
        Ok(())
    }

    /// Loads what stays fixed over the run into lane `l` of `p`.
    fn load<V: Lanes>(&self, p: &mut Pack<V>, l: usize) {
        let f = self.system.lane_form();
        let b = f.balance;
        let form = self.observer.dynamic_form().unwrap_or((0.0, 1.0));
        let to = &mut p.balance;
        for (c, v) in [
            (&mut to.heating, b.heating),
            (&mut to.conduction, b.conduction),
            (&mut to.radiation_front, b.radiation_front),
            (&mut to.radiation_back, b.radiation_back),
            (&mut p.load_per_kelvin, f.load_per_kelvin),
            (&mut p.damping, f.damping),
            (&mut p.stiffness, f.stiffness),
            (&mut p.atol, self.tol.atol),
            (&mut p.rtol, self.tol.rtol),
            (&mut p.moment_per_kelvin, form.0),
            (&mut p.hinge_stiffness, form.1),
        ] {
            c.lanes_mut()[l] = v;
        }
    }

    /// Accepts or rejects the trial in lane `l` of `trial` (the tail of `dopri5::segment`'s
    /// loop); `Some` when the run has ended.
    fn end_trial<V: Lanes>(&mut self, trial: &Trial<V>, l: usize) -> Option<Outcome> {
        let (t, t_new) = (self.t, self.t_new);
        let h = t_new - t;
        self.stats.n_rhs += 6;
        let mean_square = trial.mean_square.lanes()[l];
        let lane = |v: &[V; 4]| Vector4::from(v.map(|x| x.lanes()[l]));
        if mean_square < 1.0 {
            self.stats.n_steps += 1;
            let y0 = self.y;
            let y_new = lane(&trial.y_new);
            self.y = y_new;
            let at = |v: &V| v.lanes()[l];
            let reads = StepReads {
                t0: t,
                t_mid: at(&trial.t_mid),
                t1: t_new,
                theta: [at(&trial.mid[2]), y_new[2]],
                dynamic: trial.dynamic.map(|d| at(&d)),
                rising: [y0[3] > 0.0, at(&trial.mid[3]) > 0.0, y_new[3] > 0.0],
            };
            let flow = self.observer.on_reads(&reads).unwrap_or_else(|| {
                let r_j = |j: usize| Vector4::from(trial.dense.map(|c| c[j].lanes()[l]));
                let r = [y0, r_j(0), r_j(1), r_j(2), r_j(3)];
                let mid = lane(&trial.mid);
                let dense = DenseStep::with_coefficients(t, t_new, y0, y_new, r, mid);
                self.observer.on_step(&dense)
            });
            self.t = t_new;
            self.stats.t_end = t_new;
            self.h_abs = dopri5::next_step(h, mean_square, self.rejected, self.tol.max_step);
            self.rejected = false;
            if flow.is_break() {
                self.stats.stopped = self.stats.t_end < self.t1;
                return Some(Ok((self.stats, self.y)));
            }
            if self.t >= self.b && !self.enter_segment() {
                return Some(Ok((self.stats, self.y)));
            }
            return None;
        }
        self.stats.n_rejected += 1;
        let err_norm = mean_square.sqrt();
        self.h_abs = dopri5::shrunk_step(h, err_norm, ERROR_EXPONENT);
        self.rejected = true;
        if self.h_abs < self.min_step {
            return Some(Err(dopri5::step_too_small(
                t,
                self.h_abs,
                self.y.as_slice(),
            )));
        }
        None
    }
}

/// Groups of [`LANES`] runs the loop alternates between. While one group's trial step runs its
/// chain of dependent vector operations, the processor does the other group's bookkeeping (its
/// accepts, rejections, next steps and the observers' reads), which needs none of that step's
/// results.
const GROUPS: usize = 2;

/// Runs a core holds at once: [`GROUPS`] groups of [`LANES`].
pub const RUNS_PER_CORE: usize = GROUPS * LANES;

/// One group of lanes: their runs, their inputs to the next trial and the last trial's results.
struct Group<V, O> {
    lanes: [Option<Lane<O>>; LANES],
    pack: Pack<V>,
    /// Kept in place (not moved in and out of an `Option`: two kilobytes a step).
    trial: Trial<V>,
    /// `trial` has been taken and not yet finished.
    pending: bool,
}

impl<V: Lanes, O: LaneObserver> Group<V, O> {
    fn new() -> Self {
        Group {
            lanes: std::array::from_fn(|_| None),
            pack: Pack::zeros(),
            trial: Trial::zeros(),
            pending: false,
        }
    }

    /// Gives every idle lane the next job (a job of another model or coupling than the loop's
    /// runs alone, at once).
    fn fill<N, F>(
        &mut self,
        next: &mut N,
        done: &mut F,
        form: &mut Option<(HingeModel, Coupling)>,
        exhausted: &mut bool,
    ) where
        N: FnMut() -> Option<Job<O>>,
        F: FnMut(O, Result<(Stats, Vector4<f64>)>),
    {
        for (l, slot) in self.lanes.iter_mut().enumerate() {
            while slot.is_none() && !*exhausted {
                let Some(mut job) = next() else {
                    *exhausted = true;
                    break;
                };
                let LaneForm {
                    model, coupling, ..
                } = job.system.lane_form();
                let (m, c) = *form.get_or_insert((model, coupling));
                if (model, coupling) != (m, c) {
                    let outcome = solve_on(
                        kernel_of::<V>(),
                        &mut job.system,
                        &Method::Dopri5(job.tol),
                        Span {
                            t0: job.t0,
                            y0: job.y0,
                            t1: job.t1,
                        },
                        &mut job.observer,
                    );
                    done(job.observer, outcome);
                    continue;
                }
                match Lane::start(job, kernel_of::<V>()) {
                    Ok(lane) => {
                        lane.load(&mut self.pack, l);
                        *slot = Some(lane);
                    }
                    Err((observer, outcome)) => done(observer, outcome),
                }
            }
        }
    }

    /// Loads every run's next trial into the pack; false when no lane holds a run.
    fn begin<F>(&mut self, done: &mut F) -> bool
    where
        F: FnMut(O, Result<(Stats, Vector4<f64>)>),
    {
        let mut busy = false;
        for (l, slot) in self.lanes.iter_mut().enumerate() {
            let Some(lane) = slot else {
                continue;
            };
            match lane.begin_trial(&mut self.pack, l) {
                Ok(()) => busy = true,
                Err(e) => {
                    let lane = slot.take().expect("a lane");
                    self.pack.clear(l);
                    done(lane.observer, Err(e));
                }
            }
        }
        busy
    }

    /// Accepts or rejects the last trial in every lane, and hands back the runs that ended.
    fn finish<F>(&mut self, done: &mut F)
    where
        F: FnMut(O, Result<(Stats, Vector4<f64>)>),
    {
        let trial = &self.trial;
        // The lanes that accept start their next trial from y_new with k1 = k7 (a lane that
        // then enters a segment or ends is reloaded or cleared below).
        let accepted: [bool; LANES] =
            std::array::from_fn(|l| self.lanes[l].is_some() && trial.mean_square.lanes()[l] < 1.0);
        let p = &mut self.pack;
        for i in 0..4 {
            p.y0[i] = p.y0[i].or_where(accepted, trial.y_new[i]);
            p.k1[i] = p.k1[i].or_where(accepted, trial.k7[i]);
        }
        for (l, slot) in self.lanes.iter_mut().enumerate() {
            let Some(lane) = slot else {
                continue;
            };
            if let Some(outcome) = lane.end_trial(trial, l) {
                let lane = slot.take().expect("a lane");
                self.pack.clear(l);
                done(lane.observer, outcome);
            }
        }
    }
}

/// The scalar kernel whose arithmetic the lane type `V` has.
fn kernel_of<V: Lanes>() -> ScalarKernel {
    if V::FUSED {
        ScalarKernel::Fma
    } else {
        ScalarKernel::Portable
    }
}

/// The lockstep loop (compiled once per [`Kernel`]): [`GROUPS`] groups in turn, each finishing
/// its last trial, taking new jobs into its idle lanes and starting its next trial.
#[inline(always)]
fn drive<V: Lanes, O, N, F>(mut next: N, mut done: F)
where
    O: LaneObserver,
    N: FnMut() -> Option<Job<O>>,
    F: FnMut(O, Result<(Stats, Vector4<f64>)>),
{
    let mut groups: [Group<V, O>; GROUPS] = std::array::from_fn(|_| Group::new());
    let mut form: Option<(HingeModel, Coupling)> = None;
    let mut exhausted = false;
    loop {
        let mut busy = false;
        for group in &mut groups {
            if group.pending {
                group.finish(&mut done);
                group.pending = false;
            }
            group.fill(&mut next, &mut done, &mut form, &mut exhausted);
            let Some((model, coupling)) = form else {
                // No job has been taken in lockstep, so none is left.
                return;
            };
            if group.begin(&mut done) {
                group.trial = step_lanes(model, coupling, &group.pack);
                group.pending = true;
                busy = true;
            }
        }
        if !busy && exhausted {
            return;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::analysis::steady::equilibrium;
    use crate::inputs::orbit::Orbit;
    use crate::inputs::panel::Panel;
    use crate::numerics::integrate::Recorder;
    use nalgebra::U4;

    /// A run's samples, with its index.
    struct Tagged(usize, Recorder<U4>);

    impl Observer<U4> for Tagged {
        fn on_step(&mut self, step: &DenseStep<U4>) -> std::ops::ControlFlow<()> {
            self.1.on_step(step)
        }
    }

    impl LaneObserver for Tagged {}

    /// A job per panel: one orbit sampled at 200 times, with its index.
    fn jobs(panels: &[Panel], model: HingeModel, coupling: Coupling) -> Vec<Job<Tagged>> {
        let orbit = Orbit {
            radius: 7.0e6,
            period: 5828.5,
            ..Orbit::geo_equinox()
        };
        jobs_on(orbit, panels, model, coupling)
    }

    fn jobs_on(
        orbit: Orbit,
        panels: &[Panel],
        model: HingeModel,
        coupling: Coupling,
    ) -> Vec<Job<Tagged>> {
        panels
            .iter()
            .enumerate()
            .map(|(k, p)| {
                let eq = equilibrium(p, coupling, orbit.flux_scale(0.0)).unwrap();
                Job {
                    system: Coupled::new(*p, orbit, model, coupling),
                    tol: Tolerances {
                        rtol: 1e-7,
                        atol: 1e-9,
                        max_step: 3.0 + k as f64,
                        ..Tolerances::default()
                    },
                    t0: 0.0,
                    t1: orbit.period,
                    y0: Vector4::new(eq.t_front, eq.t_back, eq.theta + 0.15 * (k % 8) as f64, 0.0),
                    observer: Tagged(k, Recorder::every(0.0, orbit.period, orbit.period / 200.0)),
                }
            })
            .collect()
    }

    fn panels(n: usize) -> Vec<Panel> {
        (0..n)
            .map(|k| Panel {
                damping: 0.4 * k as f64,
                conductance: 18.0 + 1.5 * k as f64,
                ..Panel::paper()
            })
            .collect()
    }

    /// A run's samples and end state by their bits, with its counters.
    type Run = (Vec<u64>, Vec<u64>, Stats);
    type Runs = Vec<Run>;

    /// Each job's samples and end state by their bits, with its counters, in job order.
    fn in_lockstep(kernel: Kernel, jobs: Vec<Job<Tagged>>) -> Runs {
        let n = jobs.len();
        let mut out: Vec<Option<Run>> = vec![None; n];
        let mut queue = jobs.into_iter();
        solve_lockstep(
            kernel,
            || queue.next(),
            |Tagged(k, recorder), outcome| {
                let (stats, y_end) = outcome.unwrap();
                out[k] = Some(bits(&recorder, &y_end, stats));
            },
        );
        out.into_iter().map(Option::unwrap).collect()
    }

    fn bits(s: &Recorder<U4>, y: &Vector4<f64>, stats: Stats) -> Run {
        let samples = s.y.iter().flat_map(|v| v.iter()).map(|x| x.to_bits());
        let end = y.iter().map(|x| x.to_bits()).collect();
        (samples.collect(), end, stats)
    }

    /// Each job run alone on `kernel`.
    fn alone(kernel: ScalarKernel, jobs: Vec<Job<Tagged>>) -> Runs {
        jobs.into_iter()
            .map(|mut j| {
                let method = Method::Dopri5(j.tol);
                let span = Span {
                    t0: j.t0,
                    y0: j.y0,
                    t1: j.t1,
                };
                let (stats, y_end) =
                    solve_on(kernel, &mut j.system, &method, span, &mut j.observer.1).unwrap();
                bits(&j.observer.1, &y_end, stats)
            })
            .collect()
    }

    #[test]
    fn lanes_equal_single_runs() {
        // Three runs more than a core holds: lanes of both groups refill, and the last ones run
        // with idle lanes. Runs 6 and 7 start beyond π/4, where sin/cos come from the library.
        for (model, coupling) in [
            (HingeModel::Nonlinear, Coupling::ProjectedArea),
            (HingeModel::Linear, Coupling::Frozen),
            (HingeModel::Nonlinear, Coupling::Frozen),
        ] {
            let ps = panels(RUNS_PER_CORE + 3);
            for kernel in Kernel::available() {
                let want = alone(kernel.scalar(), jobs(&ps, model, coupling));
                assert!(want
                    .iter()
                    .all(|(_, _, s)| s.n_rejected > 0 || s.n_steps > 100));
                let got = in_lockstep(kernel, jobs(&ps, model, coupling));
                for (k, (g, w)) in got.iter().zip(&want).enumerate() {
                    assert_eq!(g, w, "{model:?} {coupling:?} {kernel:?}: run {k}");
                }
            }
        }
    }

    #[test]
    fn lanes_equal_single_runs_through_a_penumbra() {
        // The Sun's distance and the penumbra make the illumination vary within segments.
        let orbit = Orbit::geo_year(273.0);
        assert!(orbit.eclipses(0.0, orbit.period).len() == 1);
        let ps = panels(5);
        let (m, c) = (HingeModel::Nonlinear, Coupling::ProjectedArea);
        for kernel in Kernel::available() {
            let want = alone(kernel.scalar(), jobs_on(orbit, &ps, m, c));
            assert_eq!(in_lockstep(kernel, jobs_on(orbit, &ps, m, c)), want);
        }
    }

    #[test]
    fn a_failing_run_leaves_the_others_alone() {
        let ps = panels(5);
        let mut js = jobs(&ps, HingeModel::Nonlinear, Coupling::ProjectedArea);
        js[1].tol.max_steps = 50;
        js[3].y0[0] = f64::NAN;
        let kernel = Kernel::detect();
        let want = alone(
            kernel.scalar(),
            jobs(&ps, HingeModel::Nonlinear, Coupling::ProjectedArea),
        );
        let mut errors = Vec::new();
        let mut ok = Vec::new();
        let mut queue = js.into_iter();
        solve_lockstep(
            kernel,
            || queue.next(),
            |Tagged(k, s), outcome| match outcome {
                Ok((stats, y)) => ok.push((k, bits(&s, &y, stats))),
                Err(e) => errors.push((k, e.to_string())),
            },
        );
        errors.sort_by_key(|e| e.0);
        assert_eq!(errors.len(), 2, "{errors:?}");
        assert_eq!(errors[0].0, 1);
        assert!(errors[0].1.contains("max_steps = 50"), "{}", errors[0].1);
        assert_eq!(errors[1].0, 3);
        assert!(errors[1].1.starts_with("y0"), "{}", errors[1].1);
        for (k, got) in ok {
            assert_eq!(got, want[k], "run {k}");
        }
    }

    #[test]
    fn a_job_of_another_model_runs_alone() {
        let ps = panels(3);
        // Alone on the scalar kernel of the lanes' (the fused one beside fused lanes).
        for kernel in Kernel::available() {
            let scalar = kernel.scalar();
            let mut want = alone(
                scalar,
                jobs(&ps, HingeModel::Nonlinear, Coupling::ProjectedArea),
            );
            let linear = jobs(&ps, HingeModel::Linear, Coupling::ProjectedArea);
            want[1] = alone(scalar, linear).remove(1);
            let js = jobs(&ps, HingeModel::Nonlinear, Coupling::ProjectedArea)
                .into_iter()
                .enumerate()
                .map(|(k, j)| if k == 1 { other_job(&ps) } else { j })
                .collect();
            assert_eq!(in_lockstep(kernel, js), want, "{kernel:?}");
        }
    }

    /// The second job of [`a_job_of_another_model_runs_alone`]: the linear hinge.
    fn other_job(ps: &[Panel]) -> Job<Tagged> {
        jobs(ps, HingeModel::Linear, Coupling::ProjectedArea)
            .into_iter()
            .nth(1)
            .unwrap()
    }
}
