//! Discrete Wigner transform kernels: the Wigner-d recurrence fused with the accumulation.
//!
//! One call handles one cluster (see `symmetry.rs`) and a list of beta points. The
//! recurrence runs in registers, vectorised over `W` betas; nothing of size
//! `(B - m) x 2B` is ever stored.
//!
//! * forward: `f[i][q] = sum_s dt_{l0+i}(beta_s) * xin[row(s)][q]` (`P` real columns `q`)
//! * inverse: `y[row(s)][q] = sum_i dt_{l0+i}(beta_s) * fin[i][q]`
//!
//! where `row(s)` is `s` or, for the chunk buffer's blocks, interleaves each beta with its
//! mirror ([`Lanes::interleaved`]).
//!
//! `P` is 16 (8 complex order pairs) or 8 (4 pairs). Each beta lane starts in the scaled
//! form of `wigner.rs`; lanes below the skip threshold contribute nothing, and while no lane
//! of a vector is active only the recurrence runs (the negligible prefix in `l` is skipped).

use crate::simd::{Isa, Scalar, Simd};
use crate::wigner::{BetaTables, Ext, RecCoeffs, RecTables, REC_PAD, SKIP_BITS_RANGE, TINY};
use std::mem::MaybeUninit;

/// Recurrence coefficients of one cluster, index `i = l - l0`, for the scaled values
/// `e_i` of `RecTables::coeffs`: `e_{i+1} = (A'_i x + C'_i) e_i - e_{i-1}`. Each slice
/// holds [`REC_PAD`] finite values past the `n` degrees (what the forward kernel's last
/// block steps through).
pub(crate) struct Rec<'a> {
    /// `A'_i`
    pub a: &'a [f64],
    /// `-A'_i`
    pub an: &'a [f64],
    /// `A'_i + C'_i`
    pub d: &'a [f64],
    /// `C'_i - A'_i`
    pub e: &'a [f64],
    n: usize,
}

impl<'a> Rec<'a> {
    /// The first `n` degrees of `r`.
    pub fn new(r: &'a RecCoeffs, n: usize) -> Rec<'a> {
        assert!(n <= r.len());
        let end = n + REC_PAD;
        Rec {
            a: &r.a[..end],
            an: &r.an[..end],
            d: &r.d[..end],
            e: &r.e[..end],
            n,
        }
    }

    fn len(&self) -> usize {
        self.n
    }

    /// Whether every slice holds the `n` degrees and the padding.
    fn padded(&self) -> bool {
        [self.a, self.an, self.d, self.e]
            .iter()
            .all(|v| v.len() == self.n + REC_PAD)
    }
}

/// Per-lane inputs: recurrence argument `tau`, scaled starting value and scale index.
/// Lengths are a multiple of the vector width (pad with zeros). Vectors starting before
/// `upper_from` are in the lower half (`beta < pi/2`, `tau = 1 - cos beta`), the others in
/// the upper half (`tau = 1 + cos beta`): the recurrence multiplier `A cos(beta) + C` is
/// formed as `(A + C) - A tau` or `A tau + (C - A)`, never from a rounded `cos(beta)`,
/// which near the poles would shift beta and move `d^l` by up to `l^2 eps`.
pub(crate) struct Lanes<'a> {
    pub tau: &'a [f64],
    pub p: &'a [f64],
    pub sc: &'a [f64],
    pub upper_from: usize,
    /// Rescale threshold of the scaled values, `wigner::big(skip bits)`.
    pub big: f64,
    /// Skip the degrees where no lane of a vector is active yet (`false` only to measure
    /// what skipping saves: inactive lanes then accumulate exact zeros).
    pub skip: bool,
    /// Row of lane `u` in the data arrays: `u`, or, interleaved, `2u` for `u < upper_from`
    /// and `2(u - upper_from) + 1` above (the lanes count `2 upper_from`), so that lanes
    /// `u` and `u + upper_from` (a beta and its mirror, see `plan/blocks.rs`) are adjacent.
    pub interleaved: bool,
    /// Memory to prefetch into L2 while the kernel runs, a few lines at a time (the next
    /// cluster's block and coefficient rows); hints only, never read.
    pub prefetch: Prefetch,
    /// Inverse: write the output with non-temporal stores (for outputs far larger than
    /// the caches, read back only later; ordinary stores would first read every line).
    pub stream: bool,
    /// Interleaved only: doubles from one pair of rows (`2j`, `2j + 1`) of the inverse's
    /// output or the forward's input (`forward_raw`) to the next; row `r` is at
    /// `(r / 2) * pair_stride + (r % 2) * row_gap`. 0 means `2P`, rows one after another.
    pub pair_stride: usize,
    /// With `pair_stride`: doubles from row `2j` to row `2j + 1` (0 means `P`, side by
    /// side). Far larger in the half-major and split layouts of `plan/blocks.rs`, where
    /// the low-beta rows and the mirror rows are in two separate halves.
    pub row_gap: usize,
}

/// Up to [`Prefetch::MAX`] address ranges to be prefetched gradually.
#[derive(Clone, Copy)]
pub(crate) struct Prefetch {
    /// `(start, 64-byte lines)`.
    ranges: [(*const u8, usize); Prefetch::MAX],
    n: usize,
    /// Position: range index and line within it.
    at: (usize, usize),
}

impl Prefetch {
    const MAX: usize = 10;

    /// Nothing to prefetch.
    pub fn none() -> Prefetch {
        Prefetch {
            ranges: [(std::ptr::null(), 0); Prefetch::MAX],
            n: 0,
            at: (0, 0),
        }
    }

    /// Add `len` doubles from `p` (ignored beyond [`Prefetch::MAX`] ranges).
    pub fn push(&mut self, p: *const f64, len: usize) {
        if self.n < Prefetch::MAX && len > 0 {
            self.ranges[self.n] = (p as *const u8, (len * 8).div_ceil(64));
            self.n += 1;
        }
    }

    /// Lines in all ranges.
    fn lines(&self) -> usize {
        self.ranges[..self.n].iter().map(|r| r.1).sum()
    }

    /// Issue the next `k` prefetches (into L2).
    #[inline(always)]
    fn issue(&mut self, mut k: usize) {
        while k > 0 && self.at.0 < self.n {
            let (p, len) = self.ranges[self.at.0];
            #[cfg(target_arch = "x86_64")]
            // SAFETY: a prefetch is a hint; it never faults.
            unsafe {
                use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T1};
                _mm_prefetch::<_MM_HINT_T1>(p.wrapping_add(64 * self.at.1) as *const i8);
            }
            #[cfg(not(target_arch = "x86_64"))]
            let _ = p;
            self.at.1 += 1;
            if self.at.1 >= len {
                self.at = (self.at.0 + 1, 0);
            }
            k -= 1;
        }
    }
}

impl Lanes<'_> {
    /// Interleaved rows: doubles from one pair of rows to the next and from row `2j` to
    /// row `2j + 1` (`pair_stride`, `row_gap` with their defaults for `P` doubles a row).
    #[inline(always)]
    fn pair_layout(&self, p: usize) -> (usize, usize) {
        let ps = if self.pair_stride == 0 {
            2 * p
        } else {
            self.pair_stride
        };
        (ps, if self.row_gap == 0 { p } else { self.row_gap })
    }

    /// Panics unless the rows of the `tau.len()` lanes (`p` doubles each) cannot overlap:
    /// consecutive, the two rows of a pair side by side, or the second rows of all pairs
    /// after the first rows (the split layouts of `plan/blocks.rs`).
    fn assert_rows_apart(&self, p: usize) {
        let (ps, gap, nb) = (self.pair_stride, self.row_gap, self.tau.len());
        assert!(ps == 0 || self.interleaved);
        assert!(gap == 0 || ps > 0);
        assert!(gap > 0 || ps == 0 || ps >= 2 * p);
        assert!(gap == 0 || (ps >= p && (gap == p || gap >= nb / 2 * ps)));
        assert!(gap != p || ps >= 2 * p);
    }

    /// First row and row step (in rows) of the vector of lanes starting at `s0`.
    #[inline(always)]
    fn rows(&self, s0: usize) -> (usize, usize) {
        if !self.interleaved {
            (s0, 1)
        } else if s0 < self.upper_from {
            (2 * s0, 2)
        } else {
            (2 * (s0 - self.upper_from) + 1, 2)
        }
    }
}

/// Recurrence state of one vector of betas.
#[derive(Clone, Copy)]
struct State<'r, S: Simd> {
    tau: S::V,
    /// `-A` (lower half) or `A` (upper half).
    ka: &'r [f64],
    /// `A + C` (lower half) or `C - A` (upper half).
    kc: &'r [f64],
    p0: S::V,
    p1: S::V,
    /// Scale index of each lane (`<= 0`, see `wigner.rs`).
    sc: S::V,
    /// 1 for the active lanes (scale index 0), else 0.
    mask: S::V,
    /// Next degree index (`l - l0`).
    i: usize,
    /// Rescale threshold (see [`Lanes::big`]).
    big: S::V,
    /// See [`Lanes::skip`].
    skip: bool,
}

