//! The single-precision rotational matching C API, `so3fftf_*` on `float` samples and grids:
//! correlation plans, grid peaks, refinement and the whole matching with its uncertainty. Each function is a thin wrapper over the
//! body its `so3fft_*` twin runs (`matching.rs`), instantiated for `f32`, so the checks and
//! error messages are the same in both precisions. Euler angles, peak values and indices
//! stay `double` (refinement computes in double from the float samples, exactly widened);
//! `so3fft_rotation_matrix` and `so3fft_rotation_quaternion` are shared.

use super::matching::{
    correlate, correlate_argmax, correlate_real, correlate_real_argmax, correlation_degree_limit,
    correlation_find, correlation_find_real, correlation_grid_size, correlation_refine_many,
    correlation_weights, correlation_weights_real, destroy_correlation, grid_argmax,
    grid_argmax_real, grid_top_peaks, grid_top_peaks_real, plan_correlation, so3fft_match,
    CorrelationHandle,
};
use super::single::so3fftf_complex;
use crate::matching::Correlation;
use std::ffi::{c_double, c_float, c_int, c_uint};

/// Opaque single-precision correlation plan (made by `so3fftf_plan_correlation`).
pub struct so3fftf_correlation_s {
    plan: Correlation<f32>,
}

/// A single-precision correlation plan: a pointer to an opaque object.
pub type so3fftf_correlation = *mut so3fftf_correlation_s;

impl CorrelationHandle for so3fftf_correlation_s {
    type T = f32;
    fn wrap(plan: Correlation<f32>) -> Self {
        so3fftf_correlation_s { plan }
    }
    fn plan(&self) -> &Correlation<f32> {
        &self.plan
    }
}

/// As `so3fft_plan_correlation`, in single precision: float samples and grids (same
/// arguments and flags). NULL on error.
#[no_mangle]
pub extern "C" fn so3fftf_plan_correlation(
    L: c_int,
    B_out: c_int,
    deg_lim: c_int,
    flags: c_uint,
    nthreads: c_int,
) -> so3fftf_correlation {
    // SAFETY: no weights array.
    unsafe { plan_correlation(L, B_out, deg_lim, flags, nthreads, None) }
}

/// As `so3fft_plan_correlation_weighted`, in single precision (the weights stay double).
/// NULL on error.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_plan_correlation_weighted(
    L: c_int,
    B_out: c_int,
    deg_lim: c_int,
    flags: c_uint,
    nthreads: c_int,
    weights: *const c_double,
) -> so3fftf_correlation {
    // SAFETY: `weights` NULL or `D + 1` doubles (the API's contract).
    unsafe { plan_correlation(L, B_out, deg_lim, flags, nthreads, Some(weights)) }
}

/// Destroys a single-precision correlation plan; NULL is a no-op.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_destroy_correlation(p: so3fftf_correlation) {
    // SAFETY: `p` is NULL or a live plan of this type, used by no other thread (the API's
    // contract).
    unsafe { destroy_correlation(p) }
}

/// Number of values `(2 B_out)^3` of the plan's grid (`SO3FFT_ENULL` for NULL).
#[no_mangle]
pub unsafe extern "C" fn so3fftf_correlation_grid_size(p: so3fftf_correlation) -> isize {
    // SAFETY: `p` is NULL or a live plan (the API's contract).
    unsafe { correlation_grid_size(p) }
}

/// As `so3fft_correlate`: complex float samples (`(2L)^2` each) into the grid `out`.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_correlate(
    p: so3fftf_correlation,
    signal: *mut so3fftf_complex,
    pattern: *mut so3fftf_complex,
    out: *mut so3fftf_complex,
) -> c_int {
    // SAFETY: `p` is NULL or a live plan; non-NULL arrays hold the plan's sizes (the API's
    // contract).
    unsafe { correlate(p, signal, pattern, out) }
}

/// As `so3fft_correlate_real`: real float samples into the real grid `out`.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_correlate_real(
    p: so3fftf_correlation,
    signal: *const c_float,
    pattern: *const c_float,
    out: *mut c_float,
) -> c_int {
    // SAFETY: as in `so3fftf_correlate`.
    unsafe { correlate_real(p, signal, pattern, out) }
}

