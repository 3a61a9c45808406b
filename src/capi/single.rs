//! The single-precision C API, `so3fftf_*` on `float` data (as FFTW's `fftwf_*`): the SO(3)
//! plans, the partial plans, the S^2 transforms and single-precision FFTW's wisdom (the
//! correlation plans are in `single_matching.rs`). Each
//! function is a thin wrapper over the body its `so3fft_*` twin runs (`planner.rs`,
//! `execute.rs`, `query.rs`, `grid.rs`, `partial.rs`, `s2.rs`, `wisdom.rs`), instantiated
//! for `f32`, so the checks and error messages are the same in both precisions. Sizes,
//! indices, angles, shapes, planner settings and the error state are shared, not duplicated
//! (`so3fft_num_samples`, `so3fft_coef_index`, `so3fft_shape_default`,
//! `so3fft_plan_with_nthreads`, `so3fft_s2_num_samples`, `so3fft_last_error`, ...).

use super::execute::{execute, execute_forward, execute_inverse};
use super::grid::weights;
use super::partial::{
    destroy_partial, partial_forward_many, partial_forward_real_many, partial_inverse_many,
    partial_inverse_real_many, partial_num_coeffs, partial_num_samples, plan_partial,
    so3fft_partial_options, so3fft_shape, PartialHandle,
};
use super::planner::{destroy_plan, make_plan, planner_threads};
use super::query::{get_bandwidth, get_fft_threading, get_memory, get_nthreads, plan_memory};
use super::s2::{
    destroy_s2_plan, plan_s2, plan_s2_limited, s2_forward_many, s2_forward_real_many,
    s2_get_bandwidth, s2_inverse_many, s2_inverse_real_many, S2Handle,
};
use super::wisdom::{
    export_wisdom_to_filename, export_wisdom_to_string, forget_wisdom, import_wisdom_from_filename,
    import_wisdom_from_string,
};
use super::{PlanHandle, PlanState, SO3FFT_BOTH, SO3FFT_FORWARD, SO3FFT_INVERSE};
use crate::s2::S2Plan;
use crate::PartialPlan;
use std::ffi::{c_char, c_float, c_int, c_uint};

/// One single-precision complex number `{re, im}`, identical to `fftwf_complex` (`float[2]`).
pub type so3fftf_complex = [c_float; 2];

/// Opaque single-precision plan object (made by a `so3fftf_plan_*` planner, released by
/// `so3fftf_destroy_plan`).
pub struct so3fftf_plan_s {
    state: PlanState<f32>,
}

/// A single-precision plan: a pointer to an opaque object (like `fftwf_plan`).
pub type so3fftf_plan = *mut so3fftf_plan_s;

impl PlanHandle for so3fftf_plan_s {
    type T = f32;
    const PREFIX: &'static str = "so3fftf";
    fn wrap(state: PlanState<f32>) -> Self {
        so3fftf_plan_s { state }
    }
    fn state(&self) -> &PlanState<f32> {
        &self.state
    }
}

/// Opaque single-precision partial plan object (made by `so3fftf_plan_partial`).
pub struct so3fftf_partial_s {
    plan: PartialPlan<f32>,
}

/// A single-precision partial plan: a pointer to an opaque object.
pub type so3fftf_partial = *mut so3fftf_partial_s;

impl PartialHandle for so3fftf_partial_s {
    type T = f32;
    fn wrap(plan: PartialPlan<f32>) -> Self {
        so3fftf_partial_s { plan }
    }
    fn plan(&self) -> &PartialPlan<f32> {
        &self.plan
    }
}

/// Opaque single-precision S^2 plan object (made by `so3fftf_plan_s2`, released by
/// `so3fftf_destroy_s2_plan`).
pub struct so3fftf_s2_plan_s {
    plan: S2Plan<f32>,
}

/// A single-precision S^2 plan: a pointer to an opaque object.
pub type so3fftf_s2_plan = *mut so3fftf_s2_plan_s;

impl S2Handle for so3fftf_s2_plan_s {
    type T = f32;
    fn wrap(plan: S2Plan<f32>) -> Self {
        so3fftf_s2_plan_s { plan }
    }
    fn plan(&self) -> &S2Plan<f32> {
        &self.plan
    }
}

// ---------------------------------------------------------------------------------------
// SO(3) plans
// ---------------------------------------------------------------------------------------

