//! The float kernels against the double kernels on the same (float-rounded) inputs, and a
//! float batch against float single calls, bit for bit.

use super::fixtures::{cluster_setup, cluster_setup_at, grid_lanes};
use super::tests::{batch_case, inverse_from, pseudo};
use super::{forward, forward_parity, inverse_parity, parity_partial_len, Rec};
use crate::simd::Isa;

/// `max |u - r| / max |r|`
fn rel_err(u: &[f32], r: &[f64]) -> f64 {
    let scale = r.iter().fold(0.0f64, |s, x| s.max(x.abs()));
    let e = u
        .iter()
        .zip(r)
        .fold(0.0f64, |s, (a, b)| s.max((*a as f64 - b).abs()));
    e / scale
}

fn to_f32(v: &[f64]) -> Vec<f32> {
    v.iter().map(|&x| x as f32).collect()
}

fn to_f64(v: &[f32]) -> Vec<f64> {
    v.iter().map(|&x| x as f64).collect()
}

/// The float forward and inverse kernels give the double kernels' sums of the same
/// float data to a relative error (against the largest sum) that grows with the degrees
/// run: every instruction set, 8 and 16 columns, low and high orders, the diagonal.
#[test]
fn float_kernels_match_double_kernels() {
    let b = 192;
    for &(m, mp) in &[
        (0usize, 0usize),
        (5, 3),
        (150, 20),
        (191, 191),
        (120, 0),
        (40, 40),
        (16, 0),
    ] {
        let (n, nb) = (b - m, 2 * b);
        let ci = cluster_setup(b, m, mp, nb);
        let rec = Rec::new(&ci.coeffs, n);
        let lanes = grid_lanes(&ci.tau, &ci.p, &ci.sc, b);
        let nw = ci.to_f32();
        let (rec32, lanes32) = (nw.rec(n), nw.lanes(b));
        for pw in [8usize, 16] {
            let xin = to_f32(&pseudo(nb * pw, 7 + m as u64));
            let fin = to_f32(&pseudo(n * pw, 11 + mp as u64));
            let mut f_ref = vec![f64::NAN; (n + 8) * pw];
            let mut y_ref = vec![0.0; nb * pw];
            forward(Isa::Scalar, pw, &rec, &lanes, &to_f64(&xin), &mut f_ref);
            inverse_from(Isa::Scalar, pw, &rec, &lanes, &to_f64(&fin), &mut y_ref);
            for isa in [Isa::Scalar, Isa::Avx512, Isa::Avx2] {
                if !isa.is_supported() {
                    continue;
                }
                let mut f = vec![f32::NAN; (n + 16) * pw];
                let mut y = vec![0.0f32; nb * pw];
                forward(isa, pw, &rec32, &lanes32, &xin, &mut f);
                inverse_from(isa, pw, &rec32, &lanes32, &fin, &mut y);
                let nf = n * pw;
                assert!(f[..nf].iter().all(|v| v.is_finite()));
                let (ef, ey) = (rel_err(&f[..nf], &f_ref[..nf]), rel_err(&y, &y_ref));
                // The recurrence's error grows like l eps (l <= 192, eps = 6e-8); far more
                // at the lowest orders and on the diagonal (see `docs/precision.md`).
                let tol = if m < 16 {
                    1e-3
                } else if m == mp {
                    1e-4
                } else {
                    1e-5
                };
                assert!(
                    ef < tol && ey < tol,
                    "{isa:?} m={m} mp={mp} P={pw}: {ef} {ey}"
                );
            }
        }
    }
}

/// A float batch gives bitwise the results of float single calls (every instruction set,
/// 8 and 16 columns, one to three transforms).
#[test]
fn float_batch_equals_single_calls() {
    let b = 96;
    let nbs = 160;
    for &(m, mp) in &[(5usize, 2usize), (40, 17), (95, 95), (95, 0)] {
        let ci = cluster_setup(b, m, mp, nbs);
        let nw = ci.to_f32();
        let rec = nw.rec(b - m);
        for pw in [8usize, 16] {
            for isa in [Isa::Scalar, Isa::Avx2, Isa::Avx512] {
                if isa.is_supported() {
                    let mut lanes = nw.lanes(nbs / 2);
                    batch_case(isa, pw, &rec, &mut lanes, 7 + m as u64);
                    lanes.interleaved = false;
                    batch_case(isa, pw, &rec, &mut lanes, 9 + m as u64);
                }
            }
        }
    }
}

/// The float parity kernels (S^2) give the double ones' sums of the same float data to
/// float rounding: every instruction set, 2 and 4 columns.
#[test]
fn float_parity_kernels_match_double() {
    let b = 160;
    for &m in &[0usize, 3, 90] {
        let n = b - m;
        for &rings in &[160usize, 152, 40] {
            let ks: Vec<usize> = (0..rings).map(|s| s * b / rings).collect();
            let mut ci = cluster_setup_at(b, m, 0, &ks);
            let nb = rings.next_multiple_of(16);
            for v in [&mut ci.tau, &mut ci.p, &mut ci.sc] {
                v.resize(nb, 0.0);
            }
            let rec = Rec::new(&ci.coeffs, n);
            let mut lanes = grid_lanes(&ci.tau, &ci.p, &ci.sc, nb);
            (lanes.interleaved, lanes.stream) = (false, false);
            let nw = ci.to_f32();
            let rec32 = nw.rec(n);
            let mut lanes32 = nw.lanes(nb);
            (lanes32.interleaved, lanes32.stream) = (false, false);
            for c in [2usize, 4] {
                let fin = to_f32(&pseudo(n * c, 3 + m as u64));
                let x = to_f32(&pseudo(2 * c * nb, 5 + m as u64));
                let mut y_ref = vec![0.0; 2 * c * nb];
                inverse_parity(Isa::Scalar, c, &rec, &lanes, &to_f64(&fin), &mut y_ref);
                let mut part = vec![0.0; parity_partial_len(n, c, 1)];
                let mut ft_ref = vec![0.0; n * c];
                forward_parity(
                    Isa::Scalar,
                    c,
                    &rec,
                    &lanes,
                    &to_f64(&x),
                    (&mut part, &mut ft_ref),
                );
                for isa in [Isa::Scalar, Isa::Avx512, Isa::Avx2] {
                    if !isa.is_supported() {
                        continue;
                    }
                    let w = isa.lanes_of::<f32>();
                    let mut y = vec![f32::NAN; 2 * c * nb];
                    inverse_parity(isa, c, &rec32, &lanes32, &fin, &mut y);
                    let mut part = vec![0.0f32; parity_partial_len(n, c, w)];
                    let mut ft = vec![0.0f32; (n * c).next_multiple_of(w)];
                    forward_parity(isa, c, &rec32, &lanes32, &x, (&mut part, &mut ft));
                    let (ey, ef) = (rel_err(&y, &y_ref), rel_err(&ft[..n * c], &ft_ref));
                    let tol = if m < 16 { 1e-3 } else { 1e-5 };
                    assert!(
                        ey < tol && ef < tol,
                        "{isa:?} m={m} rings={rings} C={c}: {ey} {ef}"
                    );
                }
            }
        }
    }
}