impl<'r, S: Simd> State<'r, S> {
    #[inline(always)]
    unsafe fn new(rec: &Rec<'r>, lanes: &Lanes, s0: usize) -> Self {
        let sc = S::load(lanes.sc.as_ptr().add(s0));
        let p1 = S::load(lanes.p.as_ptr().add(s0));
        let (ka, kc) = if s0 >= lanes.upper_from {
            (rec.a, rec.e)
        } else {
            (rec.an, rec.d)
        };
        State {
            tau: S::load(lanes.tau.as_ptr().add(s0)),
            ka,
            kc,
            p0: S::zero(),
            p1,
            sc,
            // Active: scale index 0 and a nonzero value. Padding lanes (value 0, scale 0)
            // are neither active nor scaled down: they never hold back the skipping of
            // their vector's prefix, nor its fast phase.
            mask: S::mul(
                S::blend_ge(sc, S::zero(), S::splat(1.0), S::zero()),
                S::blend_ge(
                    S::abs(p1),
                    S::splat(f64::MIN_POSITIVE),
                    S::splat(1.0),
                    S::zero(),
                ),
            ),
            i: 0,
            big: S::splat(lanes.big),
            skip: lanes.skip,
        }
    }

    /// Whether no lane is active yet.
    #[inline(always)]
    unsafe fn none_active(&self) -> bool {
        !S::any_ge(self.mask, S::splat(0.5))
    }

    /// Whether every lane is active.
    #[inline(always)]
    unsafe fn all_active(&self) -> bool {
        !S::any_ge(S::splat(-0.5), self.sc)
    }

    /// Rescale the scaled-down lanes of `(p0, p1)` that grew past `big` by `2^-SCALE_STEP`
    /// (at most once per `2^SCALE_STEP` of growth), activating those that reach scale
    /// index 0. All in registers: with a low skip threshold nearly every lane passes
    /// through here once on its way to being active.
    #[inline(always)]
    unsafe fn rescale(&mut self, p0: &mut S::V, p1: &mut S::V) {
        let (zero, one) = (S::zero(), S::splat(1.0));
        // |p1| of the scaled-down lanes, 0 for the active ones.
        let a = S::blend_ge(self.sc, zero, zero, S::abs(*p1));
        let f = S::blend_ge(a, self.big, S::splat(TINY), one);
        *p0 = S::mul(*p0, f);
        *p1 = S::mul(*p1, f);
        let hit = S::blend_ge(a, self.big, one, zero);
        self.sc = S::add(self.sc, hit);
        // Lanes rescaled to scale index 0 become active; the others keep their state.
        self.mask = S::max(
            self.mask,
            S::mul(hit, S::blend_ge(self.sc, zero, one, zero)),
        );
    }

    /// Step without accumulating until some lane is active (or degree `n`): the rest of
    /// the negligible prefix after [`skip_inactive`], one vector at a time.
    #[inline(always)]
    unsafe fn finish_prefix(&mut self, n: usize) {
        if !self.skip {
            return;
        }
        let (mut p0, mut p1, mut i) = (self.p0, self.p1, self.i);
        while i < n && self.none_active() {
            let p2 = self.step(p0, p1, i);
            (p0, p1) = (p1, p2);
            i += 1;
            if S::any_ge(S::abs(p1), self.big) {
                self.rescale(&mut p0, &mut p1);
            }
        }
        (self.p0, self.p1, self.i) = (p0, p1, i);
    }

    /// The values of degrees `i0 .. i0 + D` (the state is at degree `i >= i0`), masked to
    /// the active lanes, zero before `i` and from `n` on; advances the state to
    /// `min(i0 + D, n)`. For the blocks where not all lanes are active yet, or which start
    /// before the state does.
    #[inline(always)]
    unsafe fn masked_block<const D: usize>(&mut self, i0: usize, n: usize) -> [S::V; D] {
        let mut d = [S::zero(); D];
        let (mut p0, mut p1, mut i) = (self.p0, self.p1, self.i);
        let end = (i0 + D).min(n);
        while i < end {
            d[i - i0] = S::mul(p1, self.mask);
            let p2 = self.step(p0, p1, i);
            (p0, p1) = (p1, p2);
            i += 1;
            if S::any_ge(S::abs(p1), self.big) {
                self.rescale(&mut p0, &mut p1);
            }
        }
        (self.p0, self.p1, self.i) = (p0, p1, i);
        d
    }

    /// One recurrence step from `(p0, p1)` at degree index `i`: the next value.
    #[inline(always)]
    unsafe fn step(&self, p0: S::V, p1: S::V, i: usize) -> S::V {
        let t = S::fma(
            S::splat(*self.ka.get_unchecked(i)),
            self.tau,
            S::splat(*self.kc.get_unchecked(i)),
        );
        S::fms(t, p1, p0)
    }

    /// Run the remaining degrees up to `n`, calling `acc(v, i)` with the value vector at
    /// each degree from the first one where some lane is active. The recurrence values
    /// live in locals (registers) throughout.
    #[inline(always)]
    unsafe fn run(&mut self, n: usize, mut acc: impl FnMut(S::V, usize)) {
        self.run_slow(n, &mut acc);
        self.run_fast(n, &mut acc);
    }

    /// The slow phase of [`State::run`]: while some lanes are still scaled down (and
    /// masked to zero), up to degree `n`.
    #[inline(always)]
    unsafe fn run_slow(&mut self, n: usize, acc: &mut impl FnMut(S::V, usize)) {
        if self.all_active() {
            return;
        }
        let mut i = self.i;
        let (mut p0, mut p1) = (self.p0, self.p1);
        let mut accumulate = !self.none_active() || !self.skip;
        while i < n {
            let v = S::mul(p1, self.mask);
            let p2 = S::fence(self.step(p0, p1, i));
            (p0, p1) = (p1, p2);
            if accumulate {
                acc(v, i);
            }
            i += 1;
            if S::any_ge(S::abs(p1), self.big) {
                self.rescale(&mut p0, &mut p1);
                accumulate = !self.none_active() || !self.skip;
                if self.all_active() {
                    break;
                }
            }
        }
        (self.p0, self.p1, self.i) = (p0, p1, i);
    }

    /// The fast phase of [`State::run`] (all lanes hold true values), up to degree `end`.
    /// The step to the next degree comes first in program order: the FMA pipes issue the
    /// oldest ready instruction, so a step placed after the accumulation would queue behind
    /// it and put its latency on the critical path at every degree (measured: 13.4 against
    /// 10.7 cycles per degree).
    #[inline(always)]
    unsafe fn run_fast(&mut self, end: usize, acc: &mut impl FnMut(S::V, usize)) {
        let mut i = self.i;
        let (mut p0, mut p1) = (self.p0, self.p1);
        while i < end {
            let v = p1;
            let p2 = S::fence(self.step(p0, p1, i));
            (p0, p1) = (p1, p2);
            acc(v, i);
            i += 1;
        }
        (self.p0, self.p1) = (p0, p1);
        self.i = i;
    }
}

/// Vectors whose recurrences are advanced together through their negligible prefix.
const GROUP: usize = 4;

