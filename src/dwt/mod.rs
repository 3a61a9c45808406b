//! Discrete Wigner transform kernels: the Wigner-d recurrence fused with the accumulation.
//!
//! One call handles one cluster (see the `symmetry` module) and a list of beta points. The
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
//! form of the `wigner::starts` module; lanes below the skip threshold contribute nothing,
//! and while no lane of a vector is active only the recurrence runs (the negligible prefix
//! in `l` is skipped).
//!
//! Files: [`lanes`] (the kernels' inputs), `state` (the recurrence state of a vector of
//! betas, shared by the kernels), `forward`, `inverse`, `batch` (many transforms sharing
//! one recurrence), `parity` (the `m' = 0` kernels of the S^2 transforms); this file checks
//! the arguments and dispatches on the instruction set.

mod batch;
#[cfg(any(test, feature = "internals"))]
pub(crate) mod fixtures;
mod forward;
mod inverse;
pub(crate) mod lanes;
mod parity;
mod state;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod tests_f32;

use crate::numeric::Elem;
use crate::simd::Isa;

pub(crate) use batch::{inverse_tile_len, BatchFill, BatchRows};
pub(crate) use inverse::Fill;
pub(crate) use lanes::{Lanes, Prefetch, Rec};

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
#[cfg(any(test, feature = "internals"))]
pub fn forward<E: DwtElem>(
    isa: Isa,
    p: usize,
    rec: &Rec<E>,
    lanes: &Lanes<E>,
    xin: &[E],
    ft: &mut [E],
) -> usize {
    assert!(lanes.pair_stride == 0 && lanes.row_gap == 0);
    assert!(xin.len() >= lanes.tau.len() * p);
    // SAFETY: the rows are consecutive, within `xin`.
    unsafe { forward_raw(isa, p, rec, lanes, xin.as_ptr(), ft) }
}

/// The inverse kernel of the `m' = 0` recurrences, whose degrees alternate parity (the
/// S^2 Legendre stage): `y[(par c + q) nb + s] = sum_{i % 2 = par} dt_{l0+i}(beta_s)
/// fin[i c + q]` for `c` = 2 or 4 columns, `nb = lanes.tau.len()` lanes, all in the lower
/// half and not interleaved. Rows `0..rec.len()` of `fin` are read.
pub fn inverse_parity<E: DwtElem>(
    isa: Isa,
    c: usize,
    rec: &Rec<E>,
    lanes: &Lanes<E>,
    fin: &[E],
    y: &mut [E],
) {
    check_shared(isa, c, rec, lanes);
    let nb = lanes.tau.len();
    assert!(c == 2 || c == 4);
    assert!(!lanes.interleaved && lanes.upper_from >= nb);
    assert!(fin.len() >= rec.len() * c && y.len() >= 2 * c * nb);
    // SAFETY: lengths and lanes checked above, instruction set by `check_shared`.
    unsafe { E::inverse_parity_kernel(isa, c, rec, lanes, fin.as_ptr(), y.as_mut_ptr()) }
}

/// Values of the forward parity kernel's partial sums for `n` degrees, `c` columns and
/// vectors of `w` lanes (see [`forward_parity`]).
pub fn parity_partial_len(n: usize, c: usize, w: usize) -> usize {
    (n * c).next_multiple_of(w) * w
}

/// The forward kernel of the `m' = 0` recurrences (the S^2 analysis):
/// `ft[i c + q] = sum_s dt_{l0+i}(beta_s) x[(i % 2) c + q][s]`, with `x` in `2 c` columns of
/// `nb = lanes.tau.len()` values (the even combinations, then the odd ones), lanes as for
/// [`inverse_parity`]. `part` is scratch of [`parity_partial_len`] values; `ft` holds at
/// least `(n c).next_multiple_of(isa.lanes())` values, rows from `n` on are scratch.
pub fn forward_parity<E: DwtElem>(
    isa: Isa,
    c: usize,
    rec: &Rec<E>,
    lanes: &Lanes<E>,
    x: &[E],
    (part, ft): (&mut [E], &mut [E]),
) {
    check_shared(isa, c, rec, lanes);
    let (nb, n, w) = (lanes.tau.len(), rec.len(), isa.lanes_of::<E>());
    assert!(c == 2 || c == 4);
    assert!(!lanes.interleaved && lanes.upper_from >= nb);
    assert!(x.len() >= 2 * c * nb && part.len() >= parity_partial_len(n, c, w));
    assert!(ft.len() >= (n * c).next_multiple_of(w));
    // SAFETY: lengths and lanes checked above, instruction set by `check_shared`.
    unsafe {
        E::forward_parity_kernel(
            isa,
            c,
            rec,
            lanes,
            x.as_ptr(),
            (part.as_mut_ptr(), ft.as_mut_ptr()),
        )
    }
}

