//! The kernels of the `m' = 0` recurrences (the Legendre stage of the S^2 transforms),
//! whose degrees alternate between two sets of columns:
//! - inverse: `y[(par C + q) nb + s] = sum over i with i % 2 = par of dt_{l0+i}(beta_s) fin[i C + q]`,
//! - forward: `ft[i C + q] = sum_s dt_{l0+i}(beta_s) x[(par(i) C + q) nb + s]`, `par(i) = i % 2`.
//!
//! For `m' = 0` the value at the mirror ring, `dt^l_{m,0}(pi - beta)`, is
//! `(-1)^(l+m) dt^l_{m,0}(beta)`, so a ring and its mirror need only the even and the odd
//! degree sums of one ring. The general inverse kernel holds both sums in columns of a row
//! and multiplies the zeros of the other parity; this one keeps `C` columns per degree and
//! sends each degree to the sums of its parity: per vector of betas and degree, `C`
//! multiply-adds and the recurrence step. With so little work per step, `K` vectors run
//! together so that their recurrence chains overlap.

use super::lanes::{Lanes, Rec};
use super::state::{prefix_states, State};
use crate::simd::Simd;
use std::mem::MaybeUninit;

/// Vectors of betas whose states are set up together (through their negligible prefixes).
const VECTORS: usize = 16;

/// `acc[par C + q] += v * row[q]` for the degree `i` of parity `par` in row `fin + i C`.
///
/// # Safety
/// The CPU supports `S`'s instruction set; row `i` of `fin` holds `C` values.
#[inline(always)]
unsafe fn acc_degree<S: Simd, const C: usize>(
    acc: &mut [S::V],
    v: S::V,
    fin: *const f64,
    i: usize,
) {
    // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
    unsafe {
        let row = fin.add(i * C);
        let a = &mut acc[(i % 2) * C..][..C];
        for (q, a) in a.iter_mut().enumerate() {
            *a = S::fma(v, S::splat(*row.add(q)), *a);
        }
    }
}

/// # Safety
/// The CPU supports `S`'s instruction set; `fin` holds `rec.len()` rows of `C` values;
/// `y` is valid for writes of `2 C` columns of `lanes.tau.len()` values; every lane is in
/// the lower half (`lanes.upper_from >= lanes.tau.len()`).
#[inline(always)]
unsafe fn body<S: Simd, const W: usize, const C: usize, const K: usize>(
    rec: &Rec,
    lanes: &Lanes,
    fin: *const f64,
    y: *mut f64,
) {
    // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
    unsafe {
        let n = rec.len();
        let nb = lanes.tau.len();
        let (slope, offset) = (rec.neg_a.as_ptr(), rec.a_plus_c.as_ptr());
        let mut v0 = 0;
        while v0 < nb {
            let vectors = ((nb - v0) / W).min(VECTORS);
            let mut state_mem = [const { MaybeUninit::<State<S>>::uninit() }; VECTORS];
            let (_, states) = prefix_states::<S, W>(rec, lanes, v0, n, &mut state_mem[..vectors]);
            let mut j = 0;
            while j < vectors {
                // `k` vectors of their own; the other chains repeat the last one (not stored).
                let k = (vectors - j).min(K);
                let mut st: [State<S>; K] = [states[j]; K];
                for (c, s) in st.iter_mut().enumerate() {
                    *s = states[j + c.min(k - 1)];
                }
                let mut acc = [[S::zero(); 8]; K];
                // Each chain alone until all its lanes are active, then up to a common degree.
                for (s, a) in st.iter_mut().zip(acc.iter_mut()) {
                    s.run_slow(n, &mut |v, i| acc_degree::<S, C>(a, v, fin, i));
                }
                let i0 = st.iter().map(|s| s.i).max().unwrap_or(n);
                for (s, a) in st.iter_mut().zip(acc.iter_mut()) {
                    s.run_fast(i0, &mut |v, i| acc_degree::<S, C>(a, v, fin, i));
                }
                // A fresh copy indexed only by constants, so that it lives in registers.
                let mut sums = acc;
                let mut p0 = [S::zero(); K];
                let mut p1 = [S::zero(); K];
                let mut tau = [S::zero(); K];
                for c in 0..K {
                    (p0[c], p1[c], tau[c]) = (st[c].p0, st[c].p1, st[c].tau);
                }
                // All chains together, one degree: the step first (see `State::run_fast`).
                macro_rules! degree {
                    ($i:expr, $par:expr) => {{
                        let i = $i;
                        let (a, b) = (S::splat(*slope.add(i)), S::splat(*offset.add(i)));
                        let v = p1;
                        for c in 0..K {
                            let t = S::fma(a, tau[c], b);
                            let p2 = S::fence(S::fms(t, p1[c], p0[c]));
                            (p0[c], p1[c]) = (p1[c], p2);
                        }
                        let row = fin.add(i * C);
                        for q in 0..C {
                            let x = S::splat(*row.add(q));
                            for c in 0..K {
                                sums[c][$par * C + q] = S::fma(v[c], x, sums[c][$par * C + q]);
                            }
                        }
                    }};
                }
                let mut i = i0;
                if i < n && i % 2 == 1 {
                    degree!(i, 1);
                    i += 1;
                }
                while i + 1 < n {
                    degree!(i, 0);
                    degree!(i + 1, 1);
                    i += 2;
                }
                if i < n {
                    degree!(i, 0);
                }
                for (c, a) in sums.iter().enumerate().take(k) {
                    let s0 = v0 + (j + c) * W;
                    for (col, x) in a.iter().enumerate().take(2 * C) {
                        S::store(y.add(col * nb + s0), *x);
                    }
                }
                j += k;
            }
            v0 += vectors * W;
        }
    }
}

