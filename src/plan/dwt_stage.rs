//! The DWT stage: per cluster and chunk, the recurrence coefficients and starting values,
//! the kernel on the cluster's block of the chunk buffer (see `blocks.rs`), and the
//! coefficients' signs and layout.

use super::blocks::{BlockRows, Blocks, BufLayout};
use super::coeffs::{self, DegreeFactors};
use super::members::{all_members, neg_sign, representatives};
use super::schedule::{Chunk, ClusterStep, Pass, PlacedChunk};
use super::shared::{lock_free, SendPtr};
use crate::dwt::{self, Lanes, Prefetch, Rec};
use crate::grid::block_start;
use crate::numeric::Ext;
use crate::simd::Isa;
use crate::symmetry::{Cluster, Member};
use crate::wigner::{big, start_norms, BetaTables, RecCoeffs, RecTables};
use num_complex::Complex64;
use rayon::prelude::*;
use std::f64::consts::PI;
use std::ops::Range;
use std::sync::Mutex;

/// Which blocks a transform's DWT stage works on, and which order pairs they hold.
#[derive(Clone, Copy)]
pub(super) struct DwtLayout<'a> {
    /// The blocks' layout in the chunk buffer.
    pub blocks: &'a Blocks,
    /// A real-signal transform: the blocks hold the representatives of each cluster (see
    /// `real.rs`), and the forward also writes each representative's partner.
    pub real: bool,
}

impl DwtLayout<'_> {
    /// The order pairs of a cluster this layout holds, in slot order, and their number.
    fn members(&self, cl: &Cluster) -> ([Member; 8], usize) {
        if self.real {
            representatives(cl)
        } else {
            all_members(cl)
        }
    }
}

/// Per-worker scratch, sized for the largest cluster and chunk.
pub(super) struct Scratch {
    /// Recurrence coefficients of the current cluster.
    rec: RecCoeffs,
    /// Per lane: the recurrence argument.
    tau: Vec<f64>,
    /// Per lane: the scaled starting value.
    start: Vec<f64>,
    /// Per lane: the scale of the starting value (see `Lanes::sc`).
    scale: Vec<f64>,
    /// Inverse: coefficients in the kernel's layout (`n` degrees x `P`).
    data: Vec<f64>,
    /// Forward: the kernel's sums (`n + 8` degrees x `P`, see [`DwtStage::run_forward`]).
    out: Vec<f64>,
    /// The lowest degree `l` the worker's last call needed (the previous cluster, or the
    /// same cluster on the group's previous chunk): the guess for where the next
    /// cluster's coefficient rows start to matter (prefetch only).
    from_l: usize,
    /// Inverse: rows `have..` of `data` hold the current cluster's coefficients (kept
    /// over the chunks of a group, see `Plan::run_chunks`).
    have: usize,
    /// Forward: a cluster's sums over the chunks of a group so far (layout of `out`);
    /// rows below `sum_lo` are zero by definition (not stored: stale values there).
    sum: Vec<f64>,
    sum_lo: usize,
}

impl Scratch {
    /// Scratch for bandwidth `b` and blocks of up to `lanes` lanes.
    fn new(b: usize, lanes: usize) -> Scratch {
        Scratch {
            rec: RecCoeffs::new(b),
            tau: vec![0.0; lanes],
            start: vec![0.0; lanes],
            scale: vec![0.0; lanes],
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
}

/// Where the inverse reads a cluster's coefficients from: the cluster, the order pairs of
/// its slots, the coefficient array, and the kernels' value scale per degree.
struct CoeffSource<'a> {
    cluster: &'a Cluster,
    members: &'a [Member],
    coef: &'a [Complex64],
    vscale: &'a [f64],
}

/// The DWT stage of a plan: the cluster order, the Wigner-d tables and per-worker scratch.
pub(super) struct DwtStage {
    b: usize,
    isa: Isa,
    /// Base pairs of the clusters, in processing order (8 x 8 tiles, see
    /// `symmetry::cluster_pairs`).
    clusters: Vec<(u32, u32)>,
    /// Recurrence arguments and starting-value tables of the beta grid.
    beta_tables: BetaTables,
    /// Norms of the starting values, per order pair `(m, m')`, `m >= m' >= 0`.
    start_norms: Vec<Ext>,
    /// Three-term recurrence coefficients.
    recurrence: RecTables,
    /// Per-worker scratch.
    scratch: Vec<Mutex<Scratch>>,
    /// Lanes of the largest block (for a private scratch when all are busy).
    scratch_lanes: usize,
    /// Skip threshold `2^-skip_bits` for negligible Wigner-d values.
    skip_bits: u32,
    /// Whether degrees below the threshold are skipped (`Options::skip_bits` not `Some(0)`).
    skip: bool,
}

impl DwtStage {
    /// The stage for bandwidth `b` with the cluster order `clusters`, `threads` scratches
    /// for blocks of up to `lanes` lanes.
    pub(super) fn new(
        b: usize,
        isa: Isa,
        clusters: Vec<(u32, u32)>,
        (threads, lanes): (usize, usize),
        (skip_bits, skip): (u32, bool),
    ) -> DwtStage {
        DwtStage {
            b,
            isa,
            clusters,
            beta_tables: BetaTables::grid(b),
            start_norms: start_norms(b),
            recurrence: RecTables::new(b),
            scratch: (0..threads)
                .map(|_| Mutex::new(Scratch::new(b, lanes)))
                .collect(),
            scratch_lanes: lanes,
            skip_bits,
            skip,
        }
    }

