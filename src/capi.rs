//! C ABI in the spirit of `fftw3.h` (see `include/so3fft.h`, generated from this file by
//! `build.rs` through cbindgen: the doc comments below are the header's documentation).
//!
//! Every exported function catches panics at the boundary, validates its pointers and
//! sizes, and reports failures through a return value plus a thread-local error state
//! (code and message). Nothing is ever written outside the caller's arrays, whose sizes
//! are fixed by the bandwidth.

// Names follow C conventions (so3fft_plan, B); the unsafe functions state their
// requirements in prose for the C header rather than in "# Safety" sections.
#![allow(non_camel_case_types, non_snake_case, clippy::missing_safety_doc)]

use crate::error::Error;
use crate::{Complex64, Direction, Plan, PlanOptions, Rigor, MAX_BANDWIDTH};
use std::cell::RefCell;
use std::ffi::{c_char, c_double, c_int, c_uint, CString};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicI32, AtomicUsize, Ordering};

/// One complex number: `[0]` is the real part, `[1]` the imaginary part.
///
/// Identical to `fftw_complex` (`double[2]`): a `fftw_complex *` can be passed where a
/// `so3fft_complex *` is expected without any cast. Arrays of C99 `double _Complex`
/// have the same layout and are passed with a pointer cast `(so3fft_complex *)`.
/// No alignment beyond that of `double` is required.
pub type so3fft_complex = [c_double; 2];

/// Opaque plan object, created by a planner and released by `so3fft_destroy_plan`.
pub struct so3fft_plan_s {
    plan: Plan,
    /// Input array given at planning (samples for a forward plan, coefficients for an
    /// inverse plan), or NULL.
    input: *mut so3fft_complex,
    /// Output array given at planning, or NULL.
    output: *mut so3fft_complex,
    /// Made with `SO3FFT_REAL`: transforms take the real-signal path.
    real: bool,
    /// Made with `SO3FFT_DESTROY_INPUT`: the forward may overwrite its samples.
    destroy_input: bool,
}

/// A plan: a pointer to an opaque object (like `fftw_plan`).
pub type so3fft_plan = *mut so3fft_plan_s;

// ---------------------------------------------------------------------------------------
// Constants
// ---------------------------------------------------------------------------------------

/// Largest bandwidth `B` accepted by the planners and the helpers.
pub const SO3FFT_MAX_BANDWIDTH: c_int = 2048;
const _: () = assert!(SO3FFT_MAX_BANDWIDTH as usize == MAX_BANDWIDTH);

/// Planner flag: heuristic FFTW plans, no measurement (fast planning). This is the
/// default (the value is 0), like `FFTW_ESTIMATE`.
pub const SO3FFT_ESTIMATE: c_uint = 0;
/// Planner flag: FFTW measures a few candidate plans (planning takes up to about a
/// second; transforms are faster), like `FFTW_MEASURE`. The caller's arrays are never
/// used for the measurements: so3fft plans on its own scratch memory.
pub const SO3FFT_MEASURE: c_uint = 1;
/// Planner flag: FFTW measures more candidates (`FFTW_PATIENT`).
pub const SO3FFT_PATIENT: c_uint = 2;
/// Planner flag: FFTW measures every candidate (`FFTW_EXHAUSTIVE`).
/// When several rigour flags are given, the most rigorous one applies.
pub const SO3FFT_EXHAUSTIVE: c_uint = 4;
/// Planner flag: the forward transform may overwrite its input (sample) array, like
/// `FFTW_DESTROY_INPUT`; its contents afterwards are unspecified. When the plan's chunk
/// buffer holds fewer betas than the grid (large bandwidths, see `so3fft_plan_memory`),
/// the forward then keeps its later chunk buffers in the sample slices it has already
/// read and adds to the coefficients once per group of chunks instead of once per chunk
/// (at B = 512 under the default memory rule: one pass over the coefficients instead of
/// one per chunk: 22 of them, fewer with `SO3FFT_REAL`, whose chunks are larger). No
/// extra memory; the same results up to rounding. Concurrent forwards with such a plan
/// need distinct input arrays. The inverse never reads its output and never
/// modifies its input. (Earlier builds accepted this flag and ignored it.)
pub const SO3FFT_DESTROY_INPUT: c_uint = 16;
/// Planner flag: the signal is real-valued. The array layouts do not change, and about
/// half the work is done (r2c/c2r FFTs, one order pair of each `(m,m')`, `(-m,-m')`).
/// Forward: only the real parts of the samples are read; all coefficients are written
/// and satisfy `fhat(l,-m,-m') = (-1)^(m-m') conj(fhat(l,m,m'))` exactly. Inverse: the
/// coefficients must satisfy that symmetry, and only the blocks with `m' > 0`, or `m' = 0`
/// and `m >= 0`, are read; the samples' imaginary parts are written as exactly 0.
pub const SO3FFT_REAL: c_uint = 32;

