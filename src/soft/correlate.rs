//! The correlation helpers of `so3_correlate_fftw.h` (S^2 coefficient index, combination of
//! S^2 coefficients into SO(3) coefficients).

use super::cache::made_plan;
use super::{guarded, soft_bandwidth, to_int, FftwComplex};
use crate::ffi::checks::{self, input_output, Array};
use crate::ffi::CallError;
use crate::{num_coeffs, Complex64};
use std::ffi::{c_double, c_int};

/// Outputs of [`so3CombineCoef_fftw`] shorter than this are written on the calling thread
/// (waking the workers costs more than the work).
const PARALLEL_MIN_COEFFS: usize = 1 << 14;

/// Index of the spherical-harmonic coefficient of degree `l` and order `m` at bandwidth `b`
/// in SOFT's/S2kit's layout (docs/conventions.md, spherical harmonics): `m >= 0`: `m b - m(m-1)/2 + (l-m)`;
/// `m < 0`: `L(L+3)/2 + 1 + (L+m)(L+m+1)/2 + (l-|m|)` with `L = b-1`.
fn sean_index(m: i64, l: i64, b: i64) -> i64 {
    if m >= 0 {
        m * b - m * (m - 1) / 2 + (l - m)
    } else {
        negative_order_index(m, l, b)
    }
}

/// The `m < 0` branch of [`sean_index`] (for `m <= 0`).
fn negative_order_index(m: i64, l: i64, b: i64) -> i64 {
    let big_l = b - 1;
    big_l * (big_l + 3) / 2 + 1 + (big_l + m) * (big_l + m + 1) / 2 + (l + m)
}

/// Index of the S^2 coefficient `(l, m)` at bandwidth `bw` in S2kit's layout (see docs/conventions.md,
/// spherical harmonics); -1 if `|m| > l` or `l >= bw`.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_seanindex"]
pub extern "C" fn seanindex(m: c_int, l: c_int, bw: c_int) -> c_int {
    guarded("seanindex", -1, || {
        soft_bandwidth(bw.into())?;
        if l < 0 || l >= bw || (m as i64).abs() > l as i64 {
            return Err(CallError::invalid(format!(
                "coefficient (m={m}, l={l}) does not exist at bandwidth {bw}"
            )));
        }
        to_int(sean_index(m as i64, l as i64, bw as i64))
    })
}

/// Both indices of the S^2 coefficients `(l, m)` and `(l, -m)` at bandwidth `bw`:
/// `loc[0] = seanindex(m, l, bw)`, `loc[1] = seanindex(-m, l, bw)`, meant for `m > 0`. As in
/// SOFT, `m = 0` gives `loc[1] = bw^2 + l` (the negative-order formula at `m = 0`, past
/// the end of the array). Nothing is written if `|m| > l`, `l >= bw` or `loc` is NULL.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_seanindex2"]
pub unsafe extern "C" fn seanindex2(m: c_int, l: c_int, bw: c_int, loc: *mut c_int) {
    guarded("seanindex2", (), || {
        soft_bandwidth(bw.into())?;
        if l < 0 || l >= bw || (m as i64).abs() > l as i64 {
            return Err(CallError::invalid(format!(
                "coefficient (m={m}, l={l}) does not exist at bandwidth {bw}"
            )));
        }
        Array::new(loc.cast_const(), 2, "loc").check()?;
        let (m, l, b) = (m as i64, l as i64, bw as i64);
        let first = to_int(sean_index(m, l, b))?;
        // The negative-order formula also for m = 0 (SOFT's value).
        let second = to_int(if m >= 0 {
            negative_order_index(-m, l, b)
        } else {
            sean_index(-m, l, b)
        })?;
        // SAFETY: `loc` is non-NULL and aligned (checked) and holds 2 ints (the module's
        // safety contract).
        unsafe {
            *loc = first;
            *loc.add(1) = second;
        }
        Ok(())
    })
}

/// Combine the S^2 coefficients of a signal (`sigCoefR/I`) and a pattern (`patCoefR/I`),
/// both of bandwidth `bwIn` in `seanindex` order, into the SO(3) coefficients of their
/// correlation at bandwidth `bwOut`:
/// `so3Coef[so3CoefLoc(m1,m2,l,bwOut)] = 2pi sqrt(2/(2l+1)) (-1)^(m1+m2) f(l,-m1) conj(h(l,-m2))`
/// for `l <= degLim`, 0 for all other coefficients (all `(4bwOut^3-bwOut)/3` are written,
/// each once). Requires `degLim < min(bwIn, bwOut)` (a negative `degLim` gives all zeros).
/// Inputs with the exact S^2 real symmetry (those of real signals) compute half of the
/// order pairs and fill the others by the SO(3) symmetry: the same numbers.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_so3CombineCoef_fftw"]
pub unsafe extern "C" fn so3CombineCoef_fftw(
    bwIn: c_int,
    bwOut: c_int,
    degLim: c_int,
    sigCoefR: *mut c_double,
    sigCoefI: *mut c_double,
    patCoefR: *mut c_double,
    patCoefI: *mut c_double,
    so3Coef: *mut FftwComplex,
) {
    guarded("so3CombineCoef_fftw", (), || {
        let bin = checks::bandwidth(bwIn)?;
        let bout = checks::bandwidth(bwOut)?;
        if degLim >= bwIn || degLim >= bwOut {
            return Err(CallError::invalid(format!(
                "degLim {degLim} must be below both bandwidths ({bwIn}, {bwOut})"
            )));
        }
        let nin = bin * bin;
        let nout = num_coeffs(bout);
        let output = Array::new(so3Coef.cast_const(), nout, "so3Coef");
        output.check()?;
        let ins = [sigCoefR, sigCoefI, patCoefR, patCoefI];
        if degLim >= 0 {
            for (p, name) in ins
                .iter()
                .zip(["sigCoefR", "sigCoefI", "patCoefR", "patCoefI"])
            {
                input_output(&Array::new(p.cast_const(), nin, name), &output)?;
            }
        }
        // SAFETY: non-NULL and aligned (checked); (4bwOut^3-bwOut)/3 values, not used by
        // anyone else during the call (the module's safety contract); disjoint from the
        // inputs (checked when they are read).
        let out = unsafe { std::slice::from_raw_parts_mut(so3Coef.cast::<Complex64>(), nout) };
        if degLim < 0 {
            out.fill(Complex64::new(0.0, 0.0));
            return Ok(());
        }
        // SAFETY: each input is non-NULL, aligned and disjoint from the output (checked)
        // and holds bwIn^2 doubles (the module's safety contract); only read.
        let read = |p: *mut c_double| unsafe { std::slice::from_raw_parts(p.cast_const(), nin) };
        let join = |re: &[f64], im: &[f64]| -> Vec<Complex64> {
            re.iter()
                .zip(im)
                .map(|(&r, &i)| Complex64::new(r, i))
                .collect()
        };
        let sig = join(read(sigCoefR), read(sigCoefI));
        let pat = join(read(patCoefR), read(patCoefI));
        // Every entry written once; real-symmetric inputs (real signals) compute half of
        // the order pairs. On the worker threads of the cached plan of bwOut if it exists
        // (a correlation's inverse makes it; a plan is not made here for that).
        let run = |out: &mut [Complex64]| {
            crate::matching::combine((&sig, &pat), bin, degLim as usize, bout, out)
        };
        match made_plan(bout) {
            Some(plan) if nout >= PARALLEL_MIN_COEFFS => plan.install(|| run(out))?,
            _ => run(out)?,
        }
        Ok(())
    })
}