/// As `so3fft_correlate_argmax`: the grid, and the index of its largest `|C|^2` (angles
/// into `angles`, 3 doubles, or NULL). -1 on error.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_correlate_argmax(
    p: so3fftf_correlation,
    signal: *mut so3fftf_complex,
    pattern: *mut so3fftf_complex,
    out: *mut so3fftf_complex,
    angles: *mut c_double,
) -> isize {
    // SAFETY: as in `so3fftf_correlate`; `angles` NULL or 3 doubles (the API's contract).
    unsafe { correlate_argmax(p, signal, pattern, out, angles) }
}

/// As `so3fft_correlate_real_argmax`, on real float samples.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_correlate_real_argmax(
    p: so3fftf_correlation,
    signal: *const c_float,
    pattern: *const c_float,
    out: *mut c_float,
    angles: *mut c_double,
) -> isize {
    // SAFETY: as in `so3fftf_correlate_argmax`.
    unsafe { correlate_real_argmax(p, signal, pattern, out, angles) }
}

/// As `so3fft_grid_argmax`, on a complex float grid (angles in double).
#[no_mangle]
pub unsafe extern "C" fn so3fftf_grid_argmax(
    B: c_int,
    grid: *mut so3fftf_complex,
    angles: *mut c_double,
) -> isize {
    // SAFETY: `grid` NULL or (2B)^3 values, `angles` NULL or 3 doubles (the API's contract).
    unsafe { grid_argmax(B, grid, angles) }
}

/// As `so3fft_grid_argmax_real`, on a real float grid.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_grid_argmax_real(
    B: c_int,
    grid: *const c_float,
    angles: *mut c_double,
) -> isize {
    // SAFETY: as in `so3fftf_grid_argmax`.
    unsafe { grid_argmax_real(B, grid, angles) }
}

/// As `so3fft_grid_top_peaks`, on a complex float grid (angles and values in double).
#[no_mangle]
pub unsafe extern "C" fn so3fftf_grid_top_peaks(
    B: c_int,
    grid: *mut so3fftf_complex,
    k: usize,
    min_angle: c_double,
    angles: *mut c_double,
    values: *mut c_double,
    indices: *mut isize,
) -> isize {
    // SAFETY: `grid` NULL or (2B)^3 values, the peak arrays NULL or of `k` peaks (the API's
    // contract).
    unsafe { grid_top_peaks(B, grid, k, min_angle, angles, values, indices) }
}

/// As `so3fft_grid_top_peaks_real`, on a real float grid.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_grid_top_peaks_real(
    B: c_int,
    grid: *const c_float,
    k: usize,
    min_angle: c_double,
    angles: *mut c_double,
    values: *mut c_double,
    indices: *mut isize,
) -> isize {
    // SAFETY: as in `so3fftf_grid_top_peaks`.
    unsafe { grid_top_peaks_real(B, grid, k, min_angle, angles, values, indices) }
}

/// As `so3fft_correlation_refine`: float samples (complex ones as interleaved floats),
/// `angles` and `value` in double; the refinement computes in double.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_correlation_refine(
    p: so3fftf_correlation,
    signal: *const c_float,
    pattern: *const c_float,
    angles: *mut c_double,
    value: *mut c_double,
) -> c_int {
    // SAFETY: the caller's contract is `so3fftf_correlation_refine_many`'s with one peak.
    unsafe { correlation_refine_many(p, signal, pattern, 1, angles, value) }
}

/// As `so3fft_correlation_refine_many`: float samples, `npeaks` peaks in double.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_correlation_refine_many(
    p: so3fftf_correlation,
    signal: *const c_float,
    pattern: *const c_float,
    npeaks: usize,
    angles: *mut c_double,
    values: *mut c_double,
) -> c_int {
    // SAFETY: `p` is NULL or a live plan; the arrays hold the documented sizes (the API's
    // contract).
    unsafe { correlation_refine_many(p, signal, pattern, npeaks, angles, values) }
}

/// As `so3fft_correlation_degree_limit`.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_correlation_degree_limit(p: so3fftf_correlation) -> c_int {
    // SAFETY: `p` is NULL or a live plan (the API's contract).
    unsafe { correlation_degree_limit(p) }
}

