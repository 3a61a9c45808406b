//! The inverse: the DWT stage into lane rows of a chunk (or a chain of chunks), then
//! the FFT stage from the lane rows into the output slices.

use super::chunks::{Data, Engine, Members, PlacedLanes};
use super::dwt_stage::{ChunkLanes, KERNEL_BATCH};
use super::fft_stage::{SliceRef, SliceWatch};
use crate::batch::Batch;
use crate::dwt::{BatchRows, Prefetch};
use crate::error::Result;
use crate::transform::Scratch;
use crate::transform::StageTimes;
use crate::workers::{SendConstPtr, SendPtr};
use crate::Real;
use num_complex::Complex;
use rayon::prelude::*;
use std::time::Instant;

impl<T: Real> Engine<T> {
    /// Inverse of a group of transforms: chunk by chunk, or all chunks in one pass of the
    /// DWT stage where [`Engine::inverse_chain`] places their buffers.
    pub(super) fn inverse_group(
        &self,
        (batch, m): (Batch, Members<T>),
        coef: SendConstPtr<Complex<T>>,
        out: Data<T>,
        (scratch, watch): (Option<&Scratch>, Option<SliceWatch<T>>),
    ) -> Result<StageTimes> {
        let start = Instant::now();
        let mut times = StageTimes::default();
        let hp_max = self.chunk_pairs(m).next_multiple_of(self.lanes_w());
        let per_t_max = m.dwt.row_stride * 2 * hp_max;
        let real = out.is_real();
        self.with_buf((batch.count * per_t_max, scratch), |buf| {
            let own = SendPtr(buf);
            let chain = self.inverse_chain((batch.count, m), out, own);
            let groups: Vec<Vec<PlacedLanes<T>>> = match chain {
                Some(chain) => vec![chain],
                None => self
                    .chunks((self.chunk_pairs(m), m))
                    .map(|ch| vec![PlacedLanes { ch, buf: own }])
                    .collect(),
            };
            self.workers.pool().install(|| {
                for group in groups {
                    // Chunks of padding pairs only (selections) write nothing.
                    let group: Vec<PlacedLanes<T>> = group
                        .into_iter()
                        .filter(|pl| (0..pl.ch.h).any(|jj| self.writes(pl.ch, jj)))
                        .collect();
                    if group.is_empty() {
                        continue;
                    }
                    // Rows far larger than the caches go out with non-temporal stores.
                    let stream = group.len() * batch.count * per_t_max * T::BYTES > 8 << 20;
                    let t0 = Instant::now();
                    self.inverse_dwt((batch, m), coef, &group, (real, stream));
                    let t1 = Instant::now();
                    times.dwt += (t1 - t0).as_secs_f64();
                    // Last chunk first: a chained chunk's buffer is in the slices of the
                    // chunk before it, which its FFT stage writes.
                    for pl in group.iter().rev() {
                        self.inverse_fft((batch, m), *pl, (out, watch))?;
                    }
                    times.fft += t1.elapsed().as_secs_f64();
                }
                Ok(())
            })
        })?;
        times.total = start.elapsed().as_secs_f64();
        Ok(times)
    }

    /// Whether pair `jj` of `ch` writes a slice.
    pub(super) fn writes(&self, ch: ChunkLanes, jj: usize) -> bool {
        self.pairs.outputs[ch.j0 + jj]
            .iter()
            .any(|&s| s != usize::MAX)
    }

