//! Discrete Wigner transform kernels: the Wigner-d recurrence fused with the accumulation.
//!
//! One call handles one cluster (see `symmetry.rs`) and a list of beta points. The
//! recurrence runs in registers, vectorised over `W` betas; nothing of size
//! `(B - m) x 2B` is ever stored.
//!
//! * forward: `f[i][q] += sum_s dt_{l0+i}(beta_s) * xin[row(s)][q]` (`P` real columns `q`)
//! * inverse: `y[row(s)][q] = sum_i dt_{l0+i}(beta_s) * fin[i][q]`
//!
//! where `row(s)` is `s` or, for the chunk buffer's blocks, interleaves each beta with its
//! mirror ([`Lanes::interleaved`]).
//!
//! `P` is 16 (8 complex order pairs) or 8 (4 pairs). Each beta lane starts in the scaled
//! form of `wigner.rs`; lanes below the skip threshold contribute nothing, and while no lane
//! of a vector is active only the recurrence runs (the negligible prefix in `l` is skipped).

use crate::simd::{Isa, Scalar, Simd};
use crate::wigner::{BetaTables, Ext, RecCoeffs, RecTables, DEFAULT_SKIP_BITS, TINY};

/// Recurrence coefficients of one cluster, index `i = l - l0` (see `RecTables::coeffs`).
pub(crate) struct Rec<'a> {
    /// `A_l`
    pub a: &'a [f64],
    /// `-A_l`
    pub an: &'a [f64],
    /// `A_l + C_l`
    pub d: &'a [f64],
    /// `C_l - A_l`
    pub e: &'a [f64],
    /// `Bc_l`
    pub bb: &'a [f64],
}

impl<'a> Rec<'a> {
    /// The first `n` degrees of `r`.
    pub fn new(r: &'a RecCoeffs, n: usize) -> Rec<'a> {
        Rec {
            a: &r.a[..n],
            an: &r.an[..n],
            d: &r.d[..n],
            e: &r.e[..n],
            bb: &r.bb[..n],
        }
    }

    fn len(&self) -> usize {
        self.a.len()
    }
}

/// Per-lane inputs: recurrence argument `tau`, scaled starting value and scale index.
/// Lengths are a multiple of the vector width (pad with zeros). Vectors starting before
/// `upper_from` are in the lower half (`beta < pi/2`, `tau = 1 - cos beta`), the others in
/// the upper half (`tau = 1 + cos beta`): the recurrence multiplier `A cos(beta) + C` is
/// formed as `(A + C) - A tau` or `A tau + (C - A)`, never from a rounded `cos(beta)`,
/// which near the poles would shift beta and move `d^l` by up to `l^2 eps`.
pub(crate) struct Lanes<'a> {
    pub tau: &'a [f64],
    pub p: &'a [f64],
    pub sc: &'a [f64],
    pub upper_from: usize,
    /// Rescale threshold of the scaled values, `wigner::big(skip bits)`.
    pub big: f64,
    /// Skip the degrees where no lane of a vector is active yet (`false` only to measure
    /// what skipping saves: inactive lanes then accumulate exact zeros).
    pub skip: bool,
    /// Row of lane `u` in the data arrays: `u`, or, interleaved, `2u` for `u < upper_from`
    /// and `2(u - upper_from) + 1` above (the lanes count `2 upper_from`), so that lanes
    /// `u` and `u + upper_from` (a beta and its mirror, see `plan/blocks.rs`) are adjacent.
    pub interleaved: bool,
}

impl Lanes<'_> {
    /// First row and row step (in rows) of the vector of lanes starting at `s0`.
    #[inline(always)]
    fn rows(&self, s0: usize) -> (usize, usize) {
        if !self.interleaved {
            (s0, 1)
        } else if s0 < self.upper_from {
            (2 * s0, 2)
        } else {
            (2 * (s0 - self.upper_from) + 1, 2)
        }
    }
}

