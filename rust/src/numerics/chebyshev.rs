//! Piecewise Chebyshev interpolation of a function on [a, b] that is smooth inside and behaves
//! at its ends like odd powers of √(t − a) and √(b − t) (the visible fraction of a disc at its
//! contacts with another, (t − a)^{3/2}). In the variable v of t = a + (b − a)(1 − cos πv)/2
//! such terms are analytic, t − a growing like v²: the interpolant is a polynomial in v on each
//! of [`PIECES`] equal parts of v ∈ [0, 1].
//!
//! Each part is checked after its fit at the points halfway (in angle) between its nodes, and
//! left to the function itself where it strays from it by more than the tolerance asked, plus
//! what the function itself is known to at times this large (its slope times a few roundings
//! of t: [`TIME_ROUNDINGS`]): [`EndpointInterpolant::at`] then answers None.

use std::f64::consts::{FRAC_1_PI, PI};

/// Equal parts of v ∈ [0, 1], each with its own polynomial.
pub const PIECES: usize = 8;
/// Degree of each part's polynomial.
pub const DEGREE: usize = 10;

/// Roundings of t (ε |t| each) by which a function of time evaluated in floating point is
/// uncertain: its arguments (a phase rate × t + an offset, and what follows) each round once.
pub const TIME_ROUNDINGS: f64 = 16.0;

/// A function on [a, b] as [`PIECES`] Chebyshev series of degree [`DEGREE`] in v.
#[derive(Debug, Clone)]
pub struct EndpointInterpolant {
    a: f64,
    /// 2 / (b − a).
    scale: f64,
    coefficients: [[f64; DEGREE + 1]; PIECES],
    /// Parts whose check failed: the caller evaluates the function there.
    refused: [bool; PIECES],
}

/// t of v on [a, b].
fn time_of(a: f64, b: f64, v: f64) -> f64 {
    a + (b - a) * 0.5 * (1.0 - (PI * v).cos())
}

/// v ∈ [0, 1] of part `k` at x ∈ [−1, 1].
fn v_of(k: usize, x: f64) -> f64 {
    (k as f64 + 0.5 * (x + 1.0)) / PIECES as f64
}

/// The Chebyshev series Σ c_m T_m(x) by Clenshaw's recurrence.
#[inline(always)]
fn clenshaw(c: &[f64; DEGREE + 1], x: f64) -> f64 {
    let (mut b1, mut b2) = (0.0, 0.0);
    for &cm in c[1..].iter().rev() {
        let b0 = 2.0 * x * b1 - b2 + cm;
        b2 = b1;
        b1 = b0;
    }
    x * b1 - b2 + c[0]
}

impl EndpointInterpolant {
    /// Fits `f` on [a, b] (a < b) at the Chebyshev–Lobatto points of each part, then checks
    /// each part at the [`DEGREE`] points between them: a part where |interpolant − f| exceeds
    /// `tol` + [`TIME_ROUNDINGS`] ε max(|a|, |b|) × (its largest slope between nodes)
    /// anywhere, or where f is not finite, is refused.
    pub fn fit(f: impl Fn(f64) -> f64, a: f64, b: f64, tol: f64) -> Self {
        let n = DEGREE;
        let mut out = EndpointInterpolant {
            a,
            scale: 2.0 / (b - a),
            coefficients: [[0.0; DEGREE + 1]; PIECES],
            refused: [false; PIECES],
        };
        let rounding = TIME_ROUNDINGS * f64::EPSILON * a.abs().max(b.abs());
        // cos(iπ/n) for i < 2n: the nodes (i ≤ n) and the transform's cos(jmπ/n), jm mod 2n.
        let turn: [f64; 2 * DEGREE] = std::array::from_fn(|i| (i as f64 * PI / n as f64).cos());
        for k in 0..PIECES {
            let times: [f64; DEGREE + 1] = std::array::from_fn(|j| time_of(a, b, v_of(k, turn[j])));
            let values = times.map(&f);
            let slope = (0..n)
                .map(|j| ((values[j + 1] - values[j]) / (times[j + 1] - times[j])).abs())
                .fold(0.0, f64::max);
            let tol = tol + rounding * slope;
            let c = &mut out.coefficients[k];
            for (m, cm) in c.iter_mut().enumerate() {
                let sum: f64 = values
                    .iter()
                    .enumerate()
                    .map(|(j, fj)| {
                        let w = if j == 0 || j == n { 0.5 } else { 1.0 };
                        w * fj * turn[(j * m) % (2 * n)]
                    })
                    .sum();
                *cm = 2.0 / n as f64 * sum;
            }
            c[0] *= 0.5;
            c[n] *= 0.5;
            out.refused[k] = (0..n).any(|j| {
                let x = ((j as f64 + 0.5) * PI / n as f64).cos();
                let exact = f(time_of(a, b, v_of(k, x)));
                // Not finite when f or the fit is not finite there: refused too.
                let error = (clenshaw(c, x) - exact).abs();
                !error.is_finite() || error > tol
            });
        }
        out
    }

    /// The interpolant at t ∈ [a, b], None in a refused part.
    #[inline(always)]
    pub fn at(&self, t: f64) -> Option<f64> {
        let cos = (1.0 - (t - self.a) * self.scale).clamp(-1.0, 1.0);
        let v = cos.acos() * FRAC_1_PI * PIECES as f64;
        let k = (v as usize).min(PIECES - 1);
        if self.refused[k] {
            return None;
        }
        Some(clenshaw(&self.coefficients[k], 2.0 * (v - k as f64) - 1.0))
    }

    /// How many parts were refused.
    pub fn refused(&self) -> usize {
        self.refused.iter().filter(|&&r| r).count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_contact_like_function_is_interpolated_to_its_rounding() {
        // 1 − (t − a)^{3/2} at one end, (b − t)^{3/2} weight at the other, a smooth factor.
        let (a, b) = (100.0, 227.0);
        let f = |t: f64| {
            let (u, w) = ((t - a) / (b - a), (b - t) / (b - a));
            (1.0 - u.max(0.0).powf(1.5)) * (1.0 + 0.3 * (t / 50.0).sin()) + w.max(0.0).powf(1.5)
        };
        let p = EndpointInterpolant::fit(f, a, b, 1e-12);
        assert_eq!(p.refused(), 0);
        for i in 0..=10_000 {
            let t = a + (b - a) * i as f64 / 10_000.0;
            let got = p.at(t).unwrap();
            assert!((got - f(t)).abs() < 1e-12, "t = {t}: {got} vs {}", f(t));
        }
    }

    #[test]
    fn a_part_that_strays_is_refused() {
        // A kink inside the span: the polynomial of its part cannot follow it.
        let (a, b) = (0.0, 1.0);
        let f = |t: f64| (t - 0.3).abs();
        let p = EndpointInterpolant::fit(f, a, b, 1e-9);
        assert!(p.refused() >= 1);
        assert_eq!(p.at(0.3), None);
        // The parts away from the kink are smooth there and kept.
        assert!((p.at(0.01).unwrap() - f(0.01)).abs() < 1e-9);
    }
}
