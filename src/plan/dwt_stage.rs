//! The DWT stage of the complex transforms: per cluster and chunk, the recurrence
//! coefficients and starting values, the kernel on the cluster's block of the chunk buffer
//! (see `blocks.rs`), and the coefficients' signs and layout.

use super::blocks::{Blocks, BufLayout};
use super::coeffs;
use super::members;
use super::schedule::{At, Chunk, Pass};
use super::shared::SendPtr;
use super::Plan;
use crate::dwt::{self, Lanes, Prefetch, Rec};
use crate::grid::block_start;
use crate::symmetry::{Cluster, Member};
use crate::wigner::{big, RecCoeffs};
use num_complex::Complex64;
use std::f64::consts::PI;

/// The order pairs of a cluster a layout transforms, in slot order, and their number:
/// [`all_members`] (complex layout) or `real::representatives` (real layout).
pub(super) type Members = fn(&Cluster) -> ([Member; 8], usize);

/// Per-worker scratch, sized for the largest cluster and chunk.
pub(super) struct Scratch {
    pub rec: RecCoeffs,
    pub tau: Vec<f64>,
    pub p: Vec<f64>,
    pub sc: Vec<f64>,
    /// Inverse: coefficients in the kernel's layout (`n` degrees x `P`).
    pub data: Vec<f64>,
    /// Forward: the kernel's sums (`n + 8` degrees x `P`, see [`Plan::run_forward`]).
    pub out: Vec<f64>,
    /// The lowest degree `l` the worker's last call needed (the previous cluster, or the
    /// same cluster on the group's previous chunk): the guess for where the next
    /// cluster's coefficient rows start to matter (prefetch only).
    pub from_l: usize,
    /// Inverse: rows `have..` of `data` hold the current cluster's coefficients (kept
    /// over the chunks of a group, see `Plan::run_chunks`).
    pub have: usize,
    /// Forward: a cluster's sums over the chunks of a group so far (layout of `out`);
    /// rows below `sum_lo` are zero by definition (not stored: stale values there).
    pub sum: Vec<f64>,
    pub sum_lo: usize,
}

impl Scratch {
    pub fn new(b: usize, lanes: usize) -> Scratch {
        Scratch {
            rec: RecCoeffs::new(b),
            tau: vec![0.0; lanes],
            p: vec![0.0; lanes],
            sc: vec![0.0; lanes],
            data: vec![0.0; b * 16],
            out: vec![0.0; (b + 8) * 16],
            from_l: 0,
            have: 0,
            sum: vec![0.0; b * 16],
            sum_lo: 0,
        }
    }

    /// `buf` taken out of the scratch for a kernel call (put back afterwards). Only after a
    /// panic left the scratch without it is it shorter than `need`: then a fresh one of
    /// `full` values.
    fn take(buf: &mut Vec<f64>, need: usize, full: usize) -> Vec<f64> {
        let v = std::mem::take(buf);
        if v.len() < need {
            vec![0.0; full]
        } else {
            v
        }
    }

    /// Scratch for the chunks of the complex layout and, if present, the real one.
    pub fn for_layouts(b: usize, complex: &Blocks, real: Option<&Blocks>) -> Scratch {
        Scratch::new(b, complex.lanes.max(real.map_or(0, |t| t.lanes)))
    }

    /// Lane inputs of the kernels after [`Plan::setup`].
    pub fn lanes<'a>(&'a self, plan: &Plan, ch: &Chunk) -> Lanes<'a> {
        let nl = ch.lanes();
        Lanes {
            tau: &self.tau[..nl],
            p: &self.p[..nl],
            sc: &self.sc[..nl],
            upper_from: ch.hp,
            big: big(plan.skip_bits),
            skip: plan.skip,
            interleaved: true,
            prefetch: Prefetch::none(),
            stream: true,
            pair_stride: 0,
            row_gap: 0,
        }
    }
}

