//! The `m' = 0` recurrence two degrees at a time (the Legendre stage of the S^2 transforms).
//!
//! For `m' = 0` the scaled values `e_i = dt^{m+i}_{m,0} / S_i` of `RecTables::coeffs`
//! satisfy `e_{i+1} = A'_i x e_i - e_{i-1}` (`C' = 0`, `x = cos beta`). Two steps with
//! the odd degree eliminated (`x e_{i-1} = (e_i + e_{i-2}) / A'_{i-1}`) give, for even `i`,
//!
//! `e_{i+2} = (A'_{i+1} A'_i x^2 - 1 - r_i) e_i - r_i e_{i-2}`, `r_i = A'_{i+1} / A'_{i-1}`
//!
//! (`r_0 = 0`, as `e_{-1} = 0`). On `f_j = e_{2j} / T_j` with `T_0 = T_1 = 1` and
//! `T_{j+1} = r_{2j} T_{j-1}` the last coefficient is 1 again, the form the kernels run:
//! `f_{j+1} = (alpha_j u + beta_j) f_j - f_{j-1}` in `u = x^2`, whose argument is
//! `tau = 1 - u = sin^2 beta`: one step per two degrees.
//!
//! The odd degrees are `x` times sums over the even ones, `x e_i = (e_{i+1} + e_{i-1}) / A'_i`:
//! - synthesis: `sum_{i odd} c_i e_i = x sum_j A'_{2j} h_j e_{2j}` with
//!   `h_j = c_{2j+1} - h_{j+1}` (from the top, [`odd_to_even`]);
//! - analysis: with `G_j = sum_s e_{2j}(beta_s) x_s y_s`, the odd sums
//!   `g_{2j+1} = sum_s e_{2j+1}(beta_s) y_s` are `A'_{2j} G_j - g_{2j-1}` ([`even_to_odd`]).

use super::RecCoeffs;

/// The coefficients of `steps` two-degree steps into `out` (`out.s` holds `T_j`) from the
/// degree-wise coefficients `base` of an `m' = 0` pair, which must hold at least `2 steps`
/// degrees. In `out`'s argument forms, `x` stands for `u = x^2` and the lower-half argument
/// `tau` for `1 - u = sin^2 beta`.
pub(crate) fn two_step_coeffs(base: &RecCoeffs, steps: usize, out: &mut RecCoeffs) {
    assert!(base.len() >= 2 * steps);
    out.resize(steps);
    let a = &base.a;
    let (mut t0, mut t1) = (1.0, 1.0);
    for j in 0..steps {
        let i = 2 * j;
        let r = if j == 0 { 0.0 } else { a[i + 1] / a[i - 1] };
        let t2 = if j == 0 { 1.0 } else { r * t0 };
        let ratio = t1 / t2;
        // alpha + beta = (A'_{i+1} A'_i - 1 - r) T_j / T_{j+1}, the product kept exact.
        let alpha = a[i + 1] * a[i] * ratio;
        let alpha_beta = a[i + 1].mul_add(a[i], -1.0 - r) * ratio;
        let beta = -(1.0 + r) * ratio;
        out.a[j] = alpha;
        out.neg_a[j] = -alpha;
        out.a_plus_c[j] = alpha_beta;
        out.c_minus_a[j] = beta - alpha;
        out.s[j] = t1;
        (t0, t1) = (t1, t2);
    }
}

/// Synthesis: the even-step coefficients of the odd degrees. `odd(j)` is the coefficient
/// of `e_{2j+1}` (0 past the last degree); `put(j, v)` receives `A'_{2j} h_j` for
/// `j < steps`, so that `sum_j odd(j) e_{2j+1} = x sum_j v_j e_{2j}`.
#[inline(always)]
pub(crate) fn odd_to_even<T>(
    base: &RecCoeffs,
    steps: usize,
    odd: impl Fn(usize) -> T,
    mut put: impl FnMut(usize, T),
) where
    T: Copy + std::ops::Sub<Output = T> + std::ops::Mul<f64, Output = T>,
{
    let mut h: Option<T> = None;
    for j in (0..steps).rev() {
        let v = match h {
            Some(h) => odd(j) - h,
            None => odd(j),
        };
        h = Some(v);
        put(j, v * base.a[2 * j]);
    }
}

