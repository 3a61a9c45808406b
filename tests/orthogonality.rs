//! Discrete orthonormality of the normalised Wigner-d on the quadrature grid:
//!   sum_k w_B(k) dt^l_{m,m'}(beta_k) dt^{l'}_{m,m'}(beta_k) = delta_{l l'}   for max(|m|,|m'|) <= l, l' < B,
//! which holds exactly for the quadrature weights of docs/conventions.md (the products are
//! band-limited below 2B), using the library's dt_on_grid (the DWT's own code path) and weights.
//! Plus dt_on_grid against the mpmath reference values at grid angles.

mod common;

use common::*;

const TOL: f64 = 1e-12;

/// Returns (max |G - I| over checked entries, number of entries checked, worst (l, l')).
fn gram_residual(b: usize, m: isize, mp: isize, row_step: usize) -> (f64, usize, (usize, usize)) {
    let n = 2 * b;
    let l0 = m.unsigned_abs().max(mp.unsigned_abs());
    let rows = b - l0;
    let dt = so3fft::wigner::dt_on_grid(b, m, mp);
    assert_eq!(dt.len(), rows * n, "dt_on_grid({b},{m},{mp}) length");
    let w = so3fft::weights(b);
    assert_eq!(w.len(), n);
    let weighted: Vec<f64> = dt
        .chunks(n)
        .flat_map(|r| r.iter().zip(&w).map(|(x, y)| x * y))
        .collect();
    let dot = |i: usize, j: usize| -> f64 {
        let a = &weighted[i * n..(i + 1) * n];
        let c = &dt[j * n..(j + 1) * n];
        // four independent accumulators (lets the compiler vectorise; fine for a residual check)
        let mut acc = [0.0f64; 4];
        let (ac, ar) = (a.chunks_exact(4), a.chunks_exact(4).remainder());
        let (cc, cr) = (c.chunks_exact(4), c.chunks_exact(4).remainder());
        for (x, y) in ac.zip(cc) {
            for t in 0..4 {
                acc[t] += x[t] * y[t];
            }
        }
        let tail: f64 = ar.iter().zip(cr).map(|(x, y)| x * y).sum();
        (acc[0] + acc[1]) + (acc[2] + acc[3]) + tail
    };
    // rows checked against every row: every row_step-th row plus the last one; plus the full diagonal
    let mut sel: Vec<usize> = (0..rows).step_by(row_step).collect();
    if *sel.last().unwrap() != rows - 1 {
        sel.push(rows - 1);
    }
    let mut worst = (0.0f64, (0, 0));
    let mut count = 0usize;
    let upd = |v: f64, i: usize, j: usize, worst: &mut (f64, (usize, usize))| {
        let target = if i == j { 1.0 } else { 0.0 };
        let r = if v.is_nan() {
            f64::INFINITY
        } else {
            (v - target).abs()
        };
        if r > worst.0 {
            *worst = (r, (l0 + i, l0 + j));
        }
    };
    for &i in &sel {
        for j in 0..rows {
            upd(dot(i, j), i, j, &mut worst);
            count += 1;
        }
    }
    for i in 0..rows {
        upd(dot(i, i), i, i, &mut worst);
        count += 1;
    }
    (worst.0, count, worst.1)
}

fn run(b: usize, pairs: &[(isize, isize)], row_step: usize) {
    let mut fails = Vec::new();
    for &(m, mp) in pairs {
        let t0 = std::time::Instant::now();
        let (r, cnt, (l, lp)) = gram_residual(b, m, mp, row_step);
        println!(
            "B={b} (m,m')=({m},{mp}): max |G-I| = {r:.3e} over {cnt} entries (worst at l={l}, l'={lp}) [{:.2}s]",
            t0.elapsed().as_secs_f64()
        );
        if r.is_nan() || r > TOL {
            fails.push(format!(
                "B={b} (m,m')=({m},{mp}): residual {r:.3e} at (l,l')=({l},{lp})"
            ));
        }
    }
    assert!(fails.is_empty(), "{}", fails.join("\n"));
}

fn std_pairs(b: usize) -> Vec<(isize, isize)> {
    let bi = b as isize;
    vec![
        (0, 0),
        (bi - 1, bi - 1),
        (bi - 1, -(bi - 1)),
        (0, bi - 1),
        (bi / 2, -(bi / 3)),
        (7, 3),
        (-5, bi - 2),
        (-(bi / 4), -(bi / 2)),
        (1, -1),
    ]
}

