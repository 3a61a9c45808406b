//! Plans: everything that depends only on the bandwidth is computed once here, and
//! executing a plan runs the two stages (FFTW over (alpha, gamma), DWT per cluster)
//! chunk by chunk over mirrored pairs of beta slices.
//!
//! Beta slices are processed in chunks of `h` low slices `k` plus their mirrors
//! `2B-1-k` (the Wigner-d symmetries pair `beta` with `pi - beta`), so the only large
//! buffer is the chunk buffer, which holds the `2h` transformed slices in the DWT
//! kernels' own layout (`plan/blocks.rs`), never a copy of the grid.
//!
//! Modules: `blocks` (the chunk buffer's layout), `fft_stage` (FFTW and the moves in and
//! out of the blocks), `dwt_stage` (kernels per cluster, coefficient signs and layout),
//! `real` (the real-signal transforms), `fft_tune` (plan-time choice of FFT threading).

use crate::dwt::{self, Lanes, Prefetch, Rec};
use crate::error::{Error, Result};
use crate::fft::{self, AlignedBuf, Rigor, SliceFft, SliceFftReal, SIGN_MINUS, SIGN_PLUS};

mod blocks;
mod coeffs;
mod dwt_stage;
mod fft_stage;
mod fft_tune;
mod real;
use crate::grid::{block_start, num_coeffs, num_samples, weights};
use crate::numeric::Ext;
use crate::simd::Isa;
use crate::symmetry::{cluster_pairs, Cluster, Member};
use crate::wigner::{
    big, start_norms, BetaTables, RecCoeffs, RecTables, DEFAULT_SKIP_BITS, SKIP_BITS_RANGE,
};
use blocks::{Blocks, BufLayout};
use dwt_stage::{all_members, Scratch};
use num_complex::Complex64;
use rayon::prelude::*;
use std::f64::consts::PI;
use std::sync::Mutex;
use std::time::Instant;

/// Largest bandwidth a plan accepts.
pub const MAX_BANDWIDTH: usize = 2048;

/// Which transforms a plan can run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum Direction {
    /// Samples to coefficients only.
    Forward,
    /// Coefficients to samples only.
    Inverse,
    /// Both.
    #[default]
    Both,
}

/// Options for [`Plan::new`].
#[derive(Clone, Debug, Default)]
pub struct PlanOptions {
    /// Which transforms the plan runs (default both).
    pub direction: Direction,
    /// Worker threads; 0 means all available cores.
    pub threads: usize,
    /// FFTW planner rigour.
    pub rigor: Rigor,
    /// Cap on the chunk buffer in bytes (`None`: the library default, see [`Plan::workspace_bytes`]).
    pub max_workspace_bytes: Option<usize>,
    /// Force an instruction set for the DWT kernels (`None`: the best this CPU has).
    pub isa: Option<Isa>,
    /// How the FFT stage uses the threads.
    pub fft_threading: FftThreading,
    /// Skip threshold `2^-skip_bits` (`None`: 64, i.e. about 5.4e-20). For each cluster and
    /// beta, the normalised Wigner-d values `sqrt((2l+1)/2) d^l` are negligible below some
    /// degree (they grow from tiny starting values until the turning point); the degrees where
    /// they are below the threshold cost only the recurrence, without accumulation. At
    /// B = 128 that is about a fifth of all (degree, beta) pairs with the default, against 3%
    /// with `2^-300`. A skipped contribution is below `2^-skip_bits` times the data it
    /// multiplies: the forward changes a coefficient by less than `2 * 2^-skip_bits` times the
    /// largest value of the transformed slices (the quadrature weights sum to 2); the inverse
    /// changes a value of a transformed slice by less than `B 2^-skip_bits` times the largest
    /// coefficient (a sample, a 2-D DFT of such values, by at most `(2B-1)^2` times that, a
    /// worst case of aligned errors). The benchmark (`so3fft-bench`) shows round-trip errors
    /// with and without skipping equal to the printed digits at every bandwidth up to 512. Accepted: 24..=560, and `Some(0)`, which
    /// turns skipping off: every degree of every beta runs the full recurrence and accumulation
    /// (values below `2^-560` still enter as exact zeros). That mode exists to measure what
    /// skipping saves; it gives the same results up to rounding, only slower.
    pub skip_bits: Option<u32>,
    /// Also prepare the real-signal transforms [`Plan::forward_real`] and
    /// [`Plan::inverse_real`] (real-to-complex FFTW plans; planning takes longer).
    pub real: bool,
}

/// How the FFT stage is parallelised.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum FftThreading {
    /// Library's choice, made when the plan is created.
    ///
    /// - With [`Rigor::Estimate`] (no measuring), or with one thread: slices across workers.
    ///   With the block copies that follow each slice FFT this was faster than FFTW's
    ///   threads at every bandwidth measured on the development machine.
    /// - With [`Rigor::Measure`], [`Rigor::Patient`] or [`Rigor::Exhaustive`] and more than
    ///   one thread: both variants are planned and timed, and the faster one is kept
    ///   ([`Plan::fft_threading`] tells which). The timed work is the FFT stage, for every
    ///   direction the plan has, of the first groups of a chunk (up to 4 groups of up to 4
    ///   mirrored pairs of slices per worker, within 64 MiB), on a scratch array standing
    ///   in for the samples and on the plan's own chunk buffer, so the block copies run
    ///   with their real strides. The variants alternate for up to five rounds (one when
    ///   slices across workers are more than 25% faster) and each is judged by its fastest
    ///   round (interference from other processes only adds time); FFTW's threads are kept
    ///   only when at least 10% faster over all rounds, as slices across workers balance
    ///   their load dynamically and suffer less from other processes on the machine. On the
    ///   development machine (two cores) this added about 5 ms to plan creation at B = 64,
    ///   15 to 60 ms at B = 128 and 0.1 to 0.25 s at B = 256 with one group per worker and
    ///   at most three rounds (one transform takes about 0.01, 0.09 and 1.1 s there; the
    ///   larger sample left the whole planning time at B = 128 and 256 unchanged within its
    ///   noise, 0.8 and 4.2-4.6 s; up to five rounds when the host is busy made plans at
    ///   B = 64 and 128 take 15-30% longer under load), plus FFTW's
    ///   planning of the second variant: 0.2 to 0.5 s the first time at each bandwidth
    ///   with `Rigor::Measure`. The scratch array is freed before [`Plan::new`] returns.
    ///   When the other variant cannot be planned, or the scratch array would take more
    ///   than a quarter of the available memory, the plan keeps slices across workers.
    ///
    ///   Measuring plans the FFTW-threaded variant, with the effects on FFTW's global state
    ///   described under [`FftThreading::FftwThreads`], even when it is not kept.
    ///
    /// The real-signal transforms ([`PlanOptions::real`]) always spread slices across the
    /// workers.
    #[default]
    Auto,
    /// Each worker transforms whole beta slices with a single-threaded FFTW plan.
    SlicesAcrossWorkers,
    /// Slices one after another, each on FFTW's own threads (`fftw3_threads`); the copies
    /// into and out of the chunk buffer are spread over the workers. Making such a plan
    /// calls `fftw_init_threads` once and sets FFTW's process-wide thread count for new
    /// plans, restoring the previous value before returning. Our own planner calls are
    /// serialised, but a host thread that plans an FFTW transform at that same moment may
    /// pick up this thread count. `Auto` does this only when it measures (see above).
    /// With one thread this is the same as `SlicesAcrossWorkers`.
    FftwThreads,
}

/// Wall time of each stage of one execution, in seconds.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StageTimes {
    /// FFT stage: FFTW and the copies between the slices and the chunk buffer.
    pub fft: f64,
    /// Discrete Wigner transform stage: recurrence coefficients, starting values, kernels,
    /// and the coefficients' gather (inverse) or accumulation (forward).
    pub dwt: f64,
    /// Whole call.
    pub total: f64,
}

