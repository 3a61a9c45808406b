//! [`Simd`] in portable scalar code: one element per "vector", no fused multiply-add.

use super::Simd;
use crate::numeric::Elem;
use std::marker::PhantomData;

/// Portable scalar implementation for elements `E` (also the reference the SIMD paths are
/// tested against).
#[derive(Clone, Copy)]
pub(crate) struct Scalar<E = f64>(PhantomData<E>);

impl<E: Elem> Simd for Scalar<E> {
    type E = E;
    type V = E;
    // Scalar code keeps the kernels' register-hungry shapes (as with AVX-512).
    const REGS: usize = 32;
    #[inline(always)]
    unsafe fn splat(x: E) -> E {
        x
    }
    #[inline(always)]
    unsafe fn load(p: *const E) -> E {
        // SAFETY: the caller guarantees `p` valid for one element (the contract of `Simd`).
        unsafe { *p }
    }
    #[inline(always)]
    unsafe fn store(p: *mut E, v: E) {
        // SAFETY: the caller guarantees `p` valid for one element (the contract of `Simd`).
        unsafe { *p = v }
    }
    #[inline(always)]
    unsafe fn add(a: E, b: E) -> E {
        a + b
    }
    #[inline(always)]
    unsafe fn mul(a: E, b: E) -> E {
        a * b
    }
    #[inline(always)]
    unsafe fn fma(a: E, b: E, c: E) -> E {
        a * b + c
    }
    #[inline(always)]
    unsafe fn fms(a: E, b: E, c: E) -> E {
        a * b - c
    }
    #[inline(always)]
    unsafe fn any_ge(a: E, b: E) -> bool {
        a >= b
    }
    #[inline(always)]
    unsafe fn abs(v: E) -> E {
        v.abs()
    }
    #[inline(always)]
    unsafe fn blend_ge(a: E, b: E, x: E, y: E) -> E {
        if a >= b {
            x
        } else {
            y
        }
    }
    #[inline(always)]
    unsafe fn max(a: E, b: E) -> E {
        // As `f64::max` for the kernels' operands (never NaN).
        if a >= b {
            a
        } else {
            b
        }
    }
    #[inline(always)]
    unsafe fn transpose(_v: &mut [E]) {}
    // One lane has no pairs: the kernels never pair betas with `W = 1`.
    unsafe fn splat2(_p: *const E) -> E {
        unreachable!("no lane pairs with W = 1")
    }
    unsafe fn unpack_even(_a: E, _b: E) -> E {
        unreachable!("no lane pairs with W = 1")
    }
    unsafe fn unpack_odd(_a: E, _b: E) -> E {
        unreachable!("no lane pairs with W = 1")
    }
}

/// [`Scalar`] on floats.
pub(crate) type ScalarF32 = Scalar<f32>;
