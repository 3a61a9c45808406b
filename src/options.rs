//! [`Options`]: the one options type of every plan ([`Plan`](crate::Plan),
//! [`PartialPlan`](crate::PartialPlan), [`DistributedPlan`](crate::DistributedPlan),
//! [`S2Plan`](crate::s2::S2Plan)), the kinds of its fields, its checks, and the one default
//! workspace rule.

use crate::error::{Error, Result};
use crate::fft::Rigor;
use crate::real::Elem;
use crate::simd::Isa;
use crate::system::mem_available;
use crate::wigner::{skip_bits_range, DEFAULT_SKIP_BITS};

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
    /// transform, else [`Error::WrongDirection`].
    pub(crate) fn check_runs(self, forward: bool) -> Result<()> {
        let excluded = if forward {
            Direction::Inverse
        } else {
            Direction::Forward
        };
        if self == excluded {
            return Err(Error::WrongDirection);
        }
        Ok(())
    }
}

/// How the FFT stage of a [`Plan`](crate::Plan) is parallelised. Every plan now spreads
/// its beta slices across its workers, each slice on a single-threaded FFTW plan: that was
/// the faster way at every bandwidth measured, and FFTW's process-wide thread settings stay
/// the host's. The other variants are accepted and give the same plan
/// ([`Plan::fft_threading`](crate::Plan::fft_threading) reports
/// [`FftThreading::SlicesAcrossWorkers`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum FftThreading {
    /// Library's choice: slices across workers.
    #[default]
    Auto,
    /// Each worker transforms whole beta slices with a single-threaded FFTW plan.
    SlicesAcrossWorkers,
    /// Formerly: slices one after another, each on FFTW's own threads. Accepted; the plan
    /// spreads slices across its workers.
    FftwThreads,
}

/// The betas an inverse evaluates.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Betas {
    /// Every beta of the grid (`2 B_grid` slices).
    #[default]
    All,
    /// The grid betas of these indices (each `< 2 B_grid`), in this order: output slice
    /// `i` is `beta_{k_i}`.
    Indices(Vec<usize>),
    /// These beta values in `[0, pi]` (not necessarily on the grid), in this order.
    Values(Vec<f64>),
}

/// Options of every plan. Each plan type reads the fields that apply to it (listed with
/// each field) and ignores the others. Made with [`Options::default`] and the `with_*`
/// setters (the type is `#[non_exhaustive]`: fields may be added):
///
/// ```
/// let o = so3fft::Options::default().with_threads(2).with_real(true);
/// assert_eq!(o.threads, 2);
/// ```
#[non_exhaustive]
#[derive(Clone, Debug, Default)]
pub struct Options {
    /// Which transforms the plan runs (default both). SO(3) plans.
    pub direction: Direction,
    /// Worker threads; 0 means all available cores. The plans of a process with the same
    /// count share one pool of workers, which the last of them stops when dropped. Every
    /// plan.
    pub threads: usize,
    /// FFTW planner rigour. Every plan.
    pub rigor: Rigor,
    /// Instruction set of the kernels (`None`: [`Isa::selected`], the best this CPU has
    /// unless the environment variable `SO3FFT_ISA` names another). Every plan.
    pub isa: Option<Isa>,
    /// Also prepare the real-signal transforms (real-to-complex FFTW plans; planning takes
    /// longer). SO(3) plans (an S^2 plan always has them).
    pub real: bool,
    /// Skip threshold `2^-skip_bits` (`None`: 64, i.e. about 5.4e-20). For each cluster and
    /// beta, the normalised Wigner-d values `sqrt((2l+1)/2) d^l` are negligible below some
    /// degree (they grow from tiny starting values until the turning point); the degrees
    /// where they are below the threshold cost only the recurrence, without accumulation.
    /// A skipped contribution is below `2^-skip_bits` times the data it multiplies: the
    /// forward changes a coefficient by less than `2 * 2^-skip_bits` times the largest value
    /// of the transformed slices (the quadrature weights sum to 2); the inverse changes a
    /// value of a transformed slice by less than `B 2^-skip_bits` times the largest
    /// coefficient (a sample, a 2-D DFT of such values, by at most `(2B-1)^2` times that, a
    /// worst case of aligned errors). Accepted: 24..=560, and `Some(0)`, which turns
    /// skipping off: every degree of every beta runs the full recurrence and accumulation
    /// (values below `2^-560` still enter as exact zeros), with the same results up to
    /// rounding, only slower. SO(3) plans.
    pub skip_bits: Option<u32>,
    /// Cap on the chunk buffer in bytes (`None`: the default rule, which caps the plan's
    /// whole memory, see [`Options::default_workspace`]). SO(3) plans; for a distributed
    /// plan, per rank.
    pub max_workspace_bytes: Option<usize>,
    /// How the FFT stage uses the threads (accepted; see [`FftThreading`]).
    pub fft_threading: FftThreading,
    /// The betas the inverse evaluates (default all; a plan with a selection runs the
    /// inverse only). [`PartialPlan`](crate::PartialPlan).
    pub betas: Betas,
}

