//! The automatic real paths of the SOFT layer's `flag = 0` calls and of
//! `so3CombineCoef_fftw`, against independent truths: the native complex [`Plan`] on the
//! same data, and the combination formula evaluated term by term. Complex data (one nonzero
//! imaginary part, one broken pair, a NaN) must stay on the complex path: checked by the
//! per-thread counter of the real paths taken ([`REAL_PATHS`]) and by results only the
//! complex transform gives.

use super::correlate::so3CombineCoef_fftw;
use super::real::{parity, real_primary_pairs, REAL_PATHS};
use super::s2::FST_semi_memo;
use super::so3::{
    Forward_SO3_Naive_fftw, Forward_SO3_Naive_fftw_W, Forward_SO3_Naive_fftw_nt,
    Forward_SO3_Naive_fftw_pc, Inverse_SO3_Naive_fftw, Inverse_SO3_Naive_fftw_W,
    Inverse_SO3_Naive_fftw_nt, Inverse_SO3_Naive_fftw_pc,
};
use super::*;
use crate::grid::{block_start, coef_index};
use crate::s2::s2_coef_index;
use crate::{num_coeffs, num_samples, Complex64, Options, Plan};
use std::f64::consts::PI;
use std::ptr::null_mut;

/// Real paths taken on this thread so far, `[forward, inverse]`.
fn taken() -> [usize; 2] {
    REAL_PATHS.with(|c| c.get())
}

/// Deterministic values in [-0.5, 0.5).
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64 - 0.5
    }

    fn below(&mut self, n: usize) -> usize {
        ((self.next() + 0.5) * n as f64) as usize % n
    }
}

/// The native complex plan (an independent path: complex slice FFTs and layout).
fn native(b: usize) -> Plan {
    Plan::new(
        b,
        &Options {
            threads: 2,
            ..Default::default()
        },
    )
    .unwrap()
}

fn fc(v: &mut [Complex64]) -> *mut FftwComplex {
    v.as_mut_ptr().cast()
}

/// Largest `|a - b|` and largest `|b|`.
fn diff(a: &[Complex64], b: &[Complex64]) -> (f64, f64) {
    let e = a
        .iter()
        .zip(b)
        .map(|(x, y)| (x - y).norm())
        .fold(0.0, f64::max);
    (e, b.iter().map(|z| z.norm()).fold(0.0, f64::max))
}

/// The documented accuracy: agreement with the complex transform to 1e-12 of the scale.
fn close(a: &[Complex64], b: &[Complex64], what: &str) {
    let (e, scale) = diff(a, b);
    assert!(
        e <= 1e-12 * scale.max(1e-300),
        "{what}: error {e:.2e} of {scale:.2e}"
    );
}

/// Random coefficients of a real signal: every pair exactly symmetric, `(l,0,0)` real.
fn real_coeffs(b: usize, rng: &mut Rng) -> Vec<Complex64> {
    let mut c: Vec<Complex64> = (0..num_coeffs(b))
        .map(|_| Complex64::new(rng.next(), rng.next()))
        .collect();
    let s00 = block_start(b, 0, 0);
    for z in &mut c[s00..s00 + b] {
        z.im = 0.0;
    }
    for (m, mp) in real_primary_pairs(b) {
        let (p, q) = (block_start(b, m, mp), block_start(b, -m, -mp));
        for i in 0..b - m.unsigned_abs().max(mp.unsigned_abs()) {
            c[q + i] = c[p + i].conj() * parity(m, mp);
        }
    }
    c
}