/// A precomputed SO(3) FFT of one bandwidth: weights, Wigner starting-value tables,
/// cluster schedule, FFTW plans, worker pool and chunk buffer.
///
/// Execution methods take `&self`; a plan may be executed from several threads at once
/// on different arrays (a concurrent call that finds the chunk buffer busy allocates its own).
pub struct Plan {
    b: usize,
    direction: Direction,
    threads: usize,
    isa: Isa,
    /// Worker pool (an `Option` so `Drop` can release it before waiting for the workers).
    pool: Option<rayon::ThreadPool>,
    /// Number of pool threads still running; `Drop` waits for zero.
    live: std::sync::Arc<(Mutex<usize>, std::sync::Condvar)>,
    /// Base pairs of the clusters, in processing order (8 x 8 tiles, see
    /// `symmetry::cluster_pairs`).
    clusters: Vec<(u32, u32)>,
    bt: BetaTables,
    norms: Vec<Ext>,
    /// `w_B(k) * pi / (2 B^2)`: forward quadrature weight with the normalisation folded in.
    wq: Vec<f64>,
    rt: RecTables,
    fwd_fft: Option<SliceFft>,
    inv_fft: Option<SliceFft>,
    /// Real-data slice FFTs (with `PlanOptions::real`).
    real_fft: Option<SliceFftReal>,
    /// Per-worker buffers of `2 group` padded slices (see [`fft::slice_stride`]): a group
    /// of mirrored pairs of beta slices in the FFT stage.
    fft_scratch: Vec<Mutex<AlignedBuf>>,
    /// Per-worker DWT scratch.
    dwt_scratch: Vec<Mutex<Scratch>>,
    /// Whether the slice FFTs run on FFTW's threads (else slices are spread over workers).
    fftw_threaded: bool,
    /// Mirrored pairs of beta slices per group of the complex FFT stage.
    group: usize,
    /// Chunk-buffer layout of the complex transforms.
    blocks: Blocks,
    /// Chunk-buffer layout of the real-signal transforms (with `PlanOptions::real`).
    blocks_real: Option<Blocks>,
    /// Bytes this plan holds.
    memory: usize,
    /// Skip threshold `2^-skip_bits` for negligible Wigner-d values.
    skip_bits: u32,
    /// Whether degrees below the threshold are skipped (`PlanOptions::skip_bits` not `Some(0)`).
    skip: bool,
    buf: Mutex<Option<AlignedBuf>>,
    /// Bytes of the chunk buffer.
    buf_bytes: usize,
    /// Most bytes of blocks an inverse group writes with ordinary stores (see
    /// [`plain_store_limit`]).
    plain_store_limit: usize,
    /// The process that made the plan: its worker threads exist only there (a child made
    /// by `fork()` has none of them).
    pid: u32,
}

/// A cluster of the processing order for the DWT stage: its index, the cluster, and the
/// one after it (whose memory its kernel prefetches), if any.
#[derive(Clone, Copy)]
struct At {
    c: usize,
    cl: Cluster,
    next: Option<Cluster>,
}

/// Where a chunk stands for the DWT stage of a cluster.
#[derive(Clone, Copy)]
struct Pass {
    /// A chunk of the transform's first group (the forward assigns the coefficients
    /// rather than adds to them then).
    first: bool,
    /// Position in its group; for `k > 0` the previous call was the same cluster on the
    /// group's previous chunk (the inverse reuses its coefficient rows, the forward adds
    /// to its sums).
    k: usize,
    /// The group's last chunk (the forward writes the cluster's sums then).
    last: bool,
    /// The last chunk of the transform's last group: after this call the forward's
    /// coefficients of the cluster are final.
    done: bool,
    /// The buffer of the group's next chunk and its layout, if any: the next call is this
    /// cluster on it, so that is what to prefetch (forward: this cluster's block there;
    /// inverse: nothing, its coefficient rows are kept).
    next_buf: Option<(SyncPtr<f64>, BufLayout)>,
    /// The group's first chunk, its buffer and layout: after the group's last chunk the
    /// next call is the next cluster on that one (the forward prefetches its block there).
    head: (Chunk, SyncPtr<f64>, BufLayout),
    /// How the chunk's buffer holds the blocks: cluster-major, split in two halves (the
    /// forward's chain, [`Plan::chain`]), or half-major (an inverse whose blocks are too
    /// large to stay in the cache until the FFT stage reads them, written with
    /// non-temporal stores, see [`plain_store_limit`]); see `plan/blocks.rs`.
    layout: BufLayout,
}

/// Shared mutable pointer for disjoint parallel writes.
#[derive(Clone, Copy)]
struct SyncPtr<T>(*mut T);
// SAFETY: used only for writes to disjoint index sets from different tasks.
unsafe impl<T> Send for SyncPtr<T> {}
unsafe impl<T> Sync for SyncPtr<T> {}

impl<T> SyncPtr<T> {
    /// The pointer (a method, so closures capture the whole `Sync` wrapper).
    fn get(self) -> *mut T {
        self.0
    }
}

/// The beta slices of one chunk: the `h` low betas `lo .. lo+h` and their mirrors
/// `2B-1-lo .. 2B-1-lo-h`. The DWT kernels see them as lanes, each half padded to `hp` (a
/// multiple of the vector width) so that no vector mixes the lower and upper half: lane
/// `j < h` is beta `lo + j` and lane `hp + j` its mirror `2B-1-lo-j` (the upper half runs
/// down). In the blocks of the chunk buffer the two are adjacent rows `2j` and `2j+1`
/// (`dwt::Lanes::interleaved`), so the FFT stage moves each mirrored pair of slices in
/// and out of one contiguous piece of every block; in the split and half-major layouts
/// (`plan/blocks.rs`) row `2j` is in one half and row `2j+1` in the other.
#[derive(Clone, Copy)]
struct Chunk {
    lo: usize,
    h: usize,
    hp: usize,
}

impl Chunk {
    /// `(first lane, lowest beta)` of the lower and upper half; each holds `h` betas,
    /// ascending in the lower half and descending in the upper one.
    fn halves(&self, b: usize) -> [(usize, usize); 2] {
        [(0, self.lo), (self.hp, 2 * b - self.lo - self.h)]
    }

    /// Number of lanes.
    fn lanes(&self) -> usize {
        2 * self.hp
    }

    /// Betas of the mirrored pair `j < h` (lanes `j` and `hp + j`, block rows `2j` and
    /// `2j + 1`): `lo + j` and `2B-1-lo-j`.
    fn pair_betas(&self, b: usize, j: usize) -> (usize, usize) {
        (self.lo + j, 2 * b - 1 - self.lo - j)
    }
}

/// The output array of an inverse, or the input of a forward allowed to overwrite it, as
/// room for chunk buffers. The inverse's FFT stage
/// writes the output slice of a beta only when that beta's chunk is done, so the slices of
/// the betas of later chunks are free until then: a group of chunks whose buffers (all
/// but the first, which uses the plan's buffer) fit there runs its DWT stage as one pass,
/// reading each cluster's coefficients once for the whole group instead of once per
/// chunk (the real inverse; at B = 512 the 22 chunks of the 5% memory rule became 6
/// groups that way). A forward may
/// likewise put the buffers of a group in the input slices of earlier groups (already
/// read), and adds each cluster's sums over the group's chunks to the coefficients once
/// (the real forward of real samples).
///
/// Where the buffers fit, both go further: a buffer in two halves (half-major for the
/// inverse, two cluster-major halves for the forward, see `plan/blocks.rs`) can live in
/// the low-beta and the mirror slices of one other chunk, and all chunks run as one group
/// (see [`Plan::chain`]).
struct Spare {
    /// Start of the array (`2B` slices of `slice_bytes`, beta slowest).
    base: *mut u8,
    slice_bytes: usize,
}

impl Spare {
    /// The `2B` beta slices of a sample array at `base` (`4B^2` values of `T` each).
    fn over<T>(base: *mut T, b: usize) -> Spare {
        Spare {
            base: base as *mut u8,
            slice_bytes: 4 * b * b * std::mem::size_of::<T>(),
        }
    }

    /// Forward: buffers of `bytes` each (a multiple of 64), 64-byte aligned, as many as
    /// fit (up to `g`) in the input slices of the betas before `lo` and from `2B-lo` on,
    /// which the FFT stage has read already.
    fn consumed(&self, b: usize, lo: usize, g: usize, bytes: usize) -> Vec<*mut f64> {
        let mut out = Vec::new();
        for (from, to) in [(0, lo), (2 * b - lo, 2 * b)] {
            let (from, to) = (from * self.slice_bytes, to * self.slice_bytes);
            let mut at = from + self.base.wrapping_add(from).align_offset(64);
            while out.len() < g && at <= to && to - at >= bytes {
                out.push(self.base.wrapping_add(at) as *mut f64);
                at += bytes;
            }
        }
        out
    }

