//! Execution: `so3fft_execute` on the arrays given at planning, and the new-array execute
//! functions.
//!
//! The bodies are generic over the plan's handle ([`PlanHandle`]), whose element type is the
//! precision: the `so3fft_execute*` functions here and the `so3fftf_execute*` ones of
//! `single.rs` are one-line wrappers over them.

use super::{guarded_code, plan_ref, so3fft_complex, so3fft_plan, PlanHandle, PlanState};
use crate::ffi::checks::{input_output, Array};
use crate::ffi::{CallError, ErrorKind};
use crate::{Complex, Direction, Real};
use std::ffi::c_int;

/// Forward transform of the plan `state` from the samples at `samples` to the coefficients
/// at `coeffs`, after checking the direction and the arrays (non-NULL, aligned like `T`,
/// not overlapping).
///
/// # Safety
/// Non-NULL `samples` and `coeffs` point to `(2B)^3` and `(4B^3-B)/3` values of the plan's
/// bandwidth `B`, not accessed by anyone else during the call (the samples may be read
/// concurrently unless the plan destroys its input).
unsafe fn run_forward<T: Real>(
    state: &PlanState<T>,
    samples: *mut [T; 2],
    coeffs: *mut [T; 2],
) -> Result<(), CallError> {
    if state.plan.direction() == Direction::Inverse {
        return Err(CallError::new(
            ErrorKind::Direction,
            "forward transform requested from a plan made for the inverse transform only",
        ));
    }
    let plan = &state.plan;
    let (ns, nc) = (plan.num_samples(), plan.num_coeffs());
    input_output(
        &Array::new(samples, ns, "samples"),
        &Array::new(coeffs, nc, "coefficients"),
    )?;
    // SAFETY: checked non-NULL, aligned and disjoint; `nc` values by this function's
    // contract. Complex<T> is #[repr(C)] { re: T, im: T }, the layout of T[2].
    let coeffs = unsafe { std::slice::from_raw_parts_mut(coeffs.cast::<Complex<T>>(), nc) };
    // SAFETY: as above, `ns` values, only read.
    let samples =
        unsafe { std::slice::from_raw_parts(samples.cast_const().cast::<Complex<T>>(), ns) };
    if state.real {
        return plan
            .engine()
            .forward_real_parts(samples, coeffs)
            .map(|_| ())
            .map_err(CallError::from);
    }
    plan.forward(samples, coeffs)
        .map(|_| ())
        .map_err(CallError::from)
}

/// Inverse transform of the plan `state` from the coefficients at `coeffs` to the samples
/// at `samples`, after the same checks as [`run_forward`].
///
/// # Safety
/// As [`run_forward`]; the coefficients are only read.
unsafe fn run_inverse<T: Real>(
    state: &PlanState<T>,
    coeffs: *mut [T; 2],
    samples: *mut [T; 2],
) -> Result<(), CallError> {
    if state.plan.direction() == Direction::Forward {
        return Err(CallError::new(
            ErrorKind::Direction,
            "inverse transform requested from a plan made for the forward transform only",
        ));
    }
    let plan = &state.plan;
    let (ns, nc) = (plan.num_samples(), plan.num_coeffs());
    input_output(
        &Array::new(coeffs, nc, "coefficients"),
        &Array::new(samples, ns, "samples"),
    )?;
    // SAFETY: checked non-NULL, aligned and disjoint; the sizes by this function's contract;
    // the coefficients are only read, the samples only written by this call.
    let (coeffs, samples) = unsafe {
        (
            std::slice::from_raw_parts(coeffs.cast_const().cast::<Complex<T>>(), nc),
            std::slice::from_raw_parts_mut(samples.cast::<Complex<T>>(), ns),
        )
    };
    if state.real {
        return plan
            .engine()
            .inverse_real_to_complex(coeffs, samples)
            .map(|_| ())
            .map_err(CallError::from);
    }
    plan.inverse(coeffs, samples)
        .map(|_| ())
        .map_err(CallError::from)
}

