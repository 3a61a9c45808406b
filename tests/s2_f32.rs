//! S^2 transforms in single precision: against the reference data (`tests/data/s2/`),
//! against the double-precision plan on the same data, and round trips.

mod common;

use common::{narrow, relative_l2, widen, Rng};
use num_complex::{Complex32, Complex64};
use so3fft::s2::{s2_coef_index, S2Plan};
use so3fft::{Isa, Options};

fn plan32(b: usize, isa: Option<Isa>) -> S2Plan<f32> {
    let mut options = Options::default().with_threads(2);
    options.isa = isa;
    S2Plan::<f32>::new(b, &options).unwrap()
}

/// Coefficients of a real function: `fhat(l, -m) = (-1)^m conj(fhat(l, m))`.
fn hermitian(mut c: Vec<Complex64>, b: usize) -> Vec<Complex64> {
    for l in 0..b {
        c[s2_coef_index(b, l, 0)].im = 0.0;
        for m in 1..=l as isize {
            let z = c[s2_coef_index(b, l, m)];
            c[s2_coef_index(b, l, -m)] = if m % 2 == 0 { z.conj() } else { -z.conj() };
        }
    }
    c
}

/// The reference transforms (mpmath) at B = 8, to single-precision accuracy.
#[test]
fn float_transforms_match_reference() {
    let b = 8;
    let p = plan32(b, None);
    let (samples, want) = common::s2_samples_and_coefs("fst_B8_complex.txt", b);
    let mut got = vec![Complex32::default(); b * b];
    p.forward(&narrow(&samples), &mut got).unwrap();
    let err = relative_l2(&widen(&got), &want);
    assert!(err < 1e-6, "forward against the reference: {err:e}");
    let (want, coefs) = common::s2_samples_and_coefs("inv_B8_complex.txt", b);
    let mut back = vec![Complex32::default(); 4 * b * b];
    p.inverse(&narrow(&coefs), &mut back).unwrap();
    let err = relative_l2(&widen(&back), &want);
    assert!(err < 1e-6, "inverse against the reference: {err:e}");
}

/// The float plan against the double plan on the same (float) data, and float round trips,
/// complex and real, every instruction set: relative L2 errors within 1e-5 up to B = 256.
#[test]
fn float_plan_matches_double_plan() {
    let mut rng = Rng::new(11);
    for b in [5usize, 16, 64, 256] {
        let p64 = S2Plan::<f64>::new(b, &Options::default().with_threads(2)).unwrap();
        let coefs = widen(&narrow(&rng.complex_vec(b * b)));
        let mut s64 = vec![Complex64::default(); 4 * b * b];
        p64.inverse(&coefs, &mut s64).unwrap();
        let real_coefs = hermitian(coefs.clone(), b);
        let mut r64 = vec![0.0f64; 4 * b * b];
        p64.inverse_real(&real_coefs, &mut r64).unwrap();
        for isa in [Isa::Scalar, Isa::Avx2, Isa::Avx512] {
            if !isa.is_supported() {
                continue;
            }
            let p = plan32(b, Some(isa));
            let mut s = vec![Complex32::default(); 4 * b * b];
            p.inverse(&narrow(&coefs), &mut s).unwrap();
            let e_inv = relative_l2(&widen(&s), &s64);
            let mut back = vec![Complex32::default(); b * b];
            p.forward(&s, &mut back).unwrap();
            let e_trip = relative_l2(&widen(&back), &coefs);
            // Real fields.
            let mut r = vec![0.0f32; 4 * b * b];
            p.inverse_real(&narrow(&real_coefs), &mut r).unwrap();
            let num: f64 = r
                .iter()
                .zip(&r64)
                .map(|(x, y)| (*x as f64 - y).powi(2))
                .sum();
            let den: f64 = r64.iter().map(|y| y * y).sum();
            let e_real = (num / den).sqrt();
            p.forward_real(&r, &mut back).unwrap();
            let e_real_trip = relative_l2(&widen(&back), &real_coefs);
            for (what, e) in [
                ("inverse", e_inv),
                ("round trip", e_trip),
                ("real inverse", e_real),
                ("real round trip", e_real_trip),
            ] {
                assert!(e < 1e-5, "B = {b} {isa:?}: {what} {e:e}");
            }
        }
    }
}

/// Bad arguments give the double plan's errors.
#[test]
fn float_bad_arguments_are_errors() {
    assert!(S2Plan::<f32>::new(0, &Options::default()).is_err());
    let p = plan32(8, None);
    let mut out = vec![Complex32::default(); 63];
    assert!(p.forward(&[Complex32::default(); 256], &mut out).is_err());
}