/// Single precision (`so3fftf_`, `float` data): as `so3fft_plan_forward`, samples `in`
/// ((2B)^3) to coefficients `out` ((4B^3-B)/3), both NULL for new-array execute only.
/// Planner settings (`so3fft_plan_with_nthreads` ...) are shared with double. NULL on error.
#[no_mangle]
pub extern "C" fn so3fftf_plan_forward(
    B: c_int,
    r#in: *mut so3fftf_complex,
    out: *mut so3fftf_complex,
    flags: c_uint,
) -> so3fftf_plan {
    make_plan(B, SO3FFT_FORWARD, r#in, out, flags, planner_threads())
}

/// As `so3fft_plan_inverse`, in single precision: coefficients `in` to samples `out`.
#[no_mangle]
pub extern "C" fn so3fftf_plan_inverse(
    B: c_int,
    r#in: *mut so3fftf_complex,
    out: *mut so3fftf_complex,
    flags: c_uint,
) -> so3fftf_plan {
    make_plan(B, SO3FFT_INVERSE, r#in, out, flags, planner_threads())
}

/// As `so3fft_plan_both`, in single precision (new-array execute only).
#[no_mangle]
pub extern "C" fn so3fftf_plan_both(B: c_int, flags: c_uint) -> so3fftf_plan {
    make_plan(
        B,
        SO3FFT_BOTH,
        std::ptr::null_mut(),
        std::ptr::null_mut(),
        flags,
        planner_threads(),
    )
}

/// As `so3fft_plan_general`, in single precision.
#[no_mangle]
pub extern "C" fn so3fftf_plan_general(
    B: c_int,
    direction: c_int,
    r#in: *mut so3fftf_complex,
    out: *mut so3fftf_complex,
    flags: c_uint,
    nthreads: c_int,
) -> so3fftf_plan {
    make_plan(B, direction, r#in, out, flags, nthreads)
}

/// Destroys a single-precision plan; NULL is a no-op.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_destroy_plan(p: so3fftf_plan) {
    // SAFETY: `p` is NULL or a live plan of this type, used by no other thread (the API's
    // contract).
    unsafe { destroy_plan(p) }
}

/// As `so3fft_execute`: runs a plan on the arrays given at planning.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_execute(p: so3fftf_plan) -> c_int {
    // SAFETY: `p` is NULL or a live plan whose planning arrays are valid (the API's
    // contract).
    unsafe { execute(p) }
}

/// As `so3fft_execute_forward`: samples `in` to coefficients `out` (new-array execute).
#[no_mangle]
pub unsafe extern "C" fn so3fftf_execute_forward(
    p: so3fftf_plan,
    r#in: *mut so3fftf_complex,
    out: *mut so3fftf_complex,
) -> c_int {
    // SAFETY: `p` is NULL or a live plan, and non-NULL arrays have the sizes of its
    // bandwidth (the API's contract).
    unsafe { execute_forward(p, r#in, out) }
}

/// As `so3fft_execute_inverse`: coefficients `in` to samples `out` (new-array execute).
#[no_mangle]
pub unsafe extern "C" fn so3fftf_execute_inverse(
    p: so3fftf_plan,
    r#in: *mut so3fftf_complex,
    out: *mut so3fftf_complex,
) -> c_int {
    // SAFETY: as in `so3fftf_execute_forward`.
    unsafe { execute_inverse(p, r#in, out) }
}

/// The bandwidth of a single-precision plan (`SO3FFT_ENULL` for NULL).
#[no_mangle]
pub unsafe extern "C" fn so3fftf_get_bandwidth(p: so3fftf_plan) -> c_int {
    // SAFETY: `p` is NULL or a live plan (the API's contract).
    unsafe { get_bandwidth(p) }
}

/// The worker thread count of a single-precision plan (`SO3FFT_ENULL` for NULL).
#[no_mangle]
pub unsafe extern "C" fn so3fftf_get_nthreads(p: so3fftf_plan) -> c_int {
    // SAFETY: `p` is NULL or a live plan (the API's contract).
    unsafe { get_nthreads(p) }
}

/// Bytes of memory a single-precision plan holds (`SO3FFT_ENULL` for NULL).
#[no_mangle]
pub unsafe extern "C" fn so3fftf_get_memory(p: so3fftf_plan) -> isize {
    // SAFETY: `p` is NULL or a live plan (the API's contract).
    unsafe { get_memory(p) }
}

/// As `so3fft_plan_memory`, for a single-precision plan (its own figure).
#[no_mangle]
pub extern "C" fn so3fftf_plan_memory(B: c_int, flags: c_uint, nthreads: c_int) -> isize {
    plan_memory::<f32>(B, flags, nthreads)
}

/// As `so3fft_get_fft_threading` (`SO3FFT_ENULL` for NULL).
#[no_mangle]
pub unsafe extern "C" fn so3fftf_get_fft_threading(p: so3fftf_plan) -> c_int {
    // SAFETY: `p` is NULL or a live plan (the API's contract).
    unsafe { get_fft_threading(p) }
}

/// Writes the `2B` quadrature weights `w_B(k)` to `w` as floats (`so3fft_weights` rounded).
#[no_mangle]
pub unsafe extern "C" fn so3fftf_weights(B: c_int, w: *mut c_float) -> c_int {
    // SAFETY: `w` is NULL or has room for 2B floats (the API's contract).
    unsafe { weights(B, w) }
}

// ---------------------------------------------------------------------------------------
// Partial plans
// ---------------------------------------------------------------------------------------

/// As `so3fft_plan_partial`, in single precision (the shape and the options, with their
/// double beta values, are the same). NULL on error.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_plan_partial(
    shape: *const so3fft_shape,
    options: *const so3fft_partial_options,
    flags: c_uint,
) -> so3fftf_partial {
    // SAFETY: `shape` and `options` are NULL or valid (the API's contract).
    unsafe { plan_partial(shape, options, flags) }
}

/// Destroys a single-precision partial plan; NULL is a no-op.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_destroy_partial(p: so3fftf_partial) {
    // SAFETY: `p` is NULL or a live plan of this type, used by no other thread (the API's
    // contract).
    unsafe { destroy_partial(p) }
}

/// Coefficients of one transform of the plan.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_partial_num_coeffs(p: so3fftf_partial) -> isize {
    // SAFETY: `p` is NULL or a live plan (the API's contract).
    unsafe { partial_num_coeffs(p) }
}

/// Samples of one transform of the plan (`n_alpha n_gamma` per beta evaluated).
#[no_mangle]
pub unsafe extern "C" fn so3fftf_partial_num_samples(p: so3fftf_partial) -> isize {
    // SAFETY: `p` is NULL or a live plan (the API's contract).
    unsafe { partial_num_samples(p) }
}

/// As `so3fft_partial_forward_many`: `howmany` forwards, samples `idist` values apart to
/// coefficients `odist` apart.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_partial_forward_many(
    p: so3fftf_partial,
    howmany: c_int,
    samples: *mut so3fftf_complex,
    idist: isize,
    coeffs: *mut so3fftf_complex,
    odist: isize,
) -> c_int {
    // SAFETY: `p` is NULL or a live plan; non-NULL arrays hold the batch's extents (the
    // API's contract).
    unsafe { partial_forward_many(p, howmany, samples, idist, coeffs, odist) }
}

/// As `so3fft_partial_inverse_many`.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_partial_inverse_many(
    p: so3fftf_partial,
    howmany: c_int,
    coeffs: *mut so3fftf_complex,
    idist: isize,
    samples: *mut so3fftf_complex,
    odist: isize,
) -> c_int {
    // SAFETY: as in `so3fftf_partial_forward_many`.
    unsafe { partial_inverse_many(p, howmany, coeffs, idist, samples, odist) }
}