const KNOWN_FLAGS: c_uint =
    SO3FFT_MEASURE | SO3FFT_PATIENT | SO3FFT_EXHAUSTIVE | SO3FFT_DESTROY_INPUT | SO3FFT_REAL;

/// Direction for `so3fft_plan_general`: samples to coefficients.
pub const SO3FFT_FORWARD: c_int = 1;
/// Direction for `so3fft_plan_general`: coefficients to samples.
pub const SO3FFT_INVERSE: c_int = 2;
/// Direction for `so3fft_plan_general`: both (no arrays; new-array execute only).
pub const SO3FFT_BOTH: c_int = 3;

/// Returned by `so3fft_get_fft_threading`: each worker thread of the plan transforms whole
/// beta slices with a single-threaded FFTW plan.
pub const SO3FFT_FFT_SLICES_ACROSS_WORKERS: c_int = 1;
/// Returned by `so3fft_get_fft_threading`: the beta slices are transformed one after
/// another, each on FFTW's own threads.
pub const SO3FFT_FFT_FFTW_THREADS: c_int = 2;

/// Success.
pub const SO3FFT_OK: c_int = 0;
/// Invalid argument: unknown flag bits, index or thread count out of range, direction
/// value unknown, arrays misaligned (not aligned like `double`) or overlapping.
pub const SO3FFT_EINVAL: c_int = -1;
/// Bandwidth `B` outside `1 .. SO3FFT_MAX_BANDWIDTH`.
pub const SO3FFT_EBANDWIDTH: c_int = -2;
/// A required pointer is NULL (plan, array, or an execute of a plan made without arrays).
pub const SO3FFT_ENULL: c_int = -3;
/// Memory allocation failed (nothing was leaked; the library stays usable).
pub const SO3FFT_ENOMEM: c_int = -4;
/// The plan was made for the other direction only.
pub const SO3FFT_EDIRECTION: c_int = -5;
/// FFTW could not create a plan.
pub const SO3FFT_EFFTW: c_int = -6;
/// Internal error (a Rust panic, caught at the library boundary). Please report it.
pub const SO3FFT_EPANIC: c_int = -7;

// ---------------------------------------------------------------------------------------
// Error state and the panic boundary
// ---------------------------------------------------------------------------------------

struct LastError {
    code: c_int,
    msg: CString,
}

thread_local! {
    static LAST: RefCell<LastError> = RefCell::new(LastError { code: 0, msg: CString::default() });
}

/// An error on its way to the C caller.
struct CErr {
    code: c_int,
    msg: String,
}

impl CErr {
    fn new(code: c_int, msg: impl Into<String>) -> CErr {
        CErr {
            code,
            msg: msg.into(),
        }
    }
}

impl From<Error> for CErr {
    fn from(e: Error) -> CErr {
        let code = match e {
            Error::InvalidBandwidth { .. } => SO3FFT_EBANDWIDTH,
            Error::LengthMismatch { .. } | Error::InvalidArgument(_) => SO3FFT_EINVAL,
            Error::OutOfMemory { .. } | Error::Resources(_) => SO3FFT_ENOMEM,
            Error::WrongDirection => SO3FFT_EDIRECTION,
            Error::Fftw(_) => SO3FFT_EFFTW,
        };
        CErr::new(code, e.to_string())
    }
}

fn set_error(code: c_int, msg: &str) {
    let msg = CString::new(msg.replace('\0', " ")).unwrap_or_default();
    // try_with: the thread may be exiting (TLS destroyed); then there is nowhere to report.
    let _ = LAST.try_with(|l| {
        if let Ok(mut l) = l.try_borrow_mut() {
            *l = LastError { code, msg };
        }
    });
}

fn clear_error() {
    let _ = LAST.try_with(|l| {
        if let Ok(mut l) = l.try_borrow_mut() {
            if l.code != 0 {
                *l = LastError {
                    code: 0,
                    msg: CString::default(),
                };
            }
        }
    });
}

fn panic_message(p: &(dyn std::any::Any + Send)) -> String {
    let what = if let Some(s) = p.downcast_ref::<&str>() {
        s
    } else if let Some(s) = p.downcast_ref::<String>() {
        s.as_str()
    } else {
        "unknown panic payload"
    };
    format!("internal error (panic): {what}")
}

