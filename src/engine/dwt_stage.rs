//! The DWT stage of a partial plan: the clusters whose order pairs the shape holds, and the
//! kernels over a chunk of lane pairs, writing (inverse) or reading (forward) each
//! cluster's block of the chunk buffer.
//!
//! A chunk of `h` lane pairs (padded to `hp`, a multiple of the vector width) has `2 hp`
//! lane rows: rows `0..hp` the pairs' lower points, rows `hp..2hp` their mirrors. The
//! chunk buffer is lane-major: a lane row holds every cluster's `P` doubles (16 for
//! clusters of more than four order pairs in the shape, else 8) one after another, so the
//! FFT stage reads or writes a slice's values in one sequential pass. Slot `q` of a
//! cluster's row holds the value of its `q`-th order pair present in the shape (or, for a
//! reversed member, its value at the row's mirror). With a batch, the lane rows of
//! transform `t` follow those of transform `t - 1`.

use super::betas::LanePairs;
use super::coeffs::{self, DegreeFactors};
use crate::dwt::{self, BatchRows, Lanes, Prefetch, Rec};
use crate::numeric::Ext;
use crate::shape::CoefLayout;
use crate::simd::Isa;
use crate::symmetry::{Cluster, Member};
use crate::wigner::{big, start_norm, RecCoeffs, RecTables};
use num_complex::Complex64;
use rayon::prelude::*;
use std::f64::consts::PI;
use std::sync::Mutex;

/// Transforms of a batch per kernel call: they share the cluster's recurrence values
/// (enough to make the recurrence a small part of the call), and their kernel inputs or
/// sums stay in L2.
pub(crate) const KERNEL_BATCH: usize = 8;

/// One order pair of a cluster that the shape holds.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Slot {
    pub member: Member,
    /// Index of `(M, M')` in a work buffer of `n_alpha` rows of `n_gamma` values, rows
    /// `row_stride` apart.
    pub work: usize,
    /// Start of the pair's coefficient block and its lowest stored degree.
    pub block: usize,
    pub first: usize,
    /// The real layout's representative of `(M, M')`, `(-M, -M')` (`M' > 0`, or `M' = 0`
    /// and `M >= 0`): the real inverse reads the other one's values from it.
    pub representative: bool,
    /// Start of the block of `(-M, -M')` (the real inverse's source for a non-representative).
    pub partner_block: usize,
}

/// A cluster of the shape: base pair, starting-value norm, its slots and its block.
#[derive(Clone, Debug)]
pub(crate) struct ClusterPlan {
    pub m: usize,
    pub mp: usize,
    norm: Ext,
    /// Doubles per block row: 16 for more than four slots, else 8.
    pub p: usize,
    pub slots: Vec<Slot>,
    /// Doubles before this cluster's in a lane row.
    pub offset: usize,
}

/// Doubles from one lane row of `len` doubles (a multiple of 8) to the next in a buffer:
/// `len` padded to an odd number of cache lines, so that a cluster's values in all rows
/// fall in different cache sets (rows of a multiple of 4 KiB put them all in one); empty
/// rows stay empty.
pub(crate) fn padded_row(len: usize) -> usize {
    len + if len > 0 && (len / 8).is_multiple_of(2) {
        8
    } else {
        0
    }
}

/// What one kernel call of a cluster works on: the lanes of a chunk.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ChunkLanes {
    /// First pair and number of pairs.
    pub j0: usize,
    pub h: usize,
    /// `h` rounded up to the vector width.
    pub hp: usize,
    /// Doubles of a lane row in the buffer the kernels run on (the DWT stage's
    /// `row_total`, or a distributed plan's segment of it).
    pub row_len: usize,
    /// Doubles from the first lower lane row to the first upper one (`hp row_len` in a
    /// buffer in one piece; an inverse's chained buffer has its halves apart).
    pub upper_gap: usize,
    /// Split chunks (see [`super::betas::LanePairs::first_upper_pair`]): pairs
    /// `0..k` write their lower point (or nothing: padding, also the chunk's pairs
    /// `h..hp`), pairs `k..hp` their upper one; `k` is a multiple of the vector width.
    pub first_upper_pair: Option<usize>,
}

impl ChunkLanes {
    pub fn lanes(&self) -> usize {
        2 * self.hp
    }
}