/// As `so3fft_correlation_find`: complex float samples and grid, the result in double (the
/// refinement and the uncertainty computed in double).
#[no_mangle]
pub unsafe extern "C" fn so3fftf_correlation_find(
    p: so3fftf_correlation,
    signal: *mut so3fftf_complex,
    pattern: *mut so3fftf_complex,
    grid: *mut so3fftf_complex,
    out: *mut so3fft_match,
) -> c_int {
    // SAFETY: as in `so3fftf_correlate`; `out` NULL or one so3fft_match (the API's contract).
    unsafe { correlation_find(p, signal, pattern, grid, out) }
}

/// As `so3fft_correlation_find_real`: real float samples and grid.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_correlation_find_real(
    p: so3fftf_correlation,
    signal: *const c_float,
    pattern: *const c_float,
    grid: *mut c_float,
    out: *mut so3fft_match,
) -> c_int {
    // SAFETY: as in `so3fftf_correlation_find`.
    unsafe { correlation_find_real(p, signal, pattern, grid, out) }
}

/// As `so3fft_correlation_weights`: complex float samples, double weights.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_correlation_weights(
    p: so3fftf_correlation,
    signal: *mut so3fftf_complex,
    pattern: *mut so3fftf_complex,
    w: *mut c_double,
) -> c_int {
    // SAFETY: `p` NULL or a live plan, the inputs NULL or `(2L)^2` samples, `w` NULL or
    // `D + 1` doubles (the API's contract).
    unsafe { correlation_weights(p, signal, pattern, w) }
}

/// As `so3fft_correlation_weights_real`: real float samples.
#[no_mangle]
pub unsafe extern "C" fn so3fftf_correlation_weights_real(
    p: so3fftf_correlation,
    signal: *const c_float,
    pattern: *const c_float,
    w: *mut c_double,
) -> c_int {
    // SAFETY: as in `so3fftf_correlation_weights`.
    unsafe { correlation_weights_real(p, signal, pattern, w) }
}

#[cfg(test)]
mod tests {
    use super::super::errors::{so3fft_last_error, so3fft_last_error_code};
    use super::super::matching::{
        so3fft_correlate_real, so3fft_correlate_real_argmax, so3fft_correlation_degree_limit,
        so3fft_correlation_find_real, so3fft_correlation_grid_size, so3fft_correlation_refine,
        so3fft_correlation_weights_real, so3fft_destroy_correlation, so3fft_plan_correlation,
        so3fft_plan_correlation_weighted, SO3FFT_NOISE_WEIGHTS,
    };
    use super::super::{SO3FFT_EINVAL, SO3FFT_ENULL, SO3FFT_OK, SO3FFT_REAL};
    use super::*;
    use std::ffi::CStr;

    /// The thread's last error code and message.
    fn last_error() -> (c_int, String) {
        // SAFETY: the library's error message is a NUL-terminated static or thread-local
        // string, read before the next call.
        let msg = unsafe { CStr::from_ptr(so3fft_last_error()) };
        (so3fft_last_error_code(), msg.to_string_lossy().into_owned())
    }

