//! The matrix exponential of small fixed-size matrices and the φ-functions of exponential
//! integrators, φ_k(z) = Σ_j z^j / (j + k)!, applied to vectors.
//!
//! exp(A) by scaling and squaring: A / 2^s has 1-norm at most 1/2, where the Taylor polynomial
//! of degree 16 is exact to about 1e-18 relative; it is evaluated in powers of B³ (six products
//! instead of sixteen), then squared s times.
//!
//! φ_k(A) w follows from one exponential of an augmented matrix (Al-Mohy & Higham 2011, Thm 2.1):
//! for Ã = [[A, W], [0, K]] with W = [w_p, …, w_1] and K the p×p upward shift, the last column of
//! the top-right block of exp(Ã) is Σ_k φ_k(A) w_k.

use nalgebra::{SMatrix, SVector};

const TAYLOR_DEGREE: usize = 16;

/// exp(a).
pub fn expm<const M: usize>(a: &SMatrix<f64, M, M>) -> SMatrix<f64, M, M> {
    let norm = (0..M)
        .map(|j| a.column(j).iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max);
    let mut squarings = 0i32;
    if norm > 0.5 {
        squarings = (norm / 0.5).log2().ceil() as i32;
    }
    let b = a * 0.5f64.powi(squarings);
    // 1/j! for j = 0..=TAYLOR_DEGREE.
    let mut inv_fact = [1.0; TAYLOR_DEGREE + 1];
    for j in 1..=TAYLOR_DEGREE {
        inv_fact[j] = inv_fact[j - 1] / j as f64;
    }
    let id = SMatrix::<f64, M, M>::identity();
    let b2 = b * b;
    let b3 = b2 * b;
    // p(B) = Σ_g (c_{3g} I + c_{3g+1} B + c_{3g+2} B²) (B³)^g, Horner in B³ from the top group.
    let group = |g: usize| -> SMatrix<f64, M, M> {
        let c = |j: usize| if j <= TAYLOR_DEGREE { inv_fact[j] } else { 0.0 };
        id * c(3 * g) + b * c(3 * g + 1) + b2 * c(3 * g + 2)
    };
    let top = TAYLOR_DEGREE / 3;
    let mut e = group(top);
    for g in (0..top).rev() {
        e = e * b3 + group(g);
    }
    for _ in 0..squarings {
        e = e * e;
    }
    e
}

/// φ1(a) w1 + φ2(a) w2 for a 4×4 `a` (one exponential of a 6×6 matrix).
pub fn phi12(
    a: &SMatrix<f64, 4, 4>,
    w1: &SVector<f64, 4>,
    w2: &SVector<f64, 4>,
) -> SVector<f64, 4> {
    // The vectors are scaled to the size of `a` so that they do not set the number of squarings.
    let gamma = balance(a, &[w1, w2]);
    let mut m = SMatrix::<f64, 6, 6>::zeros();
    m.fixed_view_mut::<4, 4>(0, 0).copy_from(a);
    m.fixed_view_mut::<4, 1>(0, 4).copy_from(&(w2 * gamma));
    m.fixed_view_mut::<4, 1>(0, 5).copy_from(&(w1 * gamma));
    m[(4, 5)] = 1.0;
    let e = expm(&m);
    e.fixed_view::<4, 1>(0, 5).into_owned() / gamma
}

/// φ3(a) w for a 4×4 `a` (one exponential of a 7×7 matrix).
pub fn phi3(a: &SMatrix<f64, 4, 4>, w: &SVector<f64, 4>) -> SVector<f64, 4> {
    let gamma = balance(a, &[w]);
    let mut m = SMatrix::<f64, 7, 7>::zeros();
    m.fixed_view_mut::<4, 4>(0, 0).copy_from(a);
    m.fixed_view_mut::<4, 1>(0, 4).copy_from(&(w * gamma));
    m[(4, 5)] = 1.0;
    m[(5, 6)] = 1.0;
    let e = expm(&m);
    e.fixed_view::<4, 1>(0, 6).into_owned() / gamma
}

/// A power of two that brings the vectors' 1-norms to about the 1-norm of `a` (at least 1).
fn balance(a: &SMatrix<f64, 4, 4>, ws: &[&SVector<f64, 4>]) -> f64 {
    let a_norm = (0..4)
        .map(|j| a.column(j).iter().map(|v| v.abs()).sum::<f64>())
        .fold(1.0, f64::max);
    let w_norm = ws
        .iter()
        .map(|w| w.iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max);
    if w_norm == 0.0 || !w_norm.is_finite() {
        return 1.0;
    }
    2f64.powi((a_norm / w_norm).log2().round() as i32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{Matrix2, Matrix4, Vector4};

    #[test]
    fn exponential_of_a_damped_oscillator_is_its_closed_form() {
        // x'' + 2ζω x' + ω² x = 0 over t: the exact flow map, many periods long.
        let (w, z, t) = (0.7866_f64, 2e-4_f64, 1234.5_f64);
        let a = Matrix2::new(0.0, 1.0, -w * w, -2.0 * z * w) * t;
        let e = expm(&a);
        let wd = w * (1.0 - z * z).sqrt();
        let decay = (-z * w * t).exp();
        let (s, c) = (wd * t).sin_cos();
        let want = Matrix2::new(
            decay * (c + z * w / wd * s),
            decay * s / wd,
            -decay * w * w / wd * s,
            decay * (c - z * w / wd * s),
        );
        assert!((e - want).amax() < 1e-11, "{e} vs {want}");
    }

    #[test]
    fn phi_functions_of_a_diagonal_matrix_are_the_scalar_ones() {
        let lam = [-0.02, -3e-3, 1e-9, -40.0];
        let a = Matrix4::from_diagonal(&Vector4::from(lam));
        let w1 = Vector4::new(1.0, -2.0, 300.0, 1e-3);
        let w2 = Vector4::new(-5.0, 0.5, 2.0, 7.0);
        let got = phi12(&a, &w1, &w2);
        let got3 = phi3(&a, &w2);
        for i in 0..4 {
            let z: f64 = lam[i];
            // The series Σ z^j / (j + k)! for |z| < 1, the recurrences φ_{k+1} = (φ_k − 1/k!)/z
            // (well conditioned there) otherwise.
            let series = |k: usize| {
                let mut fact = (1..=k).map(|v| v as f64).product::<f64>();
                let (mut term, mut sum) = (1.0 / fact, 0.0);
                for j in 0..30 {
                    sum += term;
                    fact = (j + k + 1) as f64;
                    term *= z / fact;
                }
                sum
            };
            let (p1, p2, p3) = if z.abs() < 1.0 {
                (series(1), series(2), series(3))
            } else {
                let p1 = z.exp_m1() / z;
                let p2 = (p1 - 1.0) / z;
                (p1, p2, (p2 - 0.5) / z)
            };
            let want = p1 * w1[i] + p2 * w2[i];
            assert!((got[i] - want).abs() < 1e-12 * want.abs().max(1.0), "{i}");
            assert!((got3[i] - p3 * w2[i]).abs() < 1e-12 * w2[i].abs(), "{i}");
        }
    }
}
