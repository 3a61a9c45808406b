//! Real-valued signals: real samples, r2c/c2r slice FFTs, and half the order pairs.
//!
//! For real `f`, `fhat(l,-M,-M') = (-1)^(M-M') conj(fhat(l,M,M'))`: the members of a
//! cluster come in negation pairs `(M,M') <-> (-M,-M')`, and only one of each pair (the
//! representative: `M' > 0`, or `M' = 0` and `M >= 0`) is transformed, which halves the
//! DWT work. The r2c FFT of a slice gives `R[a][b']` for `b' <= B` (sign -1); with `f` real,
//! `S(M,M') = conj(R[M mod 2B][M'])` for `M' >= 0`. The chunk buffer holds these
//! `2B (B+1)` half-spectrum rows per slot. The inverse fills the c2r input
//! `Y[M mod 2B][M'] = conj(G(M,M'))` for `M' >= 0`, which makes `f = c2r(Y)` the samples.

use super::blocks::Blocks;
use super::dwt_stage::DwtLayout;
use super::fft_stage::{RealInput, RealOutput, RealSamples, SliceWatch};
use super::options::StageTimes;
use super::schedule::Spare;
use super::shared::{SendConstPtr, SendPtr};
use super::Plan;
use crate::error::{Error, Result};
use crate::transform::Scratch;
use num_complex::Complex64;

impl Plan {
    /// Forward transform of a real signal: `(2B)^3` real samples (the sample layout of docs/conventions.md) to all
    /// `(4B^3-B)/3` coefficients, which satisfy the real symmetry. About half the work of
    /// [`Plan::forward`]. Needs a plan made with [`Options::real`](crate::Options::real).
    pub fn forward_real(&self, samples: &[f64], coeffs: &mut [Complex64]) -> Result<StageTimes> {
        self.check(true, samples.len(), coeffs.len())?;
        self.forward_real_impl(
            RealInput::Real(SendConstPtr(samples.as_ptr())),
            coeffs,
            (None, None),
        )
    }

    /// Inverse transform to a real signal: coefficients (only one of each pair
    /// `(M,M')`, `(-M,-M')` is read: those with `M' > 0`, or `M' = 0` and `M >= 0`) to
    /// `(2B)^3` real samples. Needs a plan made with [`Options::real`](crate::Options::real).
    pub fn inverse_real(&self, coeffs: &[Complex64], samples: &mut [f64]) -> Result<StageTimes> {
        self.check(false, samples.len(), coeffs.len())?;
        // One raw pointer for the output slices and for the buffers in the free ones.
        let out = samples.as_mut_ptr();
        self.inverse_real_impl(
            coeffs,
            (RealOutput::Real(SendPtr(out)), None),
            (Spare::over(out, self.b), None),
        )
    }

    /// [`Plan::inverse_real`] into a complex sample array: real parts are the samples,
    /// imaginary parts exactly 0 (for callers whose interface is complex, such as the C API
    /// with `SO3FFT_REAL`, SOFT's `flag = 1` and SOFT's `flag = 0` on real-symmetric
    /// coefficients). No extra memory and no extra pass: the FFT stage writes each slice's
    /// reals as `(x, 0)` (the chunk buffers live in the complex output's free slices).
    pub(crate) fn inverse_real_to_complex(
        &self,
        coeffs: &[Complex64],
        samples: &mut [Complex64],
    ) -> Result<()> {
        self.check(false, samples.len(), coeffs.len())?;
        let out = samples.as_mut_ptr();
        // Non-temporal stores only for an output that would not stay in the cache anyway
        // (below, ordinary stores into the cache are faster).
        let stream = 16 * samples.len() > self.schedule.plain_store_limit;
        self.inverse_real_impl(
            coeffs,
            (
                RealOutput::RealParts {
                    samples: SendPtr(out),
                    stream,
                },
                None,
            ),
            (Spare::over(out, self.b), None),
        )
        .map(|_| ())
    }

    /// [`Plan::forward_real`] that may overwrite `samples`, for fewer passes over the
    /// coefficients when the plan works in chunks (see [`Plan::forward_destroying_input`]).
    pub fn forward_real_destroying_input(
        &self,
        samples: &mut [f64],
        coeffs: &mut [Complex64],
    ) -> Result<StageTimes> {
        self.check(true, samples.len(), coeffs.len())?;
        // One raw pointer for reading the slices and for the buffers in the read ones.
        let base = samples.as_mut_ptr();
        let spare = Spare::over(base, self.b);
        self.forward_real_impl(
            RealInput::Real(SendConstPtr(base)),
            coeffs,
            (Some(spare), None),
        )
    }

