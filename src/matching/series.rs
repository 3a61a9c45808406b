//! A band-limited function on SO(3) and its first two derivatives in the Euler angles,
//! evaluated from its coefficients at several rotations at once (for peak refinement).
//!
//! `C(alpha, beta, gamma) = sum_{M,M'} e^{-iM alpha} S_{M,M'}(beta) e^{-iM' gamma}` with the
//! beta sums `S_{M,M'}(beta) = sum_l fhat(l,M,M') (1/2pi) dt^l_{M,M'}(beta)`. The alpha and
//! gamma derivatives multiply by `-iM` and `-iM'`; the beta derivatives come from the
//! differentiated recurrence of the Wigner module ([`columns`]). One pass over the
//! coefficients serves every rotation of the batch: the rotations sit in the vector lanes,
//! as the betas do in the DWT kernels, and each coefficient, loaded once per cluster, feeds
//! every lane.

use crate::grid::block_start;
use crate::numeric::{Dd, Ext};
#[cfg(target_arch = "x86_64")]
use crate::simd::{avx2::Avx2, avx512::Avx512};
use crate::simd::{scalar::Scalar, Isa, Simd};
use crate::symmetry::Cluster;
use crate::wigner::derivatives::{columns, half_angles, Points};
use crate::wigner::{start_norms, RecCoeffs, RecTables};
use num_complex::Complex64;
use rayon::prelude::*;
use std::f64::consts::PI;

/// Value, gradient and Hessian of a series in `(alpha, beta, gamma)` at one rotation.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Local {
    /// The value.
    pub c: Complex64,
    /// First derivatives in `(alpha, beta, gamma)`.
    pub d: [Complex64; 3],
    /// Second derivatives.
    pub dd: [[Complex64; 3]; 3],
}

/// What evaluating a series needs besides its coefficients: per cluster the recurrence
/// coefficients, the norm of the starting values and where its members' coefficients are
/// (built once per shape, about `lmax^3 / 6` degrees of five doubles each).
pub(crate) struct SeriesTables {
    pub(crate) b: usize,
    pub(crate) lmax: usize,
    /// Clusters with base pair `(m, mp)` at `m(m+1)/2 + mp`.
    clusters: Vec<ClusterTable>,
    /// Start of each base order's clusters in the packed order, and the total (`lmax + 2`
    /// entries).
    row_packed: Vec<usize>,
}

/// One cluster's share of [`SeriesTables`].
struct ClusterTable {
    rec: RecCoeffs,
    norm: Ext,
    /// The members reading the base function at beta (`[0]`) and at pi - beta (`[1]`).
    groups: [Group; 2],
}

/// The (1, 2 or 4) members of a cluster that read the same column.
#[derive(Clone, Copy, Default)]
struct Group {
    len: usize,
    /// `(M, M')`
    orders: [(isize, isize); 4],
    /// Start of the member's coefficient block.
    block: [usize; 4],
    /// Start of the group's coefficients in the packed order (see [`SeriesTables::pack`]).
    packed: usize,
    /// The member's sign at degree `m`, over `2 pi`.
    factor: [f64; 4],
}

