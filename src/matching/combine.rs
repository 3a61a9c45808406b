//! SO(3) coefficients of a correlation from the S^2 coefficients of signal and pattern.

use crate::error::{Error, Result};
use crate::grid::{block_start, num_coeffs};
use crate::s2::order_start;
use crate::workers::SendPtr;
use num_complex::Complex64;
use rayon::prelude::*;
use std::f64::consts::PI;

/// The SO(3) coefficients (bandwidth `b_out`, `so3CoefLoc` order) of the correlation
/// `C(g) = int f(x) conj(h(g^-1 x)) dx` of a signal `f` and a pattern `h` given by their S^2
/// coefficients (bandwidth `b_in`, `seanindex` order):
/// `Chat(l, m1, m2) = 2 pi sqrt(2/(2l+1)) (-1)^(m1+m2) fhat(l,-m1) conj(hhat(l,-m2))` for
/// `l <= deg_lim`, zero for every other coefficient (SOFT's `so3CombineCoef_fftw`).
/// `deg_lim < min(b_in, b_out)`.
pub fn combine(
    (sig, pat): (&[Complex64], &[Complex64]),
    b_in: usize,
    deg_lim: usize,
    b_out: usize,
    out: &mut [Complex64],
) -> Result<()> {
    check(sig.len(), pat.len(), (b_in, deg_lim, b_out), out.len())?;
    out.fill(Complex64::default());
    add_combined(
        (sig, pat),
        b_in,
        (0, deg_lim),
        b_out,
        (1.0, out),
        (false, Combine::Add),
    );
    Ok(())
}

/// An error unless the lengths fit the bandwidths and `deg_lim < min(b_in, b_out)`.
pub(super) fn check(
    sig: usize,
    pat: usize,
    (b_in, deg_lim, b_out): (usize, usize, usize),
    out: usize,
) -> Result<()> {
    if deg_lim >= b_in.min(b_out) {
        return Err(Error::InvalidArgument(format!(
            "degree limit {deg_lim} must be below both bandwidths ({b_in}, {b_out})"
        )));
    }
    for (what, expected, got) in [
        ("signal coefficients", b_in * b_in, sig),
        ("pattern coefficients", b_in * b_in, pat),
        ("SO(3) coefficients", num_coeffs(b_out), out),
    ] {
        if expected != got {
            return Err(Error::LengthMismatch {
                what,
                expected,
                got,
            });
        }
    }
    Ok(())
}

/// How [`add_combined`] treats the output.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Combine {
    /// Add to what `out` holds.
    Add,
    /// Overwrite it: the degrees `from..=to` of each order pair with the combination, its
    /// degrees below `from` with 0 (one pass over the array instead of zeroing it first
    /// and then adding). Degrees above `to` are not written.
    Assign,
}

/// Adds `scale` times the combination of degrees `from..=to` to `out` (lengths checked by
/// the caller with [`check`]), or writes it (`mode`); with `half`, only the order pairs a
/// real-signal inverse reads (`M' > 0`, or `M' = 0` and `M >= 0`; the others are left as
/// they are). For each order pair the degrees are consecutive in all three arrays, so the
/// inner loop runs over contiguous runs.
pub(super) fn add_combined(
    (sig, pat): (&[Complex64], &[Complex64]),
    b_in: usize,
    (from, to): (usize, usize),
    b_out: usize,
    (scale, out): (f64, &mut [Complex64]),
    (half, mode): (bool, Combine),
) {
    if from > to && mode == Combine::Add {
        return;
    }
    let norms: Vec<f64> = (0..=to)
        .map(|l| scale * 2.0 * PI * (2.0 / (2 * l + 1) as f64).sqrt())
        .collect();
    let top = to as isize;
    let len = out.len();
    let dst = SendPtr(out.as_mut_ptr());
    let row = |m1: isize| {
        // fhat(l, -m1) for l = |m1|.. is consecutive from order_start(-m1).
        let f_row = &sig[order_start(b_in, -m1)..];
        let lowest = if half { 0 } else { -top };
        for m2 in lowest..=top {
            if half && m2 == 0 && m1 < 0 {
                continue;
            }
            let h_row = &pat[order_start(b_in, -m2)..];
            let (a1, a2) = (m1.unsigned_abs(), m2.unsigned_abs());
            let first = a1.max(a2);
            let l0 = first.max(from);
            if first > to {
                continue;
            }
            let sign = if (m1 + m2).rem_euclid(2) == 0 {
                1.0
            } else {
                -1.0
            };
            let base = block_start(b_out, m1, m2) - first;
            assert!(base + to < len);
            let value = |l: usize| f_row[l - a1] * h_row[l - a2].conj() * (sign * norms[l]);
            // Entry `base + l`, `l <= to`, is inside `out` (asserted above) and in the block
            // of `(m1, m2)`, which is this row's alone: no other task touches it.
            let at = |l: usize| dst.get().wrapping_add(base + l);
            if mode == Combine::Assign {
                for l in first..l0.min(to + 1) {
                    // SAFETY: `at` above.
                    unsafe { *at(l) = Complex64::default() };
                }
                for l in l0..=to {
                    // SAFETY: `at` above.
                    unsafe { *at(l) = value(l) };
                }
            } else {
                for l in l0..=to {
                    // SAFETY: `at` above.
                    unsafe { *at(l) += value(l) };
                }
            }
        }
    };
    // On a worker pool (the correlation plan's), the orders are spread over its threads.
    if rayon::current_thread_index().is_some() {
        (-top..=top).into_par_iter().for_each(row);
    } else {
        (-top..=top).for_each(row);
    }
}
