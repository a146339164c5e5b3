//! Arithmetic written once for one value (`f64`) and for one value per SIMD lane ([`Lanes`]), so
//! that the model's formulas have a single source and a lane computes exactly what the scalar
//! code does, operation for operation (`integrate::lockstep`); and the one-dimensional search
//! the engine's modules share ([`golden_section`]).

use std::ops::{Add, Div, Mul, Neg, Sub};

/// The bracket [a, b] of the minimum of a unimodal `f` by golden-section search: once it is
/// narrower than `width`, or after `max_iter` steps.
pub(crate) fn golden_section(
    f: impl Fn(f64) -> f64,
    mut a: f64,
    mut b: f64,
    width: f64,
    max_iter: usize,
) -> (f64, f64) {
    let g = 0.5 * (5f64.sqrt() - 1.0);
    let mut c = b - g * (b - a);
    let mut d = a + g * (b - a);
    let (mut fc, mut fd) = (f(c), f(d));
    for _ in 0..max_iter {
        if (b - a).abs() < width {
            break;
        }
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - g * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + g * (b - a);
            fd = f(d);
        }
    }
    (a, b)
}

/// What the model's formulas need of a number: the four operations, constants, and a
/// multiply-add.
pub(crate) trait Num:
    Copy
    + Add<Output = Self>
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Neg<Output = Self>
    + From<f64>
{
    /// b + self · a: two roundings (a multiplication, then an addition) unless the type is a
    /// fused one, which rounds once. (The three forms keep the unfused arithmetic written as it
    /// always was, operand for operand.)
    #[inline(always)]
    fn mul_add(self, a: Self, b: Self) -> Self {
        b + self * a
    }
    /// self · a − b, likewise.
    #[inline(always)]
    fn mul_sub(self, a: Self, b: Self) -> Self {
        self * a - b
    }
    /// b − self · a, likewise.
    #[inline(always)]
    fn neg_mul_add(self, a: Self, b: Self) -> Self {
        b - self * a
    }
}

impl Num for f64 {}

/// One f64 whose [`Num::mul_add`] rounds once (a fused multiply-add): the scalar twin of the
/// AVX2 and AVX-512 lanes, used by the scalar loop compiled for FMA
/// (`numerics::cpu::ScalarKernel::Fma`). Compiled without FMA, `f64::mul_add` is a library call:
/// the same bits, slowly.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Fused(pub(crate) f64);

impl From<f64> for Fused {
    #[inline(always)]
    fn from(x: f64) -> Fused {
        Fused(x)
    }
}

impl From<Fused> for f64 {
    #[inline(always)]
    fn from(x: Fused) -> f64 {
        x.0
    }
}

macro_rules! fused_operation {
    ($trait:ident, $method:ident, $op:tt) => {
        impl $trait for Fused {
            type Output = Fused;
            #[inline(always)]
            fn $method(self, o: Fused) -> Fused {
                Fused(self.0 $op o.0)
            }
        }
    };
}
fused_operation!(Add, add, +);
fused_operation!(Sub, sub, -);
fused_operation!(Mul, mul, *);
fused_operation!(Div, div, /);

impl Neg for Fused {
    type Output = Fused;
    #[inline(always)]
    fn neg(self) -> Fused {
        Fused(-self.0)
    }
}

impl Num for Fused {
    #[inline(always)]
    fn mul_add(self, a: Fused, b: Fused) -> Fused {
        Fused(self.0.mul_add(a.0, b.0))
    }
    #[inline(always)]
    fn mul_sub(self, a: Fused, b: Fused) -> Fused {
        Fused(self.0.mul_add(a.0, -b.0))
    }
    #[inline(always)]
    fn neg_mul_add(self, a: Fused, b: Fused) -> Fused {
        Fused((-self.0).mul_add(a.0, b.0))
    }
}

/// Values advanced side by side, one per lane.
pub(crate) const LANES: usize = 8;