impl SeriesTables {
    /// Tables for coefficients of bandwidth `b`, degrees `<= lmax`.
    pub(crate) fn new(b: usize, lmax: usize) -> SeriesTables {
        assert!(lmax < b);
        let recurrence = RecTables::new(lmax + 1);
        let norms = start_norms(lmax + 1);
        // The clusters of base order `m`, their packed offsets from the row's start, and the
        // row's packed length.
        let row = |m: usize| {
            let n = lmax + 1 - m;
            let mut packed = 0;
            let tables: Vec<ClusterTable> = (0..=m)
                .map(|mp| {
                    let mut rec = RecCoeffs::new(n);
                    recurrence.coeffs(m, mp, &mut rec);
                    let mut groups = [Group::default(); 2];
                    for mem in Cluster::new(m, mp).members() {
                        let g = &mut groups[usize::from(mem.reversed)];
                        g.orders[g.len] = (mem.m, mem.mp);
                        g.block[g.len] = block_start(b, mem.m, mem.mp);
                        g.factor[g.len] = mem.sign_at(m) / (2.0 * PI);
                        g.len += 1;
                    }
                    for g in &mut groups {
                        g.packed = packed;
                        packed += g.len * n;
                    }
                    ClusterTable {
                        rec,
                        norm: norms[m * (m + 1) / 2 + mp],
                        groups,
                    }
                })
                .collect();
            (tables, packed)
        };
        // On a worker pool the rows are made by its threads.
        let rows: Vec<(Vec<ClusterTable>, usize)> = if rayon::current_thread_index().is_some() {
            (0..=lmax).into_par_iter().map(row).collect()
        } else {
            (0..=lmax).map(row).collect()
        };
        let mut clusters = Vec::with_capacity((lmax + 1) * (lmax + 2) / 2);
        let mut row_packed = Vec::with_capacity(lmax + 2);
        let mut packed = 0;
        for (tables, len) in rows {
            row_packed.push(packed);
            for mut t in tables {
                t.groups.iter_mut().for_each(|g| g.packed += packed);
                clusters.push(t);
            }
            packed += len;
        }
        row_packed.push(packed);
        SeriesTables {
            b,
            lmax,
            clusters,
            row_packed,
        }
    }

    /// The coefficients (`(4b^3 - b)/3` values, `so3CoefLoc` order) of degrees `<= lmax` in
    /// the order the evaluation reads them: cluster after cluster, group after group, and
    /// in a group degree after degree with the members side by side (one stream instead of
    /// up to eight short blocks per cluster). On a worker pool the rows are spread over its
    /// threads.
    pub(crate) fn pack(&self, coeffs: &[Complex64]) -> Vec<Complex64> {
        assert!(coeffs.len() == crate::num_coeffs(self.b));
        let mut packed = vec![Complex64::default(); self.row_packed[self.lmax + 1]];
        let mut rows = Vec::with_capacity(self.lmax + 1);
        let mut rest = &mut packed[..];
        for m in 0..=self.lmax {
            let (row, tail) = rest.split_at_mut(self.row_packed[m + 1] - self.row_packed[m]);
            rows.push((m, row));
            rest = tail;
        }
        let fill = |(m, row): (usize, &mut [Complex64])| {
            let n = self.lmax + 1 - m;
            let base = self.row_packed[m];
            for table in &self.clusters[m * (m + 1) / 2..][..m + 1] {
                for g in &table.groups {
                    let out = &mut row[g.packed - base..][..g.len * n];
                    for (j, &block) in g.block[..g.len].iter().enumerate() {
                        for (i, c) in coeffs[block..][..n].iter().enumerate() {
                            out[i * g.len + j] = *c;
                        }
                    }
                }
            }
        };
        if rayon::current_thread_index().is_some() {
            rows.into_par_iter().for_each(fill);
        } else {
            rows.into_iter().for_each(fill);
        }
        packed
    }

    /// Value, gradient and Hessian of the series with coefficients `packed` (from
    /// [`SeriesTables::pack`]) at every rotation `(alpha, beta, gamma)` of `points`, with
    /// the kernels of `isa` (supported by this CPU). On a worker pool the base orders are
    /// spread over its threads.
    pub(crate) fn evaluate(
        &self,
        isa: Isa,
        coeffs: &[Complex64],
        points: &[[f64; 3]],
    ) -> Vec<Local> {
        assert!(coeffs.len() == self.row_packed[self.lmax + 1] && isa.is_supported());
        if points.is_empty() {
            return Vec::new();
        }
        // Bounded buffers: at most `BATCH` rotations per pass.
        const BATCH: usize = 64;
        if points.len() > BATCH {
            return points
                .chunks(BATCH)
                .flat_map(|p| self.evaluate(isa, coeffs, p))
                .collect();
        }
        let lanes = Lanes::new(isa, self.lmax, points);
        let size = lanes.acc_len();
        // On a worker pool the base orders are dealt out round-robin (balancing the
        // rows' sizes) to one task per thread, each with its own accumulators.
        let tasks = if rayon::current_thread_index().is_some() {
            rayon::current_num_threads().min(self.lmax + 1)
        } else {
            1
        };
        let task = |t: usize| {
            let mut acc = vec![0.0; size];
            for m in (t..=self.lmax).step_by(tasks) {
                self.row_terms(&lanes, coeffs, m, &mut acc);
            }
            acc
        };
        let acc = if tasks > 1 {
            let parts: Vec<Vec<f64>> = (0..tasks).into_par_iter().map(task).collect();
            let mut sum = parts[0].clone();
            for part in &parts[1..] {
                sum.iter_mut().zip(part).for_each(|(x, y)| *x += y);
            }
            sum
        } else {
            task(0)
        };
        lanes.finish(&acc, points)
    }

