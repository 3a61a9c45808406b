//! The forward kernel: `ft[i][q] = sum_s dt_{l0+i}(beta_s) x[row(s)][q]`, a reduction over
//! the betas for each degree.

use super::lanes::{Lanes, Rec};
use super::state::{prefix_states, State};
use crate::numeric::Elem;
use crate::simd::{group_of, Simd};
use crate::wigner::REC_PAD;
use std::mem::MaybeUninit;

/// Vectors of betas whose states the forward kernel keeps at once.
pub(super) const FWD_VECTORS: usize = 16;

/// Registers for the forward kernel's sums (`DB x P / W` of them are used).
pub(super) const ACC: usize = 16;

/// Small buffer for one vector's Wigner-d block (`DB` degrees x `W` betas), read back as
/// broadcasts.
#[repr(C, align(64))]
#[derive(Clone, Copy)]
struct DBlock<E>([E; 128]);

/// The multiply-adds of one beta lane `w` of a stored d block: for each degree `j` of the
/// block, `acc[j][h] += d[j][w] * x[h]` with `x` the `P / W` vectors of the beta's data
/// row `xw` (lane = data column) and `d[j][w]` a broadcast load.
///
/// # Safety
/// The CPU supports `S`'s instruction set; the pointers are valid for the rows and
/// entries read or written (`P` values a data row, `DB x W` a d block).
#[inline(always)]
unsafe fn beta_fmas<S: Simd, const W: usize, const P: usize, const DB: usize>(
    acc: &mut [S::V; ACC],
    db: *const S::E,
    w: usize,
    xw: *const S::E,
) {
    // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
    unsafe {
        let col_vectors = P / W;
        let mut x = [S::zero(); P];
        for (h, xh) in x.iter_mut().enumerate().take(col_vectors) {
            *xh = S::load(xw.add(h * W));
        }
        for j in 0..DB {
            let e = S::splat(*db.add(j * W + w));
            for h in 0..col_vectors {
                // Pinned in program order: left alone, LLVM hoists the broadcasts of the next
                // lanes above these multiply-adds and spills them and half of the sums.
                acc[j * col_vectors + h] = S::fence(S::fma(e, x[h], acc[j * col_vectors + h]));
            }
        }
    }
}

/// Degrees per block of the forward kernels for vectors of `w` lanes, `p` columns and
/// `regs` vector registers: 8 with 32 registers (16 sums with paired betas), with 16
/// registers as many as keep 8 sums.
pub(super) const fn degree_block(w: usize, p: usize, regs: usize) -> usize {
    if w == 1 {
        1
    } else if regs >= 32 {
        if w < 8 {
            w
        } else {
            8
        }
    } else if p <= w {
        // Grouped (two sums per degree, see `grouped`).
        4
    } else {
        8 / (p / w)
    }
}

/// Compile-time checks of a forward block shape: the sums fit the registers, the d block
/// its buffer, and the last block's steps the coefficients' padding.
pub(super) const fn assert_block<S: Simd, const W: usize, const P: usize, const DB: usize>() {
    assert!(DB <= W && DB * W <= 128 && DB <= REC_PAD);
    if grouped::<S>(P) {
        assert!(2 * DB <= ACC && W * 2 == P * group_of::<S>(P));
    } else {
        assert!(DB * (P / W) <= ACC && P.is_multiple_of(W));
    }
}

/// Whether the forward kernel groups betas ([`group_fmas`]): with one vector of columns
/// or less (`P <= W`) a broadcast d value would feed a single multiply-add.
pub(super) const fn grouped<S: Simd>(p: usize) -> bool {
    group_of::<S>(p) > 1
}

/// [`beta_fmas`] for the `G` neighbouring lanes from `w` when `G P = 2 W` (`G` = 2 or 4,
/// [`group_of`]): one broadcast of the group's d values `d[j][w..w + G]` feeds two
/// multiply-adds with the group's rows arranged by [`Simd::group_rows`], lane `k` of the
/// sums holding beta `k % G`'s share ([`Simd::fold_group`] adds them). Fewer broadcasts
/// per multiply-add leave more of the load ports to the data.
///
/// # Safety
/// The CPU supports `S`'s instruction set; the pointers are valid for the rows and
/// entries read or written (`P` values a data row, `DB x W` a d block).
#[inline(always)]
unsafe fn group_fmas<S: Simd, const W: usize, const P: usize, const DB: usize>(
    acc: &mut [S::V; ACC],
    db: *const S::E,
    w: usize,
    x0: *const S::E,
    xs: usize,
) {
    // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
    unsafe {
        let [lo, hi] = S::group_rows::<P>(x0, xs);
        for j in 0..DB {
            let e = S::splat_group::<P>(db.add(j * W + w));
            acc[2 * j] = S::fence(S::fma(e, lo, acc[2 * j]));
            acc[2 * j + 1] = S::fence(S::fma(e, hi, acc[2 * j + 1]));
        }
    }
}

