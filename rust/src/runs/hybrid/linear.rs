//! Exact propagation of the linearised system over a sunlit arc, in modal form.
//!
//! About the sunlit equilibrium y_r at the arc's initial flux f_r, with the flux drifting
//! linearly, f(t) = f_r + ḟ τ (the Sun's distance changes by at most 6e-4 per day), the deviation
//! δ = y − y_r obeys δ' = A δ + b τ with A the Jacobian at y_r and b = (∂f/∂flux) ḟ. Its solution
//! is a particular part p0 + p1 τ (p1 = −A⁻¹ b, p0 = A⁻¹ p1, the quasi-static drift) plus
//! Σ_k c_k v_k e^{λ_k τ} over the eigenpairs of A: two thermal modes and the hinge's complex pair.
//! Every per-orbit summary over the arc then follows from this closed form.

use crate::error::{Error, Result};
use nalgebra::{Complex, DMatrix, SMatrix, SVector};

type C64 = Complex<f64>;

/// y(τ) = base + slope τ + Re Σ_k modes_k e^{λ_k τ} for τ in [0, length].
#[derive(Debug, Clone, Copy)]
pub struct Arc<const N: usize> {
    pub length: f64,
    base: SVector<f64, N>,
    slope: SVector<f64, N>,
    lambda: [C64; N],
    modes: [SVector<C64, N>; N],
}

/// A scalar linear functional w·y(τ) of an arc: q0 + q1 τ + Σ_k a_k e^{λ_k τ} (real in total).
#[derive(Debug, Clone, Copy)]
pub struct Signal<const N: usize> {
    q0: f64,
    q1: f64,
    a: [C64; N],
    lambda: [C64; N],
}

impl<const N: usize> Arc<N> {
    /// The arc from y(0) = y0 about the equilibrium `y_ref` with Jacobian `a` and drift forcing b τ.
    /// `scale` balances the state's units for the eigen-solve (a diagonal similarity).
    pub fn new(
        a: &SMatrix<f64, N, N>,
        b: &SVector<f64, N>,
        y_ref: &SVector<f64, N>,
        y0: &SVector<f64, N>,
        length: f64,
        scale: &SVector<f64, N>,
    ) -> Result<Arc<N>> {
        let fail = |reason: &str| Error::NoConvergence {
            what: "modal decomposition".into(),
            reason: reason.into(),
        };
        let lu = Lu::of(a);
        let p1 = -lu.solve(b).ok_or_else(|| fail("singular Jacobian"))?;
        let p0 = lu.solve(&p1).ok_or_else(|| fail("singular Jacobian"))?;
        let (ab, ev) = balanced_eigenvalues(a, scale);
        let abc: SMatrix<C64, N, N> = ab.map(|v| C64::new(v, 0.0));
        let mut vecs: [SVector<C64, N>; N] = [SVector::zeros(); N];
        for k in 0..N {
            let lam = ev[k];
            if !(lam.re.is_finite() && lam.im.is_finite()) {
                return Err(fail("non-finite eigenvalue"));
            }
            vecs[k] = eigenvector(&abc, lam)
                .ok_or_else(|| fail("eigenvector not found to rounding (defective Jacobian?)"))?;
        }
        let v = SMatrix::<C64, N, N>::from_columns(&vecs);
        let h0 = y0 - y_ref - p0;
        let h0b: SVector<C64, N> = SVector::from_fn(|i, _| C64::new(h0[i] / scale[i], 0.0));
        let c = Lu::of(&v)
            .solve(&h0b)
            .ok_or_else(|| fail("eigenvectors not independent"))?;
        let back = v * c;
        let err = (back - h0b).norm();
        if err.is_nan() || err > 1e-9 * h0b.norm().max(1e-300) {
            return Err(fail("eigenvectors nearly dependent"));
        }
        let mut modes = [SVector::<C64, N>::zeros(); N];
        for k in 0..N {
            modes[k] = SVector::from_fn(|i, _| vecs[k][i] * c[k] * scale[i]);
        }
        Ok(Arc {
            length,
            base: y_ref + p0,
            slope: p1,
            lambda: std::array::from_fn(|k| ev[k]),
            modes,
        })
    }

