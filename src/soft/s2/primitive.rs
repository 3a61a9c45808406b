//! The helpers of `s2_primitive.h` (normalised Legendre recurrence coefficients, nodes,
//! `Pt_m^m`, small vector operations, in-place transpose) and the per-order naive Legendre
//! sums of `s2_legendreTransforms.h`, from their mathematical definitions
//! (docs/conventions-s2.md, spherical harmonics). Nodes use the exact `pi`.

use super::super::{guarded, SoftResult};
use crate::ffi::checks::{self, Array};
use crate::ffi::CallError;
use std::f64::consts::PI;
use std::ffi::{c_double, c_int};

/// Coefficient `a(m, l) = sqrt((2l+1)(2l+3) / ((l+1-m)(l+1+m)))` of the normalised
/// three-term recurrence `Pt_{l+1}^m(x) = a(m,l) x Pt_l^m(x) + c(m,l) Pt_{l-1}^m(x)`.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_L2_an"]
pub extern "C" fn L2_an(m: c_int, l: c_int) -> c_double {
    let (m, l) = (f64::from(m), f64::from(l));
    ((2.0 * l + 1.0) * (2.0 * l + 3.0) / ((l + 1.0 - m) * (l + 1.0 + m))).sqrt()
}

/// Coefficient `c(m, l) = -sqrt((2l+3)(l-m)(l+m) / ((2l-1)(l+1-m)(l+1+m)))` of the
/// normalised recurrence (see [`L2_an`]); 0 for `l = 0`.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_L2_cn"]
pub extern "C" fn L2_cn(m: c_int, l: c_int) -> c_double {
    if l == 0 {
        return 0.0;
    }
    let (m, l) = (f64::from(m), f64::from(l));
    -((2.0 * l + 3.0) * (l - m) * (l + m) / ((2.0 * l - 1.0) * (l + 1.0 - m) * (l + 1.0 + m)))
        .sqrt()
}

/// `n` as a length: an error if negative.
fn length(n: c_int) -> SoftResult<usize> {
    usize::try_from(n).map_err(|_| CallError::invalid(format!("length {n} is negative")))
}

