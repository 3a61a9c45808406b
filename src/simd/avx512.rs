//! [`Simd`] for AVX-512F: 8 doubles per vector.

use super::Simd;
use std::arch::x86_64::*;

/// AVX-512F: 8 doubles.
#[derive(Clone, Copy)]
pub(crate) struct Avx512;

impl Simd for Avx512 {
    type E = f64;
    type V = __m512d;
    const GROUP_8: usize = 2;
    const GROUP_16: usize = 1;
    const REGS: usize = 32;
    #[inline(always)]
    unsafe fn splat(x: f64) -> __m512d {
        // SAFETY: the caller guarantees AVX-512F (the contract of `Simd`).
        unsafe { _mm512_set1_pd(x) }
    }
    #[inline(always)]
    unsafe fn load(p: *const f64) -> __m512d {
        // SAFETY: the caller guarantees AVX-512F and that `p` is valid for 8 doubles
        // (the contract of `Simd`).
        unsafe { _mm512_loadu_pd(p) }
    }
    #[inline(always)]
    unsafe fn store(p: *mut f64, v: __m512d) {
        // SAFETY: the caller guarantees AVX-512F and that `p` is valid for 8 doubles
        // (the contract of `Simd`).
        unsafe { _mm512_storeu_pd(p, v) }
    }
    #[inline(always)]
    unsafe fn add(a: __m512d, b: __m512d) -> __m512d {
        // SAFETY: the caller guarantees AVX-512F (the contract of `Simd`).
        unsafe { _mm512_add_pd(a, b) }
    }
    #[inline(always)]
    unsafe fn mul(a: __m512d, b: __m512d) -> __m512d {
        // SAFETY: the caller guarantees AVX-512F (the contract of `Simd`).
        unsafe { _mm512_mul_pd(a, b) }
    }
    #[inline(always)]
    unsafe fn fma(a: __m512d, b: __m512d, c: __m512d) -> __m512d {
        // SAFETY: the caller guarantees AVX-512F (the contract of `Simd`).
        unsafe { _mm512_fmadd_pd(a, b, c) }
    }
    #[inline(always)]
    unsafe fn fms(a: __m512d, b: __m512d, c: __m512d) -> __m512d {
        // SAFETY: the caller guarantees AVX-512F (the contract of `Simd`).
        unsafe { _mm512_fmsub_pd(a, b, c) }
    }
    #[inline]
    #[target_feature(enable = "avx512f")]
    unsafe fn fence(mut v: __m512d) -> __m512d {
        // SAFETY: an empty instruction sequence on a register operand.
        unsafe {
            std::arch::asm!("/* {0} */", inout(zmm_reg) v, options(nomem, nostack, preserves_flags))
        };
        v
    }
    #[inline(always)]
    unsafe fn stream(p: *mut f64, v: __m512d) {
        // SAFETY: the caller guarantees AVX-512F and that `p` is valid for 8 doubles
        // (the contract of `Simd`).
        unsafe {
            if (p as usize).is_multiple_of(64) {
                _mm512_stream_pd(p, v)
            } else {
                _mm512_storeu_pd(p, v)
            }
        }
    }
    #[inline(always)]
    unsafe fn any_ge(a: __m512d, b: __m512d) -> bool {
        // SAFETY: the caller guarantees AVX-512F (the contract of `Simd`).
        unsafe { _mm512_cmp_pd_mask::<_CMP_GE_OQ>(a, b) != 0 }
    }
    #[inline(always)]
    unsafe fn abs(v: __m512d) -> __m512d {
        // SAFETY: the caller guarantees AVX-512F (the contract of `Simd`).
        unsafe { _mm512_abs_pd(v) }
    }
    #[inline(always)]
    unsafe fn blend_ge(a: __m512d, b: __m512d, x: __m512d, y: __m512d) -> __m512d {
        // SAFETY: the caller guarantees AVX-512F (the contract of `Simd`).
        unsafe { _mm512_mask_blend_pd(_mm512_cmp_pd_mask::<_CMP_GE_OQ>(a, b), y, x) }
    }
    #[inline(always)]
    unsafe fn max(a: __m512d, b: __m512d) -> __m512d {
        // SAFETY: the caller guarantees AVX-512F (the contract of `Simd`).
        unsafe { _mm512_max_pd(a, b) }
    }
    #[inline(always)]
    unsafe fn splat2(p: *const f64) -> __m512d {
        // SAFETY: the caller guarantees AVX-512F and that `p` is valid for 2 doubles
        // (the contract of `Simd`).
        unsafe {
            // vbroadcastf32x4 moves the same 128 bits and needs only AVX-512F (f64x2 is DQ).
            _mm512_castps_pd(_mm512_broadcast_f32x4(_mm_castpd_ps(_mm_loadu_pd(p))))
        }
    }
    #[inline(always)]
    unsafe fn unpack_even(a: __m512d, b: __m512d) -> __m512d {
        // SAFETY: the caller guarantees AVX-512F (the contract of `Simd`).
        unsafe { _mm512_unpacklo_pd(a, b) }
    }
    #[inline(always)]
    unsafe fn unpack_odd(a: __m512d, b: __m512d) -> __m512d {
        // SAFETY: the caller guarantees AVX-512F (the contract of `Simd`).
        unsafe { _mm512_unpackhi_pd(a, b) }
    }
    #[inline(always)]
    unsafe fn transpose(v: &mut [__m512d]) {
        // SAFETY: the caller guarantees AVX-512F (the contract of `Simd`); `v` holds
        // 8 vectors (indexing is bounds checked).
        unsafe {
            // 8 x 8: pairs of rows interleaved, then 2 x 2 blocks of 128 bits, then 4 x 4
            // blocks of 128 bits.
            let t: [__m512d; 8] = [
                _mm512_unpacklo_pd(v[0], v[1]),
                _mm512_unpackhi_pd(v[0], v[1]),
                _mm512_unpacklo_pd(v[2], v[3]),
                _mm512_unpackhi_pd(v[2], v[3]),
                _mm512_unpacklo_pd(v[4], v[5]),
                _mm512_unpackhi_pd(v[4], v[5]),
                _mm512_unpacklo_pd(v[6], v[7]),
                _mm512_unpackhi_pd(v[6], v[7]),
            ];
            let even = _mm512_set_epi64(13, 12, 5, 4, 9, 8, 1, 0);
            let odd = _mm512_set_epi64(15, 14, 7, 6, 11, 10, 3, 2);
            // u[0]: lanes 0 and 4 of rows 0..4; u[1]: lanes 2, 6; u[2]: 1, 5; u[3]: 3, 7.
            let u = [
                _mm512_permutex2var_pd(t[0], even, t[2]),
                _mm512_permutex2var_pd(t[0], odd, t[2]),
                _mm512_permutex2var_pd(t[1], even, t[3]),
                _mm512_permutex2var_pd(t[1], odd, t[3]),
            ];
            let w = [
                _mm512_permutex2var_pd(t[4], even, t[6]),
                _mm512_permutex2var_pd(t[4], odd, t[6]),
                _mm512_permutex2var_pd(t[5], even, t[7]),
                _mm512_permutex2var_pd(t[5], odd, t[7]),
            ];
            // Lane order of u: 0, 2, 1, 3 (and +4 in the upper halves).
            for (i, lane) in [0usize, 2, 1, 3].into_iter().enumerate() {
                v[lane] = _mm512_shuffle_f64x2::<0x44>(u[i], w[i]);
                v[lane + 4] = _mm512_shuffle_f64x2::<0xEE>(u[i], w[i]);
            }
        }
    }
}