    /// Instruction set of the kernels.
    pub(super) fn isa(&self) -> Isa {
        self.isa
    }

    /// Run `f(scratch, step)` on every cluster of `t` in parallel (work stealing over runs
    /// of consecutive clusters, whose blocks are consecutive in the chunk buffer). While a
    /// cluster's kernel runs it prefetches what the next one will touch (see
    /// [`DwtStage::next_cluster`]), so `step` carries that one too; each cluster is built
    /// once.
    pub(super) fn for_each_cluster(
        &self,
        t: &Blocks,
        f: impl Fn(&mut Scratch, &ClusterStep) + Sync,
    ) {
        let nc = t.len();
        const RUN: usize = 8;
        (0..nc.div_ceil(RUN)).into_par_iter().for_each(|r| {
            let mut guard = lock_free(&self.scratch);
            let mut own = None;
            let sc: &mut Scratch = match guard.as_deref_mut() {
                Some(s) => s,
                // All busy (concurrent executions of this plan): use a private one.
                None => own.insert(Scratch::new(self.b, self.scratch_lanes)),
            };
            let (c0, c1) = (r * RUN, ((r + 1) * RUN).min(nc));
            let pair = |c: usize| {
                let (m, mp) = self.clusters[c];
                Cluster::new(m as usize, mp as usize)
            };
            let mut cluster = pair(c0);
            for index in c0..c1 {
                let next = (index + 1 < nc).then(|| pair(index + 1));
                f(
                    sc,
                    &ClusterStep {
                        index,
                        cluster,
                        next,
                    },
                );
                if let Some(n) = next {
                    cluster = n;
                }
            }
        });
    }