/// How a cluster's inverse splits over a split chunk (see [`ChunkLanes::first_upper_pair`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct Split {
    /// The chunk's first pair writing its upper point.
    first_upper: usize,
    /// Direct members (the first slots) and the width of their kernel call.
    direct: usize,
    direct_p: usize,
}

impl Split {
    /// The split of `cl` over `ch`, if the chunk is split and the cluster's slots allow it:
    /// direct members first, and the reversed ones (if any) in 8 columns after them
    /// within the cluster's width.
    fn of(cl: &ClusterPlan, ch: ChunkLanes) -> Option<Split> {
        let first_upper = ch.first_upper_pair?;
        let direct = cl.slots.iter().take_while(|s| !s.member.reversed).count();
        let reversed = cl.slots.len() - direct;
        if cl.slots[direct..].iter().any(|s| !s.member.reversed) {
            return None;
        }
        let direct_p = if reversed == 0 { cl.p } else { 8 };
        (reversed == 0 || (direct <= 4 && 2 * direct + 8 <= cl.p && 2 * reversed <= 8)).then_some(
            Split {
                first_upper,
                direct,
                direct_p,
            },
        )
    }
}

/// One kernel call of [`DwtStage::inverse_split`].
struct SplitCall<'a> {
    /// The cluster's slots it computes, in `p` columns from `column` of each row.
    slots: std::ops::Range<usize>,
    p: usize,
    column: usize,
    /// Its input rows.
    fin: &'a mut [f64],
    /// Its lanes (reordered), the lower-form ones before `upper_from`.
    lanes: std::ops::Range<usize>,
    upper_from: usize,
    /// The pair of its first lower lane's row, and the offset from that row to its first
    /// upper lane's row.
    first_pair: usize,
    row_gap: usize,
}

/// Per-worker scratch.
pub(crate) struct Scratch {
    rec: RecCoeffs,
    tau: Vec<f64>,
    start: Vec<f64>,
    scale: Vec<f64>,
    /// Inverse input / forward sums (one transform's or a batch's).
    data: Vec<f64>,
    /// The batched kernels' d values.
    tile: Vec<f64>,
}

impl Scratch {
    fn new(l: usize, lanes: usize) -> Scratch {
        Scratch {
            rec: RecCoeffs::new(l),
            tau: vec![0.0; lanes],
            start: vec![0.0; lanes],
            scale: vec![0.0; lanes],
            data: vec![0.0; (l + 8) * 16],
            tile: Vec::new(),
        }
    }
}

/// The DWT stage of a partial plan.
pub(crate) struct DwtStage {
    isa: Isa,
    /// Degree limit `L`.
    l: usize,
    pub clusters: Vec<ClusterPlan>,
    /// Doubles of a lane row (all clusters).
    pub row_total: usize,
    /// Doubles from one lane row to the next in a lane-major chunk buffer: `row_total`
    /// padded ([`padded_row`]).
    pub row_stride: usize,
    recurrence: RecTables,
    skip_bits: u32,
    skip: bool,
    /// Only the members `M' >= 0` (see [`DwtStage::new`]).
    half: bool,
    scratch: Vec<Mutex<Scratch>>,
    max_lanes: usize,
}

impl DwtStage {
    /// The clusters of `layout` (slices of `n_alpha x n_gamma` values, work buffers with
    /// rows `row_stride` apart), scratch for `workers` workers and chunks of up to
    /// `max_lanes` lanes. With `half`, the clusters hold only their members `M' >= 0`: the
    /// half spectrum of real signals, whose forward writes each member's partner
    /// `(-M, -M')` from it (`fhat(l,-M,-M') = (-1)^(M-M') conj(fhat(l,M,M'))`).
    pub fn new(
        (layout, half): (&CoefLayout, bool),
        (n_alpha, n_gamma, row_stride): (usize, usize, usize),
        isa: Isa,
        (skip_bits, skip): (u32, bool),
        (workers, max_lanes): (usize, usize),
    ) -> DwtStage {
        let l = layout.l;
        let mut clusters = Vec::new();
        let mut offset = 0;
        for m in 0..l {
            for mp in 0..=m {
                let cl = Cluster::new(m, mp);
                let slots: Vec<Slot> = cl
                    .members()
                    .iter()
                    .filter(|mem| Self::held(layout, half, mem))
                    .map(|mem| Slot {
                        member: *mem,
                        work: mem.m.rem_euclid(n_alpha as isize) as usize * row_stride
                            + mem.mp.rem_euclid(n_gamma as isize) as usize,
                        block: layout.block_start(mem.m, mem.mp),
                        first: layout.first_degree(mem.m, mem.mp),
                        representative: mem.mp > 0 || (mem.mp == 0 && mem.m >= 0),
                        partner_block: layout.block_start(-mem.m, -mem.mp),
                    })
                    .collect();
                let p = Self::slot_doubles(slots.len());
                if p == 0 {
                    continue;
                }
                clusters.push(ClusterPlan {
                    m,
                    mp,
                    norm: start_norm(m, mp),
                    p,
                    slots,
                    offset,
                });
                offset += p;
            }
        }
        let top = clusters.iter().map(|c| c.m).max().unwrap_or(0);
        let orders: Vec<usize> = (0..=top).collect();
        DwtStage {
            isa,
            l,
            clusters,
            row_total: offset,
            row_stride: padded_row(offset),
            recurrence: RecTables::for_orders(l, &orders),
            skip_bits,
            skip,
            scratch: (0..workers)
                .map(|_| Mutex::new(Scratch::new(l, max_lanes)))
                .collect(),
            max_lanes,
            half,
        }
    }

