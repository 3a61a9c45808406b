//! Plans: everything that depends only on the bandwidth is computed once here, and
//! executing a plan runs the two stages (FFTW over (alpha, gamma), DWT per cluster)
//! chunk by chunk over mirrored pairs of beta slices.
//!
//! Beta slices are processed in chunks of `h` low slices `k` plus their mirrors
//! `2B-1-k` (the Wigner-d symmetries pair `beta` with `pi - beta`), so the only large
//! buffer is the chunk buffer of `2h` transformed slices, never a copy of the grid.

use crate::dwt::{self, Lanes, Rec};
use crate::error::{Error, Result};
use crate::fft::{self, AlignedBuf, Rigor, SliceFft, SliceFftReal, SIGN_MINUS, SIGN_PLUS};

mod fft_tune;
mod real;
use crate::grid::{block_start, num_coeffs, num_samples, weights};
use crate::simd::Isa;
use crate::symmetry::{cluster_pairs, Cluster, Member};
use crate::wigner::{
    big, start_norms, BetaTables, Ext, RecCoeffs, RecTables, DEFAULT_SKIP_BITS, SKIP_BITS_RANGE,
};
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
    /// Skip threshold `2^-skip_bits` (`None`: 300, i.e. about 5e-91). For each cluster and beta,
    /// Wigner-d values below it are treated as zero, so the leading degrees where they are
    /// negligible cost only the recurrence. A contribution skipped this way is at most
    /// `2^-skip_bits` times the data it multiplies, so with `skip_bits >= 64` the total
    /// change is below `B 2^-64`, under the rounding error of the transform. Accepted: 24..=560,
    /// and `Some(0)`, which turns skipping off: every degree of every beta runs the full
    /// recurrence and accumulation (values below `2^-560` still enter as exact zeros). That
    /// mode exists to measure what skipping saves; it gives the same results, only slower.
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
    ///   With the pair-major copy that follows each slice FFT this was faster than FFTW's
    ///   threads at every bandwidth measured on the development machine.
    /// - With [`Rigor::Measure`], [`Rigor::Patient`] or [`Rigor::Exhaustive`] and more than
    ///   one thread: both variants are planned and timed, and the faster one is kept
    ///   ([`Plan::fft_threading`] tells which). The timed work is the FFT stage, for every
    ///   direction the plan has, of the first slice groups of a chunk (one group of 4 or 8
    ///   slices per worker), on a scratch array standing in for the samples and on the
    ///   plan's own chunk buffer, so the transposition into the chunk runs with its real
    ///   stride. The variants alternate for up to three rounds (one when they differ by
    ///   more than 25%) and each is judged by its fastest round (interference from other
    ///   processes only adds time); FFTW's threads are kept only when at least 10% faster,
    ///   as slices across workers balance their load dynamically and suffer less from other
    ///   processes on the machine. On the development machine (two cores) this added about
    ///   5 ms to plan creation at B = 64, 15 to 60 ms at B = 128 and 0.1 to 0.25 s at
    ///   B = 256 (one transform takes about 0.01, 0.09 and 1.1 s there), plus FFTW's
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
    /// FFTW stage.
    pub fft: f64,
    /// Discrete Wigner transform stage (including gathers and scatters).
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
    /// Base pairs of the clusters, in scheduling order (kappa order first).
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
    /// Per-worker buffers of `group` slices, for transposing between the
    /// slice-major sample arrays and the pair-major chunk buffer.
    fft_scratch: Vec<Mutex<AlignedBuf>>,
    /// Per-worker DWT scratch.
    dwt_scratch: Vec<Mutex<Scratch>>,
    /// Whether the slice FFTs run on FFTW's threads (else slices are spread over workers).
    fftw_threaded: bool,
    /// Low beta slices per chunk.
    chunk: usize,
    /// Slices per FFT group (inverse and real transforms).
    group: usize,
    /// Slices per FFT group of the complex forward transform (see [`fft_group_forward`]).
    fwd_group: usize,
    /// Bytes this plan holds.
    memory: usize,
    /// Skip threshold `2^-skip_bits` for negligible Wigner-d values.
    skip_bits: u32,
    /// Whether degrees below the threshold are skipped (`PlanOptions::skip_bits` not `Some(0)`).
    skip: bool,
    buf: Mutex<Option<AlignedBuf>>,
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

