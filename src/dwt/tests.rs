//! Tests of the kernels: layouts, adjointness, instruction sets against the scalar code,
//! and the one-beta column against the reference evaluation of `wigner`.

use super::fixtures::{cluster_setup, cluster_setup_at, grid_lanes, test_skip_bits, ClusterInputs};
use super::{forward, forward_raw, inverse, inverse_raw, DwtElem, Lanes, Prefetch, Rec};
use crate::simd::Isa;
use crate::wigner::column::column;
use crate::wigner::starts::{big, start_norm, BaseStart, BetaTables, SKIP_BITS_RANGE};
use crate::wigner::{RecCoeffs, RecTables};

/// [`inverse`] with its input rows filled on demand from `fin`: rows start as NaN, so
/// a read before the fill shows in `y`. Checks the fill contract (top down, each row
/// once, down to a contiguous end at `n`) and returns the lowest row filled.
pub(super) fn inverse_from<E: DwtElem>(
    isa: Isa,
    pw: usize,
    rec: &Rec<E>,
    lanes: &Lanes<E>,
    fin: &[E],
    y: &mut [E],
) -> usize {
    let n = rec.len();
    let mut buf = vec![E::from_f64(f64::NAN); n * pw];
    let mut have = n;
    inverse(
        isa,
        pw,
        rec,
        lanes,
        &mut buf,
        &mut |b: &mut [E], from: usize, to: usize| {
            assert!(
                from < to && to == have,
                "fill {from}..{to} with rows {have}.. filled"
            );
            b[from * pw..to * pw].copy_from_slice(&fin[from * pw..to * pw]);
            have = from;
        },
        y,
    );
    have
}

/// [`inverse_raw`] with every input row of `fin` present (no fill), rows at `out` as
/// `lanes` address them.
///
/// # Safety
/// `out` holds every row of the lanes.
unsafe fn inverse_rows_at(
    isa: Isa,
    pw: usize,
    rec: &Rec,
    lanes: &Lanes,
    fin: &[f64],
    out: *mut f64,
) {
    let mut buf = fin.to_vec();
    // SAFETY: the caller's contract.
    unsafe { inverse_raw(isa, pw, rec, lanes, &mut buf, &mut |_, _, _| {}, out) }
}