    /// A real correlation through the single-precision entry points against the double
    /// ones on the same (widened) samples: the grid, its argmax, the refined peak; a NULL
    /// plan fails the same way in both.
    #[test]
    fn single_precision_correlation_entry_points() {
        let (l, b_out) = (6, 8);
        let ns = 4 * l * l;
        let sig: Vec<f32> = (0..ns)
            .map(|i| ((i * 7919) % 101) as f32 / 50.0 - 1.0)
            .collect();
        let pat: Vec<f32> = (0..ns)
            .map(|i| ((i * 104729) % 97) as f32 / 48.0 - 1.0)
            .collect();
        let (sig_d, pat_d): (Vec<f64>, Vec<f64>) = (
            sig.iter().map(|&x| x.into()).collect(),
            pat.iter().map(|&x| x.into()).collect(),
        );
        let pf = so3fftf_plan_correlation(l as c_int, b_out, -1, SO3FFT_REAL, 1);
        let pd = so3fft_plan_correlation(l as c_int, b_out, -1, SO3FFT_REAL, 1);
        assert!(!pf.is_null() && !pd.is_null(), "{:?}", last_error());
        // SAFETY: live plans; the arrays hold their sizes.
        unsafe {
            let ng = so3fftf_correlation_grid_size(pf);
            assert_eq!(ng, 8 * (b_out as isize).pow(3));
            let mut grid = vec![0.0f32; ng as usize];
            let mut grid_d = vec![0.0f64; ng as usize];
            let (mut af, mut ad) = ([0.0f64; 3], [0.0f64; 3]);
            let at = so3fftf_correlate_real_argmax(
                pf,
                sig.as_ptr(),
                pat.as_ptr(),
                grid.as_mut_ptr(),
                af.as_mut_ptr(),
            );
            let at_d = so3fft_correlate_real_argmax(
                pd,
                sig_d.as_ptr(),
                pat_d.as_ptr(),
                grid_d.as_mut_ptr(),
                ad.as_mut_ptr(),
            );
            assert_eq!((at, af), (at_d, ad));
            let (num, den) = grid
                .iter()
                .zip(&grid_d)
                .fold((0.0, 0.0), |(n, d), (&x, &y)| {
                    (n + (f64::from(x) - y).powi(2), d + y * y)
                });
            assert!((num / den).sqrt() < 1e-5, "{}", (num / den).sqrt());
            assert_eq!(
                so3fftf_grid_argmax_real(b_out, grid.as_ptr(), af.as_mut_ptr()),
                at
            );

            let (mut vf, mut vd) = (0.0, 0.0);
            let rf = so3fftf_correlation_refine(
                pf,
                sig.as_ptr(),
                pat.as_ptr(),
                af.as_mut_ptr(),
                &mut vf,
            );
            let rd = so3fft_correlation_refine(
                pd,
                sig_d.as_ptr(),
                pat_d.as_ptr(),
                ad.as_mut_ptr(),
                &mut vd,
            );
            assert_eq!((rf, rd), (SO3FFT_OK, SO3FFT_OK), "{:?}", last_error());
            for k in 0..3 {
                assert!((af[k] - ad[k]).abs() < 1e-8, "{af:?} {ad:?}");
            }
            assert!((vf - vd).abs() <= 1e-10 * vd);

            let (null_f, null_d) = (std::ptr::null_mut(), std::ptr::null_mut());
            let fr = so3fftf_correlate_real(null_f, sig.as_ptr(), pat.as_ptr(), grid.as_mut_ptr());
            let f = last_error();
            let dr =
                so3fft_correlate_real(null_d, sig_d.as_ptr(), pat_d.as_ptr(), grid_d.as_mut_ptr());
            assert_eq!((fr, dr), (SO3FFT_ENULL, SO3FFT_ENULL));
            assert_eq!(f, last_error());
            assert!(f.1.contains("correlation plan is NULL"), "{f:?}");
            so3fftf_destroy_correlation(pf);
            so3fft_destroy_correlation(pd);
        }
    }

