//! [`Plan`]: the full SO(3) transform of one bandwidth, SOFT's grid and coefficient layout.
//! It is the engine's full shape ([`Shape::new`]): the same plan a [`PartialPlan`] of that
//! shape is, with the names of the full transform and its calls for the C API and the
//! SOFT layer (real data in complex arrays, watched slices, inputs it may overwrite).

#[cfg(test)]
mod tests;
mod transform;

use crate::error::{Error, Result};
use crate::grid::MAX_BANDWIDTH;
use crate::options::{Direction, FftThreading, Options};
use crate::partial::PartialPlan;
use crate::shape::Shape;
use crate::simd::Isa;
use crate::transform::StageTimes;
use crate::workers::WorkerPool;
use crate::Real;
use num_complex::Complex;

/// A precomputed SO(3) FFT of one bandwidth: Wigner starting-value tables, cluster
/// schedule, FFTW plans, worker pool and chunk buffer.
///
/// Execution methods take `&self`; a plan may be executed from several threads at once
/// on different arrays (a concurrent call that finds the chunk buffer busy allocates its
/// own; the `*_with_scratch` calls of [`Transform`](crate::Transform) never do).
///
/// `T` is the precision of the arrays and of the computation: `f64`, or `f32`
/// (`Plan::<f32>::new`) for about half the time and memory at a relative error near
/// `1e-6` (see `docs/precision.md`).
pub struct Plan<T: Real = f64> {
    /// The engine's full shape of `B`.
    engine: PartialPlan<T>,
}

impl<T: Real> Plan<T> {
    /// Make a plan for bandwidth `bandwidth` (1 ..= [`MAX_BANDWIDTH`]).
    pub fn new(bandwidth: usize, options: &Options) -> Result<Plan<T>> {
        Self::new_on(bandwidth, options, None)
    }

    /// [`Plan::new`] on the workers of `shared` if given (with the plan's thread count).
    pub(crate) fn new_on(
        bandwidth: usize,
        options: &Options,
        shared: Option<&WorkerPool>,
    ) -> Result<Plan<T>> {
        let shape = Self::shape(bandwidth)?;
        Ok(Plan {
            engine: PartialPlan::new_on(&shape, &Self::engine_options(options), shared)?,
        })
    }

    /// The full shape of a valid bandwidth.
    fn shape(bandwidth: usize) -> Result<Shape> {
        if bandwidth == 0 || bandwidth > MAX_BANDWIDTH {
            return Err(Error::InvalidBandwidth {
                bandwidth,
                max: MAX_BANDWIDTH,
            });
        }
        Ok(Shape::new(bandwidth))
    }

    /// `options` for the engine: every beta of the grid.
    fn engine_options(options: &Options) -> Options {
        Options {
            betas: crate::options::Betas::All,
            ..options.clone()
        }
    }

    /// Bytes of memory a plan made now with these arguments would hold
    /// ([`Plan::memory_bytes`]), without making it: the same checks as [`Plan::new`]
    /// (bandwidth, threads, options) and the same formulas, nothing large allocated. The
    /// default workspace depends on the memory available at the time of the call (at most
    /// half of it is used), so a plan made later may differ if that has changed.
    pub fn memory_needed(bandwidth: usize, options: &Options) -> Result<usize> {
        let shape = Self::shape(bandwidth)?;
        PartialPlan::<T>::memory_needed(&shape, &Self::engine_options(options))
    }

    /// Runs `f` on the plan's worker threads (rayon's parallel iterators inside it use
    /// them), for work that goes with a transform, such as the SOFT layer's checks.
    pub(crate) fn install<R: Send>(&self, f: impl FnOnce() -> R + Send) -> R {
        self.engine.install(f)
    }

    /// The bandwidth `B`.
    pub fn bandwidth(&self) -> usize {
        self.engine.shape().degree_limit
    }

    /// Number of worker threads.
    pub fn threads(&self) -> usize {
        self.engine.threads()
    }

    /// Which transforms this plan runs.
    pub fn direction(&self) -> Direction {
        self.engine.direction()
    }

    /// Instruction set of the DWT kernels.
    pub fn isa(&self) -> Isa {
        self.engine.isa()
    }

    /// How the FFT stage uses the threads: always
    /// [`FftThreading::SlicesAcrossWorkers`] (see [`FftThreading`]).
    pub fn fft_threading(&self) -> FftThreading {
        FftThreading::SlicesAcrossWorkers
    }

    /// `(2B)^3`.
    pub fn num_samples(&self) -> usize {
        self.engine.num_samples()
    }

    /// `(4B^3 - B)/3`.
    pub fn num_coeffs(&self) -> usize {
        self.engine.num_coeffs()
    }

