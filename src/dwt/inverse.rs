//! The inverse kernel: `y[row(s)][q] = sum_i dt_{l0+i}(beta_s) fin[i][q]`.

use super::lanes::{Lanes, Rec};
use super::state::{prefix_states, State};
use crate::simd::Simd;
use std::mem::MaybeUninit;

/// `acc[q] += v * row[q]` (the inverse kernel's accumulation of one degree).
///
/// # Safety
/// The CPU supports `S`'s instruction set; the pointers are valid for the rows and
/// entries read or written (`P` values an input row, the output rows of the lanes).
#[inline(always)]
unsafe fn acc_row<S: Simd, const P: usize>(acc: &mut [S::V; P], v: S::V, row: *const S::E) {
    // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
    unsafe {
        for (q, a) in acc.iter_mut().enumerate() {
            *a = S::fma(v, S::splat(*row.add(q)), *a);
        }
    }
}

/// Whether the 8-column kernel runs two vectors of betas together (16 sums in registers:
/// AVX-512 and scalar code; `regs` = 16 (AVX2) would spill the sums).
const fn paired_vectors(regs: usize, p: usize) -> bool {
    p <= 8 && regs >= 32
}

/// Passes over the columns per vector of betas: with AVX2's 16 registers, 16 sums do not
/// fit beside the recurrence, so the columns go in two halves of 8 (see [`two_passes`]).
const fn column_passes(regs: usize, p: usize) -> usize {
    if regs == 16 && p == 16 {
        2
    } else {
        1
    }
}

/// Degrees per block of [`two_passes`] (its buffer of d values: 2 KiB with AVX2).
const PASS_BLOCK: usize = 64;

/// One vector's sums of `P = 16` columns in two passes of 8 per block of degrees: the
/// first runs the recurrence, adds to columns `0..8` and keeps each degree's values in a
/// small buffer; the second reads them back for columns `8..16`. Eight sums and the
/// recurrence fit 16 registers; each column's sum is the same chain of multiply-adds as
/// in the one-pass kernel.
///
/// # Safety
/// As [`inverse_body`]; `fin` holds `n` rows of `P` values.
#[inline(always)]
unsafe fn two_passes<S: Simd, const P: usize>(
    s: &mut State<S>,
    n: usize,
    fin: *const S::E,
    acc: &mut [S::V; P],
) {
    // SAFETY: this function's contract (see `# Safety`), upheld by the caller; the
    // buffer index `i - i0` is below `PASS_BLOCK` (`i0 <= i < i1 <= i0 + PASS_BLOCK`), and
    // the second pass reads only entries the first wrote in the same block: the run calls
    // back at every degree from the first accumulated one (`first`) on.
    unsafe {
        const H: usize = 8;
        // Each half's sums are kept in memory between its loops and in locals during them
        // (the opaque use of their address makes the reload real): left alone, LLVM keeps
        // both halves in registers throughout and spills sums inside the loops instead.
        let (mut lo_mem, mut hi_mem) = ([S::zero(); H], [S::zero(); H]);
        // Written by the first pass before the second reads it (from the first degree
        // accumulated on, the run calls back at every degree); not cleared per vector.
        let mut d = [const { MaybeUninit::<S::V>::uninit() }; PASS_BLOCK];
        // First degree accumulated: the run calls back from there on, in every block.
        let mut first = n;
        let mut i0 = s.i;
        while i0 < n {
            let i1 = (i0 + PASS_BLOCK).min(n);
            let mut lo = lo_mem;
            let mut add = |v: S::V, i: usize| {
                acc_row::<S, H>(&mut lo, v, fin.add(i * P));
                d.get_unchecked_mut(i - i0).write(v);
                first = first.min(i);
            };
            s.run_slow(i1, &mut add);
            s.run_fast(i1, &mut add);
            lo_mem = lo;
            std::hint::black_box(&mut lo_mem);
            let mut hi = hi_mem;
            for i in first.max(i0)..i1 {
                let v = d.get_unchecked(i - i0).assume_init();
                acc_row::<S, H>(&mut hi, v, fin.add(i * P + H));
            }
            hi_mem = hi;
            std::hint::black_box(&mut hi_mem);
            i0 = i1;
        }
        let (lo, hi) = (lo_mem, hi_mem);
        acc[..H].copy_from_slice(&lo);
        acc[H..2 * H].copy_from_slice(&hi);
    }
}

