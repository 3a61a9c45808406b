//! [`PartialPlan`]: building a plan for a [`Shape`] and running its transforms, one chunk
//! of lane pairs at a time (the DWT stage over all clusters, then the FFT stage over the
//! chunk's slices).

use super::betas::{Betas, LanePairs};
use super::dwt_stage::{ChunkLanes, DwtStage, KERNEL_BATCH};
use super::fft_stage::{FftStage, Work};
use super::shape::{CoefLayout, Shape};
use crate::dwt::{BatchRows, Prefetch};
use crate::error::{Error, Result};
use crate::fft::{AlignedBuf, Rigor};
use crate::plan::{Direction, Plan, PlanOptions, SliceWatch, StageTimes};
use crate::simd::Isa;
use crate::system::check_headroom;
use crate::wigner::{DEFAULT_SKIP_BITS, SKIP_BITS_RANGE};
use crate::workers::{lock_free, SendConstPtr, SendPtr, WorkerPool, WORKER_STACK_BYTES};
use num_complex::Complex64;
use rayon::prelude::*;
use std::f64::consts::PI;
use std::sync::Mutex;
use std::time::Instant;

/// Options of a [`PartialPlan`].
#[derive(Clone, Debug, Default)]
pub struct PartialOptions {
    /// Which transforms the plan runs (default both).
    pub direction: Direction,
    /// Worker threads (0 = all cores).
    pub threads: usize,
    /// FFTW planner rigour.
    pub rigor: Rigor,
    /// Instruction set of the kernels (`None`: [`Isa::selected`], the best this CPU has
    /// unless the environment variable `SO3FFT_ISA` names another).
    pub isa: Option<Isa>,
    /// Also prepare the real-signal transforms.
    pub real: bool,
    /// The betas the inverse evaluates (default all; a plan with a selection runs the
    /// inverse only).
    pub betas: Betas,
    /// Skip threshold `2^-skip_bits` of negligible Wigner-d prefixes, as
    /// [`PlanOptions::skip_bits`] (`None`: 64; `Some(0)`: nothing skipped; else 24..=560).
    /// Thresholds above the default save nothing measurable (`docs/partial-plans.md`).
    pub skip_bits: Option<u32>,
    /// Cap on the chunk buffer in bytes (`None`: 256 MiB).
    pub max_workspace_bytes: Option<usize>,
    /// Run the full shape on the general engine too (normally the full shape runs on
    /// [`Plan`], which is faster): for tests and benchmarks.
    #[doc(hidden)]
    pub general_engine: bool,
}

/// Several transforms in one call, FFTW `plan_many` style: `count` inputs `in_dist` values
/// apart and `count` outputs `out_dist` values apart.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Batch {
    /// Number of transforms.
    pub count: usize,
    /// Values from one input to the next.
    pub in_dist: usize,
    /// Values from one output to the next (at least one output's length).
    pub out_dist: usize,
}

/// The skip threshold's exponent of a `skip_bits` option (0: no skipping).
fn skip_bits(option: Option<u32>) -> Result<u32> {
    match option {
        None => Ok(DEFAULT_SKIP_BITS),
        Some(0) => Ok(0),
        Some(b) if SKIP_BITS_RANGE.contains(&b) => Ok(b),
        Some(b) => Err(Error::InvalidArgument(format!(
            "skip_bits {b} outside {SKIP_BITS_RANGE:?}"
        ))),
    }
}

/// A plan of the general engine.
pub(super) struct General {
    pub(super) layout: CoefLayout,
    pub(super) pairs: LanePairs,
    /// Its clusters are never changed after `new`: `slots` is made from them.
    pub(super) dwt: DwtStage,
    pub(super) fft: FftStage,
    /// The slots of a lane row, flat (for the scatters and gathers, complex and real).
    slots: SlotTable,
    /// Forward: `w_{B_grid}(j) 2 pi / (n_alpha n_gamma)` per lane pair (grid betas).
    pub(super) pair_weight: Vec<f64>,
    /// Per-worker FFT buffers (made on first use).
    work: Vec<Mutex<Work>>,
    /// The chunk buffer (taken by one execution at a time).
    buf: Mutex<Option<AlignedBuf>>,
    budget: usize,
    pub(super) lanes_w: usize,
    /// The order limit `N` of `M'`.
    layout_n: usize,
    pub(super) workers: WorkerPool,
}

enum Engine {
    Full(Box<Plan>),
    General(Box<General>),
}

/// A transform on SO(3) that computes only what a [`Shape`] holds: band-limited,
/// order-limited, oversampled or undersampled in alpha and gamma, restricted to some
/// betas, several at once ([`Batch`]), complex or real.
///
/// The full shape ([`Shape::new`]) with all betas runs on [`Plan`]; everything else on
/// the general engine: the DWT kernels per cluster of order pairs over chunks of beta
/// pairs, and pruned slice DFTs. Execution takes `&self`; one plan may run on different
/// arrays from several threads.
pub struct PartialPlan {
    shape: Shape,
    direction: Direction,
    real: bool,
    threads: usize,
    n_slices: usize,
    engine: Engine,
}

