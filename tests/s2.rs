//! S^2 transforms against the reference data (`tests/data/s2/`, mpmath), direct summation
//! with independently computed `Y_l^m`, and exact properties (round trip, real against
//! complex, orthonormality on the grid).

mod common;

use common::Rng;
use num_complex::Complex64;
use so3fft::s2::{s2_coef_index, S2Limits, S2Plan};
use so3fft::Options;
use std::f64::consts::PI;

/// Samples and coefficients of a reference file, each coefficient's `(l, m)` checked
/// against its index.
fn samples_and_coefs(name: &str, b: usize) -> (Vec<Complex64>, Vec<Complex64>) {
    for row in &common::read_s2_reference(name)["coefs"] {
        let (l, m) = (row[1] as usize, row[2] as isize);
        assert_eq!(s2_coef_index(b, l, m), row[0] as usize);
    }
    common::s2_samples_and_coefs(name, b)
}

fn max_abs(v: &[Complex64]) -> f64 {
    v.iter().map(|z| z.norm()).fold(0.0, f64::max)
}

fn max_diff(a: &[Complex64], b: &[Complex64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).norm())
        .fold(0.0, f64::max)
}

fn plan(b: usize, threads: usize) -> S2Plan {
    S2Plan::new(b, &Options::default().with_threads(threads)).unwrap()
}

#[test]
fn forward_matches_reference() {
    for (name, b) in [("fst_B4_complex.txt", 4), ("fst_B8_complex.txt", 8)] {
        let (samples, want) = samples_and_coefs(name, b);
        let mut got = vec![Complex64::default(); b * b];
        plan(b, 2).forward(&samples, &mut got).unwrap();
        let err = max_diff(&got, &want);
        assert!(err < 1e-13, "{name}: max error {err:e}");
    }
}

#[test]
fn inverse_matches_reference() {
    for (name, b) in [("inv_B4_complex.txt", 4), ("inv_B8_complex.txt", 8)] {
        let (want, coefs) = samples_and_coefs(name, b);
        let mut got = vec![Complex64::default(); 4 * b * b];
        plan(b, 2).inverse(&coefs, &mut got).unwrap();
        let err = max_diff(&got, &want) / max_abs(&want);
        assert!(err < 1e-13, "{name}: relative error {err:e}");
    }
}

#[test]
fn real_transforms_match_reference() {
    let b = 8;
    let (samples, want) = samples_and_coefs("fst_B8_real.txt", b);
    let real: Vec<f64> = samples.iter().map(|z| z.re).collect();
    let p = plan(b, 1);
    let mut got = vec![Complex64::default(); b * b];
    p.forward_real(&real, &mut got).unwrap();
    let err = max_diff(&got, &want);
    assert!(err < 1e-13, "forward_real: max error {err:e}");

    let (want, coefs) = samples_and_coefs("inv_B8_real.txt", b);
    let mut got = vec![0.0; 4 * b * b];
    p.inverse_real(&coefs, &mut got).unwrap();
    let err = got
        .iter()
        .zip(&want)
        .map(|(x, y)| (x - y.re).abs())
        .fold(0.0, f64::max)
        / max_abs(&want);
    assert!(err < 1e-13, "inverse_real: relative error {err:e}");
}

/// `Y_l^m(theta, phi)` from the explicit sum for the associated Legendre function
/// (`common::wigner_d_explicit`, with `Pt_l^m = dt^l_{m,0}`, checked against SciPy's
/// convention by the reference data above).
fn y_lm(l: usize, m: isize, theta: f64, phi: f64) -> Complex64 {
    let pt = common::dt_explicit(l, m, 0, theta);
    Complex64::from_polar(pt / (2.0 * PI).sqrt(), m as f64 * phi)
}