/// Analysis: the odd-degree sums from the even-step sums of `x` times the data. `big_g(j)`
/// is `G_j`; `put(j, g)` receives `g_{2j+1}` for `j < steps`.
#[inline(always)]
pub(crate) fn even_to_odd<T>(
    base: &RecCoeffs,
    steps: usize,
    big_g: impl Fn(usize) -> T,
    mut put: impl FnMut(usize, T),
) where
    T: Copy + std::ops::Sub<Output = T> + std::ops::Mul<f64, Output = T>,
{
    let mut prev: Option<T> = None;
    for j in 0..steps {
        let g = big_g(j) * base.a[2 * j];
        let v = match prev {
            Some(p) => g - p,
            None => g,
        };
        prev = Some(v);
        put(j, v);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::wigner::RecTables;

    /// The even chain of [`two_step_coeffs`] reproduces every second value of the
    /// degree-wise recurrence (run in double precision from the same start), and the odd
    /// transforms are exact identities of that recurrence.
    #[test]
    fn two_steps_equal_two_single_steps() {
        let b = 200;
        let tables = RecTables::new(b);
        for m in [0usize, 1, 2, 5, 60, 150, 198] {
            let n = b - m;
            let mut base = RecCoeffs::new(n + 1);
            tables.coeffs(m, 0, &mut base);
            let steps = n.div_ceil(2);
            let mut two = RecCoeffs::new(0);
            two_step_coeffs(&base, steps, &mut two);
            for &x in &[0.999_9, 0.93, 0.5, 0.07, 1e-3] {
                // Degree-wise values e_i from e_0 = 1.
                let mut e = vec![0.0f64; n + 1];
                e[0] = 1.0;
                for i in 0..n {
                    let prev = if i == 0 { 0.0 } else { e[i - 1] };
                    e[i + 1] = base.a[i] * x * e[i] - prev;
                }
                let tau = 1.0 - x * x;
                let (mut f0, mut f1) = (0.0f64, 1.0f64);
                let size = e.iter().fold(1.0f64, |s, v| s.max(v.abs()));
                for j in 0..steps {
                    let want = e[2 * j];
                    let got = f1 * two.s[j];
                    assert!(
                        (got - want).abs() <= 1e-12 * size,
                        "m {m} x {x} j {j}: {got:e} vs {want:e}"
                    );
                    let t = two.neg_a[j].mul_add(tau, two.a_plus_c[j]);
                    (f0, f1) = (f1, t * f1 - f0);
                }
                // Synthesis of odd degrees through the even ones.
                let c: Vec<f64> = (0..n).map(|i| ((i * 7 + m) % 11) as f64 - 5.0).collect();
                let odd = |j: usize| c.get(2 * j + 1).copied().unwrap_or(0.0);
                let (mut want, mut got, mut scale) = (0.0, 0.0, 0.0);
                for i in (1..n).step_by(2) {
                    want += c[i] * e[i];
                    scale += (c[i] * e[i]).abs();
                }
                odd_to_even(&base, steps, odd, |j, v| got += x * v * e[2 * j]);
                assert!(
                    (got - want).abs() <= 1e-11 * scale.max(1.0),
                    "m {m} x {x}: odd synthesis {got:e} vs {want:e}"
                );
                // Analysis: g_{2j+1} = e_{2j+1} y from G_j = e_{2j} x y (one sample, y = 1).
                let big_g = |j: usize| e[2 * j] * x;
                even_to_odd(&base, steps, big_g, |j, g| {
                    if 2 * j + 1 < n {
                        let want = e[2 * j + 1];
                        assert!(
                            (g - want).abs() <= 1e-11 * size,
                            "m {m} x {x} j {j}: odd analysis {g:e} vs {want:e}"
                        );
                    }
                });
            }
        }
    }
}