    /// Adds the terms of the clusters with base order `m` to `acc`.
    fn row_terms(&self, lanes: &Lanes, coeffs: &[Complex64], m: usize, acc: &mut [f64]) {
        match lanes.isa {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: `evaluate` checked that the CPU supports the instruction set.
            Isa::Avx512 => unsafe { self.row_terms_avx512(lanes, coeffs, m, acc) },
            #[cfg(target_arch = "x86_64")]
            // SAFETY: as above.
            Isa::Avx2 => unsafe { self.row_terms_avx2(lanes, coeffs, m, acc) },
            _ => self.row_terms_in::<Scalar>(lanes, coeffs, m, acc),
        }
    }

    /// [`SeriesTables::row_terms_in`] compiled for AVX-512.
    ///
    /// # Safety
    /// The CPU supports AVX-512F and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx512f,fma")]
    unsafe fn row_terms_avx512(
        &self,
        lanes: &Lanes,
        coeffs: &[Complex64],
        m: usize,
        acc: &mut [f64],
    ) {
        self.row_terms_in::<Avx512>(lanes, coeffs, m, acc)
    }

    /// [`SeriesTables::row_terms_in`] compiled for AVX2 and FMA.
    ///
    /// # Safety
    /// The CPU supports AVX2 and FMA.
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,fma")]
    unsafe fn row_terms_avx2(
        &self,
        lanes: &Lanes,
        coeffs: &[Complex64],
        m: usize,
        acc: &mut [f64],
    ) {
        self.row_terms_in::<Avx2>(lanes, coeffs, m, acc)
    }

    #[inline(always)]
    fn row_terms_in<S: Simd<E = f64>>(
        &self,
        lanes: &Lanes,
        coeffs: &[Complex64],
        m: usize,
        acc: &mut [f64],
    ) {
        assert!(std::mem::size_of::<S::V>() / 8 == lanes.w);
        let n = self.lmax + 1 - m;
        let size = 3 * n * lanes.w;
        let mut scratch = vec![0.0; 2 * size];
        for (mp, table) in self.clusters[m * (m + 1) / 2..][..m + 1].iter().enumerate() {
            let [g0, g1] = &table.groups;
            let base = (m, mp, table.norm);
            for chunk in 0..lanes.chunks {
                let (s0, s1) = scratch.split_at_mut(size);
                // Group `k` reads the points `k padded + chunk w ..` (beta, then pi - beta),
                // the reversed one with the sign `(-1)^(l-m)`.
                let first = |k: usize| k * lanes.padded + chunk * lanes.w;
                let (isa, points, rec) = (lanes.isa, &lanes.points, &table.rec);
                // SAFETY: `S` is the instruction set this function was compiled for (the
                // callers' contract) and has `lanes.w` lanes (asserted); the scratch areas
                // hold `3 n w` doubles, the other lengths are checked inside.
                unsafe {
                    // With AVX2's 16 registers the two groups' recurrences go one after
                    // the other (side by side they spill); each lane's values are the same.
                    match (g0.len > 0, g1.len > 0) {
                        (true, true) if lanes.w == 4 => {
                            columns::<S, 1>(isa, points, base, rec, [first(0)], [false], [s0]);
                            columns::<S, 1>(isa, points, base, rec, [first(1)], [true], [s1]);
                        }
                        (true, true) => columns::<S, 2>(
                            isa,
                            points,
                            base,
                            rec,
                            [first(0), first(1)],
                            [false, true],
                            [s0, s1],
                        ),
                        (true, false) => {
                            columns::<S, 1>(isa, points, base, rec, [first(0)], [false], [s0])
                        }
                        (false, true) => {
                            columns::<S, 1>(isa, points, base, rec, [first(1)], [true], [s1])
                        }
                        (false, false) => {}
                    }
                    for (k, (group, s)) in [(g0, &*s0), (g1, &*s1)].into_iter().enumerate() {
                        if group.len > 0 {
                            group_terms::<S>(lanes, table, group, (chunk, k), coeffs, s, acc);
                        }
                    }
                }
            }
        }
    }
}

