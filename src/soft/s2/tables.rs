//! The Legendre tables of `s2_cospmls.h`: SOFT's sizes (docs/conventions-s2.md, SOFT's S^2
//! functions) and table builders whose pointer arrays come from C `malloc`.
//!
//! The transforms of this layer never read a table. The naive tables (orders at or above
//! the cutoff, and `PmlTableGen`) hold the normalised Legendre functions
//! `Pt_l^m(cos theta_j)`, row `l - m`, column `j` (what `Naive_AnalysisX` and
//! `Naive_SynthesizeX` read); the cosine-series tables, which SOFT's semi-naive algorithm
//! alone reads, are opaque to clients and filled with zeros.

use super::super::{guarded, soft_bandwidth, to_int, SoftResult};
use crate::ffi::checks::{self, Array};
use crate::ffi::{CallError, ErrorKind};
use rayon::prelude::*;
use std::ffi::{c_double, c_int};

/// Non-zero cosine coefficients of `Pt_l^m` (even `m`) or `Pt_l^m / sin` (odd `m`): 0 for
/// `l < m`.
fn row_size(m: i64, l: i64) -> i64 {
    if l < m {
        0
    } else if m % 2 == 0 {
        l / 2 + 1
    } else {
        (l - 1) / 2 + 1
    }
}

/// `sum_{l=m}^{bw-1} row_size(m, l)`: the cosine-series table of order `m`.
fn table_size(m: i64, bw: i64) -> i64 {
    (m..bw).map(|l| row_size(m, l)).sum()
}

/// `sum_{i<m} table_size(i, bw)`: the cosine-series tables of the orders below `m`.
fn reduced_spharmonic_size(bw: i64, m: i64) -> i64 {
    (0..m).map(|i| table_size(i, bw)).sum()
}

/// `sum_{i=m}^{bw-1} 2 bw (bw - i) = bw (bw - m)(bw - m + 1)`: the naive tables of the
/// orders from `m` on.
fn reduced_naive_size(bw: i64, m: i64) -> i64 {
    bw * (bw - m) * (bw - m + 1)
}

/// SOFT's `Spharmonic_TableSize`: `floor((4bw^3 + 6bw^2 - 8bw)/24) + bw` (an upper bound of
/// the sum) up to `bw = 512`, the exact sum above.
fn spharmonic_size(bw: i64) -> i64 {
    if bw <= 512 {
        (4 * bw * bw * bw + 6 * bw * bw - 8 * bw) / 24 + bw
    } else {
        reduced_spharmonic_size(bw, bw)
    }
}

/// Row `row` of the transposed cosine table of order `m`: the degrees `l < bw` with
/// `l >= max(m, row + (m mod 2))` and `l = row + m (mod 2)` (those whose cosine series has
/// a term `cos(row theta)`).
fn transpose_row_size(row: i64, m: i64, bw: i64) -> i64 {
    let low = m.max(row + m % 2);
    let first = low + (low - row - m).rem_euclid(2);
    if first >= bw {
        0
    } else {
        (bw - 1 - first) / 2 + 1
    }
}

/// `v` as a table size or order: an error unless `0 <= v <= max`.
fn in_range(v: c_int, max: i64, what: &str) -> SoftResult<i64> {
    let v = i64::from(v);
    if v < 0 || v > max {
        return Err(CallError::invalid(format!("{what} {v} outside 0..={max}")));
    }
    Ok(v)
}

/// The bandwidth and an order or cutoff `m` (`0..=bw`) of a size function.
fn bw_and_order(bw: c_int, m: c_int, what: &str) -> SoftResult<(i64, i64)> {
    let b = soft_bandwidth(bw.into())?;
    Ok((b, in_range(m, b, what)?))
}

/// Number of doubles of the cosine-series table of order `m` at bandwidth `bw`
/// (`sum_{l=m}^{bw-1} RowSize(m, l)`); -1 on invalid arguments.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_TableSize"]
pub extern "C" fn TableSize(m: c_int, bw: c_int) -> c_int {
    guarded("TableSize", -1, || {
        let (b, m) = bw_and_order(bw, m, "order")?;
        to_int(table_size(m, b))
    })
}

/// Doubles SOFT's clients allocate for `Spharmonic_Pml_Table`:
/// `floor((4bw^3 + 6bw^2 - 8bw)/24) + bw` for `bw <= 512`, the exact size above; -1 on
/// invalid arguments or when it does not fit in an `int`.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_Spharmonic_TableSize"]
pub extern "C" fn Spharmonic_TableSize(bw: c_int) -> c_int {
    guarded("Spharmonic_TableSize", -1, || {
        to_int(spharmonic_size(soft_bandwidth(bw.into())?))
    })
}