/// Advance the states of `st` through the degrees where none of their lanes is active yet.
///
/// That prefix needs only the recurrence, whose one-FMA-per-degree dependency chain would
/// leave a lone vector latency-bound. While all `GROUP` vectors are in their prefix they
/// step together, held in registers, with one test per degree of whether any value has
/// reached the rescale threshold. The vectors are neighbouring betas, whose prefixes end at
/// similar degrees; once one of them has an active lane, each finishes its own prefix in
/// [`State::finish_prefix`] (forward) or [`State::run_slow`] (inverse).
#[inline(always)]
unsafe fn skip_inactive<S: Simd>(st: &mut [State<'_, S>; GROUP], rec: &Rec, n: usize) {
    if st.iter().any(|s| !s.none_active() || s.i >= n) {
        return;
    }
    let mut i = st[0].i;
    debug_assert!(st.iter().all(|s| s.i == i));
    let big = st[0].big;
    let (mut p0, mut p1, mut tau) = ([S::zero(); GROUP], [S::zero(); GROUP], [S::zero(); GROUP]);
    let (mut ka, mut kc) = ([rec.a; GROUP], [rec.a; GROUP]);
    for k in 0..GROUP {
        (p0[k], p1[k], tau[k], ka[k], kc[k]) = (st[k].p0, st[k].p1, st[k].tau, st[k].ka, st[k].kc);
    }
    loop {
        let mut hit = false;
        while i < n {
            let mut m = S::zero();
            for k in 0..GROUP {
                let t = S::fma(
                    S::splat(*ka[k].get_unchecked(i)),
                    tau[k],
                    S::splat(*kc[k].get_unchecked(i)),
                );
                let p2 = S::fms(t, p1[k], p0[k]);
                p0[k] = p1[k];
                p1[k] = p2;
                m = S::max(m, S::abs(p2));
            }
            i += 1;
            if S::any_ge(m, big) {
                hit = true;
                break;
            }
        }
        let mut activated = false;
        for k in 0..GROUP {
            if hit {
                st[k].rescale(&mut p0[k], &mut p1[k]);
                activated |= !st[k].none_active();
            }
            (st[k].p0, st[k].p1, st[k].i) = (p0[k], p1[k], i);
        }
        if !hit || activated {
            return;
        }
    }
}

/// Lane offsets of the vectors processed together, starting at `s0` (unused entries
/// repeat the last vector and are marked done).
#[inline(always)]
unsafe fn group_states<'r, S: Simd, const W: usize>(
    rec: &Rec<'r>,
    lanes: &Lanes,
    s0: usize,
    nb: usize,
    n: usize,
) -> (usize, [State<'r, S>; GROUP]) {
    let g = ((nb - s0) / W).min(GROUP);
    // Written out rather than `std::array::from_fn`, which is not inlined into the
    // `target_feature` entry points and so would call the SIMD loads out of line.
    let at = |j: usize| s0 + j.min(g - 1) * W;
    let mut st: [State<'r, S>; GROUP] = [
        State::new(rec, lanes, at(0)),
        State::new(rec, lanes, at(1)),
        State::new(rec, lanes, at(2)),
        State::new(rec, lanes, at(3)),
    ];
    for s in st.iter_mut().skip(g) {
        s.i = n;
    }
    if lanes.skip {
        skip_inactive(&mut st, rec, n);
    }
    (g, st)
}

/// The states of the `mem.len()` vectors of lanes from `v0`, each advanced through its
/// negligible prefix, written into `mem`; returns the lowest degree index any of them
/// reached (`n` if none) and the states. Both kernels set up their vectors this way
/// before touching data, so they agree on the first degree a set of betas needs.
#[inline(always)]
unsafe fn prefix_states<'m, 'r, S: Simd, const W: usize>(
    rec: &Rec<'r>,
    lanes: &Lanes,
    v0: usize,
    n: usize,
    mem: &'m mut [MaybeUninit<State<'r, S>>],
) -> (usize, &'m mut [State<'r, S>]) {
    let nv = mem.len();
    let mut g = 0;
    while g < nv {
        let (gn, group) = group_states::<S, W>(rec, lanes, v0 + g * W, v0 + nv * W, n);
        for (k, s) in group.iter().enumerate().take(gn) {
            let mut s = *s;
            s.finish_prefix(n);
            mem[g + k].write(s);
        }
        g += gn;
    }
    // SAFETY: every entry was written above (`gn >= 1` per round).
    let st = std::slice::from_raw_parts_mut(mem.as_mut_ptr() as *mut State<'r, S>, nv);
    let first = st.iter().map(|s| s.i).min().unwrap_or(n);
    (first, st)
}

/// Vectors of betas whose states the forward kernel keeps at once.
const FWD_VECTORS: usize = 16;

/// Registers for the forward kernel's sums (`DB x P / W` of them are used).
const ACC: usize = 16;

/// Small buffer for one vector's Wigner-d block (`DB` degrees x `W` betas), read back as
/// broadcasts.
#[repr(C, align(64))]
#[derive(Clone, Copy)]
struct DBlock([f64; 128]);

/// The multiply-adds of one beta lane `w` of a stored d block: for each degree `j` of the
/// block, `acc[j][h] += d[j][w] * x[h]` with `x` the `P / W` vectors of the beta's data
/// row `xw` (lane = data column) and `d[j][w]` a broadcast load.
#[inline(always)]
unsafe fn beta_fmas<S: Simd, const W: usize, const P: usize, const DB: usize>(
    acc: &mut [S::V; ACC],
    db: *const f64,
    w: usize,
    xw: *const f64,
) {
    let pv = P / W;
    let mut x = [S::zero(); P];
    for (h, xh) in x.iter_mut().enumerate().take(pv) {
        *xh = S::load(xw.add(h * W));
    }
    for j in 0..DB {
        let e = S::splat(*db.add(j * W + w));
        for h in 0..pv {
            // Pinned in program order: left alone, LLVM hoists the broadcasts of the next
            // lanes above these multiply-adds and spills them and half of the sums
            // (measured: 40% of the FMA peak against 51%).
            acc[j * pv + h] = S::fence(S::fma(e, x[h], acc[j * pv + h]));
        }
    }
}

/// Whether the forward kernel pairs betas ([`pair_fmas`]): with one vector of columns
/// (`P == W`) a broadcast d value would feed a single multiply-add.
const fn paired(w: usize, p: usize) -> bool {
    p == w && w >= 2
}

/// [`beta_fmas`] for the neighbouring lanes `w` and `w + 1` when `P == W`: one broadcast
/// of the pair `(d[j][w], d[j][w + 1])` feeds two multiply-adds, with the two beta rows
/// interleaved column by column: `acc[2j]` holds columns `0, 2, 4, ...` and `acc[2j + 1]`
/// columns `1, 3, 5, ...`, alternate lanes summing the even and the odd betas
/// ([`fold_pair`] adds them). A broadcast per multiply-add ran at about two thirds of the
/// FMA peak on Zen 5; one per two at about four fifths.
#[inline(always)]
unsafe fn pair_fmas<S: Simd, const W: usize, const DB: usize>(
    acc: &mut [S::V; ACC],
    db: *const f64,
    w: usize,
    x0: *const f64,
    x1: *const f64,
) {
    let (a, b) = (S::load(x0), S::load(x1));
    let (even, odd) = (S::unpack_even(a, b), S::unpack_odd(a, b));
    for j in 0..DB {
        let e = S::splat2(db.add(j * W + w));
        acc[2 * j] = S::fence(S::fma(e, even, acc[2 * j]));
        acc[2 * j + 1] = S::fence(S::fma(e, odd, acc[2 * j + 1]));
    }
}

/// The column sums of degree `j` from [`pair_fmas`]'s accumulators: lane `2k` of
/// `acc[2j]` and `acc[2j + 1]` holds the even betas' sums of columns `2k` and `2k + 1`,
/// lane `2k + 1` the odd betas'.
#[inline(always)]
unsafe fn fold_pair<S: Simd>(acc: &[S::V; ACC], j: usize) -> S::V {
    let (a, b) = (acc[2 * j], acc[2 * j + 1]);
    S::add(S::unpack_even(a, b), S::unpack_odd(a, b))
}

/// Lane `w`'s share of the multiply-adds of a stored d block: [`beta_fmas`], or with
/// paired betas [`pair_fmas`] for lanes `w - 1` and `w` at each odd `w` (nothing at even
/// `w`). `x` is lane 0's data row, `xs` the stride between rows.
#[inline(always)]
unsafe fn lane_fmas<S: Simd, const W: usize, const P: usize, const DB: usize>(
    acc: &mut [S::V; ACC],
    db: *const f64,
    w: usize,
    x: *const f64,
    xs: usize,
) {
    if !paired(W, P) {
        beta_fmas::<S, W, P, DB>(acc, db, w, x.add(w * xs));
    } else if w % 2 == 1 {
        pair_fmas::<S, W, DB>(acc, db, w - 1, x.add((w - 1) * xs), x.add(w * xs));
    }
}

/// All `W` lanes of a stored d block ([`lane_fmas`]).
#[inline(always)]
unsafe fn block_fmas<S: Simd, const W: usize, const P: usize, const DB: usize>(
    acc: &mut [S::V; ACC],
    db: *const f64,
    x: *const f64,
    xs: usize,
) {
    // Only the lanes that do work (each pair at its odd lane), so the loop unrolls.
    let step = if paired(W, P) { 2 } else { 1 };
    for w in (step - 1..W).step_by(step) {
        lane_fmas::<S, W, P, DB>(acc, db, w, x, xs);
    }
}

/// Forward kernel body: `ft[i][q] = sum_s dt_i(beta_s) x[s][q]`, a reduction over the
/// betas for each degree.
///
/// The loops run degree blocks (`DB` degrees) outer and beta vectors inner, so that the
/// sums of a block stay in registers while every vector of betas adds its share, and are
/// stored once per block: `DB x P / W` vectors, lane = data column (the output is
/// degree-major, the inverse kernel's input layout). Each vector's recurrence state
/// (kept in L1 between blocks) produces its `DB x W` values, which are stored to a small
/// buffer and read back as broadcasts, one per (degree, beta), each feeding `P / W`
/// multiply-adds with the beta's data row in registers: no shuffles, the same instruction
/// mix as the inverse kernel.
///
/// For the vectors whose lanes are all active, the recurrence steps of the next vector are
/// spread over the lanes of the current one (`DB / W` steps before each lane's
/// multiply-adds, in program order): the floating-point pipes issue the oldest ready
/// instruction first, so the latency-bound chain of steps never waits behind a block of
/// independent multiply-adds. The pipeline runs on from one block to the next while the
/// list of such vectors stays the same.
///
/// `DB <= W`: callers size `ft` for `n + W` degrees. Returns the lowest degree index any
/// lane reached active (rows below it are zero).
#[inline(always)]
unsafe fn forward_body<S: Simd, const W: usize, const P: usize, const DB: usize>(
    rec: &Rec,
    lanes: &Lanes,
    xin: *const f64,
    ft: &mut [f64],
) -> usize {
    let n = rec.len();
    let nb = lanes.tau.len();
    let pv = P / W;
    const {
        assert!(DB <= W && DB * W <= 128 && DB * (P / W) <= ACC && P.is_multiple_of(W));
        assert!(DB <= REC_PAD);
        assert!(!paired(W, P) || (2 * DB <= ACC && W.is_multiple_of(2)));
    }
    let pair = paired(W, P);
    debug_assert!(nb.is_multiple_of(W));
    debug_assert!(ft.len() >= n.next_multiple_of(DB) * P);
    let fp = ft.as_mut_ptr();
    // Prefetch hints: the lines of `lanes.prefetch`, a few per vector and block. (Issued in
    // bursts at each block start they stalled the core when the miss buffers ran full: 9%
    // of the 8-column kernel's time in the real forward at B = 256.) The (block, vector)
    // pairs of skipped prefixes issue nothing, so the end of the list (8-16% of the lines,
    // the last coefficient rows) is left to demand loads; issuing twice as fast was 3%
    // slower at B = 128.
    let mut pf = lanes.prefetch;
    let pf_per_vector = pf.lines().div_ceil((n / DB).max(1) * (nb / W).max(1));
    let (ps, gap) = lanes.pair_layout(P);
    let xrows = |s0: usize| {
        let (r0, step) = lanes.rows(s0);
        if step == 2 {
            (xin.add((r0 / 2) * ps + (r0 % 2) * gap), ps)
        } else {
            (xin.add(r0 * P), P)
        }
    };
    let mut dbuf = [DBlock([0.0; 128]); 2];
    let mut lo = n;
    let mut v0 = 0;
    while v0 < nb {
        // Up to FWD_VECTORS vectors, each through its negligible prefix.
        let nv = ((nb - v0) / W).min(FWD_VECTORS);
        let mut st_mem = [const { MaybeUninit::<State<S>>::uninit() }; FWD_VECTORS];
        let (first, st) = prefix_states::<S, W>(rec, lanes, v0, n, &mut st_mem[..nv]);
        lo = lo.min(first);
        let mut i0 = first - first % DB;
        // The first group of vectors writes the sums (zeros below its first block), the
        // others add to them: `ft` needs no clearing beforehand.
        let assign = v0 == 0;
        if assign {
            std::ptr::write_bytes(fp, 0, i0 * P);
        }
        let mut fast = [0usize; FWD_VECTORS];
        let mut nf = 0;
        // Whether `dbuf[cur]` already holds the block of `fast[0]` at `i0`; whether some
        // vector took the masked path in the last full scan, and the lowest degree index
        // at which a vector not yet started starts.
        let (mut primed, mut cur) = (false, 0);
        let (mut masked, mut wait) = (false, n);
        while i0 < n {
            let mut acc = [S::zero(); ACC];
            // Paired sums are folded and added to `ft` at the end of the block.
            if !assign && !pair {
                for j in 0..DB {
                    for h in 0..pv {
                        acc[j * pv + h] = S::load(fp.add((i0 + j) * P + h * W));
                    }
                }
            }
            // Vectors that start inside this block or still have inactive lanes, one at a
            // time; the others are listed for the pipelined loop. While the list stays the
            // same (no vector in its masked phase, none starting) it is not rebuilt.
            if !primed {
                nf = 0;
                (masked, wait) = (false, n);
                for (v, s) in st.iter_mut().enumerate() {
                    if s.i >= n {
                        continue;
                    }
                    if s.i >= i0 + DB {
                        wait = wait.min(s.i);
                        continue;
                    }
                    // A last block that ends past `n` runs in full too: its steps read the
                    // zero padding of the coefficients, and its rows from `n` on are
                    // scratch.
                    if s.i == i0 && s.all_active() {
                        fast[nf] = v;
                        nf += 1;
                        continue;
                    }
                    masked = true;
                    pf.issue(pf_per_vector);
                    let d = s.masked_block::<DB>(i0, n);
                    let db = dbuf[0].0.as_mut_ptr();
                    for (j, dj) in d.iter().enumerate() {
                        S::store(db.add(j * W), *dj);
                    }
                    let (x, xs) = xrows(v0 + v * W);
                    block_fmas::<S, W, P, DB>(&mut acc, db, x, xs);
                }
            }
            if nf > 0 {
                // The first fast vector's block (unless the previous block computed it),
                // then each next vector's steps interleaved with the previous one's
                // multiply-adds.
                if !primed {
                    cur = 0;
                    let s = &mut st[fast[0]];
                    let (mut p0, mut p1) = (s.p0, s.p1);
                    let db = dbuf[cur].0.as_mut_ptr();
                    for j in 0..DB {
                        S::store(db.add(j * W), p1);
                        let p2 = S::fence(s.step(p0, p1, i0 + j));
                        (p0, p1) = (p1, p2);
                    }
                    (s.p0, s.p1, s.i) = (p0, p1, i0 + DB);
                }
                // When the next block has the same list (no vector masked here, none
                // starting there), its first vector's steps go with this block's last
                // vector instead of running alone (their dependency chain exposed) at the
                // start of the next block.
                let next = !masked && wait >= (i0 + 2 * DB).min(n) && i0 + DB < n;
                let mut ev = fast[0];
                for idx in 1..nf + next as usize {
                    let (v, base) = if idx < nf {
                        (fast[idx], i0)
                    } else {
                        (fast[0], i0 + DB)
                    };
                    pf.issue(pf_per_vector);
                    let (x, xs) = xrows(v0 + ev * W);
                    let s = &mut st[v];
                    let (mut p0, mut p1) = (s.p0, s.p1);
                    let dc = dbuf[cur].0.as_ptr();
                    let dn = dbuf[1 - cur].0.as_mut_ptr();
                    // Written out for each lane, so that the state stays in registers.
                    macro_rules! lane {
                        ($w:literal) => {
                            if $w < W {
                                // This lane's share of the next vector's steps.
                                for k in $w * DB / W..($w + 1) * DB / W {
                                    S::store(dn.add(k * W), p1);
                                    let p2 = S::fence(s.step(p0, p1, base + k));
                                    (p0, p1) = (p1, p2);
                                }
                                lane_fmas::<S, W, P, DB>(&mut acc, dc, $w, x, xs);
                            }
                        };
                    }
                    lane!(0);
                    lane!(1);
                    lane!(2);
                    lane!(3);
                    lane!(4);
                    lane!(5);
                    lane!(6);
                    lane!(7);
                    (s.p0, s.p1, s.i) = (p0, p1, base + DB);
                    cur = 1 - cur;
                    ev = v;
                }
                primed = next;
                if !next {
                    pf.issue(pf_per_vector);
                    let (x, xs) = xrows(v0 + ev * W);
                    let dc = dbuf[cur].0.as_ptr();
                    block_fmas::<S, W, P, DB>(&mut acc, dc, x, xs);
                }
            }
            if pair {
                for j in 0..DB {
                    let r = fp.add((i0 + j) * P);
                    let v = fold_pair::<S>(&acc, j);
                    S::store(r, if assign { v } else { S::add(S::load(r), v) });
                }
            } else {
                for j in 0..DB {
                    for h in 0..pv {
                        S::store(fp.add((i0 + j) * P + h * W), acc[j * pv + h]);
                    }
                }
            }
            i0 += DB;
        }
        v0 += nv * W;
    }
    lo
}

/// `acc[q] += v * row[q]` (the inverse kernel's accumulation of one degree).
#[inline(always)]
unsafe fn acc_row<S: Simd, const P: usize>(acc: &mut [S::V; P], v: S::V, row: *const f64) {
    for (q, a) in acc.iter_mut().enumerate() {
        *a = S::fma(v, S::splat(*row.add(q)), *a);
    }
}

/// Fills rows `from..to` of the inverse kernel's input (see [`inverse_raw`]).
pub(crate) type Fill<'a> = &'a mut dyn FnMut(&mut [f64], usize, usize);

/// Vectors of betas whose states the inverse kernel sets up before it needs their input
/// rows.
const INV_VECTORS: usize = 16;

#[inline(always)]
unsafe fn inverse_body<S: Simd, const W: usize, const P: usize, const NT: bool>(
    rec: &Rec,
    lanes: &Lanes,
    fin: &mut [f64],
    fill: Fill,
    y: *mut f64,
) {
    let n = rec.len();
    let nb = lanes.tau.len();
    debug_assert!(nb.is_multiple_of(W) && fin.len() >= n * P);
    let (ps, gap) = lanes.pair_layout(P);
    let mut pf = lanes.prefetch;
    let pf_per_vector = pf.lines().div_ceil((nb / W).max(1));
    // Rows `have..n` of `fin` are filled.
    let mut have = n;
    let mut v0 = 0;
    while v0 < nb {
        // Up to INV_VECTORS vectors through their negligible prefixes, then the rows from
        // the first degree any of them needs.
        let nv = ((nb - v0) / W).min(INV_VECTORS);
        let mut st_mem = [const { MaybeUninit::<State<S>>::uninit() }; INV_VECTORS];
        let (first, states) = prefix_states::<S, W>(rec, lanes, v0, n, &mut st_mem[..nv]);
        if first < have {
            fill(fin, first, have);
            have = first;
        }
        let fp = fin.as_ptr();
        let mut gi = 0;
        while gi < nv {
            // With 8 columns, two vectors run together once both are fully active: each
            // data broadcast then feeds two multiply-adds, and the two recurrences are
            // independent chains (one vector's step and 8 multiply-adds per degree leave
            // the pipes half idle).
            let pair = P <= 8 && gi + 1 < nv;
            let mut st = [states[gi], states[(gi + 1).min(nv - 1)]];
            let mut acc = [[S::zero(); P]; 2];
            pf.issue(pf_per_vector * (1 + pair as usize));
            if pair {
                let [a0, a1] = &mut acc;
                for (s, a) in st.iter_mut().zip([&mut *a0, &mut *a1]) {
                    s.run_slow(n, &mut |v, i| acc_row::<S, P>(a, v, fp.add(i * P)));
                }
                // The one behind catches up alone, then both run together.
                let i0 = st[0].i.max(st[1].i);
                for (s, a) in st.iter_mut().zip([&mut *a0, &mut *a1]) {
                    s.run_fast(i0, &mut |v, i| acc_row::<S, P>(a, v, fp.add(i * P)));
                }
                let [s0, s1] = &mut st;
                let (mut p0, mut p1, mut r0, mut r1) = (s0.p0, s0.p1, s1.p0, s1.p1);
                for i in i0..n {
                    let (v, u) = (p1, r1);
                    let p2 = S::fence(s0.step(p0, p1, i));
                    let r2 = S::fence(s1.step(r0, r1, i));
                    (p0, p1, r0, r1) = (p1, p2, r1, r2);
                    let row = fp.add(i * P);
                    for q in 0..P {
                        let c = S::splat(*row.add(q));
                        a0[q] = S::fma(v, c, a0[q]);
                        a1[q] = S::fma(u, c, a1[q]);
                    }
                }
            } else {
                // A local copy, so the state lives in registers during the run.
                let mut s = st[0];
                let a = &mut acc[0];
                s.run(n, |v, i| acc_row::<S, P>(a, v, fp.add(i * P)));
            }
            // Rows of the output are lanes: each W x W block of (order column, lane) is
            // transposed in registers on the way out, and with `lanes.stream` written
            // without reading the lines first (see `Lanes::stream`).
            // `NT` is a parameter of the kernel: a run-time branch here cost the 8-column
            // kernel a third of its speed (its register allocation changed).
            for (k, a) in acc.iter().enumerate().take(1 + pair as usize) {
                // Interleaved rows step by 2: one pair of rows to the next.
                let (r0, step) = lanes.rows(v0 + (gi + k) * W);
                let (at, stride) = (
                    (r0 / 2) * ps + (r0 % 2) * gap,
                    if step == 2 { ps } else { P },
                );
                for q0 in (0..P).step_by(W) {
                    S::store_transposed(&a[q0..q0 + W], y.add(at + q0), stride, NT);
                }
            }
            gi += 1 + pair as usize;
        }
        v0 += nv * W;
    }
}

macro_rules! entry {
    ($name:ident, $feat:literal, inverse_body, $S:ty, $W:literal, $N:literal) => {
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = $feat)]
        unsafe fn $name<const NT: bool>(
            rec: &Rec,
            lanes: &Lanes,
            a: &mut [f64],
            f: Fill,
            b: *mut f64,
        ) {
            inverse_body::<$S, $W, $N, NT>(rec, lanes, a, f, b)
        }
    };
    ($name:ident, $feat:literal, forward_body, $S:ty, $W:literal, $N:literal, $DB:literal) => {
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = $feat)]
        unsafe fn $name(rec: &Rec, lanes: &Lanes, a: *const f64, b: &mut [f64]) -> usize {
            forward_body::<$S, $W, $N, $DB>(rec, lanes, a, b)
        }
    };
}

