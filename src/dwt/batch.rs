//! The batched inverse: the transforms of a batch share each cluster's recurrence.
//!
//! The single kernels fuse the recurrence with one transform's multiply-adds. Here the
//! Wigner-d values of every degree of two vectors of betas are computed once into a small
//! buffer (their recurrences run together, `2 n W` doubles, in L1 up to a few hundred
//! degrees), and each transform of the batch runs only the multiply-adds against it:
//! `y_t[row(s)][q] = sum_i dt_{l0+i}(beta_s) fin_t[i][q]`, with the sums held as vectors
//! over the columns of one lane (no transposes on the way out), each d value a broadcast
//! feeding `16 / W` multiply-adds (two transforms at once for 8 columns).
//!
//! Every output value is the same chain of fused multiply-adds in the same order as in
//! the single kernel (`inverse`): a batch gives bitwise the results of single calls.
//! (A batch's forward runs the single forward kernel per transform: with the next
//! transform's rows prefetched it was faster than a shared recurrence.)

use super::inverse::INV_VECTORS;
use super::lanes::{Lanes, Prefetch, Rec};
use super::state::{prefix_states, State};
use crate::simd::Simd;
use std::mem::MaybeUninit;

/// Vectors whose recurrences the inverse runs together (independent chains in flight).
const CHAINS: usize = 2;

/// Runs the chains `st[..used]` from their states to degree `n`, storing each degree's
/// values (masked to the active lanes while some are not) at `tiles[k] + i W`; returns the
/// first degree stored for each chain (`n` for the unused ones). The values are those the
/// single inverse kernel accumulates (`State::run`), bit for bit.
///
/// # Safety
/// The CPU supports `S`'s instruction set; `tiles[k]` holds `n W` values; degree indices
/// stay below the padded length of the coefficients.
#[inline(always)]
unsafe fn fill_tiles<S: Simd, const W: usize, const K: usize>(
    st: &mut [State<S>; K],
    used: usize,
    n: usize,
    tiles: [*mut S::E; K],
) -> [usize; K] {
    // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
    unsafe {
        let mut lo = [n; K];
        // Each chain alone until all its lanes are active, then up to the degree the
        // furthest one reached, then all together (as `State::run_slow`, `run_fast`).
        for k in 0..used {
            let (t, l) = (tiles[k], &mut lo[k]);
            let mut store = |v: S::V, i: usize| {
                S::store(t.add(i * W), v);
                *l = (*l).min(i);
            };
            st[k].run_slow(n, &mut store);
        }
        let i0 = st[..used].iter().map(|s| s.i).max().unwrap_or(n);
        for k in 0..used {
            let (t, l) = (tiles[k], &mut lo[k]);
            let mut store = |v: S::V, i: usize| {
                S::store(t.add(i * W), v);
                *l = (*l).min(i);
            };
            st[k].run_fast(i0, &mut store);
            lo[k] = lo[k].min(i0);
        }
        // Unused chains repeat the last one into their own tiles.
        let (mut p0, mut p1) = ([S::zero(); K], [S::zero(); K]);
        for k in 0..K {
            let s = &st[k.min(used - 1)];
            (p0[k], p1[k]) = (s.p0, s.p1);
        }
        for i in i0..n {
            for k in 0..K {
                S::store(tiles[k].add(i * W), p1[k]);
                let p2 = S::fence(st[k.min(used - 1)].step(p0[k], p1[k], i));
                (p0[k], p1[k]) = (p1[k], p2);
            }
        }
        lo
    }
}

/// Fills rows `from..to` of transform `t`'s input (see [`crate::dwt::inverse_batch_raw`]).
pub type BatchFill<'a, E = f64> = &'a mut dyn FnMut(usize, &mut [E], usize, usize);

/// The rows of a batch's transforms: transform `t`'s array at `base + t * dist`.
#[derive(Clone, Copy)]
pub struct BatchRows<T> {
    /// Transform 0's array.
    pub base: T,
    /// Values from one transform's array to the next.
    pub dist: usize,
    /// Transforms.
    pub count: usize,
}

/// Values of the inverse's d-value buffer for `n` degrees and vectors of `w` lanes.
pub fn inverse_tile_len(n: usize, w: usize) -> usize {
    CHAINS * n * w
}

