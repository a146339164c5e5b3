//! Dormand–Prince 5(4) with error control, FSAL and Hairer's fourth-order continuous extension.
//!
//! The controller is the standard one (the same family as SciPy's RK45): RMS error norm scaled by
//! atol + rtol·max(|y_old|, |y_new|), new step h·min(10, 0.9·err^(−1/5)), shrink at most 5×, no
//! growth right after a rejection, and Hairer's initial-step estimate at the start of every segment.
//! It takes the same steps as SciPy's RK45 (tests/test_controller.py); the arithmetic is arranged
//! for short dependency chains (benches/README.md), which moves results by rounding only.

use super::{rms_scaled, DenseStep, Integration, Observer, OdeSystem, State, Stats, Tolerances};
use crate::error::{Error, Result};
use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim};
use std::ops::ControlFlow;

// Butcher tableau.
pub const C: [f64; 7] = [0.0, 1.0 / 5.0, 3.0 / 10.0, 4.0 / 5.0, 8.0 / 9.0, 1.0, 1.0];
pub const A21: f64 = 1.0 / 5.0;
pub const A3: [f64; 2] = [3.0 / 40.0, 9.0 / 40.0];
pub const A4: [f64; 3] = [44.0 / 45.0, -56.0 / 15.0, 32.0 / 9.0];
pub const A5: [f64; 4] = [
    19372.0 / 6561.0,
    -25360.0 / 2187.0,
    64448.0 / 6561.0,
    -212.0 / 729.0,
];
pub const A6: [f64; 5] = [
    9017.0 / 3168.0,
    -355.0 / 33.0,
    46732.0 / 5247.0,
    49.0 / 176.0,
    -5103.0 / 18656.0,
];
/// Fifth-order weights (also the seventh row: first same as last).
pub const B: [f64; 7] = [
    35.0 / 384.0,
    0.0,
    500.0 / 1113.0,
    125.0 / 192.0,
    -2187.0 / 6784.0,
    11.0 / 84.0,
    0.0,
];
/// Fourth-order embedded weights.
pub const B_HAT: [f64; 7] = [
    5179.0 / 57600.0,
    0.0,
    7571.0 / 16695.0,
    393.0 / 640.0,
    -92097.0 / 339200.0,
    187.0 / 2100.0,
    1.0 / 40.0,
];
/// Dense-output coefficients (Hairer, Nørsett & Wanner, dopri5).
pub(crate) const DENSE: [f64; 7] = [
    -12715105075.0 / 11282082432.0,
    0.0,
    87487479700.0 / 32700410799.0,
    -10690763975.0 / 1880347072.0,
    701980252875.0 / 199316789632.0,
    -1453857185.0 / 822651844.0,
    69997945.0 / 29380423.0,
];

pub(crate) const SAFETY: f64 = 0.9;
pub(crate) const MIN_FACTOR: f64 = 0.2;
pub(crate) const MAX_FACTOR: f64 = 10.0;
pub(crate) const ERROR_EXPONENT: f64 = -1.0 / 5.0;

/// Hairer's estimate of a first step for an error estimator of order `order` (the step's local
/// error goes as h^(order + 1)).
#[allow(clippy::too_many_arguments)]
pub(crate) fn initial_step<D: Dim, S: OdeSystem<D>>(
    order: i32,
    system: &S,
    t0: f64,
    y0: &State<D>,
    f0: &State<D>,
    interval: f64,
    tol: &Tolerances,
    stats: &mut Stats,
) -> f64
where
    DefaultAllocator: Allocator<D>,
{
    let scale = y0.map(|v| tol.atol + v.abs() * tol.rtol);
    let d0 = rms_scaled(y0, &scale);
    let d1 = rms_scaled(f0, &scale);
    let h0 = if d0 < 1e-5 || d1 < 1e-5 {
        1e-6
    } else {
        0.01 * d0 / d1
    };
    let h0 = h0.min(interval);
    let y1 = y0 + f0 * h0;
    let f1 = system.rhs(t0 + h0, &y1);
    stats.n_rhs += 1;
    let d2 = rms_scaled(&(f1 - f0), &scale) / h0;
    let h1 = if d1 <= 1e-15 && d2 <= 1e-15 {
        (h0 * 1e-3).max(1e-6)
    } else {
        (0.01 / d1.max(d2)).powf(1.0 / f64::from(order + 1))
    };
    (100.0 * h0).min(h1).min(interval)
}

/// One trial step: the new state, the stage slopes k1..k7 (k7 = f(t_new, y_new)) and the
/// difference between the fifth- and fourth-order solutions.
#[derive(Debug, Clone)]
pub struct Step<D: Dim>
where
    DefaultAllocator: Allocator<D>,
{
    pub y_new: State<D>,
    pub k: [State<D>; 7],
    pub err: State<D>,
}

