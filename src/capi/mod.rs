//! The native C API, in the spirit of `fftw3.h`. `include/so3fft.h` is generated from this
//! module and its submodules by `build.rs` through cbindgen: their doc comments are the
//! header's (terse) comments. The full reference is `docs/c-api.md`.
//!
//! Every exported function runs through the shared boundary of `crate::ffi`: panics are
//! caught, arguments checked, and failures reported through a return value plus the
//! thread-local error state (code and message). Nothing is written outside the caller's
//! arrays, whose sizes are fixed by the bandwidth.
//!
//! # Safety
//!
//! The `unsafe` functions dereference the caller's pointers. Their contract, the same for all:
//!
//! - a plan argument `p` is NULL or a plan returned by a planner and not yet destroyed, and
//!   no other thread destroys it during the call;
//! - a non-NULL array argument points to at least the number of values the function
//!   documents for the plan's bandwidth (`(2B)^3` samples, `(4B^3-B)/3` coefficients, `2B`
//!   weights), valid for reads (inputs) or writes (outputs) for the whole call, and no other
//!   thread writes an input or accesses an output during the call;
//! - the arrays given to a planner stay valid as long as `so3fft_execute` is used on the plan.
//!
//! The library checks what it can: NULL, alignment like the element type (`double`, or
//! `float` for the single-precision `so3fftf_*` functions), overlap of input and output, and
//! that an array's extent fits in the address space. The extent itself cannot be checked and
//! rests on the caller, as with FFTW.

// Names follow C conventions (so3fft_plan, B); the safety contract is stated once above
// rather than in a "# Safety" section per function (those sections would fill the header).
#![allow(non_camel_case_types, non_snake_case, clippy::missing_safety_doc)]

// Declared in the order of their items in the header: cbindgen follows the declarations.
// A comment before each keeps rustfmt from sorting them.
// Planner settings, planners, destroy.
mod planner;
// Execute, new-array execute.
mod execute;
// Plan queries, memory of a plan to be made.
mod query;
// Sizes, indices, angles, weights.
mod grid;
// Partial plans (guru interface).
mod partial;
// Distributed plans for libso3fft_mpi (private so3fft_dist_* entry points).
mod distributed;
// Spherical-harmonic transforms.
mod s2;
// Rotational matching.
mod matching;
// FFTW wisdom.
mod wisdom;
// Version and errors.
mod errors;
// Single precision (so3fftf_*): last, so that its section follows the double API.
mod single;
// Single-precision rotational matching (so3fftf_correlation ...).
mod single_matching;

use crate::ffi::last_error::LastErrorSink;
use crate::ffi::{boundary, CallError, ErrorKind};
use crate::{Direction, Plan, Real, Rigor, MAX_BANDWIDTH};
use std::ffi::{c_double, c_int, c_uint};

/// One complex number `{re, im}`, identical to `fftw_complex` (`double[2]`).
pub type so3fft_complex = [c_double; 2];

/// Opaque plan object (made by a planner, released by `so3fft_destroy_plan`).
pub struct so3fft_plan_s {
    state: PlanState<f64>,
}

/// A plan: a pointer to an opaque object (like `fftw_plan`).
pub type so3fft_plan = *mut so3fft_plan_s;

/// What an SO(3) plan handle of the element type `T` holds: the plan and the arrays given
/// at planning.
struct PlanState<T: Real> {
    plan: Plan<T>,
    /// Input array given at planning (samples for a forward plan, coefficients for an
    /// inverse plan), or NULL.
    input: *mut [T; 2],
    /// Output array given at planning, or NULL.
    output: *mut [T; 2],
    /// Made with `SO3FFT_REAL`: transforms take the real-signal path.
    real: bool,
}

