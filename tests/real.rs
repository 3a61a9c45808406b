//! The real-signal path (`forward_real`, `inverse_real`) against the reference data, the
//! complex path and the real symmetry.

mod common;

use common::*;
use so3fft::{coef_index, sample_index, Complex64, Options, Plan};

fn real_plan(b: usize) -> Plan {
    Plan::new(b, &Options::default().with_real(true)).unwrap()
}

fn zeros(n: usize) -> Vec<Complex64> {
    vec![Complex64::new(0.0, 0.0); n]
}

/// transform_B8_real.txt: forward_real of the samples gives the coefficients and
/// inverse_real of the coefficients gives the samples (imaginary parts there are 0).
#[test]
fn real_reference_b8() {
    let r = parse_transform("transform_B8_real.txt");
    let b = r.b;
    let plan = real_plan(b);
    let mut f = vec![0.0; n_samples(b)];
    for &(k, j1, j2, v) in &r.samples {
        f[sample_index(b, j1, k, j2)] = v.re;
    }
    let mut c = zeros(n_coeffs(b));
    plan.forward_real(&f, &mut c).unwrap();
    let mut ef = 0.0f64;
    for &(l, m, mp, v) in &r.coefs {
        ef = ef.max((c[coef_index(b, l, m, mp)] - v).norm());
    }
    let mut cref = zeros(n_coeffs(b));
    for &(l, m, mp, v) in &r.coefs {
        cref[coef_index(b, l, m, mp)] = v;
    }
    let mut g = vec![0.0; n_samples(b)];
    plan.inverse_real(&cref, &mut g).unwrap();
    let mut ei = 0.0f64;
    for &(k, j1, j2, v) in &r.samples {
        ei = ei.max((g[sample_index(b, j1, k, j2)] - v.re).abs());
    }
    println!("B8 real reference: forward {ef:.2e}, inverse {ei:.2e}");
    assert!(ef <= 1e-13 && ei <= 1e-13);
}

/// On real data the real path gives what the complex path gives, for every bandwidth
/// from 1 to 24 and a few larger ones, in both directions; and round trips are exact.
#[test]
fn real_path_matches_complex_path() {
    for b in (1..=24).chain([31, 32, 48]) {
        let plan = real_plan(b);
        let mut rng = Rng::new(777 + b as u64);
        let c = random_real_signal_coefs(b, &mut rng);
        // inverse: real path vs real part of the complex path
        let mut fc = zeros(n_samples(b));
        plan.inverse(&c, &mut fc).unwrap();
        let mut fr = vec![0.0; n_samples(b)];
        plan.inverse_real(&c, &mut fr).unwrap();
        let scale = fc.iter().fold(1.0f64, |s, z| s.max(z.norm()));
        let ei = fr
            .iter()
            .zip(&fc)
            .fold(0.0f64, |s, (a, z)| s.max((a - z.re).abs()));
        // forward: real path vs complex path on the same real samples
        let freal: Vec<Complex64> = fr.iter().map(|&x| Complex64::new(x, 0.0)).collect();
        let mut cc = zeros(n_coeffs(b));
        plan.forward(&freal, &mut cc).unwrap();
        let mut cr = zeros(n_coeffs(b));
        plan.forward_real(&fr, &mut cr).unwrap();
        let (ef, _) = max_abs_diff(&cr, &cc);
        let (er, _) = max_abs_diff(&cr, &c);
        assert!(
            ei <= 1e-14 * scale && ef <= 1e-13 && er <= 1e-13,
            "B={b}: inverse {ei:.2e} (scale {scale:.1e}), forward {ef:.2e}, round trip {er:.2e}"
        );
    }
}

