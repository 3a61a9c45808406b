//! A plain discrete Wigner transform: the yardstick for the library's DWT stage.
//!
//! Straightforward loops on one thread, no SIMD intrinsics, every value in plain `f64`:
//! for each order pair `(M, M')` with `|M|, |M'| < B` and each of the `2B` betas, the Wigner
//! `d^l_{M,M'}(beta)` for `l = max(|M|,|M'|) .. B-1` come from the textbook three-term
//! recurrence in `l`, and each degree costs one complex-times-real multiply-add (two FMAs) in
//! the quadrature sum. That is the work the library's forward (or inverse) DWT is counted
//! with, `8B (4B^3 - B)/3` flops, so the time ratio is a fair measure of what the library's
//! kernels, symmetries and skipping buy.
//!
//! Conventions are those of docs/conventions.md (Wigner d, sample grid): `d^1_{1,0}(b) = -sin(b)/sqrt 2`, `dt^l = sqrt((2l+1)/2) d^l`,
//! `beta_k = pi (2k+1)/(4B)` and the weights `w_B(k)` of `so3fft::weights`.
//!
//! The data of the DWT stage are the 2-D Fourier coefficients of the beta slices,
//! `G[k][M mod 2B][M' mod 2B]` (`2B` slices of `(2B)^2` complex values, frequencies `+-B`
//! unused). With that normalisation a band-limited signal has
//! `G(k, M, M') = sum_l fhat(l, M, M') dt^l_{M,M'}(beta_k)` (its slice DFT
//! `sum_{j1,j2} e^{+i M alpha} e^{+i M' gamma} f` is `(2B)^2 / (2 pi)` times that), and the
//! forward transform is `fhat(l, M, M') = sum_k w_B(k) dt^l_{M,M'}(beta_k) G(k, M, M')`.

use so3fft::Complex64;

/// `d^l_{M,M'}` of one order pair: starting value at `l0 = max(|M|,|M'|)` and the
/// coefficients of the three-term recurrence for `l = l0 .. lmax`.
///
/// Starting value (Wigner's formula with one term left):
/// `d^{l0}_{M,M'}(beta) = sign sqrt(binom(2 l0, k)) cos(beta/2)^p sin(beta/2)^q` with
/// * `M = l0`:   sign `(-1)^(l0-M')`, `k = p = l0+M'`, `q = l0-M'`;
/// * `M = -l0`:  sign `+1`, `k = q = l0+M'`, `p = l0-M'`;
/// * `M' = l0`:  sign `+1`, `k = p = l0+M`, `q = l0-M`;
/// * `M' = -l0`: sign `(-1)^(l0+M)`, `k = q = l0+M`, `p = l0-M`.
///
/// Recurrence (Edmonds (4.1.24) rearranged), with `A_l = (l^2-M^2)(l^2-M'^2)`:
/// `d^{l+1} = a_l (cos(beta) - M M' / (l(l+1))) d^l - b_l d^{l-1}`,
/// `a_l = (l+1)(2l+1) / sqrt(A_{l+1})`, `b_l = a_l sqrt(A_l) / (l (2l+1))`
/// (`b_{l0} = 0` since `A_{l0} = 0`; at `l = 0` the middle term is 0).
pub struct Column {
    pub l0: usize,
    prefactor: f64,
    /// Powers of `cos(beta/2)` and `sin(beta/2)` in the starting value.
    cos_power: i32,
    sin_power: i32,
    /// `a_l`, `M M'/(l(l+1))`, `b_l`, `sqrt((2l+1)/2)` for `l = l0 ..= lmax`.
    a: Vec<f64>,
    c: Vec<f64>,
    b: Vec<f64>,
    norm: Vec<f64>,
}