/// `Forward_SO3_Naive_fftw` with `flag` and standard weights.
fn soft_forward(b: usize, samples: &[Complex64], flag: i32) -> Vec<Complex64> {
    let mut data = samples.to_vec();
    let mut out = vec![Complex64::new(f64::NAN, f64::NAN); num_coeffs(b)];
    // SAFETY: SOFT's sizes; NULL workspaces, weights and plan are accepted.
    unsafe {
        Forward_SO3_Naive_fftw(
            b as i32,
            fc(&mut data),
            fc(&mut out),
            null_mut(),
            null_mut(),
            null_mut(),
            null_mut(),
            null_mut(),
            flag,
        )
    };
    assert!(
        data.iter()
            .zip(samples)
            .all(|(x, y)| x.re.to_bits() == y.re.to_bits() && x.im.to_bits() == y.im.to_bits()),
        "input modified"
    );
    out
}

/// `Inverse_SO3_Naive_fftw` with `flag`.
fn soft_inverse(b: usize, coeffs: &[Complex64], flag: i32) -> Vec<Complex64> {
    let mut c = coeffs.to_vec();
    let mut out = vec![Complex64::new(f64::NAN, f64::NAN); num_samples(b)];
    // SAFETY: SOFT's sizes; NULL workspaces and plan are accepted.
    unsafe {
        Inverse_SO3_Naive_fftw(
            b as i32,
            fc(&mut c),
            fc(&mut out),
            null_mut(),
            null_mut(),
            null_mut(),
            null_mut(),
            flag,
        )
    };
    assert!(
        c.iter()
            .zip(coeffs)
            .all(|(x, y)| x.re.to_bits() == y.re.to_bits() && x.im.to_bits() == y.im.to_bits()),
        "input modified"
    );
    out
}

/// Whether the coefficients are exactly real-symmetric (as the layer checks).
fn asymmetry(b: usize, c: &[Complex64]) -> f64 {
    let s00 = block_start(b, 0, 0);
    let zero = c[s00..s00 + b]
        .iter()
        .map(|z| z.im.abs())
        .fold(0.0, f64::max);
    real_primary_pairs(b)
        .flat_map(|(m, mp)| {
            let (p, q) = (block_start(b, m, mp), block_start(b, -m, -mp));
            let n = b - m.unsigned_abs().max(mp.unsigned_abs());
            (0..n).map(move |i| (p + i, q + i, parity(m, mp)))
        })
        .map(|(p, q, s)| (c[q] - c[p].conj() * s).norm())
        .fold(zero, f64::max)
}

/// Real samples in a complex array take the real forward (flag 0), which gives the complex
/// forward's coefficients, exactly symmetric; so do imaginary parts of -0. One nonzero
/// imaginary part anywhere, a NaN imaginary part or a non-finite real part stays complex.
#[test]
fn forward_flag0_real_samples() {
    let mut rng = Rng(7);
    for b in [1usize, 2, 5, 8, 13] {
        let plan = native(b);
        let ns = num_samples(b);
        let mut samples: Vec<Complex64> =
            (0..ns).map(|_| Complex64::new(rng.next(), 0.0)).collect();
        let mut want = vec![Complex64::default(); num_coeffs(b)];
        plan.forward(&samples, &mut want).unwrap();

        let before = taken();
        let got = soft_forward(b, &samples, 0);
        assert_eq!(taken()[0], before[0] + 1, "B={b}: real forward not taken");
        close(&got, &want, &format!("B={b} real forward"));
        assert_eq!(asymmetry(b, &got), 0.0, "B={b}");
        // The real path is flag 1's: the same numbers.
        let flag1 = soft_forward(b, &samples, 1);
        assert!(got == flag1, "B={b}: flag 0 and flag 1 differ on real data");

        // Negative zeros are zeros.
        for z in samples.iter_mut().step_by(3) {
            z.im = -0.0;
        }
        let before = taken();
        let neg = soft_forward(b, &samples, 0);
        assert_eq!(taken()[0], before[0] + 1, "B={b}: -0 imaginary parts");
        assert!(neg == got, "B={b}");

        // One nonzero imaginary part at a random place: complex, and the result is the
        // complex transform's, which is not symmetric (the real path's would be).
        let at = rng.below(ns);
        let mut one = samples.clone();
        one[at].im = 0.25;
        plan.forward(&one, &mut want).unwrap();
        let before = taken();
        let got = soft_forward(b, &one, 0);
        assert_eq!(
            taken(),
            before,
            "B={b}: one imaginary part at {at} took the real path"
        );
        close(&got, &want, &format!("B={b} complex forward"));
        assert!(
            asymmetry(b, &want) > 1e-6,
            "B={b}: the test needs an asymmetric truth"
        );

        // A NaN imaginary part, a NaN or infinite real part.
        for (re, im) in [(0.5, f64::NAN), (f64::NAN, 0.0), (f64::INFINITY, 0.0)] {
            let mut bad = samples.clone();
            bad[rng.below(ns)] = Complex64::new(re, im);
            let before = taken();
            let got = soft_forward(b, &bad, 0);
            assert_eq!(taken(), before, "B={b}: ({re}, {im}) took the real path");
            assert!(
                got.iter().any(|z| !z.re.is_finite() || !z.im.is_finite()),
                "B={b}"
            );
        }
    }
}

