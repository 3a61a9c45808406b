//! The FMA peak of one core, the yardstick of the kernels' measuring tools.

use crate::simd::Isa;

/// FMA peak of one core with the vectors of `isa`, GFLOP/s: independent chains of FMAs
/// (16 with AVX-512's 32 registers, 12 with AVX2's 16), best of a few short runs; NaN
/// where `isa` is missing or has no FMA (scalar).
pub fn fma_peak(isa: Isa) -> f64 {
    #[cfg(target_arch = "x86_64")]
    {
        if !isa.is_supported() || isa == Isa::Scalar {
            return f64::NAN;
        }
        let iters = 2_000_000;
        let (chains, lanes) = match isa {
            Isa::Avx512 => (16, 8),
            _ => (12, 4),
        };
        (0..5)
            .map(|_| {
                let t = std::time::Instant::now();
                // SAFETY: the instruction set is supported, checked above.
                std::hint::black_box(unsafe {
                    match isa {
                        Isa::Avx512 => chains_avx512(iters),
                        _ => chains_avx2(iters),
                    }
                });
                (iters * chains * lanes * 2) as f64 / t.elapsed().as_secs_f64() / 1e9
            })
            .fold(0.0, f64::max)
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let _ = isa;
        f64::NAN
    }
}

/// `iters` rounds of `C` independent FMAs on `S`'s vectors; returns their sum (to keep
/// them alive).
///
/// # Safety
/// The CPU supports `S`'s instruction set.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn chains<S: crate::simd::Simd<E = f64>, const C: usize>(iters: usize) -> f64 {
    // SAFETY: the caller guarantees the instruction set; `t` holds the 8 doubles a vector
    // stores at most.
    unsafe {
        let mut a = [S::zero(); C];
        let b = S::splat(0.999_999_9);
        let c = S::splat(1e-9);
        for _ in 0..iters {
            for x in a.iter_mut() {
                *x = S::fma(*x, b, c);
            }
            a[0] = S::fence(a[0]);
        }
        let mut t = [0.0; 8];
        S::store(
            t.as_mut_ptr(),
            a.iter().fold(S::zero(), |s, x| S::add(s, *x)),
        );
        t.iter().sum()
    }
}

/// [`chains`] with 16 AVX-512 chains.
///
/// # Safety
/// The CPU supports AVX-512F and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,fma")]
unsafe fn chains_avx512(iters: usize) -> f64 {
    // SAFETY: the caller guarantees AVX-512F and FMA.
    unsafe { chains::<crate::simd::avx512::Avx512, 16>(iters) }
}

/// [`chains`] with 12 AVX2 chains (16 registers).
///
/// # Safety
/// The CPU supports AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn chains_avx2(iters: usize) -> f64 {
    // SAFETY: the caller guarantees AVX2 and FMA.
    unsafe { chains::<crate::simd::avx2::Avx2, 12>(iters) }
}
