//! Double-precision FMA peak of this machine, measured in the same run as the transforms.
//!
//! On a shared machine whose speed drifts, a peak copied from a data sheet or another run
//! would make "fraction of peak" meaningless; measuring it next to the transform keeps the
//! ratio honest.
//!
//! The kernel keeps many independent FMA chains in registers: with a 4-cycle FMA latency and two
//! FMA pipes at least 8 chains are needed to fill the pipes, so we use 16 (AVX-512, 32 registers)
//! or 12 (AVX2, 16 registers). Each chain iterates `x = x * a + c` with `a` just below 1, which
//! converges to a normal number: no overflow, no denormal slow path.

use std::hint::black_box;
use std::time::{Duration, Instant};

/// Target wall time of one repetition.
const REP_TIME: Duration = Duration::from_millis(40);
/// Repetitions; the best one is reported (noise only ever slows a run down).
const REPS: usize = 5;
/// Multiplier and addend of the chain recurrence (fixed point c / (1 - a) = 1).
const A: f64 = 0.999_999_9;
const C: f64 = 1.0e-7;

/// Instruction set used by the kernel.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Isa {
    Avx512,
    Avx2Fma,
    Scalar,
}

impl Isa {
    /// The instruction set of the library's kernels: the widest FMA set the CPU supports,
    /// or the one `SO3FFT_ISA` (`--isa`) names.
    pub fn detect() -> Isa {
        match so3fft::Isa::selected().unwrap_or_else(|_| so3fft::Isa::detect()) {
            so3fft::Isa::Avx512 => Isa::Avx512,
            so3fft::Isa::Avx2 => Isa::Avx2Fma,
            so3fft::Isa::Scalar => Isa::Scalar,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Isa::Avx512 => "AVX-512 FMA (16 chains x 8 lanes)",
            Isa::Avx2Fma => "AVX2 FMA (12 chains x 4 lanes)",
            Isa::Scalar => "scalar mul+add (12 chains)",
        }
    }

    /// Floating-point operations of one kernel iteration (an FMA counts as 2).
    fn flops_per_iter(self) -> f64 {
        match self {
            Isa::Avx512 => (16 * 8 * 2) as f64,
            Isa::Avx2Fma => (12 * 4 * 2) as f64,
            Isa::Scalar => (12 * 2) as f64,
        }
    }

    /// Runs `iters` kernel iterations and returns a value depending on all chains.
    fn run(self, iters: u64) -> f64 {
        let iters = black_box(iters);
        match self {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: `Isa::detect` chose this variant after detecting AVX-512F at run time.
            Isa::Avx512 => unsafe { kernel_avx512(iters) },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: `Isa::detect` chose this variant after detecting AVX2 and FMA at run time.
            Isa::Avx2Fma => unsafe { kernel_avx2(iters) },
            _ => kernel_scalar(iters),
        }
    }
}

/// Measured peaks in GFLOP/s.
#[derive(Clone, Copy, Debug)]
pub struct Peak {
    pub isa: Isa,
    pub one_core: f64,
    pub all_threads: f64,
    pub threads: usize,
}

/// Measures the single-core peak and the peak with `threads` concurrent kernels.
pub fn measure(threads: usize) -> Peak {
    let isa = Isa::detect();
    let iters = calibrate(isa);
    let one_core = best_of(|| timed_parallel(isa, iters, 1));
    let all_threads = best_of(|| timed_parallel(isa, iters, threads));
    Peak {
        isa,
        one_core,
        all_threads,
        threads,
    }
}

/// Iteration count that takes about [`REP_TIME`] on one core.
fn calibrate(isa: Isa) -> u64 {
    let mut iters: u64 = 1 << 12;
    loop {
        let start = Instant::now();
        black_box(isa.run(iters));
        let elapsed = start.elapsed();
        if elapsed >= Duration::from_millis(5) {
            let scale = REP_TIME.as_secs_f64() / elapsed.as_secs_f64();
            return ((iters as f64 * scale) as u64).max(1);
        }
        iters *= 4;
    }
}

/// Best (highest) GFLOP/s over [`REPS`] repetitions.
fn best_of(mut measure: impl FnMut() -> f64) -> f64 {
    (0..REPS).map(|_| measure()).fold(0.0, f64::max)
}

/// GFLOP/s of `threads` kernels of `iters` iterations started together, by wall time.
///
/// A barrier releases the workers together; each worker reads the clock itself, and the wall
/// time is from the earliest start to the latest end. (Timing from the spawning thread would be
/// wrong here: with every core busy it may be scheduled late and miss part of the run.)
fn timed_parallel(isa: Isa, iters: u64, threads: usize) -> f64 {
    let threads = threads.max(1);
    let barrier = std::sync::Barrier::new(threads);
    let spans: Vec<(Instant, Instant, f64)> = std::thread::scope(|scope| {
        let workers: Vec<_> = (0..threads)
            .map(|_| {
                scope.spawn(|| {
                    barrier.wait();
                    let start = Instant::now();
                    let value = isa.run(iters);
                    (start, Instant::now(), value)
                })
            })
            .collect();
        workers.into_iter().map(|w| w.join().unwrap()).collect()
    });
    let first_start = spans.iter().map(|s| s.0).min().unwrap();
    let last_end = spans.iter().map(|s| s.1).max().unwrap();
    black_box(spans.iter().map(|s| s.2).sum::<f64>());
    let elapsed = (last_end - first_start).as_secs_f64();
    isa.flops_per_iter() * iters as f64 * threads as f64 / elapsed / 1e9
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f")]
fn kernel_avx512(iters: u64) -> f64 {
    use core::arch::x86_64::*;
    let a = _mm512_set1_pd(A);
    let c = _mm512_set1_pd(C);
    let mut acc: [__m512d; 16] = core::array::from_fn(|i| _mm512_set1_pd(i as f64));
    for _ in 0..iters {
        for x in acc.iter_mut() {
            *x = _mm512_fmadd_pd(*x, a, c);
        }
    }
    let sum = acc
        .iter()
        .fold(_mm512_setzero_pd(), |s, &x| _mm512_add_pd(s, x));
    _mm512_reduce_add_pd(sum)
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn kernel_avx2(iters: u64) -> f64 {
    use core::arch::x86_64::*;
    let a = _mm256_set1_pd(A);
    let c = _mm256_set1_pd(C);
    let mut acc: [__m256d; 12] = core::array::from_fn(|i| _mm256_set1_pd(i as f64));
    for _ in 0..iters {
        for x in acc.iter_mut() {
            *x = _mm256_fmadd_pd(*x, a, c);
        }
    }
    let sum = acc
        .iter()
        .fold(_mm256_setzero_pd(), |s, &x| _mm256_add_pd(s, x));
    let mut lanes = [0.0; 4];
    // SAFETY: `lanes` holds exactly 4 doubles; storeu has no alignment requirement.
    unsafe { _mm256_storeu_pd(lanes.as_mut_ptr(), sum) };
    lanes.iter().sum()
}

/// Portable fallback: separate multiply and add (a software `mul_add` would be far slower).
fn kernel_scalar(iters: u64) -> f64 {
    let mut acc: [f64; 12] = core::array::from_fn(|i| i as f64);
    for _ in 0..iters {
        for x in acc.iter_mut() {
            *x = *x * A + C;
        }
    }
    acc.iter().sum()
}
