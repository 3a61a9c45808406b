//! The recurrence state of one vector of betas and the skipping of the negligible prefix
//! in `l`, shared by the kernels.

use super::lanes::{Lanes, Rec};
use crate::numeric::Elem;
use crate::simd::Simd;
use std::mem::MaybeUninit;

/// Recurrence state of one vector of betas.
#[derive(Clone, Copy)]
pub(crate) struct State<'r, S: Simd> {
    /// Recurrence argument of each lane (see [`Lanes`]).
    pub(crate) tau: S::V,
    /// `-A` (lower half) or `A` (upper half).
    pub(crate) slope: &'r [S::E],
    /// `A + C` (lower half) or `C - A` (upper half).
    pub(crate) offset: &'r [S::E],
    /// The (scaled) values of the degree before the next one.
    pub(crate) p0: S::V,
    /// The (scaled) values of the next degree `i`.
    pub(crate) p1: S::V,
    /// Scale index of each lane (`<= 0`, see the `wigner::starts` module).
    pub(crate) scale_index: S::V,
    /// 1 for the active lanes (scale index 0), else 0.
    pub(crate) mask: S::V,
    /// Next degree index (`l - l0`).
    pub(crate) i: usize,
    /// Rescale threshold (see [`Lanes::big`]).
    pub(crate) big: S::V,
    /// See [`Lanes::skip`].
    pub(crate) skip: bool,
}

impl<'r, S: Simd> State<'r, S> {
    /// # Safety
    /// The CPU supports `S`'s instruction set; the lanes from the vector's first one hold `W`
    /// entries each; degree indices stay below the padded length of the coefficients.
    #[inline(always)]
    pub(crate) unsafe fn new(rec: &Rec<'r, S::E>, lanes: &Lanes<S::E>, s0: usize) -> Self {
        // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
        unsafe {
            let scale_index = S::load(lanes.sc.as_ptr().add(s0));
            let p1 = S::load(lanes.p.as_ptr().add(s0));
            let (slope, offset) = if s0 >= lanes.upper_from {
                (rec.a, rec.c_minus_a)
            } else {
                (rec.neg_a, rec.a_plus_c)
            };
            State {
                tau: S::load(lanes.tau.as_ptr().add(s0)),
                slope,
                offset,
                p0: S::zero(),
                p1,
                scale_index,
                // Active: scale index 0 and a nonzero value. Padding lanes (value 0, scale 0)
                // are neither active nor scaled down: they never hold back the skipping of
                // their vector's prefix, nor its fast phase.
                mask: S::mul(
                    S::blend_ge(scale_index, S::zero(), S::splat(S::E::ONE), S::zero()),
                    S::blend_ge(
                        S::abs(p1),
                        S::splat(S::E::MIN_POSITIVE),
                        S::splat(S::E::ONE),
                        S::zero(),
                    ),
                ),
                i: 0,
                big: S::splat(lanes.big),
                skip: lanes.skip,
            }
        }
    }

    /// Whether no lane is active yet.
    ///
    /// # Safety
    /// The CPU supports `S`'s instruction set; the lanes from the vector's first one hold `W`
    /// entries each; degree indices stay below the padded length of the coefficients.
    #[inline(always)]
    pub(crate) unsafe fn none_active(&self) -> bool {
        // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
        unsafe { !S::any_ge(self.mask, S::splat(S::E::from_f64(0.5))) }
    }

    /// Whether every lane is active.
    ///
    /// # Safety
    /// The CPU supports `S`'s instruction set.
    #[inline(always)]
    pub(crate) unsafe fn all_active(&self) -> bool {
        // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
        unsafe { !S::any_ge(S::splat(S::E::from_f64(-0.5)), self.scale_index) }
    }

