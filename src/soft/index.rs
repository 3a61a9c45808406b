//! Index utilities of `utils_so3.h`: sizes and positions in SOFT's coefficient and sample
//! arrays.

use super::{guarded, soft_bandwidth, to_int, SoftResult};
use crate::ffi::CallError;
use crate::try_coef_index;
use std::ffi::c_int;

/// Number of coefficients at bandwidth `bw`: `(4 bw^3 - bw) / 3` (-1 if `bw` is outside
/// `1..=2048` or the value does not fit in an `int`, from `bw = 1173`).
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_totalCoeffs_so3"]
pub extern "C" fn totalCoeffs_so3(bw: c_int) -> c_int {
    guarded("totalCoeffs_so3", -1, || {
        let b = i128::from(soft_bandwidth(bw.into())?);
        to_int((4 * b * b * b - b) / 3)
    })
}

/// Number of coefficients of order `m1` (all `m2`, all degrees) at bandwidth `bw`:
/// `bw^2 - m1^2`. The two arguments may be given in either order (the larger is taken as
/// the bandwidth), so the value is right whichever order a client uses; -1 if that
/// bandwidth is outside `1..=2048` or the order's magnitude exceeds it.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_numCoeffs_so3"]
pub extern "C" fn numCoeffs_so3(bw: c_int, m1: c_int) -> c_int {
    guarded("numCoeffs_so3", -1, || {
        let (x, y) = (i64::from(bw), i64::from(m1));
        let (b, m) = (soft_bandwidth(x.max(y))?, x.min(y).abs());
        if m > b {
            return Err(CallError::invalid(format!(
                "order {m1} out of range for bandwidth {bw}"
            )));
        }
        to_int(b * b - m * m)
    })
}

/// Number of coefficients of the order pair `(m1, m2)`: `bw - max(|m1|, |m2|)`; -1 if `bw`
/// is outside `1..=2048` or `max(|m1|, |m2|) >= bw` (no such block).
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_howMany_so3"]
pub extern "C" fn howMany_so3(m1: c_int, m2: c_int, bw: c_int) -> c_int {
    guarded("howMany_so3", -1, || {
        let b = soft_bandwidth(bw.into())?;
        let m = i64::from(m1).abs().max(i64::from(m2).abs());
        if m >= b {
            return Err(CallError::invalid(format!(
                "orders ({m1}, {m2}) out of range for bandwidth {bw}"
            )));
        }
        to_int(b - m)
    })
}

/// Start, in SOFT's internal FFT'd sample array (orders in FFT order `m mod 2B`, each order
/// pair holding its `2B` beta samples contiguously), of the data of the order pair
/// `(m1, m2)`: `2bw * (2bw * (m1 mod 2bw) + (m2 mod 2bw))`. Orders must satisfy
/// `-2bw < m < 2bw`; -1 otherwise, for `bw` outside `1..=2048`, and when the start does not
/// fit in an `int` (orders `(-1, -1)` from `bw = 646`, `(bw-1, bw-1)` from `bw = 813`).
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_sampLoc_so3"]
pub extern "C" fn sampLoc_so3(m1: c_int, m2: c_int, bw: c_int) -> c_int {
    guarded("sampLoc_so3", -1, || {
        let n = 2 * i128::from(soft_bandwidth(bw.into())?);
        let (m1, m2) = (m1 as i128, m2 as i128);
        if m1.abs() >= n || m2.abs() >= n {
            return Err(CallError::invalid(format!(
                "orders ({m1}, {m2}) out of range for bandwidth {bw}"
            )));
        }
        to_int(n * (n * m1.rem_euclid(n) + m2.rem_euclid(n)))
    })
}

/// Checked index of `fhat(l, m, mp)` at bandwidth `bw`, as an `i64`.
fn coef_loc(m: c_int, mp: c_int, l: c_int, bw: c_int) -> SoftResult<i64> {
    soft_bandwidth(bw.into())?;
    if l < 0 {
        return Err(CallError::invalid(format!(
            "coefficient (m={m}, mp={mp}, l={l}) does not exist at bandwidth {bw}"
        )));
    }
    try_coef_index(bw as usize, l as usize, m as isize, mp as isize)
        .map(|i| i as i64)
        .map_err(CallError::from)
}

/// Index of the first coefficient (degree `max(|m1|, |m2|)`) of the block `(m1, m2)`;
/// -1 if `max(|m1|,|m2|) >= bw`.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_coefLoc_so3"]
pub extern "C" fn coefLoc_so3(m1: c_int, m2: c_int, bw: c_int) -> c_int {
    guarded("coefLoc_so3", -1, || {
        let l = (m1 as i64).abs().max((m2 as i64).abs());
        let l = c_int::try_from(l)
            .map_err(|_| CallError::invalid(format!("orders ({m1}, {m2}) out of range")))?;
        to_int(coef_loc(m1, m2, l, bw)?)
    })
}

/// Index of `fhat(l, m, mp)` (`m` pairs with alpha, `mp` with gamma) in the coefficient
/// array of bandwidth `bw` (docs/conventions.md, sample and coefficient layout); -1 if the coefficient does not exist.
///
/// cbindgen:ignore
#[export_name = "so3fft_soft_so3CoefLoc"]
pub extern "C" fn so3CoefLoc(m: c_int, mp: c_int, l: c_int, bw: c_int) -> c_int {
    guarded("so3CoefLoc", -1, || to_int(coef_loc(m, mp, l, bw)?))
}
