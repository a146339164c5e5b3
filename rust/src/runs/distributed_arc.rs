//! Exact propagation of the distributed panel's linearised system over a sunlit arc.
//!
//! About a sunlit equilibrium y_r (at a flux near the arc's), with the flux's offset from it and
//! its linear drift (the Sun's distance) as forcings, the deviation δ = y − y_r obeys
//! δ' = A δ + c + b τ, A the Jacobian at y_r. Its solution is the quasi-static drift p0 + p1 τ
//! (p1 = −A⁻¹ b, p0 = A⁻¹ (p1 − c)) plus the free response, split into two exact parts:
//!
//! - the structural pairs: the complex eigenpairs of A whose frequency is that of a kept elastic
//!   mode, 2 Re(v_k c_k e^{λ_k τ}) with c_k = w_k·δ_h(0) (right and left eigenvectors by inverse
//!   iteration, w_k·v_k = 1). They ring for hours (ζ of 1e-4) and are read in closed form.
//! - the rest, R(τ) = e^{Aτ} R(0) in the complementary invariant subspace: the thermal modes,
//!   which decay on the thermal time scales. It is propagated exactly on a grid of step h
//!   (one matrix exponential per arc) and read between the nodes by its cubic Hermite
//!   interpolant, whose error is bounded by h⁴/384 · max|s''''| (s'''' = w·A⁴R, known at the
//!   nodes).
//!
//! A scalar functional w·y of the arc ([`ArcSignal`]) is then the smooth part (drift and R, the
//! interpolant) plus the pairs. Its extremes over any span are found by branch and bound: each
//! cell of the grid has an upper bound (the smooth part's ends and slopes, the pairs'
//! envelopes); the cells whose bound exceeds the best value found by more than the tolerance
//! are sampled finely enough that no peak between samples is missed by more than it.

use crate::error::{Error, Result};
use nalgebra::{Complex, DMatrix, DVector};

pub(crate) type C64 = Complex<f64>;

/// Largest grid step of the thermal part, s.
const GRID_STEP: f64 = 30.0;

/// A structural eigenpair of the Jacobian: λ (Im λ > 0), right v and left w with w·v = 1.
#[derive(Debug, Clone)]
pub(crate) struct Pair {
    pub lambda: C64,
    pub right: DVector<C64>,
    pub left: DVector<C64>,
}

impl Pair {
    /// The pair's coordinate w·x of a real vector.
    pub fn coordinate(&self, x: &DVector<f64>) -> C64 {
        self.left.iter().zip(x.iter()).map(|(w, v)| w * *v).sum()
    }

    /// Its contribution 2 Re(v c e^{λτ}) to the state.
    pub fn part(&self, c: C64, tau: f64) -> DVector<f64> {
        let z = c * (self.lambda * tau).exp();
        self.right.map(|v| 2.0 * (v * z).re)
    }
}

/// The structural pairs of `a` (`count` of them, frequencies above `slowest` rad/s), found on
/// the matrix balanced by `scale`; None when there are not exactly `count` of them or their
/// eigenvectors are not found to rounding.
pub(crate) fn structural_pairs(
    a: &DMatrix<f64>,
    scale: &DVector<f64>,
    count: usize,
    slowest: f64,
) -> Option<Vec<Pair>> {
    let n = a.nrows();
    let ab = DMatrix::from_fn(n, n, |i, j| a[(i, j)] * scale[j] / scale[i]);
    let schur = nalgebra::linalg::Schur::try_new(ab.clone(), 1e-14, 10_000)?;
    let mut lambdas: Vec<C64> = schur
        .complex_eigenvalues()
        .iter()
        .copied()
        .filter(|l| l.im > slowest)
        .collect();
    if lambdas.len() != count {
        return None;
    }
    lambdas.sort_by(|x, y| x.im.total_cmp(&y.im));
    let abc = ab.map(|v| C64::new(v, 0.0));
    let abt = abc.transpose();
    let mut pairs = Vec::with_capacity(count);
    for lambda in lambdas {
        let right = inverse_iteration(&abc, lambda)?;
        let left = inverse_iteration(&abt, lambda)?;
        // Back to the state's units: v = D v_b, w = D⁻¹ w_b, then w·v = 1.
        let right = DVector::from_fn(n, |i, _| right[i] * scale[i]);
        let left = DVector::from_fn(n, |i, _| left[i] / scale[i]);
        let norm: C64 = left.iter().zip(right.iter()).map(|(w, v)| w * v).sum();
        let size = norm.norm();
        if size.is_nan() || size <= 1e-12 * left.norm() * right.norm() {
            return None;
        }
        pairs.push(Pair {
            lambda,
            right,
            left: left / norm,
        });
    }
    Some(pairs)
}

