//! Piecewise Chebyshev interpolation of a function of time on [a, b] that is smooth inside and
//! behaves at its ends like odd powers of √(t − a) and √(b − t) (the visible fraction of a disc
//! at its contacts with another, (t − a)^{3/2}; a view factor where a face's plane leaves the
//! Earth's limb). In the variable v of t = a + (b − a)(1 − cos πv)/2 such terms are analytic,
//! t − a growing like v²: the interpolant is a polynomial in v on each of a number of equal
//! parts of v ∈ [0, 1]. Fitted once and read many times (a segment's loads, read at every stage
//! of its integration).
//!
//! Each part is checked after its fit at the points halfway (in angle) between its nodes, and
//! left to the function itself where it strays from it by more than the tolerance asked, plus
//! what the function itself is known to at times this large (its slope times a few roundings
//! of t: [`TIME_ROUNDINGS`]): [`Table::at`] then answers None.

use std::f64::consts::{FRAC_1_PI, PI};

/// Equal parts of v ∈ [0, 1] of an [`EndpointInterpolant`], each with its own polynomial.
pub const PIECES: usize = 8;
/// Degree of each part's polynomial.
pub const DEGREE: usize = 10;

/// Roundings of t (ε |t| each) by which a function of time evaluated in floating point is
/// uncertain: its arguments (a phase rate × t + an offset, and what follows) each round once.
pub const TIME_ROUNDINGS: f64 = 16.0;

/// N functions on [a, b] as Chebyshev series of degree [`DEGREE`] in v, one per part.
#[derive(Debug, Clone)]
pub struct Table<const N: usize> {
    a: f64,
    /// 2 / (b − a).
    scale: f64,
    parts: usize,
    coefficients: Vec<[[f64; N]; DEGREE + 1]>,
    /// Parts whose check failed: the caller evaluates the functions there.
    refused: Vec<bool>,
}

/// The Chebyshev series Σ c_m T_m(x) of each component by Clenshaw's recurrence, the
/// components' recurrences side by side (each a chain of dependent operations: interleaved,
/// they overlap).
#[inline(always)]
fn clenshaw<const N: usize>(c: &[[f64; N]; DEGREE + 1], x: f64) -> [f64; N] {
    let two_x = 2.0 * x;
    let (mut b1, mut b2) = ([0.0; N], [0.0; N]);
    for cm in c[1..].iter().rev() {
        for i in 0..N {
            let b0 = two_x * b1[i] - b2[i] + cm[i];
            b2[i] = b1[i];
            b1[i] = b0;
        }
    }
    std::array::from_fn(|i| x * b1[i] - b2[i] + c[0][i])
}

impl<const N: usize> Table<N> {
    /// Fits `f` on [a, b] (a < b) in `parts` parts of v at the Chebyshev–Lobatto points of
    /// each, then checks each part at the [`DEGREE`] points between them: a part where a
    /// component's |interpolant − f| exceeds its `tol` + [`TIME_ROUNDINGS`] ε max(|a|, |b|) ×
    /// (its largest slope between nodes) anywhere, or where f is not finite, is refused.
    pub fn fit(f: impl Fn(f64) -> [f64; N], a: f64, b: f64, parts: usize, tol: [f64; N]) -> Self {
        let n = DEGREE;
        let parts = parts.max(1);
        let mut out = Table {
            a,
            scale: 2.0 / (b - a),
            parts,
            coefficients: vec![[[0.0; N]; DEGREE + 1]; parts],
            refused: vec![false; parts],
        };
        let rounding = TIME_ROUNDINGS * f64::EPSILON * a.abs().max(b.abs());
        // cos(iπ/n) for i < 2n: the nodes (i ≤ n) and the transform's cos(jmπ/n), jm mod 2n.
        let turn: [f64; 2 * DEGREE] = std::array::from_fn(|i| (i as f64 * PI / n as f64).cos());
        let time_of = |k: usize, x: f64| {
            let v = (k as f64 + 0.5 * (x + 1.0)) / parts as f64;
            a + (b - a) * 0.5 * (1.0 - (PI * v).cos())
        };
        for k in 0..parts {
            let times: [f64; DEGREE + 1] = std::array::from_fn(|j| time_of(k, turn[j]));
            let values = times.map(&f);
            let tol: [f64; N] = std::array::from_fn(|i| {
                let slope = (0..n)
                    .map(|j| ((values[j + 1][i] - values[j][i]) / (times[j + 1] - times[j])).abs())
                    .fold(0.0, f64::max);
                tol[i] + rounding * slope
            });
            let c = &mut out.coefficients[k];
            for (m, cm) in c.iter_mut().enumerate() {
                *cm = std::array::from_fn(|i| {
                    let sum: f64 = values
                        .iter()
                        .enumerate()
                        .map(|(j, fj)| {
                            let w = if j == 0 || j == n { 0.5 } else { 1.0 };
                            w * fj[i] * turn[(j * m) % (2 * n)]
                        })
                        .sum();
                    2.0 / n as f64 * sum
                });
            }
            for m in [0, n] {
                c[m] = c[m].map(|x| x * 0.5);
            }
            let c = &out.coefficients[k];
            let refused = (0..n).any(|j| {
                let x = ((j as f64 + 0.5) * PI / n as f64).cos();
                let exact = f(time_of(k, x));
                let fit = clenshaw(c, x);
                // Not finite when f or the fit is not finite there: refused too.
                (0..N).any(|i| {
                    let error = (fit[i] - exact[i]).abs();
                    !error.is_finite() || error > tol[i]
                })
            });
            out.refused[k] = refused;
        }
        out
    }

    /// The interpolant at t ∈ [a, b], None in a refused part.
    #[inline(always)]
    pub fn at(&self, t: f64) -> Option<[f64; N]> {
        let cos = (1.0 - (t - self.a) * self.scale).clamp(-1.0, 1.0);
        let v = cos.acos() * FRAC_1_PI * self.parts as f64;
        let k = (v as usize).min(self.parts - 1);
        if self.refused[k] {
            return None;
        }
        Some(clenshaw(&self.coefficients[k], 2.0 * (v - k as f64) - 1.0))
    }

    /// How many parts were refused.
    pub fn refused(&self) -> usize {
        self.refused.iter().filter(|&&r| r).count()
    }

    /// How many parts the table has.
    pub fn parts(&self) -> usize {
        self.parts
    }
}

/// A function on [a, b] as [`PIECES`] Chebyshev series of degree [`DEGREE`] in v: a [`Table`]
/// of one function.
#[derive(Debug, Clone)]
pub struct EndpointInterpolant(Table<1>);

impl EndpointInterpolant {
    /// Fits `f` on [a, b] (a < b), each part checked to `tol` ([`Table::fit`]).
    pub fn fit(f: impl Fn(f64) -> f64, a: f64, b: f64, tol: f64) -> Self {
        EndpointInterpolant(Table::fit(|t| [f(t)], a, b, PIECES, [tol]))
    }

    /// The interpolant at t ∈ [a, b], None in a refused part.
    #[inline(always)]
    pub fn at(&self, t: f64) -> Option<f64> {
        self.0.at(t).map(|[x]| x)
    }

    /// How many parts were refused.
    pub fn refused(&self) -> usize {
        self.0.refused()
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
