//! The coefficients' side of the DWT stage: the kernels read and write degree-major rows
//! of `P` doubles (`(re, im)` of each slot side by side), the coefficient array holds one
//! contiguous run of degrees per order pair. These copies move one pair's run between the
//! two, with the pair's sign for even and odd degree offsets applied on the way.
//!
//! Coefficients and kernel rows may differ in precision (an f32 plan runs some clusters'
//! kernels in f64); the factors are applied in f64 and each value rounded once. A complex
//! double moves as one 16-byte vector (SSE2, part of x86-64).

use crate::numeric::Elem;
use crate::Real;
use num_complex::{Complex, Complex64};

/// The factor of degree offset `i < n` (`n = scales.len()`): `signs[i % 2] * scales[i]`,
/// the order pair's sign for even and odd offsets times the kernels' value scale (see
/// `RecTables::coeffs`).
#[derive(Clone, Copy)]
pub(crate) struct DegreeFactors<'a> {
    pub signs: [f64; 2],
    pub scales: &'a [f64],
}

/// `dst[i * p .. i * p + 2] = src[i] * f(i)` for `i < n` (`f`: the factors, `n` their
/// number).
///
/// # Safety
/// `src` valid for `n` reads, `dst` for writes at `i * p` and `i * p + 1`, `i < n`.
pub(crate) unsafe fn gather<T: Real, K: Elem>(
    dst: *mut K,
    src: *const Complex<T>,
    p: usize,
    f: DegreeFactors,
) {
    if T::BYTES == 8 && K::BYTES == 8 {
        // SAFETY: both types are f64 (the only 8-byte `Real` and `Elem`); the caller's
        // contract.
        unsafe { gather_f64(dst.cast::<f64>(), src.cast::<Complex64>(), p, f) };
        return;
    }
    for (i, &si) in f.scales.iter().enumerate() {
        let g = f.signs[i & 1] * si;
        // SAFETY: the caller's contract.
        unsafe {
            let z = *src.add(i);
            *dst.add(i * p) = K::from_f64(z.re.to_f64() * g);
            *dst.add(i * p + 1) = K::from_f64(z.im.to_f64() * g);
        }
    }
}

