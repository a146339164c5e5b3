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

use std::borrow::{Borrow, Cow};
use std::f64::consts::{FRAC_1_PI, PI};
use std::sync::OnceLock;

/// Equal parts of v ∈ [0, 1] of an [`EndpointInterpolant`], each with its own polynomial.
pub const PIECES: usize = 8;
/// Degree of each part's polynomial.
pub const DEGREE: usize = 10;

/// Roundings of t (ε |t| each) by which a function of time evaluated in floating point is
/// uncertain: its arguments (a phase rate × t + an offset, and what follows) each round once.
pub const TIME_ROUNDINGS: f64 = 16.0;

/// How a [`Table`] keeps and reads each part's polynomial.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Form {
    /// The Chebyshev series, read by Clenshaw's recurrence: a chain of [`DEGREE`] dependent
    /// multiply-adds (the form the records of the GEO penumbra were made with).
    Chebyshev,
    /// The same polynomial in powers of x, read by Estrin's scheme: a tree of multiply-adds
    /// about half as deep. Converting a series of degree 10 to powers loses a few digits at
    /// most (its terms of high degree, whose power coefficients grow as 2^m, are ~1e-12 of the
    /// function's size): each part is checked in this form. A table of two parts or more in
    /// this form also finds a time's part and x without an arc cosine ([`PartAngles`]).
    Power,
}

/// N functions on [a, b] as Chebyshev series of degree [`DEGREE`] in v, one per part.
#[derive(Debug, Clone)]
pub struct Table<const N: usize> {
    a: f64,
    /// 2 / (b − a).
    scale: f64,
    parts: usize,
    form: Form,
    /// Each part's polynomial in `form`.
    coefficients: Vec<[[f64; N]; DEGREE + 1]>,
    /// Parts whose check failed: the caller evaluates the functions there.
    refused: Vec<bool>,
    /// Where a time falls without an arc cosine: the power form's tables of two or more parts.
    angles: Option<Cow<'static, PartAngles>>,
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

/// The polynomial Σ p_j x^j of each component by Estrin's scheme: pairs of terms joined by x,
/// then pairs of pairs by x², and so on (written out for [`DEGREE`] = 10).
#[inline(always)]
fn estrin<const N: usize>(p: &[[f64; N]; DEGREE + 1], x: f64) -> [f64; N] {
    const { assert!(DEGREE == 10) };
    let (x2, x4) = (x * x, x * x * (x * x));
    let x8 = x4 * x4;
    std::array::from_fn(|i| {
        let pair = |j: usize| p[j][i] + p[j + 1][i] * x;
        let (a, b, c) = (
            pair(0) + pair(2) * x2,
            pair(4) + pair(6) * x2,
            pair(8) + p[10][i] * x2,
        );
        (a + b * x4) + c * x8
    })
}

/// The Chebyshev series `c` in powers of x: T_0 = 1, T_1 = x, T_{m+1} = 2x T_m − T_{m−1}.
fn to_powers<const N: usize>(c: &[[f64; N]; DEGREE + 1]) -> [[f64; N]; DEGREE + 1] {
    let mut out = [[0.0; N]; DEGREE + 1];
    // The power coefficients of T_{m−1} and T_m.
    let (mut before, mut now) = ([0.0; DEGREE + 1], [0.0; DEGREE + 1]);
    now[0] = 1.0;
    for (m, cm) in c.iter().enumerate() {
        if m == 1 {
            (before, now) = (now, [0.0; DEGREE + 1]);
            now[1] = 1.0;
        } else if m > 1 {
            let next: [f64; DEGREE + 1] = std::array::from_fn(|j| {
                let shifted = if j > 0 { 2.0 * now[j - 1] } else { 0.0 };
                shifted - before[j]
            });
            (before, now) = (now, next);
        }
        for (j, tj) in now.iter().enumerate() {
            for i in 0..N {
                out[j][i] += cm[i] * tj;
            }
        }
    }
    out
}

/// A part's points in x: its Chebyshev–Lobatto nodes cos(iπ/n) (i ≤ n = [`DEGREE`]), then the
/// n points halfway between them in angle, where its fit is checked.
const POINTS: usize = 2 * DEGREE + 1;

/// x at each of a part's [`POINTS`].
fn point(i: usize) -> f64 {
    let angle = if i <= DEGREE {
        i as f64
    } else {
        (i - DEGREE - 1) as f64 + 0.5
    };
    (angle * PI / DEGREE as f64).cos()
}

/// Tables of up to this many parts share what depends on their number of parts alone
/// ([`places`], [`part_angles`]).
const SHARED_PARTS: usize = 16;

/// `compute`'s value for a table of `parts` parts: made once in `cells` and shared for up to
/// [`SHARED_PARTS`] parts, made afresh beyond.
fn shared_by_parts<T: ?Sized + ToOwned>(
    cells: &'static [OnceLock<T::Owned>; SHARED_PARTS],
    parts: usize,
    compute: impl FnOnce() -> T::Owned,
) -> Cow<'static, T> {
    match cells.get(parts.wrapping_sub(1)) {
        Some(cell) => Cow::Borrowed(cell.get_or_init(compute).borrow()),
        None => Cow::Owned(compute()),
    }
}