/// As `so3fft_partial_forward_real_many`, real samples as floats.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_partial_forward_real_many(
    p: so3fftf_partial,
    howmany: c_int,
    samples: *const c_float,
    idist: isize,
    coeffs: *mut so3fftf_complex,
    odist: isize,
) -> c_int {
    // SAFETY: as in `so3fftf_partial_forward_many`.
    unsafe { partial_forward_real_many(p, howmany, samples, idist, coeffs, odist) }
}

/// As `so3fft_partial_inverse_real_many`, real samples as floats.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_partial_inverse_real_many(
    p: so3fftf_partial,
    howmany: c_int,
    coeffs: *mut so3fftf_complex,
    idist: isize,
    samples: *mut c_float,
    odist: isize,
) -> c_int {
    // SAFETY: as in `so3fftf_partial_forward_many`.
    unsafe { partial_inverse_real_many(p, howmany, coeffs, idist, samples, odist) }
}

/// One forward transform (`so3fftf_partial_forward_many` with `howmany = 1`).
#[no_mangle]
pub unsafe extern "C" fn so3fftf_partial_forward(
    p: so3fftf_partial,
    samples: *mut so3fftf_complex,
    coeffs: *mut so3fftf_complex,
) -> c_int {
    // SAFETY: `p` is NULL or a live plan; non-NULL arrays hold one transform (the API's
    // contract).
    unsafe { partial_forward_many(p, 1, samples, 0, coeffs, 0) }
}