/// The multiply-adds of one vector of lanes for transforms `t .. t + K` from degree `lo`:
/// `acc[w][k][h] += d_i[w] * fin_{t+k}[i][h W ..]`, then the sums stored as the lanes'
/// output rows.
///
/// # Safety
/// The CPU supports `S`'s instruction set; `tile` holds the vector's values for degrees
/// `lo..n` (`W` doubles each); the inputs hold `n` rows of `P` values; the output rows
/// `rows(w)` are valid for `P` doubles each and nobody else's.
#[inline(always)]
unsafe fn lane_sums<S: Simd, const W: usize, const P: usize, const K: usize, const NT: bool>(
    tile: *const S::E,
    (lo, n): (usize, usize),
    fin: [*const S::E; K],
    out: [*mut S::E; K],
    rows: &impl Fn(usize) -> usize,
    (hint, lines): (&mut Prefetch, usize),
) {
    // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
    unsafe {
        // Instantiated (never called) for `P = 16` with two transforms as well.
        debug_assert!(K * P <= 16);
        let cv = P / W;
        // Lanes per pass over the degrees: all of them where the sums fit the registers
        // beside the coefficients (AVX-512's 32), a part with AVX2's 16 (8 sums a pass).
        let lanes_per_pass = if S::REGS == 16 {
            (8 / (K * cv)).clamp(1, W)
        } else {
            W
        };
        hint.issue(lines);
        let mut w0 = 0;
        while w0 < W {
            let mut acc = [S::zero(); 16];
            for i in lo..n {
                let mut f = [S::zero(); 16];
                for k in 0..K {
                    for h in 0..cv {
                        f[k * cv + h] = S::load(fin[k].add(i * P + h * W));
                    }
                }
                for w in 0..lanes_per_pass {
                    let v = S::splat(*tile.add(i * W + w0 + w));
                    for k in 0..K {
                        for h in 0..cv {
                            let a = &mut acc[(w * K + k) * cv + h];
                            *a = S::fma(v, f[k * cv + h], *a);
                        }
                    }
                }
            }
            for w in 0..lanes_per_pass {
                let r = rows(w0 + w);
                for k in 0..K {
                    for h in 0..cv {
                        let x = acc[(w * K + k) * cv + h];
                        let p = out[k].add(r + h * W);
                        if NT {
                            S::stream(p, x);
                        } else {
                            S::store(p, x);
                        }
                    }
                }
            }
            w0 += lanes_per_pass;
        }
    }
}

/// Inverse of a batch (see [`crate::dwt::inverse_batch_raw`]).
///
/// # Safety
/// The CPU supports `S`'s instruction set; `fin` holds `count` inputs of `n P` values
/// `fin.dist` apart, `hints` one entry per transform; `tile` holds [`inverse_tile_len`] values; every output row of every
/// transform is valid for writes and nobody else's.
#[inline(always)]
unsafe fn inverse_body<S: Simd, const W: usize, const P: usize, const NT: bool>(
    rec: &Rec<S::E>,
    lanes: &Lanes<S::E>,
    (fin, fill, hints): (BatchRows<*mut S::E>, BatchFill<S::E>, &mut [Prefetch]),
    tile: *mut S::E,
    y: BatchRows<*mut S::E>,
) {
    // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
    unsafe {
        let (n, nb) = (rec.len(), lanes.tau.len());
        // Lines of a transform's hints issued per vector of lanes.
        let per_vector = |h: &Prefetch| h.lines().div_ceil((nb / W).max(1));
        let count = fin.count;
        let mut have = n;
        let mut v0 = 0;
        while v0 < nb {
            let vectors = ((nb - v0) / W).min(INV_VECTORS);
            let mut state_mem = [const { MaybeUninit::<State<S>>::uninit() }; INV_VECTORS];
            let (first, states) =
                prefix_states::<S, W>(rec, lanes, v0, n, &mut state_mem[..vectors]);
            if first < have {
                for t in 0..count {
                    let rows = std::slice::from_raw_parts_mut(fin.base.add(t * fin.dist), n * P);
                    fill(t, rows, first, have);
                }
                have = first;
            }
            let mut vector = 0;
            while vector < vectors {
                let used = (vectors - vector).min(CHAINS);
                let mut st = [states[vector]; CHAINS];
                for (k, s) in st.iter_mut().enumerate().take(used) {
                    *s = states[vector + k];
                }
                let tiles: [*mut S::E; CHAINS] = std::array::from_fn(|k| tile.add(k * n * W));
                let lo = fill_tiles::<S, W, CHAINS>(&mut st, used, n, tiles);
                let at = |b: BatchRows<*mut S::E>, t: usize| b.base.add(t * b.dist);
                let mut t = 0;
                while t < count {
                    // Two transforms at once with 8 columns (16 sums), one with 16.
                    let two = P == 8 && t + 1 < count;
                    let lines_t = per_vector(&hints[t]);
                    for (k, &lo_k) in lo.iter().enumerate().take(used) {
                        let (at0, stride) = lanes.vector_rows(v0 + (vector + k) * W, P);
                        let rows = |w: usize| at0 + w * stride;
                        if two {
                            let lines = per_vector(&hints[t + 1]);
                            hints[t + 1].issue(lines);
                            lane_sums::<S, W, P, 2, NT>(
                                tiles[k],
                                (lo_k, n),
                                [at(fin, t).cast_const(), at(fin, t + 1).cast_const()],
                                [at(y, t), at(y, t + 1)],
                                &rows,
                                (&mut hints[t], lines_t),
                            );
                        } else {
                            lane_sums::<S, W, P, 1, NT>(
                                tiles[k],
                                (lo_k, n),
                                [at(fin, t).cast_const()],
                                [at(y, t)],
                                &rows,
                                (&mut hints[t], lines_t),
                            );
                        }
                    }
                    t += 1 + two as usize;
                }
                vector += used;
            }
            v0 += vectors * W;
        }
    }
}

