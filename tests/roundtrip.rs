//! Round trips, linearity, real-signal symmetry and grid-shift (rotation about z) properties.

mod common;

use common::*;
use so3fft::{Complex64, Options, Plan};
use std::f64::consts::PI;

const TOL: f64 = 1e-13;

fn zeros(n: usize) -> Vec<Complex64> {
    vec![Complex64::new(0.0, 0.0); n]
}

fn plan(b: usize) -> Plan {
    Plan::new(b, &Options::default()).unwrap_or_else(|e| panic!("Plan::new({b}) failed: {e:?}"))
}

/// forward(inverse(c)) == c for random band-limited coefficients (exact quadrature => identity).
#[test]
fn roundtrip_inverse_then_forward() {
    let bs: Vec<usize> = (1..=64).collect();
    let mut fails = Vec::new();
    let mut worst = (0.0f64, 0usize);
    for &b in &bs {
        let t0 = std::time::Instant::now();
        let p = plan(b);
        assert_eq!(p.bandwidth(), b);
        assert_eq!(p.num_coeffs(), n_coeffs(b));
        assert_eq!(p.num_samples(), n_samples(b));
        let mut rng = Rng::new(31337 + b as u64);
        let c = rng.complex_vec(n_coeffs(b));
        let mut f = zeros(n_samples(b));
        p.inverse(&c, &mut f).expect("inverse");
        let mut c2 = zeros(n_coeffs(b));
        p.forward(&f, &mut c2).expect("forward");
        let (e, i) = max_abs_diff(&c2, &c);
        if e > worst.0 {
            worst = (e, b);
        }
        if b <= 4 || b % 8 == 0 || b == 63 || (e.is_nan() || e > TOL) {
            println!(
                "B={b:3}: roundtrip max abs err {e:.3e}  ({:.3}s)",
                t0.elapsed().as_secs_f64()
            );
        }
        if e.is_nan() || e > TOL {
            fails.push(format!(
                "B={b}: err {e:.3e} at coef {i}: got {} want {}",
                c2[i], c[i]
            ));
        }
    }
    println!("roundtrip worst: {:.3e} at B={}", worst.0, worst.1);
    assert!(fails.is_empty(), "{}", fails.join("\n"));
}

#[test]
fn linearity() {
    let b = 10;
    let p = plan(b);
    let mut rng = Rng::new(4242);
    let (a, bb) = (Complex64::new(0.7, -1.3), Complex64::new(-2.1, 0.4));
    // forward
    let x = rng.complex_vec(n_samples(b));
    let y = rng.complex_vec(n_samples(b));
    let z: Vec<Complex64> = x.iter().zip(&y).map(|(x, y)| a * x + bb * y).collect();
    let (mut fx, mut fy, mut fz) = (zeros(n_coeffs(b)), zeros(n_coeffs(b)), zeros(n_coeffs(b)));
    p.forward(&x, &mut fx).unwrap();
    p.forward(&y, &mut fy).unwrap();
    p.forward(&z, &mut fz).unwrap();
    let comb: Vec<Complex64> = fx.iter().zip(&fy).map(|(x, y)| a * x + bb * y).collect();
    let (ef, _) = max_abs_diff(&fz, &comb);
    // inverse
    let u = rng.complex_vec(n_coeffs(b));
    let v = rng.complex_vec(n_coeffs(b));
    let w: Vec<Complex64> = u.iter().zip(&v).map(|(x, y)| a * x + bb * y).collect();
    let (mut iu, mut iv, mut iw) = (
        zeros(n_samples(b)),
        zeros(n_samples(b)),
        zeros(n_samples(b)),
    );
    p.inverse(&u, &mut iu).unwrap();
    p.inverse(&v, &mut iv).unwrap();
    p.inverse(&w, &mut iw).unwrap();
    let comb2: Vec<Complex64> = iu.iter().zip(&iv).map(|(x, y)| a * x + bb * y).collect();
    let (ei, _) = max_abs_diff(&iw, &comb2);
    // tolerance 1e-13 relative to the size of the result (the inverse's samples are O(10) here,
    // being sums of ~1300 unit-size terms), but never below 1e-13 absolute
    let (sf, si) = (max_abs(&fz).max(1.0), max_abs(&iw).max(1.0));
    println!(
        "linearity B={b}: forward {ef:.3e} (|fz|max {sf:.3}), inverse {ei:.3e} (|iw|max {si:.3})"
    );
    assert!(
        ef <= TOL * sf && ei <= TOL * si,
        "linearity violated: forward {ef:e} (scale {sf}), inverse {ei:e} (scale {si})"
    );
}

