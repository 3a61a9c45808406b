//! Version, the thread-local error state and error descriptions.

use super::{
    error_code, guarded_code, SO3FFT_EBANDWIDTH, SO3FFT_EDIRECTION, SO3FFT_EFFTW, SO3FFT_EINVAL,
    SO3FFT_ENOMEM, SO3FFT_ENULL, SO3FFT_EPANIC, SO3FFT_OK,
};
use crate::ffi::last_error;
use std::ffi::{c_char, c_int};

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
    last_error::kind().map_or(SO3FFT_OK, error_code)
}

/// A message describing the last error on the calling thread, "" if the last so3fft
/// call on this thread succeeded. Never NULL. The string is owned by the library and
/// stays valid until the next so3fft call on the same thread (other than
/// `so3fft_last_error_code`, `so3fft_last_error`, `so3fft_strerror`, `so3fft_version`)
/// or until the thread exits: copy it to keep it.
#[no_mangle]
pub extern "C" fn so3fft_last_error() -> *const c_char {
    last_error::message()
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
    guarded_code(|| panic!("test panic requested by so3fft_internal_test_panic"))
}
