//! The coefficient layout of the S^2 transforms: SOFT's `seanindex` order, complex values
//! interleaved.
//!
//! Orders `m = 0, 1, ..., B-1`, each with its degrees `l = m..B-1`, then
//! `m = -(B-1), ..., -1`, each with `l = |m|..B-1`: `B^2` coefficients. Within an order the
//! degrees are contiguous (what the Legendre stage reads and writes).

use crate::error::{Error, Result};

/// Number of coefficients `B^2` of a bandwidth-`b` function on the sphere.
pub fn s2_num_coeffs(b: usize) -> usize {
    b * b
}

/// Number of samples `(2B)^2` of a bandwidth-`b` function on the sphere.
pub fn s2_num_samples(b: usize) -> usize {
    4 * b * b
}

/// First index of order `m`'s block (its degree `|m|`); `|m| < b`.
pub(crate) fn order_start(b: usize, m: isize) -> usize {
    let a = m.unsigned_abs();
    if m >= 0 {
        a * b - a * a.saturating_sub(1) / 2
    } else {
        // Orders -(B-1)..=-1 after the b(b+1)/2 non-negative ones, in increasing m: the
        // orders -k, k = a+1..b-1, before it hold b-k coefficients each.
        b * (b + 1) / 2 + (b - a - 1) * (b - a) / 2
    }
}

/// Index of `fhat(l, m)` (`|m| <= l < b`) in the coefficient array; an
/// [`Error::InvalidArgument`] for a coefficient that does not exist.
pub fn s2_try_coef_index(b: usize, l: usize, m: isize) -> Result<usize> {
    if l >= b || m.unsigned_abs() > l {
        return Err(Error::InvalidArgument(format!(
            "S^2 coefficient (l={l}, m={m}) does not exist at bandwidth {b}"
        )));
    }
    Ok(order_start(b, m) + (l - m.unsigned_abs()))
}

/// Index of `fhat(l, m)` (`|m| <= l < b`) in the coefficient array (SOFT's
/// `seanindex(m, l, b)`). Panics for a coefficient that does not exist.
pub fn s2_coef_index(b: usize, l: usize, m: isize) -> usize {
    s2_try_coef_index(b, l, m).unwrap_or_else(|e| panic!("{e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The closed form of `docs/conventions-s2.md` against the enumeration order.
    #[test]
    fn layout_is_seanindex() {
        for b in 1..12usize {
            let mut k = 0;
            for m in (0..b as isize).chain(-(b as isize - 1)..0) {
                for l in m.unsigned_abs()..b {
                    assert_eq!(s2_coef_index(b, l, m), k, "b={b} l={l} m={m}");
                    let big_l = b as i64 - 1;
                    let (mi, li) = (m as i64, l as i64);
                    let closed = if mi >= 0 {
                        mi * b as i64 - mi * (mi - 1) / 2 + (li - mi)
                    } else {
                        let a = -mi;
                        big_l * (big_l + 3) / 2 + 1 + (big_l - a) * (big_l - a + 1) / 2 + (li - a)
                    };
                    assert_eq!(k as i64, closed);
                    k += 1;
                }
            }
            assert_eq!(k, s2_num_coeffs(b));
        }
        assert!(s2_try_coef_index(4, 4, 0).is_err());
        assert!(s2_try_coef_index(4, 2, -3).is_err());
    }
}
