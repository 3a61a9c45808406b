//! Making a plan: validation of the options, the memory layout, and construction.

use super::blocks::Blocks;
use super::dwt_stage::DwtStage;
use super::fft_stage::{self, FftStage};
use super::options::MAX_BANDWIDTH;
use super::schedule::Schedule;
use super::Plan;
use crate::error::{Error, Result};
use crate::fft::{planning_bytes, AlignedBuf, ChunkBuffer};
use crate::grid::{num_coeffs, num_samples};
use crate::options::{FftThreading, Options};
use crate::simd::Isa;
use crate::symmetry::cluster_pairs;
use crate::system::{check_headroom, mem_available, mem_total};
use crate::workers::{WorkerPool, WORKER_STACK_BYTES};

/// Default cap on the plan's memory ([`Plan::memory_bytes`]): the library's one rule
/// ([`Options::default_workspace`]) for its sample and coefficient arrays (real samples
/// for a real plan).
pub(super) fn default_workspace(b: usize, real: bool) -> usize {
    let sample_bytes = if real { 8 } else { 16 };
    Options::default_workspace_here(num_samples(b) * sample_bytes + num_coeffs(b) * 16)
}

/// Most bytes of blocks an inverse group writes with ordinary stores into cluster-major
/// blocks rather than with non-temporal ones into the half-major layout (see
/// `plan/blocks.rs`): a quarter of the last-level cache (from Linux's sysfs; the cache is
/// shared with the other cores), 0 (always non-temporal) where unknown. Blocks that stay
/// in the cache are read back by the FFT stage much faster; blocks that do not are better
/// written with non-temporal stores.
pub(super) fn plain_store_limit() -> usize {
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
pub(super) struct Layout {
    /// Low betas per chunk of the complex layout.
    pub(super) chunk: usize,
    /// Low betas per chunk of the real layout (plans with `Options::real`).
    pub(super) chunk_real: Option<usize>,
    pub(super) chunk_bytes: usize,
    pub(super) fft_scratch_bytes: usize,
    pub(super) table_bytes: usize,
}

impl Layout {
    /// The layout whose chunk buffer takes at most `budget` bytes (but at least one beta
    /// pair): each chunk layout gets the largest chunk that fits, and the buffer is the
    /// larger of the two.
    pub(super) fn new(b: usize, threads: usize, budget: usize, real: bool) -> Layout {
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

    pub(super) fn total(&self) -> usize {
        self.chunk_bytes + self.fft_scratch_bytes + self.table_bytes
    }
}

/// A plan's options after the checks: worker threads, skip threshold and instruction set.
pub(super) struct Checked {
    pub(super) threads: usize,
    pub(super) skip_bits: u32,
    pub(super) isa: Isa,
}

impl Plan {
    /// The options checked against the bandwidth and this machine.
    pub(super) fn validate(bandwidth: usize, options: &Options) -> Result<Checked> {
        let b = bandwidth;
        if b == 0 || b > MAX_BANDWIDTH {
            return Err(Error::InvalidBandwidth {
                bandwidth: b,
                max: MAX_BANDWIDTH,
            });
        }
        let threads = crate::workers::thread_count(options.threads)?;
        let (skip_bits, _) = options.skip()?;
        let isa = Isa::resolve(options.isa)?;
        Ok(Checked {
            threads,
            skip_bits,
            isa,
        })
    }

    /// How a plan's memory splits up (see [`Plan::workspace_bytes`]).
    pub(super) fn layout(b: usize, threads: usize, options: &Options) -> Layout {
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

    /// [`Plan::new`] without the measured choice of [`FftThreading::Auto`](crate::FftThreading::Auto) (which then
    /// means slices across workers).
    /// On the workers of `shared` if given (which must have the plan's thread count).
    pub(super) fn build(
        bandwidth: usize,
        options: &Options,
        shared: Option<&WorkerPool>,
    ) -> Result<Plan> {
        let b = bandwidth;
        let Checked {
            threads,
            skip_bits,
            isa,
        } = Plan::validate(b, options)?;
        let skip = options.skip_bits != Some(0);
        let layout = Plan::layout(b, threads, options);
        // Fail cleanly instead of meeting the OOM killer: the plan must fit in the
        // available memory, and plan plus the caller's arrays in the machine.
        let arrays = (num_samples(b) + num_coeffs(b)).saturating_mul(16);
        let too_big = match (mem_available(), mem_total()) {
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
        // Everything the plan maps (its memory, its workers' stacks, FFTW's planning) must
        // fit under the address-space limit: an allocation that fails inside FFTW, or an
        // ordinary Rust allocation, aborts the process.
        // (`FftThreading::Auto` plans FFTW's threads only while tuning, which gives up
        // the variant when the headroom is not there.)
        let fftw_threads = if options.fft_threading == FftThreading::FftwThreads {
            threads
        } else {
            1
        };
        check_headroom(
            layout
                .total()
                .saturating_add(threads.saturating_mul(WORKER_STACK_BYTES))
                .saturating_add(planning_bytes(4 * b * b, fftw_threads)),
        )?;
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
        let fft = FftStage::new(b, threads, options)?;
        let clusters = cluster_pairs(b);
        let blocks = Blocks::complex(b, &clusters, layout.chunk);
        // The real layout is about half as large per beta: its chunks take twice the betas.
        let blocks_real = layout.chunk_real.map(|h| Blocks::real(b, &clusters, h));
        let lanes = blocks
            .lanes
            .max(blocks_real.as_ref().map_or(0, |t| t.lanes));
        // The large, fallible mappings before the tables: a shortage shows as an error there.
        let buf = AlignedBuf::new(layout.chunk_bytes.div_ceil(16))?;
        let dwt = DwtStage::new(b, isa, clusters, (threads, lanes), (skip_bits, skip));
        // The pool comes last: nothing after it can fail, so a failed plan leaves no threads.
        let workers = WorkerPool::shared_or_new(shared, threads)?;
        Ok(Plan {
            b,
            direction: options.direction,
            threads,
            workers,
            fft,
            dwt,
            blocks,
            blocks_real,
            memory: layout.total(),
            schedule: Schedule {
                b,
                vector_lanes: isa.lanes(),
                buf_bytes: layout.chunk_bytes,
                plain_store_limit: plain_store_limit(),
            },
            buf: ChunkBuffer::new(Some(buf)),
        })
    }
}
