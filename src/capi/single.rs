//! The single-precision C API, `so3fftf_*` on `float` data (as FFTW's `fftwf_*`): the S^2
//! transforms and single-precision FFTW's wisdom. Each function is a thin wrapper over the
//! body its `so3fft_*` twin runs (`s2.rs`, `wisdom.rs`), instantiated for `f32`, so the
//! checks and error messages are the same in both precisions. Sizes, indices, planner
//! settings and the error state are shared, not duplicated (`so3fft_s2_num_samples`,
//! `so3fft_s2_coef_index`, `so3fft_last_error`, ...).

use super::s2::{
    destroy_s2_plan, plan_s2, plan_s2_limited, s2_forward_many, s2_forward_real_many,
    s2_get_bandwidth, s2_inverse_many, s2_inverse_real_many, S2Handle,
};
use super::wisdom::{
    export_wisdom_to_filename, export_wisdom_to_string, forget_wisdom, import_wisdom_from_filename,
    import_wisdom_from_string,
};
use crate::s2::S2Plan;
use std::ffi::{c_char, c_float, c_int, c_uint};

/// One single-precision complex number `{re, im}`, identical to `fftwf_complex` (`float[2]`).
pub type so3fftf_complex = [c_float; 2];

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

/// Single precision (`so3fftf_`, `float` data): as `so3fft_plan_s2`. The ring DFTs use
/// single-precision FFTW (libfftw3f); the lowest orders run in double. NULL on error.
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
