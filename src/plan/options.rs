//! The plan's options and what a plan reports about its executions.

use crate::fft::Rigor;
use crate::simd::Isa;

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
