//! Accuracy of the recurrence in f32 (stage 0a of the single-precision tier, see
//! `notes/single-precision-plan.md`): the f32 twin of `column` (`column_in::<f32>`: f32
//! scaled starting values, coefficients narrowed from the f64 ones, f32 `tau`, f32 fused
//! multiply-adds, rescaling by `tiny::<f32>()`) against the f64 column, per cluster over
//! every grid beta and degree; beside it a variant of the step (the "delta form", below).
//! The study itself is `#[ignore]`d: `cargo test --release --lib f32_accuracy -- --ignored
//! --nocapture`; results in `notes/reference/f32_recurrence/rust-twin.md`.

use super::column::column_in;
use super::recurrence::{RecCoeffs, RecTables};
use super::starts::SKIP_BITS_RANGE;
use super::starts::{big, start_norm, tiny, BaseStart, BetaTables, DEFAULT_SKIP_BITS};
use crate::grid::weights;
use crate::numeric::Ext;

/// The f32 recurrence in the "delta form": the multiplier less 2 (lower half,
/// `t - 2 = (A' + C' - 2) - A' tau`) or plus 2 (upper half, `t + 2 = A' tau + (C' - A' + 2)`),
/// with the shifted offsets rounded to f32 from the f64 ones, and the step
/// `p2 = (t -+ 2) p1 + (+-2 p1 - p0)` (three fused operations instead of two). Near the
/// poles, where `t` is close to `+-2`, the rounding errors of the coefficients and of the
/// multiplier then scale with `|t -+ 2|` instead of 2. Otherwise as `column_in::<f32>`
/// (fused, skip threshold `2^-bits`).
fn column_delta_f32(
    betas: &BetaTables,
    k: usize,
    (m, mp, norm): (usize, usize, Ext),
    c64: &RecCoeffs<f64>,
    c32: &RecCoeffs<f32>,
    bits: u32,
) -> Vec<f32> {
    let n = c64.len();
    let base = BaseStart::new(m, mp, norm, bits);
    let (start, mut scale_index) = betas.start::<f32>(k, &base, 1.0);
    let upper = betas.upper(k);
    let (tau, slope, two) = if upper {
        (betas.tau_hi[k], &c32.a, -2.0f32)
    } else {
        (betas.tau_lo[k], &c32.neg_a, 2.0f32)
    };
    let offset: Vec<f32> = if upper {
        c64.c_minus_a.iter().map(|&x| (x + 2.0) as f32).collect()
    } else {
        c64.a_plus_c.iter().map(|&x| (x - 2.0) as f32).collect()
    };
    let tau = tau as f32;
    let (threshold, tiny) = (big::<f32>(bits), tiny::<f32>());
    let mut active = scale_index >= 0.0 && start.abs() >= f32::MIN_POSITIVE;
    let (mut prev, mut cur) = (0.0f32, start);
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let value = if active { cur } else { 0.0 };
        out.push((value + 0.0) * c32.s[i]);
        let shifted = slope[i].mul_add(tau, offset[i]);
        let next = shifted.mul_add(cur, two.mul_add(cur, -prev));
        (prev, cur) = (cur, next);
        if scale_index < 0.0 && cur.abs() >= threshold {
            prev *= tiny;
            cur *= tiny;
            scale_index += 1.0;
            active = scale_index >= 0.0;
        }
    }
    out
}

/// Relative errors of one cluster's values against the f64 ones.
#[derive(Clone, Copy, Debug, Default)]
struct Errors {
    /// Relative L2 error over all betas and degrees.
    l2: f64,
    /// The same with each beta weighted by its quadrature weight (what a transform sees:
    /// the round trip's coefficient error is bounded by this norm of the value errors).
    weighted: f64,
    /// Largest relative L2 error of one degree over the betas (degrees whose norm is at
    /// least 1e-3 of the largest one).
    worst_degree: f64,
    /// Relative L2 error of the cluster's round trip (inverse then forward, sums in f64)
    /// of fixed pseudo-random coefficients, with these values in both directions.
    roundtrip: f64,
}

/// Sums of squares for [`Errors`].
struct Sums {
    num: f64,
    den: f64,
    wnum: f64,
    wden: f64,
    row_num: Vec<f64>,
    row_den: Vec<f64>,
}

impl Sums {
    fn new(n: usize) -> Sums {
        Sums {
            num: 0.0,
            den: 0.0,
            wnum: 0.0,
            wden: 0.0,
            row_num: vec![0.0; n],
            row_den: vec![0.0; n],
        }
    }