/// Exactly symmetric coefficients take the real inverse (flag 0): the complex inverse's
/// samples, with imaginary parts exactly 0. One partner off by one ulp, an imaginary part
/// of `(l,0,0)`, a NaN: complex, giving what only the complex inverse gives.
#[test]
fn inverse_flag0_symmetric_coefficients() {
    let mut rng = Rng(11);
    for b in [1usize, 2, 5, 8, 13] {
        let plan = native(b);
        let nc = num_coeffs(b);
        let coeffs = real_coeffs(b, &mut rng);
        let mut want = vec![Complex64::default(); num_samples(b)];
        plan.inverse(&coeffs, &mut want).unwrap();

        let before = taken();
        let got = soft_inverse(b, &coeffs, 0);
        assert_eq!(taken()[1], before[1] + 1, "B={b}: real inverse not taken");
        close(&got, &want, &format!("B={b} real inverse"));
        assert!(
            got.iter().all(|z| z.im.to_bits() == 0),
            "B={b}: imaginary parts"
        );

        // Each kind of break, at a random place of a random pair.
        let pairs: Vec<_> = real_primary_pairs(b).collect();
        let mut breaks: Vec<(&str, Vec<Complex64>)> = Vec::new();
        let s00 = block_start(b, 0, 0);
        let mut zero = coeffs.clone();
        zero[s00 + rng.below(b)].im = 1e-3;
        breaks.push(("imaginary (l,0,0)", zero));
        if !pairs.is_empty() {
            let (m, mp) = pairs[rng.below(pairs.len())];
            let n = b - m.unsigned_abs().max(mp.unsigned_abs());
            let i = rng.below(n);
            let q = block_start(b, -m, -mp) + i;
            for part in [0, 1] {
                let mut ulp = coeffs.clone();
                let v = if part == 0 {
                    &mut ulp[q].re
                } else {
                    &mut ulp[q].im
                };
                *v = f64::from_bits(v.to_bits() + 1);
                breaks.push(("partner off by one ulp", ulp));
            }
        }
        let cached = super::cache::plan_for(b).unwrap();
        let bits = |v: &[Complex64]| -> Vec<u64> {
            v.iter()
                .flat_map(|z| [z.re.to_bits(), z.im.to_bits()])
                .collect()
        };
        for (what, c) in &breaks {
            plan.inverse(c, &mut want).unwrap();
            let before = taken();
            let got = soft_inverse(b, c, 0);
            assert_eq!(taken(), before, "B={b}: {what} took the real path");
            close(&got, &want, &format!("B={b} {what}"));
            // Bit for bit the layer plan's complex inverse, which the real inverse is not.
            let mut complex = vec![Complex64::default(); got.len()];
            cached.inverse(c, &mut complex).unwrap();
            assert!(
                bits(&got) == bits(&complex),
                "B={b} {what}: not the complex inverse"
            );
            let mut real = vec![Complex64::default(); got.len()];
            cached
                .engine()
                .inverse_real_to_complex(c, &mut real)
                .unwrap();
            // (At small B the two may round alike, and this check would say nothing.)
            assert!(
                b < 8 || bits(&real) != bits(&complex),
                "B={b} {what}: indistinct"
            );
        }
        for bad in [f64::NAN, f64::INFINITY] {
            let mut c = coeffs.clone();
            let i = rng.below(nc);
            c[i].re = bad;
            let before = taken();
            let got = soft_inverse(b, &c, 0);
            assert_eq!(taken(), before, "B={b}: {bad} at {i} took the real path");
            assert!(got.iter().any(|z| !z.re.is_finite() || !z.im.is_finite()));
        }
    }
}

