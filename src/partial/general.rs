//! The engine of every plan shape (a [`PartialPlan`](super::PartialPlan); [`Plan`](crate::Plan)
//! is its full shape): its construction, and its transforms one chunk of lane pairs at a
//! time (the DWT stage over all clusters, and the FFT stage over the chunk's slices).

use super::betas::LanePairs;
use super::dwt_stage::{ChunkLanes, DwtStage, KERNEL_BATCH};
use super::fft_stage::{BufPair, FftStage, SliceRef, SliceWatch, Work, ROW_PAD};
use super::options::Batch;
use super::shape::{CoefLayout, Shape};
use super::slots::{Clear, LaneRows, SlotTable};
use crate::dwt::{BatchRows, Prefetch};
use crate::error::Result;
use crate::fft::ChunkBuffer;
use crate::options::{Betas, Options};
use crate::simd::Isa;
use crate::system::check_headroom;
use crate::transform::Scratch;
use crate::transform::StageTimes;
use crate::workers::{lock_free, SendConstPtr, SendPtr, WorkerPool, WORKER_STACK_BYTES};
use num_complex::Complex64;
use rayon::prelude::*;
use std::f64::consts::PI;
use std::sync::Mutex;
use std::time::Instant;

/// A plan of the engine.
pub(super) struct General {
    pub(super) layout: CoefLayout,
    pub(super) pairs: LanePairs,
    /// Every member of each cluster (complex transforms, distributed plans). Its clusters
    /// are never changed after `new`: `slots` is made from them.
    pub(super) dwt: DwtStage,
    pub(super) fft: FftStage,
    /// The slots of a lane row, flat (for the scatters and gathers, complex and real).
    pub(super) slots: SlotTable,
    /// The real transforms' members (`M' >= 0`, see `DwtStage::new`) with their slots, for
    /// plans made with `Options::real`.
    half: Option<(DwtStage, SlotTable)>,
    /// What the complex and the real inverse zero in a worker's buffer before each slice.
    clears: [Clear; 2],
    /// Forward: `w_{B_grid}(j) 2 pi / (n_alpha n_gamma)` per lane pair (grid betas).
    pub(super) pair_weight: Vec<f64>,
    /// Per-worker FFT buffers (made on first use).
    work: Vec<Mutex<Work>>,
    /// The chunk buffer (taken by one execution at a time).
    buf: ChunkBuffer,
    footprint: Footprint,
    pub(super) workers: WorkerPool,
}

/// What a plan of the engine holds, known before it is made.
#[derive(Clone, Copy, Debug)]
pub(super) struct Footprint {
    /// Everything but the chunk buffer: the DWT stage's tables and per-worker scratch, the
    /// workers' FFT buffers and stacks, the lane pairs' tables.
    rest: usize,
    /// What the chunk buffer may take (the workspace cap).
    budget: usize,
    /// Lane pairs and lanes per vector.
    pairs: usize,
    lanes_w: usize,
    /// Lane-row strides of the complex transforms and (real plans) of the real ones.
    strides: [Option<usize>; 2],
}

impl Footprint {
    /// The footprint of the plan [`General::new`] makes of these arguments.
    pub(super) fn new(
        shape: &Shape,
        pairs: &LanePairs,
        (isa, threads): (Isa, usize),
        options: &Options,
    ) -> Footprint {
        let layout = CoefLayout::new(shape);
        let w = isa.lanes();
        let max_lanes = 2 * pairs.pairs.next_multiple_of(w);
        let tables = pairs.pairs * LanePairs::bytes_per_pair(shape.degree_limit);
        let rest = DwtStage::bytes(shape.degree_limit, 0, threads, max_lanes)
            .saturating_add(threads * (Self::work_bytes(shape, options) + WORKER_STACK_BYTES))
            .saturating_add(tables);
        // The library's one rule (see `Options::default_workspace`).
        let sample_bytes = if options.real { 8 } else { 16 };
        let arrays = sample_bytes * shape.num_samples() + 16 * shape.num_coeffs();
        let budget = options
            .max_workspace_bytes
            .unwrap_or_else(|| Options::default_workspace_here(arrays).saturating_sub(rest));
        let strides = [
            Some(DwtStage::row_stride_of(&layout, false)),
            options.real.then(|| DwtStage::row_stride_of(&layout, true)),
        ];
        Footprint {
            rest,
            budget,
            pairs: pairs.pairs,
            lanes_w: w,
            strides,
        }
    }

    /// Bytes of one worker's FFT buffers (see [`General::reserve`]): two work buffers of
    /// a slice (the forward's and the inverse's), and on a real plan two half-spectrum
    /// buffers and the reals of a slice.
    fn work_bytes(shape: &Shape, options: &Options) -> usize {
        let (na, ng) = (shape.n_alpha, shape.n_gamma);
        let mut bytes = 2 * na * (ng + ROW_PAD) * 16;
        if options.real {
            bytes += 2 * na * (ng / 2 + 1 + ROW_PAD) * 16 + na * ng * 8;
        }
        bytes
    }

    /// Lane pairs whose rows, `row_stride` doubles apart, the workspace cap holds.
    fn room(&self, row_stride: usize) -> usize {
        self.budget / (row_stride * 2 * 8).max(1)
    }

    /// [`Footprint::room`] for one transform: at least one pair, at most all.
    fn most_pairs(&self, row_stride: usize) -> usize {
        self.room(row_stride).clamp(1, self.pairs)
    }

    /// Lane pairs per chunk: what the workspace cap holds for one transform with the rows
    /// of the padding lanes (a chunk's pairs rounded up to the vector width; at least one
    /// pair), the pairs spread evenly over the fewest chunks, a multiple of the vector
    /// width when that fits. It does not depend on the batch, so a batch sums in the order
    /// of single executes.
    fn chunk_pairs(&self, row_stride: usize) -> usize {
        let pairs = self.pairs;
        let w = self.lanes_w;
        let room = self.room(row_stride);
        let fit = if room >= w { room / w * w } else { room }.clamp(1, pairs);
        let h = pairs.div_ceil(pairs.div_ceil(fit));
        if h >= w && h.next_multiple_of(w) <= fit {
            h.next_multiple_of(w)
        } else {
            h
        }
    }

