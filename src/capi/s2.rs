//! Spherical-harmonic (S^2) transforms: planner, execute, destroy, sizes and index.
//!
//! The bodies are generic over the plan's handle ([`S2Handle`]), whose element type is the
//! precision: the `so3fft_s2_*` functions here and the `so3fftf_s2_*` ones of `single.rs`
//! are one-line wrappers over them.

use super::{guarded, guarded_code, rigor_of, so3fft_complex, threads_of, SO3FFT_ENULL};
use super::{SO3FFT_DESTROY_INPUT, SO3FFT_REAL};
use crate::ffi::checks::{self, input_output, Array};
use crate::ffi::{CallError, ErrorKind};
use crate::options::Options;
use crate::s2::{s2_num_coeffs, s2_num_samples, s2_try_coef_index, S2Limits, S2Plan};
use crate::{Complex, Real};
use std::ffi::{c_int, c_uint};

/// Largest bandwidth of the S^2 transforms.
pub const SO3FFT_S2_MAX_BANDWIDTH: c_int = 4096;
const _: () = assert!(SO3FFT_S2_MAX_BANDWIDTH as usize == crate::s2::S2_MAX_BANDWIDTH);

/// Opaque S^2 plan object (made by `so3fft_plan_s2`, released by `so3fft_destroy_s2_plan`).
pub struct so3fft_s2_plan_s {
    plan: S2Plan<f64>,
}

/// An S^2 plan: a pointer to an opaque object.
pub type so3fft_s2_plan = *mut so3fft_s2_plan_s;

/// The opaque object behind the S^2 plan handles of one precision (`so3fft_s2_plan_s`,
/// `so3fftf_s2_plan_s`): it owns an `S2Plan` of its element type.
pub(super) trait S2Handle: Sized + 'static {
    /// The element type of the plan (`f64` or `f32`).
    type T: Real;
    /// The object owning `plan`.
    fn wrap(plan: S2Plan<Self::T>) -> Self;
    /// The plan it owns.
    fn plan(&self) -> &S2Plan<Self::T>;
}

impl S2Handle for so3fft_s2_plan_s {
    type T = f64;
    fn wrap(plan: S2Plan<f64>) -> Self {
        so3fft_s2_plan_s { plan }
    }
    fn plan(&self) -> &S2Plan<f64> {
        &self.plan
    }
}

/// The S^2 bandwidth `b` as a `usize`, or an error unless `1 <= b <= SO3FFT_S2_MAX_BANDWIDTH`.
fn s2_bandwidth(b: c_int) -> Result<usize, CallError> {
    checks::bandwidth_up_to(b, SO3FFT_S2_MAX_BANDWIDTH as usize)
}

/// The body of `so3fft_plan_s2` for the handle type `H`: a new plan, or NULL on error.
pub(super) fn plan_s2<H: S2Handle>(B: c_int, flags: c_uint, nthreads: c_int) -> *mut H {
    guarded(std::ptr::null_mut(), || {
        let b = s2_bandwidth(B)?;
        if flags & (SO3FFT_DESTROY_INPUT | SO3FFT_REAL) != 0 {
            return Err(CallError::invalid(format!(
                "flags 0x{flags:x}: an S^2 plan takes only a planner rigour (real samples have their own execute functions)"
            )));
        }
        let options = Options {
            threads: threads_of(nthreads)?,
            rigor: rigor_of(flags)?,
            ..Options::default()
        };
        let plan = S2Plan::<H::T>::new(b, &options)?;
        Ok(Box::into_raw(Box::new(H::wrap(plan))))
    })
}

/// The body of `so3fft_plan_s2_limited` for the handle type `H`.
pub(super) fn plan_s2_limited<H: S2Handle>(
    B: c_int,
    L: c_int,
    Mmax: c_int,
    flags: c_uint,
    nthreads: c_int,
) -> *mut H {
    guarded(std::ptr::null_mut(), || {
        let b = s2_bandwidth(B)?;
        let limit = |v: c_int, what: &str| {
            usize::try_from(v).map_err(|_| CallError::invalid(format!("{what} {v} must be >= 0")))
        };
        if flags & (SO3FFT_DESTROY_INPUT | SO3FFT_REAL) != 0 {
            return Err(CallError::invalid(format!(
                "flags 0x{flags:x}: an S^2 plan takes only a planner rigour"
            )));
        }
        let options = Options {
            threads: threads_of(nthreads)?,
            rigor: rigor_of(flags)?,
            ..Options::default()
        };
        let limits = S2Limits {
            degree_limit: Some(limit(L, "degree limit L")?),
            order_limit: Some(limit(Mmax, "order limit Mmax")?),
        };
        let plan = S2Plan::<H::T>::with_limits(b, limits, &options)?;
        Ok(Box::into_raw(Box::new(H::wrap(plan))))
    })
}