/// The `_pc`, `_nt` and `_W` variants share the bodies: the same real paths, the same
/// numbers.
#[test]
fn variants_share_the_real_paths() {
    let b = 6;
    let mut rng = Rng(3);
    let ns = num_samples(b);
    let samples: Vec<Complex64> = (0..ns).map(|_| Complex64::new(rng.next(), 0.0)).collect();
    let coeffs = real_coeffs(b, &mut rng);
    let want_f = soft_forward(b, &samples, 0);
    let want_i = soft_inverse(b, &coeffs, 0);
    let bw = b as i32;
    let forwards: [&dyn Fn(*mut FftwComplex, *mut FftwComplex); 3] = [
        // SAFETY: SOFT's sizes; NULL workspaces, tables and plans are accepted.
        &|d, c| unsafe {
            Forward_SO3_Naive_fftw_pc(
                bw,
                d,
                c,
                null_mut(),
                null_mut(),
                null_mut(),
                null_mut(),
                null_mut(),
                null_mut(),
                0,
            )
        },
        // SAFETY: SOFT's sizes; NULL workspaces, tables and plans are accepted.
        &|d, c| unsafe {
            Forward_SO3_Naive_fftw_nt(bw, d, c, null_mut(), null_mut(), null_mut(), null_mut(), 0)
        },
        // SAFETY: SOFT's sizes; NULL workspaces, tables and plans are accepted.
        &|d, c| unsafe { Forward_SO3_Naive_fftw_W(bw, d, c, 0) },
    ];
    for (k, f) in forwards.iter().enumerate() {
        let mut d = samples.clone();
        let mut c = vec![Complex64::new(f64::NAN, 0.0); num_coeffs(b)];
        let before = taken();
        f(fc(&mut d), fc(&mut c));
        assert_eq!(taken()[0], before[0] + 1, "forward variant {k}");
        assert!(c == want_f, "forward variant {k}");
    }
    let inverses: [&dyn Fn(*mut FftwComplex, *mut FftwComplex); 3] = [
        // SAFETY: SOFT's sizes; NULL workspaces, tables and plans are accepted.
        &|c, d| unsafe {
            Inverse_SO3_Naive_fftw_pc(
                bw,
                c,
                d,
                null_mut(),
                null_mut(),
                null_mut(),
                null_mut(),
                null_mut(),
                0,
            )
        },
        // SAFETY: SOFT's sizes; NULL workspaces, tables and plans are accepted.
        &|c, d| unsafe {
            Inverse_SO3_Naive_fftw_nt(bw, c, d, null_mut(), null_mut(), null_mut(), 0)
        },
        // SAFETY: SOFT's sizes; NULL workspaces, tables and plans are accepted.
        &|c, d| unsafe { Inverse_SO3_Naive_fftw_W(bw, c, d, 0) },
    ];
    for (k, f) in inverses.iter().enumerate() {
        let mut c = coeffs.clone();
        let mut d = vec![Complex64::new(f64::NAN, 0.0); ns];
        let before = taken();
        f(fc(&mut c), fc(&mut d));
        assert_eq!(taken()[1], before[1] + 1, "inverse variant {k}");
        assert!(d == want_i, "inverse variant {k}");
    }
}