    /// Bytes of the chunk buffer of one transform (the scratch a single call needs): the
    /// larger of the complex and the real transforms'.
    pub(super) fn scratch_bytes(&self) -> usize {
        self.strides
            .iter()
            .flatten()
            .map(|&rs| 8 * rs * 2 * self.chunk_pairs(rs).next_multiple_of(self.lanes_w))
            .max()
            .unwrap_or(0)
    }

    /// Bytes of the whole plan: the chunk buffer and the rest.
    pub(super) fn total(&self) -> usize {
        self.rest.saturating_add(self.scratch_bytes())
    }
}

/// The clusters and slots a transform runs on (see [`General::members`]).
#[derive(Clone, Copy)]
pub(super) struct Members<'a> {
    pub(super) dwt: &'a DwtStage,
    pub(super) slots: &'a SlotTable,
}

/// A chunk and its buffer (lane row `r < hp` at `buf + r row_len`, the upper half
/// `ch.upper_gap` further).
#[derive(Clone, Copy)]
struct PlacedLanes {
    ch: ChunkLanes,
    buf: SendPtr<f64>,
}

/// The samples of one execution (all arrays of a batch) and how they are stored. A
/// forward only reads them.
#[derive(Clone, Copy)]
pub(super) enum Data {
    Complex(SendPtr<Complex64>),
    Real(SendPtr<f64>),
    /// Reals in the real parts of complex values: the inverse sets the imaginary parts to
    /// 0, the forward does not read them.
    RealParts(SendPtr<Complex64>),
}

impl Data {
    /// Whether the samples are a real signal.
    pub(super) fn is_real(self) -> bool {
        !matches!(self, Data::Complex(_))
    }

    /// The samples `values` values further on (in the samples' own type).
    fn offset(self, values: usize) -> Data {
        match self {
            Data::Complex(p) => Data::Complex(SendPtr(p.get().wrapping_add(values))),
            Data::Real(p) => Data::Real(SendPtr(p.get().wrapping_add(values))),
            Data::RealParts(p) => Data::RealParts(SendPtr(p.get().wrapping_add(values))),
        }
    }

    /// Bytes of one value.
    fn value_bytes(self) -> usize {
        match self {
            Data::Real(_) => 8,
            _ => 16,
        }
    }
}

impl General {
    pub(super) fn new(
        shape: &Shape,
        pairs: LanePairs,
        (isa, skip, threads): (Isa, (u32, bool), usize),
        options: &Options,
        shared: Option<&WorkerPool>,
    ) -> Result<General> {
        let layout = CoefLayout::new(shape);
        let (na, ng) = (shape.n_alpha, shape.n_gamma);
        let w = isa.lanes();
        let max_lanes = 2 * pairs.pairs.next_multiple_of(w);
        let footprint = Footprint::new(shape, &pairs, (isa, threads), options);
        check_headroom(
            footprint
                .rest
                .saturating_add(crate::fft::planning_bytes(4 * na * ng)),
        )?;
        let fft = FftStage::new(
            (na, ng),
            shape.order_limit_gamma,
            options.real,
            options.rigor,
        )?;
        let stage = |half: bool| {
            DwtStage::new(
                (&layout, half),
                (na, ng, fft.strides().0),
                isa,
                skip,
                (threads, max_lanes),
            )
        };
        let dwt = stage(false);
        debug_assert_eq!(Some(dwt.row_stride), footprint.strides[0]);
        let pair_weight = if options.betas == Betas::All {
            let wts = crate::grid::weights(shape.grid_bandwidth);
            let f = 2.0 * PI / (na * ng) as f64;
            wts[..pairs.pairs].iter().map(|x| x * f).collect()
        } else {
            Vec::new()
        };
        let slots = SlotTable::new(&dwt, (na, fft.strides().1))?;
        let (rs, hs) = fft.strides();
        let half_spectrum = 0..ng / 2 + 1;
        let clears = [
            Clear::new(&slots, false, (na, rs), &fft.inverse_clears()),
            Clear::new(&slots, true, (na, hs), std::slice::from_ref(&half_spectrum)),
        ];
        let half = if options.real {
            let dwt = stage(true);
            debug_assert_eq!(Some(dwt.row_stride), footprint.strides[1]);
            let slots = SlotTable::new(&dwt, (na, fft.strides().1))?;
            Some((dwt, slots))
        } else {
            None
        };
        Ok(General {
            half,
            clears,
            layout,
            pairs,
            slots,
            dwt,
            fft,
            pair_weight,
            work: (0..threads).map(|_| Mutex::new(Work::default())).collect(),
            buf: ChunkBuffer::new(None),
            footprint,
            workers: WorkerPool::shared_or_new(shared, threads)?,
        })
    }

    /// Lane pairs the workspace cap holds for one transform (at least one).
    fn most_pairs(&self, m: Members) -> usize {
        self.footprint.most_pairs(m.dwt.row_stride)
    }

    /// Lane pairs per chunk (see [`Footprint::chunk_pairs`]).
    fn chunk_pairs(&self, m: Members) -> usize {
        self.footprint.chunk_pairs(m.dwt.row_stride)
    }

    /// Transforms of a batch run together (sharing each cluster's recurrence coefficients,
    /// starting values and d values, see `dwt/batch.rs`): as many as the workspace cap holds
    /// at the chunk size (at least one).
    fn group_size(&self, m: Members) -> usize {
        let hp = self.chunk_pairs(m).next_multiple_of(self.lanes_w());
        (self.footprint.budget / (hp * m.dwt.row_stride * 2 * 8).max(1)).max(1)
    }

