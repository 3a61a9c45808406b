//! Plan-time choice of how the FFT stage uses the threads ([`FftThreading::Auto`]).
//!
//! With a measuring rigour (`Rigor::Measure` or stronger), more than one thread and
//! `FftThreading::Auto`, [`Plan::new`] builds the slice plans of both variants and times
//! them on a sample of the real work: the FFT stage, for each direction the plan has, of
//! the first slice groups of a chunk (up to [`SAMPLE_GROUPS`] groups per worker, within
//! [`SAMPLE_BYTES`]), on a scratch array standing in for the sample grid and on the plan's
//! own chunk buffer, so the block copies run with the real stride. FFTW's threads are
//! started by one untimed slice transform first. Rounds alternate between the variants and
//! each keeps its fastest round (interference from other processes only ever adds time);
//! after a round in which slices across workers lead by more than [`CLEAR`], no more are
//! run, else up to [`ROUNDS`]. The faster variant is kept (FFTW's threads need a margin of
//! [`FFTW_MARGIN`]) and the other's FFTW plans are destroyed.

use super::blocks::{BufLayout, ChunkBuf};
use super::fft_stage::SliceRun;
use super::schedule::Chunk;
use super::shared::SendPtr;
use super::Plan;
use crate::error::Result;
use crate::fft::{self, AlignedBuf, Rigor, SliceFft, SIGN_MINUS, SIGN_PLUS};
use crate::options::{FftThreading, Options};
use crate::system::mem_available;
use std::time::Instant;

/// Timed rounds per variant, at most (the fastest of them counts).
const ROUNDS: usize = 5;

/// Groups of slice pairs per worker in the timed sample, at most: with a single group per
/// worker, one worker delayed by another process doubles the time of the
/// slices-across-workers variant.
const SAMPLE_GROUPS: usize = 4;

/// Most bytes of the scratch sample grid (at least one group per worker is timed).
const SAMPLE_BYTES: usize = 64 << 20;

/// Ratio by which FFTW's threads must be slower than slices across workers for no further
/// round to be run.
const CLEAR: f64 = 1.25;

/// FFTW's threads are kept only when faster by at least this fraction: within the noise
/// of the measurement, slices across workers are preferred, as they balance their load
/// dynamically (a core taken by another process delays a worker, not every slice).
const FFTW_MARGIN: f64 = 0.1;

impl Plan {
    /// Resolve [`FftThreading::Auto`] by measurement (see the module documentation). Does
    /// nothing unless the options ask for `Auto` with a measuring rigour and more than one
    /// thread. Never fails: if the other variant cannot be planned, or the scratch array
    /// does not fit comfortably in memory, the plan keeps slices across workers.
    pub(super) fn tune_fft_threading(&mut self, options: &Options) {
        if options.fft_threading != FftThreading::Auto
            || options.rigor == Rigor::Estimate
            || self.threads < 2
            || self.fft.fftw_threaded()
        {
            return;
        }
        let n = 2 * self.b;
        let plan_threaded = |have: bool, sign: i32| -> Result<Option<SliceFft>> {
            if have {
                SliceFft::new(n, sign, options.rigor, self.threads).map(Some)
            } else {
                Ok(None)
            }
        };
        let (own_fwd, own_inv) = self.fft.complex_ffts();
        let (Ok(fwd), Ok(inv)) = (
            plan_threaded(own_fwd.is_some(), SIGN_PLUS),
            plan_threaded(own_inv.is_some(), SIGN_MINUS),
        ) else {
            return;
        };
        let Some([workers, fftw]) = self.time_fft_variants(fwd.as_ref(), inv.as_ref()) else {
            return;
        };
        if fftw < (1.0 - FFTW_MARGIN) * workers {
            self.fft.use_fftw_threads(fwd, inv);
        }
    }

