//! FFTW wisdom: export, import, forget (FFTW's process-wide wisdom, shared with the host).
//!
//! The bodies are generic over the element type `T`, whose FFTW library holds the wisdom
//! (`f64`: libfftw3, `f32`: libfftw3f): the `so3fft_*_wisdom*` functions here and the
//! `so3fftf_*_wisdom*` ones of `single.rs` are one-line wrappers over them.

use super::{guarded, guarded_code};
use crate::ffi::{last_error, CallError, ErrorKind};
use crate::wisdom;
use crate::Real;
use std::ffi::{c_char, c_int, CStr};
use std::path::Path;

/// A caller's NUL-terminated string argument, as UTF-8 where it is valid.
///
/// # Safety
/// `s` is NULL or a NUL-terminated string valid for the call.
unsafe fn text<'a>(s: *const c_char, what: &str) -> Result<&'a str, CallError> {
    if s.is_null() {
        return Err(CallError::new(ErrorKind::Null, format!("{what} is NULL")));
    }
    // SAFETY: non-NULL and NUL-terminated (this function's contract).
    unsafe { CStr::from_ptr(s) }
        .to_str()
        .map_err(|_| CallError::invalid(format!("{what} is not valid UTF-8")))
}

/// The body of `so3fft_export_wisdom_to_filename` for `T`'s FFTW.
///
/// # Safety
/// `filename` is NULL or a NUL-terminated string valid for the call.
pub(super) unsafe fn export_wisdom_to_filename<T: Real>(filename: *const c_char) -> c_int {
    guarded_code(|| {
        // SAFETY: NULL or a C string (this function's contract).
        let name = unsafe { text(filename, "the file name") }?;
        Ok(wisdom::export_file::<T>(Path::new(name))?)
    })
}

/// The body of `so3fft_import_wisdom_from_filename` for `T`'s FFTW.
///
/// # Safety
/// As [`export_wisdom_to_filename`].
pub(super) unsafe fn import_wisdom_from_filename<T: Real>(filename: *const c_char) -> c_int {
    guarded_code(|| {
        // SAFETY: NULL or a C string (this function's contract).
        let name = unsafe { text(filename, "the file name") }?;
        Ok(wisdom::import_file::<T>(Path::new(name))?)
    })
}

/// The body of `so3fft_export_wisdom_to_string` for `T`'s FFTW: a copy in memory from
/// `malloc`, or NULL on error.
pub(super) fn export_wisdom_to_string<T: Real>() -> *mut c_char {
    guarded(std::ptr::null_mut(), || {
        let s = wisdom::export_string::<T>()?;
        // SAFETY: malloc of the string's length plus the NUL; checked for NULL below.
        let out = unsafe { libc::malloc(s.len() + 1) }.cast::<c_char>();
        if out.is_null() {
            return Err(CallError::new(
                ErrorKind::NoMemory,
                format!("cannot allocate {} bytes for the wisdom", s.len() + 1),
            ));
        }
        // SAFETY: `out` holds `s.len() + 1` bytes; the regions do not overlap.
        unsafe {
            std::ptr::copy_nonoverlapping(s.as_ptr().cast::<c_char>(), out, s.len());
            *out.add(s.len()) = 0;
        }
        Ok(out)
    })
}

/// The body of `so3fft_import_wisdom_from_string` for `T`'s FFTW.
///
/// # Safety
/// `wisdom` is NULL or a NUL-terminated string valid for the call.
pub(super) unsafe fn import_wisdom_from_string<T: Real>(wisdom: *const c_char) -> c_int {
    guarded_code(|| {
        // SAFETY: NULL or a C string (this function's contract).
        let s = unsafe { text(wisdom, "the wisdom") }?;
        Ok(wisdom::import_string::<T>(s)?)
    })
}

/// The body of `so3fft_forget_wisdom` for `T`'s FFTW.
pub(super) fn forget_wisdom<T: Real>() {
    last_error::clear();
    wisdom::forget_all::<T>();
}

/// Writes FFTW's wisdom to the file `filename` (replaced atomically). `SO3FFT_OK` or an
/// error code.
#[no_mangle]
pub unsafe extern "C" fn so3fft_export_wisdom_to_filename(filename: *const c_char) -> c_int {
    // SAFETY: the caller passes NULL or a C string (the API's contract).
    unsafe { export_wisdom_to_filename::<f64>(filename) }
}

/// Loads FFTW wisdom from the file `filename`. `SO3FFT_OK` or an error code
/// (`SO3FFT_EINVAL`: unreadable file or not FFTW wisdom).
#[no_mangle]
pub unsafe extern "C" fn so3fft_import_wisdom_from_filename(filename: *const c_char) -> c_int {
    // SAFETY: as in `so3fft_export_wisdom_to_filename`.
    unsafe { import_wisdom_from_filename::<f64>(filename) }
}

/// FFTW's wisdom as a NUL-terminated string to be released with `free()`; NULL on error.
#[no_mangle]
pub extern "C" fn so3fft_export_wisdom_to_string() -> *mut c_char {
    export_wisdom_to_string::<f64>()
}

/// Loads FFTW wisdom from the NUL-terminated string `wisdom`. `SO3FFT_OK` or an error code.
#[no_mangle]
pub unsafe extern "C" fn so3fft_import_wisdom_from_string(wisdom: *const c_char) -> c_int {
    // SAFETY: as in `so3fft_export_wisdom_to_filename`.
    unsafe { import_wisdom_from_string::<f64>(wisdom) }
}

/// Forgets FFTW's wisdom (plans already made are not affected).
#[no_mangle]
pub extern "C" fn so3fft_forget_wisdom() {
    forget_wisdom::<f64>()
}