/// The body of `so3fft_destroy_s2_plan` for the handle type `H`.
///
/// # Safety
/// `p` is NULL or a plan made by [`plan_s2`] or [`plan_s2_limited`] with the same `H`, not
/// destroyed yet and used by no other thread.
pub(super) unsafe fn destroy_s2_plan<H: S2Handle>(p: *mut H) {
    guarded((), || {
        if !p.is_null() {
            // SAFETY: a non-NULL `p` came from Box::into_raw of a `Box<H>` in a planner and
            // is destroyed once, while no other thread uses it (this function's contract).
            drop(unsafe { Box::from_raw(p) });
        }
        Ok(())
    })
}

/// Plans the S^2 transforms of bandwidth `B` (both directions, complex and real samples),
/// `flags` a planner rigour (`SO3FFT_ESTIMATE` ...), `nthreads` workers (0 = all cores).
/// NULL on error.
#[no_mangle]
pub extern "C" fn so3fft_plan_s2(B: c_int, flags: c_uint, nthreads: c_int) -> so3fft_s2_plan {
    plan_s2(B, flags, nthreads)
}

/// As `so3fft_plan_s2`, computing only degrees `l < L` (`1 <= L <= B`) of orders
/// `|m| <= Mmax` (`Mmax >= 0`): the forward writes the other coefficients as 0, the inverse
/// does not read them. NULL on error.
#[no_mangle]
pub extern "C" fn so3fft_plan_s2_limited(
    B: c_int,
    L: c_int,
    Mmax: c_int,
    flags: c_uint,
    nthreads: c_int,
) -> so3fft_s2_plan {
    plan_s2_limited(B, L, Mmax, flags, nthreads)
}

/// Destroys an S^2 plan (after the worker threads it was the last to use have finished);
/// NULL is a no-op.
#[no_mangle]
pub unsafe extern "C" fn so3fft_destroy_s2_plan(p: so3fft_s2_plan) {
    // SAFETY: `p` is NULL or a live plan of this type, used by no other thread (the API's
    // contract).
    unsafe { destroy_s2_plan(p) }
}

/// The plan behind a handle; an error for NULL.
///
/// # Safety
/// `p` is NULL or a live S^2 plan, not destroyed during the returned reference's use.
unsafe fn s2_plan_ref<'a, H: S2Handle>(p: *mut H) -> Result<&'a S2Plan<H::T>, CallError> {
    // SAFETY: non-NULL handles are live plans (this function's contract), only read.
    unsafe { p.as_ref() }
        .map(H::plan)
        .ok_or_else(|| CallError::new(ErrorKind::Null, "the S^2 plan is NULL"))
}

/// The body of `so3fft_s2_get_bandwidth` for the handle type `H`.
///
/// # Safety
/// `p` is NULL or a live plan of type `H`.
pub(super) unsafe fn s2_get_bandwidth<H: S2Handle>(p: *mut H) -> c_int {
    guarded(SO3FFT_ENULL, || {
        // SAFETY: `p` is NULL or a live plan (this function's contract).
        Ok(unsafe { s2_plan_ref(p) }?.bandwidth() as c_int)
    })
}

/// The bandwidth of an S^2 plan (`SO3FFT_ENULL` for NULL).
#[no_mangle]
pub unsafe extern "C" fn so3fft_s2_get_bandwidth(p: so3fft_s2_plan) -> c_int {
    // SAFETY: `p` is NULL or a live plan (the API's contract).
    unsafe { s2_get_bandwidth(p) }
}

