//! The options of a [`PartialPlan`](super::PartialPlan) and the layout of a batch of
//! transforms ([`Batch`]): the public arguments of its construction and execution.

use super::betas::Betas;
use crate::error::{Error, Result};
use crate::fft::Rigor;
use crate::plan::Direction;
use crate::simd::Isa;
use crate::wigner::{DEFAULT_SKIP_BITS, SKIP_BITS_RANGE};

/// Options of a [`PartialPlan`](super::PartialPlan).
#[derive(Clone, Debug, Default)]
pub struct PartialOptions {
    /// Which transforms the plan runs (default both).
    pub direction: Direction,
    /// Worker threads (0 = all cores), shared with the process's other plans of the same
    /// count (see [`PlanOptions::threads`](crate::plan::PlanOptions::threads)).
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
    /// [`PlanOptions::skip_bits`](crate::plan::PlanOptions::skip_bits) (`None`: 64;
    /// `Some(0)`: nothing skipped; else 24..=560). Thresholds above the default save nothing
    /// measurable (`docs/partial-plans.md`).
    pub skip_bits: Option<u32>,
    /// Cap on the chunk buffer in bytes (`None`: the larger of 512 MiB and a twentieth of
    /// the plan's sample and coefficient arrays; for a distributed plan, of the rank's
    /// share of them).
    pub max_workspace_bytes: Option<usize>,
    /// Run the full shape on the general engine too (normally the full shape runs on
    /// [`Plan`](crate::plan::Plan), which is faster): for tests and benchmarks.
    #[doc(hidden)]
    pub general_engine: bool,
}

/// The skip threshold's exponent of a `skip_bits` option (0: no skipping); an error
/// outside 0 and [`SKIP_BITS_RANGE`].
pub(super) fn skip_bits(option: Option<u32>) -> Result<u32> {
    match option {
        None => Ok(DEFAULT_SKIP_BITS),
        Some(0) => Ok(0),
        Some(b) if SKIP_BITS_RANGE.contains(&b) => Ok(b),
        Some(b) => Err(Error::InvalidArgument(format!(
            "skip_bits {b} outside {SKIP_BITS_RANGE:?}"
        ))),
    }
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