pub(super) fn pseudo(n: usize, seed: u64) -> Vec<f64> {
    let mut s = seed;
    (0..n)
        .map(|_| {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            (s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
        })
        .collect()
}

/// The cases of the row-layout tests: B = 40, three base pairs, 48 betas over the
/// grid, 8 and 16 columns, every supported instruction set, as
/// `f(isa, columns, m, rec, lanes)` (interleaved lanes, default skip threshold).
fn layout_cases(mut f: impl FnMut(Isa, usize, usize, &Rec, Lanes)) {
    let (b, nbs) = (40, 48);
    for &(m, mp) in &[(3usize, 1usize), (20, 20), (33, 0)] {
        let ClusterInputs {
            coeffs: rc,
            tau,
            p,
            sc,
        } = cluster_setup(b, m, mp, nbs);
        let rec = Rec::new(&rc, b - m);
        for pw in [8usize, 16] {
            for isa in [Isa::Scalar, Isa::Avx2, Isa::Avx512] {
                if isa.is_supported() {
                    f(isa, pw, m, &rec, grid_lanes(&tau, &p, &sc, nbs / 2));
                }
            }
        }
    }
}

/// The forward reading its rows in the split layout (`Lanes::pair_stride` = `P`, the
/// mirror rows `Lanes::row_gap` after the low-beta rows; a forward chain's buffers)
/// gives the sums it gives from consecutive rows, bit for bit: every instruction set,
/// 8 and 16 columns.
#[test]
fn split_rows_give_the_same_sums() {
    layout_cases(|isa, pw, m, rec, mut lanes| {
        let (n, nbs) = (rec.len(), lanes.tau.len());
        let x = pseudo(nbs * pw, 11 + m as u64);
        let mut want = vec![0.0; (n + 8) * pw];
        forward(isa, pw, rec, &lanes, &x, &mut want);
        // Low-beta rows from 5 values in, mirror rows 3 values after them; NaN
        // everywhere else.
        let gap = nbs / 2 * pw + 3;
        let mut z = vec![f64::NAN; 5 + gap + nbs / 2 * pw];
        for r in 0..nbs {
            let at = 5 + (r / 2) * pw + (r % 2) * gap;
            z[at..at + pw].copy_from_slice(&x[r * pw..(r + 1) * pw]);
        }
        (lanes.pair_stride, lanes.row_gap) = (pw, gap);
        let mut f = vec![0.0; (n + 8) * pw];
        // SAFETY: every row of the lanes is inside `z`.
        unsafe { forward_raw(isa, pw, rec, &lanes, z.as_ptr().add(5), &mut f) };
        for (i, (u, v)) in f[..n * pw].iter().zip(&want).enumerate() {
            assert_eq!(u.to_bits(), v.to_bits(), "{isa:?} P={pw} m={m} at {i}");
        }
    });
}

/// The inverse into rows a pair stride apart (`Lanes::pair_stride`), the two rows of a
/// pair side by side or (`Lanes::row_gap`, the plan's half-major layout) in two
/// separate halves, writes exactly what it writes into consecutive rows, each row at
/// its place, and nothing elsewhere: every instruction set, both store modes.
#[test]
fn strided_rows_hold_the_consecutive_rows() {
    layout_cases(|isa, pw, m, rec, lanes| {
        let (n, nbs) = (rec.len(), lanes.tau.len());
        let fin = pseudo(n * pw, 7 + m as u64);
        for (stream, half) in [(true, false), (false, false), (true, true)] {
            let mut lanes = Lanes { stream, ..lanes };
            let mut y = vec![f64::NAN; nbs * pw];
            inverse_from(isa, pw, rec, &lanes, &fin, &mut y);
            // Pairs 2p + 8 values apart, 5 values into the buffer; half-major: rows
            // p + 8 apart in each half, the second half 3 values after the first.
            let ps = if half { pw + 8 } else { 2 * pw + 8 };
            let gap = if half { nbs / 2 * ps + 3 } else { pw };
            lanes.pair_stride = ps;
            lanes.row_gap = if half { gap } else { 0 };
            let mut z = vec![f64::NAN; 5 + nbs / 2 * ps + gap];
            // SAFETY: z holds nbs / 2 pairs of two rows after offset 5.
            unsafe { inverse_rows_at(isa, pw, rec, &lanes, &fin, z.as_mut_ptr().add(5)) };
            let mut want = vec![f64::NAN; z.len()];
            for r in 0..nbs {
                let at = 5 + (r / 2) * ps + (r % 2) * gap;
                want[at..at + pw].copy_from_slice(&y[r * pw..(r + 1) * pw]);
            }
            for (i, (v, w)) in z.iter().zip(&want).enumerate() {
                assert_eq!(
                    v.to_bits(),
                    w.to_bits(),
                    "{isa:?} P={pw} half={half} at {i}"
                );
            }
        }
    });
}

/// Fewer lower-half lanes than upper ones (`Lanes::upper_from` other than half the lanes,
/// as in a partial plan's split selections): lower lanes `0..a` and upper lanes
/// `24 + a..48` of the grid, the lower rows one after another and the upper rows after
/// them, give each lane's row of the full call bit for bit, and nothing elsewhere.
#[test]
fn unequal_halves_give_each_lanes_row() {
    layout_cases(|isa, pw, m, rec, lanes| {
        let (n, nbs) = (rec.len(), lanes.tau.len());
        let half = lanes.upper_from;
        let fin = pseudo(n * pw, 5 + m as u64);
        let mut y = vec![f64::NAN; nbs * pw];
        inverse_from(isa, pw, rec, &lanes, &fin, &mut y);
        for a in [0, 8, 16, 24] {
            let pick: Vec<usize> = (0..a).chain(half + a..nbs).collect();
            let take = |v: &[f64]| pick.iter().map(|&u| v[u]).collect::<Vec<_>>();
            let (tau, p, sc) = (take(lanes.tau), take(lanes.p), take(lanes.sc));
            // Upper rows 3 values after the last lower one.
            let gap = a * pw + 3;
            let split = Lanes {
                tau: &tau,
                p: &p,
                sc: &sc,
                upper_from: a,
                pair_stride: pw,
                row_gap: gap,
                ..lanes
            };
            let mut z = vec![f64::NAN; gap + (pick.len() - a) * pw];
            // SAFETY: `z` holds the lower rows `u pw` (`u < a`) and the upper rows
            // `gap + (u - a) pw`.
            unsafe { inverse_rows_at(isa, pw, rec, &split, &fin, z.as_mut_ptr()) };
            let mut want = vec![f64::NAN; z.len()];
            for (u, &orig) in pick.iter().enumerate() {
                let at = if u < a { u * pw } else { gap + (u - a) * pw };
                let (r, _) = lanes.rows(orig);
                want[at..at + pw].copy_from_slice(&y[r * pw..(r + 1) * pw]);
            }
            for (i, (v, w)) in z.iter().zip(&want).enumerate() {
                assert_eq!(v.to_bits(), w.to_bits(), "{isa:?} P={pw} a={a} at {i}");
            }
        }
    });
}

/// The forward kernel is the transpose of the inverse one: `<y, x> = <fin, f>` for
/// `f = forward(x)` and `y = inverse(fin)`, on every path, with and without skipping,
/// for odd and even numbers of vectors (the 8-column inverse pairs vectors), halves of
/// unequal size, and clusters of 1 to 67 degrees. Skipping changes nothing beyond
/// rounding.
#[test]
fn forward_is_the_adjoint_of_inverse() {
    let b = 67;
    // Rows below `lo` summed over the runs: the skipped rows must occur here.
    let mut rows_below_lo = 0;
    for &(m, mp) in &[
        (0usize, 0usize),
        (5, 2),
        (30, 30),
        (41, 0),
        (65, 12),
        (66, 66),
    ] {
        let n = b - m;
        // Spread over the grid, and (16) the 8 betas nearest each pole, where the
        // kernels skip the first degrees of every lane.
        for nbs in [24usize, 40, 56, 72, 16] {
            let ClusterInputs {
                coeffs: rc,
                tau,
                p,
                sc,
            } = if nbs == 16 {
                let ks: Vec<usize> = (0..8).chain(2 * b - 8..2 * b).collect();
                cluster_setup_at(b, m, mp, &ks)
            } else {
                cluster_setup(b, m, mp, nbs)
            };
            let rec = Rec::new(&rc, n);
            for pw in [8usize, 16] {
                let x = pseudo(nbs * pw, 3 + nbs as u64);
                let fin = pseudo(n * pw, 5 + m as u64);
                let mut runs = Vec::new();
                for isa in [Isa::Scalar, Isa::Avx2, Isa::Avx512] {
                    if !isa.is_supported() {
                        continue;
                    }
                    for skip in [true, false] {
                        let lanes = Lanes {
                            tau: &tau,
                            p: &p,
                            sc: &sc,
                            // Vectors below this lane are the lower half.
                            upper_from: 8 * (nbs / 16),
                            big: big(test_skip_bits()),
                            skip,
                            interleaved: false,
                            prefetch: Prefetch::none(),
                            // Both ways of storing the inverse's output.
                            stream: skip,
                            pair_stride: 0,
                            row_gap: 0,
                        };
                        // Stale values in every row the kernel must write.
                        let mut f = vec![0.0; (n + 8) * pw];
                        f[..n * pw].fill(f64::NAN);
                        let mut y = vec![f64::NAN; nbs * pw];
                        let lo = forward(isa, pw, &rec, &lanes, &x, &mut f);
                        assert!(f[..lo * pw].iter().all(|&v| v == 0.0), "rows below lo");
                        let filled = inverse_from(isa, pw, &rec, &lanes, &fin, &mut y);
                        // Both kernels find the same first degree any lane needs.
                        assert_eq!(filled, lo, "first row read by the inverse");
                        rows_below_lo += lo;
                        let dot =
                            |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(u, v)| u * v).sum::<f64>();
                        let norm = |a: &[f64]| dot(a, a).sqrt();
                        let (lhs, rhs) = (dot(&y, &x), dot(&fin, &f[..n * pw]));
                        let scale = norm(&y) * norm(&x) + norm(&fin) * norm(&f[..n * pw]);
                        assert!(
                            (lhs - rhs).abs() <= 1e-13 * scale,
                            "{isa:?} skip={skip} m={m} mp={mp} nbs={nbs} P={pw}: {lhs} {rhs}"
                        );
                        // Rows from `n` on are scratch (the last block runs in full),
                        // but never a non-finite value.
                        assert!(f[n * pw..].iter().all(|v| v.is_finite()));
                        f.truncate(n * pw);
                        runs.push((f, y));
                    }
                }
                let (f0, y0) = &runs[0];
                let fs = f0.iter().fold(0.0f64, |a, v| a.max(v.abs())).max(1e-300);
                let ys = y0.iter().fold(0.0f64, |a, v| a.max(v.abs())).max(1e-300);
                for (f, y) in &runs[1..] {
                    for (u, v) in f.iter().zip(f0) {
                        assert!(
                            (u - v).abs() <= 1e-13 * fs,
                            "m={m} mp={mp} nbs={nbs} P={pw}"
                        );
                    }
                    for (u, v) in y.iter().zip(y0) {
                        assert!(
                            (u - v).abs() <= 1e-13 * ys,
                            "m={m} mp={mp} nbs={nbs} P={pw}"
                        );
                    }
                }
            }
        }
    }
    assert!(rows_below_lo > 0, "no run skipped a row");
}