/// Recurrence state of one vector of betas.
#[derive(Clone, Copy)]
struct State<'r, S: Simd, const W: usize> {
    tau: S::V,
    /// `-A` (lower half) or `A` (upper half).
    ka: &'r [f64],
    /// `A + C` (lower half) or `C - A` (upper half).
    kc: &'r [f64],
    p0: S::V,
    p1: S::V,
    sc: [f64; W],
    mask: [f64; W],
    active: usize,
    /// Next degree index (`l - l0`).
    i: usize,
    /// Rescale threshold (see [`Lanes::big`]).
    big: f64,
    /// See [`Lanes::skip`].
    skip: bool,
}

impl<'r, S: Simd, const W: usize> State<'r, S, W> {
    #[inline(always)]
    unsafe fn new(rec: &Rec<'r>, lanes: &Lanes, s0: usize) -> Self {
        let mut sc = [0.0; W];
        sc.copy_from_slice(&lanes.sc[s0..s0 + W]);
        let mut mask = [0.0; W];
        let mut active = 0;
        for w in 0..W {
            if sc[w] == 0.0 {
                mask[w] = 1.0;
                active += 1;
            }
        }
        let (ka, kc) = if s0 >= lanes.upper_from {
            (rec.a, rec.e)
        } else {
            (rec.an, rec.d)
        };
        State {
            tau: S::load(lanes.tau.as_ptr().add(s0)),
            ka,
            kc,
            p0: S::zero(),
            p1: S::load(lanes.p.as_ptr().add(s0)),
            sc,
            mask,
            active,
            i: 0,
            big: lanes.big,
            skip: lanes.skip,
        }
    }

    /// Advance from degree `l0+i` to `l0+i+1`.
    #[inline(always)]
    ///
    /// # Safety
    /// `i < rec.len()` (all coefficient slices have that length, checked by the entry points).
    unsafe fn step(&mut self, rec: &Rec, i: usize) {
        debug_assert!(i < self.ka.len() && i < self.kc.len() && i < rec.bb.len());
        let t = S::fma(
            S::splat(*self.ka.get_unchecked(i)),
            self.tau,
            S::splat(*self.kc.get_unchecked(i)),
        );
        let u = S::mul(S::splat(*rec.bb.get_unchecked(i)), self.p0);
        let p2 = S::fms(t, self.p1, u);
        self.p0 = self.p1;
        self.p1 = p2;
    }

    /// Rescale lanes that grew past `big` (rare: at most once per `2^600` of growth).
    #[inline(never)]
    unsafe fn rescale(&mut self) {
        let mut a0 = [0.0; W];
        let mut a1 = [0.0; W];
        S::store(a0.as_mut_ptr(), self.p0);
        S::store(a1.as_mut_ptr(), self.p1);
        for w in 0..W {
            if self.sc[w] < 0.0 && a1[w].abs() >= self.big {
                a0[w] *= TINY;
                a1[w] *= TINY;
                self.sc[w] += 1.0;
                if self.sc[w] == 0.0 {
                    self.mask[w] = 1.0;
                    self.active += 1;
                }
            }
        }
        self.p0 = S::load(a0.as_ptr());
        self.p1 = S::load(a1.as_ptr());
    }

    /// Run the remaining degrees up to `n`, calling `acc(v, i)` with the value vector at
    /// each degree from the first one where some lane is active.
    #[inline(always)]
    unsafe fn run(&mut self, rec: &Rec, n: usize, mut acc: impl FnMut(S::V, usize)) {
        let mut i = self.i;
        // Slow phase: some lanes still scaled down.
        while i < n && self.active < W {
            let accumulate = self.active > 0 || !self.skip;
            let v = S::mul(self.p1, S::load(self.mask.as_ptr()));
            self.step(rec, i);
            self.p1 = S::fence(self.p1);
            if accumulate {
                acc(v, i);
            }
            i += 1;
            if S::any_abs_ge(self.p1, self.big) {
                self.rescale();
            }
        }
        // Fast phase: all lanes hold true values. The step to the next degree comes first
        // in program order: the FMA pipes issue the oldest ready instruction, so a step
        // placed after the accumulation would queue behind it and put its latency on the
        // critical path at every degree (measured: 13.4 against 10.7 cycles per degree).
        while i < n {
            let v = self.p1;
            self.step(rec, i);
            self.p1 = S::fence(self.p1);
            acc(v, i);
            i += 1;
        }
        self.i = i;
    }
}

