//! The floating-point types the transforms run in: [`Real`], implemented by `f64` (the
//! default everywhere) and `f32` (the single-precision tier, about half the time and
//! memory at a relative error near `1e-6`; see `docs/precision.md`).

use std::fmt::{Debug, Display};
use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// A floating-point type the library computes in: `f64` or `f32`. Sealed: the kernels,
/// the FFT stage and the recurrence's scaled form are written for these two only.
pub trait Real: private::Elem + crate::fft::FftwApi {}

impl Real for f64 {}
impl Real for f32 {}

pub(crate) use private::Elem;

mod private {
    use super::*;

    /// What the library's code needs of a floating-point type (crate-private: sealing
    /// [`Real`](super::Real)).
    pub trait Elem:
        Copy
        + Default
        + Debug
        + Display
        + PartialEq
        + PartialOrd
        + Send
        + Sync
        + 'static
        + Add<Output = Self>
        + Sub<Output = Self>
        + Mul<Output = Self>
        + Div<Output = Self>
        + Neg<Output = Self>
        + AddAssign
        + SubAssign
        + MulAssign
    {
        /// `"f64"` or `"f32"`, for messages and reports.
        const NAME: &'static str;
        /// Size in bytes.
        const BYTES: usize;
        /// `0`
        const ZERO: Self;
        /// `1`
        const ONE: Self;
        /// The smallest positive normal value.
        const MIN_POSITIVE: Self;
        /// The distance from 1 to the next larger value.
        const EPSILON: Self;
        /// Exponent step of one rescaling of the recurrence's scaled starting values
        /// (`wigner::starts`): small enough that a value scaled by `2^-step` and the skip
        /// threshold stay normal numbers of this type.
        const SCALE_STEP: i64;
        /// The largest accepted skip-threshold exponent (see `Options::skip_bits`): the
        /// scaled values `[2^(-bits-1), 2^(SCALE_STEP - bits))` stay normal.
        const MAX_SKIP_BITS: u32;
        /// The rescaling factor `2^-SCALE_STEP`.
        const TINY: Self;
        /// `x` rounded to this type (to nearest).
        fn from_f64(x: f64) -> Self;
        /// `self` as `f64` (exact).
        fn to_f64(self) -> f64;
        /// `|self|`
        fn abs(self) -> Self;
        /// Whether `self` is neither infinite nor NaN.
        fn is_finite(self) -> bool;
        /// `self * a + b` with one rounding.
        fn mul_add(self, a: Self, b: Self) -> Self;
    }

    impl Elem for f64 {
        const NAME: &'static str = "f64";
        const BYTES: usize = 8;
        const ZERO: f64 = 0.0;
        const ONE: f64 = 1.0;
        const MIN_POSITIVE: f64 = f64::MIN_POSITIVE;
        const EPSILON: f64 = f64::EPSILON;
        const SCALE_STEP: i64 = 600;
        const MAX_SKIP_BITS: u32 = 560;
        const TINY: f64 = f64::from_bits(((1023 - Self::SCALE_STEP) as u64) << 52);
        #[inline(always)]
        fn from_f64(x: f64) -> f64 {
            x
        }
        #[inline(always)]
        fn to_f64(self) -> f64 {
            self
        }
        #[inline(always)]
        fn abs(self) -> f64 {
            f64::abs(self)
        }
        #[inline(always)]
        fn is_finite(self) -> bool {
            f64::is_finite(self)
        }
        #[inline(always)]
        fn mul_add(self, a: f64, b: f64) -> f64 {
            f64::mul_add(self, a, b)
        }
    }

    impl Elem for f32 {
        const NAME: &'static str = "f32";
        const BYTES: usize = 4;
        const ZERO: f32 = 0.0;
        const ONE: f32 = 1.0;
        const MIN_POSITIVE: f32 = f32::MIN_POSITIVE;
        const EPSILON: f32 = f32::EPSILON;
        const SCALE_STEP: i64 = 96;
        const MAX_SKIP_BITS: u32 = 100;
        const TINY: f32 = f32::from_bits(((127 - Self::SCALE_STEP) as u32) << 23);
        #[inline(always)]
        fn from_f64(x: f64) -> f32 {
            x as f32
        }
        #[inline(always)]
        fn to_f64(self) -> f64 {
            self as f64
        }
        #[inline(always)]
        fn abs(self) -> f32 {
            f32::abs(self)
        }
        #[inline(always)]
        fn is_finite(self) -> bool {
            f32::is_finite(self)
        }
        #[inline(always)]
        fn mul_add(self, a: f32, b: f32) -> f32 {
            f32::mul_add(self, a, b)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Elem;

    /// The scaled form's range stays normal: the smallest scaled value `2^(-bits-1)` at
    /// the largest skip exponent and the rescale factor `2^-SCALE_STEP`.
    fn scaled_range_normal<E: Elem>() {
        let smallest = crate::numeric::ldexp(1.0, -(E::MAX_SKIP_BITS as i64) - 1);
        let tiny = crate::numeric::ldexp(1.0, -E::SCALE_STEP);
        assert_eq!(E::TINY.to_f64(), tiny);
        for x in [smallest, tiny] {
            let v = E::from_f64(x);
            assert!(v >= E::MIN_POSITIVE && v.to_f64() == x, "{} {x}", E::NAME);
        }
        // The rescale threshold 2^(SCALE_STEP - bits) at the smallest skip exponent.
        let big = crate::numeric::ldexp(1.0, E::SCALE_STEP - 24);
        assert!(E::from_f64(big).is_finite());
    }

    #[test]
    fn scaled_range() {
        scaled_range_normal::<f64>();
        scaled_range_normal::<f32>();
    }
}