/// Lane `w`'s share of the multiply-adds of a stored d block: [`beta_fmas`], or with
/// grouped betas [`group_fmas`] for lanes `w + 1 - G ..= w` at each `w = G - 1 (mod G)`
/// (nothing at the others). `x` is lane 0's data row, `xs` the stride between rows.
///
/// # Safety
/// The CPU supports `S`'s instruction set; `db` holds a `DB x W` d block and the data
/// rows `x + w * xs` of the lanes used are valid for `P` values each.
#[inline(always)]
unsafe fn lane_fmas<S: Simd, const W: usize, const P: usize, const DB: usize>(
    acc: &mut [S::V; ACC],
    db: *const S::E,
    w: usize,
    x: *const S::E,
    xs: usize,
) {
    // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
    unsafe {
        let g = group_of::<S>(P);
        if g == 1 {
            beta_fmas::<S, W, P, DB>(acc, db, w, x.add(w * xs));
        } else if w % g == g - 1 {
            let w0 = w + 1 - g;
            group_fmas::<S, W, P, DB>(acc, db, w0, x.add(w0 * xs), xs);
        }
    }
}

/// All `W` lanes of a stored d block ([`lane_fmas`]).
///
/// # Safety
/// The CPU supports `S`'s instruction set; the pointers are valid for the rows and
/// entries read or written (`P` values a data row, `DB x W` a d block).
#[inline(always)]
pub(super) unsafe fn block_fmas<S: Simd, const W: usize, const P: usize, const DB: usize>(
    acc: &mut [S::V; ACC],
    db: *const S::E,
    x: *const S::E,
    xs: usize,
) {
    // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
    unsafe {
        // Only the lanes that do work (each group at its last lane), so the loop unrolls.
        let step = group_of::<S>(P);
        for w in (step - 1..W).step_by(step) {
            lane_fmas::<S, W, P, DB>(acc, db, w, x, xs);
        }
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
///
/// # Safety
/// The CPU supports `S`'s instruction set; the pointers are valid for the rows and
/// entries read or written (`P` values a data row, `DB x W` a d block).
#[inline(always)]
unsafe fn forward_body<S: Simd, const W: usize, const P: usize, const DB: usize>(
    rec: &Rec<S::E>,
    lanes: &Lanes<S::E>,
    xin: *const S::E,
    ft: &mut [S::E],
) -> usize {
    // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
    unsafe {
        let n = rec.len();
        let nb = lanes.tau.len();
        let col_vectors = P / W;
        const { assert_block::<S, W, P, DB>() };
        let pair = grouped::<S>(P);
        debug_assert!(nb.is_multiple_of(W));
        debug_assert!(ft.len() >= n.next_multiple_of(DB) * P);
        let sums = ft.as_mut_ptr();
        // Prefetch hints: the lines of `lanes.prefetch`, a few per vector and block (bursts
        // at each block start would fill the miss buffers and stall the core). The (block,
        // vector) pairs of skipped prefixes issue nothing, so the end of the list (the last
        // coefficient rows) is left to demand loads.
        let mut prefetch = lanes.prefetch;
        let prefetch_per_vector = prefetch.lines().div_ceil((n / DB).max(1) * (nb / W).max(1));
        // Every vector's rows are the same distance apart (`Lanes::vector_rows`).
        let xs = lanes.vector_rows(0, P).1;
        let mut d_blocks = [DBlock([S::E::ZERO; 128]); 2];
        let mut lo = n;
        let mut v0 = 0;
        while v0 < nb {
            // Up to FWD_VECTORS vectors, each through its negligible prefix.
            let vectors = ((nb - v0) / W).min(FWD_VECTORS);
            let mut state_mem = [const { MaybeUninit::<State<S>>::uninit() }; FWD_VECTORS];
            let (first, states) =
                prefix_states::<S, W>(rec, lanes, v0, n, &mut state_mem[..vectors]);
            lo = lo.min(first);
            // Each vector's first data row, found once rather than at every block.
            let mut rows_at = [xin; FWD_VECTORS];
            for (v, r) in rows_at.iter_mut().enumerate().take(vectors) {
                let (at, stride) = lanes.vector_rows(v0 + v * W, P);
                debug_assert_eq!(stride, xs);
                *r = xin.add(at);
            }
            let mut i0 = first - first % DB;
            // The first group of vectors writes the sums (zeros below its first block), the
            // others add to them: `ft` needs no clearing beforehand.
            let assign = v0 == 0;
            if assign {
                std::ptr::write_bytes(sums, 0, i0 * P);
            }
            let mut fast = [0usize; FWD_VECTORS];
            let mut n_fast = 0;
            // Whether `d_blocks[cur]` already holds the block of `fast[0]` at `i0`; whether some
            // vector took the masked path in the last full scan, and the lowest degree index
            // at which a vector not yet started starts.
            let (mut primed, mut cur) = (false, 0);
            let (mut masked, mut wait) = (false, n);
            while i0 < n {
                let mut acc = [S::zero(); ACC];
                // Paired sums are folded and added to `ft` at the end of the block.
                if !assign && !pair {
                    for j in 0..DB {
                        for h in 0..col_vectors {
                            acc[j * col_vectors + h] = S::load(sums.add((i0 + j) * P + h * W));
                        }
                    }
                }
                // Vectors that start inside this block or still have inactive lanes, one at a
                // time; the others are listed for the pipelined loop. While the list stays the
                // same (no vector in its masked phase, none starting) it is not rebuilt.
                if !primed {
                    n_fast = 0;
                    (masked, wait) = (false, n);
                    for (v, s) in states.iter_mut().enumerate() {
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
                            fast[n_fast] = v;
                            n_fast += 1;
                            continue;
                        }
                        masked = true;
                        prefetch.issue(prefetch_per_vector);
                        let d = s.masked_block::<DB>(i0, n);
                        let db = d_blocks[0].0.as_mut_ptr();
                        for (j, dj) in d.iter().enumerate() {
                            S::store(db.add(j * W), *dj);
                        }
                        let x = rows_at[v];
                        block_fmas::<S, W, P, DB>(&mut acc, db, x, xs);
                    }
                }
                if n_fast > 0 {
                    // The first fast vector's block (unless the previous block computed it),
                    // then each next vector's steps interleaved with the previous one's
                    // multiply-adds.
                    if !primed {
                        cur = 0;
                        let s = &mut states[fast[0]];
                        let (mut p0, mut p1) = (s.p0, s.p1);
                        let db = d_blocks[cur].0.as_mut_ptr();
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
                    let mut fma_vector = fast[0];
                    for idx in 1..n_fast + next as usize {
                        let (v, base) = if idx < n_fast {
                            (fast[idx], i0)
                        } else {
                            (fast[0], i0 + DB)
                        };
                        prefetch.issue(prefetch_per_vector);
                        let x = rows_at[fma_vector];
                        let s = &mut states[v];
                        let (mut p0, mut p1) = (s.p0, s.p1);
                        let d_cur = d_blocks[cur].0.as_ptr();
                        let d_next = d_blocks[1 - cur].0.as_mut_ptr();
                        // Written out for each lane, so that the state stays in registers.
                        macro_rules! lane {
                            ($w:literal) => {
                                if $w < W {
                                    // This lane's share of the next vector's steps.
                                    for k in $w * DB / W..($w + 1) * DB / W {
                                        S::store(d_next.add(k * W), p1);
                                        let p2 = S::fence(s.step(p0, p1, base + k));
                                        (p0, p1) = (p1, p2);
                                    }
                                    lane_fmas::<S, W, P, DB>(&mut acc, d_cur, $w, x, xs);
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
                        lane!(8);
                        lane!(9);
                        lane!(10);
                        lane!(11);
                        lane!(12);
                        lane!(13);
                        lane!(14);
                        lane!(15);
                        (s.p0, s.p1, s.i) = (p0, p1, base + DB);
                        cur = 1 - cur;
                        fma_vector = v;
                    }
                    primed = next;
                    if !next {
                        prefetch.issue(prefetch_per_vector);
                        let x = rows_at[fma_vector];
                        let d_cur = d_blocks[cur].0.as_ptr();
                        block_fmas::<S, W, P, DB>(&mut acc, d_cur, x, xs);
                    }
                }
                if pair {
                    for j in 0..DB {
                        let r = sums.add((i0 + j) * P);
                        let v = S::fold_group::<P>(acc[2 * j], acc[2 * j + 1]);
                        // With P < W the load reads the next row too (`ft` holds `n + W`
                        // rows), of which nothing is stored.
                        let v = if assign { v } else { S::add(S::load(r), v) };
                        if P < W {
                            S::store_first(r, v, P);
                        } else {
                            S::store(r, v);
                        }
                    }
                } else {
                    for j in 0..DB {
                        for h in 0..col_vectors {
                            S::store(sums.add((i0 + j) * P + h * W), acc[j * col_vectors + h]);
                        }
                    }
                }
                i0 += DB;
            }
            v0 += vectors * W;
        }
        lo
    }
}

/// A `#[target_feature]` entry point: [`forward_body`] for one instruction set, vector
/// width, column count and degree block.
macro_rules! entry {
    ($name:ident, $feat:literal, $S:ty, $E:ty, $W:literal, $N:literal) => {
        /// # Safety
        /// As [`forward_body`], for the instruction set of `$S`.
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = $feat)]
        unsafe fn $name(rec: &Rec<$E>, lanes: &Lanes<$E>, xin: *const $E, ft: &mut [$E]) -> usize {
            const DB: usize = degree_block($W, $N, <$S as Simd>::REGS);
            // SAFETY: the caller upholds `forward_body`'s contract.
            unsafe { forward_body::<$S, $W, $N, DB>(rec, lanes, xin, ft) }
        }
    };
}

#[cfg(target_arch = "x86_64")]
use crate::simd::{avx2::Avx2, avx2_f32::Avx2F32, avx512::Avx512, avx512_f32::Avx512F32};
use crate::simd::{
    scalar::{Scalar, ScalarF32},
    Isa,
};

entry!(fwd_avx512_16, "avx512f,fma", Avx512, f64, 8, 16);
entry!(fwd_avx512_8, "avx512f,fma", Avx512, f64, 8, 8);
entry!(fwd_avx2_16, "avx2,fma", Avx2, f64, 4, 16);
entry!(fwd_avx2_8, "avx2,fma", Avx2, f64, 4, 8);
entry!(fwd_avx512_f32_16, "avx512f,fma", Avx512F32, f32, 16, 16);
entry!(fwd_avx512_f32_8, "avx512f,fma", Avx512F32, f32, 16, 8);
entry!(fwd_avx2_f32_16, "avx2,fma", Avx2F32, f32, 8, 16);
entry!(fwd_avx2_f32_8, "avx2,fma", Avx2F32, f32, 8, 8);

/// The forward kernel for `isa` and `p` columns (8 or 16).
///
/// # Safety
/// `isa` is supported by this CPU; `ft` holds `(n + isa.lanes()) * p` values; every row of
/// the lanes is valid for reads at its place after `xin` (see `dwt::forward_raw`), and the
/// lane arrays hold `lanes.tau.len()` entries, a multiple of `isa.lanes()`.
pub(super) unsafe fn run(
    isa: Isa,
    p: usize,
    rec: &Rec,
    lanes: &Lanes,
    xin: *const f64,
    ft: &mut [f64],
) -> usize {
    // SAFETY: the caller's contract covers every kernel's (`forward_body`'s) and the
    // instruction set of the one chosen.
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

/// [`run`] for floats: 16-lane vectors with AVX-512, 8-lane vectors with AVX2.
///
/// # Safety
/// As [`run`], with `ft` holding `(n + isa.lanes_of::<f32>()) * p` values.
pub(super) unsafe fn run_f32(
    isa: Isa,
    p: usize,
    rec: &Rec<f32>,
    lanes: &Lanes<f32>,
    xin: *const f32,
    ft: &mut [f32],
) -> usize {
    // SAFETY: the caller's contract covers every kernel's (`forward_body`'s) and the
    // instruction set of the one chosen (every AVX-512 CPU has AVX2).
    unsafe {
        match (isa, p) {
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx512, 16) => fwd_avx512_f32_16(rec, lanes, xin, ft),
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx512, 8) => fwd_avx512_f32_8(rec, lanes, xin, ft),
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx2, 16) => fwd_avx2_f32_16(rec, lanes, xin, ft),
            #[cfg(target_arch = "x86_64")]
            (Isa::Avx2, 8) => fwd_avx2_f32_8(rec, lanes, xin, ft),
            (_, 16) => forward_body::<ScalarF32, 1, 16, 1>(rec, lanes, xin, ft),
            (_, 8) => forward_body::<ScalarF32, 1, 8, 1>(rec, lanes, xin, ft),
            _ => unreachable!("P must be 8 or 16"),
        }
    }
}
