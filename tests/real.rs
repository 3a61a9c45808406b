//! The real-signal path (`forward_real`, `inverse_real`) against the reference data, the
//! complex path and the real symmetry.

mod common;

use common::*;
use so3fft::{coef_index, sample_index, Complex64, Plan, PlanOptions};

fn real_plan(b: usize) -> Plan {
    Plan::new(
        b,
        &PlanOptions {
            real: true,
            ..Default::default()
        },
    )
    .unwrap()
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
    let plan = Plan::new(4, &PlanOptions::default()).unwrap();
    let f = vec![0.0; n_samples(4)];
    let mut c = zeros(n_coeffs(4));
    assert!(plan.forward_real(&f, &mut c).is_err());
    assert!(c.iter().all(|z| *z == Complex64::new(0.0, 0.0)));
}
