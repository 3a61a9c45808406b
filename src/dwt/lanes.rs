//! The kernels' inputs besides the data: recurrence coefficients ([`Rec`]), per-lane
//! inputs and the data layout ([`Lanes`]), prefetch hints ([`Prefetch`]).

use crate::numeric::Elem;
use crate::wigner::{RecCoeffs, REC_PAD};

/// Recurrence coefficients of one cluster, index `i = l - l0`, for the scaled values
/// `e_i` of `RecTables::coeffs`: `e_{i+1} = (A'_i x + C'_i) e_i - e_{i-1}`. Each slice
/// holds [`REC_PAD`] finite values past the `n` degrees (what the forward kernel's last
/// block steps through).
pub struct Rec<'a, E = f64> {
    /// `A'_i`
    pub a: &'a [E],
    /// `-A'_i`
    pub neg_a: &'a [E],
    /// `A'_i + C'_i`
    pub a_plus_c: &'a [E],
    /// `C'_i - A'_i`
    pub c_minus_a: &'a [E],
    n: usize,
}

impl<'a, E: Elem> Rec<'a, E> {
    /// The first `n` degrees of `r`.
    pub fn new(r: &'a RecCoeffs<E>, n: usize) -> Rec<'a, E> {
        assert!(n <= r.len());
        let end = n + REC_PAD;
        Rec {
            a: &r.a[..end],
            neg_a: &r.neg_a[..end],
            a_plus_c: &r.a_plus_c[..end],
            c_minus_a: &r.c_minus_a[..end],
            n,
        }
    }

    /// Number of degrees.
    pub(crate) fn len(&self) -> usize {
        self.n
    }

    /// Whether every slice holds the `n` degrees and the padding.
    pub(crate) fn padded(&self) -> bool {
        [self.a, self.neg_a, self.a_plus_c, self.c_minus_a]
            .iter()
            .all(|v| v.len() == self.n + REC_PAD)
    }
}

/// Per-lane inputs: recurrence argument `tau`, scaled starting value and scale index (see
/// the `wigner::starts` module).
/// Lengths are a multiple of the vector width (pad with zeros). Vectors starting before
/// `upper_from` are in the lower half (`beta < pi/2`, `tau = 1 - cos beta`), the others in
/// the upper half (`tau = 1 + cos beta`): the recurrence multiplier `A cos(beta) + C` is
/// formed as `(A + C) - A tau` or `A tau + (C - A)`, never from a rounded `cos(beta)`,
/// which near the poles would shift beta and move `d^l` by up to `l^2 eps`.
pub struct Lanes<'a, E = f64> {
    /// Recurrence argument `1 - cos beta` (lower half) or `1 + cos beta` (upper half).
    pub tau: &'a [E],
    /// Scaled starting value (`wigner::starts::to_scaled`).
    pub p: &'a [E],
    /// Scale index of the starting value (`<= 0`).
    pub sc: &'a [E],
    /// First lane of the upper half.
    pub upper_from: usize,
    /// Rescale threshold of the scaled values, `wigner::big(skip bits)`.
    pub big: E,
    /// Skip the degrees where no lane of a vector is active yet (`false` only to measure
    /// what skipping saves: inactive lanes then accumulate exact zeros).
    pub skip: bool,
    /// Row of lane `u` in the data arrays: `u`, or, interleaved, `2u` for `u < upper_from`
    /// and `2(u - upper_from) + 1` above, so that with `2 upper_from` lanes, lanes `u` and
    /// `u + upper_from` (a beta and its mirror, see `plan/blocks.rs`) are adjacent (a
    /// partial plan's split selections use other counts of lower lanes).
    pub interleaved: bool,
    /// Memory to prefetch into L2 while the kernel runs, a few lines at a time (the next
    /// cluster's block and coefficient rows); hints only, never read.
    pub prefetch: Prefetch,
    /// Inverse: write the output with non-temporal stores (for outputs far larger than
    /// the caches, read back only later; ordinary stores would first read every line).
    pub stream: bool,
    /// Interleaved only: values from one pair of rows (`2j`, `2j + 1`) of the inverse's
    /// output or the forward's input (`forward_raw`) to the next; row `r` is at
    /// `(r / 2) * pair_stride + (r % 2) * row_gap`. 0 means `2P`, rows one after another.
    pub pair_stride: usize,
    /// With `pair_stride`: values from row `2j` to row `2j + 1` (0 means `P`, side by
    /// side). Far larger in the half-major and split layouts of `plan/blocks.rs`, where
    /// the low-beta rows and the mirror rows are in two separate halves, and in a partial
    /// plan's lane-major chunks (`engine/dwt_stage.rs`).
    pub row_gap: usize,
}

/// Up to [`Prefetch::MAX`] address ranges to be prefetched gradually; a range is a run of
/// 64-byte lines, or several such runs a fixed stride apart (rows of a lane-major buffer).
#[derive(Clone, Copy)]
pub struct Prefetch {
    /// `(start, lines per run, bytes from one run to the next, runs)`.
    ranges: [(*const u8, usize, usize, usize); Prefetch::MAX],
    n: usize,
    /// Position: range index, run within it, line within the run.
    at: (usize, usize, usize),
}