/// The real inverse reads only one order pair of each pair (M,M'), (-M,-M'): those with
/// M' > 0, or M' = 0 and M >= 0. NaN in all the others must not reach the samples.
#[test]
fn real_inverse_reads_only_representatives() {
    let b = 9;
    let plan = real_plan(b);
    let mut rng = Rng::new(99);
    let c = random_real_signal_coefs(b, &mut rng);
    let mut poisoned = c.clone();
    for l in 0..b {
        let li = l as isize;
        for m in -li..=li {
            for mp in -li..=li {
                if !(mp > 0 || (mp == 0 && m >= 0)) {
                    poisoned[coef_index(b, l, m, mp)] = Complex64::new(f64::NAN, f64::NAN);
                }
            }
        }
    }
    let (mut f1, mut f2) = (vec![0.0; n_samples(b)], vec![0.0; n_samples(b)]);
    plan.inverse_real(&c, &mut f1).unwrap();
    plan.inverse_real(&poisoned, &mut f2).unwrap();
    assert!(f1.iter().zip(&f2).all(|(a, b)| a == b));
}

/// A plan made without `real` refuses the real transforms.
#[test]
fn real_needs_the_option() {
    let plan = Plan::new(4, &Options::default()).unwrap();
    let f = vec![0.0; n_samples(4)];
    let mut c = zeros(n_coeffs(4));
    assert!(plan.forward_real(&f, &mut c).is_err());
    assert!(c.iter().all(|z| *z == Complex64::new(0.0, 0.0)));
}

/// A real plan's inverse into complex samples (the C API with `SO3FFT_REAL`, SOFT's flag 1)
/// spreads the reals in place over the sample array on the plan's threads. At odd B >= 41
/// the halving rounds meet an odd count, where an earlier split let one piece overwrite a
/// real another still had to read (one sample wrong in 3 of 5 runs at B = 41 on 2 threads).
/// Checked against the complex path's inverse of the same coefficients.
#[test]
fn real_inverse_into_complex_at_odd_b() {
    // The C API as a C program sees it (`include/so3fft.h`); it is not part of the Rust API.
    #[allow(non_camel_case_types)]
    type so3fft_complex = [f64; 2];
    type Plan = *mut std::ffi::c_void;
    const SO3FFT_BOTH: i32 = 3;
    const SO3FFT_REAL: u32 = 32;
    const SO3FFT_OK: i32 = 0;
    extern "C" {
        fn so3fft_plan_general(
            b: i32,
            direction: i32,
            input: *mut so3fft_complex,
            output: *mut so3fft_complex,
            flags: u32,
            nthreads: i32,
        ) -> Plan;
        fn so3fft_execute_inverse(
            p: Plan,
            input: *mut so3fft_complex,
            out: *mut so3fft_complex,
        ) -> i32;
        fn so3fft_destroy_plan(p: Plan);
    }
    for (b, threads) in [(41usize, 2), (43, 3)] {
        let mut rng = Rng::new(4100 + b as u64);
        let c = random_real_signal_coefs(b, &mut rng);
        let cp = c.as_ptr() as *mut so3fft_complex;
        let (ns, bi) = (n_samples(b), b as i32);
        let mut want = zeros(ns);
        let mut got = zeros(ns);
        // SAFETY: plans and arrays as the C API documents; sizes from the same B.
        unsafe {
            let plan = |flags| {
                let null = std::ptr::null_mut();
                so3fft_plan_general(bi, SO3FFT_BOTH, null, null, flags, threads)
            };
            let (pc, pr) = (plan(0), plan(SO3FFT_REAL));
            assert!(!pc.is_null() && !pr.is_null());
            let wp = want.as_mut_ptr() as *mut so3fft_complex;
            assert_eq!(so3fft_execute_inverse(pc, cp, wp), SO3FFT_OK);
            for _ in 0..3 {
                got.iter_mut()
                    .for_each(|z| *z = Complex64::new(f64::NAN, f64::NAN));
                let gp = got.as_mut_ptr() as *mut so3fft_complex;
                assert_eq!(so3fft_execute_inverse(pr, cp, gp), SO3FFT_OK);
                let scale = want.iter().fold(1.0f64, |s, z| s.max(z.norm()));
                let bad = got
                    .iter()
                    .zip(&want)
                    .filter(|(g, w)| !((g.re - w.re).abs() <= 1e-13 * scale && g.im == 0.0))
                    .count();
                assert_eq!(bad, 0, "B={b}, {threads} threads: {bad} samples differ");
            }
            so3fft_destroy_plan(pc);
            so3fft_destroy_plan(pr);
        }
    }
}