impl Column {
    pub fn new(m: isize, mp: isize, lmax: usize) -> Column {
        let l0 = m.unsigned_abs().max(mp.unsigned_abs());
        let l = l0 as isize;
        let (negative, k, p, q) = if m == l {
            ((l - mp) % 2 != 0, l + mp, l + mp, l - mp)
        } else if m == -l {
            (false, l + mp, l - mp, l + mp)
        } else if mp == l {
            (false, l + m, l + m, l - m)
        } else {
            ((l + m).rem_euclid(2) != 0, l + m, l - m, l + m)
        };
        let root = sqrt_binomial(2 * l0, k as usize);
        let (mf, mpf) = (m as f64, mp as f64);
        let count = (lmax + 1).saturating_sub(l0);
        let (mut a, mut c, mut b, mut norm) = (
            Vec::with_capacity(count),
            Vec::with_capacity(count),
            Vec::with_capacity(count),
            Vec::with_capacity(count),
        );
        let big_a = |l: f64| (l * l - mf * mf) * (l * l - mpf * mpf);
        for deg in l0..=lmax {
            let lf = deg as f64;
            let al = (lf + 1.0) * (2.0 * lf + 1.0) / big_a(lf + 1.0).sqrt();
            a.push(al);
            c.push(if deg == 0 {
                0.0
            } else {
                mf * mpf / (lf * (lf + 1.0))
            });
            b.push(if deg == l0 {
                0.0
            } else {
                al * big_a(lf).sqrt() / (lf * (2.0 * lf + 1.0))
            });
            norm.push(((2.0 * lf + 1.0) / 2.0).sqrt());
        }
        Column {
            l0,
            prefactor: if negative { -root } else { root },
            cos_power: p as i32,
            sin_power: q as i32,
            a,
            c,
            b,
            norm,
        }
    }

    /// Degrees covered, `lmax + 1 - l0`.
    pub fn len(&self) -> usize {
        self.a.len()
    }

    /// `d^{l0}` at the beta with half-angle cosine `ch` and sine `sh`. A value below the
    /// normal range is returned as 0: the whole column is then negligible (below about 1e-290)
    /// and subnormal arithmetic would only make the recurrence crawl.
    pub fn start(&self, ch: f64, sh: f64) -> f64 {
        let v = self.prefactor * ch.powi(self.cos_power) * sh.powi(self.sin_power);
        if v.abs() < f64::MIN_POSITIVE {
            0.0
        } else {
            v
        }
    }

    /// Unnormalised `d^l_{M,M'}(beta)` for `l = l0 ..= lmax` (for the tests).
    #[cfg(test)]
    pub fn values(&self, beta: f64) -> Vec<f64> {
        let (ch, sh, cb) = ((beta / 2.0).cos(), (beta / 2.0).sin(), beta.cos());
        let mut out = Vec::with_capacity(self.len());
        let (mut prev, mut d) = (0.0, self.start(ch, sh));
        for i in 0..self.len() {
            out.push(d);
            let next = self.a[i] * (cb - self.c[i]) * d - self.b[i] * prev;
            prev = d;
            d = next;
        }
        out
    }
}

/// `sqrt(binom(n, k))` as a running product (exact enough and finite for `n < 1030`).
fn sqrt_binomial(n: usize, k: usize) -> f64 {
    let k = k.min(n - k);
    let mut r = 1.0f64;
    for i in 1..=k {
        r *= (n - k + i) as f64 / i as f64;
    }
    r.sqrt()
}

/// Per-beta constants of bandwidth `b`: `cos(beta_k)`, `cos(beta_k/2)`, `sin(beta_k/2)`, `w_B(k)`.
pub struct Betas {
    cos: Vec<f64>,
    half_cos: Vec<f64>,
    half_sin: Vec<f64>,
    weight: Vec<f64>,
}

impl Betas {
    pub fn new(b: usize) -> Betas {
        let betas: Vec<f64> = (0..2 * b).map(|k| so3fft::beta(b, k)).collect();
        Betas {
            cos: betas.iter().map(|x| x.cos()).collect(),
            half_cos: betas.iter().map(|x| (x / 2.0).cos()).collect(),
            half_sin: betas.iter().map(|x| (x / 2.0).sin()).collect(),
            weight: so3fft::weights(b),
        }
    }
}

/// Index of frequency `(m, mp)` in one slice of `G` (`(2B)^2` values, row `m mod 2B`).
fn freq_index(b: usize, m: isize, mp: isize) -> usize {
    let n = 2 * b as isize;
    (m.rem_euclid(n) * n + mp.rem_euclid(n)) as usize
}

/// All orders `-(B-1) ..= B-1`.
fn orders(b: usize) -> std::ops::RangeInclusive<isize> {
    -(b as isize - 1)..=(b as isize - 1)
}