impl Plan {
    /// Recurrence coefficients and per-lane inputs (recurrence argument, scaled starting
    /// value) of a cluster for one chunk; returns the number of degrees. Padding lanes get
    /// zeros (a zero starting value keeps them at exactly 0).
    /// With `rec` false the recurrence coefficients are kept from the previous call (the
    /// same cluster in another chunk).
    pub(super) fn setup(&self, sc: &mut Scratch, cl: &Cluster, ch: &Chunk, rec: bool) -> usize {
        let n = self.b - cl.l0();
        if rec {
            sc.rec.resize(n);
            self.rt.coeffs(cl.m, cl.mp, &mut sc.rec);
        }
        let norm = self.norms[cl.m * (cl.m + 1) / 2 + cl.mp];
        let nl = ch.lanes();
        for (half, (u0, k0)) in ch.halves(self.b).into_iter().enumerate() {
            let (u1, pad) = (u0 + ch.h, u0 + ch.hp);
            let (p, scale) = (&mut sc.p[u0..u1], &mut sc.sc[u0..u1]);
            self.bt
                .starts(self.isa, k0, cl.m, cl.mp, norm, self.skip_bits, p, scale);
            if half == 0 {
                sc.tau[u0..u1].copy_from_slice(&self.bt.tau_lo[k0..k0 + ch.h]);
            } else {
                // The upper half runs down from 2B-1-lo (the mirrors of the lower half).
                sc.tau[u0..u1].copy_from_slice(&self.bt.tau_hi[k0..k0 + ch.h]);
                for v in [&mut sc.tau, &mut sc.p, &mut sc.sc] {
                    v[u0..u1].reverse();
                }
            }
            for v in [&mut sc.tau, &mut sc.p, &mut sc.sc] {
                v[u1..pad.min(nl)].fill(0.0);
            }
        }
        n
    }

