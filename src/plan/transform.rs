//! [`Transform`] for [`Plan`]: the caller's scratch is the chunk buffer.

use super::fft_stage::{RealInput, RealOutput};
use super::schedule::Spare;
use super::shared::{SendConstPtr, SendPtr};
use super::{Plan, StageTimes};
use crate::error::Result;
use crate::transform::{Scratch, Transform};
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
        self.check(true, samples.len(), coeffs.len())?;
        self.forward_impl(samples.as_ptr(), coeffs, (None, Some(scratch)))
    }

    fn inverse_with_scratch(
        &self,
        coeffs: &[Complex64],
        samples: &mut [Complex64],
        scratch: &mut Scratch,
    ) -> Result<StageTimes> {
        self.check(false, samples.len(), coeffs.len())?;
        self.inverse_impl(coeffs, samples, (None, Some(scratch)))
    }

    fn forward_real_with_scratch(
        &self,
        samples: &[f64],
        coeffs: &mut [Complex64],
        scratch: &mut Scratch,
    ) -> Result<StageTimes> {
        self.check(true, samples.len(), coeffs.len())?;
        self.forward_real_impl(
            RealInput::Real(SendConstPtr(samples.as_ptr())),
            coeffs,
            (None, Some(scratch)),
        )
    }

    fn inverse_real_with_scratch(
        &self,
        coeffs: &[Complex64],
        samples: &mut [f64],
        scratch: &mut Scratch,
    ) -> Result<StageTimes> {
        self.check(false, samples.len(), coeffs.len())?;
        let out = samples.as_mut_ptr();
        self.inverse_real_impl(
            coeffs,
            (RealOutput::Real(SendPtr(out)), None),
            (Spare::over(out, self.b), Some(scratch)),
        )
    }
}