impl Options {
    /// With [`Options::direction`].
    pub fn with_direction(mut self, direction: Direction) -> Options {
        self.direction = direction;
        self
    }

    /// With [`Options::threads`].
    pub fn with_threads(mut self, threads: usize) -> Options {
        self.threads = threads;
        self
    }

    /// With [`Options::rigor`].
    pub fn with_rigor(mut self, rigor: Rigor) -> Options {
        self.rigor = rigor;
        self
    }

    /// With [`Options::isa`].
    pub fn with_isa(mut self, isa: Option<Isa>) -> Options {
        self.isa = isa;
        self
    }

    /// With [`Options::real`].
    pub fn with_real(mut self, real: bool) -> Options {
        self.real = real;
        self
    }

    /// With [`Options::skip_bits`].
    pub fn with_skip_bits(mut self, skip_bits: Option<u32>) -> Options {
        self.skip_bits = skip_bits;
        self
    }

    /// With [`Options::max_workspace_bytes`].
    pub fn with_max_workspace_bytes(mut self, bytes: Option<usize>) -> Options {
        self.max_workspace_bytes = bytes;
        self
    }

    /// With [`Options::fft_threading`].
    pub fn with_fft_threading(mut self, fft_threading: FftThreading) -> Options {
        self.fft_threading = fft_threading;
        self
    }

    /// With [`Options::betas`].
    pub fn with_betas(mut self, betas: Betas) -> Options {
        self.betas = betas;
        self
    }

    /// The skip threshold's exponent and whether degrees below it are skipped, for f64
    /// plans: [`Options::skip_for`] of `f64`.
    pub(crate) fn skip(&self) -> Result<(u32, bool)> {
        self.skip_for::<f64>()
    }

    /// The skip threshold's exponent and whether degrees below it are skipped, for plans
    /// computing in `E`: the default 64; `Some(0)`, no skipping (the starting values still
    /// need a threshold: the widest); an error outside 0 and `skip_bits_range::<E>()`
    /// (24..=560 for f64, 24..=100 for f32).
    pub(crate) fn skip_for<E: Elem>(&self) -> Result<(u32, bool)> {
        let range = skip_bits_range::<E>();
        match self.skip_bits {
            None => Ok((DEFAULT_SKIP_BITS, true)),
            Some(0) => Ok((*range.end(), false)),
            Some(b) if range.contains(&b) => Ok((b, true)),
            Some(b) => Err(Error::InvalidArgument(format!(
                "skip_bits {b} outside {range:?}"
            ))),
        }
    }

    /// An error for a workspace cap of 0.
    pub(crate) fn check_workspace(&self) -> Result<()> {
        if self.max_workspace_bytes == Some(0) {
            return Err(Error::InvalidArgument("max_workspace_bytes is 0".into()));
        }
        Ok(())
    }

    /// The default workspace cap of a plan whose sample and coefficient arrays (of one
    /// transform; for a distributed plan, of the rank's share) take `array_bytes`: the
    /// larger of 512 MiB and 4.7% of them. [`Plan`](crate::Plan) and
    /// [`PartialPlan`](crate::PartialPlan) take at most half the memory available when
    /// they are made and hold their whole memory to the cap (tables, FFT buffers and the
    /// chunk buffer, which gets what the rest leaves, at least one chunk of one beta pair);
    /// at large bandwidths a transform so needs at most about 5% beyond the caller's
    /// arrays. The ranks of a [`DistributedPlan`](crate::DistributedPlan) hold their
    /// exchange rows to it (without the available memory, which the ranks would not agree
    /// on).
    pub fn default_workspace(array_bytes: usize) -> usize {
        (512usize << 20).max(array_bytes / 1000 * 47)
    }

    /// [`Options::default_workspace`] at most half the memory available now.
    pub(crate) fn default_workspace_here(array_bytes: usize) -> usize {
        let d = Options::default_workspace(array_bytes);
        match mem_available() {
            Some(avail) => d.min(avail / 2),
            None => d,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Options;

    /// The accepted skip exponents per element type: f64 up to 560, f32 up to 100 (the
    /// scaled starting values stay normal); `Some(0)` takes the widest threshold.
    #[test]
    fn skip_bits_per_element() {
        let with = |b| Options::default().with_skip_bits(b);
        assert_eq!(with(None).skip().unwrap(), (64, true));
        assert_eq!(with(None).skip_for::<f32>().unwrap(), (64, true));
        assert_eq!(with(Some(0)).skip().unwrap(), (560, false));
        assert_eq!(with(Some(0)).skip_for::<f32>().unwrap(), (100, false));
        assert_eq!(with(Some(560)).skip().unwrap(), (560, true));
        assert_eq!(with(Some(100)).skip_for::<f32>().unwrap(), (100, true));
        assert_eq!(with(Some(24)).skip_for::<f32>().unwrap(), (24, true));
        assert!(with(Some(101)).skip_for::<f32>().is_err());
        assert!(with(Some(561)).skip().is_err());
        assert!(with(Some(23)).skip().is_err());
        assert!(with(Some(23)).skip_for::<f32>().is_err());
    }
}
