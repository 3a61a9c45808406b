//! [`Simd`] for AVX-512F on floats: 16 per vector.

use super::Simd;
use std::arch::x86_64::*;

/// AVX-512F: 16 floats.
#[derive(Clone, Copy)]
pub(crate) struct Avx512F32;

impl Simd for Avx512F32 {
    type E = f32;
    type V = __m512;
    const GROUP_8: usize = 4;
    const GROUP_16: usize = 2;
    const REGS: usize = 32;
    #[inline(always)]
    unsafe fn splat(x: f32) -> __m512 {
        // SAFETY: the caller guarantees AVX-512F (the contract of `Simd`).
        unsafe { _mm512_set1_ps(x) }
    }
    #[inline(always)]
    unsafe fn load(p: *const f32) -> __m512 {
        // SAFETY: the caller guarantees AVX-512F and that `p` is valid for 16 floats
        // (the contract of `Simd`).
        unsafe { _mm512_loadu_ps(p) }
    }
    #[inline(always)]
    unsafe fn store(p: *mut f32, v: __m512) {
        // SAFETY: the caller guarantees AVX-512F and that `p` is valid for 16 floats
        // (the contract of `Simd`).
        unsafe { _mm512_storeu_ps(p, v) }
    }
    #[inline(always)]
    unsafe fn add(a: __m512, b: __m512) -> __m512 {
        // SAFETY: the caller guarantees AVX-512F (the contract of `Simd`).
        unsafe { _mm512_add_ps(a, b) }
    }
    #[inline(always)]
    unsafe fn mul(a: __m512, b: __m512) -> __m512 {
        // SAFETY: the caller guarantees AVX-512F (the contract of `Simd`).
        unsafe { _mm512_mul_ps(a, b) }
    }
    #[inline(always)]
    unsafe fn fma(a: __m512, b: __m512, c: __m512) -> __m512 {
        // SAFETY: the caller guarantees AVX-512F (the contract of `Simd`).
        unsafe { _mm512_fmadd_ps(a, b, c) }
    }
    #[inline(always)]
    unsafe fn fms(a: __m512, b: __m512, c: __m512) -> __m512 {
        // SAFETY: the caller guarantees AVX-512F (the contract of `Simd`).
        unsafe { _mm512_fmsub_ps(a, b, c) }
    }
    #[inline]
    #[target_feature(enable = "avx512f")]
    unsafe fn fence(mut v: __m512) -> __m512 {
        // SAFETY: an empty instruction sequence on a register operand.
        unsafe {
            std::arch::asm!("/* {0} */", inout(zmm_reg) v, options(nomem, nostack, preserves_flags))
        };
        v
    }
    #[inline(always)]
    unsafe fn stream(p: *mut f32, v: __m512) {
        // SAFETY: the caller guarantees AVX-512F and that `p` is valid for 16 floats
        // (the contract of `Simd`).
        unsafe {
            if (p as usize).is_multiple_of(64) {
                _mm512_stream_ps(p, v)
            } else {
                _mm512_storeu_ps(p, v)
            }
        }
    }
    #[inline(always)]
    unsafe fn any_ge(a: __m512, b: __m512) -> bool {
        // SAFETY: the caller guarantees AVX-512F (the contract of `Simd`).
        unsafe { _mm512_cmp_ps_mask::<_CMP_GE_OQ>(a, b) != 0 }
    }
    #[inline(always)]
    unsafe fn abs(v: __m512) -> __m512 {
        // SAFETY: the caller guarantees AVX-512F (the contract of `Simd`).
        unsafe { _mm512_abs_ps(v) }
    }
    #[inline(always)]
    unsafe fn blend_ge(a: __m512, b: __m512, x: __m512, y: __m512) -> __m512 {
        // SAFETY: the caller guarantees AVX-512F (the contract of `Simd`).
        unsafe { _mm512_mask_blend_ps(_mm512_cmp_ps_mask::<_CMP_GE_OQ>(a, b), y, x) }
    }
    #[inline(always)]
    unsafe fn max(a: __m512, b: __m512) -> __m512 {
        // SAFETY: the caller guarantees AVX-512F (the contract of `Simd`).
        unsafe { _mm512_max_ps(a, b) }
    }
    #[inline(always)]
    unsafe fn splat2(p: *const f32) -> __m512 {
        // SAFETY: the caller guarantees AVX-512F and that `p` is valid for 2 floats (the
        // contract of `Simd`); `_mm_load_sd` reads those 8 bytes without alignment.
        unsafe { _mm512_castpd_ps(_mm512_broadcastsd_pd(_mm_load_sd(p as *const f64))) }
    }
    #[inline(always)]
    unsafe fn unpack_even(a: __m512, b: __m512) -> __m512 {
        // SAFETY: the caller guarantees AVX-512F (the contract of `Simd`).
        unsafe { _mm512_mask_blend_ps(0xAAAA, a, _mm512_moveldup_ps(b)) }
    }
    #[inline(always)]
    unsafe fn unpack_odd(a: __m512, b: __m512) -> __m512 {
        // SAFETY: the caller guarantees AVX-512F (the contract of `Simd`).
        unsafe { _mm512_mask_blend_ps(0xAAAA, _mm512_movehdup_ps(a), b) }
    }
    #[inline(always)]
    unsafe fn splat_group<const P: usize>(p: *const f32) -> __m512 {
        // SAFETY: the caller guarantees AVX-512F and `p` valid for the group's values (the
        // contract of `Simd`).
        unsafe {
            if P == 8 {
                // Four values, one 128-bit broadcast.
                _mm512_broadcast_f32x4(_mm_loadu_ps(p))
            } else {
                Self::splat2(p)
            }
        }
    }
    #[inline(always)]
    unsafe fn group_rows<const P: usize>(x: *const f32, stride: usize) -> [__m512; 2] {
        // SAFETY: the caller guarantees AVX-512F and the group's rows valid for `P` values
        // each (the contract of `Simd`).
        unsafe {
            if P != 8 {
                let (a, b) = (Self::load(x), Self::load(x.add(stride)));
                return [Self::unpack_even(a, b), Self::unpack_odd(a, b)];
            }
            // Rows r0..r4 of 8 values: lane 4g + b of the first vector holds r_b[g], of the
            // second r_b[4 + g] (columns 0..4 and 4..8, beta b of the group).
            let row = |b: usize| _mm256_castps_pd(_mm256_loadu_ps(x.add(b * stride)));
            let join = |lo: __m256d, hi: __m256d| {
                _mm512_castpd_ps(_mm512_insertf64x4::<1>(_mm512_castpd256_pd512(lo), hi))
            };
            let (r01, r23) = (join(row(0), row(1)), join(row(2), row(3)));
            // Indices into (r01, r23): r_b[c] is at 8 b + c.
            let lo = _mm512_set_epi32(27, 19, 11, 3, 26, 18, 10, 2, 25, 17, 9, 1, 24, 16, 8, 0);
            let hi = _mm512_set_epi32(31, 23, 15, 7, 30, 22, 14, 6, 29, 21, 13, 5, 28, 20, 12, 4);
            [
                _mm512_permutex2var_ps(r01, lo, r23),
                _mm512_permutex2var_ps(r01, hi, r23),
            ]
        }
    }
    #[inline(always)]
    unsafe fn fold_group<const P: usize>(a: __m512, b: __m512) -> __m512 {
        // SAFETY: the caller guarantees AVX-512F (the contract of `Simd`).
        unsafe {
            if P != 8 {
                return Self::add(Self::unpack_even(a, b), Self::unpack_odd(a, b));
            }
            // Per 128-bit chunk g: [a0, a1, b0, b1] + [a2, a3, b2, b3], then the pairs
            // added: lane 4g holds column g's sum, lane 4g + 2 column 4 + g's.
            let s = _mm512_add_ps(
                _mm512_shuffle_ps::<0x44>(a, b),
                _mm512_shuffle_ps::<0xEE>(a, b),
            );
            let u = _mm512_add_ps(s, _mm512_permute_ps::<0xB1>(s));
            let order = _mm512_set_epi32(0, 0, 0, 0, 0, 0, 0, 0, 14, 10, 6, 2, 12, 8, 4, 0);
            _mm512_permutexvar_ps(order, u)
        }
    }
    #[inline(always)]
    unsafe fn store_first(p: *mut f32, v: __m512, k: usize) {
        // SAFETY: the caller guarantees AVX-512F and `p` valid for `k <= 16` floats (the
        // contract of `Simd`); masked-off lanes are not written.
        unsafe {
            if k == 8 {
                _mm256_storeu_ps(p, _mm512_castps512_ps256(v))
            } else {
                _mm512_mask_storeu_ps(p, ((1u32 << k) - 1) as __mmask16, v)
            }
        }
    }
    #[inline(always)]
    unsafe fn transpose(v: &mut [__m512]) {
        // SAFETY: the caller guarantees AVX-512F (the contract of `Simd`); `v` holds
        // 16 vectors (indexing is bounds checked).
        unsafe {
            // Within each 128-bit lane j: rows interleaved in pairs, then in fours, so that
            // `u[g][e]` holds in lane j column 4j + e of rows 4g .. 4g + 4.
            let mut u = [[_mm512_setzero_ps(); 4]; 4];
            for (g, ug) in u.iter_mut().enumerate() {
                let r = 4 * g;
                let t0 = _mm512_castps_pd(_mm512_unpacklo_ps(v[r], v[r + 1]));
                let t1 = _mm512_castps_pd(_mm512_unpackhi_ps(v[r], v[r + 1]));
                let t2 = _mm512_castps_pd(_mm512_unpacklo_ps(v[r + 2], v[r + 3]));
                let t3 = _mm512_castps_pd(_mm512_unpackhi_ps(v[r + 2], v[r + 3]));
                ug[0] = _mm512_castpd_ps(_mm512_unpacklo_pd(t0, t2));
                ug[1] = _mm512_castpd_ps(_mm512_unpackhi_pd(t0, t2));
                ug[2] = _mm512_castpd_ps(_mm512_unpacklo_pd(t1, t3));
                ug[3] = _mm512_castpd_ps(_mm512_unpackhi_pd(t1, t3));
            }
            // Row 4j + e gathers lane j of u[0][e] .. u[3][e].
            for e in 0..4 {
                let x = _mm512_shuffle_f32x4::<0x44>(u[0][e], u[1][e]);
                let y = _mm512_shuffle_f32x4::<0xEE>(u[0][e], u[1][e]);
                let z = _mm512_shuffle_f32x4::<0x44>(u[2][e], u[3][e]);
                let w = _mm512_shuffle_f32x4::<0xEE>(u[2][e], u[3][e]);
                v[e] = _mm512_shuffle_f32x4::<0x88>(x, z);
                v[4 + e] = _mm512_shuffle_f32x4::<0xDD>(x, z);
                v[8 + e] = _mm512_shuffle_f32x4::<0x88>(y, w);
                v[12 + e] = _mm512_shuffle_f32x4::<0xDD>(y, w);
            }
        }
    }
}