/// Runs `f` at the C boundary: clears the thread's error state, converts errors and
/// panics into the error state and returns `fail` for them.
fn boundary<R>(fail: R, f: impl FnOnce() -> Result<R, CErr>) -> R {
    clear_error();
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(r)) => r,
        Ok(Err(e)) => {
            set_error(e.code, &e.msg);
            fail
        }
        Err(p) => {
            set_error(SO3FFT_EPANIC, &panic_message(&*p));
            fail
        }
    }
}

/// Like [`boundary`] for functions returning a count: the error's (negative) code on
/// failure.
fn boundary_count(f: impl FnOnce() -> Result<isize, CErr>) -> isize {
    clear_error();
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(v)) => v,
        Ok(Err(e)) => {
            set_error(e.code, &e.msg);
            e.code as isize
        }
        Err(p) => {
            set_error(SO3FFT_EPANIC, &panic_message(&*p));
            SO3FFT_EPANIC as isize
        }
    }
}

/// Like [`boundary`] for functions returning an error code.
fn boundary_code(f: impl FnOnce() -> Result<(), CErr>) -> c_int {
    clear_error();
    match catch_unwind(AssertUnwindSafe(f)) {
        Ok(Ok(())) => SO3FFT_OK,
        Ok(Err(e)) => {
            set_error(e.code, &e.msg);
            e.code
        }
        Err(p) => {
            set_error(SO3FFT_EPANIC, &panic_message(&*p));
            SO3FFT_EPANIC
        }
    }
}

// ---------------------------------------------------------------------------------------
// Validation helpers
// ---------------------------------------------------------------------------------------

fn check_bandwidth(b: c_int) -> Result<usize, CErr> {
    if !(1..=SO3FFT_MAX_BANDWIDTH).contains(&b) {
        return Err(CErr::new(
            SO3FFT_EBANDWIDTH,
            format!("invalid bandwidth {b}: must be between 1 and {SO3FFT_MAX_BANDWIDTH}"),
        ));
    }
    Ok(b as usize)
}

fn rigor_of(flags: c_uint) -> Result<Rigor, CErr> {
    let unknown = flags & !KNOWN_FLAGS;
    if unknown != 0 {
        return Err(CErr::new(
            SO3FFT_EINVAL,
            format!("unknown planner flag bits 0x{unknown:x} in flags 0x{flags:x}"),
        ));
    }
    Ok(if flags & SO3FFT_EXHAUSTIVE != 0 {
        Rigor::Exhaustive
    } else if flags & SO3FFT_PATIENT != 0 {
        Rigor::Patient
    } else if flags & SO3FFT_MEASURE != 0 {
        Rigor::Measure
    } else {
        Rigor::Estimate
    })
}

fn direction_of(direction: c_int) -> Result<Direction, CErr> {
    match direction {
        SO3FFT_FORWARD => Ok(Direction::Forward),
        SO3FFT_INVERSE => Ok(Direction::Inverse),
        SO3FFT_BOTH => Ok(Direction::Both),
        d => Err(CErr::new(
            SO3FFT_EINVAL,
            format!("unknown direction {d} (use SO3FFT_FORWARD, SO3FFT_INVERSE or SO3FFT_BOTH)"),
        )),
    }
}

fn threads_of(nthreads: c_int) -> Result<usize, CErr> {
    if nthreads < 0 {
        return Err(CErr::new(
            SO3FFT_EINVAL,
            format!("invalid thread count {nthreads}: must be >= 0 (0 = all cores)"),
        ));
    }
    Ok(nthreads as usize)
}

/// Byte range `[start, end)` of an array of `len` complex values at `p`, checking that it
/// is aligned like `double` and does not wrap around the address space.
fn byte_range(p: *const so3fft_complex, len: usize, what: &str) -> Result<(usize, usize), CErr> {
    let start = p as usize;
    if !start.is_multiple_of(std::mem::align_of::<c_double>()) {
        return Err(CErr::new(
            SO3FFT_EINVAL,
            format!(
                "{what} array {p:p} is not aligned to {} bytes (the alignment of double)",
                std::mem::align_of::<c_double>()
            ),
        ));
    }
    let end = len
        .checked_mul(std::mem::size_of::<so3fft_complex>())
        .and_then(|n| start.checked_add(n))
        .filter(|&e| e <= isize::MAX as usize)
        .ok_or_else(|| {
            CErr::new(
                SO3FFT_EINVAL,
                format!("{what} array {p:p} of {len} values does not fit in memory"),
            )
        })?;
    Ok((start, end))
}

