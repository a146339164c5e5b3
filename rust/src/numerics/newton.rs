//! Newton's method for steady states, whose first unknowns are temperatures (kept positive).

use crate::error::{Error, Result};
use nalgebra::{DMatrix, DVector};

/// Newton's method from `x` for a steady state whose first `n_temps` unknowns are temperatures:
/// each step solves J dx = −f, with (f, J) at x from `system`, shortened by halves where it
/// would take a temperature to zero or below (wild parameter sets); it stops when
/// `settled(x, dx)` after a step, and gives up after 100 steps. `what` names the state in errors.
pub fn newton(
    what: &str,
    mut x: DVector<f64>,
    n_temps: usize,
    mut system: impl FnMut(&DVector<f64>) -> (DVector<f64>, DMatrix<f64>),
    settled: impl Fn(&DVector<f64>, &DVector<f64>) -> bool,
) -> Result<DVector<f64>> {
    for _ in 0..100 {
        let (f, jac) = system(&x);
        let dx = jac.lu().solve(&(-f)).ok_or_else(|| Error::NoConvergence {
            what: what.into(),
            reason: "singular Jacobian".into(),
        })?;
        let mut lambda = 1.0;
        while (0..n_temps).any(|i| x[i] + lambda * dx[i] <= 0.0) {
            lambda *= 0.5;
        }
        x += &dx * lambda;
        if settled(&x, &dx) {
            return Ok(x);
        }
    }
    Err(Error::NoConvergence {
        what: what.into(),
        reason: "Newton did not converge in 100 iterations".into(),
    })
}