    /// Lane inputs of the kernels after [`DwtStage::setup`].
    fn lanes<'a>(&self, sc: &'a Scratch, ch: &Chunk) -> Lanes<'a> {
        let nl = ch.lanes();
        Lanes {
            tau: &sc.tau[..nl],
            p: &sc.start[..nl],
            sc: &sc.scale[..nl],
            upper_from: ch.hp,
            big: big(self.skip_bits),
            skip: self.skip,
            interleaved: true,
            prefetch: Prefetch::none(),
            stream: true,
            pair_stride: 0,
            row_gap: 0,
        }
    }

    /// Recurrence coefficients and per-lane inputs (recurrence argument, scaled starting
    /// value) of a cluster for one chunk; returns the number of degrees. Padding lanes get
    /// zeros (a zero starting value keeps them at exactly 0).
    /// With `rec` false the recurrence coefficients are kept from the previous call (the
    /// same cluster in another chunk).
    fn setup(&self, sc: &mut Scratch, cl: &Cluster, ch: &Chunk, rec: bool) -> usize {
        let n = self.b - cl.l0();
        if rec {
            sc.rec.resize(n);
            self.recurrence.coeffs(cl.m, cl.mp, &mut sc.rec);
        }
        let norm = self.start_norms[cl.m * (cl.m + 1) / 2 + cl.mp];
        let nl = ch.lanes();
        for (half, (u0, k0)) in ch.halves(self.b).into_iter().enumerate() {
            let (u1, pad) = (u0 + ch.h, u0 + ch.hp);
            let (start, scale) = (&mut sc.start[u0..u1], &mut sc.scale[u0..u1]);
            self.beta_tables.starts(
                self.isa,
                k0,
                cl.m,
                cl.mp,
                norm,
                self.skip_bits,
                start,
                scale,
            );
            if half == 0 {
                sc.tau[u0..u1].copy_from_slice(&self.beta_tables.tau_lo[k0..k0 + ch.h]);
            } else {
                // The upper half runs down from 2B-1-lo (the mirrors of the lower half).
                sc.tau[u0..u1].copy_from_slice(&self.beta_tables.tau_hi[k0..k0 + ch.h]);
                for v in [&mut sc.tau, &mut sc.start, &mut sc.scale] {
                    v[u0..u1].reverse();
                }
            }
            for v in [&mut sc.tau, &mut sc.start, &mut sc.scale] {
                v[u1..pad.min(nl)].fill(0.0);
            }
        }
        n
    }

    /// Inverse DWT input, degree rows `rows` of `fin` (`n` rows of `p` values):
    /// `fin[i][2q..2q+2]` = coefficient of `members[q]` at degree `l0 + i`, times the
    /// member's sign, `1/(2 pi)` and the kernels' value scale `vscale[i]` (see
    /// `RecTables::coeffs`); unused columns zero.
    fn gather_coeffs(&self, fin: &mut [f64], src: &CoeffSource, rows: Range<usize>) {
        let (cl, members) = (src.cluster, src.members);
        let (from, to) = (rows.start, rows.end);
        let n = self.b - cl.l0();
        let p = fin.len() / n;
        assert!(2 * members.len() <= p && fin.len() == n * p && from <= to && to <= n);
        let rows = &mut fin[from * p..to * p];
        if members.len() * 2 < p {
            rows.fill(0.0);
        }
        let scale = 1.0 / (2.0 * PI);
        for (q, mem) in members.iter().enumerate() {
            let coef = &src.coef[block_start(self.b, mem.m, mem.mp) + from..][..to - from];
            // Degree `l0 + from` has the parity of `cl.m + from`.
            let sg = [
                mem.sign_at(cl.m + from) * scale,
                mem.sign_at(cl.m + from + 1) * scale,
            ];
            let (dst, s) = (rows[2 * q..].as_mut_ptr(), &src.vscale[from..to]);
            // SAFETY: `rows` has `to - from` rows of `p >= 2 members.len()` values, so
            // doubles `i * p + 2q` and `+ 1` are in it for `i < to - from`; `coef` has
            // `to - from` values.
            unsafe {
                let factors = DegreeFactors {
                    signs: sg,
                    scales: s,
                };
                coeffs::gather(dst, coef.as_ptr(), p, factors)
            };
        }
    }

    /// Prefetch hints for a block of `lanes` rows at `rows` (one range per half when the
    /// halves are apart: the split and half-major layouts).
    fn push_block(pf: &mut Prefetch, rows: BlockRows, lanes: usize) {
        let x = rows.base as *const f64;
        pf.push(x, lanes / 2 * rows.pair_stride);
        if rows.row_gap != rows.width {
            pf.push(x.wrapping_add(rows.row_gap), lanes / 2 * rows.pair_stride);
        }
    }

    /// Zero the padding rows of a block (lanes `h..hp` of each half: rows `2h..2hp`) at
    /// `rows`, which the FFT stage does not write: the forward kernel multiplies them by
    /// exact zeros, which must not meet a stale non-finite value.
    ///
    /// # Safety
    /// The block's `ch.lanes()` rows are the caller's.
    unsafe fn zero_padding(rows: BlockRows, ch: &Chunk) {
        for j in ch.h..ch.hp {
            for r in [0, rows.row_gap] {
                // SAFETY: row `2j` or `2j + 1` of the block, inside it (`j < hp`), the
                // caller's.
                unsafe {
                    std::ptr::write_bytes(rows.base.add(j * rows.pair_stride + r), 0, rows.width)
                };
            }
        }
    }

    /// The forward kernel on the block at `rows` into `sc.out`: degree `i` of column `q`
    /// (the real or imaginary part of a slot) at `i * p + q`, for `n` degrees. `next` is
    /// what to prefetch while the kernel runs (see [`Lanes::prefetch`]). Returns the
    /// kernel's `lo`: rows below it are zero.
    ///
    /// # Safety
    /// The block's `ch.lanes()` rows are written by no one meanwhile.
    unsafe fn run_forward(
        &self,
        sc: &mut Scratch,
        ch: &Chunk,
        rows: BlockRows,
        n: usize,
        next: Prefetch,
    ) -> usize {
        let p = rows.width;
        let mut out = Scratch::take(&mut sc.out, (n + 8) * p, (self.b + 8) * 16);
        let f = &mut out[..(n + 8) * p];
        let rec = Rec::new(&sc.rec, n);
        let mut lanes = self.lanes(sc, ch);
        lanes.prefetch = next;
        (lanes.pair_stride, lanes.row_gap) = (rows.pair_stride, rows.row_gap);
        // SAFETY: row `2j` of the block at `base + j * pair_stride`, row `2j + 1`
        // `row_gap` further (`Blocks::rows`), `p` doubles each, are read by this call only
        // (caller's contract).
        let lo = unsafe { dwt::forward_raw(self.isa, p, &rec, &lanes, rows.base, f) };
        sc.out = out;
        lo
    }

    /// What the cluster after `step` in `layout` will touch: its block of the chunk buffer
    /// (with `block`, a chunk and its buffer, see [`DwtStage::push_block`]) and its
    /// coefficient rows from degree `from_l` less a margin, as prefetch hints (never read
    /// through these pointers). Rows below the first degree some beta of the chunk needs are
    /// not touched (see [`dwt::forward`]); `from_l` guesses that degree from the previous
    /// cluster.
    fn next_cluster(
        &self,
        layout: &DwtLayout,
        step: &ClusterStep,
        block: Option<PlacedChunk>,
        coef: *const Complex64,
        from_l: usize,
    ) -> Prefetch {
        let mut pf = Prefetch::none();
        if let Some(cl) = &step.next {
            if let Some(placed) = block {
                let rows = layout.blocks.rows(step.index + 1, placed.buf);
                Self::push_block(&mut pf, rows, placed.chunk.lanes());
            }
            // Neighbouring clusters need similar degrees; a few below the guess cover
            // the drift from one to the next.
            let lo = from_l.saturating_sub(8).max(cl.l0()).min(self.b) - cl.l0();
            let n = self.b - cl.l0();
            let (mem, nm) = layout.members(cl);
            for mem in &mem[..nm] {
                let row = coef.wrapping_add(block_start(self.b, mem.m, mem.mp) + lo);
                pf.push(row as *const f64, 2 * (n - lo));
            }
        }
        pf
    }

    /// Forward DWT of cluster `step` of `layout` over the chunk of `pass`, accumulated into
    /// `coef` for the order pairs the layout holds; the real forward (whose members are the
    /// representatives) also writes, at the transform's last chunk, each member's partner
    /// `fhat(l,-M,-M') = (-1)^(M-M') conj(fhat(l,M,M'))` (not for `(0,0)`, its own
    /// partner). Within a group of chunks the sums are collected in `sc.sum` and added to
    /// `coef` at the group's last chunk.
    ///
    /// # Safety
    /// The chunk's buffer holds its blocks; `coef` has `num_coeffs` entries; no other task
    /// touches this cluster's blocks or coefficients meanwhile.
    pub(super) unsafe fn forward_cluster(
        &self,
        sc: &mut Scratch,
        layout: &DwtLayout,
        step: &ClusterStep,
        coef: SendPtr<Complex64>,
        pass: &Pass,
    ) {
        let t = layout.blocks;
        let (c, cl) = (step.index, &step.cluster);
        let ch = &pass.placed.chunk;
        let n = self.setup(sc, cl, ch, pass.position == 0);
        let rows = t.rows(c, pass.placed.buf);
        let p = rows.width;
        // SAFETY: this cluster's block, the caller's.
        unsafe { Self::zero_padding(rows, ch) };
        let next = match pass.next_in_group {
            // Within a group: this cluster's block in the next chunk.
            Some(buf) => {
                let mut pf = Prefetch::none();
                Self::push_block(&mut pf, t.rows(c, buf), ch.lanes());
                pf
            }
            None => {
                // The first group writes every row of the coefficients. The next cluster
                // starts on the group's first chunk.
                let from_l = if pass.first_group { 0 } else { sc.from_l };
                let head = Some(pass.group_head);
                self.next_cluster(layout, step, head, coef.get(), from_l)
            }
        };
        // SAFETY: the block is the caller's.
        let lo = unsafe { self.run_forward(sc, ch, rows, n, next) }.min(n);
        sc.from_l = cl.l0() + lo;
        let (sums, lo) = if pass.position == 0 && pass.last_in_group {
            (&sc.out, lo)
        } else {
            let (sum, out) = (&mut sc.sum[..n * p], &sc.out[..n * p]);
            if pass.position == 0 {
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
            if !pass.last_in_group {
                return;
            }
            if pass.first_group {
                sum[..sc.sum_lo * p].fill(0.0);
            }
            (&sc.sum, sc.sum_lo)
        };
        // Later groups add only the degrees where some beta is past its negligible
        // prefix: the coefficient array's read-modify-write per group is the main memory
        // traffic of a chunked forward, and near the poles most clusters contribute
        // nothing to most degrees.
        let lo = if pass.first_group { 0 } else { lo };
        let (mem, nm) = layout.members(cl);
        assert!(2 * nm <= p && sums.len() >= n * p);
        for (q, mem) in mem[..nm].iter().enumerate() {
            // SAFETY: `block_start` of an order pair of degree range `l0..B` plus degrees
            // below `n` stays inside the `num_coeffs` entries of `coef`; these rows (and
            // the partner's) belong to this cluster, which no other task handles; `sums`
            // has `n` rows of `p >= 2 nm` values.
            unsafe {
                let dst = coef.get().add(block_start(self.b, mem.m, mem.mp));
                // The real forward's partner `(-M, -M')`, from the final values; the
                // degrees below `lo` (not touched by this group) are final already.
                let partner = if layout.real && pass.last_of_transform && (mem.m, mem.mp) != (0, 0)
                {
                    let d2 = coef.get().add(block_start(self.b, -mem.m, -mem.mp));
                    let ps = neg_sign(mem.m, mem.mp);
                    coeffs::partner_copy(d2, dst, lo, ps);
                    Some((d2.add(lo), ps))
                } else {
                    None
                };
                // Degree `l0 + lo` has the parity of `cl.m + lo`.
                let sg = [mem.sign_at(cl.m + lo), mem.sign_at(cl.m + lo + 1)];
                let src = sums.as_ptr().add(lo * p + 2 * q);
                let s = &sc.rec.s[lo..n];
                let add = !pass.first_group;
                let factors = DegreeFactors {
                    signs: sg,
                    scales: s,
                };
                coeffs::scatter(dst.add(lo), src, p, factors, add, partner);
            }
        }
    }

    /// Inverse DWT of cluster `step` of `layout` over the chunk of `pass` (the order pairs
    /// the layout holds), written into its rows of the chunk buffer (see `plan/blocks.rs`;
    /// half-major with non-temporal stores). For a position above 0 in the group the
    /// previous call was this cluster on the group's previous chunk, whose recurrence
    /// coefficients and coefficient rows are reused.
    ///
    /// # Safety
    /// The chunk's buffer holds its blocks; no other task touches this cluster's block
    /// meanwhile.
    pub(super) unsafe fn inverse_cluster(
        &self,
        sc: &mut Scratch,
        layout: &DwtLayout,
        step: &ClusterStep,
        coef: &[Complex64],
        pass: &Pass,
    ) {
        let k = pass.position;
        let (c, cl) = (step.index, &step.cluster);
        let ch = &pass.placed.chunk;
        let n = self.setup(sc, cl, ch, k == 0);
        let rows = layout.blocks.rows(c, pass.placed.buf);
        let p = rows.width;
        let (mem, nm) = layout.members(cl);
        let mut data = Scratch::take(&mut sc.data, n * p, self.b * 16);
        let rec = Rec::new(&sc.rec, n);
        let mut lanes = self.lanes(sc, ch);
        // Blocks too large for the cache are half-major, written with non-temporal
        // stores (see `plan/blocks.rs`).
        lanes.stream = matches!(pass.placed.buf.layout, BufLayout::HalfMajor(_));
        (lanes.pair_stride, lanes.row_gap) = (rows.pair_stride, rows.row_gap);
        // Within a group the next call needs nothing new (its rows are kept here, its
        // block is written with non-temporal stores): prefetch for the next cluster only
        // on the group's last chunk.
        if pass.next_in_group.is_none() {
            lanes.prefetch = self.next_cluster(layout, step, None, coef.as_ptr(), sc.from_l);
        }
        let mut lo = n;
        let mut have = if k == 0 { n } else { sc.have };
        // Only the degrees some beta of the chunk needs are read from the coefficients
        // (near the poles most clusters need few or none), and each once per group.
        let src = CoeffSource {
            cluster: cl,
            members: &mem[..nm],
            coef,
            vscale: &sc.rec.s[..n],
        };
        let mut fill = |fin: &mut [f64], from: usize, to: usize| {
            if from < have {
                self.gather_coeffs(fin, &src, from..to.min(have));
                have = from;
            }
            lo = from;
        };
        // SAFETY: this cluster's `ch.lanes() <= t.lanes` rows (`p` values each, row `2j`
        // at `j * pair_stride`, row `2j + 1` `row_gap` further, `j < ch.hp`) are in the
        // chunk buffer (`Blocks::rows`); the caller owns them.
        unsafe {
            dwt::inverse_raw(
                self.isa,
                p,
                &rec,
                &lanes,
                &mut data[..n * p],
                &mut fill,
                rows.base,
            )
        };
        sc.data = data;
        sc.have = have;
        if k == 0 || lo < n {
            sc.from_l = cl.l0() + lo;
        }
    }
}