/// Pointers of one execution (all arrays of a batch).
#[derive(Clone, Copy)]
enum Data {
    Complex(SendPtr<Complex64>),
    Real(SendPtr<f64>),
}

impl PartialPlan {
    /// A plan for `shape` with `options`.
    pub fn new(shape: &Shape, options: &PartialOptions) -> Result<PartialPlan> {
        PartialPlan::new_on(shape, options, None)
    }

    /// [`PartialPlan::new`] on the workers of `shared` if given (with the plan's thread
    /// count).
    pub(crate) fn new_on(
        shape: &Shape,
        options: &PartialOptions,
        shared: Option<&WorkerPool>,
    ) -> Result<PartialPlan> {
        shape.validate()?;
        let restricted = options.betas != Betas::All;
        let direction = if restricted {
            match options.direction {
                Direction::Forward => {
                    return Err(Error::InvalidArgument(
                        "a forward transform needs every beta of the grid".into(),
                    ))
                }
                _ => Direction::Inverse,
            }
        } else {
            options.direction
        };
        if direction != Direction::Inverse {
            shape.check_forward()?;
        }
        let threads = crate::workers::thread_count(options.threads)?;
        let isa = Isa::resolve(options.isa)?;
        let bits = skip_bits(options.skip_bits)?;
        if let Some(0) = options.max_workspace_bytes {
            return Err(Error::InvalidArgument("max_workspace_bytes is 0".into()));
        }
        let pairs = LanePairs::new(shape, &options.betas, Some(isa.lanes()))?;
        let n_slices = pairs.n_slices;
        let engine = if shape.is_full() && !restricted && !options.general_engine {
            let po = PlanOptions {
                direction,
                threads,
                rigor: options.rigor,
                max_workspace_bytes: options.max_workspace_bytes,
                isa: Some(isa),
                skip_bits: Some(bits),
                real: options.real,
                ..PlanOptions::default()
            };
            Engine::Full(Box::new(Plan::new_on(shape.degree_limit, &po, shared)?))
        } else {
            Engine::General(Box::new(General::new(
                shape,
                pairs,
                (isa, bits, threads),
                options,
                shared,
            )?))
        };
        Ok(PartialPlan {
            shape: *shape,
            direction,
            real: options.real,
            threads,
            n_slices,
            engine,
        })
    }

    /// The plan's shape.
    pub fn shape(&self) -> &Shape {
        &self.shape
    }

    /// Which transforms the plan runs.
    pub fn direction(&self) -> Direction {
        self.direction
    }

    /// Worker threads.
    pub fn threads(&self) -> usize {
        self.threads
    }

    /// Whether the plan runs on [`Plan`] (the full shape) rather than the general engine.
    pub fn uses_full_plan(&self) -> bool {
        matches!(self.engine, Engine::Full(_))
    }

    /// Coefficients of one transform ([`Shape::num_coeffs`]).
    pub fn num_coeffs(&self) -> usize {
        match &self.engine {
            Engine::Full(p) => p.num_coeffs(),
            Engine::General(g) => g.layout.total,
        }
    }

    /// Samples of one transform: `n_alpha n_gamma` per beta slice, times the number of
    /// betas (`2 B_grid`, or the selection's length).
    pub fn num_samples(&self) -> usize {
        self.n_slices * self.shape.slice_len()
    }

    /// Number of beta slices of the samples.
    pub fn num_slices(&self) -> usize {
        self.n_slices
    }

    /// Forward: samples to coefficients.
    pub fn forward(&self, samples: &[Complex64], coeffs: &mut [Complex64]) -> Result<()> {
        self.forward_many(one(samples.len(), coeffs.len()), samples, coeffs)
            .map(|_| ())
    }

    /// Inverse: coefficients to samples.
    pub fn inverse(&self, coeffs: &[Complex64], samples: &mut [Complex64]) -> Result<()> {
        self.inverse_many(one(coeffs.len(), samples.len()), coeffs, samples)
            .map(|_| ())
    }

    /// Forward of a real signal (`num_samples` doubles): every coefficient block written.
    pub fn forward_real(&self, samples: &[f64], coeffs: &mut [Complex64]) -> Result<()> {
        self.forward_real_many(one(samples.len(), coeffs.len()), samples, coeffs)
            .map(|_| ())
    }

