//! Version, the thread-local error state and error descriptions.

use super::{
    error_code, guarded_code, SO3FFT_EBANDWIDTH, SO3FFT_EDIRECTION, SO3FFT_EFFTW, SO3FFT_EINVAL,
    SO3FFT_ENOMEM, SO3FFT_ENULL, SO3FFT_EPANIC, SO3FFT_OK,
};
use crate::ffi::last_error;
use std::ffi::{c_char, c_int};

static VERSION: &str = concat!(env!("CARGO_PKG_VERSION"), "\0");

/// The library version string (static; compare with `SO3FFT_VERSION`).
#[no_mangle]
pub extern "C" fn so3fft_version() -> *const c_char {
    VERSION.as_ptr() as *const c_char
}

/// Code of the last error on this thread (`SO3FFT_OK` after success).
#[no_mangle]
pub extern "C" fn so3fft_last_error_code() -> c_int {
    last_error::kind().map_or(SO3FFT_OK, error_code)
}

/// Message of the last error on this thread ("" after success; never NULL; library-owned).
#[no_mangle]
pub extern "C" fn so3fft_last_error() -> *const c_char {
    last_error::message()
}

/// Static description of an error code.
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
    guarded_code(|| panic!("test panic requested by so3fft_internal_test_panic"))
}