/// [`gather`] in f64.
///
/// # Safety
/// As for [`gather`].
unsafe fn gather_f64(dst: *mut f64, src: *const Complex64, p: usize, f: DegreeFactors) {
    let (sg, s) = (f.signs, f.scales);
    // SAFETY: the caller's contract (see `# Safety`): reads of `src` below `n`, writes at
    // `i * p` and `i * p + 1` of `dst` for `i < n`.
    unsafe {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::*;
            for (i, &si) in s.iter().enumerate() {
                let z = _mm_loadu_pd(src.add(i) as *const f64);
                _mm_storeu_pd(dst.add(i * p), _mm_mul_pd(z, _mm_set1_pd(sg[i & 1] * si)));
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        for (i, &si) in s.iter().enumerate() {
            let z = *src.add(i);
            let g = sg[i & 1] * si;
            *dst.add(i * p) = z.re * g;
            *dst.add(i * p + 1) = z.im * g;
        }
    }
}

/// `dst[i] = src[i * p .. i * p + 2] * f(i)` (or `+=` if `add`) for `i < n` (`f` as for
/// [`gather`]); with
/// `partner = Some((d2, ps))` also `d2[i] = ps * conj(dst[i])` (the real forward's partner
/// pair, from the value in a register: no second pass over the coefficients).
///
/// Plain stores: the coefficients are read back by the next group or stay in the
/// last-level cache.
///
/// # Safety
/// `dst` valid for `n` reads and writes (and `d2` for `n` writes), `src` for reads at
/// `i * p` and `i * p + 1`, `i < n`; no overlap.
pub(crate) unsafe fn scatter<T: Real, K: Elem>(
    dst: *mut Complex<T>,
    src: *const K,
    p: usize,
    f: DegreeFactors,
    add: bool,
    partner: Option<(*mut Complex<T>, f64)>,
) {
    if T::BYTES == 8 && K::BYTES == 8 {
        let partner = partner.map(|(d2, ps)| (d2.cast::<Complex64>(), ps));
        // SAFETY: both types are f64 (the only 8-byte `Real` and `Elem`); the caller's
        // contract.
        unsafe {
            scatter_f64(
                dst.cast::<Complex64>(),
                src.cast::<f64>(),
                p,
                f,
                add,
                partner,
            )
        };
        return;
    }
    let narrow = |z: Complex64| Complex::new(T::from_f64(z.re), T::from_f64(z.im));
    for (i, &si) in f.scales.iter().enumerate() {
        let g = f.signs[i & 1] * si;
        // SAFETY: the caller's contract.
        unsafe {
            let mut z =
                Complex64::new((*src.add(i * p)).to_f64(), (*src.add(i * p + 1)).to_f64()) * g;
            if add {
                let d = *dst.add(i);
                z += Complex64::new(d.re.to_f64(), d.im.to_f64());
            }
            let v = narrow(z);
            *dst.add(i) = v;
            if let Some((d2, ps)) = partner {
                *d2.add(i) = narrow(Complex64::new(v.re.to_f64(), v.im.to_f64()).conj() * ps);
            }
        }
    }
}

/// [`scatter`] in f64.
///
/// # Safety
/// As for [`scatter`].
unsafe fn scatter_f64(
    dst: *mut Complex64,
    src: *const f64,
    p: usize,
    f: DegreeFactors,
    add: bool,
    partner: Option<(*mut Complex64, f64)>,
) {
    let (sg, s) = (f.signs, f.scales);
    // SAFETY: the caller's contract (see `# Safety`): `n` values of `dst` (and `d2`), reads
    // at `i * p`, `i * p + 1` of `src`, no overlap.
    unsafe {
        #[cfg(target_arch = "x86_64")]
        {
            use std::arch::x86_64::*;
            let d = dst as *mut f64;
            let (d2, conj) = match partner {
                Some((d2, ps)) => (d2 as *mut f64, _mm_set_pd(-ps, ps)),
                None => (std::ptr::null_mut(), _mm_setzero_pd()),
            };
            for (i, &si) in s.iter().enumerate() {
                let g = _mm_set1_pd(sg[i & 1] * si);
                let mut z = _mm_mul_pd(_mm_loadu_pd(src.add(i * p)), g);
                if add {
                    z = _mm_add_pd(_mm_loadu_pd(d.add(2 * i)), z);
                }
                _mm_storeu_pd(d.add(2 * i), z);
                if !d2.is_null() {
                    _mm_storeu_pd(d2.add(2 * i), _mm_mul_pd(z, conj));
                }
            }
        }
        #[cfg(not(target_arch = "x86_64"))]
        for (i, &si) in s.iter().enumerate() {
            let g = sg[i & 1] * si;
            let mut z = Complex64::new(*src.add(i * p) * g, *src.add(i * p + 1) * g);
            if add {
                z += *dst.add(i);
            }
            *dst.add(i) = z;
            if let Some((d2, ps)) = partner {
                *d2.add(i) = z.conj() * ps;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Both copies against the definition, with a row length wider than the data.
    #[test]
    fn copies_follow_the_definition() {
        let (p, n) = (16, 13);
        let z: Vec<Complex64> = (0..n)
            .map(|i| Complex64::new(i as f64 + 0.5, -(i as f64) * 0.25))
            .collect();
        let sg = [-1.5, 2.0];
        // Scales that are powers of two keep every product exact.
        let sc: Vec<f64> = (0..n).map(|i| [1.0, 0.5, 4.0][i % 3]).collect();
        let mut rows = vec![7.0; n * p];
        // SAFETY: `n - 1` values of `z`; rows `i < n - 1` of `p` doubles from offset 4
        // reach at most double `(n - 2) p + 5 < n p`.
        unsafe {
            gather(
                rows[4..].as_mut_ptr(),
                z.as_ptr(),
                p,
                DegreeFactors {
                    signs: sg,
                    scales: &sc[..n - 1],
                },
            )
        };
        for i in 0..n {
            for q in 0..p {
                let want = match q {
                    4 if i < n - 1 => z[i].re * sg[i % 2] * sc[i],
                    5 if i < n - 1 => z[i].im * sg[i % 2] * sc[i],
                    _ => 7.0,
                };
                assert_eq!(rows[i * p + q], want, "i={i} q={q}");
            }
        }
        let factors = DegreeFactors {
            signs: sg,
            scales: &sc[..n - 1],
        };
        let mut back = vec![Complex64::new(1.0, 1.0); n];
        // SAFETY: `n - 1` values of `back` (`n` long); reads of `rows` as above.
        let back_from_rows = |back: &mut [Complex64], add: bool| unsafe {
            scatter(back.as_mut_ptr(), rows[4..].as_ptr(), p, factors, add, None)
        };
        back_from_rows(&mut back, false);
        for i in 0..n - 1 {
            // Signs and scales squared.
            let s2 = (sg[i % 2] * sc[i]).powi(2);
            assert_eq!(back[i], z[i] * s2);
        }
        assert_eq!(back[n - 1], Complex64::new(1.0, 1.0));
        back_from_rows(&mut back, true);
        for i in 0..n - 1 {
            let s2 = (sg[i % 2] * sc[i]).powi(2);
            assert_eq!(back[i], z[i] * (2.0 * s2));
        }
        // Assigned or added, with partners, at both alignments of 16 bytes (offsets of 0
        // and 1 doubles); the value after `n - 1` is untouched.
        for add in [false, true] {
            for off in [0usize, 1] {
                let mut a = vec![3.0f64; 2 * n + 2];
                let mut b = vec![5.0f64; 2 * n + 2];
                // SAFETY: `off <= 1` of `2n + 2` doubles.
                let (pa, pb) = unsafe {
                    (
                        a.as_mut_ptr().add(off) as *mut Complex64,
                        b.as_mut_ptr().add(off) as *mut Complex64,
                    )
                };
                // SAFETY: `n - 1` complex values from `pa` and `pb` fit in the `2n + 1`
                // doubles after `off`; reads of `rows` as above; `a`, `b`, `rows` distinct.
                unsafe { scatter(pa, rows[4..].as_ptr(), p, factors, add, Some((pb, -2.0))) };
                for i in 0..n {
                    // SAFETY: `i < n`: inside the `2n + 1` doubles after `off`.
                    let (x, y) = unsafe { (*pa.add(i), *pb.add(i)) };
                    if i == n - 1 {
                        assert_eq!((x, y), (Complex64::new(3.0, 3.0), Complex64::new(5.0, 5.0)));
                        continue;
                    }
                    let mut want = z[i] * (sg[i % 2] * sc[i]).powi(2);
                    if add {
                        want += Complex64::new(3.0, 3.0);
                    }
                    assert_eq!(x, want, "add={add} off={off} i={i}");
                    assert_eq!(y, want.conj() * -2.0, "add={add} off={off} i={i}");
                }
            }
        }
    }
}
