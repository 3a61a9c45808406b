//! Running a plan: the chunk loop shared by every transform and the parallel loop over
//! the clusters of the DWT stage.

use super::blocks::{Blocks, BufLayout, ChunkBuf};
use super::build::mem_available;
use super::dwt_stage::Scratch;
use super::members::all_members;
use super::schedule::{At, Chunk, Pass, Spare};
use super::shared::{lock_free, SendPtr};
use super::{Plan, StageTimes};
use crate::error::{Error, Result};
use crate::fft::AlignedBuf;
use crate::symmetry::Cluster;
use num_complex::Complex64;
use rayon::prelude::*;
use std::time::Instant;

impl Plan {
    /// Run `f` with a chunk buffer: the plan's own if free, else a temporary one.
    ///
    /// A concurrent execution gets a private chunk buffer only while the memory it needs is
    /// available (twice over); otherwise a plain thread waits for the plan's buffer, and a
    /// worker of some rayon pool (which must not block: the holder may be further down its
    /// own stack) gets `Error::OutOfMemory`.
    pub(super) fn with_buf<R>(&self, f: impl FnOnce(&AlignedBuf) -> Result<R>) -> Result<R> {
        let g = match self.buf.try_lock() {
            Ok(g) => g,
            Err(std::sync::TryLockError::Poisoned(e)) => e.into_inner(),
            Err(std::sync::TryLockError::WouldBlock) => {
                let bytes = self.workspace_bytes();
                if mem_available().is_none_or(|a| a / 2 >= bytes) {
                    let tmp = AlignedBuf::new(bytes.div_ceil(16))?;
                    return f(&tmp);
                }
                if rayon::current_thread_index().is_some() {
                    return Err(Error::OutOfMemory { bytes });
                }
                self.buf.lock().unwrap_or_else(|e| e.into_inner())
            }
        };
        f(g.as_ref().expect("plan buffer present"))
    }

    pub(super) fn forward_impl(
        &self,
        samples: *const Complex64,
        coeffs: &mut [Complex64],
        spare: Option<Spare>,
    ) -> Result<StageTimes> {
        let coef = SendPtr(coeffs.as_mut_ptr());
        // The forward only reads the samples (a forward that may overwrite them puts
        // chunk buffers in read slices through `spare`, never through this pointer).
        let input = SendPtr(samples as *mut Complex64);
        self.run_chunks(
            true,
            &self.blocks,
            spare,
            |ch, buf| self.fft.chunk(&self.blocks, ch, true, input, buf),
            |sc, at, ch, buf, pass| unsafe {
                self.forward_cluster(
                    sc,
                    &self.blocks,
                    all_members,
                    false,
                    at,
                    ch,
                    buf,
                    coef,
                    pass,
                );
            },
        )
    }

    /// Like [`Plan::inverse`], also returning the time of each stage.
    pub fn inverse_timed(
        &self,
        coeffs: &[Complex64],
        samples: &mut [Complex64],
    ) -> Result<StageTimes> {
        self.check(false, samples.len(), coeffs.len())?;
        // One raw pointer for the output slices and for the buffers in the free ones.
        let out = SendPtr(samples.as_mut_ptr());
        let spare = Spare::over(out.get(), self.b);
        self.run_chunks(
            false,
            &self.blocks,
            Some(spare),
            |ch, buf| self.fft.chunk(&self.blocks, ch, false, out, buf),
            |sc, at, ch, buf, pass| unsafe {
                self.inverse_cluster(sc, &self.blocks, all_members, at, ch, buf, coeffs, pass)
            },
        )
    }

