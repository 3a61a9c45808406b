//! `--soft`: the SOFT 2.0 entry points against the native plan doing the same work: the
//! complex transforms for `flag = 0`, the real-signal transforms for `flag = 1`.
//!
//! The SOFT layer caches one plan per bandwidth (all cores, FFTW_MEASURE, real transforms
//! prepared), so the native plan here uses the same settings; the first SOFT call (which
//! builds the cached plan) is not timed. Inputs are random coefficients and their samples; the SOFT workspaces are
//! allocated at the sizes SOFT documents (the layer does not touch them).

use crate::workload::{median, random_coeffs};
use so3fft::{Complex64, Options, Plan, Rigor};
use std::ffi::c_void;
use std::fmt::Write as _;
use std::os::raw::c_int;
use std::time::Instant;

/// One measured SOFT entry point.
pub struct SoftRow {
    pub bandwidth: usize,
    pub call: &'static str,
    pub seconds: f64,
    pub native_seconds: f64,
}

/// Median wall time of `runs` calls of `call`.
fn time_median(runs: usize, mut call: impl FnMut()) -> f64 {
    let seconds: Vec<f64> = (0..runs)
        .map(|_| {
            let start = Instant::now();
            call();
            start.elapsed().as_secs_f64()
        })
        .collect();
    median(&seconds)
}

/// SOFT's complex type, `double[2]`.
type SoftComplex = [f64; 2];

// The SOFT entry points, called as a SOFT client calls them through libso3fft_soft. They are
// not part of the Rust API: the library exports them under private `so3fft_soft_` names,
// which the SOFT library's one-line wrappers forward to.
extern "C" {
    #[link_name = "so3fft_soft_makeweights2"]
    fn makeweights2(bw: c_int, w: *mut f64);
    #[allow(clippy::too_many_arguments)]
    #[link_name = "so3fft_soft_Forward_SO3_Naive_fftw"]
    fn Forward_SO3_Naive_fftw(
        bw: c_int,
        data: *mut SoftComplex,
        coeffs: *mut SoftComplex,
        workspace_cx: *mut SoftComplex,
        workspace_cx2: *mut SoftComplex,
        workspace_re: *mut f64,
        weights: *mut f64,
        p1: *mut c_void,
        flag: c_int,
    );
    #[link_name = "so3fft_soft_Inverse_SO3_Naive_fftw"]
    fn Inverse_SO3_Naive_fftw(
        bw: c_int,
        coeffs: *mut SoftComplex,
        data: *mut SoftComplex,
        workspace_cx: *mut SoftComplex,
        workspace_cx2: *mut SoftComplex,
        workspace_re: *mut f64,
        p1: *mut c_void,
        flag: c_int,
    );
}

/// `v` as a SOFT complex array (`Complex64` has the same layout).
fn as_soft(v: &mut [Complex64]) -> *mut SoftComplex {
    v.as_mut_ptr() as *mut SoftComplex
}

/// Times forward and inverse through the SOFT layer (flags 0 and 1) and the native plan.
pub fn compare(b: usize, runs: usize) -> Result<Vec<SoftRow>, so3fft::Error> {
    let native = Plan::new(
        b,
        &Options::default()
            .with_rigor(Rigor::Measure)
            .with_real(true),
    )?;
    let n = native.num_samples();
    let mut coeffs = random_coeffs(native.num_coeffs(), 7 + b as u64);
    let mut samples = vec![Complex64::new(0.0, 0.0); n];
    let mut coeffs_out = vec![Complex64::new(0.0, 0.0); native.num_coeffs()];
    native.inverse(&coeffs, &mut samples)?;
    let native_inverse = time_median(runs, || {
        native.inverse(&coeffs, &mut samples).unwrap();
    });
    let native_forward = time_median(runs, || {
        native.forward(&samples, &mut coeffs_out).unwrap();
    });
    // Real-signal path on real data (real parts of the samples; real-symmetric coefficients
    // are what flag = 1 clients pass, and the timing does not depend on the values).
    let mut real = vec![0.0f64; n];
    let native_inverse_real = time_median(runs, || {
        native.inverse_real(&coeffs, &mut real).unwrap();
    });
    let native_forward_real = time_median(runs, || {
        native.forward_real(&real, &mut coeffs_out).unwrap();
    });

    let bandwidth = b as c_int;
    let mut workspace1 = vec![Complex64::new(0.0, 0.0); n];
    let mut workspace2 = vec![Complex64::new(0.0, 0.0); n];
    let mut workspace_real = vec![0.0f64; 24 * b + 2 * b * b];
    let mut weights = vec![0.0f64; 2 * b];
    let mut samples_out = vec![Complex64::new(0.0, 0.0); n];
    // SAFETY: every array has the size SOFT documents; the plan argument may be NULL
    // for this layer (it never executes client plans).
    unsafe {
        makeweights2(bandwidth, weights.as_mut_ptr());
        let mut fwd = |flag: c_int| {
            Forward_SO3_Naive_fftw(
                bandwidth,
                as_soft(&mut samples),
                as_soft(&mut coeffs_out),
                as_soft(&mut workspace1),
                as_soft(&mut workspace2),
                workspace_real.as_mut_ptr(),
                weights.as_mut_ptr(),
                std::ptr::null_mut(),
                flag,
            )
        };
        fwd(0); // builds the cached plan
        let forward_complex = time_median(runs, || fwd(0));
        let forward_real = time_median(runs, || fwd(1));
        let mut inv = |flag: c_int| {
            Inverse_SO3_Naive_fftw(
                bandwidth,
                as_soft(&mut coeffs),
                as_soft(&mut samples_out),
                as_soft(&mut workspace1),
                as_soft(&mut workspace2),
                workspace_real.as_mut_ptr(),
                std::ptr::null_mut(),
                flag,
            )
        };
        let inverse_complex = time_median(runs, || inv(0));
        let inverse_real = time_median(runs, || inv(1));
        let row = |call, seconds, native_seconds| SoftRow {
            bandwidth: b,
            call,
            seconds,
            native_seconds,
        };
        Ok(vec![
            row(
                "Forward_SO3_Naive_fftw flag 0",
                forward_complex,
                native_forward,
            ),
            row(
                "Forward_SO3_Naive_fftw flag 1",
                forward_real,
                native_forward_real,
            ),
            row(
                "Inverse_SO3_Naive_fftw flag 0",
                inverse_complex,
                native_inverse,
            ),
            row(
                "Inverse_SO3_Naive_fftw flag 1",
                inverse_real,
                native_inverse_real,
            ),
        ])
    }
}

/// Printable table of the comparison.
pub fn table(rows: &[SoftRow]) -> String {
    let mut s = String::from(
        "\nSOFT entry points vs the native plan (all cores, FFTW_MEASURE, medians; flag 1 against the real-signal path):\n",
    );
    for r in rows {
        let _ = writeln!(
            s,
            "  B = {:4}  {:32} {:10.4e} s   native {:10.4e} s   ratio {:.2}",
            r.bandwidth,
            r.call,
            r.seconds,
            r.native_seconds,
            r.seconds / r.native_seconds
        );
    }
    s
}