#[test]
fn orthogonality_b512() {
    run(512, &std_pairs(512), 7);
}

#[test]
fn orthogonality_b1024() {
    run(1024, &std_pairs(1024), 7);
}

#[test]
fn orthogonality_b2048_two_pairs() {
    run(2048, &[(0, 0), (1024, -682)], 31);
}

#[test]
fn library_weights_match_formula_large_b() {
    for b in [512usize, 1024, 2048] {
        let w = so3fft::weights(b);
        let mine = weights_formula(b);
        assert_eq!(w.len(), 2 * b);
        let e = w
            .iter()
            .zip(&mine)
            .map(|(x, y)| (x - y).abs())
            .fold(0.0, f64::max);
        let s: f64 = w.iter().sum();
        println!(
            "B={b}: |weights - formula| max {e:.3e}, sum-2 = {:.3e}",
            s - 2.0
        );
        // each weight: (2/B) sin(beta) * (sum of B terms bounded by 1): error a few eps in absolute
        assert!(
            e <= 1e-14,
            "B={b}: weights differ from the formula of docs/conventions.md by {e:e}"
        );
        assert!((s - 2.0).abs() <= 1e-12, "B={b}: sum of weights {s}");
    }
}

/// dt_on_grid rows against the mpmath reference: the csv's betas include grid angles of B = 512
/// (k = 0, 1) and B = 1024 (k = 0, 100, 1023, 2047).
#[test]
fn dt_on_grid_vs_reference_csv() {
    use std::collections::BTreeMap;
    let rows = parse_wigner_csv();
    // (b, m, mp) -> list of (l, k, beta, d)
    // (b, m, mp) -> [(l, k, beta, d)]
    type Wanted = BTreeMap<(usize, isize, isize), Vec<(usize, usize, f64, f64)>>;
    let mut want: Wanted = BTreeMap::new();
    for r in rows.iter().filter(|r| r.l >= 63) {
        for (b, ks) in [
            (512usize, &[0usize, 1][..]),
            (1024, &[0, 100, 1023, 2047][..]),
        ] {
            if r.l >= b {
                continue;
            }
            for &k in ks {
                if (grid_beta(b, k) - r.beta).abs() <= 4.0 * f64::EPSILON {
                    want.entry((b, r.m, r.mp))
                        .or_default()
                        .push((r.l, k, r.beta, r.d));
                }
            }
        }
    }
    let nchecks: usize = want.values().map(|v| v.len()).sum();
    assert!(
        nchecks > 100,
        "too few grid-angle rows found in the csv: {nchecks}"
    );
    let mut fails = Vec::new();
    let mut maxerr: BTreeMap<usize, f64> = BTreeMap::new();
    for (&(b, m, mp), list) in &want {
        let l0 = m.unsigned_abs().max(mp.unsigned_abs());
        let dt = so3fft::wigner::dt_on_grid(b, m, mp);
        assert_eq!(dt.len(), (b - l0) * 2 * b);
        for &(l, k, beta_csv, d) in list {
            let norm = ((2 * l + 1) as f64 / 2.0).sqrt();
            let got = dt[(l - l0) * 2 * b + k] / norm;
            // tolerance as in reference.rs (common::wigner_tol) plus the effect of a possibly
            // different rounding of beta_k (library's so3fft::beta vs the csv's exact double):
            // |d/dbeta d^l| <= l + 1.
            let dbeta = (so3fft::beta(b, k) - beta_csv).abs();
            let tol = common::wigner_tol(l, beta_csv) + (l + 1) as f64 * dbeta;
            let err = if got.is_nan() {
                f64::INFINITY
            } else {
                (got - d).abs()
            };
            let e = maxerr.entry(l).or_insert(0.0);
            *e = e.max(err);
            if err.is_nan() || err > tol {
                fails.push(format!("B={b} m={m} mp={mp} l={l} k={k}: d = {got:e}, want {d:e}, err {err:.3e} > {tol:.2e}"));
            }
        }
    }
    for (l, e) in &maxerr {
        println!("dt_on_grid vs csv: l={l:5} max abs err (of d) {e:.3e}");
    }
    println!("{nchecks} grid-angle values checked");
    assert!(
        fails.is_empty(),
        "{} failures:\n  {}",
        fails.len(),
        fails
            .iter()
            .take(50)
            .cloned()
            .collect::<Vec<_>>()
            .join("\n  ")
    );
}
