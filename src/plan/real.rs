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
use super::fft_stage::RealInput;
use super::options::StageTimes;
use super::schedule::Spare;
use super::shared::{SendConstPtr, SendPtr};
use super::Plan;
use crate::error::{Error, Result};
use num_complex::Complex64;
use rayon::prelude::*;

impl Plan {
    /// Forward transform of a real signal: `(2B)^3` real samples (the sample layout of docs/conventions.md) to all
    /// `(4B^3-B)/3` coefficients, which satisfy the real symmetry. About half the work of
    /// [`Plan::forward`]. Needs a plan made with [`PlanOptions::real`](crate::PlanOptions::real).
    pub fn forward_real(&self, samples: &[f64], coeffs: &mut [Complex64]) -> Result<()> {
        self.forward_real_timed(samples, coeffs).map(|_| ())
    }

    /// Inverse transform to a real signal: coefficients (only one of each pair
    /// `(M,M')`, `(-M,-M')` is read: those with `M' > 0`, or `M' = 0` and `M >= 0`) to
    /// `(2B)^3` real samples. Needs a plan made with [`PlanOptions::real`](crate::PlanOptions::real).
    pub fn inverse_real(&self, coeffs: &[Complex64], samples: &mut [f64]) -> Result<()> {
        self.inverse_real_timed(coeffs, samples).map(|_| ())
    }

    /// [`Plan::inverse_real`] into a complex sample array: real parts are the samples,
    /// imaginary parts exactly 0 (for callers whose interface is complex, such as the C API
    /// with `SO3FFT_REAL` and SOFT's `flag = 1`). No extra memory: the reals are written to
    /// the first half of `samples` and spread in place.
    pub(crate) fn inverse_real_to_complex(
        &self,
        coeffs: &[Complex64],
        samples: &mut [Complex64],
    ) -> Result<()> {
        self.check(false, samples.len(), coeffs.len())?;
        let ns = samples.len();
        // SAFETY: `samples` spans 2 ns doubles; the f64 view ends before `samples` is used.
        let re = unsafe { std::slice::from_raw_parts_mut(samples.as_mut_ptr() as *mut f64, ns) };
        self.inverse_real(coeffs, re)?;
        // SAFETY: `samples` is valid for 2 ns doubles.
        unsafe {
            spread_real_in_place(
                self.pool(),
                samples.as_mut_ptr() as *mut f64,
                ns,
                self.threads,
            )
        };
        Ok(())
    }

    /// Like [`Plan::forward_real`], also returning the time of each stage.
    pub fn forward_real_timed(
        &self,
        samples: &[f64],
        coeffs: &mut [Complex64],
    ) -> Result<StageTimes> {
        self.check(true, samples.len(), coeffs.len())?;
        self.forward_real_impl(
            RealInput::Real(SendConstPtr(samples.as_ptr())),
            coeffs,
            None,
        )
    }

    /// [`Plan::forward_real`] that may overwrite `samples`, for fewer passes over the
    /// coefficients when the plan works in chunks (see [`Plan::forward_destroying_input`]).
    pub fn forward_real_destroying_input(
        &self,
        samples: &mut [f64],
        coeffs: &mut [Complex64],
    ) -> Result<()> {
        self.forward_real_destroying_input_timed(samples, coeffs)
            .map(|_| ())
    }