    /// Rescale the scaled-down lanes of `(p0, p1)` that grew past `big` by `2^-SCALE_STEP`
    /// (at most once per `2^SCALE_STEP` of growth), activating those that reach scale
    /// index 0. All in registers: with a low skip threshold nearly every lane passes
    /// through here once on its way to being active.
    ///
    /// # Safety
    /// The CPU supports `S`'s instruction set; the lanes from the vector's first one hold `W`
    /// entries each; degree indices stay below the padded length of the coefficients.
    #[inline(always)]
    pub(crate) unsafe fn rescale(&mut self, p0: &mut S::V, p1: &mut S::V) {
        // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
        unsafe {
            let (zero, one) = (S::zero(), S::splat(S::E::ONE));
            // |p1| of the scaled-down lanes, 0 for the active ones.
            let a = S::blend_ge(self.scale_index, zero, zero, S::abs(*p1));
            let f = S::blend_ge(a, self.big, S::splat(S::E::TINY), one);
            *p0 = S::mul(*p0, f);
            *p1 = S::mul(*p1, f);
            let hit = S::blend_ge(a, self.big, one, zero);
            self.scale_index = S::add(self.scale_index, hit);
            // Lanes rescaled to scale index 0 become active; the others keep their state.
            self.mask = S::max(
                self.mask,
                S::mul(hit, S::blend_ge(self.scale_index, zero, one, zero)),
            );
        }
    }