    /// Inverse DWT input, rows `from..to` of `fin` (`n` rows of `p` values):
    /// `fin[i][2q..2q+2]` = coefficient of `members[q]` at degree `l0 + i`, times the
    /// member's sign, `1/(2 pi)` and the kernels' value scale `vscale[i]` (see
    /// `RecTables::coeffs`); unused columns zero.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn gather_coeffs(
        &self,
        fin: &mut [f64],
        cl: &Cluster,
        members: &[Member],
        coef: &[Complex64],
        vscale: &[f64],
        from: usize,
        to: usize,
    ) {
        let n = self.b - cl.l0();
        let p = fin.len() / n;
        assert!(2 * members.len() <= p && fin.len() == n * p && from <= to && to <= n);
        let rows = &mut fin[from * p..to * p];
        if members.len() * 2 < p {
            rows.fill(0.0);
        }
        let scale = 1.0 / (2.0 * PI);
        for (q, mem) in members.iter().enumerate() {
            let src = &coef[block_start(self.b, mem.m, mem.mp) + from..][..to - from];
            // Degree `l0 + from` has the parity of `cl.m + from`.
            let sg = [
                mem.sign_at(cl.m + from) * scale,
                mem.sign_at(cl.m + from + 1) * scale,
            ];
            // SAFETY: `rows` has `to - from` rows of `p >= 2 members.len()` values.
            let (dst, s) = (rows[2 * q..].as_mut_ptr(), &vscale[from..to]);
            unsafe { coeffs::gather(dst, src.as_ptr(), p, to - from, sg, s) };
        }
    }

    /// Prefetch hints for cluster `c`'s block of `lanes` rows in `buf`, laid out as
    /// `layout` (a forward's: cluster-major, one range, or split, a range in each half).
    fn push_block(
        pf: &mut Prefetch,
        t: &Blocks,
        buf: *mut f64,
        c: usize,
        lanes: usize,
        layout: BufLayout,
    ) {
        let (at, ps, gap) = t.pair_rows(c, 0, layout);
        let x = buf.wrapping_add(at) as *const f64;
        pf.push(x, lanes / 2 * ps);
        if gap != t.p(c) {
            pf.push(x.wrapping_add(gap), lanes / 2 * ps);
        }
    }

    /// Zero the padding rows of a block (lanes `h..hp` of each half: rows `2h..2hp`) at
    /// `(x, ps, gap)` (see [`Blocks::pair_rows`]), which the FFT stage does not write: the
    /// forward kernel multiplies them by exact zeros, which must not meet a stale
    /// non-finite value.
    ///
    /// # Safety
    /// The block's `ch.lanes()` rows of `p` doubles are the caller's.
    pub(super) unsafe fn zero_padding(
        (x, ps, gap): (*mut f64, usize, usize),
        p: usize,
        ch: &Chunk,
    ) {
        for j in ch.h..ch.hp {
            for r in [0, gap] {
                std::ptr::write_bytes(x.add(j * ps + r), 0, p);
            }
        }
    }

    /// The forward kernel on the block at `(x, ps, gap)` (see [`Blocks::pair_rows`]) into
    /// `sc.out`: degree `i` of column `q` (the real or imaginary part of a slot) at
    /// `i * p + q`. `next` is what to prefetch while the kernel runs (see
    /// [`Lanes::prefetch`]). Returns the kernel's `lo`: rows below it are zero.
    ///
    /// # Safety
    /// The block's `ch.lanes()` rows of `p` doubles are written by no one meanwhile.
    pub(super) unsafe fn run_forward(
        &self,
        sc: &mut Scratch,
        ch: &Chunk,
        p: usize,
        n: usize,
        (x, ps, gap): (*const f64, usize, usize),
        next: Prefetch,
    ) -> usize {
        let mut out = Scratch::take(&mut sc.out, (n + 8) * p, (self.b + 8) * 16);
        let f = &mut out[..(n + 8) * p];
        let rec = Rec::new(&sc.rec, n);
        let mut lanes = sc.lanes(self, ch);
        lanes.prefetch = next;
        (lanes.pair_stride, lanes.row_gap) = (ps, gap);
        let lo = dwt::forward_raw(self.isa, p, &rec, &lanes, x, f);
        sc.out = out;
        lo
    }

    /// What the cluster after `at` in layout `t` will touch: its block of the chunk buffer
    /// (with `block = Some(layout)`, see [`Plan::push_block`]) and its coefficient rows
    /// (`members` of it) from degree `from_l`
    /// less a margin, as prefetch hints (never read through these pointers). Rows below
    /// the first degree some beta of the chunk needs are not touched (see
    /// [`dwt::forward`]); `from_l` guesses that degree from the previous cluster.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn next_cluster(
        &self,
        t: &Blocks,
        buf: *mut f64,
        at: &At,
        ch: &Chunk,
        block: Option<BufLayout>,
        coef: *const Complex64,
        members: Members,
        from_l: usize,
    ) -> Prefetch {
        let mut pf = Prefetch::none();
        if let Some(cl) = &at.next {
            if let Some(layout) = block {
                Self::push_block(&mut pf, t, buf, at.c + 1, ch.lanes(), layout);
            }
            // Neighbouring clusters need similar degrees; a few below the guess cover
            // the drift from one to the next.
            let lo = from_l.saturating_sub(8).max(cl.l0()).min(self.b) - cl.l0();
            let n = self.b - cl.l0();
            let (mem, nm) = members(cl);
            for mem in &mem[..nm] {
                let row = coef.wrapping_add(block_start(self.b, mem.m, mem.mp) + lo);
                pf.push(row as *const f64, 2 * (n - lo));
            }
        }
        pf
    }

    /// Forward DWT of cluster `at` of layout `t` over one chunk, accumulated into `coef`
    /// for the order pairs `members` gives; with `partners` (the real forward, whose
    /// members are the representatives) the last chunk also writes each member's partner
    /// `fhat(l,-M,-M') = (-1)^(M-M') conj(fhat(l,M,M'))` (not for `(0,0)`, its own
    /// partner). Within a group of chunks the sums are collected in `sc.sum` and added to
    /// `coef` at the group's last chunk.
    ///
    /// # Safety
    /// `buf` holds the chunk's blocks; `coef` has `num_coeffs` entries and no other task
    /// writes this cluster's blocks or coefficients.
    #[allow(clippy::too_many_arguments)]
    pub(super) unsafe fn forward_cluster(
        &self,
        sc: &mut Scratch,
        t: &Blocks,
        members: Members,
        partners: bool,
        at: &At,
        ch: &Chunk,
        buf: *mut f64,
        coef: SendPtr<Complex64>,
        pass: Pass,
    ) {
        let (c, cl) = (at.c, &at.cl);
        let n = self.setup(sc, cl, ch, pass.k == 0);
        let p = t.p(c);
        let (at_c, ps, gap) = t.pair_rows(c, 0, pass.layout);
        let x = buf.add(at_c);
        Self::zero_padding((x, ps, gap), p, ch);
        let next = match pass.next_buf {
            // Within a group: this cluster's block in the next chunk.
            Some((nb, layout)) => {
                let mut pf = Prefetch::none();
                Self::push_block(&mut pf, t, nb.get(), c, ch.lanes(), layout);
                pf
            }
            None => {
                // The first group writes every row of the coefficients. The next cluster
                // starts on the group's first chunk.
                let from_l = if pass.first { 0 } else { sc.from_l };
                let (hch, hbuf, hl) = pass.head;
                let c = coef.get();
                self.next_cluster(t, hbuf.get(), at, &hch, Some(hl), c, members, from_l)
            }
        };
        let lo = self.run_forward(sc, ch, p, n, (x, ps, gap), next).min(n);
        sc.from_l = cl.l0() + lo;
        let (sums, lo) = if pass.k == 0 && pass.last {
            (&sc.out, lo)
        } else {
            let (sum, out) = (&mut sc.sum[..n * p], &sc.out[..n * p]);
            if pass.k == 0 {
                sum[lo * p..].copy_from_slice(&out[lo * p..]);
                sc.sum_lo = lo;
            } else {
                if lo < sc.sum_lo {
                    sum[lo * p..sc.sum_lo * p].fill(0.0);
                    sc.sum_lo = lo;
                }
                for (s, o) in sum[lo * p..].iter_mut().zip(&out[lo * p..]) {
                    *s += o;
                }
            }
            if !pass.last {
                return;
            }
            if pass.first {
                sum[..sc.sum_lo * p].fill(0.0);
            }
            (&sc.sum, sc.sum_lo)
        };
        // Later groups add only the degrees where some beta is past its negligible
        // prefix: the coefficient array's read-modify-write per group is the main memory
        // traffic of a chunked forward (B = 512), and near the poles most clusters
        // contribute nothing to most degrees.
        let lo = if pass.first { 0 } else { lo };
        let (mem, nm) = members(cl);
        assert!(2 * nm <= p && sums.len() >= n * p);
        for (q, mem) in mem[..nm].iter().enumerate() {
            let dst = coef.get().add(block_start(self.b, mem.m, mem.mp));
            // The real forward's partner `(-M, -M')`, from the final values; the degrees
            // below `lo` (not touched by this group) are final already.
            let partner = if partners && pass.done && (mem.m, mem.mp) != (0, 0) {
                let d2 = coef.get().add(block_start(self.b, -mem.m, -mem.mp));
                let ps = members::neg_sign(mem.m, mem.mp);
                coeffs::partner_copy(d2, dst, lo, ps);
                Some((d2.add(lo), ps))
            } else {
                None
            };
            // Degree `l0 + lo` has the parity of `cl.m + lo`.
            let sg = [mem.sign_at(cl.m + lo), mem.sign_at(cl.m + lo + 1)];
            let src = sums.as_ptr().add(lo * p + 2 * q);
            let s = &sc.rec.s[lo..n];
            coeffs::scatter(dst.add(lo), src, p, n - lo, sg, s, !pass.first, partner);
        }
    }

    /// Inverse DWT of cluster `at` of layout `t` over one chunk (the order pairs `members`
    /// gives), written into its rows of the chunk buffer of `pass.layout` (see
    /// `plan/blocks.rs`; half-major with non-temporal stores). For `pass.k > 0` the previous call was this
    /// cluster on the group's previous chunk, whose recurrence coefficients and
    /// coefficient rows are reused.
    ///
    /// # Safety
    /// `buf` is the chunk buffer; no other task writes this cluster's block.
    #[allow(clippy::too_many_arguments)]
    pub(super) unsafe fn inverse_cluster(
        &self,
        sc: &mut Scratch,
        t: &Blocks,
        members: Members,
        at: &At,
        ch: &Chunk,
        buf: *mut f64,
        coef: &[Complex64],
        pass: Pass,
    ) {
        let k = pass.k;
        let (c, cl) = (at.c, &at.cl);
        let n = self.setup(sc, cl, ch, k == 0);
        let p = t.p(c);
        let (mem, nm) = members(cl);
        let mut data = Scratch::take(&mut sc.data, n * p, self.b * 16);
        let rec = Rec::new(&sc.rec, n);
        let mut lanes = sc.lanes(self, ch);
        // Blocks too large for the cache are half-major, written with non-temporal
        // stores (see `plan/blocks.rs`).
        lanes.stream = matches!(pass.layout, BufLayout::HalfMajor(_));
        let (at_c, ps, gap) = t.pair_rows(c, 0, pass.layout);
        (lanes.pair_stride, lanes.row_gap) = (ps, gap);
        // Within a group the next call needs nothing new (its rows are kept here, its
        // block is written with non-temporal stores): prefetch for the next cluster only
        // on the group's last chunk.
        if pass.next_buf.is_none() {
            let from_l = sc.from_l;
            lanes.prefetch =
                self.next_cluster(t, buf, at, ch, None, coef.as_ptr(), members, from_l);
        }
        let mut lo = n;
        let mut have = if k == 0 { n } else { sc.have };
        // Only the degrees some beta of the chunk needs are read from the coefficients
        // (near the poles most clusters need few or none), and each once per group.
        let scale = &sc.rec.s[..n];
        let mut fill = |fin: &mut [f64], from: usize, to: usize| {
            if from < have {
                self.gather_coeffs(fin, cl, &mem[..nm], coef, scale, from, to.min(have));
                have = from;
            }
            lo = from;
        };
        // SAFETY: this cluster's `ch.lanes() <= t.lanes` rows (`p` values each, row `2j`
        // at `j * ps`, row `2j + 1` `gap` further, `j < ch.hp`) are in the chunk buffer
        // (`Blocks::pair_rows`); the caller owns them.
        dwt::inverse_raw(
            self.isa,
            p,
            &rec,
            &lanes,
            &mut data[..n * p],
            &mut fill,
            buf.add(at_c),
        );
        sc.data = data;
        sc.have = have;
        if k == 0 || lo < n {
            sc.from_l = cl.l0() + lo;
        }
    }
}