/// Checks a pair of arrays (non-NULL, aligned, not overlapping).
fn check_arrays(
    input: *const so3fft_complex,
    in_len: usize,
    in_what: &str,
    output: *const so3fft_complex,
    out_len: usize,
    out_what: &str,
) -> Result<(), CErr> {
    if input.is_null() {
        return Err(CErr::new(
            SO3FFT_ENULL,
            format!("the {in_what} array is NULL"),
        ));
    }
    if output.is_null() {
        return Err(CErr::new(
            SO3FFT_ENULL,
            format!("the {out_what} array is NULL"),
        ));
    }
    let (a0, a1) = byte_range(input, in_len, in_what)?;
    let (b0, b1) = byte_range(output, out_len, out_what)?;
    if a0 < b1 && b0 < a1 {
        return Err(CErr::new(
            SO3FFT_EINVAL,
            format!("the {in_what} and {out_what} arrays overlap (in-place transforms are not supported)"),
        ));
    }
    Ok(())
}

fn plan_ref<'a>(p: so3fft_plan) -> Result<&'a so3fft_plan_s, CErr> {
    if p.is_null() {
        return Err(CErr::new(SO3FFT_ENULL, "the plan is NULL"));
    }
    // SAFETY: the caller passes a plan returned by a planner and not yet destroyed.
    Ok(unsafe { &*p })
}

/// Forward transform on caller arrays (validated here).
///
/// Requirements: `samples` and `coeffs` point to arrays of the sizes the plan needs.
unsafe fn run_forward(
    ps: &so3fft_plan_s,
    samples: *mut so3fft_complex,
    coeffs: *mut so3fft_complex,
) -> Result<(), CErr> {
    if ps.plan.direction() == Direction::Inverse {
        return Err(CErr::new(
            SO3FFT_EDIRECTION,
            "forward transform requested from a plan made for the inverse transform only",
        ));
    }
    let (ns, nc) = (ps.plan.num_samples(), ps.plan.num_coeffs());
    check_arrays(samples, ns, "samples", coeffs, nc, "coefficients")?;
    // SAFETY: non-NULL, aligned, non-overlapping; sizes are the caller's contract.
    // Complex64 is #[repr(C)] { re: f64, im: f64 }, the layout of double[2].
    let c = std::slice::from_raw_parts_mut(coeffs as *mut Complex64, nc);
    if ps.destroy_input {
        // SAFETY: as above; the caller allowed the samples to be overwritten.
        let s = std::slice::from_raw_parts_mut(samples as *mut Complex64, ns);
        return if ps.real {
            ps.plan
                .forward_real_parts_destroying_input(s, c)
                .map(|_| ())
        } else {
            ps.plan.forward_destroying_input(s, c)
        }
        .map_err(CErr::from);
    }
    let s = std::slice::from_raw_parts(samples as *const Complex64, ns);
    if ps.real {
        return ps
            .plan
            .forward_real_parts(s, c)
            .map(|_| ())
            .map_err(CErr::from);
    }
    ps.plan.forward(s, c).map_err(CErr::from)
}

/// Inverse transform on caller arrays (validated here).
///
/// Requirements: As [`run_forward`].
unsafe fn run_inverse(
    ps: &so3fft_plan_s,
    coeffs: *mut so3fft_complex,
    samples: *mut so3fft_complex,
) -> Result<(), CErr> {
    if ps.plan.direction() == Direction::Forward {
        return Err(CErr::new(
            SO3FFT_EDIRECTION,
            "inverse transform requested from a plan made for the forward transform only",
        ));
    }
    let (ns, nc) = (ps.plan.num_samples(), ps.plan.num_coeffs());
    check_arrays(coeffs, nc, "coefficients", samples, ns, "samples")?;
    // SAFETY: as in run_forward.
    let c = std::slice::from_raw_parts(coeffs as *const Complex64, nc);
    let s = std::slice::from_raw_parts_mut(samples as *mut Complex64, ns);
    if ps.real {
        return ps.plan.inverse_real_to_complex(c, s).map_err(CErr::from);
    }
    ps.plan.inverse(c, s).map_err(CErr::from)
}

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
    boundary_code(|| {
        threads_of(nthreads)?;
        PLANNER_THREADS.store(nthreads, Ordering::Relaxed);
        Ok(())
    })
}

/// The current process-wide thread setting of `so3fft_plan_with_nthreads`
/// (0 = all available cores). Thread-safe; never fails.
#[no_mangle]
pub extern "C" fn so3fft_planner_nthreads() -> c_int {
    clear_error();
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
    clear_error();
    PLANNER_MAX_WORKSPACE.store(bytes, Ordering::Relaxed);
    SO3FFT_OK
}