    /// Step without accumulating until some lane is active (or degree `n`): the rest of
    /// the negligible prefix after [`skip_inactive`], one vector at a time.
    ///
    /// # Safety
    /// The CPU supports `S`'s instruction set; the lanes from the vector's first one hold `W`
    /// entries each; degree indices stay below the padded length of the coefficients.
    #[inline(always)]
    pub(crate) unsafe fn finish_prefix(&mut self, n: usize) {
        // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
        unsafe {
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
    }

    /// The values of degrees `i0 .. i0 + D` (the state is at degree `i >= i0`), masked to
    /// the active lanes, zero before `i` and from `n` on; advances the state to
    /// `min(i0 + D, n)`. For the blocks where not all lanes are active yet, or which start
    /// before the state does.
    ///
    /// # Safety
    /// The CPU supports `S`'s instruction set; the lanes from the vector's first one hold `W`
    /// entries each; degree indices stay below the padded length of the coefficients.
    #[inline(always)]
    pub(crate) unsafe fn masked_block<const D: usize>(&mut self, i0: usize, n: usize) -> [S::V; D] {
        // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
        unsafe {
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
    }

    /// One recurrence step from `(p0, p1)` at degree index `i`: the next value.
    ///
    /// # Safety
    /// The CPU supports `S`'s instruction set; the lanes from the vector's first one hold `W`
    /// entries each; degree indices stay below the padded length of the coefficients.
    #[inline(always)]
    pub(crate) unsafe fn step(&self, p0: S::V, p1: S::V, i: usize) -> S::V {
        // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
        unsafe {
            let t = S::fma(
                S::splat(*self.slope.get_unchecked(i)),
                self.tau,
                S::splat(*self.offset.get_unchecked(i)),
            );
            S::fms(t, p1, p0)
        }
    }

    /// Run the remaining degrees up to `n`, calling `acc(v, i)` with the value vector at
    /// each degree from the first one where some lane is active. The recurrence values
    /// live in locals (registers) throughout.
    ///
    /// # Safety
    /// The CPU supports `S`'s instruction set; the lanes from the vector's first one hold `W`
    /// entries each; degree indices stay below the padded length of the coefficients.
    #[inline(always)]
    pub(crate) unsafe fn run(&mut self, n: usize, mut acc: impl FnMut(S::V, usize)) {
        // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
        unsafe {
            self.run_slow(n, &mut acc);
            self.run_fast(n, &mut acc);
        }
    }

    /// The slow phase of [`State::run`]: while some lanes are still scaled down (and
    /// masked to zero), up to degree `n`.
    #[inline(always)]
    pub(crate) unsafe fn run_slow(&mut self, n: usize, acc: &mut impl FnMut(S::V, usize)) {
        // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
        unsafe {
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
    }

    /// The fast phase of [`State::run`] (all lanes hold true values), up to degree `end`.
    /// The step to the next degree comes first in program order: the FMA pipes issue the
    /// oldest ready instruction, so a step placed after the accumulation would queue behind
    /// it and put its latency on the critical path at every degree.
    ///
    /// # Safety
    /// The CPU supports `S`'s instruction set; the lanes from the vector's first one hold `W`
    /// entries each; degree indices stay below the padded length of the coefficients.
    #[inline(always)]
    pub(crate) unsafe fn run_fast(&mut self, end: usize, acc: &mut impl FnMut(S::V, usize)) {
        // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
        unsafe {
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
///
/// # Safety
/// The CPU supports `S`'s instruction set; the lanes from the vector's first one hold `W`
/// entries each; degree indices stay below the padded length of the coefficients.
#[inline(always)]
pub(crate) unsafe fn skip_inactive<S: Simd>(
    st: &mut [State<'_, S>; GROUP],
    rec: &Rec<S::E>,
    n: usize,
) {
    // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
    unsafe {
        if st.iter().any(|s| !s.none_active() || s.i >= n) {
            return;
        }
        let mut i = st[0].i;
        debug_assert!(st.iter().all(|s| s.i == i));
        let big = st[0].big;
        let (mut p0, mut p1, mut tau) =
            ([S::zero(); GROUP], [S::zero(); GROUP], [S::zero(); GROUP]);
        let (mut slope, mut offset) = ([rec.a; GROUP], [rec.a; GROUP]);
        for k in 0..GROUP {
            (p0[k], p1[k], tau[k], slope[k], offset[k]) =
                (st[k].p0, st[k].p1, st[k].tau, st[k].slope, st[k].offset);
        }
        loop {
            let mut hit = false;
            while i < n {
                let mut m = S::zero();
                for k in 0..GROUP {
                    let t = S::fma(
                        S::splat(*slope[k].get_unchecked(i)),
                        tau[k],
                        S::splat(*offset[k].get_unchecked(i)),
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
}

/// Lane offsets of the vectors processed together, starting at `s0` (unused entries
/// repeat the last vector and are marked done).
///
/// # Safety
/// The CPU supports `S`'s instruction set; the lanes from the vector's first one hold `W`
/// entries each; degree indices stay below the padded length of the coefficients.
#[inline(always)]
unsafe fn group_states<'r, S: Simd, const W: usize>(
    rec: &Rec<'r, S::E>,
    lanes: &Lanes<S::E>,
    s0: usize,
    nb: usize,
    n: usize,
) -> (usize, [State<'r, S>; GROUP]) {
    // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
    unsafe {
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
}

/// The states of the `mem.len()` vectors of lanes from `v0`, each advanced through its
/// negligible prefix, written into `mem`; returns the lowest degree index any of them
/// reached (`n` if none) and the states. Both kernels set up their vectors this way
/// before touching data, so they agree on the first degree a set of betas needs.
///
/// # Safety
/// The CPU supports `S`'s instruction set; the lanes from the vector's first one hold `W`
/// entries each; degree indices stay below the padded length of the coefficients.
#[inline(always)]
pub(crate) unsafe fn prefix_states<'m, 'r, S: Simd, const W: usize>(
    rec: &Rec<'r, S::E>,
    lanes: &Lanes<S::E>,
    v0: usize,
    n: usize,
    mem: &'m mut [MaybeUninit<State<'r, S>>],
) -> (usize, &'m mut [State<'r, S>]) {
    // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
    unsafe {
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
        // SAFETY (of the cast): every entry was written above (`gn >= 1` per round).
        let st = std::slice::from_raw_parts_mut(mem.as_mut_ptr() as *mut State<'r, S>, nv);
        let first = st.iter().map(|s| s.i).min().unwrap_or(n);
        (first, st)
    }
}