    /// Add one beta's values `got` against `want`, weight `w`.
    fn add(&mut self, want: &[f64], got: impl Iterator<Item = f64>, w: f64) {
        for (i, (&x, y)) in want.iter().zip(got).enumerate() {
            let (e2, x2) = ((y - x).powi(2), x * x);
            self.num += e2;
            self.den += x2;
            self.wnum += w * e2;
            self.wden += w * x2;
            self.row_num[i] += e2;
            self.row_den[i] += x2;
        }
    }

    fn errors(&self, roundtrip: f64) -> Errors {
        let top = self.row_den.iter().cloned().fold(0.0, f64::max);
        let worst_degree = self
            .row_num
            .iter()
            .zip(&self.row_den)
            .filter(|(_, &d)| d >= 1e-6 * top)
            .map(|(e, d)| (e / d).sqrt())
            .fold(0.0, f64::max);
        Errors {
            l2: (self.num / self.den).sqrt(),
            weighted: (self.wnum / self.wden).sqrt(),
            worst_degree,
            roundtrip,
        }
    }
}

/// Relative L2 error of `c -> forward(inverse(c))` for one cluster: `cols[k]` the values of
/// every degree at beta `k`, `w` the quadrature weights, `c` the coefficients.
fn roundtrip(cols: &[Vec<f64>], w: &[f64], c: &[f64]) -> f64 {
    let mut back = vec![0.0; c.len()];
    for (col, &wk) in cols.iter().zip(w) {
        let f: f64 = col.iter().zip(c).map(|(d, c)| d * c).sum();
        for (b, d) in back.iter_mut().zip(col) {
            *b += wk * d * f;
        }
    }
    let num: f64 = back.iter().zip(c).map(|(b, c)| (b - c).powi(2)).sum();
    let den: f64 = c.iter().map(|c| c * c).sum();
    (num / den).sqrt()
}

/// Errors of one cluster: the f32 recurrence, its delta form, and the f64 values rounded
/// to f32 (the floor of the "mixed" scheme: f64 recurrence, f32 data).
#[derive(Clone, Copy, Debug)]
struct ClusterError {
    single: Errors,
    delta: Errors,
    rounded: Errors,
}

/// Tables of one bandwidth shared by its clusters.
struct Bandwidth {
    b: usize,
    betas: BetaTables,
    rec: RecTables,
    weights: Vec<f64>,
}

impl Bandwidth {
    fn new(b: usize) -> Bandwidth {
        Bandwidth {
            b,
            betas: BetaTables::grid(b),
            rec: RecTables::new(b),
            weights: weights(b),
        }
    }

