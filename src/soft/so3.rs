//! The SO(3) transforms of `soft_fftw.h`, `soft_fftw_pc.h`, `soft_fftw_nt.h` and
//! `wrap_fftw.h`: eight entry points on two shared bodies.

use super::cache::plan_for;
use super::real::{
    expand_real, note_real_path, real_samples, real_symmetric, release_real_buf, try_zeroed,
};
use super::{guarded, FftwComplex, SoftResult};
use crate::ffi::checks::{self, input_output, Array};
use crate::ffi::CallError;
use crate::{num_coeffs, num_samples, Complex64};
use std::ffi::{c_double, c_int, c_void};

/// Ratios `weights[k] / w_B(k)` when the caller's weights differ from the standard ones by
/// more than rounding, else `None` (the engine's own weights are then used as they are).
fn weight_ratios(b: usize, user: &[f64]) -> Option<Vec<f64>> {
    let std_w = crate::weights(b);
    let same = user
        .iter()
        .zip(&std_w)
        .all(|(u, w)| (u - w).abs() <= 1e-12 * w.abs().max(1e-300));
    if same {
        None
    } else {
        Some(user.iter().zip(&std_w).map(|(u, w)| u / w).collect())
    }
}

/// Forward transform of the `(2B)^3` samples at `data` into the `(4B^3-B)/3` coefficients
/// at `coeffs`, with SOFT's weights semantics and real flag.
///
/// # Safety
/// `data` and `coeffs` are NULL or point to `(2B)^3` and `(4B^3-B)/3` values; `weights` is
/// NULL or points to `2B` doubles; `coeffs` is not used by anyone else during the call.
unsafe fn forward_core(
    bw: c_int,
    data: *const FftwComplex,
    coeffs: *mut FftwComplex,
    weights: *const c_double,
    flag: c_int,
) -> SoftResult<()> {
    let b = checks::bandwidth(bw)?;
    let (ns, nc) = (num_samples(b), num_coeffs(b));
    input_output(
        &Array::new(data, ns, "data"),
        &Array::new(coeffs.cast_const(), nc, "coeffs"),
    )?;
    let ratios = if weights.is_null() {
        None
    } else {
        Array::new(weights, 2 * b, "weights").check()?;
        // SAFETY: non-NULL and aligned (checked); 2B doubles by this function's contract.
        weight_ratios(b, unsafe { std::slice::from_raw_parts(weights, 2 * b) })
    };
    let plan = plan_for(b)?;
    // SAFETY: checked non-NULL, aligned and disjoint; the sizes by this function's contract;
    // fftw_complex is layout-identical to Complex64 (#[repr(C)] { re, im }).
    let (samples, out) = unsafe {
        (
            std::slice::from_raw_parts(data.cast::<Complex64>(), ns),
            std::slice::from_raw_parts_mut(coeffs.cast::<Complex64>(), nc),
        )
    };
    // Real data: flag = 1 (the transform of the real parts), or flag = 0 on samples whose
    // imaginary parts are all exactly 0 (and real parts finite), where the real-signal path
    // (half the work) computes the same transform. It reads the real parts and writes
    // exactly symmetric coefficients.
    let real = flag != 0 || real_samples(&plan, samples);
    if flag == 0 && real {
        note_real_path(false);
    }
    let run = |samples: &[Complex64], out: &mut [Complex64]| {
        if real {
            plan.engine().forward_real_parts(samples, out).map(|_| ())
        } else {
            plan.forward(samples, out).map(|_| ())
        }
    };
    match ratios {
        None => run(samples, out),
        Some(r) => {
            // Custom weights: the forward is linear in each beta slice, so scaling slice k
            // by weights[k] / w_B(k) gives exactly SOFT's sum with the caller's weights.
            let mut scaled = try_zeroed(ns)?;
            let slice = 4 * b * b;
            for (k, (dst, src)) in scaled
                .chunks_exact_mut(slice)
                .zip(samples.chunks_exact(slice))
                .enumerate()
            {
                for (d, s) in dst.iter_mut().zip(src) {
                    *d = *s * r[k];
                }
            }
            run(&scaled, out)
        }
    }
    .map_err(CallError::from)
}

