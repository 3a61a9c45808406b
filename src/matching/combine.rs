//! SO(3) coefficients of a correlation from the S^2 coefficients of signal and pattern.

use crate::error::{Error, Result};
use crate::grid::{block_start, num_coeffs};
use crate::s2::order_start;
use crate::workers::SendPtr;
use crate::Real;
use num_complex::{Complex, Complex64};
use rayon::prelude::*;
use std::f64::consts::PI;

/// The SO(3) coefficients (bandwidth `b_out`, `so3CoefLoc` order) of the correlation
/// `C(g) = int f(x) conj(h(g^-1 x)) dx` of a signal `f` and a pattern `h` given by their S^2
/// coefficients (bandwidth `b_in`, `seanindex` order):
/// `Chat(l, m1, m2) = 2 pi sqrt(2/(2l+1)) (-1)^(m1+m2) fhat(l,-m1) conj(hhat(l,-m2))` for
/// `l <= deg_lim`, zero for every other coefficient (SOFT's `so3CombineCoef_fftw`).
/// `deg_lim < min(b_in, b_out)`.
///
/// Every entry of `out` is written once (no zeroing pass). When both inputs have the real
/// symmetry `fhat(l,-m) = (-1)^m conj(fhat(l,m))` exactly up to degree `deg_lim` (all
/// finite, `fhat(l,0)` real), only the order pairs `(m1 >= 0, ...)` are computed and their
/// partners written as `(-1)^(m1-m2) conj(Chat(l,m1,m2))`, which is then the same number as
/// the formula gives. Called on a rayon worker (inside `ThreadPool::install`), the orders
/// are spread over the pool's threads.
pub fn combine(
    (sig, pat): (&[Complex64], &[Complex64]),
    b_in: usize,
    deg_lim: usize,
    b_out: usize,
    out: &mut [Complex64],
) -> Result<()> {
    check(sig.len(), pat.len(), (b_in, deg_lim, b_out), out.len())?;
    let real = s2_real_symmetric(sig, b_in, deg_lim) && s2_real_symmetric(pat, b_in, deg_lim);
    write_combined((sig, pat), b_in, deg_lim, b_out, out, real);
    Ok(())
}

/// Whether the S^2 coefficients `c` (bandwidth `b`) of degrees up to `deg_lim` are finite and
/// have the real symmetry exactly: `c(l,0)` real, `c(l,-m) = (-1)^m conj(c(l,m))` (as
/// numbers: `+0` and `-0` are equal).
pub(crate) fn s2_real_symmetric(c: &[Complex64], b: usize, deg_lim: usize) -> bool {
    let zero = order_start(b, 0);
    let m0 = c[zero..=zero + deg_lim]
        .iter()
        .all(|z| z.im == 0.0 && z.re.is_finite());
    m0 && (1..=deg_lim).all(|m| {
        let (p, q) = (order_start(b, m as isize), order_start(b, -(m as isize)));
        let n = deg_lim + 1 - m;
        let s = if m % 2 == 0 { 1.0 } else { -1.0 };
        c[p..p + n].iter().zip(&c[q..q + n]).all(|(a, z)| {
            a.re.is_finite() && a.im.is_finite() && z.re == s * a.re && z.im == -s * a.im
        })
    })
}