/// The current process-wide setting of `so3fft_plan_with_max_workspace` (0 = the library
/// default). Thread-safe; never fails.
#[no_mangle]
pub extern "C" fn so3fft_planner_max_workspace() -> usize {
    clear_error();
    PLANNER_MAX_WORKSPACE.load(Ordering::Relaxed)
}

/// The workspace cap of plans made now (`None`: the library default).
fn planner_workspace_cap() -> Option<usize> {
    match PLANNER_MAX_WORKSPACE.load(Ordering::Relaxed) {
        0 => None,
        bytes => Some(bytes),
    }
}

// ---------------------------------------------------------------------------------------
// Planners
// ---------------------------------------------------------------------------------------

fn make_plan(
    b: c_int,
    direction: c_int,
    input: *mut so3fft_complex,
    output: *mut so3fft_complex,
    flags: c_uint,
    nthreads: c_int,
) -> so3fft_plan {
    boundary(std::ptr::null_mut(), || {
        let b = check_bandwidth(b)?;
        let direction = direction_of(direction)?;
        let rigor = rigor_of(flags)?;
        let threads = threads_of(nthreads)?;
        match (input.is_null(), output.is_null()) {
            (true, true) => {}
            (false, false) => {
                if direction == Direction::Both {
                    return Err(CErr::new(
                        SO3FFT_EINVAL,
                        "a plan for both directions takes no arrays (pass NULL and use the new-array execute functions)",
                    ));
                }
                let (ns, nc) = (crate::num_samples(b), crate::num_coeffs(b));
                if direction == Direction::Forward {
                    check_arrays(input, ns, "samples", output, nc, "coefficients")?;
                } else {
                    check_arrays(input, nc, "coefficients", output, ns, "samples")?;
                }
            }
            _ => {
                return Err(CErr::new(
                    SO3FFT_ENULL,
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
    boundary((), || {
        if !p.is_null() {
            // SAFETY: `p` came from Box::into_raw in a planner (caller's contract).
            drop(unsafe { Box::from_raw(p) });
        }
        Ok(())
    })
}

// ---------------------------------------------------------------------------------------
// Execution
// ---------------------------------------------------------------------------------------

/// Executes a plan on the arrays given at planning: the forward transform for a
/// forward plan, the inverse for an inverse plan. The input array is not modified,
/// except by the forward of a plan made with `SO3FFT_DESTROY_INPUT`.
///
/// Returns `SO3FFT_OK`, or an error code with `so3fft_last_error()` set:
/// `SO3FFT_ENULL` (NULL plan, or a plan made without arrays, such as every
/// `so3fft_plan_both` plan), `SO3FFT_ENOMEM` (a concurrent execution of the same plan
/// could not allocate its temporary buffer), `SO3FFT_EFFTW`, `SO3FFT_EPANIC`. On error
/// the output array (and, with `SO3FFT_DESTROY_INPUT`, the forward's input) may have
/// been partly written; nothing outside them is.
///
/// Thread safety: a plan may be executed by several threads at the same time (each
/// call uses the plan's worker pool; a call that finds the plan's buffer in use
/// allocates a temporary one), but with this function they would all write the same
/// output array: use the new-array execute functions with distinct outputs instead.
///
/// Requirements: `p` is NULL or a live plan whose arrays are still valid.
#[no_mangle]
pub unsafe extern "C" fn so3fft_execute(p: so3fft_plan) -> c_int {
    boundary_code(|| {
        let ps = plan_ref(p)?;
        if ps.input.is_null() || ps.output.is_null() {
            return Err(CErr::new(
                SO3FFT_ENULL,
                "the plan was made without arrays: use so3fft_execute_forward or so3fft_execute_inverse",
            ));
        }
        // SAFETY: arrays given at planning (caller's contract: still valid).
        unsafe {
            match ps.plan.direction() {
                Direction::Forward => run_forward(ps, ps.input, ps.output),
                Direction::Inverse => run_inverse(ps, ps.input, ps.output),
                Direction::Both => Err(CErr::new(
                    SO3FFT_ENULL,
                    "a plan for both directions has no arrays",
                )),
            }
        }
    })
}

/// New-array execute of the forward transform: samples `in` (`(2B)^3` values) to
/// coefficients `out` (`(4B^3-B)/3` values) with a plan made by `so3fft_plan_forward`,
/// `so3fft_plan_both` or `so3fft_plan_general` (with or without arrays; the arrays
/// given at planning are ignored). `in` is not modified, unless the plan was made with
/// `SO3FFT_DESTROY_INPUT`: then its contents afterwards are unspecified (and on error too).
///
/// The arrays need no particular alignment beyond that of `double` (unlike FFTW's
/// new-array execute), must not overlap, and are not retained after the call.
///
/// Returns `SO3FFT_OK`, or `SO3FFT_ENULL` (NULL plan or array), `SO3FFT_EDIRECTION`
/// (inverse-only plan), `SO3FFT_EINVAL` (misaligned or overlapping arrays),
/// `SO3FFT_ENOMEM`, `SO3FFT_EFFTW`, `SO3FFT_EPANIC`, with `so3fft_last_error()` set.
/// Nothing is written on argument errors.
///
/// Thread safety: one plan may be executed from several threads at the same time on
/// different output arrays (inputs may be shared, except with `SO3FFT_DESTROY_INPUT`,
/// where each call needs its own input). A call that finds the plan's chunk
/// buffer in use by another call allocates a temporary one of `so3fft`'s workspace
/// size (may fail with `SO3FFT_ENOMEM`).
///
/// Requirements: `p` is NULL or a live plan; non-NULL arrays have the sizes above.
#[no_mangle]
pub unsafe extern "C" fn so3fft_execute_forward(
    p: so3fft_plan,
    r#in: *mut so3fft_complex,
    out: *mut so3fft_complex,
) -> c_int {
    boundary_code(|| {
        let ps = plan_ref(p)?;
        // SAFETY: validated in run_forward; sizes are the caller's contract.
        unsafe { run_forward(ps, r#in, out) }
    })
}

/// New-array execute of the inverse transform: coefficients `in` (`(4B^3-B)/3`
/// values) to samples `out` (`(2B)^3` values) with a plan made by
/// `so3fft_plan_inverse`, `so3fft_plan_both` or `so3fft_plan_general`.
///
/// Everything else as for `so3fft_execute_forward` (`SO3FFT_EDIRECTION` for a
/// forward-only plan).
///
/// Requirements: `p` is NULL or a live plan; non-NULL arrays have the sizes above.
#[no_mangle]
pub unsafe extern "C" fn so3fft_execute_inverse(
    p: so3fft_plan,
    r#in: *mut so3fft_complex,
    out: *mut so3fft_complex,
) -> c_int {
    boundary_code(|| {
        let ps = plan_ref(p)?;
        // SAFETY: validated in run_inverse; sizes are the caller's contract.
        unsafe { run_inverse(ps, r#in, out) }
    })
}

/// The bandwidth of a plan, or `SO3FFT_ENULL` if `p` is NULL. Thread-safe.
///
/// Requirements: `p` is NULL or a live plan.
#[no_mangle]
pub unsafe extern "C" fn so3fft_get_bandwidth(p: so3fft_plan) -> c_int {
    boundary(SO3FFT_ENULL, || Ok(plan_ref(p)?.plan.bandwidth() as c_int))
}

/// The number of worker threads of a plan (after resolving 0 = all cores), or
/// `SO3FFT_ENULL` if `p` is NULL. Thread-safe.
///
/// Requirements: `p` is NULL or a live plan.
#[no_mangle]
pub unsafe extern "C" fn so3fft_get_nthreads(p: so3fft_plan) -> c_int {
    boundary(SO3FFT_ENULL, || Ok(plan_ref(p)?.plan.threads() as c_int))
}

/// Bytes of memory a plan holds: its chunk buffer (beta slices in the layout of the
/// Wigner transforms), per-worker FFT buffers and `O(B^2)` tables; `SO3FFT_ENULL` if `p`
/// is NULL. A transform needs its input and output arrays on top and nothing else large.
/// Thread-safe.
///
/// Requirements: `p` is NULL or a live plan.
#[no_mangle]
pub unsafe extern "C" fn so3fft_get_memory(p: so3fft_plan) -> isize {
    boundary_count(|| Ok(plan_ref(p)?.plan.memory_bytes() as isize))
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
    boundary_count(|| {
        let b = check_bandwidth(B)?;
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
    boundary(SO3FFT_ENULL, || {
        Ok(match plan_ref(p)?.plan.fft_threading() {
            crate::FftThreading::FftwThreads => SO3FFT_FFT_FFTW_THREADS,
            _ => SO3FFT_FFT_SLICES_ACROSS_WORKERS,
        })
    })
}

// ---------------------------------------------------------------------------------------
// Sizes, indices, grid
// ---------------------------------------------------------------------------------------

/// Number of samples `(2B)^3` at bandwidth `B`: the length of a sample array.
/// Returns 0 (and sets the error state to `SO3FFT_EBANDWIDTH`) for an invalid `B`.
/// Thread-safe, as are all the helpers below.
#[no_mangle]
pub extern "C" fn so3fft_num_samples(B: c_int) -> usize {
    boundary(0, || Ok(crate::num_samples(check_bandwidth(B)?)))
}

/// Number of coefficients `(4B^3-B)/3` at bandwidth `B`: the length of a coefficient
/// array. Returns 0 (and sets `SO3FFT_EBANDWIDTH`) for an invalid `B`.
#[no_mangle]
pub extern "C" fn so3fft_num_coeffs(B: c_int) -> usize {
    boundary(0, || Ok(crate::num_coeffs(check_bandwidth(B)?)))
}

/// Index of the coefficient `fhat(l, m, mp)` in a coefficient array (SOFT's
/// `so3CoefLoc(m, mp, l, B)`; note the different argument order). `m` pairs with
/// alpha, `mp` with gamma. Requires `0 <= l < B`, `|m| <= l`, `|mp| <= l`.
///
/// Returns the index, or -1 (error state `SO3FFT_EBANDWIDTH` or `SO3FFT_EINVAL`).
#[no_mangle]
pub extern "C" fn so3fft_coef_index(B: c_int, l: c_int, m: c_int, mp: c_int) -> isize {
    boundary(-1, || {
        let b = check_bandwidth(B)?;
        if l < 0 {
            return Err(CErr::new(
                SO3FFT_EINVAL,
                format!("coefficient (l={l}, m={m}, m'={mp}) does not exist at bandwidth {b}"),
            ));
        }
        let i = crate::try_coef_index(b, l as usize, m as isize, mp as isize)?;
        Ok(i as isize)
    })
}

/// Index of the sample `f(alpha_{j_alpha}, beta_{k_beta}, gamma_{j_gamma})` in a sample
/// array: `k_beta*(2B)^2 + j_alpha*(2B) + j_gamma`. Requires all three in `0 .. 2B-1`.
///
/// Returns the index, or -1 (error state `SO3FFT_EBANDWIDTH` or `SO3FFT_EINVAL`).
#[no_mangle]
pub extern "C" fn so3fft_sample_index(
    B: c_int,
    j_alpha: c_int,
    k_beta: c_int,
    j_gamma: c_int,
) -> isize {
    boundary(-1, || {
        let b = check_bandwidth(B)?;
        let n = 2 * B;
        for (v, name) in [
            (j_alpha, "j_alpha"),
            (k_beta, "k_beta"),
            (j_gamma, "j_gamma"),
        ] {
            if v < 0 || v >= n {
                return Err(CErr::new(
                    SO3FFT_EINVAL,
                    format!("{name} = {v} out of range 0..{} at bandwidth {b}", n - 1),
                ));
            }
        }
        Ok(crate::sample_index(b, j_alpha as usize, k_beta as usize, j_gamma as usize) as isize)
    })
}

fn angle(b: c_int, j: c_int, name: &str, f: fn(usize, usize) -> f64) -> f64 {
    boundary(f64::NAN, || {
        let bw = check_bandwidth(b)?;
        if j < 0 || j >= 2 * b {
            return Err(CErr::new(
                SO3FFT_EINVAL,
                format!(
                    "{name} index {j} out of range 0..{} at bandwidth {bw}",
                    2 * b - 1
                ),
            ));
        }
        Ok(f(bw, j as usize))
    })
}

/// Sample angle `alpha_j = pi j / B`, `0 <= j < 2B`. NaN on invalid arguments (error
/// state `SO3FFT_EBANDWIDTH` or `SO3FFT_EINVAL`).
#[no_mangle]
pub extern "C" fn so3fft_alpha(B: c_int, j: c_int) -> c_double {
    angle(B, j, "alpha", crate::alpha)
}

/// Sample angle `beta_k = pi (2k+1) / (4B)`, `0 <= k < 2B`. NaN on invalid arguments.
#[no_mangle]
pub extern "C" fn so3fft_beta(B: c_int, k: c_int) -> c_double {
    angle(B, k, "beta", crate::beta)
}

/// Sample angle `gamma_j = pi j / B`, `0 <= j < 2B`. NaN on invalid arguments.
#[no_mangle]
pub extern "C" fn so3fft_gamma(B: c_int, j: c_int) -> c_double {
    angle(B, j, "gamma", crate::gamma)
}

/// Fills `w[0 .. 2B-1]` with the quadrature weights
/// `w_B(k) = (2/B) sin(beta_k) sum_{i<B} sin((2i+1) beta_k)/(2i+1)` (the values of
/// SOFT's `makeweights2`). Writes exactly `2B` doubles; no alignment beyond that of
/// `double` is required.
///
/// Returns `SO3FFT_OK`, or `SO3FFT_EBANDWIDTH`, `SO3FFT_ENULL` or `SO3FFT_EINVAL` (`w` not
/// aligned like `double`); nothing is written then.
///
/// Requirements: `w` is NULL or points to at least `2B` writable doubles.
#[no_mangle]
pub unsafe extern "C" fn so3fft_weights(B: c_int, w: *mut c_double) -> c_int {
    boundary_code(|| {
        let b = check_bandwidth(B)?;
        if w.is_null() {
            return Err(CErr::new(SO3FFT_ENULL, "the weights array is NULL"));
        }
        if !(w as usize).is_multiple_of(std::mem::align_of::<c_double>()) {
            return Err(CErr::new(
                SO3FFT_EINVAL,
                "the weights array is not aligned like double",
            ));
        }
        let v = crate::weights(b);
        // SAFETY: `w` has room for 2B doubles (caller's contract); v.len() == 2B.
        unsafe { std::ptr::copy_nonoverlapping(v.as_ptr(), w, v.len()) };
        Ok(())
    })
}

/// Largest bandwidth accepted (the value of `SO3FFT_MAX_BANDWIDTH` in the library
/// actually linked). Never fails.
#[no_mangle]
pub extern "C" fn so3fft_max_bandwidth() -> c_int {
    clear_error();
    SO3FFT_MAX_BANDWIDTH
}

// ---------------------------------------------------------------------------------------
// Version and errors
// ---------------------------------------------------------------------------------------

static VERSION: &str = concat!(env!("CARGO_PKG_VERSION"), "\0");

/// The library version, e.g. "0.1.0" (the value of `SO3FFT_VERSION` in the library
/// actually linked). A static string: do not free. Thread-safe; does not touch the
/// error state.
#[no_mangle]
pub extern "C" fn so3fft_version() -> *const c_char {
    VERSION.as_ptr() as *const c_char
}

/// The code of the last error on the calling thread: `SO3FFT_OK` (0) if the last
/// so3fft call on this thread succeeded, else one of the negative `SO3FFT_E*` codes.
/// Every so3fft function except `so3fft_last_error_code`, `so3fft_last_error`,
/// `so3fft_strerror` and `so3fft_version` resets the error state when it starts.
/// Useful after a planner returned NULL.
#[no_mangle]
pub extern "C" fn so3fft_last_error_code() -> c_int {
    LAST.try_with(|l| l.try_borrow().map(|l| l.code).unwrap_or(0))
        .unwrap_or(0)
}

/// A message describing the last error on the calling thread, "" if the last so3fft
/// call on this thread succeeded. Never NULL. The string is owned by the library and
/// stays valid until the next so3fft call on the same thread (other than
/// `so3fft_last_error_code`, `so3fft_last_error`, `so3fft_strerror`, `so3fft_version`)
/// or until the thread exits: copy it to keep it.
#[no_mangle]
pub extern "C" fn so3fft_last_error() -> *const c_char {
    static EMPTY: &[u8] = b"\0";
    LAST.try_with(|l| l.try_borrow().map(|l| l.msg.as_ptr()).ok())
        .ok()
        .flatten()
        .unwrap_or(EMPTY.as_ptr() as *const c_char)
}

/// A static description of an error code ("success", "invalid argument", ...; "unknown
/// error code" for other values). Do not free. Thread-safe; does not touch the error
/// state.
#[no_mangle]
pub extern "C" fn so3fft_strerror(code: c_int) -> *const c_char {
    let s: &'static str = match code {
        SO3FFT_OK => "success\0",
        SO3FFT_EINVAL => "invalid argument\0",
        SO3FFT_EBANDWIDTH => "invalid bandwidth\0",
        SO3FFT_ENULL => "NULL pointer\0",
        SO3FFT_ENOMEM => "out of memory\0",
        SO3FFT_EDIRECTION => "plan made for the other direction\0",
        SO3FFT_EFFTW => "FFTW could not create a plan\0",
        SO3FFT_EPANIC => "internal error\0",
        _ => "unknown error code\0",
    };
    s.as_ptr() as *const c_char
}

/// Test hook (not in the public header): panics inside the boundary, so the C tests can
/// check that panics become `SO3FFT_EPANIC` instead of crossing into C.
#[doc(hidden)]
#[no_mangle]
pub extern "C" fn so3fft_internal_test_panic() -> c_int {
    boundary_code(|| panic!("test panic requested by so3fft_internal_test_panic"))
}
