//! Planners, `so3fft_destroy_plan`, and the process-wide planner settings (thread count,
//! workspace cap).

use super::{
    direction_of, guarded, guarded_code, rigor_of, so3fft_complex, so3fft_plan, so3fft_plan_s,
    threads_of, SO3FFT_BOTH, SO3FFT_DESTROY_INPUT, SO3FFT_FORWARD, SO3FFT_INVERSE, SO3FFT_OK,
    SO3FFT_REAL,
};
use crate::ffi::checks::{self, input_output, Array};
use crate::ffi::{last_error, CallError, ErrorKind};
use crate::{Direction, Plan, PlanOptions};
use std::ffi::{c_int, c_uint};
use std::sync::atomic::{AtomicI32, AtomicUsize, Ordering};

// ---------------------------------------------------------------------------------------
// Threads
// ---------------------------------------------------------------------------------------

static PLANNER_THREADS: AtomicI32 = AtomicI32::new(0);

/// Sets the number of worker threads of plans created afterwards by
/// `so3fft_plan_forward`, `so3fft_plan_inverse` and `so3fft_plan_both`
/// (like `fftw_plan_with_nthreads`).
///
/// `nthreads`: 0 = all available cores (the initial setting), n > 0 = n threads.
/// The setting is **process-wide** (not thread-local): it applies to plans created
/// afterwards by any thread; existing plans keep their thread count. Each plan owns its
/// own pool of worker threads, started by the planner; `so3fft_destroy_plan` stops them
/// and waits until they have finished. `so3fft_plan_general`
/// takes its thread count as an argument instead. so3fft never changes FFTW's own thread
/// settings.
///
/// Returns `SO3FFT_OK`, or `SO3FFT_EINVAL` if `nthreads < 0` (the setting is unchanged).
/// Thread-safe. Counts above the engine's limit (1024) are reported by the planners.
#[no_mangle]
pub extern "C" fn so3fft_plan_with_nthreads(nthreads: c_int) -> c_int {
    guarded_code(|| {
        threads_of(nthreads)?;
        PLANNER_THREADS.store(nthreads, Ordering::Relaxed);
        Ok(())
    })
}

/// The current process-wide thread setting of `so3fft_plan_with_nthreads`
/// (0 = all available cores). Thread-safe; never fails.
#[no_mangle]
pub extern "C" fn so3fft_planner_nthreads() -> c_int {
    last_error::clear();
    PLANNER_THREADS.load(Ordering::Relaxed)
}

// ---------------------------------------------------------------------------------------
// Workspace
// ---------------------------------------------------------------------------------------

static PLANNER_MAX_WORKSPACE: AtomicUsize = AtomicUsize::new(0);

/// Caps the chunk buffer of plans created afterwards by every planner (process-wide, like
/// `so3fft_plan_with_nthreads`): `bytes` = 0 restores the library default (the initial
/// setting), any other value is the most the plan's chunk buffer may take.
///
/// The chunk buffer holds the beta slices of one chunk in the DWT's layout; a transform
/// runs its slices through it a chunk at a time. The default keeps a whole plan within
/// about 5% of the caller's arrays at large `B` (and within half of the available memory);
/// a smaller cap means more, smaller chunks: less memory, somewhat more time (each chunk
/// passes over the coefficients once). The buffer always holds at least one pair of beta
/// slices, so a tiny cap is not an error. `so3fft_plan_memory` and `so3fft_get_memory`
/// report the memory with the cap applied. Existing plans are not changed.
///
/// Returns `SO3FFT_OK`. Thread-safe; never fails.
#[no_mangle]
pub extern "C" fn so3fft_plan_with_max_workspace(bytes: usize) -> c_int {
    last_error::clear();
    PLANNER_MAX_WORKSPACE.store(bytes, Ordering::Relaxed);
    SO3FFT_OK
}

/// The current process-wide setting of `so3fft_plan_with_max_workspace` (0 = the library
/// default). Thread-safe; never fails.
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
// Planners
// ---------------------------------------------------------------------------------------

/// The shared body of the planners: checks the arguments and makes the plan object.
fn make_plan(
    b: c_int,
    direction: c_int,
    input: *mut so3fft_complex,
    output: *mut so3fft_complex,
    flags: c_uint,
    nthreads: c_int,
) -> so3fft_plan {
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
        let options = PlanOptions {
            direction,
            threads,
            rigor,
            real,
            max_workspace_bytes: planner_workspace_cap(),
            ..PlanOptions::default()
        };
        let plan = Plan::new(b, &options)?;
        Ok(Box::into_raw(Box::new(so3fft_plan_s {
            plan,
            input,
            output,
            real,
            destroy_input: flags & SO3FFT_DESTROY_INPUT != 0,
        })))
    })
}