/// Every SIMD path agrees with the portable scalar one, forward and inverse,
/// including lanes that start scaled down (large m at betas near the poles).
#[test]
fn simd_paths_match_scalar() {
    let b = 200;
    for &(m, mp) in &[(0usize, 0usize), (5, 3), (150, 20), (199, 199), (120, 0)] {
        let n = b - m;
        let nb = 2 * b;
        let ClusterInputs {
            coeffs: rc,
            tau: x,
            p,
            sc,
        } = cluster_setup(b, m, mp, nb);
        let rec = Rec::new(&rc, n);
        let lanes = grid_lanes(&x, &p, &sc, b);
        for pw in [8usize, 16] {
            let xin = pseudo(nb * pw, 7 + m as u64);
            let fin = pseudo(n * pw, 11 + mp as u64);
            let mut f_ref = vec![f64::NAN; (n + 8) * pw];
            let mut y_ref = vec![0.0; nb * pw];
            forward(Isa::Scalar, pw, &rec, &lanes, &xin, &mut f_ref);
            inverse_from(Isa::Scalar, pw, &rec, &lanes, &fin, &mut y_ref);
            for isa in [Isa::Avx512, Isa::Avx2] {
                if !isa.is_supported() {
                    continue;
                }
                let mut f = vec![f64::NAN; (n + 8) * pw];
                let mut y = vec![0.0; nb * pw];
                forward(isa, pw, &rec, &lanes, &xin, &mut f);
                inverse_from(isa, pw, &rec, &lanes, &fin, &mut y);
                // FMA and plain multiply-add round differently; the recurrence error
                // grows like l * eps (l <= 200 here), so compare relative to the largest value.
                let rel = |u: &[f64], r: &[f64]| {
                    let scale = r.iter().fold(0.0f64, |s, x| s.max(x.abs()));
                    let e = u
                        .iter()
                        .zip(r)
                        .fold(0.0f64, |s, (a, b)| s.max((a - b).abs()));
                    e / scale
                };
                // Rows from n on are not part of the result; every row below is
                // written (f starts out NaN, which `max` would otherwise skip).
                let nf = n * pw;
                assert!(f[..nf].iter().chain(&f_ref[..nf]).all(|v| v.is_finite()));
                let (ef, ey) = (rel(&f[..nf], &f_ref[..nf]), rel(&y, &y_ref));
                assert!(
                    ef < 1e-12 && ey < 1e-12,
                    "{isa:?} m={m} mp={mp} P={pw}: {ef} {ey}"
                );
            }
        }
    }
}

