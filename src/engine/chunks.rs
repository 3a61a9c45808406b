//! [`Engine`], the engine of every plan shape (a [`PartialPlan`](crate::PartialPlan);
//! [`Plan`](crate::Plan) is its full shape): its construction, and the chunks of lane
//! pairs its transforms run one at a time (the DWT stage over all clusters, the FFT stage
//! over the chunk's slices).

use super::betas::LanePairs;
use super::dwt_stage::{ChunkLanes, DwtStage};
use super::fft_stage::{FftStage, SliceWatch, Work};
use super::footprint::Footprint;
use super::slots::{Clear, SlotTable};
use crate::batch::Batch;
use crate::error::Result;
use crate::fft::ChunkBuffer;
use crate::options::{Betas, Options};
use crate::shape::{CoefLayout, Shape};
use crate::simd::Isa;
use crate::system::check_headroom;
use crate::transform::Scratch;
use crate::transform::StageTimes;
use crate::workers::{lock_free, SendConstPtr, SendPtr, WorkerPool};
use crate::Real;
use num_complex::Complex;
use std::f64::consts::PI;
use std::sync::Mutex;

/// A plan of the engine, computing in `T`.
pub(crate) struct Engine<T: Real = f64> {
    pub(crate) layout: CoefLayout,
    pub(crate) pairs: LanePairs,
    /// Every member of each cluster (complex transforms, distributed plans). Its clusters
    /// are never changed after `new`: `slots` is made from them.
    pub(crate) dwt: DwtStage<T>,
    pub(crate) fft: FftStage<T>,
    /// The slots of a lane row, flat (for the scatters and gathers, complex and real).
    pub(crate) slots: SlotTable,
    /// The real transforms' members (`M' >= 0`, see `DwtStage::new`) with their slots, for
    /// plans made with `Options::real`.
    pub(super) half: Option<(DwtStage<T>, SlotTable)>,
    /// What the complex and the real inverse zero in a worker's buffer before each slice.
    pub(super) clears: [Clear; 2],
    /// Forward: `w_{B_grid}(j) 2 pi / (n_alpha n_gamma)` per lane pair (grid betas).
    pub(crate) pair_weight: Vec<T>,
    /// Per-worker FFT buffers (made on first use).
    pub(super) work: Vec<Mutex<Work>>,
    /// The chunk buffer (taken by one execution at a time).
    pub(super) buf: ChunkBuffer,
    pub(super) footprint: Footprint,
    pub(crate) workers: WorkerPool,
}

/// The clusters and slots a transform runs on (see [`Engine::members`]).
#[derive(Clone, Copy)]
pub(crate) struct Members<'a, T: Real = f64> {
    pub(crate) dwt: &'a DwtStage<T>,
    pub(crate) slots: &'a SlotTable,
}

/// A chunk and its buffer (lane row `r < hp` at `buf + r row_len`, the upper half
/// `ch.upper_gap` further).
#[derive(Clone, Copy)]
pub(super) struct PlacedLanes<T> {
    pub(super) ch: ChunkLanes,
    pub(super) buf: SendPtr<T>,
}

/// The samples of one execution (all arrays of a batch) and how they are stored. A
/// forward only reads them.
#[derive(Clone, Copy)]
pub(crate) enum Data<T = f64> {
    Complex(SendPtr<Complex<T>>),
    Real(SendPtr<T>),
    /// Reals in the real parts of complex values: the inverse sets the imaginary parts to
    /// 0, the forward does not read them.
    RealParts(SendPtr<Complex<T>>),
}

impl<T: Copy> Data<T> {
    /// Whether the samples are a real signal.
    pub(crate) fn is_real(self) -> bool {
        !matches!(self, Data::Complex(_))
    }

    /// The samples `values` values further on (in the samples' own type).
    pub(super) fn offset(self, values: usize) -> Data<T> {
        match self {
            Data::Complex(p) => Data::Complex(SendPtr(p.get().wrapping_add(values))),
            Data::Real(p) => Data::Real(SendPtr(p.get().wrapping_add(values))),
            Data::RealParts(p) => Data::RealParts(SendPtr(p.get().wrapping_add(values))),
        }
    }

    /// Bytes of one value.
    pub(super) fn value_bytes(self) -> usize {
        match self {
            Data::Real(_) => size_of::<T>(),
            _ => 2 * size_of::<T>(),
        }
    }
}