/// The rotations of one evaluation in vector lanes (`w` per chunk, the last chunk padded
/// with copies of the last rotation), and per lane what the recurrence needs.
struct Lanes {
    isa: Isa,
    w: usize,
    chunks: usize,
    /// Lanes in all (`chunks * w`).
    padded: usize,
    lmax: usize,
    /// The `2 * padded` points of the recurrence: beta of every lane, then pi - beta.
    points: Points,
    /// `e^{-i M' gamma}` of every lane, real parts then imaginary parts, at
    /// `((M' + lmax) * 2 + part) * padded + lane`.
    gamma_phase: Vec<f64>,
}

impl Lanes {
    fn new(isa: Isa, lmax: usize, points: &[[f64; 3]]) -> Lanes {
        let w = isa.lanes();
        let chunks = points.len().div_ceil(w);
        let padded = chunks * w;
        let at = |lane: usize| points[lane.min(points.len() - 1)];
        let mut half: Vec<(Dd, Dd)> = (0..padded).map(|lane| half_angles(at(lane)[1])).collect();
        // pi - beta without rounding: the half-angle cosine and sine swapped.
        let reversed: Vec<(Dd, Dd)> = half.iter().map(|&(c, s)| (s, c)).collect();
        half.extend(reversed);
        let beta_points = Points::new(&half, lmax);
        let top = lmax as isize;
        let mut gamma_phase = vec![0.0; (2 * lmax + 1) * 2 * padded];
        for (i, mp) in (-top..=top).enumerate() {
            for lane in 0..padded {
                let e = Complex64::from_polar(1.0, -(mp as f64) * at(lane)[2]);
                gamma_phase[(i * 2) * padded + lane] = e.re;
                gamma_phase[(i * 2 + 1) * padded + lane] = e.im;
            }
        }
        Lanes {
            isa,
            w,
            chunks,
            padded,
            lmax,
            points: beta_points,
            gamma_phase,
        }
    }

    /// Length of the accumulators: per order `M` six sums over `M'` (`S`, `M' S`,
    /// `M'^2 S`, `S'`, `M' S'`, `S''`, each with the gamma phase), real and imaginary
    /// parts, per lane: index `(((M + lmax) * 6 + q) * 2 + part) * padded + lane`.
    fn acc_len(&self) -> usize {
        (2 * self.lmax + 1) * 12 * self.padded
    }