    /// Inverse to a real signal: reads only the blocks `M' > 0`, or `M' = 0` and `M >= 0`,
    /// and takes the others as `fhat(l,-M,-M') = (-1)^(M-M') conj(fhat(l,M,M'))`.
    pub fn inverse_real(&self, coeffs: &[Complex64], samples: &mut [f64]) -> Result<()> {
        self.inverse_real_many(one(coeffs.len(), samples.len()), coeffs, samples)
            .map(|_| ())
    }

    /// [`PartialPlan::inverse`] that shows every output slice to `watch` as it is
    /// computed, where the plan runs on [`Plan`] (the full shape); `Ok(false)` (and
    /// `watch` never called) on the general engine.
    pub(crate) fn inverse_watched(
        &self,
        coeffs: &[Complex64],
        samples: &mut [Complex64],
        watch: SliceWatch,
    ) -> Result<bool> {
        match &self.engine {
            Engine::Full(p) if self.direction != Direction::Forward => {
                p.inverse_watched(coeffs, samples, watch).map(|()| true)
            }
            _ => self.inverse(coeffs, samples).map(|()| false),
        }
    }

    /// [`PartialPlan::inverse_real`] with a watch, as [`PartialPlan::inverse_watched`].
    pub(crate) fn inverse_real_watched(
        &self,
        coeffs: &[Complex64],
        samples: &mut [f64],
        watch: SliceWatch,
    ) -> Result<bool> {
        match &self.engine {
            Engine::Full(p) if self.real && self.direction != Direction::Forward => p
                .inverse_real_watched(coeffs, samples, watch)
                .map(|()| true),
            _ => self.inverse_real(coeffs, samples).map(|()| false),
        }
    }

    /// `batch.count` forwards; the time of each stage.
    pub fn forward_many(
        &self,
        batch: Batch,
        samples: &[Complex64],
        coeffs: &mut [Complex64],
    ) -> Result<StageTimes> {
        self.check(true, false, batch, samples.len(), coeffs.len())?;
        match &self.engine {
            Engine::Full(p) => full_many(batch, self.sizes(true), |i, o| {
                p.forward_timed(&samples[i..][..o.0], &mut coeffs[o.1..][..o.2])
            }),
            Engine::General(g) => g.forward(
                batch,
                SendConstPtr(samples.as_ptr().cast()),
                SendPtr(coeffs.as_mut_ptr()),
                false,
            ),
        }
    }

    /// `batch.count` inverses; the time of each stage.
    pub fn inverse_many(
        &self,
        batch: Batch,
        coeffs: &[Complex64],
        samples: &mut [Complex64],
    ) -> Result<StageTimes> {
        self.check(false, false, batch, coeffs.len(), samples.len())?;
        match &self.engine {
            Engine::Full(p) => full_many(batch, self.sizes(false), |i, o| {
                p.inverse_timed(&coeffs[i..][..o.0], &mut samples[o.1..][..o.2])
            }),
            Engine::General(g) => g.inverse(
                batch,
                SendConstPtr(coeffs.as_ptr()),
                Data::Complex(SendPtr(samples.as_mut_ptr())),
            ),
        }
    }

    /// `batch.count` real forwards; the time of each stage.
    pub fn forward_real_many(
        &self,
        batch: Batch,
        samples: &[f64],
        coeffs: &mut [Complex64],
    ) -> Result<StageTimes> {
        self.check(true, true, batch, samples.len(), coeffs.len())?;
        match &self.engine {
            Engine::Full(p) => full_many(batch, self.sizes(true), |i, o| {
                p.forward_real_timed(&samples[i..][..o.0], &mut coeffs[o.1..][..o.2])
            }),
            Engine::General(g) => g.forward(
                batch,
                SendConstPtr(samples.as_ptr().cast()),
                SendPtr(coeffs.as_mut_ptr()),
                true,
            ),
        }
    }

    /// `batch.count` real inverses; the time of each stage.
    pub fn inverse_real_many(
        &self,
        batch: Batch,
        coeffs: &[Complex64],
        samples: &mut [f64],
    ) -> Result<StageTimes> {
        self.check(false, true, batch, coeffs.len(), samples.len())?;
        match &self.engine {
            Engine::Full(p) => full_many(batch, self.sizes(false), |i, o| {
                p.inverse_real_timed(&coeffs[i..][..o.0], &mut samples[o.1..][..o.2])
            }),
            Engine::General(g) => g.inverse(
                batch,
                SendConstPtr(coeffs.as_ptr()),
                Data::Real(SendPtr(samples.as_mut_ptr())),
            ),
        }
    }

    /// Input and output lengths of one transform.
    fn sizes(&self, forward: bool) -> (usize, usize) {
        if forward {
            (self.num_samples(), self.num_coeffs())
        } else {
            (self.num_coeffs(), self.num_samples())
        }
    }