    /// The inverse's buffers of every chunk of a single transform as one chain, if they
    /// fit: chunk 0 in the plan's buffer `own`, chunk `k` in two halves, its lower lanes'
    /// rows in the output slices of the lower points of chunk `k - 1` and its upper lanes'
    /// rows in those of its upper points. The DWT stage then runs once over all chunks
    /// (each cluster's coefficients read once), and the FFT stage runs the chunks last to
    /// first: chunk `k` reads its rows before chunk `k - 1` writes its slices. The chunks
    /// are a multiple of the vector width (the padding rows need room too); the slices of a
    /// chunk's lower (upper) points must be consecutive. `None` for batches, fewer than two
    /// chunks, or rows that do not fit.
    pub(super) fn inverse_chain(
        &self,
        (count, m): (usize, Members<T>),
        out: Data<T>,
        own: SendPtr<T>,
    ) -> Option<Vec<PlacedLanes<T>>> {
        // The most pairs the plan's buffer holds, rounded down to the vector width.
        let w = self.lanes_w();
        let most = (self.chunk_pairs(m).next_multiple_of(w)).min(self.most_pairs(m));
        let h = if most >= w { most / w * w } else { most };
        let chunks: Vec<ChunkLanes> = self.chunks((h, m)).collect();
        if count != 1 || chunks.len() < 2 {
            return None;
        }
        let base = match out {
            Data::Complex(p) | Data::RealParts(p) => p.get().cast::<u8>(),
            Data::Real(p) => p.get().cast::<u8>(),
        };
        let slice_bytes = self.fft.slice_len() * out.value_bytes();
        let rt = m.dwt.row_stride;
        let mut chain = vec![PlacedLanes {
            ch: chunks[0],
            buf: own,
        }];
        for pair in chunks.windows(2) {
            let (host, ch) = (pair[0], pair[1]);
            let half_bytes = T::BYTES * ch.hp * rt;
            // The first slice of `host`'s consecutive lower (u = 0) or upper (u = 1)
            // points, aligned room for a half from there.
            let region = |u: usize| -> Option<*mut u8> {
                let first = self.pairs.outputs[host.j0 + if u == 0 { 0 } else { host.h - 1 }][u];
                let consecutive = (0..host.h).all(|jj| {
                    let s = self.pairs.outputs[host.j0 + jj][u];
                    s != usize::MAX
                        && s == if u == 0 {
                            first + jj
                        } else {
                            first + host.h - 1 - jj
                        }
                });
                let from = base.wrapping_add(first * slice_bytes);
                let skip = from.align_offset(64);
                (consecutive && skip + half_bytes <= host.h * slice_bytes)
                    .then(|| from.wrapping_add(skip))
            };
            let (lower, upper) = (region(0)?, region(1)?);
            // Both halves as one lane-major buffer: rows `0..hp` at `lower`, rows
            // `hp..2 hp` from `upper`, which must follow.
            if (upper as usize) < lower as usize + half_bytes {
                return None;
            }
            let gap = (upper as usize - lower as usize) / T::BYTES;
            if gap * T::BYTES != upper as usize - lower as usize {
                return None;
            }
            chain.push(PlacedLanes {
                ch: ChunkLanes {
                    upper_gap: gap,
                    ..ch
                },
                buf: SendPtr(lower.cast::<T>()),
            });
        }
        Some(chain)
    }

    /// The inverse's DWT stage of the chunks of `group` (each cluster over every chunk in
    /// turn, its coefficients cached after the first).
    pub(super) fn inverse_dwt(
        &self,
        (batch, m): (Batch, Members<T>),
        coef: SendConstPtr<Complex<T>>,
        group: &[PlacedLanes<T>],
        (real, stream): (bool, bool),
    ) {
        let clusters = &m.dwt.clusters;
        m.dwt.for_each_cluster(|sc, i, cl| {
            for (k, pl) in group.iter().enumerate() {
                let ch = pl.ch;
                let per_t = m.dwt.row_stride * ch.lanes();
                let n = if k == 0 {
                    m.dwt.setup(sc, cl, &self.pairs, ch)
                } else {
                    m.dwt.setup_lanes(sc, cl, &self.pairs, ch)
                };
                let last_chunk = k + 1 == group.len();
                for t0 in (0..batch.count).step_by(KERNEL_BATCH) {
                    let count = KERNEL_BATCH.min(batch.count - t0);
                    // What the next kernel call will gather: this cluster for the
                    // next transforms, nothing new for the next chunk (the same
                    // blocks), else the next cluster (likely this task's next one)
                    // for the first transforms.
                    let next = if t0 + count < batch.count {
                        Some((cl, t0 + count))
                    } else if last_chunk {
                        clusters.get(i + 1).map(|c| (c, 0))
                    } else {
                        None
                    };
                    let next = next.map(|(c, u)| {
                        let rows = BatchRows {
                            base: coef.get().wrapping_add(u * batch.in_dist),
                            dist: batch.in_dist,
                            count: KERNEL_BATCH.min(batch.count - u),
                        };
                        (c, rows)
                    });
                    let c = BatchRows {
                        base: coef.get().wrapping_add(t0 * batch.in_dist),
                        dist: batch.in_dist,
                        count,
                    };
                    let b = BatchRows {
                        base: pl.buf.get().wrapping_add(t0 * per_t + cl.offset),
                        dist: per_t,
                        count,
                    };
                    // SAFETY: coefficient arrays `t0..t0 + count` of the batch
                    // (checked lengths), read only; this cluster's `cl.p` doubles of
                    // the lane rows of those transforms in the chunk's buffer (the
                    // plan's, or output slices no FFT task writes before the stage
                    // ends, see `inverse_chain`), written by this task only.
                    unsafe {
                        if count == 1 {
                            let hints = next.map_or(Prefetch::none(), |(c, r)| {
                                m.dwt.coefficient_hints(c, r.base, real)
                            });
                            m.dwt
                                .inverse(sc, cl, ch, n, c.base, (real, stream, hints), b.base)
                        } else {
                            m.dwt
                                .inverse_many(sc, cl, ch, n, c, (real, stream, next), b)
                        }
                    }
                }
            }
        });
    }