/// `#[target_feature]` entry points: [`inverse_body`] for one instruction set, vector
/// width and column count.
macro_rules! entry {
    ($inv:ident, $feat:literal, $S:ty, $E:ty, $W:literal, $N:literal) => {
        /// # Safety
        /// As [`inverse_body`], for the instruction set of `$S`.
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = $feat)]
        unsafe fn $inv<const NT: bool>(
            rec: &Rec<$E>,
            lanes: &Lanes<$E>,
            fin: (BatchRows<*mut $E>, BatchFill<$E>, &mut [Prefetch]),
            tile: *mut $E,
            y: BatchRows<*mut $E>,
        ) {
            // SAFETY: the caller upholds `inverse_body`'s contract.
            unsafe { inverse_body::<$S, $W, $N, NT>(rec, lanes, fin, tile, y) }
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
entry!(inv_avx2_f32_16, "avx2,fma", Avx2F32, f32, 8, 16);
entry!(inv_avx2_f32_8, "avx2,fma", Avx2F32, f32, 8, 8);

/// The batched inverse for `isa` and `p` columns (8 or 16).
///
/// # Safety
/// As [`inverse_body`]; `isa` is supported by this CPU.
pub(super) unsafe fn run_inverse(
    isa: Isa,
    p: usize,
    (rec, lanes): (&Rec, &Lanes),
    fin: (BatchRows<*mut f64>, BatchFill, &mut [Prefetch]),
    tile: *mut f64,
    y: BatchRows<*mut f64>,
) {
    // SAFETY: the caller's contract covers every kernel's (`inverse_body`'s) and the
    // instruction set of the one chosen.
    unsafe {
        macro_rules! nt {
            ($f:ident $(::<$($g:tt),*>)?) => {
                if lanes.stream {
                    $f::<$($($g,)*)? true>(rec, lanes, fin, tile, y)
                } else {
                    $f::<$($($g,)*)? false>(rec, lanes, fin, tile, y)
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
    crate::simd::sfence();
}

/// [`run_inverse`] for floats: 16-lane vectors for 16 columns with AVX-512, 8-lane
/// vectors otherwise (a lane's 8 columns would fill half a 16-lane vector).
///
/// # Safety
/// As [`run_inverse`].
pub(super) unsafe fn run_inverse_f32(
    isa: Isa,
    p: usize,
    (rec, lanes): (&Rec<f32>, &Lanes<f32>),
    fin: (BatchRows<*mut f32>, BatchFill<f32>, &mut [Prefetch]),
    tile: *mut f32,
    y: BatchRows<*mut f32>,
) {
    // SAFETY: the caller's contract covers every kernel's (`inverse_body`'s) and the
    // instruction set of the one chosen (every AVX-512 CPU has AVX2).
    unsafe {
        macro_rules! nt {
            ($f:ident $(::<$($g:tt),*>)?) => {
                if lanes.stream {
                    $f::<$($($g,)*)? true>(rec, lanes, fin, tile, y)
                } else {
                    $f::<$($($g,)*)? false>(rec, lanes, fin, tile, y)
                }
            };
        }
        match (isa, p) {
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx512, 16) => nt!(inv_avx512_f32_16),
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx2, 16) => nt!(inv_avx2_f32_16),
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx512 | Isa::Avx2, 8) => nt!(inv_avx2_f32_8),
            (_, 16) => nt!(inverse_body::<ScalarF32, 1, 16>),
            (_, 8) => nt!(inverse_body::<ScalarF32, 1, 8>),
            _ => unreachable!("P must be 8 or 16"),
        }
    }
    crate::simd::sfence();
}
