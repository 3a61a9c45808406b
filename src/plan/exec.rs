//! Running a plan: the chunk loop shared by every transform and the parallel loop over
//! the clusters of the DWT stage.

use super::blocks::{Blocks, BufLayout, ChunkBuf};
use super::dwt_stage::{DwtLayout, Scratch as DwtScratch};
use super::fft_stage::SliceWatch;
use super::options::StageTimes;
use super::schedule::{Chunk, ChunkGroups, ClusterStep, Pass, PlacedChunk, Spare};
use super::shared::SendPtr;
use super::Plan;
use crate::error::{Error, Result};
use crate::fft::AlignedBuf;
use crate::transform::Scratch;
use num_complex::Complex64;
use std::time::Instant;

impl Plan {
    /// Run `f` with a chunk buffer of the plan's workspace size: the caller's `scratch`
    /// if given (checked to hold it), else the plan's own (see [`ChunkBuffer`]).
    pub(super) fn with_buf<R>(
        &self,
        scratch: Option<&Scratch>,
        f: impl FnOnce(&AlignedBuf) -> Result<R>,
    ) -> Result<R> {
        match scratch {
            Some(s) => f(s.holding(self.workspace_bytes())?),
            None => self.buf.with(self.workspace_bytes().div_ceil(16), f),
        }
    }

    /// The forward of complex samples at `samples` into `coeffs`, with chunk buffers in
    /// the read input slices when `spare` is given, in the caller's `scratch` if given.
    pub(super) fn forward_impl(
        &self,
        samples: *const Complex64,
        coeffs: &mut [Complex64],
        (spare, scratch): (Option<Spare>, Option<&Scratch>),
    ) -> Result<StageTimes> {
        let coef = SendPtr(coeffs.as_mut_ptr());
        // The forward only reads the samples (a forward that may overwrite them puts
        // chunk buffers in read slices through `spare`, never through this pointer).
        let input = SendPtr(samples as *mut Complex64);
        let layout = DwtLayout {
            blocks: &self.blocks,
            real: false,
        };
        self.run_chunks(
            true,
            &self.blocks,
            (spare, scratch),
            |ch, buf| self.fft.chunk(&self.blocks, ch, (true, None), input, buf),
            // SAFETY: `run_chunks` hands each task distinct clusters, whose blocks of the
            // chunk buffer and coefficient rows no other task touches; the buffer holds the
            // chunk's blocks (filled by the FFT stage before); `coeffs` has
            // `num_coeffs` entries (checked by the caller).
            |sc, step, pass| unsafe { self.dwt.forward_cluster(sc, &layout, step, coef, pass) },
        )
    }

    /// The inverse of `coeffs` into the complex samples `samples` (lengths checked by the
    /// caller), with chunk buffers in the output slices not yet written, in the caller's
    /// `scratch` if given.
    pub(super) fn inverse_impl(
        &self,
        coeffs: &[Complex64],
        samples: &mut [Complex64],
        (watch, scratch): (Option<SliceWatch>, Option<&Scratch>),
    ) -> Result<StageTimes> {
        // One raw pointer for the output slices and for the buffers in the free ones.
        let out = SendPtr(samples.as_mut_ptr());
        let spare = Spare::over(out.get(), self.b);
        let layout = DwtLayout {
            blocks: &self.blocks,
            real: false,
        };
        self.run_chunks(
            false,
            &self.blocks,
            (Some(spare), scratch),
            |ch, buf| self.fft.chunk(&self.blocks, ch, (false, watch), out, buf),
            // SAFETY: `run_chunks` hands each task distinct clusters, whose blocks of the
            // chunk buffer no other task touches; the buffer is the chunk's.
            |sc, step, pass| unsafe { self.dwt.inverse_cluster(sc, &layout, step, coeffs, pass) },
        )
    }

    /// The chunk loop shared by every transform: for each group of chunks (see
    /// `Schedule::chunk_groups`), the FFT stage of each chunk and the DWT of every cluster of
    /// layout `t` over the group's chunks, in the order of the direction (forward: FFT
    /// then DWT), timed. The cluster stage learns where the chunk stands ([`Pass`]). The
    /// first chunk's buffer is the caller's `scratch` if given, else the plan's.
    pub(super) fn run_chunks(
        &self,
        forward: bool,
        t: &Blocks,
        (spare, scratch): (Option<Spare>, Option<&Scratch>),
        fft: impl Fn(&Chunk, ChunkBuf) -> Result<()> + Sync,
        cluster: impl Fn(&mut DwtScratch, &ClusterStep, &Pass) + Sync,
    ) -> Result<StageTimes> {
        let t0 = Instant::now();
        let mut times = StageTimes::default();
        let ChunkGroups { groups, chained } =
            self.schedule.chunk_groups(t, forward, spare.as_ref());
        self.with_buf(scratch, |buf| {
            let own = SendPtr(buf.as_mut_ptr() as *mut f64);
            let whole = t.total() / 2;
            let groups: Vec<Vec<PlacedChunk>> = groups
                .iter()
                .map(|group| {
                    // The chains' buffers are in two pieces: the forward's split, the
                    // inverse's half-major.
                    let layout: fn(usize) -> BufLayout = if forward && chained {
                        BufLayout::Split
                    } else if !forward && (chained || self.schedule.streams_blocks(group.len())) {
                        BufLayout::HalfMajor
                    } else {
                        |_| BufLayout::Blocks
                    };
                    group
                        .iter()
                        .map(|place| {
                            let (base, gap) = match place.spare {
                                Some(s) => (SendPtr(s.low), s.gap),
                                None => (own, whole),
                            };
                            PlacedChunk {
                                chunk: place.chunk,
                                buf: ChunkBuf {
                                    base,
                                    layout: layout(gap),
                                },
                            }
                        })
                        .collect()
                })
                .collect();
            self.pool().install(|| {
                for (gi, group) in groups.iter().enumerate() {
                    let mut fft_stage = || -> Result<()> {
                        let t = Instant::now();
                        for placed in group {
                            fft(&placed.chunk, placed.buf)?;
                        }
                        times.fft += t.elapsed().as_secs_f64();
                        Ok(())
                    };
                    if forward {
                        fft_stage()?;
                    }
                    let t1 = Instant::now();
                    self.dwt.for_each_cluster(t, |sc, step| {
                        for (k, placed) in group.iter().enumerate() {
                            let last_in_group = k + 1 == group.len();
                            let pass = Pass {
                                placed: *placed,
                                first_group: gi == 0,
                                position: k,
                                last_in_group,
                                last_of_transform: gi + 1 == groups.len() && last_in_group,
                                next_in_group: group.get(k + 1).map(|g| g.buf),
                                group_head: group[0],
                            };
                            cluster(sc, step, &pass);
                        }
                    });
                    times.dwt += t1.elapsed().as_secs_f64();
                    if !forward {
                        fft_stage()?;
                    }
                }
                Ok::<(), Error>(())
            })
        })?;
        times.total = t0.elapsed().as_secs_f64();
        Ok(times)
    }
}
