//! The thread-local error state of the native C API (`so3fft_last_error_code`,
//! `so3fft_last_error`).

use super::{CallError, ErrorKind, ErrorSink};
use std::cell::RefCell;
use std::ffi::{c_char, CString};

/// The last error of this thread: `kind` is `None` after a successful call.
struct LastError {
    kind: Option<ErrorKind>,
    msg: CString,
}

thread_local! {
    static LAST: RefCell<LastError> = RefCell::new(LastError { kind: None, msg: CString::default() });
}

/// The [`ErrorSink`] of the native API: a call resets the state when it starts, and a
/// failure stores its kind and message.
pub(crate) struct LastErrorSink;

impl ErrorSink for LastErrorSink {
    fn start(&self) {
        clear();
    }

    fn report(&self, err: &CallError) {
        set(err.kind, &err.msg);
    }
}

/// Stores `kind` and `msg` (interior NULs become spaces) as this thread's last error.
fn set(kind: ErrorKind, msg: &str) {
    let msg = CString::new(msg.replace('\0', " ")).unwrap_or_default();
    // try_with: the thread may be exiting (TLS destroyed); then there is nowhere to report.
    let _ = LAST.try_with(|l| {
        if let Ok(mut l) = l.try_borrow_mut() {
            *l = LastError {
                kind: Some(kind),
                msg,
            };
        }
    });
}

/// Resets this thread's error state to "no error".
pub(crate) fn clear() {
    let _ = LAST.try_with(|l| {
        if let Ok(mut l) = l.try_borrow_mut() {
            if l.kind.is_some() {
                *l = LastError {
                    kind: None,
                    msg: CString::default(),
                };
            }
        }
    });
}

/// The kind of this thread's last error, `None` if the last call succeeded.
pub(crate) fn kind() -> Option<ErrorKind> {
    LAST.try_with(|l| l.try_borrow().ok().and_then(|l| l.kind))
        .ok()
        .flatten()
}

/// This thread's last error message as a C string, valid until the next call that changes
/// the state on this thread or until the thread exits; `""` (a static string) when the
/// state cannot be read.
pub(crate) fn message() -> *const c_char {
    LAST.try_with(|l| l.try_borrow().map(|l| l.msg.as_ptr()).ok())
        .ok()
        .flatten()
        .unwrap_or(c"".as_ptr())
}
