//! [`Simd`] in portable scalar code: one double per "vector", no fused multiply-add.

use super::Simd;

/// Portable scalar implementation (also the reference the SIMD paths are tested against).
#[derive(Clone, Copy)]
pub(crate) struct Scalar;

impl Simd for Scalar {
    type V = f64;
    #[inline(always)]
    unsafe fn splat(x: f64) -> f64 {
        x
    }
    #[inline(always)]
    unsafe fn load(p: *const f64) -> f64 {
        // SAFETY: the caller guarantees `p` valid for one double (the contract of `Simd`).
        unsafe { *p }
    }
    #[inline(always)]
    unsafe fn store(p: *mut f64, v: f64) {
        // SAFETY: the caller guarantees `p` valid for one double (the contract of `Simd`).
        unsafe { *p = v }
    }
    #[inline(always)]
    unsafe fn add(a: f64, b: f64) -> f64 {
        a + b
    }
    #[inline(always)]
    unsafe fn mul(a: f64, b: f64) -> f64 {
        a * b
    }
    #[inline(always)]
    unsafe fn fma(a: f64, b: f64, c: f64) -> f64 {
        a * b + c
    }
    #[inline(always)]
    unsafe fn fms(a: f64, b: f64, c: f64) -> f64 {
        a * b - c
    }
    #[inline(always)]
    unsafe fn any_ge(a: f64, b: f64) -> bool {
        a >= b
    }
    #[inline(always)]
    unsafe fn abs(v: f64) -> f64 {
        v.abs()
    }
    #[inline(always)]
    unsafe fn blend_ge(a: f64, b: f64, x: f64, y: f64) -> f64 {
        if a >= b {
            x
        } else {
            y
        }
    }
    #[inline(always)]
    unsafe fn max(a: f64, b: f64) -> f64 {
        a.max(b)
    }
    #[inline(always)]
    unsafe fn transpose(_v: &mut [f64]) {}
    // One lane has no pairs: the kernels never pair betas with `W = 1`.
    unsafe fn splat2(_p: *const f64) -> f64 {
        unreachable!("no lane pairs with W = 1")
    }
    unsafe fn unpack_even(_a: f64, _b: f64) -> f64 {
        unreachable!("no lane pairs with W = 1")
    }
    unsafe fn unpack_odd(_a: f64, _b: f64) -> f64 {
        unreachable!("no lane pairs with W = 1")
    }
}