/// The stages of one Dormand–Prince step from (t, y) to t_new, given k1 = f(t, y).
#[inline(always)]
pub fn step<D: Dim, S: OdeSystem<D>>(
    system: &S,
    t: f64,
    t_new: f64,
    y0: &State<D>,
    k1: &State<D>,
) -> Step<D>
where
    DefaultAllocator: Allocator<D>,
{
    let h = t_new - t;
    // Each stage's state is y0 + Σ k_j (a_j h), summed in stage order: the newest slope enters
    // last, through one multiply and one add, which keeps the chain from stage to stage short.
    let k2 = system.rhs(t + C[1] * h, &(y0 + k1 * (A21 * h)));
    let k3 = system.rhs(t + C[2] * h, &(y0 + k1 * (A3[0] * h) + &k2 * (A3[1] * h)));
    let k4 = system.rhs(
        t + C[3] * h,
        &(y0 + k1 * (A4[0] * h) + &k2 * (A4[1] * h) + &k3 * (A4[2] * h)),
    );
    let k5 = system.rhs(
        t + C[4] * h,
        &(y0 + k1 * (A5[0] * h) + &k2 * (A5[1] * h) + &k3 * (A5[2] * h) + &k4 * (A5[3] * h)),
    );
    let k6 = system.rhs(
        t_new,
        &(y0 + k1 * (A6[0] * h)
            + &k2 * (A6[1] * h)
            + &k3 * (A6[2] * h)
            + &k4 * (A6[3] * h)
            + &k5 * (A6[4] * h)),
    );
    let y_new = y0
        + k1 * (B[0] * h)
        + &k3 * (B[2] * h)
        + &k4 * (B[3] * h)
        + &k5 * (B[4] * h)
        + &k6 * (B[5] * h);
    let k7 = system.rhs(t_new, &y_new);
    let err = k1 * ((B[0] - B_HAT[0]) * h)
        + &k3 * ((B[2] - B_HAT[2]) * h)
        + &k4 * ((B[3] - B_HAT[3]) * h)
        + &k5 * ((B[4] - B_HAT[4]) * h)
        + &k6 * ((B[5] - B_HAT[5]) * h)
        + &k7 * ((B[6] - B_HAT[6]) * h);
    Step {
        y_new,
        k: [k1.clone(), k2, k3, k4, k5, k6, k7],
        err,
    }
}

/// Integrates one segment [a, b] on which the right-hand side is smooth; `y` goes from y(a) to y(b).
#[inline(always)]
pub(super) fn segment<D: Dim, S: OdeSystem<D>, O: Observer<D>>(
    system: &S,
    (a, b): (f64, f64),
    tol: &Tolerances,
    run: &mut Integration<'_, D, O>,
) -> Result<ControlFlow<()>>
where
    DefaultAllocator: Allocator<D>,
{
    let mut t = a;
    let mut k1 = system.rhs(t, &run.y);
    run.stats.n_rhs += 1;
    let mut h_abs =
        initial_step(4, system, t, &run.y, &k1, b - a, tol, &mut run.stats).min(tol.max_step);

    while t < b {
        let min_step = 10.0 * (next_up(t) - t);
        if h_abs < min_step {
            h_abs = min_step;
        }
        let mut rejected = false;
        loop {
            if run.stats.n_steps + run.stats.n_rejected >= tol.max_steps {
                return Err(Error::Integration {
                    t,
                    reason: format!("max_steps = {} reached", tol.max_steps),
                });
            }
            let t_new = if t + h_abs >= b { b } else { t + h_abs };
            let h = t_new - t;

            let y0 = run.y.clone();
            let Step { y_new, k, err } = step(system, t, t_new, &y0, &k1);
            run.stats.n_rhs += 6;
            // The error's scale is known before the last stage is, so its reciprocal is ready
            // by the time the error is; the growth factor comes straight from the mean square.
            let weight = y0.zip_map(&y_new, |u, v| {
                1.0 / (tol.atol + u.abs().max(v.abs()) * tol.rtol)
            });
            // err_norm² (the RMS norm squared): err_norm < 1 when this is < 1 (but for the one
            // double just below 1, whose root rounds to 1), so the root is taken on rejection only.
            let mean_square = err.component_mul(&weight).norm_squared() / y0.len() as f64;

            if mean_square < 1.0 {
                // NaN fails this test, so a non-finite state is rejected and shrinks h.
                run.stats.n_steps += 1;
                let [_, _, k3, k4, k5, k6, k7] = k;
                run.y = y_new.clone();
                let next_k1 = k7.clone();
                let dense = DenseStep::dopri5(t, t_new, y0, y_new, [k1, k3, k4, k5, k6, k7]);
                t = t_new;
                run.stats.t_end = t;
                k1 = next_k1;
                h_abs = next_step(h, mean_square, rejected, tol.max_step);
                if run.observer.on_step(&dense).is_break() {
                    return Ok(ControlFlow::Break(()));
                }
                break;
            }
            run.stats.n_rejected += 1;
            h_abs = shrunk_step(h, mean_square.sqrt(), ERROR_EXPONENT);
            rejected = true;
            if h_abs < min_step {
                return Err(step_too_small(t, h_abs, y0.as_slice()));
            }
        }
    }
    Ok(ControlFlow::Continue(()))
}

