//! Classical fourth-order Runge–Kutta with a fixed step.

use super::{DenseStep, Integration, Observer, OdeSystem};
use crate::error::Result;
use nalgebra::allocator::Allocator;
use nalgebra::{DefaultAllocator, Dim};
use std::ops::ControlFlow;

/// Integrates the segment [a, b] in n equal steps, n = ceil((b − a)/dt), so the last step lands
/// exactly on b. Dense output is the cubic Hermite interpolant (slopes at both step ends).
#[inline(always)]
pub(super) fn segment<D: Dim, S: OdeSystem<D>, O: Observer<D>>(
    system: &S,
    (a, b): (f64, f64),
    dt: f64,
    run: &mut Integration<'_, D, O>,
) -> Result<ControlFlow<()>>
where
    DefaultAllocator: Allocator<D>,
{
    // The small allowance keeps a span that is a whole number of dt from gaining a sliver step.
    let n = (((b - a) / dt) * (1.0 - 1e-12)).ceil().max(1.0) as u64;
    let h = (b - a) / n as f64;
    let mut k1 = system.rhs(a, &run.y);
    run.stats.n_rhs += 1;
    for i in 0..n {
        let t = a + i as f64 * h;
        let t_new = if i + 1 == n {
            b
        } else {
            a + (i + 1) as f64 * h
        };
        let y0 = run.y.clone();
        let k2 = system.rhs(t + 0.5 * h, &(&y0 + &k1 * (0.5 * h)));
        let k3 = system.rhs(t + 0.5 * h, &(&y0 + &k2 * (0.5 * h)));
        let k4 = system.rhs(t_new, &(&y0 + &k3 * h));
        let y_new = &y0 + (&k1 + (k2 + k3) * 2.0 + k4) * (h / 6.0);
        // Slope at the step end: the next step's first stage, so it costs nothing extra.
        let f_new = system.rhs(t_new, &y_new);
        run.stats.n_rhs += 4;
        run.stats.n_steps += 1;
        if let Some(i) = y_new.iter().position(|v| !v.is_finite()) {
            return Err(crate::error::Error::Integration {
                t: t_new,
                reason: format!("state component {i} is not finite; reduce dt"),
            });
        }
        run.y = y_new.clone();
        run.stats.t_end = t_new;
        let dense = DenseStep::hermite(t, t_new, y0, y_new, k1, f_new.clone());
        k1 = f_new;
        if run.observer.on_step(&dense).is_break() {
            return Ok(ControlFlow::Break(()));
        }
    }
    Ok(ControlFlow::Continue(()))
}