    /// The state at τ.
    pub fn state(&self, tau: f64) -> SVector<f64, N> {
        let mut y = self.base + self.slope * tau;
        for k in 0..N {
            let e = (self.lambda[k] * tau).exp();
            for i in 0..N {
                y[i] += (self.modes[k][i] * e).re;
            }
        }
        y
    }

    /// The modes' part of the state at τ: y(τ) less the quasi-static drift base + slope τ.
    pub fn transient(&self, tau: f64) -> SVector<f64, N> {
        self.state(tau) - self.base - self.slope * tau
    }

    /// The functional w·y(τ).
    pub fn signal(&self, w: &SVector<f64, N>) -> Signal<N> {
        let a = self.modes.map(|m| (0..N).map(|i| m[i] * w[i]).sum::<C64>());
        Signal {
            q0: w.dot(&self.base),
            q1: w.dot(&self.slope),
            a,
            lambda: self.lambda,
        }
    }
}

/// The matrix balanced by `scale`, ab = D⁻¹ A D (so that kelvin and radian rows have comparable
/// sizes for the eigen-solve), and its eigenvalues (those of A).
pub fn balanced_eigenvalues<const N: usize>(
    a: &SMatrix<f64, N, N>,
    scale: &SVector<f64, N>,
) -> (SMatrix<f64, N, N>, nalgebra::DVector<C64>) {
    let ab = SMatrix::<f64, N, N>::from_fn(|i, j| a[(i, j)] * scale[j] / scale[i]);
    let ev = DMatrix::from_column_slice(N, N, ab.as_slice()).complex_eigenvalues();
    (ab, ev)
}

/// The hinge's oscillatory eigenpair of a Jacobian: λ (the eigenvalue of the complex pair with
/// Im λ > 0 and the largest |Im λ|), its right eigenvector v and left eigenvector w, scaled so that
/// w·v = 1 (bilinear). About a fixed point y*, a state's hinge coordinate is c = w·(y − y*) and
/// its θ oscillates as 2 Re(v_θ c e^{λt}).
#[derive(Debug, Clone, Copy)]
pub struct HingeMode<const N: usize> {
    pub lambda: C64,
    pub right: SVector<C64, N>,
    pub left: SVector<C64, N>,
}

impl<const N: usize> HingeMode<N> {
    /// The pair of `a`, balanced by `scale` for the eigen-solve; None when `a` has no complex
    /// pair (an over-damped hinge) or the eigenvectors cannot be found to rounding.
    pub fn of(a: &SMatrix<f64, N, N>, scale: &SVector<f64, N>) -> Option<HingeMode<N>> {
        let (ab, ev) = balanced_eigenvalues(a, scale);
        let lambda = ev
            .iter()
            .copied()
            .filter(|l| l.im > 1e-12 * l.norm() && l.re.is_finite())
            .max_by(|x, y| x.im.total_cmp(&y.im))?;
        let abc: SMatrix<C64, N, N> = ab.map(|v| C64::new(v, 0.0));
        let x = eigenvector(&abc, lambda)?;
        let z = eigenvector(&abc.transpose(), lambda)?;
        let norm = z.dot(&x);
        if norm.norm().is_nan() || norm.norm() <= 1e-12 {
            return None;
        }
        Some(HingeMode {
            lambda,
            right: SVector::from_fn(|i, _| x[i] * scale[i]),
            left: SVector::from_fn(|i, _| z[i] / (norm * scale[i])),
        })
    }

    /// The hinge coordinate w·x of a (real) vector x.
    pub fn coordinate(&self, x: &SVector<f64, N>) -> C64 {
        (0..N).map(|i| self.left[i] * x[i]).sum()
    }

    /// Amplitude in θ (component `i`) of a hinge coordinate c: 2 |v_θ c|.
    pub fn theta_amplitude(&self, i: usize, c: C64) -> f64 {
        2.0 * (self.right[i] * c).norm()
    }
}