/// Creates a plan for the forward transform (samples to coefficients) of bandwidth `B`.
///
/// - `B`: bandwidth, 1 .. `SO3FFT_MAX_BANDWIDTH`.
/// - `in`: the samples, `(2B)^3` values (`so3fft_num_samples(B)`), sample
///   `f(alpha_j1, beta_k, gamma_j2)` at index `k*(2B)^2 + j1*(2B) + j2`.
/// - `out`: the coefficients, `(4B^3-B)/3` values (`so3fft_num_coeffs(B)`), in SOFT's
///   `so3CoefLoc` order (see `so3fft_coef_index`).
/// - `flags`: bitwise OR of `SO3FFT_ESTIMATE` (0, default) / `SO3FFT_MEASURE` /
///   `SO3FFT_PATIENT` / `SO3FFT_EXHAUSTIVE`, `SO3FFT_REAL`, `SO3FFT_DESTROY_INPUT`.
///
/// `in` and `out` may both be NULL for a plan used only with `so3fft_execute_forward`;
/// otherwise both must be non-NULL, aligned like `double` (no further alignment is
/// required) and must not overlap. The plan stores the two pointers (it does not copy
/// or own the arrays) for `so3fft_execute`: they must stay valid as long as
/// `so3fft_execute` is used. Planning never reads or writes the arrays (not even with
/// `SO3FFT_MEASURE`, unlike FFTW).
///
/// The worker thread count is the process-wide setting of `so3fft_plan_with_nthreads`.
///
/// Returns the plan, owned by the caller (release it with `so3fft_destroy_plan`), or
/// NULL on error with `so3fft_last_error_code()` / `so3fft_last_error()` set:
/// `SO3FFT_EBANDWIDTH`, `SO3FFT_EINVAL` (unknown flag bits, misaligned or overlapping
/// arrays, thread count too large), `SO3FFT_ENULL` (exactly one array NULL),
/// `SO3FFT_ENOMEM`, `SO3FFT_EFFTW`, `SO3FFT_EPANIC`.
///
/// Planners may be called concurrently from several threads. so3fft serialises its
/// calls to the FFTW planner with an internal lock and calls
/// `fftw_make_planner_thread_safe()` once (see the FFTW section at the top of this file).
#[no_mangle]
pub extern "C" fn so3fft_plan_forward(
    B: c_int,
    r#in: *mut so3fft_complex,
    out: *mut so3fft_complex,
    flags: c_uint,
) -> so3fft_plan {
    make_plan(
        B,
        SO3FFT_FORWARD,
        r#in,
        out,
        flags,
        PLANNER_THREADS.load(Ordering::Relaxed),
    )
}

/// Creates a plan for the inverse transform (coefficients to samples) of bandwidth `B`.
///
/// - `in`: the coefficients, `(4B^3-B)/3` values (`so3fft_num_coeffs(B)`).
/// - `out`: the samples, `(2B)^3` values (`so3fft_num_samples(B)`).
///
/// Everything else (flags, NULL arrays for new-array execute only, ownership,
/// threads, errors, thread safety) as for `so3fft_plan_forward`.
#[no_mangle]
pub extern "C" fn so3fft_plan_inverse(
    B: c_int,
    r#in: *mut so3fft_complex,
    out: *mut so3fft_complex,
    flags: c_uint,
) -> so3fft_plan {
    make_plan(
        B,
        SO3FFT_INVERSE,
        r#in,
        out,
        flags,
        PLANNER_THREADS.load(Ordering::Relaxed),
    )
}

/// Creates a plan for both transforms of bandwidth `B`, without arrays: use it with
/// `so3fft_execute_forward` and `so3fft_execute_inverse` (`so3fft_execute` on it
/// returns `SO3FFT_ENULL`). Costs a little more memory than a one-direction plan
/// (two sets of FFTW plans, which `so3fft_get_memory` does not count).
///
/// Flags, threads, ownership, errors and thread safety as for `so3fft_plan_forward`.
#[no_mangle]
pub extern "C" fn so3fft_plan_both(B: c_int, flags: c_uint) -> so3fft_plan {
    make_plan(
        B,
        SO3FFT_BOTH,
        std::ptr::null_mut(),
        std::ptr::null_mut(),
        flags,
        PLANNER_THREADS.load(Ordering::Relaxed),
    )
}

/// General planner: like `so3fft_plan_forward` (`direction = SO3FFT_FORWARD`),
/// `so3fft_plan_inverse` (`SO3FFT_INVERSE`) or `so3fft_plan_both` (`SO3FFT_BOTH`,
/// arrays must be NULL), with an explicit worker thread count for this plan:
/// `nthreads` = 0 for all available cores, n > 0 for n threads (the process-wide
/// setting of `so3fft_plan_with_nthreads` is ignored).
///
/// Errors as for `so3fft_plan_forward`, plus `SO3FFT_EINVAL` for an unknown direction,
/// `nthreads < 0`, or arrays given with `SO3FFT_BOTH`.
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

/// Destroys a plan and releases everything it owns (tables, FFTW plans, buffers), and
/// stops its worker threads, returning once they have finished their work (only the
/// threads' final exit from the C library may trail the return). The arrays given at
/// planning are not touched (they belong to the caller).
/// `p = NULL` is a no-op.
///
/// Must not run while another thread executes the same plan; destroying different
/// plans concurrently is safe. Never fails.
///
/// Requirements: `p` is NULL or a plan returned by a planner and not destroyed yet.
#[no_mangle]
pub unsafe extern "C" fn so3fft_destroy_plan(p: so3fft_plan) {
    guarded((), || {
        if !p.is_null() {
            // SAFETY: a non-NULL `p` came from Box::into_raw in a planner and is destroyed
            // once, while no other thread uses it (the caller's contract).
            drop(unsafe { Box::from_raw(p) });
        }
        Ok(())
    })
}