/// Vectors whose recurrences are advanced together through their negligible prefix.
const GROUP: usize = 4;

/// Advance every state of `st` through the degrees where none of its lanes is active yet.
///
/// That prefix needs only the recurrence, whose one-FMA-per-degree dependency chain would
/// leave a lone vector latency-bound; interleaving `GROUP` independent chains keeps the
/// floating-point pipes busy.
#[inline(always)]
unsafe fn skip_inactive<S: Simd, const W: usize>(
    st: &mut [State<'_, S, W>; GROUP],
    rec: &Rec,
    n: usize,
) {
    loop {
        let mut any = false;
        for s in st.iter_mut() {
            if s.active == 0 && s.i < n {
                s.step(rec, s.i);
                s.i += 1;
                if S::any_abs_ge(s.p1, s.big) {
                    s.rescale();
                }
                any = true;
            }
        }
        if !any {
            break;
        }
    }
}

/// Lane offsets of the vectors processed together, starting at `s0` (unused entries
/// repeat the last vector and are marked done).
#[inline(always)]
unsafe fn group_states<'r, S: Simd, const W: usize>(
    rec: &Rec<'r>,
    lanes: &Lanes,
    s0: usize,
    nb: usize,
    n: usize,
) -> (usize, [State<'r, S, W>; GROUP]) {
    let g = ((nb - s0) / W).min(GROUP);
    // Written out rather than `std::array::from_fn`, which is not inlined into the
    // `target_feature` entry points and so would call the SIMD loads out of line.
    let at = |j: usize| s0 + j.min(g - 1) * W;
    let mut st: [State<'r, S, W>; GROUP] = [
        State::new(rec, lanes, at(0)),
        State::new(rec, lanes, at(1)),
        State::new(rec, lanes, at(2)),
        State::new(rec, lanes, at(3)),
    ];
    for s in st.iter_mut().skip(g) {
        s.i = n;
    }
    if lanes.skip {
        skip_inactive(&mut st, rec, n);
    }
    (g, st)
}

#[inline(always)]
unsafe fn forward_body<S: Simd, const W: usize, const NV: usize>(
    rec: &Rec,
    lanes: &Lanes,
    xin: &[f64],
    f: &mut [f64],
) {
    let p = W * NV;
    let n = rec.len();
    let nb = lanes.tau.len();
    debug_assert!(nb.is_multiple_of(W) && xin.len() >= nb * p && f.len() >= n * p);
    let fp = f.as_mut_ptr();
    let mut g0 = 0;
    while g0 < nb {
        let (g, group) = group_states::<S, W>(rec, lanes, g0, nb, n);
        for (gi, st) in group.iter().enumerate().take(g) {
            // A local copy, so the state lives in registers during the run.
            let mut st = *st;
            let s0 = g0 + gi * W;
            let (r0, step) = lanes.rows(s0);
            let mut xr = [[S::zero(); NV]; W];
            for (w, row) in xr.iter_mut().enumerate() {
                for (j, v) in row.iter_mut().enumerate() {
                    *v = S::load(xin.as_ptr().add((r0 + w * step) * p + j * W));
                }
            }
            st.run(
                rec,
                n,
                #[inline(always)]
                |v, i| {
                    let row = fp.add(i * p);
                    let mut acc0 = [S::zero(); NV];
                    let mut acc1 = [S::zero(); NV];
                    for (j, a) in acc0.iter_mut().enumerate() {
                        *a = S::load(row.add(j * W));
                    }
                    let mut w = 0;
                    while w < W {
                        let t = S::lane(v, w);
                        for j in 0..NV {
                            acc0[j] = S::fma(t, xr[w][j], acc0[j]);
                        }
                        if w + 1 < W {
                            let t = S::lane(v, w + 1);
                            for j in 0..NV {
                                acc1[j] = S::fma(t, xr[w + 1][j], acc1[j]);
                            }
                        }
                        w += 2;
                    }
                    for j in 0..NV {
                        S::store(row.add(j * W), S::add(acc0[j], acc1[j]));
                    }
                },
            );
        }
        g0 += g * W;
    }
}

#[inline(always)]
unsafe fn inverse_body<S: Simd, const W: usize, const P: usize>(
    rec: &Rec,
    lanes: &Lanes,
    fin: &[f64],
    y: &mut [f64],
) {
    let n = rec.len();
    let nb = lanes.tau.len();
    debug_assert!(nb.is_multiple_of(W) && fin.len() >= n * P && y.len() >= nb * P);
    let fp = fin.as_ptr();
    let mut g0 = 0;
    while g0 < nb {
        let (g, group) = group_states::<S, W>(rec, lanes, g0, nb, n);
        for (gi, st) in group.iter().enumerate().take(g) {
            // A local copy, so the state lives in registers during the run.
            let mut st = *st;
            let s0 = g0 + gi * W;
            let mut acc = [S::zero(); P];
            st.run(
                rec,
                n,
                #[inline(always)]
                |v, i| {
                    let row = fp.add(i * P);
                    for (q, a) in acc.iter_mut().enumerate() {
                        *a = S::fma(v, S::splat(*row.add(q)), *a);
                    }
                },
            );
            // Rows of the output are lanes: each W x W block of (order column, lane) is
            // transposed in registers on the way out.
            let (r0, step) = lanes.rows(s0);
            for q0 in (0..P).step_by(W) {
                let dst = y.as_mut_ptr().add(r0 * P + q0);
                S::store_transposed(&acc[q0..q0 + W], dst, step * P);
            }
        }
        g0 += g * W;
    }
}

macro_rules! entry {
    ($name:ident, $feat:literal, $body:ident, $S:ty, $W:literal, $N:literal) => {
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = $feat)]
        unsafe fn $name(rec: &Rec, lanes: &Lanes, a: &[f64], b: &mut [f64]) {
            $body::<$S, $W, $N>(rec, lanes, a, b)
        }
    };
}