/// The eigenvector of `m` for the eigenvalue `lam`, unit norm, by inverse iteration with a
/// slightly perturbed shift (two solves give it to rounding); None when its residual is large.
fn eigenvector<const N: usize>(m: &SMatrix<C64, N, N>, lam: C64) -> Option<SVector<C64, N>> {
    let eps = 1e-10 * lam.norm().max(1e-12);
    let shifted = m - SMatrix::<C64, N, N>::identity() * (lam + C64::new(eps, eps));
    let lu = Lu::of(&shifted);
    let mut x = SVector::<C64, N>::from_fn(|i, _| start_component(i));
    for _ in 0..3 {
        x = lu.solve(&x)?;
        let n = x.norm();
        if !(n.is_finite() && n > 0.0) {
            return None;
        }
        x /= C64::new(n, 0.0);
    }
    ((m * x - x * lam).norm() <= 1e-9 * m.norm()).then_some(x)
}

/// The LU factors of an N×N matrix, computed on the run-time size (the compile-time one asks
/// for dimension bounds a size generic over N does not carry); the same elimination either way.
struct Lu<T: nalgebra::ComplexField, const N: usize>(
    nalgebra::linalg::LU<T, nalgebra::Dyn, nalgebra::Dyn>,
);

impl<T: nalgebra::ComplexField + Copy, const N: usize> Lu<T, N> {
    fn of(m: &SMatrix<T, N, N>) -> Self {
        Lu(nalgebra::DMatrix::from_column_slice(N, N, m.as_slice()).lu())
    }

    fn solve(&self, b: &SVector<T, N>) -> Option<SVector<T, N>> {
        let x = self
            .0
            .solve(&nalgebra::DVector::from_column_slice(b.as_slice()))?;
        Some(SVector::from_column_slice(x.as_slice()))
    }
}

/// The start of inverse iteration: a vector with no special direction (the first four are the
/// two-layer model's).
fn start_component(i: usize) -> C64 {
    const FIRST: [(f64, f64); 4] = [(1.0, 0.0), (0.7, 0.1), (-0.3, 0.5), (0.2, -0.4)];
    match FIRST.get(i) {
        Some(&(re, im)) => C64::new(re, im),
        None => C64::new(0.37 + 0.11 * i as f64, 0.23 - 0.05 * i as f64),
    }
}

/// φ1(x) = (eˣ − 1)/x and φ2(x) = (eˣ − 1 − x)/x², by their series near 0.
fn phi12(x: C64) -> (C64, C64) {
    if x.norm() < 0.5 {
        let (mut t1, mut t2) = (C64::new(1.0, 0.0), C64::new(0.5, 0.0));
        let (mut s1, mut s2) = (C64::new(0.0, 0.0), C64::new(0.0, 0.0));
        for j in 0..25 {
            s1 += t1;
            s2 += t2;
            t1 = t1 * x / (j as f64 + 2.0);
            t2 = t2 * x / (j as f64 + 3.0);
        }
        (s1, s2)
    } else {
        let p1 = (x.exp() - 1.0) / x;
        (p1, (p1 - 1.0) / x)
    }
}

impl<const N: usize> Signal<N> {
    /// The signal plus a constant.
    pub fn shifted(mut self, c: f64) -> Signal<N> {
        if c != 0.0 {
            self.q0 += c;
        }
        self
    }

    pub fn at(&self, tau: f64) -> f64 {
        let mut v = self.q0 + self.q1 * tau;
        for k in 0..N {
            v += (self.a[k] * (self.lambda[k] * tau).exp()).re;
        }
        v
    }

    /// The signal and its first two derivatives at τ.
    fn with_derivatives(&self, tau: f64) -> (f64, f64, f64) {
        let (mut v, mut d1, mut d2) = (self.q0 + self.q1 * tau, self.q1, 0.0);
        for k in 0..N {
            let l = self.lambda[k];
            let term = self.a[k] * (l * tau).exp();
            v += term.re;
            d1 += (term * l).re;
            d2 += (term * l * l).re;
        }
        (v, d1, d2)
    }

    /// Smooth part (drift and real modes) and the envelope of the oscillatory terms at τ.
    fn smooth_and_envelope(&self, tau: f64) -> (f64, f64) {
        let (mut smooth, mut env) = (self.q0 + self.q1 * tau, 0.0);
        for k in 0..N {
            let l = self.lambda[k];
            // Re(a e^{λτ}) of a real λ is Re(a) e^{λτ}.
            let decay = (l.re * tau).exp();
            if l.im != 0.0 {
                env += self.a[k].norm() * decay;
            } else {
                smooth += self.a[k].re * decay;
            }
        }
        (smooth, env)
    }

