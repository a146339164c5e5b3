//! The matrix exponential of small fixed-size matrices and the φ-functions of exponential
//! integrators, φ_k(z) = Σ_j z^j / (j + k)!, applied to vectors.
//!
//! exp(A) by scaling and squaring: A / 2^s has 1-norm at most 1/2, where the Taylor polynomial
//! of degree 16 is exact to about 1e-18 relative; it is evaluated in powers of B³ (six products
//! instead of sixteen), then squared s times.
//!
//! φ_k(A) for k ≤ 3 follow by the same scaling and squaring, as matrices ([`phi_matrices`]).

use nalgebra::SMatrix;

const TAYLOR_DEGREE: usize = 16;

/// exp(a).
pub fn expm<const M: usize>(a: &SMatrix<f64, M, M>) -> SMatrix<f64, M, M> {
    let squarings = squarings_for(a, 0.5);
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

/// The matrices φ_k(a), k = 0..=3 (φ0 = exp), by scaling and squaring (Skaflestad & Wright
/// 2009): with B = a / 2^s of 1-norm at most 1, φ3(B) by its Taylor polynomial of degree
/// [`PHI_DEGREE`] (truncation below 1e-18 relative), evaluated in powers of B⁴ (seven products
/// instead of sixteen); the lower ones by φ_{k−1}(B) = I/(k−1)! + B φ_k(B), then s doublings
/// φ_k(2z) = 2^{−k} (φ0(z) φ_k(z) + Σ_{j=1..k} φ_j(z) / (k − j)!).
///
/// One such evaluation serves every φ-function product of a step, at the cost of matrices of
/// the state's size (the augmented-matrix form needs one exponential of a larger matrix for
/// each combination of vectors).
pub fn phi_matrices<const M: usize>(a: &SMatrix<f64, M, M>) -> [SMatrix<f64, M, M>; 4] {
    doubled_phi(a).0
}

/// φ_k(a) and φ_k(a/2), k = 0..=3: the second is the scaling and squaring's last step but one,
/// so that a step's midpoint costs no second evaluation (one only where a needs no squaring).
pub fn phi_matrices_and_half<const M: usize>(
    a: &SMatrix<f64, M, M>,
) -> [[SMatrix<f64, M, M>; 4]; 2] {
    match doubled_phi(a) {
        (full, Some(half)) => [full, half],
        (full, None) => [full, phi_matrices(&(a * 0.5))],
    }
}

/// φ_k(a) by scaling and squaring, and the φ_k(a/2) it went through (None without squarings).
#[allow(clippy::type_complexity)]
fn doubled_phi<const M: usize>(
    a: &SMatrix<f64, M, M>,
) -> ([SMatrix<f64, M, M>; 4], Option<[SMatrix<f64, M, M>; 4]>) {
    let squarings = squarings_for(a, 1.0);
    let b = a * 0.5f64.powi(squarings);
    let id = SMatrix::<f64, M, M>::identity();
    // φ3(B) = Σ_j c_j B^j, c_j = 1 / (j + 3)!, as Σ_g (c_4g I + c_4g+1 B + c_4g+2 B² + c_4g+3 B³)
    // (B⁴)^g, by Horner in B⁴ from the top group.
    let coef = |j: usize| {
        if j > PHI_DEGREE {
            0.0
        } else {
            1.0 / (1..=j + 3).map(|v| v as f64).product::<f64>()
        }
    };
    let b2 = b * b;
    let b3 = b2 * b;
    let b4 = b2 * b2;
    let group = |g: usize| {
        id * coef(4 * g) + b * coef(4 * g + 1) + b2 * coef(4 * g + 2) + b3 * coef(4 * g + 3)
    };
    let top = PHI_DEGREE / 4;
    let mut p3 = group(top);
    for g in (0..top).rev() {
        p3 = p3 * b4 + group(g);
    }
    let p2 = id * 0.5 + b * p3;
    let p1 = id + b * p2;
    let p0 = id + b * p1;
    let mut phi = [p0, p1, p2, p3];
    let mut half = None;
    for _ in 0..squarings {
        half = Some(phi);
        let [p0, p1, p2, p3] = phi;
        phi = [
            p0 * p0,
            (p0 * p1 + p1) * 0.5,
            (p0 * p2 + p1 + p2) * 0.25,
            (p0 * p3 + p1 * 0.5 + p2 + p3) * 0.125,
        ];
    }
    (phi, half)
}

/// Degree of the Taylor polynomial of φ3 in [`phi_matrices`]: 1/(16 + 4)! is 4e-19.
const PHI_DEGREE: usize = 16;

/// The number of halvings that bring a's 1-norm to at most `limit`.
fn squarings_for<const M: usize>(a: &SMatrix<f64, M, M>, limit: f64) -> i32 {
    let norm = (0..M)
        .map(|j| a.column(j).iter().map(|v| v.abs()).sum::<f64>())
        .fold(0.0, f64::max);
    if norm > limit {
        (norm / limit).log2().ceil() as i32
    } else {
        0
    }
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
        let phi = phi_matrices(&a);
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
            let want = if z.abs() < 1.0 {
                [series(0), series(1), series(2), series(3)]
            } else {
                let p1 = z.exp_m1() / z;
                let p2 = (p1 - 1.0) / z;
                [z.exp(), p1, p2, (p2 - 0.5) / z]
            };
            for k in 0..4 {
                let got = phi[k][(i, i)];
                assert!(
                    (got - want[k]).abs() < 1e-13 * want[k].abs(),
                    "φ{k} of {z}: {got}"
                );
                let off = (0..4).filter(|&j| j != i).all(|j| phi[k][(i, j)] == 0.0);
                assert!(off, "φ{k} row {i}");
            }
        }
    }

    #[test]
    fn the_half_step_matrices_are_those_of_half_the_matrix() {
        let j = Matrix4::new(
            -0.025, 0.01, -0.4, 0.0, 0.01, -0.012, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 4.9e-3, -4.9e-3,
            -0.62, -3e-4,
        );
        for h in [0.3, 7.0, 150.0] {
            let [full, half] = phi_matrices_and_half(&(j * h));
            let direct = phi_matrices(&(j * (0.5 * h)));
            for k in 0..4 {
                assert_eq!(full[k], phi_matrices(&(j * h))[k], "h {h} k {k}");
                let size = direct[k].amax().max(1.0);
                assert!((half[k] - direct[k]).amax() < 1e-12 * size, "h {h} k {k}");
            }
        }
    }

    #[test]
    fn phi_functions_of_a_long_oscillator_step_satisfy_their_recurrence() {
        // A hinge-like oscillator coupled to two thermal layers, over a step of many periods:
        // A φ_{k+1}(A) = φ_k(A) − I/k!, with φ0 against the independent exponential.
        let j = Matrix4::new(
            -0.025, 0.01, -0.4, 0.0, 0.01, -0.012, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 4.9e-3, -4.9e-3,
            -0.62, -3e-4,
        );
        for h in [0.3, 7.0, 150.0] {
            let a = j * h;
            let phi = phi_matrices(&a);
            let e = expm(&a);
            let size = e.amax().max(1.0);
            assert!((phi[0] - e).amax() < 1e-12 * size, "h {h}");
            let id = Matrix4::<f64>::identity();
            for (k, fact) in [(0, 1.0), (1, 1.0), (2, 2.0)] {
                let lhs = a * phi[k + 1];
                let rhs = phi[k] - id / fact;
                assert!((lhs - rhs).amax() < 1e-11 * size, "h {h} k {k}");
            }
        }
    }
}
