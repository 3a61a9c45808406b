//! Planners, `so3fft_destroy_plan`, and the process-wide planner settings (thread count,
//! workspace cap, FFT threading).
//!
//! The planner and destroy bodies are generic over the plan's handle ([`PlanHandle`]), whose
//! element type is the precision: the `so3fft_*` functions here and the `so3fftf_*` ones of
//! `single.rs` are one-line wrappers over them. The settings are the library's, shared by
//! both precisions.

use super::{
    direction_of, guarded, guarded_code, rigor_of, so3fft_complex, so3fft_plan, threads_of,
    PlanHandle, PlanState, SO3FFT_BOTH, SO3FFT_FFT_FFTW_THREADS, SO3FFT_FFT_SLICES_ACROSS_WORKERS,
    SO3FFT_FORWARD, SO3FFT_INVERSE, SO3FFT_OK, SO3FFT_REAL,
};
use crate::ffi::checks::{self, input_output, Array};
use crate::ffi::{last_error, CallError, ErrorKind};
use crate::{Direction, FftThreading, Options, Plan};
use std::ffi::{c_int, c_uint};
use std::sync::atomic::{AtomicI32, AtomicUsize, Ordering};

// ---------------------------------------------------------------------------------------
// Threads
// ---------------------------------------------------------------------------------------

static PLANNER_THREADS: AtomicI32 = AtomicI32::new(0);

/// Sets the worker threads of plans made afterwards by the planners other than
/// `so3fft_plan_general` (process-wide; 0 = all cores). `SO3FFT_EINVAL` if `nthreads < 0`.
#[no_mangle]
pub extern "C" fn so3fft_plan_with_nthreads(nthreads: c_int) -> c_int {
    guarded_code(|| {
        threads_of(nthreads)?;
        PLANNER_THREADS.store(nthreads, Ordering::Relaxed);
        Ok(())
    })
}

/// The setting of `so3fft_plan_with_nthreads` (0 = all cores).
#[no_mangle]
pub extern "C" fn so3fft_planner_nthreads() -> c_int {
    last_error::clear();
    PLANNER_THREADS.load(Ordering::Relaxed)
}

// ---------------------------------------------------------------------------------------
// Workspace
// ---------------------------------------------------------------------------------------

static PLANNER_MAX_WORKSPACE: AtomicUsize = AtomicUsize::new(0);

/// Caps the chunk buffer of plans made afterwards (process-wide; 0 = library default).
#[no_mangle]
pub extern "C" fn so3fft_plan_with_max_workspace(bytes: usize) -> c_int {
    last_error::clear();
    PLANNER_MAX_WORKSPACE.store(bytes, Ordering::Relaxed);
    SO3FFT_OK
}

/// The setting of `so3fft_plan_with_max_workspace` (0 = library default).
#[no_mangle]
pub extern "C" fn so3fft_planner_max_workspace() -> usize {
    last_error::clear();
    PLANNER_MAX_WORKSPACE.load(Ordering::Relaxed)
}

/// The workspace cap of plans made now (`None`: the library default).
pub(super) fn planner_workspace_cap() -> Option<usize> {
    match PLANNER_MAX_WORKSPACE.load(Ordering::Relaxed) {
        0 => None,
        bytes => Some(bytes),
    }
}

// ---------------------------------------------------------------------------------------
// FFT threading
// ---------------------------------------------------------------------------------------

static PLANNER_FFT_THREADING: AtomicI32 = AtomicI32::new(0);

/// Sets how plans made afterwards use their threads in the FFT stage (process-wide):
/// 0 = library's choice, `SO3FFT_FFT_SLICES_ACROSS_WORKERS` or `SO3FFT_FFT_FFTW_THREADS`, all
/// accepted and giving the same plan (slices across workers). `SO3FFT_EINVAL` for other
/// values.
#[no_mangle]
pub extern "C" fn so3fft_plan_with_fft_threading(mode: c_int) -> c_int {
    guarded_code(|| {
        fft_threading_of(mode)?;
        PLANNER_FFT_THREADING.store(mode, Ordering::Relaxed);
        Ok(())
    })
}

/// The setting of `so3fft_plan_with_fft_threading` (0 = library's choice).
#[no_mangle]
pub extern "C" fn so3fft_planner_fft_threading() -> c_int {
    last_error::clear();
    PLANNER_FFT_THREADING.load(Ordering::Relaxed)
}

/// The FFT threading of a `so3fft_plan_with_fft_threading` value.
fn fft_threading_of(mode: c_int) -> Result<FftThreading, CallError> {
    match mode {
        0 => Ok(FftThreading::Auto),
        SO3FFT_FFT_SLICES_ACROSS_WORKERS => Ok(FftThreading::SlicesAcrossWorkers),
        SO3FFT_FFT_FFTW_THREADS => Ok(FftThreading::FftwThreads),
        m => Err(CallError::invalid(format!(
            "unknown FFT threading {m} (use 0, SO3FFT_FFT_SLICES_ACROSS_WORKERS or SO3FFT_FFT_FFTW_THREADS)"
        ))),
    }
}

