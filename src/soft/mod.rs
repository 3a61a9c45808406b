//! SOFT 2.0 drop-in layer: C entry points with the names, prototypes, array layouts and
//! semantics of Kostelec and Rockmore's SOFT 2.0 (docs/conventions.md: layouts, normalisation,
//! SOFT compatibility), running on the so3fft engine. The C declarations are the hand-written headers in `include/soft/`
//! (`soft_fftw.h`, `soft_fftw_pc.h`, `soft_fftw_nt.h`, `wrap_fftw.h`, `utils_so3.h`,
//! `makeweights.h`, `makeWigner.h`, `so3_correlate_fftw.h`, `csecond.h`, and for S^2
//! (docs/conventions-s2.md) `s2_semi_memo.h`, `s2_semi_fly.h`, `s2_cospmls.h`,
//! `s2_primitive.h`, `s2_legendreTransforms.h`); none of these
//! functions belongs to the native API in `so3fft.h` (every item carries `cbindgen:ignore`).
//!
//! **Symbol names.** Each function is exported as `so3fft_soft_<SOFT name>`, a private name
//! declared in no header, so libso3fft defines nothing but `so3fft_*`. SOFT's own names live in
//! libso3fft_soft: `soft_names.c` in this directory, one forwarder per function, compiled by
//! CMake against the headers. A new entry point needs its line there and in
//! `c_tests/soft/soft_symbols.txt` (the symbol test checks both lists).
//!
//! Behaviour shared by all transform entry points:
//!
//! - **Plans.** One [`Plan`](crate::Plan) per bandwidth is created on first use and cached for the life of
//!   the process (a global map, [`Direction::Both`](crate::Direction::Both); likewise one
//!   [`S2Plan`](crate::s2::S2Plan) per bandwidth for the S^2 transforms), so repeated calls at the same bandwidth
//!   pay set-up once. Plans use all cores and FFTW's `MEASURE` rigour by default; the
//!   environment variables `SO3FFT_SOFT_THREADS` (a positive number) and `SO3FFT_SOFT_RIGOR`
//!   (`estimate`, `measure`, `patient`, `exhaustive`), read once, override that. Calls from
//!   several client threads at once are safe (the cache is locked; plans execute concurrently).
//! - **Caller's FFTW plans and workspaces** are accepted and never used: the `fftw_plan *`
//!   argument is never dereferenced or executed and the workspaces are never read or written
//!   (all temporaries are private), so any buffer at least as large as SOFT documents (or
//!   smaller) is fine.
//! - **Inputs are never modified** (including the sample array of the `_nt` forward, which
//!   SOFT may overwrite).
//! - **Errors.** SOFT has no error channel: on invalid input (bandwidth outside
//!   `1..=MAX_BANDWIDTH`, NULL or misaligned arrays, overlapping input and output) or an
//!   internal error (e.g. out of memory), a function prints one line to stderr and returns
//!   without writing its output; functions returning `int` return -1. Panics never cross the
//!   C boundary.
//! - **Safety contract.** The `unsafe` entry points dereference the caller's pointers: each
//!   array argument that is read or written must be NULL (reported as an error where the
//!   function checks it) or point to at least as many values as SOFT documents for the
//!   bandwidth, valid for the whole call, and output arrays must not be accessed by other
//!   threads during the call. NULL, alignment and input/output overlap are checked; the
//!   extent cannot be, and rests on the caller (as in SOFT).
//! - **Real data** (`flag != 0`): see [`Forward_SO3_Naive_fftw`] and [`Inverse_SO3_Naive_fftw`].
//!   `flag = 0` calls on real data (samples with imaginary parts exactly 0, coefficients with
//!   the exact real symmetry) take the same real paths (docs/migrating-from-soft.md).

#![allow(non_snake_case)]
#![allow(clippy::missing_safety_doc)]

mod cache;
mod correlate;
mod index;
mod matching;
mod real;
#[cfg(test)]
mod real_paths_tests;
mod rotate;
mod s2;
mod so3;
mod tables;