    /// Doubles of a cluster with `n` slots in a lane row: 16 for more than four, 8 for one
    /// to four, none for none.
    fn slot_doubles(n: usize) -> usize {
        match n {
            0 => 0,
            1..=4 => 8,
            _ => 16,
        }
    }

    /// Whether the clusters of `layout` (with `half`: the members `M' >= 0`) hold `mem`.
    fn held(layout: &CoefLayout, half: bool, mem: &Member) -> bool {
        layout.holds(mem.m, mem.mp) && (!half || mem.mp >= 0)
    }

    /// [`DwtStage::row_stride`] of the stage [`DwtStage::new`] makes of `(layout, half)`,
    /// without making it.
    pub fn row_stride_of(layout: &CoefLayout, half: bool) -> usize {
        let mut offset = 0;
        for m in 0..layout.l {
            for mp in 0..=m {
                let cl = Cluster::new(m, mp);
                let held = cl
                    .members()
                    .iter()
                    .filter(|mem| Self::held(layout, half, mem));
                offset += Self::slot_doubles(held.count());
            }
        }
        padded_row(offset)
    }

    /// Bytes of the stage's tables and scratch (approximately).
    pub fn bytes(l: usize, clusters: usize, workers: usize, max_lanes: usize) -> usize {
        32 * (l + 1) * (l + 2)
            + clusters * 256
            + workers * 8 * (3 * max_lanes + (KERNEL_BATCH + 1) * 16 * (l + 8) + 21 * l)
    }

    /// Runs `f(scratch, index, cluster)` on every cluster in parallel: work stealing over
    /// runs of consecutive clusters (consecutive slots of a lane row), a scratch taken once
    /// per run.
    pub fn for_each_cluster(&self, f: impl Fn(&mut Scratch, usize, &ClusterPlan) + Sync) {
        const RUN: usize = 8;
        let nc = self.clusters.len();
        (0..nc.div_ceil(RUN)).into_par_iter().for_each(|r| {
            self.with_scratch(|sc| {
                for i in r * RUN..((r + 1) * RUN).min(nc) {
                    f(sc, i, &self.clusters[i]);
                }
            })
        });
    }

    /// Runs `f` with a free scratch (a private one when all are busy).
    pub fn with_scratch<R>(&self, f: impl FnOnce(&mut Scratch) -> R) -> R {
        match crate::workers::lock_free(&self.scratch) {
            Some(mut g) => f(&mut g),
            None => f(&mut Scratch::new(self.l, self.max_lanes)),
        }
    }

    /// Recurrence coefficients (with `rec`) and lane inputs of cluster `cl` for chunk `ch`;
    /// the number of degrees. Lanes `0..hp` are the pairs' lower points and `hp..2 hp` their
    /// mirrors, except where the inverse splits at pair `k` (see [`Split`]): there lanes
    /// `0..hp` are the written points (lower ones of pairs `0..k`, then upper ones of the rest) and
    /// lanes `hp..2 hp` their mirrors (lower ones of pairs `k..hp`, then upper ones of
    /// pairs `0..k`), so that each kernel call's lanes are contiguous, lower form first.
    pub fn setup(
        &self,
        sc: &mut Scratch,
        cl: &ClusterPlan,
        pairs: &LanePairs,
        ch: ChunkLanes,
    ) -> usize {
        let n = self.l - cl.m;
        sc.rec.resize(n);
        self.recurrence.coeffs(cl.m, cl.mp, &mut sc.rec);
        self.setup_lanes(sc, cl, pairs, ch);
        n
    }