#[cfg(target_arch = "x86_64")]
use crate::simd::{Avx2, Avx512};

entry!(fwd_avx512_16, "avx512f,fma", forward_body, Avx512, 8, 16, 8);
// 16 degrees per block would keep 16 sums in flight with 8 columns: 41% of the peak
// against 39% for one cluster in cache, but 7% slower in the real forward's DWT stage at
// B = 128 (shorter clusters, more partial blocks); it would also need `ft` sized for
// `n + 16` degrees.
entry!(fwd_avx512_8, "avx512f,fma", forward_body, Avx512, 8, 8, 8);
entry!(fwd_avx2_16, "avx2,fma", forward_body, Avx2, 4, 16, 2);
entry!(fwd_avx2_8, "avx2,fma", forward_body, Avx2, 4, 8, 4);
entry!(inv_avx512_16, "avx512f,fma", inverse_body, Avx512, 8, 16);
entry!(inv_avx512_8, "avx512f,fma", inverse_body, Avx512, 8, 8);
entry!(inv_avx2_16, "avx2,fma", inverse_body, Avx2, 4, 16);
entry!(inv_avx2_8, "avx2,fma", inverse_body, Avx2, 4, 8);

/// Forward kernel: `ft[i*P + q] = sum_s dt_{l0+i}(beta_s) xin[row(s)*P + q]` for `i < n`,
/// `P` = 8 or 16 (`row` see [`Lanes::interleaved`]): degree-major, the inverse kernel's
/// input layout; what `ft` held before is ignored. `ft` holds at least `(n + W) * P`
/// values, `W = isa.lanes()` (rows from `n` on are scratch: the last block of degrees runs in full).
///
/// Returns `lo <= n`: rows `0..lo` are zero because every lane of every beta is still in
/// its negligible prefix there (see [`Lanes::skip`]). Callers that accumulate the sums
/// elsewhere need only add rows `lo..n`.
///
/// `isa` must be supported by this CPU ([`Isa::is_supported`]), and the lane arrays'
/// length a multiple of `isa.lanes()`.
pub(crate) fn forward(
    isa: Isa,
    p: usize,
    rec: &Rec,
    lanes: &Lanes,
    xin: &[f64],
    ft: &mut [f64],
) -> usize {
    assert!(lanes.pair_stride == 0 && lanes.row_gap == 0);
    assert!(xin.len() >= lanes.tau.len() * p);
    // SAFETY: the rows are consecutive, within `xin`.
    unsafe { forward_raw(isa, p, rec, lanes, xin.as_ptr(), ft) }
}