    /// The f32 recurrences of base pair `(m, mp)` at every grid beta (degrees `m .. b`)
    /// at the default threshold (`2^-64`, as the kernels run them), against the f64 one at
    /// the widest threshold.
    fn error(&self, m: usize, mp: usize) -> ClusterError {
        let n = self.b - m;
        let mut c64 = RecCoeffs::<f64>::new(n);
        self.rec.coeffs(m, mp, &mut c64);
        let mut c32 = RecCoeffs::<f32>::default();
        c32.narrow_from(&c64);
        let base = (m, mp, start_norm(m, mp));
        let bits64 = *SKIP_BITS_RANGE.end();
        let [mut single, mut delta, mut rounded] = [Sums::new(n), Sums::new(n), Sums::new(n)];
        let widen = |v: Vec<f32>| -> Vec<f64> { v.into_iter().map(f64::from).collect() };
        let (mut cols32, mut cols_delta, mut cols_rounded) = (vec![], vec![], vec![]);
        for (k, &w) in self.weights.iter().enumerate() {
            let d64 = column_in::<f64>(true, &self.betas, k, base, &c64, bits64);
            let d32 = column_in::<f32>(true, &self.betas, k, base, &c32, DEFAULT_SKIP_BITS);
            let dd = column_delta_f32(&self.betas, k, base, &c64, &c32, DEFAULT_SKIP_BITS);
            let (d32, dd) = (widen(d32), widen(dd));
            let dr: Vec<f64> = d64.iter().map(|&y| y as f32 as f64).collect();
            single.add(&d64, d32.iter().copied(), w);
            delta.add(&d64, dd.iter().copied(), w);
            rounded.add(&d64, dr.iter().copied(), w);
            cols32.push(d32);
            cols_delta.push(dd);
            cols_rounded.push(dr);
        }
        // Coefficients uniform in [-1, 1) (a fixed linear congruential sequence).
        let mut state = 0x9e37_79b9_7f4a_7c15u64 ^ (m * 4099 + mp) as u64;
        let c: Vec<f64> = (0..n)
            .map(|_| {
                state = state
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                (state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
            })
            .collect();
        let w = &self.weights;
        ClusterError {
            single: single.errors(roundtrip(&cols32, w, &c)),
            delta: delta.errors(roundtrip(&cols_delta, w, &c)),
            rounded: rounded.errors(roundtrip(&cols_rounded, w, &c)),
        }
    }
}

/// The sampled clusters of bandwidth `b`: every `m <= 16`, then every `b/64`-th (and
/// `b/16 +- 1`, `b - 2`, `b - 1`), each with `m'` at 0, 1, 2, `m/2` and `m - d` for
/// `d` in 0..4, 6, 8, 12, 16, 24, 32, 48, ... (the near-diagonal band densely).
fn sample(b: usize) -> Vec<(usize, usize)> {
    let mut ms: Vec<usize> = (0..=16).collect();
    ms.extend((16..b).step_by((b / 64).max(1)));
    ms.extend([b / 16 - 1, b / 16, b / 16 + 1, b - 2, b - 1]);
    ms.retain(|&m| m < b);
    ms.sort();
    ms.dedup();
    let mut ds = vec![0, 1, 2, 3, 4, 6];
    let mut d = 8;
    while d < b {
        ds.extend([d, d + d / 2]);
        d *= 2;
    }
    let mut out = Vec::new();
    for m in ms {
        let mut mps = vec![0, 1, 2, m / 2];
        mps.extend(ds.iter().filter(|&&d| d <= m).map(|d| m - d));
        mps.retain(|&mp| mp <= m);
        mps.sort();
        mps.dedup();
        out.extend(mps.into_iter().map(|mp| (m, mp)));
    }
    out
}

/// The f32 recurrence stays close to the f64 one at a small bandwidth, above the floor of
/// rounding the f64 values, with the errors the study finds (low orders the worst).
#[test]
fn f32_recurrence_is_close_at_small_bandwidth() {
    let bw = Bandwidth::new(64);
    for (m, mp) in [
        (0, 0),
        (1, 0),
        (2, 2),
        (8, 3),
        (20, 20),
        (40, 10),
        (63, 0),
        (63, 63),
    ] {
        let e = bw.error(m, mp);
        let what = format!("({m}, {mp}): {e:?}");
        assert!(e.single.weighted < 5e-6 && e.single.l2 < 2e-5, "{what}");
        assert!(e.delta.weighted < 5e-6 && e.delta.l2 < 2e-5, "{what}");
        // (At m = 63 the only degree is the starting value: the rounded f64 one.)
        assert!(e.rounded.l2 < 4e-8 && e.single.l2 >= e.rounded.l2, "{what}");
        // The round trip with the rounded f64 values, near f32 precision; the f32 ones
        // within a few times their value error.
        assert!(e.rounded.roundtrip < 1e-7, "{what}");
        assert!(
            e.single.roundtrip < 4.0 * e.single.weighted + 1e-7,
            "{what}"
        );
    }
}

/// Stage 0a: the tables of `rust-twin.md`. Bandwidths from `SO3FFT_F32_B` (comma-separated;
/// default 128, 256, 512, 1024). One row per cluster.
#[test]
#[ignore = "study: about a minute; run with --ignored --nocapture"]
fn f32_recurrence_accuracy_study() {
    let bs: Vec<usize> = std::env::var("SO3FFT_F32_B")
        .ok()
        .map(|s| s.split(',').map(|x| x.trim().parse().unwrap()).collect())
        .unwrap_or(vec![128, 256, 512, 1024]);
    println!(
        "B,m,mp,single_l2,single_weighted,single_worst_degree,single_roundtrip,\
         delta_l2,delta_weighted,delta_worst_degree,delta_roundtrip,rounded_l2,rounded_roundtrip"
    );
    for b in bs {
        let bw = Bandwidth::new(b);
        for (m, mp) in sample(b) {
            let e = bw.error(m, mp);
            println!(
                "{b},{m},{mp},{:.3e},{:.3e},{:.3e},{:.3e},{:.3e},{:.3e},{:.3e},{:.3e},{:.3e},{:.3e}",
                e.single.l2,
                e.single.weighted,
                e.single.worst_degree,
                e.single.roundtrip,
                e.delta.l2,
                e.delta.weighted,
                e.delta.worst_degree,
                e.delta.roundtrip,
                e.rounded.l2,
                e.rounded.roundtrip
            );
        }
    }
}
