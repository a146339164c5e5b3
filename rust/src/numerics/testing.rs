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