    /// Value, gradient and Hessian per point from the accumulated sums.
    fn finish(&self, acc: &[f64], points: &[[f64; 3]]) -> Vec<Local> {
        let top = self.lmax as isize;
        let i = Complex64::new(0.0, 1.0);
        let get = |m: usize, q: usize, lane: usize| {
            let at = |part: usize| acc[((m * 6 + q) * 2 + part) * self.padded + lane];
            Complex64::new(at(0), at(1))
        };
        points
            .iter()
            .enumerate()
            .map(|(lane, p)| {
                let mut out = Local::default();
                for (row, m) in (-top..=top).enumerate() {
                    let [r0, r0g, r0gg, r1, r1g, r2] = std::array::from_fn(|q| get(row, q, lane));
                    let ea = Complex64::from_polar(1.0, -(m as f64) * p[0]);
                    let fm = m as f64;
                    // d/dalpha -> -i M, d/dgamma -> -i M' (the M' weights are in r0g, r0gg,
                    // r1g).
                    out.c += r0 * ea;
                    out.d[0] += r0 * ea * (-i * fm);
                    out.d[1] += r1 * ea;
                    out.d[2] += r0g * ea * (-i);
                    out.dd[0][0] += r0 * ea * (-fm * fm);
                    out.dd[0][1] += r1 * ea * (-i * fm);
                    out.dd[0][2] += r0g * ea * (-fm);
                    out.dd[1][1] += r2 * ea;
                    out.dd[1][2] += r1g * ea * (-i);
                    out.dd[2][2] -= r0gg * ea;
                }
                out.dd[1][0] = out.dd[0][1];
                out.dd[2][0] = out.dd[0][2];
                out.dd[2][1] = out.dd[1][2];
                out
            })
            .collect()
    }
}

/// The terms of one group of cluster `table` for the lanes of one chunk: the sums of its
/// column and the column's two derivatives (in `scratch`, from [`columns`]) against
/// each member's coefficients, and those with the gamma phases into the row sums `acc`.
///
/// # Safety
/// The CPU supports the instruction set of `S`.
#[inline(always)]
unsafe fn group_terms<S: Simd<E = f64>>(
    lanes: &Lanes,
    table: &ClusterTable,
    group: &Group,
    (chunk, k): (usize, usize),
    coeffs: &[Complex64],
    scratch: &[f64],
    acc: &mut [f64],
) {
    let w = lanes.w;
    let n = table.rec.len();
    assert!(scratch.len() == 3 * n * w && acc.len() == lanes.acc_len());
    let packed = &coeffs[group.packed..][..group.len * n];
    // SAFETY: the instruction set by the caller; `scratch` holds `3 n w` doubles and
    // `packed` `len n` coefficients (asserted and sliced above).
    let sums = unsafe {
        match group.len {
            4 => member_sums::<S, 4>(packed, scratch),
            2 => member_sums::<S, 2>(packed, scratch),
            _ => member_sums::<S, 1>(packed, scratch),
        }
    };
    let top = lanes.lmax as isize;
    let base = chunk * w;
    // SAFETY: every access below is at `base + lane < padded` in a row of length `padded`
    // (the phase and accumulator layouts of `Lanes`).
    unsafe {
        let ld = |v: &[f64], row: usize| S::load(v.as_ptr().add(row * lanes.padded + base));
        for (j, sum) in sums.iter().enumerate().take(group.len) {
            let (m, mp) = group.orders[j];
            let f = group.factor[j];
            // Members at pi - beta: the first beta derivative changes sign.
            let f1 = if k == 1 { -f } else { f };
            let g = ((mp + top) as usize) * 2;
            let (er, ei) = (ld(&lanes.gamma_phase, g), ld(&lanes.gamma_phase, g + 1));
            let x: [(S::V, S::V); 3] = std::array::from_fn(|d| {
                let fd = S::splat(if d == 1 { f1 } else { f });
                let (re, im) = (S::mul(sum[d].0, fd), S::mul(sum[d].1, fd));
                // (re + i im)(er + i ei)
                (
                    S::fms(re, er, S::mul(im, ei)),
                    S::fma(re, ei, S::mul(im, er)),
                )
            });
            let fmp = S::splat(mp as f64);
            let fmp2 = S::splat((mp * mp) as f64);
            let terms = [
                (x[0], None),
                (x[0], Some(fmp)),
                (x[0], Some(fmp2)),
                (x[1], None),
                (x[1], Some(fmp)),
                (x[2], None),
            ];
            let row = ((m + top) as usize) * 12;
            for (q, ((re, im), weight)) in terms.into_iter().enumerate() {
                for (part, v) in [re, im].into_iter().enumerate() {
                    let p = acc
                        .as_mut_ptr()
                        .add((row + q * 2 + part) * lanes.padded + base);
                    let old = S::load(p);
                    let new = match weight {
                        Some(wt) => S::fma(v, wt, old),
                        None => S::add(v, old),
                    };
                    S::store(p, new);
                }
            }
        }
    }
}