    fn check(&self, forward: bool, real: bool, b: Batch, inp: usize, out: usize) -> Result<()> {
        let in_process = match &self.engine {
            Engine::Full(_) => true,
            Engine::General(g) => g.workers.in_own_process(),
        };
        if !in_process {
            return Err(Error::InvalidArgument(
                "plan made in another process (before fork()); make a new plan here".into(),
            ));
        }
        self.direction.check_runs(forward)?;
        if real && !self.real {
            return Err(Error::InvalidArgument(
                "real-signal transform on a plan made without the real option".into(),
            ));
        }
        let (ilen, olen) = self.sizes(forward);
        let (iname, oname) = if forward {
            ("samples", "coefficients")
        } else {
            ("coefficients", "samples")
        };
        if b.count == 0 {
            return Err(Error::InvalidArgument("batch of 0 transforms".into()));
        }
        if b.count > 1 && b.out_dist < olen {
            return Err(Error::InvalidArgument(format!(
                "batch: outputs {} values apart overlap (each has {olen})",
                b.out_dist
            )));
        }
        let need = |dist: usize, len: usize| {
            dist.checked_mul(b.count - 1)
                .and_then(|x| x.checked_add(len))
                .unwrap_or(usize::MAX)
        };
        if inp < need(b.in_dist, ilen) {
            return Err(Error::LengthMismatch {
                what: iname,
                expected: need(b.in_dist, ilen),
                got: inp,
            });
        }
        if out < need(b.out_dist, olen) {
            return Err(Error::LengthMismatch {
                what: oname,
                expected: need(b.out_dist, olen),
                got: out,
            });
        }
        if b.count == 1 && (inp != ilen || out != olen) {
            let (what, expected, got) = if inp != ilen {
                (iname, ilen, inp)
            } else {
                (oname, olen, out)
            };
            return Err(Error::LengthMismatch {
                what,
                expected,
                got,
            });
        }
        Ok(())
    }
}

/// A batch of one for arrays of these lengths.
fn one(inp: usize, out: usize) -> Batch {
    Batch {
        count: 1,
        in_dist: inp,
        out_dist: out,
    }
}

/// A batch on the full plan: `run(in_offset, (in_len, out_offset, out_len))` per transform.
fn full_many(
    b: Batch,
    (ilen, olen): (usize, usize),
    mut run: impl FnMut(usize, (usize, usize, usize)) -> Result<StageTimes>,
) -> Result<StageTimes> {
    let mut sum = StageTimes::default();
    for t in 0..b.count {
        let s = run(t * b.in_dist, (ilen, t * b.out_dist, olen))?;
        sum.fft += s.fft;
        sum.dwt += s.dwt;
        sum.total += s.total;
    }
    Ok(sum)
}

impl General {
    pub(super) fn new(
        shape: &Shape,
        pairs: LanePairs,
        (isa, bits, threads): (Isa, u32, usize),
        options: &PartialOptions,
        shared: Option<&WorkerPool>,
    ) -> Result<General> {
        let layout = CoefLayout::new(shape);
        let (na, ng) = (shape.n_alpha, shape.n_gamma);
        let arrays = 16 * (shape.num_samples() + shape.num_coeffs());
        let budget = options
            .max_workspace_bytes
            .unwrap_or_else(|| (512usize << 20).max(arrays / 20));
        let w = isa.lanes();
        let max_lanes = 2 * pairs.pairs.next_multiple_of(w);
        let slice_bytes = na * ng * 16 * if options.real { 2 } else { 1 };
        let tables = 64 * 2 * pairs.pairs * (2 * shape.degree_limit + 66);
        check_headroom(
            DwtStage::bytes(shape.degree_limit, 0, threads, max_lanes)
                .saturating_add(threads * (slice_bytes + WORKER_STACK_BYTES))
                .saturating_add(tables)
                .saturating_add(crate::fft::planning_bytes(4 * na * ng, 1)),
        )?;
        // No skipping: the scaled starting values still need a threshold (the widest).
        let skip = if bits == 0 {
            (*SKIP_BITS_RANGE.end(), false)
        } else {
            (bits, true)
        };
        let fft = FftStage::new(
            (na, ng),
            shape.order_limit_gamma,
            options.real,
            options.rigor,
        )?;
        let dwt = DwtStage::new(
            &layout,
            (na, ng, fft.strides().0),
            isa,
            skip,
            (threads, max_lanes),
        );
        let pair_weight = if options.betas == Betas::All {
            let wts = crate::grid::weights(shape.grid_bandwidth);
            let f = 2.0 * PI / (na * ng) as f64;
            wts[..pairs.pairs].iter().map(|x| x * f).collect()
        } else {
            Vec::new()
        };
        let slots = SlotTable::new(&dwt, (na, fft.strides().1))?;
        Ok(General {
            layout,
            pairs,
            slots,
            dwt,
            fft,
            pair_weight,
            work: (0..threads).map(|_| Mutex::new(Work::default())).collect(),
            buf: Mutex::new(None),
            budget,
            lanes_w: w,
            layout_n: shape.order_limit_gamma,
            workers: WorkerPool::shared_or_new(shared, threads)?,
        })
    }