/// Panics unless the arguments every kernel takes are consistent: `isa` supported, the
/// coefficients padded, every lane array of the same length (a multiple of the vector
/// width), and rows of `p` values that cannot overlap.
fn check_shared<E: Elem>(isa: Isa, p: usize, rec: &Rec<E>, lanes: &Lanes<E>) {
    let nb = lanes.tau.len();
    assert!(isa.is_supported());
    assert!(rec.padded());
    let w = isa.lanes_of::<E>();
    assert!(lanes.p.len() == nb && lanes.sc.len() == nb && nb.is_multiple_of(w));
    // A vector of lanes lies in one half.
    assert!(lanes.upper_from >= nb || lanes.upper_from.is_multiple_of(w));
    lanes.assert_rows_apart(p);
}

/// [`forward`] reading row `r` of the input at `xin + r * P`, or for interleaved lanes at
/// `xin + (r / 2) * lanes.pair_stride + (r % 2) * lanes.row_gap` (defaults `2P` and `P`:
/// consecutive rows; see `plan/blocks.rs` for the split layout).
///
/// # Safety
/// Every row of the lanes (`lanes.tau.len()` rows of `p` values) is valid for reads and
/// written by no one meanwhile.
pub(crate) unsafe fn forward_raw<E: DwtElem>(
    isa: Isa,
    p: usize,
    rec: &Rec<E>,
    lanes: &Lanes<E>,
    xin: *const E,
    ft: &mut [E],
) -> usize {
    check_shared(isa, p, rec, lanes);
    assert!(ft.len() >= (rec.len() + isa.lanes_of::<E>()) * p);
    // SAFETY: lengths checked above, rows by the caller, instruction set checked by
    // is_supported.
    unsafe { E::forward_kernel(isa, p, rec, lanes, xin, ft) }
}

