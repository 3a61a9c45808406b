//! The boundary shared by the two C surfaces (`capi`, the native API of `so3fft.h`, and
//! `soft`, the SOFT 2.0 layer): one panic boundary, the error of a C call, the thread-local
//! last-error state and the argument checks.
//!
//! A C entry point runs its body through [`boundary`]: a panic never crosses into C, and a
//! failure is handed to the surface's [`ErrorSink`] (the thread-local error state for the
//! native API, one line on stderr for the SOFT layer), after which the entry point returns
//! its own failure value.

pub(crate) mod checks;
pub(crate) mod last_error;

use crate::error::Error;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// What went wrong in a C call: each kind has its own `SO3FFT_E*` code in the native API.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum ErrorKind {
    /// Invalid argument (flags, index, thread count, misaligned or overlapping arrays).
    Invalid,
    /// Bandwidth outside `1 ..= MAX_BANDWIDTH`.
    Bandwidth,
    /// A required pointer is NULL.
    Null,
    /// An allocation (or another resource) was refused.
    NoMemory,
    /// The plan was made for the other direction only.
    Direction,
    /// FFTW could not create a plan.
    Fftw,
    /// A Rust panic, caught at the boundary.
    Panic,
}

/// An error on its way to the C caller: its kind and a message.
#[derive(Debug)]
pub(crate) struct CallError {
    /// What went wrong.
    pub kind: ErrorKind,
    /// Human-readable description.
    pub msg: String,
}

impl CallError {
    /// An error of `kind` with message `msg`.
    pub fn new(kind: ErrorKind, msg: impl Into<String>) -> CallError {
        CallError {
            kind,
            msg: msg.into(),
        }
    }

    /// An invalid argument.
    pub fn invalid(msg: impl Into<String>) -> CallError {
        CallError::new(ErrorKind::Invalid, msg)
    }

    /// The same error with `context: ` in front of its message.
    pub fn context(self, context: &str) -> CallError {
        CallError::new(self.kind, format!("{context}: {}", self.msg))
    }

    /// The error that reports a caught panic with `payload`.
    fn panic(payload: &(dyn std::any::Any + Send)) -> CallError {
        let what = if let Some(s) = payload.downcast_ref::<&str>() {
            s
        } else if let Some(s) = payload.downcast_ref::<String>() {
            s.as_str()
        } else {
            "unknown panic payload"
        };
        CallError::new(ErrorKind::Panic, format!("internal error (panic): {what}"))
    }
}

impl From<Error> for CallError {
    fn from(e: Error) -> CallError {
        let kind = match e {
            Error::InvalidBandwidth { .. } => ErrorKind::Bandwidth,
            Error::LengthMismatch { .. } | Error::InvalidArgument(_) => ErrorKind::Invalid,
            Error::OutOfMemory { .. } | Error::Resources(_) => ErrorKind::NoMemory,
            Error::WrongDirection => ErrorKind::Direction,
            Error::Fftw(_) => ErrorKind::Fftw,
        };
        CallError::new(kind, e.to_string())
    }
}

/// Where a C surface reports its failed calls.
pub(crate) trait ErrorSink {
    /// Called when a call starts (e.g. to reset an error state).
    fn start(&self) {}
    /// Reports the failure of the call.
    fn report(&self, err: &CallError);
}

/// Runs the body of a C entry point: `sink.start()`, then `body` with panics caught; an
/// error or a panic is reported to `sink` and returned as its kind, for the entry point to
/// turn into its failure value.
pub(crate) fn boundary<R>(
    sink: &impl ErrorSink,
    body: impl FnOnce() -> Result<R, CallError>,
) -> Result<R, ErrorKind> {
    sink.start();
    // AssertUnwindSafe: after a panic the call only reports it; state shared across calls
    // (plans, the SOFT layer's caches) is behind locks whose poisoning is recovered from.
    let err = match catch_unwind(AssertUnwindSafe(body)) {
        Ok(Ok(value)) => return Ok(value),
        Ok(Err(err)) => err,
        Err(payload) => CallError::panic(&*payload),
    };
    sink.report(&err);
    Err(err.kind)
}