#[test]
fn direct_summation_at_small_bandwidths() {
    let mut rng = Rng::new(21);
    for b in [1usize, 2, 3, 5, 6] {
        let n = 2 * b;
        let coefs = rng.complex_vec(b * b);
        let mut want = vec![Complex64::default(); n * n];
        for j in 0..n {
            let theta = PI * (2 * j + 1) as f64 / (4 * b) as f64;
            for k in 0..n {
                let phi = PI * k as f64 / b as f64;
                for l in 0..b {
                    for m in -(l as isize)..=l as isize {
                        want[j * n + k] += coefs[s2_coef_index(b, l, m)] * y_lm(l, m, theta, phi);
                    }
                }
            }
        }
        let p = plan(b, 2);
        let mut got = vec![Complex64::default(); n * n];
        p.inverse(&coefs, &mut got).unwrap();
        let err = max_diff(&got, &want) / max_abs(&want);
        assert!(err < 1e-13, "B = {b}: inverse error {err:e}");
        let mut back = vec![Complex64::default(); b * b];
        p.forward(&got, &mut back).unwrap();
        let err = max_diff(&back, &coefs);
        assert!(err < 1e-13, "B = {b}: round trip error {err:e}");
    }
}

fn relative_l2(a: &[Complex64], b: &[Complex64]) -> f64 {
    let num: f64 = a.iter().zip(b).map(|(x, y)| (x - y).norm_sqr()).sum();
    let den: f64 = b.iter().map(|y| y.norm_sqr()).sum();
    (num / den).sqrt()
}

#[test]
fn round_trips_complex_and_real() {
    let mut rng = Rng::new(5);
    for b in [7usize, 16, 33, 64, 128] {
        let p = plan(b, 2);
        let coefs = rng.complex_vec(b * b);
        let mut samples = vec![Complex64::default(); 4 * b * b];
        let mut back = vec![Complex64::default(); b * b];
        p.inverse(&coefs, &mut samples).unwrap();
        p.forward(&samples, &mut back).unwrap();
        let err = relative_l2(&back, &coefs);
        assert!(err < 1e-14, "B = {b}: complex round trip {err:e}");

        // Coefficients of a real function: the real inverse equals the complex one, and
        // the real forward brings them back.
        let mut hermitian = coefs.clone();
        for l in 0..b {
            hermitian[s2_coef_index(b, l, 0)].im = 0.0;
            for m in 1..=l as isize {
                let c = hermitian[s2_coef_index(b, l, m)];
                hermitian[s2_coef_index(b, l, -m)] = if m % 2 == 0 { c.conj() } else { -c.conj() };
            }
        }
        let mut complex = vec![Complex64::default(); 4 * b * b];
        p.inverse(&hermitian, &mut complex).unwrap();
        let mut real = vec![0.0; 4 * b * b];
        p.inverse_real(&hermitian, &mut real).unwrap();
        let scale = max_abs(&complex);
        for (z, x) in complex.iter().zip(&real) {
            assert!((z.re - x).abs() < 1e-14 * scale && z.im.abs() < 1e-14 * scale);
        }
        p.forward_real(&real, &mut back).unwrap();
        let err = relative_l2(&back, &hermitian);
        assert!(err < 1e-14, "B = {b}: real round trip {err:e}");
    }
}

/// The inverse of a single coefficient is `Y_l^m` on the grid; the forward of those samples
/// gives back exactly that coefficient (orthonormality of the sampled harmonics under the
/// quadrature), for sampled degrees and orders up to B = 512.
#[test]
fn sampled_harmonics_are_orthonormal() {
    for b in [64usize, 512] {
        let p = plan(b, 2);
        let (n, nc) = (2 * b, b * b);
        for (l, m) in [
            (0usize, 0isize),
            (b - 1, 0),
            (b - 1, -(b as isize - 1)),
            (b / 2, 3),
            (b - 1, b as isize / 3),
        ] {
            let mut coefs = vec![Complex64::default(); nc];
            coefs[s2_coef_index(b, l, m)] = Complex64::new(1.0, 0.0);
            let mut samples = vec![Complex64::default(); n * n];
            p.inverse(&coefs, &mut samples).unwrap();
            let mut back = vec![Complex64::default(); nc];
            p.forward(&samples, &mut back).unwrap();
            let err = max_diff(&back, &coefs);
            assert!(err < 1e-12, "B = {b}, (l, m) = ({l}, {m}): error {err:e}");
        }
    }
}

#[test]
fn bad_arguments_are_errors() {
    assert!(S2Plan::<f64>::new(0, &Options::default()).is_err());
    assert!(S2Plan::<f64>::new(1 << 20, &Options::default()).is_err());
    let p = plan(4, 1);
    let mut c = vec![Complex64::default(); 16];
    assert!(p.forward(&[Complex64::default(); 63], &mut c).is_err());
    let mut s = vec![Complex64::default(); 64];
    assert!(p.inverse(&c[..15], &mut s).is_err());
}