/// The eigenvector of `m` for the eigenvalue `lambda` by two solves with a slightly shifted
/// matrix, unit norm; None when its residual is not at rounding.
fn inverse_iteration(m: &DMatrix<C64>, lambda: C64) -> Option<DVector<C64>> {
    let n = m.nrows();
    let size = m.norm().max(lambda.norm());
    let shift = lambda + C64::new(1e-10 * size, 1e-10 * size);
    let mut shifted = m.clone();
    for i in 0..n {
        shifted[(i, i)] -= shift;
    }
    let lu = shifted.lu();
    let mut v = DVector::from_fn(n, |i, _| C64::new(1.0 + 0.37 * i as f64, 0.11 * i as f64));
    for _ in 0..3 {
        v = lu.solve(&v)?;
        let norm = v.norm();
        if !(norm.is_finite() && norm > 0.0) {
            return None;
        }
        v /= C64::new(norm, 0.0);
    }
    let mut residual = m * &v;
    residual -= &v * lambda;
    (residual.norm() <= 1e-8 * size).then_some(v)
}

/// φ1(z) = (e^z − 1)/z, by its series near 0.
fn phi1(z: C64) -> C64 {
    if z.norm() < 1e-4 {
        C64::new(1.0, 0.0) + z * 0.5 + z * z / 6.0
    } else {
        (z.exp() - 1.0) / z
    }
}

/// The exact solution of the linearised system over an arc of `length` s.
#[derive(Debug, Clone)]
pub(crate) struct LinearArc {
    pub length: f64,
    /// Grid step, s, and the thermal part R at the nodes j h (j = 0 ..= m).
    pub step: f64,
    nodes: Vec<DVector<f64>>,
    base: DVector<f64>,
    slope: DVector<f64>,
    pub pairs: Vec<Pair>,
    /// c_k of each pair.
    pub coeff: Vec<C64>,
    a: DMatrix<f64>,
}