#[cfg(target_arch = "x86_64")]
use crate::simd::{Avx2, Avx512};

entry!(fwd_avx512_16, "avx512f,fma", forward_body, Avx512, 8, 2);
entry!(fwd_avx512_8, "avx512f,fma", forward_body, Avx512, 8, 1);
entry!(fwd_avx2_16, "avx2,fma", forward_body, Avx2, 4, 4);
entry!(fwd_avx2_8, "avx2,fma", forward_body, Avx2, 4, 2);
entry!(inv_avx512_16, "avx512f,fma", inverse_body, Avx512, 8, 16);
entry!(inv_avx512_8, "avx512f,fma", inverse_body, Avx512, 8, 8);
entry!(inv_avx2_16, "avx2,fma", inverse_body, Avx2, 4, 16);
entry!(inv_avx2_8, "avx2,fma", inverse_body, Avx2, 4, 8);

/// Forward kernel: `f[i*P + q] += sum_s dt_{l0+i}(beta_s) xin[row(s)*P + q]`, `P` = 8 or 16
/// (`row` see [`Lanes::interleaved`]).
///
/// `isa` must be supported by this CPU ([`Isa::is_supported`]), and the lane arrays'
/// length a multiple of `isa.lanes()`.
pub(crate) fn forward(isa: Isa, p: usize, rec: &Rec, lanes: &Lanes, xin: &[f64], f: &mut [f64]) {
    let n = rec.len();
    let nb = lanes.tau.len();
    assert!(rec.an.len() == n && rec.d.len() == n && rec.e.len() == n && rec.bb.len() == n);
    assert!(lanes.p.len() == nb && lanes.sc.len() == nb && nb.is_multiple_of(isa.lanes()));
    assert!(xin.len() >= nb * p && f.len() >= n * p && isa.is_supported());
    // SAFETY: lengths checked above, instruction set checked by is_supported.
    unsafe {
        match (isa, p) {
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx512, 16) => fwd_avx512_16(rec, lanes, xin, f),
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx512, 8) => fwd_avx512_8(rec, lanes, xin, f),
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx2, 16) => fwd_avx2_16(rec, lanes, xin, f),
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx2, 8) => fwd_avx2_8(rec, lanes, xin, f),
            (_, 16) => forward_body::<Scalar, 1, 16>(rec, lanes, xin, f),
            (_, 8) => forward_body::<Scalar, 1, 8>(rec, lanes, xin, f),
            _ => unreachable!("P must be 8 or 16"),
        }
    }
}