/// `howmany` fields: bitwise the same as one field at a time (the real transforms pair the
/// fields in one kernel call; the columns of the two fields never mix).
#[test]
fn many_fields_equal_single_ones() {
    let mut rng = Rng::new(9);
    for (b, howmany) in [(9usize, 3usize), (32, 2), (32, 5)] {
        let p = plan(b, 2);
        let (ns, nc) = (4 * b * b, b * b);
        let real: Vec<f64> = (0..howmany * ns).map(|_| rng.sym()).collect();
        let mut many = vec![Complex64::default(); howmany * nc];
        p.forward_real_many(&real, &mut many, howmany).unwrap();
        let mut back = vec![0.0; howmany * ns];
        p.inverse_real_many(&many, &mut back, howmany).unwrap();
        let samples = rng.complex_vec(howmany * ns);
        let mut many_cx = vec![Complex64::default(); howmany * nc];
        p.forward_many(&samples, &mut many_cx, howmany).unwrap();
        let mut back_cx = vec![Complex64::default(); howmany * ns];
        p.inverse_many(&many_cx, &mut back_cx, howmany).unwrap();
        for f in 0..howmany {
            let mut one = vec![Complex64::default(); nc];
            p.forward_real(&real[f * ns..][..ns], &mut one).unwrap();
            assert!(
                one == many[f * nc..][..nc],
                "B = {b}: real forward field {f}"
            );
            let mut one_back = vec![0.0; ns];
            p.inverse_real(&one, &mut one_back).unwrap();
            assert!(
                one_back == back[f * ns..][..ns],
                "B = {b}: real inverse field {f}"
            );
            p.forward(&samples[f * ns..][..ns], &mut one).unwrap();
            assert!(one == many_cx[f * nc..][..nc], "B = {b}: forward field {f}");
            let mut one_cx = vec![Complex64::default(); ns];
            p.inverse(&one, &mut one_cx).unwrap();
            assert!(
                one_cx == back_cx[f * ns..][..ns],
                "B = {b}: inverse field {f}"
            );
        }
    }
    let p = plan(4, 1);
    let mut c = vec![Complex64::default(); 32];
    assert!(p.forward_real_many(&[0.0; 64], &mut c, 2).is_err());
    assert!(p.forward_real_many(&[], &mut [], 0).is_err());
}

/// B = 2048 in full (4096 x 4096 samples): a real round trip within 1e-12 (relative L2)
/// and sampled harmonics that come back exactly.
#[test]
fn bandwidth_2048() {
    let b = 2048;
    let p = plan(b, 0);
    let (ns, nc) = (4 * b * b, b * b);
    let mut rng = Rng::new(2048);
    let mut coefs = rng.complex_vec(nc);
    for l in 0..b {
        coefs[s2_coef_index(b, l, 0)].im = 0.0;
        for m in 1..=l as isize {
            let c = coefs[s2_coef_index(b, l, m)];
            coefs[s2_coef_index(b, l, -m)] = if m % 2 == 0 { c.conj() } else { -c.conj() };
        }
    }
    let mut samples = vec![0.0; ns];
    p.inverse_real(&coefs, &mut samples).unwrap();
    let mut back = vec![Complex64::default(); nc];
    p.forward_real(&samples, &mut back).unwrap();
    let err = relative_l2(&back, &coefs);
    assert!(err < 1e-12, "B = 2048: real round trip {err:e}");
    drop(samples);
    let mut samples = vec![Complex64::default(); ns];
    for (l, m) in [(b - 1, 0isize), (b - 1, -(b as isize - 1)), (1500, 700)] {
        let mut single = vec![Complex64::default(); nc];
        single[s2_coef_index(b, l, m)] = Complex64::new(1.0, 0.0);
        p.inverse(&single, &mut samples).unwrap();
        p.forward(&samples, &mut back).unwrap();
        let err = max_diff(&back, &single);
        assert!(err < 1e-11, "B = 2048, (l, m) = ({l}, {m}): error {err:e}");
    }
}

