//! The forward kernel: `ft[i][q] = sum_s dt_{l0+i}(beta_s) x[row(s)][q]`, a reduction over
//! the betas for each degree.

use super::lanes::{Lanes, Rec};
use super::state::{prefix_states, State};
use crate::simd::Simd;
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
struct DBlock([f64; 128]);

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
    db: *const f64,
    w: usize,
    xw: *const f64,
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

/// Degrees per block of the forward kernels for vectors of `w` lanes and `p` columns.
pub(super) const fn degree_block(w: usize, p: usize) -> usize {
    match (w, p) {
        (8, _) => 8,
        (4, 16) => 2,
        (4, _) => 4,
        _ => 1,
    }
}

/// Compile-time checks of a forward block shape: the sums fit the registers, the d block
/// its buffer, and the last block's steps the coefficients' padding.
pub(super) const fn assert_block<const W: usize, const P: usize, const DB: usize>() {
    assert!(DB <= W && DB * W <= 128 && DB * (P / W) <= ACC && P.is_multiple_of(W));
    assert!(DB <= REC_PAD);
    assert!(!paired(W, P) || (2 * DB <= ACC && W.is_multiple_of(2)));
}

/// Whether the forward kernel pairs betas ([`pair_fmas`]): with one vector of columns
/// (`P == W`) a broadcast d value would feed a single multiply-add.
pub(super) const fn paired(w: usize, p: usize) -> bool {
    p == w && w >= 2
}

/// [`beta_fmas`] for the neighbouring lanes `w` and `w + 1` when `P == W`: one broadcast
/// of the pair `(d[j][w], d[j][w + 1])` feeds two multiply-adds, with the two beta rows
/// interleaved column by column: `acc[2j]` holds columns `0, 2, 4, ...` and `acc[2j + 1]`
/// columns `1, 3, 5, ...`, alternate lanes summing the even and the odd betas
/// ([`fold_pair`] adds them). Half as many broadcasts per multiply-add leave more of the
/// load ports to the data.
///
/// # Safety
/// The CPU supports `S`'s instruction set; the pointers are valid for the rows and
/// entries read or written (`P` values a data row, `DB x W` a d block).
#[inline(always)]
unsafe fn pair_fmas<S: Simd, const W: usize, const DB: usize>(
    acc: &mut [S::V; ACC],
    db: *const f64,
    w: usize,
    x0: *const f64,
    x1: *const f64,
) {
    // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
    unsafe {
        let (a, b) = (S::load(x0), S::load(x1));
        let (even, odd) = (S::unpack_even(a, b), S::unpack_odd(a, b));
        for j in 0..DB {
            let e = S::splat2(db.add(j * W + w));
            acc[2 * j] = S::fence(S::fma(e, even, acc[2 * j]));
            acc[2 * j + 1] = S::fence(S::fma(e, odd, acc[2 * j + 1]));
        }
    }
}

/// The column sums of degree `j` from [`pair_fmas`]'s accumulators: lane `2k` of
/// `acc[2j]` and `acc[2j + 1]` holds the even betas' sums of columns `2k` and `2k + 1`,
/// lane `2k + 1` the odd betas'.
///
/// # Safety
/// The CPU supports `S`'s instruction set; the pointers are valid for the rows and
/// entries read or written (`P` values a data row, `DB x W` a d block).
#[inline(always)]
pub(super) unsafe fn fold_pair<S: Simd>(acc: &[S::V; ACC], j: usize) -> S::V {
    // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
    unsafe {
        let (a, b) = (acc[2 * j], acc[2 * j + 1]);
        S::add(S::unpack_even(a, b), S::unpack_odd(a, b))
    }
}

/// Lane `w`'s share of the multiply-adds of a stored d block: [`beta_fmas`], or with
/// paired betas [`pair_fmas`] for lanes `w - 1` and `w` at each odd `w` (nothing at even
/// `w`). `x` is lane 0's data row, `xs` the stride between rows.
///
/// # Safety
/// The CPU supports `S`'s instruction set; `db` holds a `DB x W` d block and the data
/// rows `x + w * xs` of the lanes used are valid for `P` values each.
#[inline(always)]
unsafe fn lane_fmas<S: Simd, const W: usize, const P: usize, const DB: usize>(
    acc: &mut [S::V; ACC],
    db: *const f64,
    w: usize,
    x: *const f64,
    xs: usize,
) {
    // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
    unsafe {
        if !paired(W, P) {
            beta_fmas::<S, W, P, DB>(acc, db, w, x.add(w * xs));
        } else if w % 2 == 1 {
            pair_fmas::<S, W, DB>(acc, db, w - 1, x.add((w - 1) * xs), x.add(w * xs));
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
    db: *const f64,
    x: *const f64,
    xs: usize,
) {
    // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
    unsafe {
        // Only the lanes that do work (each pair at its odd lane), so the loop unrolls.
        let step = if paired(W, P) { 2 } else { 1 };
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
    rec: &Rec,
    lanes: &Lanes,
    xin: *const f64,
    ft: &mut [f64],
) -> usize {
    // SAFETY: this function's contract (see `# Safety`), upheld by the caller.
    unsafe {
        let n = rec.len();
        let nb = lanes.tau.len();
        let col_vectors = P / W;
        const { assert_block::<W, P, DB>() };
        let pair = paired(W, P);
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
        let mut d_blocks = [DBlock([0.0; 128]); 2];
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
                        let v = fold_pair::<S>(&acc, j);
                        S::store(r, if assign { v } else { S::add(S::load(r), v) });
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
    ($name:ident, $feat:literal, $S:ty, $W:literal, $N:literal, $DB:tt) => {
        /// # Safety
        /// As [`forward_body`], for the instruction set of `$S`.
        #[cfg(target_arch = "x86_64")]
        #[target_feature(enable = $feat)]
        unsafe fn $name(rec: &Rec, lanes: &Lanes, xin: *const f64, ft: &mut [f64]) -> usize {
            // SAFETY: the caller upholds `forward_body`'s contract.
            unsafe { forward_body::<$S, $W, $N, $DB>(rec, lanes, xin, ft) }
        }
    };
}

#[cfg(target_arch = "x86_64")]
use crate::simd::{avx2::Avx2, avx512::Avx512};
use crate::simd::{scalar::Scalar, Isa};

entry!(fwd_avx512_16, "avx512f,fma", Avx512, 8, 16, {
    degree_block(8, 16)
});
entry!(fwd_avx512_8, "avx512f,fma", Avx512, 8, 8, {
    degree_block(8, 8)
});
entry!(fwd_avx2_16, "avx2,fma", Avx2, 4, 16, {
    degree_block(4, 16)
});
entry!(fwd_avx2_8, "avx2,fma", Avx2, 4, 8, { degree_block(4, 8) });

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
            (_, 16) => forward_body::<Scalar, 1, 16, { degree_block(1, 16) }>(rec, lanes, xin, ft),
            (_, 8) => forward_body::<Scalar, 1, 8, { degree_block(1, 8) }>(rec, lanes, xin, ft),
            _ => unreachable!("P must be 8 or 16"),
        }
    }
}
