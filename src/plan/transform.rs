//! [`Transform`] for [`Plan`]: the engine's, with the caller's scratch as its chunk buffer.

use super::Plan;
use crate::error::Result;
use crate::transform::{Scratch, StageTimes, Transform};
use num_complex::Complex64;

impl Transform for Plan {
    fn num_samples(&self) -> usize {
        Plan::num_samples(self)
    }

    fn num_coeffs(&self) -> usize {
        Plan::num_coeffs(self)
    }

    /// The chunk buffer ([`Plan::workspace_bytes`]).
    fn scratch_bytes(&self) -> usize {
        self.workspace_bytes()
    }

    fn forward(&self, samples: &[Complex64], coeffs: &mut [Complex64]) -> Result<StageTimes> {
        Plan::forward(self, samples, coeffs)
    }

    fn inverse(&self, coeffs: &[Complex64], samples: &mut [Complex64]) -> Result<StageTimes> {
        Plan::inverse(self, coeffs, samples)
    }

    fn forward_real(&self, samples: &[f64], coeffs: &mut [Complex64]) -> Result<StageTimes> {
        Plan::forward_real(self, samples, coeffs)
    }

    fn inverse_real(&self, coeffs: &[Complex64], samples: &mut [f64]) -> Result<StageTimes> {
        Plan::inverse_real(self, coeffs, samples)
    }

    fn forward_with_scratch(
        &self,
        samples: &[Complex64],
        coeffs: &mut [Complex64],
        scratch: &mut Scratch,
    ) -> Result<StageTimes> {
        self.engine().forward_with_scratch(samples, coeffs, scratch)
    }

    fn inverse_with_scratch(
        &self,
        coeffs: &[Complex64],
        samples: &mut [Complex64],
        scratch: &mut Scratch,
    ) -> Result<StageTimes> {
        self.engine().inverse_with_scratch(coeffs, samples, scratch)
    }

    fn forward_real_with_scratch(
        &self,
        samples: &[f64],
        coeffs: &mut [Complex64],
        scratch: &mut Scratch,
    ) -> Result<StageTimes> {
        self.engine()
            .forward_real_with_scratch(samples, coeffs, scratch)
    }

    fn inverse_real_with_scratch(
        &self,
        coeffs: &[Complex64],
        samples: &mut [f64],
        scratch: &mut Scratch,
    ) -> Result<StageTimes> {
        self.engine()
            .inverse_real_with_scratch(coeffs, samples, scratch)
    }
}