/// Degree and order limits: the limited transforms equal the full ones on coefficients with
/// the absent degrees and orders zeroed (the forward writes those as 0), complex and real.
#[test]
fn degree_and_order_limits_equal_zeroed_full_transforms() {
    let mut rng = Rng::new(44);
    for (b, lim, mmax) in [(16usize, 9usize, 16usize), (16, 16, 3), (21, 12, 5)] {
        let full = plan(b, 2);
        let limited = S2Plan::with_limits(
            b,
            S2Limits {
                degree_limit: Some(lim),
                order_limit: Some(mmax),
            },
            &Options::default().with_threads(2),
        )
        .unwrap();
        let keep = |l: usize, m: isize| l < lim && m.unsigned_abs() <= mmax;
        let mut coefs = rng.complex_vec(b * b);
        let mut zeroed = coefs.clone();
        for l in 0..b {
            for m in -(l as isize)..=l as isize {
                if !keep(l, m) {
                    zeroed[s2_coef_index(b, l, m)] = Complex64::default();
                }
            }
        }
        let n = 4 * b * b;
        let (mut a, mut c) = (vec![Complex64::default(); n], vec![Complex64::default(); n]);
        limited.inverse(&coefs, &mut a).unwrap();
        full.inverse(&zeroed, &mut c).unwrap();
        let err = max_diff(&a, &c) / max_abs(&c);
        assert!(err < 1e-14, "B {b} L {lim} M {mmax}: inverse {err:e}");
        let (mut fa, mut fc) = (
            vec![Complex64::default(); b * b],
            vec![Complex64::default(); b * b],
        );
        let samples = rng.complex_vec(n);
        limited.forward(&samples, &mut fa).unwrap();
        full.forward(&samples, &mut fc).unwrap();
        for l in 0..b {
            for m in -(l as isize)..=l as isize {
                let i = s2_coef_index(b, l, m);
                if keep(l, m) {
                    assert!((fa[i] - fc[i]).norm() < 1e-13, "B {b}: forward ({l}, {m})");
                } else {
                    assert_eq!(fa[i], Complex64::default());
                }
            }
        }
        // Real: the round trip of a band- and order-limited real function.
        for l in 0..b {
            zeroed[s2_coef_index(b, l, 0)].im = 0.0;
            for m in 1..=l as isize {
                let v = zeroed[s2_coef_index(b, l, m)];
                zeroed[s2_coef_index(b, l, -m)] = if m % 2 == 0 { v.conj() } else { -v.conj() };
            }
        }
        let mut real = vec![0.0; n];
        limited.inverse_real(&zeroed, &mut real).unwrap();
        limited.forward_real(&real, &mut coefs).unwrap();
        assert!(
            relative_l2(&coefs, &zeroed) < 1e-14,
            "B {b}: limited real round trip"
        );
    }
    let bad = |d, o| {
        S2Plan::<f64>::with_limits(
            8,
            S2Limits {
                degree_limit: d,
                order_limit: o,
            },
            &Options::default(),
        )
    };
    assert!(bad(Some(0), None).is_err());
    assert!(bad(Some(9), None).is_err());
    assert!(bad(None, Some(0)).is_ok());
}