/// Fills rows `from..to` of the inverse kernel's input (see [`crate::dwt::inverse_raw`]).
pub type Fill<'a, E = f64> = &'a mut dyn FnMut(&mut [E], usize, usize);

/// Vectors of betas whose states the inverse kernel sets up before it needs their input
/// rows.
pub(super) const INV_VECTORS: usize = 16;

/// # Safety
/// The CPU supports `S`'s instruction set; the pointers are valid for the rows and
/// entries read or written (`P` values an input row, the output rows of the lanes).
#[inline(always)]
unsafe fn inverse_body<S: Simd, const W: usize, const P: usize, const NT: bool>(
    rec: &Rec<S::E>,
    lanes: &Lanes<S::E>,
    fin: &mut [S::E],
    fill: Fill<S::E>,
    y: *mut S::E,
) {
    // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
    unsafe {
        let n = rec.len();
        let nb = lanes.tau.len();
        debug_assert!(nb.is_multiple_of(W) && fin.len() >= n * P);
        let (pair_stride, row_gap) = lanes.pair_layout(P);
        let mut prefetch = lanes.prefetch;
        let prefetch_per_vector = prefetch.lines().div_ceil((nb / W).max(1));
        // Rows `have..n` of `fin` are filled.
        let mut have = n;
        let mut v0 = 0;
        while v0 < nb {
            // Up to INV_VECTORS vectors through their negligible prefixes, then the rows from
            // the first degree any of them needs.
            let vectors = ((nb - v0) / W).min(INV_VECTORS);
            let mut state_mem = [const { MaybeUninit::<State<S>>::uninit() }; INV_VECTORS];
            let (first, states) =
                prefix_states::<S, W>(rec, lanes, v0, n, &mut state_mem[..vectors]);
            if first < have {
                fill(fin, first, have);
                have = first;
            }
            let fin_rows = fin.as_ptr();
            let mut vector = 0;
            while vector < vectors {
                // With 8 columns, two vectors run together once both are fully active: each
                // data broadcast then feeds two multiply-adds, and the two recurrences are
                // independent chains (one vector's step and 8 multiply-adds per degree leave
                // the pipes half idle).
                let pair = paired_vectors(S::REGS, P) && vector + 1 < vectors;
                let mut run_states = [states[vector], states[(vector + 1).min(vectors - 1)]];
                let mut acc = [[S::zero(); P]; 2];
                prefetch.issue(prefetch_per_vector * (1 + pair as usize));
                if pair {
                    let [a0, a1] = &mut acc;
                    for (s, a) in run_states.iter_mut().zip([&mut *a0, &mut *a1]) {
                        s.run_slow(n, &mut |v, i| acc_row::<S, P>(a, v, fin_rows.add(i * P)));
                    }
                    // The one behind catches up alone, then both run together.
                    let i0 = run_states[0].i.max(run_states[1].i);
                    for (s, a) in run_states.iter_mut().zip([&mut *a0, &mut *a1]) {
                        s.run_fast(i0, &mut |v, i| acc_row::<S, P>(a, v, fin_rows.add(i * P)));
                    }
                    let [s0, s1] = &mut run_states;
                    let (mut p0, mut p1, mut r0, mut r1) = (s0.p0, s0.p1, s1.p0, s1.p1);
                    for i in i0..n {
                        let (v, u) = (p1, r1);
                        let p2 = S::fence(s0.step(p0, p1, i));
                        let r2 = S::fence(s1.step(r0, r1, i));
                        (p0, p1, r0, r1) = (p1, p2, r1, r2);
                        let row = fin_rows.add(i * P);
                        for q in 0..P {
                            let c = S::splat(*row.add(q));
                            a0[q] = S::fma(v, c, a0[q]);
                            a1[q] = S::fma(u, c, a1[q]);
                        }
                    }
                } else if column_passes(S::REGS, P) == 2 {
                    let mut s = run_states[0];
                    two_passes::<S, P>(&mut s, n, fin_rows, &mut acc[0]);
                } else {
                    // A local copy, so the state lives in registers during the run.
                    let mut s = run_states[0];
                    let a = &mut acc[0];
                    s.run(n, |v, i| acc_row::<S, P>(a, v, fin_rows.add(i * P)));
                }
                // Rows of the output are lanes: each W x W block of (order column, lane) is
                // transposed in registers on the way out, and with `lanes.stream` written
                // without reading the lines first (see `Lanes::stream`).
                // `NT` is a parameter of the kernel: a run-time branch here changes the
                // register allocation of the 8-column kernel and slows it down markedly.
                for (k, a) in acc.iter().enumerate().take(1 + pair as usize) {
                    // Interleaved rows step by 2: one pair of rows to the next.
                    let (r0, step) = lanes.rows(v0 + (vector + k) * W);
                    let (at, stride) = (
                        (r0 / 2) * pair_stride + (r0 % 2) * row_gap,
                        if step == 2 { pair_stride } else { P },
                    );
                    for q0 in (0..P).step_by(W) {
                        let cols = &a[q0..(q0 + W).min(P)];
                        S::store_transposed::<W>(cols, y.add(at + q0), stride, NT);
                    }
                }
                vector += 1 + pair as usize;
            }
            v0 += vectors * W;
        }
    }
}