/// Forward DWT: `coeffs[(l, M, M')] = sum_k w_B(k) dt^l_{M,M'}(beta_k) G[k][M][M']` for
/// every coefficient (SOFT layout). `spectra` holds `2B` slices of `(2B)^2` values.
pub fn forward(b: usize, betas: &Betas, spectra: &[Complex64], coeffs: &mut [Complex64]) {
    let n = 2 * b;
    assert_eq!(spectra.len(), n * n * n);
    assert_eq!(coeffs.len(), so3fft::num_coeffs(b));
    for m in orders(b) {
        for mp in orders(b) {
            let column = Column::new(m, mp, b - 1);
            let start = so3fft::coef_index(b, column.l0, m, mp);
            let out = &mut coeffs[start..start + column.len()];
            out.fill(Complex64::new(0.0, 0.0));
            let freq = freq_index(b, m, mp);
            for k in 0..n {
                let x = spectra[k * n * n + freq] * betas.weight[k];
                let cos_beta = betas.cos[k];
                let (mut prev, mut d) = (0.0, column.start(betas.half_cos[k], betas.half_sin[k]));
                for (i, out_value) in out.iter_mut().enumerate() {
                    *out_value += x * (d * column.norm[i]);
                    let next = column.a[i] * (cos_beta - column.c[i]) * d - column.b[i] * prev;
                    prev = d;
                    d = next;
                }
            }
        }
    }
}