/// A lane type's values, lane by lane.
pub(crate) trait LaneArray {
    fn lanes(&self) -> &[f64; LANES];
    fn lanes_mut(&mut self) -> &mut [f64; LANES];
}

/// What every lane type (an array of [`LANES`] f64) shares: made from one value, the same in
/// every lane; read and written lane by lane; and the four operations, each applied to the two
/// values by the type's method `$pair` with the closure given (one instruction per register).
macro_rules! lane_type {
    ($t:ident, $pair:ident, $add:expr, $sub:expr, $mul:expr, $div:expr) => {
        lane_type!($t, $pair, $add, $sub, $mul, $div, fused: false);
        impl Num for $t {}
    };
    (
        $t:ident, $pair:ident, $add:expr, $sub:expr, $mul:expr, $div:expr,
        $triple:ident, $fmadd:expr, $fmsub:expr, $fnmadd:expr
    ) => {
        lane_type!($t, $pair, $add, $sub, $mul, $div, fused: true);
        impl Num for $t {
            #[inline(always)]
            fn mul_add(self, a: $t, b: $t) -> $t {
                self.$triple(a, b, $fmadd)
            }
            #[inline(always)]
            fn mul_sub(self, a: $t, b: $t) -> $t {
                self.$triple(a, b, $fmsub)
            }
            #[inline(always)]
            fn neg_mul_add(self, a: $t, b: $t) -> $t {
                self.$triple(a, b, $fnmadd)
            }
        }
    };
    ($t:ident, $pair:ident, $add:expr, $sub:expr, $mul:expr, $div:expr, fused: $fused:expr) => {
        impl Fusion for $t {
            const FUSED: bool = $fused;
        }
        impl From<f64> for $t {
            #[inline(always)]
            fn from(x: f64) -> $t {
                $t([x; LANES])
            }
        }
        impl LaneArray for $t {
            #[inline(always)]
            fn lanes(&self) -> &[f64; LANES] {
                &self.0
            }
            #[inline(always)]
            fn lanes_mut(&mut self) -> &mut [f64; LANES] {
                &mut self.0
            }
        }
        impl std::ops::Add for $t {
            type Output = $t;
            #[inline(always)]
            fn add(self, o: $t) -> $t {
                self.$pair(o, $add)
            }
        }
        impl std::ops::Sub for $t {
            type Output = $t;
            #[inline(always)]
            fn sub(self, o: $t) -> $t {
                self.$pair(o, $sub)
            }
        }
        impl std::ops::Mul for $t {
            type Output = $t;
            #[inline(always)]
            fn mul(self, o: $t) -> $t {
                self.$pair(o, $mul)
            }
        }
        impl std::ops::Div for $t {
            type Output = $t;
            #[inline(always)]
            fn div(self, o: $t) -> $t {
                self.$pair(o, $div)
            }
        }
    };
}

/// Whether a lane type's [`Num::mul_add`] is fused (rounds once).
pub(crate) trait Fusion {
    const FUSED: bool;
}

/// One f64 per lane: what the lockstep kernel needs beyond [`Num`]. Every operation is the same
/// IEEE operation in each lane, nothing reordered, so each lane's bits are those of the scalar
/// code in the same arithmetic: `f64` for the unfused lane types, [`Fused`] for the fused ones
/// ([`Fusion::FUSED`]), whose `mul_add` is one FMA per lane.
pub(crate) trait Lanes: Num + LaneArray + Fusion {
    /// |x| in each lane.
    fn abs(self) -> Self;
    /// `f64::max` in each lane.
    fn max(self, o: Self) -> Self;
    /// `a` in the lanes where `take` holds, else `self`.
    fn or_where(self, take: [bool; LANES], a: Self) -> Self;
    /// Whether |x| > bound in any lane.
    fn any_abs_above(self, bound: f64) -> bool;
}

/// [`Lanes`] written lane by lane, for any processor (the compiler vectorises what it can).
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(C, align(64))]
pub(crate) struct Portable(pub(crate) [f64; LANES]);

