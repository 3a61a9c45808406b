//! Plans: everything that depends only on the bandwidth is computed once here, and
//! executing a plan runs the two stages (FFTW over (alpha, gamma), DWT per cluster)
//! chunk by chunk over mirrored pairs of beta slices.
//!
//! Beta slices are processed in chunks of `h` low slices `k` plus their mirrors
//! `2B-1-k` (the Wigner-d symmetries pair `beta` with `pi - beta`), so the only large
//! buffer is the chunk buffer, which holds the `2h` transformed slices in the DWT
//! kernels' own layout (`plan/blocks.rs`), never a copy of the grid.
//!
//! Modules, lowest first (none imports one above it; the `impl Plan` blocks of `build`,
//! `exec`, `real` and `fft_tune` import only the `Plan` type from here):
//! - `shared`: pointer wrappers sent across rayon tasks, per-worker scratch pools;
//! - `options`: the largest bandwidth and [`StageTimes`];
//! - `members`, `coeffs`: which order pairs a layout holds; copies of coefficient rows;
//! - `blocks`: the chunk buffer's layouts (slot tables, block offsets);
//! - `schedule`: chunks, groups of chunks and where their buffers live;
//! - `block_copies`: the moves between transformed slices and the rows of the blocks;
//! - `fft_stage`: [`FftStage`], the slice FFTs of a chunk, a group of pairs at a time;
//! - `dwt_stage`: [`DwtStage`], the kernels per cluster, coefficient signs and layout;
//! - `build`: validation, memory layout and construction of a plan;
//! - `exec`: the chunk loop every transform runs;
//! - `real`: the real-signal transforms;
//! - `fft_tune`: the plan-time choice of FFT threading ([`FftThreading::Auto`]).

mod block_copies;
mod blocks;
mod build;
pub(crate) mod coeffs;
mod dwt_stage;
mod exec;
mod fft_stage;
mod fft_tune;
mod members;
mod options;
mod real;
mod schedule;
mod shared;
#[cfg(test)]
mod tests;
mod transform;

pub use options::{StageTimes, MAX_BANDWIDTH};

#[cfg(feature = "internals")]
pub use fft_stage::BlockCopies;
pub(crate) use fft_stage::{SliceRef, SliceWatch};

use crate::error::{check_length, Result};
use crate::fft::ChunkBuffer;
use crate::grid::{num_coeffs, num_samples};
use crate::options::{Direction, FftThreading, Options};
use crate::simd::Isa;
use crate::workers::WorkerPool;
use blocks::Blocks;
use dwt_stage::DwtStage;
use fft_stage::FftStage;
use num_complex::Complex64;
use schedule::{Schedule, Spare};

/// A precomputed SO(3) FFT of one bandwidth: weights, Wigner starting-value tables,
/// cluster schedule, FFTW plans, worker pool and chunk buffer.
///
/// Execution methods take `&self`; a plan may be executed from several threads at once
/// on different arrays (a concurrent call that finds the chunk buffer busy allocates its own).
pub struct Plan {
    /// The bandwidth `B`.
    b: usize,
    direction: Direction,
    threads: usize,
    /// Worker threads (exist only in the process that made the plan).
    workers: WorkerPool,
    /// Bytes this plan holds.
    memory: usize,
    /// The FFT stage: slice FFTs, weights, per-worker FFT scratch.
    fft: FftStage,
    /// The DWT stage: cluster order, Wigner-d tables, per-worker DWT scratch.
    dwt: DwtStage,
    /// Chunk-buffer layout of the complex transforms.
    blocks: Blocks,
    /// Chunk-buffer layout of the real-signal transforms (with `Options::real`).
    blocks_real: Option<Blocks>,
    /// The chunk buffer (taken by one execution at a time, see `Plan::with_buf`).
    buf: ChunkBuffer,
    /// How executions go through the chunks (and the chunk buffer's size).
    schedule: Schedule,
}

impl Plan {
    /// Make a plan for bandwidth `bandwidth` (1 ..= [`MAX_BANDWIDTH`]).
    ///
    /// With [`FftThreading::Auto`], a measuring rigour and more than one thread, this also
    /// times both ways of threading the FFT stage and keeps the faster one (see
    /// [`FftThreading::Auto`]; [`Plan::fft_threading`] tells which).
    pub fn new(bandwidth: usize, options: &Options) -> Result<Plan> {
        Plan::new_on(bandwidth, options, None)
    }

