//! The DWT stage of a partial plan: the clusters whose order pairs the shape holds, and the
//! kernels over a chunk of lane pairs, writing (inverse) or reading (forward) each
//! cluster's block of the chunk buffer.
//!
//! A chunk of `h` lane pairs (padded to `hp`, a multiple of the vector width) has `2 hp`
//! lane rows: rows `0..hp` the pairs' lower points, rows `hp..2hp` their mirrors. The
//! chunk buffer is lane-major: a lane row holds every cluster's `P` values (16 for
//! clusters of more than four order pairs in the shape, else 8) one after another, so the
//! FFT stage reads or writes a slice's values in one sequential pass. Slot `q` of a
//! cluster's row holds the value of its `q`-th order pair present in the shape (or, for a
//! reversed member, its value at the row's mirror). With a batch, the lane rows of
//! transform `t` follow those of transform `t - 1`.
//!
//! A stage in `f32` runs most clusters' kernels in `f32`; the clusters where the `f32`
//! recurrence loses too much ([`f64_recurrence`]) run the `f64` kernels on rows of their
//! own, rounded into (inverse) or widened from (forward) the chunk's rows.

use super::betas::LanePairs;
use super::coeffs::{self, DegreeFactors};
use crate::dwt::{self, BatchRows, Lanes, Prefetch, Rec};
use crate::numeric::{Elem, Ext};
use crate::shape::CoefLayout;
use crate::simd::Isa;
use crate::symmetry::{Cluster, Member};
use crate::wigner::{big, start_norm, RecCoeffs, RecTables};
use crate::Real;
use num_complex::Complex;
use rayon::prelude::*;
use std::f64::consts::PI;
use std::marker::PhantomData;
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
    /// Values per block row: 16 for more than four slots, else 8.
    pub p: usize,
    pub slots: Vec<Slot>,
    /// Values before this cluster's in a lane row.
    pub offset: usize,
    /// Whether its kernels run in `f64` in a stage of a narrower type (see
    /// [`f64_recurrence`]).
    pub wide: bool,
}

/// Whether the `f32` recurrence of cluster `(m, m')` at degree limit `l` loses more than
/// the single-precision tier allows (a cluster round trip above about `5e-6`), so its
/// kernels run in `f64`: orders 0 and 1 up to `L = 128`; from `L = 256` on the orders
/// below 16 and the near-diagonal band `m - m' <= 4` below `L / 2`; from `L = 512` on
/// every cluster (the `f32` recurrence's own error grows past the bound there). Measured
/// in `notes/reference/f32_recurrence/rust-twin.md`.
pub(crate) fn f64_recurrence(l: usize, m: usize, mp: usize) -> bool {
    if l > 256 {
        true
    } else if l > 128 {
        m < 16 || (m - mp <= 4 && 2 * m < l)
    } else {
        m < 2
    }
}