    /// Runs `run(first, sub_batch)` on the groups of `batch` (see [`General::group_size`]),
    /// summing the stage times.
    fn by_groups(
        &self,
        (batch, m): (Batch, Members),
        mut run: impl FnMut(usize, Batch) -> Result<StageTimes>,
    ) -> Result<StageTimes> {
        let g = self.group_size(m);
        let mut sum = StageTimes::default();
        let mut t0 = 0;
        while t0 < batch.count {
            let count = g.min(batch.count - t0);
            sum += run(t0, Batch { count, ..batch })?;
            t0 += count;
        }
        Ok(sum)
    }

    /// Inverse of a batch, group by group (chunk buffer: the caller's `scratch` if given).
    pub(super) fn inverse(
        &self,
        batch: Batch,
        coef: SendConstPtr<Complex64>,
        out: Data,
        (scratch, watch): (Option<&Scratch>, Option<SliceWatch>),
    ) -> Result<StageTimes> {
        let m = self.members(out.is_real());
        self.by_groups((batch, m), |t0, b| {
            let c = SendConstPtr(coef.get().wrapping_add(t0 * batch.in_dist));
            let o = out.offset(t0 * batch.out_dist);
            self.inverse_group((b, m), c, o, (scratch, watch))
        })
    }

    /// Forward of a batch, group by group (the samples `inp` only read; chunk buffer: the
    /// caller's `scratch` if given).
    pub(super) fn forward(
        &self,
        batch: Batch,
        inp: Data,
        coef: SendPtr<Complex64>,
        scratch: Option<&Scratch>,
    ) -> Result<StageTimes> {
        let m = self.members(inp.is_real());
        self.by_groups((batch, m), |t0, b| {
            let i = inp.offset(t0 * batch.in_dist);
            let c = SendPtr(coef.get().wrapping_add(t0 * batch.out_dist));
            self.forward_group((b, m), i, c, scratch)
        })
    }

    /// Runs `f` with a chunk buffer of at least `len` doubles: the caller's `scratch` if
    /// given (checked to hold them), else the plan's (see [`ChunkBuffer`]).
    fn with_buf<R>(
        &self,
        (len, scratch): (usize, Option<&Scratch>),
        f: impl FnOnce(*mut f64) -> Result<R>,
    ) -> Result<R> {
        match scratch {
            Some(s) => f(s.holding(8 * len)?.as_mut_ptr().cast::<f64>()),
            None => self
                .buf
                .with(len.div_ceil(2), |b| f(b.as_mut_ptr().cast::<f64>())),
        }
    }

    /// Makes the buffers a single transform needs now (the chunk buffer and each worker's
    /// FFT buffers), so that executing allocates nothing large and a plan that cannot have
    /// them is refused when it is made.
    pub(super) fn reserve(&self) -> Result<()> {
        self.buf
            .with(self.scratch_bytes().div_ceil(16), |_| Ok(()))?;
        let real = self.half.is_some();
        for w in &self.work {
            let mut w = w.lock().unwrap_or_else(|e| e.into_inner());
            self.fft.inv_pair(&mut w)?;
            if real {
                self.fft.half_pair_reals(&mut w)?;
            }
        }
        Ok(())
    }

    /// Lanes per vector of the plan's kernels.
    pub(super) fn lanes_w(&self) -> usize {
        self.footprint.lanes_w
    }

    /// Bytes of the chunk buffer of one transform (the scratch a single call needs).
    pub(super) fn scratch_bytes(&self) -> usize {
        self.footprint.scratch_bytes()
    }

    /// Bytes the plan holds (see [`Footprint`]).
    pub(super) fn memory_bytes(&self) -> usize {
        self.footprint.total()
    }