impl LinearArc {
    /// The arc from y0 about `y_ref` with Jacobian `a`, its structural `pairs`, and the forcing
    /// c + b τ.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        a: &DMatrix<f64>,
        c: &DVector<f64>,
        b: &DVector<f64>,
        y_ref: &DVector<f64>,
        y0: &DVector<f64>,
        pairs: Vec<Pair>,
        length: f64,
    ) -> Result<LinearArc> {
        let lu = a.clone().lu();
        let singular = || Error::NoConvergence {
            what: "linear arc".into(),
            reason: "singular Jacobian".into(),
        };
        let p1 = -lu.solve(b).ok_or_else(singular)?;
        let p0 = lu.solve(&(&p1 - c)).ok_or_else(singular)?;
        let h0 = y0 - y_ref - &p0;
        let coeff: Vec<C64> = pairs.iter().map(|p| p.coordinate(&h0)).collect();
        let mut r0 = h0;
        for (p, c) in pairs.iter().zip(&coeff) {
            r0 -= p.part(*c, 0.0);
        }
        let m = (length / GRID_STEP).ceil().max(1.0) as usize;
        let step = length / m as f64;
        let e = (a * step).exp();
        let mut nodes = Vec::with_capacity(m + 1);
        nodes.push(r0);
        for j in 0..m {
            let next = &e * &nodes[j];
            nodes.push(next);
        }
        Ok(LinearArc {
            length,
            step,
            nodes,
            base: y_ref + p0,
            slope: p1,
            pairs,
            coeff,
            a: a.clone(),
        })
    }

    /// Number of grid cells.
    pub fn cells(&self) -> usize {
        self.nodes.len() - 1
    }

    /// The state at node j (exact).
    pub fn state_at_node(&self, j: usize) -> DVector<f64> {
        let tau = j as f64 * self.step;
        let mut y = &self.base + &self.slope * tau + &self.nodes[j];
        for (p, c) in self.pairs.iter().zip(&self.coeff) {
            y += p.part(*c, tau);
        }
        y
    }

    /// The state at τ within a pair's period after node j: the thermal part to first order from
    /// the node (it moves on the thermal time scales), the rest exact.
    pub fn state_near_node(&self, j: usize, tau: f64) -> DVector<f64> {
        let d = tau - j as f64 * self.step;
        let r = &self.nodes[j] + (&self.a * &self.nodes[j]) * d;
        let mut y = &self.base + &self.slope * tau + r;
        for (p, c) in self.pairs.iter().zip(&self.coeff) {
            y += p.part(*c, tau);
        }
        y
    }

    /// The functional w·y + offset over the arc.
    pub fn signal(&self, w: &DVector<f64>, offset: f64) -> ArcSignal {
        let wa = self.a.tr_mul(w);
        let wa4 = {
            let wa2 = self.a.tr_mul(&wa);
            let wa3 = self.a.tr_mul(&wa2);
            self.a.tr_mul(&wa3)
        };
        let (q0, q1) = (w.dot(&self.base) + offset, w.dot(&self.slope));
        let values = self
            .nodes
            .iter()
            .enumerate()
            .map(|(j, r)| q0 + q1 * j as f64 * self.step + w.dot(r))
            .collect();
        let slopes = self.nodes.iter().map(|r| q1 + wa.dot(r)).collect();
        let fourth = self.nodes.iter().map(|r| wa4.dot(r)).collect();
        let amps = self
            .pairs
            .iter()
            .zip(&self.coeff)
            .map(|(p, c)| {
                let wv: C64 = p.right.iter().zip(w.iter()).map(|(v, x)| v * *x).sum();
                wv * c * 2.0
            })
            .collect();
        ArcSignal {
            step: self.step,
            values,
            slopes,
            fourth,
            amps,
            lambdas: self.pairs.iter().map(|p| p.lambda).collect(),
        }
    }
}

/// A scalar functional of an arc: the smooth part at the grid nodes (value, slope and fourth
/// derivative) and the pairs' terms Re(a_k e^{λ_k τ}) (a_k holding both of the pair's halves).
#[derive(Debug, Clone)]
pub(crate) struct ArcSignal {
    step: f64,
    values: Vec<f64>,
    slopes: Vec<f64>,
    fourth: Vec<f64>,
    amps: Vec<C64>,
    lambdas: Vec<C64>,
}

/// Cubic Hermite basis on [0, 1] times the cell length for the slopes.
#[inline]
fn hermite(v0: f64, v1: f64, d0: f64, d1: f64, h: f64, s: f64) -> f64 {
    let s2 = s * s;
    let s3 = s2 * s;
    v0 * (1.0 - 3.0 * s2 + 2.0 * s3)
        + v1 * (3.0 * s2 - 2.0 * s3)
        + h * d0 * (s - 2.0 * s2 + s3)
        + h * d1 * (s3 - s2)
}

impl ArcSignal {
    fn cells(&self) -> usize {
        self.values.len() - 1
    }

    /// The interpolant's error bound in cell j: h⁴/384 max|s''''| at its ends, doubled.
    fn interpolation_error(&self, j: usize) -> f64 {
        let h = self.step;
        h.powi(4) / 192.0 * self.fourth[j].abs().max(self.fourth[j + 1].abs())
    }