    /// Bytes of one transform's blocks per lane pair.
    fn pair_bytes(&self) -> usize {
        (self.dwt.row_total * 2 * 8).max(1)
    }

    /// Lane pairs per chunk: what the workspace cap holds for one transform (at least
    /// one), the pairs spread evenly over the fewest chunks, a multiple of the vector
    /// width when that is at least one vector. It does not depend on the batch, so a batch
    /// sums in the order of single executes.
    fn chunk_pairs(&self) -> usize {
        let pairs = self.pairs.pairs;
        let most = (self.budget / self.pair_bytes()).clamp(1, pairs);
        let h = pairs.div_ceil(pairs.div_ceil(most));
        let w = self.lanes_w;
        if h >= w && h.next_multiple_of(w) <= most {
            h.next_multiple_of(w)
        } else {
            h
        }
    }

    /// Transforms of a batch run together (sharing each cluster's recurrence coefficients,
    /// starting values and d values, see `dwt/batch.rs`): as many as the workspace cap holds
    /// at the chunk size (at least one).
    fn group_size(&self) -> usize {
        let hp = self.chunk_pairs().next_multiple_of(self.lanes_w);
        (self.budget / (hp * self.pair_bytes())).max(1)
    }

    /// Runs `run(first, sub_batch)` on the groups of `batch` (see [`General::group_size`]),
    /// summing the stage times.
    fn by_groups(
        &self,
        batch: Batch,
        mut run: impl FnMut(usize, Batch) -> Result<StageTimes>,
    ) -> Result<StageTimes> {
        let g = self.group_size();
        let mut sum = StageTimes::default();
        let mut t0 = 0;
        while t0 < batch.count {
            let count = g.min(batch.count - t0);
            let s = run(t0, Batch { count, ..batch })?;
            sum.fft += s.fft;
            sum.dwt += s.dwt;
            sum.total += s.total;
            t0 += count;
        }
        Ok(sum)
    }

    /// Inverse of a batch, group by group.
    fn inverse(
        &self,
        batch: Batch,
        coef: SendConstPtr<Complex64>,
        out: Data,
    ) -> Result<StageTimes> {
        self.by_groups(batch, |t0, b| {
            let c = SendConstPtr(coef.get().wrapping_add(t0 * batch.in_dist));
            let o = match out {
                Data::Complex(p) => {
                    Data::Complex(SendPtr(p.get().wrapping_add(t0 * batch.out_dist)))
                }
                Data::Real(p) => Data::Real(SendPtr(p.get().wrapping_add(t0 * batch.out_dist))),
            };
            self.inverse_group(b, c, o)
        })
    }

    /// Forward of a batch, group by group (`inp` complex values, or reals with `real`).
    fn forward(
        &self,
        batch: Batch,
        inp: SendConstPtr<f64>,
        coef: SendPtr<Complex64>,
        real: bool,
    ) -> Result<StageTimes> {
        let per_value = if real { 1 } else { 2 };
        self.by_groups(batch, |t0, b| {
            let i = SendConstPtr(inp.get().wrapping_add(t0 * batch.in_dist * per_value));
            let c = SendPtr(coef.get().wrapping_add(t0 * batch.out_dist));
            self.forward_group(b, i, c, real)
        })
    }

    /// Runs `f` with the chunk buffer of at least `len` doubles (the plan's, else a new one).
    fn with_buf<R>(&self, len: usize, f: impl FnOnce(*mut f64) -> Result<R>) -> Result<R> {
        let mut guard = self.buf.try_lock().ok();
        let mut own = None;
        let slot: &mut Option<AlignedBuf> = match guard.as_deref_mut() {
            Some(s) => s,
            None => &mut own,
        };
        let complex = len.div_ceil(2);
        if slot.as_ref().is_none_or(|b| b.len() < complex) {
            *slot = None;
            check_headroom(complex * 16)?;
            *slot = Some(AlignedBuf::new(complex)?);
        }
        let p = slot.as_ref().expect("just made").as_mut_ptr().cast::<f64>();
        f(p)
    }

    /// Runs `f` with a worker's FFT buffers (a private set when all are busy).
    pub(super) fn with_work<R>(&self, f: impl FnOnce(&mut Work) -> Result<R>) -> Result<R> {
        match lock_free(&self.work) {
            Some(mut g) => f(&mut g),
            None => f(&mut Work::default()),
        }
    }

