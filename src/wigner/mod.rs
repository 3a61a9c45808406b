//! Wigner-d functions: the public d functions on top of the recurrence coefficients
//! (`recurrence.rs`) and the overflow/underflow-free starting values (`starts.rs`) that
//! the DWT kernels use; `column.rs` runs the recurrence for one beta as the kernels do,
//! `derivatives.rs` its beta derivatives for several betas at once (peak refinement).
//!
//! The kernels run the three-term recurrence in `l` for the normalised
//! `dt^l = sqrt((2l+1)/2) d^l` of a base pair `(m, m')`, `m >= m' >= 0`:
//!
//! `dt^{l+1} = (A_l cos(beta) + C_l) dt^l - Bc_l dt^{l-1}`, starting at `l0 = m` with
//! `dt^{m}_{m,m'} = (-1)^(m-m') sqrt((2m+1)/2) sqrt(binom(2m, m-m')) cos(beta/2)^(m+m') sin(beta/2)^(m-m')`.

pub(crate) mod column;
pub(crate) mod derivatives;
#[cfg(test)]
mod f32_accuracy;
pub(crate) mod recurrence;
pub(crate) mod starts;

use crate::numeric::{sin_cos_dd, Dd};
use crate::simd::Isa;
use column::column;
pub use derivatives::wigner_d_derivatives;
pub(crate) use recurrence::{RecCoeffs, RecTables, REC_PAD};
pub(crate) use starts::{
    big, skip_bits_range, start_norm, start_norms, BetaTables, DEFAULT_SKIP_BITS,
};

/// `d^l_{m,mp}(beta)` (standard, not normalised) for `l = max(|m|,|mp|) ..= lmax`.
///
/// Computed from the same starting values and recurrence coefficients as the transforms,
/// in the arithmetic of the DWT kernels for the best instruction set of this CPU (the
/// kernels' tests check that they reproduce it bit for bit).
pub fn wigner_d_column(m: isize, mp: isize, lmax: usize, beta: f64) -> Vec<f64> {
    wigner_d_column_isa(Isa::detect(), m, mp, lmax, beta)
}

/// [`wigner_d_column`] in the arithmetic of the kernels for `isa`.
pub(crate) fn wigner_d_column_isa(
    isa: Isa,
    m: isize,
    mp: isize,
    lmax: usize,
    beta: f64,
) -> Vec<f64> {
    let (base_m, base_mp, member) = crate::symmetry::locate(m, mp);
    if lmax < base_m {
        return Vec::new();
    }
    // pi - beta for reversed members, without rounding: swap the half-angle cos and sin.
    // (`beta / 2` is exact; outside [0, pi] the half-angle functions take their signs.)
    let (s, c) = if (0.0..=std::f64::consts::PI).contains(&beta) {
        sin_cos_dd(Dd::new(beta / 2.0))
    } else {
        (Dd::new((beta / 2.0).sin()), Dd::new((beta / 2.0).cos()))
    };
    let point = if member.reversed { (s, c) } else { (c, s) };
    let betas = BetaTables::new(&[point], 2 * base_m);
    let tables = RecTables::for_orders(lmax + 1, &[base_m, base_mp]);
    let col = column(isa, &betas, &tables, 0, (base_m, base_mp), lmax + 1);
    col.iter()
        .enumerate()
        .map(|(i, v)| {
            let l = base_m + i;
            member.sign_at(l) * v / ((2 * l + 1) as f64 / 2.0).sqrt()
        })
        .collect()
}

/// Normalised `dt^l_{m,mp}(beta_k)` on the bandwidth-`b` grid: rows `l = max(|m|,|mp|)..b`,
/// each of `2b` values (`k = 0..2b`), row-major. Same tables and arithmetic as the DWT.
pub fn dt_on_grid(b: usize, m: isize, mp: isize) -> Vec<f64> {
    let (base_m, base_mp, member) = crate::symmetry::locate(m, mp);
    assert!(
        base_m < b,
        "order ({m},{mp}) out of range for bandwidth {b}"
    );
    let n = 2 * b;
    let betas = BetaTables::grid(b);
    let tables = RecTables::new(b);
    let isa = Isa::detect();
    let rows = b - base_m;
    let mut out = vec![0.0; rows * n];
    for k in 0..n {
        let src = if member.reversed { n - 1 - k } else { k };
        let col = column(isa, &betas, &tables, src, (base_m, base_mp), b);
        for (i, v) in col.iter().enumerate() {
            out[i * n + k] = member.sign_at(base_m + i) * v;
        }
    }
    out
}

/// The lowest order from which the `m' = 0` recurrences (the S^2 Legendre stage) run in
/// single precision at bandwidth `b`; lower orders run in doubles. The single-precision
/// recurrence loses accuracy near the poles, where the low orders have their weight: at
/// `m < 16` its error reaches 1e-5 to 4e-4 from B = 256 on, at `m >= 16` it stays near
/// `B x 1e-8` (measured in `notes/reference/f32_recurrence/rust-twin.md`).
pub(crate) fn single_precision_orders(b: usize) -> usize {
    16.min(b)
}
