//! The moves between the transformed slices of a group of mirrored pairs and the rows of
//! every cluster's block in the chunk buffer (see `blocks.rs`): the forward's weighted
//! scatter, written as whole cache lines with non-temporal stores, and the inverse's
//! gather, with prefetches ahead of both.

use super::blocks::{Blocks, BufLayout, ChunkBuf, NONE};
use super::shared::SendPtr;
use num_complex::Complex64;

/// Most pairs per group (the row buffers of [`scatter_group`] hold `2 * MAX_GROUP` rows).
pub(super) const MAX_GROUP: usize = 4;

/// The slices of a group of mirrored pairs and where their rows are in the blocks.
pub(super) struct SliceGroup<'a> {
    /// The group's transformed slices: beta, mirror, beta, mirror, ...
    pub slices: &'a [SendPtr<Complex64>],
    /// Forward: the weight of each slice (quadrature weight and normalisation); unused by
    /// the inverse.
    pub weights: &'a [f64],
    /// The group's first pair in its chunk (block rows `2 first_pair ..`).
    pub first_pair: usize,
}

/// Clusters ahead whose slice values [`prefetch_slots`] requests.
const PREFETCH_SLOTS: usize = 8;

/// Prefetch the slice values of cluster `c`'s slots in the slices `sp` (into L2 for
/// reading, into L1 for writing with `write`): the slots of a cluster lie in different
/// rows of the slices, which from B = 256 on are larger than L2.
///
/// # Safety
/// `c < t.len()`.
#[inline(always)]
unsafe fn prefetch_slots(t: &Blocks, c: usize, sp: &[SendPtr<Complex64>], write: bool) {
    // SAFETY: `c < t.len()` (caller), so the slot indices `8c..8c+8` are in the
    // table; prefetches are hints and never fault.
    unsafe {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::{_mm_prefetch, _MM_HINT_ET0, _MM_HINT_T1};
            for q in 0..t.row_len(c) / 2 {
                let idx = *t.slot_index.get_unchecked(8 * c + q);
                if idx == NONE {
                    continue;
                }
                for s in sp {
                    let a = s.get().wrapping_add(idx as usize) as *const i8;
                    if write {
                        _mm_prefetch::<_MM_HINT_ET0>(a);
                    } else {
                        _mm_prefetch::<_MM_HINT_T1>(a);
                    }
                }
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        let _ = (t, c, sp, write);
    }
}

/// Write the rows of the group's pairs (rows `2 first_pair ..`, where the buffer's layout
/// puts them, see `plan/blocks.rs`) of the blocks of clusters `cs` from the group's
/// transformed slices (beta, then pi - beta, for each pair), scaled by their weights (and
/// conjugated with `conj`): the first row of a pair takes each slot from its own slice,
/// the second from the other one; reversed slots the other way round. Unused slots are
/// zero.
///
/// # Safety
/// The group's slices are valid for every index in the slot tables; `buf` holds the blocks
/// of `t`, 64-byte aligned, and nobody else writes these rows meanwhile.
// Always inlined: the real path's call (one pair, conjugated, every cluster) then compiles
// for its fixed slice count and `conj`, without the general loops' bookkeeping.
#[inline(always)]
pub(super) unsafe fn scatter_group(
    t: &Blocks,
    group: &SliceGroup,
    conj: bool,
    buf: ChunkBuf,
    cs: std::ops::Range<usize>,
) {
    // SAFETY: the caller's contract (above): the slices hold every slot index of `t`,
    // `buf` holds the blocks, and the rows written are the caller's alone.
    unsafe {
        let (s, w, j0) = (group.slices, group.weights, group.first_pair);
        let (buf, layout) = (buf.base.get(), buf.layout);
        let ns = s.len();
        debug_assert!(ns.is_multiple_of(2) && ns <= 2 * MAX_GROUP && w.len() == ns);
        let mut sp = [std::ptr::null::<Complex64>(); 2 * MAX_GROUP];
        let (mut wr, mut wi) = ([0.0; 2 * MAX_GROUP], [0.0; 2 * MAX_GROUP]);
        for i in 0..ns {
            sp[i] = s[i].get();
            (wr[i], wi[i]) = (w[i], if conj { -w[i] } else { w[i] });
        }
        // Rows of the irregular blocks (each block clears only the part it uses) and of the
        // regular ones (written in full), made once per call, not per block.
        let mut rows = [0.0f64; 16 * 2 * MAX_GROUP];
        let mut regular_rows = [Complex64::new(0.0, 0.0); 8 * 2 * MAX_GROUP];
        let end = cs.end;
        for c in cs {
            if t.prefetch_slices && c + PREFETCH_SLOTS < end {
                prefetch_slots(t, c + PREFETCH_SLOTS, s, false);
            }
            let p = t.row_len(c);
            let reversed = t.reversed[c];
            let (at, ps, gap) = t.pair_rows(c, j0, layout);
            let dst = (buf.add(at), ps, gap);
            if t.regular[c] {
                // The common case (`Blocks::regular`), written out.
                match p {
                    16 => {
                        scatter_regular::<8>(t, c, (&sp[..ns], &wr), conj, dst, &mut regular_rows)
                    }
                    _ => scatter_regular::<4>(t, c, (&sp[..ns], &wr), conj, dst, &mut regular_rows),
                }
                continue;
            }
            rows[..ns * p].fill(0.0);
            for q in 0..p / 2 {
                let idx = *t.slot_index.get_unchecked(8 * c + q);
                if idx == NONE {
                    continue;
                }
                let idx = idx as usize;
                let r = ((reversed >> q) & 1) as usize;
                for jj in 0..ns / 2 {
                    let (a, b) = (*sp[2 * jj].add(idx), *sp[2 * jj + 1].add(idx));
                    let (ra, rb) = ((2 * jj + r) * p + 2 * q, (2 * jj + 1 - r) * p + 2 * q);
                    rows[ra] = a.re * wr[2 * jj];
                    rows[ra + 1] = a.im * wi[2 * jj];
                    rows[rb] = b.re * wr[2 * jj + 1];
                    rows[rb + 1] = b.im * wi[2 * jj + 1];
                }
            }
            store_rows(dst, &rows[..ns * p], p);
        }
        fence();
    }
}

/// Store the rows of `p` doubles of a group of pairs (low-beta row and mirror row of each
/// pair in turn) at `(dst, ps, gap)` from [`Blocks::pair_rows`]: row `2j` at
/// `dst + j * ps`, row `2j + 1` `gap` further; in one piece where they are consecutive.
///
/// # Safety
/// `dst` holds `rows.len() / p` rows of `p` doubles, row `2j` at `dst + j ps` and row
/// `2j + 1` `gap` further, 64-byte aligned and written by no one else meanwhile.
#[inline(always)]
unsafe fn store_rows((dst, ps, gap): (*mut f64, usize, usize), rows: &[f64], p: usize) {
    // SAFETY: the caller's contract: the rows lie in the block at `dst`, 64-byte aligned.
    unsafe {
        if ps == 2 * p && gap == p {
            return stream_rows(dst, rows);
        }
        for (k, row) in rows.chunks_exact(p).enumerate() {
            stream_rows(dst.add((k / 2) * ps + (k % 2) * gap), row);
        }
    }
}

/// Prefetch `lines` cache lines from `a` into L1 (hints only: `a` may point past the
/// buffer).
#[inline(always)]
fn prefetch_lines(a: *const f64, lines: usize) {
    #[cfg(target_arch = "x86_64")]
    for line in 0..lines {
        use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
        // SAFETY: a prefetch is a hint; it never faults.
        unsafe { _mm_prefetch::<_MM_HINT_T0>((a as *const i8).wrapping_add(64 * line)) };
    }
    #[cfg(not(target_arch = "x86_64"))]
    let _ = (a, lines);
}

/// Clusters ahead whose rows [`gather_group`] prefetches in the cluster-major layout
/// (blocks in the cache).
const PREFETCH_CLUSTERS: usize = 16;

/// Bytes ahead of its reads in the half-major buffer that [`gather_group`] prefetches.
/// The hardware prefetchers follow the sequential reads, but not far enough ahead.
const GATHER_AHEAD: usize = 4096;

/// The reverse of [`scatter_group`] without weights, from a buffer of any layout (blocks,
/// or the half-major layout of a large inverse, see `plan/blocks.rs`): slots of the rows of
/// the group's pairs into its slices (conjugated with `conj`; the real layout's second
/// index (`Blocks::slot_neg_index`) gets the value itself).
///
/// # Safety
/// As for [`scatter_group`], with the slices written (their slots of clusters `cs` by no
/// one else) and the rows read.
// Always inlined, for the reason given at `scatter_group`.
#[inline(always)]
pub(super) unsafe fn gather_group(
    t: &Blocks,
    group: &SliceGroup,
    conj: bool,
    buf: ChunkBuf,
    cs: std::ops::Range<usize>,
) {
    // SAFETY: the caller's contract (above): `buf` holds the blocks of `t`, the slices
    // every slot index, and no one else writes the slots of these clusters.
    unsafe {
        let (s, j0) = (group.slices, group.first_pair);
        let (buf, layout) = (buf.base.get() as *const f64, buf.layout);
        let ns = s.len();
        debug_assert!(ns.is_multiple_of(2) && ns <= 2 * MAX_GROUP);
        let mut sp = [std::ptr::null_mut::<Complex64>(); 2 * MAX_GROUP];
        for i in 0..ns {
            sp[i] = s[i].get();
        }
        let end = cs.end;
        for c in cs {
            if t.prefetch_slices && c + PREFETCH_SLOTS < end {
                prefetch_slots(t, c + PREFETCH_SLOTS, s, true);
            }
            let p = t.row_len(c);
            let (at, ps, gap) = t.pair_rows(c, j0, layout);
            let row = buf.add(at);
            match layout {
                // The rows of a cluster further on.
                BufLayout::Blocks => {
                    let cf = c + PREFETCH_CLUSTERS;
                    if cf < end {
                        let (at, _, _) = t.pair_rows(cf, j0, layout);
                        prefetch_lines(buf.wrapping_add(at), ns * t.row_len(cf) / 8);
                    }
                }
                // The same distance ahead in the sequential run of each half.
                BufLayout::Split(_) | BufLayout::HalfMajor(_) => {
                    for half in [row, row.wrapping_add(gap)] {
                        let a = half.wrapping_add(GATHER_AHEAD / 8);
                        prefetch_lines(a, (ns * p / 16).max(1));
                    }
                }
            }
            let reversed = t.reversed[c];
            if t.regular[c] {
                // The common case (`Blocks::regular`), written out.
                match p {
                    16 => gather_regular::<8>(t, c, &sp[..ns], conj, (row, ps, gap)),
                    _ => gather_regular::<4>(t, c, &sp[..ns], conj, (row, ps, gap)),
                }
                continue;
            }
            for q in 0..p / 2 {
                let idx = *t.slot_index.get_unchecked(8 * c + q);
                if idx == NONE {
                    continue;
                }
                let idx = idx as usize;
                let neg_idx = *t.slot_neg_index.get_unchecked(8 * c + q);
                let r = ((reversed >> q) & 1) as usize;
                for jj in 0..ns / 2 {
                    let (ra, rb) = (jj * ps + r * gap + 2 * q, jj * ps + (1 - r) * gap + 2 * q);
                    let a = Complex64::new(*row.add(ra), *row.add(ra + 1));
                    let b = Complex64::new(*row.add(rb), *row.add(rb + 1));
                    let (s0, s1) = (sp[2 * jj], sp[2 * jj + 1]);
                    if conj {
                        *s0.add(idx) = a.conj();
                        *s1.add(idx) = b.conj();
                        if neg_idx != NONE {
                            *s0.add(neg_idx as usize) = a;
                            *s1.add(neg_idx as usize) = b;
                        }
                    } else {
                        *s0.add(idx) = a;
                        *s1.add(idx) = b;
                    }
                }
            }
        }
    }
}

/// [`scatter_group`] for a regular block of `S` slots (`Blocks::regular`): slots below
/// `S/2` from the own slice, the others from the mirrored one.
///
/// # Safety
/// `c < t.len()`; `sp` are valid for every slot index of cluster `c`; `dst` as for
/// [`store_rows`], with room for `sp.len()` rows of `2S` doubles.
#[inline(always)]
unsafe fn scatter_regular<const S: usize>(
    t: &Blocks,
    c: usize,
    (sp, w): (&[*const Complex64], &[f64]),
    conj: bool,
    dst: (*mut f64, usize, usize),
    rows: &mut [Complex64; 8 * 2 * MAX_GROUP],
) {
    // SAFETY: `c < t.len()`, and the caller's contract for the slices and rows.
    unsafe {
        let f: [usize; S] =
            std::array::from_fn(|q| *t.slot_index.get_unchecked(8 * c + q) as usize);
        let (h, ns) = (S / 2, sp.len());
        for jj in 0..ns / 2 {
            let (s0, s1) = (sp[2 * jj], sp[2 * jj + 1]);
            let (w0, w1) = (w[2 * jj], w[2 * jj + 1]);
            let (lo, hi) = (2 * S * jj, 2 * S * jj + S);
            for q in 0..h {
                rows[lo + q] = *s0.add(f[q]) * w0;
                rows[hi + q] = *s1.add(f[q]) * w1;
                rows[hi + h + q] = *s0.add(f[h + q]) * w0;
                rows[lo + h + q] = *s1.add(f[h + q]) * w1;
            }
        }
        if conj {
            for z in &mut rows[..ns * S] {
                *z = z.conj();
            }
        }
        store_rows(
            dst,
            std::slice::from_raw_parts(rows.as_ptr() as *const f64, ns * 2 * S),
            2 * S,
        );
    }
}

/// [`gather_group`] for a regular block of `S` slots (see [`scatter_regular`]).
///
/// # Safety
/// `c < t.len()`; `sp` are valid for writes at every slot index of cluster `c`, which no
/// one else writes; `row` holds `sp.len()` rows of `2S` doubles, row `2j` at `row + j ps`
/// and row `2j + 1` `gap` further.
#[inline(always)]
unsafe fn gather_regular<const S: usize>(
    t: &Blocks,
    c: usize,
    sp: &[*mut Complex64],
    conj: bool,
    (row, ps, gap): (*const f64, usize, usize),
) {
    // SAFETY: `c < t.len()`, and the caller's contract for the slices and rows.
    unsafe {
        let f: [usize; S] =
            std::array::from_fn(|q| *t.slot_index.get_unchecked(8 * c + q) as usize);
        let h = S / 2;
        let rows = row as *const Complex64;
        let v = |z: Complex64| if conj { z.conj() } else { z };
        for jj in 0..sp.len() / 2 {
            let (s0, s1) = (sp[2 * jj], sp[2 * jj + 1]);
            // `ps` and `gap` are even: whole complex values.
            let (lo, hi) = (rows.add(jj * ps / 2), rows.add((jj * ps + gap) / 2));
            for q in 0..h {
                *s0.add(f[q]) = v(*lo.add(q));
                *s1.add(f[q]) = v(*hi.add(q));
                *s0.add(f[h + q]) = v(*hi.add(h + q));
                *s1.add(f[h + q]) = v(*lo.add(h + q));
            }
        }
    }
}

/// Store `rows` (whole 64-byte lines at a 64-byte aligned `dst`) without reading the
/// lines first.
///
/// # Safety
/// `dst` is valid for writes of `rows.len()` doubles (an even number), not overlapping
/// `rows`, and written by no one else meanwhile.
#[inline(always)]
unsafe fn stream_rows(dst: *mut f64, rows: &[f64]) {
    // SAFETY: `dst` is valid for `rows.len()` doubles (caller), and `rows` does not
    // overlap it (a local array).
    unsafe {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::{_mm_loadu_pd, _mm_stream_pd};
            if (dst as usize).is_multiple_of(64) {
                for i in (0..rows.len()).step_by(2) {
                    _mm_stream_pd(dst.add(i), _mm_loadu_pd(rows.as_ptr().add(i)));
                }
                return;
            }
        }
        std::ptr::copy_nonoverlapping(rows.as_ptr(), dst, rows.len());
    }
}

/// Orders the non-temporal stores of [`stream_rows`] before later stores and loads.
#[inline(always)]
fn fence() {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: a store fence has no memory operands.
    unsafe {
        std::arch::x86_64::_mm_sfence()
    };
}