/// [`forward`] reading row `r` of the input at `xin + r * P`, or for interleaved lanes at
/// `xin + (r / 2) * lanes.pair_stride + (r % 2) * lanes.row_gap` (defaults `2P` and `P`:
/// consecutive rows; see `plan/blocks.rs` for the split layout).
///
/// # Safety
/// Every row of the lanes (`lanes.tau.len()` rows of `p` values) is valid for reads and
/// written by no one meanwhile.
pub(crate) unsafe fn forward_raw(
    isa: Isa,
    p: usize,
    rec: &Rec,
    lanes: &Lanes,
    xin: *const f64,
    ft: &mut [f64],
) -> usize {
    let n = rec.len();
    let nb = lanes.tau.len();
    assert!(rec.padded());
    assert!(lanes.p.len() == nb && lanes.sc.len() == nb && nb.is_multiple_of(isa.lanes()));
    assert!(ft.len() >= (n + isa.lanes()) * p);
    assert!(isa.is_supported());
    lanes.assert_rows_apart(p);
    // SAFETY: lengths checked above, rows by the caller, instruction set checked by
    // is_supported.
    unsafe {
        match (isa, p) {
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx512, 16) => fwd_avx512_16(rec, lanes, xin, ft),
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx512, 8) => fwd_avx512_8(rec, lanes, xin, ft),
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx2, 16) => fwd_avx2_16(rec, lanes, xin, ft),
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx2, 8) => fwd_avx2_8(rec, lanes, xin, ft),
            (_, 16) => forward_body::<Scalar, 1, 16, 1>(rec, lanes, xin, ft),
            (_, 8) => forward_body::<Scalar, 1, 8, 1>(rec, lanes, xin, ft),
            _ => unreachable!("P must be 8 or 16"),
        }
    }
}

/// [`inverse_raw`] into consecutive rows of `y` (bounds checked).
#[cfg(test)]
pub(crate) fn inverse(
    isa: Isa,
    p: usize,
    rec: &Rec,
    lanes: &Lanes,
    fin: &mut [f64],
    fill: Fill,
    y: &mut [f64],
) {
    assert!(lanes.pair_stride == 0 && y.len() >= lanes.tau.len() * p);
    // SAFETY: `y` holds every row (consecutive rows of `p` values).
    unsafe { inverse_raw(isa, p, rec, lanes, fin, fill, y.as_mut_ptr()) }
}