    /// The two halves of a half-major buffer, `bytes` each, 64-byte aligned: one in the
    /// low-beta slices of chunk `ch`, one in its mirror slices; `None` if they do not fit.
    fn halves(&self, b: usize, ch: &Chunk, bytes: usize) -> Option<(*mut f64, *mut f64)> {
        let region = |first: usize| {
            let (from, to) = (first * self.slice_bytes, (first + ch.h) * self.slice_bytes);
            let at = from + self.base.wrapping_add(from).align_offset(64);
            (at <= to && to - at >= bytes).then(|| self.base.wrapping_add(at) as *mut f64)
        };
        Some((region(ch.lo)?, region(2 * b - ch.lo - ch.h)?))
    }

    /// Inverse: buffers of `bytes` each (a multiple of 64) for `g` chunks in the slices of the
    /// betas `hi..2B-hi`, 64-byte aligned; `None` if they do not fit.
    fn room(&self, b: usize, hi: usize, g: usize, bytes: usize) -> Option<Vec<*mut f64>> {
        let (from, to) = (
            hi * self.slice_bytes,
            (2 * b).checked_sub(hi)? * self.slice_bytes,
        );
        let start = self.base.wrapping_add(from);
        let from = from + start.align_offset(64);
        (to >= from && to - from >= g * bytes).then(|| {
            (0..g)
                .map(|k| self.base.wrapping_add(from + k * bytes) as *mut f64)
                .collect()
        })
    }
}

/// Lock a free entry of `pool`, trying the current worker's own first; `None` if all are
/// in use (possible only when one plan is executed from several threads at once).
fn lock_free<T>(pool: &[Mutex<T>]) -> Option<std::sync::MutexGuard<'_, T>> {
    let n = pool.len();
    let tid = rayon::current_thread_index().unwrap_or(0);
    (0..n).find_map(|i| match pool[(tid + i) % n].try_lock() {
        Ok(g) => Some(g),
        Err(std::sync::TryLockError::Poisoned(e)) => Some(e.into_inner()),
        Err(std::sync::TryLockError::WouldBlock) => None,
    })
}

/// Worker pools of plans dropped in a child made by `fork()` (see `Plan::drop`).
static ORPHAN_POOLS: Mutex<Vec<rayon::ThreadPool>> = Mutex::new(Vec::new());