/// Doubles of the cosine-series tables of the orders below `m`:
/// `sum_{i<m} TableSize(i, bw)`.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_Reduced_SpharmonicTableSize"]
pub extern "C" fn Reduced_SpharmonicTableSize(bw: c_int, m: c_int) -> c_int {
    guarded("Reduced_SpharmonicTableSize", -1, || {
        let (b, m) = bw_and_order(bw, m, "cutoff")?;
        to_int(reduced_spharmonic_size(b, m))
    })
}

/// Doubles of the naive tables of the orders `m..bw-1`: `bw (bw - m)(bw - m + 1)`; -1 on
/// invalid arguments or when it does not fit in an `int`.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_Reduced_Naive_TableSize"]
pub extern "C" fn Reduced_Naive_TableSize(bw: c_int, m: c_int) -> c_int {
    guarded("Reduced_Naive_TableSize", -1, || {
        let (b, m) = bw_and_order(bw, m, "cutoff")?;
        to_int(reduced_naive_size(b, m))
    })
}

/// Offset of degree `l`'s row in the cosine-series table of order `m`:
/// `sum_{i=m}^{l-1} RowSize(m, i)`.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_NewTableOffset"]
pub extern "C" fn NewTableOffset(m: c_int, l: c_int) -> c_int {
    guarded("NewTableOffset", -1, || {
        let max = crate::MAX_BANDWIDTH as i64;
        let (m, l) = (in_range(m, max, "order")?, in_range(l, max, "degree")?);
        to_int((m..l).map(|i| row_size(m, i)).sum::<i64>())
    })
}

/// Length of degree `l`'s row in the cosine-series table of order `m`: 0 for `l < m`,
/// `floor(l/2) + 1` for even `m`, `floor((l-1)/2) + 1` for odd `m`.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_RowSize"]
pub extern "C" fn RowSize(m: c_int, l: c_int) -> c_int {
    guarded("RowSize", -1, || {
        let max = crate::MAX_BANDWIDTH as i64;
        let (m, l) = (in_range(m, max, "order")?, in_range(l, max, "degree")?);
        to_int(row_size(m, l))
    })
}

/// Length of row `row` (cosine index) of the transposed cosine-series table of order `m`:
/// the number of degrees `l < bw`, `l >= max(m, row + (m mod 2))`, `l = row + m (mod 2)`
/// (0 for `row >= bw`). The rows sum to `TableSize(m, bw)`.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_Transpose_RowSize"]
pub extern "C" fn Transpose_RowSize(row: c_int, m: c_int, bw: c_int) -> c_int {
    guarded("Transpose_RowSize", -1, || {
        let (b, m) = bw_and_order(bw, m, "order")?;
        let row = in_range(row, i64::from(c_int::MAX), "row")?;
        to_int(transpose_row_size(row, m, b))
    })
}

/// Checks `bw` and an order `m < bw` of a table builder.
fn bw_and_table_order(bw: c_int, m: c_int) -> SoftResult<(usize, usize)> {
    let b = checks::bandwidth(bw)?;
    let m = in_range(m, b as i64 - 1, "order")? as usize;
    Ok((b, m))
}

/// The caller's array of `len` doubles at `ptr`, checked (non-NULL, aligned).
///
/// # Safety
/// `ptr` is NULL or points to `len` doubles, valid and not used by anyone else during the
/// call.
unsafe fn caller_array<'a>(
    ptr: *mut c_double,
    len: usize,
    what: &'static str,
) -> SoftResult<&'a mut [f64]> {
    Array::new(ptr.cast_const(), len, what).check()?;
    // SAFETY: non-NULL and aligned (checked); length and exclusive use by the contract.
    Ok(unsafe { std::slice::from_raw_parts_mut(ptr, len) })
}

/// Writes the naive table of order `m`, `Pt_l^m(cos theta_j)` at `out[(l - m) 2B + j]`.
fn naive_table(b: usize, m: usize, out: &mut [f64]) {
    out.copy_from_slice(&crate::wigner::dt_on_grid(b, m as isize, 0));
}

