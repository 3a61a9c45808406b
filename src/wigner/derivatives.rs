//! Wigner-d columns with their first two beta derivatives: `dt^l(beta)`, `dt^l'(beta)` and
//! `dt^l''(beta)` of a base pair for every degree, at several betas at once in vector
//! lanes (peak refinement evaluates a series and its derivatives at several rotations per
//! pass).
//!
//! Differentiating the recurrence of the `wigner` module on the kernels' scaled values
//! (`u_{i+1} = p_i u_i - u_{i-1}`, `p_i = A'_i cos(beta) + C'_i`, see `RecTables::coeffs`)
//! twice in beta, with `p_i' = -A'_i sin(beta)` and `p_i'' = -A'_i cos(beta)`:
//!
//! `u'_{i+1} = p_i u'_i + p_i' u_i - u'_{i-1}`,
//! `u''_{i+1} = p_i u''_i + 2 p_i' u'_i + p_i'' u_i - u''_{i-1}`.
//!
//! The starting value `u_0 = N cos(beta/2)^a sin(beta/2)^b` (`a = m + m'`, `b = m - m'`)
//! has `u_0' = r_1 u_0` and `u_0'' = (r_1' + r_1^2) u_0 = r_2 u_0` with
//! `r_1 = (b cot(beta/2) - a tan(beta/2)) / 2` and
//! `r_2 = (b (b-1) / sin^2(beta/2) + a (a-1) / cos^2(beta/2)) / 4 - m^2`, in half angles so
//! that nothing cancels near the poles. The three values share the starting value's scale
//! index and are rescaled together by the rule of the `starts` module (as in `column` and
//! the DWT kernels) when the value grows past the threshold. The values are those of
//! `column`, in the same arithmetic.

use super::recurrence::RecCoeffs;
use super::starts::{big, BetaTables, SKIP_BITS_RANGE, TINY};
use crate::numeric::{sin_cos_dd, Dd, Ext};
use crate::simd::{Isa, Simd};
use std::f64::consts::PI;

/// The betas at which derivative columns are evaluated (the lanes of [`columns`]): the
/// half-angle powers of the starting values and, per point, what the differentiated
/// recurrence needs.
pub(crate) struct Points {
    /// Half-angle powers and recurrence arguments of every point.
    betas: BetaTables,
    /// Per point `k` (at index `k`): the recurrence argument `-tau_lo` (below pi/2) or
    /// `tau_hi` (above), its sign (`-1`, `+1`), `-sin(beta)`, `-cos(beta)`,
    /// `cot(beta/2)`, `tan(beta/2)`, `1/sin^2(beta/2)`, `1/cos^2(beta/2)`.
    point: [Vec<f64>; 8],
}

impl Points {
    /// The points given as `(cos(beta/2), sin(beta/2))` in double-double (from
    /// [`half_angles`], or swapped for `pi - beta`), for base orders up to `max_m`.
    pub(crate) fn new(half: &[(Dd, Dd)], max_m: usize) -> Points {
        let betas = BetaTables::new(half, 2 * max_m);
        let mut point: [Vec<f64>; 8] = Default::default();
        for (k, &(c, s)) in half.iter().enumerate() {
            let (c, s) = (c.to_f64(), s.to_f64());
            let upper = betas.upper(k);
            let values = [
                if upper {
                    betas.tau_hi[k]
                } else {
                    -betas.tau_lo[k]
                },
                if upper { 1.0 } else { -1.0 },
                -2.0 * s * c,
                -(c - s) * (c + s),
                c / s,
                s / c,
                1.0 / (s * s),
                1.0 / (c * c),
            ];
            for (p, v) in point.iter_mut().zip(values) {
                p.push(v);
            }
        }
        Points { betas, point }
    }

    /// Number of points.
    pub(crate) fn len(&self) -> usize {
        self.point[0].len()
    }
}

/// `(cos(beta/2), sin(beta/2))` in double-double for [`Points::new`] (`pi - beta` without
/// rounding: the two swapped). The derivatives of the starting values divide by
/// `sin(beta/2)`: `beta = 0` (the only pole a double hits exactly) becomes `1e-30`, which
/// moves every value and derivative by far less than its rounding error.
pub(crate) fn half_angles(beta: f64) -> (Dd, Dd) {
    let beta = if beta.abs() < 1e-30 {
        1e-30f64.copysign(beta)
    } else {
        beta
    };
    // `beta / 2` is exact; outside [0, pi] the half-angle functions take their signs.
    let (s, c) = if (0.0..=PI).contains(&beta) {
        sin_cos_dd(Dd::new(beta / 2.0))
    } else {
        (Dd::new((beta / 2.0).sin()), Dd::new((beta / 2.0).cos()))
    };
    (c, s)
}

