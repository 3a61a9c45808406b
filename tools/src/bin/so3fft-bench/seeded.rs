//! Coefficients that are a pure function of (seed, index), for the memory-lean runs at large
//! B: they are generated into the array, transformed, and compared with the transform's
//! output by generating them again, so no reference copy (2.9 GB at B = 512) is kept.
//!
//! Both filling and comparing run in parallel on rayon's global pool: one thread writing
//! or reading gigabytes would take longer than the transform's FFT stage.

use crate::workload::RoundTripError;
use rayon::prelude::*;
use so3fft::{coef_index, Complex64};

/// Entries per parallel work item of the flat (complex) variant.
const CHUNK: usize = 1 << 16;

/// SplitMix64 finaliser (Steele, Lea, Flood 2014): a bijective, well-mixed 64-bit hash.
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// Uniform in [-1, 1) from the top 53 bits.
fn signed_unit(x: u64) -> f64 {
    2.0 * ((x >> 11) as f64 * (1.0 / (1u64 << 53) as f64)) - 1.0
}

/// The value of `key` under `seed`: real and imaginary parts uniform in [-1, 1).
pub fn value(seed: u64, key: u64) -> Complex64 {
    let base = seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ key.wrapping_mul(2);
    Complex64::new(signed_unit(mix(base)), signed_unit(mix(base ^ 1)))
}

/// Whether `(m, mp)` is the representative of its pair `(m, mp)`, `(-m, -mp)` (the half the
/// real-signal transforms read): `mp > 0`, or `mp = 0` and `m >= 0`.
pub fn representative(m: isize, mp: isize) -> bool {
    mp > 0 || (mp == 0 && m >= 0)
}

/// `(-1)^(m - mp)`.
fn parity_sign(m: isize, mp: isize) -> f64 {
    if (m - mp).rem_euclid(2) == 0 {
        1.0
    } else {
        -1.0
    }
}

/// Coefficient `(l, m, mp)` of a real signal: free values on the representatives (real on
/// `(0, 0)`), the others from `fhat(l, -M, -M') = (-1)^(M-M') conj(fhat(l, M, M'))`.
///
/// The sign follows from the Wigner-D conventions of docs/conventions.md: `conj(D^l_{M,M'}) = e^{iM alpha} d^l_{M,M'}
/// e^{iM' gamma}` and `d^l_{M,M'} = (-1)^(M-M') d^l_{-M,-M'}`, so `conj(Dt^l_{M,M'}) =
/// (-1)^(M-M') Dt^l_{-M,-M'}`; `f = conj(f)` then requires the relation above.
pub fn real_value(seed: u64, b: usize, l: usize, m: isize, mp: isize) -> Complex64 {
    if representative(m, mp) {
        let v = value(seed, coef_index(b, l, m, mp) as u64);
        if m == 0 && mp == 0 {
            Complex64::new(v.re, 0.0)
        } else {
            v
        }
    } else {
        value(seed, coef_index(b, l, -m, -mp) as u64).conj() * parity_sign(m, mp)
    }
}

/// Fills `coeffs` with `value(seed, index)`.
pub fn fill_complex(seed: u64, coeffs: &mut [Complex64]) {
    coeffs
        .par_chunks_mut(CHUNK)
        .enumerate()
        .for_each(|(c, part)| {
            for (i, x) in part.iter_mut().enumerate() {
                *x = value(seed, (c * CHUNK + i) as u64);
            }
        });
}

/// Error of `result` against `value(seed, index)`.
pub fn compare_complex(seed: u64, result: &[Complex64]) -> RoundTripError {
    result
        .par_chunks(CHUNK)
        .enumerate()
        .map(|(c, part)| {
            let mut acc = ErrorSums::default();
            for (i, x) in part.iter().enumerate() {
                acc.add(value(seed, (c * CHUNK + i) as u64), *x);
            }
            acc
        })
        .reduce(ErrorSums::default, ErrorSums::merge)
        .finish()
}

