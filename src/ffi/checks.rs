//! Argument checks shared by the C entry points: bandwidth, array pointers (NULL,
//! alignment, extent) and overlap of an input with an output array.

use super::{CallError, ErrorKind};
use crate::MAX_BANDWIDTH;
use std::ffi::c_int;

/// The bandwidth `b` as a `usize`, or an error unless `1 <= b <= MAX_BANDWIDTH`.
pub(crate) fn bandwidth(b: c_int) -> Result<usize, CallError> {
    bandwidth_up_to(b, MAX_BANDWIDTH)
}

/// The bandwidth `b` as a `usize`, or an error unless `1 <= b <= max`.
pub(crate) fn bandwidth_up_to(b: c_int, max: usize) -> Result<usize, CallError> {
    match usize::try_from(b) {
        Ok(bw) if (1..=max).contains(&bw) => Ok(bw),
        _ => Err(CallError::new(
            ErrorKind::Bandwidth,
            format!("invalid bandwidth {b}: must be between 1 and {max}"),
        )),
    }
}

/// A caller's array argument: `len` values of type `T` at `ptr`, named `what` in messages.
pub(crate) struct Array<T> {
    /// Start of the array (as passed by the caller; may be NULL or misaligned).
    pub ptr: *const T,
    /// Number of values the call reads or writes.
    pub len: usize,
    /// Name of the array in error messages ("samples", "coefficients", ...).
    pub what: &'static str,
}

impl<T> Array<T> {
    /// The array of `len` values at `ptr`, named `what`.
    pub fn new(ptr: *const T, len: usize, what: &'static str) -> Array<T> {
        Array { ptr, len, what }
    }

    /// An error if the pointer is NULL.
    pub fn non_null(&self) -> Result<(), CallError> {
        if self.ptr.is_null() {
            return Err(CallError::new(
                ErrorKind::Null,
                format!("the {} array is NULL", self.what),
            ));
        }
        Ok(())
    }

    /// Byte range `[start, end)` of the array, checking that it is aligned for `T` and
    /// does not wrap around or exceed the address space (`isize::MAX`).
    pub fn byte_range(&self) -> Result<(usize, usize), CallError> {
        let (start, what, ptr, len) = (self.ptr as usize, self.what, self.ptr, self.len);
        let align = std::mem::align_of::<T>();
        if !start.is_multiple_of(align) {
            return Err(CallError::invalid(format!(
                "{what} array {ptr:p} is not aligned to {align} bytes (the alignment of its values)"
            )));
        }
        let end = len
            .checked_mul(std::mem::size_of::<T>())
            .and_then(|n| start.checked_add(n))
            .filter(|&e| e <= isize::MAX as usize)
            .ok_or_else(|| {
                CallError::invalid(format!(
                    "{what} array {ptr:p} of {len} values does not fit in memory"
                ))
            })?;
        Ok((start, end))
    }

    /// An error if the array is NULL, misaligned or does not fit in the address space.
    pub fn check(&self) -> Result<(), CallError> {
        self.non_null()?;
        self.byte_range().map(|_| ())
    }
}

/// Checks the input and output arrays of a call: both non-NULL (input first), both aligned
/// and within the address space, and not overlapping (in-place calls are not supported).
pub(crate) fn input_output<I, O>(input: &Array<I>, output: &Array<O>) -> Result<(), CallError> {
    input.non_null()?;
    output.non_null()?;
    let (a0, a1) = input.byte_range()?;
    let (b0, b1) = output.byte_range()?;
    if a0 < b1 && b0 < a1 {
        return Err(CallError::invalid(format!(
            "the {} and {} arrays overlap (in-place transforms are not supported)",
            input.what, output.what
        )));
    }
    Ok(())
}