/// Legendre functions of order `m` at the nodes `theta_j = pi(2j+1)/(4bw)`: `storeplm`
/// receives `2bw (bw - m)` doubles, `Pt_l^m(cos theta_j)` at `(l - m) 2bw + j`
/// (`l = m..bw-1`, `j < 2bw`). `workspace` is not used.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_PmlTableGen"]
pub unsafe extern "C" fn PmlTableGen(
    bw: c_int,
    m: c_int,
    storeplm: *mut c_double,
    _workspace: *mut c_double,
) {
    guarded("PmlTableGen", (), || {
        let (b, m) = bw_and_table_order(bw, m)?;
        // SAFETY: 2bw(bw-m) doubles (the module's safety contract).
        let out = unsafe { caller_array(storeplm, 2 * b * (b - m), "storeplm") }?;
        naive_table(b, m, out);
        Ok(())
    })
}

/// Cosine-series table of order `m`: writes `TableSize(m, bw)` doubles (zeros: the
/// transforms of this layer do not read it). `workspace` is not used.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_CosPmlTableGen"]
pub unsafe extern "C" fn CosPmlTableGen(
    bw: c_int,
    m: c_int,
    tablespace: *mut c_double,
    _workspace: *mut c_double,
) {
    guarded("CosPmlTableGen", (), || {
        let (b, m) = bw_and_table_order(bw, m)?;
        let len = table_size(m as i64, b as i64) as usize;
        // SAFETY: TableSize(m, bw) doubles (the module's safety contract).
        unsafe { caller_array(tablespace, len, "tablespace") }?.fill(0.0);
        Ok(())
    })
}

/// Transposed cosine-series table of order `m`: writes `TableSize(m, bw)` doubles to
/// `result` (zeros, as [`CosPmlTableGen`]); `cos_pml_table` is not read.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_Transpose_CosPmlTableGen"]
pub unsafe extern "C" fn Transpose_CosPmlTableGen(
    bw: c_int,
    m: c_int,
    _cos_pml_table: *mut c_double,
    result: *mut c_double,
) {
    guarded("Transpose_CosPmlTableGen", (), || {
        let (b, m) = bw_and_table_order(bw, m)?;
        let len = table_size(m as i64, b as i64) as usize;
        // SAFETY: TableSize(m, bw) doubles (the module's safety contract).
        unsafe { caller_array(result, len, "result") }?.fill(0.0);
        Ok(())
    })
}

/// Builds a table in `space`: `entries` pointers (from C `malloc`, released by the caller
/// with `free()`), entry `m < bw` at the start of order `m`'s part. Orders below `cutoff`
/// get a cosine-series table (`TableSize(m, bw)` zeros), the others a naive table
/// (`2bw (bw - m)` values `Pt_l^m(cos theta_j)`); an entry `bw` points to the end.
///
/// # Safety
/// `space` is NULL or holds `Reduced_SpharmonicTableSize(bw, cutoff) +
/// Reduced_Naive_TableSize(bw, cutoff)` doubles, not used by anyone else during the call.
unsafe fn build_table(
    bw: c_int,
    cutoff: c_int,
    entries: usize,
    space: *mut c_double,
) -> SoftResult<*mut *mut c_double> {
    let b = checks::bandwidth(bw)?;
    let cutoff = in_range(cutoff, b as i64, "cutoff")? as usize;
    let sizes: Vec<usize> = (0..b)
        .map(|m| {
            if m < cutoff {
                table_size(m as i64, b as i64) as usize
            } else {
                2 * b * (b - m)
            }
        })
        .collect();
    let total: usize = sizes.iter().sum();
    // SAFETY: `total` doubles (this function's contract).
    let out = unsafe { caller_array(space, total, "resultspace") }?;
    // SAFETY: plain C allocation of `entries` pointers; checked for NULL below.
    let table = unsafe { libc::malloc(entries * std::mem::size_of::<*mut c_double>()) }
        .cast::<*mut c_double>();
    if table.is_null() {
        return Err(CallError::new(
            ErrorKind::NoMemory,
            format!("out of memory allocating {entries} table pointers"),
        ));
    }
    let mut parts = Vec::with_capacity(b);
    let mut rest = out;
    let mut offset = 0;
    for (m, &len) in sizes.iter().enumerate() {
        // SAFETY: entry m < entries of the new array; `space + offset` is within (or one
        // past the end of) the caller's `total` doubles.
        unsafe { *table.add(m) = space.add(offset) };
        let (part, tail) = rest.split_at_mut(len);
        parts.push((m, part));
        rest = tail;
        offset += len;
    }
    if entries > b {
        // SAFETY: entry b < entries; one past the end of the caller's array.
        unsafe { *table.add(b) = space.add(offset) };
    }
    parts.into_par_iter().for_each(|(m, part)| {
        if m < cutoff {
            part.fill(0.0);
        } else {
            naive_table(b, m, part);
        }
    });
    Ok(table)
}