impl Portable {
    #[inline(always)]
    fn map2(self, o: Portable, f: impl Fn(f64, f64) -> f64) -> Portable {
        let (a, b) = (self.0, o.0);
        Portable(std::array::from_fn(|l| f(a[l], b[l])))
    }
}

lane_type!(
    Portable,
    map2,
    |a, b| a + b,
    |a, b| a - b,
    |a, b| a * b,
    |a, b| a / b
);

impl Lanes for Portable {
    #[inline(always)]
    fn abs(self) -> Portable {
        Portable(self.0.map(f64::abs))
    }
    #[inline(always)]
    fn max(self, o: Portable) -> Portable {
        self.map2(o, f64::max)
    }
    #[inline(always)]
    fn or_where(self, take: [bool; LANES], a: Portable) -> Portable {
        Portable(std::array::from_fn(|l| {
            if take[l] {
                a.0[l]
            } else {
                self.0[l]
            }
        }))
    }
    #[inline(always)]
    fn any_abs_above(self, bound: f64) -> bool {
        self.0.iter().any(|x| x.abs() > bound)
    }
}

impl Neg for Portable {
    type Output = Portable;
    #[inline(always)]
    fn neg(self) -> Portable {
        Portable(self.0.map(|a| -a))
    }
}

/// [`Lanes`] as AVX instructions, two per operation (four lanes each), `mul_add` fused. Values
/// of this type are made only inside the lockstep kernel compiled for AVX2 and FMA, which runs
/// only once the processor is known to have both (`numerics::cpu::Kernel`); its
/// operations are inlined there. The lanes
/// are kept in an array (no vector type crosses a function boundary compiled without AVX).
#[cfg(target_arch = "x86_64")]
pub(crate) use avx::Avx;

#[cfg(target_arch = "x86_64")]
mod avx {
    use super::{Fusion, LaneArray, Lanes, Num, LANES};
    use std::arch::x86_64::*;
    use std::ops::Neg;

    /// Four lanes in one AVX register; the type's methods hold two.
    const HALF: usize = 4;
    const _: () = assert!(LANES == 2 * HALF);

    #[derive(Debug, Clone, Copy, PartialEq)]
    #[repr(C, align(64))]
    pub(crate) struct Avx(pub(crate) [f64; LANES]);

    impl Avx {
        /// The lanes as two AVX registers (lanes 0-3, 4-7).
        #[inline(always)]
        fn get(self) -> [__m256d; 2] {
            // SAFETY: see the type's comment (the processor has AVX); the array is aligned.
            unsafe {
                [
                    _mm256_load_pd(self.0.as_ptr()),
                    _mm256_load_pd(self.0.as_ptr().add(HALF)),
                ]
            }
        }
        #[inline(always)]
        fn put(v: [__m256d; 2]) -> Avx {
            let mut out = Avx([0.0; LANES]);
            // SAFETY: as in `get`.
            unsafe {
                _mm256_store_pd(out.0.as_mut_ptr(), v[0]);
                _mm256_store_pd(out.0.as_mut_ptr().add(HALF), v[1]);
            }
            out
        }
        /// `f` on each half.
        #[inline(always)]
        fn each(self, f: impl Fn(__m256d) -> __m256d) -> Avx {
            let [a, b] = self.get();
            Avx::put([f(a), f(b)])
        }
        /// `f` on each half of the two.
        #[inline(always)]
        fn each2(self, o: Avx, f: impl Fn(__m256d, __m256d) -> __m256d) -> Avx {
            let ([a, b], [c, d]) = (self.get(), o.get());
            Avx::put([f(a, c), f(b, d)])
        }
        /// `f` on each half of the three.
        #[inline(always)]
        fn each3(self, o: Avx, p: Avx, f: impl Fn(__m256d, __m256d, __m256d) -> __m256d) -> Avx {
            let ([a, b], [c, d], [e, g]) = (self.get(), o.get(), p.get());
            Avx::put([f(a, c, e), f(b, d, g)])
        }
    }