/// fhat(l,-M,-M') = (-1)^(M-M') conj(fhat(l,M,M'))  <=>  real samples.
#[test]
fn real_signal_symmetry() {
    let mut fails = Vec::new();
    for b in [1usize, 2, 5, 8, 12, 16] {
        let p = plan(b);
        let lay = Layout::new(b);
        let mut rng = Rng::new(555 + b as u64);
        // coefficients with the symmetry -> real samples
        let c = random_real_signal_coefs(b, &mut rng);
        let mut f = zeros(n_samples(b));
        p.inverse(&c, &mut f).unwrap();
        let maxim = f.iter().map(|z| z.im.abs()).fold(0.0, f64::max);
        // real samples -> coefficients with the symmetry
        let fr: Vec<Complex64> = (0..n_samples(b))
            .map(|_| Complex64::new(rng.sym(), 0.0))
            .collect();
        let mut ch = zeros(n_coeffs(b));
        p.forward(&fr, &mut ch).unwrap();
        let mut maxsym = 0.0f64;
        for (l, m, mp) in triples(b) {
            let sign = if (m - mp).rem_euclid(2) == 0 {
                1.0
            } else {
                -1.0
            };
            let d = (ch[lay.idx(l, -m, -mp)] - ch[lay.idx(l, m, mp)].conj() * sign).norm();
            maxsym = maxsym.max(d);
        }
        println!("B={b}: max |Im f| for symmetric coefs {maxim:.3e} (|f|max {:.2}); max symmetry defect of forward(real) {maxsym:.3e}", max_abs(&f));
        if maxim.is_nan() || maxim > TOL {
            fails.push(format!("B={b}: imaginary part {maxim:e}"));
        }
        if maxsym.is_nan() || maxsym > TOL {
            fails.push(format!(
                "B={b}: forward of real samples violates the symmetry by {maxsym:e}"
            ));
        }
    }
    assert!(fails.is_empty(), "{}", fails.join("\n"));
}

