//! One beta's column of the recurrence, `dt^l` for every degree, in exactly the arithmetic
//! of the DWT kernels: the reference the kernels are tested against (bit for bit) and the
//! evaluation behind the public d functions.

use super::recurrence::{RecCoeffs, RecTables};
use super::starts::{big, tiny, BaseStart, BetaTables, SKIP_BITS_RANGE};
use crate::real::Elem;
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
    let fused = isa != Isa::Scalar;
    column_in(
        fused,
        betas,
        k,
        (m, mp, norm),
        coeffs,
        *SKIP_BITS_RANGE.end(),
    )
}

/// [`column_with`] in element type `E` at skip threshold `2^-bits`: every value and
/// operation in `E` (for f32: the recurrence argument `tau` rounded to f32, the f32
/// scaled starting value, coefficients narrowed by [`RecCoeffs::narrow_from`], rescaling by
/// `tiny::<f32>()`), fused multiply-adds if `fused`, else separate multiplications and
/// additions (as [`Isa::Scalar`]). For f64 at the widest threshold, [`column_with`].
pub(crate) fn column_in<E: Elem>(
    fused: bool,
    betas: &BetaTables,
    k: usize,
    (m, mp, norm): (usize, usize, crate::numeric::Ext),
    coeffs: &RecCoeffs<E>,
    bits: u32,
) -> Vec<E> {
    let n = coeffs.len();
    let base = BaseStart::new(m, mp, norm, bits);
    let (start, mut scale_index) = betas.start::<E>(k, &base, 1.0);
    // The recurrence multiplier `A x + C` as `(A + C) - A tau` below pi/2 and as
    // `A tau + (C - A)` above (see `BetaTables`).
    let (tau, slope, offset) = if betas.upper(k) {
        (betas.tau_hi[k], &coeffs.a, &coeffs.c_minus_a)
    } else {
        (betas.tau_lo[k], &coeffs.neg_a, &coeffs.a_plus_c)
    };
    let tau = E::from_f64(tau);
    let mul_add = |a: E, b: E, c: E| if fused { a.mul_add(b, c) } else { a * b + c };
    let (threshold, tiny) = (big::<E>(bits), tiny::<E>());
    let mut active = scale_index >= E::ZERO && start.abs() >= E::MIN_POSITIVE;
    let (mut prev, mut cur) = (E::ZERO, start);
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        // The kernels add each value to sums that start at +0 (turning -0 into +0), and
        // scale the sums back by `S_i`.
        let value = if active { cur } else { E::ZERO };
        out.push((value + E::ZERO) * coeffs.s[i]);
        let next = mul_add(mul_add(slope[i], tau, offset[i]), cur, -prev);
        (prev, cur) = (cur, next);
        if scale_index < E::ZERO && cur.abs() >= threshold {
            prev *= tiny;
            cur *= tiny;
            scale_index += E::ONE;
            active = scale_index >= E::ZERO;
        }
    }
    out
}