/// `dt^l_{m,mp}` of the base pair at point `k` of `betas`, for `l = m..lend`, through the
/// forward kernel (one beta, unit data in column 0, no skipping).
fn kernel_column(
    isa: Isa,
    betas: &BetaTables,
    tables: &RecTables,
    k: usize,
    (m, mp): (usize, usize),
    lend: usize,
) -> Vec<f64> {
    let n = lend - m;
    let mut rc = RecCoeffs::new(n);
    tables.coeffs(m, mp, &mut rc);
    let w = isa.lanes();
    let bits = *SKIP_BITS_RANGE.end();
    let base = BaseStart::new(m, mp, start_norm(m, mp), bits);
    let (p0, sc0) = betas.start(k, &base, 1.0);
    let (mut tau, mut p, mut sc) = (vec![0.0; w], vec![0.0; w], vec![0.0; w]);
    let upper = betas.upper(k);
    tau[0] = if upper {
        betas.tau_hi[k]
    } else {
        betas.tau_lo[k]
    };
    p[0] = p0;
    sc[0] = sc0;
    let mut xin = vec![0.0; w * 8];
    xin[0] = 1.0;
    let mut f = vec![0.0; (n + w) * 8];
    let rec = Rec::new(&rc, n);
    let lanes = Lanes {
        tau: &tau,
        p: &p,
        sc: &sc,
        upper_from: if upper { 0 } else { w },
        big: big(bits),
        skip: false,
        interleaved: false,
        prefetch: Prefetch::none(),
        stream: false,
        pair_stride: 0,
        row_gap: 0,
    };
    forward(isa, 8, &rec, &lanes, &xin, &mut f);
    f.iter()
        .step_by(8)
        .zip(&rc.s[..n])
        .map(|(v, s)| v * s)
        .collect()
}

