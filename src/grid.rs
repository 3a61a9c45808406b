//! Sample grid, quadrature weights, array sizes and index maps (see docs/conventions.md:
//! the sample grid and layout, the coefficients and their layout).

use crate::error::{Error, Result};
use std::f64::consts::PI;

/// Largest bandwidth an SO(3) plan accepts.
pub const MAX_BANDWIDTH: usize = 2048;

/// Number of samples `(2B)^3` of a bandwidth-`b` signal.
pub fn num_samples(b: usize) -> usize {
    8 * b * b * b
}

/// Number of coefficients `(4B^3 - B)/3` of a bandwidth-`b` signal.
pub fn num_coeffs(b: usize) -> usize {
    (4 * b * b * b - b) / 3
}

/// Flat index of the sample `f(alpha_j_alpha, beta_k_beta, gamma_j_gamma)`:
/// `k_beta*(2B)^2 + j_alpha*(2B) + j_gamma` (beta slowest, gamma fastest).
pub fn sample_index(b: usize, j_alpha: usize, k_beta: usize, j_gamma: usize) -> usize {
    let n = 2 * b;
    (k_beta * n + j_alpha) * n + j_gamma
}

/// `alpha_j = pi j / B`.
pub fn alpha(b: usize, j: usize) -> f64 {
    PI * j as f64 / b as f64
}

/// `beta_k = pi (2k+1) / (4B)`.
pub fn beta(b: usize, k: usize) -> f64 {
    PI * (2 * k + 1) as f64 / (4 * b) as f64
}

/// `gamma_j = pi j / B`.
pub fn gamma(b: usize, j: usize) -> f64 {
    alpha(b, j)
}

/// Quadrature weights `w_B(k) = (2/B) sin(beta_k) sum_{i<B} sin((2i+1) beta_k)/(2i+1)`, `k < 2B`.
///
/// They integrate band-limited functions against `sin(beta) dbeta` exactly.
pub fn weights(b: usize) -> Vec<f64> {
    use crate::numeric::{sin_cos_dd, Dd, PI_DD};
    // sin(pi j / (4B)) for j = 0..8B in double-double: every angle of the sums is such a
    // multiple of pi / (4B), `(2i+1) beta_k = pi (2i+1)(2k+1) / (4B)`, reduced exactly
    // in integers; forming it in doubles instead would put an error of up to
    // `(2i+1) ulp(beta_k)` into the argument.
    let n = 8 * b;
    let quarter: Vec<Dd> = (0..=2 * b)
        .map(|j| sin_cos_dd(PI_DD.mul_f(j as f64).div(Dd::new((4 * b) as f64))).0)
        .collect();
    // sin(pi j / (4B)) from the first quadrant.
    let sin_at = |j: usize| {
        let j = j % n;
        let (half, r) = (j / (4 * b), j % (4 * b));
        let v = quarter[if r <= 2 * b { r } else { 4 * b - r }];
        if half == 0 {
            v
        } else {
            v.neg()
        }
    };
    // 1 / (2i + 1), shared by every beta.
    let inv_odd: Vec<Dd> = (0..b)
        .map(|i| Dd::new(1.0).div(Dd::new((2 * i + 1) as f64)))
        .collect();
    (0..2 * b)
        .map(|k| {
            // Small terms first.
            let s = (0..b).rev().fold(Dd::new(0.0), |acc, i| {
                let t = sin_at((2 * i + 1) * (2 * k + 1)).mul(inv_odd[i]);
                acc.add_dd(t)
            });
            sin_at(2 * k + 1)
                .mul(s)
                .mul_f(2.0)
                .div(Dd::new(b as f64))
                .to_f64()
        })
        .collect()
}

/// Start of the coefficient block of order `m` (all `m'`), SOFT's layout.
fn row_start(b: i64, m: i64) -> i64 {
    let t = (4 * b * b * b - b) / 3;
    if m >= 0 {
        m * b * b - (m - 1) * m * (2 * m - 1) / 6
    } else {
        let a = -m;
        t - (a * b * b - a * (a + 1) * (2 * a + 1) / 6)
    }
}

/// `sum_{k=0}^{n-1} (B - max(a, k))`, in closed form.
fn sum_len(b: i64, a: i64, n: i64) -> i64 {
    // k < a contribute B - a each; k >= a contribute B - k.
    let below = n.min(a);
    let mut s = below * (b - a);
    if n > a {
        // sum_{k=a}^{n-1} (B - k)
        let cnt = n - a;
        s += cnt * b - (a + n - 1) * cnt / 2;
    }
    s
}