    // SAFETY (the operations): see the type's comment; the kernel compiled for AVX2 is
    // compiled for FMA too, and runs only where the processor has both.
    lane_type!(
        Avx,
        each2,
        |a, b| unsafe { _mm256_add_pd(a, b) },
        |a, b| unsafe { _mm256_sub_pd(a, b) },
        |a, b| unsafe { _mm256_mul_pd(a, b) },
        |a, b| unsafe { _mm256_div_pd(a, b) },
        each3,
        |a, b, c| unsafe { _mm256_fmadd_pd(a, b, c) },
        |a, b, c| unsafe { _mm256_fmsub_pd(a, b, c) },
        |a, b, c| unsafe { _mm256_fnmadd_pd(a, b, c) }
    );

    impl Neg for Avx {
        type Output = Avx;
        #[inline(always)]
        fn neg(self) -> Avx {
            // SAFETY: see the type's comment. Flipping the sign bit is IEEE negation.
            self.each(|a| unsafe { _mm256_xor_pd(a, _mm256_set1_pd(-0.0)) })
        }
    }

    impl Lanes for Avx {
        #[inline(always)]
        fn abs(self) -> Avx {
            // SAFETY: see the type's comment. Clearing the sign bit is `f64::abs`.
            self.each(|a| unsafe { _mm256_andnot_pd(_mm256_set1_pd(-0.0), a) })
        }
        #[inline(always)]
        fn max(self, o: Avx) -> Avx {
            // `vmaxpd` gives its second operand when either is NaN; `f64::max` gives the other
            // operand when one is NaN: take `self` where `o` is NaN.
            // SAFETY: see the type's comment.
            self.each2(o, |a, b| unsafe {
                let m = _mm256_max_pd(a, b);
                _mm256_blendv_pd(m, a, _mm256_cmp_pd(b, b, _CMP_UNORD_Q))
            })
        }
        #[inline(always)]
        fn or_where(self, take: [bool; LANES], a: Avx) -> Avx {
            let mask = Avx(take.map(|t| if t { -0.0 } else { 0.0 }));
            let ([x, y], [p, q], [m, n]) = (self.get(), a.get(), mask.get());
            // SAFETY: see the type's comment. `blendv` picks by the mask's sign bit.
            unsafe { Avx::put([_mm256_blendv_pd(x, p, m), _mm256_blendv_pd(y, q, n)]) }
        }
        #[inline(always)]
        fn any_abs_above(self, bound: f64) -> bool {
            let [a, b] = self.abs().get();
            // SAFETY: see the type's comment.
            unsafe {
                let bound = _mm256_set1_pd(bound);
                let above = _mm256_or_pd(
                    _mm256_cmp_pd(a, bound, _CMP_GT_OQ),
                    _mm256_cmp_pd(b, bound, _CMP_GT_OQ),
                );
                _mm256_movemask_pd(above) != 0
            }
        }
    }
}

/// [`Lanes`] as AVX-512 instructions, all eight lanes in one register, `mul_add` fused: made
/// only inside the lockstep kernel compiled for AVX-512F and FMA, under the same rules as
/// [`Avx`].
#[cfg(target_arch = "x86_64")]
pub(crate) use avx512::Avx512;

#[cfg(target_arch = "x86_64")]
mod avx512 {
    use super::{Fusion, LaneArray, Lanes, Num, LANES};
    use std::arch::x86_64::*;
    use std::ops::Neg;

    // One register holds all the lanes (`get`, `put`, `mask`).
    const _: () = assert!(LANES == 8);

    #[derive(Debug, Clone, Copy, PartialEq)]
    #[repr(C, align(64))]
    pub(crate) struct Avx512(pub(crate) [f64; LANES]);

