//! Plan::inverse / Plan::forward against naive direct summation of the defining formulas
//! (docs/conventions.md, forward and inverse transforms) using an independent Wigner-d (explicit factorial sum, tests/common).

mod common;

use common::*;
use so3fft::{Complex64, Options, Plan};
use std::f64::consts::{PI, SQRT_2};

const TOL: f64 = 1e-12;
const BMAX: usize = 8;

// ---- sanity of the independent helpers themselves ---------------------------------------------

#[test]
fn independent_wigner_closed_forms() {
    let mut maxerr = 0.0f64;
    for i in 0..=40 {
        let b = PI * i as f64 / 40.0;
        let (c, s) = (b.cos(), b.sin());
        let cases = [
            (1, 1, 0, -s / SQRT_2),
            (1, 0, 1, s / SQRT_2),
            (1, 0, 0, c),
            (1, 1, 1, (1.0 + c) / 2.0),
            (1, 1, -1, (1.0 - c) / 2.0),
            (1, -1, -1, (1.0 + c) / 2.0),
            (2, 0, 0, (3.0 * c * c - 1.0) / 2.0),
            (2, 2, 2, ((1.0 + c) / 2.0).powi(2)),
            (2, 1, 0, -(1.5f64).sqrt() * s * c),
            (0, 0, 0, 1.0),
        ];
        for &(l, m, mp, want) in &cases {
            let got = wigner_d_explicit(l, m, mp, b);
            let e = (got - want).abs();
            maxerr = maxerr.max(e);
            assert!(
                e <= 2e-15,
                "d^{l}_{{{m},{mp}}}({b}) = {got}, closed form {want}"
            );
        }
    }
    println!("explicit Wigner sum vs closed forms: max err {maxerr:.2e}");
}

#[test]
fn independent_wigner_vs_reference_csv_and_unitarity() {
    // against the mpmath reference for l <= 6
    let mut maxerr = 0.0f64;
    let mut n = 0;
    for r in parse_wigner_csv().iter().filter(|r| r.l <= 6) {
        let e = (wigner_d_explicit(r.l, r.m, r.mp, r.beta) - r.d).abs();
        maxerr = maxerr.max(e);
        n += 1;
        assert!(
            e <= 1e-14,
            "explicit sum l={} M={} Mp={} beta={}: err {e:e}",
            r.l,
            r.m,
            r.mp,
            r.beta
        );
    }
    assert!(n > 1000);
    println!("explicit Wigner sum vs reference csv (l <= 6, {n} rows): max err {maxerr:.2e}");
    // unitarity: sum_{M'} d^l_{M,M'}(b)^2 = 1, up to l = 9
    for l in 0..=9usize {
        let li = l as isize;
        for &b in &[0.2, 1.1, 2.5] {
            for m in -li..=li {
                let s: f64 = (-li..=li)
                    .map(|mp| wigner_d_explicit(l, m, mp, b).powi(2))
                    .sum();
                assert!((s - 1.0).abs() < 1e-13, "unitarity l={l} m={m} b={b}: {s}");
            }
        }
    }
}

#[test]
fn weights_formula_and_library_weights() {
    for b in [1usize, 2, 3, 4, 7, 8, 16, 33, 64] {
        let w = weights_formula(b);
        assert_eq!(w.len(), 2 * b);
        let sum: f64 = w.iter().sum();
        // sum_k w_B(k) = int_0^pi sin(beta) dbeta = 2
        assert!((sum - 2.0).abs() < 1e-13, "B={b}: sum of weights {sum}");
        let lw = so3fft::weights(b);
        assert_eq!(lw.len(), 2 * b, "so3fft::weights({b}) length");
        let e = w
            .iter()
            .zip(lw.iter())
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
        // each weight is a sum of B terms bounded by 1, times 2/B: error ~ a few eps
        assert!(
            e <= 1e-14,
            "B={b}: so3fft::weights differs from the formula of docs/conventions.md by {e:e}"
        );
    }
}