// ---------------------------------------------------------------------------------------
// Planners
// ---------------------------------------------------------------------------------------

/// The thread count the planners other than `so3fft_plan_general` use
/// (`so3fft_plan_with_nthreads`).
pub(super) fn planner_threads() -> c_int {
    PLANNER_THREADS.load(Ordering::Relaxed)
}

/// The shared body of the planners for the handle type `H`: checks the arguments and makes
/// the plan object (NULL on error).
pub(super) fn make_plan<H: PlanHandle>(
    b: c_int,
    direction: c_int,
    input: *mut [H::T; 2],
    output: *mut [H::T; 2],
    flags: c_uint,
    nthreads: c_int,
) -> *mut H {
    guarded(std::ptr::null_mut(), || {
        let b = checks::bandwidth(b)?;
        let direction = direction_of(direction)?;
        let rigor = rigor_of(flags)?;
        let threads = threads_of(nthreads)?;
        match (input.is_null(), output.is_null()) {
            (true, true) => {}
            (false, false) => {
                if direction == Direction::Both {
                    return Err(CallError::invalid(
                        "a plan for both directions takes no arrays (pass NULL and use the new-array execute functions)",
                    ));
                }
                let (ns, nc) = (crate::num_samples(b), crate::num_coeffs(b));
                let samples = |ptr| Array::new(ptr, ns, "samples");
                let coeffs = |ptr| Array::new(ptr, nc, "coefficients");
                if direction == Direction::Forward {
                    input_output(&samples(input), &coeffs(output))?;
                } else {
                    input_output(&coeffs(input), &samples(output))?;
                }
            }
            _ => {
                return Err(CallError::new(
                    ErrorKind::Null,
                    "exactly one of the two arrays is NULL (pass both, or both NULL for a plan used with new-array execute only)",
                ))
            }
        }
        let real = flags & SO3FFT_REAL != 0;
        let options = Options {
            direction,
            threads,
            rigor,
            real,
            max_workspace_bytes: planner_workspace_cap(),
            fft_threading: fft_threading_of(PLANNER_FFT_THREADING.load(Ordering::Relaxed))?,
            ..Options::default()
        };
        let plan = Plan::<H::T>::new(b, &options)?;
        Ok(Box::into_raw(Box::new(H::wrap(PlanState {
            plan,
            input,
            output,
            real,
        }))))
    })
}

/// Plans the forward transform, samples `in` ((2B)^3) to coefficients `out` ((4B^3-B)/3);
/// `in`, `out` both NULL for new-array execute only. NULL on error.
#[no_mangle]
pub extern "C" fn so3fft_plan_forward(
    B: c_int,
    r#in: *mut so3fft_complex,
    out: *mut so3fft_complex,
    flags: c_uint,
) -> so3fft_plan {
    make_plan(B, SO3FFT_FORWARD, r#in, out, flags, planner_threads())
}

/// Plans the inverse transform, coefficients `in` to samples `out`. NULL on error.
#[no_mangle]
pub extern "C" fn so3fft_plan_inverse(
    B: c_int,
    r#in: *mut so3fft_complex,
    out: *mut so3fft_complex,
    flags: c_uint,
) -> so3fft_plan {
    make_plan(B, SO3FFT_INVERSE, r#in, out, flags, planner_threads())
}

/// Plans both transforms, without arrays (new-array execute only). NULL on error.
#[no_mangle]
pub extern "C" fn so3fft_plan_both(B: c_int, flags: c_uint) -> so3fft_plan {
    make_plan(
        B,
        SO3FFT_BOTH,
        std::ptr::null_mut(),
        std::ptr::null_mut(),
        flags,
        planner_threads(),
    )
}

/// Planner with a direction (`SO3FFT_FORWARD`, `_INVERSE`, `_BOTH`) and an explicit thread
/// count (0 = all cores). NULL on error.
#[no_mangle]
pub extern "C" fn so3fft_plan_general(
    B: c_int,
    direction: c_int,
    r#in: *mut so3fft_complex,
    out: *mut so3fft_complex,
    flags: c_uint,
    nthreads: c_int,
) -> so3fft_plan {
    make_plan(B, direction, r#in, out, flags, nthreads)
}

/// The body of `so3fft_destroy_plan` for the handle type `H`.
///
/// # Safety
/// `p` is NULL or a plan made by [`make_plan`] with the same `H`, not destroyed yet and
/// used by no other thread.
pub(super) unsafe fn destroy_plan<H: PlanHandle>(p: *mut H) {
    guarded((), || {
        if !p.is_null() {
            // SAFETY: a non-NULL `p` came from Box::into_raw of a `Box<H>` in a planner and
            // is destroyed once, while no other thread uses it (this function's contract).
            drop(unsafe { Box::from_raw(p) });
        }
        Ok(())
    })
}

/// Destroys a plan (after the worker threads it was the last to use have finished); NULL
/// is a no-op.
#[no_mangle]
pub unsafe extern "C" fn so3fft_destroy_plan(p: so3fft_plan) {
    // SAFETY: `p` is NULL or a live plan of this type, used by no other thread (the API's
    // contract).
    unsafe { destroy_plan(p) }
}