    impl Avx512 {
        #[inline(always)]
        fn get(self) -> __m512d {
            // SAFETY: see the type's comment (the processor has AVX-512F); the array is aligned.
            unsafe { _mm512_load_pd(self.0.as_ptr()) }
        }
        #[inline(always)]
        fn put(v: __m512d) -> Avx512 {
            let mut out = Avx512([0.0; LANES]);
            // SAFETY: as in `get`.
            unsafe { _mm512_store_pd(out.0.as_mut_ptr(), v) };
            out
        }
        /// `f` on the two (one register each), as `Avx::each2` on each half.
        #[inline(always)]
        fn each2(self, o: Avx512, f: impl Fn(__m512d, __m512d) -> __m512d) -> Avx512 {
            Avx512::put(f(self.get(), o.get()))
        }
        /// `f` on the three.
        #[inline(always)]
        fn each3(
            self,
            o: Avx512,
            p: Avx512,
            f: impl Fn(__m512d, __m512d, __m512d) -> __m512d,
        ) -> Avx512 {
            Avx512::put(f(self.get(), o.get(), p.get()))
        }
        /// The lanes where `take` holds, as a mask.
        #[inline(always)]
        fn mask(take: [bool; LANES]) -> __mmask8 {
            take.iter()
                .enumerate()
                .fold(0, |m, (l, &t)| m | (u8::from(t) << l))
        }
    }

    // SAFETY (the operations): see the type's comment.
    lane_type!(
        Avx512,
        each2,
        |a, b| unsafe { _mm512_add_pd(a, b) },
        |a, b| unsafe { _mm512_sub_pd(a, b) },
        |a, b| unsafe { _mm512_mul_pd(a, b) },
        |a, b| unsafe { _mm512_div_pd(a, b) },
        each3,
        |a, b, c| unsafe { _mm512_fmadd_pd(a, b, c) },
        |a, b, c| unsafe { _mm512_fmsub_pd(a, b, c) },
        |a, b, c| unsafe { _mm512_fnmadd_pd(a, b, c) }
    );

    impl Neg for Avx512 {
        type Output = Avx512;
        #[inline(always)]
        fn neg(self) -> Avx512 {
            // SAFETY: see the type's comment. Flipping the sign bit is IEEE negation (an integer
            // xor: the floating-point one needs AVX-512DQ).
            Avx512::put(unsafe {
                let sign = _mm512_set1_epi64(i64::MIN);
                _mm512_castsi512_pd(_mm512_xor_si512(_mm512_castpd_si512(self.get()), sign))
            })
        }
    }

    impl Lanes for Avx512 {
        #[inline(always)]
        fn abs(self) -> Avx512 {
            // SAFETY: see the type's comment. Clearing the sign bit is `f64::abs`.
            Avx512::put(unsafe { _mm512_abs_pd(self.get()) })
        }
        #[inline(always)]
        fn max(self, o: Avx512) -> Avx512 {
            // As `Avx::max`: `vmaxpd` gives its second operand when either is NaN, `f64::max`
            // the other operand when one is: take `self` where `o` is NaN.
            // SAFETY: see the type's comment.
            Avx512::put(unsafe {
                let (a, b) = (self.get(), o.get());
                let nan = _mm512_cmp_pd_mask::<_CMP_UNORD_Q>(b, b);
                _mm512_mask_blend_pd(nan, _mm512_max_pd(a, b), a)
            })
        }
        #[inline(always)]
        fn or_where(self, take: [bool; LANES], a: Avx512) -> Avx512 {
            // SAFETY: see the type's comment. The blend takes `a` where the mask's bit is set.
            Avx512::put(unsafe { _mm512_mask_blend_pd(Avx512::mask(take), self.get(), a.get()) })
        }
        #[inline(always)]
        fn any_abs_above(self, bound: f64) -> bool {
            // SAFETY: see the type's comment.
            unsafe {
                _mm512_cmp_pd_mask::<_CMP_GT_OQ>(self.abs().get(), _mm512_set1_pd(bound)) != 0
            }
        }
    }
}