/// Random S^2 coefficients (bandwidth `b`), with the real symmetry when `real`.
fn s2_coeffs(b: usize, real: bool, rng: &mut Rng) -> Vec<Complex64> {
    let mut c: Vec<Complex64> = (0..b * b)
        .map(|_| Complex64::new(rng.next(), rng.next()))
        .collect();
    if real {
        for l in 0..b {
            c[s2_coef_index(b, l, 0)].im = 0.0;
            for m in 1..=l as isize {
                let s = if m % 2 == 0 { 1.0 } else { -1.0 };
                c[s2_coef_index(b, l, -m)] = c[s2_coef_index(b, l, m)].conj() * s;
            }
        }
    }
    c
}

/// `so3CombineCoef_fftw` through the split arrays, into an output full of NaN.
fn soft_combine(
    (b_in, b_out, deg): (usize, usize, i32),
    sig: &[Complex64],
    pat: &[Complex64],
) -> Vec<Complex64> {
    let split = |v: &[Complex64]| -> (Vec<f64>, Vec<f64>) {
        (
            v.iter().map(|z| z.re).collect(),
            v.iter().map(|z| z.im).collect(),
        )
    };
    let ((mut sr, mut si), (mut pr, mut pi)) = (split(sig), split(pat));
    let mut out = vec![Complex64::new(f64::NAN, f64::NAN); num_coeffs(b_out)];
    // SAFETY: bwIn^2 doubles per input, (4bwOut^3-bwOut)/3 outputs.
    unsafe {
        so3CombineCoef_fftw(
            b_in as i32,
            b_out as i32,
            deg,
            sr.as_mut_ptr(),
            si.as_mut_ptr(),
            pr.as_mut_ptr(),
            pi.as_mut_ptr(),
            fc(&mut out),
        )
    };
    out
}

/// The combination formula term by term (SOFT's definition, in the library's order of
/// operations, so the numbers compare exactly).
fn combine_formula(
    (b_in, b_out, deg): (usize, usize, i32),
    sig: &[Complex64],
    pat: &[Complex64],
) -> Vec<Complex64> {
    let mut out = vec![Complex64::default(); num_coeffs(b_out)];
    for l in 0..=deg.max(-1) {
        let l = l as usize;
        let norm = 2.0 * PI * (2.0 / (2 * l + 1) as f64).sqrt();
        for m1 in -(l as isize)..=l as isize {
            for m2 in -(l as isize)..=l as isize {
                let sign = if (m1 + m2) % 2 == 0 { 1.0 } else { -1.0 };
                let f = sig[s2_coef_index(b_in, l, -m1)];
                let h = pat[s2_coef_index(b_in, l, -m2)];
                out[coef_index(b_out, l, m1, m2)] = f * h.conj() * (sign * norm);
            }
        }
    }
    out
}

/// Every output entry written (no NaN left), equal as numbers to the formula: real
/// inputs (half computed, partners by the symmetry), complex ones, one input off the
/// symmetry by one ulp (complex), degree limits below both bandwidths, on the workers of a
/// cached plan (large enough outputs) and with non-temporal stores (outputs over 8 MiB).
/// With real inputs the output is exactly symmetric.
#[test]
fn combine_writes_the_formula_once() {
    let mut rng = Rng(5);
    // Make the plan of bandwidth 24 so the combine there runs on its workers.
    let _ = soft_inverse(24, &vec![Complex64::default(); num_coeffs(24)], 0);
    for (b_in, b_out, deg) in [
        (8usize, 8usize, 7i32),
        (8, 11, 5),
        (10, 6, 5),
        (5, 5, 0),
        (4, 4, -1),
        (24, 24, 23),
        (24, 24, 12),
        // Outputs over 8 MiB: non-temporal stores.
        (12, 80, 11),
        (80, 80, 79),
    ] {
        for (real_sig, real_pat, ulp) in [
            (true, true, false),
            (true, true, true),
            (true, false, false),
            (false, false, false),
        ] {
            let sig = s2_coeffs(b_in, real_sig, &mut rng);
            let mut pat = s2_coeffs(b_in, real_pat, &mut rng);
            if ulp && deg >= 1 {
                let i = s2_coef_index(b_in, deg as usize, -1);
                pat[i].im = f64::from_bits(pat[i].im.to_bits() + 1);
            }
            let dims = (b_in, b_out, deg);
            let got = soft_combine(dims, &sig, &pat);
            let want = combine_formula(dims, &sig, &pat);
            let what = format!("{dims:?} real {real_sig}/{real_pat} ulp {ulp}");
            assert!(
                got.iter().all(|z| !z.re.is_nan() && !z.im.is_nan()),
                "{what}: unwritten"
            );
            assert!(got == want, "{what}: differs from the formula");
            if real_sig && real_pat && !ulp {
                assert_eq!(asymmetry(b_out, &got), 0.0, "{what}");
            }
        }
    }
}

