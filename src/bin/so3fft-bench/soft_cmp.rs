//! `--soft`: the SOFT 2.0 entry points against the native plan doing the same work: the
//! complex transforms for `flag = 0`, the real-signal transforms for `flag = 1`.
//!
//! The SOFT layer caches one plan per bandwidth (all cores, FFTW_MEASURE, real transforms
//! prepared), so the native plan here uses the same settings; the first SOFT call (which
//! builds the cached plan) is not timed. Inputs are random coefficients and their samples; the SOFT workspaces are
//! allocated at the sizes SOFT documents (the layer does not touch them).

use crate::workload::{median, random_coeffs};
use so3fft::soft;
use so3fft::{Complex64, Plan, PlanOptions, Rigor};
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

fn time_median(runs: usize, mut f: impl FnMut()) -> f64 {
    let t: Vec<f64> = (0..runs)
        .map(|_| {
            let t = Instant::now();
            f();
            t.elapsed().as_secs_f64()
        })
        .collect();
    median(&t)
}

type Cx = [f64; 2];

fn as_cx(v: &mut [Complex64]) -> *mut Cx {
    v.as_mut_ptr() as *mut Cx
}

/// Times forward and inverse through the SOFT layer (flags 0 and 1) and the native plan.
pub fn compare(b: usize, runs: usize) -> Result<Vec<SoftRow>, so3fft::Error> {
    let native = Plan::new(
        b,
        &PlanOptions {
            rigor: Rigor::Measure,
            real: true,
            ..Default::default()
        },
    )?;
    let n = native.num_samples();
    let mut coeffs = random_coeffs(native.num_coeffs(), 7 + b as u64);
    let mut samples = vec![Complex64::new(0.0, 0.0); n];
    let mut out_c = vec![Complex64::new(0.0, 0.0); native.num_coeffs()];
    native.inverse(&coeffs, &mut samples)?;
    let t_inv = time_median(runs, || native.inverse(&coeffs, &mut samples).unwrap());
    let t_fwd = time_median(runs, || native.forward(&samples, &mut out_c).unwrap());
    // Real-signal path on real data (real parts of the samples; real-symmetric coefficients
    // are what flag = 1 clients pass, and the timing does not depend on the values).
    let mut real = vec![0.0f64; n];
    let t_inv_real = time_median(runs, || native.inverse_real(&coeffs, &mut real).unwrap());
    let t_fwd_real = time_median(runs, || native.forward_real(&real, &mut out_c).unwrap());

    let bw = b as c_int;
    let mut ws1 = vec![Complex64::new(0.0, 0.0); n];
    let mut ws2 = vec![Complex64::new(0.0, 0.0); n];
    let mut wre = vec![0.0f64; 24 * b + 2 * b * b];
    let mut weights = vec![0.0f64; 2 * b];
    let mut out_s = vec![Complex64::new(0.0, 0.0); n];
    // SAFETY: every array has the size SOFT documents; the plan argument may be NULL
    // for this layer (it never executes client plans).
    unsafe {
        soft::makeweights2(bw, weights.as_mut_ptr());
        let mut fwd = |flag: c_int| {
            soft::Forward_SO3_Naive_fftw(
                bw,
                as_cx(&mut samples),
                as_cx(&mut out_c),
                as_cx(&mut ws1),
                as_cx(&mut ws2),
                wre.as_mut_ptr(),
                weights.as_mut_ptr(),
                std::ptr::null_mut(),
                flag,
            )
        };
        fwd(0); // builds the cached plan
        let f0 = time_median(runs, || fwd(0));
        let f1 = time_median(runs, || fwd(1));
        let mut inv = |flag: c_int| {
            soft::Inverse_SO3_Naive_fftw(
                bw,
                as_cx(&mut coeffs),
                as_cx(&mut out_s),
                as_cx(&mut ws1),
                as_cx(&mut ws2),
                wre.as_mut_ptr(),
                std::ptr::null_mut(),
                flag,
            )
        };
        let i0 = time_median(runs, || inv(0));
        let i1 = time_median(runs, || inv(1));
        let row = |call, seconds, native_seconds| SoftRow {
            bandwidth: b,
            call,
            seconds,
            native_seconds,
        };
        Ok(vec![
            row("Forward_SO3_Naive_fftw flag 0", f0, t_fwd),
            row("Forward_SO3_Naive_fftw flag 1", f1, t_fwd_real),
            row("Inverse_SO3_Naive_fftw flag 0", i0, t_inv),
            row("Inverse_SO3_Naive_fftw flag 1", i1, t_inv_real),
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