/// The forward kernel on one beta reproduces the reference column of `wigner` (which the
/// public d functions return) bit for bit, on every instruction set: grid betas of both
/// halves, the poles, and betas where the start lies far below the skip threshold.
#[test]
fn one_beta_forward_is_the_reference_column() {
    use crate::numeric::{sin_cos_dd, Dd};
    let b = 70;
    let grid = BetaTables::grid(b);
    let tables = RecTables::new(b);
    let mut points = vec![];
    for beta in [
        0.0,
        1e-3,
        0.3,
        std::f64::consts::FRAC_PI_2,
        2.9,
        std::f64::consts::PI,
    ] {
        let (s, c) = sin_cos_dd(Dd::new(beta / 2.0));
        points.push((c, s));
    }
    let few = BetaTables::new(&points, 2 * b);
    for isa in [Isa::Scalar, Isa::Avx2, Isa::Avx512] {
        if !isa.is_supported() {
            continue;
        }
        for &(m, mp) in &[
            (0usize, 0usize),
            (1, 0),
            (7, 3),
            (40, 40),
            (69, 0),
            (60, 31),
        ] {
            for (betas, ks) in [
                (&grid, vec![0, 1, 33, 70, 100, 139]),
                (&few, (0..6).collect()),
            ] {
                for k in ks {
                    let want = column(isa, betas, &tables, k, (m, mp), b);
                    let got = kernel_column(isa, betas, &tables, k, (m, mp), b);
                    assert_eq!(got.len(), want.len());
                    for (i, (u, v)) in got.iter().zip(&want).enumerate() {
                        assert_eq!(
                            u.to_bits(),
                            v.to_bits(),
                            "{isa:?} m={m} mp={mp} k={k} l={}: {u:e} {v:e}",
                            m + i
                        );
                    }
                }
            }
        }
    }
}