/// The order pairs of bandwidth `b` in layout order: `(m, mp, l0)`, blocks of `b - l0`
/// degrees, rows of `m` (orders `0, 1, .., B-1, -(B-1), .., -1`).
fn layout_orders(b: usize) -> impl Iterator<Item = isize> {
    let b = b as isize;
    (0..b).chain(-(b - 1)..0)
}

/// Start and length of each row of the layout (one per `m`, in layout order).
fn row_spans(b: usize) -> Vec<(isize, usize, usize)> {
    let mut start = 0;
    layout_orders(b)
        .map(|m| {
            let len = b * b - m.unsigned_abs() * m.unsigned_abs();
            start += len;
            (m, start - len, len)
        })
        .collect()
}

/// `coeffs` split into the rows of the layout, for parallel work per row.
fn rows_mut<T>(b: usize, mut coeffs: &mut [T]) -> Vec<(isize, &mut [T])> {
    let mut out = Vec::with_capacity(2 * b);
    for (m, _, len) in row_spans(b) {
        let (row, rest) = std::mem::take(&mut coeffs).split_at_mut(len);
        out.push((m, row));
        coeffs = rest;
    }
    assert!(
        coeffs.is_empty(),
        "not a coefficient array of bandwidth {b}"
    );
    out
}

/// Calls `f(l, mp, position in the row)` for every entry of row `m`, in layout order.
fn walk_row(b: usize, m: isize, mut f: impl FnMut(usize, isize, usize)) {
    let mut pos = 0;
    for mp in layout_orders(b) {
        let l0 = m.unsigned_abs().max(mp.unsigned_abs());
        for l in l0..b {
            f(l, mp, pos);
            pos += 1;
        }
    }
}

/// Fills `coeffs` with the real-signal coefficients [`real_value`].
pub fn fill_real(seed: u64, b: usize, coeffs: &mut [Complex64]) {
    rows_mut(b, coeffs).into_par_iter().for_each(|(m, row)| {
        walk_row(b, m, |l, mp, i| row[i] = real_value(seed, b, l, m, mp));
    });
}

/// Error of `result` against [`real_value`].
pub fn compare_real(seed: u64, b: usize, result: &[Complex64]) -> RoundTripError {
    assert_eq!(result.len(), so3fft::num_coeffs(b));
    row_spans(b)
        .into_par_iter()
        .map(|(m, start, len)| {
            let row = &result[start..start + len];
            let mut acc = ErrorSums::default();
            walk_row(b, m, |l, mp, i| {
                acc.add(real_value(seed, b, l, m, mp), row[i])
            });
            acc
        })
        .reduce(ErrorSums::default, ErrorSums::merge)
        .finish()
}

/// Partial sums of [`RoundTripError`] (NaN-propagating max, as in `roundtrip_error`).
#[derive(Clone, Copy, Default)]
struct ErrorSums {
    max_abs: f64,
    diff2: f64,
    ref2: f64,
}

impl ErrorSums {
    fn add(&mut self, reference: Complex64, x: Complex64) {
        let d = (x - reference).norm();
        self.max_abs = if d.is_nan() || self.max_abs.is_nan() {
            f64::NAN
        } else {
            self.max_abs.max(d)
        };
        self.diff2 += d * d;
        self.ref2 += reference.norm_sqr();
    }

    fn merge(a: ErrorSums, b: ErrorSums) -> ErrorSums {
        ErrorSums {
            max_abs: if a.max_abs.is_nan() || b.max_abs.is_nan() {
                f64::NAN
            } else {
                a.max_abs.max(b.max_abs)
            },
            diff2: a.diff2 + b.diff2,
            ref2: a.ref2 + b.ref2,
        }
    }

    fn finish(self) -> RoundTripError {
        RoundTripError {
            max_abs: self.max_abs,
            rel_l2: (self.diff2 / self.ref2).sqrt(),
        }
    }
}