use crate::ffi::{boundary, CallError, ErrorSink};
use std::ffi::{c_double, c_int};
use std::io::Write;

/// `fftw_complex`: interleaved real and imaginary parts.
type FftwComplex = [f64; 2];

/// Result of an entry point's body: the error's message is printed to stderr.
type SoftResult<T> = Result<T, CallError>;

/// The [`ErrorSink`] of the SOFT layer, which has no error channel: one line on stderr
/// naming the function.
struct Stderr {
    /// The C function that failed.
    func: &'static str,
}

impl ErrorSink for Stderr {
    fn report(&self, err: &CallError) {
        // Never panic here (eprintln! would on a closed stderr).
        let _ = writeln!(
            std::io::stderr(),
            "so3fft (SOFT layer): {}: {}",
            self.func,
            err.msg
        );
    }
}

/// Runs the body of the SOFT entry point `func` through the shared boundary (panics
/// caught, failures printed to stderr); `fallback` on failure.
fn guarded<T>(func: &'static str, fallback: T, body: impl FnOnce() -> SoftResult<T>) -> T {
    boundary(&Stderr { func }, body).unwrap_or(fallback)
}

/// Converts an index or size to the C `int` SOFT returns.
fn to_int(v: impl Into<i128> + Copy + std::fmt::Display) -> SoftResult<c_int> {
    c_int::try_from(v.into())
        .map_err(|_| CallError::invalid(format!("result {v} does not fit in a C int")))
}

/// `bw` when it is a bandwidth this layer accepts (`1..=MAX_BANDWIDTH`); wider than a C
/// `int` for the functions that take the larger of two arguments.
fn soft_bandwidth(bw: i64) -> SoftResult<i64> {
    let bad = c_int::try_from(bw).unwrap_or(c_int::MAX);
    crate::ffi::checks::bandwidth(bad).map(|b| b as i64)
}

// csecond.h

/// Wall-clock time in seconds (since the Unix epoch), for timing as SOFT's clients do.
/// (SOFT's `csecond` may return CPU time; with multithreaded transforms wall time is the
/// meaningful measure.)
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_csecond"]
pub extern "C" fn csecond() -> c_double {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs_f64())
        .unwrap_or(0.0)
}

#[cfg(test)]
mod tests {
    use super::correlate::seanindex;
    use super::index::{howMany_so3, numCoeffs_so3, sampLoc_so3, so3CoefLoc, totalCoeffs_so3};

    #[test]
    fn index_functions() {
        assert_eq!(so3CoefLoc(0, 0, 0, 256), 0);
        assert_eq!(so3CoefLoc(0, 0, 255, 256), 255);
        assert_eq!(so3CoefLoc(0, 1, 1, 256), 256);
        assert_eq!(so3CoefLoc(0, -1, 1, 256), 65281);
        assert_eq!(so3CoefLoc(1, 0, 1, 256), 65536);
        assert_eq!(so3CoefLoc(-1, 0, 1, 256), 22304001);
        assert_eq!(so3CoefLoc(-1, -1, 255, 256), 22369535);
        assert_eq!(totalCoeffs_so3(256), 22369536);
        assert_eq!(totalCoeffs_so3(2048), -1);
        assert_eq!(numCoeffs_so3(8, 3), 55);
        assert_eq!(numCoeffs_so3(3, 8), 55);
        assert_eq!(numCoeffs_so3(8, -3), 55);
        assert_eq!(howMany_so3(-2, 5, 8), 3);
        assert_eq!(sampLoc_so3(1, -1, 4), 8 * (8 + 7));
        for bw in 1..6 {
            let mut k = 0;
            for m in 0..bw {
                for l in m..bw {
                    assert_eq!(seanindex(m, l, bw), k);
                    k += 1;
                }
            }
            for m in (1..bw).rev() {
                for l in m..bw {
                    assert_eq!(seanindex(-m, l, bw), k);
                    k += 1;
                }
            }
            assert_eq!(k, bw * bw);
        }
    }
}
