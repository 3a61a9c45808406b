//! The FMA peak of one core, the yardstick of the kernels' measuring tools.

use crate::simd::Isa;

/// FMA peak of one core, GFLOP/s: 16 independent chains of AVX-512 FMAs, best of a few
/// short runs; NaN where AVX-512 is missing.
pub fn fma_peak() -> f64 {
    #[cfg(target_arch = "x86_64")]
    {
        if !Isa::Avx512.is_supported() {
            return f64::NAN;
        }
        let iters = 2_000_000;
        (0..5)
            .map(|_| {
                let t = std::time::Instant::now();
                // SAFETY: AVX-512F (and FMA) are supported, checked above.
                std::hint::black_box(unsafe { chains(iters) });
                (iters * 16 * 16) as f64 / t.elapsed().as_secs_f64() / 1e9
            })
            .fold(0.0, f64::max)
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        let _ = Isa::Scalar;
        f64::NAN
    }
}

/// `iters` rounds of 16 independent AVX-512 FMAs; returns their sum (to keep them alive).
///
/// # Safety
/// The CPU supports AVX-512F and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,fma")]
unsafe fn chains(iters: usize) -> f64 {
    use crate::simd::avx512::Avx512;
    use crate::simd::Simd;
    // SAFETY: the caller guarantees AVX-512F; `t` holds the 8 doubles stored.
    unsafe {
        let mut a = [Avx512::zero(); 16];
        let b = Avx512::splat(0.999_999_9);
        let c = Avx512::splat(1e-9);
        for _ in 0..iters {
            for x in a.iter_mut() {
                *x = Avx512::fma(*x, b, c);
            }
            a[0] = Avx512::fence(a[0]);
        }
        let mut t = [0.0; 8];
        Avx512::store(
            t.as_mut_ptr(),
            a.iter().fold(Avx512::zero(), |s, x| Avx512::add(s, *x)),
        );
        t.iter().sum()
    }
}
