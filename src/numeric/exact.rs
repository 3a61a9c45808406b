//! Exact integer checks of rounded results (tests only).

/// Whether `x > 0` is `sqrt(n / d)` rounded to the nearest double (within half an ulp
/// of `x`, in exact integer arithmetic), or `None` where 128 bits do not suffice.
pub(crate) fn is_rounded_sqrt(x: f64, n: u128, d: u128) -> Option<bool> {
    let bits = x.to_bits();
    let e = ((bits >> 52) & 0x7ff) as i64 - 1075;
    let m = ((bits & ((1 << 52) - 1)) | (1 << 52)) as u128;
    // x + ulp/2 = (2m + 1) 2^(e-1); squared, times 2^k with k = 2 - 2e. Below a power
    // of two the gap to the next double is half as large: x - ulp/4 = (4m - 1) 2^(e-2).
    let k = u32::try_from(2 - 2 * e).ok()?;
    let mid = n.checked_mul(1u128.checked_shl(k)?)?;
    let hi = (2 * m + 1).checked_pow(2)?.checked_mul(d)?;
    let lo_ok = if m == 1 << 52 {
        let mid4 = n.checked_mul(1u128.checked_shl(k + 2)?)?;
        (4 * m - 1).checked_pow(2)?.checked_mul(d)? <= mid4
    } else {
        (2 * m - 1).checked_pow(2)?.checked_mul(d)? <= mid
    };
    Some(lo_ok && mid <= hi)
}