    /// The largest interpolation error bound over the arc.
    pub fn max_interpolation_error(&self) -> f64 {
        (0..self.cells())
            .map(|j| self.interpolation_error(j))
            .fold(0.0, f64::max)
    }

    /// The smooth part at τ (in cell j).
    fn smooth(&self, j: usize, tau: f64) -> f64 {
        let h = self.step;
        let s = ((tau - j as f64 * h) / h).clamp(0.0, 1.0);
        hermite(
            self.values[j],
            self.values[j + 1],
            self.slopes[j],
            self.slopes[j + 1],
            h,
            s,
        )
    }

    /// The value at τ.
    pub fn at(&self, tau: f64) -> f64 {
        let j = ((tau / self.step).floor() as usize).min(self.cells() - 1);
        let mut v = self.smooth(j, tau);
        for (a, l) in self.amps.iter().zip(&self.lambdas) {
            v += (a * (l * tau).exp()).re;
        }
        v
    }

    /// The value at the end (exact: a node).
    #[cfg(test)]
    pub fn at_end(&self) -> f64 {
        let tau = self.cells() as f64 * self.step;
        let mut v = self.values[self.cells()];
        for (a, l) in self.amps.iter().zip(&self.lambdas) {
            v += (a * (l * tau).exp()).re;
        }
        v
    }

    /// Sum of the pairs' envelopes at τ.
    fn envelope(&self, tau: f64) -> f64 {
        self.amps
            .iter()
            .zip(&self.lambdas)
            .map(|(a, l)| a.norm() * (l.re * tau).exp())
            .sum()
    }