/// The opaque object behind the SO(3) plan handles of one precision (`so3fft_plan_s`,
/// `so3fftf_plan_s`): it owns a [`PlanState`] of its element type. The bodies of the
/// planners, executes and queries are generic over it.
trait PlanHandle: Sized + 'static {
    /// The element type of the plan (`f64` or `f32`).
    type T: Real;
    /// The prefix of the precision's C names (`so3fft` or `so3fftf`), for messages.
    const PREFIX: &'static str;
    /// The object owning `state`.
    fn wrap(state: PlanState<Self::T>) -> Self;
    /// The state it owns.
    fn state(&self) -> &PlanState<Self::T>;
}

impl PlanHandle for so3fft_plan_s {
    type T = f64;
    const PREFIX: &'static str = "so3fft";
    fn wrap(state: PlanState<f64>) -> Self {
        so3fft_plan_s { state }
    }
    fn state(&self) -> &PlanState<f64> {
        &self.state
    }
}

// ---------------------------------------------------------------------------------------
// Constants
// ---------------------------------------------------------------------------------------

/// Largest bandwidth `B` accepted.
pub const SO3FFT_MAX_BANDWIDTH: c_int = 2048;
const _: () = assert!(SO3FFT_MAX_BANDWIDTH as usize == MAX_BANDWIDTH);

/// Planner flag: heuristic FFTW plans, no measurement (the default, 0).
#[allow(dead_code)] // for the header: the default is the absence of the other flags
pub const SO3FFT_ESTIMATE: c_uint = 0;
/// Planner flag: FFTW measures a few candidate plans (on so3fft's own scratch memory).
pub const SO3FFT_MEASURE: c_uint = 1;
/// Planner flag: FFTW measures more candidates.
pub const SO3FFT_PATIENT: c_uint = 2;
/// Planner flag: FFTW measures every candidate (the most rigorous flag given applies).
pub const SO3FFT_EXHAUSTIVE: c_uint = 4;
/// Planner flag: the forward transform may overwrite its sample array (accepted; the
/// library leaves the samples as they are at present).
pub const SO3FFT_DESTROY_INPUT: c_uint = 16;
/// Planner flag: real-valued signal (same layouts, about half the work).
pub const SO3FFT_REAL: c_uint = 32;

const KNOWN_FLAGS: c_uint =
    SO3FFT_MEASURE | SO3FFT_PATIENT | SO3FFT_EXHAUSTIVE | SO3FFT_DESTROY_INPUT | SO3FFT_REAL;

/// Direction for `so3fft_plan_general`: samples to coefficients.
pub const SO3FFT_FORWARD: c_int = 1;
/// Direction for `so3fft_plan_general`: coefficients to samples.
pub const SO3FFT_INVERSE: c_int = 2;
/// Direction for `so3fft_plan_general`: both (no arrays; new-array execute only).
pub const SO3FFT_BOTH: c_int = 3;

/// FFT threading: each worker transforms whole slices with a single-threaded FFTW plan.
pub const SO3FFT_FFT_SLICES_ACROSS_WORKERS: c_int = 1;
/// FFT threading: formerly slices on FFTW's own threads; accepted, same plan as
/// `SO3FFT_FFT_SLICES_ACROSS_WORKERS`.
pub const SO3FFT_FFT_FFTW_THREADS: c_int = 2;

/// Success.
pub const SO3FFT_OK: c_int = 0;
/// Invalid argument (flags, index, thread count, direction; misaligned or overlapping arrays).
pub const SO3FFT_EINVAL: c_int = -1;
/// Bandwidth `B` outside `1 .. SO3FFT_MAX_BANDWIDTH`.
pub const SO3FFT_EBANDWIDTH: c_int = -2;
/// A required pointer is NULL (plan, array, or the arrays of a plan made without them).
pub const SO3FFT_ENULL: c_int = -3;
/// Memory allocation failed (nothing leaked; the library stays usable).
pub const SO3FFT_ENOMEM: c_int = -4;
/// The plan was made for the other direction only.
pub const SO3FFT_EDIRECTION: c_int = -5;
/// FFTW could not create a plan.
pub const SO3FFT_EFFTW: c_int = -6;
/// Internal error (a Rust panic caught at the boundary). Please report it.
pub const SO3FFT_EPANIC: c_int = -7;
// ---------------------------------------------------------------------------------------
// Error codes, the boundary and argument conversion
// ---------------------------------------------------------------------------------------

