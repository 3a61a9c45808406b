//! [`Simd`] for AVX2 with FMA: 4 doubles per vector.

use super::Simd;
use std::arch::x86_64::*;

/// AVX2 + FMA: 4 doubles.
#[derive(Clone, Copy)]
pub(crate) struct Avx2;

impl Simd for Avx2 {
    type E = f64;
    type V = __m256d;
    const REGS: usize = 16;
    #[inline(always)]
    unsafe fn splat(x: f64) -> __m256d {
        // SAFETY: the caller guarantees AVX2 and FMA (the contract of `Simd`).
        unsafe { _mm256_set1_pd(x) }
    }
    #[inline(always)]
    unsafe fn load(p: *const f64) -> __m256d {
        // SAFETY: the caller guarantees AVX2 and FMA and that `p` is valid for 4 doubles
        // (the contract of `Simd`).
        unsafe { _mm256_loadu_pd(p) }
    }
    #[inline(always)]
    unsafe fn store(p: *mut f64, v: __m256d) {
        // SAFETY: the caller guarantees AVX2 and FMA and that `p` is valid for 4 doubles
        // (the contract of `Simd`).
        unsafe { _mm256_storeu_pd(p, v) }
    }
    #[inline(always)]
    unsafe fn add(a: __m256d, b: __m256d) -> __m256d {
        // SAFETY: the caller guarantees AVX2 and FMA (the contract of `Simd`).
        unsafe { _mm256_add_pd(a, b) }
    }
    #[inline(always)]
    unsafe fn mul(a: __m256d, b: __m256d) -> __m256d {
        // SAFETY: the caller guarantees AVX2 and FMA (the contract of `Simd`).
        unsafe { _mm256_mul_pd(a, b) }
    }
    #[inline(always)]
    unsafe fn fma(a: __m256d, b: __m256d, c: __m256d) -> __m256d {
        // SAFETY: the caller guarantees AVX2 and FMA (the contract of `Simd`).
        unsafe { _mm256_fmadd_pd(a, b, c) }
    }
    #[inline(always)]
    unsafe fn fms(a: __m256d, b: __m256d, c: __m256d) -> __m256d {
        // SAFETY: the caller guarantees AVX2 and FMA (the contract of `Simd`).
        unsafe { _mm256_fmsub_pd(a, b, c) }
    }
    #[inline]
    #[target_feature(enable = "avx")]
    unsafe fn fence(mut v: __m256d) -> __m256d {
        // SAFETY: an empty instruction sequence on a register operand.
        unsafe {
            std::arch::asm!("/* {0} */", inout(ymm_reg) v, options(nomem, nostack, preserves_flags))
        };
        v
    }
    #[inline(always)]
    unsafe fn stream(p: *mut f64, v: __m256d) {
        // SAFETY: the caller guarantees AVX2 and FMA and that `p` is valid for 4 doubles
        // (the contract of `Simd`).
        unsafe {
            if (p as usize).is_multiple_of(32) {
                _mm256_stream_pd(p, v)
            } else {
                _mm256_storeu_pd(p, v)
            }
        }
    }
    #[inline(always)]
    unsafe fn any_ge(a: __m256d, b: __m256d) -> bool {
        // SAFETY: the caller guarantees AVX2 and FMA (the contract of `Simd`).
        unsafe { _mm256_movemask_pd(_mm256_cmp_pd::<_CMP_GE_OQ>(a, b)) != 0 }
    }
    #[inline(always)]
    unsafe fn abs(v: __m256d) -> __m256d {
        // SAFETY: the caller guarantees AVX2 and FMA (the contract of `Simd`).
        unsafe { _mm256_andnot_pd(_mm256_set1_pd(-0.0), v) }
    }
    #[inline(always)]
    unsafe fn blend_ge(a: __m256d, b: __m256d, x: __m256d, y: __m256d) -> __m256d {
        // SAFETY: the caller guarantees AVX2 and FMA (the contract of `Simd`).
        unsafe { _mm256_blendv_pd(y, x, _mm256_cmp_pd::<_CMP_GE_OQ>(a, b)) }
    }
    #[inline(always)]
    unsafe fn max(a: __m256d, b: __m256d) -> __m256d {
        // SAFETY: the caller guarantees AVX2 and FMA (the contract of `Simd`).
        unsafe { _mm256_max_pd(a, b) }
    }
    #[inline(always)]
    unsafe fn splat2(p: *const f64) -> __m256d {
        // SAFETY: the caller guarantees AVX2 and FMA and that `p` is valid for 2 doubles
        // (the contract of `Simd`).
        unsafe { _mm256_broadcast_pd(&_mm_loadu_pd(p)) }
    }
    #[inline(always)]
    unsafe fn unpack_even(a: __m256d, b: __m256d) -> __m256d {
        // SAFETY: the caller guarantees AVX2 and FMA (the contract of `Simd`).
        unsafe { _mm256_unpacklo_pd(a, b) }
    }
    #[inline(always)]
    unsafe fn unpack_odd(a: __m256d, b: __m256d) -> __m256d {
        // SAFETY: the caller guarantees AVX2 and FMA (the contract of `Simd`).
        unsafe { _mm256_unpackhi_pd(a, b) }
    }
    #[inline(always)]
    unsafe fn transpose(v: &mut [__m256d]) {
        // SAFETY: the caller guarantees AVX2 and FMA (the contract of `Simd`); `v` holds
        // 4 vectors (indexing is bounds checked).
        unsafe {
            let t0 = _mm256_unpacklo_pd(v[0], v[1]); // v0[0] v1[0] v0[2] v1[2]
            let t1 = _mm256_unpackhi_pd(v[0], v[1]); // v0[1] v1[1] v0[3] v1[3]
            let t2 = _mm256_unpacklo_pd(v[2], v[3]);
            let t3 = _mm256_unpackhi_pd(v[2], v[3]);
            v[0] = _mm256_permute2f128_pd::<0x20>(t0, t2);
            v[1] = _mm256_permute2f128_pd::<0x20>(t1, t3);
            v[2] = _mm256_permute2f128_pd::<0x31>(t0, t2);
            v[3] = _mm256_permute2f128_pd::<0x31>(t1, t3);
        }
    }
}