/// Offset of block `(m, m')` inside the row of `m`.
fn block_offset(b: i64, m: i64, mp: i64) -> i64 {
    let a = m.abs();
    if mp >= 0 {
        sum_len(b, a, mp)
    } else {
        // sum_{k=mp}^{-1} (B - max(a,|k|)) = sum_{k=1}^{|mp|} ... = sum_len(b,a,|mp|+1) - (B - a)
        let neg = sum_len(b, a, -mp + 1) - (b - a);
        (b * b - m * m) - neg
    }
}

/// Index of the first coefficient (degree `max(|m|,|m'|)`) of block `(m, m')`.
pub(crate) fn block_start(b: usize, m: isize, mp: isize) -> usize {
    let (b, m, mp) = (b as i64, m as i64, mp as i64);
    (row_start(b, m) + block_offset(b, m, mp)) as usize
}

/// Index of `fhat(l, m, m')` in SOFT's coefficient layout (`so3CoefLoc(m, m', l, B)`).
///
/// Requires `max(|m|,|m'|) <= l < b`; use [`try_coef_index`] for a checked version.
pub fn coef_index(b: usize, l: usize, m: isize, mp: isize) -> usize {
    debug_assert!(valid_lmm(b, l, m, mp));
    block_start(b, m, mp) + l - m.unsigned_abs().max(mp.unsigned_abs())
}

fn valid_lmm(b: usize, l: usize, m: isize, mp: isize) -> bool {
    // Beyond 2^20 the layout's indices would overflow 64-bit arithmetic.
    b <= 1 << 20 && l < b && m.unsigned_abs() <= l && mp.unsigned_abs() <= l
}

/// Checked [`coef_index`]: an error if `l >= b` or `|m| > l` or `|m'| > l` (or `b > 2^20`).
pub fn try_coef_index(b: usize, l: usize, m: isize, mp: isize) -> Result<usize> {
    if !valid_lmm(b, l, m, mp) {
        return Err(Error::InvalidArgument(format!(
            "coefficient (l={l}, m={m}, m'={mp}) does not exist at bandwidth {b}"
        )));
    }
    Ok(coef_index(b, l, m, mp))
}

#[cfg(test)]
mod tests {
    use super::{beta, coef_index, num_coeffs, weights};

    #[test]
    fn spec_spot_values() {
        let b = 256;
        assert_eq!(coef_index(b, 0, 0, 0), 0);
        assert_eq!(coef_index(b, 255, 0, 0), 255);
        assert_eq!(coef_index(b, 1, 0, 1), 256);
        assert_eq!(coef_index(b, 1, 0, -1), 65281);
        assert_eq!(coef_index(b, 1, 1, 0), 65536);
        assert_eq!(coef_index(b, 1, -1, 0), 22304001);
        assert_eq!(coef_index(b, 255, -1, -1), 22369535);
        assert_eq!(num_coeffs(b), 22369536);
    }

    #[test]
    fn layout_is_soft_block_order() {
        // Walk the blocks in SOFT's order and check contiguity.
        for b in 1..10usize {
            let bi = b as isize;
            let order: Vec<isize> = (0..bi).chain(-(bi - 1)..0).collect();
            let mut next = 0;
            for &m in &order {
                for &mp in &order {
                    let l0 = m.unsigned_abs().max(mp.unsigned_abs());
                    for l in l0..b {
                        assert_eq!(coef_index(b, l, m, mp), next, "b={b} m={m} mp={mp} l={l}");
                        next += 1;
                    }
                }
            }
            assert_eq!(next, num_coeffs(b));
        }
    }

    #[test]
    fn weights_integrate_sin() {
        // sum_k w_k = int_0^pi sin = 2, and sum_k w_k cos^2 = 2/3.
        for b in [1usize, 2, 7, 64] {
            let w = weights(b);
            let s: f64 = w.iter().sum();
            assert!((s - 2.0).abs() < 1e-14, "b={b} sum={s}");
            if b >= 2 {
                let s2: f64 = (0..2 * b).map(|k| w[k] * beta(b, k).cos().powi(2)).sum();
                assert!((s2 - 2.0 / 3.0).abs() < 1e-14);
            }
        }
    }
}