    /// The lane inputs of [`DwtStage::setup`] alone: for another chunk of the cluster last
    /// set up with this scratch (its recurrence coefficients kept); the number of degrees.
    pub fn setup_lanes(
        &self,
        sc: &mut Scratch,
        cl: &ClusterPlan,
        pairs: &LanePairs,
        ch: ChunkLanes,
    ) -> usize {
        let n = self.l - cl.m;
        let t = &pairs.tables;
        let (h, hp) = (ch.h, ch.hp);
        // Runs of lanes: (first lane, upper form, first pair in the chunk, lanes). Unsplit
        // is the split order with every pair writing its lower point (`k = hp`).
        let k = Split::of(cl, ch).map_or(hp, |s| s.first_upper);
        let runs = [
            (0, false, 0, k),
            (k, true, k, hp - k),
            (hp, false, k, hp - k),
            (2 * hp - k, true, 0, k),
        ];
        for (u0, upper, j, len) in runs.into_iter().filter(|r| r.3 > 0) {
            let live = len.min(h.saturating_sub(j));
            let first_point = ch.j0 + j + if upper { pairs.pairs } else { 0 };
            t.starts(
                self.isa,
                first_point,
                cl.m,
                cl.mp,
                cl.norm,
                self.skip_bits,
                &mut sc.start[u0..u0 + live],
                &mut sc.scale[u0..u0 + live],
            );
            let tau = if upper { &t.tau_hi } else { &t.tau_lo };
            sc.tau[u0..u0 + live].copy_from_slice(&tau[first_point..first_point + live]);
            for v in [&mut sc.tau, &mut sc.start, &mut sc.scale] {
                v[u0 + live..u0 + len].fill(0.0);
            }
        }
        n
    }

    /// The coefficient blocks the inverse of `cl` reads from `coef` (with `real`, the
    /// partners of the non-representatives), as prefetch hints (never read through them):
    /// issued while the kernel of the cluster before runs, they bring the blocks into the
    /// cache before the kernel's fill gathers them.
    pub fn coefficient_hints(
        &self,
        cl: &ClusterPlan,
        coef: *const Complex64,
        real: bool,
    ) -> Prefetch {
        let mut pf = Prefetch::none();
        self.push_coefficients(&mut pf, cl, coef, real);
        pf
    }

    /// What the forward of `cl` will read and write, as prefetch hints (never read through
    /// them): its lane rows of the chunk (`2 hp` rows of `cl.p` doubles, `ch.row_len`
    /// apart, from `rows`: in a lane-major buffer far apart, which the hardware does not
    /// prefetch) and its coefficient blocks at `coef`.
    pub fn forward_hints(
        &self,
        cl: &ClusterPlan,
        ch: ChunkLanes,
        rows: *const f64,
        coef: *const Complex64,
    ) -> Prefetch {
        let mut pf = Prefetch::none();
        pf.push_rows(rows, cl.p, (ch.row_len, ch.hp));
        pf.push_rows(rows.wrapping_add(ch.upper_gap), cl.p, (ch.row_len, ch.hp));
        self.push_coefficients(&mut pf, cl, coef, false);
        pf
    }

    /// Adds to `pf` the degrees of the coefficient blocks of `cl`'s slots that a kernel
    /// touches (with `real`, the partners' blocks of the non-representatives).
    fn push_coefficients(
        &self,
        pf: &mut Prefetch,
        cl: &ClusterPlan,
        coef: *const Complex64,
        real: bool,
    ) {
        for s in &cl.slots {
            let block = if real && !s.representative {
                s.partner_block
            } else {
                s.block
            };
            let lo = cl.m.max(s.first);
            let len = self.l.saturating_sub(lo);
            pf.push(
                coef.wrapping_add(block + lo - s.first).cast::<f64>(),
                2 * len,
            );
        }
    }