/// [`inverse_raw`] into consecutive rows of `y` (bounds checked).
#[cfg(any(test, feature = "internals"))]
pub fn inverse<E: DwtElem>(
    isa: Isa,
    p: usize,
    rec: &Rec<E>,
    lanes: &Lanes<E>,
    fin: &mut [E],
    fill: Fill<E>,
    y: &mut [E],
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
pub(crate) unsafe fn inverse_raw<E: DwtElem>(
    isa: Isa,
    p: usize,
    rec: &Rec<E>,
    lanes: &Lanes<E>,
    fin: &mut [E],
    fill: Fill<E>,
    y: *mut E,
) {
    check_shared(isa, p, rec, lanes);
    assert!(fin.len() >= rec.len() * p);
    // SAFETY: lengths checked above, rows by the caller, instruction set checked by
    // is_supported.
    unsafe { E::inverse_kernel(isa, p, rec, lanes, fin, fill, y) }
}

/// [`inverse_raw`] for a batch of `fin.count` transforms sharing the recurrence: transform
/// `t` reads its rows from `fin.base + t fin.dist` (filled by `fill(t, rows, from, to)` as
/// for [`inverse_raw`]) and writes its output rows (addressed as in [`inverse_raw`]) from
/// `y.base + t y.dist`. `hints[t]` (memory a later call will read) is prefetched while
/// transform `t`'s multiply-adds run; `lanes.prefetch` is not used. `tile` is scratch of
/// [`inverse_tile_len`] values. Bitwise the results of `fin.count` calls of
/// [`inverse_raw`].
///
/// # Safety
/// `fin` holds `fin.count` arrays of `rec.len() p` values `fin.dist` apart, nobody else's;
/// every output row of every transform is valid for writes and nobody else's.
pub(crate) unsafe fn inverse_batch_raw<E: DwtElem>(
    isa: Isa,
    p: usize,
    (rec, lanes): (&Rec<E>, &Lanes<E>),
    (fin, fill, hints): (BatchRows<*mut E>, BatchFill<E>, &mut [Prefetch]),
    tile: &mut [E],
    y: BatchRows<*mut E>,
) {
    check_shared(isa, p, rec, lanes);
    assert!(fin.count == y.count && fin.dist >= rec.len() * p && hints.len() == fin.count);
    assert!(tile.len() >= inverse_tile_len(rec.len(), isa.lanes_of::<E>()));
    // SAFETY: lengths checked above, rows by the caller, instruction set by `check_shared`.
    unsafe {
        E::inverse_batch_kernel(
            isa,
            p,
            (rec, lanes),
            (fin, fill, hints),
            tile.as_mut_ptr(),
            y,
        )
    }
}

/// The element types the kernels are instantiated for: each names its kernels per
/// instruction set (the `run` functions of the kernel files).
///
/// # Safety
/// Every method has the contract of the kernel file's function it forwards to.
pub trait DwtElem: Elem {
    /// `forward::run`
    unsafe fn forward_kernel(
        isa: Isa,
        p: usize,
        rec: &Rec<Self>,
        lanes: &Lanes<Self>,
        xin: *const Self,
        ft: &mut [Self],
    ) -> usize;
    /// `inverse::run`
    #[allow(clippy::too_many_arguments)]
    unsafe fn inverse_kernel(
        isa: Isa,
        p: usize,
        rec: &Rec<Self>,
        lanes: &Lanes<Self>,
        fin: &mut [Self],
        fill: Fill<Self>,
        y: *mut Self,
    );
    /// `batch::run_inverse`
    unsafe fn inverse_batch_kernel(
        isa: Isa,
        p: usize,
        rl: (&Rec<Self>, &Lanes<Self>),
        fin: (BatchRows<*mut Self>, BatchFill<Self>, &mut [Prefetch]),
        tile: *mut Self,
        y: BatchRows<*mut Self>,
    );
    /// `parity::run`
    unsafe fn inverse_parity_kernel(
        isa: Isa,
        c: usize,
        rec: &Rec<Self>,
        lanes: &Lanes<Self>,
        fin: *const Self,
        y: *mut Self,
    );
    /// `parity::run_forward`
    unsafe fn forward_parity_kernel(
        isa: Isa,
        c: usize,
        rec: &Rec<Self>,
        lanes: &Lanes<Self>,
        x: *const Self,
        out: (*mut Self, *mut Self),
    );
}

/// Forwards each [`DwtElem`] method to the kernel files' functions for one element type.
macro_rules! dwt_elem {
    ($E:ty, $fwd:path, $inv:path, $batch:path, $par:path, $par_fwd:path) => {
        impl DwtElem for $E {
            unsafe fn forward_kernel(
                isa: Isa,
                p: usize,
                rec: &Rec<$E>,
                lanes: &Lanes<$E>,
                xin: *const $E,
                ft: &mut [$E],
            ) -> usize {
                // SAFETY: the trait's contract.
                unsafe { $fwd(isa, p, rec, lanes, xin, ft) }
            }
            unsafe fn inverse_kernel(
                isa: Isa,
                p: usize,
                rec: &Rec<$E>,
                lanes: &Lanes<$E>,
                fin: &mut [$E],
                fill: Fill<$E>,
                y: *mut $E,
            ) {
                // SAFETY: the trait's contract.
                unsafe { $inv(isa, p, rec, lanes, fin, fill, y) }
            }
            unsafe fn inverse_batch_kernel(
                isa: Isa,
                p: usize,
                rl: (&Rec<$E>, &Lanes<$E>),
                fin: (BatchRows<*mut $E>, BatchFill<$E>, &mut [Prefetch]),
                tile: *mut $E,
                y: BatchRows<*mut $E>,
            ) {
                // SAFETY: the trait's contract.
                unsafe { $batch(isa, p, rl, fin, tile, y) }
            }
            unsafe fn inverse_parity_kernel(
                isa: Isa,
                c: usize,
                rec: &Rec<$E>,
                lanes: &Lanes<$E>,
                fin: *const $E,
                y: *mut $E,
            ) {
                // SAFETY: the trait's contract.
                unsafe { $par(isa, c, rec, lanes, fin, y) }
            }
            unsafe fn forward_parity_kernel(
                isa: Isa,
                c: usize,
                rec: &Rec<$E>,
                lanes: &Lanes<$E>,
                x: *const $E,
                out: (*mut $E, *mut $E),
            ) {
                // SAFETY: the trait's contract.
                unsafe { $par_fwd(isa, c, rec, lanes, x, out) }
            }
        }
    };
}

dwt_elem!(
    f64,
    forward::run,
    inverse::run,
    batch::run_inverse,
    parity::run,
    parity::run_forward
);
dwt_elem!(
    f32,
    forward::run_f32,
    inverse::run_f32,
    batch::run_inverse_f32,
    parity::run_f32,
    parity::run_forward_f32
);