    /// [`Plan::new`] on the workers of `shared` if given (with the plan's thread count).
    pub(crate) fn new_on(
        bandwidth: usize,
        options: &Options,
        shared: Option<&WorkerPool>,
    ) -> Result<Plan> {
        let mut plan = Plan::build(bandwidth, options, shared)?;
        plan.tune_fft_threading(options);
        Ok(plan)
    }

    /// Bytes of memory a plan made now with these arguments would hold
    /// ([`Plan::memory_bytes`]), without making it: the same checks as [`Plan::new`]
    /// (bandwidth, threads, options) and the same formulas, nothing allocated. The default
    /// workspace depends on the memory available at the time of the call (at most half of
    /// it is used), so a plan made later may differ if that has changed.
    pub fn memory_needed(bandwidth: usize, options: &Options) -> Result<usize> {
        let threads = Plan::validate(bandwidth, options)?.threads;
        Ok(Plan::layout(bandwidth, threads, options).total())
    }

    fn pool(&self) -> &rayon::ThreadPool {
        self.workers.pool()
    }

    /// Runs `f` on the plan's worker threads (rayon's parallel iterators inside it use
    /// them), for work that goes with a transform, such as the SOFT layer's checks.
    pub(crate) fn install<R: Send>(&self, f: impl FnOnce() -> R + Send) -> R {
        self.pool().install(f)
    }

    /// The bandwidth `B`.
    pub fn bandwidth(&self) -> usize {
        self.b
    }

    /// Number of worker threads.
    pub fn threads(&self) -> usize {
        self.threads
    }

    /// Which transforms this plan runs.
    pub fn direction(&self) -> Direction {
        self.direction
    }

    /// Instruction set of the DWT kernels.
    pub fn isa(&self) -> Isa {
        self.dwt.isa()
    }

    /// How the FFT stage of the complex transforms uses the threads: the resolved variant,
    /// never [`FftThreading::Auto`]. With one thread this is always
    /// [`FftThreading::SlicesAcrossWorkers`] (FFTW's threads are not used).
    pub fn fft_threading(&self) -> FftThreading {
        if self.fft.fftw_threaded() {
            FftThreading::FftwThreads
        } else {
            FftThreading::SlicesAcrossWorkers
        }
    }

    /// `(2B)^3`.
    pub fn num_samples(&self) -> usize {
        num_samples(self.b)
    }

    /// `(4B^3 - B)/3`.
    pub fn num_coeffs(&self) -> usize {
        num_coeffs(self.b)
    }

    /// Bytes of memory the plan holds (chunk buffer, per-worker FFT buffers, tables),
    /// computed before allocating: the chunk buffer ([`Plan::workspace_bytes`]) plus
    /// `threads * 2g * 2B (2B + 4) * 16` for the per-worker FFT buffers (a group of `g`
    /// pairs of beta slices, each row padded by 4 values;
    /// `g = clamp(512 KiB / (2 (2B)^2 16), 1, 4)`, i.e. 4 for B <= 32 and 1 from B = 64 on)
    /// plus `O(B^2)` tables. A transform needs the
    /// caller's arrays on top (`(2B)^3` and `(4B^3-B)/3` complex values) and nothing else
    /// large. [`Plan::memory_needed`] gives the same number before planning.
    /// [`Plan::new`] fails with [`Error::OutOfMemory`](crate::Error::OutOfMemory) when this exceeds the available memory.
    pub fn memory_bytes(&self) -> usize {
        self.memory
    }

    /// Bytes of the chunk buffer. For the complex transforms it holds `2 h'` betas of
    /// `8B^2 - 8B + 8` doubles (the `(2B-1)^2` in-band values of a transformed slice in the
    /// DWT kernels' layout: 16 doubles per 8-member cluster, 8 per other one), with `h` low
    /// betas per chunk and `h'` = `h` rounded up to a multiple of 8; the real-signal
    /// transforms ([`Options::real`]) hold `4B^2 + 4B` doubles per beta (8 per
    /// cluster), and so about twice the betas per chunk. For a cap `c` bytes each layout
    /// takes `h = min(B, max(8, 8 floor(c / (16 * 8 * d))))` with `d` its doubles per beta,
    /// and the buffer is the larger of the two. With `max_workspace_bytes` the cap is that
    /// value. By default the whole plan ([`Plan::memory_bytes`]) is held to
    /// `max(512 MiB, 4.7% of the sample and coefficient arrays)` (real samples for a real
    /// plan; at most half the available memory), and the cap is what the FFT buffers and
    /// tables leave of it. At B = 512 that keeps a complex transform within the caller's
    /// arrays plus 5%.
    pub fn workspace_bytes(&self) -> usize {
        self.schedule.buf_bytes
    }