/// The step after an accepted step of size h whose error norm squared is `mean_square` (< 1):
/// h·min(10, 0.9·err_norm^(−1/5)), at most h after a rejection, at most `max_step`.
///
/// The growth factor is a heuristic capped at 10: single precision is plenty for it and its pow
/// is about twice as cheap (err_norm^(−1/5) = mean_square^(−1/10); an underflow to 0 gives +inf,
/// capped like err_norm = 0). Accept/reject decisions stay in double precision. Where the result
/// is `max_step` whatever the factor's last bits (a full step with a small error: the usual
/// case when the step is capped at the hinge period), the pow is skipped: the factor is then at
/// least 0.9·0.3^(−1/10) = 1.015, and h·1.015 ≥ 0.99·max_step·1.015 > max_step.
#[inline(always)]
pub(crate) fn next_step(h: f64, mean_square: f64, rejected: bool, max_step: f64) -> f64 {
    if !rejected && mean_square < 0.3 && h >= 0.99 * max_step {
        return max_step;
    }
    step_by_factor(h, mean_square, rejected, max_step)
}

/// [`next_step`] without its shortcut: the growth factor always computed.
#[inline(always)]
fn step_by_factor(h: f64, mean_square: f64, rejected: bool, max_step: f64) -> f64 {
    let mut factor = if mean_square == 0.0 {
        MAX_FACTOR
    } else {
        let grow = (mean_square as f32).powf(0.5 * ERROR_EXPONENT as f32);
        MAX_FACTOR.min(SAFETY * f64::from(grow))
    };
    if rejected {
        factor = factor.min(1.0);
    }
    (h * factor).min(max_step)
}

/// Hairer's continuous extension of one step: the coefficients r1..r5 of the interpolant in
/// [`DenseStep`] from y0, diff = y1 − y0 and the slopes (k1, k3, k4, k5, k6, k7).
pub(super) fn dense_coefficients<D: Dim>(
    h: f64,
    y0: &State<D>,
    diff: State<D>,
    k: &[State<D>; 6],
) -> [State<D>; 5]
where
    DefaultAllocator: Allocator<D>,
{
    let [k1, k3, k4, k5, k6, k7] = k;
    let bspl = k1 * h - &diff;
    let r4 = &diff - k7 * h - &bspl;
    let r5 = (k1 * DENSE[0]
        + k3 * DENSE[2]
        + k4 * DENSE[3]
        + k5 * DENSE[4]
        + k6 * DENSE[5]
        + k7 * DENSE[6])
        * h;
    [y0.clone(), diff, bspl, r4, r5]
}

/// The step after a rejected step of size h whose error norm is `err_norm`:
/// h·max(0.2, 0.9·err_norm^exponent), 0.2 h for a non-finite error.
#[inline]
pub(crate) fn shrunk_step(h: f64, err_norm: f64, exponent: f64) -> f64 {
    let shrink = if err_norm.is_finite() {
        MIN_FACTOR.max(SAFETY * err_norm.powf(exponent))
    } else {
        MIN_FACTOR
    };
    h * shrink
}

/// The error of an integration whose step, shrunk to `h_abs` at t (the state `y`), fell below
/// the smallest resolvable one.
pub(crate) fn step_too_small(t: f64, h_abs: f64, y: &[f64]) -> Error {
    Error::Integration {
        t,
        reason: format!(
            "step size {h_abs:e} s fell below the smallest resolvable step \
             (state {y:?}); the solution is not finite or the problem is too stiff"
        ),
    }
}

/// The next representable f64 above x (x finite).
pub(crate) fn next_up(x: f64) -> f64 {
    if x == 0.0 {
        return f64::from_bits(1);
    }
    let bits = x.to_bits();
    if x > 0.0 {
        f64::from_bits(bits + 1)
    } else {
        f64::from_bits(bits - 1)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn skipping_the_pow_changes_no_step() {
        let mut skipped = 0;
        for max_step in [0.2017, 1.0, 3.7e5] {
            for scale in [0.5, 0.98, 0.99, 0.990001, 1.0, 1.0 + 1e-15, 1.3] {
                let h = scale * max_step;
                for k in 0..=4000 {
                    // 0 and mean squares from 1e-40 to just below 1, densest near 0.3.
                    let ms = if k == 0 {
                        0.0
                    } else {
                        let x = k as f64 / 4000.0;
                        (0.3f64).powf(1.0 + 80.0 * (0.5 - x).powi(3)).min(0.999_999)
                    };
                    for rejected in [false, true] {
                        let got = next_step(h, ms, rejected, max_step);
                        // The growth factor computed every time, as the controller did
                        // before the shortcut.
                        let full = step_by_factor(h, ms, rejected, max_step);
                        assert_eq!(got, full, "{h} {ms} {rejected}");
                        skipped += usize::from(!rejected && ms < 0.3 && h >= 0.99 * max_step);
                    }
                }
            }
        }
        assert!(skipped > 10_000);
    }
}