/// The forward kernel (see the module doc): the chains of `K` vectors of betas run over the
/// degrees as in [`body`], each degree adding `v * x` of every chain into a vector of
/// partial sums per column (`part`, lanes = betas, in L1 or L2), whose lanes are summed at
/// the end (transposed `W` rows at a time).
///
/// # Safety
/// The CPU supports `S`'s instruction set; `x` holds `2 C` columns of `lanes.tau.len()`
/// values; `part` is valid for writes of `(rec.len() C).next_multiple_of(W) W` values and
/// `ft` for `(rec.len() C).next_multiple_of(W)` values; every lane is in the lower half.
#[inline(always)]
unsafe fn forward_body<S: Simd, const W: usize, const C: usize, const K: usize>(
    rec: &Rec,
    lanes: &Lanes,
    x: *const f64,
    part: *mut f64,
    ft: *mut f64,
) {
    // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
    unsafe {
        let n = rec.len();
        let nb = lanes.tau.len();
        let rows = (n * C).next_multiple_of(W);
        std::ptr::write_bytes(part, 0, rows * W);
        let (slope, offset) = (rec.neg_a.as_ptr(), rec.a_plus_c.as_ptr());
        // `part[(i C + q) W ..][..W] += v * xc[par C + q]` for chain data `xc`.
        let add_degree = |xc: &[S::V; 8], v: S::V, i: usize| {
            let par = i % 2;
            for q in 0..C {
                let p = part.add((i * C + q) * W);
                S::store(p, S::fma(v, xc[par * C + q], S::load(p)));
            }
        };
        let mut v0 = 0;
        while v0 < nb {
            let vectors = ((nb - v0) / W).min(VECTORS);
            let mut state_mem = [const { MaybeUninit::<State<S>>::uninit() }; VECTORS];
            let (_, states) = prefix_states::<S, W>(rec, lanes, v0, n, &mut state_mem[..vectors]);
            let mut j = 0;
            while j < vectors {
                // `k` vectors of their own; the other chains repeat the last one with zero
                // data (they add nothing).
                let k = (vectors - j).min(K);
                let mut st: [State<S>; K] = [states[j]; K];
                let mut xv = [[S::zero(); 8]; K];
                for c in 0..K {
                    st[c] = states[j + c.min(k - 1)];
                    if c < k {
                        let s0 = v0 + (j + c) * W;
                        for (col, v) in xv[c].iter_mut().enumerate().take(2 * C) {
                            *v = S::load(x.add(col * nb + s0));
                        }
                    }
                }
                for (s, xc) in st.iter_mut().zip(&xv) {
                    s.run_slow(n, &mut |v, i| add_degree(xc, v, i));
                }
                let i0 = st.iter().map(|s| s.i).max().unwrap_or(n);
                for (s, xc) in st.iter_mut().zip(&xv) {
                    s.run_fast(i0, &mut |v, i| add_degree(xc, v, i));
                }
                let mut p0 = [S::zero(); K];
                let mut p1 = [S::zero(); K];
                let mut tau = [S::zero(); K];
                for c in 0..K {
                    (p0[c], p1[c], tau[c]) = (st[c].p0, st[c].p1, st[c].tau);
                }
                macro_rules! degree {
                    ($i:expr, $par:expr) => {{
                        let i = $i;
                        let (a, b) = (S::splat(*slope.add(i)), S::splat(*offset.add(i)));
                        let v = p1;
                        for c in 0..K {
                            let t = S::fma(a, tau[c], b);
                            let p2 = S::fence(S::fms(t, p1[c], p0[c]));
                            (p0[c], p1[c]) = (p1[c], p2);
                        }
                        for q in 0..C {
                            let p = part.add((i * C + q) * W);
                            let mut f = S::load(p);
                            for c in 0..K {
                                f = S::fma(v[c], xv[c][$par * C + q], f);
                            }
                            S::store(p, f);
                        }
                    }};
                }
                let mut i = i0;
                if i < n && i % 2 == 1 {
                    degree!(i, 1);
                    i += 1;
                }
                while i + 1 < n {
                    degree!(i, 0);
                    degree!(i + 1, 1);
                    i += 2;
                }
                if i < n {
                    degree!(i, 0);
                }
                j += k;
            }
            v0 += vectors * W;
        }
        // Lane sums: W rows of partial sums transposed, then added.
        let mut r = 0;
        while r < rows {
            let mut t = [S::zero(); 8];
            for (w, v) in t.iter_mut().enumerate().take(W) {
                *v = S::load(part.add((r + w) * W));
            }
            S::transpose(&mut t[..W]);
            let mut sum = t[0];
            for v in &t[1..W] {
                sum = S::add(sum, *v);
            }
            S::store(ft.add(r), sum);
            r += W;
        }
    }
}

