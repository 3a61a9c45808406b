//! The floating-point types the transforms run in: [`Real`], implemented by `f64` (the
//! default everywhere) and `f32` (the single-precision tier, about half the time and
//! memory at a relative error near `1e-6`; see `docs/precision.md`).

use crate::dwt::DwtElem;
use crate::fft::FftwApi;
pub(crate) use crate::numeric::Elem;

/// A floating-point type the library computes in: `f64` or `f32`. Sealed: the kernels,
/// the FFT stage and the recurrence's scaled form are written for these two only.
pub trait Real: Elem + FftwApi + DwtElem {}

impl Real for f64 {}
impl Real for f32 {}

#[cfg(test)]
mod tests {
    use crate::numeric::Elem;

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
