//! Values between a slice's work buffer and its slots in the lane rows: the inverse's
//! scatters, the forward's gathers (weighted), and the FFT stage's task lists.

use super::chunks::{Engine, Members};
use super::dwt_stage::ChunkLanes;
use super::slots::{LaneRows, SlotTable};
use crate::Real;
use num_complex::Complex;

/// `z w`
#[inline(always)]
fn times<T: Real>(z: Complex<T>, w: T) -> Complex<T> {
    Complex::new(z.re * w, z.im * w)
}

/// `conj(z)`
#[inline(always)]
fn conj<T: Real>(z: Complex<T>) -> Complex<T> {
    Complex::new(z.re, -z.im)
}

impl<T: Real> Engine<T> {
    /// The FFT stage's tasks of a chunk: `(transform, pair in chunk, upper, slice)` for
    /// every slice the chunk's pairs write.
    pub(super) fn slice_tasks(
        &self,
        ch: ChunkLanes,
        count: usize,
    ) -> Vec<(usize, usize, bool, usize)> {
        let mut v = Vec::new();
        for t in 0..count {
            for jj in (0..ch.h).filter(|&jj| !self.paired(ch, jj)) {
                for (u, &s) in self.pairs.outputs[ch.j0 + jj].iter().enumerate() {
                    if s != usize::MAX {
                        v.push((t, jj, u == 1, s));
                    }
                }
            }
        }
        v
    }

    /// Whether the inverse writes both slices of pair `jj` of `ch` (in one task).
    pub(super) fn paired(&self, ch: ChunkLanes, jj: usize) -> bool {
        !self.pairs.outputs[ch.j0 + jj].contains(&usize::MAX)
    }

    /// The inverse's tasks of a chunk that write a slice and its mirror:
    /// `(transform, pair in chunk, [lower slice, upper slice])`.
    pub(super) fn pair_tasks(
        &self,
        ch: ChunkLanes,
        count: usize,
    ) -> Vec<(usize, usize, [usize; 2])> {
        let mut v = Vec::new();
        for t in 0..count {
            for jj in (0..ch.h).filter(|&jj| self.paired(ch, jj)) {
                v.push((t, jj, self.pairs.outputs[ch.j0 + jj]));
            }
        }
        v
    }

    /// Calls `f(lower, upper, index)` for every slot of `parts` (`real`: the real table's
    /// entries and half-buffer indices, flags included): `lower` points at the slot's two
    /// doubles that belong to the lower point's slice, `upper` at the upper slice's (the
    /// own row for a direct member, the mirror row for a reversed one, and the other way).
    #[inline(always)]
    pub(super) fn for_each_pair_slot(
        m: Members<T>,
        parts: &[LaneRows<T>],
        real: bool,
        mut f: impl FnMut(*mut T, *mut T, u32),
    ) {
        for rows in parts {
            let table = if real {
                m.slots.real_of(rows.clusters)
            } else {
                m.slots.of(rows.clusters)
            };
            for &(at, idx) in table {
                let off = (at & !SlotTable::MIRROR) as usize;
                let (own, mirror) = (rows.own.wrapping_add(off), rows.mirror.wrapping_add(off));
                if at & SlotTable::MIRROR != 0 {
                    f(mirror, own, idx);
                } else {
                    f(own, mirror, idx);
                }
            }
        }
    }

    /// [`Engine::scatter`] of a slice and its mirror at once (complex): from the lane
    /// rows of `parts` (own: the lower point's, mirror: the upper point's) into `w0` (the
    /// lower slice) and `w1` (the upper one), each lane row and table entry read once.
    ///
    /// # Safety
    /// As for [`Engine::scatter`].
    pub(crate) unsafe fn scatter_pair(
        &self,
        m: Members<T>,
        (w0, w1): (&mut [Complex<T>], &mut [Complex<T>]),
        parts: &[LaneRows<T>],
    ) {
        self.clear_inverse_buffer(w0);
        self.clear_inverse_buffer(w1);
        Self::for_each_pair_slot(m, parts, false, |lo, hi, work| {
            // SAFETY: the slot's two doubles in both lane rows of the part (the table holds
            // the offsets of `dwt.clusters`' slots).
            unsafe {
                w0[work as usize] = Complex::new(*lo, *lo.add(1));
                w1[work as usize] = Complex::new(*hi, *hi.add(1));
            }
        });
    }