    /// Weighted plans and the whole matching through the entry points of both precisions on
    /// the same (widened) real samples: the same weights, grid peak, refined rotation and
    /// uncertainty; weights that the plan refuses give the Rust check's message.
    #[test]
    fn weighted_find_entry_points() {
        let (l, b_out, d) = (8usize, 10, 6);
        let ns = 4 * l * l;
        let sig: Vec<f32> = (0..ns)
            .map(|i| ((i * 7919) % 101) as f32 / 50.0 - 1.0)
            .collect();
        let pat: Vec<f32> = (0..ns)
            .map(|i| ((i * 104729) % 97) as f32 / 48.0 - 1.0)
            .collect();
        let (sig_d, pat_d): (Vec<f64>, Vec<f64>) = (
            sig.iter().map(|&x| x.into()).collect(),
            pat.iter().map(|&x| x.into()).collect(),
        );
        let w: Vec<f64> = (0..=d).map(|k| 1.0 / (1.0 + k as f64)).collect();
        // SAFETY: `w` holds `d + 1` doubles; the plans are live and the arrays hold their
        // sizes below.
        unsafe {
            let (lc, dc) = (l as c_int, d as c_int);
            let pf = so3fftf_plan_correlation_weighted(lc, b_out, dc, SO3FFT_REAL, 1, w.as_ptr());
            let pd = so3fft_plan_correlation_weighted(lc, b_out, dc, SO3FFT_REAL, 1, w.as_ptr());
            assert!(!pf.is_null() && !pd.is_null(), "{:?}", last_error());
            assert_eq!(so3fftf_correlation_degree_limit(pf), dc);
            assert_eq!(so3fft_correlation_degree_limit(pd), dc);
            let mut got = vec![0.0; d + 1];
            let r =
                so3fftf_correlation_weights_real(pf, sig.as_ptr(), pat.as_ptr(), got.as_mut_ptr());
            assert_eq!((r, &got), (SO3FFT_OK, &w));
            let r = so3fft_correlation_weights_real(
                pd,
                sig_d.as_ptr(),
                pat_d.as_ptr(),
                got.as_mut_ptr(),
            );
            assert_eq!((r, &got), (SO3FFT_OK, &w));

            let ng = so3fft_correlation_grid_size(pd) as usize;
            let (mut grid, mut grid_d) = (vec![0.0f32; ng], vec![0.0f64; ng]);
            let (mut mf, mut md) = (so3fft_match::default(), so3fft_match::default());
            let rf = so3fftf_correlation_find_real(
                pf,
                sig.as_ptr(),
                pat.as_ptr(),
                grid.as_mut_ptr(),
                &mut mf,
            );
            let rd = so3fft_correlation_find_real(
                pd,
                sig_d.as_ptr(),
                pat_d.as_ptr(),
                grid_d.as_mut_ptr(),
                &mut md,
            );
            assert_eq!((rf, rd), (SO3FFT_OK, SO3FFT_OK), "{:?}", last_error());
            assert_eq!(mf.grid_index, md.grid_index);
            for (a, b) in [
                (mf.alpha, md.alpha),
                (mf.beta, md.beta),
                (mf.gamma, md.gamma),
            ] {
                assert!((a - b).abs() < 1e-8, "{mf:?} {md:?}");
            }
            assert!(
                (mf.sigma - md.sigma).abs() <= 1e-6 * md.sigma,
                "{mf:?} {md:?}"
            );
            assert!(md.sigma > 0.0 && md.peak_ratio >= 1.0, "{md:?}");
            let tr = md.covariance[0] + md.covariance[4] + md.covariance[8];
            assert!((tr.sqrt() - md.sigma).abs() <= 1e-12 * md.sigma);
            // The degree weights ending at 1/7 weight degree 6 at least a tenth of 1.
            assert!((md.separation - 2.0 * std::f64::consts::PI / 7.0).abs() < 1e-15);
            so3fftf_destroy_correlation(pf);
            so3fft_destroy_correlation(pd);

            let bad = [1.0, -0.5, 1.0];
            let pf = so3fftf_plan_correlation_weighted(lc, 0, 2, 0, 1, bad.as_ptr());
            let f = last_error();
            let pd = so3fft_plan_correlation_weighted(lc, 0, 2, 0, 1, bad.as_ptr());
            assert!(pf.is_null() && pd.is_null());
            assert_eq!(f, last_error());
            assert_eq!(f.0, SO3FFT_EINVAL);
            assert!(f.1.contains("w_1 = -0.5") && f.1.contains(">= 0"), "{f:?}");
            let both =
                so3fft_plan_correlation_weighted(lc, 0, 2, SO3FFT_NOISE_WEIGHTS, 1, w.as_ptr());
            assert!(both.is_null());
            assert!(
                last_error().1.contains("SO3FFT_NOISE_WEIGHTS"),
                "{:?}",
                last_error()
            );
            let null = so3fftf_plan_correlation_weighted(lc, 0, -1, 0, 1, std::ptr::null());
            assert!(null.is_null());
            assert_eq!(last_error().0, SO3FFT_ENULL);
            let auto = so3fft_plan_correlation(lc, 0, -1, SO3FFT_NOISE_WEIGHTS, 1);
            assert!(!auto.is_null(), "{:?}", last_error());
            assert_eq!(so3fft_correlation_degree_limit(auto), lc - 1);
            so3fft_destroy_correlation(auto);
            assert_eq!(
                so3fft_correlation_degree_limit(std::ptr::null_mut()),
                SO3FFT_ENULL
            );
        }
    }
}