/// `sum_i c_j(i) column_d(i)` per lane for the `J` members `j` of a group, whose
/// coefficients `packed` hold degree after degree, the members side by side, and the three
/// orders `d`, as (real parts, imaginary parts).
///
/// # Safety
/// The CPU supports the instruction set of `S`; `packed` holds `J n` coefficients and
/// `scratch` `3 n w` doubles (`n` from the scratch length).
#[inline(always)]
unsafe fn member_sums<S: Simd<E = f64>, const J: usize>(
    packed: &[Complex64],
    scratch: &[f64],
) -> [[(S::V, S::V); 3]; 4] {
    let w = std::mem::size_of::<S::V>() / 8;
    let n = scratch.len() / (3 * w);
    assert!(packed.len() == J * n);
    // SAFETY: the instruction set by the caller; loads at `(3 i + d) w + w <= 3 n w`, and
    // coefficient `J i + j < J n`.
    unsafe {
        let mut acc = [[(S::zero(), S::zero()); 3]; 4];
        let c = packed.as_ptr().cast::<f64>();
        // The sums of members `js` (indices into `J`) in one pass over the degrees.
        let pass = |acc: &mut [[(S::V, S::V); 3]; 4], js: std::ops::Range<usize>| {
            for i in 0..n {
                let v: [S::V; 3] =
                    std::array::from_fn(|d| S::load(scratch.as_ptr().add((3 * i + d) * w)));
                for j in js.clone() {
                    let (re, im) = (
                        S::splat(*c.add(2 * (J * i + j))),
                        S::splat(*c.add(2 * (J * i + j) + 1)),
                    );
                    for (a, x) in acc[j].iter_mut().zip(v) {
                        a.0 = S::fma(re, x, a.0);
                        a.1 = S::fma(im, x, a.1);
                    }
                }
            }
        };
        if w == 4 {
            // AVX2's 16 registers hold one member's six sums beside the three values:
            // one member per pass, so that no sum is spilled.
            for j in 0..J {
                let mut one = [[(S::zero(), S::zero()); 3]; 4];
                pass(&mut one, j..j + 1);
                acc[j] = one[j];
            }
        } else {
            pass(&mut acc, 0..J);
        }
        acc
    }
}

#[cfg(test)]
mod tests {
    use super::{Local, SeriesTables};
    use crate::grid::coef_index;
    use crate::simd::Isa;
    use crate::wigner::wigner_d_column;
    use num_complex::Complex64;
    use std::f64::consts::PI;

    /// `d^l_{m,k}(beta)` (0 where `|k| > l`).
    fn d(l: usize, m: isize, k: isize, beta: f64) -> f64 {
        let lo = m.unsigned_abs().max(k.unsigned_abs());
        if l < lo {
            return 0.0;
        }
        wigner_d_column(m, k, l, beta)[l - lo]
    }

    /// The first and second beta derivatives of `d^l_{m,k}` by the ladder identity
    /// `d' = (sqrt((l+k)(l-k+1)) d_{k-1} - sqrt((l-k)(l+k+1)) d_{k+1}) / 2`, applied once
    /// and twice: independent of the differentiated recurrence.
    fn ladder(l: usize, m: isize, k: isize, beta: f64) -> (f64, f64) {
        let lf = l as f64;
        let up = |k: isize| ((lf + k as f64) * (lf - k as f64 + 1.0)).max(0.0).sqrt();
        let dn = |k: isize| ((lf - k as f64) * (lf + k as f64 + 1.0)).max(0.0).sqrt();
        let d1 = |k: isize| 0.5 * (up(k) * d(l, m, k - 1, beta) - dn(k) * d(l, m, k + 1, beta));
        (d1(k), 0.5 * (up(k) * d1(k - 1) - dn(k) * d1(k + 1)))
    }

    fn isas() -> Vec<Isa> {
        [Isa::Avx512, Isa::Avx2, Isa::Scalar]
            .into_iter()
            .filter(|i| i.is_supported())
            .collect()
    }

