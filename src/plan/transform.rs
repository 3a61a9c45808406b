//! [`Transform`] for [`Plan`]: the engine's, with the caller's scratch as its chunk buffer.

use super::Plan;
use crate::error::Result;
use crate::transform::{Scratch, StageTimes, Transform};
use crate::Real;
use num_complex::Complex;

impl<T: Real> Transform<T> for Plan<T> {
    fn num_samples(&self) -> usize {
        Plan::<T>::num_samples(self)
    }

    fn num_coeffs(&self) -> usize {
        Plan::<T>::num_coeffs(self)
    }

    /// The chunk buffer ([`Plan::workspace_bytes`]).
    fn scratch_bytes(&self) -> usize {
        self.workspace_bytes()
    }

    fn forward(&self, samples: &[Complex<T>], coeffs: &mut [Complex<T>]) -> Result<StageTimes> {
        Plan::<T>::forward(self, samples, coeffs)
    }

    fn inverse(&self, coeffs: &[Complex<T>], samples: &mut [Complex<T>]) -> Result<StageTimes> {
        Plan::<T>::inverse(self, coeffs, samples)
    }

    fn forward_real(&self, samples: &[T], coeffs: &mut [Complex<T>]) -> Result<StageTimes> {
        Plan::<T>::forward_real(self, samples, coeffs)
    }

    fn inverse_real(&self, coeffs: &[Complex<T>], samples: &mut [T]) -> Result<StageTimes> {
        Plan::<T>::inverse_real(self, coeffs, samples)
    }

    fn forward_with_scratch(
        &self,
        samples: &[Complex<T>],
        coeffs: &mut [Complex<T>],
        scratch: &mut Scratch,
    ) -> Result<StageTimes> {
        self.engine().forward_with_scratch(samples, coeffs, scratch)
    }

    fn inverse_with_scratch(
        &self,
        coeffs: &[Complex<T>],
        samples: &mut [Complex<T>],
        scratch: &mut Scratch,
    ) -> Result<StageTimes> {
        self.engine().inverse_with_scratch(coeffs, samples, scratch)
    }

    fn forward_real_with_scratch(
        &self,
        samples: &[T],
        coeffs: &mut [Complex<T>],
        scratch: &mut Scratch,
    ) -> Result<StageTimes> {
        self.engine()
            .forward_real_with_scratch(samples, coeffs, scratch)
    }

    fn inverse_real_with_scratch(
        &self,
        coeffs: &[Complex<T>],
        samples: &mut [T],
        scratch: &mut Scratch,
    ) -> Result<StageTimes> {
        self.engine()
            .inverse_real_with_scratch(coeffs, samples, scratch)
    }
}