/// The columns `dt^l_{m,mp}` of the base pair `(m, mp)` (starting-value norm `norm`,
/// recurrence coefficients `rec` from `RecTables::coeffs`, `n = rec.len()` degrees) and
/// their first two beta derivatives, for `K` vectors of points in one loop (independent
/// recurrences side by side hide each other's latency): vector `q` holds the points
/// `first[q] .. first[q] + w` of `points` (`w` the lanes of `S`), and degree `m + i` goes to
/// `out[q][(3 i + d) w ..][..w]`, `d` the order of the derivative, times `(-1)^i` where
/// `alternate[q]` (the sign members at `pi - beta` need). The arithmetic is that of the DWT
/// kernels' recurrence (see `column`); lanes below the skip threshold `2^-560` read 0.
/// `isa` computes the starting values (every instruction set gives the same bits).
///
/// # Safety
/// The CPU supports the instruction set of `S`.
#[inline(always)]
pub(crate) unsafe fn columns<S: Simd, const K: usize>(
    isa: Isa,
    points: &Points,
    (m, mp, norm): (usize, usize, Ext),
    rec: &RecCoeffs,
    first: [usize; K],
    alternate: [bool; K],
    out: [&mut [f64]; K],
) {
    let w = std::mem::size_of::<S::V>() / 8;
    let n = rec.len();
    assert!(out.iter().all(|x| x.len() == 3 * n * w) && w <= 8);
    assert!(first.iter().all(|&k| k + w <= points.len()));
    let bits = *SKIP_BITS_RANGE.end();
    let mut start = [[0.0; 8]; K];
    let mut index = [[0.0; 8]; K];
    for q in 0..K {
        points.betas.starts(
            isa,
            first[q],
            m,
            mp,
            norm,
            bits,
            &mut start[q][..w],
            &mut index[q][..w],
        );
    }
    let (a, b) = ((m + mp) as f64, (m - mp) as f64);
    let (rec_a, apc, cma, s) = (
        &rec.a[..n],
        &rec.a_plus_c[..n],
        &rec.c_minus_a[..n],
        &rec.s[..n],
    );
    // SAFETY: the instruction set by the caller; the point vectors are read at
    // `first .. first + w <= points.len()` (asserted), `start` and `index` hold 8 doubles
    // per vector, and every store is at `(3 i + d) w + w <= 3 n w`, the length of `out[q]`
    // (asserted).
    unsafe {
        let point: [[S::V; 8]; K] = std::array::from_fn(|q| {
            points
                .point
                .each_ref()
                .map(|v| S::load(v.as_ptr().add(first[q])))
        });
        let (zero, one) = (S::zero(), S::splat(1.0));
        let inf = S::splat(f64::INFINITY);
        let threshold = S::splat(big(bits));
        let tiny = S::splat(TINY);
        let mut cur = [[zero; 3]; K];
        let mut prev = [[zero; 3]; K];
        let mut index: [S::V; K] = std::array::from_fn(|q| S::load(index[q].as_ptr()));
        let mut weight = [zero; K];
        let mut limit = [zero; K];
        let mut scaled = false;
        for q in 0..K {
            let [_, _, _, _, cot, tan, isq, icq] = point[q];
            let u0 = S::load(start[q].as_ptr());
            // `r_1` and `r_2` of the module doc; terms with a zero exponent are absent (their
            // splats are 0).
            let r1 = S::mul(
                S::splat(0.5),
                S::fms(S::splat(b), cot, S::mul(S::splat(a), tan)),
            );
            let r2 = S::fms(
                S::splat(0.25),
                S::fma(
                    S::splat(b * (b - 1.0).max(0.0)),
                    isq,
                    S::mul(S::splat(a * (a - 1.0).max(0.0)), icq),
                ),
                S::splat((m * m) as f64),
            );
            cur[q] = [u0, S::mul(r1, u0), S::mul(r2, u0)];
            // Lanes still below the skip threshold read 0 and are rescaled when their value
            // grows past `threshold`; the others never are (their limit is infinite).
            weight[q] = S::blend_ge(index[q], zero, one, zero);
            limit[q] = S::blend_ge(index[q], zero, inf, threshold);
            scaled |= S::any_ge(S::splat(-0.5), index[q]);
        }
        let out = out.map(|x| x.as_mut_ptr());
        for i in 0..n {
            let ai = S::splat(rec_a[i]);
            let (cma, apc) = (S::splat(cma[i]), S::splat(apc[i]));
            for q in 0..K {
                let [sigtau, sigma, nsin, ncos, ..] = point[q];
                let sign = if alternate[q] && i % 2 == 1 {
                    -s[i]
                } else {
                    s[i]
                };
                let ws = S::mul(weight[q], S::splat(sign));
                for (d, u) in cur[q].iter().enumerate() {
                    S::store(out[q].add((3 * i + d) * w), S::mul(*u, ws));
                }
                // `p = A' cos(beta) + C'` in the kernels' argument forms, `p'`, `p''`.
                let p = S::fma(ai, sigtau, S::blend_ge(sigma, zero, cma, apc));
                let dp = S::mul(ai, nsin);
                let ddp = S::mul(ai, ncos);
                let [u0, u1, u2] = cur[q];
                let next = [
                    S::fms(p, u0, prev[q][0]),
                    S::fma(p, u1, S::fms(dp, u0, prev[q][1])),
                    S::fma(
                        p,
                        u2,
                        S::fma(S::add(dp, dp), u1, S::fms(ddp, u0, prev[q][2])),
                    ),
                ];
                prev[q] = cur[q];
                cur[q] = next;
            }
            if scaled {
                scaled = false;
                for q in 0..K {
                    let size = S::abs(cur[q][0]);
                    if S::any_ge(size, limit[q]) {
                        let factor = S::blend_ge(size, limit[q], tiny, one);
                        prev[q] = prev[q].map(|v| S::mul(v, factor));
                        cur[q] = cur[q].map(|v| S::mul(v, factor));
                        index[q] = S::add(index[q], S::blend_ge(size, limit[q], one, zero));
                        weight[q] = S::blend_ge(index[q], zero, one, zero);
                        limit[q] = S::blend_ge(index[q], zero, inf, threshold);
                    }
                    scaled |= S::any_ge(S::splat(-0.5), index[q]);
                }
            }
        }
    }
}