    /// The chunks of lane pairs for `count` transforms.
    fn chunks(&self) -> impl Iterator<Item = ChunkLanes> + '_ {
        let h = self.chunk_pairs();
        let w = self.lanes_w;
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
                row_len: self.dwt.row_total,
                first_upper_pair,
            }
        })
    }

    /// Inverse of a group of transforms, chunk by chunk.
    fn inverse_group(
        &self,
        batch: Batch,
        coef: SendConstPtr<Complex64>,
        out: Data,
    ) -> Result<StageTimes> {
        let start = Instant::now();
        let mut times = StageTimes::default();
        let hp_max = self.chunk_pairs().next_multiple_of(self.lanes_w);
        let per_t_max = self.dwt.row_total * 2 * hp_max;
        let slice_len = self.fft.slice_len();
        let real = matches!(out, Data::Real(_));
        // Rows far larger than the caches go out with non-temporal stores.
        let stream = batch.count * per_t_max * 8 > 8 << 20;
        self.with_buf(batch.count * per_t_max, |buf| {
            let buf = SendPtr(buf);
            self.workers.pool().install(|| {
                for ch in self.chunks() {
                    // Chunks of padding pairs only (selections) write nothing.
                    let tasks = self.slice_tasks(ch, batch.count);
                    if tasks.is_empty() {
                        continue;
                    }
                    let lanes = ch.lanes();
                    let per_t = self.dwt.row_total * lanes;
                    let t0 = Instant::now();
                    let clusters = &self.dwt.clusters;
                    clusters
                        .par_iter()
                        .enumerate()
                        .with_min_len(4)
                        .for_each(|(i, cl)| {
                            self.dwt.with_scratch(|sc| {
                                let n = self.dwt.setup(sc, cl, &self.pairs, ch);
                                for t0 in (0..batch.count).step_by(KERNEL_BATCH) {
                                    let count = KERNEL_BATCH.min(batch.count - t0);
                                    // What the next kernel call will gather: this cluster
                                    // for the next transforms, else the next cluster (likely
                                    // this task's next one) for the first ones.
                                    let next = if t0 + count < batch.count {
                                        Some((cl, t0 + count))
                                    } else {
                                        clusters.get(i + 1).map(|c| (c, 0))
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
                                        base: buf.get().wrapping_add(t0 * per_t + cl.offset),
                                        dist: per_t,
                                        count,
                                    };
                                    // SAFETY: coefficient arrays `t0..t0 + count` of the
                                    // batch (checked lengths), read only; this cluster's
                                    // `cl.p` doubles of the lane rows of those transforms,
                                    // inside the chunk buffer, written by this task only.
                                    unsafe {
                                        if count == 1 {
                                            let hints = next.map_or(Prefetch::none(), |(c, r)| {
                                                self.dwt.coefficient_hints(c, r.base, real)
                                            });
                                            self.dwt.inverse(
                                                sc,
                                                cl,
                                                ch,
                                                n,
                                                c.base,
                                                (real, stream, hints),
                                                b.base,
                                            )
                                        } else {
                                            self.dwt.inverse_many(
                                                sc,
                                                cl,
                                                ch,
                                                n,
                                                c,
                                                (real, stream, next),
                                                b,
                                            )
                                        }
                                    }
                                }
                            })
                        });
                    let t1 = Instant::now();
                    times.dwt += (t1 - t0).as_secs_f64();
                    tasks.par_iter().try_for_each(|&(t, jj, upper, s)| {
                        self.with_work(|work| {
                            let rows = self.lane_rows(buf.get(), t * per_t, ch, (jj, upper));
                            let at = t * batch.out_dist + s * slice_len;
                            match out {
                                Data::Complex(o) => {
                                    let w = self.fft.inv_buf(work)?;
                                    // SAFETY: the lane rows were written by the DWT stage
                                    // above (finished); slice `s` of output `t` is inside
                                    // the checked output and this task's alone.
                                    unsafe {
                                        self.scatter(w, &[rows]);
                                        self.fft.inverse(w, o.get().add(at));
                                    }
                                }
                                Data::Real(o) => {
                                    let w = self.fft.half_buf(work)?;
                                    // SAFETY: as above, for the real output.
                                    unsafe {
                                        self.scatter_real(w, &[rows]);
                                        self.fft.inverse_real(w, o.get().add(at));
                                    }
                                }
                            }
                            Ok(())
                        })
                    })?;
                    times.fft += t1.elapsed().as_secs_f64();
                }
                Ok(())
            })
        })?;
        times.total = start.elapsed().as_secs_f64();
        Ok(times)
    }

    /// Forward of a group of transforms, chunk by chunk.
    fn forward_group(
        &self,
        batch: Batch,
        inp: SendConstPtr<f64>,
        coef: SendPtr<Complex64>,
        real: bool,
    ) -> Result<StageTimes> {
        let start = Instant::now();
        let mut times = StageTimes::default();
        let hp_max = self.chunk_pairs().next_multiple_of(self.lanes_w);
        let per_t_max = self.dwt.row_total * 2 * hp_max;
        let slice_len = self.fft.slice_len();
        self.with_buf(batch.count * per_t_max, |buf| {
            let buf = SendPtr(buf);
            self.workers.pool().install(|| {
                for ch in self.chunks() {
                    let lanes = ch.lanes();
                    let per_t = self.dwt.row_total * lanes;
                    let t0 = Instant::now();
                    let tasks = self.slice_tasks(ch, batch.count);
                    tasks.par_iter().try_for_each(|&(t, jj, upper, s)| {
                        self.with_work(|work| {
                            let rows = self.lane_rows(buf.get(), t * per_t, ch, (jj, upper));
                            let weight = self.pair_weight[ch.j0 + jj];
                            // SAFETY: slice `s` of input `t` is inside the checked input
                            // (complex values, or reals for the real forward); the values
                            // written are this slice's slots of two lane rows: no other
                            // task writes them (its mirror writes the other slots of the
                            // same rows).
                            unsafe {
                                if real {
                                    let w = self.fft.half_buf(work)?;
                                    let at = t * batch.in_dist + s * slice_len;
                                    self.fft.forward_real(w, inp.get().add(at));
                                    self.gather_real(w, &[rows], weight);
                                } else {
                                    let w = self.fft.fwd_buf(work)?;
                                    let at = 2 * (t * batch.in_dist + s * slice_len);
                                    self.fft.forward(w, inp.get().add(at).cast());
                                    self.gather(w, &[rows], weight);
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
                        unsafe { self.zero_padding(buf.get().add(t * per_t), ch) };
                    }
                    self.dwt.clusters.par_iter().with_min_len(4).for_each(|cl| {
                        self.dwt.with_scratch(|sc| {
                            let n = self.dwt.setup(sc, cl, &self.pairs, ch);
                            for t0 in (0..batch.count).step_by(KERNEL_BATCH) {
                                let count = KERNEL_BATCH.min(batch.count - t0);
                                let block = buf.get().wrapping_add(t0 * per_t + cl.offset);
                                let c = coef.get().wrapping_add(t0 * batch.out_dist);
                                // SAFETY: this cluster's slots of the lane rows of
                                // transforms `t0..t0 + count` (written by the FFT stage or
                                // zeroed above, finished); their coefficient arrays are
                                // inside the checked output, and this cluster's slots'
                                // blocks are this task's.
                                unsafe {
                                    if count == 1 {
                                        self.dwt.forward(sc, cl, ch, n, block, c, first)
                                    } else {
                                        self.dwt.forward_many(
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
                        })
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
            for jj in 0..ch.h {
                for (u, &s) in self.pairs.outputs[ch.j0 + jj].iter().enumerate() {
                    if s != usize::MAX {
                        v.push((t, jj, u == 1, s));
                    }
                }
            }
        }
        v
    }

    /// The lane rows of a slice (its own, and its mirror's, where its reversed members
    /// are) in the chunk buffer at `buf`, transform offset `at`.
    pub(super) fn lane_rows(
        &self,
        buf: *mut f64,
        at: usize,
        ch: ChunkLanes,
        (jj, upper): (usize, bool),
    ) -> LaneRows {
        let rt = self.dwt.row_total;
        let (r, rm) = if upper {
            (ch.hp + jj, jj)
        } else {
            (jj, ch.hp + jj)
        };
        LaneRows {
            own: buf.wrapping_add(at + r * rt),
            mirror: buf.wrapping_add(at + rm * rt),
            clusters: (0, self.dwt.clusters.len()),
        }
    }

    /// Complex inverse: a slice's values from its lane rows into the inverse's work buffer
    /// (whose columns `|M'| <= N` are cleared first; the others stay zero).
    ///
    /// # Safety
    /// Each part's lane rows hold its clusters' slots, written by the DWT stage.
    pub(super) unsafe fn scatter(&self, w: &mut [Complex64], rows: &[LaneRows]) {
        let (na, ng) = self.fft.dims();
        let (rs, _) = self.fft.strides();
        let n = self.layout_n;
        for row in w.chunks_exact_mut(rs).take(na) {
            row[..=n].fill(Complex64::default());
            row[ng - n..ng].fill(Complex64::default());
        }
        for part in rows {
            for &(at, work) in self.slots.of(part.clusters) {
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
    pub(super) unsafe fn scatter_real(&self, w: &mut [Complex64], rows: &[LaneRows]) {
        w.fill(Complex64::default());
        for part in rows {
            for &(at, idx) in self.slots.real_of(part.clusters) {
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
    pub(super) unsafe fn gather(&self, w: &[Complex64], rows: &[LaneRows], weight: f64) {
        for part in rows {
            for &(at, work) in self.slots.of(part.clusters) {
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
    pub(super) unsafe fn gather_real(&self, w: &[Complex64], rows: &[LaneRows], weight: f64) {
        for part in rows {
            for &(at, idx) in self.slots.real_of(part.clusters) {
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
    pub(super) unsafe fn zero_padding(&self, rows: *mut f64, ch: ChunkLanes) {
        let rt = self.dwt.row_total;
        for half in 0..2 {
            let from = half * ch.hp + ch.h;
            // SAFETY: lane rows `from..(half + 1) hp`, inside the chunk's rows.
            unsafe { std::ptr::write_bytes(rows.add(from * rt), 0, (ch.hp - ch.h) * rt) };
        }
    }
}

/// A slice's lane rows: its own and its mirror's, for the clusters `clusters.0 ..
/// clusters.1`; cluster `c`'s slots start `offset(c)` doubles after the pointers (which may
/// point before the rows when they hold only a later part of the clusters).
#[derive(Clone, Copy)]
pub(super) struct LaneRows {
    own: *mut f64,
    mirror: *mut f64,
    clusters: (usize, usize),
}

impl LaneRows {
    /// Rows that hold the clusters `clusters` only, the first of which at offset `first`
    /// of the full lane row: their slots at `own` and `mirror` onwards.
    pub(super) fn part(
        (own, mirror): (*mut f64, *mut f64),
        clusters: (usize, usize),
        first: usize,
    ) -> LaneRows {
        LaneRows {
            own: own.wrapping_sub(first),
            mirror: mirror.wrapping_sub(first),
            clusters,
        }
    }

    /// Where a slot of a [`SlotTable`] entry is.
    #[inline(always)]
    fn at(&self, at: u32) -> *mut f64 {
        let row = if at & SlotTable::MIRROR != 0 {
            self.mirror
        } else {
            self.own
        };
        row.wrapping_add((at & !SlotTable::MIRROR) as usize)
    }
}

/// Every slot of a lane row in cluster order, flat: the FFT stage's scatters and gathers
/// read 8 bytes a slot here (one table for the complex layout, one for the real) instead of
/// each cluster's list of slots (a heap allocation per cluster, 64 bytes a slot: at
/// B = 128 about 4 MB read per slice).
pub(super) struct SlotTable {
    /// `(offset in the lane row, or'ed with MIRROR for a reversed member, whose value is in
    /// the mirror's row; index in the FFT stage's work buffer)`.
    entries: Vec<(u32, u32)>,
    /// First entry of each cluster, then the total.
    start: Vec<usize>,
    /// The same for the real layout's half buffer (`n_alpha` rows `hs` apart, `M' >= 0`):
    /// the index of `(M, M')` if `M' >= 0`, else of `(-M, -M')` or'ed with `CONJ` (the real
    /// forward reads the value there unconjugated; the real inverse skips it).
    real: Vec<(u32, u32)>,
}

impl SlotTable {
    const MIRROR: u32 = 1 << 31;
    const CONJ: u32 = 1 << 31;

    /// The table of `dwt`'s clusters; the real entries for a half buffer of `na` rows `hs`
    /// apart.
    fn new(dwt: &DwtStage, (na, hs): (usize, usize)) -> Result<SlotTable> {
        let too_large =
            || Error::InvalidArgument("shape too large for the general engine's slot table".into());
        let fits = |x: usize| u32::try_from(x).ok().filter(|a| a & (1 << 31) == 0);
        let half = |m: isize, mp: isize| m.rem_euclid(na as isize) as usize * hs + mp as usize;
        let mut entries = Vec::new();
        let mut real = Vec::new();
        let mut start = Vec::with_capacity(dwt.clusters.len() + 1);
        for cl in &dwt.clusters {
            start.push(entries.len());
            for (q, s) in cl.slots.iter().enumerate() {
                let mem = &s.member;
                let (Some(at), Ok(work)) = (fits(cl.offset + 2 * q), u32::try_from(s.work)) else {
                    return Err(too_large());
                };
                let at = at | if mem.reversed { Self::MIRROR } else { 0 };
                entries.push((at, work));
                let idx = if mem.mp >= 0 {
                    fits(half(mem.m, mem.mp))
                } else {
                    fits(half(-mem.m, -mem.mp)).map(|i| i | Self::CONJ)
                };
                real.push((at, idx.ok_or_else(too_large)?));
            }
        }
        start.push(entries.len());
        Ok(SlotTable {
            entries,
            start,
            real,
        })
    }

    /// The entries of clusters `a..b`.
    fn of(&self, (a, b): (usize, usize)) -> &[(u32, u32)] {
        &self.entries[self.start[a]..self.start[b]]
    }

    /// The real entries of clusters `a..b`.
    fn real_of(&self, (a, b): (usize, usize)) -> &[(u32, u32)] {
        &self.real[self.start[a]..self.start[b]]
    }
}