    /// Bytes of memory the plan holds, all made with the plan: the chunk buffer
    /// ([`Plan::workspace_bytes`]), per worker a stack and two slice buffers of `2B (2B + 4)`
    /// complex values, which the forward and the inverse share (on a real plan also two
    /// half-spectrum buffers and a slice of reals), and the tables (`O(B^2)`). A transform needs the
    /// caller's arrays on top (`(2B)^3` and `(4B^3-B)/3` complex values) and nothing else
    /// large. [`Plan::memory_needed`] gives the same number before planning. [`Plan::new`]
    /// fails with [`Error::OutOfMemory`] when this exceeds the
    /// available memory.
    pub fn memory_bytes(&self) -> usize {
        self.engine.memory_bytes()
    }

    /// Bytes of the chunk buffer (the scratch of one `*_with_scratch` call). It holds the
    /// lane rows of `2h` betas (`h` low betas and their mirrors, rounded up to the vector
    /// width): per beta one row of `16` doubles per 8-member cluster and `8` per other one,
    /// padded to an odd number of cache lines (`8B^2 - 8B + 8` doubles before the padding;
    /// `4B^2 + 4B` on the real transforms' rows, the larger of the two counts). The `B`
    /// pairs of betas are spread evenly over the fewest chunks the cap holds. With
    /// `max_workspace_bytes` the buffer is at most that value (but at least one vector of
    /// pairs); by default the whole plan
    /// ([`Plan::memory_bytes`]) is held to [`Options::default_workspace`] of the sample and
    /// coefficient arrays (real samples for a real plan; at most half the available memory)
    /// and the buffer is what the rest leaves of it. At B = 512 that keeps a complex
    /// transform within the caller's arrays plus 5%.
    pub fn workspace_bytes(&self) -> usize {
        self.engine.scratch_bytes()
    }

    /// Forward transform: samples (`(2B)^3`, the sample layout of docs/conventions.md) to
    /// coefficients (`(4B^3-B)/3`); the time of each stage. As
    /// [`Transform::forward`](crate::Transform::forward).
    pub fn forward(&self, samples: &[Complex<T>], coeffs: &mut [Complex<T>]) -> Result<StageTimes> {
        self.engine.forward(samples, coeffs)
    }

    /// Inverse transform: coefficients to samples; the time of each stage. As
    /// [`Transform::inverse`](crate::Transform::inverse).
    pub fn inverse(&self, coeffs: &[Complex<T>], samples: &mut [Complex<T>]) -> Result<StageTimes> {
        self.engine.inverse(coeffs, samples)
    }

    /// Forward transform of a real signal: `(2B)^3` real samples to all `(4B^3-B)/3`
    /// coefficients, which satisfy the real symmetry. About half the work of
    /// [`Plan::forward`]. Needs a plan made with [`Options::real`].
    pub fn forward_real(&self, samples: &[T], coeffs: &mut [Complex<T>]) -> Result<StageTimes> {
        self.engine.forward_real(samples, coeffs)
    }

    /// Inverse transform to a real signal: reads only the coefficients `M' > 0`, or
    /// `M' = 0` and `M >= 0`, and takes the others as
    /// `fhat(l,-M,-M') = (-1)^(M-M') conj(fhat(l,M,M'))`. Needs a plan made with
    /// [`Options::real`].
    pub fn inverse_real(&self, coeffs: &[Complex<T>], samples: &mut [T]) -> Result<StageTimes> {
        self.engine.inverse_real(coeffs, samples)
    }

    /// [`Plan::forward`] that may overwrite `samples` (like FFTW's `FFTW_DESTROY_INPUT`):
    /// their contents afterwards are unspecified. The plan does not use the permission at
    /// present (the samples are left as they were); results are those of
    /// [`Plan::forward`].
    pub fn forward_destroying_input(
        &self,
        samples: &mut [Complex<T>],
        coeffs: &mut [Complex<T>],
    ) -> Result<StageTimes> {
        self.engine.forward(samples, coeffs)
    }

    /// [`Plan::forward_real`] that may overwrite `samples`, as
    /// [`Plan::forward_destroying_input`].
    pub fn forward_real_destroying_input(
        &self,
        samples: &mut [T],
        coeffs: &mut [Complex<T>],
    ) -> Result<StageTimes> {
        self.engine.forward_real(samples, coeffs)
    }

    /// The engine's plan of the full shape, for the crate's calls beyond the public ones
    /// (watched inverses, real data in complex arrays).
    pub(crate) fn engine(&self) -> &PartialPlan<T> {
        &self.engine
    }
}
