//! Index utilities of `utils_so3.h`: sizes and positions in SOFT's coefficient and sample
//! arrays.

use super::{guarded, to_int, SoftResult};
use crate::ffi::CallError;
use crate::try_coef_index;
use std::ffi::c_int;

/// Number of coefficients at bandwidth `bw`: `(4 bw^3 - bw) / 3` (-1 if `bw < 1` or the
/// value does not fit in an `int`).
///
/// cbindgen:ignore
#[no_mangle]
pub extern "C" fn totalCoeffs_so3(bw: c_int) -> c_int {
    guarded("totalCoeffs_so3", -1, || {
        if bw < 1 {
            return Err(CallError::invalid(format!("invalid bandwidth {bw}")));
        }
        let b = bw as i128;
        to_int((4 * b * b * b - b) / 3)
    })
}

/// Number of coefficients of order `m1` (all `m2`, all degrees) at bandwidth `bw`:
/// `bw^2 - m1^2`. The two arguments may be given in either order (the larger absolute value
/// is taken as the bandwidth), so the value is right whichever order a client uses.
///
/// cbindgen:ignore
#[no_mangle]
pub extern "C" fn numCoeffs_so3(bw: c_int, m1: c_int) -> c_int {
    guarded("numCoeffs_so3", -1, || {
        let (x, y) = ((bw as i64).abs(), (m1 as i64).abs());
        let (b, m) = (x.max(y), x.min(y));
        to_int(b * b - m * m)
    })
}

/// Number of coefficients of the order pair `(m1, m2)`: `bw - max(|m1|, |m2|)`.
///
/// cbindgen:ignore
#[no_mangle]
pub extern "C" fn howMany_so3(m1: c_int, m2: c_int, bw: c_int) -> c_int {
    guarded("howMany_so3", -1, || {
        to_int(bw as i64 - (m1 as i64).abs().max((m2 as i64).abs()))
    })
}

/// Start, in SOFT's internal FFT'd sample array (orders in FFT order `m mod 2B`, each order
/// pair holding its `2B` beta samples contiguously), of the data of the order pair
/// `(m1, m2)`: `2bw * (2bw * (m1 mod 2bw) + (m2 mod 2bw))`. Orders must satisfy
/// `-2bw < m < 2bw`; -1 otherwise.
///
/// cbindgen:ignore
#[no_mangle]
pub extern "C" fn sampLoc_so3(m1: c_int, m2: c_int, bw: c_int) -> c_int {
    guarded("sampLoc_so3", -1, || {
        if bw < 1 {
            return Err(CallError::invalid(format!("invalid bandwidth {bw}")));
        }
        let n = 2 * bw as i128;
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
    if bw < 1 || l < 0 {
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
#[no_mangle]
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
#[no_mangle]
pub extern "C" fn so3CoefLoc(m: c_int, mp: c_int, l: c_int, bw: c_int) -> c_int {
    guarded("so3CoefLoc", -1, || to_int(coef_loc(m, mp, l, bw)?))
}