    /// Largest value of the oscillation's envelope over [t0, t1] (it is monotonic: at an end).
    pub fn envelope_max(&self, t0: f64, t1: f64) -> f64 {
        self.smooth_and_envelope(t0)
            .1
            .max(self.smooth_and_envelope(t1).1)
    }

    /// ∫₀^L (w·y)² dτ in closed form.
    pub fn integral_sq(&self, length: f64) -> f64 {
        let l = length;
        let (q0, q1) = (self.q0, self.q1);
        let mut total = C64::new(
            q0 * q0 * l + q0 * q1 * l * l + q1 * q1 * l * l * l / 3.0,
            0.0,
        );
        for k in 0..N {
            // ∫ e^{λτ} = L φ1(λL), ∫ τ e^{λτ} = L² (φ1 − φ2)(λL).
            let (p1, p2) = phi12(self.lambda[k] * l);
            total += self.a[k] * 2.0 * (p1 * (q0 * l) + (p1 - p2) * (q1 * l * l));
            for j in 0..N {
                let (p1, _) = phi12((self.lambda[j] + self.lambda[k]) * l);
                total += self.a[j] * self.a[k] * p1 * l;
            }
        }
        total.re.max(0.0)
    }

    /// (min, max) of the signal over [t0, t1]: where its upper (lower) envelope, the smooth part
    /// ± the oscillation's envelope, is largest (smallest), located on a grid and refined; then
    /// the signal's own peaks within a period either side, in closed form (below).
    pub fn extremes(&self, t0: f64, t1: f64) -> (f64, f64) {
        let hi = self.search(t0, t1, 1.0);
        let lo = -self.search(t0, t1, -1.0);
        (lo, hi)
    }

    /// sign × smooth part + envelope at GRID + 1 evenly spaced points of [t0, t1]: each
    /// exponential advanced by its factor over one interval (rounding of 1e-14 at most, ample
    /// to locate the largest).
    fn bound_on_grid(&self, sign: f64, t0: f64, t1: f64) -> [f64; GRID + 1] {
        let dx = (t1 - t0) / GRID as f64;
        let mut values = [0.0; GRID + 1];
        for (i, v) in values.iter_mut().enumerate() {
            *v = sign * (self.q0 + self.q1 * (t0 + i as f64 * dx));
        }
        for k in 0..N {
            let l = self.lambda[k];
            let (mut term, step) = ((l.re * t0).exp(), (l.re * dx).exp());
            let weight = if l.im != 0.0 {
                self.a[k].norm()
            } else {
                sign * self.a[k].re
            };
            for v in values.iter_mut() {
                *v += weight * term;
                term *= step;
            }
        }
        values
    }

    /// max over [t0, t1] of sign × signal.
    ///
    /// The hinge's pair of modes makes the oscillation 2|a| e^{στ} cos(ωτ + arg a), so sign × signal
    /// peaks near ωτ + arg a = 2πm (+ π for the minimum), at most one peak within a quarter period
    /// of each: its slope falls there from positive to negative (the smooth part varies on the
    /// thermal time scales, far slower). Each peak is the zero of the slope, found by Newton's
    /// method safeguarded by bisection; where the slope does not change sign the largest value is
    /// at an end. Between peaks the slope rises, so no maximum lies there.
    fn search(&self, t0: f64, t1: f64, sign: f64) -> f64 {
        let bound = |tau: f64| {
            let (s, e) = self.smooth_and_envelope(tau);
            sign * s + e
        };
        let value = |tau: f64| sign * self.at(tau);
        let oscillating = (0..N)
            .filter(|&k| self.lambda[k].im > 0.0)
            .max_by(|&i, &j| self.a[i].norm().total_cmp(&self.a[j].norm()));
        let grid = self.bound_on_grid(sign, t0, t1);
        let Some(k) = oscillating else {
            let t_star = grid_max(&bound, t0, t1, &grid, 0.0);
            return value(t0).max(value(t1)).max(value(t_star));
        };
        let omega = self.lambda[k].im;
        let period = 2.0 * std::f64::consts::PI / omega;
        // The signal's peaks are searched a period either side: an eighth of one will do here.
        let t_star = grid_max(&bound, t0, t1, &grid, 0.125 * period);
        let ends = value(t0).max(value(t1)).max(value(t_star));
        let (a, b) = ((t_star - period).max(t0), (t_star + period).min(t1));
        let shift = self.a[k].arg()
            + if sign > 0.0 {
                0.0
            } else {
                std::f64::consts::PI
            };
        let quarter = 0.25 * period;
        // Peaks at τ_m = (2πm − shift) / ω, from the last one before a.
        let mut peak =
            period * ((a * omega + shift) / (2.0 * std::f64::consts::PI)).floor() - shift / omega;
        let mut best = ends.max(value(a)).max(value(b));
        while peak - quarter < b {
            let (lo, hi) = ((peak - quarter).max(a), (peak + quarter).min(b));
            if hi > lo {
                best = best.max(self.peak(lo, hi, sign, period));
            }
            peak += period;
        }
        best
    }