/// Per-task scratch, sized for the largest cluster and chunk.
struct Scratch {
    rec: RecCoeffs,
    tau: Vec<f64>,
    p: Vec<f64>,
    sc: Vec<f64>,
    data: Vec<f64>,
    out: Vec<f64>,
}

impl Scratch {
    fn new(b: usize, nbp: usize) -> Scratch {
        Scratch {
            rec: RecCoeffs::new(b),
            tau: vec![0.0; nbp],
            p: vec![0.0; nbp],
            sc: vec![0.0; nbp],
            data: vec![0.0; nbp.max(b) * 16],
            out: vec![0.0; nbp.max(b) * 16],
        }
    }
}

impl Scratch {
    /// Run the DWT kernel on this scratch after [`Plan::setup`]: forward from `data` (`nl`
    /// lanes of `p` values) into `out` (`n` degrees, zeroed first), inverse from `data`
    /// (`n` degrees) into `out` (`p` rows of `nl` lanes).
    fn kernel(&mut self, plan: &Plan, forward: bool, p: usize, n: usize, ch: &Chunk) {
        let nl = ch.lanes();
        let rec = Rec::new(&self.rec, n);
        let lanes = Lanes {
            tau: &self.tau[..nl],
            p: &self.p[..nl],
            sc: &self.sc[..nl],
            upper_from: ch.hp,
            big: big(plan.skip_bits),
            skip: plan.skip,
        };
        if forward {
            let f = &mut self.out[..n * p];
            f.fill(0.0);
            dwt::forward(plan.isa, p, &rec, &lanes, &self.data[..nl * p], f);
        } else {
            dwt::inverse(
                plan.isa,
                p,
                &rec,
                &lanes,
                &self.data[..n * p],
                &mut self.out[..nl * p],
            );
        }
    }
}

/// The beta slices of one chunk, in slot order: slots `0..h` hold betas `lo..lo+h`,
/// slots `h..2h` the mirrored betas `2B-lo-h .. 2B-lo` (ascending), so slot `s` and
/// slot `2h-1-s` hold `beta` and `pi - beta`.
///
/// The DWT kernels see the slots as lanes, each half padded to `hp` (a multiple of the
/// vector width) so that no vector mixes the lower and upper half: lanes `0..h` are
/// slots `0..h`, lanes `hp..hp+h` are slots `h..2h`.
struct Chunk {
    ks: Vec<usize>,
    h: usize,
    hp: usize,
}

impl Chunk {
    /// `(first lane, first slot)` of the lower and upper half; each holds `h` slots.
    fn halves(&self) -> [(usize, usize); 2] {
        [(0, 0), (self.hp, self.h)]
    }

    /// Number of lanes.
    fn lanes(&self) -> usize {
        2 * self.hp
    }
}

/// Slices transformed and transposed together: 4 complex values fill a cache line; fewer
/// when slices are large (the per-worker buffer holds a whole group).
fn fft_group(b: usize) -> usize {
    let slice_bytes = 64 * b * b;
    ((64usize << 20) / slice_bytes).clamp(1, 4)
}

