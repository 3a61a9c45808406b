//! The forward: the FFT stage from the input slices into lane rows, chunk by chunk, then
//! the DWT stage adding each chunk into the coefficients.

use super::chunks::{Data, Engine, Members};
use super::fft_stage::{BufPair, Work};
use crate::batch::Batch;
use crate::dwt::Prefetch;
use crate::error::Result;
use crate::transform::Scratch;
use crate::transform::StageTimes;
use crate::workers::SendPtr;
use crate::Real;
use num_complex::Complex;
use rayon::prelude::*;
use std::time::Instant;

impl<T: Real> Engine<T> {
    /// The slice DFTs of a forward from the slices `inp` (one or two, of one kind) into
    /// `work`'s two buffers for that kind, in order; returns the buffers (for a gather).
    ///
    /// # Safety
    /// Each of `inp` is valid for reads of one slice.
    pub(super) unsafe fn slices_in<'a>(
        &self,
        work: &'a mut Work,
        inp: &[Data<T>],
    ) -> Result<BufPair<'a, T>> {
        let ((w0, w1), mut reals) = match inp[0] {
            Data::Complex(_) => (self.fft.fwd_pair(work)?, None),
            Data::Real(_) => (self.fft.half_pair(work)?, None),
            Data::RealParts(_) => {
                let (pair, reals) = self.fft.half_pair_reals(work)?;
                (pair, Some(reals))
            }
        };
        for (w, i) in [&mut *w0, &mut *w1].into_iter().zip(inp) {
            // SAFETY: the caller's contract; the buffers are this worker's.
            unsafe {
                match (i, reals.as_deref_mut()) {
                    (Data::Complex(i), _) => self.fft.forward(w, i.get()),
                    (Data::Real(i), _) => self.fft.forward_real(w, i.get()),
                    (Data::RealParts(i), Some(r)) => self.fft.forward_real_parts((w, r), i.get()),
                    (Data::RealParts(_), None) => unreachable!("one kind per call"),
                }
            }
        }
        Ok((w0, w1))
    }

    /// Forward of a group of transforms, chunk by chunk.
    pub(super) fn forward_group(
        &self,
        (batch, m): (Batch, Members<T>),
        inp: Data<T>,
        coef: SendPtr<Complex<T>>,
        scratch: Option<&Scratch>,
    ) -> Result<StageTimes> {
        let start = Instant::now();
        let mut times = StageTimes::default();
        let hp_max = self.chunk_pairs(m).next_multiple_of(self.lanes_w());
        let per_t_max = m.dwt.row_stride * 2 * hp_max;
        let slice_len = self.fft.slice_len();
        let real = inp.is_real();
        self.with_buf((batch.count * per_t_max, scratch), |buf| {
            let buf = SendPtr(buf);
            self.workers.pool().install(|| {
                for ch in self.chunks((self.chunk_pairs(m), m)) {
                    let lanes = ch.lanes();
                    let per_t = m.dwt.row_stride * lanes;
                    let t0 = Instant::now();
                    // A beta and its mirror in one task (each lane row written whole by
                    // one task, each slot read once), as the inverse.
                    let pair_tasks = self.pair_tasks(ch, batch.count);
                    pair_tasks.par_iter().try_for_each(|&(t, jj, [s0, s1])| {
                        self.with_work(|work| {
                            let rows = Self::lane_rows(m, (buf.get(), t * per_t), ch, (jj, false));
                            let weight = self.pair_weight[ch.j0 + jj];
                            let at = |s: usize| inp.offset(t * batch.in_dist + s * slice_len);
                            // SAFETY: slices `s0` and `s1` of input `t` are inside the
                            // checked input; the two lane rows are this task's alone.
                            unsafe {
                                let (w0, w1) = self.slices_in(work, &[at(s0), at(s1)])?;
                                if real {
                                    self.gather_real_pair(m, (w0, w1), &[rows], weight);
                                } else {
                                    self.gather_pair(m, (w0, w1), &[rows], weight);
                                }
                            }
                            Ok(())
                        })
                    })?;
                    let tasks = self.slice_tasks(ch, batch.count);
                    tasks.par_iter().try_for_each(|&(t, jj, upper, s)| {
                        self.with_work(|work| {
                            let rows = Self::lane_rows(m, (buf.get(), t * per_t), ch, (jj, upper));
                            let weight = self.pair_weight[ch.j0 + jj];
                            let at = inp.offset(t * batch.in_dist + s * slice_len);
                            // SAFETY: slice `s` of input `t` is inside the checked input;
                            // the values written are this slice's slots of two lane rows:
                            // no other task writes them (its mirror writes the other slots
                            // of the same rows).
                            unsafe {
                                let (w, _) = self.slices_in(work, &[at])?;
                                if real {
                                    self.gather_real(m, w, &[rows], weight);
                                } else {
                                    self.gather(m, w, &[rows], weight);
                                }
                            }
                            Ok(())
                        })
                    })?;
                    let t1 = Instant::now();
                    times.fft += (t1 - t0).as_secs_f64();
                    let first = ch.j0 == 0;
                    for t in 0..batch.count {
                        // SAFETY: the padding lane rows of transform `t` in the chunk
                        // buffer, written by nobody (the FFT stage is finished).
                        unsafe { Self::zero_padding(m, buf.get().add(t * per_t), ch) };
                    }
                    let clusters = &m.dwt.clusters;
                    m.dwt.for_each_cluster(|sc, i, cl| {
                        let n = m.dwt.setup(sc, cl, &self.pairs, ch);
                        // Transform by transform (the cluster's set-up shared), each
                        // kernel prefetching what the next one reads: the next
                        // transform's rows of this cluster, after the last the next
                        // cluster's (likely this task's next one) of the first.
                        for t in 0..batch.count {
                            let block = buf.get().wrapping_add(t * per_t + cl.offset);
                            let c = coef.get().wrapping_add(t * batch.out_dist);
                            let next = if t + 1 < batch.count {
                                m.dwt.forward_hints(
                                    cl,
                                    ch,
                                    buf.get().wrapping_add((t + 1) * per_t + cl.offset),
                                    coef.get().wrapping_add((t + 1) * batch.out_dist),
                                )
                            } else if let Some(nc) = clusters.get(i + 1) {
                                m.dwt.forward_hints(
                                    nc,
                                    ch,
                                    buf.get().wrapping_add(nc.offset),
                                    coef.get(),
                                )
                            } else {
                                Prefetch::none()
                            };
                            // SAFETY: this cluster's slots of transform `t`'s lane rows
                            // (written by the FFT stage or zeroed above, finished); its
                            // coefficient array is inside the checked output, and this
                            // cluster's slots' blocks are this task's.
                            unsafe { m.dwt.forward(sc, cl, (ch, n), block, (c, first, next)) };
                        }
                    });
                    times.dwt += t1.elapsed().as_secs_f64();
                }
                Ok(())
            })
        })?;
        times.total = start.elapsed().as_secs_f64();
        Ok(times)
    }
}