/// Checks that each of `arrays` (pointer, name) is non-NULL and aligned for `n` doubles
/// (nothing to check when `n = 0`).
fn check_arrays(n: usize, arrays: &[(*const f64, &'static str)]) -> SoftResult<()> {
    if n == 0 {
        return Ok(());
    }
    for &(ptr, what) in arrays {
        Array::new(ptr, n, what).check()?;
    }
    Ok(())
}

/// Applies `op` element-wise: `result[i] = op(i)`, each `result[i]` written after all reads
/// of index `i` (so `result` may be one of the inputs).
///
/// # Safety
/// `result` points to `n` doubles; `op(i)` reads only index `i` of its arrays.
unsafe fn elementwise(n: usize, result: *mut f64, op: impl Fn(usize) -> f64) {
    for i in 0..n {
        let v = op(i);
        // SAFETY: i < n, inside `result` (this function's contract).
        unsafe { result.add(i).write(v) };
    }
}

/// `result[i] = data1[i] + data2[i]`, `i < n` (`result` may be either input).
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_vec_add"]
pub unsafe extern "C" fn vec_add(
    data1: *mut c_double,
    data2: *mut c_double,
    result: *mut c_double,
    n: c_int,
) {
    guarded("vec_add", (), || {
        let n = length(n)?;
        check_arrays(n, &[(data1, "data1"), (data2, "data2"), (result, "result")])?;
        // SAFETY: n doubles each (checked non-NULL and aligned; extent by the caller's
        // contract); element i is read before it is written.
        unsafe { elementwise(n, result, |i| *data1.add(i) + *data2.add(i)) };
        Ok(())
    })
}

/// `result[i] = scalar data1[i]`, `i < n` (`result` may be `data1`).
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_vec_mul"]
pub unsafe extern "C" fn vec_mul(
    scalar: c_double,
    data1: *mut c_double,
    result: *mut c_double,
    n: c_int,
) {
    guarded("vec_mul", (), || {
        let n = length(n)?;
        check_arrays(n, &[(data1, "data1"), (result, "result")])?;
        // SAFETY: as in `vec_add`.
        unsafe { elementwise(n, result, |i| scalar * *data1.add(i)) };
        Ok(())
    })
}

/// `result[i] = data1[i] data2[i]`, `i < n` (`result` may be either input).
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_vec_pt_mul"]
pub unsafe extern "C" fn vec_pt_mul(
    data1: *mut c_double,
    data2: *mut c_double,
    result: *mut c_double,
    n: c_int,
) {
    guarded("vec_pt_mul", (), || {
        let n = length(n)?;
        check_arrays(n, &[(data1, "data1"), (data2, "data2"), (result, "result")])?;
        // SAFETY: as in `vec_add`.
        unsafe { elementwise(n, result, |i| *data1.add(i) * *data2.add(i)) };
        Ok(())
    })
}

/// Node angle `(2i+1) pi / (2n)`.
fn node(i: usize, n: usize) -> f64 {
    (2 * i + 1) as f64 * PI / (2 * n) as f64
}

/// `eval_pts[i] = (2i+1) pi / (2n)`, `i < n` (the colatitudes `theta_j` for `n = 2bw`).
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_ArcCosEvalPts"]
pub unsafe extern "C" fn ArcCosEvalPts(n: c_int, eval_pts: *mut c_double) {
    guarded("ArcCosEvalPts", (), || {
        let n = length(n)?;
        check_arrays(n, &[(eval_pts, "eval_pts")])?;
        // SAFETY: n doubles (checked non-NULL and aligned; extent by the caller's contract).
        unsafe { elementwise(n, eval_pts, |i| node(i, n)) };
        Ok(())
    })
}

/// `eval_pts[i] = cos((2i+1) pi / (2n))`, `i < n`.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_EvalPts"]
pub unsafe extern "C" fn EvalPts(n: c_int, eval_pts: *mut c_double) {
    guarded("EvalPts", (), || {
        let n = length(n)?;
        check_arrays(n, &[(eval_pts, "eval_pts")])?;
        // SAFETY: as in `ArcCosEvalPts`.
        unsafe { elementwise(n, eval_pts, |i| node(i, n).cos()) };
        Ok(())
    })
}

/// `sqrt((2m+1)/2 (2m)!) / (2^m m!)`, as `sqrt((2m+1)/2 prod_{i=1}^m (2i-1)/(2i))`.
fn pmm_norm(m: usize) -> f64 {
    let prod: f64 = (1..=m)
        .map(|i| (2 * i - 1) as f64 / (2 * i) as f64)
        .product();
    ((2 * m + 1) as f64 / 2.0 * prod).sqrt()
}

/// `result[i] = Pt_m^m(cos t_i) = (-1)^m sqrt((2m+1)/2 (2m)!) / (2^m m!) sin^m(t_i)` for the
/// angles `t_i = eval_pts[i]`, `i < n` (`result` may be `eval_pts`).
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_Pmm_L2"]
pub unsafe extern "C" fn Pmm_L2(
    m: c_int,
    eval_pts: *mut c_double,
    n: c_int,
    result: *mut c_double,
) {
    guarded("Pmm_L2", (), || {
        let n = length(n)?;
        let m =
            usize::try_from(m).map_err(|_| CallError::invalid(format!("order {m} is negative")))?;
        check_arrays(n, &[(eval_pts, "eval_pts"), (result, "result")])?;
        let norm = if m % 2 == 0 { 1.0 } else { -1.0 } * pmm_norm(m);
        let power = i32::try_from(m).unwrap_or(i32::MAX);
        // SAFETY: as in `vec_add`.
        unsafe { elementwise(n, result, |i| norm * (*eval_pts.add(i)).sin().powi(power)) };
        Ok(())
    })
}

/// Transposes the `size x size` matrix `array` in place.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_transpose"]
pub unsafe extern "C" fn transpose(array: *mut c_double, size: c_int) {
    guarded("transpose", (), || {
        let n = length(size)?;
        let len = n
            .checked_mul(n)
            .ok_or_else(|| CallError::invalid(format!("matrix size {n} too large")))?;
        check_arrays(len, &[(array, "array")])?;
        if len == 0 {
            return Ok(());
        }
        // SAFETY: size^2 doubles (checked non-NULL and aligned; extent and exclusive use
        // by the caller's contract).
        let a = unsafe { std::slice::from_raw_parts_mut(array, len) };
        for i in 0..n {
            for j in i + 1..n {
                a.swap(i * n + j, j * n + i);
            }
        }
        Ok(())
    })
}

/// Checks `bw` and the order `m` (`0..bw`) of a per-order Legendre sum.
fn bw_and_order(bw: c_int, m: c_int) -> SoftResult<(usize, usize)> {
    let b = checks::bandwidth(bw)?;
    match usize::try_from(m) {
        Ok(m) if m < b => Ok((b, m)),
        _ => Err(CallError::invalid(format!("order {m} outside 0..{bw}"))),
    }
}

/// Naive Legendre analysis of order `m`: `result[l - m] = sum_{j<2bw} data[j] weights[j]
/// plmtable[(l - m) 2bw + j]` for `l = m..bw-1`, with `weights` from `makeweights` (its
/// first `2bw` values are read) and `plmtable` from `PmlTableGen` (or an entry `m >= cutoff`
/// of `SemiNaive_Naive_Pml_Table`). `workspace` is not used.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_Naive_AnalysisX"]
pub unsafe extern "C" fn Naive_AnalysisX(
    data: *mut c_double,
    bw: c_int,
    m: c_int,
    weights: *mut c_double,
    result: *mut c_double,
    plmtable: *mut c_double,
    _workspace: *mut c_double,
) {
    guarded("Naive_AnalysisX", (), || {
        let (b, m) = bw_and_order(bw, m)?;
        let (n, rows) = (2 * b, b - m);
        check_arrays(n, &[(data, "data"), (weights, "weights")])?;
        check_arrays(rows, &[(result, "result")])?;
        check_arrays(n * rows, &[(plmtable, "plmtable")])?;
        // SAFETY: the documented sizes (checked non-NULL and aligned; extent by the
        // caller's contract); the inputs are copied before `result` is written.
        let (data, weights, table) = unsafe {
            (
                std::slice::from_raw_parts(data, n).to_vec(),
                std::slice::from_raw_parts(weights, n).to_vec(),
                std::slice::from_raw_parts(plmtable, n * rows).to_vec(),
            )
        };
        let weighted: Vec<f64> = data.iter().zip(&weights).map(|(d, w)| d * w).collect();
        // SAFETY: `rows` doubles; each value depends only on the copies above.
        unsafe {
            elementwise(rows, result, |r| {
                table[r * n..(r + 1) * n]
                    .iter()
                    .zip(&weighted)
                    .map(|(p, v)| p * v)
                    .sum()
            })
        };
        Ok(())
    })
}

/// Naive Legendre synthesis of order `m`: `result[j] = sum_{l=m}^{bw-1} coeffs[l - m]
/// plmtable[(l - m) 2bw + j]` for `j < 2bw` (`plmtable` as for [`Naive_AnalysisX`]).
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_Naive_SynthesizeX"]
pub unsafe extern "C" fn Naive_SynthesizeX(
    coeffs: *mut c_double,
    bw: c_int,
    m: c_int,
    result: *mut c_double,
    plmtable: *mut c_double,
) {
    guarded("Naive_SynthesizeX", (), || {
        let (b, m) = bw_and_order(bw, m)?;
        let (n, rows) = (2 * b, b - m);
        check_arrays(rows, &[(coeffs, "coeffs")])?;
        check_arrays(n, &[(result, "result")])?;
        check_arrays(n * rows, &[(plmtable, "plmtable")])?;
        // SAFETY: as in `Naive_AnalysisX`.
        let (coeffs, table) = unsafe {
            (
                std::slice::from_raw_parts(coeffs, rows).to_vec(),
                std::slice::from_raw_parts(plmtable, n * rows).to_vec(),
            )
        };
        let mut out = vec![0.0; n];
        for (c, row) in coeffs.iter().zip(table.chunks_exact(n)) {
            for (o, p) in out.iter_mut().zip(row) {
                *o += c * p;
            }
        }
        // SAFETY: `n` doubles, written from the private sums.
        unsafe { elementwise(n, result, |j| out[j]) };
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::{pmm_norm, L2_an, L2_cn};

    /// `Pt_m^m` from the norm, raised by the recurrence, against the crate's Wigner d on the
    /// grid (`Pt_l^m = sqrt((2l+1)/2) d^l_{m,0}`), which the naive tables hold.
    #[test]
    fn recurrence_matches_wigner_d() {
        let b = 12;
        for m in 0..b {
            let d = crate::wigner::dt_on_grid(b, m as isize, 0);
            for j in 0..2 * b {
                let theta = std::f64::consts::PI * (2 * j + 1) as f64 / (4 * b) as f64;
                let x = theta.cos();
                let sign = if m % 2 == 0 { 1.0 } else { -1.0 };
                let (mut prev, mut cur) = (0.0, sign * pmm_norm(m) * theta.sin().powi(m as i32));
                for l in m..b {
                    let got = d[(l - m) * 2 * b + j];
                    assert!(
                        (got - cur).abs() < 1e-13,
                        "m={m} l={l} j={j}: {got} vs {cur}"
                    );
                    let next =
                        L2_an(m as i32, l as i32) * x * cur + L2_cn(m as i32, l as i32) * prev;
                    (prev, cur) = (cur, next);
                }
            }
        }
    }
}