/// [`combine`]'s writing: each row `m1` of `out` (contiguous in the layout) written once,
/// the combination in degrees `max(|m1|,|m2|)..=deg_lim` of each block, zeros elsewhere;
/// with `real`, rows `m1 >= 0` computed and rows `m1 < 0` filled by the SO(3) real
/// symmetry (row 0: blocks `m2 >= 0` computed, `m2 < 0` filled).
fn write_combined(
    (sig, pat): (&[Complex64], &[Complex64]),
    b_in: usize,
    deg_lim: usize,
    b_out: usize,
    out: &mut [Complex64],
    real: bool,
) {
    let norms: Vec<f64> = (0..=deg_lim)
        .map(|l| 2.0 * PI * (2.0 / (2 * l + 1) as f64).sqrt())
        .collect();
    let bo = b_out as isize;
    let len = out.len();
    let dst = SendPtr(out.as_mut_ptr());
    // An output too large for the cache is written by non-temporal stores (ordinary ones
    // would first read every line).
    let stream = 16 * len > STREAM_BYTES && (dst.get() as usize).is_multiple_of(16);
    // Block (m1, m2): the entries of degrees first..b_out, as a raw range of `out`.
    let block = |m1: isize, m2: isize| {
        let first = m1.unsigned_abs().max(m2.unsigned_abs());
        let start = block_start(b_out, m1, m2);
        assert!(start + (b_out - first) <= len);
        (first, dst.get().wrapping_add(start))
    };
    // Writes block (m1, m2) and, with `mirror`, its partner (-m1, -m2) by the symmetry.
    let one_block = |m1: isize, m2: isize, mirror: bool| {
        let (first, at) = block(m1, m2);
        let partner = mirror.then(|| block(-m1, -m2).1);
        let sign = if (m1 + m2).rem_euclid(2) == 0 {
            1.0
        } else {
            -1.0
        };
        let computed = if first <= deg_lim {
            let f_row = &sig[order_start(b_in, -m1)..];
            let h_row = &pat[order_start(b_in, -m2)..];
            let (a1, a2) = (m1.unsigned_abs(), m2.unsigned_abs());
            for l in first..=deg_lim {
                let v = f_row[l - a1] * h_row[l - a2].conj() * (sign * norms[l]);
                // SAFETY: entry `l - first < b_out - first` of the block (asserted in
                // `block`), which is this task's alone (see the loop over rows below).
                unsafe {
                    put(at.add(l - first), v, stream);
                    if let Some(p) = partner {
                        // (-1)^(m1-m2) = (-1)^(m1+m2) = sign.
                        put(p.add(l - first), v.conj() * sign, stream);
                    }
                }
            }
            deg_lim + 1 - first
        } else {
            0
        };
        for i in computed..b_out - first {
            // SAFETY: as above.
            unsafe {
                put(at.add(i), Complex64::default(), stream);
                if let Some(p) = partner {
                    put(p.add(i), Complex64::default(), stream);
                }
            }
        }
    };
    // Row m1 (and, with `real`, row -m1): the tasks write disjoint rows.
    let row = |m1: isize| {
        if real {
            if m1 < 0 {
                return;
            }
            let lowest = if m1 == 0 { 0 } else { -(bo - 1) };
            for m2 in lowest..bo {
                one_block(m1, m2, !(m1 == 0 && m2 == 0));
            }
        } else {
            for m2 in -(bo - 1)..bo {
                one_block(m1, m2, false);
            }
        }
        if stream {
            crate::simd::sfence();
        }
    };
    if rayon::current_thread_index().is_some() {
        (-(bo - 1)..bo).into_par_iter().for_each(row);
    } else {
        (-(bo - 1)..bo).for_each(row);
    }
}

/// Bytes of output from which [`combine`] writes with non-temporal stores: a quarter of a
/// 32 MiB last-level cache.
const STREAM_BYTES: usize = 8 << 20;

/// Write `v` at `p`; with `stream`, by a non-temporal store (`p` 16-byte aligned).
///
/// # Safety
/// `p` is valid for writing one value and, with `stream`, 16-byte aligned.
#[inline(always)]
unsafe fn put(p: *mut Complex64, v: Complex64, stream: bool) {
    #[cfg(target_arch = "x86_64")]
    if stream {
        use std::arch::x86_64::{_mm_set_pd, _mm_stream_pd};
        // SAFETY: the caller's contract; SSE2 is part of x86_64.
        unsafe { _mm_stream_pd(p as *mut f64, _mm_set_pd(v.im, v.re)) };
        return;
    }
    let _ = stream;
    // SAFETY: the caller's contract.
    unsafe { *p = v };
}

/// An error unless the lengths fit the bandwidths and `deg_lim < min(b_in, b_out)`.
pub(super) fn check(
    sig: usize,
    pat: usize,
    (b_in, deg_lim, b_out): (usize, usize, usize),
    out: usize,
) -> Result<()> {
    if deg_lim >= b_in.min(b_out) {
        return Err(Error::InvalidArgument(format!(
            "degree limit {deg_lim} must be below both bandwidths ({b_in}, {b_out})"
        )));
    }
    for (what, expected, got) in [
        ("signal coefficients", b_in * b_in, sig),
        ("pattern coefficients", b_in * b_in, pat),
        ("SO(3) coefficients", num_coeffs(b_out), out),
    ] {
        if expected != got {
            return Err(Error::LengthMismatch {
                what,
                expected,
                got,
            });
        }
    }
    Ok(())
}

/// How [`add_combined`] treats the output.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(super) enum Combine {
    /// Add to what `out` holds.
    Add,
    /// Overwrite it: the degrees `from..=to` of each order pair with the combination, its
    /// degrees below `from` with 0 (one pass over the array instead of zeroing it first
    /// and then adding). Degrees above `to` are not written.
    Assign,
}