/// Inverse kernel: `y[row(s)*P + q] = sum_i dt_{l0+i}(beta_s) fin[i*P + q]`, `P` = 8 or 16
/// (the layout of the forward kernel's input, see `plan/blocks.rs`), with row `r` of the
/// output at `y + r * P`, or, with a nonzero `lanes.pair_stride` (the half-major layout),
/// at `y + (r / 2) * lanes.pair_stride + (r % 2) * lanes.row_gap` (`P` if `row_gap` is 0).
///
/// The input rows are filled on demand: before it reads them, the kernel calls
/// `fill(fin, from, to)` to fill rows `from..to` (the calls cover the rows from the first
/// degree where some lane is past its negligible prefix up to `n`, top down, each row
/// once; rows below are never read). A chunked inverse thus reads only the coefficients
/// its betas need.
///
/// # Safety
/// Every row of the lanes (`lanes.tau.len()` rows of `p` values) is valid for writes and
/// written by no one else meanwhile; a nonzero `pair_stride` needs interleaved lanes.
pub(crate) unsafe fn inverse_raw(
    isa: Isa,
    p: usize,
    rec: &Rec,
    lanes: &Lanes,
    fin: &mut [f64],
    fill: Fill,
    y: *mut f64,
) {
    let n = rec.len();
    let nb = lanes.tau.len();
    assert!(rec.padded());
    assert!(lanes.p.len() == nb && lanes.sc.len() == nb && nb.is_multiple_of(isa.lanes()));
    assert!(fin.len() >= n * p && isa.is_supported());
    lanes.assert_rows_apart(p);
    // SAFETY: lengths checked above, rows by the caller, instruction set checked by
    // is_supported.
    unsafe {
        // The kernel for the store mode `lanes.stream`.
        macro_rules! nt {
            ($f:ident $(::<$($g:tt),*>)?) => {
                if lanes.stream {
                    $f::<$($($g,)*)? true>(rec, lanes, fin, fill, y)
                } else {
                    $f::<$($($g,)*)? false>(rec, lanes, fin, fill, y)
                }
            };
        }
        match (isa, p) {
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx512, 16) => nt!(inv_avx512_16),
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx512, 8) => nt!(inv_avx512_8),
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx2, 16) => nt!(inv_avx2_16),
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx2, 8) => nt!(inv_avx2_8),
            (_, 16) => nt!(inverse_body::<Scalar, 1, 16>),
            (_, 8) => nt!(inverse_body::<Scalar, 1, 8>),
            _ => unreachable!("P must be 8 or 16"),
        }
    }
    // The output rows may have been written with non-temporal stores.
    crate::simd::sfence();
}

