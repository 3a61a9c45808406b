//! Wigner-d columns with their first two beta derivatives: `dt^l(beta)`, `dt^l'(beta)` and
//! `dt^l''(beta)` of a base pair for every degree, at several betas at once in vector
//! lanes (peak refinement evaluates a series and its derivatives at several rotations per
//! pass), and the public [`wigner_d_derivatives`] on top.
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

use super::recurrence::{RecCoeffs, RecTables};
use super::starts::{big, start_norm, BetaTables, SKIP_BITS_RANGE, TINY};
use crate::numeric::{sin_cos_dd, Dd, Ext};
#[cfg(target_arch = "x86_64")]
use crate::simd::{avx2::Avx2, avx512::Avx512};
use crate::simd::{scalar::Scalar, Isa, Simd};
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
pub(crate) unsafe fn columns<S: Simd<E = f64>, const K: usize>(
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

/// [`columns`] of one vector of points with the instruction set `isa` (supported by this
/// CPU).
fn column_isa(
    isa: Isa,
    points: &Points,
    base: (usize, usize, Ext),
    rec: &RecCoeffs,
    first: usize,
    alternate: bool,
    out: &mut [f64],
) {
    assert!(isa.is_supported());
    match isa {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: the CPU supports the instruction set (asserted).
        Isa::Avx512 => unsafe { column_avx512(points, base, rec, first, alternate, out) },
        #[cfg(target_arch = "x86_64")]
        // SAFETY: as above.
        Isa::Avx2 => unsafe { column_avx2(points, base, rec, first, alternate, out) },
        // SAFETY: the scalar code runs on every CPU.
        _ => unsafe { columns::<Scalar, 1>(isa, points, base, rec, [first], [alternate], [out]) },
    }
}

/// [`columns`] of one vector compiled for AVX-512.
///
/// # Safety
/// The CPU supports AVX-512F and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,fma")]
unsafe fn column_avx512(
    points: &Points,
    base: (usize, usize, Ext),
    rec: &RecCoeffs,
    first: usize,
    alternate: bool,
    out: &mut [f64],
) {
    // SAFETY: the caller's contract.
    unsafe { columns::<Avx512, 1>(Isa::Avx512, points, base, rec, [first], [alternate], [out]) }
}

/// [`columns`] of one vector compiled for AVX2 and FMA.
///
/// # Safety
/// The CPU supports AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
unsafe fn column_avx2(
    points: &Points,
    base: (usize, usize, Ext),
    rec: &RecCoeffs,
    first: usize,
    alternate: bool,
    out: &mut [f64],
) {
    // SAFETY: the caller's contract.
    unsafe { columns::<Avx2, 1>(Isa::Avx2, points, base, rec, [first], [alternate], [out]) }
}

/// `d^l_{m,mp}(beta)` (standard, not normalised) and its first and second derivatives in
/// beta, `[d, d', d'']` for `l = max(|m|,|mp|) ..= lmax` (empty if `lmax` is below).
///
/// The recurrence of [`wigner_d_column`](super::wigner_d_column) differentiated in beta
/// (the one peak refinement runs), in the arithmetic of the best instruction set of this
/// CPU: the values are exactly those of `wigner_d_column`. Values below about `2^-560`
/// (deep in the classically forbidden range near the poles) are returned as 0 with their
/// derivatives; `beta = 0` is evaluated at `1e-30`.
///
/// ```
/// // d^1_{0,0}(beta) = cos(beta)
/// let beta = 0.7;
/// let [d, d1, d2] = so3fft::wigner::wigner_d_derivatives(0, 0, 1, beta)[1];
/// assert!((d - beta.cos()).abs() < 1e-15 && (d1 + beta.sin()).abs() < 1e-15);
/// assert!((d2 + beta.cos()).abs() < 1e-15);
/// ```
pub fn wigner_d_derivatives(m: isize, mp: isize, lmax: usize, beta: f64) -> Vec<[f64; 3]> {
    let mut all = wigner_d_derivatives_isa(Isa::detect(), m, mp, lmax, &[beta]);
    all.pop().unwrap_or_default()
}

/// [`wigner_d_derivatives`] at every beta of `betas` (one column each), with the betas in
/// the vector lanes of `isa` (supported by this CPU).
pub(crate) fn wigner_d_derivatives_isa(
    isa: Isa,
    m: isize,
    mp: isize,
    lmax: usize,
    betas: &[f64],
) -> Vec<Vec<[f64; 3]>> {
    let (base_m, base_mp, member) = crate::symmetry::locate(m, mp);
    if lmax < base_m || betas.is_empty() {
        return vec![Vec::new(); betas.len()];
    }
    let w = isa.lanes();
    let padded = betas.len().div_ceil(w) * w;
    // The last vector padded with copies of the last beta; members at pi - beta read the
    // swapped half angles (no rounding).
    let half: Vec<(Dd, Dd)> = (0..padded)
        .map(|k| {
            let (c, s) = half_angles(betas[k.min(betas.len() - 1)]);
            if member.reversed {
                (s, c)
            } else {
                (c, s)
            }
        })
        .collect();
    let points = Points::new(&half, base_m);
    let n = lmax + 1 - base_m;
    let mut rec = RecCoeffs::new(n);
    RecTables::for_orders(lmax + 1, &[base_m, base_mp]).coeffs(base_m, base_mp, &mut rec);
    let base = (base_m, base_mp, start_norm(base_m, base_mp));
    // The member's sign at degree `m`; `alternate` gives the `(-1)^(l-m)` of the members at
    // pi - beta, whose first derivative changes sign.
    let f = member.sign_at(base_m);
    let f1 = if member.reversed { -f } else { f };
    let mut scratch = vec![0.0; 3 * n * w];
    let mut out = Vec::with_capacity(betas.len());
    for first in (0..padded).step_by(w) {
        column_isa(
            isa,
            &points,
            base,
            &rec,
            first,
            member.reversed,
            &mut scratch,
        );
        for lane in 0..w.min(betas.len() - first) {
            let column = (0..n)
                .map(|i| {
                    let norm = ((2 * (base_m + i) + 1) as f64 / 2.0).sqrt();
                    let at = |d: usize| scratch[(3 * i + d) * w + lane];
                    [f * at(0) / norm, f1 * at(1) / norm, f * at(2) / norm]
                })
                .collect();
            out.push(column);
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::wigner_d_derivatives_isa;
    use crate::numeric::{sin_cos_dd, Dd};
    use crate::simd::Isa;
    use crate::wigner::{wigner_d_column, wigner_d_column_isa};
    use std::f64::consts::{FRAC_PI_2, PI};

    fn isas() -> Vec<Isa> {
        [Isa::Avx512, Isa::Avx2, Isa::Scalar]
            .into_iter()
            .filter(|i| i.is_supported())
            .collect()
    }

    /// Order pairs of every member kind of a cluster (both columns, both parities, `m'` of
    /// either sign and above or below `m`), clusters of 1, 4 and 8 members.
    const PAIRS: [(isize, isize); 17] = [
        (0, 0),
        (1, 0),
        (0, -1),
        (3, 3),
        (-3, 3),
        (5, 2),
        (-5, -2),
        (2, 5),
        (-2, -5),
        (5, -2),
        (-5, 2),
        (2, -5),
        (-2, 5),
        (17, -11),
        (30, 0),
        (-30, 30),
        (29, 28),
    ];

    /// Betas near and away from the poles, on them and outside `[0, pi]`: in one call they
    /// share vectors, so that lanes below the skip threshold sit beside active ones.
    const BETAS: [f64; 14] = [
        1.1,
        0.0,
        1e-9,
        1e-4,
        0.05,
        0.7,
        FRAC_PI_2,
        2.0,
        3.0,
        PI - 1e-4,
        PI - 1e-9,
        PI,
        -0.4,
        3.7,
    ];

    /// `d^l_{m,k}(beta)` from the public column (0 where `|k| > l`).
    fn d(l: usize, m: isize, k: isize, beta: f64) -> f64 {
        let lo = m.unsigned_abs().max(k.unsigned_abs());
        if l < lo {
            return 0.0;
        }
        wigner_d_column(m, k, l, beta)[l - lo]
    }

    /// The first beta derivative by the ladder identity, as its two terms. With
    /// `d^l_{m,k}(beta) = <l m| exp(-i beta J_y) |l k>`:
    /// `d' = <l m| exp(-i beta J_y) (-i J_y) |l k>` and `-i J_y = (J_- - J_+) / 2`, where
    /// `J_± |l k> = c_± |l k±1>`, `c_± = sqrt((l ∓ k)(l ± k + 1))`, so
    /// `d' = (c_- d^l_{m,k-1} - c_+ d^l_{m,k+1}) / 2`: neighbouring columns, no derivative.
    fn ladder_terms(l: usize, m: isize, k: isize, beta: f64) -> [f64; 2] {
        let (lf, kf) = (l as f64, k as f64);
        let c_minus = ((lf + kf) * (lf - kf + 1.0)).max(0.0).sqrt();
        let c_plus = ((lf - kf) * (lf + kf + 1.0)).max(0.0).sqrt();
        [
            0.5 * c_minus * d(l, m, k - 1, beta),
            -0.5 * c_plus * d(l, m, k + 1, beta),
        ]
    }

    /// The first beta derivative by the ladder identity.
    fn ladder(l: usize, m: isize, k: isize, beta: f64) -> f64 {
        let [a, b] = ladder_terms(l, m, k, beta);
        a + b
    }

    /// The four terms of the Wigner differential equation at degree `l` (their sum is 0),
    /// `d'' + cot(beta) d' + [l(l+1) - (m^2 + k^2 - 2 m k cos(beta)) / sin^2(beta)] d`, from
    /// the half-angle sine and cosine, with `m^2 + k^2 - 2 m k cos(beta)` as
    /// `(m - k)^2 + 4 m k sin^2(beta/2)` below pi/2 and `(m + k)^2 - 4 m k cos^2(beta/2)`
    /// above (no cancellation near either pole).
    fn ode_terms(l: usize, (m, k): (isize, isize), (s, c): (f64, f64), dd: [f64; 3]) -> [f64; 4] {
        let [v, d1, d2] = dd;
        let (sin, cot) = (2.0 * s * c, (c - s) * (c + s) / (2.0 * s * c));
        let (mf, kf, lf) = (m as f64, k as f64, l as f64);
        let q = if s.abs() < c.abs() {
            (mf - kf).powi(2) + 4.0 * mf * kf * s * s
        } else {
            (mf + kf).powi(2) - 4.0 * mf * kf * c * c
        } / (sin * sin);
        [d2, cot * d1, lf * (lf + 1.0) * v, -q * v]
    }

    /// The signs of the ladder identity in this library's convention, against central
    /// differences of the public column.
    #[test]
    fn ladder_identity_agrees_with_finite_differences() {
        let h = 1e-5;
        for &(m, k) in &[(0isize, 0isize), (2, 1), (-3, 1), (1, -4), (5, 5), (-6, 2)] {
            for beta in [0.3, 1.1, 2.5] {
                let lo = m.unsigned_abs().max(k.unsigned_abs());
                for l in lo..=20 {
                    let fd = (d(l, m, k, beta + h) - d(l, m, k, beta - h)) / (2.0 * h);
                    let want = ladder(l, m, k, beta);
                    assert!(
                        (fd - want).abs() < 1e-6,
                        "l={l} ({m},{k}) beta={beta}: difference {fd:e}, ladder {want:e}"
                    );
                }
            }
        }
    }

    /// The first derivative against the ladder identity, every member kind, on every
    /// instruction set; and the values are those of the public column computed in the same
    /// arithmetic (one recurrence), away from `beta = 0` (evaluated at `1e-30` here).
    #[test]
    fn first_derivative_matches_the_ladder_identity() {
        let lmax = 40;
        let mut worst = 0.0f64;
        for isa in isas() {
            for &(m, k) in &PAIRS {
                let all = wigner_d_derivatives_isa(isa, m, k, lmax, &BETAS);
                let lo = m.unsigned_abs().max(k.unsigned_abs());
                for (&beta, column) in BETAS.iter().zip(&all) {
                    assert_eq!(column.len(), lmax + 1 - lo);
                    let values = wigner_d_column_isa(isa, m, k, lmax, beta);
                    for (i, v) in column.iter().enumerate() {
                        let l = lo + i;
                        let what = format!("{isa:?} l={l} ({m},{k}) beta={beta:e}");
                        let want = ladder(l, m, k, beta);
                        // Both sides' rounding errors grow like `l^2 eps` near the poles.
                        let err = (v[1] - want).abs() / ((l + 1) * (l + 1)) as f64;
                        worst = worst.max(err);
                        assert!(err < 2e-15, "{what}: d' {:e}, ladder {want:e}", v[1]);
                        if beta != 0.0 {
                            assert!(v[0] == values[i], "{what}: d {:e} {:e}", v[0], values[i]);
                        }
                    }
                }
            }
        }
        println!("first derivative: worst |error| / (l + 1)^2 {worst:.2e}");
    }

    /// The second derivative against the Wigner differential equation
    /// `d'' + cot(beta) d' + [l(l+1) - (m^2 + k^2 - 2 m k cos(beta)) / sin^2(beta)] d = 0`,
    /// its residual relative to the sum of the terms' sizes (they cancel near the poles;
    /// `d` is at most 1), every member kind, on every instruction set.
    #[test]
    fn second_derivative_satisfies_the_differential_equation() {
        let lmax = 40;
        let mut worst = 0.0f64;
        for isa in isas() {
            for &(m, k) in &PAIRS {
                let all = wigner_d_derivatives_isa(isa, m, k, lmax, &BETAS);
                let lo = m.unsigned_abs().max(k.unsigned_abs());
                for (&beta, column) in BETAS.iter().zip(&all) {
                    if beta == 0.0 || beta == PI {
                        continue;
                    }
                    let half = (beta / 2.0).sin_cos();
                    for (i, &dd) in column.iter().enumerate() {
                        let l = lo + i;
                        let terms = ode_terms(l, (m, k), half, dd);
                        let size: f64 = terms.iter().map(|t| t.abs()).sum();
                        let residual: f64 = terms.iter().sum();
                        // (`+ 1`: near a zero of `d` every term is rounding noise.)
                        let err = residual.abs() / (size + 1.0) / (l + 1) as f64;
                        worst = worst.max(err);
                        assert!(
                            err < 1e-13,
                            "{isa:?} l={l} ({m},{k}) beta={beta:e}: residual {residual:e} \
                             of terms {terms:?}"
                        );
                    }
                }
            }
        }
        println!("differential equation: worst relative residual / (l + 1) {worst:.2e}");
    }

    /// `mant * 2^exp` with a double-double `mant` kept within `2^±300` (or 0): products of
    /// hundreds of factors far outside the range of a double, rounded far below a double's
    /// precision.
    #[derive(Clone, Copy, Debug)]
    struct Wide {
        mant: Dd,
        exp: i64,
    }

    impl Wide {
        fn new(x: Dd) -> Wide {
            Wide { mant: x, exp: 0 }.norm()
        }

        fn norm(self) -> Wide {
            let (up, down) = (2f64.powi(300), 2f64.powi(-300));
            let (mut mant, mut exp) = (self.mant, self.exp);
            while mant.hi != 0.0 && mant.hi.abs() > up {
                (mant, exp) = (mant.mul_f(down), exp + 300);
            }
            while mant.hi != 0.0 && mant.hi.abs() < down {
                (mant, exp) = (mant.mul_f(up), exp - 300);
            }
            Wide { mant, exp }
        }

        fn mul(self, o: Wide) -> Wide {
            Wide {
                mant: self.mant.mul(o.mant),
                exp: self.exp + o.exp,
            }
            .norm()
        }

        fn div(self, o: Wide) -> Wide {
            Wide {
                mant: self.mant.div(o.mant),
                exp: self.exp - o.exp,
            }
            .norm()
        }

        fn sqrt(self) -> Wide {
            let odd = self.exp.rem_euclid(2);
            Wide {
                mant: self.mant.mul_f((1 << odd) as f64).sqrt(),
                exp: (self.exp - odd) / 2,
            }
            .norm()
        }

        /// The value times `2^shift` (`shift <= 0`) in double-double (0 below its range).
        fn scaled(self, shift: i64) -> Dd {
            if self.mant.hi == 0.0 {
                return self.mant;
            }
            let (mut x, mut e) = (self.mant, self.exp + shift);
            while e <= -300 {
                (x, e) = (x.mul_f(2f64.powi(-300)), e + 300);
            }
            x.mul_f(2f64.powi(e as i32))
        }

        /// The double nearest (or 0 below the subnormals).
        fn to_f64(self) -> f64 {
            let (mut x, mut e) = (self.mant.to_f64(), self.exp);
            while e >= 300 {
                (x, e) = (x * 2f64.powi(300), e - 300);
            }
            while e <= -300 {
                (x, e) = (x * 2f64.powi(-300), e + 300);
            }
            x * 2f64.powi(e as i32)
        }

        /// `log2 |x|`.
        fn log2(self) -> f64 {
            self.mant.hi.abs().log2() + self.exp as f64
        }
    }

    /// `x^0 .. x^n`.
    fn powers(x: Dd, n: usize) -> Vec<Wide> {
        let x = Wide::new(x);
        std::iter::successors(Some(Wide::new(Dd::new(1.0))), |p| Some(p.mul(x)))
            .take(n + 1)
            .collect()
    }

    /// `d^l_{m,k}(beta)` by Wigner's explicit sum,
    /// `sqrt((l+m)! (l-m)! (l+k)! (l-k)!) sum_s (-1)^(m-k+s) cos(beta/2)^(2l+k-m-2s)
    /// sin(beta/2)^(m-k+2s) / ((l+k-s)! s! (m-k+s)! (l-m-s)!)`, in double-double (the
    /// powers, factorials and terms each within a few hundred double-double roundings), and
    /// the sum's condition number `sum |t_s| / |sum t_s|`. `fact` holds `0! ..`, `cos` and
    /// `sin` the powers of the half angles.
    fn explicit(
        l: usize,
        m: isize,
        k: isize,
        (fact, cos, sin): (&[Wide], &[Wide], &[Wide]),
    ) -> (Wide, f64) {
        let l = l as isize;
        let f = |n: isize| fact[n as usize];
        let norm = f(l + m).mul(f(l - m)).mul(f(l + k)).mul(f(l - k)).sqrt();
        let terms: Vec<Wide> = (0.max(k - m)..=(l + k).min(l - m))
            .map(|s| {
                let t = cos[(2 * l + k - m - 2 * s) as usize]
                    .mul(sin[(m - k + 2 * s) as usize])
                    .mul(norm)
                    .div(f(l + k - s).mul(f(s)).mul(f(m - k + s)).mul(f(l - m - s)));
                let sign = if (m - k + s) % 2 == 0 { 1.0 } else { -1.0 };
                Wide {
                    mant: t.mant.mul_f(sign),
                    exp: t.exp,
                }
            })
            .collect();
        let top = terms
            .iter()
            .filter(|t| t.mant.hi != 0.0)
            .map(|t| t.exp)
            .max()
            .unwrap_or(0);
        let sum = terms
            .iter()
            .fold(Dd::new(0.0), |acc, t| acc.add_dd(t.scaled(-top)));
        let size: f64 = terms.iter().map(|t| t.scaled(-top).hi.abs()).sum();
        let value = Wide {
            mant: sum,
            exp: top,
        }
        .norm();
        let cond = if sum.hi == 0.0 {
            1.0
        } else {
            size / sum.hi.abs()
        };
        (value, cond)
    }

    /// Values near the poles and in the extended-exponent range against Wigner's explicit
    /// sum in double-double (its terms cancel by up to 1e9 in the forbidden range, far
    /// within its precision), with the first derivative against the ladder identity and
    /// the second against the differential equation, on every instruction set. Orders 400
    /// at `beta = 0.6` and `pi - 0.6` start near `2^-1407`, far below the doubles, and
    /// grow past the skip threshold `2^-560` by degree 700 (values below it must read 0);
    /// within `1e-3` of a pole every degree up to 300 is checked, down to `beta = 0` and
    /// `pi` themselves.
    #[test]
    fn values_near_the_poles_match_the_explicit_sum() {
        // Within 1e-3 of a pole, and on the poles.
        let poles = [1e-6, 1e-3, PI - 1e-3, PI - 1e-6, 0.0, PI];
        // Order pairs, degree limit, and a beta in their classically forbidden range (0:
        // none): members read their base pair's function at `pi - beta` or at `beta`, so
        // that `(400, -400)` at 0.6 and `(400, 400)` at `pi - 0.6` both start at
        // `sin(0.3)^800 ~ 2^-1407`.
        let cases: [((isize, isize), usize, f64); 8] = [
            ((400, -400), 700, 0.6),
            ((400, 400), 700, PI - 0.6),
            ((330, -300), 560, 0.6),
            ((-300, -330), 560, PI - 0.6),
            ((40, 3), 300, 0.0),
            ((-100, 100), 300, 0.0),
            ((200, 150), 300, 0.0),
            ((150, -7), 300, 0.0),
        ];
        let fact: Vec<Wide> = (0..=1400)
            .scan(Wide::new(Dd::new(1.0)), |f, n| {
                if n > 0 {
                    *f = f.mul(Wide::new(Dd::new(n as f64)));
                }
                Some(*f)
            })
            .collect();
        // Above every skipped value: `dt < 2^-560` times at most `1.2` (the scale of the
        // recurrence's values).
        let skipped = 2f64.powi(-559);
        // Worst errors (value, d', ODE) and checks (the same), all and in the extended range.
        let (mut worst, mut extended) = ([[0.0f64; 3]; 2], [0; 3]);
        for isa in isas() {
            for &((m, k), lmax, forbidden) in &cases {
                let mut betas = poles.to_vec();
                if forbidden != 0.0 {
                    betas.insert(0, forbidden);
                }
                let all = wigner_d_derivatives_isa(isa, m, k, lmax, &betas);
                let lo = m.unsigned_abs().max(k.unsigned_abs());
                for (&beta, column) in betas.iter().zip(&all) {
                    // The half angles of the double `beta` to double-double precision, as
                    // the library takes them (rounded to doubles, their powers would be off
                    // by up to `2 lmax` ulps).
                    let (sd, cd) = sin_cos_dd(Dd::new(beta / 2.0));
                    let (s, c) = (sd.to_f64(), cd.to_f64());
                    let (cos, sin) = (powers(cd, 2 * lmax + 2), powers(sd, 2 * lmax + 2));
                    let tables = (&fact[..], &cos[..], &sin[..]);
                    let start = explicit(lo, m, k, tables).0;
                    for (i, &[v, d1, d2]) in column.iter().enumerate() {
                        let l = lo + i;
                        let (want, cond) = explicit(l, m, k, tables);
                        let want = want.to_f64();
                        let what = format!("{isa:?} l={l} ({m},{k}) beta={beta:e}");
                        if v == 0.0 {
                            // Below the skip threshold (`dt < 2^-560`) the lane reads 0, with
                            // its derivatives.
                            assert!(want.abs() < skipped, "{what}: d 0, explicit sum {want:e}");
                            assert!(d1 == 0.0 && d2 == 0.0, "{what}: d 0, d' {d1:e}, d'' {d2:e}");
                            continue;
                        }
                        // The sum in double-double is exact to far below a double's
                        // rounding unless it cancels beyond 1e14.
                        assert!(cond < 1e14, "{what}: explicit sum with condition {cond:e}");
                        // Rounding errors grow with the degree.
                        let err = (v - want).abs() / (want.abs() * (l + 1) as f64);
                        assert!(err < 5e-15, "{what}: d {v:e}, explicit sum {want:e}");
                        let ranges = if start.log2() < -1022.0 { 0..2 } else { 0..1 };
                        let mut record = |q: usize, err: f64| {
                            for r in ranges.clone() {
                                worst[r][q] = worst[r][q].max(err);
                            }
                            extended[q] += ranges.len() - 1;
                        };
                        record(0, err);
                        if beta == 0.0 || beta == PI {
                            continue;
                        }
                        // The differential equation relative to its terms' sizes (no zero
                        // of `d` in these ranges).
                        let terms = ode_terms(l, (m, k), (s, c), [v, d1, d2]);
                        let size: f64 = terms.iter().map(|t| t.abs()).sum();
                        let err = terms.iter().sum::<f64>().abs() / size / (l + 1) as f64;
                        record(2, err);
                        assert!(err < 5e-15, "{what}: residual of terms {terms:?}");
                        // The ladder identity relative to its terms' sizes, where neither
                        // neighbour (of degree `l`) is skipped.
                        let terms = ladder_terms(l, m, k, beta);
                        let skipped_neighbour = [k - 1, k + 1]
                            .iter()
                            .zip(terms)
                            .any(|(j, t)| j.unsigned_abs() <= l && t == 0.0);
                        if !skipped_neighbour {
                            let want = terms[0] + terms[1];
                            let size = terms[0].abs() + terms[1].abs();
                            let err = (d1 - want).abs() / size / (l + 1) as f64;
                            record(1, err);
                            assert!(err < 5e-15, "{what}: d' {d1:e}, ladder {want:e}");
                        }
                    }
                }
            }
        }
        println!(
            "near the poles, worst relative error / (l + 1) of value, d', ODE: {:?}; \
             where the start underflows a double: {:?} in {extended:?} checks",
            worst[0].map(|x| format!("{x:.2e}")),
            worst[1].map(|x| format!("{x:.2e}"))
        );
        assert!(
            extended.iter().all(|&n| n >= 100),
            "too few checks in the extended range: {extended:?}"
        );
    }
}
