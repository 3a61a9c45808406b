//! `softFFTWCor2` of `wrap_fftw.h`: rotational matching of two functions on the sphere.

use super::cache::plan_for;
use super::guarded;
use super::s2::s2_plan_for;
use crate::ffi::checks::{self, Array};
use crate::ffi::{CallError, ErrorKind};
use crate::matching::{combine, SliceArgmax};
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
#[export_name = "so3fft_soft_softFFTWCor2"]
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
        // The layer's cached plans of this bandwidth (no planning after the first call).
        let (s2, so3) = (s2_plan_for(b)?, plan_for(b)?);
        let (s2, nc) = (s2.plan(), b * b);
        let (mut sig_hat, mut pat_hat) = (
            vec![Complex64::default(); nc],
            vec![Complex64::default(); nc],
        );
        let mut so3_hat = vec![Complex64::default(); so3.num_coeffs()];
        let peak = if real {
            // SAFETY: non-NULL, aligned (checked); (2bw)^2 doubles each (SOFT's contract);
            // only read.
            let (s, p) = unsafe {
                (
                    std::slice::from_raw_parts(sig.cast_const(), n),
                    std::slice::from_raw_parts(pat.cast_const(), n),
                )
            };
            s2.forward_real(s, &mut sig_hat)?;
            s2.forward_real(p, &mut pat_hat)?;
            combine((&sig_hat, &pat_hat), b, b - 1, b, &mut so3_hat)?;
            let mut out = vec![0.0; so3.num_samples()];
            // The argmax taken slice by slice while the inverse computes them.
            let seen = SliceArgmax::new(b);
            so3.engine()
                .inverse_real_watched(&so3_hat, &mut out, &|k, s| seen.watch(k, s))?;
            seen.peak()
        } else {
            // SAFETY: as above, 2 (2bw)^2 doubles each, read as (2bw)^2 complex values
            // (Complex64 is #[repr(C)] {re, im}); only read.
            let (s, p) = unsafe {
                (
                    std::slice::from_raw_parts(sig.cast_const().cast::<Complex64>(), n),
                    std::slice::from_raw_parts(pat.cast_const().cast::<Complex64>(), n),
                )
            };
            s2.forward(s, &mut sig_hat)?;
            s2.forward(p, &mut pat_hat)?;
            combine((&sig_hat, &pat_hat), b, b - 1, b, &mut so3_hat)?;
            let mut out = vec![Complex64::default(); so3.num_samples()];
            let seen = SliceArgmax::new(b);
            so3.engine()
                .inverse_watched(&so3_hat, &mut out, &|k, s| seen.watch(k, s))?;
            seen.peak()
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