/// Inverse kernel: `y[row(s)*P + q] = sum_i dt_{l0+i}(beta_s) fin[i*P + q]`, `P` = 8 or 16
/// (the layout of the forward kernel's input, see `plan/blocks.rs`).
pub(crate) fn inverse(isa: Isa, p: usize, rec: &Rec, lanes: &Lanes, fin: &[f64], y: &mut [f64]) {
    let n = rec.len();
    let nb = lanes.tau.len();
    assert!(rec.an.len() == n && rec.d.len() == n && rec.e.len() == n && rec.bb.len() == n);
    assert!(lanes.p.len() == nb && lanes.sc.len() == nb && nb.is_multiple_of(isa.lanes()));
    assert!(fin.len() >= n * p && y.len() >= nb * p && isa.is_supported());
    // SAFETY: lengths checked above, instruction set checked by is_supported.
    unsafe {
        match (isa, p) {
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx512, 16) => inv_avx512_16(rec, lanes, fin, y),
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx512, 8) => inv_avx512_8(rec, lanes, fin, y),
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx2, 16) => inv_avx2_16(rec, lanes, fin, y),
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx2, 8) => inv_avx2_8(rec, lanes, fin, y),
            (_, 16) => inverse_body::<Scalar, 1, 16>(rec, lanes, fin, y),
            (_, 8) => inverse_body::<Scalar, 1, 8>(rec, lanes, fin, y),
            _ => unreachable!("P must be 8 or 16"),
        }
    }
}