/// `dt^l_{m,mp}` of the base pair at point `k` of `bt`, for `l = m..lend`, through the
/// forward kernel (one beta, unit data in column 0).
#[allow(clippy::too_many_arguments)]
pub(crate) fn column(
    isa: Isa,
    bt: &BetaTables,
    rt: &RecTables,
    k: usize,
    m: usize,
    mp: usize,
    norm: Ext,
    lend: usize,
) -> Vec<f64> {
    let n = lend - m;
    let mut rc = RecCoeffs::new(n);
    rt.coeffs(m, mp, &mut rc);
    let w = isa.lanes();
    // No skipping: values down to 2^-560 are returned (below that, 0).
    let bits = *SKIP_BITS_RANGE.end();
    let (p0, sc0) = bt.start(k, m, mp, norm, 1.0, bits);
    let mut tau = vec![0.0; w];
    let mut p = vec![0.0; w];
    let mut sc = vec![0.0; w];
    let upper = bt.upper(k);
    tau[0] = if upper { bt.tau_hi[k] } else { bt.tau_lo[k] };
    p[0] = p0;
    sc[0] = sc0;
    let mut xin = vec![0.0; w * 8];
    xin[0] = 1.0;
    let mut f = vec![0.0; (n + w) * 8];
    let rec = Rec::new(&rc, n);
    let lanes = Lanes {
        tau: &tau,
        p: &p,
        sc: &sc,
        upper_from: if upper { 0 } else { w },
        big: crate::wigner::big(bits),
        skip: false,
        interleaved: false,
        prefetch: Prefetch::none(),
        stream: false,
        pair_stride: 0,
        row_gap: 0,
    };
    forward(isa, 8, &rec, &lanes, &xin, &mut f);
    f.iter()
        .step_by(8)
        .zip(&rc.s[..n])
        .map(|(v, s)| v * s)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// [`inverse`] with its input rows filled on demand from `fin`: rows start as NaN, so
    /// a read before the fill shows in `y`. Checks the fill contract (top down, each row
    /// once, down to a contiguous end at `n`) and returns the lowest row filled.
    pub(super) fn inverse_from(
        isa: Isa,
        pw: usize,
        rec: &Rec,
        lanes: &Lanes,
        fin: &[f64],
        y: &mut [f64],
    ) -> usize {
        let n = rec.len();
        let mut buf = vec![f64::NAN; n * pw];
        let mut have = n;
        inverse(
            isa,
            pw,
            rec,
            lanes,
            &mut buf,
            &mut |b: &mut [f64], from: usize, to: usize| {
                assert!(
                    from < to && to == have,
                    "fill {from}..{to} with rows {have}.. filled"
                );
                b[from * pw..to * pw].copy_from_slice(&fin[from * pw..to * pw]);
                have = from;
            },
            y,
        );
        have
    }

    fn pseudo(n: usize, seed: u64) -> Vec<f64> {
        let mut s = seed;
        (0..n)
            .map(|_| {
                s ^= s << 13;
                s ^= s >> 7;
                s ^= s << 17;
                (s >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
            })
            .collect()
    }

    /// Skip threshold of the kernel tests and benchmarks: `SO3FFT_SKIP_BITS` or the default.
    pub(super) fn test_skip_bits() -> u32 {
        std::env::var("SO3FFT_SKIP_BITS")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(crate::wigner::DEFAULT_SKIP_BITS)
    }

    /// Recurrence coefficients of base pair `(m, mp)` at bandwidth `b` and lane inputs for
    /// `nbs` points spread evenly over the grid (lower half first, as in a chunk).
    pub(super) fn cluster_setup(
        b: usize,
        m: usize,
        mp: usize,
        nbs: usize,
    ) -> (RecCoeffs, Vec<f64>, Vec<f64>, Vec<f64>) {
        let ks: Vec<usize> = (0..nbs).map(|s| s * (2 * b) / nbs).collect();
        cluster_setup_at(b, m, mp, &ks)
    }

    /// As [`cluster_setup`], for the grid betas `ks`.
    pub(super) fn cluster_setup_at(
        b: usize,
        m: usize,
        mp: usize,
        ks: &[usize],
    ) -> (RecCoeffs, Vec<f64>, Vec<f64>, Vec<f64>) {
        let nbs = ks.len();
        let bt = BetaTables::grid(b);
        let norm = crate::wigner::start_norm(m, mp);
        let mut rc = RecCoeffs::new(b - m);
        RecTables::new(b).coeffs(m, mp, &mut rc);
        let (mut tau, mut p, mut sc) = (vec![0.0; nbs], vec![0.0; nbs], vec![0.0; nbs]);
        for (s, &k) in ks.iter().enumerate() {
            tau[s] = if k < b { bt.tau_lo[k] } else { bt.tau_hi[k] };
            (p[s], sc[s]) = bt.start(k, m, mp, norm, 1.0, test_skip_bits());
        }
        (rc, tau, p, sc)
    }

    /// `len` values of `buf` from its first 64-byte boundary (as the plan's chunk
    /// buffers); `buf` holds at least `len + 7`.
    pub(super) fn aligned(buf: &[f64], len: usize) -> &[f64] {
        &buf[buf.as_ptr().align_offset(64)..][..len]
    }

    /// Kernel lanes over `cluster_setup`'s arrays, default skip threshold.
    pub(super) fn grid_lanes<'a>(
        tau: &'a [f64],
        p: &'a [f64],
        sc: &'a [f64],
        upper_from: usize,
    ) -> Lanes<'a> {
        Lanes {
            tau,
            p,
            sc,
            upper_from,
            big: crate::wigner::big(test_skip_bits()),
            skip: true,
            interleaved: true,
            prefetch: Prefetch::none(),
            stream: true,
            pair_stride: 0,
            row_gap: 0,
        }
    }

    /// The cases of the row-layout tests: B = 40, three base pairs, 48 betas over the
    /// grid, 8 and 16 columns, every supported instruction set, as
    /// `f(isa, columns, m, rec, lanes)` (interleaved lanes, default skip threshold).
    fn layout_cases(mut f: impl FnMut(Isa, usize, usize, &Rec, Lanes)) {
        let (b, nbs) = (40, 48);
        for &(m, mp) in &[(3usize, 1usize), (20, 20), (33, 0)] {
            let (rc, tau, p, sc) = cluster_setup(b, m, mp, nbs);
            let rec = Rec::new(&rc, b - m);
            for pw in [8usize, 16] {
                for isa in [Isa::Scalar, Isa::Avx2, Isa::Avx512] {
                    if isa.is_supported() {
                        f(isa, pw, m, &rec, grid_lanes(&tau, &p, &sc, nbs / 2));
                    }
                }
            }
        }
    }

    /// The forward reading its rows in the split layout (`Lanes::pair_stride` = `P`, the
    /// mirror rows `Lanes::row_gap` after the low-beta rows; a forward chain's buffers)
    /// gives the sums it gives from consecutive rows, bit for bit: every instruction set,
    /// 8 and 16 columns.
    #[test]
    fn split_rows_give_the_same_sums() {
        layout_cases(|isa, pw, m, rec, mut lanes| {
            let (n, nbs) = (rec.len(), lanes.tau.len());
            let x = pseudo(nbs * pw, 11 + m as u64);
            let mut want = vec![0.0; (n + 8) * pw];
            forward(isa, pw, rec, &lanes, &x, &mut want);
            // Low-beta rows from 5 values in, mirror rows 3 values after them; NaN
            // everywhere else.
            let gap = nbs / 2 * pw + 3;
            let mut z = vec![f64::NAN; 5 + gap + nbs / 2 * pw];
            for r in 0..nbs {
                let at = 5 + (r / 2) * pw + (r % 2) * gap;
                z[at..at + pw].copy_from_slice(&x[r * pw..(r + 1) * pw]);
            }
            (lanes.pair_stride, lanes.row_gap) = (pw, gap);
            let mut f = vec![0.0; (n + 8) * pw];
            // SAFETY: every row of the lanes is inside `z`.
            unsafe { forward_raw(isa, pw, rec, &lanes, z.as_ptr().add(5), &mut f) };
            for (i, (u, v)) in f[..n * pw].iter().zip(&want).enumerate() {
                assert_eq!(u.to_bits(), v.to_bits(), "{isa:?} P={pw} m={m} at {i}");
            }
        });
    }

    /// The inverse into rows a pair stride apart (`Lanes::pair_stride`), the two rows of a
    /// pair side by side or (`Lanes::row_gap`, the plan's half-major layout) in two
    /// separate halves, writes exactly what it writes into consecutive rows, each row at
    /// its place, and nothing elsewhere: every instruction set, both store modes.
    #[test]
    fn strided_rows_hold_the_consecutive_rows() {
        layout_cases(|isa, pw, m, rec, lanes| {
            let (n, nbs) = (rec.len(), lanes.tau.len());
            let fin = pseudo(n * pw, 7 + m as u64);
            for (stream, half) in [(true, false), (false, false), (true, true)] {
                let mut lanes = Lanes { stream, ..lanes };
                let mut y = vec![f64::NAN; nbs * pw];
                inverse_from(isa, pw, rec, &lanes, &fin, &mut y);
                // Pairs 2p + 8 values apart, 5 values into the buffer; half-major: rows
                // p + 8 apart in each half, the second half 3 values after the first.
                let ps = if half { pw + 8 } else { 2 * pw + 8 };
                let gap = if half { nbs / 2 * ps + 3 } else { pw };
                lanes.pair_stride = ps;
                lanes.row_gap = if half { gap } else { 0 };
                let mut z = vec![f64::NAN; 5 + nbs / 2 * ps + gap];
                let mut buf = fin.clone();
                // SAFETY: z holds nbs / 2 pairs of two rows after offset 5.
                unsafe {
                    inverse_raw(
                        isa,
                        pw,
                        rec,
                        &lanes,
                        &mut buf,
                        &mut |_, _, _| {},
                        z.as_mut_ptr().add(5),
                    )
                };
                let mut want = vec![f64::NAN; z.len()];
                for r in 0..nbs {
                    let at = 5 + (r / 2) * ps + (r % 2) * gap;
                    want[at..at + pw].copy_from_slice(&y[r * pw..(r + 1) * pw]);
                }
                for (i, (v, w)) in z.iter().zip(&want).enumerate() {
                    assert_eq!(
                        v.to_bits(),
                        w.to_bits(),
                        "{isa:?} P={pw} half={half} at {i}"
                    );
                }
            }
        });
    }

    /// The forward kernel is the transpose of the inverse one: `<y, x> = <fin, f>` for
    /// `f = forward(x)` and `y = inverse(fin)`, on every path, with and without skipping,
    /// for odd and even numbers of vectors (the 8-column inverse pairs vectors), halves of
    /// unequal size, and clusters of 1 to 67 degrees. Skipping changes nothing beyond
    /// rounding.
    #[test]
    fn forward_is_the_adjoint_of_inverse() {
        let b = 67;
        // Rows below `lo` summed over the runs: the skipped rows must occur here.
        let mut rows_below_lo = 0;
        for &(m, mp) in &[
            (0usize, 0usize),
            (5, 2),
            (30, 30),
            (41, 0),
            (65, 12),
            (66, 66),
        ] {
            let n = b - m;
            // Spread over the grid, and (16) the 8 betas nearest each pole, where the
            // kernels skip the first degrees of every lane.
            for nbs in [24usize, 40, 56, 72, 16] {
                let (rc, tau, p, sc) = if nbs == 16 {
                    let ks: Vec<usize> = (0..8).chain(2 * b - 8..2 * b).collect();
                    cluster_setup_at(b, m, mp, &ks)
                } else {
                    cluster_setup(b, m, mp, nbs)
                };
                let rec = Rec::new(&rc, n);
                for pw in [8usize, 16] {
                    let x = pseudo(nbs * pw, 3 + nbs as u64);
                    let fin = pseudo(n * pw, 5 + m as u64);
                    let mut runs = Vec::new();
                    for isa in [Isa::Scalar, Isa::Avx2, Isa::Avx512] {
                        if !isa.is_supported() {
                            continue;
                        }
                        for skip in [true, false] {
                            let lanes = Lanes {
                                tau: &tau,
                                p: &p,
                                sc: &sc,
                                // Vectors below this lane are the lower half.
                                upper_from: 8 * (nbs / 16),
                                big: crate::wigner::big(test_skip_bits()),
                                skip,
                                interleaved: false,
                                prefetch: Prefetch::none(),
                                // Both ways of storing the inverse's output.
                                stream: skip,
                                pair_stride: 0,
                                row_gap: 0,
                            };
                            // Stale values in every row the kernel must write.
                            let mut f = vec![0.0; (n + 8) * pw];
                            f[..n * pw].fill(f64::NAN);
                            let mut y = vec![f64::NAN; nbs * pw];
                            let lo = forward(isa, pw, &rec, &lanes, &x, &mut f);
                            assert!(f[..lo * pw].iter().all(|&v| v == 0.0), "rows below lo");
                            let filled = inverse_from(isa, pw, &rec, &lanes, &fin, &mut y);
                            // Both kernels find the same first degree any lane needs.
                            assert_eq!(filled, lo, "first row read by the inverse");
                            rows_below_lo += lo;
                            let dot = |a: &[f64], b: &[f64]| {
                                a.iter().zip(b).map(|(u, v)| u * v).sum::<f64>()
                            };
                            let norm = |a: &[f64]| dot(a, a).sqrt();
                            let (lhs, rhs) = (dot(&y, &x), dot(&fin, &f[..n * pw]));
                            let scale = norm(&y) * norm(&x) + norm(&fin) * norm(&f[..n * pw]);
                            assert!(
                                (lhs - rhs).abs() <= 1e-13 * scale,
                                "{isa:?} skip={skip} m={m} mp={mp} nbs={nbs} P={pw}: {lhs} {rhs}"
                            );
                            // Rows from `n` on are scratch (the last block runs in full),
                            // but never a non-finite value.
                            assert!(f[n * pw..].iter().all(|v| v.is_finite()));
                            f.truncate(n * pw);
                            runs.push((f, y));
                        }
                    }
                    let (f0, y0) = &runs[0];
                    let fs = f0.iter().fold(0.0f64, |a, v| a.max(v.abs())).max(1e-300);
                    let ys = y0.iter().fold(0.0f64, |a, v| a.max(v.abs())).max(1e-300);
                    for (f, y) in &runs[1..] {
                        for (u, v) in f.iter().zip(f0) {
                            assert!(
                                (u - v).abs() <= 1e-13 * fs,
                                "m={m} mp={mp} nbs={nbs} P={pw}"
                            );
                        }
                        for (u, v) in y.iter().zip(y0) {
                            assert!(
                                (u - v).abs() <= 1e-13 * ys,
                                "m={m} mp={mp} nbs={nbs} P={pw}"
                            );
                        }
                    }
                }
            }
        }
        assert!(rows_below_lo > 0, "no run skipped a row");
    }

    /// Every SIMD path agrees with the portable scalar one, forward and inverse,
    /// including lanes that start scaled down (large m at betas near the poles).
    #[test]
    fn simd_paths_match_scalar() {
        let b = 200;
        for &(m, mp) in &[(0usize, 0usize), (5, 3), (150, 20), (199, 199), (120, 0)] {
            let n = b - m;
            let nb = 2 * b;
            let (rc, x, p, sc) = cluster_setup(b, m, mp, nb);
            let rec = Rec::new(&rc, n);
            let lanes = grid_lanes(&x, &p, &sc, b);
            for pw in [8usize, 16] {
                let xin = pseudo(nb * pw, 7 + m as u64);
                let fin = pseudo(n * pw, 11 + mp as u64);
                let mut f_ref = vec![f64::NAN; (n + 8) * pw];
                let mut y_ref = vec![0.0; nb * pw];
                forward(Isa::Scalar, pw, &rec, &lanes, &xin, &mut f_ref);
                inverse_from(Isa::Scalar, pw, &rec, &lanes, &fin, &mut y_ref);
                for isa in [Isa::Avx512, Isa::Avx2] {
                    if !isa.is_supported() {
                        continue;
                    }
                    let mut f = vec![f64::NAN; (n + 8) * pw];
                    let mut y = vec![0.0; nb * pw];
                    forward(isa, pw, &rec, &lanes, &xin, &mut f);
                    inverse_from(isa, pw, &rec, &lanes, &fin, &mut y);
                    // FMA and plain multiply-add round differently; the recurrence error
                    // grows like l * eps (l <= 200 here), so compare relative to the largest value.
                    let rel = |u: &[f64], r: &[f64]| {
                        let scale = r.iter().fold(0.0f64, |s, x| s.max(x.abs()));
                        let e = u
                            .iter()
                            .zip(r)
                            .fold(0.0f64, |s, (a, b)| s.max((a - b).abs()));
                        e / scale
                    };
                    // Rows from n on are not part of the result; every row below is
                    // written (f starts out NaN, which `max` would otherwise skip).
                    let nf = n * pw;
                    assert!(f[..nf].iter().chain(&f_ref[..nf]).all(|v| v.is_finite()));
                    let (ef, ey) = (rel(&f[..nf], &f_ref[..nf]), rel(&y, &y_ref));
                    assert!(
                        ef < 1e-12 && ey < 1e-12,
                        "{isa:?} m={m} mp={mp} P={pw}: {ef} {ey}"
                    );
                }
            }
        }
    }
}