    /// [`Engine::scatter_real`] of a slice and its mirror at once, as
    /// [`Engine::scatter_pair`].
    ///
    /// # Safety
    /// As for [`Engine::scatter`].
    pub(crate) unsafe fn scatter_real_pair(
        &self,
        m: Members<T>,
        (w0, w1): (&mut [Complex<T>], &mut [Complex<T>]),
        parts: &[LaneRows<T>],
    ) {
        self.clears[1].apply(w0);
        self.clears[1].apply(w1);
        Self::for_each_pair_slot(m, parts, true, |lo, hi, idx| {
            if idx & SlotTable::CONJ == 0 {
                // SAFETY: as in `scatter_pair`.
                unsafe {
                    w0[idx as usize] = Complex::new(*lo, -*lo.add(1));
                    w1[idx as usize] = Complex::new(*hi, -*hi.add(1));
                }
            }
        });
    }

    /// [`Engine::gather`] of a slice and its mirror at once (`w0` the lower slice's
    /// values, `w1` the upper one's) into the pair's lane rows in `parts` (own: the lower
    /// point's, mirror: the upper point's), each slot read once.
    ///
    /// # Safety
    /// As for [`Engine::gather`]; both lane rows of every part are the caller's.
    pub(crate) unsafe fn gather_pair(
        &self,
        m: Members<T>,
        (w0, w1): (&[Complex<T>], &[Complex<T>]),
        parts: &[LaneRows<T>],
        weight: T,
    ) {
        Self::for_each_pair_slot(m, parts, false, |lo, hi, work| {
            let (v0, v1) = (
                times(w0[work as usize], weight),
                times(w1[work as usize], weight),
            );
            // SAFETY: the slot's two doubles in both lane rows (the table holds the offsets
            // of `dwt.clusters`' slots), the caller's.
            unsafe { (*lo, *lo.add(1), *hi, *hi.add(1)) = (v0.re, v0.im, v1.re, v1.im) };
        });
    }

    /// [`Engine::gather_real`] of a slice and its mirror at once, as
    /// [`Engine::gather_pair`].
    ///
    /// # Safety
    /// As for [`Engine::gather_pair`].
    pub(crate) unsafe fn gather_real_pair(
        &self,
        m: Members<T>,
        (w0, w1): (&[Complex<T>], &[Complex<T>]),
        parts: &[LaneRows<T>],
        weight: T,
    ) {
        Self::for_each_pair_slot(m, parts, true, |lo, hi, idx| {
            let value = |w: &[Complex<T>]| {
                let v = if idx & SlotTable::CONJ != 0 {
                    w[(idx & !SlotTable::CONJ) as usize]
                } else {
                    conj(w[idx as usize])
                };
                times(v, weight)
            };
            let (v0, v1) = (value(w0), value(w1));
            // SAFETY: as in `gather_pair`.
            unsafe { (*lo, *lo.add(1), *hi, *hi.add(1)) = (v0.re, v0.im, v1.re, v1.im) };
        });
    }

    /// The lane rows of a slice (its own, and its mirror's, where its reversed members
    /// are) in the chunk buffer at `buf`, transform offset `at`.
    pub(crate) fn lane_rows(
        m: Members<T>,
        (buf, at): (*mut T, usize),
        ch: ChunkLanes,
        (jj, upper): (usize, bool),
    ) -> LaneRows<T> {
        let lower = buf.wrapping_add(at + jj * m.dwt.row_stride);
        let mirror = lower.wrapping_add(ch.upper_gap);
        let (own, mirror) = if upper {
            (mirror, lower)
        } else {
            (lower, mirror)
        };
        LaneRows {
            own,
            mirror,
            clusters: (0, m.dwt.clusters.len()),
        }
    }