/// Inverse transform of the coefficients at `coeffs` into the samples at `data`.
///
/// # Safety
/// `coeffs` and `data` are NULL or point to `(4B^3-B)/3` and `(2B)^3` values; `data` is
/// not used by anyone else during the call.
unsafe fn inverse_core(
    bw: c_int,
    coeffs: *const FftwComplex,
    data: *mut FftwComplex,
    flag: c_int,
) -> SoftResult<()> {
    let b = checks::bandwidth(bw)?;
    let (ns, nc) = (num_samples(b), num_coeffs(b));
    input_output(
        &Array::new(coeffs, nc, "coeffs"),
        &Array::new(data.cast_const(), ns, "data"),
    )?;
    let plan = plan_for(b)?;
    // SAFETY: checked non-NULL, aligned and disjoint; the sizes by this function's contract.
    let (input, out) = unsafe {
        (
            std::slice::from_raw_parts(coeffs.cast::<Complex64>(), nc),
            std::slice::from_raw_parts_mut(data.cast::<Complex64>(), ns),
        )
    };
    if flag == 0 {
        // Coefficients with the exact real symmetry (a real signal's, e.g. a correlation's
        // of real functions) have a real inverse: the real-signal path (half the work)
        // writes it as (x, 0). Anything else, even one pair off by an ulp, stays complex.
        if real_symmetric(&plan, b, input) {
            note_real_path(true);
            return plan
                .engine()
                .inverse_real_to_complex(input, out)
                .map(|_| ())
                .map_err(CallError::from);
        }
        return plan
            .inverse(input, out)
            .map(|_| ())
            .map_err(CallError::from);
    }
    let expanded = expand_real(b, input)?;
    let res = plan.engine().inverse_real_to_complex(&expanded, out);
    release_real_buf(b, expanded);
    res.map(|_| ()).map_err(CallError::from)
}

// soft_fftw.h

/// Forward SO(3) transform (`soft_fftw.h`): samples `data` (`(2B)^3`, the layout of docs/conventions.md) to
/// coefficients `coeffs` (`(4B^3-B)/3`, `so3CoefLoc` order).
///
/// `weights` (2B doubles, from `makeweights2` or the first half of `makeweights`) are the
/// quadrature weights: when they equal `w_B(k)` to rounding the engine's identical weights
/// are used; other values are honoured exactly (each beta slice is scaled by
/// `weights[k]/w_B(k)` in a private copy); NULL means the standard weights.
/// `flag != 0`: real data; the output is the transform of the real part of `data` and is
/// exactly symmetric, `fhat(l,-M,-M') = (-1)^(M-M') conj(fhat(l,M,M'))`, `fhat(l,0,0)` real.
/// `flag = 0` on samples whose imaginary parts are all exactly 0 (and real parts finite)
/// takes the same real path: the complex transform's result within rounding.
/// The workspaces and the plan `p1` are accepted and not used; `data` is not modified.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_Forward_SO3_Naive_fftw"]
pub unsafe extern "C" fn Forward_SO3_Naive_fftw(
    bw: c_int,
    data: *mut FftwComplex,
    coeffs: *mut FftwComplex,
    _workspace_cx: *mut FftwComplex,
    _workspace_cx2: *mut FftwComplex,
    _workspace_re: *mut c_double,
    weights: *mut c_double,
    _p1: *mut c_void,
    flag: c_int,
) {
    guarded("Forward_SO3_Naive_fftw", (), || {
        // SAFETY: the arrays have SOFT's sizes (the module's safety contract).
        unsafe { forward_core(bw, data, coeffs, weights, flag) }
    })
}

/// Inverse SO(3) transform (`soft_fftw.h`): coefficients `coeffs` to samples `data`.
///
/// `flag != 0`: real data; only the blocks `(0,0)`, `(0,M')` for `M' > 0`, `(M,M')` for
/// `M > 0, M' != -M` and `(-m,m)` for `m > 0` of `coeffs` are read (the others are rebuilt by
/// the real symmetry in a private array; they may hold anything) and the imaginary parts of
/// `data` are exactly 0. `flag = 0` on coefficients with the exact real symmetry (every
/// pair, `fhat(l,0,0)` real, all finite) takes the real path too and writes `(x, 0)`: the
/// complex transform's result within rounding. The workspaces and the plan `p1` are
/// accepted and not used; `coeffs` is not modified.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_Inverse_SO3_Naive_fftw"]
pub unsafe extern "C" fn Inverse_SO3_Naive_fftw(
    bw: c_int,
    coeffs: *mut FftwComplex,
    data: *mut FftwComplex,
    _workspace_cx: *mut FftwComplex,
    _workspace_cx2: *mut FftwComplex,
    _workspace_re: *mut c_double,
    _p1: *mut c_void,
    flag: c_int,
) {
    guarded("Inverse_SO3_Naive_fftw", (), || {
        // SAFETY: the arrays have SOFT's sizes (the module's safety contract).
        unsafe { inverse_core(bw, coeffs, data, flag) }
    })
}

// soft_fftw_pc.h