/// Slices per group of the complex forward transform: 8 (two cache lines per pair-major
/// row) while they take at most 64 MiB, else as [`fft_group`]. Measured at B = 128 on two
/// threads: forward FFT stage 10% faster than with 4; the inverse gains nothing from it.
fn fft_group_forward(b: usize) -> usize {
    let (g, slice_bytes) = (fft_group(b), 64 * b * b);
    if g == 4 && 8 * slice_bytes <= 64 << 20 {
        8
    } else {
        g
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

/// Default cap on the plan's memory ([`Plan::memory_bytes`]): `max(512 MiB, 4.5%` of the
/// sample plus coefficient arrays`)` (real samples for a real plan), and at most a quarter of the available memory. The
/// chunk buffer gets what the FFT buffers and tables leave of it (at least one slice pair).
fn default_workspace(b: usize, real: bool) -> usize {
    // Real plans: real samples (8 bytes each). A margin of 0.5% is left for the rest of
    // the process.
    let sample_bytes = if real { 8 } else { 16 };
    let grid_bytes = num_samples(b) * sample_bytes + num_coeffs(b) * 16;
    let d = (512usize << 20).max(grid_bytes / 1000 * 45);
    match mem_available() {
        Some(avail) => d.min(avail / 4),
        None => d,
    }
}

/// How a plan's memory splits up (see [`Plan::memory_bytes`]).
struct Layout {
    chunk: usize,
    group: usize,
    fwd_group: usize,
    chunk_bytes: usize,
    fft_scratch_bytes: usize,
    table_bytes: usize,
}

impl Layout {
    fn new(b: usize, threads: usize, budget: usize) -> Layout {
        let slice_bytes = 64 * b * b;
        let chunk = (budget / (2 * slice_bytes)).clamp(1, b);
        let group = fft_group(b);
        let fwd_group = fft_group_forward(b);
        // Recurrence tables (2 (B+1)(B+2) doubles), starting-value norms (B(B+1)/2 Ext),
        // power tables (2 * 2B * (64 + 2B/64 + 1) Ext), cluster list, per-worker DWT scratch.
        let table_bytes = 16 * (b + 1) * (b + 2)
            + 8 * b * (b + 1)
            + 64 * b * (66 + b / 32)
            + 8 * b * b
            + threads * 8 * (6 * b + 3 * (2 * chunk + 8) + 32 * (2 * chunk + 8).max(b));
        Layout {
            chunk,
            group,
            fwd_group,
            chunk_bytes: 2 * chunk * slice_bytes,
            // One slice more than a group: room for packing real samples (real path) and
            // for the inverse FFT's output.
            fft_scratch_bytes: threads * (group.max(fwd_group) + 1) * slice_bytes,
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

    /// [`Plan::new`] without the measured choice of [`FftThreading::Auto`] (which then
    /// means slices across workers).
    fn build(bandwidth: usize, options: &PlanOptions) -> Result<Plan> {
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
        let skip = options.skip_bits != Some(0);
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
        let n = 2 * b;
        let layout = match options.max_workspace_bytes {
            Some(cap) => Layout::new(b, threads, cap),
            None => {
                // The default caps the plan's whole memory, not only the chunk buffer, so
                // that at large B a transform needs at most 5% beyond the caller's arrays.
                let target = default_workspace(b, options.real);
                let rest = {
                    let probe = Layout::new(b, threads, target);
                    probe.total() - probe.chunk_bytes
                };
                Layout::new(b, threads, target.saturating_sub(rest))
            }
        };
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
        let chunk = layout.chunk;
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
        let fwd_fft = if want_fwd {
            let p = SliceFft::new(n, SIGN_PLUS, options.rigor, fftw_threads, true)?;
            // Slices across workers copy each slice into their cache-resident scratch and
            // transform it there (see `Plan::fft_group`).
            Some(if fftw_threaded {
                p
            } else {
                p.with_in_place(n, SIGN_PLUS, options.rigor)?
            })
        } else {
            None
        };
        let inv_fft = if want_inv {
            // The inverse transforms the per-worker scratch, which it may overwrite.
            Some(SliceFft::new(
                n,
                SIGN_MINUS,
                options.rigor,
                fftw_threads,
                false,
            )?)
        } else {
            None
        };
        let nbp = 2 * chunk.next_multiple_of(isa.lanes());
        let dwt_scratch = (0..threads)
            .map(|_| Mutex::new(Scratch::new(b, nbp)))
            .collect();
        let real_fft = if options.real {
            Some(SliceFftReal::new(n, options.rigor)?)
        } else {
            None
        };
        let fft_scratch = (0..threads)
            .map(|_| {
                AlignedBuf::new((layout.group.max(layout.fwd_group) + 1) * n * n).map(Mutex::new)
            })
            .collect::<Result<Vec<_>>>()?;
        let norm = PI / (2.0 * (b * b) as f64);
        let wq = weights(b).iter().map(|w| w * norm).collect();
        let buf = AlignedBuf::new(2 * chunk * n * n)?;
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
            .map_err(|e| Error::InvalidArgument(format!("thread pool: {e}")))?;
        Ok(Plan {
            b,
            direction: options.direction,
            threads,
            isa,
            pool: Some(pool),
            live,
            clusters: cluster_pairs(b),
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
            chunk,
            group: layout.group,
            fwd_group: layout.fwd_group,
            memory: layout.total(),
            skip_bits,
            skip,
            buf: Mutex::new(Some(buf)),
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
    /// computed before allocating: `2h (2B)^2 16` for the chunk buffer (below) plus
    /// `threads * (g + 1) * (2B)^2 * 16` for the FFT group buffers (`g = clamp(64 MiB / slice, 1, 4)`,
    /// or 8 when that is 4 and 8 slices take at most 64 MiB, i.e. for `B <= 362`)
    /// plus `O(B^2)` tables. A transform needs the caller's arrays on top
    /// (`(2B)^3` and `(4B^3-B)/3` complex values) and nothing else large.
    /// [`Plan::new`] fails with [`Error::OutOfMemory`] when this exceeds the available memory.
    pub fn memory_bytes(&self) -> usize {
        self.memory
    }

    /// Bytes of the chunk buffer: `2 h (2B)^2 * 16` with `h` low beta slices per chunk,
    /// `h = clamp(cap / (2 (2B)^2 16), 1, B)`. With `max_workspace_bytes` the cap is that
    /// value. By default the whole plan ([`Plan::memory_bytes`]) is held to
    /// `max(512 MiB, 4.5% of the sample and coefficient arrays)` (at most a quarter of the
    /// available memory), and the cap is what the FFT buffers and tables leave of it. At
    /// B = 512 that keeps a complex transform within the caller's arrays plus 5%.
    pub fn workspace_bytes(&self) -> usize {
        2 * self.chunk * 4 * self.b * self.b * 16
    }

    fn check(&self, fwd: bool, samples: usize, coeffs: usize) -> Result<()> {
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
                    let tmp = AlignedBuf::new(bytes / 16)?;
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

    fn chunks(&self) -> impl Iterator<Item = Chunk> + '_ {
        let b = self.b;
        (0..b).step_by(self.chunk).map(move |lo| {
            let h = self.chunk.min(b - lo);
            let mut ks: Vec<usize> = (lo..lo + h).collect();
            ks.extend(2 * b - lo - h..2 * b - lo);
            let hp = h.next_multiple_of(self.isa.lanes());
            Chunk { ks, h, hp }
        })
    }

    /// Like [`Plan::forward`], also returning the time of each stage.
    pub fn forward_timed(
        &self,
        samples: &[Complex64],
        coeffs: &mut [Complex64],
    ) -> Result<StageTimes> {
        self.check(true, samples.len(), coeffs.len())?;
        let coef = SyncPtr(coeffs.as_mut_ptr());
        self.run_chunks(
            true,
            coef,
            |ch, buf| self.fft_chunk(ch, true, samples.as_ptr() as *mut Complex64, buf),
            |sc, cl, ch, buf, first| unsafe {
                self.forward_cluster(sc, cl, ch, buf, coef, first);
            },
        )
    }

    /// The chunk loop shared by every transform: for each chunk, the FFT stage and the DWT
    /// of every cluster, in the order of the direction (forward: FFT then DWT), timed.
    /// `coef` is the coefficient array (for prefetching); `first` tells the cluster stage
    /// whether this is the first chunk (the forward assigns rather than accumulates then).
    fn run_chunks(
        &self,
        forward: bool,
        coef: SyncPtr<Complex64>,
        fft: impl Fn(&Chunk, *mut Complex64) -> Result<()> + Sync,
        cluster: impl Fn(&mut Scratch, &Cluster, &Chunk, *mut Complex64, bool) + Sync,
    ) -> Result<StageTimes> {
        let t0 = Instant::now();
        let mut times = StageTimes::default();
        self.with_buf(|buf| {
            let bp = SyncPtr(buf.as_mut_ptr());
            self.pool().install(|| {
                for (ci, ch) in self.chunks().enumerate() {
                    let mut fft_stage = || -> Result<()> {
                        let t = Instant::now();
                        fft(&ch, bp.get())?;
                        times.fft += t.elapsed().as_secs_f64();
                        Ok(())
                    };
                    if forward {
                        fft_stage()?;
                    }
                    let t = Instant::now();
                    self.for_each_cluster(&ch, bp.get(), coef.get(), |sc, cl| {
                        cluster(sc, cl, &ch, bp.get(), ci == 0)
                    });
                    times.dwt += t.elapsed().as_secs_f64();
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

    /// Run `f` on every cluster in parallel (work stealing over runs of consecutive
    /// clusters). Before a cluster is processed, the chunk-buffer rows and coefficient
    /// rows of the next one are prefetched: they are short streams in arrays far larger
    /// than the caches, so without it each cluster would start by waiting on memory.
    fn for_each_cluster(
        &self,
        ch: &Chunk,
        buf: *mut Complex64,
        coef: *mut Complex64,
        f: impl Fn(&mut Scratch, &Cluster) + Sync,
    ) {
        let (buf, coef) = (SyncPtr(buf), SyncPtr(coef));
        self.clusters.par_chunks(8).for_each(|run| {
            let mut guard = lock_free(&self.dwt_scratch);
            let mut own = None;
            let sc: &mut Scratch = match guard.as_deref_mut() {
                Some(s) => s,
                // All busy (concurrent executions of this plan): use a private one.
                None => own.insert(Scratch::new(self.b, 2 * self.chunk.next_multiple_of(8))),
            };
            let mut next = Cluster::new(run[0].0 as usize, run[0].1 as usize);
            for i in 0..run.len() {
                let cl = next;
                if let Some(&(m, mp)) = run.get(i + 1) {
                    next = Cluster::new(m as usize, mp as usize);
                    self.prefetch(&next, ch.ks.len(), buf.get(), coef.get());
                }
                f(sc, &cl);
            }
        });
    }

    /// Hint the cache about the rows a cluster will touch.
    fn prefetch(&self, cl: &Cluster, nb: usize, buf: *mut Complex64, coef: *mut Complex64) {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
            let n = self.b - cl.l0();
            for mem in cl.members() {
                // 4 complex values per 64-byte line; wrapping_add: hints never fault.
                let row = buf.wrapping_add(self.freq_index(mem.m, mem.mp) * nb);
                for s in (0..nb).step_by(4) {
                    unsafe { _mm_prefetch::<_MM_HINT_T0>(row.wrapping_add(s) as *const i8) };
                }
                let row = coef.wrapping_add(block_start(self.b, mem.m, mem.mp));
                for i in (0..n).step_by(4) {
                    unsafe { _mm_prefetch::<_MM_HINT_T0>(row.wrapping_add(i) as *const i8) };
                }
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = (cl, nb, buf, coef);
    }

    /// Run `f` with a per-worker FFT scratch buffer (`max(group, fwd_group) + 1` slices). A worker may take
    /// on another execution's group while it waits inside a parallel copy, so buffers are
    /// taken by try_lock, never by blocking; when all are busy a private one is allocated.
    fn with_fft_scratch<R>(&self, f: impl FnOnce(&AlignedBuf) -> Result<R>) -> Result<R> {
        match lock_free(&self.fft_scratch) {
            Some(g) => f(&g),
            None => f(&AlignedBuf::new(
                (self.group.max(self.fwd_group) + 1) * 4 * self.b * self.b,
            )?),
        }
    }

    /// FFT stage of one chunk. Forward: slices `ks[s]` of `grid` are transformed and
    /// transposed into the pair-major chunk buffer (`buf[fi * nb + s]`). Inverse: the
    /// reverse, into `grid`. Groups of `self.fwd_group` (forward) or `self.group` (inverse)
    /// slots are spread over the workers.
    fn fft_chunk(
        &self,
        ch: &Chunk,
        forward: bool,
        grid: *mut Complex64,
        buf: *mut Complex64,
    ) -> Result<()> {
        let fft = if forward {
            self.fwd_fft.as_ref()
        } else {
            self.inv_fft.as_ref()
        }
        .ok_or(Error::WrongDirection)?;
        let group = if forward { self.fwd_group } else { self.group };
        let ngroups = ch.ks.len().div_ceil(group);
        self.fft_groups(
            ch,
            fft,
            self.fftw_threaded,
            forward,
            grid,
            buf,
            group,
            ngroups,
        )
    }

    /// The first `ngroups` groups of `group` slots of [`Plan::fft_chunk`] with the slice plan `fft`:
    /// with `fftw_threaded`, groups one after another (`fft` runs on FFTW's threads and
    /// the copies are spread over the workers), else groups spread over the workers.
    #[allow(clippy::too_many_arguments)]
    fn fft_groups(
        &self,
        ch: &Chunk,
        fft: &SliceFft,
        fftw_threaded: bool,
        forward: bool,
        grid: *mut Complex64,
        buf: *mut Complex64,
        group: usize,
        ngroups: usize,
    ) -> Result<()> {
        let nb = ch.ks.len();
        let (grid, buf) = (SyncPtr(grid), SyncPtr(buf));
        let run = |gi: usize, parallel_copy: bool| -> Result<()> {
            let s0 = gi * group;
            let g = group.min(nb - s0);
            self.with_fft_scratch(|scratch| unsafe {
                // SAFETY: the scratch holds `group` slices; group `gi` owns slots s0..s0+g.
                self.fft_group(
                    ch,
                    fft,
                    forward,
                    grid,
                    buf,
                    scratch.as_mut_ptr(),
                    s0,
                    g,
                    parallel_copy,
                )
            })
        };
        if fftw_threaded {
            // FFTW parallelises each slice; the copies are spread over the workers.
            (0..ngroups).try_for_each(|gi| run(gi, true))
        } else {
            (0..ngroups)
                .into_par_iter()
                .try_for_each(|gi| run(gi, false))
        }
    }

    /// Transform slots `s0..s0+g` of a chunk through the scratch buffer `sp` (see
    /// [`Plan::fft_chunk`]); `parallel_copy` spreads the transposition over the workers.
    #[allow(clippy::too_many_arguments)]
    unsafe fn fft_group(
        &self,
        ch: &Chunk,
        fft: &SliceFft,
        forward: bool,
        grid: SyncPtr<Complex64>,
        buf: SyncPtr<Complex64>,
        sp: *mut Complex64,
        s0: usize,
        g: usize,
        parallel_copy: bool,
    ) -> Result<()> {
        let (b, n) = (self.b, 2 * self.b);
        let nn = n * n;
        let nb = ch.ks.len();
        let spp = SyncPtr(sp);
        // Copy frequencies fi0..fi1 between the slice-major scratch and the pair-major buffer.
        // Separate monomorphic loops for each case: a run-time switch inside one loop was
        // measured to halve its speed. With a multiple of 4 slots starting on a cache line
        // (the usual case), each row of the group is whole lines: written with
        // non-temporal stores (no read of the lines first), or read with a software
        // prefetch (see `fft::from_pairs4`).
        let lines = g.is_multiple_of(4)
            && nb.is_multiple_of(4)
            && (buf.get().add(s0) as usize).is_multiple_of(64);
        let to_pairs = |fi0: usize, fi1: usize| {
            let (sp, bp) = (spp.get(), buf.get());
            for fi in fi0..fi1 {
                for j in 0..g {
                    *bp.add(fi * nb + s0 + j) = *sp.add(j * nn + fi);
                }
            }
        };
        let to_pairs4 = |fi0: usize, fi1: usize| {
            fft::to_pairs_stream4(spp.get(), nn, g / 4, buf.get().add(s0), nb, fi0, fi1);
        };
        let from_pairs = |fi0: usize, fi1: usize| {
            let (sp, bp) = (spp.get(), buf.get());
            for fi in fi0..fi1 {
                for j in 0..g {
                    *sp.add(j * nn + fi) = *bp.add(fi * nb + s0 + j);
                }
            }
        };
        let from_pairs4 = |fi0: usize, fi1: usize| {
            fft::from_pairs4(spp.get(), nn, g / 4, buf.get().add(s0), nb, fi0, fi1);
        };
        const STEP: usize = 1 << 14;
        let copy_all = |copy: &(dyn Fn(usize, usize) + Sync)| {
            if parallel_copy {
                (0..nn.div_ceil(STEP))
                    .into_par_iter()
                    .for_each(|c| copy(c * STEP, ((c + 1) * STEP).min(nn)));
            } else {
                copy(0, nn);
            }
        };
        if forward {
            for j in 0..g {
                let src = grid.get().add(ch.ks[s0 + j] * nn);
                if fft.has_in_place() {
                    // Copied first (a sequential read the prefetchers follow), then
                    // transformed in the cache: faster than FFTW reading the samples.
                    std::ptr::copy_nonoverlapping(src, sp.add(j * nn), nn);
                    fft.in_place(sp.add(j * nn), sp.add(g * nn), n);
                } else {
                    fft.execute(src, sp.add(j * nn));
                }
            }
            copy_all(if lines { &to_pairs4 } else { &to_pairs });
        } else {
            copy_all(if g.is_multiple_of(4) {
                &from_pairs4
            } else {
                &from_pairs
            });
            // The spare slice after the group (the scratch holds `group + 1`).
            let spare = sp.add(g * nn);
            for j in 0..g {
                let slot = sp.add(j * nn);
                // Frequency B (alpha or gamma) is outside the band limit.
                for i in 0..n {
                    *slot.add(b * n + i) = Complex64::new(0.0, 0.0);
                    *slot.add(i * n + b) = Complex64::new(0.0, 0.0);
                }
                let dst = grid.get().add(ch.ks[s0 + j] * nn);
                if (dst as usize).is_multiple_of(16) {
                    // Into the cache-resident spare slice, then streamed to the samples:
                    // FFTW's own stores would first read every line of `dst` from memory.
                    fft.execute(slot, spare);
                    fft::stream_copy(spare, dst, nn);
                } else {
                    fft.execute(slot, dst);
                }
            }
        }
        Ok(())
    }

    /// Like [`Plan::inverse`], also returning the time of each stage.
    pub fn inverse_timed(
        &self,
        coeffs: &[Complex64],
        samples: &mut [Complex64],
    ) -> Result<StageTimes> {
        self.check(false, samples.len(), coeffs.len())?;
        let out = SyncPtr(samples.as_mut_ptr());
        self.run_chunks(
            false,
            SyncPtr(coeffs.as_ptr() as *mut Complex64),
            |ch, buf| self.fft_chunk(ch, false, out.get(), buf),
            |sc, cl, ch, buf, _| unsafe { self.inverse_cluster(sc, cl, ch, buf, coeffs) },
        )
    }

    /// Recurrence coefficients and per-beta lane inputs of a cluster for one chunk.
    /// (The forward transform applies the quadrature weights to the gathered data.)
    fn setup(&self, sc: &mut Scratch, cl: &Cluster, ch: &Chunk) -> (usize, usize) {
        let n = self.b - cl.l0();
        sc.rec.resize(n);
        self.rt.coeffs(cl.m, cl.mp, &mut sc.rec);
        let norm = self.norms[cl.m * (cl.m + 1) / 2 + cl.mp];
        let nl = ch.lanes();
        sc.tau[..nl].fill(0.0);
        sc.p[..nl].fill(0.0);
        sc.sc[..nl].fill(0.0);
        for (half, (u0, s0)) in ch.halves().into_iter().enumerate() {
            let tau = if half == 0 {
                &self.bt.tau_lo
            } else {
                &self.bt.tau_hi
            };
            for j in 0..ch.h {
                let k = ch.ks[s0 + j];
                sc.tau[u0 + j] = tau[k];
                let (p, scale) = self.bt.start(k, cl.m, cl.mp, norm, 1.0, self.skip_bits);
                sc.p[u0 + j] = p;
                sc.sc[u0 + j] = scale;
            }
        }
        (n, nl)
    }

    /// Inverse DWT input: `fin[i][2q..2q+2]` = coefficient of `members[q]` at degree
    /// `l0 + i`, times the member's sign and `1/(2 pi)`; unused columns zero.
    fn gather_coeffs(&self, fin: &mut [f64], cl: &Cluster, members: &[Member], coef: &[Complex64]) {
        let p = fin.len() / (self.b - cl.l0());
        if members.len() * 2 < p {
            fin.fill(0.0);
        }
        let n = self.b - cl.l0();
        let scale = 1.0 / (2.0 * PI);
        for (q, mem) in members.iter().enumerate() {
            let src = &coef[block_start(self.b, mem.m, mem.mp)..][..n];
            let sg = [mem.sign_at(cl.m) * scale, mem.sign_at(cl.m + 1) * scale];
            for (i, (row, z)) in fin.chunks_exact_mut(p).zip(src).enumerate() {
                let g = sg[i & 1];
                row[2 * q] = z.re * g;
                row[2 * q + 1] = z.im * g;
            }
        }
    }

    /// Index of order pair `(m, mp)` inside a transformed slice.
    fn freq_index(&self, m: isize, mp: isize) -> usize {
        let n = 2 * self.b as isize;
        (m.rem_euclid(n) * n + mp.rem_euclid(n)) as usize
    }

    /// Forward DWT of one cluster over one chunk, accumulated into `coef`.
    ///
    /// # Safety
    /// `buf` holds the chunk's transformed slices; `coef` has `num_coeffs` entries and
    /// no other task writes this cluster's blocks.
    unsafe fn forward_cluster(
        &self,
        sc: &mut Scratch,
        cl: &Cluster,
        ch: &Chunk,
        buf: *const Complex64,
        coef: SyncPtr<Complex64>,
        first: bool,
    ) {
        let (n, nl) = self.setup(sc, cl, ch);
        let p = if cl.members().len() > 4 { 16 } else { 8 };
        let nb = ch.ks.len();
        let data = &mut sc.data[..nl * p];
        if cl.members().len() * 2 < p || ch.h < ch.hp {
            data.fill(0.0);
        }
        // All members' rows are read together (betas outer): several memory streams in
        // flight instead of one short stream at a time.
        let mut src = [(std::ptr::null::<Complex64>(), false); 8];
        for (q, mem) in cl.members().iter().enumerate() {
            src[q] = (buf.add(self.freq_index(mem.m, mem.mp) * nb), mem.reversed);
        }
        let src = &src[..cl.members().len()];
        for (u0, s0) in ch.halves() {
            let rows = data[u0 * p..].chunks_exact_mut(p).take(ch.h);
            for (j, d) in rows.enumerate() {
                let s = s0 + j;
                // Quadrature weight (w_k = w_{2B-1-k}); applied to the data, not folded into
                // the starting values, so the skip threshold bounds the Wigner-d values.
                let w = self.wq[ch.ks[s]];
                for (q, &(row, reversed)) in src.iter().enumerate() {
                    let z = *row.add(if reversed { nb - 1 - s } else { s });
                    d[2 * q] = z.re * w;
                    d[2 * q + 1] = z.im * w;
                }
            }
        }
        sc.kernel(self, true, p, n, ch);
        let f = &sc.out[..n * p];
        for (q, mem) in cl.members().iter().enumerate() {
            let dst = std::slice::from_raw_parts_mut(
                coef.get().add(block_start(self.b, mem.m, mem.mp)),
                n,
            );
            let sg = [mem.sign_at(cl.m), mem.sign_at(cl.m + 1)];
            let rows = f.chunks_exact(p).map(|r| (r[2 * q], r[2 * q + 1]));
            if first {
                for (i, (d, (re, im))) in dst.iter_mut().zip(rows).enumerate() {
                    let g = sg[i & 1];
                    *d = Complex64::new(re * g, im * g);
                }
            } else {
                for (i, (d, (re, im))) in dst.iter_mut().zip(rows).enumerate() {
                    let g = sg[i & 1];
                    *d += Complex64::new(re * g, im * g);
                }
            }
        }
    }

    /// Inverse DWT of one cluster over one chunk, written into the chunk buffer.
    ///
    /// # Safety
    /// `buf` is the chunk buffer; no other task writes this cluster's order pairs.
    unsafe fn inverse_cluster(
        &self,
        sc: &mut Scratch,
        cl: &Cluster,
        ch: &Chunk,
        buf: *mut Complex64,
        coef: &[Complex64],
    ) {
        let (n, nl) = self.setup(sc, cl, ch);
        let p = if cl.members().len() > 4 { 16 } else { 8 };
        let nb = ch.ks.len();
        self.gather_coeffs(&mut sc.data[..n * p], cl, cl.members(), coef);
        sc.kernel(self, false, p, n, ch);
        let y = &sc.out[..nl * p];
        for (q, mem) in cl.members().iter().enumerate() {
            let dst = buf.add(self.freq_index(mem.m, mem.mp) * nb);
            let (yr, yi) = (&y[2 * q * nl..][..nl], &y[(2 * q + 1) * nl..][..nl]);
            for (u0, s0) in ch.halves() {
                for j in 0..ch.h {
                    let s = s0 + j;
                    let z = Complex64::new(yr[u0 + j], yi[u0 + j]);
                    *dst.add(if mem.reversed { nb - 1 - s } else { s }) = z;
                }
            }
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

    #[test]
    fn plan_is_send_sync() {
        fn is<T: Send + Sync>() {}
        is::<super::Plan>();
    }
}