    /// max over [lo, hi] of sign × signal, where its slope falls (at most one zero).
    fn peak(&self, mut lo: f64, mut hi: f64, sign: f64, period: f64) -> f64 {
        let slope = |tau: f64| {
            let (_, d1, d2) = self.with_derivatives(tau);
            (sign * d1, sign * d2)
        };
        let ends = (sign * self.at(lo)).max(sign * self.at(hi));
        if !(slope(lo).0 > 0.0 && slope(hi).0 < 0.0) {
            return ends;
        }
        let mut x = 0.5 * (lo + hi);
        for _ in 0..60 {
            let (g, dg) = slope(x);
            if g > 0.0 {
                lo = x;
            } else {
                hi = x;
            }
            let newton = x - g / dg;
            let next = if newton > lo && newton < hi {
                newton
            } else {
                0.5 * (lo + hi)
            };
            let done = (next - x).abs() <= 1e-9 * period;
            x = next;
            if done {
                break;
            }
        }
        ends.max(sign * self.at(x))
    }
}

/// Intervals of the grid on which the envelopes' largest value is located.
const GRID: usize = 64;

/// The maximiser of f over [a, b] from its values on an evenly spaced grid (`values`, ends
/// included), refined by golden section between the best point's neighbours (until the bracket
/// is narrower than `width`, at most 40 times).
fn grid_max(f: &impl Fn(f64) -> f64, a: f64, b: f64, values: &[f64], width: f64) -> f64 {
    if b <= a {
        return a;
    }
    let n = values.len() - 1;
    let dx = (b - a) / n as f64;
    let (mut best, mut best_v) = (a, values[0]);
    for (i, &v) in values.iter().enumerate().skip(1) {
        if v > best_v {
            best = if i == n { b } else { a + i as f64 * dx };
            best_v = v;
        }
    }
    // The maximum of f is the minimum of −f (negation is exact: the same comparisons).
    let (lo, hi) = crate::numerics::simd::golden_section(
        |x| -f(x),
        (best - dx).max(a),
        (best + dx).min(b),
        width,
        40,
    );
    let x = 0.5 * (lo + hi);
    if f(x) >= best_v {
        x
    } else {
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::runs::hybrid::expm::expm;
    use nalgebra::{Matrix4, Matrix5, Vector4};

    /// A coupled thermal–oscillator matrix like the panel's (balanced units).
    fn system() -> (Matrix4<f64>, Vector4<f64>) {
        let a = Matrix4::new(
            -0.025, 0.01, -0.4, 0.0, 0.01, -0.012, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 4.9e-3, -4.9e-3,
            -0.62, -3e-4,
        );
        (a, Vector4::new(2e-7, 0.0, 0.0, 0.0))
    }

    #[test]
    fn arc_state_is_the_exact_flow_of_the_forced_linear_system() {
        let (a, b) = system();
        let y_ref = Vector4::new(380.0, 370.0, 0.08, 0.0);
        let y0 = y_ref + Vector4::new(0.3, -0.2, 1e-4, 2e-5);
        let scale = Vector4::new(1.0, 1.0, 1.0 / 380.0, 0.79 / 380.0);
        let arc = Arc::new(&a, &b, &y_ref, &y0, 5000.0, &scale).unwrap();
        // Augmented (δ, τ): d/dt [δ; τ] = [[A, b], [0, 0]] [δ; τ] + [0; 1]; as a 6×6 with a
        // constant 1, exp gives the exact flow.
        for &tau in &[0.0, 3.7, 1000.0, 5000.0] {
            let mut m = nalgebra::SMatrix::<f64, 6, 6>::zeros();
            m.fixed_view_mut::<4, 4>(0, 0).copy_from(&a);
            m.fixed_view_mut::<4, 1>(0, 4).copy_from(&b);
            m[(4, 5)] = 1.0;
            let e = expm(&(m * tau));
            let z0 = nalgebra::SVector::<f64, 6>::new(
                y0[0] - y_ref[0],
                y0[1] - y_ref[1],
                y0[2] - y_ref[2],
                y0[3] - y_ref[3],
                0.0,
                1.0,
            );
            let z = e * z0;
            let got = arc.state(tau) - y_ref;
            for i in 0..4 {
                assert!(
                    (got[i] - z[i]).abs() < 1e-9 * (1.0 + z[i].abs()) * scale[i].max(1e-3),
                    "tau {tau} component {i}: {} vs {}",
                    got[i],
                    z[i]
                );
            }
        }
        let _ = Matrix5::<f64>::zeros();
    }

    #[test]
    fn closed_form_integral_and_extremes_match_fine_sampling() {
        let (a, b) = system();
        let y_ref = Vector4::new(380.0, 370.0, 0.08, 0.0);
        let y0 = y_ref + Vector4::new(0.3, -0.2, 1e-4, 2e-5);
        let scale = Vector4::new(1.0, 1.0, 1.0 / 380.0, 0.79 / 380.0);
        let length = 3000.0;
        let arc = Arc::new(&a, &b, &y_ref, &y0, length, &scale).unwrap();
        let sig = arc.signal(&Vector4::new(-0.0079, 0.0079, 1.0, 0.0));
        let n = 3_000_000;
        let dt = length / n as f64;
        let (mut sq, mut lo, mut hi) = (0.0, f64::INFINITY, f64::NEG_INFINITY);
        for i in 0..=n {
            let v = sig.at(i as f64 * dt);
            let w = if i == 0 || i == n { 0.5 } else { 1.0 };
            sq += w * v * v * dt;
            lo = lo.min(v);
            hi = hi.max(v);
        }
        let exact = sig.integral_sq(length);
        assert!((exact / sq - 1.0).abs() < 1e-6, "{exact} vs {sq}");
        let (elo, ehi) = sig.extremes(0.0, length);
        let span = hi - lo;
        assert!((ehi - hi).abs() < 1e-6 * span && (elo - lo).abs() < 1e-6 * span);
        let (wlo, whi) = sig.extremes(1200.0, 1300.0);
        let (mut slo, mut shi) = (f64::INFINITY, f64::NEG_INFINITY);
        for i in 0..=100_000 {
            let v = sig.at(1200.0 + i as f64 * 1e-3);
            slo = slo.min(v);
            shi = shi.max(v);
        }
        assert!((whi - shi).abs() < 1e-6 * span && (wlo - slo).abs() < 1e-6 * span);
        // Windows shorter and longer than the hinge period (8 s), anywhere in the arc.
        for (start, width) in [(0.0, 3.0), (17.3, 9.0), (400.0, 40.0), (2210.0, 700.0)] {
            let steps = (width * 1e3) as usize;
            let (mut slo, mut shi) = (f64::INFINITY, f64::NEG_INFINITY);
            for i in 0..=steps {
                let v = sig.at(start + width * i as f64 / steps as f64);
                slo = slo.min(v);
                shi = shi.max(v);
            }
            let (wlo, whi) = sig.extremes(start, start + width);
            let tol = 1e-9 * span;
            assert!(
                whi >= shi - tol && whi - shi < 1e-6 * span,
                "{start}+{width}"
            );
            assert!(
                wlo <= slo + tol && slo - wlo < 1e-6 * span,
                "{start}+{width}"
            );
        }
    }
}