/// Forward transform with a precomputed Wigner table (`soft_fftw_pc.h`): same as
/// [`Forward_SO3_Naive_fftw`]; the table `wigners` (from [`genWigAll`](super::genWigAll)) is not read.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_Forward_SO3_Naive_fftw_pc"]
pub unsafe extern "C" fn Forward_SO3_Naive_fftw_pc(
    bw: c_int,
    data: *mut FftwComplex,
    coeffs: *mut FftwComplex,
    _workspace_cx: *mut FftwComplex,
    _workspace_cx2: *mut FftwComplex,
    _workspace_re: *mut c_double,
    weights: *mut c_double,
    _p1: *mut c_void,
    _wigners: *mut c_double,
    flag: c_int,
) {
    guarded("Forward_SO3_Naive_fftw_pc", (), || {
        // SAFETY: the arrays have SOFT's sizes (the module's safety contract).
        unsafe { forward_core(bw, data, coeffs, weights, flag) }
    })
}

/// Inverse transform with a precomputed Wigner table (`soft_fftw_pc.h`): same as
/// [`Inverse_SO3_Naive_fftw`]; the table `wignersTrans` (from [`genWigAllTrans`](super::genWigAllTrans)) is not read.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_Inverse_SO3_Naive_fftw_pc"]
pub unsafe extern "C" fn Inverse_SO3_Naive_fftw_pc(
    bw: c_int,
    coeffs: *mut FftwComplex,
    data: *mut FftwComplex,
    _workspace_cx: *mut FftwComplex,
    _workspace_cx2: *mut FftwComplex,
    _workspace_re: *mut c_double,
    _p1: *mut c_void,
    _wigners_trans: *mut c_double,
    flag: c_int,
) {
    guarded("Inverse_SO3_Naive_fftw_pc", (), || {
        // SAFETY: the arrays have SOFT's sizes (the module's safety contract).
        unsafe { inverse_core(bw, coeffs, data, flag) }
    })
}

// soft_fftw_nt.h

/// Forward transform, "nt" variant (`soft_fftw_nt.h`; one complex workspace). Same as
/// [`Forward_SO3_Naive_fftw`]; unlike SOFT's, it does not overwrite `data`.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_Forward_SO3_Naive_fftw_nt"]
pub unsafe extern "C" fn Forward_SO3_Naive_fftw_nt(
    bw: c_int,
    data: *mut FftwComplex,
    coeffs: *mut FftwComplex,
    _workspace_cx: *mut FftwComplex,
    _workspace_re: *mut c_double,
    weights: *mut c_double,
    _p1: *mut c_void,
    flag: c_int,
) {
    guarded("Forward_SO3_Naive_fftw_nt", (), || {
        // SAFETY: the arrays have SOFT's sizes (the module's safety contract).
        unsafe { forward_core(bw, data, coeffs, weights, flag) }
    })
}

/// Inverse transform, "nt" variant (`soft_fftw_nt.h`; one complex workspace). Same as
/// [`Inverse_SO3_Naive_fftw`]; `coeffs` is not modified.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_Inverse_SO3_Naive_fftw_nt"]
pub unsafe extern "C" fn Inverse_SO3_Naive_fftw_nt(
    bw: c_int,
    coeffs: *mut FftwComplex,
    data: *mut FftwComplex,
    _workspace_cx: *mut FftwComplex,
    _workspace_re: *mut c_double,
    _p1: *mut c_void,
    flag: c_int,
) {
    guarded("Inverse_SO3_Naive_fftw_nt", (), || {
        // SAFETY: the arrays have SOFT's sizes (the module's safety contract).
        unsafe { inverse_core(bw, coeffs, data, flag) }
    })
}

// wrap_fftw.h

/// Forward transform that manages its own workspaces and weights (`wrap_fftw.h`).
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_Forward_SO3_Naive_fftw_W"]
pub unsafe extern "C" fn Forward_SO3_Naive_fftw_W(
    bw: c_int,
    signal: *mut FftwComplex,
    coeffs: *mut FftwComplex,
    flag: c_int,
) {
    guarded("Forward_SO3_Naive_fftw_W", (), || {
        // SAFETY: the arrays have SOFT's sizes (the module's safety contract).
        unsafe { forward_core(bw, signal, coeffs, std::ptr::null(), flag) }
    })
}

/// Inverse transform that manages its own workspaces (`wrap_fftw.h`).
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_Inverse_SO3_Naive_fftw_W"]
pub unsafe extern "C" fn Inverse_SO3_Naive_fftw_W(
    bw: c_int,
    coeffs: *mut FftwComplex,
    signal: *mut FftwComplex,
    flag: c_int,
) {
    guarded("Inverse_SO3_Naive_fftw_W", (), || {
        // SAFETY: the arrays have SOFT's sizes (the module's safety contract).
        unsafe { inverse_core(bw, coeffs, signal, flag) }
    })
}