/// One inverse transform.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_partial_inverse(
    p: so3fftf_partial,
    coeffs: *mut so3fftf_complex,
    samples: *mut so3fftf_complex,
) -> c_int {
    // SAFETY: as in `so3fftf_partial_forward`.
    unsafe { partial_inverse_many(p, 1, coeffs, 0, samples, 0) }
}

/// One forward transform of real samples.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_partial_forward_real(
    p: so3fftf_partial,
    samples: *const c_float,
    coeffs: *mut so3fftf_complex,
) -> c_int {
    // SAFETY: as in `so3fftf_partial_forward`.
    unsafe { partial_forward_real_many(p, 1, samples, 0, coeffs, 0) }
}

/// One inverse transform to real samples.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_partial_inverse_real(
    p: so3fftf_partial,
    coeffs: *mut so3fftf_complex,
    samples: *mut c_float,
) -> c_int {
    // SAFETY: as in `so3fftf_partial_forward`.
    unsafe { partial_inverse_real_many(p, 1, coeffs, 0, samples, 0) }
}

// ---------------------------------------------------------------------------------------
// S^2 transforms
// ---------------------------------------------------------------------------------------

/// As `so3fft_plan_s2`, in single precision. The ring DFTs use single-precision FFTW
/// (libfftw3f); the lowest orders run in double. NULL on error.
#[no_mangle]
pub extern "C" fn so3fftf_plan_s2(B: c_int, flags: c_uint, nthreads: c_int) -> so3fftf_s2_plan {
    plan_s2(B, flags, nthreads)
}

/// As `so3fft_plan_s2_limited`, in single precision.
#[no_mangle]
pub extern "C" fn so3fftf_plan_s2_limited(
    B: c_int,
    L: c_int,
    Mmax: c_int,
    flags: c_uint,
    nthreads: c_int,
) -> so3fftf_s2_plan {
    plan_s2_limited(B, L, Mmax, flags, nthreads)
}

/// As `so3fft_destroy_s2_plan`; NULL is a no-op.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_destroy_s2_plan(p: so3fftf_s2_plan) {
    // SAFETY: `p` is NULL or a live plan of this type, used by no other thread (the API's
    // contract).
    unsafe { destroy_s2_plan(p) }
}

/// The bandwidth of a single-precision S^2 plan (`SO3FFT_ENULL` for NULL).
#[no_mangle]
pub unsafe extern "C" fn so3fftf_s2_get_bandwidth(p: so3fftf_s2_plan) -> c_int {
    // SAFETY: `p` is NULL or a live plan (the API's contract).
    unsafe { s2_get_bandwidth(p) }
}

/// As `so3fft_s2_execute_forward`: `(2B)^2` complex samples to `B^2` coefficients.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_s2_execute_forward(
    p: so3fftf_s2_plan,
    samples: *mut so3fftf_complex,
    coeffs: *mut so3fftf_complex,
) -> c_int {
    // SAFETY: `p` is NULL or a live plan; non-NULL arrays hold one field (the API's
    // contract).
    unsafe { s2_forward_many(p, 1, samples, coeffs) }
}

/// As `so3fft_s2_execute_inverse`: `B^2` coefficients to `(2B)^2` complex samples.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_s2_execute_inverse(
    p: so3fftf_s2_plan,
    coeffs: *mut so3fftf_complex,
    samples: *mut so3fftf_complex,
) -> c_int {
    // SAFETY: as in `so3fftf_s2_execute_forward`.
    unsafe { s2_inverse_many(p, 1, coeffs, samples) }
}