/// Arrays 8 bytes off FFTW's 16-byte alignment (the transforms then go through the plan's
/// scratch instead of running the ring DFTs in the caller's arrays) give the same values,
/// bit for bit, as aligned ones, and the inputs are left as they were.
#[test]
fn arrays_off_fftw_alignment_give_the_same_values() {
    let mut rng = Rng::new(21);
    let b = 24;
    let p = plan(b, 2);
    let (ns, nc) = (4 * b * b, b * b);
    // `n` complex values 8 bytes off a 16-byte boundary (Complex64 needs 8), in `store`.
    fn shifted(store: &mut Vec<f64>, n: usize) -> &mut [Complex64] {
        store.clear();
        store.resize(2 * n + 2, 0.0);
        let off = if (store.as_ptr() as usize).is_multiple_of(16) {
            1
        } else {
            0
        };
        // SAFETY: 2n doubles from `off` are inside `store`; Complex64 is two f64 (repr C),
        // alignment 8, which every f64 address has.
        unsafe { std::slice::from_raw_parts_mut(store.as_mut_ptr().add(off).cast(), n) }
    }
    let samples = rng.complex_vec(ns);
    let mut coefs = vec![Complex64::default(); nc];
    p.forward(&samples, &mut coefs).unwrap();
    let mut back = vec![Complex64::default(); ns];
    p.inverse(&coefs, &mut back).unwrap();
    // The references take the direct path (glibc's allocations are 16-byte aligned).
    for a in [samples.as_ptr(), coefs.as_ptr(), back.as_ptr()] {
        assert!((a as usize).is_multiple_of(16));
    }
    let (mut s1, mut s2) = (vec![], vec![]);
    let odd_samples = shifted(&mut s1, ns);
    odd_samples.copy_from_slice(&samples);
    let odd_coefs = shifted(&mut s2, nc);
    p.forward(odd_samples, odd_coefs).unwrap();
    assert!(odd_coefs == &coefs[..], "complex forward");
    assert!(odd_samples == &samples[..], "complex forward input");
    let keep = odd_coefs.to_vec();
    p.inverse(odd_coefs, odd_samples).unwrap();
    assert!(odd_samples == &back[..], "complex inverse");
    assert!(odd_coefs == &keep[..], "complex inverse input");

    let real: Vec<f64> = (0..ns).map(|_| rng.sym()).collect();
    let mut rc = vec![Complex64::default(); nc];
    p.forward_real(&real, &mut rc).unwrap();
    let mut rback = vec![0.0; ns];
    p.inverse_real(&rc, &mut rback).unwrap();
    assert!((real.as_ptr() as usize).is_multiple_of(16));
    assert!((rback.as_ptr() as usize).is_multiple_of(16));
    let mut store = vec![0.0; ns + 2];
    let off = if (store.as_ptr() as usize).is_multiple_of(16) {
        1
    } else {
        0
    };
    let odd_real = &mut store[off..off + ns];
    odd_real.copy_from_slice(&real);
    let mut rc2 = vec![Complex64::default(); nc];
    p.forward_real(odd_real, &mut rc2).unwrap();
    assert!(rc2 == rc, "real forward");
    assert!(odd_real == &real[..], "real forward input");
    p.inverse_real(&rc, odd_real).unwrap();
    assert!(odd_real == &rback[..], "real inverse");
}

/// Every instruction set this CPU has gives the same transforms to rounding: plans forced
/// to the scalar, AVX2 and AVX-512 kernels against each other, complex and real, at
/// bandwidths whose ring counts leave vectors and kernel chains partly unused.
#[test]
fn instruction_sets_agree() {
    use so3fft::Isa;
    let mut rng = Rng::new(33);
    for b in [1usize, 3, 5, 13, 33, 130] {
        let (ns, nc) = (4 * b * b, b * b);
        let samples = rng.complex_vec(ns);
        let real: Vec<f64> = (0..ns).map(|_| rng.sym()).collect();
        let mut results: Vec<(Isa, [Vec<Complex64>; 3], Vec<f64>)> = Vec::new();
        for isa in [Isa::Scalar, Isa::Avx2, Isa::Avx512] {
            if !isa.is_supported() {
                continue;
            }
            let p =
                S2Plan::new(b, &Options::default().with_threads(2).with_isa(Some(isa))).unwrap();
            let mut fwd = vec![Complex64::default(); nc];
            p.forward(&samples, &mut fwd).unwrap();
            let mut inv = vec![Complex64::default(); ns];
            p.inverse(&fwd, &mut inv).unwrap();
            let mut rfwd = vec![Complex64::default(); nc];
            p.forward_real(&real, &mut rfwd).unwrap();
            let mut rinv = vec![0.0; ns];
            p.inverse_real(&rfwd, &mut rinv).unwrap();
            results.push((isa, [fwd, inv, rfwd], rinv));
        }
        let (first, rest) = results.split_first().unwrap();
        for (isa, arrays, rinv) in rest {
            for (k, (a, r)) in arrays.iter().zip(&first.1).enumerate() {
                let err = max_diff(a, r);
                assert!(
                    err <= 1e-13 * max_abs(r).max(1.0),
                    "B = {b}: {isa:?} against {:?}, array {k}: {err:e}",
                    first.0
                );
            }
            let err = rinv
                .iter()
                .zip(&first.2)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max);
            assert!(err <= 1e-13, "B = {b}: {isa:?} real inverse: {err:e}");
        }
    }
}
