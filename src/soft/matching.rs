//! `softFFTWCor2` of `wrap_fftw.h`: rotational matching of two functions on the sphere.

use super::guarded;
use crate::ffi::checks::{self, Array};
use crate::ffi::{CallError, ErrorKind};
use crate::matching::{grid_argmax, grid_argmax_real, Correlation, CorrelationOptions};
use crate::Complex64;
use std::ffi::{c_double, c_int};

/// The rotation `g = Rz(alpha) Ry(beta) Rz(gamma)` of the SO(3) grid of bandwidth `bw` that
/// maximises `|C(g)|^2`, `C(g) = int sig(x) conj(pat(g^-1 x)) dx`: the signal is about the
/// pattern rotated by `g`. `sig`, `pat`: `(2bw)^2` S^2 samples, interleaved complex
/// (`2 (2bw)^2` doubles) or, with `isReal` nonzero, real. Ties go to the lowest grid index
/// (an all-zero correlation gives `alpha = gamma = 0`, `beta = pi/(4bw)`). Inputs are not
/// modified; on invalid input one line is printed and the angles are not written.
///
/// cbindgen:ignore
#[no_mangle]
pub unsafe extern "C" fn softFFTWCor2(
    bw: c_int,
    sig: *mut c_double,
    pat: *mut c_double,
    alpha: *mut c_double,
    beta: *mut c_double,
    gamma: *mut c_double,
    isReal: c_int,
) {
    guarded("softFFTWCor2", (), || {
        let b = checks::bandwidth(bw)?;
        let real = isReal != 0;
        let n = 4 * b * b;
        let len = if real { n } else { 2 * n };
        for (p, what) in [(sig, "sig"), (pat, "pat")] {
            Array::new(p.cast_const(), len, what).check()?;
        }
        for (p, what) in [(alpha, "alpha"), (beta, "beta"), (gamma, "gamma")] {
            if p.is_null() {
                return Err(CallError::new(ErrorKind::Null, format!("{what} is NULL")));
            }
        }
        let plan = Correlation::new(
            b,
            &CorrelationOptions {
                real,
                ..CorrelationOptions::default()
            },
        )?;
        let peak = if real {
            // SAFETY: non-NULL, aligned (checked); (2bw)^2 doubles each (SOFT's contract);
            // only read.
            let (s, p) = unsafe {
                (
                    std::slice::from_raw_parts(sig.cast_const(), n),
                    std::slice::from_raw_parts(pat.cast_const(), n),
                )
            };
            let mut out = vec![0.0; plan.num_grid()];
            plan.correlate_real(s, p, &mut out)?;
            grid_argmax_real(b, &out)
        } else {
            // SAFETY: as above, 2 (2bw)^2 doubles each, read as (2bw)^2 complex values
            // (Complex64 is #[repr(C)] {re, im}); only read.
            let (s, p) = unsafe {
                (
                    std::slice::from_raw_parts(sig.cast_const().cast::<Complex64>(), n),
                    std::slice::from_raw_parts(pat.cast_const().cast::<Complex64>(), n),
                )
            };
            let mut out = vec![Complex64::default(); plan.num_grid()];
            plan.correlate(s, p, &mut out)?;
            grid_argmax(b, &out)
        };
        // SAFETY: non-NULL (checked); single doubles the caller owns.
        unsafe {
            *alpha = peak.alpha;
            *beta = peak.beta;
            *gamma = peak.gamma;
        }
        Ok(())
    })
}