    /// The kernels' lanes for a chunk in a lane-major buffer: lower row `j` at
    /// `j row_len`, its mirror `upper_gap` further.
    fn lanes<'a>(&self, sc: &'a Scratch, ch: ChunkLanes, stream: bool) -> Lanes<'a> {
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
            stream,
            pair_stride: ch.row_len,
            row_gap: ch.upper_gap,
        }
    }

    /// Fills rows `from..to` of the inverse kernel's input for cluster `cl` (`p` doubles a
    /// row, degree `cl.m + i` in row `i`) from the coefficients at `coef`, scaled by
    /// `scales` (the cluster's recurrence scales) and `1 / 2 pi`. With `real`, the
    /// non-representative order pairs are read from their representatives
    /// (`fhat(l,M,M') = (-1)^(M-M') conj(fhat(l,-M,-M'))`).
    ///
    /// # Safety
    /// `coef` holds the shape's coefficients (read only meanwhile).
    #[allow(clippy::too_many_arguments)]
    unsafe fn fill_rows(
        cl: &ClusterPlan,
        scales: &[f64],
        coef: *const Complex64,
        real: bool,
        fin: &mut [f64],
        from: usize,
        to: usize,
    ) {
        // SAFETY: the caller's contract.
        unsafe {
            Self::fill_columns(
                cl,
                (0..cl.slots.len(), cl.p),
                (scales, coef, real),
                fin,
                (from, to),
            )
        }
    }

    /// [`DwtStage::fill_rows`] for the slots `slots` only, slot `slots.start + q` in
    /// columns `2q, 2q + 1` of rows of `p` doubles.
    ///
    /// # Safety
    /// As for [`DwtStage::fill_rows`].
    unsafe fn fill_columns(
        cl: &ClusterPlan,
        (slots, p): (std::ops::Range<usize>, usize),
        (scales, coef, real): (&[f64], *const Complex64, bool),
        fin: &mut [f64],
        (from, to): (usize, usize),
    ) {
        let slots = &cl.slots[slots];
        let scale = 1.0 / (2.0 * PI);
        // Rows with no value in some column (unused slots, degrees below `L0`) start as 0.
        let partly = 2 * slots.len() < p || slots.iter().any(|s| s.first > cl.m);
        let rows = &mut fin[from * p..to * p];
        if partly {
            rows.fill(0.0);
        }
        for (q, s) in slots.iter().enumerate() {
            let lo = from.max(s.first - cl.m);
            if lo >= to {
                continue;
            }
            let mem = &s.member;
            // The real inverse reads a non-representative from its partner:
            // `(-1)^(M-M') conj(fhat(l,-M,-M'))`.
            let conj = real && !s.representative;
            let (block, sign) = if conj {
                let ps = if (mem.m - mem.mp).rem_euclid(2) == 0 {
                    1.0
                } else {
                    -1.0
                };
                (s.partner_block, ps * scale)
            } else {
                (s.block, scale)
            };
            let factors = DegreeFactors {
                signs: [
                    mem.sign_at(cl.m + lo) * sign,
                    mem.sign_at(cl.m + lo + 1) * sign,
                ],
                scales: &scales[lo..to],
            };
            let dst = &mut rows[(lo - from) * p + 2 * q..];
            // SAFETY: degrees `cl.m + lo .. cl.m + to` of the block (or of its partner,
            // which stores the same degrees) are inside the coefficient array (caller's
            // contract); `dst` holds rows `lo - from .. to - from` of `p >= 2q + 2`
            // doubles.
            unsafe {
                let src = coef.add(block + cl.m + lo - s.first);
                coeffs::gather(dst.as_mut_ptr(), src, p, factors);
            }
            if conj {
                for row in dst.chunks_mut(p).take(to - lo) {
                    row[1] = -row[1];
                }
            }
        }
    }

    /// Doubles of the batched inverse's scratch.
    fn tile_len(&self) -> usize {
        dwt::inverse_tile_len(self.l, self.isa.lanes())
    }

    /// The scratch's kernel inputs or sums for `count` transforms and the batched kernels'
    /// d values, taken out of `sc` (put back after the call), grown on first use.
    fn batch_buffers(&self, sc: &mut Scratch, count: usize) -> (Vec<f64>, Vec<f64>) {
        let mut data = std::mem::take(&mut sc.data);
        if data.len() < count * self.data_len() {
            data = vec![0.0; count * self.data_len()];
        }
        let mut tile = std::mem::take(&mut sc.tile);
        if tile.len() < self.tile_len() {
            tile = vec![0.0; self.tile_len()];
        }
        (data, tile)
    }

    /// Doubles of one transform's kernel input or sums in the scratch.
    fn data_len(&self) -> usize {
        (self.l + 8) * 16
    }

    /// Inverse kernel of `cl` (set up by [`DwtStage::setup`], `n` degrees) from the
    /// coefficients at `coef` into the cluster's slots of the chunk's lane rows at `block`
    /// (lane row `r` at `block + r row_total`, `cl.p` doubles). With `real`, the
    /// non-representative order pairs are read from their representatives (see
    /// [`DwtStage::fill_rows`]). With `stream`, written by non-temporal stores.
    ///
    /// # Safety
    /// `coef` holds the shape's coefficients (read only meanwhile); the `2 hp` rows of
    /// `cl.p` doubles at `block` are valid for writes and nobody else's meanwhile.
    #[allow(clippy::too_many_arguments)]
    pub unsafe fn inverse(
        &self,
        sc: &mut Scratch,
        cl: &ClusterPlan,
        ch: ChunkLanes,
        n: usize,
        coef: *const Complex64,
        (real, stream, next): (bool, bool, Prefetch),
        block: *mut f64,
    ) {
        if let Some(split) = Split::of(cl, ch) {
            // SAFETY: the caller's contract.
            unsafe {
                self.inverse_split(sc, (cl, ch, split), n, coef, (real, stream, next), block)
            };
            return;
        }
        let p = cl.p;
        let mut data = std::mem::take(&mut sc.data);
        if data.len() < self.data_len() {
            data = vec![0.0; self.data_len()];
        }
        let scales = &sc.rec.s;
        // SAFETY: `coef` holds the shape's coefficients (caller's contract).
        let mut fill = |fin: &mut [f64], from: usize, to: usize| unsafe {
            Self::fill_rows(cl, scales, coef, real, fin, from, to)
        };
        let rec = Rec::new(&sc.rec, n);
        let mut lanes = self.lanes(sc, ch, stream);
        lanes.prefetch = next;
        // SAFETY: the chunk's `2 hp` rows of `p` doubles at `block`, addressed as the lanes
        // say, are the caller's (caller's contract).
        unsafe {
            dwt::inverse_raw(
                self.isa,
                p,
                &rec,
                &lanes,
                &mut data[..n * p],
                &mut fill,
                block,
            )
        };
        sc.data = data;
    }

    /// [`DwtStage::inverse`] for a split chunk: the direct members at the written points
    /// and the reversed members at their mirrors, a kernel call of 8 columns each (the
    /// direct members of a cluster without reversed ones: its own width), on the lanes
    /// as [`DwtStage::setup`] orders them. Columns no slice reads (the written
    /// points' reversed ones, the mirrors' direct ones) may hold anything.
    ///
    /// # Safety
    /// As for [`DwtStage::inverse`].
    unsafe fn inverse_split(
        &self,
        sc: &mut Scratch,
        (cl, ch, split): (&ClusterPlan, ChunkLanes, Split),
        n: usize,
        coef: *const Complex64,
        (real, stream, next): (bool, bool, Prefetch),
        block: *mut f64,
    ) {
        let mut data = std::mem::take(&mut sc.data);
        if data.len() < self.data_len() {
            data = vec![0.0; self.data_len()];
        }
        let (k, hp, len, gap) = (split.first_upper, ch.hp, ch.row_len, ch.upper_gap);
        debug_assert!(k <= hp && k.is_multiple_of(self.isa.lanes()));
        let (fin_direct, fin_reversed) = data.split_at_mut(n * split.direct_p);
        let scales = &sc.rec.s;
        let rec = Rec::new(&sc.rec, n);
        let mut next = Some(next);
        let calls = [
            SplitCall {
                slots: 0..split.direct,
                p: split.direct_p,
                fin: fin_direct,
                column: 0,
                lanes: 0..hp,
                upper_from: k,
                first_pair: 0,
                row_gap: gap + k * len,
            },
            SplitCall {
                slots: split.direct..cl.slots.len(),
                p: 8,
                fin: fin_reversed,
                column: 2 * split.direct,
                lanes: hp..2 * hp,
                upper_from: hp - k,
                // Without lower lanes the upper rows are addressed from the first pair (a
                // zero gap would mean rows side by side).
                first_pair: if k < hp { k } else { 0 },
                row_gap: if k < hp { gap - k * len } else { gap },
            },
        ];
        for c in calls {
            if c.slots.is_empty() {
                continue;
            }
            debug_assert!(c.column + c.p <= cl.p);
            let (slots, p) = (c.slots, c.p);
            // SAFETY: `coef` holds the shape's coefficients (caller's contract).
            let mut fill = |fin: &mut [f64], from: usize, to: usize| unsafe {
                Self::fill_columns(
                    cl,
                    (slots.clone(), p),
                    (scales, coef, real),
                    fin,
                    (from, to),
                )
            };
            let mut l = self.lanes(sc, ch, stream);
            l.tau = &sc.tau[c.lanes.clone()];
            l.p = &sc.start[c.lanes.clone()];
            l.sc = &sc.scale[c.lanes];
            l.upper_from = c.upper_from;
            l.row_gap = c.row_gap;
            l.prefetch = next.take().unwrap_or(Prefetch::none());
            // SAFETY: the first call's lanes write rows `0..k` (lower) and `hp + k..2 hp`
            // (upper), the second call's rows `k..hp` and `hp..hp + k`: rows of the chunk,
            // each lane `p` doubles from `column`, inside the cluster's `cl.p` columns
            // (`column + p <= cl.p`, see `Split::of`), all the caller's (caller's contract).
            unsafe {
                dwt::inverse_raw(
                    self.isa,
                    p,
                    &rec,
                    &l,
                    &mut c.fin[..n * p],
                    &mut fill,
                    block.wrapping_add(c.column + c.first_pair * len),
                )
            };
        }
        sc.data = data;
    }

    /// [`DwtStage::inverse`] for a batch sharing the recurrence: transform `t` from the
    /// coefficients at `coef.base + t coef.dist` into the lane rows at
    /// `block.base + t block.dist`, prefetching meanwhile the coefficient blocks that the
    /// next call reads (`next`: its cluster and coefficient arrays). Bitwise the results of
    /// single calls.
    ///
    /// # Safety
    /// As for [`DwtStage::inverse`], for every transform of the batch.
    #[allow(clippy::too_many_arguments)]
    pub unsafe fn inverse_many(
        &self,
        sc: &mut Scratch,
        cl: &ClusterPlan,
        ch: ChunkLanes,
        n: usize,
        coef: BatchRows<*const Complex64>,
        (real, stream, next): (
            bool,
            bool,
            Option<(&ClusterPlan, BatchRows<*const Complex64>)>,
        ),
        block: BatchRows<*mut f64>,
    ) {
        if Split::of(cl, ch).is_some() {
            // Split chunks (selected betas) run their transforms one by one.
            for t in 0..coef.count {
                let hint = if t + 1 < coef.count {
                    self.coefficient_hints(cl, coef.base.wrapping_add((t + 1) * coef.dist), real)
                } else {
                    next.map_or(Prefetch::none(), |(c, rows)| {
                        self.coefficient_hints(c, rows.base, real)
                    })
                };
                // SAFETY: transform `t`'s coefficients and rows (caller's contract).
                unsafe {
                    self.inverse(
                        sc,
                        cl,
                        ch,
                        n,
                        coef.base.wrapping_add(t * coef.dist),
                        (real, stream, hint),
                        block.base.wrapping_add(t * block.dist),
                    )
                };
            }
            return;
        }
        let (p, dist) = (cl.p, self.data_len());
        let (mut data, mut tile) = self.batch_buffers(sc, coef.count);
        let scales = &sc.rec.s;
        // SAFETY: coefficient array `t` of the batch holds the shape's coefficients
        // (caller's contract).
        let mut fill = |t: usize, fin: &mut [f64], from: usize, to: usize| unsafe {
            let c = coef.base.add(t * coef.dist);
            Self::fill_rows(cl, scales, c, real, fin, from, to)
        };
        assert!(coef.count <= KERNEL_BATCH);
        let mut hints = [Prefetch::none(); KERNEL_BATCH];
        if let Some((c, rows)) = next {
            for (t, h) in hints
                .iter_mut()
                .enumerate()
                .take(rows.count.min(coef.count))
            {
                *h = self.coefficient_hints(c, rows.base.wrapping_add(t * rows.dist), real);
            }
        }
        let rec = Rec::new(&sc.rec, n);
        let lanes = self.lanes(sc, ch, stream);
        let fin = BatchRows {
            base: data.as_mut_ptr(),
            dist,
            count: coef.count,
        };
        // SAFETY: `data` holds `count` inputs `dist >= n p` doubles apart; the lane rows of
        // every transform are the caller's (caller's contract).
        unsafe {
            dwt::inverse_batch_raw(
                self.isa,
                p,
                (&rec, &lanes),
                (fin, &mut fill, &mut hints[..coef.count]),
                &mut tile,
                block,
            )
        };
        sc.data = data;
        sc.tile = tile;
    }

    /// Forward kernel of `cl` over its slots of the chunk's lane rows at `block` (as for
    /// [`DwtStage::inverse`]; padding rows zero), accumulated into the coefficients at
    /// `coef` (`first`: assign instead), prefetching `next` meanwhile.
    ///
    /// # Safety
    /// The rows at `block` are valid for reads; `coef` holds the shape's coefficients,
    /// whose blocks of this cluster's slots nobody else touches meanwhile.
    #[allow(clippy::too_many_arguments)]
    pub unsafe fn forward(
        &self,
        sc: &mut Scratch,
        cl: &ClusterPlan,
        (ch, n): (ChunkLanes, usize),
        block: *const f64,
        (coef, first, next): (*mut Complex64, bool, Prefetch),
    ) {
        let p = cl.p;
        let mut data = std::mem::take(&mut sc.data);
        if data.len() < self.data_len() {
            data = vec![0.0; self.data_len()];
        }
        let rec = Rec::new(&sc.rec, n);
        let mut lanes = self.lanes(sc, ch, false);
        lanes.prefetch = next;
        // SAFETY: the `2 hp` rows of `p` doubles at `block`, read only (caller's contract).
        let lo = unsafe { dwt::forward_raw(self.isa, p, &rec, &lanes, block, &mut data) }.min(n);
        // SAFETY: `data` holds the kernel's sums; the blocks are the caller's.
        unsafe { self.scatter_sums(cl, (n, lo), &sc.rec.s, data.as_ptr(), (coef, first)) };
        sc.data = data;
    }

    /// Adds the forward kernel's sums of `cl` (`n` rows of `cl.p`, rows below `lo` zero),
    /// scaled by the recurrence scales `scales`, into its slots' coefficient blocks at
    /// `coef` (`first`: assigns, zero below `lo`).
    ///
    /// # Safety
    /// `sums` holds the `n` rows; the blocks of this cluster's slots in `coef` are valid
    /// and nobody else's meanwhile.
    unsafe fn scatter_sums(
        &self,
        cl: &ClusterPlan,
        (n, lo): (usize, usize),
        scales: &[f64],
        sums: *const f64,
        (coef, first): (*mut Complex64, bool),
    ) {
        let p = cl.p;
        for (q, s) in cl.slots.iter().enumerate() {
            let mem = &s.member;
            let i0 = s.first - cl.m;
            // Degrees below the kernel's `lo` are zero: assigned on the first chunk, else
            // nothing to add.
            let from = i0.max(lo);
            // A half stage's member `M' > 0` also writes its partner `(-M, -M')` (whose
            // degrees start at the same one), from the final sums.
            let partner = (self.half && mem.mp > 0).then(|| {
                let sign = if (mem.m - mem.mp).rem_euclid(2) == 0 {
                    1.0
                } else {
                    -1.0
                };
                (s.partner_block, sign)
            });
            if first && lo > i0 {
                for block in std::iter::once(s.block).chain(partner.map(|p| p.0)) {
                    // SAFETY: degrees `s.first .. cl.m + lo` of the pair's block (or its
                    // partner's), this cluster's (caller's contract).
                    unsafe { std::ptr::write_bytes(coef.add(block), 0, lo - i0) };
                }
            }
            if from >= n {
                continue;
            }
            let factors = DegreeFactors {
                signs: [mem.sign_at(cl.m + from), mem.sign_at(cl.m + from + 1)],
                scales: &scales[from..n],
            };
            // SAFETY: degrees `cl.m + from .. L` of the pair's block (this cluster's, caller's
            // contract); `sums` holds the kernel's `n` rows of `p >= 2q + 2` sums.
            unsafe {
                let at = cl.m + from - s.first;
                let dst = coef.add(s.block + at);
                let partner = partner.map(|(block, sign)| (coef.add(block + at), sign));
                coeffs::scatter(dst, sums.add(from * p + 2 * q), p, factors, !first, partner);
            }
        }
    }
}