#[test]
fn direct_sum_self_consistency_b3() {
    // the two naive sums must invert each other on band-limited data (checks the helpers,
    // including the weights and the layout, before they are used as the truth)
    let b = 3;
    let mut rng = Rng::new(77);
    let c = rng.complex_vec(n_coeffs(b));
    let f = direct_inverse(b, &c);
    let c2 = direct_forward(b, &f);
    let (e, _) = max_abs_diff(&c, &c2);
    assert!(e < 1e-13, "naive forward(naive inverse) differs by {e:e}");
}

// ---- the library against direct sums ----------------------------------------------------------

#[test]
fn inverse_vs_direct_sum() {
    let mut fails = Vec::new();
    for b in 1..=BMAX {
        let t0 = std::time::Instant::now();
        let mut rng = Rng::new(1000 + b as u64);
        let coefs = rng.complex_vec(n_coeffs(b));
        let want = direct_inverse(b, &coefs);
        let tdirect = t0.elapsed().as_secs_f64();
        let plan = Plan::new(b, &Options::default()).expect("Plan::new");
        let mut got = vec![Complex64::new(0.0, 0.0); n_samples(b)];
        plan.inverse(&coefs, &mut got).expect("inverse");
        let (e, i) = max_abs_diff(&got, &want);
        println!("B={b}: inverse vs direct sum max abs err {e:.3e} (|f|max {:.2}, direct sum {tdirect:.2}s)", max_abs(&want));
        if e.is_nan() || e > TOL {
            fails.push(format!(
                "B={b}: inverse err {e:.3e} at sample {i}: got {} want {}",
                got[i], want[i]
            ));
        }
    }
    assert!(fails.is_empty(), "{}", fails.join("\n"));
}

#[test]
fn forward_vs_direct_quadrature() {
    let mut fails = Vec::new();
    for b in 1..=BMAX {
        let t0 = std::time::Instant::now();
        let mut rng = Rng::new(2000 + b as u64);
        // arbitrary (not band-limited) samples: the quadrature formula still defines the forward
        let samples = rng.complex_vec(n_samples(b));
        let want = direct_forward(b, &samples);
        let tdirect = t0.elapsed().as_secs_f64();
        let plan = Plan::new(b, &Options::default()).expect("Plan::new");
        let mut got = vec![Complex64::new(0.0, 0.0); n_coeffs(b)];
        plan.forward(&samples, &mut got).expect("forward");
        let (e, i) = max_abs_diff(&got, &want);
        println!("B={b}: forward vs direct quadrature max abs err {e:.3e} (|fhat|max {:.3}, direct sum {tdirect:.2}s)", max_abs(&want));
        if e.is_nan() || e > TOL {
            fails.push(format!(
                "B={b}: forward err {e:.3e} at coef {i}: got {} want {}",
                got[i], want[i]
            ));
        }
    }
    assert!(fails.is_empty(), "{}", fails.join("\n"));
}

/// The naive sums of tests/common reproduce the mpmath reference files (validates the helpers,
/// the layout and the weights independently of the library).
#[test]
fn direct_sum_helpers_reproduce_reference_files() {
    for name in ["transform_B4_complex.txt", "transform_B8_real.txt"] {
        let r = parse_transform(name);
        let b = r.b;
        let lay = Layout::new(b);
        let mut c = vec![Complex64::new(0.0, 0.0); n_coeffs(b)];
        for &(l, m, mp, v) in &r.coefs {
            c[lay.idx(l, m, mp)] = v;
        }
        let mut s = vec![Complex64::new(0.0, 0.0); n_samples(b)];
        for &(k, j1, j2, v) in &r.samples {
            s[s_idx(b, k, j1, j2)] = v;
        }
        let (ei, _) = max_abs_diff(&direct_inverse(b, &c), &s);
        let (ef, _) = max_abs_diff(&direct_forward(b, &s), &c);
        println!("{name}: naive inverse err {ei:.3e}, naive forward err {ef:.3e}");
        assert!(
            ei <= 1e-13 && ef <= 1e-13,
            "{name}: helpers disagree with the reference: {ei:e} {ef:e}"
        );
    }
}