/// One case of the parity kernel tests (see [`parity_cases`]): the northern rings `ks`
/// of bandwidth `b`, order `m`, lanes padded to the vector width of `isa` (`nb`), and the
/// reference columns `cols[s]` of `wigner` at each ring.
struct ParityCase<'a> {
    b: usize,
    m: usize,
    isa: Isa,
    rings: usize,
    nb: usize,
    rc: &'a RecCoeffs,
    rec: &'a Rec<'a>,
    lanes: &'a Lanes<'a>,
    cols: &'a [Vec<f64>],
}

/// Runs `f` on every case: bandwidths, orders and ring counts that leave chains of a group
/// unused on every vector width (odd vector counts with AVX2), and at B = 160 more than the
/// 16 vectors set up at once on AVX2 and AVX-512; every instruction set this CPU has.
fn parity_cases(mut f: impl FnMut(&ParityCase)) {
    let cases: [(usize, &[usize], &[usize]); 2] = [
        (40, &[0, 1, 7, 30, 39], &[40, 36, 24, 20, 12, 8]),
        (160, &[0, 3, 90], &[160, 152]),
    ];
    for (b, ms, rings) in cases {
        let grid = BetaTables::grid(b);
        let tables = RecTables::new(b);
        for &m in ms {
            for &nb_rings in rings {
                let ks: Vec<usize> = (0..nb_rings).map(|s| s * b / nb_rings).collect();
                let ClusterInputs {
                    coeffs: rc,
                    mut tau,
                    mut p,
                    mut sc,
                } = cluster_setup_at(b, m, 0, &ks);
                let rec = Rec::new(&rc, b - m);
                for isa in [Isa::Scalar, Isa::Avx2, Isa::Avx512] {
                    if !isa.is_supported() {
                        continue;
                    }
                    let cols: Vec<Vec<f64>> = ks
                        .iter()
                        .map(|&k| column(isa, &grid, &tables, k, (m, 0), b))
                        .collect();
                    let nb = nb_rings.next_multiple_of(isa.lanes());
                    for v in [&mut tau, &mut p, &mut sc] {
                        v.resize(nb, 0.0);
                    }
                    let mut lanes = grid_lanes(&tau, &p, &sc, nb);
                    (lanes.interleaved, lanes.stream) = (false, false);
                    f(&ParityCase {
                        b,
                        m,
                        isa,
                        rings: nb_rings,
                        nb,
                        rc: &rc,
                        rec: &rec,
                        lanes: &lanes,
                        cols: &cols,
                    });
                }
            }
        }
    }
}

/// The parity kernel (`m' = 0`, degrees alternating between the even and the odd sums)
/// gives what the general 8-column inverse kernel gives with each degree's coefficients
/// in the columns of its parity and zeros in the others (the same multiply-adds in the
/// same order, so to the bit up to the sign of zero), and the sums of the reference
/// columns of `wigner` to rounding (the skipped values are below the data's size times
/// the skip threshold): every instruction set, 2 and 4 columns, lane counts
/// that leave chains of a group unused.
#[test]
fn parity_kernel_sums_each_degree_into_its_parity() {
    use super::inverse_parity;
    parity_cases(|t| {
        let (isa, m, nb, n) = (t.isa, t.m, t.nb, t.b - t.m);
        for c in [2usize, 4] {
            let g = pseudo(n * c, 3 + m as u64);
            let fin: Vec<f64> = (0..n * c).map(|j| g[j] * t.rc.s[j / c]).collect();
            let mut y = vec![f64::NAN; 2 * c * nb];
            inverse_parity(isa, c, t.rec, t.lanes, &fin, &mut y);
            // The general kernel: column par * c + q of row i holds fin[i c + q] when
            // i % 2 == par.
            let mut rows = vec![0.0; n * 8];
            for i in 0..n {
                for q in 0..c {
                    rows[i * 8 + (i % 2) * c + q] = fin[i * c + q];
                }
            }
            let mut want = vec![0.0; nb * 8];
            inverse_from(isa, 8, t.rec, t.lanes, &rows, &mut want);
            for (s, col) in t.cols.iter().enumerate() {
                for j in 0..2 * c {
                    let (got, general) = (y[j * nb + s], want[s * 8 + j]);
                    assert!(
                        got == general,
                        "{isa:?} m={m} c={c} lane {s} column {j}: {got:e} {general:e}"
                    );
                    let (par, q) = (j / c, j % c);
                    let (mut sum, mut size) = (0.0, 0.0);
                    for i in (par..n).step_by(2) {
                        sum += col[i] * g[i * c + q];
                        size += (col[i] * g[i * c + q]).abs();
                    }
                    assert!(
                        (got - sum).abs() <= 1e-14 * size.max(1.0),
                        "{isa:?} m={m} c={c} lane {s} column {j}: {got:e} vs {sum:e}"
                    );
                }
            }
        }
    });
}

