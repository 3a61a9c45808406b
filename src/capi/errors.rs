//! Version, the thread-local error state and error descriptions.

use super::{
    error_code, SO3FFT_EBANDWIDTH, SO3FFT_EDIRECTION, SO3FFT_EFFTW, SO3FFT_EINVAL, SO3FFT_ENOMEM,
    SO3FFT_ENULL, SO3FFT_EPANIC, SO3FFT_OK,
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

#[cfg(test)]
mod tests {
    use super::super::{guarded_code, SO3FFT_EPANIC, SO3FFT_OK};
    use super::{so3fft_last_error, so3fft_last_error_code};
    use std::ffi::CStr;

    /// A panic inside the boundary becomes `SO3FFT_EPANIC` with a message naming it, and
    /// the next call on the same thread starts clean (the C tests cannot reach this: the
    /// library has no way to make itself panic on purpose).
    #[test]
    fn panics_become_an_error_code() {
        let code = guarded_code(|| panic!("a test panic"));
        assert_eq!(code, SO3FFT_EPANIC);
        assert_eq!(so3fft_last_error_code(), SO3FFT_EPANIC);
        // SAFETY: the library's error message is a NUL-terminated static or thread-local string.
        let msg = unsafe { CStr::from_ptr(so3fft_last_error()) }
            .to_string_lossy()
            .into_owned();
        assert!(msg.contains("panic"), "message: {msg}");
        assert_eq!(guarded_code(|| Ok(())), SO3FFT_OK);
        assert_eq!(so3fft_last_error_code(), SO3FFT_OK);
    }
}