impl Prefetch {
    const MAX: usize = 10;

    /// Nothing to prefetch.
    pub fn none() -> Prefetch {
        Prefetch {
            ranges: [(std::ptr::null(), 0, 0, 0); Prefetch::MAX],
            n: 0,
            at: (0, 0, 0),
        }
    }

    /// Add `len` values from `p` (ignored beyond [`Prefetch::MAX`] ranges).
    pub fn push<T>(&mut self, p: *const T, len: usize) {
        self.push_rows(p, len, (0, 1));
    }

    /// Add `rows` runs of `len` values, the first at `p`, each `stride` values after the
    /// one before (ignored beyond [`Prefetch::MAX`] ranges).
    pub fn push_rows<T>(&mut self, p: *const T, len: usize, (stride, rows): (usize, usize)) {
        let size = std::mem::size_of::<T>();
        if self.n < Prefetch::MAX && len > 0 && rows > 0 {
            self.ranges[self.n] = (
                p as *const u8,
                (len * size).div_ceil(64),
                size * stride,
                rows,
            );
            self.n += 1;
        }
    }

    /// Lines in all ranges.
    pub(crate) fn lines(&self) -> usize {
        self.ranges[..self.n].iter().map(|r| r.1 * r.3).sum()
    }

    /// Issue the next `k` prefetches (into L2).
    #[inline(always)]
    pub(crate) fn issue(&mut self, mut k: usize) {
        while k > 0 && self.at.0 < self.n {
            let (p, len, stride, rows) = self.ranges[self.at.0];
            let line = p.wrapping_add(self.at.1 * stride + 64 * self.at.2);
            #[cfg(target_arch = "x86_64")]
            // SAFETY: a prefetch is a hint that never faults, whatever the address; SSE is part
            // of x86-64.
            unsafe {
                use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T1};
                _mm_prefetch::<_MM_HINT_T1>(line as *const i8);
            }
            #[cfg(not(target_arch = "x86_64"))]
            let _ = line;
            self.at.2 += 1;
            if self.at.2 >= len {
                self.at.2 = 0;
                self.at.1 += 1;
                if self.at.1 >= rows {
                    self.at = (self.at.0 + 1, 0, 0);
                }
            }
            k -= 1;
        }
    }
}

impl<E> Lanes<'_, E> {
    /// Interleaved rows: values from one pair of rows to the next and from row `2j` to
    /// row `2j + 1` (`pair_stride`, `row_gap` with their defaults for `P` values a row).
    #[inline(always)]
    pub(crate) fn pair_layout(&self, p: usize) -> (usize, usize) {
        let ps = if self.pair_stride == 0 {
            2 * p
        } else {
            self.pair_stride
        };
        (ps, if self.row_gap == 0 { p } else { self.row_gap })
    }

    /// Panics unless the rows of the `tau.len()` lanes (`p` values each) cannot overlap:
    /// consecutive, the two rows of a pair side by side, or the second rows of all pairs
    /// after the first rows (the split layouts of `plan/blocks.rs`).
    pub(crate) fn assert_rows_apart(&self, p: usize) {
        let (ps, gap, nb) = (self.pair_stride, self.row_gap, self.tau.len());
        assert!(ps == 0 || self.interleaved);
        assert!(gap == 0 || ps > 0);
        assert!(gap > 0 || ps == 0 || ps >= 2 * p);
        // Lower rows `u ps` (`u < upper_from`), upper rows `gap + u ps`.
        let uf = self.upper_from;
        assert!(gap == 0 || (ps >= p && (gap == p || uf >= nb || gap >= uf * ps)));
        // A gap of one row with pairs closer than two rows leaves room for one pair only.
        assert!(gap != p || ps >= 2 * p || nb <= 2);
    }

    /// Offset (in values) of the first row of the vector of lanes starting at `s0`, rows of
    /// `p` values addressed as the data layout says, and the offset from one of its rows
    /// to the next.
    #[inline(always)]
    pub(crate) fn vector_rows(&self, s0: usize, p: usize) -> (usize, usize) {
        let (r0, step) = self.rows(s0);
        if step == 2 {
            let (pair_stride, row_gap) = self.pair_layout(p);
            ((r0 / 2) * pair_stride + (r0 % 2) * row_gap, pair_stride)
        } else {
            (r0 * p, p)
        }
    }

    /// First row and row step (in rows) of the vector of lanes starting at `s0`.
    #[inline(always)]
    pub(crate) fn rows(&self, s0: usize) -> (usize, usize) {
        if !self.interleaved {
            (s0, 1)
        } else if s0 < self.upper_from {
            (2 * s0, 2)
        } else {
            (2 * (s0 - self.upper_from) + 1, 2)
        }
    }
}