/// Values of `T` from one lane row of `len` values (a multiple of 8) to the next in a
/// buffer: `len` padded to an odd number of cache lines, so that a cluster's values in all
/// rows fall in different cache sets (rows of a multiple of 4 KiB put them all in one);
/// empty rows stay empty.
pub(crate) fn padded_row<T: Elem>(len: usize) -> usize {
    let line = 64 / T::BYTES;
    let len = len.next_multiple_of(line);
    len + if len > 0 && (len / line).is_multiple_of(2) {
        line
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
    /// Values of a lane row in the buffer the kernels run on (the DWT stage's
    /// `row_total`, or a distributed plan's segment of it).
    pub row_len: usize,
    /// Values from the first lower lane row to the first upper one (`hp row_len` in a
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

    /// The chunk's lanes of one cluster of `p` values in rows of their own: lower row `r`
    /// at `r p`, upper row `r` at `(max(hp, 2) + r) p` (the kernels take a gap of one row
    /// for interleaved rows).
    fn own_rows(self, p: usize) -> ChunkLanes {
        ChunkLanes {
            row_len: p,
            upper_gap: self.hp.max(2) * p,
            ..self
        }
    }

    /// Values from the first lane row to lane row `r` (lower rows `0..hp`, then the upper
    /// ones).
    fn row_offset(self, r: usize) -> usize {
        if r < self.hp {
            r * self.row_len
        } else {
            self.upper_gap + (r - self.hp) * self.row_len
        }
    }

    /// Values of a buffer of the lane rows in one piece ([`ChunkLanes::own_rows`]).
    fn own_len(self) -> usize {
        self.upper_gap + self.hp * self.row_len
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

/// What the next batched inverse call reads: its cluster and coefficient arrays.
pub(crate) type NextCall<'a, T> = (&'a ClusterPlan, BatchRows<*const Complex<T>>);

/// One kernel call of [`DwtStage::inverse_split`].
struct SplitCall<'a, K> {
    /// The cluster's slots it computes, in `p` columns from `column` of each row.
    slots: std::ops::Range<usize>,
    p: usize,
    column: usize,
    /// Its input rows.
    fin: &'a mut [K],
    /// Its lanes (reordered), the lower-form ones before `upper_from`.
    lanes: std::ops::Range<usize>,
    upper_from: usize,
    /// The pair of its first lower lane's row, and the offset from that row to its first
    /// upper lane's row.
    first_pair: usize,
    row_gap: usize,
}

/// A kernel's lane inputs and buffers in its element type `K`.
struct KernelScratch<K> {
    tau: Vec<K>,
    start: Vec<K>,
    scale: Vec<K>,
    /// Inverse input / forward sums (one transform's or a batch's).
    data: Vec<K>,
    /// The batched kernels' d values.
    tile: Vec<K>,
}

impl<K: Elem> KernelScratch<K> {
    fn new() -> KernelScratch<K> {
        KernelScratch {
            tau: Vec::new(),
            start: Vec::new(),
            scale: Vec::new(),
            data: Vec::new(),
            tile: Vec::new(),
        }
    }

    /// Made for `lanes` lanes and degree limit `l` on first use.
    fn ensure(&mut self, l: usize, lanes: usize) -> &mut KernelScratch<K> {
        if self.tau.len() < lanes {
            for v in [&mut self.tau, &mut self.start, &mut self.scale] {
                *v = vec![K::ZERO; lanes];
            }
        }
        if self.data.is_empty() {
            self.data = vec![K::ZERO; (l + 64 / K::BYTES) * 16];
        }
        self
    }
}

/// Per-worker scratch: the cluster's recurrence coefficients (in `f64`, and rounded to
/// `f32` for `f32` kernels) and the kernels' buffers of both types (made on first use).
pub(crate) struct Scratch {
    rec: RecCoeffs,
    rec32: RecCoeffs<f32>,
    wide: KernelScratch<f64>,
    narrow: KernelScratch<f32>,
    /// A cluster's own rows of `f64` kernels in an `f32` stage.
    rows: Vec<f64>,
}

impl Scratch {
    fn new(l: usize) -> Scratch {
        Scratch {
            rec: RecCoeffs::new(l),
            rec32: RecCoeffs::new(0),
            wide: KernelScratch::new(),
            narrow: KernelScratch::new(),
            rows: Vec::new(),
        }
    }
}

/// The kernels' element types, and where their scratch is.
trait KernelElem: Real {
    /// The cluster's coefficients in this type, its scales `S_i` (in `f64`), and this
    /// type's kernel buffers (made for `l` and `lanes` on first use).
    fn parts(sc: &mut Scratch, l: usize, lanes: usize) -> KernelParts<'_, Self>;
}

/// What [`KernelElem::parts`] gives.
type KernelParts<'a, K> = (&'a RecCoeffs<K>, &'a [f64], &'a mut KernelScratch<K>);

impl KernelElem for f64 {
    fn parts(sc: &mut Scratch, l: usize, lanes: usize) -> KernelParts<'_, f64> {
        (&sc.rec, &sc.rec.s, sc.wide.ensure(l, lanes))
    }
}

impl KernelElem for f32 {
    fn parts(sc: &mut Scratch, l: usize, lanes: usize) -> KernelParts<'_, f32> {
        (&sc.rec32, &sc.rec.s, sc.narrow.ensure(l, lanes))
    }
}