/// The forward parity kernel sums each degree over the lanes of its parity's columns: the
/// sums of the reference columns of `wigner` times the data, to rounding, on every
/// instruction set, with 2 and 4 columns, lane counts that leave chains unused, and the
/// rows past the degrees untouched by the contract (scratch).
#[test]
fn forward_parity_kernel_sums_each_degree_over_its_parity() {
    use super::{forward_parity, parity_partial_len};
    parity_cases(|t| {
        let (isa, m, nb, n, w) = (t.isa, t.m, t.nb, t.b - t.m, t.isa.lanes());
        for c in [2usize, 4] {
            // All lanes at once (every lane's share must reach the sums), then one lane at
            // a time, where each sum is that lane's term alone and a term sent to the
            // wrong parity or degree shows however small it is (skipped terms are below
            // 2^-64 of the data).
            let all = pseudo(2 * c * nb, 5 + m as u64);
            let singles = (0..t.rings).step_by(if t.b > 40 { 37 } else { 1 });
            for only in std::iter::once(None).chain(singles.map(Some)) {
                let mut x = all.clone();
                for col in 0..2 * c {
                    for s in 0..nb {
                        if s >= t.rings || only.is_some_and(|o| o != s) {
                            x[col * nb + s] = 0.0;
                        }
                    }
                }
                let mut part = vec![f64::NAN; parity_partial_len(n, c, w)];
                let mut ft = vec![f64::NAN; (n * c).next_multiple_of(w)];
                forward_parity(isa, c, t.rec, t.lanes, &x, (&mut part, &mut ft));
                for i in 0..n {
                    for q in 0..c {
                        let (mut sum, mut size) = (0.0, 0.0);
                        for (s, col) in t.cols.iter().enumerate() {
                            let term = col[i] * x[((i % 2) * c + q) * nb + s];
                            sum += term;
                            size += term.abs();
                        }
                        let got = ft[i * c + q] * t.rc.s[i];
                        let tol = if only.is_some() {
                            1e-10 * size + 1e-18
                        } else {
                            1e-12 * size.max(1.0)
                        };
                        assert!(
                            (got - sum).abs() <= tol,
                            "{isa:?} m={m} c={c} rings {} lane {only:?} degree {i} column {q}: {got:e} vs {sum:e}",
                            t.rings
                        );
                    }
                }
            }
        }
    });
}

