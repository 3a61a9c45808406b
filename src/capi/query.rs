//! Queries on a plan (bandwidth, threads, memory, FFT threading) and the memory a plan
//! would need.
//!
//! The bodies are generic over the plan's handle ([`PlanHandle`]) or its element type: the
//! `so3fft_*` functions here and the `so3fftf_*` ones of `single.rs` are one-line wrappers
//! over them.

use super::planner::planner_workspace_cap;
use super::{
    guarded, guarded_count, plan_ref, rigor_of, so3fft_plan, threads_of, PlanHandle, SO3FFT_ENULL,
    SO3FFT_FFT_SLICES_ACROSS_WORKERS, SO3FFT_REAL,
};
use crate::ffi::checks;
use crate::{Options, Plan, Real};
use std::ffi::{c_int, c_uint};

/// The body of `so3fft_get_bandwidth` for the handle type `H`.
///
/// # Safety
/// `p` is NULL or a live plan of type `H`.
pub(super) unsafe fn get_bandwidth<H: PlanHandle>(p: *mut H) -> c_int {
    guarded(SO3FFT_ENULL, || {
        // SAFETY: `p` is NULL or a live plan (this function's contract).
        Ok(unsafe { plan_ref(p) }?.plan.bandwidth() as c_int)
    })
}

/// The body of `so3fft_get_nthreads` for the handle type `H`.
///
/// # Safety
/// As [`get_bandwidth`].
pub(super) unsafe fn get_nthreads<H: PlanHandle>(p: *mut H) -> c_int {
    guarded(SO3FFT_ENULL, || {
        // SAFETY: `p` is NULL or a live plan (this function's contract).
        Ok(unsafe { plan_ref(p) }?.plan.threads() as c_int)
    })
}

/// The body of `so3fft_get_memory` for the handle type `H`.
///
/// # Safety
/// As [`get_bandwidth`].
pub(super) unsafe fn get_memory<H: PlanHandle>(p: *mut H) -> isize {
    guarded_count(|| {
        // SAFETY: `p` is NULL or a live plan (this function's contract).
        Ok(unsafe { plan_ref(p) }?.plan.memory_bytes() as isize)
    })
}

/// The body of `so3fft_get_fft_threading` for the handle type `H`.
///
/// # Safety
/// As [`get_bandwidth`].
pub(super) unsafe fn get_fft_threading<H: PlanHandle>(p: *mut H) -> c_int {
    guarded(SO3FFT_ENULL, || {
        // SAFETY: `p` is NULL or a live plan (this function's contract).
        unsafe { plan_ref(p) }?;
        Ok(SO3FFT_FFT_SLICES_ACROSS_WORKERS)
    })
}

/// The body of `so3fft_plan_memory` for plans of the element type `T`.
pub(super) fn plan_memory<T: Real>(B: c_int, flags: c_uint, nthreads: c_int) -> isize {
    guarded_count(|| {
        let b = checks::bandwidth(B)?;
        let rigor = rigor_of(flags)?;
        let threads = threads_of(nthreads)?;
        let options = Options {
            threads,
            rigor,
            real: flags & SO3FFT_REAL != 0,
            max_workspace_bytes: planner_workspace_cap(),
            ..Options::default()
        };
        Ok(Plan::<T>::memory_needed(b, &options)? as isize)
    })
}

/// The bandwidth of a plan (`SO3FFT_ENULL` for NULL).
#[no_mangle]
pub unsafe extern "C" fn so3fft_get_bandwidth(p: so3fft_plan) -> c_int {
    // SAFETY: `p` is NULL or a live plan (the caller's contract, see the module doc).
    unsafe { get_bandwidth(p) }
}

/// The worker thread count of a plan (`SO3FFT_ENULL` for NULL).
#[no_mangle]
pub unsafe extern "C" fn so3fft_get_nthreads(p: so3fft_plan) -> c_int {
    // SAFETY: `p` is NULL or a live plan (the caller's contract, see the module doc).
    unsafe { get_nthreads(p) }
}

/// Bytes of memory a plan holds (`SO3FFT_ENULL` for NULL).
#[no_mangle]
pub unsafe extern "C" fn so3fft_get_memory(p: so3fft_plan) -> isize {
    // SAFETY: `p` is NULL or a live plan (the caller's contract, see the module doc).
    unsafe { get_memory(p) }
}

/// Bytes a plan made now with these arguments would hold (whatever its direction),
/// computed without making it; or a negative `SO3FFT_E*` code.
#[no_mangle]
pub extern "C" fn so3fft_plan_memory(B: c_int, flags: c_uint, nthreads: c_int) -> isize {
    plan_memory::<f64>(B, flags, nthreads)
}

/// `SO3FFT_FFT_SLICES_ACROSS_WORKERS`, what every plan uses (`SO3FFT_ENULL` for NULL).
#[no_mangle]
pub unsafe extern "C" fn so3fft_get_fft_threading(p: so3fft_plan) -> c_int {
    // SAFETY: `p` is NULL or a live plan (the caller's contract, see the module doc).
    unsafe { get_fft_threading(p) }
}