    /// Fastest-round time of the sample work (all directions the plan has) with the plan's
    /// own slice plans across workers and with the given FFTW-threaded plans; `None` if the
    /// scratch array cannot be had.
    fn time_fft_variants(
        &self,
        fwd: Option<&SliceFft>,
        inv: Option<&SliceFft>,
    ) -> Option<[f64; 2]> {
        let n = 2 * self.b;
        let nn = n * n;
        // Up to SAMPLE_GROUPS groups of pairs per worker and direction, from the first
        // chunk (always a full one), within SAMPLE_BYTES of sample grid. The sample grid
        // holds the slices the timed pairs write: pair `j` (beta `j` and its mirror
        // `2B-1-j`) uses slices `2j` and `2j+1`, distinct for the pairs timed
        // concurrently. (Mapping fresh memory costs more than the measurement itself when
        // transparent huge pages must be compacted.)
        let per_group = self.threads * self.fft.pairs_per_group();
        let fit = SAMPLE_BYTES / (2 * nn * 16) / per_group;
        let npairs = (per_group * fit.clamp(1, SAMPLE_GROUPS)).min(self.blocks.chunk);
        let slices = 2 * npairs;
        let bytes = slices * nn * 16;
        if mem_available().is_some_and(|a| a / 4 < bytes) {
            return None;
        }
        // (At least one padded slice, for the warm-up below.)
        let grid = AlignedBuf::new((slices * nn).max(n * fft::slice_stride(n))).ok()?;
        let h = self.blocks.chunk;
        // The timed pairs: the first `npairs` of the first chunk.
        let ch = Chunk {
            lo: 0,
            h: npairs,
            hp: h.next_multiple_of(self.dwt.isa().lanes()),
        };
        let g = SendPtr(grid.as_mut_ptr());
        let (own_fwd, own_inv) = self.fft.complex_ffts();
        let b = self.b;
        let slice = move |k: usize| {
            let (j, mirror) = if k < b { (k, 0) } else { (2 * b - 1 - k, 1) };
            SendPtr(g.get().wrapping_add((2 * (j % npairs) + mirror) * nn))
        };
        let variants: [(Option<&SliceFft>, Option<&SliceFft>, bool); 2] =
            [(own_fwd, own_inv, false), (fwd, inv, true)];
        let mut best = [f64::INFINITY; 2];
        self.with_buf(None, |buf| {
            self.pool().install(|| {
                // Start FFTW's threads (created on a plan's first execution) untimed.
                if let Some(fft) = fwd.or(inv) {
                    // SAFETY: the sample grid holds at least one padded slice.
                    unsafe { fft.in_place(g.get()) };
                }
                let bp = buf.as_mut_ptr() as *mut f64;
                // The inverse's layout for one chunk (see `plan/blocks.rs`).
                let layout = if self.schedule.streams_blocks(1) {
                    BufLayout::HalfMajor(self.blocks.total() / 2)
                } else {
                    BufLayout::Blocks
                };
                for round in 0..ROUNDS {
                    for i in 0..2 {
                        // Alternate which variant goes first.
                        let v = (i + round) % 2;
                        let (f, iv, threaded) = variants[v];
                        let t = Instant::now();
                        for (fft, forward) in [(f, true), (iv, false)] {
                            if let Some(fft) = fft {
                                let run = SliceRun {
                                    fft,
                                    forward,
                                    fftw_threaded: threaded,
                                    watch: None,
                                };
                                let buf = ChunkBuf {
                                    base: SendPtr(bp),
                                    layout,
                                };
                                self.fft.pairs(&self.blocks, &ch, run, &slice, buf)?;
                            }
                        }
                        best[v] = best[v].min(t.elapsed().as_secs_f64());
                    }
                    // A clear lead of the default needs no more rounds. A lead of FFTW's
                    // threads must survive every round: one round in which another
                    // process delays a worker makes the default look slow
                    // (`benches/tune_count.rs` counts the choices under load).
                    if best[1] > CLEAR * best[0] {
                        break;
                    }
                }
                Ok(())
            })
        })
        .ok()?;
        Some(best)
    }
}