    /// A series of one term against that term's value and derivatives, for members of
    /// every kind (both columns, both parities), at points near and away from the poles
    /// and outside `[0, pi]`.
    #[test]
    fn one_term_matches_direct_values_and_ladder_derivatives() {
        let b = 24;
        let tables = SeriesTables::new(b, b - 1);
        let mut coeffs = vec![Complex64::default(); crate::num_coeffs(b)];
        let terms = [
            (0, 0, 0),
            (1, 1, 0),
            (5, -3, 2),
            (7, 2, -7),
            (13, -13, -1),
            (23, 4, 19),
            (23, -22, 23),
        ];
        let points = [
            [0.3, 1.1, 2.0],
            [5.0, 1e-7, 0.1],
            [1.0, PI - 1e-6, 4.0],
            [2.0, 2.5, -1.0],
            [0.7, -0.4, 0.2],
            [0.1, 3.6, 1.5],
            [0.0, 0.0, 0.0],
        ];
        let i = Complex64::new(0.0, 1.0);
        for isa in isas() {
            for &(l, m, mp) in &terms {
                let at = coef_index(b, l, m, mp);
                coeffs[at] = Complex64::new(0.6, -0.8);
                let got = tables.evaluate(isa, &tables.pack(&coeffs), &points);
                for (p, g) in points.iter().zip(&got) {
                    let [alpha, beta, gamma] = *p;
                    let (fm, fmp) = (m as f64, mp as f64);
                    let n = coeffs[at] * (((2 * l + 1) as f64 / 2.0).sqrt() / (2.0 * PI));
                    let e = Complex64::from_polar(1.0, -fm * alpha - fmp * gamma);
                    let (d1, d2) = ladder(l, m, mp, beta);
                    let v = [d(l, m, mp, beta), d1, d2].map(|x| n * e * x);
                    let want = Local {
                        c: v[0],
                        d: [-i * fm * v[0], v[1], -i * fmp * v[0]],
                        dd: [
                            [-fm * fm * v[0], -i * fm * v[1], -fm * fmp * v[0]],
                            [-i * fm * v[1], v[2], -i * fmp * v[1]],
                            [-fm * fmp * v[0], -i * fmp * v[1], -fmp * fmp * v[0]],
                        ],
                    };
                    // Derivatives grow like l and l^2.
                    let tol = 1e-13 * (1 + l * l) as f64;
                    let close = |a: Complex64, b: Complex64, what: &str| {
                        assert!(
                            (a - b).norm() < tol,
                            "{isa:?} l={l} ({m},{mp}) at {p:?}: {what} {a} vs {b}"
                        )
                    };
                    close(g.c, want.c, "value");
                    for r in 0..3 {
                        close(g.d[r], want.d[r], "gradient");
                        for c in 0..3 {
                            close(g.dd[r][c], want.dd[r][c], "Hessian");
                        }
                    }
                }
                coeffs[at] = Complex64::default();
            }
        }
    }

    /// A batch of rotations gives each rotation exactly what it gets alone.
    #[test]
    fn batches_equal_single_evaluations() {
        let b = 16;
        let tables = SeriesTables::new(b, b - 1);
        let coeffs: Vec<Complex64> = (0..crate::num_coeffs(b))
            .map(|k| Complex64::new((k as f64 * 0.37).sin(), (k as f64 * 0.11).cos()))
            .collect();
        let points: Vec<[f64; 3]> = (0..11)
            .map(|k| [0.5 * k as f64, 0.29 * k as f64 + 0.01, 1.0 - 0.3 * k as f64])
            .collect();
        for isa in isas() {
            let packed = tables.pack(&coeffs);
            let all = tables.evaluate(isa, &packed, &points);
            for (p, g) in points.iter().zip(&all) {
                let one = tables.evaluate(isa, &packed, std::slice::from_ref(p))[0];
                assert_eq!(format!("{one:?}"), format!("{g:?}"), "{isa:?} at {p:?}");
            }
        }
    }
}