    /// Zeroes what the complex inverse's work buffer `w` holds from the previous slice
    /// where this slice places no value (see [`Clear`](super::slots::Clear)).
    pub(super) fn clear_inverse_buffer(&self, w: &mut [Complex<T>]) {
        self.clears[0].apply(w);
    }

    /// Complex inverse: a slice's values from its lane rows into the inverse's work buffer
    /// (whose columns `|M'| <= N` are cleared first; the others stay zero).
    ///
    /// # Safety
    /// Each part's lane rows hold its clusters' slots, written by the DWT stage.
    pub(crate) unsafe fn scatter(&self, m: Members<T>, w: &mut [Complex<T>], rows: &[LaneRows<T>]) {
        self.clear_inverse_buffer(w);
        for part in rows {
            for &(at, work) in m.slots.of(part.clusters) {
                let x = part.at(at);
                // SAFETY: the slot's two doubles are inside the part's lane row (the table
                // holds the offsets of `dwt.clusters`' slots).
                w[work as usize] = unsafe { Complex::new(*x, *x.add(1)) };
            }
        }
    }

    /// Real inverse: `conj` of a slice's values with `M' >= 0` into the half buffer.
    ///
    /// # Safety
    /// As for [`Engine::scatter`].
    pub(crate) unsafe fn scatter_real(
        &self,
        m: Members<T>,
        w: &mut [Complex<T>],
        rows: &[LaneRows<T>],
    ) {
        self.clears[1].apply(w);
        for part in rows {
            for &(at, idx) in m.slots.real_of(part.clusters) {
                if idx & SlotTable::CONJ != 0 {
                    continue;
                }
                let x = part.at(at);
                // SAFETY: as in `scatter`.
                w[idx as usize] = unsafe { Complex::new(*x, -*x.add(1)) };
            }
        }
    }

    /// Forward: a slice's values (the forward's work buffer), times its weight, into
    /// its slots of the lane rows.
    ///
    /// # Safety
    /// As for [`Engine::scatter`], for writes; no other task writes these slots.
    pub(crate) unsafe fn gather(
        &self,
        m: Members<T>,
        w: &[Complex<T>],
        rows: &[LaneRows<T>],
        weight: T,
    ) {
        for part in rows {
            for &(at, work) in m.slots.of(part.clusters) {
                let v = times(w[work as usize], weight);
                let x = part.at(at);
                // SAFETY: as in `scatter`; these slots are this task's (caller's contract).
                unsafe {
                    *x = v.re;
                    *x.add(1) = v.im;
                }
            }
        }
    }

    /// Real forward: as [`Engine::gather`], from the half spectrum `C` (see the FFT
    /// stage): `F(M, M') = conj(C[M][M'])` for `M' >= 0`, `C[-M][-M']` below.
    ///
    /// # Safety
    /// As for [`Engine::gather`].
    pub(crate) unsafe fn gather_real(
        &self,
        m: Members<T>,
        w: &[Complex<T>],
        rows: &[LaneRows<T>],
        weight: T,
    ) {
        for part in rows {
            for &(at, idx) in m.slots.real_of(part.clusters) {
                let v = times(
                    if idx & SlotTable::CONJ != 0 {
                        w[(idx & !SlotTable::CONJ) as usize]
                    } else {
                        conj(w[idx as usize])
                    },
                    weight,
                );
                let x = part.at(at);
                // SAFETY: as in `gather`.
                unsafe {
                    *x = v.re;
                    *x.add(1) = v.im;
                }
            }
        }
    }

    /// Zero the padding lane rows (`h..hp` of each half) of one transform's chunk rows at
    /// `rows`, which the forward kernel multiplies by exact zeros.
    ///
    /// # Safety
    /// The chunk's `2 hp` lane rows at `rows` are the caller's.
    pub(crate) unsafe fn zero_padding(m: Members<T>, rows: *mut T, ch: ChunkLanes) {
        let rt = m.dwt.row_stride;
        for half in [0, ch.upper_gap] {
            // SAFETY: lane rows `h..hp` of the half, inside the chunk's rows.
            unsafe { std::ptr::write_bytes(rows.add(half + ch.h * rt), 0, (ch.hp - ch.h) * rt) };
        }
    }
}
