//! [`Simd`] for AVX2 with FMA on floats: 8 per vector (also the 8-column float kernels
//! of AVX-512 hosts).

use super::Simd;
use std::arch::x86_64::*;

/// AVX2 + FMA: 8 floats.
#[derive(Clone, Copy)]
pub(crate) struct Avx2F32;

impl Simd for Avx2F32 {
    type E = f32;
    type V = __m256;
    const GROUP_8: usize = 2;
    const GROUP_16: usize = 1;
    const REGS: usize = 16;
    #[inline(always)]
    unsafe fn splat(x: f32) -> __m256 {
        // SAFETY: the caller guarantees AVX2 and FMA (the contract of `Simd`).
        unsafe { _mm256_set1_ps(x) }
    }
    #[inline(always)]
    unsafe fn load(p: *const f32) -> __m256 {
        // SAFETY: the caller guarantees AVX2 and FMA and that `p` is valid for 8 floats
        // (the contract of `Simd`).
        unsafe { _mm256_loadu_ps(p) }
    }
    #[inline(always)]
    unsafe fn store(p: *mut f32, v: __m256) {
        // SAFETY: the caller guarantees AVX2 and FMA and that `p` is valid for 8 floats
        // (the contract of `Simd`).
        unsafe { _mm256_storeu_ps(p, v) }
    }
    #[inline(always)]
    unsafe fn add(a: __m256, b: __m256) -> __m256 {
        // SAFETY: the caller guarantees AVX2 and FMA (the contract of `Simd`).
        unsafe { _mm256_add_ps(a, b) }
    }
    #[inline(always)]
    unsafe fn mul(a: __m256, b: __m256) -> __m256 {
        // SAFETY: the caller guarantees AVX2 and FMA (the contract of `Simd`).
        unsafe { _mm256_mul_ps(a, b) }
    }
    #[inline(always)]
    unsafe fn fma(a: __m256, b: __m256, c: __m256) -> __m256 {
        // SAFETY: the caller guarantees AVX2 and FMA (the contract of `Simd`).
        unsafe { _mm256_fmadd_ps(a, b, c) }
    }
    #[inline(always)]
    unsafe fn fms(a: __m256, b: __m256, c: __m256) -> __m256 {
        // SAFETY: the caller guarantees AVX2 and FMA (the contract of `Simd`).
        unsafe { _mm256_fmsub_ps(a, b, c) }
    }
    #[inline]
    #[target_feature(enable = "avx")]
    unsafe fn fence(mut v: __m256) -> __m256 {
        // SAFETY: an empty instruction sequence on a register operand.
        unsafe {
            std::arch::asm!("/* {0} */", inout(ymm_reg) v, options(nomem, nostack, preserves_flags))
        };
        v
    }
    #[inline(always)]
    unsafe fn stream(p: *mut f32, v: __m256) {
        // SAFETY: the caller guarantees AVX2 and FMA and that `p` is valid for 8 floats
        // (the contract of `Simd`).
        unsafe {
            if (p as usize).is_multiple_of(32) {
                _mm256_stream_ps(p, v)
            } else {
                _mm256_storeu_ps(p, v)
            }
        }
    }
    #[inline(always)]
    unsafe fn any_ge(a: __m256, b: __m256) -> bool {
        // SAFETY: the caller guarantees AVX2 and FMA (the contract of `Simd`).
        unsafe { _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_GE_OQ>(a, b)) != 0 }
    }
    #[inline(always)]
    unsafe fn abs(v: __m256) -> __m256 {
        // SAFETY: the caller guarantees AVX2 and FMA (the contract of `Simd`).
        unsafe { _mm256_andnot_ps(_mm256_set1_ps(-0.0), v) }
    }
    #[inline(always)]
    unsafe fn blend_ge(a: __m256, b: __m256, x: __m256, y: __m256) -> __m256 {
        // SAFETY: the caller guarantees AVX2 and FMA (the contract of `Simd`).
        unsafe { _mm256_blendv_ps(y, x, _mm256_cmp_ps::<_CMP_GE_OQ>(a, b)) }
    }
    #[inline(always)]
    unsafe fn max(a: __m256, b: __m256) -> __m256 {
        // SAFETY: the caller guarantees AVX2 and FMA (the contract of `Simd`).
        unsafe { _mm256_max_ps(a, b) }
    }
    #[inline(always)]
    unsafe fn splat2(p: *const f32) -> __m256 {
        // SAFETY: the caller guarantees AVX2 and FMA and that `p` is valid for 2 floats
        // (the contract of `Simd`); `_mm_load_sd` reads those 8 bytes without alignment.
        unsafe { _mm256_castpd_ps(_mm256_broadcastsd_pd(_mm_load_sd(p as *const f64))) }
    }
    #[inline(always)]
    unsafe fn unpack_even(a: __m256, b: __m256) -> __m256 {
        // SAFETY: the caller guarantees AVX2 and FMA (the contract of `Simd`).
        unsafe { _mm256_blend_ps::<0xAA>(a, _mm256_moveldup_ps(b)) }
    }
    #[inline(always)]
    unsafe fn unpack_odd(a: __m256, b: __m256) -> __m256 {
        // SAFETY: the caller guarantees AVX2 and FMA (the contract of `Simd`).
        unsafe { _mm256_blend_ps::<0xAA>(_mm256_movehdup_ps(a), b) }
    }
    #[inline(always)]
    unsafe fn transpose(v: &mut [__m256]) {
        // SAFETY: the caller guarantees AVX2 and FMA (the contract of `Simd`); `v` holds
        // 8 vectors (indexing is bounds checked).
        unsafe {
            // Within each 128-bit lane j: `u[g][e]` holds column 4j + e of rows 4g .. 4g + 4.
            let mut u = [[_mm256_setzero_ps(); 4]; 2];
            for (g, ug) in u.iter_mut().enumerate() {
                let r = 4 * g;
                let t0 = _mm256_castps_pd(_mm256_unpacklo_ps(v[r], v[r + 1]));
                let t1 = _mm256_castps_pd(_mm256_unpackhi_ps(v[r], v[r + 1]));
                let t2 = _mm256_castps_pd(_mm256_unpacklo_ps(v[r + 2], v[r + 3]));
                let t3 = _mm256_castps_pd(_mm256_unpackhi_ps(v[r + 2], v[r + 3]));
                ug[0] = _mm256_castpd_ps(_mm256_unpacklo_pd(t0, t2));
                ug[1] = _mm256_castpd_ps(_mm256_unpackhi_pd(t0, t2));
                ug[2] = _mm256_castpd_ps(_mm256_unpacklo_pd(t1, t3));
                ug[3] = _mm256_castpd_ps(_mm256_unpackhi_pd(t1, t3));
            }
            for e in 0..4 {
                v[e] = _mm256_permute2f128_ps::<0x20>(u[0][e], u[1][e]);
                v[4 + e] = _mm256_permute2f128_ps::<0x31>(u[0][e], u[1][e]);
            }
        }
    }
}