/// Checks the arrays of an S^2 execute and runs `f` on them as slices.
///
/// # Safety
/// Non-NULL arrays hold the plan's sizes (`input_len`, `output_len` values), the input
/// only read, the output accessed by no one else during the call.
unsafe fn with_arrays<I, O>(
    input: (*const I, usize, &'static str),
    output: (*mut O, usize, &'static str),
    f: impl FnOnce(&[I], &mut [O]) -> crate::Result<()>,
) -> Result<(), CallError> {
    input_output(
        &Array::new(input.0, input.1, input.2),
        &Array::new(output.0.cast_const(), output.1, output.2),
    )?;
    // SAFETY: checked non-NULL, aligned and disjoint; the extents are the caller's
    // contract.
    let (i, o) = unsafe {
        (
            std::slice::from_raw_parts(input.0, input.1),
            std::slice::from_raw_parts_mut(output.0, output.1),
        )
    };
    f(i, o).map_err(CallError::from)
}

/// The field count of a `_many` call; an error unless positive.
fn fields(howmany: c_int) -> Result<usize, CallError> {
    match usize::try_from(howmany) {
        Ok(n) if n > 0 => Ok(n),
        _ => Err(CallError::invalid(format!(
            "howmany = {howmany}: must be positive"
        ))),
    }
}

/// An array of interleaved complex values `{re, im}` as `Complex<T>`, which is
/// `#[repr(C)] {re, im}`: the same layout (and alignment, that of `T`).
fn complex<T>(a: *mut [T; 2]) -> *mut Complex<T> {
    a.cast()
}

/// The body of `so3fft_s2_execute_forward_many` for the handle type `H` (element `H::T`).
///
/// # Safety
/// `p` is NULL or a live plan of type `H`; non-NULL arrays hold `howmany` fields (the API's
/// contract).
pub(super) unsafe fn s2_forward_many<H: S2Handle>(
    p: *mut H,
    howmany: c_int,
    samples: *mut [H::T; 2],
    coeffs: *mut [H::T; 2],
) -> c_int {
    guarded_code(|| {
        let k = fields(howmany)?;
        // SAFETY: `p` is NULL or a live plan; the arrays hold `howmany` fields (this
        // function's contract).
        unsafe {
            let plan = s2_plan_ref(p)?;
            with_arrays(
                (
                    complex(samples).cast_const(),
                    k * plan.num_samples(),
                    "samples",
                ),
                (complex(coeffs), k * plan.num_coeffs(), "coefficients"),
                |s, c| plan.forward_many(s, c, k).map(|_| ()),
            )
        }
    })
}

/// The body of `so3fft_s2_execute_inverse_many` for the handle type `H` (element `H::T`).
///
/// # Safety
/// As [`s2_forward_many`].
pub(super) unsafe fn s2_inverse_many<H: S2Handle>(
    p: *mut H,
    howmany: c_int,
    coeffs: *mut [H::T; 2],
    samples: *mut [H::T; 2],
) -> c_int {
    guarded_code(|| {
        let k = fields(howmany)?;
        // SAFETY: `p` is NULL or a live plan; the arrays hold `howmany` fields (this
        // function's contract).
        unsafe {
            let plan = s2_plan_ref(p)?;
            with_arrays(
                (
                    complex(coeffs).cast_const(),
                    k * plan.num_coeffs(),
                    "coefficients",
                ),
                (complex(samples), k * plan.num_samples(), "samples"),
                |c, s| plan.inverse_many(c, s, k).map(|_| ()),
            )
        }
    })
}

/// The body of `so3fft_s2_execute_forward_real_many` for the handle type `H` (element `H::T`).
///
/// # Safety
/// As [`s2_forward_many`].
pub(super) unsafe fn s2_forward_real_many<H: S2Handle>(
    p: *mut H,
    howmany: c_int,
    samples: *const H::T,
    coeffs: *mut [H::T; 2],
) -> c_int {
    guarded_code(|| {
        let k = fields(howmany)?;
        // SAFETY: `p` is NULL or a live plan; the arrays hold `howmany` fields (this
        // function's contract).
        unsafe {
            let plan = s2_plan_ref(p)?;
            with_arrays(
                (samples, k * plan.num_samples(), "samples"),
                (complex(coeffs), k * plan.num_coeffs(), "coefficients"),
                |s, c| plan.forward_real_many(s, c, k).map(|_| ()),
            )
        }
    })
}

/// The body of `so3fft_s2_execute_inverse_real_many` for the handle type `H` (element `H::T`).
///
/// # Safety
/// As [`s2_forward_many`].
pub(super) unsafe fn s2_inverse_real_many<H: S2Handle>(
    p: *mut H,
    howmany: c_int,
    coeffs: *mut [H::T; 2],
    samples: *mut H::T,
) -> c_int {
    guarded_code(|| {
        let k = fields(howmany)?;
        // SAFETY: `p` is NULL or a live plan; the arrays hold `howmany` fields (this
        // function's contract).
        unsafe {
            let plan = s2_plan_ref(p)?;
            with_arrays(
                (
                    complex(coeffs).cast_const(),
                    k * plan.num_coeffs(),
                    "coefficients",
                ),
                (samples, k * plan.num_samples(), "samples"),
                |c, s| plan.inverse_real_many(c, s, k).map(|_| ()),
            )
        }
    })
}

/// Forward S^2 transform: `(2B)^2` complex samples (ring-major; only read) to `B^2`
/// coefficients (`seanindex` order). `SO3FFT_OK` or an error code.
#[no_mangle]
pub unsafe extern "C" fn so3fft_s2_execute_forward(
    p: so3fft_s2_plan,
    samples: *mut so3fft_complex,
    coeffs: *mut so3fft_complex,
) -> c_int {
    // SAFETY: the same contract as the `_many` function with one field.
    unsafe { s2_forward_many(p, 1, samples, coeffs) }
}

/// Inverse S^2 transform: `B^2` coefficients (only read) to `(2B)^2` complex samples.
#[no_mangle]
pub unsafe extern "C" fn so3fft_s2_execute_inverse(
    p: so3fft_s2_plan,
    coeffs: *mut so3fft_complex,
    samples: *mut so3fft_complex,
) -> c_int {
    // SAFETY: the same contract as the `_many` function with one field.
    unsafe { s2_inverse_many(p, 1, coeffs, samples) }
}

/// Forward S^2 transform of `(2B)^2` real samples: all `B^2` coefficients, with
/// `fhat(l,-m) = (-1)^m conj(fhat(l,m))`.
#[no_mangle]
pub unsafe extern "C" fn so3fft_s2_execute_forward_real(
    p: so3fft_s2_plan,
    samples: *const f64,
    coeffs: *mut so3fft_complex,
) -> c_int {
    // SAFETY: the same contract as the `_many` function with one field.
    unsafe { s2_forward_real_many(p, 1, samples, coeffs) }
}

/// Inverse S^2 transform to `(2B)^2` real samples: reads the orders `m >= 0` (the others
/// are taken as `(-1)^m conj(fhat(l,m))`; `Im fhat(l,0)` is ignored).
#[no_mangle]
pub unsafe extern "C" fn so3fft_s2_execute_inverse_real(
    p: so3fft_s2_plan,
    coeffs: *mut so3fft_complex,
    samples: *mut f64,
) -> c_int {
    // SAFETY: the same contract as the `_many` function with one field.
    unsafe { s2_inverse_real_many(p, 1, coeffs, samples) }
}

/// `so3fft_s2_execute_forward` of `howmany` fields stored one after another
/// (`howmany (2B)^2` samples, `howmany B^2` coefficients).
#[no_mangle]
pub unsafe extern "C" fn so3fft_s2_execute_forward_many(
    p: so3fft_s2_plan,
    howmany: c_int,
    samples: *mut so3fft_complex,
    coeffs: *mut so3fft_complex,
) -> c_int {
    // SAFETY: `p` is NULL or a live plan; the arrays hold `howmany` fields (the API's
    // contract).
    unsafe { s2_forward_many(p, howmany, samples, coeffs) }
}

/// `so3fft_s2_execute_inverse` of `howmany` fields stored one after another.
#[no_mangle]
pub unsafe extern "C" fn so3fft_s2_execute_inverse_many(
    p: so3fft_s2_plan,
    howmany: c_int,
    coeffs: *mut so3fft_complex,
    samples: *mut so3fft_complex,
) -> c_int {
    // SAFETY: as in `so3fft_s2_execute_forward_many`.
    unsafe { s2_inverse_many(p, howmany, coeffs, samples) }
}

/// `so3fft_s2_execute_forward_real` of `howmany` fields (two per kernel pass: about twice
/// as fast per field as one at a time).
#[no_mangle]
pub unsafe extern "C" fn so3fft_s2_execute_forward_real_many(
    p: so3fft_s2_plan,
    howmany: c_int,
    samples: *const f64,
    coeffs: *mut so3fft_complex,
) -> c_int {
    // SAFETY: as in `so3fft_s2_execute_forward_many`.
    unsafe { s2_forward_real_many(p, howmany, samples, coeffs) }
}

/// `so3fft_s2_execute_inverse_real` of `howmany` fields (two per kernel pass).
#[no_mangle]
pub unsafe extern "C" fn so3fft_s2_execute_inverse_real_many(
    p: so3fft_s2_plan,
    howmany: c_int,
    coeffs: *mut so3fft_complex,
    samples: *mut f64,
) -> c_int {
    // SAFETY: as in `so3fft_s2_execute_forward_many`.
    unsafe { s2_inverse_real_many(p, howmany, coeffs, samples) }
}

/// Number of S^2 samples `(2B)^2` (0 for an invalid `B`).
#[no_mangle]
pub extern "C" fn so3fft_s2_num_samples(B: c_int) -> usize {
    guarded(0, || Ok(s2_num_samples(s2_bandwidth(B)?)))
}

/// Number of S^2 coefficients `B^2` (0 for an invalid `B`).
#[no_mangle]
pub extern "C" fn so3fft_s2_num_coeffs(B: c_int) -> usize {
    guarded(0, || Ok(s2_num_coeffs(s2_bandwidth(B)?)))
}

/// Index of `fhat(l, m)` (SOFT's `seanindex(m, l, B)`), or -1.
#[no_mangle]
pub extern "C" fn so3fft_s2_coef_index(B: c_int, l: c_int, m: c_int) -> isize {
    guarded(-1, || {
        let b = s2_bandwidth(B)?;
        let l = usize::try_from(l).map_err(|_| {
            CallError::invalid(format!("S^2 coefficient (l={l}, m={m}) does not exist"))
        })?;
        Ok(s2_try_coef_index(b, l, m as isize)? as isize)
    })
}
