//! The two precisions the suite runs every test in: [`Precision`] names a row's, [`Float`]
//! is what the tests need of the element type beyond `so3fft::Real` (conversions to and
//! from `f64`, bits, the exponents of the scaling and subnormal tests).
//!
//! The tests build their inputs and truths in `f64` and round the inputs to the plan's type
//! once ([`narrow`]); outputs are widened to `f64` ([`widen`], exact) before any error is
//! measured, so one body of code measures both precisions.

use crate::rng::SplitMix64;
use so3fft::{Complex, Complex64};

/// The element type of a row's transforms.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, clap::ValueEnum)]
pub enum Precision {
    /// Double precision (`Plan<f64>`, the default of every plan).
    F64,
    /// Single precision (`Plan<f32>`).
    F32,
}

impl Precision {
    /// Both, in the order the suite runs them.
    pub const ALL: [Precision; 2] = [Precision::F64, Precision::F32];

    /// `"f64"` or `"f32"` (the CSV column).
    pub fn name(self) -> &'static str {
        match self {
            Precision::F64 => "f64",
            Precision::F32 => "f32",
        }
    }

    /// The precision named `text` (as [`Precision::name`] writes it).
    pub fn parse(text: &str) -> Option<Precision> {
        Precision::ALL.into_iter().find(|p| p.name() == text.trim())
    }

    /// Powers of two of the scaling test: `+-1`, about a tenth of the exponent range,
    /// and near both ends of it (`f64`: 1022, `f32`: 126).
    pub fn scale_exponents(self) -> [i32; 8] {
        match self {
            Precision::F64 => [1, -1, 100, -100, 900, -900, 1000, -1000],
            Precision::F32 => [1, -1, 12, -12, 100, -100, 120, -120],
        }
    }

    /// The exponents of [`Precision::scale_exponents`] that keep every term of the
    /// transforms normal (every value `2^k` times the smallest term that enters, the data
    /// times the skip threshold `2^-64`, and `2^k` times the largest output): the
    /// scaling target covers these; the others are reported only.
    pub fn scale_in_range(self, k: i32) -> bool {
        match self {
            Precision::F64 => [1, -1, 100, -100, 900].contains(&k),
            Precision::F32 => [1, -1, 12, -12, 100].contains(&k),
        }
    }

    /// Exponent of the subnormal inputs: random values in `[-1, 1)` times `2^e` are
    /// subnormal and keep about a third to a half of their bits (`f64`: `2^-1040`, about
    /// 34 of 53; `f32`: `2^-136`, about 13 of 24).
    pub fn subnormal_exponent(self) -> i32 {
        match self {
            Precision::F64 => -1040,
            Precision::F32 => -136,
        }
    }
}

impl std::fmt::Display for Precision {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// An element type of the library's plans, as the suite uses it.
pub trait Float: so3fft::Real {
    /// Which one.
    const PRECISION: Precision;
    /// `x` rounded to nearest.
    fn narrowed(x: f64) -> Self;
    /// The value as `f64` (exact).
    fn widened(self) -> f64;
    /// The bit pattern, zero-extended.
    fn bit_pattern(self) -> u64;
}

impl Float for f64 {
    const PRECISION: Precision = Precision::F64;
    fn narrowed(x: f64) -> f64 {
        x
    }
    fn widened(self) -> f64 {
        self
    }
    fn bit_pattern(self) -> u64 {
        self.to_bits()
    }
}

impl Float for f32 {
    const PRECISION: Precision = Precision::F32;
    fn narrowed(x: f64) -> f32 {
        x as f32
    }
    fn widened(self) -> f64 {
        f64::from(self)
    }
    fn bit_pattern(self) -> u64 {
        u64::from(self.to_bits())
    }
}

/// `2^k` exactly, for `-1074 <= k <= 1023` (`powi` with a negative exponent computed at
/// run time takes the reciprocal of `2^-k`, which overflows below `2^-1023`).
pub fn pow2(k: i32) -> f64 {
    assert!((-1074..=1023).contains(&k), "2^{k} is not a double");
    if k >= -1022 {
        f64::from_bits(((k + 1023) as u64) << 52)
    } else {
        // Subnormal: the product of two normal powers is exact.
        pow2(k + 200) * pow2(-200)
    }
}

/// `0` of `T`.
pub fn zero<T: Float>() -> Complex<T> {
    Complex::new(T::narrowed(0.0), T::narrowed(0.0))
}

/// `z` rounded to `T`.
pub fn narrow_one<T: Float>(z: Complex64) -> Complex<T> {
    Complex::new(T::narrowed(z.re), T::narrowed(z.im))
}

/// `z` as `f64` (exact).
pub fn widen_one<T: Float>(z: Complex<T>) -> Complex64 {
    Complex64::new(z.re.widened(), z.im.widened())
}

/// Every value rounded to `T`.
pub fn narrow<T: Float>(v: &[Complex64]) -> Vec<Complex<T>> {
    v.iter().map(|&z| narrow_one(z)).collect()
}

/// Every value as `f64` (exact).
pub fn widen<T: Float>(v: &[Complex<T>]) -> Vec<Complex64> {
    v.iter().map(|&z| widen_one(z)).collect()
}

/// `n` random complex values of the generator (as [`SplitMix64::complex_vec`]), rounded to
/// `T` (the same values for `f64`).
pub fn random<T: Float>(rng: &mut SplitMix64, n: usize) -> Vec<Complex<T>> {
    (0..n).map(|_| narrow_one(rng.complex())).collect()
}

#[cfg(test)]
mod tests {
    use super::{narrow, pow2, widen, Float, Precision};
    use so3fft::Complex64;

    /// Names round-trip; narrowing rounds to nearest and widening is exact.
    #[test]
    fn names_and_conversions() {
        for p in Precision::ALL {
            assert_eq!(Precision::parse(p.name()), Some(p));
        }
        assert_eq!(Precision::parse("f16"), None);
        let x = 1.0 + f64::EPSILON;
        assert_eq!(f32::narrowed(x), 1.0f32);
        assert_eq!(f64::narrowed(x), x);
        let v = [Complex64::new(0.1, -3.0)];
        let w = widen(&narrow::<f32>(&v));
        assert_eq!(w[0].re, f64::from(0.1f32));
        assert_eq!(w[0].im, -3.0);
        assert_eq!(1.5f32.bit_pattern(), u64::from(1.5f32.to_bits()));
        assert_eq!(pow2(0), 1.0);
        assert_eq!(pow2(-1), 0.5);
        assert_eq!(pow2(1023), f64::MAX / (2.0 - f64::EPSILON));
        assert_eq!(pow2(-1040) * pow2(520) * pow2(520), 1.0);
        assert_eq!(pow2(-1074), f64::from_bits(1));
        // Every exponent the target covers is one the test runs.
        for p in Precision::ALL {
            let run = p.scale_exponents();
            assert!((-1100..1100).all(|k| !p.scale_in_range(k) || run.contains(&k)));
        }
    }
}