    /// Like [`Plan::forward_real_destroying_input`], also returning the time of each stage.
    pub fn forward_real_destroying_input_timed(
        &self,
        samples: &mut [f64],
        coeffs: &mut [Complex64],
    ) -> Result<StageTimes> {
        self.check(true, samples.len(), coeffs.len())?;
        // One raw pointer for reading the slices and for the buffers in the read ones.
        let base = samples.as_mut_ptr();
        let spare = Spare::over(base, self.b);
        self.forward_real_impl(RealInput::Real(SendConstPtr(base)), coeffs, Some(spare))
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
            None,
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
            Some(spare),
        )
    }

    fn forward_real_impl(
        &self,
        input: RealInput,
        coeffs: &mut [Complex64],
        spare: Option<Spare>,
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
            spare,
            |ch, buf| {
                let no_output = SendPtr(std::ptr::null_mut());
                self.fft.chunk_real(t, ch, Some(input), no_output, buf)
            },
            // The chunks accumulate the representatives only (half the coefficient traffic
            // per chunk); the last one also writes their partners.
            // SAFETY: `run_chunks` hands each task distinct clusters, whose blocks of the
            // chunk buffer and coefficient rows (representatives and their partners) no
            // other task touches; `coeffs` has `num_coeffs` entries (checked above).
            |sc, step, pass| unsafe { self.dwt.forward_cluster(sc, &layout, step, coef, pass) },
        )
    }

    /// Like [`Plan::inverse_real`], also returning the time of each stage.
    pub fn inverse_real_timed(
        &self,
        coeffs: &[Complex64],
        samples: &mut [f64],
    ) -> Result<StageTimes> {
        self.check(false, samples.len(), coeffs.len())?;
        self.fft.real_fft()?;
        // One raw pointer for the output slices and for the buffers in the free ones.
        let out = SendPtr(samples.as_mut_ptr());
        let t = self.real_blocks()?;
        let layout = DwtLayout {
            blocks: t,
            real: true,
        };
        let spare = Spare::over(out.get(), self.b);
        self.run_chunks(
            false,
            t,
            Some(spare),
            |ch, buf| self.fft.chunk_real(t, ch, None, out, buf),
            // SAFETY: `run_chunks` hands each task distinct clusters, whose blocks of the
            // chunk buffer no other task touches.
            |sc, step, pass| unsafe { self.dwt.inverse_cluster(sc, &layout, step, coeffs, pass) },
        )
    }

    fn real_blocks(&self) -> Result<&Blocks> {
        self.blocks_real.as_ref().ok_or_else(|| {
            Error::InvalidArgument("the plan was made without PlanOptions::real".into())
        })
    }
}

/// Turn `n` reals at `base[0..n]` into `n` complex values `(x, 0)` at `base[0..2n]`, in
/// place. Entry `i` goes to doubles `2i, 2i+1`, so going from the top down never
/// overwrites a real still to be read. With several threads (on the plan's `pool`): the
/// range `[ceil(n/2), n)` lands in `[2 ceil(n/2), 2n)`, clear of every real still to be
/// read, so its pieces can be done at once; then the range below, halving down to the
/// first few entries. One thread does it in a single pass from the top.
///
/// # Safety
/// `base` is valid for `2n` doubles.
unsafe fn spread_real_in_place(pool: &rayon::ThreadPool, base: *mut f64, n: usize, threads: usize) {
    // Entries `lo..hi` to doubles `2 lo..2 hi`, from the top down.
    let spread = |p: SendPtr<f64>, lo: usize, hi: usize| {
        for i in (lo..hi).rev() {
            // SAFETY: `i < hi <= n` and `2i + 1 < 2n`: inside the caller's `2n` doubles.
            // Within a round the pieces write disjoint ranges `[2a, 2a + 2 per)` at or
            // above `2 lo >= hi` and read reals below `hi` that no piece of the round
            // writes; the last (single) pass runs alone.
            unsafe {
                let v = *p.get().add(i);
                *p.get().add(2 * i + 1) = 0.0;
                *p.get().add(2 * i) = v;
            }
        }
    };
    let mut hi = n;
    if threads > 1 {
        while hi > 1 << 16 {
            // Rounded up: with `hi` odd, `hi / 2` would write double `hi - 1`, a real
            // another piece of this round still reads.
            let lo = hi.div_ceil(2);
            let per = (hi - lo).div_ceil(threads);
            let p = SendPtr(base);
            pool.install(|| {
                (lo..hi)
                    .step_by(per)
                    .par_bridge()
                    .for_each(|a| spread(p, a, (a + per).min(hi)))
            });
            hi = lo;
        }
    }
    spread(SendPtr(base), 0, hi);
}

#[cfg(test)]
mod tests {
    /// Every real ends up as `(x, 0)` at its own index, with one thread (one pass) and with
    /// several (halving rounds, uneven pieces), for sizes around the rounds' threshold.
    #[test]
    fn spread_real_in_place_keeps_every_value() {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .unwrap();
        for n in [1usize, 7, 1 << 16, (1 << 16) + 1, 300_001] {
            for threads in [1usize, 2, 3] {
                let mut v: Vec<f64> = (0..2 * n)
                    .map(|i| if i < n { i as f64 + 0.5 } else { f64::NAN })
                    .collect();
                // SAFETY: `v` holds 2n doubles.
                unsafe { super::spread_real_in_place(&pool, v.as_mut_ptr(), n, threads) };
                assert!(
                    (0..n).all(|i| v[2 * i] == i as f64 + 0.5 && v[2 * i + 1] == 0.0),
                    "n={n} threads={threads}"
                );
            }
        }
    }
}
