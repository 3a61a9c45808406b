//! Error type shared by the Rust API and (through codes and messages) the C ABI.

use std::fmt;

/// Everything that can go wrong when planning or executing a transform. New kinds of
/// error may be added (match with a wildcard arm).
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Error {
    /// The bandwidth is 0 or larger than [`crate::MAX_BANDWIDTH`].
    InvalidBandwidth {
        /// The bandwidth that was asked for.
        bandwidth: usize,
        /// The largest bandwidth accepted.
        max: usize,
    },
    /// An array does not have the length the plan needs.
    LengthMismatch {
        /// Which array.
        what: &'static str,
        /// The length the plan needs.
        expected: usize,
        /// The length that was given.
        got: usize,
    },
    /// An allocation of `bytes` bytes failed.
    OutOfMemory {
        /// Size of the allocation that failed.
        bytes: usize,
    },
    /// Any other invalid argument (index out of range, bad option).
    InvalidArgument(String),
    /// The plan was made for the other direction only.
    WrongDirection,
    /// FFTW could not create a plan.
    Fftw(String),
    /// The system refused another resource than memory (e.g. worker threads).
    Resources(String),
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::InvalidBandwidth { bandwidth, max } => {
                write!(
                    f,
                    "invalid bandwidth {bandwidth}: must be between 1 and {max}"
                )
            }
            Error::LengthMismatch {
                what,
                expected,
                got,
            } => write!(f, "{what} has length {got}, the plan needs {expected}"),
            Error::OutOfMemory { bytes } => {
                write!(f, "out of memory: could not allocate {bytes} bytes")
            }
            Error::InvalidArgument(s) => write!(f, "invalid argument: {s}"),
            Error::WrongDirection => {
                write!(f, "the plan was not made for this direction")
            }
            Error::Fftw(s) => write!(f, "FFTW: {s}"),
            Error::Resources(s) => write!(f, "out of resources: {s}"),
        }
    }
}

impl std::error::Error for Error {}

/// Result type of this crate.
pub type Result<T> = std::result::Result<T, Error>;

/// [`Error::LengthMismatch`] unless an array named `what` has the `expected` length.
pub(crate) fn check_length(what: &'static str, expected: usize, got: usize) -> Result<()> {
    if got != expected {
        return Err(Error::LengthMismatch {
            what,
            expected,
            got,
        });
    }
    Ok(())
}
