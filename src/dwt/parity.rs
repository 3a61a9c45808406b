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
use crate::simd::{Simd, MAX_LANES};
use std::mem::MaybeUninit;

/// Vectors of betas whose states are set up together (through their negligible prefixes).
const VECTORS: usize = 16;

/// What a group of `K` chains does with the recurrence values of a degree: the inverse
/// accumulates them against the degree's coefficients, the forward adds their products
/// with the chains' data into the degree's partial sums.
trait Sink<S: Simd, const K: usize>: Copy {
    /// Chain `c` alone (while it catches up with the others): the values `v` of degree `i`.
    ///
    /// # Safety
    /// The CPU supports `S`'s instruction set; degree `i` is one of the kernel's.
    unsafe fn one(&mut self, c: usize, v: S::V, i: usize);
    /// All chains: the values `v` of degree `i`, whose parity is `PAR`.
    ///
    /// # Safety
    /// As for [`Sink::one`].
    unsafe fn all<const PAR: usize>(&mut self, v: &[S::V; K], i: usize);
}

/// The vectors of lanes in groups of `K` chains, each state past its negligible prefix:
/// `group(chains, first lane, k)` with `k` chains of their own (the others repeat the last
/// one; their results are to be dropped or their data zero).
///
/// # Safety
/// The CPU supports `S`'s instruction set; the lane arrays hold a multiple of `W` entries.
#[inline(always)]
unsafe fn chain_groups<'r, S: Simd, const W: usize, const K: usize>(
    rec: &Rec<'r, S::E>,
    lanes: &Lanes<S::E>,
    mut group: impl FnMut(&mut [State<'r, S>; K], usize, usize),
) {
    // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
    unsafe {
        let (n, nb) = (rec.len(), lanes.tau.len());
        let mut v0 = 0;
        while v0 < nb {
            let vectors = ((nb - v0) / W).min(VECTORS);
            let mut state_mem = [const { MaybeUninit::<State<S>>::uninit() }; VECTORS];
            let (_, states) = prefix_states::<S, W>(rec, lanes, v0, n, &mut state_mem[..vectors]);
            let mut j = 0;
            while j < vectors {
                let k = (vectors - j).min(K);
                let mut st: [State<S>; K] = [states[j]; K];
                for (c, s) in st.iter_mut().enumerate() {
                    *s = states[j + c.min(k - 1)];
                }
                group(&mut st, v0 + j * W, k);
                j += k;
            }
            v0 += vectors * W;
        }
    }
}

/// Runs the chains `st` to degree `n`: each alone until all its lanes are active, then up
/// to the degree the furthest one reached, then all together, two degrees (one of each
/// parity) per round with the recurrence step first (see `State::run_fast`).
///
/// # Safety
/// The CPU supports `S`'s instruction set; every lane is in the lower half.
#[inline(always)]
unsafe fn run_chains<S: Simd, const K: usize>(
    st: &mut [State<S>; K],
    rec: &Rec<S::E>,
    sink: &mut impl Sink<S, K>,
) {
    // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
    unsafe {
        let n = rec.len();
        for (c, s) in st.iter_mut().enumerate() {
            s.run_slow(n, &mut |v, i| sink.one(c, v, i));
        }
        let i0 = st.iter().map(|s| s.i).max().unwrap_or(n);
        for (c, s) in st.iter_mut().enumerate() {
            s.run_fast(i0, &mut |v, i| sink.one(c, v, i));
        }
        // A fresh copy indexed only by constants in the joint phase, so that its sums live
        // in registers (the phases above index them by parity at run time).
        let mut joint = *sink;
        let (slope, offset) = (rec.neg_a.as_ptr(), rec.a_plus_c.as_ptr());
        let mut p0 = [S::zero(); K];
        let mut p1 = [S::zero(); K];
        let mut tau = [S::zero(); K];
        let narrow = S::REGS == 16;
        for c in 0..K {
            (p0[c], p1[c], tau[c]) = (st[c].p0, st[c].p1, st[c].tau);
        }
        macro_rules! degree {
            ($i:expr, $par:literal) => {{
                let i = $i;
                let (a, b) = (S::splat(*slope.add(i)), S::splat(*offset.add(i)));
                let v = p1;
                for c in 0..K {
                    // With AVX2's 16 registers the arguments are read from memory at each
                    // step (a volatile read, which LLVM keeps in the loop): held in
                    // registers they push a sum onto the stack, where the store-to-load
                    // latency lands on its chain.
                    let tc = if narrow {
                        std::ptr::read_volatile(&tau[c])
                    } else {
                        tau[c]
                    };
                    let t = S::fma(a, tc, b);
                    let p2 = S::fence(S::fms(t, p1[c], p0[c]));
                    (p0[c], p1[c]) = (p1[c], p2);
                }
                joint.all::<$par>(&v, i);
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
        *sink = joint;
    }
}

/// The inverse's sink: per chain, the sums of each parity and column (`2 C` of 8), against
/// the coefficient rows `fin` (`C` values per degree).
#[derive(Clone, Copy)]
struct InverseSums<S: Simd, const C: usize, const K: usize> {
    sums: [[S::V; 8]; K],
    fin: *const S::E,
}

impl<S: Simd, const C: usize, const K: usize> Sink<S, K> for InverseSums<S, C, K> {
    #[inline(always)]
    unsafe fn one(&mut self, c: usize, v: S::V, i: usize) {
        // SAFETY: row `i` of `fin` holds `C` values (the kernel's contract).
        unsafe {
            let row = self.fin.add(i * C);
            let sums = &mut self.sums[c][(i % 2) * C..][..C];
            for (q, a) in sums.iter_mut().enumerate() {
                *a = S::fma(v, S::splat(*row.add(q)), *a);
            }
        }
    }

    #[inline(always)]
    unsafe fn all<const PAR: usize>(&mut self, v: &[S::V; K], i: usize) {
        // SAFETY: as in `one`.
        unsafe {
            let row = self.fin.add(i * C);
            for q in 0..C {
                let x = S::splat(*row.add(q));
                for (c, vc) in v.iter().enumerate() {
                    self.sums[c][PAR * C + q] = S::fma(*vc, x, self.sums[c][PAR * C + q]);
                }
            }
        }
    }
}

/// # Safety
/// The CPU supports `S`'s instruction set; `fin` holds `rec.len()` rows of `C` values;
/// `y` is valid for writes of `2 C` columns of `lanes.tau.len()` values; every lane is in
/// the lower half (`lanes.upper_from >= lanes.tau.len()`).
#[inline(always)]
unsafe fn body<S: Simd, const W: usize, const C: usize, const K: usize>(
    rec: &Rec<S::E>,
    lanes: &Lanes<S::E>,
    fin: *const S::E,
    y: *mut S::E,
) {
    // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
    unsafe {
        let nb = lanes.tau.len();
        chain_groups::<S, W, K>(rec, lanes, |st, s0, k| {
            let mut sink = InverseSums::<S, C, K> {
                sums: [[S::zero(); 8]; K],
                fin,
            };
            run_chains(st, rec, &mut sink);
            // Only the chains of their own are stored.
            for (c, a) in sink.sums.iter().enumerate().take(k) {
                for (col, x) in a.iter().enumerate().take(2 * C) {
                    S::store(y.add(col * nb + s0 + c * W), *x);
                }
            }
        });
    }
}

/// The forward's sink: per chain its data (`2 C` columns of 8, zero for the chains that
/// repeat another), added into the partial sums `part` (`W` lanes per degree and column).
#[derive(Clone, Copy)]
struct ForwardSums<S: Simd, const W: usize, const C: usize, const K: usize> {
    data: [[S::V; 8]; K],
    part: *mut S::E,
}

impl<S: Simd, const W: usize, const C: usize, const K: usize> ForwardSums<S, W, C, K> {
    /// `part[(i C + q) W ..][..W] += sum over chains of v * data[par C + q]`.
    ///
    /// # Safety
    /// The CPU supports `S`'s instruction set; the rows of degree `i` are inside `part`.
    #[inline(always)]
    unsafe fn add(
        &mut self,
        chains: impl Iterator<Item = (usize, S::V)> + Clone,
        i: usize,
        par: usize,
    ) {
        // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
        unsafe {
            for q in 0..C {
                let p = self.part.add((i * C + q) * W);
                let mut f = S::load(p);
                for (c, v) in chains.clone() {
                    f = S::fma(v, self.data[c][par * C + q], f);
                }
                S::store(p, f);
            }
        }
    }
}

impl<S: Simd, const W: usize, const C: usize, const K: usize> Sink<S, K>
    for ForwardSums<S, W, C, K>
{
    #[inline(always)]
    unsafe fn one(&mut self, c: usize, v: S::V, i: usize) {
        // SAFETY: degree `i`'s rows are inside `part` (the kernel's contract).
        unsafe { self.add(std::iter::once((c, v)), i, i % 2) }
    }

    #[inline(always)]
    unsafe fn all<const PAR: usize>(&mut self, v: &[S::V; K], i: usize) {
        // SAFETY: as in `one`.
        unsafe { self.add(v.iter().copied().enumerate(), i, PAR) }
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
    rec: &Rec<S::E>,
    lanes: &Lanes<S::E>,
    x: *const S::E,
    part: *mut S::E,
    ft: *mut S::E,
) {
    // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
    unsafe {
        let n = rec.len();
        let nb = lanes.tau.len();
        let rows = (n * C).next_multiple_of(W);
        std::ptr::write_bytes(part, 0, rows * W);
        chain_groups::<S, W, K>(rec, lanes, |st, s0, k| {
            let mut sink = ForwardSums::<S, W, C, K> {
                data: [[S::zero(); 8]; K],
                part,
            };
            for (c, d) in sink.data.iter_mut().enumerate().take(k) {
                for (col, v) in d.iter_mut().enumerate().take(2 * C) {
                    *v = S::load(x.add(col * nb + s0 + c * W));
                }
            }
            run_chains(st, rec, &mut sink);
        });
        // Lane sums: W rows of partial sums transposed, then added.
        let mut r = 0;
        while r < rows {
            let mut t = [S::zero(); MAX_LANES];
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
    ($name:ident, $feat:literal, $S:ty, $E:ty, $W:literal, $C:literal, $K:literal) => {
        /// # Safety
        /// As [`body`], for the instruction set of `$S`.
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = $feat)]
        unsafe fn $name(rec: &Rec<$E>, lanes: &Lanes<$E>, fin: *const $E, y: *mut $E) {
            // SAFETY: the caller upholds `body`'s contract.
            unsafe { body::<$S, $W, $C, $K>(rec, lanes, fin, y) }
        }
    };
}

/// A `#[target_feature]` entry point: [`forward_body`] for one instruction set, vector
/// width, column count and number of chains.
macro_rules! forward_entry {
    ($name:ident, $feat:literal, $S:ty, $E:ty, $W:literal, $C:literal, $K:literal) => {
        /// # Safety
        /// As [`forward_body`], for the instruction set of `$S`.
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = $feat)]
        unsafe fn $name(
            rec: &Rec<$E>,
            lanes: &Lanes<$E>,
            x: *const $E,
            part: *mut $E,
            ft: *mut $E,
        ) {
            // SAFETY: the caller upholds `forward_body`'s contract.
            unsafe { forward_body::<$S, $W, $C, $K>(rec, lanes, x, part, ft) }
        }
    };
}

#[cfg(target_arch = "x86_64")]
use crate::simd::{avx2::Avx2, avx2_f32::Avx2F32, avx512::Avx512, avx512_f32::Avx512F32};
use crate::simd::{
    scalar::{Scalar, ScalarF32},
    Isa,
};

entry!(avx512_2, "avx512f,fma", Avx512, f64, 8, 2, 4);
entry!(avx512_4, "avx512f,fma", Avx512, f64, 8, 4, 2);
entry!(avx2_2, "avx2,fma", Avx2, f64, 4, 2, 2);
entry!(avx2_4, "avx2,fma", Avx2, f64, 4, 4, 2);
entry!(avx512_f32_2, "avx512f,fma", Avx512F32, f32, 16, 2, 4);
entry!(avx512_f32_4, "avx512f,fma", Avx512F32, f32, 16, 4, 2);
entry!(avx2_f32_2, "avx2,fma", Avx2F32, f32, 8, 2, 2);
entry!(avx2_f32_4, "avx2,fma", Avx2F32, f32, 8, 4, 2);

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

forward_entry!(fwd_avx512_2, "avx512f,fma", Avx512, f64, 8, 2, 4);
forward_entry!(fwd_avx512_4, "avx512f,fma", Avx512, f64, 8, 4, 2);
forward_entry!(fwd_avx2_2, "avx2,fma", Avx2, f64, 4, 2, 2);
forward_entry!(fwd_avx2_4, "avx2,fma", Avx2, f64, 4, 4, 2);
forward_entry!(fwd_avx512_f32_2, "avx512f,fma", Avx512F32, f32, 16, 2, 4);
forward_entry!(fwd_avx512_f32_4, "avx512f,fma", Avx512F32, f32, 16, 4, 2);
forward_entry!(fwd_avx2_f32_2, "avx2,fma", Avx2F32, f32, 8, 2, 2);
forward_entry!(fwd_avx2_f32_4, "avx2,fma", Avx2F32, f32, 8, 4, 2);

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

/// [`run`] for floats.
///
/// # Safety
/// As [`run`]; the lane arrays hold a multiple of `isa.lanes_of::<f32>()` entries.
pub(super) unsafe fn run_f32(
    isa: Isa,
    c: usize,
    rec: &Rec<f32>,
    lanes: &Lanes<f32>,
    fin: *const f32,
    y: *mut f32,
) {
    // SAFETY: the caller's contract covers every kernel's and the instruction set of the
    // one chosen.
    unsafe {
        match (isa, c) {
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx512, 2) => avx512_f32_2(rec, lanes, fin, y),
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx512, 4) => avx512_f32_4(rec, lanes, fin, y),
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx2, 2) => avx2_f32_2(rec, lanes, fin, y),
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx2, 4) => avx2_f32_4(rec, lanes, fin, y),
            (_, 2) => body::<ScalarF32, 1, 2, 2>(rec, lanes, fin, y),
            (_, 4) => body::<ScalarF32, 1, 4, 2>(rec, lanes, fin, y),
            _ => unreachable!("C must be 2 or 4"),
        }
    }
}

/// [`run_forward`] for floats.
///
/// # Safety
/// As [`run_forward`]; the lane arrays hold a multiple of `isa.lanes_of::<f32>()` entries.
pub(super) unsafe fn run_forward_f32(
    isa: Isa,
    c: usize,
    rec: &Rec<f32>,
    lanes: &Lanes<f32>,
    x: *const f32,
    (part, ft): (*mut f32, *mut f32),
) {
    // SAFETY: the caller's contract covers every kernel's and the instruction set of the
    // one chosen.
    unsafe {
        match (isa, c) {
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx512, 2) => fwd_avx512_f32_2(rec, lanes, x, part, ft),
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx512, 4) => fwd_avx512_f32_4(rec, lanes, x, part, ft),
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx2, 2) => fwd_avx2_f32_2(rec, lanes, x, part, ft),
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx2, 4) => fwd_avx2_f32_4(rec, lanes, x, part, ft),
            (_, 2) => forward_body::<ScalarF32, 1, 2, 2>(rec, lanes, x, part, ft),
            (_, 4) => forward_body::<ScalarF32, 1, 4, 2>(rec, lanes, x, part, ft),
            _ => unreachable!("C must be 2 or 4"),
        }
    }
}
