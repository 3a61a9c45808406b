//! Queries on a plan (bandwidth, threads, memory, FFT threading) and the memory a plan
//! would need.

use super::planner::planner_workspace_cap;
use super::{
    guarded, guarded_count, plan_ref, rigor_of, so3fft_plan, threads_of, SO3FFT_ENULL,
    SO3FFT_FFT_FFTW_THREADS, SO3FFT_FFT_SLICES_ACROSS_WORKERS, SO3FFT_REAL,
};
use crate::ffi::checks;
use crate::{FftThreading, Plan, PlanOptions};
use std::ffi::{c_int, c_uint};

/// The bandwidth of a plan, or `SO3FFT_ENULL` if `p` is NULL. Thread-safe.
///
/// Requirements: `p` is NULL or a live plan.
#[no_mangle]
pub unsafe extern "C" fn so3fft_get_bandwidth(p: so3fft_plan) -> c_int {
    guarded(SO3FFT_ENULL, || {
        // SAFETY: `p` is NULL or a live plan (the caller's contract, see the module doc).
        Ok(unsafe { plan_ref(p) }?.plan.bandwidth() as c_int)
    })
}

/// The number of worker threads of a plan (after resolving 0 = all cores), or
/// `SO3FFT_ENULL` if `p` is NULL. Thread-safe.
///
/// Requirements: `p` is NULL or a live plan.
#[no_mangle]
pub unsafe extern "C" fn so3fft_get_nthreads(p: so3fft_plan) -> c_int {
    guarded(SO3FFT_ENULL, || {
        // SAFETY: `p` is NULL or a live plan (the caller's contract, see the module doc).
        Ok(unsafe { plan_ref(p) }?.plan.threads() as c_int)
    })
}

/// Bytes of memory a plan holds: its chunk buffer (beta slices in the layout of the
/// Wigner transforms), per-worker FFT buffers and `O(B^2)` tables; `SO3FFT_ENULL` if `p`
/// is NULL. A transform needs its input and output arrays on top and nothing else large.
/// Thread-safe.
///
/// Requirements: `p` is NULL or a live plan.
#[no_mangle]
pub unsafe extern "C" fn so3fft_get_memory(p: so3fft_plan) -> isize {
    guarded_count(|| {
        // SAFETY: `p` is NULL or a live plan (the caller's contract, see the module doc).
        Ok(unsafe { plan_ref(p) }?.plan.memory_bytes() as isize)
    })
}

/// Bytes of memory a plan made now by `so3fft_plan_general(B, d, ..., flags, nthreads)`
/// would hold, whatever its direction `d` (what `so3fft_get_memory` would then report;
/// FFTW's own plans are not counted), computed without making it: nothing is allocated.
/// `nthreads`: 0 = all cores. The default workspace uses
/// at most 4.7% of the caller's arrays at large B (at least 512 MiB) and at most half of
/// the memory available at the time of the call, so a plan made later may differ if that
/// has changed; the formulas are in the crate documentation of `Plan::memory_bytes` and
/// `Plan::workspace_bytes`. A cap set with `so3fft_plan_with_max_workspace` applies.
///
/// Returns the byte count, or a negative `SO3FFT_E*` code (`SO3FFT_EBANDWIDTH` for an
/// invalid `B`, `SO3FFT_EINVAL` for unknown flags or `nthreads < 0`). Thread-safe.
#[no_mangle]
pub extern "C" fn so3fft_plan_memory(B: c_int, flags: c_uint, nthreads: c_int) -> isize {
    guarded_count(|| {
        let b = checks::bandwidth(B)?;
        let rigor = rigor_of(flags)?;
        let threads = threads_of(nthreads)?;
        let options = PlanOptions {
            threads,
            rigor,
            real: flags & SO3FFT_REAL != 0,
            max_workspace_bytes: planner_workspace_cap(),
            ..PlanOptions::default()
        };
        Ok(Plan::memory_needed(b, &options)? as isize)
    })
}

/// How the FFT stage of a plan uses its threads: `SO3FFT_FFT_SLICES_ACROSS_WORKERS` or
/// `SO3FFT_FFT_FFTW_THREADS`; `SO3FFT_ENULL` if `p` is NULL. Thread-safe.
///
/// The planner chooses: with `SO3FFT_ESTIMATE` or one thread, slices across workers; with
/// `SO3FFT_MEASURE`, `SO3FFT_PATIENT` or `SO3FFT_EXHAUSTIVE` and more than one thread, it
/// plans both variants, times them on a sample of the FFT stage and keeps the faster.
/// Real-signal transforms (`SO3FFT_REAL`) always spread slices across the workers.
///
/// Requirements: `p` is NULL or a live plan.
#[no_mangle]
pub unsafe extern "C" fn so3fft_get_fft_threading(p: so3fft_plan) -> c_int {
    guarded(SO3FFT_ENULL, || {
        // SAFETY: `p` is NULL or a live plan (the caller's contract, see the module doc).
        Ok(match unsafe { plan_ref(p) }?.plan.fft_threading() {
            FftThreading::FftwThreads => SO3FFT_FFT_FFTW_THREADS,
            _ => SO3FFT_FFT_SLICES_ACROSS_WORKERS,
        })
    })
}
