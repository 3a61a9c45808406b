//! Quadrature weights (`makeweights.h`) and Wigner d tables (`makeWigner.h`).

use super::cache::plan_for;
use super::{guarded, SoftResult};
use crate::ffi::checks::{self, Array};
use crate::ffi::CallError;
use std::ffi::{c_double, c_int};

// makeweights.h

/// Quadrature weights, `4 bw` doubles: `w[j] = w_B(j)` and `w[j + 2bw] = w_B(j) sin(beta_j)`
/// for `j < 2bw` (docs/conventions.md, sample and coefficient layout).
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_makeweights"]
pub unsafe extern "C" fn makeweights(bw: c_int, w: *mut c_double) {
    guarded("makeweights", (), || {
        let b = checks::bandwidth(bw)?;
        Array::new(w.cast_const(), 4 * b, "w").check()?;
        let std_w = crate::weights(b);
        // SAFETY: `w` is non-NULL and aligned (checked) and holds 4 bw doubles, not used by
        // anyone else during the call (the module's safety contract).
        let out = unsafe { std::slice::from_raw_parts_mut(w, 4 * b) };
        for (j, wj) in std_w.iter().enumerate() {
            out[j] = *wj;
            out[j + 2 * b] = wj * crate::beta(b, j).sin();
        }
        Ok(())
    })
}

/// Quadrature weights, `2 bw` doubles: `w[j] = w_B(j)` (the `weights` argument of the
/// forward transforms).
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_makeweights2"]
pub unsafe extern "C" fn makeweights2(bw: c_int, w: *mut c_double) {
    guarded("makeweights2", (), || {
        let b = checks::bandwidth(bw)?;
        Array::new(w.cast_const(), 2 * b, "w").check()?;
        // SAFETY: `w` is non-NULL and aligned (checked) and holds 2 bw doubles, not used by
        // anyone else during the call (the module's safety contract).
        unsafe { std::slice::from_raw_parts_mut(w, 2 * b) }.copy_from_slice(&crate::weights(b));
        Ok(())
    })
}

// makeWigner.h

/// Number of doubles in a `genWigAll` / `genWigAllTrans` table: the normalised Wigner d
/// values `dt^l_{m1,m2}(beta_k)` for the order pairs of [`wig_blocks`],
/// `l = max(m1, m2)..bw-1`, `k < 2bw`: `bw^2 (bw+1) (bw+2) / 3` (the size SOFT's clients
/// allocate).
fn wig_table_len(b: usize) -> Option<usize> {
    b.checked_mul(b)?
        .checked_mul(b + 1)?
        .checked_mul(b + 2)
        .map(|v| v / 3)
}

/// The order pairs `(m1, m2)` of a `genWigAll` table's blocks, in SOFT's order: `(0, 0)`;
/// `(m, m)` for `m = 1..bw-1`; `(m, 0)` for `m = 1..bw-1`; `(m1, m2)` for `m1 = 1..bw-1`,
/// `m2 = m1+1..bw-1`. (Every pair `0 <= min <= max < bw` once; the symmetries of `d` give
/// the others.)
fn wig_blocks(b: usize) -> impl Iterator<Item = (usize, usize)> {
    std::iter::once((0, 0))
        .chain((1..b).map(|m| (m, m)))
        .chain((1..b).map(|m| (m, 0)))
        .chain((1..b).flat_map(move |m1| (m1 + 1..b).map(move |m2| (m1, m2))))
}

/// Shared body of the two table generators.
///
/// # Safety
/// `table` is NULL or points to `bw^2 (bw+1)(bw+2)/3` doubles (SOFT's table size), not
/// used by anyone else during the call.
unsafe fn gen_wig(bw: c_int, table: *mut c_double, transposed: bool) -> SoftResult<()> {
    let b = checks::bandwidth(bw)?;
    let len = wig_table_len(b).ok_or_else(|| CallError::invalid("table size overflows"))?;
    Array::new(table.cast_const(), len, "wigners").check()?;
    // SAFETY: non-NULL and aligned (checked); `len` doubles by this function's contract.
    let out = unsafe { std::slice::from_raw_parts_mut(table, len) };
    let n = 2 * b;
    let mut pos = 0;
    for (m1, m2) in wig_blocks(b) {
        let d = crate::wigner::dt_on_grid(b, m1 as isize, m2 as isize);
        let rows = b - m1.max(m2);
        let blk = &mut out[pos..pos + rows * n];
        if transposed {
            for k in 0..n {
                for r in 0..rows {
                    blk[k * rows + r] = d[r * n + k];
                }
            }
        } else {
            blk.copy_from_slice(&d);
        }
        pos += rows * n;
    }
    debug_assert_eq!(pos, len);
    // Set-up time belongs here: build (and cache) the transform plan of this bandwidth.
    // A failure is reported by the transform that needs the plan.
    let _ = plan_for(b);
    Ok(())
}

/// Table for the `_pc` forward transform (`makeWigner.h`): writes exactly
/// `bw^2 (bw+1)(bw+2)/3` doubles, the normalised Wigner d values
/// `sqrt((2l+1)/2) d^l_{m1,m2}(beta_k)`, blocks in SOFT's order: `(0, 0)`, `(m, m)` for
/// `m = 1..bw-1`, `(m, 0)` for `m = 1..bw-1`, then `(m1, m2)` for `m1 = 1..bw-1`,
/// `m2 = m1+1..bw-1`; rows `l = max(m1, m2)..bw-1`, each of the `2bw` values `k`), and creates the
/// cached transform plan of `bw`. The `_pc` transforms accept but do not read the table.
/// `workspace` is not used.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_genWigAll"]
pub unsafe extern "C" fn genWigAll(bw: c_int, wigners: *mut c_double, _workspace: *mut c_double) {
    // SAFETY: `wigners` holds SOFT's table size (the module's safety contract).
    guarded("genWigAll", (), || unsafe { gen_wig(bw, wigners, false) })
}

/// Table for the `_pc` inverse transform (`makeWigner.h`): the same values and size as
/// [`genWigAll`], each block transposed (rows `k`, columns `l`).
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_genWigAllTrans"]
pub unsafe extern "C" fn genWigAllTrans(
    bw: c_int,
    wigners: *mut c_double,
    _workspace: *mut c_double,
) {
    // SAFETY: `wigners` holds SOFT's table size (the module's safety contract).
    guarded("genWigAllTrans", (), || unsafe {
        gen_wig(bw, wigners, true)
    })
}

#[cfg(test)]
mod tests {
    use super::wig_table_len;

    #[test]
    fn wig_table_size() {
        for b in 1..12usize {
            let direct: usize = (0..b).map(|m2| (m2 + 1) * (b - m2) * 2 * b).sum();
            assert_eq!(wig_table_len(b), Some(direct));
        }
    }
}