/// Inverse DWT: `G[k][M][M'] = sum_l fhat(l, M, M') dt^l_{M,M'}(beta_k)` (frequencies `+-B`
/// are set to 0).
pub fn inverse(b: usize, betas: &Betas, coeffs: &[Complex64], spectra: &mut [Complex64]) {
    let n = 2 * b;
    assert_eq!(spectra.len(), n * n * n);
    assert_eq!(coeffs.len(), so3fft::num_coeffs(b));
    spectra.fill(Complex64::new(0.0, 0.0));
    for m in orders(b) {
        for mp in orders(b) {
            let column = Column::new(m, mp, b - 1);
            let start = so3fft::coef_index(b, column.l0, m, mp);
            let row = &coeffs[start..start + column.len()];
            let freq = freq_index(b, m, mp);
            for k in 0..n {
                let cos_beta = betas.cos[k];
                let (mut prev, mut d) = (0.0, column.start(betas.half_cos[k], betas.half_sin[k]));
                let mut acc = Complex64::new(0.0, 0.0);
                for (i, coeff) in row.iter().enumerate() {
                    acc += coeff * (d * column.norm[i]);
                    let next = column.a[i] * (cos_beta - column.c[i]) * d - column.b[i] * prev;
                    prev = d;
                    d = next;
                }
                spectra[k * n * n + freq] = acc;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::{forward, freq_index, inverse, orders, Betas, Column};
    use crate::workload::{random_coeffs, roundtrip_error};
    use so3fft::Complex64;
    use std::f64::consts::PI;

    fn column(m: isize, mp: isize, lmax: usize, beta: f64) -> Vec<f64> {
        Column::new(m, mp, lmax).values(beta)
    }

    #[test]
    fn closed_forms() {
        for &b in &[0.1, 0.7, 1.5, 2.2, 3.0] {
            let (c, s) = (f64::cos(b), f64::sin(b));
            let close = |x: f64, y: f64| assert!((x - y).abs() < 1e-15, "{x} vs {y} at {b}");
            close(column(0, 0, 2, b)[0], 1.0);
            close(column(0, 0, 2, b)[1], c);
            close(column(0, 0, 2, b)[2], 1.5 * c * c - 0.5);
            close(column(1, 0, 1, b)[0], -s / 2f64.sqrt());
            close(column(0, 1, 1, b)[0], s / 2f64.sqrt());
            close(column(-1, 0, 1, b)[0], s / 2f64.sqrt());
            close(column(1, 1, 1, b)[0], (1.0 + c) / 2.0);
            close(column(1, -1, 1, b)[0], (1.0 - c) / 2.0);
            close(column(-1, 1, 1, b)[0], (1.0 - c) / 2.0);
            // d^2_{1,0} = -sqrt(3/2) sin cos, d^2_{2,0} = sqrt(3/8) sin^2
            close(column(1, 0, 2, b)[1], -(1.5f64).sqrt() * s * c);
            close(column(2, 0, 2, b)[0], (0.375f64).sqrt() * s * s);
        }
    }

    /// Against the library's own Wigner-d (scaled starting values, vectorised recurrence).
    #[test]
    fn matches_library_wigner_d() {
        let lmax = 70;
        let mut worst = 0.0f64;
        for &(m, mp) in &[
            (0, 0),
            (3, -2),
            (-5, 5),
            (7, 7),
            (-7, -7),
            (12, -30),
            (-30, 12),
            (40, 1),
            (-2, -41),
            (25, 25),
            (60, -60),
        ] {
            for &beta in &[0.01, 0.3, 1.0, PI / 2.0, 2.0, 3.1, so3fft::beta(64, 5)] {
                let ours = column(m, mp, lmax, beta);
                let lib = so3fft::wigner::wigner_d_column(m, mp, lmax, beta);
                assert_eq!(ours.len(), lib.len());
                for (x, y) in ours.iter().zip(&lib) {
                    worst = worst.max((x - y).abs());
                }
            }
        }
        assert!(worst < 1e-12, "worst deviation {worst}");
    }

    /// Against the mpmath reference table, where it is available (degrees < 256).
    #[test]
    fn matches_reference_csv() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../tests/data/wigner_d_reference.csv"
        );
        let Ok(text) = std::fs::read_to_string(path) else {
            eprintln!("{path} not found: skipped");
            return;
        };
        let mut checked = 0;
        let mut worst = 0.0f64;
        for line in text.lines().filter(|l| !l.starts_with('#')).skip(1) {
            let f: Vec<&str> = line.split(',').collect();
            let l: usize = f[0].parse().unwrap();
            let (m, mp): (isize, isize) = (f[1].parse().unwrap(), f[2].parse().unwrap());
            let (beta, d): (f64, f64) = (f[3].parse().unwrap(), f[4].parse().unwrap());
            if l >= 256 {
                continue;
            }
            let col = column(m, mp, l, beta);
            worst = worst.max((col[col.len() - 1] - d).abs());
            checked += 1;
        }
        assert!(checked > 100, "only {checked} reference values");
        assert!(worst < 1e-12, "worst deviation {worst}");
    }

    #[test]
    fn round_trip() {
        let b = 10;
        let betas = Betas::new(b);
        let coeffs = random_coeffs(so3fft::num_coeffs(b), 3);
        let mut g = vec![Complex64::new(0.0, 0.0); 8 * b * b * b];
        let mut back = vec![Complex64::new(0.0, 0.0); coeffs.len()];
        inverse(b, &betas, &coeffs, &mut g);
        forward(b, &betas, &g, &mut back);
        let e = roundtrip_error(&coeffs, &back);
        assert!(e.max_abs < 1e-13, "{e:?}");
    }

    /// The naive stage data are the slice DFTs of the library's samples, scaled by
    /// `(2B)^2 / (2 pi)`: checks every convention (signs, which order pairs with alpha).
    #[test]
    fn inverse_matches_library_samples() {
        let b = 5;
        let n = 2 * b;
        let plan = so3fft::Plan::new(b, &so3fft::Options::default()).unwrap();
        let coeffs = random_coeffs(plan.num_coeffs(), 11);
        let mut f = vec![Complex64::new(0.0, 0.0); plan.num_samples()];
        plan.inverse(&coeffs, &mut f).unwrap();
        let mut g = vec![Complex64::new(0.0, 0.0); n * n * n];
        inverse(b, &Betas::new(b), &coeffs, &mut g);
        let scale = (n * n) as f64 / (2.0 * PI);
        let mut worst = 0.0f64;
        for k in 0..n {
            for m in orders(b) {
                for mp in orders(b) {
                    let mut s = Complex64::new(0.0, 0.0);
                    for j1 in 0..n {
                        for j2 in 0..n {
                            let ph =
                                m as f64 * so3fft::alpha(b, j1) + mp as f64 * so3fft::gamma(b, j2);
                            s += f[so3fft::sample_index(b, j1, k, j2)]
                                * Complex64::from_polar(1.0, ph);
                        }
                    }
                    worst = worst.max((s - g[k * n * n + freq_index(b, m, mp)] * scale).norm());
                }
            }
        }
        assert!(worst < 1e-11, "worst deviation {worst}");
    }
}