/// The body of `so3fft_execute` for the handle type `H`.
///
/// # Safety
/// `p` is NULL or a live plan of type `H`, whose arrays given at planning are still valid
/// (the API's contract).
pub(super) unsafe fn execute<H: PlanHandle>(p: *mut H) -> c_int {
    guarded_code(|| {
        // SAFETY: `p` is NULL or a live plan (this function's contract).
        let state = unsafe { plan_ref(p) }?;
        if state.input.is_null() || state.output.is_null() {
            return Err(CallError::new(
                ErrorKind::Null,
                format!(
                    "the plan was made without arrays: use {0}_execute_forward or {0}_execute_inverse",
                    H::PREFIX
                ),
            ));
        }
        // SAFETY: the arrays given at planning were checked then (non-NULL, aligned, disjoint)
        // and have the sizes of the plan's bandwidth; the caller keeps them valid as long as
        // the plan is executed on them (its contract); run_* check them again.
        unsafe {
            match state.plan.direction() {
                Direction::Forward => run_forward(state, state.input, state.output),
                Direction::Inverse => run_inverse(state, state.input, state.output),
                Direction::Both => Err(CallError::new(
                    ErrorKind::Null,
                    "a plan for both directions has no arrays",
                )),
            }
        }
    })
}

/// The body of `so3fft_execute_forward` for the handle type `H`.
///
/// # Safety
/// `p` is NULL or a live plan of type `H`, and non-NULL arrays have the sizes of its
/// bandwidth (the API's contract).
pub(super) unsafe fn execute_forward<H: PlanHandle>(
    p: *mut H,
    samples: *mut [H::T; 2],
    coeffs: *mut [H::T; 2],
) -> c_int {
    guarded_code(|| {
        // SAFETY: `p` is NULL or a live plan, and non-NULL arrays have the sizes of its
        // bandwidth (this function's contract); run_forward checks the rest.
        unsafe { run_forward(plan_ref(p)?, samples, coeffs) }
    })
}

/// The body of `so3fft_execute_inverse` for the handle type `H`.
///
/// # Safety
/// As [`execute_forward`].
pub(super) unsafe fn execute_inverse<H: PlanHandle>(
    p: *mut H,
    coeffs: *mut [H::T; 2],
    samples: *mut [H::T; 2],
) -> c_int {
    guarded_code(|| {
        // SAFETY: `p` is NULL or a live plan, and non-NULL arrays have the sizes of its
        // bandwidth (this function's contract); run_inverse checks the rest.
        unsafe { run_inverse(plan_ref(p)?, coeffs, samples) }
    })
}

/// Executes a plan on the arrays given at planning. Returns `SO3FFT_OK` or an error code.
#[no_mangle]
pub unsafe extern "C" fn so3fft_execute(p: so3fft_plan) -> c_int {
    // SAFETY: `p` is NULL or a live plan whose planning arrays are valid (the caller's
    // contract, see the module doc).
    unsafe { execute(p) }
}

/// Forward transform of samples `in` into coefficients `out` (new-array execute).
#[no_mangle]
pub unsafe extern "C" fn so3fft_execute_forward(
    p: so3fft_plan,
    r#in: *mut so3fft_complex,
    out: *mut so3fft_complex,
) -> c_int {
    // SAFETY: `p` is NULL or a live plan, and non-NULL arrays have the sizes of its
    // bandwidth (the caller's contract, see the module doc).
    unsafe { execute_forward(p, r#in, out) }
}

/// Inverse transform of coefficients `in` into samples `out` (new-array execute).
#[no_mangle]
pub unsafe extern "C" fn so3fft_execute_inverse(
    p: so3fft_plan,
    r#in: *mut so3fft_complex,
    out: *mut so3fft_complex,
) -> c_int {
    // SAFETY: as in `so3fft_execute_forward`.
    unsafe { execute_inverse(p, r#in, out) }
}