/// The `SO3FFT_E*` code of an error kind.
fn error_code(kind: ErrorKind) -> c_int {
    match kind {
        ErrorKind::Invalid => SO3FFT_EINVAL,
        ErrorKind::Bandwidth => SO3FFT_EBANDWIDTH,
        ErrorKind::Null => SO3FFT_ENULL,
        ErrorKind::NoMemory => SO3FFT_ENOMEM,
        ErrorKind::Direction => SO3FFT_EDIRECTION,
        ErrorKind::Fftw => SO3FFT_EFFTW,
        ErrorKind::Panic => SO3FFT_EPANIC,
    }
}

/// Runs the body of a native entry point through the shared boundary (error state reset,
/// panics caught, failures recorded in the thread's error state); `fail` on failure.
fn guarded<R>(fail: R, body: impl FnOnce() -> Result<R, CallError>) -> R {
    boundary(&LastErrorSink, body).unwrap_or(fail)
}

/// [`guarded`] for functions returning an error code: `SO3FFT_OK` or the error's code.
fn guarded_code(body: impl FnOnce() -> Result<(), CallError>) -> c_int {
    boundary(&LastErrorSink, body).map_or_else(error_code, |()| SO3FFT_OK)
}

/// [`guarded`] for functions returning a count: the count or the error's (negative) code.
fn guarded_count(body: impl FnOnce() -> Result<isize, CallError>) -> isize {
    boundary(&LastErrorSink, body).unwrap_or_else(|kind| error_code(kind) as isize)
}

/// The FFTW rigour of planner `flags`; an error for unknown flag bits.
fn rigor_of(flags: c_uint) -> Result<Rigor, CallError> {
    let unknown = flags & !KNOWN_FLAGS;
    if unknown != 0 {
        return Err(CallError::invalid(format!(
            "unknown planner flag bits 0x{unknown:x} in flags 0x{flags:x}"
        )));
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

/// The direction of an `SO3FFT_FORWARD` / `SO3FFT_INVERSE` / `SO3FFT_BOTH` value.
fn direction_of(direction: c_int) -> Result<Direction, CallError> {
    match direction {
        SO3FFT_FORWARD => Ok(Direction::Forward),
        SO3FFT_INVERSE => Ok(Direction::Inverse),
        SO3FFT_BOTH => Ok(Direction::Both),
        d => Err(CallError::invalid(format!(
            "unknown direction {d} (use SO3FFT_FORWARD, SO3FFT_INVERSE or SO3FFT_BOTH)"
        ))),
    }
}

/// A thread count argument (0 = all cores); an error if negative.
fn threads_of(nthreads: c_int) -> Result<usize, CallError> {
    usize::try_from(nthreads).map_err(|_| {
        CallError::invalid(format!(
            "invalid thread count {nthreads}: must be >= 0 (0 = all cores)"
        ))
    })
}

/// The plan state behind a handle; an error for NULL.
///
/// # Safety
/// `p` is NULL or a plan returned by a planner of `H` and not destroyed yet, not destroyed
/// while the returned reference is used.
unsafe fn plan_ref<'a, H: PlanHandle>(p: *mut H) -> Result<&'a PlanState<H::T>, CallError> {
    // SAFETY: non-NULL handles are live plans (this function's contract); the plan is only
    // read through shared references, so concurrent calls on one plan do not alias mutably.
    unsafe { p.as_ref() }
        .map(H::state)
        .ok_or_else(|| CallError::new(ErrorKind::Null, "the plan is NULL"))
}