/// As `so3fft_s2_execute_forward_real`: `(2B)^2` real samples to all `B^2` coefficients.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_s2_execute_forward_real(
    p: so3fftf_s2_plan,
    samples: *const c_float,
    coeffs: *mut so3fftf_complex,
) -> c_int {
    // SAFETY: as in `so3fftf_s2_execute_forward`.
    unsafe { s2_forward_real_many(p, 1, samples, coeffs) }
}

/// As `so3fft_s2_execute_inverse_real`: coefficients (orders `m >= 0` read) to `(2B)^2`
/// real samples.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_s2_execute_inverse_real(
    p: so3fftf_s2_plan,
    coeffs: *mut so3fftf_complex,
    samples: *mut c_float,
) -> c_int {
    // SAFETY: as in `so3fftf_s2_execute_forward`.
    unsafe { s2_inverse_real_many(p, 1, coeffs, samples) }
}

/// As `so3fft_s2_execute_forward_many`: `howmany` fields stored one after another.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_s2_execute_forward_many(
    p: so3fftf_s2_plan,
    howmany: c_int,
    samples: *mut so3fftf_complex,
    coeffs: *mut so3fftf_complex,
) -> c_int {
    // SAFETY: `p` is NULL or a live plan; non-NULL arrays hold `howmany` fields (the API's
    // contract).
    unsafe { s2_forward_many(p, howmany, samples, coeffs) }
}

/// As `so3fft_s2_execute_inverse_many`.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_s2_execute_inverse_many(
    p: so3fftf_s2_plan,
    howmany: c_int,
    coeffs: *mut so3fftf_complex,
    samples: *mut so3fftf_complex,
) -> c_int {
    // SAFETY: as in `so3fftf_s2_execute_forward_many`.
    unsafe { s2_inverse_many(p, howmany, coeffs, samples) }
}

/// As `so3fft_s2_execute_forward_real_many` (two fields per kernel pass).
#[no_mangle]
pub unsafe extern "C" fn so3fftf_s2_execute_forward_real_many(
    p: so3fftf_s2_plan,
    howmany: c_int,
    samples: *const c_float,
    coeffs: *mut so3fftf_complex,
) -> c_int {
    // SAFETY: as in `so3fftf_s2_execute_forward_many`.
    unsafe { s2_forward_real_many(p, howmany, samples, coeffs) }
}

/// As `so3fft_s2_execute_inverse_real_many` (two fields per kernel pass).
#[no_mangle]
pub unsafe extern "C" fn so3fftf_s2_execute_inverse_real_many(
    p: so3fftf_s2_plan,
    howmany: c_int,
    coeffs: *mut so3fftf_complex,
    samples: *mut c_float,
) -> c_int {
    // SAFETY: as in `so3fftf_s2_execute_forward_many`.
    unsafe { s2_inverse_real_many(p, howmany, coeffs, samples) }
}

// ---------------------------------------------------------------------------------------
// FFTW wisdom
// ---------------------------------------------------------------------------------------

/// Writes single-precision FFTW's wisdom (libfftw3f's store, separate from the double
/// one) to the file `filename`, as `so3fft_export_wisdom_to_filename`.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_export_wisdom_to_filename(filename: *const c_char) -> c_int {
    // SAFETY: the caller passes NULL or a C string (the API's contract).
    unsafe { export_wisdom_to_filename::<f32>(filename) }
}

/// Loads single-precision FFTW wisdom from the file `filename` (`SO3FFT_EINVAL` also for
/// double-precision wisdom).
#[no_mangle]
pub unsafe extern "C" fn so3fftf_import_wisdom_from_filename(filename: *const c_char) -> c_int {
    // SAFETY: as in `so3fftf_export_wisdom_to_filename`.
    unsafe { import_wisdom_from_filename::<f32>(filename) }
}

/// Single-precision FFTW's wisdom as a NUL-terminated string to be released with `free()`;
/// NULL on error.
#[no_mangle]
pub extern "C" fn so3fftf_export_wisdom_to_string() -> *mut c_char {
    export_wisdom_to_string::<f32>()
}

/// Loads single-precision FFTW wisdom from the NUL-terminated string `wisdom`.
/// `SO3FFT_OK` or an error code.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_import_wisdom_from_string(wisdom: *const c_char) -> c_int {
    // SAFETY: as in `so3fftf_export_wisdom_to_filename`.
    unsafe { import_wisdom_from_string::<f32>(wisdom) }
}