    /// The clusters and slots of the complex transforms (every member), or of the real
    /// ones (`real`: the members `M' >= 0` where the plan has them).
    pub(super) fn members(&self, real: bool) -> Members<'_> {
        match (&self.half, real) {
            (Some((dwt, slots)), true) => Members { dwt, slots },
            _ => Members {
                dwt: &self.dwt,
                slots: &self.slots,
            },
        }
    }

    /// Runs `f` with a worker's FFT buffers (a private set when all are busy).
    pub(super) fn with_work<R>(&self, f: impl FnOnce(&mut Work) -> Result<R>) -> Result<R> {
        match lock_free(&self.work) {
            Some(mut g) => f(&mut g),
            None => f(&mut Work::default()),
        }
    }

    /// The chunks of `h` lane pairs (the last one shorter).
    fn chunks(&self, (h, m): (usize, Members)) -> impl Iterator<Item = ChunkLanes> + '_ {
        let row_len = m.dwt.row_stride;
        let w = self.lanes_w();
        (0..self.pairs.pairs).step_by(h).map(move |j0| {
            let h = h.min(self.pairs.pairs - j0);
            let hp = h.next_multiple_of(w);
            // The chunk's share of a split: pairs past its last one write nothing.
            let first_upper_pair = self.pairs.first_upper_pair.and_then(|k| {
                let k = if k >= j0 + h {
                    hp
                } else {
                    k.saturating_sub(j0)
                };
                k.is_multiple_of(w).then_some(k)
            });
            ChunkLanes {
                j0,
                h,
                hp,
                row_len,
                upper_gap: hp * row_len,
                first_upper_pair,
            }
        })
    }

    /// The number of chunks a single inverse (complex, or `real`) chains into one pass of
    /// the DWT stage (see [`General::inverse_chain`]), 0 if it runs them one by one.
    pub(super) fn chained_chunks(&self, real: bool) -> usize {
        // Only the output's alignment matters (a page boundary here); nothing is accessed.
        let at = std::ptr::null_mut::<u8>().wrapping_add(4096);
        let out = if real {
            Data::Real(SendPtr(at.cast()))
        } else {
            Data::Complex(SendPtr(at.cast()))
        };
        self.inverse_chain((1, self.members(real)), out, SendPtr(at.cast()))
            .map_or(0, |c| c.len())
    }

    /// Inverse of a group of transforms: chunk by chunk, or all chunks in one pass of the
    /// DWT stage where [`General::inverse_chain`] places their buffers.
    fn inverse_group(
        &self,
        (batch, m): (Batch, Members),
        coef: SendConstPtr<Complex64>,
        out: Data,
        (scratch, watch): (Option<&Scratch>, Option<SliceWatch>),
    ) -> Result<StageTimes> {
        let start = Instant::now();
        let mut times = StageTimes::default();
        let hp_max = self.chunk_pairs(m).next_multiple_of(self.lanes_w());
        let per_t_max = m.dwt.row_stride * 2 * hp_max;
        let real = out.is_real();
        self.with_buf((batch.count * per_t_max, scratch), |buf| {
            let own = SendPtr(buf);
            let chain = self.inverse_chain((batch.count, m), out, own);
            let groups: Vec<Vec<PlacedLanes>> = match chain {
                Some(chain) => vec![chain],
                None => self
                    .chunks((self.chunk_pairs(m), m))
                    .map(|ch| vec![PlacedLanes { ch, buf: own }])
                    .collect(),
            };
            self.workers.pool().install(|| {
                for group in groups {
                    // Chunks of padding pairs only (selections) write nothing.
                    let group: Vec<PlacedLanes> = group
                        .into_iter()
                        .filter(|pl| (0..pl.ch.h).any(|jj| self.writes(pl.ch, jj)))
                        .collect();
                    if group.is_empty() {
                        continue;
                    }
                    // Rows far larger than the caches go out with non-temporal stores.
                    let stream = group.len() * batch.count * per_t_max * 8 > 8 << 20;
                    let t0 = Instant::now();
                    self.inverse_dwt((batch, m), coef, &group, (real, stream));
                    let t1 = Instant::now();
                    times.dwt += (t1 - t0).as_secs_f64();
                    // Last chunk first: a chained chunk's buffer is in the slices of the
                    // chunk before it, which its FFT stage writes.
                    for pl in group.iter().rev() {
                        self.inverse_fft((batch, m), *pl, (out, watch))?;
                    }
                    times.fft += t1.elapsed().as_secs_f64();
                }
                Ok(())
            })
        })?;
        times.total = start.elapsed().as_secs_f64();
        Ok(times)
    }

    /// Whether pair `jj` of `ch` writes a slice.
    fn writes(&self, ch: ChunkLanes, jj: usize) -> bool {
        self.pairs.outputs[ch.j0 + jj]
            .iter()
            .any(|&s| s != usize::MAX)
    }

    /// The inverse's buffers of every chunk of a single transform as one chain, if they
    /// fit: chunk 0 in the plan's buffer `own`, chunk `k` in two halves, its lower lanes'
    /// rows in the output slices of the lower points of chunk `k - 1` and its upper lanes'
    /// rows in those of its upper points. The DWT stage then runs once over all chunks
    /// (each cluster's coefficients read once), and the FFT stage runs the chunks last to
    /// first: chunk `k` reads its rows before chunk `k - 1` writes its slices. The chunks
    /// are a multiple of the vector width (the padding rows need room too); the slices of a
    /// chunk's lower (upper) points must be consecutive. `None` for batches, fewer than two
    /// chunks, or rows that do not fit.
    fn inverse_chain(
        &self,
        (count, m): (usize, Members),
        out: Data,
        own: SendPtr<f64>,
    ) -> Option<Vec<PlacedLanes>> {
        // The most pairs the plan's buffer holds, rounded down to the vector width.
        let w = self.lanes_w();
        let most = (self.chunk_pairs(m).next_multiple_of(w)).min(self.most_pairs(m));
        let h = if most >= w { most / w * w } else { most };
        let chunks: Vec<ChunkLanes> = self.chunks((h, m)).collect();
        if count != 1 || chunks.len() < 2 {
            return None;
        }
        let base = match out {
            Data::Complex(p) | Data::RealParts(p) => p.get().cast::<u8>(),
            Data::Real(p) => p.get().cast::<u8>(),
        };
        let slice_bytes = self.fft.slice_len() * out.value_bytes();
        let rt = m.dwt.row_stride;
        let mut chain = vec![PlacedLanes {
            ch: chunks[0],
            buf: own,
        }];
        for pair in chunks.windows(2) {
            let (host, ch) = (pair[0], pair[1]);
            let half_bytes = 8 * ch.hp * rt;
            // The first slice of `host`'s consecutive lower (u = 0) or upper (u = 1)
            // points, aligned room for a half from there.
            let region = |u: usize| -> Option<*mut u8> {
                let first = self.pairs.outputs[host.j0 + if u == 0 { 0 } else { host.h - 1 }][u];
                let consecutive = (0..host.h).all(|jj| {
                    let s = self.pairs.outputs[host.j0 + jj][u];
                    s != usize::MAX
                        && s == if u == 0 {
                            first + jj
                        } else {
                            first + host.h - 1 - jj
                        }
                });
                let from = base.wrapping_add(first * slice_bytes);
                let skip = from.align_offset(64);
                (consecutive && skip + half_bytes <= host.h * slice_bytes)
                    .then(|| from.wrapping_add(skip))
            };
            let (lower, upper) = (region(0)?, region(1)?);
            // Both halves as one lane-major buffer: rows `0..hp` at `lower`, rows
            // `hp..2 hp` from `upper`, which must follow.
            if (upper as usize) < lower as usize + half_bytes {
                return None;
            }
            let gap = (upper as usize - lower as usize) / 8;
            if gap * 8 != upper as usize - lower as usize {
                return None;
            }
            chain.push(PlacedLanes {
                ch: ChunkLanes {
                    upper_gap: gap,
                    ..ch
                },
                buf: SendPtr(lower.cast::<f64>()),
            });
        }
        Some(chain)
    }

    /// The inverse's DWT stage of the chunks of `group` (each cluster over every chunk in
    /// turn, its coefficients cached after the first).
    fn inverse_dwt(
        &self,
        (batch, m): (Batch, Members),
        coef: SendConstPtr<Complex64>,
        group: &[PlacedLanes],
        (real, stream): (bool, bool),
    ) {
        let clusters = &m.dwt.clusters;
        m.dwt.for_each_cluster(|sc, i, cl| {
            for (k, pl) in group.iter().enumerate() {
                let ch = pl.ch;
                let per_t = m.dwt.row_stride * ch.lanes();
                let n = if k == 0 {
                    m.dwt.setup(sc, cl, &self.pairs, ch)
                } else {
                    m.dwt.setup_lanes(sc, cl, &self.pairs, ch)
                };
                let last_chunk = k + 1 == group.len();
                for t0 in (0..batch.count).step_by(KERNEL_BATCH) {
                    let count = KERNEL_BATCH.min(batch.count - t0);
                    // What the next kernel call will gather: this cluster for the
                    // next transforms, nothing new for the next chunk (the same
                    // blocks), else the next cluster (likely this task's next one)
                    // for the first transforms.
                    let next = if t0 + count < batch.count {
                        Some((cl, t0 + count))
                    } else if last_chunk {
                        clusters.get(i + 1).map(|c| (c, 0))
                    } else {
                        None
                    };
                    let next = next.map(|(c, u)| {
                        let rows = BatchRows {
                            base: coef.get().wrapping_add(u * batch.in_dist),
                            dist: batch.in_dist,
                            count: KERNEL_BATCH.min(batch.count - u),
                        };
                        (c, rows)
                    });
                    let c = BatchRows {
                        base: coef.get().wrapping_add(t0 * batch.in_dist),
                        dist: batch.in_dist,
                        count,
                    };
                    let b = BatchRows {
                        base: pl.buf.get().wrapping_add(t0 * per_t + cl.offset),
                        dist: per_t,
                        count,
                    };
                    // SAFETY: coefficient arrays `t0..t0 + count` of the batch
                    // (checked lengths), read only; this cluster's `cl.p` doubles of
                    // the lane rows of those transforms in the chunk's buffer (the
                    // plan's, or output slices no FFT task writes before the stage
                    // ends, see `inverse_chain`), written by this task only.
                    unsafe {
                        if count == 1 {
                            let hints = next.map_or(Prefetch::none(), |(c, r)| {
                                m.dwt.coefficient_hints(c, r.base, real)
                            });
                            m.dwt
                                .inverse(sc, cl, ch, n, c.base, (real, stream, hints), b.base)
                        } else {
                            m.dwt
                                .inverse_many(sc, cl, ch, n, c, (real, stream, next), b)
                        }
                    }
                }
            }
        });
    }

    /// The inverse's FFT stage of one chunk: a beta and its mirror in one task where both
    /// are written (each lane row and slot read once for both), the others alone; each
    /// slice shown to `watch` if given.
    fn inverse_fft(
        &self,
        (batch, m): (Batch, Members),
        pl: PlacedLanes,
        (out, watch): (Data, Option<SliceWatch>),
    ) -> Result<()> {
        let (ch, buf) = (pl.ch, pl.buf);
        let per_t = m.dwt.row_stride * ch.lanes();
        let slice_len = self.fft.slice_len();
        let pair_tasks = self.pair_tasks(ch, batch.count);
        pair_tasks.par_iter().try_for_each(|&(t, jj, [s0, s1])| {
            self.with_work(|work| {
                let rows = Self::lane_rows(m, (buf.get(), t * per_t), ch, (jj, false));
                let at = |s: usize| t * batch.out_dist + s * slice_len;
                let (w0, w1) = if out.is_real() {
                    self.fft.half_pair(work)?
                } else {
                    self.fft.inv_pair(work)?
                };
                // SAFETY: the lane rows were written by the DWT stage (finished); slices `s0`
                // and `s1` of output `t` are inside the checked output and this task's
                // alone, and hold no chunk's rows still to be read (see `inverse_chain`).
                unsafe {
                    if out.is_real() {
                        self.scatter_real_pair(m, (w0, w1), &[rows]);
                    } else {
                        self.scatter_pair(m, (w0, w1), &[rows]);
                    }
                    self.slice_out(w0, out.offset(at(s0)), (watch, s0));
                    self.slice_out(w1, out.offset(at(s1)), (watch, s1));
                }
                Ok(())
            })
        })?;
        let tasks = self.slice_tasks(ch, batch.count);
        tasks.par_iter().try_for_each(|&(t, jj, upper, s)| {
            self.with_work(|work| {
                let rows = Self::lane_rows(m, (buf.get(), t * per_t), ch, (jj, upper));
                let at = t * batch.out_dist + s * slice_len;
                let w = if out.is_real() {
                    self.fft.half_buf(work)?
                } else {
                    self.fft.inv_buf(work)?
                };
                // SAFETY: as for the pairs above, for slice `s` of output `t`.
                unsafe {
                    if out.is_real() {
                        self.scatter_real(m, w, &[rows]);
                    } else {
                        self.scatter(m, w, &[rows]);
                    }
                    self.slice_out(w, out.offset(at), (watch, s));
                }
                Ok(())
            })
        })
    }

    /// The slice DFT of an inverse from the work buffer `w` (filled by a scatter) into the
    /// slice at `out`, shown to `watch` as slice `s` if given.
    ///
    /// # Safety
    /// `out` is valid for writes of one slice, nobody else's meanwhile; `w` is the work
    /// buffer of `out`'s kind (half buffer for the real kinds).
    unsafe fn slice_out(
        &self,
        w: &mut [Complex64],
        out: Data,
        (watch, s): (Option<SliceWatch>, usize),
    ) {
        let bound = watch.map(|f| move |r: SliceRef| f(s, r));
        let seen = bound.as_ref().map(|f| f as &dyn Fn(SliceRef));
        // SAFETY: the caller's contract.
        unsafe {
            match out {
                Data::Complex(o) => self.fft.inverse(w, o.get(), seen),
                Data::Real(o) => self.fft.inverse_real(w, o.get(), seen),
                Data::RealParts(o) => self.fft.inverse_real_parts(w, o.get(), seen),
            }
        }
    }

    /// The slice DFTs of a forward from the slices `inp` (one or two, of one kind) into
    /// `work`'s two buffers for that kind, in order; returns the buffers (for a gather).
    ///
    /// # Safety
    /// Each of `inp` is valid for reads of one slice.
    unsafe fn slices_in<'a>(&self, work: &'a mut Work, inp: &[Data]) -> Result<BufPair<'a>> {
        let (w0, w1) = match inp[0] {
            Data::Complex(_) => self.fft.fwd_pair(work)?,
            Data::Real(_) => self.fft.half_pair(work)?,
            Data::RealParts(_) => {
                let ((w0, w1), reals) = self.fft.half_pair_reals(work)?;
                for (w, i) in [&mut *w0, &mut *w1].into_iter().zip(inp) {
                    if let Data::RealParts(i) = i {
                        // SAFETY: the caller's contract; the buffers are this worker's.
                        unsafe { self.fft.forward_real_parts((w, &mut *reals), i.get()) };
                    }
                }
                return Ok((w0, w1));
            }
        };
        for (w, i) in [&mut *w0, &mut *w1].into_iter().zip(inp) {
            // SAFETY: the caller's contract; the buffers are this worker's.
            unsafe {
                match i {
                    Data::Complex(i) => self.fft.forward(w, i.get()),
                    Data::Real(i) => self.fft.forward_real(w, i.get()),
                    Data::RealParts(_) => unreachable!("one kind per call"),
                }
            }
        }
        Ok((w0, w1))
    }

    /// Forward of a group of transforms, chunk by chunk.
    fn forward_group(
        &self,
        (batch, m): (Batch, Members),
        inp: Data,
        coef: SendPtr<Complex64>,
        scratch: Option<&Scratch>,
    ) -> Result<StageTimes> {
        let start = Instant::now();
        let mut times = StageTimes::default();
        let hp_max = self.chunk_pairs(m).next_multiple_of(self.lanes_w());
        let per_t_max = m.dwt.row_stride * 2 * hp_max;
        let slice_len = self.fft.slice_len();
        let real = inp.is_real();
        self.with_buf((batch.count * per_t_max, scratch), |buf| {
            let buf = SendPtr(buf);
            self.workers.pool().install(|| {
                for ch in self.chunks((self.chunk_pairs(m), m)) {
                    let lanes = ch.lanes();
                    let per_t = m.dwt.row_stride * lanes;
                    let t0 = Instant::now();
                    // A beta and its mirror in one task (each lane row written whole by
                    // one task, each slot read once), as the inverse.
                    let pair_tasks = self.pair_tasks(ch, batch.count);
                    pair_tasks.par_iter().try_for_each(|&(t, jj, [s0, s1])| {
                        self.with_work(|work| {
                            let rows = Self::lane_rows(m, (buf.get(), t * per_t), ch, (jj, false));
                            let weight = self.pair_weight[ch.j0 + jj];
                            let at = |s: usize| inp.offset(t * batch.in_dist + s * slice_len);
                            // SAFETY: slices `s0` and `s1` of input `t` are inside the
                            // checked input; the two lane rows are this task's alone.
                            unsafe {
                                let (w0, w1) = self.slices_in(work, &[at(s0), at(s1)])?;
                                if real {
                                    self.gather_real_pair(m, (w0, w1), &[rows], weight);
                                } else {
                                    self.gather_pair(m, (w0, w1), &[rows], weight);
                                }
                            }
                            Ok(())
                        })
                    })?;
                    let tasks = self.slice_tasks(ch, batch.count);
                    tasks.par_iter().try_for_each(|&(t, jj, upper, s)| {
                        self.with_work(|work| {
                            let rows = Self::lane_rows(m, (buf.get(), t * per_t), ch, (jj, upper));
                            let weight = self.pair_weight[ch.j0 + jj];
                            let at = inp.offset(t * batch.in_dist + s * slice_len);
                            // SAFETY: slice `s` of input `t` is inside the checked input;
                            // the values written are this slice's slots of two lane rows:
                            // no other task writes them (its mirror writes the other slots
                            // of the same rows).
                            unsafe {
                                let (w, _) = self.slices_in(work, &[at])?;
                                if real {
                                    self.gather_real(m, w, &[rows], weight);
                                } else {
                                    self.gather(m, w, &[rows], weight);
                                }
                            }
                            Ok(())
                        })
                    })?;
                    let t1 = Instant::now();
                    times.fft += (t1 - t0).as_secs_f64();
                    let first = ch.j0 == 0;
                    for t in 0..batch.count {
                        // SAFETY: the padding lane rows of transform `t` in the chunk
                        // buffer, written by nobody (the FFT stage is finished).
                        unsafe { Self::zero_padding(m, buf.get().add(t * per_t), ch) };
                    }
                    let clusters = &m.dwt.clusters;
                    m.dwt.for_each_cluster(|sc, i, cl| {
                        let n = m.dwt.setup(sc, cl, &self.pairs, ch);
                        for t0 in (0..batch.count).step_by(KERNEL_BATCH) {
                            let count = KERNEL_BATCH.min(batch.count - t0);
                            let block = buf.get().wrapping_add(t0 * per_t + cl.offset);
                            let c = coef.get().wrapping_add(t0 * batch.out_dist);
                            // What the next cluster (likely this task's next one)
                            // reads and writes.
                            let next = match clusters.get(i + 1) {
                                Some(nc) if count == 1 => m.dwt.forward_hints(
                                    nc,
                                    ch,
                                    buf.get().wrapping_add(t0 * per_t + nc.offset),
                                    c,
                                ),
                                _ => Prefetch::none(),
                            };
                            // SAFETY: this cluster's slots of the lane rows of
                            // transforms `t0..t0 + count` (written by the FFT stage or
                            // zeroed above, finished); their coefficient arrays are
                            // inside the checked output, and this cluster's slots'
                            // blocks are this task's.
                            unsafe {
                                if count == 1 {
                                    m.dwt.forward(sc, cl, (ch, n), block, (c, first, next))
                                } else {
                                    m.dwt.forward_many(
                                        sc,
                                        cl,
                                        ch,
                                        n,
                                        BatchRows {
                                            base: block.cast_const(),
                                            dist: per_t,
                                            count,
                                        },
                                        BatchRows {
                                            base: c,
                                            dist: batch.out_dist,
                                            count,
                                        },
                                        first,
                                    )
                                }
                            }
                        }
                    });
                    times.dwt += t1.elapsed().as_secs_f64();
                }
                Ok(())
            })
        })?;
        times.total = start.elapsed().as_secs_f64();
        Ok(times)
    }

    /// The FFT stage's tasks of a chunk: `(transform, pair in chunk, upper, slice)` for
    /// every slice the chunk's pairs write.
    fn slice_tasks(&self, ch: ChunkLanes, count: usize) -> Vec<(usize, usize, bool, usize)> {
        let mut v = Vec::new();
        for t in 0..count {
            for jj in (0..ch.h).filter(|&jj| !self.paired(ch, jj)) {
                for (u, &s) in self.pairs.outputs[ch.j0 + jj].iter().enumerate() {
                    if s != usize::MAX {
                        v.push((t, jj, u == 1, s));
                    }
                }
            }
        }
        v
    }

    /// Whether the inverse writes both slices of pair `jj` of `ch` (in one task).
    fn paired(&self, ch: ChunkLanes, jj: usize) -> bool {
        !self.pairs.outputs[ch.j0 + jj].contains(&usize::MAX)
    }

    /// The inverse's tasks of a chunk that write a slice and its mirror:
    /// `(transform, pair in chunk, [lower slice, upper slice])`.
    fn pair_tasks(&self, ch: ChunkLanes, count: usize) -> Vec<(usize, usize, [usize; 2])> {
        let mut v = Vec::new();
        for t in 0..count {
            for jj in (0..ch.h).filter(|&jj| self.paired(ch, jj)) {
                v.push((t, jj, self.pairs.outputs[ch.j0 + jj]));
            }
        }
        v
    }

    /// Calls `f(lower, upper, index)` for every slot of `parts` (`real`: the real table's
    /// entries and half-buffer indices, flags included): `lower` points at the slot's two
    /// doubles that belong to the lower point's slice, `upper` at the upper slice's (the
    /// own row for a direct member, the mirror row for a reversed one, and the other way).
    #[inline(always)]
    fn for_each_pair_slot(
        m: Members,
        parts: &[LaneRows],
        real: bool,
        mut f: impl FnMut(*mut f64, *mut f64, u32),
    ) {
        for rows in parts {
            let table = if real {
                m.slots.real_of(rows.clusters)
            } else {
                m.slots.of(rows.clusters)
            };
            for &(at, idx) in table {
                let off = (at & !SlotTable::MIRROR) as usize;
                let (own, mirror) = (rows.own.wrapping_add(off), rows.mirror.wrapping_add(off));
                if at & SlotTable::MIRROR != 0 {
                    f(mirror, own, idx);
                } else {
                    f(own, mirror, idx);
                }
            }
        }
    }

    /// [`General::scatter`] of a slice and its mirror at once (complex): from the lane
    /// rows of `parts` (own: the lower point's, mirror: the upper point's) into `w0` (the
    /// lower slice) and `w1` (the upper one), each lane row and table entry read once.
    ///
    /// # Safety
    /// As for [`General::scatter`].
    pub(super) unsafe fn scatter_pair(
        &self,
        m: Members,
        (w0, w1): (&mut [Complex64], &mut [Complex64]),
        parts: &[LaneRows],
    ) {
        self.clear_inverse_buffer(w0);
        self.clear_inverse_buffer(w1);
        Self::for_each_pair_slot(m, parts, false, |lo, hi, work| {
            // SAFETY: the slot's two doubles in both lane rows of the part (the table holds
            // the offsets of `dwt.clusters`' slots).
            unsafe {
                w0[work as usize] = Complex64::new(*lo, *lo.add(1));
                w1[work as usize] = Complex64::new(*hi, *hi.add(1));
            }
        });
    }

    /// [`General::scatter_real`] of a slice and its mirror at once, as
    /// [`General::scatter_pair`].
    ///
    /// # Safety
    /// As for [`General::scatter`].
    pub(super) unsafe fn scatter_real_pair(
        &self,
        m: Members,
        (w0, w1): (&mut [Complex64], &mut [Complex64]),
        parts: &[LaneRows],
    ) {
        self.clears[1].apply(w0);
        self.clears[1].apply(w1);
        Self::for_each_pair_slot(m, parts, true, |lo, hi, idx| {
            if idx & SlotTable::CONJ == 0 {
                // SAFETY: as in `scatter_pair`.
                unsafe {
                    w0[idx as usize] = Complex64::new(*lo, -*lo.add(1));
                    w1[idx as usize] = Complex64::new(*hi, -*hi.add(1));
                }
            }
        });
    }

    /// [`General::gather`] of a slice and its mirror at once (`w0` the lower slice's
    /// values, `w1` the upper one's) into the pair's lane rows in `parts` (own: the lower
    /// point's, mirror: the upper point's), each slot read once.
    ///
    /// # Safety
    /// As for [`General::gather`]; both lane rows of every part are the caller's.
    pub(super) unsafe fn gather_pair(
        &self,
        m: Members,
        (w0, w1): (&[Complex64], &[Complex64]),
        parts: &[LaneRows],
        weight: f64,
    ) {
        Self::for_each_pair_slot(m, parts, false, |lo, hi, work| {
            let (v0, v1) = (w0[work as usize] * weight, w1[work as usize] * weight);
            // SAFETY: the slot's two doubles in both lane rows (the table holds the offsets
            // of `dwt.clusters`' slots), the caller's.
            unsafe { (*lo, *lo.add(1), *hi, *hi.add(1)) = (v0.re, v0.im, v1.re, v1.im) };
        });
    }

    /// [`General::gather_real`] of a slice and its mirror at once, as
    /// [`General::gather_pair`].
    ///
    /// # Safety
    /// As for [`General::gather_pair`].
    pub(super) unsafe fn gather_real_pair(
        &self,
        m: Members,
        (w0, w1): (&[Complex64], &[Complex64]),
        parts: &[LaneRows],
        weight: f64,
    ) {
        Self::for_each_pair_slot(m, parts, true, |lo, hi, idx| {
            let value = |w: &[Complex64]| {
                let v = if idx & SlotTable::CONJ != 0 {
                    w[(idx & !SlotTable::CONJ) as usize]
                } else {
                    w[idx as usize].conj()
                };
                v * weight
            };
            let (v0, v1) = (value(w0), value(w1));
            // SAFETY: as in `gather_pair`.
            unsafe { (*lo, *lo.add(1), *hi, *hi.add(1)) = (v0.re, v0.im, v1.re, v1.im) };
        });
    }

    /// The lane rows of a slice (its own, and its mirror's, where its reversed members
    /// are) in the chunk buffer at `buf`, transform offset `at`.
    pub(super) fn lane_rows(
        m: Members,
        (buf, at): (*mut f64, usize),
        ch: ChunkLanes,
        (jj, upper): (usize, bool),
    ) -> LaneRows {
        let lower = buf.wrapping_add(at + jj * m.dwt.row_stride);
        let mirror = lower.wrapping_add(ch.upper_gap);
        let (own, mirror) = if upper {
            (mirror, lower)
        } else {
            (lower, mirror)
        };
        LaneRows {
            own,
            mirror,
            clusters: (0, m.dwt.clusters.len()),
        }
    }

    /// Zeroes what the complex inverse's work buffer `w` holds from the previous slice
    /// where this slice places no value (see [`Clear`]).
    fn clear_inverse_buffer(&self, w: &mut [Complex64]) {
        self.clears[0].apply(w);
    }

    /// Complex inverse: a slice's values from its lane rows into the inverse's work buffer
    /// (whose columns `|M'| <= N` are cleared first; the others stay zero).
    ///
    /// # Safety
    /// Each part's lane rows hold its clusters' slots, written by the DWT stage.
    pub(super) unsafe fn scatter(&self, m: Members, w: &mut [Complex64], rows: &[LaneRows]) {
        self.clear_inverse_buffer(w);
        for part in rows {
            for &(at, work) in m.slots.of(part.clusters) {
                let x = part.at(at);
                // SAFETY: the slot's two doubles are inside the part's lane row (the table
                // holds the offsets of `dwt.clusters`' slots).
                w[work as usize] = unsafe { Complex64::new(*x, *x.add(1)) };
            }
        }
    }

    /// Real inverse: `conj` of a slice's values with `M' >= 0` into the half buffer.
    ///
    /// # Safety
    /// As for [`General::scatter`].
    pub(super) unsafe fn scatter_real(&self, m: Members, w: &mut [Complex64], rows: &[LaneRows]) {
        self.clears[1].apply(w);
        for part in rows {
            for &(at, idx) in m.slots.real_of(part.clusters) {
                if idx & SlotTable::CONJ != 0 {
                    continue;
                }
                let x = part.at(at);
                // SAFETY: as in `scatter`.
                w[idx as usize] = unsafe { Complex64::new(*x, -*x.add(1)) };
            }
        }
    }

    /// Forward: a slice's values (the forward's work buffer), times its weight, into
    /// its slots of the lane rows.
    ///
    /// # Safety
    /// As for [`General::scatter`], for writes; no other task writes these slots.
    pub(super) unsafe fn gather(
        &self,
        m: Members,
        w: &[Complex64],
        rows: &[LaneRows],
        weight: f64,
    ) {
        for part in rows {
            for &(at, work) in m.slots.of(part.clusters) {
                let v = w[work as usize] * weight;
                let x = part.at(at);
                // SAFETY: as in `scatter`; these slots are this task's (caller's contract).
                unsafe {
                    *x = v.re;
                    *x.add(1) = v.im;
                }
            }
        }
    }

    /// Real forward: as [`General::gather`], from the half spectrum `C` (see the FFT
    /// stage): `F(M, M') = conj(C[M][M'])` for `M' >= 0`, `C[-M][-M']` below.
    ///
    /// # Safety
    /// As for [`General::gather`].
    pub(super) unsafe fn gather_real(
        &self,
        m: Members,
        w: &[Complex64],
        rows: &[LaneRows],
        weight: f64,
    ) {
        for part in rows {
            for &(at, idx) in m.slots.real_of(part.clusters) {
                let v = if idx & SlotTable::CONJ != 0 {
                    w[(idx & !SlotTable::CONJ) as usize]
                } else {
                    w[idx as usize].conj()
                } * weight;
                let x = part.at(at);
                // SAFETY: as in `gather`.
                unsafe {
                    *x = v.re;
                    *x.add(1) = v.im;
                }
            }
        }
    }

    /// Zero the padding lane rows (`h..hp` of each half) of one transform's chunk rows at
    /// `rows`, which the forward kernel multiplies by exact zeros.
    ///
    /// # Safety
    /// The chunk's `2 hp` lane rows at `rows` are the caller's.
    pub(super) unsafe fn zero_padding(m: Members, rows: *mut f64, ch: ChunkLanes) {
        let rt = m.dwt.row_stride;
        for half in [0, ch.upper_gap] {
            // SAFETY: lane rows `h..hp` of the half, inside the chunk's rows.
            unsafe { std::ptr::write_bytes(rows.add(half + ch.h * rt), 0, (ch.hp - ch.h) * rt) };
        }
    }
}
