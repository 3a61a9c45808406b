//! The layout of a batch of transforms ([`Batch`]): a public argument of a
//! [`PartialPlan`](super::PartialPlan)'s execution.

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
