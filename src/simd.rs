//! Minimal SIMD abstraction with run-time dispatch (AVX-512, AVX2+FMA, portable scalar).
//!
//! Kernels are written once, generic over [`Simd`], and instantiated inside
//! `#[target_feature]` entry points (see `dwt.rs`): every method here is
//! `#[inline(always)]`, so after inlining the intrinsics sit in a function that
//! has the features enabled.

/// Instruction set chosen for the DWT kernels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Isa {
    /// AVX-512F, 8 doubles per vector.
    Avx512,
    /// AVX2 with FMA, 4 doubles per vector.
    Avx2,
    /// Portable scalar code (one double per "vector", no FMA).
    Scalar,
}

impl Isa {
    /// The best instruction set this CPU supports.
    pub fn detect() -> Isa {
        #[cfg(target_arch = "x86_64")]
        {
            if std::arch::is_x86_feature_detected!("avx512f")
                && std::arch::is_x86_feature_detected!("fma")
            {
                return Isa::Avx512;
            }
            if std::arch::is_x86_feature_detected!("avx2")
                && std::arch::is_x86_feature_detected!("fma")
            {
                return Isa::Avx2;
            }
        }
        Isa::Scalar
    }

    /// Whether this CPU can run kernels for `self`.
    pub fn is_supported(self) -> bool {
        match self {
            Isa::Scalar => true,
            #[cfg(target_arch = "x86_64")]
            Isa::Avx512 => {
                std::arch::is_x86_feature_detected!("avx512f")
                    && std::arch::is_x86_feature_detected!("fma")
            }
            #[cfg(target_arch = "x86_64")]
            Isa::Avx2 => {
                std::arch::is_x86_feature_detected!("avx2")
                    && std::arch::is_x86_feature_detected!("fma")
            }
            #[cfg(not(target_arch = "x86_64"))]
            _ => false,
        }
    }

    /// Number of doubles per vector.
    pub fn lanes(self) -> usize {
        match self {
            Isa::Avx512 => 8,
            Isa::Avx2 => 4,
            Isa::Scalar => 1,
        }
    }
}

/// Vector operations used by the kernels. All methods are unsafe: the caller
/// guarantees the CPU supports the instruction set and pointers are valid for `W` doubles.
pub(crate) trait Simd: Copy {
    /// The vector type.
    type V: Copy;
    unsafe fn splat(x: f64) -> Self::V;
    unsafe fn load(p: *const f64) -> Self::V;
    unsafe fn store(p: *mut f64, v: Self::V);
    unsafe fn add(a: Self::V, b: Self::V) -> Self::V;
    unsafe fn mul(a: Self::V, b: Self::V) -> Self::V;
    /// `a * b + c`
    unsafe fn fma(a: Self::V, b: Self::V, c: Self::V) -> Self::V;
    /// `a * b - c`
    unsafe fn fms(a: Self::V, b: Self::V, c: Self::V) -> Self::V;
    /// Whether any lane has `a >= b`.
    unsafe fn any_ge(a: Self::V, b: Self::V) -> bool;
    /// `|v|`
    unsafe fn abs(v: Self::V) -> Self::V;
    /// Lane-wise `if a >= b { x } else { y }`.
    unsafe fn blend_ge(a: Self::V, b: Self::V, x: Self::V, y: Self::V) -> Self::V;
    /// Lane-wise maximum.
    unsafe fn max(a: Self::V, b: Self::V) -> Self::V;
    /// Transpose the `W x W` block `v` (vector `j`, lane `w`) in registers: afterwards
    /// vector `w` holds lane `w` of every former vector.
    unsafe fn transpose(v: &mut [Self::V]);
    /// `[p[0], p[1]]` repeated in every pair of lanes (`W >= 2` only).
    unsafe fn splat2(p: *const f64) -> Self::V;
    /// The even lanes of `a` and `b` interleaved, `[a0, b0, a2, b2, ...]` (`W >= 2` only).
    unsafe fn unpack_even(a: Self::V, b: Self::V) -> Self::V;
    /// The odd lanes of `a` and `b` interleaved, `[a1, b1, a3, b3, ...]` (`W >= 2` only).
    unsafe fn unpack_odd(a: Self::V, b: Self::V) -> Self::V;
    /// Store `v` at `p` without reading the cache line first (a non-temporal store) where
    /// `p` is aligned to the vector size, else an ordinary store. Callers end a run of these
    /// with [`sfence`].
    #[inline(always)]
    unsafe fn stream(p: *mut f64, v: Self::V) {
        Self::store(p, v)
    }
    /// Store the `W x W` block `v` (vector `j`, lane `w`) transposed: lane `w` of every
    /// vector goes to the row `dst + w * stride`, vector `j` to its entry `j` (with
    /// [`Simd::stream`] if `stream`, else ordinary stores).
    #[inline(always)]
    unsafe fn store_transposed(v: &[Self::V], dst: *mut f64, stride: usize, stream: bool) {
        let mut t = [Self::zero(); 8];
        let w = v.len();
        t[..w].copy_from_slice(v);
        Self::transpose(&mut t[..w]);
        for (r, x) in t[..w].iter().enumerate() {
            if stream {
                Self::stream(dst.add(r * stride), *x);
            } else {
                Self::store(dst.add(r * stride), *x);
            }
        }
    }
    /// `v` unchanged, through an empty `asm!` the compiler may not move code across:
    /// pins the program order of what is computed before and after it.
    #[inline(always)]
    unsafe fn fence(v: Self::V) -> Self::V {
        v
    }
    #[inline(always)]
    unsafe fn zero() -> Self::V {
        Self::splat(0.0)
    }
}

