//! One beta's column of the recurrence, `dt^l` for every degree, in exactly the arithmetic
//! of the DWT kernels: the reference the kernels are tested against (bit for bit) and the
//! evaluation behind the public d functions.

use super::recurrence::{RecCoeffs, RecTables};
use super::starts::{big, BaseStart, BetaTables, SKIP_BITS_RANGE, TINY};
use crate::simd::Isa;

/// `dt^l_{m,mp}` of the base pair `(m, mp)` at point `k` of `betas`, for `l = m .. lend`.
///
/// The recurrence runs on the kernels' scaled values with the kernels' operations: fused
/// multiply-adds for every vector instruction set, separate multiplications and additions
/// for [`Isa::Scalar`]; a lane that starts below the skip threshold is zero until it is
/// rescaled to scale index 0. The threshold is the lowest one (`2^-560`): smaller values
/// are returned as 0.
pub(crate) fn column(
    isa: Isa,
    betas: &BetaTables,
    tables: &RecTables,
    k: usize,
    (m, mp): (usize, usize),
    lend: usize,
) -> Vec<f64> {
    let n = lend - m;
    let mut coeffs = RecCoeffs::new(n);
    tables.coeffs(m, mp, &mut coeffs);
    column_with(
        isa,
        betas,
        k,
        (m, mp, super::starts::start_norm(m, mp)),
        &coeffs,
    )
}

/// [`column`] with the recurrence coefficients of `(m, mp)` and the norm of its starting
/// value given (`RecTables::coeffs`, `start_norm`), for callers that evaluate many columns.
pub(crate) fn column_with(
    isa: Isa,
    betas: &BetaTables,
    k: usize,
    (m, mp, norm): (usize, usize, crate::numeric::Ext),
    coeffs: &RecCoeffs,
) -> Vec<f64> {
    let n = coeffs.len();
    let bits = *SKIP_BITS_RANGE.end();
    let base = BaseStart::new(m, mp, norm, bits);
    let (start, mut scale_index) = betas.start(k, &base, 1.0);
    // The recurrence multiplier `A x + C` as `(A + C) - A tau` below pi/2 and as
    // `A tau + (C - A)` above (see `BetaTables`).
    let (tau, slope, offset) = if betas.upper(k) {
        (betas.tau_hi[k], &coeffs.a, &coeffs.c_minus_a)
    } else {
        (betas.tau_lo[k], &coeffs.neg_a, &coeffs.a_plus_c)
    };
    let fused = isa != Isa::Scalar;
    let mul_add = |a: f64, b: f64, c: f64| if fused { a.mul_add(b, c) } else { a * b + c };
    let threshold = big(bits);
    let mut active = scale_index >= 0.0 && start.abs() >= f64::MIN_POSITIVE;
    let (mut prev, mut cur) = (0.0, start);
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        // The kernels add each value to sums that start at +0 (turning -0 into +0), and
        // scale the sums back by `S_i`.
        let value = if active { cur } else { 0.0 };
        out.push((value + 0.0) * coeffs.s[i]);
        let next = mul_add(mul_add(slope[i], tau, offset[i]), cur, -prev);
        (prev, cur) = (cur, next);
        if scale_index < 0.0 && cur.abs() >= threshold {
            prev *= TINY;
            cur *= TINY;
            scale_index += 1.0;
            active = scale_index >= 0.0;
        }
    }
    out
}
