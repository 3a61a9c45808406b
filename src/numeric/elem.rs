//! [`Elem`]: what the library's code needs of a floating-point type (`f64`, `f32`).

use std::fmt::{Debug, Display};
use std::ops::{Add, AddAssign, Div, Mul, MulAssign, Neg, Sub, SubAssign};

/// What the library's code needs of a floating-point type (crate-private, so it seals
/// the public `Real`).
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