/// Adds the combination of degrees `from..=to`, degree `l` times `factors[l]`, to `out` (lengths checked by
/// the caller with [`check`]), or writes it (`mode`); with `half`, only the order pairs a
/// real-signal inverse reads (`M' > 0`, or `M' = 0` and `M >= 0`; the others are left as
/// they are). For each order pair the degrees are consecutive in all three arrays, so the
/// inner loop runs over contiguous runs. In `f32` the products are formed in `f64` and each
/// result rounded once.
pub(super) fn add_combined<T: Real>(
    (sig, pat): (&[Complex<T>], &[Complex<T>]),
    b_in: usize,
    (from, to): (usize, usize),
    b_out: usize,
    (factors, out): (&[f64], &mut [Complex<T>]),
    (half, mode): (bool, Combine),
) {
    let wide = |z: Complex<T>| Complex64::new(z.re.to_f64(), z.im.to_f64());
    let narrow = |z: Complex64| Complex::new(T::from_f64(z.re), T::from_f64(z.im));
    if from > to && mode == Combine::Add {
        return;
    }
    let norms: Vec<f64> = (0..=to)
        .map(|l| factors[l] * 2.0 * PI * (2.0 / (2 * l + 1) as f64).sqrt())
        .collect();
    let top = to as isize;
    let len = out.len();
    let dst = SendPtr(out.as_mut_ptr());
    let row = |m1: isize| {
        // fhat(l, -m1) for l = |m1|.. is consecutive from order_start(-m1).
        let f_row = &sig[order_start(b_in, -m1)..];
        let lowest = if half { 0 } else { -top };
        for m2 in lowest..=top {
            if half && m2 == 0 && m1 < 0 {
                continue;
            }
            let h_row = &pat[order_start(b_in, -m2)..];
            let (a1, a2) = (m1.unsigned_abs(), m2.unsigned_abs());
            let first = a1.max(a2);
            let l0 = first.max(from);
            if first > to {
                continue;
            }
            let sign = if (m1 + m2).rem_euclid(2) == 0 {
                1.0
            } else {
                -1.0
            };
            let base = block_start(b_out, m1, m2) - first;
            assert!(base + to < len);
            let value =
                |l: usize| wide(f_row[l - a1]) * wide(h_row[l - a2]).conj() * (sign * norms[l]);
            // Entry `base + l`, `l <= to`, is inside `out` (asserted above) and in the block
            // of `(m1, m2)`, which is this row's alone: no other task touches it.
            let at = |l: usize| dst.get().wrapping_add(base + l);
            if mode == Combine::Assign {
                for l in first..l0.min(to + 1) {
                    // SAFETY: `at` above.
                    unsafe { *at(l) = Complex::new(T::ZERO, T::ZERO) };
                }
                for l in l0..=to {
                    // SAFETY: `at` above.
                    unsafe { *at(l) = narrow(value(l)) };
                }
            } else {
                for l in l0..=to {
                    // SAFETY: `at` above.
                    unsafe { *at(l) = narrow(wide(*at(l)) + value(l)) };
                }
            }
        }
    };
    // On a worker pool (the correlation plan's), the orders are spread over its threads.
    if rayon::current_thread_index().is_some() {
        (-top..=top).into_par_iter().for_each(row);
    } else {
        (-top..=top).for_each(row);
    }
}

#[cfg(test)]
mod tests {
    use super::s2_real_symmetric;
    use crate::s2::s2_coef_index;
    use num_complex::Complex64;

    /// The exact real symmetry is recognised, `-0` counting as `0`, and one broken value
    /// (one ulp, a NaN, an imaginary part at `m = 0`) up to the degree limit is enough to
    /// refuse it; values above the limit are not looked at.
    #[test]
    fn real_symmetry_is_recognised_exactly() {
        let (b, lim) = (9, 6);
        let mut c = vec![Complex64::default(); b * b];
        for l in 0..b {
            c[s2_coef_index(b, l, 0)] = Complex64::new(0.3 * l as f64 - 1.0, -0.0);
            for m in 1..=l as isize {
                let v = Complex64::new((l as f64 + 0.5 * m as f64).sin(), (m as f64).cos());
                let s = if m % 2 == 0 { 1.0 } else { -1.0 };
                c[s2_coef_index(b, l, m)] = v;
                c[s2_coef_index(b, l, -m)] = v.conj() * s;
            }
        }
        assert!(s2_real_symmetric(&c, b, lim));
        let broken = |f: &dyn Fn(&mut [Complex64])| {
            let mut d = c.clone();
            f(&mut d);
            s2_real_symmetric(&d, b, lim)
        };
        let at = |l, m| s2_coef_index(b, l, m);
        let ulp = |x: f64| f64::from_bits(x.to_bits() + 1);
        assert!(!broken(&|d| d[at(4, -3)].re = ulp(d[at(4, -3)].re)));
        assert!(!broken(&|d| d[at(6, 2)].im = ulp(d[at(6, 2)].im)));
        assert!(!broken(&|d| d[at(2, 0)].im = 1e-300));
        assert!(!broken(&|d| {
            d[at(5, 1)] = Complex64::new(f64::NAN, 0.0);
            d[at(5, -1)] = Complex64::new(f64::NAN, 0.0);
        }));
        // Above the degree limit: not part of the check.
        assert!(broken(&|d| d[at(8, -3)].re += 1.0));
    }
}
