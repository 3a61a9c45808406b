//! The largest bandwidth and what a plan reports about its executions.

/// Largest bandwidth a plan accepts.
pub const MAX_BANDWIDTH: usize = 2048;

/// Wall time of each stage of one execution, in seconds.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StageTimes {
    /// FFT stage: FFTW and the copies between the slices and the chunk buffer.
    pub fft: f64,
    /// Discrete Wigner transform stage: recurrence coefficients, starting values, kernels,
    /// and the coefficients' gather (inverse) or accumulation (forward).
    pub dwt: f64,
    /// Distributed plans: the exchange between the ranks (0 for the other plans).
    pub exchange: f64,
    /// Whole call.
    pub total: f64,
}

impl std::ops::AddAssign for StageTimes {
    /// Stage by stage (the times of several executions, as a batch reports them).
    fn add_assign(&mut self, other: StageTimes) {
        self.fft += other.fft;
        self.dwt += other.dwt;
        self.exchange += other.exchange;
        self.total += other.total;
    }
}