/// Grid shifts along gamma and alpha.
///
/// Derivation: f(a,b,g) = sum fhat(l,M,M') c_l e^{-iMa} d(b) e^{-iM'g}. Let h be f moved one step
/// forward along gamma: h[.., j2+1] = f[.., j2], i.e. h(g) = f(g - pi/B). Substituting gives
/// hhat(l,M,M') = fhat(l,M,M') e^{+iM' pi/B}. Conversely h[.., j2] = f[.., j2+1] gives e^{-iM' pi/B}.
/// The same holds for alpha with M. The samples of f are computed by independent direct summation.
#[test]
fn gamma_and_alpha_shift() {
    let b = 6;
    let n = 2 * b;
    let p = plan(b);
    let lay = Layout::new(b);
    let mut fails = Vec::new();
    for (case, only_l1) in [("l=1 only", true), ("all l", false)] {
        let mut rng = Rng::new(if only_l1 { 11 } else { 12 });
        let mut c = zeros(n_coeffs(b));
        for (l, m, mp) in triples(b) {
            if !only_l1 || l == 1 {
                c[lay.idx(l, m, mp)] = rng.complex();
            }
        }
        let f = direct_inverse(b, &c);
        // (axis is gamma?, forward_step: h[j+1] = f[j])
        for (gamma_axis, forward_step) in
            [(true, true), (true, false), (false, true), (false, false)]
        {
            let mut h = zeros(n_samples(b));
            for k in 0..n {
                for j1 in 0..n {
                    for j2 in 0..n {
                        let (t1, t2) = match (gamma_axis, forward_step) {
                            (true, true) => (j1, (j2 + 1) % n),
                            (true, false) => (j1, (j2 + n - 1) % n),
                            (false, true) => ((j1 + 1) % n, j2),
                            (false, false) => ((j1 + n - 1) % n, j2),
                        };
                        // forward_step: h[t] = f[j] with t = j + 1; else t = j - 1, i.e. h[j] = f[j + 1]
                        h[s_idx(b, k, t1, t2)] = f[s_idx(b, k, j1, j2)];
                    }
                }
            }
            let sgn = if forward_step { 1.0 } else { -1.0 };
            let mut want = zeros(n_coeffs(b));
            for (l, m, mp) in triples(b) {
                let order = if gamma_axis { mp } else { m };
                let ph = Complex64::from_polar(1.0, sgn * order as f64 * PI / b as f64);
                want[lay.idx(l, m, mp)] = c[lay.idx(l, m, mp)] * ph;
            }
            let mut got = zeros(n_coeffs(b));
            p.forward(&h, &mut got).unwrap();
            let (e, i) = max_abs_diff(&got, &want);
            let what = format!(
                "{case}: {} shift {} one step: expected factor exp({}i {} pi/B)",
                if gamma_axis { "gamma" } else { "alpha" },
                if forward_step {
                    "h[j+1]=f[j]"
                } else {
                    "h[j]=f[j+1]"
                },
                if forward_step { "+" } else { "-" },
                if gamma_axis { "M'" } else { "M" }
            );
            println!("B={b} {what}: max abs err {e:.3e}");
            if e.is_nan() || e > TOL {
                fails.push(format!(
                    "{what}: err {e:.3e} at coef {i}: got {} want {}",
                    got[i], want[i]
                ));
            }
        }
    }
    assert!(fails.is_empty(), "{}", fails.join("\n"));
}

/// Skipping Wigner-d values below 2^-64 changes neither transform beyond rounding: every
/// skipped contribution is at most 2^-64 times the value it multiplies. Compared against a
/// plan that skips only below 2^-560 (nothing of double-precision significance), on random
/// samples (forward) and random coefficients (inverse), at a bandwidth where the skipped
/// prefix is large (high orders near the poles).
#[test]
fn skip_threshold_leaves_results_unchanged() {
    let b = 96;
    let make = |bits| Plan::new(b, &Options::default().with_skip_bits(Some(bits))).unwrap();
    let (loose, strict) = (make(64), make(560));
    let mut rng = Rng::new(4242);
    let f = rng.complex_vec(n_samples(b));
    let c = rng.complex_vec(n_coeffs(b));
    let (mut c1, mut c2) = (zeros(n_coeffs(b)), zeros(n_coeffs(b)));
    loose.forward(&f, &mut c1).unwrap();
    strict.forward(&f, &mut c2).unwrap();
    let (ef, _) = max_abs_diff(&c1, &c2);
    let (mut f1, mut f2) = (zeros(n_samples(b)), zeros(n_samples(b)));
    loose.inverse(&c, &mut f1).unwrap();
    strict.inverse(&c, &mut f2).unwrap();
    let (ei, _) = max_abs_diff(&f1, &f2);
    let scale_f = max_abs(&c2);
    let scale_i = max_abs(&f2);
    println!("skip 2^-64 vs 2^-560: forward {ef:.2e} (of {scale_f:.2e}), inverse {ei:.2e} (of {scale_i:.2e})");
    assert!(ef <= 1e-14 * scale_f && ei <= 1e-14 * scale_i);

    // No skipping at all (`Some(0)`): the skipped terms are exact zeros, so the results
    // agree with the skipping plan up to the sign of zero.
    let none = make(0);
    let (mut c3, mut f3) = (zeros(n_coeffs(b)), zeros(n_samples(b)));
    none.forward(&f, &mut c3).unwrap();
    none.inverse(&c, &mut f3).unwrap();
    let (ef0, _) = max_abs_diff(&c3, &c2);
    let (ei0, _) = max_abs_diff(&f3, &f2);
    println!("no skipping vs skip 2^-560: forward {ef0:.2e}, inverse {ei0:.2e}");
    assert!(ef0 == 0.0 && ei0 == 0.0);
}