/// A registration client's sequence through the SOFT entry points on real data in split
/// arrays with zero imaginary parts: two FST_semi_memo, so3CombineCoef_fftw,
/// Inverse_SO3_Naive_fftw with flag 0. The combined coefficients are exactly symmetric, the
/// inverse takes the real path and gives the complex inverse's samples with imaginary
/// parts exactly 0. With one imaginary sample of the signal nonzero it stays complex.
#[test]
fn registration_sequence_takes_the_real_paths() {
    let mut rng = Rng(13);
    for b in [4usize, 9, 16] {
        let n = 2 * b;
        let plan = native(b);
        let mut sig_r: Vec<f64> = (0..n * n).map(|_| rng.next()).collect();
        let mut pat_r: Vec<f64> = (0..n * n).map(|_| rng.next()).collect();
        for imag in [0.0, 1e-3] {
            let mut sig_i = vec![0.0; n * n];
            sig_i[rng.below(n * n)] = imag;
            let mut pat_i = vec![0.0; n * n];
            let mut cs = [vec![0.0; b * b], vec![0.0; b * b]];
            let mut cp = [vec![0.0; b * b], vec![0.0; b * b]];
            for (r, i, c) in [
                (&mut sig_r, &mut sig_i, &mut cs),
                (&mut pat_r, &mut pat_i, &mut cp),
            ] {
                let [cr, ci] = c;
                // SAFETY: (2b)^2 samples and b^2 coefficients each; NULL tables,
                // workspace, plans and weights are accepted.
                unsafe {
                    FST_semi_memo(
                        r.as_mut_ptr(),
                        i.as_mut_ptr(),
                        cr.as_mut_ptr(),
                        ci.as_mut_ptr(),
                        b as i32,
                        null_mut(),
                        null_mut(),
                        0,
                        b as i32,
                        null_mut(),
                        null_mut(),
                        null_mut(),
                    )
                };
            }
            let join = |c: &[Vec<f64>; 2]| -> Vec<Complex64> {
                c[0].iter()
                    .zip(&c[1])
                    .map(|(&r, &i)| Complex64::new(r, i))
                    .collect()
            };
            let (sig, pat) = (join(&cs), join(&cp));
            let so3 = soft_combine((b, b, b as i32 - 1), &sig, &pat);
            let mut want = vec![Complex64::default(); num_samples(b)];
            plan.inverse(&so3, &mut want).unwrap();
            let before = taken();
            let got = soft_inverse(b, &so3, 0);
            close(&got, &want, &format!("B={b} imag {imag}"));
            if imag == 0.0 {
                assert_eq!(asymmetry(b, &so3), 0.0, "B={b}");
                assert_eq!(taken()[1], before[1] + 1, "B={b}: real inverse not taken");
                assert!(got.iter().all(|z| z.im.to_bits() == 0), "B={b}");
            } else {
                assert_eq!(taken(), before, "B={b}: complex signal took the real path");
                assert!(got.iter().any(|z| z.im.abs() > 1e-9), "B={b}");
            }
        }
    }
}
