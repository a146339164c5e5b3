//! Checks shared by the tests of several layers.

use nalgebra::{Matrix4, Vector4};

/// Asserts that `jac` is the Jacobian of `f` at `y`: column j against central differences with
/// the step 1e-6 max(|y_j|, 1e-3), each entry to 1e-6 of the column's largest (at least `floor`).
/// `case` names the case in a failure.
pub(crate) fn assert_jacobian(
    jac: &Matrix4<f64>,
    f: impl Fn(&Vector4<f64>) -> Vector4<f64>,
    y: &Vector4<f64>,
    floor: f64,
    case: &str,
) {
    for j in 0..4 {
        let h = 1e-6 * y[j].abs().max(1e-3);
        let (mut yp, mut ym) = (*y, *y);
        yp[j] += h;
        ym[j] -= h;
        let col = (f(&yp) - f(&ym)) / (2.0 * h);
        let tol = 1e-6 * jac.column(j).amax().max(floor);
        for i in 0..4 {
            assert!(
                (col[i] - jac[(i, j)]).abs() < tol,
                "{case} ({i},{j}): {} vs {}",
                col[i],
                jac[(i, j)]
            );
        }
    }
}

/// Column `j` of the Jacobian of `f` (which writes f(y) into its second argument) at `y`, by
/// central differences with step `h`.
pub(crate) fn central_difference(
    f: impl Fn(&[f64], &mut [f64]),
    y: &[f64],
    j: usize,
    h: f64,
) -> Vec<f64> {
    let n = y.len();
    let (mut yp, mut ym) = (y.to_vec(), y.to_vec());
    yp[j] += h;
    ym[j] -= h;
    let (mut fp, mut fm) = (vec![0.0; n], vec![0.0; n]);
    f(&yp, &mut fp);
    f(&ym, &mut fm);
    (0..n).map(|i| (fp[i] - fm[i]) / (2.0 * h)).collect()
}

/// Uniform draws in [0, 1) from `seed`, the same on every machine: a linear congruential
/// generator (Knuth's MMIX constants), its top 53 bits.
pub(crate) fn uniform_draws(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (seed >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// A function with one sign change, drawn for the root finders' tests: (t − t0)^p − (root −
/// t0)^p in units of the span (p in [1, 3)), the root anywhere but the span's ends, its positive
/// side five times steeper in three draws of ten (a kink at the root), scaled by 1e-6 to 1.
pub(crate) struct DrawnCrossing {
    pub t0: f64,
    pub span: f64,
    pub root: f64,
    power: f64,
    kink: bool,
    scale: f64,
}

impl DrawnCrossing {
    /// One from `draw`: t0 up to 3e8 s, the span in [shortest, shortest + spread).
    pub(crate) fn draw(draw: &mut impl FnMut() -> f64, shortest: f64, spread: f64) -> Self {
        let t0 = 3e8 * draw() * draw();
        let span = shortest + spread * draw();
        DrawnCrossing {
            t0,
            span,
            root: t0 + span * (0.01 + 0.98 * draw()),
            power: 1.0 + 2.0 * draw(),
            kink: draw() < 0.3,
            scale: 10f64.powf(-6.0 + 6.0 * draw()),
        }
    }

    /// Its value at t: negative before the root, positive after.
    pub(crate) fn at(&self, t: f64) -> f64 {
        let d = (t - self.t0) / self.span;
        let r = (self.root - self.t0) / self.span;
        let g = d.powf(self.power) - r.powf(self.power);
        self.scale * if self.kink && g > 0.0 { 5.0 * g } else { g }
    }
}