    fn check(&self, fwd: bool, samples: usize, coeffs: usize) -> Result<()> {
        self.workers.check_process()?;
        self.direction.check_runs(fwd)?;
        check_length("samples", self.num_samples(), samples)?;
        check_length("coefficients", self.num_coeffs(), coeffs)
    }

    /// Forward transform: samples (`(2B)^3`, the sample layout of docs/conventions.md) to
    /// coefficients (`(4B^3-B)/3`); the time of each stage. As [`Transform::forward`](crate::Transform::forward).
    pub fn forward(&self, samples: &[Complex64], coeffs: &mut [Complex64]) -> Result<StageTimes> {
        self.check(true, samples.len(), coeffs.len())?;
        self.forward_impl(samples.as_ptr(), coeffs, (None, None))
    }

    /// Inverse transform: coefficients to samples; the time of each stage. As
    /// [`Transform::inverse`](crate::Transform::inverse).
    pub fn inverse(&self, coeffs: &[Complex64], samples: &mut [Complex64]) -> Result<StageTimes> {
        self.check(false, samples.len(), coeffs.len())?;
        self.inverse_impl(coeffs, samples, (None, None))
    }

    /// [`Plan::inverse`] that shows every output slice to `watch` as it is computed.
    pub(crate) fn inverse_watched(
        &self,
        coeffs: &[Complex64],
        samples: &mut [Complex64],
        watch: SliceWatch,
    ) -> Result<()> {
        self.check(false, samples.len(), coeffs.len())?;
        self.inverse_impl(coeffs, samples, (Some(watch), None))
            .map(|_| ())
    }

    /// [`Plan::forward`] that may overwrite `samples` (like FFTW's `FFTW_DESTROY_INPUT`):
    /// their contents afterwards are unspecified. In return a plan whose chunk buffer
    /// holds fewer betas than the grid (see [`Plan::workspace_bytes`]) keeps the buffers
    /// of later chunks in the input slices it has read already and adds each cluster's
    /// sums to the coefficients once per group of chunks instead of once per chunk (where
    /// the buffers fit, all chunks form one group). Same memory, same results up to
    /// rounding.
    pub fn forward_destroying_input(
        &self,
        samples: &mut [Complex64],
        coeffs: &mut [Complex64],
    ) -> Result<StageTimes> {
        self.check(true, samples.len(), coeffs.len())?;
        // One raw pointer for reading the slices and for the buffers in the read ones.
        let base = samples.as_mut_ptr();
        let spare = Spare::over(base, self.b);
        self.forward_impl(base, coeffs, (Some(spare), None))
    }
}

/// The FFT stage alone, every chunk of the complex layout in one direction, with the sample
/// array `grid` as its input (forward) or output (inverse): for the measuring tools in
/// `benches/` (feature `internals`).
#[cfg(feature = "internals")]
pub fn fft_stage_alone(plan: &Plan, forward: bool, grid: &mut [Complex64]) -> Result<()> {
    check_length("samples", plan.num_samples(), grid.len())?;
    let grid = shared::SendPtr(grid.as_mut_ptr());
    plan.with_buf(None, |buf| {
        plan.pool().install(|| {
            let layout = if !forward && plan.schedule.streams_blocks(1) {
                blocks::BufLayout::HalfMajor(plan.blocks.total() / 2)
            } else {
                blocks::BufLayout::Blocks
            };
            let buf = blocks::ChunkBuf {
                base: shared::SendPtr(buf.as_mut_ptr() as *mut f64),
                layout,
            };
            for ch in plan.schedule.chunks(&plan.blocks) {
                plan.fft
                    .chunk(&plan.blocks, &ch, (forward, None), grid, buf)?;
            }
            Ok(())
        })
    })
}