/// `dt^l_{m,mp}` of the base pair at point `k` of `bt`, for `l = m..lend`, through the
/// forward kernel (one beta, unit data in column 0).
#[allow(clippy::too_many_arguments)]
pub(crate) fn column(
    isa: Isa,
    bt: &BetaTables,
    rt: &RecTables,
    k: usize,
    m: usize,
    mp: usize,
    norm: Ext,
    lend: usize,
) -> Vec<f64> {
    let n = lend - m;
    let mut rc = RecCoeffs::new(n);
    rt.coeffs(m, mp, &mut rc);
    let w = isa.lanes();
    let (p0, sc0) = bt.start(k, m, mp, norm, 1.0, DEFAULT_SKIP_BITS);
    let mut tau = vec![0.0; w];
    let mut p = vec![0.0; w];
    let mut sc = vec![0.0; w];
    let upper = bt.upper(k);
    tau[0] = if upper { bt.tau_hi[k] } else { bt.tau_lo[k] };
    p[0] = p0;
    sc[0] = sc0;
    let mut xin = vec![0.0; w * 8];
    xin[0] = 1.0;
    let mut f = vec![0.0; n * 8];
    let rec = Rec::new(&rc, n);
    let lanes = Lanes {
        tau: &tau,
        p: &p,
        sc: &sc,
        upper_from: if upper { 0 } else { w },
        big: crate::wigner::big(DEFAULT_SKIP_BITS),
        skip: true,
        interleaved: false,
    };
    forward(isa, 8, &rec, &lanes, &xin, &mut f);
    (0..n).map(|i| f[i * 8]).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pseudo(n: usize, seed: u64) -> Vec<f64> {
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

    /// Recurrence coefficients of base pair `(m, mp)` at bandwidth `b` and lane inputs for
    /// `nbs` points spread evenly over the grid (lower half first, as in a chunk).
    pub(super) fn cluster_setup(
        b: usize,
        m: usize,
        mp: usize,
        nbs: usize,
    ) -> (RecCoeffs, Vec<f64>, Vec<f64>, Vec<f64>) {
        let bt = BetaTables::grid(b);
        let norm = crate::wigner::start_norms(b)[m * (m + 1) / 2 + mp];
        let mut rc = RecCoeffs::new(b - m);
        RecTables::new(b).coeffs(m, mp, &mut rc);
        let (mut tau, mut p, mut sc) = (vec![0.0; nbs], vec![0.0; nbs], vec![0.0; nbs]);
        for s in 0..nbs {
            let k = s * (2 * b) / nbs;
            tau[s] = if k < b { bt.tau_lo[k] } else { bt.tau_hi[k] };
            (p[s], sc[s]) = bt.start(k, m, mp, norm, 1.0, DEFAULT_SKIP_BITS);
        }
        (rc, tau, p, sc)
    }

    /// Kernel lanes over `cluster_setup`'s arrays, default skip threshold.
    pub(super) fn grid_lanes<'a>(
        tau: &'a [f64],
        p: &'a [f64],
        sc: &'a [f64],
        upper_from: usize,
    ) -> Lanes<'a> {
        Lanes {
            tau,
            p,
            sc,
            upper_from,
            big: crate::wigner::big(DEFAULT_SKIP_BITS),
            skip: true,
            interleaved: true,
        }
    }

    /// Every SIMD path agrees with the portable scalar one, forward and inverse,
    /// including lanes that start scaled down (large m at betas near the poles).
    #[test]
    fn simd_paths_match_scalar() {
        let b = 200;
        for &(m, mp) in &[(0usize, 0usize), (5, 3), (150, 20), (199, 199), (120, 0)] {
            let n = b - m;
            let nb = 2 * b;
            let (rc, x, p, sc) = cluster_setup(b, m, mp, nb);
            let rec = Rec::new(&rc, n);
            let lanes = grid_lanes(&x, &p, &sc, b);
            for pw in [8usize, 16] {
                let xin = pseudo(nb * pw, 7 + m as u64);
                let fin = pseudo(n * pw, 11 + mp as u64);
                let mut f_ref = vec![0.0; n * pw];
                let mut y_ref = vec![0.0; nb * pw];
                forward(Isa::Scalar, pw, &rec, &lanes, &xin, &mut f_ref);
                inverse(Isa::Scalar, pw, &rec, &lanes, &fin, &mut y_ref);
                for isa in [Isa::Avx512, Isa::Avx2] {
                    if !isa.is_supported() {
                        continue;
                    }
                    let mut f = vec![0.0; n * pw];
                    let mut y = vec![0.0; nb * pw];
                    forward(isa, pw, &rec, &lanes, &xin, &mut f);
                    inverse(isa, pw, &rec, &lanes, &fin, &mut y);
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
                    let (ef, ey) = (rel(&f, &f_ref), rel(&y, &y_ref));
                    assert!(
                        ef < 1e-12 && ey < 1e-12,
                        "{isa:?} m={m} mp={mp} P={pw}: {ef} {ey}"
                    );
                }
            }
        }
    }
}

#[cfg(test)]
mod kernel_speed {
    use super::tests::{cluster_setup, grid_lanes};
    use super::*;