/// Where each part's [`POINTS`] lie in a table of `parts` parts: 1 − cos πv at them, v = (k +
/// (1 + x)/2) / parts in part k, which is (t − a)/(b − a) times 2 on any [a, b]. The same for
/// every table of as many parts.
fn places(parts: usize) -> Cow<'static, [[f64; POINTS]]> {
    static SHARED: [OnceLock<Vec<[f64; POINTS]>>; SHARED_PARTS] =
        [const { OnceLock::new() }; SHARED_PARTS];
    shared_by_parts(&SHARED, parts, || {
        (0..parts)
            .map(|k| {
                std::array::from_fn(|i| {
                    let v = (k as f64 + 0.5 * (point(i) + 1.0)) / parts as f64;
                    1.0 - (PI * v).cos()
                })
            })
            .collect()
    })
}

/// The parts' angles of a table of two or more parts, for finding a time's part and its x
/// there without an arc cosine. In u = 1 − cos θ (θ = πv, u = 2 (t − a)/(b − a)) a part k covers
/// θ from πk/P to π(k + 1)/P, and x is the angle δ from its middle θ_m over the half width
/// Δ = π/(2P): δ = 2 atan(tan(δ/2)), where tan(δ/2) = sin δ / (1 + cos δ) comes from sin θ =
/// √(u (2 − u)), cos θ = 1 − u and θ_m's sine and cosine by products.
#[derive(Debug, Clone)]
struct PartAngles {
    /// u at the inner boundaries of the parts, 1 − cos(πi/P) for i = 1 .. P − 1.
    starts: Vec<f64>,
    /// Cosine and sine of each part's middle angle π(k + 1/2)/P.
    middles: Vec<(f64, f64)>,
    /// 4P/π: x per radian of δ/2.
    per_half_angle: f64,
}

impl PartAngles {
    fn new(parts: usize) -> Self {
        let p = parts as f64;
        PartAngles {
            starts: (1..parts)
                .map(|i| 1.0 - (PI * i as f64 / p).cos())
                .collect(),
            middles: (0..parts)
                .map(|k| {
                    let (sin, cos) = (PI * (k as f64 + 0.5) / p).sin_cos();
                    (cos, sin)
                })
                .collect(),
            per_half_angle: 4.0 * p / PI,
        }
    }

    /// The part of u ∈ [0, 2] and x ∈ [−1, 1] in it: the arc cosine's part and x to a few
    /// roundings (|δ/2| ≤ π/8 for two parts or more, where [`small_atan`] holds).
    #[inline(always)]
    fn locate(&self, u: f64) -> (usize, f64) {
        let u = u.clamp(0.0, 2.0);
        // The inner boundaries at or before u, counted without branches.
        let k = self.starts.iter().filter(|&&start| start <= u).count();
        let (cos_m, sin_m) = self.middles[k];
        let (cos, sin) = (1.0 - u, (u * (2.0 - u)).sqrt());
        let (sin_d, cos_d) = (sin * cos_m - cos * sin_m, cos * cos_m + sin * sin_m);
        (k, small_atan(sin_d / (1.0 + cos_d)) * self.per_half_angle)
    }
}