    /// The chunk loop shared by every transform: for each group of chunks (see
    /// [`Plan::chunk_groups`]), the FFT stage of each chunk and the DWT of every cluster of
    /// layout `t` over the group's chunks, in the order of the direction (forward: FFT
    /// then DWT), timed. The cluster stage learns where the chunk stands ([`Pass`]).
    #[allow(clippy::type_complexity)]
    pub(super) fn run_chunks(
        &self,
        forward: bool,
        t: &Blocks,
        spare: Option<Spare>,
        fft: impl Fn(&Chunk, ChunkBuf) -> Result<()> + Sync,
        cluster: impl Fn(&mut Scratch, &At, &Chunk, *mut f64, Pass) + Sync,
    ) -> Result<StageTimes> {
        let t0 = Instant::now();
        let mut times = StageTimes::default();
        let (groups, chained) = self.chunk_groups(t, forward, spare.as_ref());
        self.with_buf(|buf| {
            let bp = buf.as_mut_ptr() as *mut f64;
            let whole = t.total() / 2;
            let groups: Vec<Vec<(Chunk, SendPtr<f64>, usize)>> = groups
                .iter()
                .map(|g| {
                    g.iter()
                        .map(|(c, p)| {
                            let (p, gap) = p.unwrap_or((bp, whole));
                            (*c, SendPtr(p), gap)
                        })
                        .collect()
                })
                .collect();
            self.pool().install(|| {
                for (gi, group) in groups.iter().enumerate() {
                    // The chains' buffers are in two pieces: the forward's split, the
                    // inverse's half-major.
                    let layout: fn(usize) -> BufLayout = if forward && chained {
                        BufLayout::Split
                    } else if !forward && (chained || self.streams_blocks(group.len())) {
                        BufLayout::HalfMajor
                    } else {
                        |_| BufLayout::Blocks
                    };
                    let group: Vec<_> = group.iter().map(|&(c, p, g)| (c, p, layout(g))).collect();
                    let mut fft_stage = || -> Result<()> {
                        let t = Instant::now();
                        for (ch, buf, layout) in &group {
                            fft(
                                ch,
                                ChunkBuf {
                                    base: *buf,
                                    layout: *layout,
                                },
                            )?;
                        }
                        times.fft += t.elapsed().as_secs_f64();
                        Ok(())
                    };
                    if forward {
                        fft_stage()?;
                    }
                    let t1 = Instant::now();
                    self.for_each_cluster(t, |sc, at| {
                        for (k, (ch, buf, layout)) in group.iter().enumerate() {
                            let pass = Pass {
                                first: gi == 0,
                                k,
                                last: k + 1 == group.len(),
                                done: gi + 1 == groups.len() && k + 1 == group.len(),
                                next_buf: group.get(k + 1).map(|g| (g.1, g.2)),
                                head: group[0],
                                layout: *layout,
                            };
                            cluster(sc, at, ch, buf.get(), pass);
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

    /// Run `f(scratch, at)` on every cluster in parallel (work stealing over runs of
    /// consecutive clusters, whose blocks are consecutive in the chunk buffer). While a
    /// cluster's kernel runs it prefetches what the next one will touch (see
    /// `Plan::next_cluster`), so `at` carries that one too; each cluster is built once.
    pub(super) fn for_each_cluster(&self, t: &Blocks, f: impl Fn(&mut Scratch, &At) + Sync) {
        let nc = t.len();
        const RUN: usize = 8;
        (0..nc.div_ceil(RUN)).into_par_iter().for_each(|r| {
            let mut guard = lock_free(&self.dwt_scratch);
            let mut own = None;
            let sc: &mut Scratch = match guard.as_deref_mut() {
                Some(s) => s,
                // All busy (concurrent executions of this plan): use a private one.
                None => own.insert(Scratch::for_layouts(
                    self.b,
                    &self.blocks,
                    self.blocks_real.as_ref(),
                )),
            };
            let (c0, c1) = (r * RUN, ((r + 1) * RUN).min(nc));
            let pair = |c: usize| {
                let (m, mp) = self.clusters[c];
                Cluster::new(m as usize, mp as usize)
            };
            let mut cl = pair(c0);
            for c in c0..c1 {
                let next = (c + 1 < nc).then(|| pair(c + 1));
                f(sc, &At { c, cl, next });
                if let Some(n) = next {
                    cl = n;
                }
            }
        });
    }
}