/// A `#[target_feature]` entry point: [`body`] for one instruction set, vector width,
/// column count and number of chains.
macro_rules! entry {
    ($name:ident, $feat:literal, $S:ty, $W:literal, $C:literal, $K:literal) => {
        /// # Safety
        /// As [`body`], for the instruction set of `$S`.
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = $feat)]
        unsafe fn $name(rec: &Rec, lanes: &Lanes, fin: *const f64, y: *mut f64) {
            // SAFETY: the caller upholds `body`'s contract.
            unsafe { body::<$S, $W, $C, $K>(rec, lanes, fin, y) }
        }
    };
}

/// A `#[target_feature]` entry point: [`forward_body`] for one instruction set, vector
/// width, column count and number of chains.
macro_rules! forward_entry {
    ($name:ident, $feat:literal, $S:ty, $W:literal, $C:literal, $K:literal) => {
        /// # Safety
        /// As [`forward_body`], for the instruction set of `$S`.
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = $feat)]
        unsafe fn $name(rec: &Rec, lanes: &Lanes, x: *const f64, part: *mut f64, ft: *mut f64) {
            // SAFETY: the caller upholds `forward_body`'s contract.
            unsafe { forward_body::<$S, $W, $C, $K>(rec, lanes, x, part, ft) }
        }
    };
}

#[cfg(target_arch = "x86_64")]
use crate::simd::{avx2::Avx2, avx512::Avx512};
use crate::simd::{scalar::Scalar, Isa};

entry!(avx512_2, "avx512f,fma", Avx512, 8, 2, 4);
entry!(avx512_4, "avx512f,fma", Avx512, 8, 4, 2);
entry!(avx2_2, "avx2,fma", Avx2, 4, 2, 2);
entry!(avx2_4, "avx2,fma", Avx2, 4, 4, 2);

/// The kernel for `isa` and `c` columns (2 or 4).
///
/// # Safety
/// As [`body`]; `isa` is supported by this CPU.
pub(super) unsafe fn run(
    isa: Isa,
    c: usize,
    rec: &Rec,
    lanes: &Lanes,
    fin: *const f64,
    y: *mut f64,
) {
    // SAFETY: the caller's contract covers every kernel's and the instruction set of the
    // one chosen.
    unsafe {
        match (isa, c) {
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx512, 2) => avx512_2(rec, lanes, fin, y),
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx512, 4) => avx512_4(rec, lanes, fin, y),
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx2, 2) => avx2_2(rec, lanes, fin, y),
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx2, 4) => avx2_4(rec, lanes, fin, y),
            (_, 2) => body::<Scalar, 1, 2, 2>(rec, lanes, fin, y),
            (_, 4) => body::<Scalar, 1, 4, 2>(rec, lanes, fin, y),
            _ => unreachable!("C must be 2 or 4"),
        }
    }
}

forward_entry!(fwd_avx512_2, "avx512f,fma", Avx512, 8, 2, 4);
forward_entry!(fwd_avx512_4, "avx512f,fma", Avx512, 8, 4, 2);
forward_entry!(fwd_avx2_2, "avx2,fma", Avx2, 4, 2, 2);
forward_entry!(fwd_avx2_4, "avx2,fma", Avx2, 4, 4, 2);

/// The forward kernel for `isa` and `c` columns (2 or 4).
///
/// # Safety
/// As [`forward_body`]; `isa` is supported by this CPU.
pub(super) unsafe fn run_forward(
    isa: Isa,
    c: usize,
    rec: &Rec,
    lanes: &Lanes,
    x: *const f64,
    (part, ft): (*mut f64, *mut f64),
) {
    // SAFETY: the caller's contract covers every kernel's and the instruction set of the
    // one chosen.
    unsafe {
        match (isa, c) {
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx512, 2) => fwd_avx512_2(rec, lanes, x, part, ft),
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx512, 4) => fwd_avx512_4(rec, lanes, x, part, ft),
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx2, 2) => fwd_avx2_2(rec, lanes, x, part, ft),
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx2, 4) => fwd_avx2_4(rec, lanes, x, part, ft),
            (_, 2) => forward_body::<Scalar, 1, 2, 2>(rec, lanes, x, part, ft),
            (_, 4) => forward_body::<Scalar, 1, 4, 2>(rec, lanes, x, part, ft),
            _ => unreachable!("C must be 2 or 4"),
        }
    }
}
