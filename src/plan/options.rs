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

impl Direction {
    /// `Ok` if a plan made for this direction runs a forward (`forward`) or an inverse
    /// transform, else [`Error::WrongDirection`](crate::Error::WrongDirection).
    pub(crate) fn check_runs(self, forward: bool) -> crate::Result<()> {
        let excluded = if forward {
            Direction::Inverse
        } else {
            Direction::Forward
        };
        if self == excluded {
            return Err(crate::Error::WrongDirection);
        }
        Ok(())
    }
}

/// Options for [`Plan::new`](crate::Plan::new).
#[derive(Clone, Debug, Default)]
pub struct PlanOptions {
    /// Which transforms the plan runs (default both).
    pub direction: Direction,
    /// Worker threads; 0 means all available cores. The plans of a process with the same
    /// count share one pool of workers, which the last of them stops when dropped.
    pub threads: usize,
    /// FFTW planner rigour.
    pub rigor: Rigor,
    /// Cap on the chunk buffer in bytes (`None`: the library default, see [`Plan::workspace_bytes`](crate::Plan::workspace_bytes)).
    pub max_workspace_bytes: Option<usize>,
    /// Instruction set of the kernels (`None`: [`Isa::selected`], the best this CPU has
    /// unless the environment variable `SO3FFT_ISA` names another).
    pub isa: Option<Isa>,
    /// How the FFT stage uses the threads.
    pub fft_threading: FftThreading,
    /// Skip threshold `2^-skip_bits` (`None`: 64, i.e. about 5.4e-20). For each cluster and
    /// beta, the normalised Wigner-d values `sqrt((2l+1)/2) d^l` are negligible below some
    /// degree (they grow from tiny starting values until the turning point); the degrees where
    /// they are below the threshold cost only the recurrence, without accumulation. A skipped
    /// contribution is below `2^-skip_bits` times the data it multiplies: the forward changes
    /// a coefficient by less than `2 * 2^-skip_bits` times the largest value of the
    /// transformed slices (the quadrature weights sum to 2); the inverse changes a value of a
    /// transformed slice by less than `B 2^-skip_bits` times the largest coefficient (a
    /// sample, a 2-D DFT of such values, by at most `(2B-1)^2` times that, a worst case of
    /// aligned errors). Accepted: 24..=560, and `Some(0)`, which turns skipping off: every
    /// degree of every beta runs the full recurrence and accumulation (values below `2^-560`
    /// still enter as exact zeros), with the same results up to rounding, only slower.
    pub skip_bits: Option<u32>,
    /// Also prepare the real-signal transforms [`Plan::forward_real`](crate::Plan::forward_real) and
    /// [`Plan::inverse_real`](crate::Plan::inverse_real) (real-to-complex FFTW plans; planning takes longer).
    pub real: bool,
}

/// How the FFT stage is parallelised.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum FftThreading {
    /// Library's choice, made when the plan is created: [`FftThreading::SlicesAcrossWorkers`]
    /// with [`Rigor::Estimate`] or one thread. With a measuring rigour and more than one
    /// thread, both variants are planned and timed on a sample of the plan's own work (the
    /// FFT stage of the first slice groups of a chunk, for every direction the plan has, on
    /// a scratch array of at most 64 MiB and the plan's chunk buffer) in alternating rounds,
    /// and the faster one is kept; FFTW's threads must be at least 10% faster.
    /// [`Plan::fft_threading`](crate::Plan::fft_threading) tells which was kept. When the FFTW-threaded variant cannot be
    /// planned, or the scratch array would take more than a quarter of the available memory,
    /// slices across workers are kept.
    ///
    /// Timing plans the FFTW-threaded variant, which touches FFTW's process-wide thread
    /// settings as described under [`FftThreading::FftwThreads`], even when it is not kept.
    ///
    /// The real-signal transforms ([`PlanOptions::real`]) always spread slices across the
    /// workers.
    #[default]
    Auto,
    /// Each worker transforms whole beta slices with a single-threaded FFTW plan.
    SlicesAcrossWorkers,
    /// Slices one after another, each on FFTW's own threads (`fftw3_threads`); the copies
    /// into and out of the chunk buffer are spread over the workers. Making such a plan
    /// calls `fftw_init_threads` (once per process) and, while its slice FFTs are planned,
    /// sets FFTW's process-wide thread count for new plans with `fftw_plan_with_nthreads`,
    /// restoring the previous value before returning. Our own planner calls are serialised,
    /// but a host thread that plans an FFTW transform at that same moment may pick up this
    /// thread count. `Auto` does this only when it measures (see above). With one thread
    /// this is the same as `SlicesAcrossWorkers`.
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

impl std::ops::AddAssign for StageTimes {
    /// Stage by stage (the times of several executions, as a batch reports them).
    fn add_assign(&mut self, other: StageTimes) {
        self.fft += other.fft;
        self.dwt += other.dwt;
        self.total += other.total;
    }
}