/// A `#[target_feature]` entry point: [`inverse_body`] for one instruction set, vector
/// width and column count.
macro_rules! entry {
    ($name:ident, $feat:literal, $S:ty, $E:ty, $W:literal, $N:literal) => {
        /// # Safety
        /// As [`inverse_body`], for the instruction set of `$S`.
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = $feat)]
        unsafe fn $name<const NT: bool>(
            rec: &Rec<$E>,
            lanes: &Lanes<$E>,
            fin: &mut [$E],
            fill: Fill<$E>,
            y: *mut $E,
        ) {
            // SAFETY: the caller upholds `inverse_body`'s contract.
            unsafe { inverse_body::<$S, $W, $N, NT>(rec, lanes, fin, fill, y) }
        }
    };
}

#[cfg(target_arch = "x86_64")]
use crate::simd::{avx2::Avx2, avx2_f32::Avx2F32, avx512::Avx512, avx512_f32::Avx512F32};
use crate::simd::{
    scalar::{Scalar, ScalarF32},
    Isa,
};

entry!(inv_avx512_16, "avx512f,fma", Avx512, f64, 8, 16);
entry!(inv_avx512_8, "avx512f,fma", Avx512, f64, 8, 8);
entry!(inv_avx2_16, "avx2,fma", Avx2, f64, 4, 16);
entry!(inv_avx2_8, "avx2,fma", Avx2, f64, 4, 8);
entry!(inv_avx512_f32_16, "avx512f,fma", Avx512F32, f32, 16, 16);
entry!(inv_avx512_f32_8, "avx512f,fma", Avx512F32, f32, 16, 8);
entry!(inv_avx2_f32_16, "avx2,fma", Avx2F32, f32, 8, 16);
entry!(inv_avx2_f32_8, "avx2,fma", Avx2F32, f32, 8, 8);

/// The inverse kernel for `isa` and `p` columns (8 or 16).
///
/// # Safety
/// `isa` is supported by this CPU; `fin` holds `n * p` values; every row of the lanes is
/// valid for writes at its place after `y` (see `dwt::inverse_raw`) and written by no one
/// else meanwhile; the lane arrays hold `lanes.tau.len()` entries, a multiple of
/// `isa.lanes()`.
pub(super) unsafe fn run(
    isa: Isa,
    p: usize,
    rec: &Rec,
    lanes: &Lanes,
    fin: &mut [f64],
    fill: Fill,
    y: *mut f64,
) {
    // SAFETY: the caller's contract covers every kernel's (`inverse_body`'s) and the
    // instruction set of the one chosen.
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

/// [`run`] for floats: 16-lane vectors with AVX-512, 8-lane vectors with AVX2.
///
/// # Safety
/// As [`run`]; the lane arrays hold a multiple of `isa.lanes_of::<f32>()` entries.
pub(super) unsafe fn run_f32(
    isa: Isa,
    p: usize,
    rec: &Rec<f32>,
    lanes: &Lanes<f32>,
    fin: &mut [f32],
    fill: Fill<f32>,
    y: *mut f32,
) {
    // SAFETY: the caller's contract covers every kernel's (`inverse_body`'s) and the
    // instruction set of the one chosen (every AVX-512 CPU has AVX2).
    unsafe {
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
            (Isa::Avx512, 16) => nt!(inv_avx512_f32_16),
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx512, 8) => nt!(inv_avx512_f32_8),
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx2, 16) => nt!(inv_avx2_f32_16),
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx2, 8) => nt!(inv_avx2_f32_8),
            (_, 16) => nt!(inverse_body::<ScalarF32, 1, 16>),
            (_, 8) => nt!(inverse_body::<ScalarF32, 1, 8>),
            _ => unreachable!("P must be 8 or 16"),
        }
    }
    crate::simd::sfence();
}