/// Forgets single-precision FFTW's wisdom (plans already made are not affected).
#[no_mangle]
pub extern "C" fn so3fftf_forget_wisdom() {
    forget_wisdom::<f32>()
}

#[cfg(test)]
mod tests {
    use super::super::errors::so3fft_last_error;
    use super::super::{SO3FFT_EINVAL, SO3FFT_ENULL, SO3FFT_ESTIMATE, SO3FFT_OK, SO3FFT_REAL};
    use super::*;
    use std::ffi::CStr;

    /// The thread's last error message.
    fn last_message() -> String {
        // SAFETY: the library's error message is a NUL-terminated static or thread-local
        // string, read before the next call.
        unsafe { CStr::from_ptr(so3fft_last_error()) }
            .to_string_lossy()
            .into_owned()
    }

    /// The largest difference of two complex arrays.
    fn max_diff(a: &[so3fftf_complex], b: &[so3fftf_complex]) -> f32 {
        a.iter()
            .zip(b)
            .map(|(x, y)| (x[0] - y[0]).hypot(x[1] - y[1]))
            .fold(0.0, f32::max)
    }

    /// One coefficient through the single-precision SO(3) and partial entry points: the
    /// round trips, the memory known before planning, and messages naming the `so3fftf_`
    /// functions.
    #[test]
    fn single_precision_so3_entry_points() {
        let b = 5;
        let (nc, ns) = (crate::num_coeffs(5), crate::num_samples(5));
        let mut c = vec![[0.0f32; 2]; nc];
        c[crate::coef_index(5, 3, -1, 2)] = [1.0, 0.5];
        let mut s = vec![[0.0f32; 2]; ns];
        let mut back = vec![[0.0f32; 2]; nc];
        let p = so3fftf_plan_general(
            b,
            SO3FFT_BOTH,
            std::ptr::null_mut(),
            std::ptr::null_mut(),
            SO3FFT_ESTIMATE,
            1,
        );
        assert!(!p.is_null(), "{}", last_message());
        // SAFETY: `p` is a live plan; the arrays hold the sizes of its bandwidth.
        unsafe {
            assert_eq!(so3fftf_get_bandwidth(p), b);
            assert_eq!(
                so3fftf_get_memory(p),
                so3fftf_plan_memory(b, SO3FFT_ESTIMATE, 1)
            );
            assert_eq!(
                so3fftf_execute_inverse(p, c.as_mut_ptr(), s.as_mut_ptr()),
                SO3FFT_OK
            );
            assert_eq!(
                so3fftf_execute_forward(p, s.as_mut_ptr(), back.as_mut_ptr()),
                SO3FFT_OK
            );
            assert!(max_diff(&back, &c) < 1e-5);
            assert_eq!(so3fftf_execute(p), SO3FFT_ENULL);
            assert!(last_message().contains("so3fftf_execute_forward"));
            so3fftf_destroy_plan(p);
        }

        let shape = super::super::partial::so3fft_shape_default(b);
        // SAFETY: a valid shape, no options.
        let q = unsafe { so3fftf_plan_partial(&shape, std::ptr::null(), SO3FFT_REAL) };
        assert!(!q.is_null(), "{}", last_message());
        let mut r = vec![0.0f32; ns];
        // SAFETY: `q` is a live plan of the full shape: the arrays hold its sizes.
        unsafe {
            assert_eq!(so3fftf_partial_num_coeffs(q), nc as isize);
            assert_eq!(
                so3fftf_partial_inverse(q, c.as_mut_ptr(), s.as_mut_ptr()),
                SO3FFT_OK
            );
            assert_eq!(
                so3fftf_partial_forward(q, s.as_mut_ptr(), back.as_mut_ptr()),
                SO3FFT_OK
            );
            assert!(max_diff(&back, &c) < 1e-5);
            assert_eq!(
                so3fftf_partial_inverse_real(q, c.as_mut_ptr(), r.as_mut_ptr()),
                SO3FFT_OK
            );
            assert_eq!(
                so3fftf_partial_forward_real_many(q, 0, r.as_ptr(), 0, back.as_mut_ptr(), 0),
                SO3FFT_EINVAL
            );
            assert!(last_message().contains("howmany = 0"));
            so3fftf_destroy_partial(q);
        }
    }
}