/// A field of Linux's `/proc/meminfo` in bytes, if known.
fn meminfo(field: &str) -> Option<usize> {
    let s = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = s.lines().find(|l| l.starts_with(field))?;
    let kb: usize = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// Bytes of memory the system can still give us (`MemAvailable`), if known.
pub(crate) fn mem_available() -> Option<usize> {
    meminfo("MemAvailable:")
}

/// Default cap on the plan's memory ([`Plan::memory_bytes`]): `max(512 MiB, 4.7%` of the
/// sample plus coefficient arrays`)` (real samples for a real plan), and at most half the
/// available memory. The chunk buffer gets what the FFT buffers and tables leave of it (at
/// least one slice pair).
fn default_workspace(b: usize, real: bool) -> usize {
    // Real plans: real samples (8 bytes each). A margin of 0.3% is left for the rest of
    // the process.
    let sample_bytes = if real { 8 } else { 16 };
    let grid_bytes = num_samples(b) * sample_bytes + num_coeffs(b) * 16;
    let d = (512usize << 20).max(grid_bytes / 1000 * 47);
    match mem_available() {
        Some(avail) => d.min(avail / 2),
        None => d,
    }
}

/// Most bytes of blocks an inverse group writes with ordinary stores into cluster-major
/// blocks rather than with non-temporal ones into the half-major layout (see
/// `plan/blocks.rs`): a quarter of the last-level cache (from Linux's sysfs; the cache is
/// shared with the other cores), 0 (always non-temporal) where unknown. Blocks that stay
/// in the cache are read back by the FFT stage much faster: at B = 64 (34 MiB of blocks,
/// 480 MiB of L3 on the development machine) the complex inverse took 8% less time and the
/// real one 17% less; at B = 128 (254 MiB) non-temporal stores were faster (DWT stage
/// 0.062 against 0.069 s), and with the blocks capped at 64-128 MiB the two were even.
/// Pair-major blocks (the rows of a pair side by side, what the half-major layout replaced)
/// in the cache were slower still (B = 64 complex inverse DWT stage 0.0084 against
/// 0.0053 s: each row on its own page).
fn plain_store_limit() -> usize {
    let size = |dir: &std::path::Path| -> Option<usize> {
        let level = std::fs::read_to_string(dir.join("level")).ok()?;
        if level.trim() != "3" {
            return None;
        }
        let s = std::fs::read_to_string(dir.join("size")).ok()?;
        let s = s.trim();
        let (num, mult) = match s.chars().last()? {
            'K' => (&s[..s.len() - 1], 1 << 10),
            'M' => (&s[..s.len() - 1], 1 << 20),
            'G' => (&s[..s.len() - 1], 1 << 30),
            _ => (s, 1),
        };
        num.parse::<usize>().ok().map(|v| v * mult)
    };
    let l3 = (0..8)
        .filter_map(|i| {
            size(&std::path::PathBuf::from(format!(
                "/sys/devices/system/cpu/cpu0/cache/index{i}"
            )))
        })
        .max();
    l3.map_or(0, |b| b / 4)
}

/// How a plan's memory splits up (see [`Plan::memory_bytes`]).
struct Layout {
    /// Low betas per chunk of the complex layout.
    chunk: usize,
    /// Low betas per chunk of the real layout (plans with `PlanOptions::real`).
    chunk_real: Option<usize>,
    chunk_bytes: usize,
    fft_scratch_bytes: usize,
    table_bytes: usize,
}

impl Layout {
    /// The layout whose chunk buffer takes at most `budget` bytes (but at least one beta
    /// pair): each chunk layout gets the largest chunk that fits, and the buffer is the
    /// larger of the two.
    fn new(b: usize, threads: usize, budget: usize, real: bool) -> Layout {
        let (cdpl, rdpl) = (
            Blocks::doubles_per_lane(b, false),
            Blocks::doubles_per_lane(b, true),
        );
        let chunk = Blocks::chunk_for(budget / 8, cdpl, b);
        let chunk_real = real.then(|| Blocks::chunk_for(budget / 8, rdpl, b));
        let mut chunk_bytes = 8 * Blocks::lanes_for(chunk) * cdpl;
        if let Some(h) = chunk_real {
            chunk_bytes = chunk_bytes.max(8 * Blocks::lanes_for(h) * rdpl);
        }
        let block_lanes = Blocks::lanes_for(chunk.max(chunk_real.unwrap_or(0)));
        let clusters = crate::symmetry::num_generic(b) + 2 * b;
        // Recurrence tables (2 double-double tables of (B+1)(B+2) entries), starting-value
        // norms (B(B+1)/2 Ext), power tables (2 * 2B * (64 + 2B/64 + 1) Ext), cluster list
        // and slot tables (8 + 8 * 9 bytes per cluster, twice with the real layout),
        // per-worker DWT scratch.
        let table_bytes = 32 * (b + 1) * (b + 2)
            + 8 * b * (b + 1)
            + 64 * b * (66 + b / 32)
            + 2 * 80 * clusters
            + threads * 8 * (6 * b + 3 * block_lanes + 32 * b);
        Layout {
            chunk,
            chunk_real,
            chunk_bytes,
            // A group of pairs of padded slices per worker.
            fft_scratch_bytes: threads * fft_stage::scratch_len(b) * 16,
            table_bytes,
        }
    }

    fn total(&self) -> usize {
        self.chunk_bytes + self.fft_scratch_bytes + self.table_bytes
    }
}

impl Plan {
    /// Make a plan for bandwidth `bandwidth` (1 ..= [`MAX_BANDWIDTH`]).
    ///
    /// With [`FftThreading::Auto`], a measuring rigour and more than one thread, this also
    /// times both ways of threading the FFT stage and keeps the faster one (see
    /// [`FftThreading::Auto`]; [`Plan::fft_threading`] tells which).
    pub fn new(bandwidth: usize, options: &PlanOptions) -> Result<Plan> {
        let mut plan = Plan::build(bandwidth, options)?;
        plan.tune_fft_threading(options);
        Ok(plan)
    }

    /// Bytes of memory a plan made now with these arguments would hold
    /// ([`Plan::memory_bytes`]), without making it: the same checks as [`Plan::new`]
    /// (bandwidth, threads, options) and the same formulas, nothing allocated. The default
    /// workspace depends on the memory available at the time of the call (at most half of
    /// it is used), so a plan made later may differ if that has changed.
    pub fn memory_needed(bandwidth: usize, options: &PlanOptions) -> Result<usize> {
        let (threads, _, _) = Plan::validate(bandwidth, options)?;
        Ok(Plan::layout(bandwidth, threads, options).total())
    }

    /// Checked threads, skip threshold and instruction set of a plan.
    fn validate(bandwidth: usize, options: &PlanOptions) -> Result<(usize, u32, Isa)> {
        let b = bandwidth;
        if b == 0 || b > MAX_BANDWIDTH {
            return Err(Error::InvalidBandwidth {
                bandwidth: b,
                max: MAX_BANDWIDTH,
            });
        }
        let threads = if options.threads == 0 {
            std::thread::available_parallelism()
                .map(|n| n.get())
                .unwrap_or(1)
        } else {
            options.threads
        };
        if threads > 1024 {
            return Err(Error::InvalidArgument(format!(
                "{threads} threads requested (at most 1024)"
            )));
        }
        let skip_bits = match options.skip_bits {
            None => DEFAULT_SKIP_BITS,
            Some(0) => *SKIP_BITS_RANGE.end(),
            Some(bits) => bits,
        };
        if !SKIP_BITS_RANGE.contains(&skip_bits) {
            return Err(Error::InvalidArgument(format!(
                "skip_bits {skip_bits} outside {SKIP_BITS_RANGE:?}"
            )));
        }
        let isa = options.isa.unwrap_or_else(Isa::detect);
        if !isa.is_supported() {
            return Err(Error::InvalidArgument(format!(
                "instruction set {isa:?} not supported by this CPU"
            )));
        }
        Ok((threads, skip_bits, isa))
    }

    /// How a plan's memory splits up (see [`Plan::workspace_bytes`]).
    fn layout(b: usize, threads: usize, options: &PlanOptions) -> Layout {
        match options.max_workspace_bytes {
            Some(cap) => Layout::new(b, threads, cap, options.real),
            None => {
                // The default caps the plan's whole memory, not only the chunk buffer, so
                // that at large B a transform needs at most 5% beyond the caller's arrays.
                let target = default_workspace(b, options.real);
                let rest = {
                    let probe = Layout::new(b, threads, target, options.real);
                    probe.total() - probe.chunk_bytes
                };
                Layout::new(b, threads, target.saturating_sub(rest), options.real)
            }
        }
    }

    /// [`Plan::new`] without the measured choice of [`FftThreading::Auto`] (which then
    /// means slices across workers).
    fn build(bandwidth: usize, options: &PlanOptions) -> Result<Plan> {
        let b = bandwidth;
        let (threads, skip_bits, isa) = Plan::validate(b, options)?;
        let skip = options.skip_bits != Some(0);
        let n = 2 * b;
        let layout = Plan::layout(b, threads, options);
        // Fail cleanly instead of meeting the OOM killer: the plan must fit in the
        // available memory, and plan plus the caller's arrays in the machine.
        let arrays = (num_samples(b) + num_coeffs(b)).saturating_mul(16);
        let too_big = match (mem_available(), meminfo("MemTotal:")) {
            (Some(avail), Some(total)) => {
                layout.total() > avail || layout.total().saturating_add(arrays) > total
            }
            _ => false,
        };
        if too_big {
            return Err(Error::OutOfMemory {
                bytes: layout.total().saturating_add(arrays),
            });
        }
        // The tables below are ordinary (aborting) allocations of O(B^2) bytes; reserving their
        // total once, fallibly, first turns a shortage (e.g. an address-space limit) into an
        // error. The large buffers are mapped fallibly in `AlignedBuf::new`.
        let mut probe: Vec<u8> = Vec::new();
        probe
            .try_reserve_exact(layout.table_bytes)
            .map_err(|_| Error::OutOfMemory {
                bytes: layout.table_bytes,
            })?;
        drop(probe);
        let want_fwd = options.direction != Direction::Inverse;
        let want_inv = options.direction != Direction::Forward;
        let fftw_threaded = threads > 1
            && match options.fft_threading {
                FftThreading::Auto | FftThreading::SlicesAcrossWorkers => false,
                FftThreading::FftwThreads => true,
            };
        let fftw_threads = if fftw_threaded { threads } else { 1 };
        let slice_fft = |want: bool, sign: i32| -> Result<Option<SliceFft>> {
            Ok(if want {
                Some(SliceFft::new(n, sign, options.rigor, fftw_threads)?)
            } else {
                None
            })
        };
        let fwd_fft = slice_fft(want_fwd, SIGN_PLUS)?;
        let inv_fft = slice_fft(want_inv, SIGN_MINUS)?;
        let clusters = cluster_pairs(b);
        let blocks = Blocks::complex(b, &clusters, layout.chunk);
        // The real layout is about half as large per beta: its chunks take twice the betas.
        let blocks_real = layout.chunk_real.map(|h| Blocks::real(b, &clusters, h));
        let dwt_scratch = (0..threads)
            .map(|_| Mutex::new(Scratch::for_layouts(b, &blocks, blocks_real.as_ref())))
            .collect();
        let real_fft = if options.real {
            Some(SliceFftReal::new(n, options.rigor)?)
        } else {
            None
        };
        let group = fft_stage::pairs_per_group(16 * n * n);
        let fft_scratch = (0..threads)
            .map(|_| AlignedBuf::new(fft_stage::scratch_len(b)).map(Mutex::new))
            .collect::<Result<Vec<_>>>()?;
        let norm = PI / (2.0 * (b * b) as f64);
        let wq = weights(b).iter().map(|w| w * norm).collect();
        let buf = AlignedBuf::new(layout.chunk_bytes.div_ceil(16))?;
        // The pool comes last: nothing after it can fail, so a failed plan leaves no threads.
        let live = std::sync::Arc::new((Mutex::new(threads), std::sync::Condvar::new()));
        let on_exit = live.clone();
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .thread_name(|i| format!("so3fft-{i}"))
            .exit_handler(move |_| {
                let (n, cv) = &*on_exit;
                *n.lock().unwrap_or_else(|e| e.into_inner()) -= 1;
                cv.notify_all();
            })
            .build()
            .map_err(|e| Error::Resources(format!("cannot start {threads} worker threads: {e}")))?;
        Ok(Plan {
            b,
            direction: options.direction,
            threads,
            isa,
            pool: Some(pool),
            live,
            clusters,
            bt: BetaTables::grid(b),
            norms: start_norms(b),
            wq,
            rt: RecTables::new(b),
            fwd_fft,
            inv_fft,
            real_fft,
            fft_scratch,
            dwt_scratch,
            fftw_threaded,
            group,
            blocks,
            blocks_real,
            memory: layout.total(),
            skip_bits,
            skip,
            plain_store_limit: plain_store_limit(),
            pid: std::process::id(),
            buf: Mutex::new(Some(buf)),
            buf_bytes: layout.chunk_bytes,
        })
    }

    fn pool(&self) -> &rayon::ThreadPool {
        self.pool.as_ref().expect("pool lives until drop")
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
        self.isa
    }

    /// How the FFT stage of the complex transforms uses the threads: the resolved variant,
    /// never [`FftThreading::Auto`]. With one thread this is always
    /// [`FftThreading::SlicesAcrossWorkers`] (FFTW's threads are not used).
    pub fn fft_threading(&self) -> FftThreading {
        if self.fftw_threaded {
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
    /// [`Plan::new`] fails with [`Error::OutOfMemory`] when this exceeds the available memory.
    pub fn memory_bytes(&self) -> usize {
        self.memory
    }

    /// Bytes of the chunk buffer. For the complex transforms it holds `2 h'` betas of
    /// `8B^2 - 8B + 8` doubles (the `(2B-1)^2` in-band values of a transformed slice in the
    /// DWT kernels' layout: 16 doubles per 8-member cluster, 8 per other one), with `h` low
    /// betas per chunk and `h'` = `h` rounded up to a multiple of 8; the real-signal
    /// transforms ([`PlanOptions::real`]) hold `4B^2 + 4B` doubles per beta (8 per
    /// cluster), and so about twice the betas per chunk. For a cap `c` bytes each layout
    /// takes `h = min(B, max(8, 8 floor(c / (16 * 8 * d))))` with `d` its doubles per beta,
    /// and the buffer is the larger of the two. With `max_workspace_bytes` the cap is that
    /// value. By default the whole plan ([`Plan::memory_bytes`]) is held to
    /// `max(512 MiB, 4.7% of the sample and coefficient arrays)` (real samples for a real
    /// plan; at most half the available memory), and the cap is what the FFT buffers and
    /// tables leave of it. At B = 512 that keeps a complex transform within the caller's
    /// arrays plus 5%.
    pub fn workspace_bytes(&self) -> usize {
        self.buf_bytes
    }

    /// Whether the plan's worker threads exist in this process: `false` in a child made by
    /// `fork()` after the plan was made.
    pub(crate) fn in_own_process(&self) -> bool {
        std::process::id() == self.pid
    }

    fn check(&self, fwd: bool, samples: usize, coeffs: usize) -> Result<()> {
        if !self.in_own_process() {
            return Err(Error::InvalidArgument(
                "plan made in another process (before fork()): its worker threads do not \
                 exist here; make a new plan in this process"
                    .into(),
            ));
        }
        let ok = if fwd {
            self.direction != Direction::Inverse
        } else {
            self.direction != Direction::Forward
        };
        if !ok {
            return Err(Error::WrongDirection);
        }
        if samples != self.num_samples() {
            return Err(Error::LengthMismatch {
                what: "samples",
                expected: self.num_samples(),
                got: samples,
            });
        }
        if coeffs != self.num_coeffs() {
            return Err(Error::LengthMismatch {
                what: "coefficients",
                expected: self.num_coeffs(),
                got: coeffs,
            });
        }
        Ok(())
    }

    /// Forward transform: samples (`(2B)^3`, SPEC layout) to coefficients (`(4B^3-B)/3`).
    pub fn forward(&self, samples: &[Complex64], coeffs: &mut [Complex64]) -> Result<()> {
        self.forward_timed(samples, coeffs).map(|_| ())
    }

    /// Inverse transform: coefficients to samples.
    pub fn inverse(&self, coeffs: &[Complex64], samples: &mut [Complex64]) -> Result<()> {
        self.inverse_timed(coeffs, samples).map(|_| ())
    }

    /// Run `f` with a chunk buffer: the plan's own if free, else a temporary one.
    ///
    /// A concurrent execution gets a private chunk buffer only while the memory it needs is
    /// available (twice over); otherwise a plain thread waits for the plan's buffer, and a
    /// worker of some rayon pool (which must not block: the holder may be further down its
    /// own stack) gets `Error::OutOfMemory`.
    fn with_buf<R>(&self, f: impl FnOnce(&AlignedBuf) -> Result<R>) -> Result<R> {
        let g = match self.buf.try_lock() {
            Ok(g) => g,
            Err(std::sync::TryLockError::Poisoned(e)) => e.into_inner(),
            Err(std::sync::TryLockError::WouldBlock) => {
                let bytes = self.workspace_bytes();
                if mem_available().is_none_or(|a| a / 2 >= bytes) {
                    let tmp = AlignedBuf::new(bytes.div_ceil(16))?;
                    return f(&tmp);
                }
                if rayon::current_thread_index().is_some() {
                    return Err(Error::OutOfMemory { bytes });
                }
                self.buf.lock().unwrap_or_else(|e| e.into_inner())
            }
        };
        f(g.as_ref().expect("plan buffer present"))
    }

    /// The chunks of layout `t` in groups that share one pass of the DWT stage, each with
    /// its buffer: `None` for the plan's chunk buffer, else a part of `spare` (the
    /// inverse's output, or the input of a forward that may overwrite it, see [`Spare`]).
    /// Without `spare` every group is one chunk. With each buffer comes the gap (doubles)
    /// from its low-beta half to its mirror half in the half-major layout; the plan's
    /// buffer has its halves `t.total() / 2` apart, and so do the buffers placed whole.
    /// Also returns whether the groups are a chain ([`Plan::chain`]), whose buffers are
    /// in two pieces.
    #[allow(clippy::type_complexity)]
    fn chunk_groups(
        &self,
        t: &Blocks,
        forward: bool,
        spare: Option<&Spare>,
    ) -> (Vec<Vec<(Chunk, Option<(*mut f64, usize)>)>>, bool) {
        // The inverse's chain only where the blocks would not stay in the cache anyway:
        // its buffers are half-major, written with non-temporal stores.
        let chain = match spare {
            Some(sp) if forward => self.chain(t, sp, |_| 8 * (t.total() / 2)),
            Some(sp) if self.streams_blocks(self.chunks(t).count()) => self
                .chain(t, sp, |ch| 8 * t.half_len(ch.hp))
                .map(|g| g.into_iter().rev().collect()),
            _ => None,
        };
        if let Some(g) = chain {
            return (vec![g], true);
        }
        let whole = t.total() / 2;
        let groups = self
            .chunk_groups_whole(t, forward, spare)
            .into_iter()
            .map(|g| {
                g.into_iter()
                    .map(|(c, p)| (c, p.map(|p| (p, whole))))
                    .collect()
            })
            .collect();
        (groups, false)
    }

    /// All chunks of layout `t` as one group, each chunk's buffer except chunk 0's (the
    /// plan's buffer) in two halves of `half_bytes(chunk)` bytes in the low-beta and the
    /// mirror slices of the chunk before it, with the gap (doubles) between the halves;
    /// `None` with fewer than two chunks or if a half does not fit.
    ///
    /// The forward (input it may overwrite) runs the chunks in this order: chunk `k - 1`'s
    /// FFT stage has read its slices when chunk `k`'s writes there. Its buffers are split
    /// in two cluster-major halves, each with room for a full chunk, so every cluster's
    /// sums reach the coefficients once (B = 512 under the 5% memory rule: 6 groups of
    /// the 22 chunks before). The inverse runs them in reverse (equator first): chunk
    /// `k - 1`'s FFT stage writes its output slices only after chunk `k`'s has read its
    /// buffer. Its buffers are half-major, and it reads each cluster's coefficients and
    /// computes its recurrence coefficients once, not once per group (B = 256 with the
    /// default workspace, one thread: 4 groups before).
    ///
    /// The real layout's row per lane (`4B^2 + 4B` doubles) is longer than a real slice
    /// (`4B^2`), so in real samples a full chunk's buffer never fits in another full
    /// chunk's slices: its inverse chain exists only for two chunks, the second one short
    /// (half-major halves hold only the chunk's own pairs), its forward chain never.
    #[allow(clippy::type_complexity)]
    fn chain(
        &self,
        t: &Blocks,
        spare: &Spare,
        half_bytes: impl Fn(&Chunk) -> usize,
    ) -> Option<Vec<(Chunk, Option<(*mut f64, usize)>)>> {
        let chunks: Vec<Chunk> = self.chunks(t).collect();
        if chunks.len() < 2 {
            return None;
        }
        let mut group = vec![(chunks[0], None)];
        for w in chunks.windows(2) {
            let (a, b) = spare.halves(self.b, &w[0], half_bytes(&w[1]))?;
            group.push((w[1], Some((a, (b as usize - a as usize) / 8))));
        }
        Some(group)
    }

    /// [`Plan::chunk_groups`] without the chain: every buffer in one piece.
    fn chunk_groups_whole(
        &self,
        t: &Blocks,
        forward: bool,
        spare: Option<&Spare>,
    ) -> Vec<Vec<(Chunk, Option<*mut f64>)>> {
        let chunks: Vec<Chunk> = self.chunks(t).collect();
        let bytes = (t.total() * 8).next_multiple_of(64);
        let mut groups = Vec::new();
        let mut i = 0;
        while i < chunks.len() {
            let mut g = 1;
            let mut at = Vec::new();
            if let (true, Some(sp)) = (forward, spare) {
                at = sp.consumed(self.b, chunks[i].lo, chunks.len() - i - 1, bytes);
                g += at.len();
            } else if let Some(sp) = spare {
                // Add chunks while the buffers of all but the first fit in the output
                // slices of the betas after the group's (written only by later groups).
                while i + g < chunks.len() {
                    let hi = chunks[i + g].lo + chunks[i + g].h;
                    match sp.room(self.b, hi, g, bytes) {
                        Some(ptrs) => {
                            at = ptrs;
                            g += 1;
                        }
                        None => break,
                    }
                }
            }
            let mut group = vec![(chunks[i], None)];
            group.extend(
                chunks[i + 1..i + g]
                    .iter()
                    .zip(at)
                    .map(|(c, p)| (*c, Some(p))),
            );
            groups.push(group);
            i += g;
        }
        groups
    }

    /// The chunks of layout `t`.
    fn chunks(&self, t: &Blocks) -> impl Iterator<Item = Chunk> + '_ {
        let (b, chunk) = (self.b, t.chunk);
        (0..b).step_by(chunk).map(move |lo| {
            let h = chunk.min(b - lo);
            let hp = h.next_multiple_of(self.isa.lanes());
            Chunk { lo, h, hp }
        })
    }

    /// Like [`Plan::forward`], also returning the time of each stage.
    pub fn forward_timed(
        &self,
        samples: &[Complex64],
        coeffs: &mut [Complex64],
    ) -> Result<StageTimes> {
        self.check(true, samples.len(), coeffs.len())?;
        self.forward_impl(samples.as_ptr(), coeffs, None)
    }

    /// [`Plan::forward`] that may overwrite `samples` (like FFTW's `FFTW_DESTROY_INPUT`):
    /// their contents afterwards are unspecified. In return a plan whose chunk buffer
    /// holds fewer betas than the grid (see [`Plan::workspace_bytes`]) keeps the buffers
    /// of later chunks in the input slices it has read already and adds each cluster's
    /// sums to the coefficients once per group of chunks instead of once per chunk: at
    /// B = 512 under the 5% memory rule once instead of 22 times (all chunks in one
    /// group). Same memory, same results up to rounding.
    pub fn forward_destroying_input(
        &self,
        samples: &mut [Complex64],
        coeffs: &mut [Complex64],
    ) -> Result<()> {
        self.forward_destroying_input_timed(samples, coeffs)
            .map(|_| ())
    }

    /// Like [`Plan::forward_destroying_input`], also returning the time of each stage.
    pub fn forward_destroying_input_timed(
        &self,
        samples: &mut [Complex64],
        coeffs: &mut [Complex64],
    ) -> Result<StageTimes> {
        self.check(true, samples.len(), coeffs.len())?;
        // One raw pointer for reading the slices and for the buffers in the read ones.
        let base = samples.as_mut_ptr();
        let spare = Spare::over(base, self.b);
        self.forward_impl(base, coeffs, Some(spare))
    }

    fn forward_impl(
        &self,
        samples: *const Complex64,
        coeffs: &mut [Complex64],
        spare: Option<Spare>,
    ) -> Result<StageTimes> {
        let coef = SyncPtr(coeffs.as_mut_ptr());
        let input = SyncPtr(samples as *mut Complex64);
        self.run_chunks(
            true,
            &self.blocks,
            spare,
            |ch, buf, layout| self.fft_chunk(ch, true, input.get(), buf, layout),
            |sc, at, ch, buf, pass| unsafe {
                self.forward_cluster(
                    sc,
                    &self.blocks,
                    all_members,
                    false,
                    at,
                    ch,
                    buf,
                    coef,
                    pass,
                );
            },
        )
    }

    /// Like [`Plan::inverse`], also returning the time of each stage.
    pub fn inverse_timed(
        &self,
        coeffs: &[Complex64],
        samples: &mut [Complex64],
    ) -> Result<StageTimes> {
        self.check(false, samples.len(), coeffs.len())?;
        // One raw pointer for the output slices and for the buffers in the free ones.
        let out = SyncPtr(samples.as_mut_ptr());
        let spare = Spare::over(out.get(), self.b);
        self.run_chunks(
            false,
            &self.blocks,
            Some(spare),
            |ch, buf, layout| self.fft_chunk(ch, false, out.get(), buf, layout),
            |sc, at, ch, buf, pass| unsafe {
                self.inverse_cluster(sc, &self.blocks, all_members, at, ch, buf, coeffs, pass)
            },
        )
    }

    /// The chunk loop shared by every transform: for each group of chunks (see
    /// [`Plan::chunk_groups`]), the FFT stage of each chunk and the DWT of every cluster of
    /// layout `t` over the group's chunks, in the order of the direction (forward: FFT
    /// then DWT), timed. The cluster stage learns where the chunk stands ([`Pass`]).
    #[allow(clippy::type_complexity)]
    fn run_chunks(
        &self,
        forward: bool,
        t: &Blocks,
        spare: Option<Spare>,
        fft: impl Fn(&Chunk, *mut f64, BufLayout) -> Result<()> + Sync,
        cluster: impl Fn(&mut Scratch, &At, &Chunk, *mut f64, Pass) + Sync,
    ) -> Result<StageTimes> {
        let t0 = Instant::now();
        let mut times = StageTimes::default();
        let (groups, chained) = self.chunk_groups(t, forward, spare.as_ref());
        self.with_buf(|buf| {
            let bp = buf.as_mut_ptr() as *mut f64;
            let whole = t.total() / 2;
            let groups: Vec<Vec<(Chunk, SyncPtr<f64>, usize)>> = groups
                .iter()
                .map(|g| {
                    g.iter()
                        .map(|(c, p)| {
                            let (p, gap) = p.unwrap_or((bp, whole));
                            (*c, SyncPtr(p), gap)
                        })
                        .collect()
                })
                .collect();
            self.pool().install(|| {
                for (gi, group) in groups.iter().enumerate() {
                    // The chains' buffers are in two pieces: the forward's split, the
                    // inverse's half-major.
                    let layout: fn(usize) -> BufLayout = if forward && chained {
                        BufLayout::Split
                    } else if !forward && (chained || self.streams_blocks(group.len())) {
                        BufLayout::HalfMajor
                    } else {
                        |_| BufLayout::Blocks
                    };
                    let group: Vec<_> = group.iter().map(|&(c, p, g)| (c, p, layout(g))).collect();
                    let mut fft_stage = || -> Result<()> {
                        let t = Instant::now();
                        for (ch, buf, layout) in &group {
                            fft(ch, buf.get(), *layout)?;
                        }
                        times.fft += t.elapsed().as_secs_f64();
                        Ok(())
                    };
                    if forward {
                        fft_stage()?;
                    }
                    let t1 = Instant::now();
                    self.for_each_cluster(t, |sc, at| {
                        for (k, (ch, buf, layout)) in group.iter().enumerate() {
                            let pass = Pass {
                                first: gi == 0,
                                k,
                                last: k + 1 == group.len(),
                                done: gi + 1 == groups.len() && k + 1 == group.len(),
                                next_buf: group.get(k + 1).map(|g| (g.1, g.2)),
                                head: group[0],
                                layout: *layout,
                            };
                            cluster(sc, at, ch, buf.get(), pass);
                        }
                    });
                    times.dwt += t1.elapsed().as_secs_f64();
                    if !forward {
                        fft_stage()?;
                    }
                }
                Ok::<(), Error>(())
            })
        })?;
        times.total = t0.elapsed().as_secs_f64();
        Ok(times)
    }

    /// Run `f(scratch, at)` on every cluster in parallel (work stealing over runs of
    /// consecutive clusters, whose blocks are consecutive in the chunk buffer). While a
    /// cluster's kernel runs it prefetches what the next one will touch (see
    /// `Plan::next_cluster`), so `at` carries that one too; each cluster is built once.
    fn for_each_cluster(&self, t: &Blocks, f: impl Fn(&mut Scratch, &At) + Sync) {
        let nc = t.len();
        const RUN: usize = 8;
        (0..nc.div_ceil(RUN)).into_par_iter().for_each(|r| {
            let mut guard = lock_free(&self.dwt_scratch);
            let mut own = None;
            let sc: &mut Scratch = match guard.as_deref_mut() {
                Some(s) => s,
                // All busy (concurrent executions of this plan): use a private one.
                None => own.insert(Scratch::for_layouts(
                    self.b,
                    &self.blocks,
                    self.blocks_real.as_ref(),
                )),
            };
            let (c0, c1) = (r * RUN, ((r + 1) * RUN).min(nc));
            let pair = |c: usize| {
                let (m, mp) = self.clusters[c];
                Cluster::new(m as usize, mp as usize)
            };
            let mut cl = pair(c0);
            for c in c0..c1 {
                let next = (c + 1 < nc).then(|| pair(c + 1));
                f(sc, &At { c, cl, next });
                if let Some(n) = next {
                    cl = n;
                }
            }
        });
    }

    /// Whether an inverse group of `chunks` chunks writes its blocks with non-temporal
    /// stores, half-major (see `plan/blocks.rs`): when they are too large to stay in the
    /// cache until the FFT stage reads them ([`plain_store_limit`]).
    fn streams_blocks(&self, chunks: usize) -> bool {
        chunks * self.buf_bytes > self.plain_store_limit
    }

    /// Run `f` with a per-worker FFT scratch buffer (`2 group` padded slices). A worker may
    /// take on another execution's group while it waits inside a parallel copy, so buffers
    /// are taken by try_lock, never by blocking; when all are busy a private one is
    /// allocated.
    fn with_fft_scratch<R>(&self, f: impl FnOnce(&AlignedBuf) -> Result<R>) -> Result<R> {
        match lock_free(&self.fft_scratch) {
            Some(g) => f(&g),
            None => f(&AlignedBuf::new(fft_stage::scratch_len(self.b))?),
        }
    }
}

impl Drop for Plan {
    /// Release the worker pool and wait until its threads have finished, so that nothing
    /// of the plan runs after it is gone (a C host may unload the library right after).
    fn drop(&mut self) {
        // Dropping a plan on one of its own workers would wait for itself. No code outside
        // the library runs on these workers, so this cannot happen through the public API.
        debug_assert!(self
            .pool
            .as_ref()
            .is_none_or(|p| p.current_thread_index().is_none()));
        if !self.in_own_process() {
            // A child after fork(): the workers were the parent's. Dropping the pool would
            // wait for them forever; it is kept (reachable) until the process ends.
            if let Some(pool) = self.pool.take() {
                ORPHAN_POOLS
                    .lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .push(pool);
            }
            return;
        }
        drop(self.pool.take());
        let (n, cv) = &*self.live;
        let mut g = n.lock().unwrap_or_else(|e| e.into_inner());
        while *g > 0 {
            g = cv.wait(g).unwrap_or_else(|e| e.into_inner());
        }
    }
}

#[cfg(test)]
mod tests {
    /// The chunk groups of an inverse with its output as room: in order, covering every
    /// chunk once; every spare buffer 64-byte aligned, inside the output, clear of the
    /// other buffers and of the output slices of its own and all earlier groups (which the
    /// FFT stage writes before the buffer is read); fewer groups than chunks.
    #[test]
    fn chunk_groups_keep_clear_of_written_slices() {
        // B = 36 with a 1-byte cap (the smallest chunk, 8 pairs) is the C test's `capped_workspace`.
        for (b, real, cap) in [
            (64usize, false, 1usize << 20),
            (64, true, 1 << 20),
            (40, false, 1 << 20),
            (37, true, 1 << 20),
            (36, false, 1),
            (36, true, 1),
            // Real, two chunks, the second short enough to fit in the first's slices.
            (20, true, 500_000),
        ] {
            let opts = super::PlanOptions {
                max_workspace_bytes: Some(cap),
                real,
                ..Default::default()
            };
            let mut plan = super::Plan::new(b, &opts).unwrap();
            // Blocks that would stay in the cache: no chain (ordinary stores, cluster-major).
            plan.plain_store_limit = usize::MAX;
            let t = if real {
                plan.blocks_real.as_ref().unwrap()
            } else {
                &plan.blocks
            };
            let slice_bytes = 4 * b * b * if real { 8 } else { 16 };
            let total = 2 * b * slice_bytes;
            let out = vec![0u8; total + 64];
            let spare = super::Spare {
                base: out.as_ptr().wrapping_add(8) as *mut u8,
                slice_bytes,
            };
            let chunks: Vec<_> = plan.chunks(t).map(|c| (c.lo, c.h)).collect();
            // A chain's buffer halves `(a, gap)` of `half` bytes each: 64-byte aligned,
            // in the low-beta and the mirror slices of chunk `host`.
            let in_slices = |host: super::Chunk, (a, gap): (*mut f64, usize), half: usize| {
                let a = a as usize - spare.base as usize;
                let m = a + 8 * gap;
                assert_eq!((spare.base as usize + a) % 64, 0);
                assert_eq!((spare.base as usize + m) % 64, 0);
                assert!(a >= host.lo * slice_bytes);
                let low_end = (host.lo + host.h) * slice_bytes;
                assert!(a + half <= low_end, "B={b}: low half");
                assert!(m >= (2 * b - host.lo - host.h) * slice_bytes);
                let mirror_end = (2 * b - host.lo) * slice_bytes;
                assert!(m + half <= mirror_end, "B={b}: mirror half");
            };
            // The complex forward's chain: one group in the chunks' order, chunk 0 in the
            // plan's buffer, each other buffer's halves in the slices of the chunk before
            // it (read by then). The real layout's do not fit in real slices.
            let (chain, chained) = plan.chunk_groups(t, true, Some(&spare));
            assert_eq!(chained, !real, "B={b} real={real}: forward chain");
            if chained {
                assert_eq!(chain.len(), 1);
                let g = &chain[0];
                let order: Vec<_> = g.iter().map(|(c, _)| (c.lo, c.h)).collect();
                assert_eq!(order, chunks);
                assert!(g[0].1.is_none());
                for k in 1..g.len() {
                    in_slices(g[k - 1].0, g[k].1.unwrap(), 8 * (t.total() / 2));
                }
            }
            // Otherwise: buffers in the slices of earlier groups only.
            let groups = plan.chunk_groups_whole(t, true, Some(&spare));
            let flat: Vec<_> = groups.iter().flatten().map(|(c, _)| (c.lo, c.h)).collect();
            assert_eq!(
                flat,
                plan.chunks(t).map(|c| (c.lo, c.h)).collect::<Vec<_>>()
            );
            assert!(
                groups.len() < flat.len() || flat.len() < 3,
                "B={b} real={real}: no forward group"
            );
            let bytes = t.total() * 8;
            // The spare buffers of a group (all but its first chunk's): offsets into the
            // array, each 64-byte aligned and clear of the group's other buffers.
            let offsets = |g: &[(super::Chunk, Option<*mut f64>)]| -> Vec<usize> {
                let mut ranges: Vec<(usize, usize)> = Vec::new();
                for (_, p) in &g[1..] {
                    let a = (p.unwrap() as usize) - (spare.base as usize);
                    assert_eq!((spare.base as usize + a) % 64, 0);
                    assert!(ranges.iter().all(|&(x, y)| a + bytes <= x || a >= y));
                    ranges.push((a, a + bytes));
                }
                ranges.iter().map(|r| r.0).collect()
            };
            for g in &groups {
                let lo = g[0].0.lo;
                for a in offsets(g) {
                    let low = a + bytes <= lo * slice_bytes;
                    let high = a >= (2 * b - lo) * slice_bytes && a + bytes <= total;
                    assert!(low || high, "B={b}: forward buffer outside the read slices");
                }
            }
            assert!(!plan.chunk_groups(t, false, Some(&spare)).1);
            // Blocks too large for the cache (every limit below theirs): the complex
            // inverse runs as one group, equator first, each buffer's halves in the
            // low-beta and the mirror slices of the next chunk (written after its own FFT
            // stage read the buffer), the last one in the plan's buffer. The real one's
            // full buffers do not fit there: only two chunks, the first one short.
            let mut plan = plan;
            plan.plain_store_limit = 0;
            let t = if real {
                plan.blocks_real.as_ref().unwrap()
            } else {
                &plan.blocks
            };
            let (chain, chained) = plan.chunk_groups(t, false, Some(&spare));
            let short_pair = chunks.len() == 2 && chunks[1].1 * 2 <= chunks[0].1;
            assert_eq!(chained, !real || short_pair, "B={b} real={real}");
            if chained {
                assert_eq!(chain.len(), 1);
                let g = &chain[0];
                let order: Vec<_> = g.iter().map(|(c, _)| (c.lo, c.h)).collect();
                assert_eq!(order, chunks.iter().rev().copied().collect::<Vec<_>>());
                assert!(g.last().unwrap().1.is_none());
                for (i, (ch, p)) in g[..g.len() - 1].iter().enumerate() {
                    in_slices(g[i + 1].0, p.unwrap(), 8 * t.half_len(ch.hp));
                }
                continue;
            }
            let groups = plan.chunk_groups_whole(t, false, Some(&spare));
            let flat: Vec<_> = groups.iter().flatten().map(|(c, _)| (c.lo, c.h)).collect();
            assert_eq!(flat, chunks, "B={b} real={real}");
            assert!(groups.len() < chunks.len(), "B={b} real={real}: no group");
            for g in &groups {
                assert!(g[0].1.is_none());
                let written = g.last().map(|(c, _)| c.lo + c.h).unwrap();
                for a in offsets(g) {
                    assert!(
                        a >= written * slice_bytes,
                        "B={b}: buffer below the free slices"
                    );
                    assert!(a + bytes <= (2 * b - written) * slice_bytes, "B={b}: above");
                }
            }
        }
    }

    /// After a plan is dropped none of its worker threads is still doing work: every one
    /// has run its exit handler (counted in `live`), which the drop waits for.
    #[test]
    fn drop_waits_for_workers() {
        for _ in 0..5 {
            let plan = super::Plan::new(
                4,
                &super::PlanOptions {
                    threads: 3,
                    ..Default::default()
                },
            )
            .unwrap();
            let live = plan.live.clone();
            drop(plan);
            assert_eq!(*live.0.lock().unwrap(), 0);
        }
    }

    /// The inverse's two ways of writing the blocks (non-temporal stores into the
    /// half-major layout for groups larger than `plain_store_limit`, ordinary ones into
    /// cluster-major blocks below) give the same samples, bit for bit,
    /// complex and real, with one chunk and with chunk groups, with either FFT threading;
    /// the forward brings the coefficients back.
    #[test]
    fn block_stores_do_not_change_results() {
        use super::FftThreading::{FftwThreads, SlicesAcrossWorkers};
        use num_complex::Complex64;
        for (b, cap, fft_threading) in [
            (24usize, None, SlicesAcrossWorkers),
            (36, Some(1usize), SlicesAcrossWorkers),
            (36, Some(1usize), FftwThreads),
            // Odd: padding lanes in every chunk.
            (37, Some(1usize), SlicesAcrossWorkers),
            // The real layout's chain (two chunks, the second short).
            (20, Some(500_000), SlicesAcrossWorkers),
            (41, None, SlicesAcrossWorkers),
        ] {
            for real in [false, true] {
                let opts = super::PlanOptions {
                    max_workspace_bytes: cap,
                    real,
                    threads: 2,
                    fft_threading,
                    ..Default::default()
                };
                let mut plan = super::Plan::new(b, &opts).unwrap();
                let mut x = 0.5f64;
                let mut coefs: Vec<Complex64> = (0..plan.num_coeffs())
                    .map(|_| {
                        x = (x * 3.9 * (1.0 - x)).clamp(1e-3, 1.0 - 1e-3);
                        Complex64::new(x - 0.5, 0.25 - x / 2.0)
                    })
                    .collect();
                if real {
                    // Coefficients of a real signal: fhat(l,-m,-m') = (-1)^(m-m') conj(...).
                    for l in 0..b as isize {
                        for m in -l..=l {
                            for mp in -l..=l {
                                let i = crate::grid::coef_index(b, l as usize, m, mp);
                                let j = crate::grid::coef_index(b, l as usize, -m, -mp);
                                if (m, mp) == (0, 0) {
                                    coefs[i].im = 0.0;
                                } else if i < j {
                                    coefs[j] = coefs[i].conj() * super::real::neg_sign(m, mp);
                                }
                            }
                        }
                    }
                }
                let mut runs = Vec::new();
                for limit in [0usize, usize::MAX] {
                    plan.plain_store_limit = limit;
                    if real {
                        let mut f = vec![0.0; plan.num_samples()];
                        plan.inverse_real(&coefs, &mut f).unwrap();
                        let mut c = vec![Complex64::new(f64::NAN, 0.0); coefs.len()];
                        plan.forward_real(&f, &mut c).unwrap();
                        runs.push((f.iter().map(|v| v.to_bits()).collect::<Vec<_>>(), c));
                    } else {
                        let mut f = vec![Complex64::new(0.0, 0.0); plan.num_samples()];
                        plan.inverse(&coefs, &mut f).unwrap();
                        let mut c = vec![Complex64::new(f64::NAN, 0.0); coefs.len()];
                        plan.forward(&f, &mut c).unwrap();
                        let bits = f.iter().flat_map(|v| [v.re.to_bits(), v.im.to_bits()]);
                        runs.push((bits.collect(), c));
                    }
                }
                assert!(runs[0].0 == runs[1].0, "B={b} real={real}: samples differ");
                // Chunks, groups and the complex inverse's chain change nothing either:
                // each lane's sums are its own.
                if cap.is_some() {
                    let whole = super::Plan::new(
                        b,
                        &super::PlanOptions {
                            max_workspace_bytes: None,
                            ..opts
                        },
                    )
                    .unwrap();
                    let bits: Vec<u64> = if real {
                        let mut f = vec![0.0; whole.num_samples()];
                        whole.inverse_real(&coefs, &mut f).unwrap();
                        f.iter().map(|v| v.to_bits()).collect()
                    } else {
                        let mut f = vec![Complex64::new(0.0, 0.0); whole.num_samples()];
                        whole.inverse(&coefs, &mut f).unwrap();
                        f.iter()
                            .flat_map(|v| [v.re.to_bits(), v.im.to_bits()])
                            .collect()
                    };
                    assert!(
                        bits == runs[0].0,
                        "B={b} real={real}: chunked samples differ"
                    );
                }
                for (_, c) in &runs {
                    let e = c
                        .iter()
                        .zip(&coefs)
                        .map(|(a, z)| (a - z).norm())
                        .fold(0.0f64, f64::max);
                    assert!(e < 1e-12, "B={b} real={real}: round trip {e:.2e}");
                }
            }
        }
    }

    /// A real plan's forward on the real parts of complex samples that may overwrite them
    /// (the C API's `SO3FFT_REAL | SO3FFT_DESTROY_INPUT`): its real layout fits in complex
    /// slices, so the chunks chain (split buffers in the slices read already); the
    /// coefficients match the forward that leaves its input alone.
    #[test]
    fn real_parts_forward_chains_and_matches() {
        use num_complex::Complex64;
        for (b, cap) in [(36usize, 1usize), (37, 1), (20, 500_000)] {
            let opts = super::PlanOptions {
                max_workspace_bytes: Some(cap),
                real: true,
                threads: 2,
                ..Default::default()
            };
            let plan = super::Plan::new(b, &opts).unwrap();
            let t = plan.blocks_real.as_ref().unwrap();
            let mut samples: Vec<Complex64> = (0..plan.num_samples())
                .map(|i| {
                    let x = ((i * 7919) % 1009) as f64 / 1009.0 - 0.5;
                    Complex64::new(x, 0.25 - x)
                })
                .collect();
            let spare = super::Spare::over(samples.as_mut_ptr(), b);
            assert!(
                plan.chunk_groups(t, true, Some(&spare)).1,
                "B={b}: no chain"
            );
            let mut want = vec![Complex64::new(f64::NAN, 0.0); plan.num_coeffs()];
            plan.forward_real_parts(&samples, &mut want).unwrap();
            let mut got = vec![Complex64::new(f64::NAN, 0.0); plan.num_coeffs()];
            plan.forward_real_parts_destroying_input(&mut samples, &mut got)
                .unwrap();
            let scale = want.iter().map(|z| z.norm()).fold(0.0f64, f64::max);
            for (g, w) in got.iter().zip(&want) {
                assert!((g - w).norm() <= 1e-13 * scale, "B={b}: {g} against {w}");
            }
        }
    }

    #[test]
    fn plan_is_send_sync() {
        fn is<T: Send + Sync>() {}
        is::<super::Plan>();
    }
}