/// The [`PartAngles`] of a table of `parts` parts, the same for every table of as many.
fn part_angles(parts: usize) -> Cow<'static, PartAngles> {
    static SHARED: [OnceLock<PartAngles>; SHARED_PARTS] = [const { OnceLock::new() }; SHARED_PARTS];
    shared_by_parts(&SHARED, parts, || PartAngles::new(parts))
}

/// atan τ for |τ| ≤ tan(π/8), to about a rounding: τ times a polynomial of degree 11 in τ²,
/// Chebyshev-interpolated (50 digits) to atan(√z)/√z on z ∈ [0, tan²(π/8)] and taken to powers.
#[inline(always)]
fn small_atan(tau: f64) -> f64 {
    const C: [f64; 12] = [
        1.0,
        -0.333_333_333_333_331_2,
        0.199_999_999_999_408_93,
        -0.142_857_142_792_502_45,
        0.111_111_107_449_196_58,
        -0.090_908_968_090_640_27,
        0.076_920_453_309_022_25,
        -0.066_629_518_136_291_91,
        0.058_468_782_973_308_72,
        -0.050_351_024_566_015_52,
        0.037_965_257_453_865_93,
        -0.017_805_397_205_419_446,
    ];
    let z = tau * tau;
    let (z2, z4) = (z * z, z * z * (z * z));
    let z8 = z4 * z4;
    let pair = |j: usize| C[j] + C[j + 1] * z;
    let low = (pair(0) + pair(2) * z2) + (pair(4) + pair(6) * z2) * z4;
    let high = pair(8) + pair(10) * z2;
    tau * (low + high * z8)
}

impl<const N: usize> Table<N> {
    /// Fits `f` on [a, b] (a < b) in `parts` parts of v at the Chebyshev–Lobatto points of
    /// each, then checks each part at the [`DEGREE`] points between them: a part where a
    /// component's |interpolant − f| exceeds its `tol` + [`TIME_ROUNDINGS`] ε max(|a|, |b|) ×
    /// (its largest slope between nodes) anywhere, or where f is not finite, is refused.
    pub fn fit(f: impl Fn(f64) -> [f64; N], a: f64, b: f64, parts: usize, tol: [f64; N]) -> Self {
        Self::fit_in(Form::Chebyshev, f, a, b, parts, tol)
    }