/// Orders earlier non-temporal stores ([`Simd::stream`]) before everything after it.
#[inline(always)]
pub(crate) fn sfence() {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a store fence has no operands; SSE is part of x86-64.
    unsafe {
        std::arch::x86_64::_mm_sfence()
    };
}

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
        *p
    }
    #[inline(always)]
    unsafe fn store(p: *mut f64, v: f64) {
        *p = v
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

#[cfg(target_arch = "x86_64")]
pub(crate) use x86::{Avx2, Avx512};

#[cfg(target_arch = "x86_64")]
mod x86 {
    use super::Simd;
    use std::arch::x86_64::*;

    /// AVX-512F: 8 doubles.
    #[derive(Clone, Copy)]
    pub(crate) struct Avx512;

    impl Simd for Avx512 {
        type V = __m512d;
        #[inline(always)]
        unsafe fn splat(x: f64) -> __m512d {
            _mm512_set1_pd(x)
        }
        #[inline(always)]
        unsafe fn load(p: *const f64) -> __m512d {
            _mm512_loadu_pd(p)
        }
        #[inline(always)]
        unsafe fn store(p: *mut f64, v: __m512d) {
            _mm512_storeu_pd(p, v)
        }
        #[inline(always)]
        unsafe fn add(a: __m512d, b: __m512d) -> __m512d {
            _mm512_add_pd(a, b)
        }
        #[inline(always)]
        unsafe fn mul(a: __m512d, b: __m512d) -> __m512d {
            _mm512_mul_pd(a, b)
        }
        #[inline(always)]
        unsafe fn fma(a: __m512d, b: __m512d, c: __m512d) -> __m512d {
            _mm512_fmadd_pd(a, b, c)
        }
        #[inline(always)]
        unsafe fn fms(a: __m512d, b: __m512d, c: __m512d) -> __m512d {
            _mm512_fmsub_pd(a, b, c)
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
            if (p as usize).is_multiple_of(64) {
                _mm512_stream_pd(p, v)
            } else {
                _mm512_storeu_pd(p, v)
            }
        }
        #[inline(always)]
        unsafe fn any_ge(a: __m512d, b: __m512d) -> bool {
            _mm512_cmp_pd_mask::<_CMP_GE_OQ>(a, b) != 0
        }
        #[inline(always)]
        unsafe fn abs(v: __m512d) -> __m512d {
            _mm512_abs_pd(v)
        }
        #[inline(always)]
        unsafe fn blend_ge(a: __m512d, b: __m512d, x: __m512d, y: __m512d) -> __m512d {
            _mm512_mask_blend_pd(_mm512_cmp_pd_mask::<_CMP_GE_OQ>(a, b), y, x)
        }
        #[inline(always)]
        unsafe fn max(a: __m512d, b: __m512d) -> __m512d {
            _mm512_max_pd(a, b)
        }
        #[inline(always)]
        unsafe fn splat2(p: *const f64) -> __m512d {
            // vbroadcastf32x4 moves the same 128 bits and needs only AVX-512F (f64x2 is DQ).
            _mm512_castps_pd(_mm512_broadcast_f32x4(_mm_castpd_ps(_mm_loadu_pd(p))))
        }
        #[inline(always)]
        unsafe fn unpack_even(a: __m512d, b: __m512d) -> __m512d {
            _mm512_unpacklo_pd(a, b)
        }
        #[inline(always)]
        unsafe fn unpack_odd(a: __m512d, b: __m512d) -> __m512d {
            _mm512_unpackhi_pd(a, b)
        }
        #[inline(always)]
        unsafe fn transpose(v: &mut [__m512d]) {
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

    /// AVX2 + FMA: 4 doubles.
    #[derive(Clone, Copy)]
    pub(crate) struct Avx2;

    impl Simd for Avx2 {
        type V = __m256d;
        #[inline(always)]
        unsafe fn splat(x: f64) -> __m256d {
            _mm256_set1_pd(x)
        }
        #[inline(always)]
        unsafe fn load(p: *const f64) -> __m256d {
            _mm256_loadu_pd(p)
        }
        #[inline(always)]
        unsafe fn store(p: *mut f64, v: __m256d) {
            _mm256_storeu_pd(p, v)
        }
        #[inline(always)]
        unsafe fn add(a: __m256d, b: __m256d) -> __m256d {
            _mm256_add_pd(a, b)
        }
        #[inline(always)]
        unsafe fn mul(a: __m256d, b: __m256d) -> __m256d {
            _mm256_mul_pd(a, b)
        }
        #[inline(always)]
        unsafe fn fma(a: __m256d, b: __m256d, c: __m256d) -> __m256d {
            _mm256_fmadd_pd(a, b, c)
        }
        #[inline(always)]
        unsafe fn fms(a: __m256d, b: __m256d, c: __m256d) -> __m256d {
            _mm256_fmsub_pd(a, b, c)
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
            if (p as usize).is_multiple_of(32) {
                _mm256_stream_pd(p, v)
            } else {
                _mm256_storeu_pd(p, v)
            }
        }
        #[inline(always)]
        unsafe fn any_ge(a: __m256d, b: __m256d) -> bool {
            _mm256_movemask_pd(_mm256_cmp_pd::<_CMP_GE_OQ>(a, b)) != 0
        }
        #[inline(always)]
        unsafe fn abs(v: __m256d) -> __m256d {
            _mm256_andnot_pd(_mm256_set1_pd(-0.0), v)
        }
        #[inline(always)]
        unsafe fn blend_ge(a: __m256d, b: __m256d, x: __m256d, y: __m256d) -> __m256d {
            _mm256_blendv_pd(y, x, _mm256_cmp_pd::<_CMP_GE_OQ>(a, b))
        }
        #[inline(always)]
        unsafe fn max(a: __m256d, b: __m256d) -> __m256d {
            _mm256_max_pd(a, b)
        }
        #[inline(always)]
        unsafe fn splat2(p: *const f64) -> __m256d {
            _mm256_broadcast_pd(&_mm_loadu_pd(p))
        }
        #[inline(always)]
        unsafe fn unpack_even(a: __m256d, b: __m256d) -> __m256d {
            _mm256_unpacklo_pd(a, b)
        }
        #[inline(always)]
        unsafe fn unpack_odd(a: __m256d, b: __m256d) -> __m256d {
            _mm256_unpackhi_pd(a, b)
        }
        #[inline(always)]
        unsafe fn transpose(v: &mut [__m256d]) {
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

#[cfg(all(test, target_arch = "x86_64"))]
mod tests {
    use super::*;

    /// `splat2`, `unpack_even` and `unpack_odd` against their definitions, lane by lane.
    fn pair_ops<S: Simd, const W: usize>() {
        let a: Vec<f64> = (0..W).map(|k| 1.0 + k as f64).collect();
        let b: Vec<f64> = (0..W).map(|k| -10.0 - k as f64).collect();
        let mut out = [[0.0; W]; 3];
        // SAFETY: callers check the instruction set; every pointer covers W doubles.
        unsafe {
            let (va, vb) = (S::load(a.as_ptr()), S::load(b.as_ptr()));
            S::store(out[0].as_mut_ptr(), S::splat2(a[2..].as_ptr()));
            S::store(out[1].as_mut_ptr(), S::unpack_even(va, vb));
            S::store(out[2].as_mut_ptr(), S::unpack_odd(va, vb));
        }
        for k in 0..W {
            assert_eq!(out[0][k], a[2 + k % 2]);
            let (src, lane) = (if k % 2 == 0 { &a } else { &b }, k - k % 2);
            assert_eq!(out[1][k], src[lane]);
            assert_eq!(out[2][k], src[lane + 1]);
        }
    }

    #[test]
    fn pair_operations() {
        if Isa::Avx512.is_supported() {
            pair_ops::<Avx512, 8>();
        }
        if Isa::Avx2.is_supported() {
            pair_ops::<Avx2, 4>();
        }
    }
}