/// Largest `|Im f|` and largest `|f|` of the samples of [`fill_real`]'s coefficients at
/// bandwidth `b`, through the library's complex inverse: checks the sign of the symmetry
/// (about 1e-15 relative if it is right).
pub fn real_symmetry_check(b: usize, seed: u64) -> Result<(f64, f64), so3fft::Error> {
    let plan = so3fft::Plan::new(b, &so3fft::Options::default())?;
    let mut coeffs = vec![Complex64::new(0.0, 0.0); plan.num_coeffs()];
    fill_real(seed, b, &mut coeffs);
    let mut f = vec![Complex64::new(0.0, 0.0); plan.num_samples()];
    plan.inverse(&coeffs, &mut f)?;
    let max_im = f.iter().map(|z| z.im.abs()).fold(0.0, f64::max);
    let max_abs = f.iter().map(|z| z.norm()).fold(0.0, f64::max);
    Ok((max_im, max_abs))
}

#[cfg(test)]
mod tests {
    use super::{
        compare_complex, compare_real, fill_complex, fill_real, real_symmetry_check,
        representative, rows_mut, walk_row,
    };
    use crate::workload::roundtrip_error;
    use so3fft::{coef_index, Complex64};

    #[test]
    fn rows_cover_the_layout() {
        let b = 7;
        let mut idx: Vec<usize> = (0..so3fft::num_coeffs(b)).collect();
        let mut count = 0;
        for (m, row) in rows_mut(b, &mut idx) {
            walk_row(b, m, |l, mp, i| {
                assert_eq!(row[i], coef_index(b, l, m, mp));
                count += 1;
            });
        }
        assert_eq!(count, so3fft::num_coeffs(b));
    }

    #[test]
    fn compare_matches_the_plain_error() {
        let b = 6;
        let n = so3fft::num_coeffs(b);
        let mut c = vec![Complex64::new(0.0, 0.0); n];
        fill_complex(9, &mut c);
        let reference = c.clone();
        c[17] += Complex64::new(1e-3, 0.0);
        let (x, y) = (compare_complex(9, &c), roundtrip_error(&reference, &c));
        assert_eq!(x.max_abs, y.max_abs);
        assert!((x.rel_l2 - y.rel_l2).abs() < 1e-12 * y.rel_l2);
        fill_real(4, b, &mut c);
        let reference = c.clone();
        c[5] += Complex64::new(0.0, 2e-3);
        let (x, y) = (compare_real(4, b, &c), roundtrip_error(&reference, &c));
        assert_eq!(x.max_abs, y.max_abs);
        assert!((x.rel_l2 - y.rel_l2).abs() < 1e-12 * y.rel_l2);
    }

    /// The derived symmetry makes the library's complex inverse real, and the opposite sign
    /// does not (so the check can tell).
    #[test]
    fn real_symmetry_gives_real_samples() {
        let (im, abs) = real_symmetry_check(12, 5).unwrap();
        assert!(im < 1e-14 * abs, "max |Im| {im}, max |f| {abs}");
        let b = 12;
        let plan = so3fft::Plan::new(b, &so3fft::Options::default()).unwrap();
        let mut coeffs = vec![Complex64::new(0.0, 0.0); plan.num_coeffs()];
        fill_real(5, b, &mut coeffs);
        for (m, row) in rows_mut(b, &mut coeffs) {
            walk_row(b, m, |_, mp, i| {
                if !representative(m, mp) {
                    row[i] = -row[i];
                }
            });
        }
        let mut f = vec![Complex64::new(0.0, 0.0); plan.num_samples()];
        plan.inverse(&coeffs, &mut f).unwrap();
        let im = f.iter().map(|z| z.im.abs()).fold(0.0, f64::max);
        assert!(im > 0.1, "flipped sign still real: {im}");
    }

    /// The real-signal transforms reproduce these coefficients.
    #[test]
    fn real_round_trip() {
        let b = 10;
        let plan = so3fft::Plan::new(b, &so3fft::Options::default().with_real(true)).unwrap();
        let mut c = vec![Complex64::new(0.0, 0.0); plan.num_coeffs()];
        fill_real(8, b, &mut c);
        let mut f = vec![0.0; plan.num_samples()];
        plan.inverse_real(&c, &mut f).unwrap();
        plan.forward_real(&f, &mut c).unwrap();
        let e = compare_real(8, b, &c);
        assert!(e.max_abs < 1e-13, "{e:?}");
    }
}