    /// [`Table::fit`], each part kept, checked and read in `form`.
    pub fn fit_in(
        form: Form,
        f: impl Fn(f64) -> [f64; N],
        a: f64,
        b: f64,
        parts: usize,
        tol: [f64; N],
    ) -> Self {
        let n = DEGREE;
        let parts = parts.max(1);
        let mut out = Table {
            a,
            scale: 2.0 / (b - a),
            parts,
            form,
            coefficients: vec![[[0.0; N]; DEGREE + 1]; parts],
            refused: vec![false; parts],
            angles: (form == Form::Power && parts >= 2).then(|| part_angles(parts)),
        };
        let rounding = TIME_ROUNDINGS * f64::EPSILON * a.abs().max(b.abs());
        // cos(iπ/n) for i < 2n: the nodes (i ≤ n) and the transform's cos(jmπ/n), jm mod 2n.
        let turn: [f64; 2 * DEGREE] = std::array::from_fn(|i| (i as f64 * PI / n as f64).cos());
        let places = places(parts);
        let time_of = |k: usize, i: usize| a + (b - a) * 0.5 * places[k][i];
        // The last part's end (its first node, x = 1) and f there: the next part's start.
        let mut shared: Option<(f64, [f64; N])> = None;
        for k in 0..parts {
            let times: [f64; DEGREE + 1] = std::array::from_fn(|j| time_of(k, j));
            let values: [[f64; N]; DEGREE + 1] = std::array::from_fn(|j| match shared {
                Some((t, value)) if j == n && t == times[j] => value,
                _ => f(times[j]),
            });
            shared = Some((times[0], values[0]));
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
            if form == Form::Power {
                *c = to_powers(c);
            }
            let refused = (n + 1..POINTS).any(|i| {
                let x = point(i);
                let exact = f(time_of(k, i));
                let fit = out.series(k, x);
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
        let (k, x) = match &self.angles {
            Some(angles) => angles.locate((t - self.a) * self.scale),
            None => {
                let cos = (1.0 - (t - self.a) * self.scale).clamp(-1.0, 1.0);
                let v = cos.acos() * FRAC_1_PI * self.parts as f64;
                let k = (v as usize).min(self.parts - 1);
                (k, 2.0 * (v - k as f64) - 1.0)
            }
        };
        if self.refused[k] {
            return None;
        }
        Some(self.series(k, x))
    }

    /// Part k's polynomial at x ∈ [−1, 1].
    #[inline(always)]
    fn series(&self, k: usize, x: f64) -> [f64; N] {
        let c = &self.coefficients[k];
        match self.form {
            Form::Chebyshev => clenshaw(c, x),
            Form::Power => estrin(c, x),
        }
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

    #[test]
    fn neighbouring_parts_share_their_node() {
        let calls = std::cell::Cell::new(0);
        let f = |t: f64| {
            calls.set(calls.get() + 1);
            [(t * 1e-3).sin()]
        };
        for (a, b) in [(0.0, 3.0), (1.0e6, 1.0e6 + 3000.0), (-7.0, 11.0)] {
            for parts in [1, 2, 5, 8] {
                calls.set(0);
                let table = Table::fit(f, a, b, parts, [1e-3]);
                assert_eq!(table.refused(), 0);
                // 11 nodes and 10 checks a part, less one node between each two parts.
                assert_eq!(calls.get(), parts * (2 * DEGREE + 1) - (parts - 1));
            }
        }
    }

    #[test]
    fn a_series_in_powers_is_the_series() {
        // Each T_m alone: its powers read back cos(m acos x).
        for m in 0..=DEGREE {
            let mut c = [[0.0; 1]; DEGREE + 1];
            c[m] = [1.0];
            let p = to_powers(&c);
            for i in 0..=200 {
                let x = -1.0 + i as f64 / 100.0;
                let want = (m as f64 * x.acos()).cos();
                assert!((estrin(&p, x)[0] - want).abs() < 1e-12, "T_{m}({x})");
                assert!((clenshaw(&c, x)[0] - want).abs() < 1e-12, "T_{m}({x})");
            }
        }
        // Two functions, three tables: both forms hold them, and agree to rounding.
        let (a, b) = (1.0e6, 1.0e6 + 3000.0);
        let f = |t: f64| {
            let u = (t - a) / 5700.0 * std::f64::consts::TAU;
            [
                1361.0 * (0.3 + 0.7 * u.cos()),
                240.0 * (1.0 + 0.2 * (2.0 * u).sin()),
            ]
        };
        let tol = [1e-10 * 1361.0; 2];
        let power = Table::fit_in(Form::Power, f, a, b, 10, tol);
        let chebyshev = Table::fit(f, a, b, 10, tol);
        assert_eq!((power.refused(), chebyshev.refused()), (0, 0));
        for i in 0..=5000 {
            let t = a + (b - a) * i as f64 / 5000.0;
            let (p, c, want) = (power.at(t).unwrap(), chebyshev.at(t).unwrap(), f(t));
            for k in 0..2 {
                assert!(
                    (p[k] - want[k]).abs() < tol[k],
                    "t = {t}: {} vs {}",
                    p[k],
                    want[k]
                );
                assert!((p[k] - c[k]).abs() < 1e-11, "t = {t}: {} vs {}", p[k], c[k]);
            }
        }
    }

    #[test]
    fn the_small_arctangent_is_the_arctangent_to_a_rounding() {
        let reach = (PI / 8.0).tan();
        let mut draw = crate::numerics::testing::uniform_draws(8);
        for i in 0..200_000 {
            // Over the whole reach, and over small scales down to subnormal τ.
            let tau = if i % 2 == 0 {
                reach * (2.0 * draw() - 1.0)
            } else {
                reach * (2.0 * draw() - 1.0) * 10f64.powf(-310.0 * draw())
            };
            let (got, want) = (small_atan(tau), tau.atan());
            assert!(
                (got - want).abs() <= 2.0 * f64::EPSILON * want.abs(),
                "atan({tau}): {got} vs {want}"
            );
        }
    }

    #[test]
    fn a_part_and_its_x_are_found_without_an_arc_cosine() {
        // Against θ = 2 asin √(u/2) (π less that of 2 − u past the middle), accurate at both
        // ends, where an arc cosine of 1 − u loses the digits u holds. Compared as the position
        // v = (k + (1 + x)/2)/P, continuous across the parts' boundaries.
        let mut draw = crate::numerics::testing::uniform_draws(11);
        let mut worst = 0.0_f64;
        for parts in 2..=40 {
            let angles = PartAngles::new(parts);
            let p = parts as f64;
            let boundaries: Vec<f64> = (0..=parts)
                .map(|i| 1.0 - (PI * i as f64 / p).cos())
                .collect();
            for i in 0..5000 {
                let u = match i % 4 {
                    0 => 2.0 * draw(),
                    // Near a boundary, within a few thousand roundings of it.
                    1 => {
                        let b = boundaries[(draw() * (parts + 1) as f64) as usize];
                        (b + (draw() - 0.5) * 1e-12).clamp(0.0, 2.0)
                    }
                    2 => 10f64.powf(-300.0 * draw()),
                    _ => 2.0 - 10f64.powf(-16.0 * draw()),
                };
                let theta = if u <= 1.0 {
                    2.0 * (0.5 * u).sqrt().asin()
                } else {
                    PI - 2.0 * (0.5 * (2.0 - u)).sqrt().asin()
                };
                let (k, x) = angles.locate(u);
                assert!(
                    k < parts && x.abs() <= 1.0 + 1e-12,
                    "P = {parts}, u = {u}: {k} {x}"
                );
                let v = (k as f64 + 0.5 * (1.0 + x)) / p;
                worst = worst.max((v - theta / PI).abs());
            }
        }
        assert!(worst < 4.0 * f64::EPSILON, "worst {worst:e}");
    }

    #[test]
    fn drawn_power_tables_read_their_functions_to_the_tolerance() {
        // Contact-like ends and a smooth middle, over drawn spans, times and numbers of parts:
        // every read of a part kept is within the tolerance, the ends and boundaries included.
        let mut draw = crate::numerics::testing::uniform_draws(12);
        for _ in 0..200 {
            let a = 3e8 * draw();
            let b = a + 10.0 + 3000.0 * draw();
            let parts = 2 + (draw() * 15.0) as usize;
            let (rate, phase) = (1e-3 * draw(), 6.0 * draw());
            let f = |t: f64| {
                let (u, w) = ((t - a) / (b - a), (b - t) / (b - a));
                [
                    1361.0 * (0.4 + 0.5 * (rate * t + phase).cos()) * u.max(0.0).powf(1.5),
                    200.0 * (1.0 + w.max(0.0).powf(1.5)) + 30.0 * (2.0 * rate * t).sin(),
                ]
            };
            let tol = [1e-10 * 1361.0; 2];
            let table = Table::fit_in(Form::Power, f, a, b, parts, tol);
            let rounding = TIME_ROUNDINGS * f64::EPSILON * b.abs() * 1361.0 * 1.5 / (b - a);
            for i in 0..=2000 {
                let t = if i % 2 == 0 {
                    a + (b - a) * i as f64 / 2000.0
                } else {
                    a + (b - a) * draw()
                };
                if let Some(got) = table.at(t) {
                    let want = f(t);
                    for c in 0..2 {
                        assert!(
                            (got[c] - want[c]).abs() <= tol[c] + 10.0 * rounding,
                            "parts {parts}, t - a = {}: {} vs {}",
                            t - a,
                            got[c],
                            want[c]
                        );
                    }
                }
            }
        }
    }
}
