//! Rotation of functions on the sphere (`wrap_fftw.h`'s `s2RotateFFTW`,
//! `rotate_so3_fftw.h`'s `rotateFctFFTW`, `rotateFctFFTWS`, `rotateFctFFTWS_mem`,
//! `rotate_so3_utils.h`'s `rotateCoefAll`): `sigOut = Lambda(g) sigIn`,
//! `(Lambda(g) f)(x) = f(g^-1 x)`, `g = Rz(alpha) Ry(beta) Rz(gamma)`.
//!
//! Every bandwidth works (SOFT's own versions overflow their buffers from bw = 13 to 25,
//! docs/conventions-s2.md); the caller's scratch and tables are never read or written.

use super::s2::s2_plan_for;
use super::{guarded, SoftResult};
use crate::ffi::checks::{self, input_output, Array};
use crate::ffi::CallError;
use crate::matching::{rotate_s2_coeffs_to, Rotation};
use crate::Complex64;
use std::ffi::{c_double, c_int};

/// Checks `n` doubles at each input and output (inputs disjoint from the outputs).
fn check_split(
    inputs: &[(*mut c_double, &'static str)],
    outputs: &[(*mut c_double, &'static str)],
    n_in: usize,
    n_out: usize,
) -> SoftResult<()> {
    for &(o, what_o) in outputs {
        let out = Array::new(o.cast_const(), n_out, what_o);
        out.check()?;
        for &(i, what_i) in inputs {
            input_output(&Array::new(i.cast_const(), n_in, what_i), &out)?;
        }
    }
    for (k, &(a, wa)) in outputs.iter().enumerate() {
        for &(b, wb) in &outputs[k + 1..] {
            input_output(
                &Array::new(a.cast_const(), n_out, wa),
                &Array::new(b.cast_const(), n_out, wb),
            )?;
        }
    }
    Ok(())
}

/// The rotation core: complex samples of bandwidth `b_in` to samples of `b_out`, degrees up
/// to `min(deg_out, b_in - 1)`.
fn rotate_samples(
    (b_in, b_out, deg_out): (usize, usize, usize),
    input: &[Complex64],
    g: &Rotation,
) -> SoftResult<Vec<Complex64>> {
    let plan_in = s2_plan_for(b_in)?;
    let mut coeffs = vec![Complex64::default(); b_in * b_in];
    plan_in.plan().forward(input, &mut coeffs)?;
    let rotated = rotate_s2_coeffs_to(b_in, &coeffs, g, (b_out, deg_out))?;
    let plan_out = s2_plan_for(b_out)?;
    let mut out = vec![Complex64::default(); 4 * b_out * b_out];
    plan_out.plan().inverse(&rotated, &mut out)?;
    Ok(out)
}

/// `deg_out` as a degree below `b_out`.
fn degree(deg_out: c_int, b_out: usize) -> SoftResult<usize> {
    usize::try_from(deg_out)
        .ok()
        .filter(|&d| d < b_out)
        .ok_or_else(|| CallError::invalid(format!("degOut {deg_out} must be in 0..{b_out}")))
}

/// Split arrays joined.
///
/// # Safety
/// `re`, `im` hold `n` doubles each (checked non-NULL and aligned by the caller).
unsafe fn joined(re: *const c_double, im: *const c_double, n: usize) -> Vec<Complex64> {
    // SAFETY: the caller's contract.
    let (re, im) = unsafe {
        (
            std::slice::from_raw_parts(re, n),
            std::slice::from_raw_parts(im, n),
        )
    };
    re.iter()
        .zip(im)
        .map(|(&r, &i)| Complex64::new(r, i))
        .collect()
}

/// Writes `values` split into `re`, `im`.
///
/// # Safety
/// `re`, `im` hold `values.len()` doubles each, used by no one else during the call.
unsafe fn split(values: &[Complex64], re: *mut c_double, im: *mut c_double) {
    for (k, v) in values.iter().enumerate() {
        // SAFETY: k < values.len() (the caller's contract).
        unsafe {
            *re.add(k) = v.re;
            *im.add(k) = v.im;
        }
    }
}

/// Rotates the bandwidth-`bw` function sampled in `sigIn` (interleaved complex, `2 (2bw)^2`
/// doubles, or real, `(2bw)^2`, with `isReal` nonzero; real results keep the real part)
/// into `sigOut`.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_s2RotateFFTW"]
pub unsafe extern "C" fn s2RotateFFTW(
    bw: c_int,
    sigIn: *mut c_double,
    sigOut: *mut c_double,
    alpha: c_double,
    beta: c_double,
    gamma: c_double,
    isReal: c_int,
) {
    guarded("s2RotateFFTW", (), || {
        let b = checks::bandwidth(bw)?;
        let n = 4 * b * b;
        let len = if isReal != 0 { n } else { 2 * n };
        input_output(
            &Array::new(sigIn.cast_const(), len, "sigIn"),
            &Array::new(sigOut.cast_const(), len, "sigOut"),
        )?;
        let input: Vec<Complex64> = if isReal != 0 {
            // SAFETY: checked non-NULL and aligned; (2bw)^2 doubles (SOFT's contract).
            let x = unsafe { std::slice::from_raw_parts(sigIn.cast_const(), n) };
            x.iter().map(|&v| Complex64::new(v, 0.0)).collect()
        } else {
            // SAFETY: as above, 2 (2bw)^2 doubles read as (2bw)^2 complex values.
            unsafe { std::slice::from_raw_parts(sigIn.cast_const().cast::<Complex64>(), n) }
                .to_vec()
        };
        let out = rotate_samples((b, b, b - 1), &input, &Rotation::new(alpha, beta, gamma))?;
        for (k, v) in out.iter().enumerate() {
            // SAFETY: checked non-NULL and aligned, disjoint from the input; `len` doubles.
            unsafe {
                if isReal != 0 {
                    *sigOut.add(k) = v.re;
                } else {
                    *sigOut.add(2 * k) = v.re;
                    *sigOut.add(2 * k + 1) = v.im;
                }
            }
        }
        Ok(())
    })
}

/// Rotates the function of bandwidth `bwIn` in the split arrays `sigInR/I` (`(2bwIn)^2`
/// each): degrees up to `min(degOut, bwIn - 1)`, the others zero, synthesised at `bwOut`
/// into `sigOutR/I` (`(2bwOut)^2` each). `degOut < bwOut`. `scratch` and the tables are
/// not used.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_rotateFctFFTW"]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn rotateFctFFTW(
    bwIn: c_int,
    bwOut: c_int,
    degOut: c_int,
    sigInR: *mut c_double,
    sigInI: *mut c_double,
    sigOutR: *mut c_double,
    sigOutI: *mut c_double,
    alpha: c_double,
    beta: c_double,
    gamma: c_double,
    _scratch: *mut c_double,
    _spharmonic_pml_table: *mut *mut c_double,
    _transpose_spharmonic_pml_table: *mut *mut c_double,
) {
    guarded("rotateFctFFTW", (), || {
        // SAFETY: SOFT's contract on the arrays (sizes from the bandwidths).
        unsafe {
            rotate_split(
                bwIn,
                bwOut,
                degOut,
                [sigInR, sigInI, sigOutR, sigOutI],
                (alpha, beta, gamma),
            )
        }
    })
}

/// [`rotateFctFFTW`] without scratch and tables.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_rotateFctFFTWS"]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn rotateFctFFTWS(
    bwIn: c_int,
    bwOut: c_int,
    degOut: c_int,
    sigInR: *mut c_double,
    sigInI: *mut c_double,
    sigOutR: *mut c_double,
    sigOutI: *mut c_double,
    alpha: c_double,
    beta: c_double,
    gamma: c_double,
) {
    guarded("rotateFctFFTWS", (), || {
        // SAFETY: as in `rotateFctFFTW`.
        unsafe {
            rotate_split(
                bwIn,
                bwOut,
                degOut,
                [sigInR, sigInI, sigOutR, sigOutI],
                (alpha, beta, gamma),
            )
        }
    })
}

/// [`rotateFctFFTW`] in place at bandwidth `bw` (`sigR/I`, `(2bw)^2` each).
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_rotateFctFFTWS_mem"]
pub unsafe extern "C" fn rotateFctFFTWS_mem(
    bw: c_int,
    degOut: c_int,
    sigR: *mut c_double,
    sigI: *mut c_double,
    alpha: c_double,
    beta: c_double,
    gamma: c_double,
) {
    guarded("rotateFctFFTWS_mem", (), || {
        let b = checks::bandwidth(bw)?;
        let d = degree(degOut, b)?;
        let n = 4 * b * b;
        check_split(&[], &[(sigR, "sigR"), (sigI, "sigI")], n, n)?;
        // SAFETY: checked; n doubles each (SOFT's contract).
        let input = unsafe { joined(sigR, sigI, n) };
        let out = rotate_samples((b, b, d), &input, &Rotation::new(alpha, beta, gamma))?;
        // SAFETY: as above.
        unsafe { split(&out, sigR, sigI) };
        Ok(())
    })
}

/// The body of the split-array rotations.
///
/// # Safety
/// The arrays hold SOFT's sizes for the bandwidths.
unsafe fn rotate_split(
    bw_in: c_int,
    bw_out: c_int,
    deg_out: c_int,
    [in_r, in_i, out_r, out_i]: [*mut c_double; 4],
    (alpha, beta, gamma): (f64, f64, f64),
) -> SoftResult<()> {
    let b_in = checks::bandwidth(bw_in)?;
    let b_out = checks::bandwidth(bw_out)?;
    let d = degree(deg_out, b_out)?;
    let (n_in, n_out) = (4 * b_in * b_in, 4 * b_out * b_out);
    check_split(
        &[(in_r, "sigInR"), (in_i, "sigInI")],
        &[(out_r, "sigOutR"), (out_i, "sigOutI")],
        n_in,
        n_out,
    )?;
    // SAFETY: checked; the sizes are the caller's contract.
    let input = unsafe { joined(in_r, in_i, n_in) };
    let out = rotate_samples((b_in, b_out, d), &input, &Rotation::new(alpha, beta, gamma))?;
    // SAFETY: as above.
    unsafe { split(&out, out_r, out_i) };
    Ok(())
}

/// Rotates S^2 coefficients (split, `seanindex` order): `cfR/I` of bandwidth `bwIn` into
/// `cfrR/I` of bandwidth `bwOut` (degrees up to `min(degOut, bwIn - 1)`, the others zero).
/// `scratch` is not used.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_rotateCoefAll"]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn rotateCoefAll(
    bwIn: c_int,
    bwOut: c_int,
    degOut: c_int,
    alpha: c_double,
    beta: c_double,
    gamma: c_double,
    cfR: *mut c_double,
    cfI: *mut c_double,
    cfrR: *mut c_double,
    cfrI: *mut c_double,
    _scratch: *mut c_double,
) {
    guarded("rotateCoefAll", (), || {
        let b_in = checks::bandwidth(bwIn)?;
        let b_out = checks::bandwidth(bwOut)?;
        let d = degree(degOut, b_out)?;
        let (n_in, n_out) = (b_in * b_in, b_out * b_out);
        check_split(
            &[(cfR, "cfR"), (cfI, "cfI")],
            &[(cfrR, "cfrR"), (cfrI, "cfrI")],
            n_in,
            n_out,
        )?;
        // SAFETY: checked; the sizes are the caller's contract.
        let input = unsafe { joined(cfR, cfI, n_in) };
        let out =
            rotate_s2_coeffs_to(b_in, &input, &Rotation::new(alpha, beta, gamma), (b_out, d))?;
        // SAFETY: as above.
        unsafe { split(&out, cfrR, cfrI) };
        Ok(())
    })
}