/// The DWT stage of a partial plan, its lane rows in `T`.
pub(crate) struct DwtStage<T: Real = f64> {
    isa: Isa,
    /// Degree limit `L`.
    l: usize,
    pub clusters: Vec<ClusterPlan>,
    /// Values of a lane row (all clusters).
    pub row_total: usize,
    /// Values from one lane row to the next in a lane-major chunk buffer: `row_total`
    /// padded ([`padded_row`]).
    pub row_stride: usize,
    recurrence: RecTables,
    skip_bits: u32,
    skip: bool,
    /// Only the members `M' >= 0` (see [`DwtStage::new`]).
    half: bool,
    scratch: Vec<Mutex<Scratch>>,
    max_lanes: usize,
    elem: PhantomData<T>,
}

impl<T: Real> DwtStage<T> {
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
    ) -> DwtStage<T> {
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
                    wide: T::BYTES < 8 && f64_recurrence(l, m, mp),
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
            row_stride: padded_row::<T>(offset),
            recurrence: RecTables::for_orders(l, &orders),
            skip_bits,
            skip,
            scratch: (0..workers).map(|_| Mutex::new(Scratch::new(l))).collect(),
            max_lanes,
            half,
            elem: PhantomData,
        }
    }

    /// Values of a cluster with `n` slots in a lane row: 16 for more than four, 8 for one
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
        padded_row::<T>(offset)
    }

    /// Bytes of the stage's tables and scratch (approximately): the kernels' buffers in
    /// `T`, and in an `f32` stage also those of its `f64` clusters with their own rows.
    pub fn bytes(l: usize, clusters: usize, workers: usize, max_lanes: usize) -> usize {
        let kernel =
            |bytes: usize| bytes * (3 * max_lanes + (KERNEL_BATCH + 1) * 16 * (l + 64 / bytes));
        let wide = if T::BYTES < 8 {
            kernel(8) + 8 * 16 * max_lanes + 4 * 5 * l
        } else {
            0
        };
        32 * (l + 1) * (l + 2) + clusters * 256 + workers * (kernel(T::BYTES) + 8 * 21 * l + wide)
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
            None => f(&mut Scratch::new(self.l)),
        }
    }

    /// Whether `cl`'s kernels run in `f32` (an `f32` stage, not one of its `f64` clusters).
    fn narrow(&self, cl: &ClusterPlan) -> bool {
        T::BYTES < 8 && !cl.wide
    }

    /// Lanes per vector of the kernels of element `K`.
    fn width<K: Elem>(&self) -> usize {
        self.isa.lanes_of::<K>()
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
        if self.narrow(cl) {
            sc.rec32.narrow_from(&sc.rec);
        }
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
        if self.narrow(cl) {
            self.lane_inputs::<f32>(sc, cl, pairs, ch)
        } else {
            self.lane_inputs::<f64>(sc, cl, pairs, ch)
        }
    }

    /// [`DwtStage::setup_lanes`] for kernels of element `K`.
    fn lane_inputs<K: KernelElem>(
        &self,
        sc: &mut Scratch,
        cl: &ClusterPlan,
        pairs: &LanePairs,
        ch: ChunkLanes,
    ) -> usize {
        let n = self.l - cl.m;
        let t = &pairs.tables;
        let (h, hp) = (ch.h, ch.hp);
        let (_, _, ks) = K::parts(sc, self.l, self.max_lanes);
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
            t.starts::<K>(
                self.isa,
                first_point,
                cl.m,
                cl.mp,
                cl.norm,
                self.skip_bits,
                &mut ks.start[u0..u0 + live],
                &mut ks.scale[u0..u0 + live],
            );
            let tau = if upper { &t.tau_hi } else { &t.tau_lo };
            for (d, &x) in ks.tau[u0..u0 + live]
                .iter_mut()
                .zip(&tau[first_point..first_point + live])
            {
                *d = K::from_f64(x);
            }
            for v in [&mut ks.tau, &mut ks.start, &mut ks.scale] {
                v[u0 + live..u0 + len].fill(K::ZERO);
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
        coef: *const Complex<T>,
        real: bool,
    ) -> Prefetch {
        let mut pf = Prefetch::none();
        self.push_coefficients(&mut pf, cl, coef, real);
        pf
    }

    /// What the forward of `cl` will read and write, as prefetch hints (never read through
    /// them): its lane rows of the chunk (`2 hp` rows of `cl.p` values, `ch.row_len`
    /// apart, from `rows`: in a lane-major buffer far apart, which the hardware does not
    /// prefetch) and its coefficient blocks at `coef`.
    pub fn forward_hints(
        &self,
        cl: &ClusterPlan,
        ch: ChunkLanes,
        rows: *const T,
        coef: *const Complex<T>,
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
        coef: *const Complex<T>,
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
            pf.push(coef.wrapping_add(block + lo - s.first), len);
        }
    }

    /// The kernels' lanes for a chunk in a lane-major buffer: lower row `j` at
    /// `j row_len`, its mirror `upper_gap` further.
    fn lanes<'a, K: Elem>(
        &self,
        ks: &'a KernelScratch<K>,
        ch: ChunkLanes,
        stream: bool,
    ) -> Lanes<'a, K> {
        let nl = ch.lanes();
        Lanes {
            tau: &ks.tau[..nl],
            p: &ks.start[..nl],
            sc: &ks.scale[..nl],
            upper_from: ch.hp,
            big: big::<K>(self.skip_bits),
            skip: self.skip,
            interleaved: true,
            prefetch: Prefetch::none(),
            stream,
            pair_stride: ch.row_len,
            row_gap: ch.upper_gap,
        }
    }

    /// Fills rows `from..to` of the inverse kernel's input for cluster `cl` (`p` values a
    /// row, degree `cl.m + i` in row `i`) from the coefficients at `coef`, scaled by
    /// `scales` (the cluster's recurrence scales) and `1 / 2 pi`. With `real`, the
    /// non-representative order pairs are read from their representatives
    /// (`fhat(l,M,M') = (-1)^(M-M') conj(fhat(l,-M,-M'))`).
    ///
    /// # Safety
    /// `coef` holds the shape's coefficients (read only meanwhile).
    #[allow(clippy::too_many_arguments)]
    unsafe fn fill_rows<K: Elem>(
        cl: &ClusterPlan,
        scales: &[f64],
        coef: *const Complex<T>,
        real: bool,
        fin: &mut [K],
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
    /// columns `2q, 2q + 1` of rows of `p` values.
    ///
    /// # Safety
    /// As for [`DwtStage::fill_rows`].
    unsafe fn fill_columns<K: Elem>(
        cl: &ClusterPlan,
        (slots, p): (std::ops::Range<usize>, usize),
        (scales, coef, real): (&[f64], *const Complex<T>, bool),
        fin: &mut [K],
        (from, to): (usize, usize),
    ) {
        let slots = &cl.slots[slots];
        let scale = 1.0 / (2.0 * PI);
        // Rows with no value in some column (unused slots, degrees below `L0`) start as 0.
        let partly = 2 * slots.len() < p || slots.iter().any(|s| s.first > cl.m);
        let rows = &mut fin[from * p..to * p];
        if partly {
            rows.fill(K::ZERO);
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
            // values.
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

    /// Values of the batched inverse's scratch for kernels of `K`.
    fn tile_len<K: Elem>(&self) -> usize {
        dwt::inverse_tile_len(self.l, self.width::<K>())
    }

    /// Values of one transform's kernel input or sums in the scratch for kernels of `K`
    /// (a vector's rows more than the degrees).
    fn data_len<K: Elem>(&self) -> usize {
        (self.l + self.width::<K>().max(8)) * 16
    }

    /// Inverse kernel of `cl` (set up by [`DwtStage::setup`], `n` degrees) from the
    /// coefficients at `coef` into the cluster's slots of the chunk's lane rows at `block`
    /// (lane row `r` at `block + r row_total`, `cl.p` values). With `real`, the
    /// non-representative order pairs are read from their representatives (see
    /// [`DwtStage::fill_rows`]). With `stream`, written by non-temporal stores.
    ///
    /// # Safety
    /// `coef` holds the shape's coefficients (read only meanwhile); the `2 hp` rows of
    /// `cl.p` values at `block` are valid for writes and nobody else's meanwhile.
    #[allow(clippy::too_many_arguments)]
    pub unsafe fn inverse(
        &self,
        sc: &mut Scratch,
        cl: &ClusterPlan,
        ch: ChunkLanes,
        n: usize,
        coef: *const Complex<T>,
        (real, stream, next): (bool, bool, Prefetch),
        block: *mut T,
    ) {
        let run = (real, stream, next);
        // SAFETY: the caller's contract, for all three calls; `T` is `f32` where it is not
        // `f64` (sealed), so the casts keep the element type. The copy writes `cl.p` values
        // of each of the chunk's `2 hp` lane rows at `block` (the caller's).
        unsafe {
            if T::BYTES == 8 {
                self.inverse_in::<f64>(sc, (cl, ch, n), coef, run, block.cast())
            } else if !cl.wide {
                self.inverse_in::<f32>(sc, (cl, ch, n), coef, run, block.cast())
            } else {
                // `f64` kernels into the cluster's own rows, then rounded into the chunk's.
                let own = ch.own_rows(cl.p);
                let mut rows = std::mem::take(&mut sc.rows);
                rows.resize(own.own_len(), 0.0);
                self.inverse_in::<f64>(
                    sc,
                    (cl, own, n),
                    coef,
                    (real, false, next),
                    rows.as_mut_ptr(),
                );
                for r in 0..ch.lanes() {
                    let from = &rows[own.row_offset(r)..][..cl.p];
                    let to = block.add(ch.row_offset(r));
                    for (q, &x) in from.iter().enumerate() {
                        *to.add(q) = T::from_f64(x);
                    }
                }
                sc.rows = rows;
            }
        }
    }

    /// [`DwtStage::inverse`] with kernels of `K` into rows of `K`.
    ///
    /// # Safety
    /// As for [`DwtStage::inverse`].
    unsafe fn inverse_in<K: KernelElem>(
        &self,
        sc: &mut Scratch,
        (cl, ch, n): (&ClusterPlan, ChunkLanes, usize),
        coef: *const Complex<T>,
        (real, stream, next): (bool, bool, Prefetch),
        block: *mut K,
    ) {
        if let Some(split) = Split::of(cl, ch) {
            // SAFETY: the caller's contract.
            unsafe {
                self.inverse_split::<K>(sc, (cl, ch, split), n, coef, (real, stream, next), block)
            };
            return;
        }
        let p = cl.p;
        let data_len = self.data_len::<K>();
        let (rc, scales, ks) = K::parts(sc, self.l, self.max_lanes);
        let mut data = std::mem::take(&mut ks.data);
        if data.len() < data_len {
            data = vec![K::ZERO; data_len];
        }
        // SAFETY: `coef` holds the shape's coefficients (caller's contract).
        let mut fill = |fin: &mut [K], from: usize, to: usize| unsafe {
            Self::fill_rows(cl, scales, coef, real, fin, from, to)
        };
        let rec = Rec::new(rc, n);
        let mut lanes = self.lanes(ks, ch, stream);
        lanes.prefetch = next;
        // SAFETY: the chunk's `2 hp` rows of `p` values at `block`, addressed as the lanes
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
        ks.data = data;
    }

    /// [`DwtStage::inverse_in`] for a split chunk: the direct members at the written points
    /// and the reversed members at their mirrors, a kernel call of 8 columns each (the
    /// direct members of a cluster without reversed ones: its own width), on the lanes
    /// as [`DwtStage::setup`] orders them. Columns no slice reads (the written
    /// points' reversed ones, the mirrors' direct ones) may hold anything.
    ///
    /// # Safety
    /// As for [`DwtStage::inverse`].
    unsafe fn inverse_split<K: KernelElem>(
        &self,
        sc: &mut Scratch,
        (cl, ch, split): (&ClusterPlan, ChunkLanes, Split),
        n: usize,
        coef: *const Complex<T>,
        (real, stream, next): (bool, bool, Prefetch),
        block: *mut K,
    ) {
        let data_len = self.data_len::<K>();
        let (rc, scales, ks) = K::parts(sc, self.l, self.max_lanes);
        let mut data = std::mem::take(&mut ks.data);
        if data.len() < data_len {
            data = vec![K::ZERO; data_len];
        }
        let (k, hp, len, gap) = (split.first_upper, ch.hp, ch.row_len, ch.upper_gap);
        debug_assert!(k <= hp && k.is_multiple_of(self.width::<K>()));
        let (fin_direct, fin_reversed) = data.split_at_mut(n * split.direct_p);
        let rec = Rec::new(rc, n);
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
            let mut fill = |fin: &mut [K], from: usize, to: usize| unsafe {
                Self::fill_columns(
                    cl,
                    (slots.clone(), p),
                    (scales, coef, real),
                    fin,
                    (from, to),
                )
            };
            let mut l = self.lanes(ks, ch, stream);
            l.tau = &ks.tau[c.lanes.clone()];
            l.p = &ks.start[c.lanes.clone()];
            l.sc = &ks.scale[c.lanes];
            l.upper_from = c.upper_from;
            l.row_gap = c.row_gap;
            l.prefetch = next.take().unwrap_or(Prefetch::none());
            // SAFETY: the first call's lanes write rows `0..k` (lower) and `hp + k..2 hp`
            // (upper), the second call's rows `k..hp` and `hp..hp + k`: rows of the chunk,
            // each lane `p` values from `column`, inside the cluster's `cl.p` columns
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
        ks.data = data;
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
        coef: BatchRows<*const Complex<T>>,
        (real, stream, next): (bool, bool, Option<NextCall<'_, T>>),
        block: BatchRows<*mut T>,
    ) {
        if Split::of(cl, ch).is_some() || (T::BYTES < 8 && cl.wide) {
            // Split chunks (selected betas) and the `f64` clusters of an `f32` stage run
            // their transforms one by one.
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
        let hints = &mut hints[..coef.count];
        // SAFETY: the caller's contract, for both calls; `T` is `f32` where it is not `f64`.
        unsafe {
            if T::BYTES == 8 {
                let b = BatchRows {
                    base: block.base.cast::<f64>(),
                    dist: block.dist,
                    count: block.count,
                };
                self.inverse_many_in::<f64>(sc, (cl, ch, n), coef, (real, stream, hints), b)
            } else {
                let b = BatchRows {
                    base: block.base.cast::<f32>(),
                    dist: block.dist,
                    count: block.count,
                };
                self.inverse_many_in::<f32>(sc, (cl, ch, n), coef, (real, stream, hints), b)
            }
        }
    }

    /// [`DwtStage::inverse_many`] with kernels of `K` (no split, `cl` not widened).
    ///
    /// # Safety
    /// As for [`DwtStage::inverse_many`].
    unsafe fn inverse_many_in<K: KernelElem>(
        &self,
        sc: &mut Scratch,
        (cl, ch, n): (&ClusterPlan, ChunkLanes, usize),
        coef: BatchRows<*const Complex<T>>,
        (real, stream, hints): (bool, bool, &mut [Prefetch]),
        block: BatchRows<*mut K>,
    ) {
        let (p, dist) = (cl.p, self.data_len::<K>());
        let (tile_len, l) = (self.tile_len::<K>(), self.l);
        let (rc, scales, ks) = K::parts(sc, l, self.max_lanes);
        let mut data = std::mem::take(&mut ks.data);
        if data.len() < coef.count * dist {
            data = vec![K::ZERO; coef.count * dist];
        }
        let mut tile = std::mem::take(&mut ks.tile);
        if tile.len() < tile_len {
            tile = vec![K::ZERO; tile_len];
        }
        // SAFETY: coefficient array `t` of the batch holds the shape's coefficients
        // (caller's contract).
        let mut fill = |t: usize, fin: &mut [K], from: usize, to: usize| unsafe {
            let c = coef.base.add(t * coef.dist);
            Self::fill_rows(cl, scales, c, real, fin, from, to)
        };
        assert!(coef.count <= KERNEL_BATCH);
        let rec = Rec::new(rc, n);
        let lanes = self.lanes(ks, ch, stream);
        let fin = BatchRows {
            base: data.as_mut_ptr(),
            dist,
            count: coef.count,
        };
        // SAFETY: `data` holds `count` inputs `dist >= n p` values apart; the lane rows of
        // every transform are the caller's (caller's contract).
        unsafe {
            dwt::inverse_batch_raw(
                self.isa,
                p,
                (&rec, &lanes),
                (fin, &mut fill, hints),
                &mut tile,
                block,
            )
        };
        ks.data = data;
        ks.tile = tile;
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
        block: *const T,
        (coef, first, next): (*mut Complex<T>, bool, Prefetch),
    ) {
        let out = (coef, first, next);
        // SAFETY: the caller's contract, for all three calls; `T` is `f32` where it is not
        // `f64` (sealed), so the casts keep the element type. The copy reads `cl.p` values
        // of each of the chunk's `2 hp` lane rows at `block` (the caller's).
        unsafe {
            if T::BYTES == 8 {
                self.forward_in::<f64>(sc, (cl, ch, n), block.cast(), out)
            } else if !cl.wide {
                self.forward_in::<f32>(sc, (cl, ch, n), block.cast(), out)
            } else {
                // The chunk's rows widened into the cluster's own, then `f64` kernels.
                let own = ch.own_rows(cl.p);
                let mut rows = std::mem::take(&mut sc.rows);
                rows.resize(own.own_len(), 0.0);
                for r in 0..ch.lanes() {
                    let from = block.add(ch.row_offset(r));
                    let to = &mut rows[own.row_offset(r)..][..cl.p];
                    for (q, x) in to.iter_mut().enumerate() {
                        *x = (*from.add(q)).to_f64();
                    }
                }
                self.forward_in::<f64>(sc, (cl, own, n), rows.as_ptr(), out);
                sc.rows = rows;
            }
        }
    }

    /// [`DwtStage::forward`] with kernels of `K` on rows of `K`.
    ///
    /// # Safety
    /// As for [`DwtStage::forward`].
    unsafe fn forward_in<K: KernelElem>(
        &self,
        sc: &mut Scratch,
        (cl, ch, n): (&ClusterPlan, ChunkLanes, usize),
        block: *const K,
        (coef, first, next): (*mut Complex<T>, bool, Prefetch),
    ) {
        let p = cl.p;
        let data_len = self.data_len::<K>();
        let (rc, scales, ks) = K::parts(sc, self.l, self.max_lanes);
        let mut data = std::mem::take(&mut ks.data);
        if data.len() < data_len {
            data = vec![K::ZERO; data_len];
        }
        let rec = Rec::new(rc, n);
        let mut lanes = self.lanes(ks, ch, false);
        lanes.prefetch = next;
        // SAFETY: the `2 hp` rows of `p` values at `block`, read only (caller's contract).
        let lo = unsafe { dwt::forward_raw(self.isa, p, &rec, &lanes, block, &mut data) }.min(n);
        // SAFETY: `data` holds the kernel's sums; the blocks are the caller's.
        unsafe { self.scatter_sums(cl, (n, lo), scales, data.as_ptr(), (coef, first)) };
        ks.data = data;
    }

    /// Adds the forward kernel's sums of `cl` (`n` rows of `cl.p`, rows below `lo` zero),
    /// scaled by the recurrence scales `scales`, into its slots' coefficient blocks at
    /// `coef` (`first`: assigns, zero below `lo`).
    ///
    /// # Safety
    /// `sums` holds the `n` rows; the blocks of this cluster's slots in `coef` are valid
    /// and nobody else's meanwhile.
    unsafe fn scatter_sums<K: Elem>(
        &self,
        cl: &ClusterPlan,
        (n, lo): (usize, usize),
        scales: &[f64],
        sums: *const K,
        (coef, first): (*mut Complex<T>, bool),
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