#[cfg(test)]
pub(crate) mod kernel_speed {
    use super::tests::{aligned, cluster_setup, grid_lanes};
    use super::*;

    /// FMA peak of one core, GFLOP/s: 16 independent chains of AVX-512 FMAs (AVX2 or
    /// scalar where missing), best of a few short runs.
    pub(crate) fn fma_peak() -> f64 {
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = "avx512f,fma")]
        unsafe fn chains(iters: usize) -> f64 {
            use crate::simd::Avx512;
            let mut a = [Avx512::zero(); 16];
            let b = Avx512::splat(0.999_999_9);
            let c = Avx512::splat(1e-9);
            for _ in 0..iters {
                for x in a.iter_mut() {
                    *x = Avx512::fma(*x, b, c);
                }
                a[0] = Avx512::fence(a[0]);
            }
            let mut t = [0.0; 8];
            Avx512::store(
                t.as_mut_ptr(),
                a.iter().fold(Avx512::zero(), |s, x| Avx512::add(s, *x)),
            );
            t.iter().sum()
        }
        if !Isa::Avx512.is_supported() {
            return f64::NAN;
        }
        let iters = 2_000_000;
        (0..5)
            .map(|_| {
                let t = std::time::Instant::now();
                std::hint::black_box(unsafe { chains(iters) });
                (iters * 16 * 16) as f64 / t.elapsed().as_secs_f64() / 1e9
            })
            .fold(0.0, f64::max)
    }

    /// Kernel-only throughput (run with --ignored --nocapture): GFLOP/s of the fused
    /// recurrence + accumulation for one generic cluster, all 2B grid betas, against the
    /// FMA peak. Forward, inverse and the peak are measured in alternation and each keeps
    /// its best batch: the machine is shared and noisy.
    #[test]
    #[ignore]
    fn kernel_gflops() {
        // (B, betas, columns, m): m = B / 8 has long negligible prefixes near the poles,
        // m = 2 nearly none (the fast phase alone).
        for &(b, nbs, pw, m) in &[
            (256usize, 512usize, 16usize, 32usize),
            (256, 128, 16, 32),
            (128, 256, 16, 16),
            (256, 512, 8, 32),
            (256, 512, 16, 2),
            (256, 512, 8, 2),
        ] {
            let mp = m / 2;
            let n = b - m;
            let (rc, x, p, sc) = cluster_setup(b, m, mp, nbs);
            let rec = Rec::new(&rc, n);
            let lanes = grid_lanes(&x, &p, &sc, nbs / 2);
            let xbuf = vec![0.5; nbs * 16 + 8];
            let xin = aligned(&xbuf, nbs * 16);
            let mut f = vec![0.0; (n + 8) * 16];
            let mut y = vec![0.0; nbs * 16];
            let isa = Isa::detect();
            let batch = |f: &mut dyn FnMut()| {
                let t = std::time::Instant::now();
                for _ in 0..50 {
                    f();
                }
                t.elapsed().as_secs_f64() / 50.0
            };
            let (mut tf, mut ti, mut peak) = (f64::INFINITY, f64::INFINITY, 0.0f64);
            for _ in 0..7 {
                tf = tf.min(batch(&mut || {
                    forward(isa, pw, &rec, &lanes, xin, &mut f);
                }));
                ti = ti.min(batch(&mut || {
                    inverse(
                        isa,
                        pw,
                        &rec,
                        &lanes,
                        &mut f[..n * pw],
                        &mut |_, _, _| {},
                        &mut y,
                    )
                }));
                peak = peak.max(fma_peak());
            }
            let flops = (n * nbs * pw * 2) as f64;
            let (gf, gi) = (flops / tf / 1e9, flops / ti / 1e9);
            println!(
                "B={b} nb={nbs} L={n} P={pw} m={m}: forward {gf:.1} GFLOP/s ({:.0}%), inverse {gi:.1} GFLOP/s ({:.0}%), peak {peak:.1}",
                100.0 * gf / peak,
                100.0 * gi / peak
            );
        }
    }
}

#[cfg(test)]
mod stage_speed {
    use super::tests::{aligned, cluster_setup, grid_lanes};
    use super::*;

    /// Kernel time summed over every cluster of a bandwidth (all 2B betas as one chunk),
    /// against the nominal DWT flop count (run with --ignored --nocapture).
    #[test]
    #[ignore]
    fn all_clusters_gflops() {
        let isa = Isa::detect();
        for b in [128usize, 256] {
            let nbs = 2 * b;
            let (mut tf, mut ti) = (0.0, 0.0);
            let mut qt = [0.0f64; 4];
            let mut qtf = [0.0f64; 4];
            let mut qf = [0.0f64; 4];
            let xbuf = vec![0.5; nbs * 16 + 8];
            let xin = aligned(&xbuf, nbs * 16);
            let mut f = vec![0.0; (b + 8) * 16];
            let mut y = vec![0.0; nbs * 16];
            for (m, mp) in crate::symmetry::cluster_pairs(b) {
                let (m, mp) = (m as usize, mp as usize);
                let n = b - m;
                let (rc, x, p, sc) = cluster_setup(b, m, mp, nbs);
                let rec = Rec::new(&rc, n);
                let lanes = grid_lanes(&x, &p, &sc, b);
                let pw = if m == mp || mp == 0 { 8 } else { 16 };
                let t = std::time::Instant::now();
                forward(isa, pw, &rec, &lanes, xin, &mut f[..(n + 8) * pw]);
                let dt = t.elapsed().as_secs_f64();
                tf += dt;
                qtf[4 * m / b] += dt;
                let t = std::time::Instant::now();
                let y = &mut y[..nbs * pw];
                inverse(
                    isa,
                    pw,
                    &rec,
                    &lanes,
                    &mut f[..n * pw],
                    &mut |_, _, _| {},
                    y,
                );
                let dt = t.elapsed().as_secs_f64();
                ti += dt;
                qt[4 * m / b] += dt;
                qf[4 * m / b] += (n * nbs * pw * 2) as f64;
            }
            for q in 0..4 {
                println!(
                    "  m in quarter {q}: forward {:.1}, inverse {:.1} GFLOP/s nominal, {:.3} s / {:.3} s",
                    qf[q] / qtf[q] / 1e9,
                    qf[q] / qt[q] / 1e9,
                    qtf[q],
                    qt[q]
                );
            }
            let flops = 8.0 * b as f64 * (4.0 * (b as f64).powi(3) - b as f64) / 3.0;
            let peak = super::kernel_speed::fma_peak();
            println!(
                "B={b}: kernels over all clusters: forward {:.3} s ({:.1} GFLOP/s, {:.0}%), inverse {:.3} s ({:.1} GFLOP/s, {:.0}%), peak {peak:.1}",
                tf,
                flops / tf / 1e9,
                100.0 * flops / tf / 1e9 / peak,
                ti,
                flops / ti / 1e9,
                100.0 * flops / ti / 1e9 / peak
            );
        }
    }
}
