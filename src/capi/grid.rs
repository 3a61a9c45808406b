//! Sizes, indices, sample angles and quadrature weights at a bandwidth. All but the weights
//! are the same for both precisions; the body of the weights is generic over the element
//! type (`so3fftf_weights` in `single.rs`).

use super::{guarded, guarded_code, SO3FFT_MAX_BANDWIDTH};
use crate::ffi::checks::{self, Array};
use crate::ffi::last_error;
use crate::ffi::CallError;
use crate::Real;
use std::ffi::{c_double, c_int};

/// Number of samples `(2B)^3` (0 for an invalid `B`).
#[no_mangle]
pub extern "C" fn so3fft_num_samples(B: c_int) -> usize {
    guarded(0, || Ok(crate::num_samples(checks::bandwidth(B)?)))
}

/// Number of coefficients `(4B^3-B)/3` (0 for an invalid `B`).
#[no_mangle]
pub extern "C" fn so3fft_num_coeffs(B: c_int) -> usize {
    guarded(0, || Ok(crate::num_coeffs(checks::bandwidth(B)?)))
}

/// Index of `fhat(l, m, mp)` (SOFT's `so3CoefLoc(m, mp, l, B)`), or -1.
#[no_mangle]
pub extern "C" fn so3fft_coef_index(B: c_int, l: c_int, m: c_int, mp: c_int) -> isize {
    guarded(-1, || {
        let b = checks::bandwidth(B)?;
        if l < 0 {
            return Err(CallError::invalid(format!(
                "coefficient (l={l}, m={m}, m'={mp}) does not exist at bandwidth {b}"
            )));
        }
        let i = crate::try_coef_index(b, l as usize, m as isize, mp as isize)?;
        Ok(i as isize)
    })
}

/// Index `k_beta*(2B)^2 + j_alpha*(2B) + j_gamma` of a sample, or -1.
#[no_mangle]
pub extern "C" fn so3fft_sample_index(
    B: c_int,
    j_alpha: c_int,
    k_beta: c_int,
    j_gamma: c_int,
) -> isize {
    guarded(-1, || {
        let b = checks::bandwidth(B)?;
        let n = 2 * B;
        for (v, name) in [
            (j_alpha, "j_alpha"),
            (k_beta, "k_beta"),
            (j_gamma, "j_gamma"),
        ] {
            if v < 0 || v >= n {
                return Err(CallError::invalid(format!(
                    "{name} = {v} out of range 0..{} at bandwidth {b}",
                    n - 1
                )));
            }
        }
        Ok(crate::sample_index(b, j_alpha as usize, k_beta as usize, j_gamma as usize) as isize)
    })
}

fn angle(b: c_int, j: c_int, name: &str, f: fn(usize, usize) -> f64) -> f64 {
    guarded(f64::NAN, || {
        let bw = checks::bandwidth(b)?;
        if j < 0 || j >= 2 * b {
            return Err(CallError::invalid(format!(
                "{name} index {j} out of range 0..{} at bandwidth {bw}",
                2 * b - 1
            )));
        }
        Ok(f(bw, j as usize))
    })
}

/// Sample angle `alpha_j = pi j / B`, `0 <= j < 2B` (NaN on invalid arguments).
#[no_mangle]
pub extern "C" fn so3fft_alpha(B: c_int, j: c_int) -> c_double {
    angle(B, j, "alpha", crate::alpha)
}

/// Sample angle `beta_k = pi (2k+1) / (4B)`, `0 <= k < 2B` (NaN on invalid arguments).
#[no_mangle]
pub extern "C" fn so3fft_beta(B: c_int, k: c_int) -> c_double {
    angle(B, k, "beta", crate::beta)
}

/// Sample angle `gamma_j = pi j / B`, `0 <= j < 2B` (NaN on invalid arguments).
#[no_mangle]
pub extern "C" fn so3fft_gamma(B: c_int, j: c_int) -> c_double {
    angle(B, j, "gamma", crate::gamma)
}

/// The body of `so3fft_weights` for the element type `T`: the weights (computed in double)
/// rounded to `T`.
///
/// # Safety
/// `w` is NULL or has room for `2B` values of `T` (the API's contract).
pub(super) unsafe fn weights<T: Real>(B: c_int, w: *mut T) -> c_int {
    guarded_code(|| {
        let b = checks::bandwidth(B)?;
        let values = crate::weights(b);
        Array::new(w.cast_const(), values.len(), "weights").check()?;
        for (i, &v) in values.iter().enumerate() {
            // SAFETY: `w` is non-NULL and aligned (checked) and has room for 2B values (the
            // caller's contract); `i < values.len() == 2B`. Written, never read, so the
            // caller's array may be uninitialised.
            unsafe { w.add(i).write(T::from_f64(v)) };
        }
        Ok(())
    })
}

/// Writes the `2B` quadrature weights `w_B(k)` to `w` (SOFT's `makeweights2`).
#[no_mangle]
pub unsafe extern "C" fn so3fft_weights(B: c_int, w: *mut c_double) -> c_int {
    // SAFETY: `w` is NULL or has room for 2B doubles (the caller's contract).
    unsafe { weights(B, w) }
}

/// `SO3FFT_MAX_BANDWIDTH` of the library linked.
#[no_mangle]
pub extern "C" fn so3fft_max_bandwidth() -> c_int {
    last_error::clear();
    SO3FFT_MAX_BANDWIDTH
}