impl<T: Real> Engine<T> {
    pub(crate) fn new(
        shape: &Shape,
        pairs: LanePairs,
        (isa, skip, threads): (Isa, (u32, bool), usize),
        options: &Options,
        shared: Option<&WorkerPool>,
    ) -> Result<Engine<T>> {
        let layout = CoefLayout::new(shape);
        let (na, ng) = (shape.n_alpha, shape.n_gamma);
        let w = isa.lanes_of::<T>();
        let max_lanes = 2 * pairs.pairs.next_multiple_of(w);
        let footprint = Footprint::new::<T>(shape, &pairs, (isa, threads), options);
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
            wts[..pairs.pairs]
                .iter()
                .map(|x| T::from_f64(x * f))
                .collect()
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
        Ok(Engine {
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
    pub(super) fn most_pairs(&self, m: Members<T>) -> usize {
        self.footprint.most_pairs(m.dwt.row_stride)
    }

    /// Lane pairs per chunk (see [`Footprint::chunk_pairs`]).
    pub(super) fn chunk_pairs(&self, m: Members<T>) -> usize {
        self.footprint.chunk_pairs(m.dwt.row_stride)
    }

    /// Transforms of a batch run together (sharing each cluster's recurrence coefficients,
    /// starting values and d values, see `dwt/batch.rs`): as many as the workspace cap holds
    /// at the chunk size (at least one).
    pub(super) fn group_size(&self, m: Members<T>) -> usize {
        let hp = self.chunk_pairs(m).next_multiple_of(self.lanes_w());
        (self.footprint.budget / (hp * m.dwt.row_stride * 2 * T::BYTES).max(1)).max(1)
    }

    /// Runs `run(first, sub_batch)` on the groups of `batch` (see [`Engine::group_size`]),
    /// summing the stage times.
    pub(super) fn by_groups(
        &self,
        (batch, m): (Batch, Members<T>),
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
    pub(crate) fn inverse(
        &self,
        batch: Batch,
        coef: SendConstPtr<Complex<T>>,
        out: Data<T>,
        (scratch, watch): (Option<&Scratch>, Option<SliceWatch<T>>),
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
    pub(crate) fn forward(
        &self,
        batch: Batch,
        inp: Data<T>,
        coef: SendPtr<Complex<T>>,
        scratch: Option<&Scratch>,
    ) -> Result<StageTimes> {
        let m = self.members(inp.is_real());
        self.by_groups((batch, m), |t0, b| {
            let i = inp.offset(t0 * batch.in_dist);
            let c = SendPtr(coef.get().wrapping_add(t0 * batch.out_dist));
            self.forward_group((b, m), i, c, scratch)
        })
    }

    /// Runs `f` with a chunk buffer of at least `len` values: the caller's `scratch` if
    /// given (checked to hold them), else the plan's (see [`ChunkBuffer`]).
    pub(super) fn with_buf<R>(
        &self,
        (len, scratch): (usize, Option<&Scratch>),
        f: impl FnOnce(*mut T) -> Result<R>,
    ) -> Result<R> {
        let bytes = len.saturating_mul(T::BYTES);
        match scratch {
            Some(s) => f(s.holding(bytes)?.ptr::<T>()),
            None => self.buf.with_bytes(bytes, |b| f(b.ptr::<T>())),
        }
    }

    /// Makes the buffers a single transform needs now (the chunk buffer and each worker's
    /// FFT buffers), so that executing allocates nothing large and a plan that cannot have
    /// them is refused when it is made.
    pub(crate) fn reserve(&self) -> Result<()> {
        self.buf.with_bytes(self.scratch_bytes(), |_| Ok(()))?;
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
    pub(crate) fn lanes_w(&self) -> usize {
        self.footprint.lanes_w
    }

    /// Bytes of the chunk buffer of one transform (the scratch a single call needs).
    pub(crate) fn scratch_bytes(&self) -> usize {
        self.footprint.scratch_bytes()
    }

    /// Bytes the plan holds (see [`Footprint`]).
    pub(crate) fn memory_bytes(&self) -> usize {
        self.footprint.total()
    }

    /// The clusters and slots of the complex transforms (every member), or of the real
    /// ones (`real`: the members `M' >= 0` where the plan has them).
    pub(crate) fn members(&self, real: bool) -> Members<'_, T> {
        match (&self.half, real) {
            (Some((dwt, slots)), true) => Members { dwt, slots },
            _ => Members {
                dwt: &self.dwt,
                slots: &self.slots,
            },
        }
    }

    /// Runs `f` with a worker's FFT buffers (a private set when all are busy).
    pub(crate) fn with_work<R>(&self, f: impl FnOnce(&mut Work) -> Result<R>) -> Result<R> {
        match lock_free(&self.work) {
            Some(mut g) => f(&mut g),
            None => f(&mut Work::default()),
        }
    }

    /// The chunks of `h` lane pairs (the last one shorter).
    pub(super) fn chunks(
        &self,
        (h, m): (usize, Members<T>),
    ) -> impl Iterator<Item = ChunkLanes> + '_ {
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
    /// the DWT stage (see [`Engine::inverse_chain`]), 0 if it runs them one by one.
    pub(crate) fn chained_chunks(&self, real: bool) -> usize {
        // Only the output's alignment matters (a page boundary here); nothing is accessed.
        let at = std::ptr::null_mut::<u8>().wrapping_add(4096);
        let out: Data<T> = if real {
            Data::Real(SendPtr(at.cast()))
        } else {
            Data::Complex(SendPtr(at.cast()))
        };
        self.inverse_chain((1, self.members(real)), out, SendPtr(at.cast()))
            .map_or(0, |c| c.len())
    }
}