    /// The inverse's FFT stage of one chunk: a beta and its mirror in one task where both
    /// are written (each lane row and slot read once for both), the others alone; each
    /// slice shown to `watch` if given.
    pub(super) fn inverse_fft(
        &self,
        (batch, m): (Batch, Members<T>),
        pl: PlacedLanes<T>,
        (out, watch): (Data<T>, Option<SliceWatch<T>>),
    ) -> Result<()> {
        let (ch, buf) = (pl.ch, pl.buf);
        let per_t = m.dwt.row_stride * ch.lanes();
        let slice_len = self.fft.slice_len();
        let pair_tasks = self.pair_tasks(ch, batch.count);
        pair_tasks.par_iter().try_for_each(|&(t, jj, [s0, s1])| {
            self.with_work(|work| {
                let rows = Self::lane_rows(m, (buf.get(), t * per_t), ch, (jj, false));
                let at = |s: usize| t * batch.out_dist + s * slice_len;
                let (w0, w1) = if out.is_real() {
                    self.fft.half_pair(work)?
                } else {
                    self.fft.inv_pair(work)?
                };
                // SAFETY: the lane rows were written by the DWT stage (finished); slices `s0`
                // and `s1` of output `t` are inside the checked output and this task's
                // alone, and hold no chunk's rows still to be read (see `inverse_chain`).
                unsafe {
                    if out.is_real() {
                        self.scatter_real_pair(m, (w0, w1), &[rows]);
                    } else {
                        self.scatter_pair(m, (w0, w1), &[rows]);
                    }
                    self.slice_out(w0, out.offset(at(s0)), (watch, s0));
                    self.slice_out(w1, out.offset(at(s1)), (watch, s1));
                }
                Ok(())
            })
        })?;
        let tasks = self.slice_tasks(ch, batch.count);
        tasks.par_iter().try_for_each(|&(t, jj, upper, s)| {
            self.with_work(|work| {
                let rows = Self::lane_rows(m, (buf.get(), t * per_t), ch, (jj, upper));
                let at = t * batch.out_dist + s * slice_len;
                let w = if out.is_real() {
                    self.fft.half_buf(work)?
                } else {
                    self.fft.inv_buf(work)?
                };
                // SAFETY: as for the pairs above, for slice `s` of output `t`.
                unsafe {
                    if out.is_real() {
                        self.scatter_real(m, w, &[rows]);
                    } else {
                        self.scatter(m, w, &[rows]);
                    }
                    self.slice_out(w, out.offset(at), (watch, s));
                }
                Ok(())
            })
        })
    }

    /// The slice DFT of an inverse from the work buffer `w` (filled by a scatter) into the
    /// slice at `out`, shown to `watch` as slice `s` if given.
    ///
    /// # Safety
    /// `out` is valid for writes of one slice, nobody else's meanwhile; `w` is the work
    /// buffer of `out`'s kind (half buffer for the real kinds).
    pub(super) unsafe fn slice_out(
        &self,
        w: &mut [Complex<T>],
        out: Data<T>,
        (watch, s): (Option<SliceWatch<T>>, usize),
    ) {
        let bound = watch.map(|f| move |r: SliceRef<T>| f(s, r));
        let seen = bound.as_ref().map(|f| f as &dyn Fn(SliceRef<T>));
        // SAFETY: the caller's contract.
        unsafe {
            match out {
                Data::Complex(o) => self.fft.inverse(w, o.get(), seen),
                Data::Real(o) => self.fft.inverse_real(w, o.get(), seen),
                Data::RealParts(o) => self.fft.inverse_real_parts(w, o.get(), seen),
            }
        }
    }
}