/// All-semi-naive Legendre table of the forward transform: `bw` pointers (C `malloc`; the
/// caller frees them with `free()`) into `resultspace`, which receives
/// `Reduced_SpharmonicTableSize(bw, bw)` doubles (at most `Spharmonic_TableSize(bw)`).
/// NULL on invalid arguments. `workspace` is not used.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_Spharmonic_Pml_Table"]
pub unsafe extern "C" fn Spharmonic_Pml_Table(
    bw: c_int,
    resultspace: *mut c_double,
    _workspace: *mut c_double,
) -> *mut *mut c_double {
    guarded("Spharmonic_Pml_Table", std::ptr::null_mut(), || {
        let b = checks::bandwidth(bw)?;
        // SAFETY: the space SOFT's clients allocate (the module's safety contract).
        unsafe { build_table(bw, bw, b, resultspace) }
    })
}

/// Transposed all-semi-naive table of the inverse transform: as [`Spharmonic_Pml_Table`];
/// `spharmonic_pml_table` is not read.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_Transpose_Spharmonic_Pml_Table"]
pub unsafe extern "C" fn Transpose_Spharmonic_Pml_Table(
    _spharmonic_pml_table: *mut *mut c_double,
    bw: c_int,
    resultspace: *mut c_double,
    _workspace: *mut c_double,
) -> *mut *mut c_double {
    guarded(
        "Transpose_Spharmonic_Pml_Table",
        std::ptr::null_mut(),
        || {
            let b = checks::bandwidth(bw)?;
            // SAFETY: the space SOFT's clients allocate (the module's safety contract).
            unsafe { build_table(bw, bw, b, resultspace) }
        },
    )
}

/// Legendre table of `FST_semi_memo` for `cutoff` (`0..=bw`): `bw + 1` pointers (C
/// `malloc`; the caller frees them with `free()`) into `resultspace`, which receives
/// `Reduced_SpharmonicTableSize(bw, cutoff) + Reduced_Naive_TableSize(bw, cutoff)`
/// doubles: orders `m < cutoff` a cosine-series table (opaque, zeros), orders `m >= cutoff`
/// the naive table `Pt_l^m(cos theta_j)` at `(l - m) 2bw + j`. NULL on invalid
/// arguments. `workspace` is not used.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_SemiNaive_Naive_Pml_Table"]
pub unsafe extern "C" fn SemiNaive_Naive_Pml_Table(
    bw: c_int,
    cutoff: c_int,
    resultspace: *mut c_double,
    _workspace: *mut c_double,
) -> *mut *mut c_double {
    guarded("SemiNaive_Naive_Pml_Table", std::ptr::null_mut(), || {
        let b = checks::bandwidth(bw)?;
        // SAFETY: the space SOFT's clients allocate (the module's safety contract).
        unsafe { build_table(bw, cutoff, b + 1, resultspace) }
    })
}

/// Legendre table of `InvFST_semi_memo`: the same layout and contents as
/// [`SemiNaive_Naive_Pml_Table`] (`seminaive_naive_pml_table` is not read).
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_Transpose_SemiNaive_Naive_Pml_Table"]
pub unsafe extern "C" fn Transpose_SemiNaive_Naive_Pml_Table(
    _seminaive_naive_pml_table: *mut *mut c_double,
    bw: c_int,
    cutoff: c_int,
    resultspace: *mut c_double,
    _workspace: *mut c_double,
) -> *mut *mut c_double {
    guarded(
        "Transpose_SemiNaive_Naive_Pml_Table",
        std::ptr::null_mut(),
        || {
            let b = checks::bandwidth(bw)?;
            // SAFETY: the space SOFT's clients allocate (the module's safety contract).
            unsafe { build_table(bw, cutoff, b + 1, resultspace) }
        },
    )
}

#[cfg(test)]
mod tests {
    use super::{
        reduced_naive_size, reduced_spharmonic_size, spharmonic_size, table_size,
        transpose_row_size,
    };

    /// The transposed rows hold the same entries as the rows; the closed forms agree with
    /// the sums; the upper bound holds.
    #[test]
    fn sizes_are_consistent() {
        for bw in 1..41i64 {
            for m in 0..bw {
                let rows: i64 = (0..bw + 2).map(|r| transpose_row_size(r, m, bw)).sum();
                assert_eq!(rows, table_size(m, bw), "bw={bw} m={m}");
            }
            for m in 0..=bw {
                let naive: i64 = (m..bw).map(|i| 2 * bw * (bw - i)).sum();
                assert_eq!(reduced_naive_size(bw, m), naive);
            }
            assert!(spharmonic_size(bw) >= reduced_spharmonic_size(bw, bw));
        }
    }
}