    /// Forward transform of the real parts of complex samples (the imaginary parts are not
    /// read): the real path for callers whose real data sit in a complex array.
    pub(crate) fn forward_real_parts(
        &self,
        samples: &[Complex64],
        coeffs: &mut [Complex64],
    ) -> Result<StageTimes> {
        self.check(true, samples.len(), coeffs.len())?;
        self.forward_real_impl(
            RealInput::RealParts(SendConstPtr(samples.as_ptr())),
            coeffs,
            (None, None),
        )
    }

    /// [`Plan::forward_real_parts`] that may overwrite `samples`.
    pub(crate) fn forward_real_parts_destroying_input(
        &self,
        samples: &mut [Complex64],
        coeffs: &mut [Complex64],
    ) -> Result<StageTimes> {
        self.check(true, samples.len(), coeffs.len())?;
        let base = samples.as_mut_ptr();
        let spare = Spare::over(base, self.b);
        self.forward_real_impl(
            RealInput::RealParts(SendConstPtr(base)),
            coeffs,
            (Some(spare), None),
        )
    }

    /// The real forward of `input` into `coeffs` (lengths checked by the caller), with
    /// chunk buffers in the read input slices when `spare` is given, in the caller's
    /// `scratch` if given.
    pub(super) fn forward_real_impl(
        &self,
        input: RealInput,
        coeffs: &mut [Complex64],
        (spare, scratch): (Option<Spare>, Option<&Scratch>),
    ) -> Result<StageTimes> {
        self.fft.real_fft()?;
        let coef = SendPtr(coeffs.as_mut_ptr());
        let t = self.real_blocks()?;
        let layout = DwtLayout {
            blocks: t,
            real: true,
        };
        self.run_chunks(
            true,
            t,
            (spare, scratch),
            |ch, buf| self.fft.chunk_real(t, ch, RealSamples::Forward(input), buf),
            // The chunks accumulate the representatives only (half the coefficient traffic
            // per chunk); the last one also writes their partners.
            // SAFETY: `run_chunks` hands each task distinct clusters, whose blocks of the
            // chunk buffer and coefficient rows (representatives and their partners) no
            // other task touches; `coeffs` has `num_coeffs` entries (checked above).
            |sc, step, pass| unsafe { self.dwt.forward_cluster(sc, &layout, step, coef, pass) },
        )
    }

    /// [`Plan::inverse_real`] that shows every output slice to `watch` as it is computed.
    pub(crate) fn inverse_real_watched(
        &self,
        coeffs: &[Complex64],
        samples: &mut [f64],
        watch: SliceWatch,
    ) -> Result<()> {
        self.check(false, samples.len(), coeffs.len())?;
        let out = samples.as_mut_ptr();
        self.inverse_real_impl(
            coeffs,
            (RealOutput::Real(SendPtr(out)), Some(watch)),
            (Spare::over(out, self.b), None),
        )
        .map(|_| ())
    }

    /// The real inverse of `coeffs` (length checked by the caller) into `output`, with
    /// chunk buffers in the output slices not yet written (`spare`, over the same array),
    /// in the caller's `scratch` if given.
    pub(super) fn inverse_real_impl(
        &self,
        coeffs: &[Complex64],
        (output, watch): (RealOutput, Option<SliceWatch>),
        (spare, scratch): (Spare, Option<&Scratch>),
    ) -> Result<StageTimes> {
        self.fft.real_fft()?;
        let t = self.real_blocks()?;
        let layout = DwtLayout {
            blocks: t,
            real: true,
        };
        self.run_chunks(
            false,
            t,
            (Some(spare), scratch),
            |ch, buf| {
                self.fft
                    .chunk_real(t, ch, RealSamples::Inverse(output, watch), buf)
            },
            // SAFETY: `run_chunks` hands each task distinct clusters, whose blocks of the
            // chunk buffer no other task touches.
            |sc, step, pass| unsafe { self.dwt.inverse_cluster(sc, &layout, step, coeffs, pass) },
        )
    }

    fn real_blocks(&self) -> Result<&Blocks> {
        self.blocks_real
            .as_ref()
            .ok_or_else(|| Error::InvalidArgument("the plan was made without Options::real".into()))
    }
}