/// The batched inverse against single calls, bit for bit, for `counts` transforms: every
/// output row (both store modes).
pub(super) fn batch_case<E: DwtElem>(
    isa: Isa,
    pw: usize,
    rec: &Rec<E>,
    lanes: &mut Lanes<E>,
    seed: u64,
) {
    use super::{inverse_batch_raw, inverse_tile_len};
    use super::{BatchRows, Prefetch};
    let (n, nbs, w) = (rec.len(), lanes.tau.len(), isa.lanes_of::<E>());
    let nan = E::from_f64(f64::NAN);
    for count in [1usize, 2, 3] {
        for stream in [false, true] {
            lanes.stream = stream;
            let fins: Vec<Vec<E>> = (0..count)
                .map(|t| {
                    pseudo(n * pw, seed + t as u64)
                        .into_iter()
                        .map(E::from_f64)
                        .collect()
                })
                .collect();
            let mut want = vec![nan; count * nbs * pw];
            for (t, f) in fins.iter().enumerate() {
                inverse_from(
                    isa,
                    pw,
                    rec,
                    lanes,
                    f,
                    &mut want[t * nbs * pw..][..nbs * pw],
                );
            }
            let mut buf = vec![nan; count * n * pw];
            let mut y = vec![nan; count * nbs * pw];
            let mut tile = vec![nan; inverse_tile_len(n, w)];
            let mut hints = vec![Prefetch::none(); count];
            let mut fill = |t: usize, rows: &mut [E], from: usize, to: usize| {
                rows[from * pw..to * pw].copy_from_slice(&fins[t][from * pw..to * pw]);
            };
            let fin = BatchRows {
                base: buf.as_mut_ptr(),
                dist: n * pw,
                count,
            };
            let out = BatchRows {
                base: y.as_mut_ptr(),
                dist: nbs * pw,
                count,
            };
            // SAFETY: `buf` holds `count` inputs of `n pw` values, `y` the `count` outputs
            // of `nbs` consecutive rows.
            unsafe {
                inverse_batch_raw(
                    isa,
                    pw,
                    (rec, lanes),
                    (fin, &mut fill, &mut hints),
                    &mut tile,
                    out,
                )
            };
            for (i, (u, v)) in y.iter().zip(&want).enumerate() {
                assert_eq!(
                    u.to_f64().to_bits(),
                    v.to_f64().to_bits(),
                    "{} {isa:?} P={pw} inverse x{count} at {i}",
                    E::NAME
                );
            }
        }
    }
}

/// A batch gives bitwise the results of single kernel calls: every instruction set, 8
/// and 16 columns, one to three transforms, on the layout cases, on clusters with more
/// vectors than one group (B = 96, 176 betas) or a single degree, without skipping, and on
/// an odd number of vectors in consecutive rows (one recurrence chain left alone).
#[test]
fn batched_kernels_equal_single_calls() {
    layout_cases(|isa, pw, m, rec, mut lanes| batch_case(isa, pw, rec, &mut lanes, m as u64));
    let b = 96;
    let ks: Vec<usize> = (0..40).map(|s| s * b / 40).collect();
    let ClusterInputs {
        coeffs: rc,
        tau,
        p,
        sc,
    } = cluster_setup_at(b, 7, 3, &ks);
    let rec = Rec::new(&rc, b - 7);
    for pw in [8usize, 16] {
        for isa in [Isa::Scalar, Isa::Avx2, Isa::Avx512] {
            if isa.is_supported() {
                let mut lanes = grid_lanes(&tau, &p, &sc, 40);
                lanes.interleaved = false;
                batch_case(isa, pw, &rec, &mut lanes, 3);
                lanes.skip = false;
                batch_case(isa, pw, &rec, &mut lanes, 4);
            }
        }
    }
    let nbs = 176;
    for &(m, mp) in &[(5usize, 2usize), (40, 17), (95, 95), (95, 0)] {
        let ClusterInputs {
            coeffs: rc,
            tau,
            p,
            sc,
        } = cluster_setup(b, m, mp, nbs);
        let rec = Rec::new(&rc, b - m);
        for pw in [8usize, 16] {
            for isa in [Isa::Scalar, Isa::Avx2, Isa::Avx512] {
                if isa.is_supported() {
                    let mut lanes = grid_lanes(&tau, &p, &sc, nbs / 2);
                    batch_case(isa, pw, &rec, &mut lanes, 7 + m as u64);
                }
            }
        }
    }
}