    /// A scale of the signal's variation: its pairs' envelopes at the start and the smooth
    /// part's range.
    pub fn variation(&self) -> f64 {
        let (lo, hi) = self
            .values
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| {
                (l.min(*v), h.max(*v))
            });
        self.envelope(0.0) + (hi - lo)
    }

    /// Upper bound of sign × signal over [a, b] inside cell j.
    fn bound(&self, j: usize, a: f64, b: f64, sign: f64) -> f64 {
        let h = self.step;
        let (v0, v1) = (sign * self.values[j], sign * self.values[j + 1]);
        let smooth = v0.max(v1)
            + 4.0 / 27.0 * h * (self.slopes[j].abs() + self.slopes[j + 1].abs())
            + self.interpolation_error(j);
        smooth + self.envelope(a).max(self.envelope(b))
    }

    /// max over [a, b] of sign × signal to within `tol` (the value found is a sample of the
    /// signal, below the true maximum by at most `tol` plus the interpolation error).
    pub fn max(&self, a: f64, b: f64, sign: f64, tol: f64) -> f64 {
        let h = self.step;
        let first = ((a / h).floor() as usize).min(self.cells() - 1);
        let last = (((b / h).ceil() as usize).max(first + 1)).min(self.cells());
        let mut cells: Vec<(f64, usize, f64, f64)> = (first..last)
            .filter_map(|j| {
                let (ca, cb) = ((j as f64 * h).max(a), ((j + 1) as f64 * h).min(b));
                (cb >= ca).then(|| (self.bound(j, ca, cb, sign), j, ca, cb))
            })
            .collect();
        cells.sort_by(|x, y| y.0.total_cmp(&x.0));
        let mut best = (sign * self.at(a)).max(sign * self.at(b));
        // Sample spacing: a peak of the pair k between samples Δ apart is missed by at most
        // |a_k| (ω_k Δ)²/8; the pairs share half the tolerance.
        let share = 0.5 * tol / self.amps.len().max(1) as f64;
        let spacing = self
            .amps
            .iter()
            .zip(&self.lambdas)
            .filter(|(amp, _)| amp.norm() > 0.0)
            .map(|(amp, l)| (8.0 * share / amp.norm()).sqrt() / l.im)
            .fold(0.25 * h, f64::min)
            .max(1e-6 * h);
        for (bound, j, ca, cb) in cells {
            if bound <= best + tol {
                break;
            }
            let n = ((cb - ca) / spacing).ceil().max(1.0) as usize;
            let dt = (cb - ca) / n as f64;
            // The pairs' terms advanced by their factor over one sample.
            let mut terms: Vec<C64> = self
                .amps
                .iter()
                .zip(&self.lambdas)
                .map(|(amp, l)| amp * (l * ca).exp())
                .collect();
            let factors: Vec<C64> = self.lambdas.iter().map(|l| (l * dt).exp()).collect();
            for i in 0..=n {
                let tau = ca + i as f64 * dt;
                let mut v = self.smooth(j, tau);
                for (t, f) in terms.iter_mut().zip(&factors) {
                    v += t.re;
                    *t *= f;
                }
                best = best.max(sign * v);
            }
        }
        sign * best
    }

    /// (min, max) over [a, b] within `tol`.
    pub fn extremes(&self, a: f64, b: f64, tol: f64) -> (f64, f64) {
        (self.max(a, b, -1.0, tol), self.max(a, b, 1.0, tol))
    }

    /// ∫₀^L signal² dτ: the smooth part by four-point Gauss–Legendre per cell (exact for the
    /// cubic squared), its products with the pairs and the pairs' squares in closed form.
    pub fn integral_sq(&self) -> f64 {
        let h = self.step;
        let gauss = [
            (0.5 - 0.430_568_155_797_026_3, 0.173_927_422_568_726_9),
            (0.5 - 0.169_990_521_792_428_1, 0.326_072_577_431_273_1),
            (0.5 + 0.169_990_521_792_428_1, 0.326_072_577_431_273_1),
            (0.5 + 0.430_568_155_797_026_3, 0.173_927_422_568_726_9),
        ];
        let mut total = 0.0;
        let mut cross = C64::new(0.0, 0.0);
        for j in 0..self.cells() {
            let t0 = j as f64 * h;
            for (s, w) in gauss {
                let v = self.smooth(j, t0 + s * h);
                total += w * h * v * v;
            }
            // The cubic c0 + c1 x + c2 x² + c3 x³ (x = τ − t0) against e^{λτ}:
            // ∫₀^h x^m e^{λx} dx by the recursion I_m = (h^m e^{λh} − m I_{m−1})/λ.
            let (v0, v1, d0, d1) = (
                self.values[j],
                self.values[j + 1],
                self.slopes[j],
                self.slopes[j + 1],
            );
            let c = [
                v0,
                d0,
                (3.0 * (v1 - v0) / h - 2.0 * d0 - d1) / h,
                (2.0 * (v0 - v1) / h + d0 + d1) / (h * h),
            ];
            for (amp, l) in self.amps.iter().zip(&self.lambdas) {
                let e = (l * h).exp();
                let mut integral = (e - 1.0) / l;
                let mut sum = integral * c[0];
                let mut power = 1.0;
                for (m, cm) in c.iter().enumerate().skip(1) {
                    power *= h;
                    integral = (e * power - integral * m as f64) / l;
                    sum += integral * *cm;
                }
                cross += amp * (l * t0).exp() * sum;
            }
        }
        // (Σ Re(a e^{λτ}))² = ½ Σ_jk Re(a_j a_k e^{(λ_j+λ_k)τ} + a_j ā_k e^{(λ_j+λ̄_k)τ}).
        let length = self.cells() as f64 * h;
        let mut pairs = 0.0;
        for (aj, lj) in self.amps.iter().zip(&self.lambdas) {
            for (ak, lk) in self.amps.iter().zip(&self.lambdas) {
                let same = aj * ak * phi1((lj + lk) * length);
                let conj = aj * ak.conj() * phi1((lj + lk.conj()) * length);
                pairs += 0.5 * length * (same + conj).re;
            }
        }
        (total + 2.0 * cross.re + pairs).max(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A damped oscillator (q, q̇) driven by a slow thermal pair: x' = −x/40, u' = −u/300,
    /// q̈ = −ω² q − 2ζω q̇ + x + u.
    fn system() -> DMatrix<f64> {
        let (w, z) = (0.9, 2e-3);
        DMatrix::from_row_slice(
            4,
            4,
            &[
                -1.0 / 40.0,
                0.0,
                0.0,
                0.0,
                0.0,
                -1.0 / 300.0,
                0.0,
                0.0,
                0.0,
                0.0,
                0.0,
                1.0,
                1.0,
                1.0,
                -w * w,
                -2.0 * z * w,
            ],
        )
    }

    /// The arc from y0 against a fine RK4 integration of δ' = A δ + c + b τ: its end state, and
    /// its reads of q (extremes, ∫q²) against the integration's samples. Returns the reads'
    /// interpolation error bound and the swing of q.
    fn check_arc(y0: &DVector<f64>) -> (f64, f64) {
        let a = system();
        let b = DVector::from_vec(vec![1e-4, -2e-5, 0.0, 0.0]);
        let c = DVector::from_vec(vec![2e-3, 0.0, 0.0, 1e-4]);
        let y_ref = DVector::from_vec(vec![1.0, 2.0, 3.0, 0.0]);
        let scale = DVector::from_element(4, 1.0);
        let pairs = structural_pairs(&a, &scale, 1, 0.1).expect("one pair");
        let length = 1000.0;
        let arc = LinearArc::new(&a, &c, &b, &y_ref, y0, pairs, length).unwrap();
        let mut d = y0 - &y_ref;
        let n = 200_000;
        let dt = length / n as f64;
        let f = |tau: f64, d: &DVector<f64>| &a * d + &c + &b * tau;
        let w = DVector::from_vec(vec![0.0, 0.0, 1.0, 0.0]);
        let signal = arc.signal(&w, 0.0);
        let (mut lo, mut hi, mut sq) = (f64::INFINITY, f64::NEG_INFINITY, 0.0);
        for i in 0..n {
            let tau = i as f64 * dt;
            let k1 = f(tau, &d);
            let k2 = f(tau + 0.5 * dt, &(&d + &k1 * (0.5 * dt)));
            let k3 = f(tau + 0.5 * dt, &(&d + &k2 * (0.5 * dt)));
            let k4 = f(tau + dt, &(&d + &k3 * dt));
            d += (k1 + k2 * 2.0 + k3 * 2.0 + k4) * (dt / 6.0);
            let v = d[2] + y_ref[2];
            lo = lo.min(v);
            hi = hi.max(v);
            sq += v * v * dt;
        }
        let end = arc.state_at_node(arc.cells());
        assert!((&end - (&d + &y_ref)).norm() < 1e-8, "{end} vs {d}");
        assert!((signal.at_end() - end[2]).abs() < 1e-12);
        // The extremes within the tolerance and the interpolant's error bound, which holds.
        let bound = signal.max_interpolation_error();
        let (slo, shi) = signal.extremes(0.0, length, 1e-9);
        let close = |x: f64, y: f64| (x - y).abs() <= bound + 1e-7;
        assert!(
            close(slo, lo) && close(shi, hi),
            "{slo} {shi} vs {lo} {hi}, bound {bound}"
        );
        let isq = signal.integral_sq();
        assert!(
            (isq - sq).abs() <= 1e-6 * sq + 2.0 * bound * hi.abs() * length,
            "{isq} vs {sq}"
        );
        (bound, hi - lo)
    }

    #[test]
    fn the_arc_is_the_exact_flow_and_its_reads_match_fine_sampling() {
        // A start far from the equilibrium (the fast thermal mode large: a loose bound) and one
        // near it (the thermal part small: a tight one).
        // (Near: on the drift's base y_ref + p0, p0 = A⁻¹(p1 − c) = (−0.08, 1.8) in x and u.)
        let (far, swing) = check_arc(&DVector::from_vec(vec![1.5, 1.0, 3.2, 0.05]));
        assert!(far < 1e-3 * swing, "{far} against {swing}");
        let (near, _) = check_arc(&DVector::from_vec(vec![0.92 + 1e-4, 3.8, 3.2, 0.05]));
        assert!(near < 1e-2 * far, "{near} against {far}");
    }
}
