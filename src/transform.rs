//! [`Transform`]: the transforms every plan offers, with one meaning for each, and
//! [`Scratch`], workspace the caller owns, and [`StageTimes`], what each call reports.

use crate::error::{Error, Result};
use crate::fft::AlignedBuf;
use crate::Real;
use num_complex::Complex;

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

/// Workspace for a plan's `*_with_scratch` calls, owned by the caller (64-byte aligned,
/// backed by huge pages where it is large). One scratch serves any plan whose
/// [`Transform::scratch_bytes`] it holds, one call at a time.
pub struct Scratch {
    buf: AlignedBuf,
}

impl Scratch {
    /// A scratch of at least `bytes` bytes (zero-filled and touched).
    pub fn new(bytes: usize) -> Result<Scratch> {
        crate::system::check_headroom(bytes)?;
        Ok(Scratch {
            buf: AlignedBuf::new(bytes.div_ceil(16))?,
        })
    }

    /// A scratch for the calls of `plan`.
    pub fn for_plan<T: Real>(plan: &(impl Transform<T> + ?Sized)) -> Result<Scratch> {
        Scratch::new(plan.scratch_bytes())
    }

    /// Its size in bytes.
    pub fn bytes(&self) -> usize {
        16 * self.buf.len()
    }

    /// Its first `len` doubles, if it holds them; else [`Error::LengthMismatch`].
    pub(crate) fn doubles(&mut self, len: usize) -> Result<&mut [f64]> {
        let buf = self.holding(8 * len)?;
        // SAFETY: the buffer holds at least `len` doubles, initialised (zero-filled at
        // creation) and owned by `self`, which `&mut self` borrows exclusively.
        Ok(unsafe { std::slice::from_raw_parts_mut(buf.as_mut_ptr().cast::<f64>(), len) })
    }

    /// The buffer, if it holds `bytes` bytes; else [`Error::LengthMismatch`].
    pub(crate) fn holding(&self, bytes: usize) -> Result<&AlignedBuf> {
        if self.bytes() < bytes {
            return Err(Error::LengthMismatch {
                what: "scratch bytes",
                expected: bytes,
                got: self.bytes(),
            });
        }
        Ok(&self.buf)
    }
}

/// The transforms of every plan ([`Plan`](crate::Plan), [`PartialPlan`](crate::PartialPlan),
/// [`DistributedPlan`](crate::DistributedPlan) on each rank's share, collectively, and
/// [`S2Plan`](crate::s2::S2Plan)): forward (samples to coefficients), inverse, and their
/// real-signal forms, each returning the wall time of its stages. The plain calls use the
/// plan's own workspace (made with the plan or on first use; a call that finds it taken by
/// a concurrent one gets a private workspace while memory allows, see `docs/design.md`,
/// "Memory"); the `*_with_scratch` calls use the caller's [`Scratch`] and allocate nothing.
/// Both give the same results, bit for bit.
///
/// Lengths: [`Transform::num_samples`] samples (complex, or real for the real forms) and
/// [`Transform::num_coeffs`] coefficients, else [`Error::LengthMismatch`]. `T` is the
/// precision the plan computes in (`f64`, or `f32` for the single-precision plans).
pub trait Transform<T: Real = f64> {
    /// Samples of one transform.
    fn num_samples(&self) -> usize;

    /// Coefficients of one transform.
    fn num_coeffs(&self) -> usize;

    /// Bytes of [`Scratch`] the `*_with_scratch` calls need.
    fn scratch_bytes(&self) -> usize;

    /// Forward transform: samples to coefficients.
    fn forward(&self, samples: &[Complex<T>], coeffs: &mut [Complex<T>]) -> Result<StageTimes>;

    /// Inverse transform: coefficients to samples.
    fn inverse(&self, coeffs: &[Complex<T>], samples: &mut [Complex<T>]) -> Result<StageTimes>;

    /// Forward transform of real samples (a plan made with [`Options::real`](crate::Options::real)).
    fn forward_real(&self, samples: &[T], coeffs: &mut [Complex<T>]) -> Result<StageTimes>;

    /// Inverse transform to real samples (a plan made with [`Options::real`](crate::Options::real)).
    fn inverse_real(&self, coeffs: &[Complex<T>], samples: &mut [T]) -> Result<StageTimes>;

    /// [`Transform::forward`] in the caller's scratch.
    fn forward_with_scratch(
        &self,
        samples: &[Complex<T>],
        coeffs: &mut [Complex<T>],
        scratch: &mut Scratch,
    ) -> Result<StageTimes>;

    /// [`Transform::inverse`] in the caller's scratch.
    fn inverse_with_scratch(
        &self,
        coeffs: &[Complex<T>],
        samples: &mut [Complex<T>],
        scratch: &mut Scratch,
    ) -> Result<StageTimes>;

    /// [`Transform::forward_real`] in the caller's scratch.
    fn forward_real_with_scratch(
        &self,
        samples: &[T],
        coeffs: &mut [Complex<T>],
        scratch: &mut Scratch,
    ) -> Result<StageTimes>;

    /// [`Transform::inverse_real`] in the caller's scratch.
    fn inverse_real_with_scratch(
        &self,
        coeffs: &[Complex<T>],
        samples: &mut [T],
        scratch: &mut Scratch,
    ) -> Result<StageTimes>;
}