    /// Kernel-only throughput (run with --ignored --nocapture): GFLOP/s of the fused
    /// recurrence + accumulation for one generic cluster, all 2B grid betas.
    #[test]
    #[ignore]
    fn kernel_gflops() {
        for &(b, nbs) in &[(256usize, 512usize), (256, 128), (128, 256)] {
            let (m, mp) = (b / 8, b / 16);
            let n = b - m;
            let (rc, x, p, sc) = cluster_setup(b, m, mp, nbs);
            let rec = Rec::new(&rc, n);
            let lanes = grid_lanes(&x, &p, &sc, nbs / 2);
            let xin = vec![0.5; nbs * 16];
            let mut f = vec![0.0; n * 16];
            let mut y = vec![0.0; nbs * 16];
            let isa = Isa::detect();
            // Best of several batches: the machine is shared and noisy.
            let best = |f: &mut dyn FnMut()| {
                (0..7)
                    .map(|_| {
                        let t = std::time::Instant::now();
                        for _ in 0..50 {
                            f();
                        }
                        t.elapsed().as_secs_f64() / 50.0
                    })
                    .fold(f64::INFINITY, f64::min)
            };
            let tf = best(&mut || forward(isa, 16, &rec, &lanes, &xin, &mut f));
            let ti = best(&mut || inverse(isa, 16, &rec, &lanes, &f, &mut y));
            let flops = (n * nbs * 16 * 2) as f64;
            println!(
                "B={b} nb={nbs} L={n}: forward {:.1} GFLOP/s, inverse {:.1} GFLOP/s",
                flops / tf / 1e9,
                flops / ti / 1e9
            );
        }
    }
}

#[cfg(test)]
mod stage_speed {
    use super::tests::{cluster_setup, grid_lanes};
    use super::*;

    /// Kernel time summed over every cluster of a bandwidth (all 2B betas as one chunk),
    /// against the nominal DWT flop count (run with --ignored --nocapture).
    #[test]
    #[ignore]
    fn all_clusters_gflops() {
        let isa = Isa::detect();
        for b in [128usize, 256] {
            let nbs = 2 * b;
            let (mut tf, mut ti) = (0.0, 0.0);
            let mut qt = [0.0f64; 4];
            let mut qf = [0.0f64; 4];
            let xin = vec![0.5; nbs * 16];
            let mut f = vec![0.0; b * 16];
            let mut y = vec![0.0; nbs * 16];
            for (m, mp) in crate::symmetry::cluster_pairs(b) {
                let (m, mp) = (m as usize, mp as usize);
                let n = b - m;
                let (rc, x, p, sc) = cluster_setup(b, m, mp, nbs);
                let rec = Rec::new(&rc, n);
                let lanes = grid_lanes(&x, &p, &sc, b);
                let pw = if m == mp || mp == 0 { 8 } else { 16 };
                let t = std::time::Instant::now();
                forward(isa, pw, &rec, &lanes, &xin, &mut f[..n * pw]);
                tf += t.elapsed().as_secs_f64();
                let t = std::time::Instant::now();
                inverse(isa, pw, &rec, &lanes, &f[..n * pw], &mut y[..nbs * pw]);
                let dt = t.elapsed().as_secs_f64();
                ti += dt;
                qt[4 * m / b] += dt;
                qf[4 * m / b] += (n * nbs * pw * 2) as f64;
            }
            for q in 0..4 {
                println!(
                    "  m in quarter {q}: inverse {:.1} GFLOP/s nominal, {:.3} s",
                    qf[q] / qt[q] / 1e9,
                    qt[q]
                );
            }
            let flops = 8.0 * b as f64 * (4.0 * (b as f64).powi(3) - b as f64) / 3.0;
            println!(
                "B={b}: kernels over all clusters: forward {:.3} s ({:.1} GFLOP/s), inverse {:.3} s ({:.1} GFLOP/s)",
                tf,
                flops / tf / 1e9,
                ti,
                flops / ti / 1e9
            );
        }
    }
}
